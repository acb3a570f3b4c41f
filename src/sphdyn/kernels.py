"""SPH smoothing kernels.

Every kernel is written as

    W(r, h) = sigma_d / h^d * w(q),    q = r / h,

with ``w`` a dimensionless radial shape function of compact support
``0 <= q < q_max`` and ``sigma_d`` the normalisation constant that makes
``integral W dV = 1`` in ``d`` dimensions.  Kernels are referred to by an
integer id so that the Numba hot loops can dispatch with a plain if-chain:

====  ================  =====  =======================================
 id   name              q_max  w(q)
====  ================  =====  =======================================
 0    cubic_spline      2      (2-q)^3 - 4(1-q)^3 | (2-q)^3
 1    quintic_spline    3      (3-q)^5 - 6(2-q)^5 + 15(1-q)^5
 2    wendland_c2       2      (1-q/2)^4 (2q+1)
 3    wendland_c4       2      (1-q/2)^6 (35/12 q^2 + 3q + 1)
 4    gaussian          3      exp(-q^2), truncated
 5    quadratic         2      3/16 q^2 - 3/4 q + 3/4
====  ================  =====  =======================================

All normalisation constants below were re-derived for exactly these ``w``
(closed-form radial integrals, see ``normalisation``) and are checked by
quadrature in ``tests/test_kernels.py``.  Two published values do not match
the ``w`` written above and are corrected here:

* cubic spline, 2D: ``sigma_2 = 5/(14 pi)``.  The often quoted
  ``15/(14 pi)`` (and ``10/(7 pi)``, ``15/(7 pi)``) belong to other scalings
  of the same M4 spline; with ``w = (2-q)^3 - 4(1-q)^3`` the integral
  ``2 pi int_0^2 w q dq = 14 pi / 5``.
* quintic spline, 3D: ``sigma_3 = 1/(120 pi)``.  The value ``3/(359 pi)``
  printed by Liu & Liu (2003) is off by 0.3 %; ``4 pi int_0^3 w q^2 dq =
  120 pi`` exactly.

The shape functions take ``q >= 0`` (a distance); negative ``q`` is not
supported.

References
----------
Monaghan, J.J., Lattanzio, J.C. (1985). A refined particle method for
    astrophysical problems. Astron. Astrophys. 149, 135-143.
Morris, J.P. (1996). Analysis of smoothed particle hydrodynamics with
    applications. PhD thesis, Monash University.
Liu, G.R., Liu, M.B. (2003). Smoothed Particle Hydrodynamics: a meshfree
    particle method. World Scientific.
Wendland, H. (1995). Piecewise polynomial, positive definite and compactly
    supported radial functions of minimal degree. Adv. Comput. Math. 4,
    389-396.
Dehnen, W., Aly, H. (2012). Improving convergence in smoothed particle
    hydrodynamics simulations without pairing instability. MNRAS 425,
    1068-1082.
Johnson, G.R., Stryk, R.A., Beissel, S.R. (1996). SPH for high velocity
    impact computations. Comput. Methods Appl. Mech. Engrg. 139, 347-373.
Swegle, J.W., Hicks, D.L., Attaway, S.W. (1995). Smoothed particle
    hydrodynamics stability analysis. J. Comput. Phys. 116, 123-134.
Hušek, M. SPH for concrete under impact (PhD thesis), eq. 2.2.2, Fig. 2.4.

The model and its tests: docs/theory.md, "Kernels".
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from numba import njit

__all__ = [
    "KERNEL_IDS",
    "KERNEL_NAMES",
    "kernel_id",
    "support",
    "radius_factor",
    "support_nb",
    "normalisation",
    "w",
    "dwdq",
    "d2wdq2",
    "dwdq_over_q",
    "kernel_value",
    "grad_factor",
    "second_derivative",
]

CUBIC_SPLINE = 0
QUINTIC_SPLINE = 1
WENDLAND_C2 = 2
WENDLAND_C4 = 3
GAUSSIAN = 4
QUADRATIC = 5

KERNEL_NAMES: tuple[str, ...] = (
    "cubic_spline",
    "quintic_spline",
    "wendland_c2",
    "wendland_c4",
    "gaussian",
    "quadratic",
)
KERNEL_IDS: dict[str, int] = {name: i for i, name in enumerate(KERNEL_NAMES)}

_Q_MAX = (2.0, 3.0, 2.0, 2.0, 3.0, 2.0)

_PI = math.pi
_E9 = math.exp(-9.0)
_ERF3 = math.erf(3.0)

# sigma_d for d = 1, 2, 3, indexed [kid][d - 1].  Derivations (S_d = 2, 2 pi,
# 4 pi is the measure of the unit sphere, sigma_d = 1 / (S_d int w q^(d-1) dq)):
#   cubic:    int_0^2 w q^(d-1) dq = 3, 7/5, 1            (Beta integrals)
#   quintic:  sum_k c_k a_k^(d+5) (d-1)! 5!/(d+5)!        = 60, 239/7, 30
#   wendland: substitute s = q/2, integrals are Beta functions B(d+k, 5 or 7)
#   gaussian: int_0^3 exp(-q^2) q^(d-1) dq in closed form (erf)
#   quadratic: elementary polynomial integrals = 1/2, 1/4, 1/5
_SIGMA = (
    (1.0 / 6.0, 5.0 / (14.0 * _PI), 1.0 / (4.0 * _PI)),
    (1.0 / 120.0, 7.0 / (478.0 * _PI), 1.0 / (120.0 * _PI)),
    (3.0 / 4.0, 7.0 / (4.0 * _PI), 21.0 / (16.0 * _PI)),
    (27.0 / 32.0, 9.0 / (4.0 * _PI), 495.0 / (256.0 * _PI)),
    (
        1.0 / (math.sqrt(_PI) * _ERF3),
        1.0 / (_PI * (1.0 - _E9)),
        1.0 / (4.0 * _PI * (math.sqrt(_PI) / 4.0 * _ERF3 - 1.5 * _E9)),
    ),
    (1.0, 2.0 / _PI, 5.0 / (4.0 * _PI)),
)


def kernel_id(name: str) -> int:
    """Integer id of the kernel called ``name``.

    Raises
    ------
    ValueError
        If ``name`` is unknown; the message lists the valid names.
    """
    try:
        return KERNEL_IDS[name]
    except (KeyError, TypeError):
        raise ValueError(
            f"unknown kernel {name!r}; valid names: {', '.join(KERNEL_NAMES)}"
        ) from None


def _check_kid(kid: int) -> int:
    if isinstance(kid, bool) or not 0 <= int(kid) < len(KERNEL_NAMES) or int(kid) != kid:
        raise ValueError(f"unknown kernel id {kid!r}; valid ids: 0..{len(KERNEL_NAMES) - 1}")
    return int(kid)


def support(kid: int) -> float:
    """Support radius ``q_max`` of kernel ``kid`` in units of ``h``.

    ``W(r, h) = 0`` for ``r >= q_max * h``.
    """
    return _Q_MAX[_check_kid(kid)]


def radius_factor(kid: int, support_scale: float) -> float:
    r"""The support radius in units of ``h``: :math:`q_{max}\,\kappa`, the
    kernel's ``q_max`` (:func:`support`) times the paper's :math:`\kappa`
    (``sph.support_scale``; pairs use :math:`h_{ij} = \kappa (h_i + h_j)/2`).
    The one formula of the support radius: the parts' neighbour searches
    (:class:`KernelContext`) and the deck's checks use it."""
    return support(kid) * support_scale


@njit(cache=True, error_model="numpy")
def support_nb(kid):
    """Numba version of :func:`support` (``kid`` int -> ``q_max`` float)."""
    if kid == 0:
        return 2.0
    elif kid == 1:
        return 3.0
    elif kid == 2:
        return 2.0
    elif kid == 3:
        return 2.0
    elif kid == 4:
        return 3.0
    elif kid == 5:
        return 2.0
    return math.nan  # unknown id: rejected in Python by kernel_id(); NaN is caught by the guards


def normalisation(kid: int, dim: int) -> float:
    """Normalisation constant ``sigma_d`` of kernel ``kid`` in ``dim`` dimensions.

    ``sigma_d = 1 / (S_d * int_0^q_max w(q) q^(d-1) dq)`` with ``S_d = 2, 2 pi,
    4 pi`` for ``d = 1, 2, 3``, so that ``integral W(|x|, h) d^d x = 1``.
    See the module docstring for the two corrected literature values.

    Parameters
    ----------
    kid : int
        Kernel id.
    dim : int
        Spatial dimension, 1, 2 or 3.

    Returns
    -------
    float
        ``sigma_d`` (dimensionless).
    """
    kid = _check_kid(kid)
    if dim not in (1, 2, 3) or isinstance(dim, bool):
        raise ValueError(f"dim must be 1, 2 or 3, got {dim!r}")
    return _SIGMA[kid][dim - 1]


@njit(cache=True, error_model="numpy")
def w(kid, q):
    """Unnormalised kernel shape function ``w(q)``, zero for ``q >= q_max``.

    Parameters
    ----------
    kid : int
        Kernel id (see module table for the formulas and references).
    q : float
        ``r / h >= 0`` (dimensionless).

    Returns
    -------
    float
        ``w(q)`` (dimensionless).
    """
    if kid == 0:  # cubic spline, Monaghan & Lattanzio (1985)
        if q < 1.0:
            a = 2.0 - q
            b = 1.0 - q
            return a * a * a - 4.0 * b * b * b
        elif q < 2.0:
            a = 2.0 - q
            return a * a * a
        return 0.0
    elif kid == 1:  # quintic spline, Morris (1996)
        if q >= 3.0:
            return 0.0
        a = 3.0 - q
        s = a * a * a * a * a
        if q < 2.0:
            b = 2.0 - q
            s -= 6.0 * b * b * b * b * b
            if q < 1.0:
                c = 1.0 - q
                s += 15.0 * c * c * c * c * c
        return s
    elif kid == 2:  # Wendland C2, Dehnen & Aly (2012)
        if q < 2.0:
            a = 1.0 - 0.5 * q
            a2 = a * a
            return a2 * a2 * (2.0 * q + 1.0)
        return 0.0
    elif kid == 3:  # Wendland C4, Dehnen & Aly (2012)
        if q < 2.0:
            a = 1.0 - 0.5 * q
            a2 = a * a
            return a2 * a2 * a2 * ((35.0 / 12.0) * q * q + 3.0 * q + 1.0)
        return 0.0
    elif kid == 4:  # truncated Gaussian
        if q < 3.0:
            return math.exp(-q * q)
        return 0.0
    elif kid == 5:  # quadratic, Johnson, Stryk & Beissel (1996)
        if q < 2.0:
            return (3.0 / 16.0) * q * q - 0.75 * q + 0.75
        return 0.0
    return math.nan  # unknown id: rejected in Python by kernel_id(); NaN is caught by the guards


@njit(cache=True, error_model="numpy")
def dwdq(kid, q):
    """First derivative ``dw/dq`` of the shape function, zero for ``q >= q_max``.

    Parameters
    ----------
    kid : int
        Kernel id.
    q : float
        ``r / h >= 0``.

    Returns
    -------
    float
        ``w'(q)`` (dimensionless).  ``w'(0) = 0`` for all kernels except
        ``quadratic`` (``w'(0) = -3/4``, a cusp at the origin).
    """
    if kid == 0:
        if q < 1.0:
            return q * (9.0 * q - 12.0)  # -3(2-q)^2 + 12(1-q)^2 expanded
        elif q < 2.0:
            a = 2.0 - q
            return -3.0 * a * a
        return 0.0
    elif kid == 1:
        if q < 1.0:
            # -5(3-q)^4 + 30(2-q)^4 - 75(1-q)^4 expanded (no cancellation at 0)
            q2 = q * q
            return q * (-120.0 + q2 * (120.0 - 50.0 * q))
        elif q < 2.0:
            a = 3.0 - q
            b = 2.0 - q
            a2 = a * a
            b2 = b * b
            return -5.0 * a2 * a2 + 30.0 * b2 * b2
        elif q < 3.0:
            a = 3.0 - q
            a2 = a * a
            return -5.0 * a2 * a2
        return 0.0
    elif kid == 2:
        if q < 2.0:
            a = 1.0 - 0.5 * q
            return -5.0 * q * a * a * a
        return 0.0
    elif kid == 3:
        if q < 2.0:
            a = 1.0 - 0.5 * q
            a2 = a * a
            return -(14.0 / 3.0) * q * a2 * a2 * a * (1.0 + 2.5 * q)
        return 0.0
    elif kid == 4:
        if q < 3.0:
            return -2.0 * q * math.exp(-q * q)
        return 0.0
    elif kid == 5:
        if q < 2.0:
            return 0.375 * q - 0.75
        return 0.0
    return math.nan  # unknown id: rejected in Python by kernel_id(); NaN is caught by the guards


@njit(cache=True, error_model="numpy")
def d2wdq2(kid, q):
    """Second derivative ``d2w/dq2`` of the shape function, zero for ``q >= q_max``.

    Its sign is the Swegle et al. (1995) tensile-instability criterion: for the
    cubic spline ``w'' = 18q - 12 < 0`` on ``q < 2/3`` and ``> 0`` on
    ``2/3 < q < 2``.

    Parameters
    ----------
    kid : int
        Kernel id.
    q : float
        ``r / h >= 0``.

    Returns
    -------
    float
        ``w''(q)`` (dimensionless).
    """
    if kid == 0:
        if q < 1.0:
            return 18.0 * q - 12.0
        elif q < 2.0:
            return 6.0 * (2.0 - q)
        return 0.0
    elif kid == 1:
        if q >= 3.0:
            return 0.0
        a = 3.0 - q
        s = 20.0 * a * a * a
        if q < 2.0:
            b = 2.0 - q
            s -= 120.0 * b * b * b
            if q < 1.0:
                c = 1.0 - q
                s += 300.0 * c * c * c
        return s
    elif kid == 2:
        if q < 2.0:
            # d/dq [-5 q a^3], a = 1 - q/2
            a = 1.0 - 0.5 * q
            return -5.0 * a * a * (a - 1.5 * q)
        return 0.0
    elif kid == 3:
        if q < 2.0:
            # d/dq [q a^5 (1 + 5q/2)], a = 1 - q/2, by the product rule:
            #   a^5 (1 + 5q/2) - (5/2) q a^4 (1 + 5q/2) + (5/2) q a^5
            #   = a^4 [1 + 2q - 35/4 q^2]
            a = 1.0 - 0.5 * q
            a2 = a * a
            return -(14.0 / 3.0) * a2 * a2 * (1.0 + 2.0 * q - 8.75 * q * q)
        return 0.0
    elif kid == 4:
        if q < 3.0:
            return (4.0 * q * q - 2.0) * math.exp(-q * q)
        return 0.0
    elif kid == 5:
        if q < 2.0:
            return 0.375
        return 0.0
    return math.nan  # unknown id: rejected in Python by kernel_id(); NaN is caught by the guards


@njit(cache=True, error_model="numpy")
def dwdq_over_q(kid, q):
    """``w'(q) / q`` evaluated without cancellation, with its limit at ``q = 0``.

    For the kernels with ``w'(0) = 0`` the limit ``q -> 0`` is ``w''(0)`` and
    the closed forms below reach it smoothly.  The ``quadratic`` kernel has
    ``w'(0) = -3/4``, so ``w'/q -> -inf``: the gradient magnitude stays finite
    (a cone) but its direction is undefined at ``r = 0``.  For it this
    function returns 0 at ``q == 0`` exactly, which yields the correct zero
    self-contribution ``F * (x_i - x_i) = 0`` instead of ``inf * 0 = nan``.

    Parameters
    ----------
    kid : int
        Kernel id.
    q : float
        ``r / h >= 0``.

    Returns
    -------
    float
        ``w'(q) / q``.
    """
    if kid == 0:
        if q < 1.0:
            return 9.0 * q - 12.0
        elif q < 2.0:
            a = 2.0 - q
            return -3.0 * a * a / q
        return 0.0
    elif kid == 1:
        if q < 1.0:
            return -120.0 + q * q * (120.0 - 50.0 * q)
        elif q < 3.0:
            return dwdq(1, q) / q
        return 0.0
    elif kid == 2:
        if q < 2.0:
            a = 1.0 - 0.5 * q
            return -5.0 * a * a * a
        return 0.0
    elif kid == 3:
        if q < 2.0:
            a = 1.0 - 0.5 * q
            a2 = a * a
            return -(14.0 / 3.0) * a2 * a2 * a * (1.0 + 2.5 * q)
        return 0.0
    elif kid == 4:
        if q < 3.0:
            return -2.0 * math.exp(-q * q)
        return 0.0
    elif kid == 5:
        if q == 0.0:
            return 0.0
        elif q < 2.0:
            return 0.375 - 0.75 / q
        return 0.0
    return math.nan  # unknown id: rejected in Python by kernel_id(); NaN is caught by the guards


@njit(cache=True, error_model="numpy")
def kernel_value(kid, sigma, dim, r, h):
    """Kernel value ``W(r, h) = sigma_d / h^d * w(r/h)``.

    Parameters
    ----------
    kid : int
        Kernel id.
    sigma : float
        ``normalisation(kid, dim)``.
    dim : int
        Spatial dimension ``d`` (1, 2 or 3).
    r : float
        Inter-particle distance ``|x_i - x_j|`` [m].
    h : float
        Smoothing length [m].

    Returns
    -------
    float
        ``W`` [1/m^d].
    """
    return sigma / h**dim * w(kid, r / h)


@njit(cache=True, error_model="numpy")
def grad_factor(kid, sigma, dim, r, h):
    """Scalar ``F`` with ``grad_i W(x_i - x_j, h) = F * (x_i - x_j)``.

    ``F = (1/r) dW/dr = sigma_d / h^(d+2) * w'(q) / q``, ``q = r/h``
    (chain rule through ``r = |x_i - x_j|``; Liu & Liu 2003, ch. 3).  It is
    finite at ``r = 0``: ``sigma_d w''(0) / h^(d+2)`` for all kernels except
    ``quadratic``, for which 0 is returned there (see :func:`dwdq_over_q`).

    Parameters
    ----------
    kid : int
        Kernel id.
    sigma : float
        ``normalisation(kid, dim)``.
    dim : int
        Spatial dimension.
    r : float
        Distance ``|x_i - x_j|`` [m].
    h : float
        Smoothing length [m].

    Returns
    -------
    float
        ``F`` [1/m^(d+2)].
    """
    return sigma / h ** (dim + 2) * dwdq_over_q(kid, r / h)


@njit(cache=True, error_model="numpy")
def second_derivative(kid, sigma, dim, r, h):
    """Second radial derivative ``d2W/dr2 = sigma_d / h^(d+2) * w''(r/h)``.

    Used for the Swegle et al. (1995) tensile-instability indicator
    (unstable when ``W'' * sigma_xx > 0``, stress positive in tension).

    Parameters
    ----------
    kid : int
        Kernel id.
    sigma : float
        ``normalisation(kid, dim)``.
    dim : int
        Spatial dimension.
    r : float
        Distance [m].
    h : float
        Smoothing length [m].

    Returns
    -------
    float
        ``d2W/dr2`` [1/m^(d+2)].
    """
    return sigma / h ** (dim + 2) * d2wdq2(kid, r / h)


@dataclass(frozen=True)
class KernelContext:
    r"""The smoothing kernel of a part, passed as one thing.

    ``kid`` the kernel id, ``sigma`` its normalisation :math:`\sigma_d` in
    ``dim`` dimensions (:func:`normalisation`) and ``support_scale`` the
    paper's :math:`\kappa` (deck key ``sph.support_scale``): pair quantities
    use :math:`h_{ij} = \kappa (h_i + h_j)/2`, so the support radius is
    ``radius_factor * h`` with ``radius_factor`` :math:`= q_{max} \kappa`.
    Python code passes the context; the Numba passes take its fields as
    scalars (thin wrappers unpack it).
    """

    kid: int
    dim: int
    support_scale: float
    sigma: float = field(init=False)
    radius_factor: float = field(init=False)

    def __post_init__(self):
        object.__setattr__(self, "sigma", normalisation(self.kid, self.dim))
        object.__setattr__(self, "radius_factor", radius_factor(self.kid, self.support_scale))

    @classmethod
    def named(cls, name: str, dim: int, support_scale: float) -> "KernelContext":
        """The context of the kernel called ``name`` (see :data:`KERNEL_IDS`)."""
        return cls(kernel_id(name), dim, float(support_scale))
