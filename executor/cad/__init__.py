"""A product from its CAD: STEP assemblies or one mesh per part in the assembled pose.

Layers, each importing only those before it: :mod:`assembly_constraints.executor.cad.parts` (reading mesh
folders, checking the parts) and :mod:`assembly_constraints.executor.cad.step` (STEP assemblies),
:mod:`assembly_constraints.executor.cad.sweep` (swept collision along straight removal paths),
:mod:`assembly_constraints.executor.cad.sections` (cross-sections of slices), :mod:`assembly_constraints.executor.cad.derive`
(insertion axes, holes, geometric precedence by disassembly), :mod:`assembly_constraints.executor.cad.write`
(the assembly folder), :mod:`assembly_constraints.executor.cad.cli` (``import``) and :mod:`assembly_constraints.executor.cad.bench`
(``bench import``). :mod:`assembly_constraints.executor.cad.assembled` writes a shipped product's parts in the
assembled pose (``executor export --assembled``). Units: metres inside.
"""
