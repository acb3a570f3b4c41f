"""Interactions: walls, particle contact, the SPH-FEM penalty coupling, nodal ones.

See :mod:`sphdyn.interactions.base` for the protocol the stepper uses.
"""

from .base import Interaction, InteractionBase
from .contact import ParticleContact
from .penalty_coupling import PenaltyCoupling
from .wall import STIFFNESS, Wall, WallSpec

__all__ = ["Interaction", "InteractionBase", "ParticleContact", "PenaltyCoupling", "STIFFNESS",
           "Wall", "WallSpec"]
