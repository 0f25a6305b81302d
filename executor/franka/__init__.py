"""The Franka backend: the cell's skills on a Franka arm (FR3, Panda) through franky
(docs/franka.md). Imports franky lazily: the rest of the executor runs without it."""
