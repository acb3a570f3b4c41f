"""Constitutive models, registered by name.

Every model provides a point function and a group kernel with the common
signature ``update(idx, L, dt, rho, sig, e, c, damage, hist, params)``
(see :mod:`sphdyn.materials.base`) and owns its deck table (keys, defaults,
checks). Importing this package registers the built-in models
``"elastic"``, ``"j2"``, ``"cscm"`` (concrete, LS-DYNA MAT_159
re-implementation, :mod:`sphdyn.materials.cscm`), ``"high_explosive"``
(JWL products with a programmed burn, :mod:`sphdyn.materials.explosive`) and
``"gas"`` (:mod:`sphdyn.materials.gas`); models of other packages
register through entry points (:mod:`sphdyn.materials.registry`).
"""

from .base import (
    KERNEL_SIGNATURE_DOC,
    REGISTRY,
    MaterialGroup,
    MaterialModel,
    available_models,
    deviatoric_split,
    energy_increment,
    get_model,
    jaumann_rotate,
    register,
    von_mises,
)
from .registry import ENTRY_POINT_GROUP, history_layout, load_entry_points, material_schemas
from .elastic import ELASTIC, ElasticParams, elastic_point, elastic_update
from .j2 import J2, J2Params, j2_point, j2_update
from .cscm import CSCM, CscmParams, cscm_point, cscm_update
from .explosive import HIGH_EXPLOSIVE, ExplosiveParams
from .gas import GAS, GasParams
from .uniaxial import UNIAXIAL, uniaxial_params

__all__ = [
    "ENTRY_POINT_GROUP",
    "KERNEL_SIGNATURE_DOC",
    "REGISTRY",
    "MaterialGroup",
    "MaterialModel",
    "available_models",
    "get_model",
    "history_layout",
    "load_entry_points",
    "material_schemas",
    "register",
    "jaumann_rotate",
    "deviatoric_split",
    "von_mises",
    "energy_increment",
    "ELASTIC",
    "ElasticParams",
    "elastic_point",
    "elastic_update",
    "J2",
    "J2Params",
    "j2_point",
    "j2_update",
    "CSCM",
    "CscmParams",
    "cscm_point",
    "cscm_update",
    "HIGH_EXPLOSIVE",
    "ExplosiveParams",
    "GAS",
    "GasParams",
    "UNIAXIAL",
    "uniaxial_params",
]
