"""A product from its CAD: STEP assemblies or one mesh per part in the assembled pose.

Layers, each importing only those before it: :mod:`executor.cad.parts` (reading mesh
folders, checking the parts) and :mod:`executor.cad.step` (STEP assemblies),
:mod:`executor.cad.sweep` (swept collision along straight removal paths),
:mod:`executor.cad.sections` (cross-sections of slices), :mod:`executor.cad.derive`
(insertion axes, holes, geometric precedence by disassembly), :mod:`executor.cad.write`
(the assembly folder), :mod:`executor.cad.cli` (``import``) and :mod:`executor.cad.bench`
(``bench import``). :mod:`executor.cad.assembled` writes a shipped product's parts in the
assembled pose (``executor export --assembled``). Units: metres inside.
"""
