"""Hole assignment and complete assembly plans from learned facts (paper 2.2, end)."""
