"""Parts: things with items that move (SPH particles now; meshes with the FEM issue).

See :mod:`sphdyn.parts.base` for the protocol the stepper uses.
"""

from .base import PART_KINDS, Part, register_part
from .sph.part import SPHPart, SPHSettings

__all__ = ["PART_KINDS", "Part", "SPHPart", "SPHSettings", "register_part"]
