"""Study: where a mesh's hourglass work comes from, step by step (issue 53).

Restarts a run from its checkpoint (``RUN/checkpoint.h5``, written with
``output.checkpoint_every > 0`` or at the end of a run stopped by
``run.t_end``; the copy runs in ``RUN_trace``, the energy guard only warns)
and takes ``--steps`` single steps. For each it prints, for mesh ``--mesh``,
the element whose hourglass work grew the most: its volume over the initial
one, its damage, the trace of the Gram matrix of its Flanagan-Belytschko
shape vectors (``nen`` x modes for an undistorted element: 32 for a hex8)
and the stability number of its viscous hourglass force, ``dt a_h
lambda_max / m`` (the largest eigenvalue of ``M^-1/2 C M^-1/2`` of the
element's own hourglass damping matrix with its nodes' whole masses, as
the element step of 68efeb8 took them (only each element's shares bound the
assembled number: studies/hourglass_patch.py), times the step: the explicit
update of a mode is stable below 2 without the element's own stiffness; docs/theory.md, "The element step with the
hourglass control"); and, for every element eroded in the
step, its points' work and its hourglass work, and the internal energy of
the particles it became; and the step's change of the model's E_total and
E_kinetic.

This found why the Forrestal target made energy (docs/validation.md):

    sphdyn run validation/cases/forrestal1994_ogive.toml \\
        --set "mesh.target.block.divisions=[30,30,36]" \\
        --set body.projectile.dx=0.00538 --set output.every="10 us" \\
        --set run.t_end="340 us" --out out/forrestal_coarse
    python studies/hourglass_trace.py out/forrestal_coarse --steps 14

both with the code of 289a237, before the hourglass step (``git worktree add
OLD 289a237``, then ``PYTHONPATH=OLD/src`` for both commands); and the full
version's eroded elements carrying their hourglass work, with the code of
e4213d4 (the two limits taken apart; ``--set run.t_end="178 us" --set
output.checkpoint_every=200`` on the deck, then ``--steps 20``).
"""

from __future__ import annotations

import argparse
import shutil
import sys
from pathlib import Path

import numpy as np


def stability_number(part, e: int, dt: float) -> tuple[float, float]:
    """Trace of the Gram matrix of element ``e``'s shape vectors, and ``dt``
    times the largest eigenvalue of its viscous hourglass damping with its
    nodes' masses (module docstring), both formed with NumPy."""
    from hourglass_patch import largest, shape_vectors

    shape, coef = shape_vectors(part, e)
    damping = coef * shape.T @ shape
    return float(np.sum(shape * shape)), dt * largest(damping, part.nodes.m[part.el.conn[e]])


def main(argv=None) -> int:
    from sphdyn.simulation import Simulation

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run", help="a run folder with checkpoint.h5")
    ap.add_argument("--mesh", default="target")
    ap.add_argument("--steps", type=int, default=20)
    args = ap.parse_args(argv)
    src = Path(args.run)
    dst = src.with_name(src.name + "_trace")
    if dst.exists():
        shutil.rmtree(dst)
    shutil.copytree(src, dst)
    deck = dst / "deck.resolved.toml"
    deck.write_text(deck.read_text().replace('energy_error_action = "stop"',
                                             'energy_error_action = "warn"'))
    sim = Simulation.from_directory(dst)
    st = sim.stepper
    part = next(p for p in st.parts if p.name == args.mesh)
    el, pts = part.el, part.pts
    p = next((q.kin for q in st.parts if q.name == "sph"), None)  # the particles, if any
    books = st.record()
    for _ in range(args.steps):
        e_hg, active = el.e_hg.copy(), el.active.copy()
        work = (pts.m * pts.e).reshape(el.n, part.ngp).sum(axis=1)
        alive = p.active.astype(bool) if p is not None else None
        sim.run(t_end=st.t + 1.0, max_steps=1, progress=False)
        k = int(np.argmax(el.e_hg - e_hg))
        trace, number = stability_number(part, k, st.dt_step)
        r = st.record()
        print(f"t {st.t * 1e6:.3f} us: element {k} hourglass work +{el.e_hg[k] - e_hg[k]:.3g} J "
              f"(in all {el.e_hg.sum():.1f} J), V/V0 {el.vol[k] / el.vol0[k]:.3f}, damage "
              f"{pts.damage[k * part.ngp]:.3f}, Gram trace {trace:.1f}, dt a_h lambda/m "
              f"{number:.2f}; E_total {r['E_total'] - books['E_total']:+.1f} J, E_kinetic "
              f"{r['E_kinetic'] - books['E_kinetic']:+.1f} J", flush=True)
        books = r
        for e in np.flatnonzero((active == 1) & (el.active == 0)):
            print(f"    eroded {e}: its work {work[e]:.1f} J, hourglass work {e_hg[e]:.1f} J",
                  flush=True)
        if p is not None:
            now = p.active.astype(bool)
            born = now.copy()
            born[:alive.size] &= ~alive  # (the arrays may have grown)
            if born.any():
                print(f"    {born.sum()} particles born, internal energy "
                      f"{np.sum(p.m[born] * p.e[born]):.1f} J", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
