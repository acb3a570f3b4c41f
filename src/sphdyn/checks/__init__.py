"""Checks of a deck before it runs: its size and memory (size), its placement
(placement), both in order (preflight); members too thin for their SPH
formulation (thin_members)."""
