"""The cell on a Franka arm (FR3, Panda) through franky, and franky-sim, the simulator of
the arm's own network protocol that its tests run against (docs/franka.md)."""
