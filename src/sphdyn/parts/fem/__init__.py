"""Finite-element parts: line elements (co-rotational beams, trusses) in :mod:`.line_part`."""

from .line_part import BeamSection, LinePart

__all__ = ["BeamSection", "LinePart"]
