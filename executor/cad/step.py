"""STEP assemblies through Open CASCADE (``OCP``, the cadquery-ocp wheels): one part per
leaf of the assembly tree with its name and its placement (the product of the locations
on the path from the root), tessellated to a closed triangle mesh [m], with the
cylindrical faces of its B-rep (axis and radius, exact where the tessellation is within
:data:`STEP_DEFLECTION` of them; planar faces tessellate exactly), and the means to
tessellate it again more coarsely (``CadPart.remesh``: the simulated cell's base).

Open CASCADE reads a STEP file's own length unit and gives millimetres; this module
converts to metres. A leaf without a name is named after its parent and position.
"""

from __future__ import annotations

import functools
from pathlib import Path
from typing import Any

import numpy as np
import trimesh

from assembly_constraints.executor import ExecutorError
from assembly_constraints.executor.cad.parts import STEP_DEFLECTION, CadPart, Cylinder, part_id

_MM = 1e-3
FINE_ANGLE = 0.1
"""The angular deflection of the tessellation the import measures on [rad]."""
COARSE_ANGLE = 0.5
"""The angular deflection of a part tessellated again for the cell [rad]: loose enough
that the linear deflection decides how many sides a round hole gets."""


def load_step(path: Path) -> list[CadPart]:
    """The leaves of the STEP assembly at ``path`` as parts; ExecutorError naming the file
    when it is not a readable STEP file or holds no solid."""
    from OCP.collections import Sequence_TDF_Label
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPCAFControl import STEPCAFControl_Reader
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDocStd import TDocStd_Document
    from OCP.XCAFDoc import XCAFDoc_DocumentTool

    document = TDocStd_Document(TCollection_ExtendedString("XmlOcaf"))
    reader = STEPCAFControl_Reader()
    reader.SetNameMode(True)
    if reader.ReadFile(str(path)) != IFSelect_RetDone or not reader.Transfer(document):
        raise ExecutorError(f"{path}: not a readable STEP file")
    tool = XCAFDoc_DocumentTool.ShapeTool_s(document.Main())
    roots = Sequence_TDF_Label()
    tool.GetFreeShapes(roots)
    leaves: list[tuple[str, Any]] = []
    for k in range(1, roots.Length() + 1):
        _collect(tool, roots.Value(k), None, _name(roots.Value(k)) or path.stem, leaves)
    if not leaves:
        raise ExecutorError(f"{path}: no solid parts in the STEP file")
    return [CadPart(part_id(name, f"{path}#{name}"), name, _mesh(shape, f"{path}#{name}"), f"{path}#{name}",
                    _cylinders(shape), functools.partial(_mesh, shape, f"{path}#{name}", angle=COARSE_ANGLE))
            for name, shape in leaves]


def _name(label: Any) -> str:
    from OCP.TDataStd import TDataStd_Name

    attribute = TDataStd_Name()
    if label.FindAttribute(TDataStd_Name.GetID_s(), attribute):
        return attribute.Get().ToExtString()
    return ""


def _collect(tool: object, label: Any, location: Any, name: str, leaves: list[tuple[str, Any]]) -> None:
    """Append ``(name, located shape)`` for every leaf under ``label``; ``location`` is the
    placement of ``label`` in the product (None at a root)."""
    from OCP.collections import Sequence_TDF_Label
    from OCP.TDF import TDF_Label
    from OCP.TopLoc import TopLoc_Location
    from OCP.XCAFDoc import XCAFDoc_ShapeTool

    here = location if location is not None else TopLoc_Location()
    referred = TDF_Label()
    definition = referred if XCAFDoc_ShapeTool.GetReferredShape_s(label, referred) else label
    if XCAFDoc_ShapeTool.IsAssembly_s(definition):
        children = Sequence_TDF_Label()
        XCAFDoc_ShapeTool.GetComponents_s(definition, children, False)
        for k in range(1, children.Length() + 1):
            child = children.Value(k)
            placement = here.Multiplied(XCAFDoc_ShapeTool.GetLocation_s(child))
            _collect(tool, child, placement, _name(child) or _name(definition) or f"{name}_{k}", leaves)
        return
    shape = XCAFDoc_ShapeTool.GetShape_s(definition)
    leaves.append((name, shape.Located(here.Multiplied(shape.Location()))))


def _mesh(shape: Any, source: str, deflection: float = STEP_DEFLECTION, angle: float = FINE_ANGLE) -> trimesh.Trimesh:
    """The shape's faces tessellated into one mesh [m]: no point of a face farther than
    ``deflection`` [m] from its triangles, no two normals of one triangle's corners more
    than ``angle`` [rad] apart (the triangles' corners lie on the faces)."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepMesh import BRepMesh_IncrementalMesh
    from OCP.BRepTools import BRepTools
    from OCP.TopAbs import TopAbs_FACE, TopAbs_REVERSED
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopLoc import TopLoc_Location
    from OCP.TopoDS import TopoDS

    BRepTools.Clean_s(shape)  # a coarser tessellation replaces an earlier one (it would only refine it)
    BRepMesh_IncrementalMesh(shape, deflection / _MM, False, angle, True)
    vertices: list[np.ndarray] = []
    faces: list[np.ndarray] = []
    count = 0
    explorer = TopExp_Explorer(shape, TopAbs_FACE)
    while explorer.More():
        face = TopoDS.Face(explorer.Current())
        location = TopLoc_Location()
        triangulation = BRep_Tool.Triangulation_s(face, location)
        explorer.Next()
        if triangulation is None:
            continue
        transform = location.Transformation()
        points = []
        for i in range(1, triangulation.NbNodes() + 1):
            p = triangulation.Node(i).Transformed(transform)
            points.append((p.X(), p.Y(), p.Z()))
        triangles = np.array([triangulation.Triangle(i).Get() for i in range(1, triangulation.NbTriangles() + 1)])
        triangles = triangles - 1
        if face.Orientation() == TopAbs_REVERSED:
            triangles = triangles[:, ::-1]
        vertices.append(np.array(points) * _MM)
        faces.append(triangles + count)
        count += len(points)
    if not faces:
        raise ExecutorError(f"{source}: the part has no faces to tessellate")
    mesh = trimesh.Trimesh(np.vstack(vertices), np.vstack(faces), process=True)
    mesh.merge_vertices(digits_vertex=9)
    return mesh


def _cylinders(shape: Any) -> tuple[Cylinder, ...]:
    """The cylindrical faces of the located ``shape`` [m] (a cylinder split by seams
    appears once per face)."""
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.GeomAbs import GeomAbs_Cylinder
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    found: list[Cylinder] = []
    explorer = TopExp_Explorer(shape, TopAbs_FACE)
    while explorer.More():
        surface = BRepAdaptor_Surface(TopoDS.Face(explorer.Current()))  # with the face's location
        explorer.Next()
        if surface.GetType() != GeomAbs_Cylinder:
            continue
        cylinder = surface.Cylinder()
        axis = cylinder.Axis()
        point, direction = axis.Location(), axis.Direction()
        found.append(Cylinder(np.array([point.X(), point.Y(), point.Z()]) * _MM,
                              np.array([direction.X(), direction.Y(), direction.Z()]), cylinder.Radius() * _MM))
    return tuple(found)
