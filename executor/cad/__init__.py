"""A product from its CAD: STEP assemblies or one mesh per part in the assembled pose.

Modules, each importing only those before it: ``fits.faces`` (the faces of nominal
zero-clearance fits), ``sweep`` (swept collision along straight removal paths),
``fits.threads`` (modelled and cosmetic threads), ``parts`` (reading mesh folders,
checking the parts) and ``step`` (STEP assemblies), ``sections`` (cross-sections of
slices), ``derive`` (insertion axes, holes, geometric precedence by disassembly),
``operations`` (what the cell does with each part, why a part is placed by hand),
``write`` (the assembly folder) and ``cli`` (``import``). ``assembled`` writes a shipped
product's parts in the assembled pose (``executor export --assembled``). Units: metres
inside.
"""
