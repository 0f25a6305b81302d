"""A product from its CAD: STEP assemblies or one mesh per part in the assembled pose.

Layers, each importing only those before it: :mod:`executor.cad.parts` (reading and
checking the parts), :mod:`executor.cad.sweep` (swept collision along straight removal
paths), :mod:`executor.cad.sections` (cross-sections and holes), :mod:`executor.cad.derive`
(insertion axes, holes, geometric precedence by disassembly), :mod:`executor.cad.write`
(the assembly folder) and :mod:`executor.cad.cli` (``import``). Units: metres inside.
"""
