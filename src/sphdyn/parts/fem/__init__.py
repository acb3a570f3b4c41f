"""Finite-element parts: solid elements (hex8, quad4; :mod:`.solid_part`) and line
elements (co-rotational beams, trusses; :mod:`.line_part`)."""

from .line_part import BeamSection, LinePart
from .solid_part import SolidPart, SolidSettings, solid_part

__all__ = ["BeamSection", "LinePart", "SolidPart", "SolidSettings", "solid_part"]
