"""Tests of the session over Zenoh (asp/session)."""
