"""Run the speed benchmarks through ``sphdyn bench`` and print a Markdown table.

Each case runs in a fresh process (so thread counts and compilation are
clean); the JSON line printed by ``sphdyn bench`` is collected. Usage::

    python benchmarks/run_benchmarks.py [--quick] > bench.md

``--quick`` runs fewer steps and skips the 1M-particle case.
"""

from __future__ import annotations

import argparse
import json
import platform
import subprocess
import sys


def bench(case, steps, threads, particles=None):
    cmd = [sys.executable, "-m", "sphdyn", "bench", case, "--steps", str(steps),
           "--threads", str(threads)]
    if particles:
        cmd += ["--particles", str(particles)]
    out = subprocess.run(cmd, check=True, capture_output=True, text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    runs = [("rings2d", 1000, None), ("rings2d_tl", 1000, None), ("block3d", 200, 10_000), ("block3d", 50, 100_000),
            ("block3d", 10, 1_000_000)]
    if args.quick:
        runs = [("rings2d", 100, None), ("rings2d_tl", 100, None), ("block3d", 20, 10_000)]
    print(f"machine: {platform.processor() or platform.machine()}, "
          f"{platform.system()} {platform.release()}, python {platform.python_version()}")
    print()
    print("| case | particles | threads | steps | seconds | compile s | "
          "particle-steps/s | neighbours | peak RSS MB | bytes/particle |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for case, steps, n in runs:
        for threads in (1, 2):
            r = bench(case, steps, threads, n)
            print(f"| {r['case']} | {r['particles']} | {r['threads']} | {r['steps']} | "
                  f"{r['seconds']:.2f} | {r['compile_seconds']:.1f} | "
                  f"{r['particle_steps_per_s']:.3g} | {r['neighbours_mean']:.1f} | "
                  f"{r['peak_rss_mb']:.0f} | {r['bytes_per_particle']:.0f} |", flush=True)


if __name__ == "__main__":
    main()
