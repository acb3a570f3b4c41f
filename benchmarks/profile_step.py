"""Where the step time goes: wall time of every Numba kernel called from Python.

Builds a deck's stepper (the code a user's run executes, without output),
runs ``--warmup`` steps (they load the Numba caches / compile), then replaces
every Numba dispatcher bound in a ``sphdyn`` module by a timing wrapper and
runs ``--steps`` more. Numba kernels are synchronous, so the time of a call
is the kernel's (parallel regions included); kernels calling kernels are
compiled together and count as their caller. What no kernel accounts for is
Python (the stepper, the parts' methods, NumPy calls): reported as
``python (rest)``.

Prints a Markdown table: kernel, calls, seconds, share of the stepping,
nanoseconds per particle-step (per item-step of all parts), and a JSON line
with the totals. The warm-up should cover a neighbour rebuild, else a kernel
compiled later would see the wrapper instead of a kernel (Numba refuses it).

Usage::

    python benchmarks/profile_step.py [--deck DECK] [--steps N] [--warmup W]
        [--threads T] [--start-steps S] [--set KEY=VALUE ...] [--hex3d ELEMENTS]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections import defaultdict

import numba
from numba.core.registry import CPUDispatcher

try:  # the tree measured may be older than the builders (compare_commits.py)
    from sphdyn.build import build_stepper
except ImportError:
    from sphdyn.assembly import build_stepper
from sphdyn.bench import hex3d_stepper
from sphdyn.deck import load_deck


def _items(stepper) -> int:
    return sum(part.kin.n for part in stepper.parts)


class _TimedModel:
    """A material model whose ``update`` (a kernel held by the model) is timed."""

    def __init__(self, model, timed_update):
        self._model = model
        self.update = timed_update

    def __getattr__(self, name):
        return getattr(self._model, name)


def instrument(stepper) -> dict:
    """Replace every dispatcher bound in a loaded ``sphdyn`` module, and the
    material groups' ``update`` kernels of the parts; return the tallies."""
    tally: dict = defaultdict(lambda: [0, 0.0])

    def wrap(name, fn):
        def timed(*args, **kw):
            t0 = time.perf_counter()
            out = fn(*args, **kw)
            rec = tally[name]
            rec[0] += 1
            rec[1] += time.perf_counter() - t0
            return out
        return timed

    for modname, mod in list(sys.modules.items()):
        if not modname.startswith("sphdyn") or mod is None:
            continue
        for attr, obj in list(vars(mod).items()):
            if isinstance(obj, CPUDispatcher):
                name = f"{obj.py_func.__module__.removeprefix('sphdyn.')}.{obj.__name__}"
                setattr(mod, attr, wrap(name, obj))
    for part in stepper.parts:
        for g in getattr(part, "groups", ()):
            name = f"material {g.model.name} ({part.name})"
            g.model = _TimedModel(g.model, wrap(name, g.model.update))
    return tally


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--deck", default="examples/disc_impact.toml")
    ap.add_argument("--hex3d", type=int, metavar="ELEMENTS",
                    help="profile `sphdyn bench hex3d` of about ELEMENTS elements instead")
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--warmup", type=int, default=5)
    ap.add_argument("--start-steps", type=int, default=0,
                    help="untimed steps before the warm-up (reach the impact first)")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    a = ap.parse_args()
    numba.set_num_threads(a.threads)
    if a.hex3d:
        stepper = hex3d_stepper(a.hex3d)
        a.deck = f"bench hex3d ({a.hex3d} elements)"
    else:
        stepper = build_stepper(load_deck(a.deck, overrides=a.set))
    for _ in range(a.start_steps + a.warmup):
        stepper.step()
    tally = instrument(stepper)
    t0 = time.perf_counter()
    for _ in range(a.steps):
        stepper.step()
    total = time.perf_counter() - t0
    n = _items(stepper)
    per = 1e9 / (n * a.steps)
    rows = sorted(tally.items(), key=lambda kv: -kv[1][1])
    print(f"deck {a.deck}, {n} items, {a.steps} steps from step {stepper.step_count - a.steps},"
          f" {a.threads} threads, {total:.3f} s\n")
    print("| kernel | calls | s | share | ns per item-step |")
    print("|---|---|---|---|---|")
    kern = 0.0
    for name, (calls, s) in rows:
        kern += s
        print(f"| {name} | {calls} | {s:.3f} | {100 * s / total:.1f} % | {s * per:.0f} |")
    rest = total - kern
    print(f"| python (rest) | | {rest:.3f} | {100 * rest / total:.1f} % | {rest * per:.0f} |")
    print(json.dumps({"deck": a.deck, "items": n, "steps": a.steps, "threads": a.threads,
                      "seconds": total, "ns_per_item_step": total * per}))


if __name__ == "__main__":
    main()
