"""Finite-element parts: solid elements (hex8, quad4) and, beside them, line elements."""

from .solid_part import SolidPart, SolidSettings, solid_part

__all__ = ["SolidPart", "SolidSettings", "solid_part"]
