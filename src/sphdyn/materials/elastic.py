"""Hypoelastic linear isotropic material (Hooke's law in rate form).

.. math:: \\Delta\\sigma = \\lambda\\,\\mathrm{tr}(\\Delta\\varepsilon)\\,I
          + 2G\\,\\Delta\\varepsilon, \\qquad \\lambda = K - \\tfrac{2}{3}G

applied to the Jaumann-rotated stress with ``Delta eps = D dt``
(Belytschko, Liu & Moran, *Nonlinear Finite Elements for Continua and
Structures*, 2000, Sec. 5.4.1, hypoelastic Jaumann model).

Parameters (``pack``): ``density`` and either ``E``, ``nu`` or ``K``, ``G``.
Vector layout ``[density, K, G]``. No history.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from .base import (
    P_G,
    P_K,
    MaterialModel,
    energy_increment,
    jaumann_rotate,
    load_sym6,
    p_wave_speed,
    pack_common,
    rate_split,
    register,
    scale6,
    store_sym6,
    to_mat33,
    to_sym6,
)


@njit(cache=True, error_model="numpy")
def elastic_increment(s, d, K, G):
    """Hooke increment on 6-tuples: ``s + lambda tr(d) I + 2 G d``.

    Parameters
    ----------
    s : 6-tuple
        Stress ``(xx, yy, zz, xy, yz, xz)`` [Pa], tension positive.
    d : 6-tuple
        Strain increment (tensor shear components) [-].
    K, G : float
        Bulk and shear modulus [Pa].

    Returns
    -------
    6-tuple, updated stress [Pa].
    """
    lam_tr = (K - 2.0 * G / 3.0) * (d[0] + d[1] + d[2])
    g2 = 2.0 * G
    return (s[0] + lam_tr + g2 * d[0],
            s[1] + lam_tr + g2 * d[1],
            s[2] + lam_tr + g2 * d[2],
            s[3] + g2 * d[3],
            s[4] + g2 * d[4],
            s[5] + g2 * d[5])


@njit(cache=True, error_model="numpy")
def elastic_point(sig, deps, K, G):
    """Hypoelastic update of one material point.

    ``sigma_new = sigma + lambda tr(deps) I + 2 G deps`` with
    ``lambda = K - 2G/3`` (linear isotropic Hooke law in increment form).

    Parameters
    ----------
    sig : (3, 3) float64
        Cauchy stress [Pa], tension positive (symmetric part is used).
    deps : (3, 3) float64
        Strain increment ``D dt`` [-] (symmetric part is used).
    K, G : float
        Bulk and shear modulus [Pa].

    Returns
    -------
    (3, 3) float64, new stress [Pa] (new array).
    """
    return to_mat33(elastic_increment(to_sym6(sig), to_sym6(deps), K, G))


@njit(cache=True, error_model="numpy", parallel=True)
def elastic_update(idx, L, dt, rho, sig, e, c, damage, hist, params, size):
    """Group kernel of the hypoelastic model (common kernel signature).

    For each ``i`` in ``idx``: ``D, W`` from ``L[i]``; Jaumann rotation
    ``sigma += dt (W sigma - sigma W)``; Hooke increment with
    ``deps = D dt``; ``e[i] += dt/2 (sigma_old + sigma_new):D / rho[i]``;
    ``c[i] = sqrt((K + 4G/3)/rho[i])``. ``damage`` and ``hist`` are not used.
    Shapes/units: see ``base.KERNEL_SIGNATURE_DOC``.
    """
    K = params[P_K]
    G = params[P_G]
    for k in prange(idx.shape[0]):
        i = idx[k]
        d, w = rate_split(L, i)
        s_old = jaumann_rotate(load_sym6(sig, i), w, dt)
        s_new = elastic_increment(s_old, scale6(d, dt), K, G)
        store_sym6(sig, i, s_new)
        e[i] += energy_increment(s_old, s_new, d, dt, rho[i])
        c[i] = p_wave_speed(K, G, rho[i])


def pack_elastic(values: dict) -> np.ndarray:
    """``[density, K, G]`` from ``density`` and ``(E, nu)`` or ``(K, G)`` [SI]."""
    return np.array(pack_common(values), dtype=np.float64)


ELASTIC = register(MaterialModel(
    name="elastic",
    history_names=(),
    pack=pack_elastic,
    update=elastic_update,
))
