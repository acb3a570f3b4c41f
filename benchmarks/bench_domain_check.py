"""The every-step check of ``[domain] outside = "remove"`` (sphdyn.events.domain_exit),
A/B in one process: the serial scan that listed the rows outside into a new array
every step (before 2026-11-27, written out here as the baseline) against the
parallel count that allocates nothing when no particle left (now).

    python benchmarks/bench_domain_check.py [--n 1000000] [--threads 2] [--rounds 20]

Prints the best time per call [us] of each, taking turns, with every particle
inside the box (the common case).
"""

from __future__ import annotations

import argparse
import time

import numba
import numpy as np
from numba import njit

from sphdyn.events.domain_exit import count_outside, outside_rows
from sphdyn.watchers.guards import outside_box


@njit(cache=True, error_model="numpy")
def _serial_rows(x, active, tl, lo, hi):
    """The old check: a serial count, then a new array of the rows outside."""
    n = 0
    for i in range(x.shape[0]):
        if active[i] != 0 and not tl[i] and outside_box(x, i, lo, hi):
            n += 1
    return outside_rows(x, active, tl, lo, hi, n)  # the second scan, as it was


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--rounds", type=int, default=20)
    a = ap.parse_args()
    numba.set_num_threads(a.threads)
    rng = np.random.default_rng(0)
    x = rng.uniform(-1.0, 1.0, (a.n, 3))
    active = np.ones(a.n, np.int8)
    tl = np.zeros(a.n, bool)
    lo, hi = np.full(3, -2.0), np.full(3, 2.0)
    calls = {"old (serial, array)": lambda: _serial_rows(x, active, tl, lo, hi),
             "new (parallel count)": lambda: count_outside(x, active, tl, lo, hi)}
    for f in calls.values():
        f()  # compile or load
    best = {k: np.inf for k in calls}
    for _ in range(a.rounds):
        for k, f in calls.items():
            t0 = time.perf_counter()
            f()
            best[k] = min(best[k], time.perf_counter() - t0)
    print(f"{a.n} particles, {a.threads} thread(s), best of {a.rounds}:")
    for k, t in best.items():
        print(f"  {k}: {1e6 * t:.0f} us")
    print(f"  old / new: {best['old (serial, array)'] / best['new (parallel count)']:.2f}")


if __name__ == "__main__":
    main()
