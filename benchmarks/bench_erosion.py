"""What the erosion check adds to the step time of a solid part (issue 16).

The ``hex3d`` benchmark block (``sphdyn bench hex3d``: one-point hex8 on a
rigid wall) is stepped with and without an
:class:`~sphdyn.events.ElementErosion` whose rules never hold, so what is
timed is the check itself, per element and step: with ``--rule effective``
(an effective strain of 10) the deformation gradient and the principal
stretches of every element; with ``--rule principal`` (a principal strain of
0.5) the deformation gradient and a bound that spares the stretches of
elements far from the limit. (The damage rule, MAT_159's ERODE, looks at
the strains of elements with damage above 0.99 only.) Runs alternate (without, with, without, ...) in one process and
the best of ``--repeat`` is kept per model, so a slow moment of a shared
machine does not land on one model only.

Prints one JSON line per model and the ratio::

    python benchmarks/bench_erosion.py [--elements 100000] [--steps 50]
        [--repeat 3] [--every 1] [--rule principal|effective] [--threads T]
"""

from __future__ import annotations

import argparse
import json

import numba
from interleaved import best_step_times

from sphdyn.bench import hex3d_stepper
from sphdyn.events import ElementErosion, ErosionRules


def stepper(elements: int, eroding: bool, every: int, rule: str):
    st = hex3d_stepper(elements)
    if eroding:
        part = st.parts[0]
        rules = {0: (ErosionRules(effective_strain=10.0) if rule == "effective"
                     else ErosionRules(principal_strain=0.5))}
        st.events.append(ElementErosion("erosion", part, rules, to="nothing", every=every))
    for _ in range(3):  # compiled and warm
        st.step()
    return st


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elements", type=int, default=100_000)
    ap.add_argument("--steps", type=int, default=50)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--every", type=int, default=1)
    ap.add_argument("--rule", choices=("principal", "effective"), default="principal")
    ap.add_argument("--threads", type=int, default=None)
    a = ap.parse_args()
    if a.threads:
        numba.set_num_threads(a.threads)
    models = {"none": stepper(a.elements, False, a.every, a.rule),
              "erosion": stepper(a.elements, True, a.every, a.rule)}
    best = best_step_times(models, a.steps, a.repeat)
    n = models["none"].parts[0].el.n
    for name, t in best.items():
        print(json.dumps({"model": name, "elements": n, "ms_per_step": 1e3 * t,
                          "threads": numba.get_num_threads(), "every": a.every}))
    print(f"erosion check adds {100 * (best['erosion'] / best['none'] - 1):+.1f} % "
          f"to the step ({n} elements, {a.rule} strain rule, checked every "
          f"{a.every} step(s))")


if __name__ == "__main__":
    main()
