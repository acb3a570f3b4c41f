"""Synthetic grey image of a concrete section with a known aggregate fraction.

Random sequential addition of non-overlapping ellipses (bounding circles
kept apart by ``gap`` pixels) with equivalent radii drawn log-uniformly in
[r_min, r_max], until the drawn area fraction reaches ``fraction`` (or
``max_attempts`` placements were tried).
Grey levels: matrix 0.35, aggregate 0.65 with a per-piece tint (+-0.08),
Gaussian pixel noise (std ``noise``) and a light blur (sigma 0.7 px),
clipped to [0, 1]. The exact truth mask is returned with the image, so the
segmentation can be checked against it. No external data is used.

Usage: ``python tests/data/make_section_image.py OUT.png [--seed S]``
writes the image (used for the figures of docs/mesostructure.md).
"""

from __future__ import annotations

import argparse

import numpy as np
from scipy import ndimage


def synthetic_section(shape=(400, 400), fraction=0.4, r_min=4.0, r_max=18.0,
                      gap=2.0, noise=0.06, seed=0, max_attempts=50000):
    """Return ``(grey, truth)``: float image in [0, 1] and bool aggregate
    mask, both of ``shape`` (rows, columns). The fraction is reached unless
    the packing jams first (about 0.38 for the default sizes); the truth
    mask gives the exact value either way."""
    rng = np.random.default_rng(seed)
    ny, nx = shape
    truth = np.zeros(shape, dtype=bool)
    grey = np.full(shape, 0.35)
    centres = np.empty((0, 2))
    radii = np.empty(0)
    area = 0
    for _ in range(max_attempts):
        if area >= fraction * ny * nx:
            break
        r = float(np.exp(rng.uniform(np.log(r_min), np.log(r_max))))
        e = rng.uniform(0.0, 0.35)
        a, b = r * (1 + e), r / (1 + e)     # equal area pi r^2
        c = rng.uniform([0, 0], [ny, nx])
        if np.any(np.hypot(*(centres - c).T) < radii + a + gap):
            continue
        th = rng.uniform(0, np.pi)
        y0, y1 = max(int(c[0] - a) - 1, 0), min(int(c[0] + a) + 2, ny)
        x0, x1 = max(int(c[1] - a) - 1, 0), min(int(c[1] + a) + 2, nx)
        dy, dx = np.mgrid[y0:y1, x0:x1].astype(np.float64)
        dy -= c[0]
        dx -= c[1]
        u = dx * np.cos(th) + dy * np.sin(th)
        v = -dx * np.sin(th) + dy * np.cos(th)
        inside = (u / a) ** 2 + (v / b) ** 2 <= 1.0
        truth[y0:y1, x0:x1] |= inside
        grey[y0:y1, x0:x1][inside] = 0.65 + rng.uniform(-0.08, 0.08)
        area += int(inside.sum())
        centres = np.vstack([centres, c])
        radii = np.append(radii, a)
    grey = grey + rng.normal(0.0, noise, shape)
    grey = np.clip(ndimage.gaussian_filter(grey, 0.7), 0.0, 1.0)
    return grey, truth


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--fraction", type=float, default=0.4)
    args = ap.parse_args()
    from PIL import Image

    grey, truth = synthetic_section(fraction=args.fraction, seed=args.seed)
    Image.fromarray(np.round(grey * 255).astype(np.uint8)).save(args.out)
    print(f"{args.out}: true aggregate area fraction {truth.mean():.4f}")


if __name__ == "__main__":
    main()
