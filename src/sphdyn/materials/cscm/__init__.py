"""CSCM concrete model (Continuous Surface Cap Model, LS-DYNA MAT_159).

Re-implementation from the equations in ``cscm-notes.md`` (sections cited
as "notes sec. x", tags [V] verified / [S] secondary source / [R] recalled /
[D] derived or chosen here) and Y.D. Murray, *Users Manual for LS-DYNA
Concrete Material Model 159*, FHWA-HRT-05-062 (2007). See ``docs/cscm.md``.

Sign convention
---------------
sphdyn stresses are **tension positive**. The CSCM literature uses the
pressure invariant compression positive, ``J1 = 3P`` (notes sec. 1.1 [S]).
Inside this package ``J1`` always means the compression-positive
``J1 = -tr(sigma)``; the conversion happens in :func:`invariants`.
Plastic volumetric strain ``ev`` is likewise compaction positive.

Algorithm of one step (notes sec. 1.2-1.11)
-------------------------------------------
The undamaged ("viscoplastic") stress ``s_vp`` and the total strain are
history variables. The strain increment is split into ``n`` equal
sub-increments with ``|deps|/n <= incre`` (subincrementation, [V] text,
default ``incre`` is a choice [D], see :func:`pack_cscm`). Per sub-step:

1. elastic trial ``s_T = s_vp + K tr(de) I + 2G dev(de)``;
2. if ``f = J2 - (Rub Ff sqrt(Fc))^2 > 0`` (or ``J1`` outside the interval
   ``[J1_apex, X]`` where the surface exists) the inviscid stress ``s_P`` is
   the closest point of the surface in the energy norm
   ``dJ1^2/(9K) + d(sqrt J2)^2/G`` at fixed Lode angle (associated flow in
   the meridian plane; the Lode-angle component of the normal is neglected:
   choice [D]); the cap is held fixed during the projection and updated
   explicitly afterwards from the plastic compaction (sub-stepping keeps the
   lag small);
3. rate effects (off by default, IRATE = 0 [V]): Duvaut-Lions
   ``s_vp = (1-g) s_T + g s_P``, ``g = (dt/eta)/(1 + dt/eta)`` [R];
4. damage update (brittle/ductile logistic laws, [R]/[S]) and the damaged
   stress ``sigma = (1-d) s_vp`` [R].

Modules: :mod:`~.defaults` (the short-form fits), :mod:`~.schema` (the deck
table), :mod:`~.layout` (parameter vector and history row),
:mod:`~.packing` (deck values to the vector), :mod:`~.surface` (yield
surface and invariants), :mod:`~.projection` (return to the surface),
:mod:`~.damage` (softening and damage laws), :mod:`~.point` (point update
and group kernel). The names of all of them are available from this package.
"""

from ..registry import MaterialModel, register
from .damage import (DMAX, brittle_softening_c, ductile_softening_a, logistic_damage,
                     max_principal, max_principal_bound, transition)
from .defaults import (CONSTANT_DEFAULTS, GFC_PER_GFT, MPA, NU, PARAM_NAMES,
                       PSI_PER_MPA, default_parameters, elastic_moduli,
                       fracture_energy_tension)
from .layout import *  # noqa: F401,F403  (P_* parameter and H_* history indices)
from .layout import HISTORY_NAMES, N_PARAMS
from .packing import cscm_parameters, dilog_neg, initial_history, kappa0, pack_cscm
from .point import N_STRIPES, cscm_point, cscm_update, damage_scale
from .projection import (NGOLDEN, NSCAN, project, project_from_trial, project_global,
                         project_on_meridian, yield_fraction)
from .schema import CscmParams
from .surface import (cap_from_compaction, cap_function, elastic_radius_bound, invariants,
                      j1_radius, kappa_from_cap, meridian, meridian_radius,
                      meridian_radius_curvature, meridian_radius_slope, rubin_factor, rubin_q,
                      shear_surface, surely_elastic, surface_radius, yield_function)

CSCM = register(MaterialModel(
    name="cscm",
    history_names=HISTORY_NAMES,
    pack=pack_cscm,
    update=cscm_update,
    history_init=initial_history,
    schema=CscmParams,
    has_damage=True,
    softening=True,
))
