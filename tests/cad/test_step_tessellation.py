"""A STEP product whose 1 µm tessellation passes its bound of triangles: its faces that are
no plane, cylinder or cone (a ball knob's sphere) are tessellated more coarsely, its planes
and cylinders as finely as before (a bored hole's diameter exact from the B-rep), the mesh
closed, and the import says so; where even the coarsest passes the bound, it is refused.
Components SolidWorks leaves unnamed (Open CASCADE names them by their records' ids,
``NAUO5``) are named after their parts."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from bridge.product.tables import is_id
from executor import ExecutorError
from executor.cad.cli import ImportOptions, run_import
from executor.cad.parts import STEP_DEFLECTION, part_id
from executor.cad.step import COARSE_DEFLECTIONS, load_step

HOLE = np.array([-0.015, 0.0])
"""The bored hole's axis (vertical) in the block [m]: radius 5 mm."""
BALL = np.array([0.015, 0.0, 0.010])
"""The centre of the ball knob on the block's top face [m]: radius 6 mm."""


@pytest.fixture(scope="module")
def ball_step(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A 60 x 40 x 20 mm block about the origin with a d 10 bored hole and a d 12 ball knob half
    out of its top, and a d 10 pin in the hole: an assembly ``ballblock`` of the components
    ``block`` and ``pin`` written by OCCT (OCP, which the STEP reader imports anyway; build123d
    on top of it was 2.4 s of CPU to import)."""
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut, BRepAlgoAPI_Fuse
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeCylinder, BRepPrimAPI_MakeSphere
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt
    from OCP.STEPCAFControl import STEPCAFControl_Writer
    from OCP.STEPControl import STEPControl_StepModelType
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDataStd import TDataStd_Name
    from OCP.TDocStd import TDocStd_Document
    from OCP.TopLoc import TopLoc_Location
    from OCP.XCAFDoc import XCAFDoc_DocumentTool

    def cylinder(x: float, z: float, height: float) -> Any:
        """A d 10 cylinder [mm] up the z axis from (x, 0, z)."""
        return BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(x, 0, z), gp_Dir(0, 0, 1)), 5, height).Shape()

    block = BRepAlgoAPI_Cut(BRepPrimAPI_MakeBox(gp_Pnt(-30, -20, -10), 60, 40, 20).Shape(), cylinder(-15, -10, 20))
    ball = BRepPrimAPI_MakeSphere(gp_Pnt(*(1000 * BALL)), 6).Shape()
    document = TDocStd_Document(TCollection_ExtendedString("XmlOcaf"))
    tool = XCAFDoc_DocumentTool.ShapeTool_s(document.Main())
    top = tool.NewShape()
    TDataStd_Name.Set_s(top, TCollection_ExtendedString("ballblock"))
    for name, shape in (("block", BRepAlgoAPI_Fuse(block.Shape(), ball).Shape()), ("pin", cylinder(-15, -5, 30))):
        label = tool.AddShape(shape, False)
        TDataStd_Name.Set_s(label, TCollection_ExtendedString(name))
        TDataStd_Name.Set_s(tool.AddComponent(top, label, TopLoc_Location()), TCollection_ExtendedString(name))
    tool.UpdateAssemblies()
    writer = STEPCAFControl_Writer()
    writer.SetNameMode(True)
    writer.Transfer(document, STEPControl_StepModelType.STEPControl_AsIs)
    path = tmp_path_factory.mktemp("step") / "ball.step"
    writer.Write(str(path))
    return path


def _on_hole(vertices: np.ndarray) -> int:
    """The vertices [m] on the bored hole's cylinder."""
    return int(np.sum(np.abs(np.linalg.norm(vertices[:, :2] - HOLE, axis=1) - 0.005) < 1e-9))


def _ball_gap(mesh: object) -> float:
    """The largest distance [m] of a triangle's centroid inside the ball knob from its sphere."""
    vertices = np.asarray(mesh.vertices)  # type: ignore[attr-defined]
    corners = vertices[np.asarray(mesh.faces)]  # type: ignore[attr-defined]
    on_ball = np.all(np.abs(np.linalg.norm(corners - BALL, axis=2) - 0.006) < 1e-9, axis=1)
    return float(0.006 - np.linalg.norm(corners[on_ball].mean(axis=1) - BALL, axis=1).min())


@pytest.mark.slow
def test_a_step_product_past_its_bound_is_tessellated_coarser_off_its_fits(ball_step: Path) -> None:
    fine = {part.id: part for part in load_step(ball_step)}
    total = sum(len(part.mesh.faces) for part in fine.values())
    assert [part.coarse_faces for part in fine.values()] == [0, 0]
    assert _ball_gap(fine["block"].mesh) <= STEP_DEFLECTION * 1.01
    coarse = {part.id: part for part in load_step(ball_step, total - 1)}
    block = coarse["block"]
    assert (block.coarse_faces, coarse["pin"].coarse_faces) == (1, 0)  # the sphere alone
    assert block.coarse_deflection == COARSE_DEFLECTIONS[0]
    assert sum(len(part.mesh.faces) for part in coarse.values()) < total / 4
    assert block.mesh.is_watertight
    assert STEP_DEFLECTION * 1.01 < _ball_gap(block.mesh) <= COARSE_DEFLECTIONS[0] * 1.01
    # the bored hole's cylinder tessellated as before
    assert _on_hole(np.asarray(block.mesh.vertices)) == _on_hole(np.asarray(fine["block"].mesh.vertices)) > 100
    with pytest.raises(ExecutorError, match=r"block: \d+ triangles, beyond the bound of 1000 .* within 0.025 mm"):
        load_step(ball_step, 1000)


@pytest.mark.slow
def test_the_import_of_a_coarser_step_product_keeps_its_hole_exact_and_says_so(ball_step: Path,
                                                                               tmp_path: Path) -> None:
    total = sum(len(part.mesh.faces) for part in load_step(ball_step))
    done = run_import(ball_step, tmp_path / "out", "mm", None, ImportOptions(max_triangles=total - 1))
    fit = done.derived.hole_of["pin"]
    assert fit.hole.kind == "round" and fit.hole.a == pytest.approx(0.010, abs=1e-9)
    assert ("STEP faces that are no plane, cylinder or cone (1 face of block) tessellated within 0.01 mm, the "
            f"finest of 0.001, 0.01, 0.025 mm within {total - 1} triangles") in "; ".join(done.assumed)


def test_components_named_by_their_record_ids_are_named_after_their_parts(ball_step: Path, tmp_path: Path) -> None:
    # as SolidWorks writes them: the name blank, the id NAUO<n>
    text = re.sub(r"NEXT_ASSEMBLY_USAGE_OCCURRENCE\s*\(\s*'(\d+)'\s*,\s*'(block|pin)'\s*,\s*''",
                  r"NEXT_ASSEMBLY_USAGE_OCCURRENCE('NAUO\1',' ',' '", ball_step.read_text())
    assert text.count("'NAUO") == 2
    (tmp_path / "nauo.step").write_text(text)
    assert [part.id for part in load_step(tmp_path / "nauo.step")] == ["block", "pin"]


def test_a_part_number_gives_a_part_id() -> None:
    assert part_id("01_02_01-block_Standard", "cutting_unit.step") == "part_01_02_01_block_standard"
    with pytest.raises(ExecutorError, match="gives no part id"):
        part_id("_block", "cutting_unit.step")


def test_a_long_name_gives_a_part_id_its_features_ids_fit_after() -> None:
    # SolidWorks' names: 62 characters made a bearing's hole id (`..._hole1`) too long for an id
    long = "01_02_05-deep_groove_ball_bearing_fag_6005_2z_standard_skf_iso"
    first, second = part_id(long + "_1", "unit.step"), part_id(long + "_2", "unit.step")
    assert first.startswith("part_01_02_05_deep_groove_ball_bearing") and len(first) == 48
    assert first != second and first == part_id(long + "_1", "other.step")
    assert is_id(f"{first}_hole12") and not is_id(f"part_{long.replace('-', '_')}_1_hole12")


def test_a_step_leaf_left_out_is_neither_tessellated_nor_counted(ball_step: Path) -> None:
    pin = {part.id: part for part in load_step(ball_step)}["pin"]
    bound = len(pin.mesh.faces)  # the block alone passes it at its coarsest: above
    seen: list[list[str]] = []

    def kept(ids: list[str]) -> set[str]:
        seen.append(ids)
        return {"pin"}

    parts = load_step(ball_step, bound, kept)
    assert seen == [["block", "pin"]] and [part.id for part in parts] == ["pin"]
    assert len(parts[0].mesh.faces) == bound and parts[0].coarse_faces == 0
