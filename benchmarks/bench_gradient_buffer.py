"""The velocity-gradient pass with its row buffer against pair by pair, one process.

Steps a deck ``--start`` steps, then calls
:func:`sphdyn.parts.sph.gradient.velocity_gradient` on that state in turns
with the part's row buffer and with a zero-width one (which sends every row
through the pair-by-pair code), ``--rounds`` times each, and prints the best
and median nanoseconds per pair within the support. Both forms give the
same bits (tests/test_sph_passes.py); taking turns in one process lets a
shared machine's slow moments hit both alike.

    python benchmarks/bench_gradient_buffer.py [--deck DECK] [--start 300]
        [--rounds 20] [--threads 2]

The elastic block of ``sphdyn bench block3d``: ``--deck block3d`` (100k
particles).
"""

from __future__ import annotations

import argparse
import time

import numba
import numpy as np

from sphdyn.build import build_stepper
from sphdyn.bench import case_deck
from sphdyn.deck import load_deck
from sphdyn.parts.sph.gradient import GRADIENT_CHUNKS, GRADIENT_ROWS, velocity_gradient


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--deck", default="examples/disc_impact.toml")
    ap.add_argument("--start", type=int, default=300)
    ap.add_argument("--rounds", type=int, default=20)
    ap.add_argument("--threads", type=int, default=2)
    a = ap.parse_args()
    deck = case_deck("block3d") if a.deck == "block3d" else load_deck(a.deck)
    stepper = build_stepper(deck)
    for _ in range(a.start):
        stepper.step()
    numba.set_num_threads(a.threads)
    part = next(q for q in stepper.parts if getattr(q, "has_ul", False))
    p, k, nl = part.p, part.kernel, part.nl
    n = p.x.shape[0]
    F = part.F.copy()
    L, B = np.zeros((n, 3, 3)), np.zeros((n, 3, 3))
    count = p.n_support.copy()
    n_own = part._pair_colouring().n_own

    def call(scratch) -> float:
        idx = nl.idx.copy()  # the pass partitions rows in place
        t0 = time.perf_counter()
        velocity_gradient(p.x, p.v, p.h, p.m, p.rho, nl.offsets, idx, n_own, k.kid, k.sigma,
                          part.dim, k.support_scale, part.s.correction, F, L, B, count,
                          scratch)
        return time.perf_counter() - t0

    forms = {"buffered": part._gradient_scratch(),
             "pair by pair": np.zeros((GRADIENT_CHUNKS, GRADIENT_ROWS, 0))}
    times: dict = {name: [] for name in forms}
    for scratch in forms.values():
        call(scratch)  # compilation or cache load
    for _ in range(a.rounds):
        for name, scratch in forms.items():
            times[name].append(call(scratch))
    pairs = int(np.count_nonzero(F))  # within the support (the skin's F = 0)
    print(f"{a.deck} at step {a.start}, {n} particles, {pairs / n:.1f} pairs each, "
          f"{a.threads} threads, ns per pair (best / median):")
    for name, t in times.items():
        print(f"  {name}: {min(t) / pairs * 1e9:.2f} / {np.median(t) / pairs * 1e9:.2f}")


if __name__ == "__main__":
    main()
