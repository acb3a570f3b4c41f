"""Interactions: walls, particle contact, the SPH-FEM couplings (penalty, tied,
hybrid), nodal ones, gravity.

See :mod:`sphdyn.interactions.base` for the protocol the stepper uses.
"""

from .base import Interaction, InteractionBase
from .contact import ParticleContact
from .gravity import Gravity
from .hybrid_coupling import HybridCoupling
from .penalty_coupling import PenaltyCoupling
from .tied_coupling import TiedCoupling
from .wall import STIFFNESS, Wall, WallSpec

__all__ = ["Gravity", "HybridCoupling", "Interaction", "InteractionBase", "ParticleContact",
           "PenaltyCoupling", "STIFFNESS", "TiedCoupling", "Wall", "WallSpec"]
