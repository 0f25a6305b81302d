"""Modelled helical threads: a screw in its nut, or in a plain hole at its tap drill, is a
screwed pair (pitch and lead measured), slid along its axis and placed by hand; a plain
cylinder in a standard thread's tap drill is one drawn with a cosmetic thread; grooves of
revolution and press fits are no thread."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import trimesh

from executor import ExecutorError
from executor.cad.derive import derive
from executor.cad.fits.faces import fit_faces, press_fits
from executor.cad.fits.threads import cosmetic_pairs, cosmetic_thread, screwed_pairs
from executor.cad.operations.view import cell_view
from executor.cad.parts import CadPart, _check_overlaps, load_meshes
from tests.conftest import Runner

CORPUS = Path(__file__).parent / "corpus"


def test_a_screw_in_its_nut_is_screwed_with_the_libraries_pitch_and_placed_by_hand() -> None:
    # BOSL2's 1/4-20 UNC screw (pitch 1.27 mm, right-handed) in its nut: every straight way
    # out collides with the nut's thread, so without the pair the screw never comes out.
    parts = load_meshes(CORPUS / "bosl2_screw_nut" / "meshes", "mm")
    derived = derive(parts, "nut", {})
    [pair] = [s for s in derived.slides if s.pitch]
    assert (pair.shaft, pair.bore) == ("screw", "nut")
    assert np.allclose(np.abs(pair.direction), [0, 0, 1])
    assert pair.pitch == pytest.approx(1.27e-3, abs=2e-5)
    assert pair.lead * np.sign(pair.direction[2]) == pytest.approx(pair.pitch)  # one start, right-handed about +z
    assert derived.axis == {"screw": "+z"}  # out past its head's side only: the head stops it along -z
    assert derived.blockers[("screw", "-z")] == {"nut"}
    _, by_hand = cell_view(derived)
    assert "screwed into 'nut'" in by_hand["screw"] and "modelled thread" in by_hand["screw"]


def _grooved(outer: bool) -> trimesh.Trimesh:
    """A rod (``outer`` False) or a ring round it (True) whose surface at the other is
    grooved by rings 1 mm apart, 0.5 mm deep (a surface of revolution: no thread) [m]."""
    z = np.linspace(0.0, 10.0, 41)
    wave = 2.5 + np.abs((z % 1.0) - 0.5)  # a triangular wave, radius 2.5 to 3.0 mm
    if outer:
        profile = np.column_stack([np.concatenate([wave + 0.05, [6.0, 6.0, wave[0] + 0.05]]),
                                   np.concatenate([z, [10.0, 0.0, 0.0]])])
    else:
        profile = np.column_stack([np.concatenate([[0.0], wave, [0.0]]), np.concatenate([[0.0], z, [10.0]])])
    mesh = trimesh.creation.revolve(profile[::-1] if outer else profile, sections=64)
    mesh.apply_scale(1e-3)
    if mesh.volume < 0:
        mesh.invert()
    return mesh


def test_grooves_of_revolution_are_no_thread_and_the_rod_never_comes_out() -> None:
    rod, ring = _grooved(False), _grooved(True)
    assert rod.is_watertight and ring.is_watertight
    assert screwed_pairs({"rod": rod, "ring": ring}) == []
    with pytest.raises(ExecutorError, match="rod never come out"):
        derive([CadPart("ring", "ring", ring, "ring"), CadPart("rod", "rod", rod, "rod")], "ring", {})


def _corpus_screw() -> CadPart:
    """BOSL2's 1/4-20 UNC screw of the corpus (pitch 1.27 mm, its head on z 9.525 mm)."""
    [screw] = [p for p in load_meshes(CORPUS / "bosl2_screw_nut" / "meshes", "mm") if p.id == "screw"]
    return screw


def _plate(hole_mm: float, low_mm: float, high_mm: float) -> CadPart:
    """A plate 30 mm across from z ``low_mm`` to ``high_mm`` with a plain round hole of
    diameter ``hole_mm`` about the z axis (48 sides)."""
    plate = trimesh.creation.annulus(r_min=hole_mm / 2e3, r_max=15e-3, height=(high_mm - low_mm) / 1e3, sections=48)
    plate.apply_translation([0.0, 0.0, (low_mm + high_mm) / 2e3])
    return CadPart("plate", "plate", plate, "plate")


def test_a_modelled_thread_in_a_plain_hole_at_its_tap_drill_is_screwed() -> None:
    # The 1/4-20 screw through a plate under its head whose hole is drawn at the thread's tap
    # drill (#7, d 5.105 mm) with no thread: the thread overlaps the plate's wall (16 mm³),
    # excused in the annulus from the hole out to the thread's crest; a screwed pair.
    parts = [_plate(5.105, 4.525, 9.525), _corpus_screw()]
    _check_overlaps(parts)
    derived = derive(parts, "plate", {})
    [pair] = derived.slides
    assert (pair.shaft, pair.bore) == ("screw", "plate")
    assert pair.thread == "a modelled thread in a plain hole at its tap drill"
    assert pair.pitch == pytest.approx(1.27e-3, abs=2e-5) and pair.hole.radius == pytest.approx(2.55e-3, abs=5e-6)
    assert derived.axis == {"screw": "+z"}  # its head stops it along -z
    assert "screwed into 'plate' along -z (a modelled thread in a plain hole" in cell_view(derived)[1]["screw"]


def test_a_thread_in_a_hole_below_its_minor_diameter_is_named_in_the_overlap() -> None:
    # The hole drawn at d 4.6, inside the thread's root (d 5.0): the screw's core overlaps
    # the plate too, no tap drill: refused, the thread and the plate named.
    named = (r"'plate' and 'screw' overlap .*'screw' has a modelled thread "
             r"\(pitch 1\.27\d mm, d 6\.\d+ mm, along z\) in 'plate', which has no thread")
    with pytest.raises(ExecutorError, match=named):
        _check_overlaps([_plate(4.6, 4.525, 9.525), _corpus_screw()])


def _cosmetic(shank_mm: float, hole_mm: float, sunk_mm: float = 0.0) -> list[CadPart]:
    """A plate (z 5 to 10 mm) with a plain hole of d ``hole_mm`` and a plain "screw": a
    shank of d ``shank_mm`` from z -2 mm up to its head (d 1.8 times it, 3 mm high) on the
    plate, sunk ``sunk_mm`` into it (negative: above it; 64 sides each)."""
    shank = trimesh.creation.cylinder(radius=shank_mm / 2e3, height=(12.5 - sunk_mm) * 1e-3, sections=64)
    shank.apply_translation([0.0, 0.0, (4.25 - sunk_mm / 2) * 1e-3])  # z -2 to 0.5 mm into the head
    head = trimesh.creation.cylinder(radius=shank_mm * 0.9e-3, height=3e-3, sections=64)
    head.apply_translation([0.0, 0.0, (11.5 - sunk_mm) * 1e-3])
    screw = trimesh.boolean.union([shank, head])
    return [_plate(hole_mm, 5.0, 10.0), CadPart("screw", "screw", screw, "screw")]


def test_a_plain_screw_in_its_tap_drill_is_drawn_with_a_cosmetic_thread() -> None:
    # M4 drawn at d 4 in its tap drill d 3.3 (ISO coarse, pitch 0.7): the overlap (20 mm³)
    # lies in the annulus d 3.3 to 4 and is excused; the pair is screwed at M4's pitch.
    parts = _cosmetic(4.0, 3.3)
    _check_overlaps(parts)
    derived = derive(parts, "plate", {})
    [pair] = derived.slides
    assert (pair.shaft, pair.bore) == ("screw", "plate")
    assert pair.thread == "a cosmetic thread, M4: d 4 in its 3.3 mm tap drill"
    assert pair.pitch == pytest.approx(0.7e-3) and pair.lead == pytest.approx(0.7e-3)
    assert derived.axis == {"screw": "+z"}
    assert "(a cosmetic thread, M4: d 4 in its 3.3 mm tap drill, pitch 0.700 mm)" in cell_view(derived)[1]["screw"]


@pytest.mark.parametrize(("shaft", "hole", "thread"), [
    (3.0, 2.5, ("M3", 0.5)), (8.0, 6.8, ("M8", 1.25)), (8.0, 7.0, ("M8x1", 1.0)), (10.0, 8.8, ("M10x1.25", 1.25)),
    (6.35, 5.105, ("1/4-20 UNC", 1.27)), (6.35, 5.41, ("1/4-28 UNF", 25.4 / 28)),
    (4.826, 3.8, ("#10-24 UNC", 25.4 / 24)),
    (16.0, 15.9, None), (17.0, 15.0, None), (4.0, 3.0, None), (4.0, 3.6, None), (3.9, 3.3, ("M4", 0.7)),
    # ISO 261's third choice and the UNEF series
    (15.0, 14.0, ("M15x1", 1.0)), (17.0, 16.0, ("M17x1", 1.0)), (11.0, 9.5, ("M11", 1.5)),
    (6.35, 5.65, ("1/4-32 UNEF", 25.4 / 32)), (19.05, 17.8, ("3/4-20 UNEF", 1.27)),
    # nearest major diameter first: 1-8 UNC's ranges hold d 25 in d 23 too
    (25.0, 23.0, ("M25x2", 2.0)),
    # one major diameter, two pitches: the common tap drill D - P nearest the hole
    (6.35, 5.556, ("1/4-32 UNEF", 25.4 / 32)), (6.35, 5.49, ("1/4-28 UNF", 25.4 / 28)),
    (12.0, 10.7, ("M12x1.25", 1.25)),
    # every pitch of ISO 261's first and second choice, and the 8-UN, large UNC and small UNF sizes
    (12.0, 11.0, ("M12x1", 1.0)), (16.0, 15.0, ("M16x1", 1.0)), (7.0, 6.0, ("M7", 1.0)), (2.2, 1.75, ("M2.2", 0.45)),
    (38.1, 34.925, ("1 1/2-8 UN", 3.175)), (50.8, 45.2, ("2-4.5 UNC", 25.4 / 4.5)),
    (1.524, 1.191, ("#0-80 UNF", 0.3175)),
])
def test_the_standard_threads_tap_drills(shaft: float, hole: float, thread: tuple[str, float] | None) -> None:
    # the shaft from D - P/4 to D, the hole from D - 1.0825 P to D - 0.85 P (10 µm slack)
    found = cosmetic_thread(shaft * 1e-3, hole * 1e-3, 1e-5)
    assert (found and (found[0], round(found[1] * 1e3, 4))) == (thread and (thread[0], round(thread[1], 4)))


@pytest.mark.parametrize(("shank", "hole", "sunk"), [
    (17.0, 15.0, 0.0),  # d 15 is no tap drill of M17 (M17x1.5: 15.376 mm up) nor of a thread nearer
    (4.0, 3.3, 0.5),  # M4 in its tap drill, its head sunk 0.5 mm into the plate: outside the annulus
])
def test_an_interference_that_is_no_cosmetic_thread_is_refused(shank: float, hole: float, sunk: float) -> None:
    with pytest.raises(ExecutorError, match="'plate' and 'screw' overlap by"):
        _check_overlaps(_cosmetic(shank, hole, sunk))


def test_a_shank_wider_than_its_hole_by_no_tap_drill_is_a_press_fit_not_a_cosmetic_thread() -> None:
    # d 16 in d 15.9: no thread's tap drill, 0.05 mm per side: pressed, its annulus excused
    parts = _cosmetic(16.0, 15.9)
    _check_overlaps(parts)
    faces = {p.id: fit_faces(p.mesh) for p in parts}
    assert cosmetic_pairs(faces) == []
    [pressed] = press_fits(faces)
    assert (pressed.shaft, pressed.bore, round(pressed.interference * 1e3, 3)) == ("screw", "plate", 0.05)


@pytest.mark.parametrize(("shank", "hole", "name", "pitch"), [
    (15.0, 14.0, "M15x1", 1.0),  # ISO 261's third choice, fine pitch only
    (6.35, 5.65, "1/4-32 UNEF", 25.4 / 32),
])
def test_a_third_choice_or_unef_screw_in_its_tap_drill_is_a_cosmetic_thread(shank: float, hole: float, name: str,
                                                                          pitch: float) -> None:
    parts = _cosmetic(shank, hole)
    _check_overlaps(parts)
    [pair] = derive(parts, "plate", {}).slides
    assert (pair.shaft, pair.bore, pair.thread) == ("screw", "plate", f"a cosmetic thread, {name}: d {shank:g} in "
                                                                      f"its {hole:g} mm tap drill")
    assert pair.pitch == pytest.approx(pitch * 1e-3)


def test_a_bracket_clamped_by_a_cosmetic_screw_goes_before_it() -> None:
    # A bracket (z 10 to 13 mm, a d 4.5 clearance hole) between the plate's tapped M4 hole
    # and the screw's head: the head closes its way up, the shank its ways across.
    plate, screw = _cosmetic(4.0, 3.3, sunk_mm=-3.0)
    bracket = trimesh.creation.annulus(r_min=2.25e-3, r_max=8e-3, height=3e-3, sections=64)
    bracket.apply_translation([0.0, 0.0, 11.5e-3])
    parts = [plate, screw, CadPart("bracket", "bracket", bracket, "bracket")]
    _check_overlaps(parts)
    derived = derive(parts, "plate", {})
    assert derived.stages == [["screw"], ["bracket"]]
    assert derived.reasons[("bracket", "screw")] == "blocks"
    assert set(cell_view(derived)[1]) == {"screw"}


def _imported(run_main: Runner, parts: list[CadPart], folder: Path) -> str:
    """``parts`` written as STL in mm under ``folder`` and imported, the plate the base,
    into ``folder / "out"``; what the import printed."""
    (folder / "cad").mkdir()
    for part in parts:
        mesh = part.mesh.copy()
        mesh.apply_scale(1e3)
        mesh.export(folder / "cad" / f"{part.id}.stl")
    (folder / "import.toml").write_text('base = "plate"\n')
    done = run_main("import", str(folder / "cad"), "--config", str(folder / "import.toml"), "--out",
                    str(folder / "out"))
    assert done.returncode == 0, done.stderr
    return done.stdout


@pytest.mark.slow  # imports the product and runs a session
@pytest.mark.parametrize(("drawn", "backend"), [("tap drill", "truth"), ("cosmetic", "sim")])
def test_a_screw_in_a_tap_drill_hole_reaches_a_session(run_main: Runner, tmp_path: Path, drawn: str,
                                                         backend: str) -> None:
    parts = [_plate(5.105, 4.525, 9.525), _corpus_screw()] if drawn == "tap drill" else _cosmetic(4.0, 3.3)
    printed = _imported(run_main, parts, tmp_path)
    thread = "a modelled thread in a plain hole at its tap drill" if drawn == "tap drill" else "a cosmetic thread, M4"
    assert f"screwed pair screw in plate ({thread}" in printed
    session = run_main("session", "--backend", backend, "--json", "--assemble", "--assembly", str(tmp_path / "out"),
                       "--out", str(tmp_path / "run"), timeout=240)
    assert session.returncode == 0, session.stderr
    result = json.loads(session.stdout)
    steps = {step["part"]: step for step in result["assembly"]["steps"]}
    assert result["assembly"]["assembled"] and steps["screw"]["skill"] == "manual"
    assert "the cell has no screwing operation" in result["assembly"]["manual_reasons"]["screw"]


@pytest.mark.slow  # the corpus screw and nut derived (1.5 s); a clamped part before its screw: the bracket's test
def test_the_screw_goes_after_the_plate_it_clamps_on_its_nut() -> None:
    # A plate with a d 7 clearance hole between the nut's top (z 6.095) and the screw's head
    # (z 9.525): the head closes the plate's way up, the shank its ways across, so the plate
    # precedes the screw (blocks); the screw, slid along its thread, leaves upwards.
    parts = load_meshes(CORPUS / "bosl2_screw_nut" / "meshes", "mm")
    plate = trimesh.creation.annulus(r_min=3.5e-3, r_max=15e-3, height=3.43e-3, sections=48)
    plate.apply_translation([0.0, 0.0, (6.095e-3 + 9.525e-3) / 2])
    derived = derive([*parts, CadPart("plate", "plate", plate, "plate")], "nut", {})
    assert derived.stages == [["screw"], ["plate"]]
    assert derived.reasons[("plate", "screw")] == "blocks"
    assert ("screw", "plate") not in derived.reasons
    assert set(cell_view(derived)[1]) == {"screw"}


def test_a_thread_in_a_plain_hole_of_its_crest_diameter_slides_out() -> None:
    # The nut replaced by a plate as thick whose hole is drawn at the thread's crest
    # diameter (a hole drawn at the screw's nominal size, as build123d's joint tutorial
    # draws an M6 screw's in its box): the 96-gon's chords cut into the crests, so every
    # straight way out collided and the screw never came out. It is a zero-clearance fit,
    # no screwed pair: the screw slides out of the plate along its axis.
    [screw] = [p for p in load_meshes(CORPUS / "bosl2_screw_nut" / "meshes", "mm") if p.id == "screw"]
    inside = (screw.mesh.vertices[:, 2] > 0.5e-3) & (screw.mesh.vertices[:, 2] < 5.5e-3)
    crest = float(np.linalg.norm(screw.mesh.vertices[inside, :2], axis=1).max())  # its vertex circle
    plate = trimesh.creation.annulus(r_min=crest, r_max=15e-3, height=6.095e-3, sections=96)
    plate.apply_translation([0.0, 0.0, 6.095e-3 / 2])
    derived = derive([screw, CadPart("plate", "plate", plate, "plate")], "plate", {})
    [plain] = derived.slides
    assert (plain.shaft, plain.bore, plain.pitch, plain.seated) == ("screw", "plate", 0.0, True)
    assert plain.face.radius == pytest.approx(crest, abs=1e-8)  # the vertex circle: its chords' sag is 1.65 µm
    assert derived.axis == {"screw": "+z"}
