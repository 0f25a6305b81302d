"""Tests of the simulated cell (executor)."""
