"""What the geometry of an assembled product decides: insertion axes, holes with their
cross-sections, and the geometric precedence by disassembly.

Disassembly: the base stays (it is the fixture); every moving body (a part with the parts
``fixed_to`` it, moved as one) is swept out along each direction tried by the product's
size, everything else fixed, which gives its blockers per direction (blocking is
pairwise, so these are the blockers at every stage). The directions tried are
:data:`executor.cad.sweep.DIRECTIONS` and both senses of the axis of
every zero-clearance fit (:func:`executor.cad.fits.faces.zero_clearance_fits`).
Stage by stage, every part that some direction frees from the parts still in place leaves.
Its **insertion axis** is the reverse of the way out
:func:`executor.cad.derive.ways._way_out` chooses (up, down, the ways the arm reaches
sideways, then the product's geometry) among the directions free of the parts present as
the cell meets it: those in place at its stage and those the precedence puts before it,
less those it puts after it (:func:`executor.cad.derive.ways.ways_in`). Where parts are
left, the screwed pairs (modelled threads, :func:`executor.cad.fits.threads.screwed_pairs`, in a nut or a
plain hole at their tap drill; cosmetic ones, :func:`executor.cad.fits.threads.cosmetic_pairs`)
between them and their blockers slide along their axes, their parts are swept again and
the stages made anew. A part that no stage frees never comes out (an error naming it and,
per direction, its blockers).

**Geometric precedence** (:func:`forced`): A must precede B (``blocks``) when A cannot go
in once B is there: of the directions the base leaves A free along, B blocks one, and B
or parts present whenever B is (its body, the base, parts already found to precede B, by
this rule or by the support rule where the blocking allows it) block every one. The base
precedes every part touching it (``base``), the owner of a feature every part going into
or onto it (``feature``, :func:`owner_pairs`). Two stated rules
of placing (:mod:`executor.cad.locating`) add ``supports`` (a part
resting on parts other than the base goes after them) and ``locates`` (whichever way a part
goes in, one other part alone locates it across that way; off with reach 0);
a pair of theirs that the blocking contradicts is dropped and reported.

**Holes** are the inner loops of the base's slices perpendicular to the axes, at the
middle of each part's depth in the base (or, with no part reaching into it, at the base's
middle along z). A part is in the hole whose loop holds its slice's centre, unless that
hole is floored and leaves the part more than :data:`CAVITY_ROOM` of room every way where
it lies (a tray's cavity the part rests in: no hole for it, nor is a moving part's loop so
roomy); an empty floored hole so roomy wherever the widest part left in a hole lies in it
is none
(:func:`executor.cad.derive.cavities.open_box`). Measured: both cross-sections, their
clearance, the hole's entry (the base's highest point around it along the axis), depth
(entry to the first face down its centre line, or through the base), entry chamfer (the
loop's growth just below the entry, taken as 45°). An empty loop whose section is a
polygon is a hole only when it has rotational symmetry about its centre
(:func:`receives`), else a pocket, reported but no hole. Both sections are those over the
stretch the part passes, from its end to the entry
(:func:`executor.cad.sections.over_span`: the hole's narrowest, the part's widest); an
empty hole's over the stretch a part goes in, from its floor (or through) to its entry, so
alike holes are measured alike, occupied or not. Where those do not pass, the part is
swept out of its hole level by level (:func:`swept_fits`: a taper in its own taper
passes).

**Holes of moving parts** (:func:`part_holes`): a moving part in no hole of the base and
onto no pin is in the hole of another moving part that the geometric precedence puts
before it when its outline across its insertion axis lies in an inner loop of that part
(a rod through a bracket's bore), measured as a hole of the base is; a part onto a pin is
so in the hole of a part the precedence does not put after it (a clutch plate's splined
outside in the outer holder's hole as its bore goes down the shaft), the parts in one hole
its occupants; a part standing in a hole of the base is in the hole of a part before it that
it passes on that hole's line too (a bolt through a bracket's flange into the plate), a hole
the planner takes for one place with the base's.

**Pins** (:func:`pins`): a moving part whose slice across its insertion axis, at the middle
of its extent along it, has an inner loop (a **bore**: a nut's, a washer's, a gear's)
around a solid loop of another part there (the base's pin, another part's shaft; or the
pieces of one loop, whole beyond them towards the pin's free end: a slit sleeve's halves),
that part the base or one the geometric precedence puts before it, and no other such
part round it in the bore (a collar round a sleeve on a shaft: the sleeve's), goes onto that pin (onto
every pin of such parts in a bore of its own: a plate on two dowel pins of the base, an
arm on the base's pivot pin through its bore and on a disk's nipple through its slot); a peg
standing in a hole of the base is a pin only of a part going in along another axis (a
nut onto a bolt's end under the plate; one going in along the peg's, over it, is a
cover), or of a part going in along its axis that rests on such pegs alone (a foot down
onto a table leg's tenon, on nothing but the leg's shoulder: no cover, which rests on the
base or on covers). The pin is a
feature of its owner (``<owner>_pin1``, ``_pin2``, ... by position), its section measured
on the owner's slice; the fit is the pin's section inside the bore's, so the planner
learns which part goes onto which pin as it learns pegs in holes. At those levels and
along those axes, a pin of the base no part is on is found too when it stands out with
its free end along the axis and some bore passes over it (:func:`executor.cad.derive.pin_fits._standing_pins`).

The modules: :mod:`~executor.cad.derive.derived` (the data found), :mod:`~executor.cad.derive.ways`
(stages and insertion axes), :mod:`~executor.cad.derive.precedence` (bodies, ``blocks`` and
``feature`` pairs), :mod:`~executor.cad.derive.base_holes` and
:mod:`~executor.cad.derive.moving_holes` (holes of the base, of moving parts), measured by
:mod:`~executor.cad.derive.measure_hole`, :mod:`~executor.cad.derive.pin_fits` and
:mod:`~executor.cad.derive.bore_on_pin` (pins), :mod:`~executor.cad.derive.swept` (fits the
sweep admits); beneath them :mod:`~executor.cad.derive.loops` (slices' loops),
:mod:`~executor.cad.derive.cavities` (open boxes) and :mod:`~executor.cad.derive.rays`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import networkx as nx
import numpy as np

from executor import ExecutorError
from executor.cad.derive.base_holes import holes, receives
from executor.cad.derive.cavities import CAVITY_ROOM
from executor.cad.derive.derived import Derived, HoleFit, PinFit
from executor.cad.derive.moving_holes import part_holes
from executor.cad.derive.pin_fits import pins
from executor.cad.derive.precedence import bodies, forced, owner_pairs
from executor.cad.derive.rays import first_hit
from executor.cad.derive.swept import swept_fits
from executor.cad.derive.ways import LEAVING, PREFERRED, disassembled, ways_in
from executor.cad.fits.faces import press_fits, zero_clearance_fits
from executor.cad.fits.threads import cosmetic_pairs, screwed_pairs
from executor.cad.locating import LOCATING_REACH, consistent, locators, placing_pairs, support_pairs
from executor.cad.parts import CadPart
from executor.cad.sweep import DIRECTIONS, Sweeper, axis_name, surveys

__all__ = ["CAVITY_ROOM", "LEAVING", "PREFERRED", "Derived", "HoleFit", "PinFit", "bodies", "derive", "first_hit",
           "forced", "owner_pairs", "part_holes", "pins", "receives", "swept_fits"]
"""The names the other modules and the tests import from here, and those the documents
cite as ``executor.cad.derive.NAME``."""


def derive(parts: list[CadPart], base: str, fixed_to: dict[str, str], reach: float = LOCATING_REACH,
           beside: Callable[[], None] = lambda: None) -> Derived:
    """Axes, stages, precedence and holes of ``parts`` with ``base`` the fixture;
    ``fixed_to`` maps a part to the part it moves with; ``reach`` [m]: the locating rule's
    (0: off); ``beside`` is called once the parts' surveys are made, as the sweeps begin
    (the import starts its overlap check there: the sweeps' first work, making the fixed
    parts' BVHs before their workers fork, runs in this process alone). ExecutorError
    naming the parts that never come out with their blockers."""
    by_id = {p.id: p for p in parts}
    result = Derived(base, by_id, reach=reach)
    made = surveys({p.id: p.mesh for p in parts})
    beside()
    faces = {pid: survey.faces for pid, survey in made.items()}
    result.slides = zero_clearance_fits(faces) + press_fits(faces)
    for slide in result.slides:
        result.directions.setdefault(axis_name(slide.direction), tuple(slide.direction))
        result.directions.setdefault(axis_name(-slide.direction), tuple(-slide.direction))
    sweeper = Sweeper({p.id: p.mesh for p in parts}, result.slides, made=made)
    lower = np.min([p.mesh.bounds[0] for p in parts], axis=0)
    upper = np.max([p.mesh.bounds[1] for p in parts], axis=0)
    length = 2 * float(np.linalg.norm(upper - lower))
    result.bodies = bodies(by_id, base, fixed_to)
    requests = [(members, name) for members in result.bodies.values() for name in result.directions]
    hits = sweeper.blocked([(members, np.array(result.directions[name]), length) for members, name in requests])
    for (members, name), hit in zip(requests, hits):
        result.blockers |= {(pid, name): hit for pid in members}
    remaining = disassembled(result)
    if remaining:  # modelled threads: sought only where a part is left, between it and its blockers
        blocked_by = {(pid, other) for pid in remaining for d in result.directions
                      for other in result.blockers[(pid, d)]}
        screwed = screwed_pairs({p.id: p.mesh for p in parts}, blocked_by)
        threaded = {frozenset((s.shaft, s.bore)) for s in screwed}
        screwed += [s for s in cosmetic_pairs({pid: survey.faces for pid, survey in made.items()}, blocked_by)
                    if frozenset((s.shaft, s.bore)) not in threaded]
        if screwed:
            result.slides += screwed
            sweeper.add(screwed)
            paired = {pid for s in screwed for pid in (s.shaft, s.bore)}
            again = [(members, name) for members, name in requests if members & paired]
            hits = sweeper.blocked([(members, np.array(result.directions[name]), length) for members, name in again])
            for (members, name), hit in zip(again, hits):
                result.blockers |= {(pid, name): hit for pid in members}
            result.stages = []
            remaining = disassembled(result)
    if remaining:
        stuck = "; ".join(f"{pid} along " + ", ".join(
            f"{d} by {' '.join(sorted(result.blockers[(pid, d)] & (remaining | {base})))}"
            for d in result.directions) for pid in sorted(remaining))
        raise ExecutorError(f"part(s) {', '.join(sorted(remaining))} never come out of the assembled product, "
                            f"blocked: {stuck} (expected a straight way out for every part but the base)")
    result.supports = support_pairs(sweeper, result.bodies, base)
    result.reasons = forced(result)
    # the support rule's pairs the blocking allows are parts present whenever their part is:
    # a ring between a bearing and a shaft's shoulder cannot go in once the shaft, which
    # rests on the bearing, is there (kept unless that closes a cycle)
    held, _ = consistent(sorted(result.supports), set(result.reasons))
    if held:
        seeded = forced(result, held)
        if nx.is_directed_acyclic_graph(nx.DiGraph(list(seeded | dict.fromkeys(held, "supports")))):
            result.reasons = seeded
    result.reasons |= {(base, pid): "base" for stage in result.stages for pid in stage if sweeper.touching(base, pid)}
    if reach > 0:
        result.located, result.nearer = locators(sweeper, result.bodies, reach)
    ways = {root: result.ways(root) for root in result.bodies}
    sweeper.close()  # its last sweep: what follows forks its own workers
    placing, result.later = placing_pairs(result.supports, result.located, ways, result.bodies, base,
                                          set(result.reasons), result.nearer)
    kept, dropped = consistent(sorted(placing), set(result.reasons))
    result.reasons |= {pair: placing[pair] for pair in kept if pair not in result.reasons}
    result.dropped = {pair for pair in dropped if placing[pair] == "locates"}
    result.dropped_supports = {pair for pair in dropped if placing[pair] == "supports"}
    result.edges = set(result.reasons)
    ways_in(result)
    order = nx.DiGraph(list(result.edges))
    found = holes(by_id[base], [by_id[pid] for pid in sorted(result.axis) if result.axis[pid] in DIRECTIONS],
                   result.axis, {pid: [by_id[p] for p in sorted(nx.ancestors(order, pid)) if p != base]
                                 for pid in result.axis if pid in order})
    result.pockets = [fit for fit in found if fit.part is None and not receives(fit)]
    result.holes = {f"h{k}": replace(fit, id=f"h{k}")
                    for k, fit in enumerate((fit for fit in found if fit not in result.pockets), start=1)}
    result.pins, result.bores, result.further_bores = pins(result)
    result.part_holes = part_holes(result)
    result.swept = swept_fits(result)
    result.reasons |= owner_pairs(result)
    result.edges = set(result.reasons)
    result.queries = sweeper.queries
    return result
