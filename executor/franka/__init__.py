"""The cell on a Franka arm (FR3, Panda) through franky (:mod:`.arm`, :mod:`.backend`,
:mod:`.safety`), and franky-sim, the simulator of the arm's own network protocol that its
tests run against (:mod:`.sim_server`; docs/franka.md). franky is imported where a module
needs it: the rest of the executor runs without it."""
