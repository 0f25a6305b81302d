"""The assembly folder of an imported product, in the vocabulary every command reads, written
from what :mod:`executor.cad.operations` finds (this package imports it, never the other way).

The modules, each importing only those listed before it:

- :mod:`~executor.cad.write.assembly`: ``assembly.toml`` (parts, holes, pins) and the import's settings;
- :mod:`~executor.cad.write.facts`: ``sizes.lp``, ``nominal_sizes.lp``, ``geometric_precedence.lp``, ``cell_order.lp``;
- :mod:`~executor.cad.write.depths`: the depth of a hole to where its part's tip is in the CAD;
- :mod:`~executor.cad.write.near_misses`: the pairs the cell cannot tell, decided from the CAD;
- :mod:`~executor.cad.write.widened`: fits the cell builds at their nominal diameter or with more room;
- :mod:`~executor.cad.write.meshes`: the parts' frames and the meshes written with their convex pieces;
- :mod:`~executor.cad.write.trays`: where each part waits (default trays within the arm's reach);
- :mod:`~executor.cad.write.manifest`: ``.import-manifest.json``, the files a later import may replace;
- :mod:`~executor.cad.write.bosses`: the plate's bosses around the holes;
- :mod:`~executor.cad.write.geometry`: ``geometry.toml``, the simulated cell's product;
- :mod:`~executor.cad.write.folder`: the folder written, ``geometry.toml`` kept where the cell answers as ``sizes.lp``.
"""
