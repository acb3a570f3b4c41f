"""Study: a penalty coupling's strongest push, step by step (issue 53).

Runs a deck to ``--from`` (seconds), then ``--steps`` single steps, and prints
for each the particle with the largest acceleration from the coupling named
``--coupling`` (``[mesh.contact]`` of mesh NAME is ``NAME_contact``), with the
face it faced before and after the step, its signed depth there (``d_last``)
and its allowance (``pen0``) before and after (docs/theory.md, "SPH-FEM
coupling by penalty"). This found the same-face leap of the full Leppanen
fragment (docs/validation.md, "The fragment stops far too early"): at commit
40978c0, before the fix,

    PYTHONPATH=src python studies/contact_trace.py \\
        validation/cases/leppanen2004_fragment.toml --coupling block_contact \\
        --from 6.8e-6 --steps 4 --set material.concrete.damage_growth=loading

The run's energy guard only warns; nothing is written but the run folder.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np


def main(argv=None) -> int:
    from sphdyn.deck import load_deck
    from sphdyn.simulation import Simulation

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("deck")
    ap.add_argument("--coupling", required=True, help="the coupling's name")
    ap.add_argument("--from", dest="t_from", type=float, required=True, help="start [s]")
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--out", default="out/contact_trace")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    args = ap.parse_args(argv)
    deck = load_deck(args.deck, ['run.energy_error_action="warn"', "output.vtk=false",
                                 'output.every="1 s"', "output.checkpoint_every=0",
                                 "output.progress=false", *args.set])
    sim = Simulation.from_deck(deck, args.out)
    found = [ix for ix in sim.stepper.interactions if getattr(ix, "name", "") == args.coupling]
    if not found:
        names = [getattr(ix, "name", type(ix).__name__) for ix in sim.stepper.interactions]
        raise SystemExit(f"no coupling {args.coupling!r}; the deck has {names}")
    c = found[0]
    if not hasattr(c, "last_face"):
        raise SystemExit(f"{args.coupling!r} is a {type(c).__name__}, not a penalty coupling")
    sim.run(t_end=args.t_from, progress=False, threads=1)
    for _ in range(args.steps):
        face, depth, allowed = c.last_face.copy(), c.d_last.copy(), c.pen0.copy()
        sim.run(max_steps=1, progress=False, threads=1)
        acc = np.linalg.norm(c.accel, axis=1)
        if not acc.size or acc.max() == 0.0:
            print(f"t = {sim.stepper.t * 1e6:.4f} us: no particle pushed", flush=True)
            continue
        i = int(np.argmax(acc))
        print(f"t = {sim.stepper.t * 1e6:.4f} us: particle {i}, |a| {acc[i]:.3e} m/s^2, "
              f"face {face[i]} -> {c.last_face[i]}, depth {depth[i] * 1e3:.4f} -> "
              f"{c.d_last[i] * 1e3:.4f} mm, allowance {allowed[i] * 1e3:.4f} -> "
              f"{c.pen0[i] * 1e3:.4f} mm", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
