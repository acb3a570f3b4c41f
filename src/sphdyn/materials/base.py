"""Material-model interface, registry and shared Numba helpers.

A material model is

* a *point function* (the constitutive update of one material point, in the
  model's own module), and
* a *group kernel* ``update(idx, L, dt, rho, sig, e, c, damage, hist, params)``
  with the same signature for every model (see :data:`KERNEL_SIGNATURE_DOC`),

bundled with its parameter packing and deck table in a
:class:`~sphdyn.materials.registry.MaterialModel` and registered by name
(:mod:`sphdyn.materials.registry`; the names are re-exported here).

Parameter vectors
-----------------
``MaterialModel.pack`` turns a dict of SI values into a float64 vector. Every
model's vector starts with the common block ``[density, K, G]`` (indices
:data:`P_DENSITY`, :data:`P_K`, :data:`P_G`), so bulk/shear modulus and wave
speed are model independent; model-specific entries follow.

Symmetric tensors in kernels
----------------------------
Inside the kernels symmetric 3x3 tensors are carried as 6-tuples of scalars
``(xx, yy, zz, xy, yz, xz)`` with *tensor* (not engineering) shear
components. Tuples live in registers, so the per-particle loop allocates
nothing. The spin tensor is carried as ``(w_xy, w_yz, w_xz)`` with
``W = (L - L^T)/2``.

The model and its tests: docs/theory.md, "Materials".
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .registry import (N_COMMON, P_DENSITY, P_G, P_K, REGISTRY,  # noqa: F401
                       MaterialGroup, MaterialModel, available_models, get_model, register)

KERNEL_SIGNATURE_DOC = """\
update(idx, L, dt, rho, sig, e, c, damage, hist, params, size) -> None

idx    : int64[:]            particles to update (unique indices)
L      : float64[:, :, :]    (N, 3, 3) velocity gradient dv_a/dx_b [1/s]
dt     : float               time step [s]
rho    : float64[:]          (N,) current density [kg/m^3]
sig    : float64[:, :, :]    (N, 3, 3) Cauchy stress [Pa], in/out
e      : float64[:]          (N,) specific internal energy [J/kg], in/out
c      : float64[:]          (N,) wave speed sqrt((K + 4G/3)/rho) [m/s], out
damage : float64[:]          (N,) scalar damage, in/out
hist   : float64[:, :]       (N, nh) history variables, in/out
params : float64[:]          packed parameters (``MaterialModel.pack``)
size   : float64[:]          (N,) particle size V0^(1/dim) [m] (fracture-energy
                             regularisation; unused by elastic and j2)
"""


# --------------------------------------------------------------------------
# Parameter parsing helpers (pure Python, used by ``pack`` functions)
# --------------------------------------------------------------------------


def get_float(values: dict, key: str, *, default: float | None = None,
              min_value: float | None = None, min_inclusive: bool = True,
              max_value: float | None = None, max_inclusive: bool = True) -> float:
    """Read ``values[key]`` as a finite float within bounds.

    Raises
    ------
    ValueError
        Naming ``key`` if it is missing (and no default), not a finite real
        number, or out of range.
    """
    if key not in values or values[key] is None:
        if default is None:
            raise ValueError(f"missing material parameter {key!r}")
        return float(default)
    raw = values[key]
    if isinstance(raw, bool):
        raise ValueError(f"material parameter {key!r} must be a number, got {raw!r}")
    try:
        x = float(raw)
    except (TypeError, ValueError):
        raise ValueError(f"material parameter {key!r} must be a number, got {raw!r}") from None
    if not math.isfinite(x):
        raise ValueError(f"material parameter {key!r} must be finite, got {x}")
    if min_value is not None and (x < min_value or (x == min_value and not min_inclusive)):
        op = ">=" if min_inclusive else ">"
        raise ValueError(f"material parameter {key!r} must be {op} {min_value}, got {x}")
    if max_value is not None and (x > max_value or (x == max_value and not max_inclusive)):
        op = "<=" if max_inclusive else "<"
        raise ValueError(f"material parameter {key!r} must be {op} {max_value}, got {x}")
    return x


def elastic_constants(values: dict) -> tuple[float, float]:
    """Bulk and shear modulus ``(K, G)`` [Pa] from ``(E, nu)`` or ``(K, G)``.

    ``K = E / (3 (1 - 2 nu))``, ``G = E / (2 (1 + nu))`` for isotropic
    linear elasticity (e.g. Timoshenko & Goodier, Theory of Elasticity).
    Exactly one of the two pairs must be given.
    """
    has_e = "E" in values or "nu" in values
    has_k = "K" in values or "G" in values
    if has_e and has_k:
        raise ValueError("give either ('E', 'nu') or ('K', 'G'), not both")
    if has_k:
        K = get_float(values, "K", min_value=0.0, min_inclusive=False)
        G = get_float(values, "G", min_value=0.0, min_inclusive=False)
        return K, G
    E = get_float(values, "E", min_value=0.0, min_inclusive=False)
    nu = get_float(values, "nu", min_value=-1.0, min_inclusive=False,
                   max_value=0.5, max_inclusive=False)
    return E / (3.0 * (1.0 - 2.0 * nu)), E / (2.0 * (1.0 + nu))


def pack_common(values: dict) -> list[float]:
    """The common block ``[density, K, G]`` of every parameter vector."""
    rho = get_float(values, "density", min_value=0.0, min_inclusive=False)
    K, G = elastic_constants(values)
    return [rho, K, G]


# --------------------------------------------------------------------------
# Shared Numba helpers on symmetric 6-tuples
# --------------------------------------------------------------------------


@njit(cache=True, error_model="numpy")
def to_sym6(a):
    """Symmetric part of a 3x3 array as ``(xx, yy, zz, xy, yz, xz)``."""
    return (a[0, 0], a[1, 1], a[2, 2],
            0.5 * (a[0, 1] + a[1, 0]),
            0.5 * (a[1, 2] + a[2, 1]),
            0.5 * (a[0, 2] + a[2, 0]))


@njit(cache=True, error_model="numpy")
def to_mat33(s):
    """New 3x3 array from a symmetric 6-tuple (allocates; not for hot loops)."""
    a = np.empty((3, 3))
    a[0, 0] = s[0]
    a[1, 1] = s[1]
    a[2, 2] = s[2]
    a[0, 1] = a[1, 0] = s[3]
    a[1, 2] = a[2, 1] = s[4]
    a[0, 2] = a[2, 0] = s[5]
    return a


@njit(cache=True, error_model="numpy")
def load_sym6(t, i):
    """Row ``i`` of a symmetric ``(N, 3, 3)`` field as a 6-tuple (upper triangle)."""
    return (t[i, 0, 0], t[i, 1, 1], t[i, 2, 2], t[i, 0, 1], t[i, 1, 2], t[i, 0, 2])


@njit(cache=True, error_model="numpy")
def store_sym6(t, i, s):
    """Write a 6-tuple into row ``i`` of an ``(N, 3, 3)`` field (both triangles)."""
    t[i, 0, 0] = s[0]
    t[i, 1, 1] = s[1]
    t[i, 2, 2] = s[2]
    t[i, 0, 1] = s[3]
    t[i, 1, 0] = s[3]
    t[i, 1, 2] = s[4]
    t[i, 2, 1] = s[4]
    t[i, 0, 2] = s[5]
    t[i, 2, 0] = s[5]


@njit(cache=True, error_model="numpy")
def rate_split(L, i):
    """Rate of deformation and spin of particle ``i``.

    ``D = (L + L^T)/2`` as a 6-tuple and ``W = (L - L^T)/2`` as
    ``(w_xy, w_yz, w_xz)``, with ``L[i, a, b] = dv_a/dx_b`` [1/s].
    """
    d = (L[i, 0, 0], L[i, 1, 1], L[i, 2, 2],
         0.5 * (L[i, 0, 1] + L[i, 1, 0]),
         0.5 * (L[i, 1, 2] + L[i, 2, 1]),
         0.5 * (L[i, 0, 2] + L[i, 2, 0]))
    w = (0.5 * (L[i, 0, 1] - L[i, 1, 0]),
         0.5 * (L[i, 1, 2] - L[i, 2, 1]),
         0.5 * (L[i, 0, 2] - L[i, 2, 0]))
    return d, w


@njit(cache=True, error_model="numpy")
def scale6(s, f):
    """``f * s`` for a 6-tuple."""
    return (f * s[0], f * s[1], f * s[2], f * s[3], f * s[4], f * s[5])


@njit(cache=True, error_model="numpy")
def trace6(s):
    """Trace ``s_kk`` of a symmetric 6-tuple."""
    return s[0] + s[1] + s[2]


@njit(cache=True, error_model="numpy")
def isotropic6(m):
    """The 6-tuple ``m I`` (an isotropic tensor; a fluid's stress is
    ``isotropic6(-p)``)."""
    return (m, m, m, 0.0, 0.0, 0.0)


@njit(cache=True, error_model="numpy")
def ddot6(a, b):
    """Double contraction ``a : b = a_ij b_ij`` of two symmetric 6-tuples."""
    return (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
            + 2.0 * (a[3] * b[3] + a[4] * b[4] + a[5] * b[5]))


@njit(cache=True, error_model="numpy")
def jaumann_rotate(s, w, dt):
    """Objective (Jaumann) rotation of a symmetric tensor over one step.

    .. math:: \\sigma \\leftarrow \\sigma + \\Delta t\\,(W\\sigma - \\sigma W),
              \\qquad W = (L - L^T)/2

    Forward-Euler integration of the Jaumann rate with the material rate set
    to zero (Belytschko, Liu & Moran, *Nonlinear Finite Elements for Continua
    and Structures*, Wiley 2000, Sec. 5.4). The trace is preserved exactly,
    the second invariant to O(dt^2) per step.

    Parameters
    ----------
    s : 6-tuple
        Stress ``(xx, yy, zz, xy, yz, xz)`` [Pa].
    w : 3-tuple
        Spin ``(w_xy, w_yz, w_xz)`` [1/s].
    dt : float
        Time step [s].

    Returns
    -------
    6-tuple, rotated stress [Pa].
    """
    sxx, syy, szz, sxy, syz, sxz = s
    w01, w12, w02 = w
    # A = W sigma; W sigma - sigma W = A + A^T since W is skew.
    a00 = w01 * sxy + w02 * sxz
    a11 = -w01 * sxy + w12 * syz
    a22 = -w02 * sxz - w12 * syz
    a01 = w01 * syy + w02 * syz
    a10 = -w01 * sxx + w12 * sxz
    a12 = -w01 * sxz + w12 * szz
    a21 = -w02 * sxy - w12 * syy
    a02 = w01 * syz + w02 * szz
    a20 = -w02 * sxx - w12 * sxy
    return (sxx + dt * 2.0 * a00,
            syy + dt * 2.0 * a11,
            szz + dt * 2.0 * a22,
            sxy + dt * (a01 + a10),
            syz + dt * (a12 + a21),
            sxz + dt * (a02 + a20))


@njit(cache=True, error_model="numpy")
def deviatoric_split(s):
    """Split ``s = dev + m I`` with ``m = tr(s)/3``.

    Returns
    -------
    dev : 6-tuple
        Deviatoric part.
    m : float
        Mean value (for stress: mean stress, ``-p``).
    """
    m = (s[0] + s[1] + s[2]) / 3.0
    return (s[0] - m, s[1] - m, s[2] - m, s[3], s[4], s[5]), m


@njit(cache=True, error_model="numpy")
def von_mises(s):
    """Von Mises equivalent stress ``q = sqrt(3 J2) = sqrt(3/2 dev:dev)`` [Pa].

    Simo & Hughes, *Computational Inelasticity*, Springer 1998, Sec. 2.3.
    """
    dev, m = deviatoric_split(s)
    return math.sqrt(1.5 * ddot6(dev, dev))


@njit(cache=True, error_model="numpy")
def energy_increment(s_old, s_new, d, dt, rho):
    """Specific internal energy increment of one step [J/kg].

    .. math:: \\Delta e = \\frac{\\Delta t}{2\\rho}
              (\\sigma^{n} + \\sigma^{n+1}) : D

    (trapezoidal rule on the stress power ``sigma : D / rho``; e.g.
    Belytschko, Liu & Moran 2000, Sec. 4.6 / explicit energy balance).
    Returns 0 for ``rho <= 0`` (void / zero-mass particles).

    Parameters
    ----------
    s_old, s_new : 6-tuple
        Stress at the start (after rotation) and end of the step [Pa].
    d : 6-tuple
        Rate of deformation [1/s].
    dt : float
        Time step [s].
    rho : float
        Density [kg/m^3].
    """
    if rho <= 0.0:
        return 0.0
    return 0.5 * dt * (ddot6(s_old, d) + ddot6(s_new, d)) / rho


@njit(cache=True, error_model="numpy")
def p_wave_speed(K, G, rho):
    """``sqrt((K + 4G/3)/rho)`` [m/s]; 0 for ``rho <= 0``."""
    if rho <= 0.0:
        return 0.0
    return math.sqrt((K + 4.0 * G / 3.0) / rho)


@njit(cache=True, error_model="numpy")
def young_modulus(K, G):
    """Young's modulus of isotropic elasticity, :math:`E = 9KG/(3K + G)` [Pa],
    from the bulk and shear moduli ``K``, ``G`` [Pa] (scalars or arrays of one
    shape)."""
    return 9.0 * K * G / (3.0 * K + G)
