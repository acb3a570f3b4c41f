"""Build-time benchmark of the neighbour search (sphdyn.neighbours).

Prints the wall time of ``build_neighbours`` for
* 100k and 1M uniformly random 3D particles (h chosen so that a particle
  has ~ 60 neighbours), and
* a 1M-particle cubic lattice with spacing dx, h = 1.2 dx,
  radius_factor = 2, skin = 0.1 * 2.4 dx (~ 78 neighbours per particle),
  natural and shuffled index order, and its rebuild via update_neighbours.

Usage: ``python benchmarks/bench_neighbours.py [--threads T] [--repeat R]``.
The first (untimed) call compiles or loads the Numba cache.
"""

from __future__ import annotations

import argparse
import time

import numba
import numpy as np

from sphdyn.neighbours import (build_neighbours, max_neighbours,
                               mean_neighbours, update_neighbours)


def _time_build(label, x, h, rf, skin, repeat):
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        nl = build_neighbours(x, h, rf, skin, 3)
        best = min(best, time.perf_counter() - t0)
    print(f"{label:<34s} N={x.shape[0]:>8d}  build {best:7.3f} s  "
          f"mean {mean_neighbours(nl):6.1f}  max {max_neighbours(nl):4d}  "
          f"nnz {nl.nnz:>10d}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--threads", type=int,
                    default=numba.config.NUMBA_NUM_THREADS)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    numba.set_num_threads(args.threads)
    print(f"numba threads: {numba.get_num_threads()}")
    rng = np.random.default_rng(1)
    rf = 2.0
    # warm-up (compilation / cache load)
    xw = rng.random((1000, 3))
    build_neighbours(xw, np.full(1000, 0.05), rf, 0.0, 3)

    for n in (100_000, 1_000_000):
        x = rng.random((n, 3))
        dx = n ** (-1.0 / 3.0)
        h = np.full(n, 1.2 * dx)
        _time_build("random 3D, h = 1.2 n^(-1/3)", x, h, rf, 0.24 * dx,
                    args.repeat)

    m = 100
    dx = 1.0e-3
    g = np.arange(m) * dx
    x = np.stack(np.meshgrid(g, g, g, indexing="ij"), axis=-1).reshape(-1, 3)
    h = np.full(x.shape[0], 1.2 * dx)
    _time_build("lattice 100^3, h = 1.2 dx", x, h, rf, 0.1 * 2.4 * dx,
                args.repeat)
    perm = rng.permutation(x.shape[0])
    _time_build("lattice 100^3, shuffled indices", x[perm], h, rf,
                0.1 * 2.4 * dx, args.repeat)
    # rebuild through update_neighbours (storage of idx reused)
    nl = build_neighbours(x, h, rf, 0.24 * dx, 3)
    best = np.inf
    for k in range(args.repeat):
        x1 = x + (0.2 * (k + 1)) * dx  # beyond the skin: forces a rebuild
        t0 = time.perf_counter()
        update_neighbours(nl, x1, h, 3)
        best = min(best, time.perf_counter() - t0)
    print(f"{'lattice 100^3, rebuild via update':<34s} N={x.shape[0]:>8d}  "
          f"build {best:7.3f} s  (n_builds {nl.n_builds})")


if __name__ == "__main__":
    main()
