"""Generated assets follow their sources: ``<assembly>/assets/`` records the digest of the
``geometry.toml`` and ``assembly.toml`` values it was made from, and a cell regenerates
assets that no longer match before it uses them; the shipped ones match."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pybullet as pb
import pytest

from bridge.assembly import DATA_DIR
from executor.world.assets import STAMP, current_assets, sources_digest
from executor.world.geometry import load_geometry, plate_obj_text
from executor.world.scene import connect, load_plate
from tests._tolerances import assert_same_asset

WITH_ASSETS = sorted(p.parent.parent.name for p in DATA_DIR.glob("*/assets/plate.obj"))
NARROW_S2 = ('[hole_shapes.square]\nholes = ["s1", "s2"]',
             '[hole_shapes.narrow]\nholes = ["s2"]\nkind = "square"\nsize = 0.010\n\n'
             '[hole_shapes.square]\nholes = ["s1"]')
"""s2 from 13.3 mm to 10 mm, below the 12 mm square pegs (s1, where the square peg's skill was taught, kept:
a skill whose teaching hole changed is refused)."""


@pytest.fixture
def cranfield(tmp_path: Path) -> Path:
    """A copy of data/cranfield with its assets."""
    return Path(shutil.copytree(DATA_DIR / "cranfield", tmp_path / "asm"))


def _narrow_s2(folder: Path) -> None:
    path = folder / "geometry.toml"
    text = path.read_text()
    assert NARROW_S2[0] in text
    path.write_text(text.replace(*NARROW_S2))


@pytest.mark.parametrize("assembly", WITH_ASSETS)
def test_the_shipped_assets_match_their_sources(assembly: str) -> None:
    geometry = load_geometry(assembly)
    assert (geometry.assets / STAMP).read_text() == sources_digest(geometry) + "\n"
    assert_same_asset((geometry.assets / "plate.obj").read_text(), plate_obj_text(geometry))


def test_stale_assets_are_regenerated_before_use(cranfield: Path) -> None:
    _narrow_s2(cranfield)
    geometry = load_geometry(str(cranfield))
    assert (geometry.assets / STAMP).read_text() != sources_digest(geometry) + "\n"
    assert current_assets(geometry) == geometry.assets
    assert (geometry.assets / STAMP).read_text() == sources_digest(geometry) + "\n"
    assert_same_asset((geometry.assets / "plate.obj").read_text(), plate_obj_text(geometry))
    (geometry.assets / "part_shaft.urdf").unlink()  # a generated file missing: made again
    current_assets(geometry)
    assert (geometry.assets / "part_shaft.urdf").is_file()


def test_an_edit_the_assets_do_not_depend_on_keeps_them(cranfield: Path) -> None:
    layout = cranfield / "assembly.toml"
    layout.write_text(layout.read_text().replace('name = "round peg 1"', 'name = "renamed"', 1) + "# a comment\n")
    stamp = cranfield / "assets" / STAMP
    before = stamp.stat().st_mtime_ns
    geometry = load_geometry(str(cranfield))
    assert stamp.read_text() == sources_digest(geometry) + "\n"
    current_assets(geometry)
    assert stamp.stat().st_mtime_ns == before  # not regenerated


def test_assets_that_cannot_be_regenerated_are_refused_naming_the_file(cranfield: Path) -> None:
    from executor import ExecutorError

    _narrow_s2(cranfield)
    (cranfield / "assets" / "plate.obj").unlink()
    (cranfield / "assets" / "plate.obj").mkdir()  # cannot be replaced by a file
    with pytest.raises(ExecutorError, match=r"assets/plate\.obj: cannot write \(Is a directory\)"):
        current_assets(load_geometry(str(cranfield)))


def test_a_new_client_loads_a_regenerated_plate(cranfield: Path) -> None:
    """PyBullet caches parsed Wavefront files per process by path: a client made after the
    plate was regenerated under the same path must read the new file (a ray down the narrowed
    s2, 6 mm off its centre, meets the floor of the 13.3 mm hole, then the top of the 10 mm one)."""
    def depth_at_s2() -> float:
        geometry = load_geometry(str(cranfield))
        client = connect()
        try:
            plate = load_plate(client, geometry, current_assets(geometry) / "plate.obj")
            x, y = geometry.holes["s2"].position
            hit = pb.rayTest((x + 0.006, y, 1.0), (x + 0.006, y, 0.0), physicsClientId=client)[0]
            assert hit[0] == plate
            return geometry.plate.top_z - hit[3][2]
        finally:
            pb.disconnect(client)

    assert depth_at_s2() > 0.02  # down to the tile's bottom (25 mm deep)
    _narrow_s2(cranfield)
    assert depth_at_s2() < 0.001  # the tile's top


@pytest.mark.slow
def test_a_trial_after_editing_a_hole_sees_the_edit(cranfield: Path, run_main) -> None:
    """Both trials in this process: the plate the first one loaded is not simulated after the edit."""
    first = run_main("executor", "trial", "--part", "p3", "--hole", "s2", "--assembly", str(cranfield), "--json")
    assert first.returncode == 0, first.stderr
    assert json.loads(first.stdout)["trials"][0]["outcome"] == "fit"
    _narrow_s2(cranfield)
    done = run_main("executor", "trial", "--part", "p3", "--hole", "s2", "--assembly", str(cranfield), "--json")
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["trials"][0]["outcome"] == "no_fit"
