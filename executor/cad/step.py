"""STEP assemblies through Open CASCADE (``OCP``, the cadquery-ocp wheels): one part per
leaf of the assembly tree with its name and its placement (the product of the locations
on the path from the root), tessellated to a closed triangle mesh [m], with the
cylindrical faces of its B-rep (axis and radius, exact where the tessellation is within
:data:`STEP_DEFLECTION` of them; planar faces tessellate exactly), and the means to
tessellate it again more coarsely (``CadPart.remesh``: the simulated cell's base).

Open CASCADE reads a STEP file's own length unit and gives millimetres; this module
converts to metres. A leaf without a name is named after its parent and position (one named
by its record's id, SolidWorks's ``NAUO12`` for a blank name, after its part); leaves
of one name (a sub-assembly placed twice) are told apart by their assemblies' names, and
leaves of one name in one assembly (a bearing's balls) are numbered. The triangles a
face's degenerate edge leaves (a sphere's poles) are dropped: the mesh stays closed.

A sub-assembly the user names (``one_part``: a bought part, a bearing of rings, balls and
shields) is one part instead of its leaves: their shapes as one compound, so its mesh is
the union of their closed meshes and its cylinders theirs, named as a leaf in its place
would be (its path's names, told apart among the sub-assemblies as leaves are).

A file whose reading Open CASCADE reports a failure for (a syntax error, a reference to a
missing record, a record with the wrong parameters: its reader goes on without the
record, which can rename a part or drop its placement) is refused, naming the record
and its line. The parts' tessellations count against the product's bound of triangles
(:data:`executor.cad.parts.MAX_TRIANGLES`) before they are copied.
"""

from __future__ import annotations

import contextlib
import functools
import re
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import trimesh

from bridge.inputs import shorten
from executor import ExecutorError
from executor.cad.parts import (
    MAX_TRIANGLES,
    STEP_DEFLECTION,
    CadPart,
    Cylinder,
    Kept,
    count_triangles,
    part_id,
)
from executor.world import SIZE_RESOLUTION

_MM = 1e-3
FINE_ANGLE = 0.1
"""The angular deflection of the tessellation the import measures on [rad]."""
COARSE_ANGLE = 0.5
"""The angular deflection of a part tessellated again for the cell [rad]: loose enough
that the linear deflection decides how many sides a round hole gets; and of the faces
tessellated within :data:`COARSE_DEFLECTIONS`."""
COARSE_DEFLECTIONS = (1e-5, SIZE_RESOLUTION)
"""The linear deflections tried, finest first, for the faces that are no plane, cylinder or
cone (spheres, tori, B-splines: a bearing's balls, fillets, engravings) when the product's
tessellation within :data:`STEP_DEFLECTION` passes its bound of triangles [m]; the last is
the least room the cell tells apart."""
_OCCURRENCE_ID = re.compile(r"NAUO\d+")
"""The id of a STEP file's ``NEXT_ASSEMBLY_USAGE_OCCURRENCE`` record as SolidWorks writes
it, the name Open CASCADE gives a component whose own is blank."""
_NAMED = 6
"""The parts named in :func:`coarse_assumption` (the others counted)."""

Whole = Callable[[dict[str, int]], set[str]]
"""Of a STEP file's sub-assemblies' ids, each with the solids (leaves) it holds, those each
imported as one part."""
Node = tuple[tuple[str, ...], int, int]
"""A sub-assembly as :func:`_collect` finds it: the names from the root down to it, and the
range of its leaves among all (first, past the last)."""


def load_step(path: Path, max_triangles: int = MAX_TRIANGLES, kept: Kept | None = None,
              whole: Whole | None = None) -> list[CadPart]:
    """The leaves of the STEP assembly at ``path`` as parts, each sub-assembly ``whole``
    chooses as one part (:func:`_joined`; None: none); ExecutorError naming the file
    when it is not a readable STEP file, a record of it failed (:func:`_failure`), it
    holds no solid or its parts' tessellations hold more than ``max_triangles`` together;
    only the parts whose ids ``kept`` keeps are tessellated and counted (None: all)."""
    from OCP.collections import Sequence_TDF_Label
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPCAFControl import STEPCAFControl_Reader
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDocStd import TDocStd_Document
    from OCP.XCAFDoc import XCAFDoc_DocumentTool

    document = TDocStd_Document(TCollection_ExtendedString("XmlOcaf"))
    reader = STEPCAFControl_Reader()
    reader.SetNameMode(True)
    with _quiet():
        if reader.ReadFile(str(path)) != IFSelect_RetDone:
            raise ExecutorError(f"{path}: not a readable STEP file")
        failure = _failure(path, reader.Reader())
        if failure is not None:
            raise ExecutorError(f"{failure} (expected a valid STEP file: read past it, a part can lose its name or "
                                "placement)")
        if not reader.Transfer(document):
            raise ExecutorError(f"{path}: not a readable STEP file")
    tool = XCAFDoc_DocumentTool.ShapeTool_s(document.Main())
    roots = Sequence_TDF_Label()
    tool.GetFreeShapes(roots)
    leaves: list[tuple[tuple[str, ...], Any]] = []
    nodes: list[Node] = []
    for k in range(1, roots.Length() + 1):
        _collect(roots.Value(k), None, (_name(roots.Value(k)) or path.stem,), leaves, nodes)
    if not leaves:
        raise ExecutorError(f"{path}: no solid parts in the STEP file")
    names = _unique_names([names for names, _ in leaves])
    shapes = [(f"{path}#{name}", shape) for name, (_, shape) in zip(names, leaves, strict=True)]
    if whole is not None:
        names, shapes = _joined(path, (names, shapes), nodes, whole)
    if kept is not None:
        keep = kept([part_id(name, source) for name, (source, _) in zip(names, shapes, strict=True)])
        chosen = [k for k, (name, (source, _)) in enumerate(zip(names, shapes, strict=True))
                  if part_id(name, source) in keep]
        names, shapes = [names[k] for k in chosen], [shapes[k] for k in chosen]
    coarse = _tessellate_within(shapes, max_triangles)
    parts: list[CadPart] = []
    for name, (source, shape) in zip(names, shapes, strict=True):
        rough = 0 if coarse is None else len(_faces(shape, exact=False))
        parts.append(CadPart(part_id(name, source), name, _tessellation(shape, source), source, _cylinders(shape),
                             functools.partial(_mesh, shape, source, angle=COARSE_ANGLE), rough,
                             STEP_DEFLECTION if coarse is None or not rough else coarse))
    return parts


def _joined(path: Path, parts: tuple[list[str], list[tuple[str, Any]]], nodes: list[Node],
            whole: Whole) -> tuple[list[str], list[tuple[str, Any]]]:
    """The ``parts`` (the leaves' names and ``(source, shape)`` pairs), the leaves of each
    sub-assembly of ``nodes`` that ``whole`` chooses replaced by one part in their place:
    their shapes as one compound, named after the sub-assembly (:func:`_unique_names` among
    the sub-assemblies); one chosen within another chosen is part of that one."""
    names, shapes = parts
    ordered = sorted(nodes, key=lambda node: (node[1], -node[2]))  # each before those within it
    titles = _unique_names([route for route, _, _ in ordered])
    ids = [part_id(title, f"{path}#{title}") for title in titles]
    chosen = whole({ident: end - start for ident, (_, start, end) in zip(ids, ordered, strict=True)})
    joined_names: list[str] = []
    joined_shapes: list[tuple[str, Any]] = []
    done = 0  # the leaves before it placed
    for ident, title, (_, start, end) in zip(ids, titles, ordered, strict=True):
        if ident not in chosen or start < done:
            continue
        compound = _compound([shape for _, shape in shapes[start:end]])
        joined_names += [*names[done:start], title]
        joined_shapes += [*shapes[done:start], (f"{path}#{title}", compound)]
        done = end
    joined_names += names[done:]
    joined_shapes += shapes[done:]
    return joined_names, joined_shapes


def _tessellate_within(shapes: list[tuple[str, Any]], max_triangles: int) -> float | None:
    """Tessellate the ``(source, shape)`` pairs within :data:`STEP_DEFLECTION`, or, where
    their triangles together pass ``max_triangles``, their faces that are no plane,
    cylinder or cone within the finest of :data:`COARSE_DEFLECTIONS` that keeps them
    within it: that deflection [m] (None: all within :data:`STEP_DEFLECTION`); ExecutorError
    naming the part at which the coarsest passes the bound."""
    for coarse in (None, *COARSE_DEFLECTIONS):
        total = 0
        for source, shape in shapes:
            _tessellate(shape, coarse=coarse)
            if coarse == COARSE_DEFLECTIONS[-1]:
                try:
                    total = count_triangles(source, _triangles(shape), total, max_triangles)
                except ExecutorError as error:
                    raise ExecutorError(f"{error}; its faces that are no plane, cylinder or cone tessellated within "
                                        f"{coarse / _MM:g} mm, the coarsest tried") from None
                continue
            total += _triangles(shape)
            if total > max_triangles:
                break
        else:
            return coarse
    raise AssertionError("the coarsest tessellation returns or raises")


def coarse_assumption(parts: list[CadPart], max_triangles: int) -> list[str]:
    """The assumption of the parts' tessellation when faces of theirs were tessellated
    coarser than :data:`STEP_DEFLECTION` (:func:`load_step`; none else)."""
    rough = [part for part in parts if part.coarse_faces]
    if not rough:
        return []
    named = ", ".join(part.id for part in rough[:_NAMED])
    more = f" and {len(rough) - _NAMED} more" if len(rough) > _NAMED else ""
    deflection = max(part.coarse_deflection for part in rough)
    faces = sum(part.coarse_faces for part in rough)
    return [f"STEP faces that are no plane, cylinder or cone ({faces} face{'s' if faces > 1 else ''} of "
            f"{named}{more}) tessellated within {deflection / _MM:g} mm, the finest of "
            f"{', '.join(f'{d / _MM:g}' for d in (STEP_DEFLECTION, *COARSE_DEFLECTIONS))} mm within "
            f"{max_triangles} triangles (--max-triangles); planes, cylinders and cones within "
            f"{STEP_DEFLECTION / _MM:g} mm"]


@contextlib.contextmanager
def _quiet() -> Iterator[None]:
    """Open CASCADE's messages below failures kept off the standard output (the reader
    prints its syntax errors there; :func:`_failure` reports them)."""
    from OCP.Message import Message, Message_Gravity

    printers = Message.DefaultMessenger_s().Printers()
    kept = [printers.Value(k) for k in range(1, printers.Size() + 1)]
    levels = [printer.GetTraceLevel() for printer in kept]
    for printer in kept:
        printer.SetTraceLevel(Message_Gravity.Message_Fail)
    try:
        yield
    finally:
        for printer, level in zip(kept, levels, strict=True):
            printer.SetTraceLevel(level)


def _failure(path: Path, reader: Any) -> str | None:
    """The first failure the reader's check of the file reports, as ``file:line: record
    #N KEYWORD: message`` (``file:line: message`` for one of the whole file, a syntax
    error or an unresolved reference), None when there is none (warnings pass)."""
    model = reader.StepModel()
    checks = reader.WS().ModelCheckList()
    checks.Start()
    while checks.More():
        check, number = checks.Value(), checks.Number()
        checks.Next()
        if check.NbFails() == 0:
            continue
        message = shorten(check.CFail(1), 160)
        more = f" (and {check.NbFails() - 1} more failures)" if check.NbFails() > 1 else ""
        if number == 0:  # the file's: "Undefined Parsing: Line 12: ...", "Unresolved Reference, Ent.Id.#5 ..."
            line = re.match(r"Undefined Parsing: Line (\d+): (.*)", message)
            return f"{path}:{line.group(1)}: {line.group(2)}{more}" if line else f"{path}: {message}{more}"
        return f"{_record(path, model, number)}: {message}{more}"
    return None


def _record(path: Path, model: Any, number: int) -> str:
    """``file:line: record #N KEYWORD`` of the model's entity ``number``: the record at
    that position among those starting a line of the file (the model numbers them in
    the file's order), checked with the reader's own map of labels (``file: entity N``
    when they disagree, e.g. records sharing a line)."""
    starts = []
    with path.open("rb") as file:
        for line, text in enumerate(file, 1):
            found = re.match(rb"\s*#(\d+)\s*=\s*\(?\s*([A-Za-z0-9_]*)", text)  # a complex record: its first type
            if found:
                starts.append((line, found.group(1).decode(), found.group(2).decode()))
    if number <= len(starts):
        line, ident, keyword = starts[number - 1]
        if model.NextNumberForLabel(f"#{ident}", 0, True) == number:
            return f"{path}:{line}: record #{ident} {keyword}".rstrip()
    return f"{path}: entity {number}"


def _name(label: Any) -> str:
    from OCP.TDataStd import TDataStd_Name

    attribute = TDataStd_Name()
    if label.FindAttribute(TDataStd_Name.GetID_s(), attribute):
        return attribute.Get().ToExtString()
    return ""


def _component_name(label: Any) -> str:
    """A component's name: its own, or where that is its record's id, its part's (the
    definition it refers to; "" when none). Open CASCADE names a component whose name is
    blank by its record's id, as SolidWorks writes them (``NAUO12``, :data:`_OCCURRENCE_ID`)."""
    from OCP.TDF import TDF_Label
    from OCP.XCAFDoc import XCAFDoc_ShapeTool

    own = _name(label)
    if not _OCCURRENCE_ID.fullmatch(own):
        return own
    referred = TDF_Label()
    return _name(referred) if XCAFDoc_ShapeTool.GetReferredShape_s(label, referred) else ""


def _unique_names(paths: list[tuple[str, ...]]) -> list[str]:
    """Each leaf's name from its ``paths`` (the names from the root down to it): its own,
    and where several leaves share it (a sub-assembly placed twice), joined with ``_``
    to those of as many of its assemblies as tell them apart (``l-bracket-assembly_1_bolt_1``);
    leaves of one name in one assembly (a bearing's balls) numbered in the file's order
    (``ball_1``, ``ball_2``)."""
    paths = list(paths)
    repeated = {path for path in paths if paths.count(path) > 1}
    seen: dict[tuple[str, ...], int] = {}
    for k, path in enumerate(paths):
        if path in repeated:
            seen[path] = seen.get(path, 0) + 1
            paths[k] = (*path[:-1], f"{path[-1]}_{seen[path]}")
    depth = [1] * len(paths)
    while True:
        names = ["_".join(path[-d:]) for path, d in zip(paths, depth, strict=True)]
        shared = {name for name in names if names.count(name) > 1}
        longer = [k for k, name in enumerate(names) if name in shared and depth[k] < len(paths[k])]
        if not longer:
            return names
        for k in longer:
            depth[k] += 1


def _collect(label: Any, location: Any, path: tuple[str, ...], leaves: list[tuple[tuple[str, ...], Any]],
             nodes: list[Node]) -> None:
    """Append ``(names from the root, located shape)`` for every leaf under ``label``
    (``path``: the names down to it) to ``leaves``, and each sub-assembly under it holding
    a leaf, ``label`` too when it is one but no root, to ``nodes``; ``location`` is the
    placement of ``label`` in the product (None at a root)."""
    from OCP.collections import Sequence_TDF_Label
    from OCP.TDF import TDF_Label
    from OCP.TopLoc import TopLoc_Location
    from OCP.XCAFDoc import XCAFDoc_ShapeTool

    here = location if location is not None else TopLoc_Location()
    referred = TDF_Label()
    definition = referred if XCAFDoc_ShapeTool.GetReferredShape_s(label, referred) else label
    if XCAFDoc_ShapeTool.IsAssembly_s(definition):
        first = len(leaves)
        children = Sequence_TDF_Label()
        XCAFDoc_ShapeTool.GetComponents_s(definition, children, False)
        for k in range(1, children.Length() + 1):
            child = children.Value(k)
            placement = here.Multiplied(XCAFDoc_ShapeTool.GetLocation_s(child))
            name = _component_name(child) or _name(definition) or f"{path[-1]}_{k}"
            _collect(child, placement, (*path, name), leaves, nodes)
        if location is not None and len(leaves) > first:
            nodes.append((path, first, len(leaves)))
        return
    shape = XCAFDoc_ShapeTool.GetShape_s(definition)
    leaves.append((path, shape.Located(here.Multiplied(shape.Location()))))


def _tessellate(shape: Any, deflection: float = STEP_DEFLECTION, angle: float = FINE_ANGLE,
                coarse: float | None = None) -> None:
    """Tessellate the shape's faces (:func:`_mesh`), replacing an earlier tessellation (a
    coarser one would only refine it); with ``coarse`` [m], its faces that are no plane,
    cylinder or cone within that and :data:`COARSE_ANGLE`: the others first, then the
    whole shape, whose edges already tessellated finer are kept and shared (a closed mesh)."""
    from OCP.BRepMesh import BRepMesh_IncrementalMesh
    from OCP.BRepTools import BRepTools

    BRepTools.Clean_s(shape)
    if coarse is None:
        BRepMesh_IncrementalMesh(shape, deflection / _MM, False, angle, True)
        return
    BRepMesh_IncrementalMesh(_compound(_faces(shape, exact=True)), deflection / _MM, False, angle, True)
    BRepMesh_IncrementalMesh(shape, coarse / _MM, False, COARSE_ANGLE, True)


def _faces(shape: Any, exact: bool) -> list[Any]:
    """The shape's faces that are planes, cylinders or cones (``exact``), or the others."""
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.GeomAbs import GeomAbs_Cone, GeomAbs_Cylinder, GeomAbs_Plane
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    found = []
    explorer = TopExp_Explorer(shape, TopAbs_FACE)
    while explorer.More():
        face = TopoDS.Face(explorer.Current())
        explorer.Next()
        if (BRepAdaptor_Surface(face).GetType() in (GeomAbs_Plane, GeomAbs_Cylinder, GeomAbs_Cone)) == exact:
            found.append(face)
    return found


def _compound(shapes: list[Any]) -> Any:
    """The shapes (faces, solids) as one compound shape."""
    from OCP.BRep import BRep_Builder
    from OCP.TopoDS import TopoDS_Compound

    compound = TopoDS_Compound()
    builder = BRep_Builder()
    builder.MakeCompound(compound)
    for shape in shapes:
        builder.Add(compound, shape)
    return compound


def _triangles(shape: Any) -> int:
    """The triangles of the shape's tessellation."""
    from OCP.BRep import BRep_Tool
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopLoc import TopLoc_Location
    from OCP.TopoDS import TopoDS

    count = 0
    explorer = TopExp_Explorer(shape, TopAbs_FACE)
    while explorer.More():
        triangulation = BRep_Tool.Triangulation_s(TopoDS.Face(explorer.Current()), TopLoc_Location())
        explorer.Next()
        count += 0 if triangulation is None else triangulation.NbTriangles()
    return count


def _mesh(shape: Any, source: str, deflection: float = STEP_DEFLECTION, angle: float = FINE_ANGLE) -> trimesh.Trimesh:
    """The shape's faces tessellated into one mesh [m]: no point of a face farther than
    ``deflection`` [m] from its triangles, no two normals of one triangle's corners more
    than ``angle`` [rad] apart (the triangles' corners lie on the faces)."""
    _tessellate(shape, deflection, angle)
    return _tessellation(shape, source)


def _tessellation(shape: Any, source: str) -> trimesh.Trimesh:
    """The shape's tessellation (:func:`_tessellate`) as one mesh [m], vertices merged,
    the triangles with two corners at one vertex left out."""
    from OCP.BRep import BRep_Tool
    from OCP.TopAbs import TopAbs_FACE, TopAbs_REVERSED
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopLoc import TopLoc_Location
    from OCP.TopoDS import TopoDS

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
    corners = mesh.faces
    # A face's degenerate edge (a sphere's or a cone's pole) is tessellated as nodes of
    # one point: the triangles on it have two corners one vertex once merged, no area,
    # and would leave the pole's edges unpaired (an open mesh).
    mesh.update_faces((corners[:, 0] != corners[:, 1]) & (corners[:, 1] != corners[:, 2])
                      & (corners[:, 0] != corners[:, 2]))
    mesh.remove_unreferenced_vertices()
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
