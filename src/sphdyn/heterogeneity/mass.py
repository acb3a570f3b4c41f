r"""Random particle-mass fields: the paper's numerical heterogeneity.

Hušek, Hokeš, Kala & Král (2017), "Inclusion of Randomness into SPH
Simulations", sec. 4 and Fig. 4: the particles of a body stay on the lattice
of the homogeneous body with its smoothing length and its density
:math:`\rho`; only the masses :math:`m_j` in the particle approximation

.. math:: f(\mathbf x_i) \approx \sum_j \frac{m_j}{\rho_j} f(\mathbf x_j)
          W(\mathbf x_i - \mathbf x_j, h)        \qquad \text{(paper eq. 6)}

vary, so the quadrature weight (the particle volume :math:`V_j = m_j /
\rho_j`, paper eq. 4) is enlarged or reduced. The total mass of the body is
kept (paper sec. 4.1): with :math:`N` particles of homogeneous mass
:math:`m_0 = \rho\,\Delta x^d` and factors :math:`f_j \ge 0` drawn from a
distribution,

.. math:: m_j = m_0\, f_j\, \frac{N}{\sum_k f_k},
          \qquad \sum_j m_j = N m_0 \ \text{(to round-off)}.

The factors are dimensionless multiples of :math:`m_0` (so one deck works in
2D, masses per unit depth, and 3D); the rescaling factor :math:`s = N /
\sum_k f_k` is 1 + O(N^{-1/2}) when the distribution has mean 1, and exactly
1 when every factor is 1 (the homogeneous limit is bitwise the deterministic
body). Laws (``distribution``):

* ``uniform``: :math:`f \sim U[a, b]` (the paper's choice, with masses
  down to almost zero: a = 0, b = 2);
* ``normal``: :math:`f \sim N(\mu, \sigma^2)` truncated at zero (the density
  renormalised on :math:`f \ge 0`);
* ``lognormal``: :math:`\ln f \sim N(-\sigma^2/2, \sigma^2)` (mean 1);
* ``poisson``: :math:`f = k/\lambda`, :math:`k \sim \mathrm{Poisson}(\lambda)`
  (discrete; zero counts give zero-mass particles, "pores");
* ``histogram``: piecewise-constant density given by bin ``edges`` and
  ``weights`` (uniform within a bin).

Draws are reproducible: :func:`body_rng` derives the generator from the
run seed and the body index with :class:`numpy.random.SeedSequence`.
"""

from __future__ import annotations

import numpy as np

__all__ = ["MASS_LAWS", "HistogramLaw", "body_rng", "distribution", "draw_factors", "mass_field"]

MASS_LAWS = ("uniform", "normal", "lognormal", "poisson", "histogram")

#: Entropy word separating mass-field streams from other random streams of a run.
_MASS_STREAM = 0x6D617373  # "mass"


def body_rng(seed: int, body_index: int) -> np.random.Generator:
    """Generator of the mass field of body ``body_index`` for run seed ``seed``.

    Independent streams per body and per purpose (``SeedSequence`` of the
    entropy ``[seed, body_index, "mass"]``), identical on every platform.
    """
    return np.random.default_rng(np.random.SeedSequence([int(seed), int(body_index),
                                                         _MASS_STREAM]))


class HistogramLaw:
    """Piecewise-constant density on ``edges`` (M+1,) with bin ``weights`` (M,).

    Offers the methods of a frozen ``scipy.stats`` law used here: :meth:`cdf`,
    :meth:`mean`, :meth:`std` and :meth:`rvs` (inverse-CDF sampling, uniform
    within a bin).
    """

    def __init__(self, edges, weights):
        self.edges = np.asarray(edges, float)
        self.p = np.asarray(weights, float) / np.sum(weights)
        self.cum = np.concatenate(([0.0], np.cumsum(self.p)))

    def cdf(self, x):
        """F(x), piecewise linear between the edges."""
        x = np.asarray(x, float)
        k = np.clip(np.searchsorted(self.edges, x, side="right") - 1, 0, len(self.p) - 1)
        frac = np.clip((x - self.edges[k]) / (self.edges[k + 1] - self.edges[k]), 0, 1)
        return self.cum[k] + self.p[k] * frac

    def ppf(self, q):
        """Inverse of :meth:`cdf` (bins of zero weight are never returned)."""
        q = np.asarray(q, float)
        k = np.clip(np.searchsorted(self.cum, q, side="right") - 1, 0, len(self.p) - 1)
        pk = self.p[k]
        frac = np.where(pk > 0, (q - self.cum[k]) / np.where(pk > 0, pk, 1.0), 0.0)
        return self.edges[k] + (self.edges[k + 1] - self.edges[k]) * np.clip(frac, 0, 1)

    def mean(self):
        """Mean of the law."""
        a, b = self.edges[:-1], self.edges[1:]
        return float(np.sum(self.p * 0.5 * (a + b)))

    def std(self):
        """Standard deviation of the law."""
        a, b = self.edges[:-1], self.edges[1:]
        second = np.sum(self.p * (a * a + a * b + b * b) / 3.0)
        return float(np.sqrt(second - self.mean() ** 2))

    def rvs(self, size, random_state):
        """``size`` draws using the generator ``random_state``."""
        return self.ppf(random_state.random(size))


def distribution(spec: dict):
    """The law of the mass factors of ``spec`` as a frozen ``scipy.stats`` object.

    ``spec`` holds ``distribution`` and its parameters (the deck's
    ``[body.mass]`` table as a dict): uniform ``low``, ``high``; normal
    ``mean``, ``std``; lognormal ``sigma``; poisson ``lam``; histogram
    ``edges``, ``weights``. Zero-variance laws (``low == high``, ``std = 0``,
    ``sigma = 0``) are not representable in SciPy and return None: every
    factor is then the mean (see :func:`draw_factors`).
    """
    from scipy import stats

    law = spec["distribution"]
    if law == "uniform":
        lo, hi = spec["low"], spec["high"]
        return None if hi == lo else stats.uniform(loc=lo, scale=hi - lo)
    if law == "normal":
        mu, sd = spec["mean"], spec["std"]
        return None if sd == 0 else stats.truncnorm((0.0 - mu) / sd, np.inf, loc=mu,
                                                      scale=sd)
    if law == "lognormal":
        s = spec["sigma"]
        return None if s == 0 else stats.lognorm(s, scale=np.exp(-0.5 * s * s))
    if law == "poisson":
        return stats.poisson(spec["lam"])
    if law == "histogram":
        return HistogramLaw(spec["edges"], spec["weights"])
    raise ValueError(f"unknown mass distribution {law!r}; use one of {MASS_LAWS}")


def _constant(spec: dict) -> float:
    """The factor of a zero-variance law."""
    return {"uniform": spec.get("low"), "normal": spec.get("mean"),
            "lognormal": 1.0}[spec["distribution"]]


def draw_factors(spec: dict, n: int, rng: np.random.Generator) -> np.ndarray:
    """Draw ``n`` mass factors (N,) >= 0 of the law ``spec`` (before rescaling).

    A Poisson law returns ``k / lam``. Zero-variance laws return their mean
    without consuming random numbers.
    """
    law = distribution(spec)
    if law is None:
        return np.full(n, float(_constant(spec)))
    draws = np.asarray(law.rvs(size=n, random_state=rng), dtype=float)
    if spec["distribution"] == "poisson":
        draws = draws / spec["lam"]
    return draws


def mass_field(m0: float, spec: dict | None, solid: np.ndarray,
               rng: np.random.Generator) -> tuple[np.ndarray, float]:
    r"""Particle masses of one body (paper sec. 4.1, Fig. 4).

    Parameters
    ----------
    m0 : homogeneous particle mass :math:`\rho \Delta x^d` [kg] (kg/m in 2D).
    spec : the ``[body.mass]`` table as a dict, or None (homogeneous body).
    solid : (N,) bool, False for particles of initial cracks (they get zero
        mass and are excluded from the draw and the total).
    rng : generator from :func:`body_rng`.

    Returns
    -------
    m : (N,) masses [kg]; ``m[solid].sum() == solid.sum() * m0`` to round-off.
    scale : the rescaling factor :math:`s = N_s / \sum f` (1 for a homogeneous
        body), so that ``m[solid] / (m0 * scale)`` are the drawn factors.

    Raises
    ------
    ValueError
        If every drawn factor is zero (nothing to rescale).
    """
    solid = np.asarray(solid, bool)
    m = np.zeros(solid.shape[0])
    n = int(solid.sum())
    if spec is None or n == 0:
        m[solid] = m0
        return m, 1.0
    f = draw_factors(spec, n, rng)
    total = float(np.sum(f))
    if not total > 0.0:
        raise ValueError(f"the mass distribution {spec['distribution']!r} drew only "
                         f"zeros for {n} particles. Fix: give [body.mass] parameters "
                         "with a positive mean (docs/heterogeneity.md)")
    scale = n / total
    m[solid] = m0 * f * scale
    return m, scale
