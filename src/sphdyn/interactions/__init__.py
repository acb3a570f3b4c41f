"""Interactions: walls, particle contact (and the SPH-FEM couplings to come).

See :mod:`sphdyn.interactions.base` for the protocol the stepper uses.
"""

from .base import Interaction, InteractionBase
from .contact import ParticleContact
from .wall import STIFFNESS, Wall, WallSpec

__all__ = ["Interaction", "InteractionBase", "ParticleContact", "STIFFNESS", "Wall",
           "WallSpec"]
