"""Checks of a deck before it runs: its size and placement (preflight), members too
thin for their SPH formulation (thin_members)."""
