"""Tests of hole assignment and plans (asp/plans)."""
