"""Tests of precedence constraints (asp/precedence)."""
