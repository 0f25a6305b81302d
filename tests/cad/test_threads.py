"""Modelled helical threads: a screw in its nut is a screwed pair (pitch and lead measured),
slid along its axis and placed by hand; grooves of revolution are no thread."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh

from executor import ExecutorError
from executor.cad.derive import derive
from executor.cad.operations import cell_view
from executor.cad.parts import CadPart, _check_overlaps, load_meshes
from executor.cad.sweep import screwed_pairs

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


def test_a_thread_in_a_hole_drawn_at_its_tap_drill_is_named_in_the_overlap() -> None:
    # The 1/4-20 screw through a plate under its head whose hole is drawn at the thread's tap
    # drill (#7, d 5.105 mm) with no thread: the thread overlaps the plate; the refusal
    # names the thread and the plate.
    [screw] = [p for p in load_meshes(CORPUS / "bosl2_screw_nut" / "meshes", "mm") if p.id == "screw"]
    plate = trimesh.creation.annulus(r_min=5.105e-3 / 2, r_max=15e-3, height=5e-3, sections=48)
    plate.apply_translation([0.0, 0.0, 7.025e-3])  # z 4.525 to 9.525 mm, the head on it
    named = (r"'plate' and 'screw' overlap .*'screw' has a modelled thread "
             r"\(pitch 1\.27\d mm, d 6\.\d+ mm, along z\) in 'plate', which has no thread")
    with pytest.raises(ExecutorError, match=named):
        _check_overlaps([CadPart("plate", "plate", plate, "plate"), screw])


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
    assert plain.face.radius == pytest.approx(crest, abs=1e-9)
    assert derived.axis == {"screw": "+z"}
