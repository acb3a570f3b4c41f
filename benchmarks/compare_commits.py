"""Side-by-side speed of two source trees (old commit against new), one run.

This VM's speed changes 2-3x from day to day, so a speed claim is a ratio
measured in one sitting. Each case runs in a fresh process per tree, the two
trees alternating so that a drift of the machine's speed hits both alike,
and taking turns to go first (A B, B A, A B, ...): the process run first in
a round was measured 10 % faster than the one after it, the same code in
both (session 40, BENCHMARKS.md), so a fixed order biases the ratio. The
best of the repeats is kept; give an even ``--repeats``. Usage::

    git worktree add /tmp/old 7e739c7
    python benchmarks/compare_commits.py /tmp/old/src src --repeats 4 > compare.md

Cases: ``sphdyn bench rings2d``, ``rings2d_tl``, ``block3d --particles
100000`` (particle-steps per second of the stepping alone) and the paper's
CSCM disc (``sphdyn run examples/disc_impact.toml --max-steps 150``,
particle-steps per second from its summary, output of the first frame
included in both), ``hex3d --elements 100000`` (element-steps per second), and the coarse
drop-weight beam in its impact (``benchmarks/profile_step.py`` on
``examples/dropweight_coarse.toml``, 300 steps after 2,000 untimed ones: the
ram meets the beam at about step 1,900; item-steps per second, the same deck
file for both trees), and the Forrestal penetration case at 10 mm elements
(``sphdyn run validation/cases/forrestal1994_ogive.toml`` with the coarse
target, 1,500 steps to 440 us: the projectile's tip 63 mm in, 224
elements eroded into particles; item-steps per second from its summary, the same deck file
for both trees); ``--cases`` picks some by name (comma-separated).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

CASES = [("rings2d", ["bench", "rings2d", "--steps", "500"]),
         ("rings2d_tl", ["bench", "rings2d_tl", "--steps", "500"]),
         ("block3d 100k", ["bench", "block3d", "--particles", "100000", "--steps", "30"]),
         ("CSCM disc", ["run", "examples/disc_impact.toml", "-q", "--max-steps", "150"]),
         ("hex3d 100k", ["bench", "hex3d", "--elements", "100000", "--steps", "100"]),
         ("HVI coarse impact", ["profile", "--deck", "examples/dropweight_coarse.toml",
                                "--start-steps", "2000", "--steps", "300"]),
         ("Forrestal 10 mm", ["run", "validation/cases/forrestal1994_ogive.toml", "-q",
                              "--set", "mesh.target.block.divisions=[30,30,36]",
                              "--set", "body.projectile.dx=0.00538",
                              "--set", "material.concrete.erosion.min_time_step=2.5e-7",
                              "--max-steps", "1500"])]

PROFILE = Path(__file__).resolve().parent / "profile_step.py"


def measure(src: str, args: list[str], threads: int) -> float:
    """Particle-steps per second of one fresh process running ``sphdyn args``."""
    env = dict(os.environ, PYTHONPATH=str(Path(src).resolve()))
    if args[0] == "profile":
        cmd = [sys.executable, str(PROFILE), *args[1:], "--threads", str(threads)]
        out = subprocess.run(cmd, check=True, capture_output=True, text=True, env=env)
        res = json.loads(out.stdout.strip().splitlines()[-1])
        return 1e9 / res["ns_per_item_step"]
    with tempfile.TemporaryDirectory() as tmp:
        extra = ["--out", tmp] if args[0] == "run" else []
        cmd = [sys.executable, "-m", "sphdyn", *args, *extra, "--threads", str(threads)]
        out = subprocess.run(cmd, check=True, capture_output=True, text=True, env=env)
        if args[0] == "run":
            summary = json.loads((Path(tmp) / "summary.json").read_text())
            return summary["particle_steps_per_s"]
    res = json.loads(out.stdout.strip().splitlines()[-1])
    return res.get("particle_steps_per_s", res.get("element_steps_per_s"))


def warm_up(args: list[str]) -> list[str]:
    """A short run of a case (a few steps, none untimed), to compile first."""
    if args[0] == "profile":
        return args[:args.index("--start-steps")] + ["--steps", "3"]
    return args[:-1] + ["5" if args[0] == "run" else "3"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("--repeats", type=int, default=4)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--cases", default=",".join(name for name, _ in CASES))
    a = ap.parse_args()
    chosen = a.cases.split(",")
    print("| case | old particle-steps/s | new particle-steps/s | new / old |")
    print("|---|---|---|---|")
    for name, args in [c for c in CASES if c[0] in chosen]:
        for src in (a.old, a.new):  # compile / fill the Numba caches first
            measure(src, warm_up(args), a.threads)
        best = {a.old: 0.0, a.new: 0.0}
        for r in range(a.repeats):  # each tree first in every other round
            for src in (a.old, a.new) if r % 2 == 0 else (a.new, a.old):
                best[src] = max(best[src], measure(src, args, a.threads))
        print(f"| {name} | {best[a.old]:.4g} | {best[a.new]:.4g} | "
              f"{best[a.new] / best[a.old]:.3f} |", flush=True)


if __name__ == "__main__":
    main()
