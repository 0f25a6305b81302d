"""Screwed pairs (a thread: :func:`executor.cad.fits.threads.screwed_pairs`) and press fits
(:func:`executor.cad.fits.faces.press_fits`): the fits at room 0 they make in a hole or on a
pin (:func:`screwed_fits`), and the parts of them that leave first in the disassembly, placed
by hand with why (:func:`screwed`, :func:`pressed`): the cell has no screwing operation, nor a
pressing one. Lengths in metres."""

from __future__ import annotations

from executor.cad.derive import Derived
from executor.cad.fits.faces import Slide
from executor.cad.sweep import opposite


def screwed_fits(derived: Derived) -> dict[tuple[str, str], Slide]:
    """(part, feature) -> the screwed pair (:meth:`Derived.screwed`) of each part in a hole
    or on a pin of the part it is screwed with (a thread): a fit at room 0, by screwing."""
    owners = {hid: fit.owner or derived.base for hid, fit in {**derived.holes, **derived.part_holes}.items()}
    owners |= {pin_id: pin.owner for pin_id, pin in derived.pins.items()}
    found = {(pid, hid): derived.screwed(pid, owners[hid]) for pid, hid in derived.swept if hid in owners}
    return {pair: slide for pair, slide in found.items() if slide is not None}


def _leaving_first(derived: Derived) -> dict[str, Slide]:
    """Part -> the screwed pair (a thread, :func:`executor.cad.fits.threads.screwed_pairs`) or
    press fit (:func:`executor.cad.fits.faces.press_fits`) of which it is the part that
    leaves first in the disassembly (both where they leave at one stage; never the base)."""
    stage = {pid: k for k, parts in enumerate(derived.stages) for pid in parts}
    found: dict[str, Slide] = {}
    for slide in (s for s in derived.slides if s.pitch or s.interference):
        pair = [pid for pid in (slide.shaft, slide.bore) if pid in stage]
        first = min((stage[pid] for pid in pair), default=None)
        for pid in (pid for pid in pair if stage[pid] == first):
            found.setdefault(pid, slide)
    return found


def screwed(derived: Derived) -> dict[str, str]:
    """Part -> why it is placed by hand, for the parts of screwed pairs and press fits that
    leave first (:func:`_leaving_first`): the cell has no screwing operation, nor a pressing one."""
    found: dict[str, str] = {}
    for pid, slide in _leaving_first(derived).items():
        other = slide.bore if pid == slide.shaft else slide.shaft
        way = f"{'into' if pid == slide.shaft else 'onto'} '{other}' along {opposite(derived.axis[pid])}"
        found[pid] = (f"part '{pid}' is pressed {way} (a press fit, {1000 * slide.interference:.3f} mm per side): "
                      "the cell has no pressing operation" if slide.interference else
                      f"part '{pid}' is screwed {way} ({slide.thread}, pitch {1000 * slide.pitch:.3f} mm): "
                      "the cell has no screwing operation")
    return found


def pressed(derived: Derived) -> set[str]:
    """The parts placed by hand for a press fit (:func:`screwed`): pressed in, no fit as the cell slides parts."""
    return {pid for pid, slide in _leaving_first(derived).items() if slide.interference}
