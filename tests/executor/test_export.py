"""``executor export``: the assembling cell as a URDF folder other tools can open."""

from __future__ import annotations

import re
import shutil
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pybullet as pb
import pytest

from executor.assembly.export import export_cell
from executor.assembly.product import load_product
from tests._files_helpers import leftovers, run_with_file_limit
from tests.conftest import CLI_MODULE


@pytest.mark.slow
def test_the_exported_cell_holds_every_part_and_the_arm_and_loads_from_a_moved_folder(tmp_path: Path) -> None:
    export_cell("cranfield", tmp_path / "cell")
    moved = shutil.move(tmp_path / "cell", tmp_path / "elsewhere")  # relative mesh paths only
    urdf = Path(moved) / "cell.urdf"
    robot = ET.parse(urdf).getroot()
    links = {link.get("name") for link in robot.iter("link")}
    assert set(load_product("cranfield").parts) <= links
    assert {"world", "lbr_iiwa_link_0", "lbr_iiwa_link_7", "flange"} <= links
    for mesh in robot.iter("mesh"):
        assert (Path(moved) / mesh.get("filename", "")).is_file()
    assert not re.search(r'filename="/', urdf.read_text())
    client = pb.connect(pb.DIRECT)
    try:
        body = pb.loadURDF(str(urdf), useFixedBase=True, physicsClientId=client)
        names = {pb.getJointInfo(body, j, physicsClientId=client)[12].decode()
                 for j in range(pb.getNumJoints(body, physicsClientId=client))}
    finally:
        pb.disconnect(client)
    assert names == links - {"world"}


@pytest.mark.slow
def test_a_full_disk_leaves_no_torn_file(tmp_path: Path) -> None:
    """Files of at most 120 kB (the first arm mesh, 185 kB, cannot be written): one line,
    exit 2, and every file that is there is whole (the same bytes as a full export's
    copy of it), no temporary file left."""
    export_cell("cranfield", tmp_path / "whole")
    out = tmp_path / "out"
    done = run_with_file_limit([sys.executable, "-m", CLI_MODULE, "executor", "export", str(out)], limit=120_000)
    assert done.returncode == 2, done.stderr
    assert done.stderr.splitlines()[-1].endswith(": cannot write (File too large)"), done.stderr
    assert "Traceback" not in done.stderr
    files = [p for p in out.rglob("*") if p.is_file()]
    assert leftovers(out / "meshes") == []
    for path in files:
        assert path.name != "cell.urdf"  # written last, after every mesh it names
        assert path.read_bytes() == (tmp_path / "whole" / path.relative_to(out)).read_bytes(), path.name
