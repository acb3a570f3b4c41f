"""Share of the step time spent in the material update (CSCM on the paper's disc).

Runs a deck (default ``examples/disc_impact.toml``, the paper's concrete
disc, 10,112 particles, CSCM) for a fixed number of steps with the plain
:class:`sphdyn.stepper.Stepper` loop (no output), and times every material
group's ``update`` call separately from the rest of the step. The solver is
not modified: each ``MaterialGroup.model`` is replaced by a thin proxy whose
``update`` forwards to the registered kernel and accumulates its wall time
(the Numba kernels are synchronous, so the timing is exact up to the timer
resolution).

The first ``--warmup`` steps (default 1) are excluded from the timing (they
load the Numba cache / compile). The steps are counted from the start of
the run, so the default 600 steps (to about 150 us) cover the approach, the
impact and the damage phase of the disc.

Prints one JSON line: threads, particles, steps, simulated time, total and
material seconds, the material share overall and per quarter of the run,
and the material cost per particle and step.

Usage::

    python benchmarks/bench_material_share.py [--deck DECK] [--steps N]
        [--threads T] [--warmup W] [--set KEY=VALUE ...]
"""

from __future__ import annotations

import argparse
import json
import time

import numba

from sphdyn.deck import load_deck
from sphdyn.build import build_stepper
from sphdyn.build.model import build_model


class TimedModel:
    """Proxy of a :class:`~sphdyn.materials.base.MaterialModel` that times ``update``.

    Every other attribute is forwarded to the wrapped model.
    """

    def __init__(self, model):
        self._model = model
        self.seconds = 0.0
        self.calls = 0

    def __getattr__(self, name):
        return getattr(self._model, name)

    def update(self, *args):
        t0 = time.perf_counter()
        self._model.update(*args)
        self.seconds += time.perf_counter() - t0
        self.calls += 1


def measure(deck_path: str, steps: int, warmup: int = 1,
            overrides: list[str] | None = None) -> dict:
    """Run ``warmup + steps`` solver steps and return the timing record."""
    deck = load_deck(deck_path, overrides)
    model = build_model(deck)
    solver = build_stepper(deck, model)
    for _ in range(warmup):
        solver.step()
    timers = []
    for g in model.groups:
        g.model = TimedModel(g.model)
        timers.append(g.model)
    quarters = []
    total = 0.0
    mat_prev = 0.0
    q_len = max(steps // 4, 1)
    q_total = 0.0
    for k in range(steps):
        t0 = time.perf_counter()
        solver.step()
        dt = time.perf_counter() - t0
        total += dt
        q_total += dt
        if (k + 1) % q_len == 0 or k + 1 == steps:
            mat = sum(t.seconds for t in timers)
            quarters.append({"to_step": solver.step_count, "t_us": solver.t * 1e6,
                             "share": (mat - mat_prev) / q_total})
            mat_prev, q_total = mat, 0.0
    mat = sum(t.seconds for t in timers)
    n_mat = sum(len(g.idx) for g in model.groups)
    return {
        "deck": deck_path, "models": [g.model.name for g in model.groups],
        "threads": numba.get_num_threads(), "particles": solver.p.n,
        "steps": steps, "t_us": solver.t * 1e6,
        "step_seconds": total, "material_seconds": mat,
        "material_share": mat / total,
        "material_ns_per_particle_step": 1e9 * mat / (n_mat * steps),
        "step_ns_per_particle_step": 1e9 * total / (solver.p.n * steps),
        "max_damage_fraction_0p9": float((solver.p.damage > 0.9).mean()),
        "share_by_segment": quarters,
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--deck", default="examples/disc_impact.toml")
    ap.add_argument("--steps", type=int, default=600)
    ap.add_argument("--warmup", type=int, default=1)
    ap.add_argument("--threads", type=int, default=numba.config.NUMBA_NUM_THREADS)
    ap.add_argument("--set", action="append", metavar="KEY=VALUE")
    args = ap.parse_args(argv)
    numba.set_num_threads(args.threads)
    print(json.dumps(measure(args.deck, args.steps, args.warmup, args.set)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
