"""Speed of the mesostructure generator (sphdyn.heterogeneity).

Times, on a 100^3 = 1M-particle cubic lattice (dx = 1 mm):
* the noise alone: fBm of gradient noise (3 octaves) and cellular noise
  (hard and soft distance) at the 1M points;
* generate_phases for rounded and crushed aggregate, one size class
  (D_max = 12 mm) and a Fuller grading (16, 8, 4 mm), with a 1 mm ITZ.

Usage: ``python benchmarks/bench_mesostructure.py [--threads T] [--n 100]``.
A warm-up call on a small lattice compiles or loads the Numba cache first.
"""

from __future__ import annotations

import argparse
import os
import time

import numba
import numpy as np

from sphdyn.heterogeneity.mesostructure import (fuller_grading,
                                                generate_phases,
                                                phase_statistics)
from sphdyn.heterogeneity.noise import cellular, fbm, grid_points


def _t(f):
    """Wall time of f(); the process CPU time is kept in _t.cpu (the
    machine may be shared: CPU time / threads bounds the idle wall time)."""
    t0, c0 = time.perf_counter(), time.process_time()
    out = f()
    _t.cpu = time.process_time() - c0
    return time.perf_counter() - t0, out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--threads", type=int,
                    default=numba.config.NUMBA_NUM_THREADS)
    ap.add_argument("--n", type=int, default=100, help="lattice size n^3")
    args = ap.parse_args()
    numba.set_num_threads(args.threads)
    dx = 1e-3
    kw = dict(aggregate_fraction=0.45, itz_thickness=dx, seed=1)
    # warm-up: compile / load the cache of every kernel used below
    xw = grid_points((12, 12, 12), dx)
    for shape in ("rounded", "crushed"):
        generate_phases(xw, dx, max_aggregate_size=6 * dx,
                        aggregate_shape=shape, **kw)
    x = grid_points((args.n,) * 3, dx)
    n = x.shape[0]
    print(f"numba threads: {numba.get_num_threads()}, particles: {n}, "
          f"load average {os.getloadavg()[0]:.1f}")
    t, _ = _t(lambda: fbm(x, feature_size=0.01, octaves=3))
    print(f"fbm, 3 octaves                 {t:7.2f} s  cpu {_t.cpu:6.2f} s")
    t, _ = _t(lambda: cellular(x, cell_size=0.01))
    print(f"cellular, hard                 {t:7.2f} s  cpu {_t.cpu:6.2f} s")
    t, _ = _t(lambda: cellular(x, cell_size=0.01, softness=0.0015))
    print(f"cellular, soft                 {t:7.2f} s  cpu {_t.cpu:6.2f} s")
    for shape in ("rounded", "crushed"):
        for name, grading in (("D_max 12 mm", None),
                              ("Fuller 16-8-4", fuller_grading(16 * dx,
                                                               4 * dx))):
            dmax = 16 * dx if grading else 12 * dx
            t, ph = _t(lambda: generate_phases(
                x, dx, max_aggregate_size=dmax, aggregate_shape=shape,
                grading=grading, **kw))
            st = phase_statistics(ph, dx, x=x)
            print(f"generate_phases {shape:8s} {name:14s} {t:7.2f} s  cpu "
                  f"{_t.cpu:6.2f} s  "
                  f"agg {st.aggregate_fraction:.4f} ITZ "
                  f"{st.itz_fraction:.3f} pieces {st.diameters.size} "
                  f"max d_eq {st.diameters.max() * 1e3:.2f} mm")


if __name__ == "__main__":
    main()
