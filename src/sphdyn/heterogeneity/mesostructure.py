"""Concrete mesostructure (aggregate, mortar, ITZ) from coherent noise.

The thesis (chapter 7.2, Fig. 7.2) generates regions of aggregate, mortar
matrix and interfacial transition zone (ITZ) with coherent noise functions
and gives SPH particles different properties in each. This module does that
for particle positions ``(N, 3)`` or voxel grids; the method and its choices
are described in docs/mesostructure.md. In short, for each size class k
(largest first) with size ``D_k`` (maximum equivalent diameter, m) and
volume fraction ``phi_k``:

1. *Skeleton*: Voronoi cells of a jittered seed lattice of spacing
   ``c_k = D_k / e_dim`` (``e_3 = (6/pi)^(1/3)``, ``e_2 = (4/pi)^(1/2)``: the
   mean cell has the volume of a sphere (disc) of diameter ``D_k``), from
   :func:`sphdyn.heterogeneity.noise.cellular` (Worley 1996).
2. *Score* of each point in its cell, normalised by ``c_k``:

   - crushed: ``s = d_face / c_k + a * r(x)`` with ``d_face`` the distance to
     the cell boundary (level sets: polyhedra with sharp edges) and ``r`` the
     ridged fBm (creased, angular faces);
   - rounded: ``s = d_soft / c_k + a * n(x)`` with ``d_soft`` the soft minimum
     of the bisector distances (``tau = 0.15 c_k``: edges and corners
     rounded) and ``n`` the smooth fBm of gradient noise (Perlin 2002;
     Mandelbrot & Van Ness 1968), both normalised to unit standard deviation,
     ``a`` the roughness.
3. *Selection*: eligible are points inside the body, not yet aggregate, with
   ``d_face > dx/2`` (two face-adjacent points of different cells cannot
   both qualify, so aggregates of one class never touch) and farther than
   ``dx`` from earlier classes' aggregate. Points are taken in decreasing
   score, skipping a point whose cell already holds the volume of a sphere
   of diameter ``D_k`` (cap), until the weight ``phi_k * W`` is reached
   (greedy quantile): the fraction is hit to one point, and no aggregate
   (a connected set lies in one cell) exceeds ``D_k``. Volume a class
   cannot place (cells full) is passed on to the next smaller class.
   Pieces smaller than ``D_k / 2`` (the class's lower bound: class k holds
   sizes in (D_k/2, D_k]) are excluded and the selection redrawn, up to 10
   times; fragments left after that are removed and their volume passed on
   (kept in the last class, which also stops redrawing when the exclusions
   would leave it short of its target, so that the fraction is hit).
4. *ITZ*: mortar points whose centre lies within ``itz_thickness`` of an
   aggregate point centre (Euclidean distance transform, SciPy).

Phases are int8: :data:`MORTAR` = 0, :data:`AGGREGATE` = 1, :data:`ITZ` = 2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numba import njit
from scipy import ndimage

from sphdyn.heterogeneity.noise import cellular, fbm, grid_points

__all__ = ["MORTAR", "AGGREGATE", "ITZ", "SHAPES", "fuller_grading",
           "generate_phase_grid", "generate_phases", "particle_grid",
           "equivalent_diameters", "roundness", "PhaseStatistics",
           "phase_statistics", "save_phase_slices", "phase_slice_figure",
           "PHASE_NAMES"]

MORTAR = np.int8(0)
AGGREGATE = np.int8(1)
ITZ = np.int8(2)
SHAPES = ("rounded", "crushed")
_ROUGHNESS = {"rounded": 0.05, "crushed": 0.05}  # default roughness a
_SOFTNESS = 0.15  # tau / c_k of the rounded shape
_MIN_SIZE_RATIO = 0.5  # pieces of class k below 0.5 D_k are redrawn
_REDRAWS = 10


def _e_dim(dim: int) -> float:
    # equivalent-diameter factor: d_eq = e_dim * (volume)^(1/dim)
    if dim == 3:
        return (6.0 / math.pi) ** (1.0 / 3.0)
    return (4.0 / math.pi) ** 0.5


def _ball_volume(d: float, dim: int) -> float:
    return math.pi * d**3 / 6.0 if dim == 3 else math.pi * d**2 / 4.0


def fuller_grading(max_size: float, min_size: float, exponent: float = 0.5
                   ) -> list[tuple[float, float]]:
    """Size classes from the Fuller-Thompson curve (Fuller & Thompson 1907).

    Passing fraction ``P(d) = (d / D_max)^q`` (``q = exponent``, 0.5 for
    Fuller, 0.45 for the US FHWA 0.45-power chart). Classes halve the size:
    ``D_k = D_max / 2^k`` down to ``min_size``; class k holds the material
    between ``D_{k+1}`` and ``D_k`` with fraction ``P(D_k) - P(D_{k+1})``,
    renormalised to sum 1 over the classes (finer material belongs to the
    mortar). Returns ``[(D_k, fraction_k), ...]``, largest first.
    """
    if not (max_size > 0 and 0 < min_size <= max_size):
        raise ValueError(f"need 0 < min_size <= max_size, got {min_size}, "
                         f"{max_size}")
    if not exponent > 0:
        raise ValueError(f"exponent must be > 0, got {exponent}")
    sizes = [max_size]
    while sizes[-1] / 2.0 >= min_size * (1.0 - 1e-12):
        sizes.append(sizes[-1] / 2.0)
    p = [(d / max_size) ** exponent for d in sizes] + [
        (sizes[-1] / 2.0 / max_size) ** exponent]
    frac = np.array([p[k] - p[k + 1] for k in range(len(sizes))])
    frac /= frac.sum()
    return [(float(d), float(f)) for d, f in zip(sizes, frac)]


def _check_grading(grading, max_aggregate_size):
    if grading is None:
        return [(float(max_aggregate_size), 1.0)]
    classes = [(float(d), float(f)) for d, f in grading]
    if not classes:
        raise ValueError("grading must list at least one (size, fraction)")
    for d, f in classes:
        if not (d > 0 and f >= 0):
            raise ValueError(f"grading entries need size > 0 m and fraction "
                             f">= 0, got ({d}, {f})")
    total = sum(f for _, f in classes)
    if abs(total - 1.0) > 1e-6:
        raise ValueError(f"grading fractions must sum to 1, got {total}")
    if max(d for d, _ in classes) > max_aggregate_size * (1 + 1e-12):
        raise ValueError("grading sizes must not exceed max_aggregate_size")
    return sorted(classes, key=lambda c: -c[0])


@njit(cache=True, error_model="numpy")
def _greedy_select(order, cell, weight, cap, target, selected):
    """Take points in `order` until the weight reaches `target`, at most
    `cap` points per cell. Returns the weight taken."""
    ncell = 0
    for q in range(order.shape[0]):
        ncell = max(ncell, cell[order[q]] + 1)
    used = np.zeros(ncell, dtype=np.int64)
    acc = 0.0
    for q in range(order.shape[0]):
        i = order[q]
        w = weight[i]
        if acc + 0.5 * w >= target:
            break
        c = cell[i]
        if used[c] >= cap:
            continue
        used[c] += 1
        selected[i] = True
        acc += w
    return acc


def _normalised(v: np.ndarray) -> np.ndarray:
    s = v.std()
    return (v - v.mean()) / s if s > 0 else v - v.mean()


def _phase_core(pts, grid_shape, dx, weight, *, aggregate_fraction,
                max_aggregate_size, itz_thickness, aggregate_shape, grading,
                octaves, persistence, lacunarity, roughness, seed):
    """Phases on the voxel grid ``grid_shape`` with centres ``pts`` (C order)
    and per-voxel weights (0 = outside the body). Returns int8 grid."""
    dim = len(grid_shape)
    if aggregate_shape not in SHAPES:
        raise ValueError(f"aggregate_shape must be one of {SHAPES}, got "
                         f"{aggregate_shape!r}")
    if not 0.0 <= aggregate_fraction < 1.0:
        raise ValueError(f"aggregate_fraction must be in [0, 1), got "
                         f"{aggregate_fraction}")
    if not dx > 0:
        raise ValueError(f"dx must be > 0 m, got {dx}")
    if not max_aggregate_size >= 2.0 * dx:
        raise ValueError(f"max_aggregate_size ({max_aggregate_size} m) must "
                         f"be at least 2 dx ({2 * dx} m): refine dx")
    if itz_thickness < 0 or 0 < itz_thickness < dx * (1 - 1e-9):
        raise ValueError(f"itz_thickness must be 0 (no ITZ) or >= dx "
                         f"({dx} m), got {itz_thickness}: the ITZ is the "
                         f"mortar within that distance of aggregate points")
    classes = _check_grading(grading, max_aggregate_size)
    a = _ROUGHNESS[aggregate_shape] if roughness is None else float(roughness)
    inside = weight > 0
    wtot = float(weight.sum())
    agg = np.zeros(weight.shape[0], dtype=bool)
    ridged = aggregate_shape == "crushed"
    noise = None
    if a != 0.0 and aggregate_fraction > 0:
        noise = _normalised(fbm(pts, feature_size=classes[0][0] / _e_dim(dim),
                                octaves=octaves, persistence=persistence,
                                lacunarity=lacunarity, seed=seed,
                                ridged=ridged))
    carry = 0.0  # volume a larger class could not place goes to the next
    for k, (dk, fk) in enumerate(classes):
        target = aggregate_fraction * fk * wtot + carry
        if target <= 0:
            continue
        ck = dk / _e_dim(dim)
        elig = inside & ~agg
        if agg.any():
            dist = ndimage.distance_transform_edt(
                ~agg.reshape(grid_shape)).ravel()
            elig &= dist > 1.0 + 1e-9
        idx = np.flatnonzero(elig)
        cn = cellular(pts[idx], cell_size=ck, seed=seed * 7919 + 101 * k + 1,
                      dim=dim,
                      softness=_SOFTNESS * ck if not ridged else 0.0)
        ok = cn.dface > 0.5 * dx
        idx = idx[ok]
        geo = (cn.dface if ridged else cn.dsoft)[ok] / ck
        score = geo + (a * noise[idx] if noise is not None else 0.0)
        order = idx[np.argsort(-score, kind="stable")]
        cell = np.full(weight.shape[0], -1, dtype=np.int64)
        _, cell[idx] = np.unique(cn.cell[ok], return_inverse=True)
        cap = int(math.floor(_ball_volume(dk, dim) / dx**dim + 1e-9))
        vmin = _ball_volume(_MIN_SIZE_RATIO * dk, dim) / dx**dim
        last = k == len(classes) - 1
        excluded = np.zeros(weight.shape[0], dtype=bool)
        wmax = float(weight[inside].max())
        prev = None
        for attempt in range(_REDRAWS + 1):
            sel = np.zeros(weight.shape[0], dtype=bool)
            taken = _greedy_select(order[~excluded[order]], cell, weight, cap,
                                   target, sel)
            if last and prev is not None and taken + 0.5 * wmax < target:
                # the exclusions cost capacity the last class needs: keep
                # the previous draw (with its fragments), which hit the target
                sel, taken = prev
                break
            # fragments below the class's lower size (clipped cells, noise
            # specks) are redrawn from the remaining points
            lab, _ = ndimage.label(sel.reshape(grid_shape))
            lab = lab.ravel()
            small = np.bincount(lab) < vmin
            small[0] = False
            frag = small[lab]
            if not frag.any() or (last and attempt == _REDRAWS):
                break
            if attempt == _REDRAWS:
                sel &= ~frag
                taken -= float(weight[frag].sum())
                break
            prev = (sel, taken)
            excluded |= frag
        agg |= sel
        carry = max(target - taken, 0.0)
        if last and taken + 0.5 * wmax < target:
            raise ValueError(
                f"aggregate_fraction {aggregate_fraction} cannot be reached: "
                f"the smallest size class {dk} m holds {taken / wtot:.3f} of "
                f"the volume (wanted {target / wtot:.3f}, including what "
                f"larger classes could not place); lower aggregate_fraction, "
                f"refine dx (max size / dx = {dk / dx:.1f}) or add smaller "
                f"size classes (grading)")
    phases = np.where(agg, AGGREGATE, MORTAR).astype(np.int8)
    if itz_thickness > 0 and agg.any():
        dist = ndimage.distance_transform_edt(~agg.reshape(grid_shape),
                                              sampling=dx).ravel()
        phases[inside & ~agg & (dist <= itz_thickness * (1 + 1e-9))] = ITZ
    return phases.reshape(grid_shape)


def generate_phase_grid(grid_shape, dx: float, *, aggregate_fraction: float,
                        max_aggregate_size: float, itz_thickness: float = 0.0,
                        aggregate_shape: str = "rounded", grading=None,
                        octaves: int = 3, persistence: float = 0.5,
                        lacunarity: float = 2.0,
                        roughness: float | None = None, seed: int = 0,
                        origin=(0.0, 0.0, 0.0), mask=None
                        ) -> np.ndarray:
    """Phase field on a voxel grid (see module doc for the algorithm).

    ``grid_shape`` (nx, ny) or (nx, ny, nz), voxel centres ``origin + dx *
    (i, j, k)`` (m). ``aggregate_fraction``: target aggregate volume fraction
    of the voxels in ``mask`` (all if None), hit to one voxel.
    ``max_aggregate_size``: largest equivalent diameter D_max (m);
    ``grading``: optional ``[(size, fraction), ...]`` (fractions of the
    aggregate volume, sizes <= D_max; see :func:`fuller_grading`).
    ``itz_thickness``: 0 or >= dx (m). ``aggregate_shape``: "rounded" or
    "crushed". ``octaves``, ``persistence``, ``lacunarity``: fBm of the
    surface roughness ``roughness`` (default 0.05). Returns int8 array of
    ``grid_shape`` (0 mortar, 1 aggregate, 2 ITZ; mortar outside ``mask``).
    """
    grid_shape = tuple(int(s) for s in grid_shape)
    pts = grid_points(grid_shape, dx, origin)
    if mask is None:
        weight = np.ones(pts.shape[0])
    else:
        mask = np.asarray(mask, dtype=bool)
        if mask.shape != grid_shape:
            raise ValueError(f"mask shape {mask.shape} != grid_shape "
                             f"{grid_shape}")
        weight = mask.ravel().astype(np.float64)
    return _phase_core(pts, grid_shape, dx, weight,
                       aggregate_fraction=aggregate_fraction,
                       max_aggregate_size=max_aggregate_size,
                       itz_thickness=itz_thickness,
                       aggregate_shape=aggregate_shape, grading=grading,
                       octaves=octaves, persistence=persistence,
                       lacunarity=lacunarity, roughness=roughness, seed=seed)


def particle_grid(x, dx: float, dim: int | None = None):
    """Voxel grid of spacing ``dx`` over the particles' bounding box.

    ``x`` (N, 3) m. Returns ``(grid_shape, origin, ijk, weight)``: each
    particle's voxel ``ijk`` (N, dim) int64 (nearest voxel centre) and the
    particle count per voxel ``weight`` (flattened grid). Particles on a
    lattice of spacing dx map one to one onto voxels. ``dim`` defaults to 2
    if all z are 0, else 3.
    """
    x = np.asarray(x, dtype=np.float64)
    if x.ndim != 2 or x.shape[1] != 3 or x.shape[0] == 0:
        raise ValueError(f"x must be a non-empty (N, 3) array, got "
                         f"{x.shape}")
    if dim is None:
        dim = 2 if not np.any(x[:, 2]) else 3
    if dim not in (2, 3):
        raise ValueError(f"dim must be 2 or 3, got {dim}")
    origin = x.min(axis=0)
    if dim == 2:
        origin[2] = 0.0
    ijk = np.rint((x[:, :dim] - origin[:dim]) / dx).astype(np.int64)
    grid_shape = tuple(int(s) for s in ijk.max(axis=0) + 1)
    flat = np.ravel_multi_index(tuple(ijk.T), grid_shape)
    weight = np.bincount(flat, minlength=int(np.prod(grid_shape))
                         ).astype(np.float64)
    return grid_shape, origin, ijk, weight


def generate_phases(x, dx: float, *, aggregate_fraction: float,
                    max_aggregate_size: float, itz_thickness: float = 0.0,
                    aggregate_shape: str = "rounded", grading=None,
                    octaves: int = 3, persistence: float = 0.5,
                    lacunarity: float = 2.0, roughness: float | None = None,
                    seed: int = 0, dim: int | None = None) -> np.ndarray:
    """Phase of each particle, (N,) int8 (0 mortar, 1 aggregate, 2 ITZ).

    ``x`` (N, 3) particle positions in m (z = 0 in 2D; ``dim`` defaults to 2
    if all z are 0), ``dx`` the particle spacing (m). The field is generated
    on the voxel grid of :func:`particle_grid` with the particle counts as
    weights, so the aggregate fraction is hit on the particles (to one
    voxel). Other arguments as in :func:`generate_phase_grid`.
    """
    grid_shape, origin, ijk, weight = particle_grid(x, dx, dim)
    pts = grid_points(grid_shape, dx, origin)
    ph = _phase_core(pts, grid_shape, dx, weight,
                     aggregate_fraction=aggregate_fraction,
                     max_aggregate_size=max_aggregate_size,
                     itz_thickness=itz_thickness,
                     aggregate_shape=aggregate_shape, grading=grading,
                     octaves=octaves, persistence=persistence,
                     lacunarity=lacunarity, roughness=roughness, seed=seed)
    return ph[tuple(ijk.T)]


def equivalent_diameters(aggregate, dx: float) -> np.ndarray:
    """Equivalent diameters (m) of the connected aggregate pieces.

    ``aggregate``: bool grid (2D or 3D); pieces are face-connected sets.
    ``d_eq = (6 V / pi)^(1/3)`` in 3D, ``(4 A / pi)^(1/2)`` in 2D, with V
    (A) the voxel count times dx^3 (dx^2). Returns (n_pieces,).
    """
    lab, n = ndimage.label(np.asarray(aggregate, dtype=bool))
    if n == 0:
        return np.empty(0)
    counts = np.bincount(lab.ravel())[1:].astype(np.float64)
    dim = lab.ndim
    return _e_dim(dim) * (counts * dx**dim) ** (1.0 / dim)


def roundness(aggregate, dx: float, min_diameter: float = 0.0) -> np.ndarray:
    """Inscribed-ball roundness of each aggregate piece, (n,) in (0, 1].

    ``R = V_ball(r_in) / V`` with ``r_in = max EDT - dx/2`` the radius of the
    largest inscribed ball (sphere in 3D, disc in 2D; EDT = distance from
    a voxel centre to the nearest non-aggregate centre, the boundary lies
    half a voxel before it) and V the piece volume (area). A ball gives 1,
    a cube pi/6 = 0.52, a square pi/4 = 0.79: angular and elongated pieces
    score lower (in the spirit of Wadell's roundness, 1932). Pieces with
    ``d_eq < min_diameter`` are skipped.
    """
    agg = np.asarray(aggregate, dtype=bool)
    lab, n = ndimage.label(agg)
    if n == 0:
        return np.empty(0)
    dim = agg.ndim
    edt = ndimage.distance_transform_edt(agg) * dx
    rin = np.asarray(ndimage.maximum(edt, lab, np.arange(1, n + 1))) - 0.5 * dx
    vol = np.bincount(lab.ravel())[1:] * dx**dim
    deq = _e_dim(dim) * vol ** (1.0 / dim)
    r = np.array([_ball_volume(2 * ri, dim) for ri in rin]) / vol
    return r[deq >= min_diameter]


@dataclass(frozen=True)
class PhaseStatistics:
    """Measured properties of a phase field (lengths in m)."""

    aggregate_fraction: float
    mortar_fraction: float
    itz_fraction: float
    diameters: np.ndarray          #: equivalent diameters of the pieces
    itz_max_distance: float        #: max distance ITZ point -> aggregate
    itz_mean_distance: float
    mean_roundness: float          #: mean of :func:`roundness` (d_eq >= 3 dx)

    def summary(self) -> str:
        d = self.diameters
        q = (np.percentile(d, [50, 95]) if d.size else [np.nan, np.nan])
        return (f"aggregate {self.aggregate_fraction:.4f}, mortar "
                f"{self.mortar_fraction:.4f}, ITZ {self.itz_fraction:.4f}; "
                f"{d.size} pieces, d_eq median {q[0]:.4g} m, 95% {q[1]:.4g} "
                f"m, max {d.max() if d.size else np.nan:.4g} m; ITZ max "
                f"distance {self.itz_max_distance:.4g} m; roundness "
                f"{self.mean_roundness:.3f}")


def phase_statistics(phases, dx: float, *, x=None, mask=None
                     ) -> PhaseStatistics:
    """Fractions, aggregate sizes, ITZ thickness and roundness of a field.

    Either a phase grid (2D/3D int8, ``mask`` optionally selects the body)
    or, with ``x`` (N, 3), particle phases (N,) mapped onto the grid of
    :func:`particle_grid` (empty voxels are outside the body).
    """
    phases = np.asarray(phases)
    if x is not None:
        grid_shape, _, ijk, weight = particle_grid(x, dx)
        if phases.shape != (ijk.shape[0],):
            raise ValueError(f"phases must have shape (N,) = "
                             f"({ijk.shape[0]},), got {phases.shape}")
        grid = np.zeros(grid_shape, dtype=np.int8)
        grid[tuple(ijk.T)] = phases
        mask = weight.reshape(grid_shape) > 0
        phases = grid
    if mask is None:
        mask = np.ones(phases.shape, dtype=bool)
    n = max(int(mask.sum()), 1)
    agg = (phases == AGGREGATE) & mask
    itz = (phases == ITZ) & mask
    if itz.any() and agg.any():
        dist = ndimage.distance_transform_edt(~agg, sampling=dx)[itz]
        dmax, dmean = float(dist.max()), float(dist.mean())
    else:
        dmax = dmean = 0.0
    rnd = roundness(agg, dx, min_diameter=3 * dx)
    return PhaseStatistics(
        aggregate_fraction=agg.sum() / n,
        mortar_fraction=((phases == MORTAR) & mask).sum() / n,
        itz_fraction=itz.sum() / n,
        diameters=equivalent_diameters(agg, dx),
        itz_max_distance=dmax, itz_mean_distance=dmean,
        mean_roundness=float(rnd.mean()) if rnd.size else float("nan"))


_COLOURS = ((0.80, 0.78, 0.72), (0.35, 0.35, 0.40), (0.85, 0.35, 0.20))
#: Legend name of each phase (index = phase value).
PHASE_NAMES = ("mortar", "aggregate", "ITZ")


def _rgb(grid2d, mask2d=None):
    img = np.asarray(_COLOURS)[np.clip(grid2d, 0, 2)]
    if mask2d is not None:
        img[~mask2d] = 1.0
    return img


def phase_slice_figure(phases, dx: float, *, x=None, index=None,
                       title: str | None = None, panel_inches: float = 5.0):
    """Figure (unsaved) of three orthogonal mid-slices of a 3D phase field
    (one panel in 2D), with a legend of the phases present.

    ``phases``: a phase grid, or particle phases (N,) with ``x`` (N, 3)
    (mapped with :func:`particle_grid`; voxels without a particle white,
    "no particle" in the legend). ``index``: voxel (i, j, k) the slices pass
    through (default centre). Colours: mortar light grey, aggregate dark
    grey, ITZ orange. The longer side of each panel is ``panel_inches``.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch

    phases = np.asarray(phases)
    mask = None
    if x is not None:
        grid_shape, _, ijk, weight = particle_grid(x, dx)
        grid = np.zeros(grid_shape, dtype=np.int8)
        grid[tuple(ijk.T)] = phases
        mask = weight.reshape(grid_shape) > 0
        phases = grid
    if mask is None:
        mask = np.ones(phases.shape, dtype=bool)
    if phases.ndim == 2:
        panels = [("xy", "", phases, mask)]
    else:
        c = [s // 2 for s in phases.shape] if index is None else list(index)
        panels = [("xy", f"z = {c[2] * dx * 1e3:.4g} mm", phases[:, :, c[2]],
                   mask[:, :, c[2]]),
                  ("xz", f"y = {c[1] * dx * 1e3:.4g} mm", phases[:, c[1], :],
                   mask[:, c[1], :]),
                  ("yz", f"x = {c[0] * dx * 1e3:.4g} mm", phases[c[0], :, :],
                   mask[c[0], :, :])]
    sizes = [(g.shape[0], g.shape[1]) for _, _, g, _ in panels]
    scale = panel_inches / max(max(s) for s in sizes)
    width = sum(w * scale for w, _ in sizes) + 0.8 * len(panels) + 1.3
    height = max(h * scale for _, h in sizes) + 1.4
    fig = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, len(panels), squeeze=False,
                        width_ratios=[w for w, _ in sizes])[0]
    for ax, (plane, where, g, m) in zip(axes, panels):
        ax.imshow(np.transpose(_rgb(g, m), (1, 0, 2)), origin="lower",
                  extent=(0, g.shape[0] * dx * 1e3, 0, g.shape[1] * dx * 1e3),
                  interpolation="nearest")
        ax.set_title(f"{plane[0]}-{plane[1]}" + (f" ({where})" if where else ""),
                     fontsize=10)
        ax.set_xlabel(f"{plane[0]} [mm]", fontsize=9)
        ax.set_ylabel(f"{plane[1]} [mm]", fontsize=9)
        ax.tick_params(labelsize=8)
    present = set(np.unique(phases[mask]).tolist())
    handles = [Patch(facecolor=_COLOURS[k], edgecolor="0.3", label=name)
               for k, name in enumerate(PHASE_NAMES) if k in present]
    if not mask.all():
        handles.append(Patch(facecolor="white", edgecolor="0.3", label="no particle"))
    fig.legend(handles=handles, loc="outside right center", title="phase",
               fontsize=9, title_fontsize=9)
    if title:
        fig.suptitle(title, fontsize=11)
    return fig


def save_phase_slices(phases, path, dx: float, *, x=None, index=None,
                      title: str | None = None) -> Path:
    """PNG of :func:`phase_slice_figure` (mid-slices with a phase legend)."""
    from sphdyn.io.plots import save_figure

    fig = phase_slice_figure(phases, dx, x=x, index=index, title=title)
    return save_figure(fig, path, 110)
