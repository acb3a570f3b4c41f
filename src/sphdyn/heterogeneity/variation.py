r"""Random variation of a material parameter: strength scatter within a phase.

Thesis sec. 7.2: "It could be that CSCM is used as a base material, yet in
the ITZ domain the unconfined or uniaxial compressive strength (UCS) or
density varies. The approach of the strength variation within the ITZ
domain was used in UCS simulations on cylindrical concrete specimens"
(Fig. 7.3). The parameter :math:`p` of a material (e.g. the CSCM ``fc``, from
which every other CSCM parameter is refitted) is multiplied by a random
factor :math:`f` of mean 1 and coefficient of variation :math:`v`:

* ``lognormal``: :math:`\ln f \sim N(-s^2/2, s^2)`, :math:`s^2 = \ln(1 + v^2)`;
* ``normal``: :math:`f \sim N(1, v^2)`, kept above :data:`FACTOR_FLOOR`.

Both are written as :math:`f = F^{-1}(\Phi(z))` of a standard normal
:math:`z` (:func:`factor_of`), which is drawn

* once per run (``scope = "sample"``): every particle of the material has the
  same factor, the samples of an ensemble differ;
* per particle (``scope = "particle"``), independent (``correlation_length =
  0``, like LS-DYNA's *DEFINE_STOCHASTIC_VARIATION) or as a Gaussian random
  field with correlation :math:`\rho(r) = \exp(-(r/\ell)^2)`
  (:func:`standard_normal_field`): white noise on a voxel grid of spacing
  :math:`\ell/4` convolved with a Gaussian of standard deviation
  :math:`\ell/2` (whose self-convolution has variance :math:`\ell^2/2`, i.e.
  :math:`\exp(-r^2/\ell^2)`), divided by the exact standard deviation
  :math:`(\sum_k w_k^2)^{1/2}` of the filtered noise, so :math:`z \sim N(0,
  1)` at every point. A correlated field lets the mean strength of a
  specimen vary from sample to sample, which independent particle values
  average out (:math:`v/\sqrt N`).

Per-particle factors are quantised to ``classes`` equal-probability classes
(:func:`quantise`): class :math:`k` holds the :math:`z` in
:math:`[\Phi^{-1}(k/K), \Phi^{-1}((k+1)/K))` and takes the factor at the
middle probability :math:`(k + 1/2)/K`; each class becomes one material
group with its own parameter fit, so the constitutive kernels need no
per-particle parameters.

Draws are reproducible from the run seed and the material index
(:func:`variation_rng`).
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage, stats

__all__ = ["FACTOR_FLOOR", "factor_of", "quantise", "standard_normal_field",
           "variation_rng"]

#: Smallest factor of the ``normal`` law (a parameter never reaches zero).
FACTOR_FLOOR = 0.05

#: Entropy word separating variation streams from the other random streams.
_VARIATION_STREAM = 0x76617279  # "vary"


def variation_rng(seed: int, material_index: int) -> np.random.Generator:
    """Generator of material ``material_index``'s variation for run ``seed``."""
    return np.random.default_rng(np.random.SeedSequence(
        [int(seed), int(material_index), _VARIATION_STREAM]))


def factor_of(z, cov: float, distribution: str = "lognormal") -> np.ndarray:
    r"""Factor of mean 1 and coefficient of variation ``cov`` from normal ``z``.

    ``lognormal``: :math:`f = \exp(s z - s^2/2)`, :math:`s^2 = \ln(1+v^2)`
    (mean 1, CoV v exactly); ``normal``: :math:`f = \max(1 + v z,`
    :data:`FACTOR_FLOOR`:math:`)`. ``z`` is any array of standard normal
    values; returns an array of its shape (dimensionless).
    """
    z = np.asarray(z, dtype=float)
    if distribution == "lognormal":
        s = np.sqrt(np.log1p(cov * cov))
        return np.exp(s * z - 0.5 * s * s)
    if distribution == "normal":
        return np.maximum(1.0 + cov * z, FACTOR_FLOOR)
    raise ValueError(f"unknown distribution {distribution!r}; use lognormal or normal")


def quantise(z: np.ndarray, classes: int) -> tuple[np.ndarray, np.ndarray]:
    r"""Equal-probability classes of standard normal values ``z`` (N,).

    Returns the class of each value (N,) int and the class-middle normal
    values :math:`\Phi^{-1}((k + 1/2)/K)` (K,), k = 0..K-1.
    """
    edges = stats.norm.ppf(np.arange(1, classes) / classes)
    mids = stats.norm.ppf((np.arange(classes) + 0.5) / classes)
    return np.searchsorted(edges, z, side="right"), mids


def standard_normal_field(x: np.ndarray, correlation_length: float,
                          rng: np.random.Generator) -> np.ndarray:
    r"""Standard normal values at points ``x`` (N, 3) [m], correlated over ``ell``.

    ``correlation_length`` :math:`\ell` [m]: correlation
    :math:`\exp(-(r/\ell)^2)` at distance r; 0 gives independent values.
    The field lives on a voxel grid of spacing :math:`\ell/4` (coarser if
    the grid would exceed 2e7 voxels) over the points' bounding box plus
    :math:`2\ell` (an axis on which all points lie in one plane, e.g. z of a
    2D body, gets a single voxel), periodic (``mode="wrap"``) so that every
    voxel sums a full kernel of independent noise; points take their
    voxel's value. Returns (N,) float.
    """
    x = np.asarray(x, dtype=float)
    n = x.shape[0]
    if correlation_length <= 0.0:
        return rng.standard_normal(n)
    flat = np.ptp(x, axis=0) <= 0.0   # the z column of a 2D body: no axis there
    lo = np.where(flat, x.min(axis=0), x.min(axis=0) - 2.0 * correlation_length)
    extent = np.where(flat, 0.0, np.ptp(x, axis=0) + 4.0 * correlation_length)
    active = max(int((~flat).sum()), 1)
    spacing = max(correlation_length / 4.0,
                  (np.prod(extent[~flat]) / 2e7) ** (1.0 / active))
    shape = tuple(1 if f else int(np.ceil(e / spacing)) + 1 for f, e in zip(flat, extent))
    sigma = [0.0 if f else 0.5 * correlation_length / spacing for f in flat]
    field = ndimage.gaussian_filter(rng.standard_normal(shape), sigma, mode="wrap")
    # exact standard deviation of the filtered unit noise: the filter's
    # weights are its response to a unit impulse (truncated at 4 sigma)
    delta = np.zeros(tuple(1 if f else 2 * int(4 * s + 0.5) + 1 for f, s in zip(flat, sigma)))
    delta[tuple(d // 2 for d in delta.shape)] = 1.0
    weights = ndimage.gaussian_filter(delta, sigma, mode="constant")
    field /= np.sqrt(np.sum(weights * weights))
    ijk = np.rint((x - lo) / spacing).astype(np.int64)
    return field[tuple(ijk.T)]
