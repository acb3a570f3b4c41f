"""Thesis sec. 6.1: a bar pulled out of a concrete block through the sublayer coupling.

Runs examples/pullout_sublayer.toml at three mass ratios (the particles'
share of the bar's mass: 0.25, 0.5, 0.75; or reuses out/pullout_sublayer_r*
with --reuse) and writes

* docs/figures/pullout_sublayer.png: the pull force against the pulled end's
  displacement and against the free end's slip, the three ratios;
* a table (stdout, markdown): peak force, the SPH step, the energy error,
  the bond force against the pull at the peak.

    python examples/pullout_sublayer.py [--reuse]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
RATIOS = (0.25, 0.5, 0.75)


def run(ratio: float, reuse: bool) -> Path:
    """Run the deck at one mass ratio (unless ``reuse`` finds it); its output folder."""
    from sphdyn.simulation import run_deck

    out = ROOT / "out" / f"pullout_sublayer_r{ratio:g}"
    run_deck(ROOT / "examples" / "pullout_sublayer.toml", out,
             [f"mesh.bar.sublayer.mass_ratio={ratio}"], reuse=reuse, progress=True)
    return out


def end_displacements(out: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Frame times [s], the pulled end's and the free end's x displacement [m]."""
    from sphdyn.io import read_frame_meshes
    from sphdyn.io.hdf5 import read_frame_header

    t, pulled, free = [], [], []
    for path in sorted((out / "frames").glob("frame_*.h5")):
        bar = read_frame_meshes(path)["bar"]
        x0 = bar.points[:, 0] - bar.point_data["displacement"][:, 0]
        t.append(read_frame_header(path)[0])
        pulled.append(bar.point_data["displacement"][np.argmax(x0), 0])
        free.append(bar.point_data["displacement"][np.argmin(x0), 0])
    return np.array(t), np.array(pulled), np.array(free)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reuse", action="store_true", help="reuse out/pullout_sublayer_r*")
    a = ap.parse_args()
    import json

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from sphdyn.io import read_history_csv

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    rows = []
    for r in RATIOS:
        out = run(r, a.reuse)
        h = read_history_csv(out / "history.csv")
        t, pulled, free = end_displacements(out)
        force = np.interp(t, h["time"], h["grip_reaction_x"])
        ax1.plot(1e3 * pulled, 1e-3 * force, marker=".", label=f"mass ratio {r:g}")
        ax2.plot(1e3 * free, 1e-3 * force, marker=".", label=f"mass ratio {r:g}")
        k = int(np.argmax(h["grip_reaction_x"]))
        summary = json.loads((out / "summary.json").read_text())
        rows.append((r, h["grip_reaction_x"][k], -h["F_bar_sublayer_x"][k], h["dt"][k],
                     summary["energy_error_max_rel"], summary["steps"]))
    for ax, what in ((ax1, "pulled end's displacement"), (ax2, "free end's slip")):
        ax.set_xlabel(f"{what} [mm]")
        ax.set_ylabel("pull force [kN]")
        ax.legend(fontsize=8)
    fig.suptitle("Bar pulled out of a CSCM block, sublayer coupling (thesis 6.1)")
    fig.tight_layout()
    figures = ROOT / "docs" / "figures"
    figures.mkdir(parents=True, exist_ok=True)
    fig.savefig(figures / "pullout_sublayer.png", dpi=130)
    print("| mass ratio | peak pull [kN] | bond force at the peak [kN] | SPH step [s] | "
          "steps | energy error (max, rel.) |")
    print("|---|---|---|---|---|---|")
    for r, peak, bond, dt, err, steps in rows:
        print(f"| {r:g} | {1e-3 * peak:.1f} | {1e-3 * bond:.1f} | {dt:.3g} | {steps} | "
              f"{err:.3f} |")


if __name__ == "__main__":
    main()
