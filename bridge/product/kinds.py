"""The cross-section kind of each part and hole of a product, from every statement the
product makes about it: ``shape`` in ``assembly.toml`` (``[parts.<id>]``,
``[holes.<id>]``) and the ``kind`` of the ``[part_shapes.*]`` or ``[hole_shapes.*]`` of
``geometry.toml`` that holds it (a part simulated from its ``mesh`` has its table's kind
too). Statements that disagree are refused by the checks
(:mod:`bridge.product.checks`, naming both files); a part no statement gives a
kind (a base, a cover, a head, or a planner-only product's part without ``shape``) has
none, and the size models put it on no other part's line (docs/sizes.md)."""

from __future__ import annotations

from bridge.product.tables import AssemblyFile, GeometryFile


def part_kinds(layout: AssemblyFile, geometry: GeometryFile | None) -> dict[str, str]:
    """Part id -> its cross-section kind, for the parts of ``assembly.toml`` some statement
    gives one: its ``shape``, else the kind of its ``[part_shapes.*]`` table."""
    tables = {} if geometry is None else {pid: table.kind for table in geometry.part_shapes.values()
                                          for pid in table.parts}
    found = {pid: part.shape or tables.get(pid) for pid, part in layout.parts.items()}
    return {pid: kind for pid, kind in found.items() if kind is not None}


def hole_kinds(layout: AssemblyFile, geometry: GeometryFile | None) -> dict[str, str]:
    """Hole id -> its cross-section kind: its ``shape``, else the kind of its
    ``[hole_shapes.*]`` table, else round (a hole no statement describes)."""
    tables = {} if geometry is None else {hid: table.kind for table in geometry.hole_shapes.values()
                                          for hid in table.holes}
    return {hid: hole.shape or tables.get(hid) or "round" for hid, hole in layout.holes.items()}


def section_label(pid: str, kind: str, label: str | None) -> str:
    """The section of part ``pid`` of ``kind``: its ``section`` ``label``, else its kind
    (round, square), a rect or polygon its own id (rects of one aspect ratio share a label
    only when the product says so)."""
    return label or (pid if kind in ("rect", "polygon") else kind)
