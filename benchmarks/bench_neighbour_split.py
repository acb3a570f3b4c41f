"""Neighbour builds where h varies: this tree against another, in one process.

The build (``_build_csr``) of this tree and of ``--old`` (another tree's
``src``; its ``sphdyn/neighbours`` package is copied to a temporary
directory and imported under another name) take turns ``--rounds`` times on
each state; best and median seconds, the ratio, whether the lists are the
same bit for bit, and the number of particles in the coarse grid (0: one
grid). Taking turns in one process lets a shared machine's slow moments hit
both alike.

States:
* ``lattice``: a cubic lattice of 46^3 particles, h = 1.2 dx, uniform;
* ``cloud2``: 100k random particles, h log-uniform over a factor 2;
* ``graded``: a bar whose spacing grows 10x along its length (h = 1.2 dx);
* ``--deck DECK --start S``: the deck's SPH particles after S steps (the
  first SPH part; e.g. ``examples/blast_slab.toml`` at 170: the products
  in flight), saved to ``--cache`` for the next run.

    python benchmarks/bench_neighbour_split.py --old /tmp/old/src
        [--deck examples/blast_slab.toml --start 170] [--rounds 8]
"""

from __future__ import annotations

import argparse
import importlib
import os
import shutil
import sys
import tempfile
import time

import numpy as np

import sphdyn.neighbours.build as new_build


def _lattice():
    g = np.arange(46) * 0.002
    x = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)
    return x, np.full(len(x), 0.0024), 2.0, 0.00024


def _cloud2():
    rng = np.random.default_rng(1)
    n = 100_000
    h = 0.1 / n ** (1 / 3) * 1.2 * 2.0 ** rng.random(n)
    return rng.random((n, 3)) * 0.1, h, 2.0, 0.0002


def _graded():
    xs = [0.0]
    while xs[-1] < 0.3:
        xs.append(xs[-1] + 0.001 * (1 + 9 * xs[-1] / 0.3))
    pts, hh = [], []
    for xi in xs:
        dx = 0.001 * (1 + 9 * xi / 0.3)
        m = max(1, int(0.03 / dx))
        yy, zz = np.meshgrid(np.linspace(0, 0.03, m), np.linspace(0, 0.03, m))
        pts.append(np.column_stack([np.full(m * m, xi), yy.ravel(),
                                    zz.ravel()]))
        hh.append(np.full(m * m, 1.2 * dx))
    return np.vstack(pts), np.concatenate(hh), 2.0, 0.0001


def _deck_state(deck, start, cache):
    if cache and os.path.exists(cache):
        d = np.load(cache)
        return d["x"], d["h"], float(d["rf"]), float(d["skin"]), d["act"]
    from sphdyn.build import build_stepper
    from sphdyn.deck import load_deck
    st = build_stepper(load_deck(deck, ["output.vtk=false"]))
    for _ in range(start):
        st.step()
    sph = next(p for p in st.parts if hasattr(p, "nl"))
    act = (np.ones(sph.p.h.shape[0], bool) if sph.ul_active is None
           else np.asarray(sph.ul_active, bool))
    out = (sph.p.x.copy(), sph.p.h.copy(), sph.nl.radius_factor,
           sph.nl.skin, act)
    if cache:
        os.makedirs(os.path.dirname(os.path.abspath(cache)), exist_ok=True)
        np.savez(cache, x=out[0], h=out[1], rf=out[2], skin=out[3],
                 act=out[4])
    return out


def _old_module(src):
    tmp = tempfile.mkdtemp()
    shutil.copytree(os.path.join(src, "sphdyn", "neighbours"),
                    os.path.join(tmp, "old_neighbours"),
                    ignore=shutil.ignore_patterns("__pycache__"))
    sys.path.insert(0, tmp)
    return importlib.import_module("old_neighbours.build")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--old", required=True, help="another tree's src")
    ap.add_argument("--deck")
    ap.add_argument("--start", type=int, default=170)
    ap.add_argument("--cache", default="out/neighbour_state.npz")
    ap.add_argument("--rounds", type=int, default=8)
    a = ap.parse_args()
    old_build = _old_module(a.old)
    states = {"lattice": _lattice(), "cloud2": _cloud2(),
              "graded": _graded()}
    if a.deck:
        states[f"{os.path.basename(a.deck)} @ {a.start}"] = _deck_state(
            a.deck, a.start, a.cache)
    print("| state | particles | old best / median [s] | new best / median "
          "[s] | old / new (best) | same list | coarse grid |")
    print("|---|---|---|---|---|---|---|")
    for name, st in states.items():
        x, h, rf, skin = st[:4]
        act = st[4] if len(st) > 4 and not np.all(st[4]) else None
        t = {"old": [], "new": []}
        for m in (old_build, new_build):  # compile or load the cache
            m._build_csr(x, h, act, rf, skin, 3)
        for _ in range(a.rounds):
            for key, m in (("old", old_build), ("new", new_build)):
                t0 = time.perf_counter()
                m._build_csr(x, h, act, rf, skin, 3)
                t[key].append(time.perf_counter() - t0)
        o = old_build._build_csr(x, h, act, rf, skin, 3)
        n = new_build._build_csr(x, h, act, rf, skin, 3)
        same = np.array_equal(o[0], n[0]) and np.array_equal(o[1], n[1])
        bo, bn = min(t["old"]), min(t["new"])
        print(f"| {name} | {x.shape[0]:,} | {bo:.3f} / "
              f"{np.median(t['old']):.3f} | {bn:.3f} / "
              f"{np.median(t['new']):.3f} | {bo / bn:.2f} | {same} | "
              f"{n[4]} |")


if __name__ == "__main__":
    main()
