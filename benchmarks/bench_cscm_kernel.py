"""The CSCM group kernel alone on one state of a deck (default: the paper's disc).

Steps the deck ``--start`` steps (default 300: on the disc 71 % of the
particles are then plastic), then calls the material group's ``update``
``--calls`` times on copies of that state (stress, energy, wave speed,
damage and history restored before each call, so every call does the same
work) and prints the best and median wall time and the best in ns per
particle. Run it on two source trees (``PYTHONPATH=OLD/src``) one after the
other to compare a change of the material update; the pair passes, the
neighbour search and the output are not timed.

    python benchmarks/bench_cscm_kernel.py [--deck DECK] [--start 300] [--calls 30]
        [--threads 2]
"""

from __future__ import annotations

import argparse
import time

import numba

from sphdyn.build import build_stepper
from sphdyn.deck import load_deck


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--deck", default="examples/disc_impact.toml")
    ap.add_argument("--start", type=int, default=300)
    ap.add_argument("--calls", type=int, default=30)
    ap.add_argument("--threads", type=int, default=2)
    a = ap.parse_args()
    stepper = build_stepper(load_deck(a.deck))
    for _ in range(a.start):
        stepper.step()
    numba.set_num_threads(a.threads)
    part = stepper.parts[0]
    p, g = part.p, part.groups[0]
    dt = stepper.dt_step
    state = [p.sig, p.e, p.c, p.damage, g.history(p.hist)]

    def call() -> float:
        sig, e, c, damage, hist = (x.copy() for x in state)
        t0 = time.perf_counter()
        g.model.update(g.idx, p.L, dt, p.rho, sig, e, c, damage, hist, g.params, p.size)
        return time.perf_counter() - t0

    call()  # compilation or cache load
    times = sorted(call() for _ in range(a.calls))
    print(f"{a.deck} at step {a.start}, {len(g.idx)} particles, {a.threads} threads: "
          f"best {1e3 * times[0]:.3f} ms, median {1e3 * times[len(times) // 2]:.3f} ms, "
          f"{1e9 * times[0] / len(g.idx):.1f} ns per particle")


if __name__ == "__main__":
    main()
