r"""Uniaxial stress along a bar: the sublayer particles of ``stiffness = "axial"``.

A bar's sublayer particle (:mod:`sphdyn.interactions.sublayer`) samples its
strain rate from the concrete around it. With this model it answers only to
the rate along the bar, as the bar's truss elements do, and its stress acts
only along the bar:

.. math::

    \dot\varepsilon = \mathbf t\cdot\mathbf D\,\mathbf t, \qquad
    \boldsymbol\sigma = s\,\mathbf t\otimes\mathbf t

with :math:`\mathbf t` the bar's unit direction at the particle (history
columns ``bar_x|y|z``, written by the sublayer coupling before each update)
and :math:`s` the axial stress (column ``axial_stress``, a scalar: the
stress turns with the bar). The axial stress follows the one-dimensional
return map of rate-independent plasticity with linear isotropic hardening
(Simo & Hughes, *Computational Inelasticity*, 1998, Box 1.4):

.. math::

    s^{tr} = s^n + E\,\dot\varepsilon\,\Delta t, \qquad
    f = |s^{tr}| - (\sigma_y + H\bar\varepsilon^p_n)

    f > 0:\quad \Delta\gamma = \frac{f}{E + H},\quad
    s^{n+1} = s^{tr} - \mathrm{sign}(s^{tr})\,E\,\Delta\gamma,\quad
    \bar\varepsilon^p_{n+1} = \bar\varepsilon^p_n + \Delta\gamma

which is what the J2 model gives in uniaxial stress (the von Mises stress is
:math:`|s|` there, the equivalent plastic strain the axial one): a J2 bar's
truss and its particles follow one law. An elastic bar has
:math:`\sigma_y = \infty`. The rates across the bar and its shear are not
resisted: the particle adds no transverse or shear stiffness of steel to the
concrete it sits in (the FEM reference's trusses have none either).

Energy: :math:`\Delta e = \tfrac{\Delta t}{2\rho}(s^n + s^{n+1})\dot\varepsilon`,
the stress power :math:`\boldsymbol\sigma:\mathbf D = s\,\dot\varepsilon`. Wave
speed: the bar's, :math:`c = \sqrt{E/\rho}`, :math:`E = 9KG/(3K + G)`.

Parameter vector ``[density, K, G, yield_stress, hardening_modulus]`` (the J2
layout, :func:`uniaxial_params`). Not a deck model: the sublayer builds its
groups (:func:`sphdyn.build.model.build_model`).

The model and its tests: docs/theory.md, "Materials".
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from .base import N_COMMON, P_G, P_K, MaterialModel, young_modulus
from .j2 import pack_j2

P_YIELD = N_COMMON
P_HARDENING = N_COMMON + 1
#: history columns: the J2 model's first, so the two share it
HISTORY_NAMES = ("plastic_strain", "axial_stress", "bar_x", "bar_y", "bar_z")
H_PLASTIC, H_STRESS, H_DIRECTION = 0, 1, 2


@njit(cache=True, error_model="numpy")
def young(params):
    """Young's modulus :math:`E = 9KG/(3K + G)` [Pa] of a packed vector."""
    return young_modulus(params[P_K], params[P_G])


def uniaxial_params(model: str, packed: np.ndarray) -> np.ndarray:
    """This model's vector from an ``elastic`` or ``j2`` vector of the bar's
    material (an elastic bar never yields: :math:`\\sigma_y = \\infty`)."""
    if model == "j2":
        return np.asarray(packed[:N_COMMON + 2], dtype=np.float64).copy()
    if model == "elastic":
        return np.concatenate([packed[:N_COMMON], [math.inf, 0.0]]).astype(np.float64)
    raise ValueError(f"a uniaxial bar follows an elastic or j2 material, not {model!r}")


@njit(cache=True, error_model="numpy")
def axial_return(s, deps, E, sigma_y, H, eps_p):
    """One-dimensional elastic predictor and return (module docstring).

    ``s`` axial stress [Pa], ``deps`` axial strain increment [-], ``E``,
    ``sigma_y``, ``H`` [Pa], ``eps_p`` plastic strain [-]. Returns the new
    stress and plastic strain.
    """
    trial = s + E * deps
    f = abs(trial) - (sigma_y + H * eps_p)
    if f <= 0.0:
        return trial, eps_p
    d_gamma = f / (E + H)
    return trial - math.copysign(E * d_gamma, trial), eps_p + d_gamma


@njit(cache=True, error_model="numpy", parallel=True)
def uniaxial_update(idx, L, dt, rho, sig, e, c, damage, hist, params, size):
    """Group kernel (common kernel signature, ``base.KERNEL_SIGNATURE_DOC``):
    per ``i`` in ``idx`` the axial rate ``t . D t`` with ``t = hist[i, 2:5]``,
    :func:`axial_return`, ``sig[i] = s t t^T``, the energy increment and
    ``c[i] = sqrt(E / rho[i])``. ``damage`` and ``size`` are not used."""
    E = young(params)
    sy, H = params[P_YIELD], params[P_HARDENING]
    for k in prange(idx.shape[0]):
        i = idx[k]
        t0, t1, t2 = hist[i, H_DIRECTION], hist[i, H_DIRECTION + 1], hist[i, H_DIRECTION + 2]
        rate = (t0 * (L[i, 0, 0] * t0 + L[i, 0, 1] * t1 + L[i, 0, 2] * t2)
                + t1 * (L[i, 1, 0] * t0 + L[i, 1, 1] * t1 + L[i, 1, 2] * t2)
                + t2 * (L[i, 2, 0] * t0 + L[i, 2, 1] * t1 + L[i, 2, 2] * t2))
        s_old = hist[i, H_STRESS]
        s_new, ep = axial_return(s_old, rate * dt, E, sy, H, hist[i, H_PLASTIC])
        hist[i, H_STRESS] = s_new
        hist[i, H_PLASTIC] = ep
        sig[i, 0, 0] = s_new * t0 * t0
        sig[i, 1, 1] = s_new * t1 * t1
        sig[i, 2, 2] = s_new * t2 * t2
        sig[i, 0, 1] = sig[i, 1, 0] = s_new * t0 * t1
        sig[i, 1, 2] = sig[i, 2, 1] = s_new * t1 * t2
        sig[i, 0, 2] = sig[i, 2, 0] = s_new * t0 * t2
        if rho[i] > 0.0:
            e[i] += 0.5 * dt * (s_old + s_new) * rate / rho[i]
            c[i] = math.sqrt(E / rho[i])
        else:
            c[i] = 0.0


#: not registered: no deck table, its groups are built by the sublayer
UNIAXIAL = MaterialModel(
    name="uniaxial_bar",
    history_names=HISTORY_NAMES,
    pack=pack_j2,  # the same layout
    update=uniaxial_update,
    modulus=young,
)
