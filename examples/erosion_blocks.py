"""Thesis sec. 5.3 (Fig. 5.3): three models of a concrete block striking a rigid surface.

Runs examples/erosion_blocks_{fem,plain,sph}.toml (or reuses their output in
out/erosion_blocks_*/ with --reuse) and writes

* docs/figures/erosion_blocks_energies.png: kinetic energy and the energy
  still in the model (E_total minus what plain erosion removed), and the
  mass in the model, against time, the three models on each plot;
* docs/figures/erosion_blocks_side.png: the three blocks seen from the side
  at the end: remaining elements (centres, grey) and particles (red);
* a table (stdout, markdown): eroded elements, mass and energies at the end,
  and the kinetic energy against the model without erosion.

    python examples/erosion_blocks.py [--reuse]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
MODELS = ("fem", "plain", "sph")
LABELS = {"fem": "FEM, no erosion (reference)", "plain": "FEM, plain erosion",
          "sph": "FEM, erosion into SPH"}
COLOURS = {"fem": "black", "plain": "tab:orange", "sph": "tab:blue"}
MASS = 2400.0 * 0.1 ** 3  # the cube's mass [kg]


def run(model: str, reuse: bool) -> Path:
    """Run one deck (unless ``reuse`` and its output exists); its output folder."""
    from sphdyn.simulation import run_deck

    out = ROOT / "out" / f"erosion_blocks_{model}"
    run_deck(ROOT / "examples" / f"erosion_blocks_{model}.toml", out, reuse=reuse,
             progress=True)
    return out


def books(h: dict) -> dict:
    """Time [ms], kinetic energy and energy in the model [kJ], mass in the model [kg]."""
    removed = h.get("E_removed", np.zeros_like(h["time"]))
    lost = h.get("m_eroded_block", np.zeros_like(h["time"]))
    return {"t": 1e3 * h["time"], "ke": 1e-3 * h["E_kinetic"],
            "e": 1e-3 * (h["E_total"] - removed), "m": MASS - lost,
            "eroded": h.get("eroded_block", np.zeros_like(h["time"]))}


def side_view(ax, out: Path, title: str) -> None:
    """Remaining element centres and particles of the last frame, seen along y."""
    from sphdyn.io import read_frame, read_frame_meshes

    path = sorted((out / "frames").glob("frame_*.h5"))[-1]
    _, _, fields, _ = read_frame(path)
    mesh = read_frame_meshes(path)["block"]
    centres = mesh.points[mesh.cells].mean(axis=1)
    ax.scatter(1e3 * centres[:, 0], 1e3 * centres[:, 2], s=6, c="0.5", label="elements")
    x = fields["position"]
    if len(x):
        ax.scatter(1e3 * x[:, 0], 1e3 * x[:, 2], s=6, c="tab:red", label="particles")
    ax.axhline(0.0, color="k", lw=1)
    ax.set_title(title, fontsize=9)
    ax.set_xlabel("x [mm]")
    ax.set_aspect("equal")
    ax.set_xlim(-120, 220)
    ax.set_ylim(-5, 120)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reuse", action="store_true", help="reuse out/erosion_blocks_*")
    a = ap.parse_args()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from sphdyn.io import read_history_csv

    outs = {m: run(m, a.reuse) for m in MODELS}
    b = {m: books(read_history_csv(outs[m] / "history.csv")) for m in MODELS}
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    for m in MODELS:
        ax1.plot(b[m]["t"], b[m]["ke"], color=COLOURS[m], ls="-", label=f"{LABELS[m]}: kinetic")
        ax1.plot(b[m]["t"], b[m]["e"], color=COLOURS[m], ls="--",
                 label=f"{LABELS[m]}: in the model")
        ax2.plot(b[m]["t"], b[m]["m"], color=COLOURS[m], label=LABELS[m])
    ax1.set_xlabel("time [ms]")
    ax1.set_ylabel("energy [kJ]")
    ax1.legend(fontsize=7)
    ax2.set_xlabel("time [ms]")
    ax2.set_ylabel("mass in the model [kg]")
    ax2.set_ylim(0, 1.1 * MASS)
    ax2.legend(fontsize=7)
    fig.suptitle("Concrete block (CSCM) at 100 m/s on a rigid surface (thesis Fig. 5.3)")
    fig.tight_layout()
    figures = ROOT / "docs" / "figures"
    figures.mkdir(parents=True, exist_ok=True)
    fig.savefig(figures / "erosion_blocks_energies.png", dpi=130)
    fig, axes = plt.subplots(1, 3, figsize=(11, 3.2), sharey=True)
    for ax, m in zip(axes, MODELS):
        side_view(ax, outs[m], LABELS[m])
    axes[0].set_ylabel("z [mm]")
    axes[-1].legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    fig.savefig(figures / "erosion_blocks_side.png", dpi=130)
    ref = b["fem"]["ke"][-1]
    print("| model | eroded elements | mass in the model [kg] | kinetic [kJ] | in the model "
          "[kJ] | kinetic vs no erosion |")
    print("|---|---|---|---|---|---|")
    for m in MODELS:
        r = b[m]
        print(f"| {LABELS[m]} | {int(r['eroded'][-1])} | {r['m'][-1]:.3f} | "
              f"{r['ke'][-1]:.3f} | {r['e'][-1]:.3f} | {100 * (r['ke'][-1] / ref - 1):+.1f} % |")


if __name__ == "__main__":
    main()
