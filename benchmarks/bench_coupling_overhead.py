"""What an SPH-FEM coupling adds to the step time of the coupled beam (issue 15).

The thesis's FEM-SPH-FEM beam (``examples/beam_<coupling>.toml``, sec. 4.1)
is run for ``--steps`` steps with each coupling (penalty, tied, hybrid) and
once with ``convert.coupling = "none"``: the same mesh ends and the same SPH
region, with nothing between them. The issue's target: a coupling adds at
most 10 % to the step time of the model without it.

Two measures, both from one process:

* ``ratio``: the step time with the coupling over the step time without it,
  runs interleaved (none, penalty, tied, hybrid, none, ...) and the best of
  ``--repeat`` taken per model, so a slow moment of a shared machine does
  not land on one model only;
* ``share``: inside the coupled run, the time spent in the coupling's own
  calls (``prescribe``, ``after_kick``, ``constrain``, ``update_geometry``,
  ``forces``, ``stable_dt``) over the whole step; wrappers time them, the
  solver is not modified. The hybrid coupling also costs a hook inside the
  SPH pass (``pair_filters``), timed the same way.

The steps start from rest (the ramp's first steps), so the neighbour lists
are not rebuilt; the coupling's cost does not depend on the motion.

Prints one JSON line per model and a markdown table::

    python benchmarks/bench_coupling_overhead.py [--steps 200] [--repeat 3]
        [--divisions 80,4,4] [--threads T]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numba

from sphdyn.build import build_stepper
from sphdyn.deck import load_deck

ROOT = Path(__file__).resolve().parents[1]
COUPLINGS = ("penalty", "tied", "hybrid")
HOOKS = ("prescribe", "after_kick", "constrain", "update_geometry", "forces",
         "stable_dt")


class Timer:
    """Accumulated wall time of wrapped callables."""

    def __init__(self):
        self.seconds = 0.0

    def wrap(self, fn):
        def timed(*args, **kw):
            t0 = time.perf_counter()
            out = fn(*args, **kw)
            self.seconds += time.perf_counter() - t0
            return out
        return timed


def stepper(coupling: str, divisions: str):
    """The beam model with ``coupling`` ('none' for the uncoupled one)."""
    name = "tied" if coupling == "none" else coupling
    sets = [f"mesh.beam.block.divisions=[{divisions}]"]
    if coupling == "none":
        sets.append('mesh.beam.convert.coupling="none"')
    return build_stepper(load_deck(ROOT / "examples" / f"beam_{name}.toml", sets))


def time_steps(coupling: str, divisions: str, steps: int, warmup: int = 3) -> dict:
    """Seconds per step of one model, and the coupling's share of them."""
    s = stepper(coupling, divisions)
    timer = Timer()
    couplings = [i for i in s.interactions if type(i).__name__.endswith("Coupling")]
    for inter in couplings:
        for hook in HOOKS:
            setattr(inter, hook, timer.wrap(getattr(inter, hook)))
    for part in s.parts:
        filters = getattr(part, "pair_filters", None)
        if filters:
            filters[:] = [timer.wrap(f) for f in filters]
    for _ in range(warmup):
        s.step()
    timer.seconds = 0.0
    t0 = time.perf_counter()
    for _ in range(steps):
        s.step()
    total = time.perf_counter() - t0
    return {"coupling": coupling, "steps": steps, "step_ms": 1e3 * total / steps,
            "coupling_ms": 1e3 * timer.seconds / steps,
            "share": timer.seconds / total, "n_couplings": len(couplings)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--divisions", default="80,4,4",
                    help="elements along, across and through the beam (160,8,8: "
                         "the example's mesh)")
    ap.add_argument("--threads", type=int, default=numba.config.NUMBA_NUM_THREADS)
    args = ap.parse_args(argv)
    numba.set_num_threads(args.threads)
    best: dict[str, dict] = {}
    for _ in range(args.repeat):
        for c in ("none", *COUPLINGS):
            r = time_steps(c, args.divisions, args.steps)
            if c not in best or r["step_ms"] < best[c]["step_ms"]:
                best[c] = r
    base = best["none"]["step_ms"]
    print(f"| model ({args.divisions}, {args.threads} threads) | ms per step | "
          "vs none | coupling's own share |")
    print("|---|---|---|---|")
    for c in ("none", *COUPLINGS):
        r = best[c]
        r["ratio"] = r["step_ms"] / base
        print(json.dumps(r))
        print(f"| {c} | {r['step_ms']:.3f} | {r['ratio']:.3f} | {100 * r['share']:.1f} % |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
