"""Parts: things with items that move (SPH particles, finite-element meshes).

See :mod:`sphdyn.parts.base` for the protocol the stepper uses.
"""

from .base import PART_KINDS, Part, register_part
from .fem import SolidPart, SolidSettings
from .sph.part import SPHPart, SPHSettings

__all__ = ["PART_KINDS", "Part", "SPHPart", "SPHSettings", "SolidPart", "SolidSettings",
           "register_part"]
