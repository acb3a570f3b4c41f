"""Concrete mesostructure from a photo of a section (thesis Fig. 7.2).

1. Read the image as grey levels in [0, 1] (Pillow).
2. Segment aggregate from matrix with Otsu's threshold (Otsu 1979): with
   the grey-level histogram ``p_i`` over bins of centre ``g_i``,
   ``w(k) = sum_{i<=k} p_i``, ``mu(k) = sum_{i<=k} p_i g_i``, the threshold
   maximises the between-class variance

   .. math::

       \\sigma_B^2(k) = \\frac{(\\mu_T\\, w(k) - \\mu(k))^2}
                             {w(k)\\,(1 - w(k))}.

3. Clean: binary opening then closing with a disc of ``radius`` pixels
   (removes noise specks and bridges), removal of pieces smaller than
   ``min_area`` pixels, hole filling (SciPy ndimage).
4. Measure the area fraction ``A_A`` and the equivalent diameters
   ``d = (4 A / pi)^(1/2)`` of the aggregate pieces.
5. Generate a 3D structure (:mod:`sphdyn.heterogeneity.mesostructure`) with
   volume fraction ``V_V = A_A`` (Delesse 1847: the area fraction of a
   random plane section is an unbiased estimate of the volume fraction) and
   a maximum aggregate size D_max chosen so that the sections of the
   generated structure have the photo's 95th-percentile section diameter:
   a section through a particle is smaller than the particle (a random plane
   cuts a sphere of diameter D in a disc of mean diameter pi D / 4), so
   D_max is found by the fixed-point iteration
   ``D <- D * d95(photo) / d95(sections of the generated structure)``
   started from ``D = 4/pi * d95(photo)``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy import ndimage

from sphdyn.heterogeneity.mesostructure import (AGGREGATE,
                                                equivalent_diameters,
                                                fuller_grading,
                                                generate_phase_grid)

__all__ = ["read_grey", "otsu_threshold", "segment_aggregate",
           "SectionStatistics", "section_statistics", "PhotoStructure",
           "structure_from_photo", "save_photo_comparison", "PhotoTargets",
           "photo_targets"]


def read_grey(path) -> np.ndarray:
    """Image file (PNG, JPEG, ... via Pillow) as float64 grey levels in
    [0, 1], shape (rows, columns)."""
    from PIL import Image

    with Image.open(path) as im:
        return np.asarray(im.convert("L"), dtype=np.float64) / 255.0


def otsu_threshold(grey, bins: int = 256) -> float:
    """Otsu's threshold (Otsu 1979, module doc eq.) of grey levels.

    ``grey``: array of any shape. Returns the grey level separating the two
    classes (the upper edge of the last bin of the dark class).
    """
    g = np.asarray(grey, dtype=np.float64).ravel()
    lo, hi = float(g.min()), float(g.max())
    if hi <= lo:
        raise ValueError("image has a single grey level: nothing to segment")
    hist, edges = np.histogram(g, bins=bins, range=(lo, hi))
    p = hist / hist.sum()
    centres = 0.5 * (edges[:-1] + edges[1:])
    w = np.cumsum(p)
    mu = np.cumsum(p * centres)
    den = w * (1.0 - w)
    with np.errstate(divide="ignore", invalid="ignore"):
        sb = np.where(den > 0, (mu[-1] * w - mu) ** 2 / den, 0.0)
    return float(edges[int(np.argmax(sb)) + 1])


def _disc(radius: int) -> np.ndarray:
    r = int(radius)
    y, x = np.mgrid[-r:r + 1, -r:r + 1]
    return x * x + y * y <= r * r


def segment_aggregate(grey, *, threshold: float | None = None,
                      aggregate: str = "bright", radius: int = 1,
                      min_area: int = 20, fill_holes: bool = True
                      ) -> np.ndarray:
    """Aggregate mask of a grey image, bool (rows, columns).

    ``threshold`` defaults to :func:`otsu_threshold`; ``aggregate`` says
    whether aggregate is the "bright" or "dark" class. Cleaning: opening and
    closing with a disc of ``radius`` pixels (0 = none), removal of pieces
    below ``min_area`` pixels, filling of holes.
    """
    grey = np.asarray(grey, dtype=np.float64)
    if grey.ndim != 2:
        raise ValueError(f"grey image must be 2D, got shape {grey.shape}")
    if aggregate not in ("bright", "dark"):
        raise ValueError(f"aggregate must be 'bright' or 'dark', got "
                         f"{aggregate!r}")
    t = otsu_threshold(grey) if threshold is None else float(threshold)
    mask = grey > t if aggregate == "bright" else grey <= t
    if radius > 0:
        s = _disc(radius)
        mask = ndimage.binary_opening(mask, structure=s)
        mask = ndimage.binary_closing(mask, structure=s, border_value=0)
    if min_area > 1:
        lab, n = ndimage.label(mask)
        if n:
            area = np.bincount(lab.ravel())
            keep = area >= min_area
            keep[0] = False
            mask = keep[lab]
    if fill_holes:
        mask = ndimage.binary_fill_holes(mask)
    return mask


@dataclass(frozen=True)
class SectionStatistics:
    """Area fraction and equivalent diameters (m) of a section's pieces."""

    area_fraction: float
    diameters: np.ndarray

    def percentile(self, q: float) -> float:
        return float(np.percentile(self.diameters, q)) if self.diameters.size \
            else float("nan")

    def summary(self) -> str:
        return (f"area fraction {self.area_fraction:.4f}, "
                f"{self.diameters.size} pieces, d_eq median "
                f"{self.percentile(50):.4g} m, 95% "
                f"{self.percentile(95):.4g} m")


def section_statistics(mask, pixel_size: float, min_area: int = 1
                       ) -> SectionStatistics:
    """Area fraction and equivalent diameters of the pieces of a 2D mask.

    ``pixel_size`` in m; pieces below ``min_area`` pixels are not counted in
    the diameters (they are in the fraction)."""
    mask = np.asarray(mask, dtype=bool)
    d = equivalent_diameters(mask, pixel_size)
    d = d[d >= np.sqrt(4.0 * min_area / np.pi) * pixel_size * (1 - 1e-12)]
    return SectionStatistics(float(mask.mean()), d)


@dataclass(frozen=True)
class PhotoStructure:
    """Result of :func:`structure_from_photo`."""

    phases: np.ndarray                #: int8 3D phase grid
    dx: float                         #: voxel size, m
    max_aggregate_size: float         #: D_max used, m
    photo: SectionStatistics          #: of the segmented photo
    sections: SectionStatistics       #: of all axis-normal grid sections
    section_fractions: np.ndarray     #: aggregate fraction of each section

    def summary(self) -> str:
        return (f"photo:     {self.photo.summary()}\n"
                f"generated: {self.sections.summary()} (sections; "
                f"D_max = {self.max_aggregate_size:.4g} m, section fraction "
                f"std {self.section_fractions.std():.4f})")


def _section_stats(phases, dx, min_area):
    agg = phases == AGGREGATE
    fr, ds = [], []
    for axis in range(3):
        for i in range(agg.shape[axis]):
            s = np.take(agg, i, axis=axis)
            fr.append(s.mean())
            ds.append(section_statistics(s, dx, min_area).diameters)
    return np.array(fr), np.concatenate(ds)


def structure_from_photo(image, *, pixel_size: float, grid_shape=None, dx: float,
                         itz_thickness: float = 0.0,
                         aggregate_shape: str = "crushed", seed: int = 0,
                         aggregate: str = "bright", radius: int = 1,
                         min_area: int = 20, iterations: int = 3,
                         fuller_exponent: float | None = None,
                         min_aggregate_size: float | None = None,
                         **generator) -> PhotoStructure:
    """3D phase grid whose sections match a photo (module doc, steps 1-5).

    ``image``: a path or a 2D grey array in [0, 1]; ``pixel_size`` m per
    pixel; ``grid_shape`` (nx, ny, nz) and ``dx`` (m) of the generated grid
    (``grid_shape`` None: a cube of ``clip(6 D0 / dx, 32, 80)`` voxels,
    D0 = 4/pi d95 of the photo, enough for a few of the largest pieces).
    Segmentation arguments as :func:`segment_aggregate`; ``iterations`` of
    the D_max fixed point. ``fuller_exponent`` q: use the Fuller grading
    (:func:`~sphdyn.heterogeneity.mesostructure.fuller_grading`) from D_max
    down to ``min_aggregate_size`` (default 4 dx) instead of one size
    class, for photos with a broad size distribution. Further keyword
    arguments go to
    :func:`generate_phase_grid`. Section statistics ignore pieces below
    ``min_area`` photo pixels (converted to voxels) on both sides.
    """
    grey = read_grey(image) if isinstance(image, (str, Path)) else \
        np.asarray(image, dtype=np.float64)
    mask = segment_aggregate(grey, aggregate=aggregate, radius=radius,
                             min_area=min_area)
    min_px = max(int(round(min_area * (pixel_size / dx) ** 2)), 1)
    photo = section_statistics(mask, pixel_size, min_area)
    if photo.diameters.size == 0:
        raise ValueError("no aggregate found in the photo: check 'aggregate' "
                         "(bright/dark) and min_area")
    target = photo.percentile(95)
    dmax = 4.0 / np.pi * target
    if grid_shape is None:
        n = int(np.clip(np.ceil(6.0 * dmax / dx), 32, 80))
        grid_shape = (n, n, n)
    for _ in range(max(int(iterations), 1)):
        dmax = max(dmax, 2.0 * dx)
        if fuller_exponent is not None:
            dmin = 4.0 * dx if min_aggregate_size is None else \
                min_aggregate_size
            generator["grading"] = fuller_grading(dmax, min(dmin, dmax),
                                                  fuller_exponent)
        phases = generate_phase_grid(
            grid_shape, dx, aggregate_fraction=photo.area_fraction,
            max_aggregate_size=dmax, itz_thickness=itz_thickness,
            aggregate_shape=aggregate_shape, seed=seed, **generator)
        fr, ds = _section_stats(phases, dx, min_px)
        got = float(np.percentile(ds, 95)) if ds.size else 0.0
        if got <= 0:
            break
        if abs(got / target - 1.0) < 0.02:
            break
        dmax *= target / got
    return PhotoStructure(phases, dx, float(dmax), photo,
                          SectionStatistics(float(fr.mean()), ds), fr)


@dataclass(frozen=True)
class PhotoTargets:
    """Generator targets measured from a photo (:func:`photo_targets`)."""

    aggregate_fraction: float         #: volume (3D) or area (2D) fraction
    max_aggregate_size: float         #: D_max, m
    photo: SectionStatistics          #: of the segmented photo
    sections: SectionStatistics | None  #: of the fitted 3D grid's sections

    def summary(self) -> str:
        text = (f"photo: {self.photo.summary()}; generator: aggregate_fraction "
                f"{self.aggregate_fraction:.4f}, max_aggregate_size "
                f"{self.max_aggregate_size:.4g} m")
        if self.sections is not None:
            text += f"; sections of the fitted structure: {self.sections.summary()}"
        return text


def photo_targets(image, *, pixel_size: float, dx: float, dim: int,
                  aggregate: str = "bright", itz_thickness: float = 0.0,
                  aggregate_shape: str = "rounded", seed: int = 0,
                  **generator) -> PhotoTargets:
    """``aggregate_fraction`` and ``max_aggregate_size`` for the generator from a photo.

    2D models are sections themselves: the fraction is the photo's area
    fraction and D_max its 95th-percentile equivalent diameter. 3D: the
    fraction is the area fraction (Delesse) and D_max comes from the
    fixed point of :func:`structure_from_photo` on its default cube of
    voxels of size ``dx``, a few seconds. ``image`` a path or a grey array
    in [0, 1]; ``pixel_size`` and ``dx`` in m.
    """
    grey = read_grey(image) if isinstance(image, (str, Path)) else \
        np.asarray(image, dtype=np.float64)
    if dim == 2:
        mask = segment_aggregate(grey, aggregate=aggregate)
        photo = section_statistics(mask, pixel_size, 20)
        if photo.diameters.size == 0:
            raise ValueError("no aggregate found in the photo: check "
                             "photo_aggregate (bright/dark)")
        return PhotoTargets(photo.area_fraction, photo.percentile(95), photo, None)
    res = structure_from_photo(grey, pixel_size=pixel_size, dx=dx,
                               itz_thickness=itz_thickness,
                               aggregate_shape=aggregate_shape, seed=seed,
                               aggregate=aggregate, **generator)
    return PhotoTargets(res.photo.area_fraction, res.max_aggregate_size, res.photo,
                        res.sections)


def save_photo_comparison(result: PhotoStructure, grey, mask, path) -> Path:
    """PNG: photo, its segmentation, a section of the generated structure,
    and the section-diameter distributions of both (cumulative)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from sphdyn.io.plots import save_figure

    from sphdyn.heterogeneity.mesostructure import _rgb

    fig, ax = plt.subplots(1, 4, figsize=(14, 4.0))
    ax[0].imshow(grey, cmap="gray", vmin=0, vmax=1)
    ax[0].set_title("photo", fontsize=9)
    ax[1].imshow(mask, cmap="gray_r")
    ax[1].set_title(f"segmented: A_A = {result.photo.area_fraction:.3f}",
                    fontsize=9)
    mid = result.phases.shape[2] // 2
    ax[2].imshow(np.transpose(_rgb(result.phases[:, :, mid]), (1, 0, 2)),
                 origin="lower", interpolation="nearest")
    ax[2].set_title(f"generated section: {result.section_fractions.mean():.3f}"
                    f" (mean of sections)", fontsize=9)
    for a in ax[:3]:
        a.set_xticks([])
        a.set_yticks([])
    for st, lab in ((result.photo, "photo"), (result.sections, "generated")):
        d = np.sort(st.diameters) * 1e3
        ax[3].plot(d, np.arange(1, d.size + 1) / max(d.size, 1), label=lab)
    ax[3].set_xlabel("section equivalent diameter (mm)", fontsize=8)
    ax[3].set_ylabel("cumulative fraction of pieces", fontsize=8)
    ax[3].legend(fontsize=8)
    ax[3].tick_params(labelsize=7)
    fig.tight_layout()
    return save_figure(fig, path, 70)
