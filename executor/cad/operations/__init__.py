"""What the simulated cell does with each part of an imported product, and why it places a part by hand.

Input: a product derived from its CAD (:class:`executor.cad.derive.Derived`: parts, holes,
pins, bores, axes, geometric precedence). Output: the product as the cell inserts it (the
holes it inserts pegs into, the pins it puts parts onto, the bores it keeps) and, for every
other moving part, the reason it is placed by hand (``[manual.<id>]``); with the figures
the product's files need too. Lengths in metres. :mod:`executor.cad.write` writes the
product's files from these (it imports this package, never the other way).

The modules, each importing only those listed before it:

- :mod:`~executor.cad.operations.frames`: the frames of holes, pins and bores, a hole's entry, a pin's end;
- :mod:`~executor.cad.operations.plate`: whether the cell builds the base as a plate, the plate's level;
- :mod:`~executor.cad.operations.precedence`: the precedence as a graph, the parts in place when a part goes;
- :mod:`~executor.cad.operations.screwed`: screwed pairs and press fits, their parts placed by hand;
- :mod:`~executor.cad.operations.rooms`: each peg's room in each hole and bore's on each pin, nominal fits;
- :mod:`~executor.cad.operations.resolution`: fits whose room the cell does not resolve, a bore widened, a peg narrowed;
- :mod:`~executor.cad.operations.fingers`: the simulated gripper and how deep its fingers hold a peg;
- :mod:`~executor.cad.operations.tools`: what holds each peg (fingers, suction cup), the orders the fingers need;
- :mod:`~executor.cad.operations.arm`: the arm's wrist clear of the product (the flange's length), its reach sideways;
- :mod:`~executor.cad.operations.pins`: parts put onto pins, the pieces of a part with a bore;
- :mod:`~executor.cad.operations.view`: the product as the cell inserts it, every other part's reason to go by hand.
"""
