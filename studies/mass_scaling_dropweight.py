"""What selective mass scaling costs on the RC drop-weight beam (docs/validation.md,
"Mass scaling on the drop-weight beam").

The Lozano & Makdesi beam from 2.5 m (``sphdyn validate lozano2017_dropweight_2.5m``)
is run with and without ``[time.mass_scaling]`` at the quick (dx 10 mm) and the
full (dx 6.25 mm) spacing. The step is set by the bars' sublayer particles
(steel, h = 1.2 times the bar's element); the scaling gives them, and the
bars and supports, the mass that brings them to the next limit: the drop
weight's elements at the quick spacing (0.75 us; the drop weight is left out:
mass added to it would add to the energy it brings), the concrete at the full
(0.62 us). Prints each run's steps, added mass and compared numbers, and draws
the mid-span deflection against the measured DIC points into
docs/figures/mass_scaling_dropweight.png.

    PYTHONPATH=src python studies/mass_scaling_dropweight.py --out OUT [--quick-only]

Runs what is not in OUT yet (``sphdyn validate --reuse``): about 10 minutes for
the quick pair, 70 for the full pair on 2 cores.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CASE = "lozano2017_dropweight_2.5m"
SCALED = ("bar_b1_sublayer", "bar_b2_sublayer", "bar_t1_sublayer", "bar_t2_sublayer",
          "bar_b1", "bar_b2", "bar_t1", "bar_t2", "support_left", "support_right")
TARGET = {True: "0.75us", False: "0.62us"}  # quick: the drop weight's step; full: the concrete's


def settings(quick: bool) -> list[str]:
    """The ``--set`` arguments of the scaled run."""
    parts = "[" + ",".join(f'"{p}"' for p in SCALED) + "]"
    return [f"time.mass_scaling.target={TARGET[quick]}", f"time.mass_scaling.parts={parts}",
            "time.mass_scaling.max_added=0.05"]


def run(out: Path, quick: bool, scaled: bool) -> Path:
    """The run directory of one variant (run by ``sphdyn validate`` unless done)."""
    where = out / ("scaled" if scaled else "plain")
    cmd = [sys.executable, "-m", "sphdyn", "validate", CASE, "--out", str(where), "--reuse"]
    if quick:
        cmd.append("--quick")
    for s in settings(quick) if scaled else []:
        cmd += ["--set", s]
    subprocess.run(cmd, check=True, cwd=ROOT, stdout=subprocess.DEVNULL)  # its table: below
    return where / (CASE + ("-quick" if quick else ""))


def main() -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from sphdyn.validation import data
    from sphdyn.validation.measures import deflection_history

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--quick-only", action="store_true")
    args = ap.parse_args()
    spacings = (True,) if args.quick_only else (True, False)
    fig, ax = plt.subplots(figsize=(7, 4.2))
    print("| spacing | mass scaling | steps | added mass (share of the model) "
          "| largest deflection [mm] | its time [ms] |")
    print("|---|---|---|---|---|---|")
    for quick in spacings:
        for scaled in (False, True):
            d = run(args.out, quick, scaled)
            summary = json.loads((d / "summary.json").read_text())
            t, u = deflection_history(d, "midspan", "rod")  # after the contact's start
            w = 1e3 * u
            k = int(np.argmax(w))
            ms = summary.get("mass_scaling")
            added = "-" if ms is None else \
                f"{sum(p['added_kg'] for p in ms['parts'].values()):.3g} kg " \
                f"({100 * ms['fraction']:.2g} %)"
            label = (f"dx {'10' if quick else '6.25'} mm, "
                     + (f"mass-scaled to {TARGET[quick]}" if scaled else "no mass scaling"))
            print(f"| {'quick, dx 10 mm' if quick else 'full, dx 6.25 mm'} | "
                  f"{TARGET[quick] if scaled else 'off'} | {summary['steps']} | {added} "
                  f"| {w[k]:.2f} | {1e3 * t[k]:.2f} |")
            ax.plot(1e3 * t, w, ("--" if scaled else "-"),
                    color="tab:orange" if quick else "tab:blue", label=label)
    table = data.read(ROOT / "validation/data/lozano2017_dropweight_deflection_history.csv")
    pts = [r for r in table.rows if r["drop_height_m"] == "2.5"]
    ax.plot([data.number(r, "t_ms") for r in pts], [data.number(r, "u_mm") for r in pts],
            "ko", ms=3, mfc="none", label="measured, DIC (Lozano & Makdesi 2017, App. F)")
    ax.set_xlabel("time after impact [ms]")
    ax.set_ylabel("mid-span deflection [mm]")
    ax.set_title("Drop weight from 2.5 m: with and without selective mass scaling")
    ax.legend(fontsize=8)
    fig.tight_layout()
    target = ROOT / "docs/figures/mass_scaling_dropweight.png"
    fig.savefig(target, dpi=110)
    print(f"wrote {target}")


if __name__ == "__main__":
    main()
