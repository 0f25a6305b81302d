"""The simulated world: the cell's geometry and generated assets (:mod:`.geometry`), the
PyBullet scene with plate, tray and parts (:mod:`.scene`) and the arm model with its
wrist force/torque sensor (:mod:`.arm`).  Nothing here knows about control or skills."""

TIME_STEP = 0.001
"""The physics and control step of every simulated cell [s] (1 kHz)."""
