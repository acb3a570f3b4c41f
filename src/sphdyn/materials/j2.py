"""J2 (von Mises) plasticity, linear isotropic hardening, radial return.

Elastic predictor / plastic corrector (Simo & Hughes, *Computational
Inelasticity*, Springer 1998, Box 3.1 and 3.2), adapted to the hypoelastic
increment on the Jaumann-rotated stress:

.. math::

    \\sigma^{tr} = \\sigma^n + \\lambda\\,\\mathrm{tr}(\\Delta\\varepsilon) I
                 + 2G\\,\\Delta\\varepsilon, \\qquad
    q^{tr} = \\sqrt{3/2}\\,\\lVert s^{tr} \\rVert

    f = q^{tr} - (\\sigma_y + H \\bar\\varepsilon^p_n)

    f > 0:\\quad \\Delta\\gamma = \\frac{f}{3G + H}, \\quad
    s^{n+1} = s^{tr}\\left(1 - \\frac{3G\\,\\Delta\\gamma}{q^{tr}}\\right),
    \\quad \\bar\\varepsilon^p_{n+1} = \\bar\\varepsilon^p_n + \\Delta\\gamma

The mean stress is untouched by the return (plastic flow is deviatoric), and
after a return ``q = sigma_y + H eps_p`` exactly.

Parameters (``pack``): ``density``, ``E``/``nu`` or ``K``/``G``,
``yield_stress`` (> 0), ``hardening_modulus`` (>= 0, absent: the deck
default, perfect plasticity). Vector
``[density, K, G, yield_stress, hardening_modulus]``.
History: ``("plastic_strain",)``, the equivalent plastic strain. Deck
table: :class:`J2Params`.

The model and its tests: docs/theory.md, "Materials".
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from numba import njit, prange
from pydantic import Field

from ..deck.units import PRESSURE
from ..deck.values import PositivePressure, quantity
from .base import (N_COMMON, P_G, P_K, MaterialModel, ddot6, deviatoric_split,
                   energy_increment, get_float, jaumann_rotate, load_sym6,
                   p_wave_speed, pack_common, rate_split, register, scale6, store_sym6,
                   to_mat33, to_sym6)
from .elastic import ElasticParams, elastic_increment
from .registry import schema_defaults

P_YIELD = N_COMMON
P_HARDENING = N_COMMON + 1


@njit(cache=True, error_model="numpy")
def j2_return(s, d, K, G, sigma_y, H, eps_p):
    """Elastic predictor and radial return on 6-tuples.

    Parameters
    ----------
    s : 6-tuple
        Stress at the start of the step [Pa] (already rotated).
    d : 6-tuple
        Strain increment [-].
    K, G : float
        Bulk and shear modulus [Pa].
    sigma_y : float
        Initial yield stress [Pa].
    H : float
        Linear isotropic hardening modulus ``d sigma_y / d eps_p`` [Pa].
    eps_p : float
        Equivalent plastic strain at the start of the step [-].

    Returns
    -------
    s_new : 6-tuple
        Updated stress [Pa].
    eps_p_new : float
        Updated equivalent plastic strain [-].
    """
    trial = elastic_increment(s, d, K, G)
    dev, m = deviatoric_split(trial)
    q_tr = math.sqrt(1.5 * ddot6(dev, dev))
    f = q_tr - (sigma_y + H * eps_p)
    if f <= 0.0:
        return trial, eps_p
    d_gamma = f / (3.0 * G + H)
    factor = 1.0 - 3.0 * G * d_gamma / q_tr
    s_new = (factor * dev[0] + m, factor * dev[1] + m, factor * dev[2] + m,
             factor * dev[3], factor * dev[4], factor * dev[5])
    return s_new, eps_p + d_gamma


@njit(cache=True, error_model="numpy")
def j2_point(sig, deps, K, G, sigma_y, H, eps_p):
    """J2 radial-return update of one material point.

    See the module docstring for the equations (Simo & Hughes 1998,
    Box 3.1/3.2).

    Parameters
    ----------
    sig, deps, K, G
        As for :func:`~sphdyn.materials.elastic.elastic_point`.
    sigma_y, H : float
        Initial yield stress and hardening modulus [Pa].
    eps_p : float
        Equivalent plastic strain [-].

    Returns
    -------
    sig_new : (3, 3) float64
        New stress [Pa] (new array).
    eps_p_new : float
        New equivalent plastic strain [-].
    """
    s_new, ep = j2_return(to_sym6(sig), to_sym6(deps), K, G, sigma_y, H, eps_p)
    return to_mat33(s_new), ep


@njit(cache=True, error_model="numpy", parallel=True)
def j2_update(idx, L, dt, rho, sig, e, c, damage, hist, params, size):
    """Group kernel of the J2 model (common kernel signature).

    For each ``i`` in ``idx``: Jaumann rotation, :func:`j2_return` with
    ``deps = D dt`` and ``eps_p = hist[i, 0]``, energy increment
    ``dt/2 (sigma_old + sigma_new):D / rho[i]`` (elastic + plastic work),
    ``c[i] = sqrt((K + 4G/3)/rho[i])``. ``damage`` is not used.
    Shapes/units: see ``base.KERNEL_SIGNATURE_DOC``.
    """
    K = params[P_K]
    G = params[P_G]
    sy = params[P_YIELD]
    H = params[P_HARDENING]
    for k in prange(idx.shape[0]):
        i = idx[k]
        d, w = rate_split(L, i)
        s_old = jaumann_rotate(load_sym6(sig, i), w, dt)
        s_new, ep = j2_return(s_old, scale6(d, dt), K, G, sy, H, hist[i, 0])
        store_sym6(sig, i, s_new)
        hist[i, 0] = ep
        e[i] += energy_increment(s_old, s_new, d, dt, rho[i])
        c[i] = p_wave_speed(K, G, rho[i])


class J2Params(ElasticParams):
    """[[material]] model = "j2": von Mises plasticity, linear hardening.

    Elastic constants as for "elastic" (E and nu, or K and G).
    """

    model: Literal["j2"] = Field(description="Constitutive model.")
    yield_stress: PositivePressure = Field(
        description="Initial yield stress in uniaxial tension.")
    hardening_modulus: quantity(PRESSURE, "hardening modulus", lo=0) = Field(
        0.0, description="Plastic modulus H of linear isotropic hardening "
                         "(0 = perfect plasticity).")


def pack_j2(values: dict) -> np.ndarray:
    """``[density, K, G, yield_stress, hardening_modulus]`` from SI values.

    An absent ``hardening_modulus`` takes the deck default (:class:`J2Params`).
    """
    out = pack_common(values)
    out.append(get_float(values, "yield_stress", min_value=0.0, min_inclusive=False))
    out.append(get_float(values, "hardening_modulus", min_value=0.0,
                         default=schema_defaults(J2Params)["hardening_modulus"]))
    return np.array(out, dtype=np.float64)


J2 = register(MaterialModel(
    name="j2",
    history_names=("plastic_strain",),
    pack=pack_j2,
    update=j2_update,
    schema=J2Params,
    initial_stress=True,
    stress_scalable=True,
    test_density=7850.0,
))
