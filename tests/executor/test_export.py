"""``executor export``: the assembling cell as a URDF folder other tools can open."""

from __future__ import annotations

import re
import shutil
import xml.etree.ElementTree as ET
from pathlib import Path

import pybullet as pb
import pytest

from executor.assembly.export import export_cell
from executor.assembly.product import load_product


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
