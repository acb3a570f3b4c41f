"""Hypoelastic linear isotropic material (Hooke's law in rate form).

.. math:: \\Delta\\sigma = \\lambda\\,\\mathrm{tr}(\\Delta\\varepsilon)\\,I
          + 2G\\,\\Delta\\varepsilon, \\qquad \\lambda = K - \\tfrac{2}{3}G

applied to the Jaumann-rotated stress with ``Delta eps = D dt``
(Belytschko, Liu & Moran, *Nonlinear Finite Elements for Continua and
Structures*, 2000, Sec. 5.4.1, hypoelastic Jaumann model).

Parameters (``pack``): ``density`` and either ``E``, ``nu`` or ``K``, ``G``.
Vector layout ``[density, K, G]``. No history. Deck table:
:class:`ElasticParams`.

The model and its tests: docs/theory.md, "Materials".
"""

from __future__ import annotations

from typing import Literal, Optional

import numpy as np
from numba import njit, prange
from pydantic import Field, model_validator

from ..deck.messages import problem
from ..deck.sections.material import MaterialSection
from ..deck.values import PositivePressure, real
from .base import (P_G, P_K, MaterialModel, energy_increment, jaumann_rotate,
                   load_sym6, p_wave_speed, pack_common, rate_split, register, scale6,
                   store_sym6, to_mat33, to_sym6)


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


class ElasticParams(MaterialSection):
    """[[material]] model = "elastic": isotropic linear elasticity.

    Give exactly one pair of elastic constants: E and nu, or K and G.
    """

    model: Literal["elastic"] = Field(description="Constitutive model.")
    E: Optional[PositivePressure] = Field(
        None, description="Young's modulus (give with nu).")
    nu: Optional[real("Poisson ratio", lo=-1, hi=0.5, lo_open=True,
                      hi_open=True)] = Field(
        None, description="Poisson ratio (give with E).")
    K: Optional[PositivePressure] = Field(
        None, description="Bulk modulus (give with G).")
    G: Optional[PositivePressure] = Field(
        None, description="Shear modulus (give with K).")

    @model_validator(mode="after")
    def _one_pair(self):
        given = [k for k in ("E", "nu", "K", "G") if getattr(self, k) is not None]
        if set(given) in ({"E", "nu"}, {"K", "G"}):
            return self
        fix = "give either E and nu, or K and G"
        if not given:
            raise problem("no elastic constants are given", fix)
        if {"E", "nu"} & set(given) and {"K", "G"} & set(given):
            raise problem(f"{', '.join(given)} mix the two ways of giving "
                          "elastic constants", fix + ", not both")
        other = {"E": "nu", "nu": "E", "K": "G", "G": "K"}[given[0]]
        raise problem(f"{given[0]} is given without {other}",
                      f"add {other} ({fix})")

    def bulk_modulus(self) -> float:
        """Return the bulk modulus K [Pa]."""
        if self.K is not None:
            return self.K
        return self.E / (3.0 * (1.0 - 2.0 * self.nu))

    def shear_modulus(self) -> float:
        """Return the shear modulus G [Pa]."""
        if self.G is not None:
            return self.G
        return self.E / (2.0 * (1.0 + self.nu))


def pack_elastic(values: dict) -> np.ndarray:
    """``[density, K, G]`` from ``density`` and ``(E, nu)`` or ``(K, G)`` [SI]."""
    return np.array(pack_common(values), dtype=np.float64)


ELASTIC = register(MaterialModel(
    name="elastic",
    history_names=(),
    pack=pack_elastic,
    update=elastic_update,
    schema=ElasticParams,
    initial_stress=True,
    linear_elastic=True,
    stress_scalable=True,
))
