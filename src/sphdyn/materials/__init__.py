"""Constitutive models, registered by name.

Every model provides a point function and a group kernel with the common
signature ``update(idx, L, dt, rho, sig, e, c, damage, hist, params)``
(see :mod:`sphdyn.materials.base`). Importing this package registers the
built-in models ``"elastic"``, ``"j2"`` and ``"cscm"`` (concrete, LS-DYNA
MAT_159 re-implementation, :mod:`sphdyn.materials.cscm`).
"""

from .base import (
    KERNEL_SIGNATURE_DOC,
    REGISTRY,
    MaterialModel,
    available_models,
    deviatoric_split,
    energy_increment,
    get_model,
    jaumann_rotate,
    register,
    von_mises,
)
from .elastic import ELASTIC, elastic_point, elastic_update
from .j2 import J2, j2_point, j2_update
from .cscm import CSCM, cscm_point, cscm_update

__all__ = [
    "KERNEL_SIGNATURE_DOC",
    "REGISTRY",
    "MaterialModel",
    "available_models",
    "get_model",
    "register",
    "jaumann_rotate",
    "deviatoric_split",
    "von_mises",
    "energy_increment",
    "ELASTIC",
    "elastic_point",
    "elastic_update",
    "J2",
    "j2_point",
    "j2_update",
    "CSCM",
    "cscm_point",
    "cscm_update",
]
