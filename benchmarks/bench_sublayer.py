"""What a sublayer bar adds to the cost of an SPH model (issue 16).

``examples/pullout_sublayer.toml`` (a CSCM block, a bar coupled by its
nodes' particles) is stepped with the bar and, for comparison, without it
(the [[mesh]], its sets and boundaries removed; the block is the same). Runs
alternate in one process, best of ``--repeat``. Reported: the step time, the
stable step (the bar's particles have the steel's moduli at the concrete's
density and may set it), and so the cost per simulated microsecond.

    python benchmarks/bench_sublayer.py [--steps 300] [--repeat 3] [--threads T]
        [--dx "6 mm"]
"""

from __future__ import annotations

import argparse
import json
import re
from pathlib import Path

import numba
from interleaved import best_step_times

from sphdyn.build import build_stepper
from sphdyn.deck import loads_deck

DECK = Path(__file__).resolve().parents[1] / "examples" / "pullout_sublayer.toml"


def without_bar(text: str) -> str:
    """The deck with the bar, its sets and boundaries taken out."""
    text = re.sub(r"\[\[mesh\]\].*?(?=\[\[set\]\])", "", text, flags=re.S)
    for name in ("grip", "free_end"):
        text = re.sub(r'\[\[set\]\]\nname = "%s".*?(?=\[\[)' % name, "", text, flags=re.S)
    return re.sub(r'\[\[boundary\]\]\nset = "grip".*?(?=\[output\])', "", text, flags=re.S)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=300)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--threads", type=int, default=None)
    ap.add_argument("--dx", default="6 mm")
    a = ap.parse_args()
    if a.threads:
        numba.set_num_threads(a.threads)
    text = DECK.read_text().replace('dx = "6 mm"', f'dx = "{a.dx}"')
    models = {"with bar": build_stepper(loads_deck(text)),
              "without bar": build_stepper(loads_deck(without_bar(text)))}
    for st in models.values():
        for _ in range(3):
            st.step()
    best = best_step_times(models, a.steps, a.repeat)
    out = {}
    for name, st in models.items():
        n = st.part("sph").p.n
        out[name] = {"model": name, "particles": n, "ms_per_step": 1e3 * best[name],
                     "dt": st.dt_prev, "ms_per_simulated_us": 1e3 * best[name] / (
                         st.dt_prev * 1e6), "threads": numba.get_num_threads()}
        print(json.dumps(out[name]))
    w, wo = out["with bar"], out["without bar"]
    print(f"step time x{w['ms_per_step'] / wo['ms_per_step']:.3f}, step length "
          f"x{w['dt'] / wo['dt']:.3f}, cost per simulated time "
          f"x{w['ms_per_simulated_us'] / wo['ms_per_simulated_us']:.3f}")


if __name__ == "__main__":
    main()
