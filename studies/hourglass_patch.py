"""Study: a patch of elements' assembled hourglass damping against each element's (issue 53).

Restarts a run from its checkpoint (``RUN/checkpoint.h5``; nothing is
written) and takes ``--steps`` steps. Every ``--every`` steps it forms, with
NumPy, the viscous hourglass damping matrix ``C = sum_e a_h gamma^T gamma``
of every element sharing a node with ``--elements`` and prints the model's
E_total and ``dt lambda_max(M^-1 C)`` of the patch with the nodes' whole
masses (the explicit update of a damped mode is stable below 2), and, per element,
``dt lambda_max`` of its own damping with its nodes' whole masses and with
its own share ``m_e / nen`` of each (docs/theory.md, "The element step with
the hourglass control": only the shares bound the assembled number).

The numbers of docs/theory.md come from the full Forrestal target with the
code of 68efeb8 (``git worktree add OLD 68efeb8``, ``PYTHONPATH=OLD/src``):

    sphdyn run validation/cases/forrestal1994_ogive.toml --set run.t_end="165 us" --out RUN
    python studies/hourglass_patch.py RUN --elements 73499,73559,76499,76559 --steps 105

and, with the code after it, the same command (``--steps 350 --every 25``)
shows those four elements eroded in the first step and E_total after it.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np


def shape_vectors(part, e: int) -> tuple[np.ndarray, float]:
    """Element ``e``'s hourglass shape vectors ``gamma`` (modes, nen) at its
    current node positions and its viscous coefficient ``a_h`` [kg/s], formed
    with NumPy (sphdyn.parts.fem.solid.hourglass_coefficient)."""
    from sphdyn.parts.fem.solid import volume_gradient
    from sphdyn.parts.fem.hourglass import HG_VISCOUS, hourglass_coefficient, hourglass_face

    el, q, pts = part.el, part.nodes, part.pts
    conn = el.conn[e]
    xl = q.x[conn] - q.x[conn[0]]
    g = np.zeros((len(conn), 3))
    V = volume_gradient(xl, part.dim, part.tab, g)
    shape = part.gam - (part.gam @ xl / V) @ g.T
    coef = hourglass_coefficient(HG_VISCOUS, part.s.hourglass_coefficient, pts.rho[e],
                                 pts.c[e], hourglass_face(V, part.dim), 0.0, V, part.dim)
    return shape, coef


def element_damping(part, e: int) -> np.ndarray:
    """Viscous hourglass damping matrix (nen, nen) of element ``e`` (one
    component), ``a_h gamma^T gamma``."""
    shape, coef = shape_vectors(part, e)
    return coef * shape.T @ shape


def largest(C: np.ndarray, m: np.ndarray) -> float:
    """lambda_max(M^-1 C) with the diagonal masses ``m``."""
    s = 1.0 / np.sqrt(m)
    return float(np.linalg.eigvalsh(s[:, None] * C * s[None, :]).max())


def main(argv=None) -> int:
    from sphdyn.simulation import Simulation

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run", help="a run folder with checkpoint.h5")
    ap.add_argument("--mesh", default="target")
    ap.add_argument("--elements", required=True, help="comma-separated element indices")
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--every", type=int, default=10)
    args = ap.parse_args(argv)
    sim = Simulation.from_directory(args.run)
    st = sim.stepper
    part = next(p for p in st.parts if p.name == args.mesh)
    el, q = part.el, part.nodes
    chosen = [int(s) for s in args.elements.split(",")]
    patch = np.flatnonzero(np.isin(el.conn, np.unique(el.conn[chosen])).any(axis=1))
    for k in range(args.steps):
        st.step()
        if k % args.every and k < args.steps - 1:
            continue
        alive = [e for e in patch if el.active[e]]
        if not alive:
            print(f"t {st.t * 1e6:.3f} us, E_total {st.record()['E_total']:.1f} J: the "
                  "patch is eroded", flush=True)
            continue
        nodes = np.unique(el.conn[alive])
        where = {n: i for i, n in enumerate(nodes)}
        C = np.zeros((nodes.size, nodes.size))
        own = []
        for e in alive:
            Ce = element_damping(part, e)
            ii = [where[n] for n in el.conn[e]]
            C[np.ix_(ii, ii)] += Ce
            if e in chosen:
                own.append(f"{e}: {st.dt_step * largest(Ce, q.m[el.conn[e]]):.2f} whole / "
                           f"{st.dt_step * largest(Ce, np.full(el.nen, el.m[e] / el.nen)):.2f}"
                           " shares")
        print(f"t {st.t * 1e6:.3f} us, dt {st.dt_step * 1e9:.2f} ns, E_total "
              f"{st.record()['E_total']:.1f} J: patch of {len(alive)} "
              f"elements {st.dt_step * largest(C, q.m[nodes]):.2f}; "
              + ("; ".join(own) if own else "the chosen elements eroded"), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
