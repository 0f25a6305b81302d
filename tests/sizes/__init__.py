"""Tests of size learning and policies (asp/sizes)."""
