"""The simulated world: the cell's geometry and generated assets (:mod:`.geometry`), the
PyBullet scene with plate, tray and parts (:mod:`.scene`) and the arm model with its
wrist force/torque sensor (:mod:`.arm`).  Nothing here knows about control or skills."""

TIME_STEP = 0.001
"""The physics and control step of every simulated cell [s] (1 kHz)."""
SIZE_RESOLUTION = 25e-6
"""The smallest room or interference per side [m] between a part's section and a hole's
that the cell's physics tells apart (docs/cell.md#what-the-physics-resolves): a part's
primitive has its edges rounded by Bullet's 1 mm collision margin, so its bottom edge meets
a hole's rim as a ramp that turns horizontal, and the contacts give by up to ~0.1 mm under
the insertion's forces. Measured (a d 11 mm peg, 2-3 trials each): 0.005 and 0.01 mm
per side came out wrong (an interference ``fit``, a clearance ``no_fit``), 0.02 to
0.1 mm right on both sides. Contact ERP or stiffness, more solver iterations, a lower
insertion force or physics substeps did not make 0.01 mm right in every trial, and the held
part's margin cannot be set (it is a link of the arm): measured in the same doc."""
