"""Model state: growable per-item arrays (kinematics) and the particle fields.

:mod:`~sphdyn.state.store` holds arrays with a capacity and grows them in one
place; :mod:`~sphdyn.state.particles` builds the kinematics every part has and
the SPH particle fields on it. The FEM issue adds mesh state beside them.
"""

from .particles import (BC_FIXED, BC_FREE, BC_VELOCITY, KINEMATICS, PARTICLE_FIELDS,
                        Kinematics, Particles)
from .store import STATE, WORK, ArrayStore

__all__ = ["ArrayStore", "BC_FIXED", "BC_FREE", "BC_VELOCITY", "KINEMATICS",
           "Kinematics", "PARTICLE_FIELDS", "Particles", "STATE", "WORK"]
