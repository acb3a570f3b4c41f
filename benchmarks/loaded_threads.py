"""Threads on a loaded machine: particle-steps/s at 1 and 2 threads, idle and with
a competing CPU-bound process, for several threading set-ups.

Each measurement is a fresh ``sphdyn run`` process (the Numba cache warm from a
first untimed run), and the run's own ``particle_steps_per_s`` (stepping only,
no start-up) is read from its summary. Configurations alternate so a drift of
the machine's speed spreads over all of them; the best of ``--repeat`` is kept.

    python benchmarks/loaded_threads.py --steps 150 --repeat 3 \
        --config default --config "OMP_WAIT_POLICY=passive"

A configuration is ``name`` or ``KEY=VALUE[;KEY=VALUE]`` environment settings;
``default`` is the environment as it is. ``--threads auto`` runs without
``--threads`` (the default a user gets).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DECK = ROOT / "examples" / "disc_impact.toml"

HOG = "import time\nwhile True:\n    pass\n"


def run_once(env_extra: dict, threads: str, steps: int, deck: Path) -> float:
    env = dict(os.environ, **env_extra)
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [sys.executable, "-m", "sphdyn", "run", str(deck), "--out", tmp,
               "--max-steps", str(steps), "-q"]
        if threads != "auto":
            cmd += ["--threads", threads]
        subprocess.run(cmd, env=env, check=True, capture_output=True, text=True)
        summary = json.loads((Path(tmp) / "summary.json").read_text())
    return float(summary["particle_steps_per_s"])


def parse_config(text: str) -> tuple[str, dict]:
    if text == "default":
        return text, {}
    env = dict(item.split("=", 1) for item in text.split(";") if item)
    return text, env


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=150)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--config", action="append", default=None)
    ap.add_argument("--threads", action="append", default=None,
                    help="1, 2 or auto (repeatable; default 1, 2, auto)")
    ap.add_argument("--deck", default=str(DECK))
    args = ap.parse_args(argv)
    configs = [parse_config(c) for c in (args.config or ["default"])]
    threads = args.threads or ["1", "2", "auto"]
    deck = Path(args.deck)
    for _, env in configs:  # warm the cache of each set-up, untimed
        run_once(env, "1", 5, deck)
    best: dict = {}
    for load in ("idle", "loaded"):
        hog = (subprocess.Popen([sys.executable, "-c", HOG]) if load == "loaded"
               else None)
        try:
            if hog is not None:
                time.sleep(1.0)
            for _ in range(args.repeat):
                for name, env in configs:
                    for t in threads:
                        r = run_once(env, t, args.steps, deck)
                        key = (load, name, t)
                        best[key] = max(best.get(key, 0.0), r)
        finally:
            if hog is not None:
                hog.kill()
                hog.wait()
    print(f"{'load':8} {'configuration':40} {'threads':>7} {'particle-steps/s':>17}")
    for (load, name, t), r in best.items():
        print(f"{load:8} {name:40} {t:>7} {r:17.4g}")


if __name__ == "__main__":
    main()
