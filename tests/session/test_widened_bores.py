"""A sim session names every fit its cell builds with room it does not resolve: the nominal
zero-clearance fits and the bores widened on pins (a pin's ``widened``), each with the CAD's
room where it is above 0 (bridge/product/nominal.py)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

from asp.session.run import _nominal_fits, _nominal_statement
from bridge.assembly import Assembly, Part


def test_a_sim_session_lists_every_widened_bore_with_its_cad_room() -> None:
    # the ring at room 0 on p1 (a nominal fit), the gear at +0.012 mm per side on p2: both
    # widened; the washer at room 0 on p3, not widened, is taken from the CAD
    parts = tuple(Part(pid, pid) for pid in ("ring", "gear", "washer"))
    assembly = Assembly(folder=Path("."), name="pins", parts=parts,
                        cell_holes=frozenset({"p1", "p2", "p3"}), pins=frozenset({"p1", "p2", "p3"}),
                        bores=frozenset({"ring", "gear", "washer"}),
                        nominal_fits=frozenset({("ring", "p1"), ("washer", "p3")}),
                        widened={("ring", "p1"): 0.0, ("gear", "p2"): 12e-6})
    nominal = _nominal_fits(assembly, "sim", ["gear", "ring", "washer"], ["p1", "p2", "p3"])
    assert nominal is not None
    assert nominal.pairs == [("gear", "p2"), ("ring", "p1")]
    assert nominal.cad_room_m == {"gear->p2": 12e-6}
    assert "(gear->p2 (+0.0120 mm) ring->p1; room 0 unless given)" in _nominal_statement(nominal)
    assert assembly.tried_by_hand("washer", "p3", "sim") and not assembly.tried_by_hand("ring", "p1", "sim")
    assert dataclasses.replace(assembly, widened={}).tried_by_hand("ring", "p1", "sim")
    assert _nominal_fits(assembly, "truth", ["gear", "ring"], ["p1", "p2"]) is None
