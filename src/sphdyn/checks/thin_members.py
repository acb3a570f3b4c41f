r"""Members too thin for their SPH formulation: the stiffness error against particles across.

An SPH member with few particles across is too soft, most of all in bending:
the surface rows, which carry the bending stress, miss the kernel support
outside the body (docs/tensile-instability.md, "Bending and free surfaces").
``studies/formulation_bending.py`` measured it (CSV
``docs/figures/formulation_bending.csv``) at n = 6 and 12 particles across a
10 mm steel strip in plane strain, for the updated-Lagrangian kernel without
correction (``"UL"``), with ``[sph] correction = true`` (``"UL+corr"``) and
the total-Lagrangian kernel (``"TL"``):

* bending: a cantilever's first frequency f against Timoshenko's
  f_T = 847.53 Hz; stiffness error :math:`e_b = 1 - (f/f_T)^2`;
* axial: a rod's plateau wall stress against :math:`\rho c v`; stiffness
  error :math:`e_a` = its relative deficit.

Between and beyond the two points each error follows the power law through
them,

.. math::
    e(n) = e(6)\,(n/6)^{-p}, \qquad p = \log_2\frac{e(6)}{e(12)},

exact at n = 6 and 12, extrapolated outside (and capped at 100 %). The
number of particles across at which the bending error is 5 % is
:math:`n_5 = 6\,(e_b(6)/0.05)^{1/p_b}`. :func:`thin_member_warnings` applies
it to every body of a deck (``sphdyn check`` and ``sphdyn run`` print them):
n = the body's thickness across its thinnest direction
(:func:`member_extents`) / dx; a member (longest extent at least
:data:`SLENDER` times the thickness) is reported when its bending error
exceeds 5 %, a compact body when its axial error does.
"""

from __future__ import annotations

import math

import numpy as np

from ..geometry.lattice import read_points

#: Timoshenko first frequency of the study's cantilever [Hz]
#: (``timoshenko_f1()`` of studies/formulation_bending.py).
F_TIMOSHENKO = 847.528
#: the two resolutions of the study (particles across the thickness)
N_MEASURED = (6.0, 12.0)
#: measured first frequency [Hz] of the cantilever at N_MEASURED
FREQUENCY = {"UL": (695.1, 758.5), "UL+corr": (751.2, 816.0), "TL": (818.1, 837.1)}
#: measured plateau-stress error [%] of the rod at N_MEASURED (the CSV's error_pct)
PLATEAU_ERROR_PCT = {"UL": (-7.352, -4.443), "UL+corr": (-0.191, -0.08839),
                     "TL": (-0.1373, -0.09726)}
#: the bending-stiffness error above which a member is reported
LIMIT = 0.05
#: a body is a member (it can bend) when its longest extent is at least this
#: many times its thickness; a more compact one is judged by the axial error
SLENDER = 3.0
#: what the formulations are called in messages
KIND_TEXT = {"UL": "the updated-Lagrangian kernel without correction",
             "UL+corr": "the updated-Lagrangian kernel with correction",
             "TL": "the total-Lagrangian kernel"}


def measured_errors(kind: str) -> dict[str, tuple[float, float]]:
    """The measured stiffness errors (fractions) of formulation ``kind``
    (``"UL"``, ``"UL+corr"``, ``"TL"``) at 6 and 12 particles across:
    ``{"bending": (e6, e12), "axial": (e6, e12)}``."""
    bending = tuple(1.0 - (f / F_TIMOSHENKO) ** 2 for f in FREQUENCY[kind])
    axial = tuple(-e / 100.0 for e in PLATEAU_ERROR_PCT[kind])
    return {"bending": bending, "axial": axial}


def convergence_rate(e6: float, e12: float) -> float:
    """p of :math:`e \\propto n^{-p}` through the errors at 6 and 12 across."""
    return math.log(e6 / e12) / math.log(N_MEASURED[1] / N_MEASURED[0])


def stiffness_error(kind: str, n_across: float, mode: str = "bending") -> float:
    """Expected stiffness error (fraction, positive = too soft) of a member
    ``n_across`` particles across, formulation ``kind`` (``"UL"``,
    ``"UL+corr"``, ``"TL"``), ``mode`` ``"bending"`` or ``"axial"``:
    :math:`e(n) = e(6) (n/6)^{-p}` through the measured points (module
    docstring), at most 1."""
    e6, e12 = measured_errors(kind)[mode]
    p = convergence_rate(e6, e12)
    return min(1.0, e6 * (n_across / N_MEASURED[0]) ** (-p))


def across_for(kind: str, error: float = LIMIT, mode: str = "bending") -> float:
    """Particles across at which the ``mode`` stiffness error of ``kind`` is
    ``error``: :math:`n = 6 (e(6)/error)^{1/p}` (extrapolated outside 6-12)."""
    e6, e12 = measured_errors(kind)[mode]
    return N_MEASURED[0] * (e6 / error) ** (1.0 / convergence_rate(e6, e12))


def _polygon_thickness(points) -> float:
    """Smallest wall thickness of a simple polygon [m]: over its edges, the
    distance from the edge's midpoint along the inward normal to where the
    polygon is left (a rectangle: its smaller side; an L: its legs' widths)."""
    p = np.asarray(points, dtype=float)
    q = np.roll(p, -1, axis=0)
    e = q - p
    signed = 0.5 * np.sum(p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1])
    inward = np.stack([-e[:, 1], e[:, 0]], axis=1) * np.sign(signed)
    inward /= np.linalg.norm(inward, axis=1)[:, None]
    mid = 0.5 * (p + q)
    best = math.inf
    for i in range(len(p)):
        # ray mid + t d against every other edge p_j + s e_j, 0 <= s <= 1
        d = inward[i]
        den = d[0] * e[:, 1] - d[1] * e[:, 0]
        w = p - mid[i]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (w[:, 0] * e[:, 1] - w[:, 1] * e[:, 0]) / den
            s = (w[:, 0] * d[1] - w[:, 1] * d[0]) / den
        hit = (np.arange(len(p)) != i) & (den != 0) & (t > 0) & (s >= 0) & (s <= 1)
        if hit.any():
            best = min(best, float(t[hit].min()))
    return best


def member_extents(geometry, dim: int, dx: float = 0.0) -> tuple[float, float]:
    """(thickness, longest extent) [m] of a body geometry.

    The thickness is taken across its thinnest direction: box: its smallest
    side in the run's ``dim`` dimensions; points: the same of the particles'
    bounding box, each particle ``dx`` wide; sphere: its diameter; ogive: its
    shank's diameter (its length the longest extent); cylinder:
    its diameter (and its length in 3D, the smaller); ring: its wall, outer
    - inner radius (the diameter if inner = 0; and the length in 3D); prism:
    the polygon's smallest wall thickness (:func:`_polygon_thickness`; and
    the length in 3D). The longest extent is the largest side of its
    bounding box (a ring's outer diameter).
    """
    g = geometry
    if g.shape in ("box", "points"):
        if g.shape == "box":
            lo, hi = g.lo, g.hi
        else:  # the particles' bounding box, each particle dx wide
            x = read_points(g.file, dim, g.length_unit)
            lo, hi = x.min(axis=0) - 0.5 * dx, x.max(axis=0) + 0.5 * dx
        sides = [h - l for l, h in zip(lo[:dim], hi[:dim])]
        return float(min(sides)), float(max(sides))
    if g.shape == "sphere":
        return 2.0 * g.radius, 2.0 * g.radius
    if g.shape == "ogive":
        return 2.0 * g.radius, max(2.0 * g.radius, g.length)
    if g.shape == "cylinder":
        across = span = 2.0 * g.radius
    elif g.shape == "ring":
        span = 2.0 * g.outer_radius
        across = g.outer_radius - g.inner_radius if g.inner_radius > 0 else span
    else:
        p = np.asarray(g.points, dtype=float)
        across, span = _polygon_thickness(p), float(np.max(p.max(axis=0) - p.min(axis=0)))
    if dim == 3:
        return min(across, g.length), max(span, g.length)
    return across, span


def _kind(formulation: str, correction: bool) -> str:
    if formulation == "total_lagrangian":
        return "TL"
    return "UL+corr" if correction else "UL"


def _converted_members(model, dim: int):
    """(name, thickness, longest, size) of each [mesh.convert]: the extents of
    the whole mesh's bounding box (remaining nodes and converted elements) and
    the converted elements' median size V^(1/d)."""
    for mm in model.meshes:
        c = mm.converted
        if c is None or len(c.vol) == 0:
            continue
        size = float(np.median(c.vol ** (1.0 / dim)))
        lo = np.min(c.x[:, :dim], axis=0) - 0.5 * size
        hi = np.max(c.x[:, :dim], axis=0) + 0.5 * size
        if len(mm.points):
            lo = np.minimum(lo, mm.points[:, :dim].min(axis=0))
            hi = np.maximum(hi, mm.points[:, :dim].max(axis=0))
        yield mm.name, float(np.min(hi - lo)), float(np.max(hi - lo)), size


def _mm(x: float) -> str:
    return f"{x * 1e3:.3g} mm"


def _pct(e: float) -> str:
    return f"{100 * e:.2g}" if e < 0.1 else f"{100 * e:.0f}"


def thin_member_warning(name: str, thickness: float, longest: float, dx: float,
                        kind: str) -> str | None:
    """The warning for a body ``thickness`` [m] thick and ``longest`` [m] long
    at spacing ``dx`` [m] with formulation ``kind``, or None when its error is
    at most 5 %: the bending error for a member (``longest >= SLENDER *
    thickness``), the axial error for a compact body."""
    n = thickness / dx
    mode = "bending" if longest >= SLENDER * thickness else "axial"
    bend, axial = stiffness_error(kind, n), stiffness_error(kind, n, "axial")
    if (bend if mode == "bending" else axial) <= LIMIT:
        return None
    lo, hi = sorted((axial, bend))
    where = ("" if N_MEASURED[0] <= n <= N_MEASURED[1]
             else ", extrapolated" + (" below 6" if n < N_MEASURED[0] else " beyond 12"))

    def finer(k: str) -> str:
        m = math.ceil(across_for(k, LIMIT, mode))
        return f"{m} across (dx <= {_mm(thickness / m)})"

    if mode == "axial":  # only UL without correction gets here (the others: < 0.2 %)
        what = "a compact body, axial error over 5 %"
        fix = (f"[sph] correction = true or formulation = \"total_lagrangian\", or "
               f"{finer(kind)}")
    else:
        what = f"a member (longest extent >= {SLENDER:g} x thickness), bending error over 5 %"
        tl = f"formulation = \"total_lagrangian\" with {finer('TL')} if it does not fracture"
        fix = {"UL": f"{tl}, or [sph] correction = true with {finer('UL+corr')}, or "
                     f"{finer('UL')} as it is",
               "UL+corr": f"{tl}, or {finer('UL+corr')}",
               "TL": finer("TL")}[kind]
    return (f"body '{name}' is {n:.3g} particles across its thinnest direction "
            f"({_mm(thickness)} / dx {_mm(dx)}): with {KIND_TEXT[kind]} it is about "
            f"{_pct(lo)}-{_pct(hi)} % too soft (axial to bending stiffness{where}; "
            f"{what}; docs/tensile-instability.md), where it stretches or bends "
            f"across that thickness. Fix (5 % or less): {fix}")


def thin_member_warnings(deck, model=None) -> list[str]:
    """Warnings (:func:`thin_member_warning`) for the deck's bodies and, given
    the built ``model``, its [mesh.convert] particles (thickness: the mesh's
    smallest extent, spacing: the elements' size). None in 1D (no free
    lateral surfaces, no bending), none for bodies of a fluid (gas,
    explosive)."""
    from ..materials.registry import get_model

    dim = deck.run.dimension
    if dim == 1:
        return []
    sph = deck.sph
    fluid = {m.name for m in deck.material if get_model(m.model).fluid}
    out = []
    for b in deck.body:
        if b.material in fluid:  # a gas or an explosive has no stiffness to lose
            continue
        kind = _kind(b.formulation or sph.formulation, sph.correction)
        out.append(thin_member_warning(b.name, *member_extents(b.geometry, dim, b.dx), b.dx, kind))
    if model is not None:
        kind = _kind(sph.formulation, sph.correction)
        for name, thickness, longest, size in _converted_members(model, dim):
            out.append(thin_member_warning(name, thickness, longest, size, kind))
    return [w for w in out if w is not None]
