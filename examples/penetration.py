"""Thesis sec. 5.3 (Fig. 5.4; Buchar, Krejci & Forejt 2001): penetration depth
of a steel projectile into concrete over a sweep of striking velocities, with
the three models: no erosion, plain erosion, erosion into SPH particles.

Runs each of examples/penetration_{fem,plain,sph}.toml as an ensemble over
the striking velocity (``sphdyn ensemble --vary body.projectile.velocity.2=...``,
one worker of two threads: the samples are small; first and last frames
only, in HDF5) into out/penetration_<model>-ensemble (done samples are kept; --reuse only
reads), and writes

* docs/figures/penetration.png: the depth against the striking velocity for
  the three models and the modified NDRC formula; the damage in the
  target's mid-section (a 2 mm layer at y = 0) of each model's fastest
  completed run;
* a table (stdout, markdown): the depth per model and velocity, the NDRC
  depth, and each run's status.

The depth is the deepest position of the projectile's nose below the
target's face: the largest magnitude of the projectile's mean
z-displacement (its probe) less the 2 mm start gap.

The modified NDRC formula (Kennedy 1976; UFC 3-340-02 and Li et al. 2005
quote it) for a rigid projectile: :func:`sphdyn.validation.estimates.ndrc_depth`
(its equations there), with the deck's projectile, f'c and a flat nose
(N* = 0.72).

    python examples/penetration.py [--reuse]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
MODELS = {"fem": "no erosion", "plain": "plain erosion", "sph": "erosion into SPH"}
VELOCITIES = (200, 400, 600, 800, 1000)  # m/s
GAP = 0.002  # the nose's start height above the face [m]
# the projectile and target of the decks (SI)
MASS = 7850 * np.pi * 0.01**2 * 0.022  # kg
DIAMETER, FC, NOSE = 0.020, 40e6, 0.72  # m, Pa, flat nose N*
#: the sweep keeps the first and last frames in HDF5 only (a frame of the
#: 75,000 elements with their CSCM state is about 80 MB with VTK)
SWEEP_OUTPUT = ["output.vtk=false", 'output.every="80 us"']


def ndrc_depth(v: float) -> float:
    """Modified NDRC depth [m] of the decks' projectile at ``v`` [m/s]."""
    from sphdyn.validation.estimates import ndrc_depth as depth

    return depth(v, MASS, DIAMETER, FC, NOSE)


def sweep(model: str, reuse: bool) -> Path:
    """Run one model's ensemble unless each velocity has its record (completed
    or stopped) or ``reuse`` says only read; its folder."""
    from sphdyn.ensemble import run_ensemble

    out = ROOT / "out" / f"penetration_{model}-ensemble"
    finished = len(list(out.glob("sample_*/result.json"))) == len(VELOCITIES)
    if not (reuse or finished):  # a stopped run counts as finished: it is a result
        values = ",".join(str(-v) for v in VELOCITIES)
        run_ensemble(ROOT / "examples" / f"penetration_{model}.toml", 1,
                     vary=[f"body.projectile.velocity.2={values}"], out=out,
                     workers=1, threads=2, overrides=SWEEP_OUTPUT)
    return out


def depths(out: Path) -> list[tuple[float, float, str, Path]]:
    """(velocity [m/s], depth [m], status, sample folder) per sample."""
    from sphdyn.io import read_history_csv

    rows = []
    for d in sorted(out.glob("sample_*")):
        if not (d / "result.json").exists():  # not run yet
            continue
        rec = json.loads((d / "result.json").read_text())
        v = -float(rec["vary"]["body.projectile.velocity.2"])
        h = read_history_csv(d / "history.csv")
        key = next(k for k in h if k.endswith("displacement_z") and "projectile" in k)
        rows.append((v, float(np.max(-h[key])) - GAP, rec["status"], d))
    return sorted(rows)


def mid_section(sample: Path, layer: float = 0.002):
    """Elements' centres (x, z) [m] and damage in the slab 0 <= y < ``layer``
    [m] of the target's last frame (one layer of the decks' 2 mm elements
    and particles, whose centres start at y = 1 mm), and the particles'
    (debris and projectile)."""
    import h5py

    from sphdyn.io import read_frame_meshes

    last = sorted((sample / "frames").glob("frame_*.h5"))[-1]
    mesh = read_frame_meshes(last)["target"]
    c = mesh.points[mesh.cells].mean(axis=1)
    keep = (c[:, 1] >= 0.0) & (c[:, 1] < layer)
    with h5py.File(last, "r") as f:
        x, dmg = f["position"][:], f["damage"][:]
    slab = (x[:, 1] >= 0.0) & (x[:, 1] < layer)
    return c[keep][:, [0, 2]], mesh.cell_data["damage"][keep], x[slab][:, [0, 2]], dmg[slab]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reuse", action="store_true", help="only read out/penetration_*")
    a = ap.parse_args()

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    results = {m: depths(sweep(m, a.reuse)) for m in MODELS}
    fig = plt.figure(figsize=(13, 8), layout="constrained")
    grid = fig.add_gridspec(2, 3, height_ratios=[1.2, 1])
    ax = fig.add_subplot(grid[0, :])
    vv = np.linspace(150, 1050, 50)
    ax.plot(vv, [1e3 * ndrc_depth(v) for v in vv], "k--", label="modified NDRC (rigid)")
    for (model, label), mark in zip(MODELS.items(), "osd"):
        rows = results[model]
        ok = [r for r in rows if r[2] == "completed"]
        ax.plot([r[0] for r in ok], [1e3 * r[1] for r in ok], mark + "-", label=label)
        bad = [r for r in rows if r[2] != "completed"]
        if bad:
            ax.plot([r[0] for r in bad], [1e3 * r[1] for r in bad], mark, mfc="none",
                    color=ax.lines[-1].get_color(), label=f"{label}: run stopped")
    ax.set_xlabel("striking velocity [m/s]")
    ax.set_ylabel("penetration depth [mm]")
    ax.legend()
    ax.grid(alpha=0.3)
    for k, (model, label) in enumerate(MODELS.items()):
        if not results[model]:
            continue
        # the fastest run that completed (a run stopped early has only its
        # first frame: the panel would show the projectile above the face)
        done = [r for r in results[model] if r[2] == "completed"] or results[model]
        fast = max(done, key=lambda r: r[0])
        ce, de, xp, dp = mid_section(fast[3])
        sub = fig.add_subplot(grid[1, k])
        sc = sub.scatter(1e3 * ce[:, 0], 1e3 * ce[:, 1], c=de, s=6, marker="s",
                         cmap="inferno_r", vmin=0, vmax=1, linewidths=0)
        sub.scatter(1e3 * xp[:, 0], 1e3 * xp[:, 1], c=dp, s=6, cmap="inferno_r", vmin=0,
                    vmax=1, linewidths=0.3, edgecolors="tab:blue")
        sub.set_aspect("equal")
        sub.set_facecolor("0.8")  # undamaged elements (pale) stand out from empty space
        sub.set_title(f"{label}, {fast[0]:.0f} m/s", fontsize=10)
        sub.set_xlabel("x [mm]")
        sub.set_ylabel("z [mm]")
    fig.colorbar(sc, ax=fig.axes[1:], shrink=0.8, label="damage (particles: blue rim)")
    fig.suptitle("Fragment-simulating projectile into concrete (thesis 5.3, Fig. 5.4)")
    figures = ROOT / "docs" / "figures"
    figures.mkdir(parents=True, exist_ok=True)
    fig.savefig(figures / "penetration.png", dpi=110)

    print("| striking velocity [m/s] | NDRC [mm] | " +
          " | ".join(f"{label} [mm]" for label in MODELS.values()) + " |")
    print("|---|---|" + "---|" * len(MODELS))
    for v in VELOCITIES:
        cells = []
        for model in MODELS:
            r = next((r for r in results[model] if r[0] == v), None)
            cells.append("not run" if r is None else f"{1e3 * r[1]:.1f}"
                         + ("" if r[2] == "completed" else f" ({r[2]})"))
        print(f"| {v} | {1e3 * ndrc_depth(v):.1f} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
