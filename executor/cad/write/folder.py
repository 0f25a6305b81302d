"""The assembly folder written (:func:`write_folder`): the product mapped as the cell inserts it
with its trays (:func:`map_product`), its files, ``geometry.toml`` kept only where the cell's
loader accepts it and its sections answer every pair as ``sizes.lp`` (:func:`_cell_disagrees`),
a moving part with no convex pieces that fit placed by hand and the product mapped again,
and the manifest last."""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path

from bridge.errors import ToolError
from bridge.files import make_folder, write_atomic
from bridge.product import Mesh
from executor.cad.covers import Mapped, map_parts
from executor.cad.derive import Derived
from executor.cad.operations.arm import tool_length
from executor.cad.operations.plate import plate_top
from executor.cad.operations.rooms import margins, nominal_fits
from executor.cad.operations.view import cell_view
from executor.cad.write.assembly import Settings, assembly_text
from executor.cad.write.facts import cell_order_text, nominal_text, precedence_text, sizes_text
from executor.cad.write.geometry import geometry_text, manual_features, pins_of
from executor.cad.write.manifest import MANIFEST, file_digest
from executor.cad.write.meshes import mesh_pieces, write_meshes
from executor.cad.write.trays import REACH, default_trays, footprints, product_box, tray_overlap
from executor.world.geometry import CellGeometry, feature_passes, load_geometry, plate_obj_text


def map_product(derived: Derived, settings: Settings, refused: Mapping[str, str] | None = None
                ) -> tuple[Mapped, Settings, Derived]:
    """The covers, heads and parts placed by hand of the product as the cell inserts it
    (:func:`executor.cad.operations.view.cell_view`: its other pegs, and those ``refused``
    (part -> why), are placed by hand), with ``why`` the cell builds
    none of it (two parts overlapping on the tray, or parts without a tray in ``settings``
    that cannot all wait within the arm's reach), its gripper's flange where the default's is
    too short (:func:`executor.cad.operations.arm.tool_length`), the settings with every part's tray
    (:func:`default_trays` for those it lacks), and that product (for :func:`write_folder`)."""
    cell, by_hand = cell_view(derived, refused)
    flange, tool = tool_length(cell)
    mapped = replace(map_parts(cell, plate_top(cell), by_hand), flange=flange, tool=tool)
    boxes = footprints(cell, mapped)
    trays, unreached = default_trays(boxes, settings.trays, derived.base, product_box(derived))
    settings = replace(settings, trays=trays)
    why = tray_overlap(boxes, trays) or (
        None if not unreached else f"parts {', '.join(unreached)} find no tray within the arm's reach "
        f"({1000 * REACH[0]:g} to {1000 * REACH[1]:g} mm) clear of the product and the other parts "
        "(set [parts.<id>] tray in the import settings)")
    return replace(mapped, why=why), settings, cell


def _cell_disagrees(derived: Derived, geometry: CellGeometry) -> str | None:
    """Why the cell's ``geometry`` would answer a pair otherwise than ``sizes.lp``
    (:func:`executor.world.geometry.feature_passes` on its sections against
    :func:`executor.cad.operations.rooms.margins` and :func:`executor.cad.operations.rooms.nominal_fits`), naming
    the first such pair; None when it answers every pair alike."""
    rooms, nominal = margins(derived), nominal_fits(derived)
    for pid, part in sorted(geometry.parts.items()):
        for hid, hole in sorted(geometry.holes.items()):
            room = rooms.get(pid, {}).get(hid)
            stated = room is not None and (room > 0 or (pid, hid) in nominal)
            if feature_passes(part, hole) != stated:
                return (f"the cell's sections would decide {pid} in {hid} as {'no fit' if stated else 'a fit'}, "
                        f"sizes.lp as {'a fit' if stated else 'no fit'}")
    return None


def write_folder(derived: Derived, cell: Derived, mapped: Mapped, settings: Settings, title: str, out: Path,
                 removable: set[str]) -> tuple[list[Path], str | None, Mapped, Derived]:
    """Write the files of the module docstring into ``out`` (removing the ``removable``
    files, :func:`claim_folder`, that this import does not write again; the manifest last),
    ``cell`` the product as the cell inserts it (:func:`executor.cad.operations.view.cell_view`, :func:`map_product`'s);
    a moving part with no convex pieces that fit (:func:`write_meshes`) is placed by hand
    with why, the product mapped again without it; returns the files, why there is no
    ``geometry.toml`` (None when there is one, checked by the cell's loader), and the
    mapped product and its cell's view as written."""
    make_folder(out)
    geometry = out / "geometry.toml"
    geometry.unlink(missing_ok=True)  # the claim made it this import's, if there was one
    why = mapped.why
    mesh_files: list[Path] = []
    stale: list[Path] = []  # the meshes written before a part was refused
    meshes: dict[str, Mesh] | None = None
    refused: dict[str, str] = {}
    while why is None and meshes is None:
        meshes, more = write_meshes(cell, mapped, out, mesh_files)
        if more:
            refused |= more
            mapped, settings, cell = map_product(derived, settings, refused)
            why, meshes = mapped.why, None
            stale, mesh_files = stale + mesh_files, []
    roles = ({pid: "cover" for pid in mapped.covers} | {pid: "head" for pid in mapped.heads}
             | {pid: "manual" for pid in mapped.manual})
    written = [write_atomic(out / "assembly.toml", assembly_text(derived, settings, title, roles)),
               write_atomic(out / "sizes.lp", sizes_text(derived)),
               write_atomic(out / "nominal_sizes.lp", nominal_text(derived)),
               write_atomic(out / "geometric_precedence.lp", precedence_text(derived))]
    if meshes is not None:
        write_atomic(geometry, geometry_text(cell, mapped, settings, meshes, manual_features(derived, mapped),
                                             mesh_pieces(out, mesh_files), pins_of(derived)))
        try:
            loaded = load_geometry(str(out))
            plate_obj_text(loaded)  # the cell builds its plate's bosses from it
            why = _cell_disagrees(derived, loaded)
        except ToolError as exc:
            why = f"the cell refuses its geometry ({exc})"
        if why is None:
            written += [*mesh_files, geometry]
            orders = cell_order_text(cell)
            written += [write_atomic(out / "cell_order.lp", orders)] if orders is not None else []
        else:
            geometry.unlink()
    kept = {path.relative_to(out).as_posix(): file_digest(path) for path in written}
    # an earlier import's files not written again, and this one's meshes of a geometry not kept
    for name in sorted((removable | {path.relative_to(out).as_posix() for path in stale + mesh_files}) - set(kept)):
        (out / name).unlink(missing_ok=True)
    write_atomic(out / MANIFEST, json.dumps({"written_by": "./run.sh import", "title": title, "files": kept},
                                            indent=1) + "\n")
    return written, why, mapped, cell
