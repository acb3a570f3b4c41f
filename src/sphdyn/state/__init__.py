"""Model state: growable per-item arrays (kinematics) and the particle fields.

:mod:`~sphdyn.state.store` holds arrays with a capacity and grows them in one
place; :mod:`~sphdyn.state.particles` builds the kinematics every part has and
the SPH particle fields on it; :mod:`~sphdyn.state.mesh` the mesh nodes,
elements and integration points of finite-element parts.
"""

from .particles import (BC_COMPONENTS, BC_FIXED, BC_FREE, BC_SLAVE, BC_VELOCITY, KINEMATICS,
                        PARTICLE_FIELDS, Kinematics, Particles)
from .mesh import POINT_FIELDS, Elements, MaterialPoints, Nodes
from .store import STATE, WORK, ArrayStore

__all__ = ["ArrayStore", "BC_COMPONENTS", "BC_FIXED", "BC_FREE", "BC_SLAVE", "BC_VELOCITY",
           "Elements", "KINEMATICS", "Kinematics", "MaterialPoints", "Nodes", "PARTICLE_FIELDS",
           "POINT_FIELDS",
           "Particles", "STATE", "WORK"]
