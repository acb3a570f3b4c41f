"""Thesis sec. 5.2: the concrete L-specimen at 2400 mm/s at three particle spacings.

Runs examples/l_specimen.toml at the thesis's coarse, normal and fine
spacings (16.67, 10 and 6.25 mm; or reuses out/l_specimen_* with --reuse)
and writes

* docs/figures/l_specimen.png: the damage on the specimen's face at the
  end (1.5 ms) for the three spacings, and the support's reaction over time;
* a table (stdout, markdown): particles, steps, peak support reaction and
  its time, the crack's angle and reach, the energy error.

The crack is measured on the front face: the particles of the vertical leg
(x < 250 mm, y > 100 mm) with damage above 0.9; per lattice column the mean
height of those particles gives the path, a straight line fitted through it
its angle (positive: the crack descends as it runs from the inner corner
into the leg), and the leftmost damaged column its reach.

    python examples/l_specimen.py [--reuse] [--set KEY=VALUE ... --tag NAME]

``--set`` overrides a deck value at all three spacings (a sensitivity
study); it needs ``--tag``, which names the runs (out/l_specimen_NAME_*)
and the figure (out/l_specimen_NAME.png; docs/figures/l_specimen.png is
drawn only for the deck as it is).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SPACINGS = {"coarse": 0.5 / 30, "normal": 0.01, "fine": 0.00625}  # m


def run(label: str, dx: float, reuse: bool, sets: tuple[str, ...] = (), tag: str = "") -> Path:
    """Run the deck at spacing ``dx`` with the overrides ``sets`` (unless
    ``reuse`` finds it); its output folder."""
    from sphdyn.simulation import run_deck

    out = ROOT / "out" / f"l_specimen_{tag + '_' if tag else ''}{label}"
    run_deck(ROOT / "examples" / "l_specimen.toml", out, [f"body.L.dx={dx!r}", *sets],
             reuse=reuse, progress=True)
    return out


def front_face(out: Path) -> tuple[np.ndarray, np.ndarray]:
    """Reference positions (n, 3) [m] and damage (n,) of the front face (largest
    z) in the last frame."""
    import h5py

    last = sorted((out / "frames").glob("frame_*.h5"))[-1]
    with h5py.File(last, "r") as f:
        x0 = f["position"][:] - f["displacement"][:]
        d = f["damage"][:]
    face = x0[:, 2] > x0[:, 2].max() - 1e-9
    return x0[face], d[face]


def crack_path(x0: np.ndarray, d: np.ndarray, dx: float) -> tuple[float, float]:
    """Angle [deg] of a straight line through the crack path in the vertical
    leg (positive: descending away from the corner) and the reach [m] (x of
    the leftmost damaged column); NaN when nothing is damaged."""
    sel = (d > 0.9) & (x0[:, 0] < 0.25) & (x0[:, 1] > 0.1)
    if not sel.any():
        return float("nan"), float("nan")
    cols = np.round(x0[sel, 0] / dx).astype(int)
    xs = np.array([x0[sel, 0][cols == c].mean() for c in np.unique(cols)])
    ys = np.array([x0[sel, 1][cols == c].mean() for c in np.unique(cols)])
    slope = np.polyfit(xs, ys, 1)[0] if xs.size > 1 else 0.0
    return float(np.degrees(np.arctan(slope))), float(xs.min())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reuse", action="store_true", help="reuse out/l_specimen_*")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="override a deck value at every spacing (needs --tag)")
    ap.add_argument("--tag", default="", help="name of a sensitivity study's runs and figure")
    a = ap.parse_args()
    if a.set and not a.tag:
        ap.error("--set needs --tag NAME (its runs go to out/l_specimen_NAME_*)")

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from sphdyn.io import read_history_csv

    fig = plt.figure(figsize=(13, 8), layout="constrained")
    grid = fig.add_gridspec(2, 3, height_ratios=[1.1, 1])
    force_ax = fig.add_subplot(grid[1, :])
    rows = []
    for k, (label, dx) in enumerate(SPACINGS.items()):
        out = run(label, dx, a.reuse, tuple(a.set), a.tag)
        x0, d = front_face(out)
        ax = fig.add_subplot(grid[0, k])
        sc = ax.scatter(1e3 * x0[:, 0], 1e3 * x0[:, 1], c=d, s=600 * dx, cmap="inferno_r",
                        vmin=0, vmax=1, marker="s", linewidths=0)
        ax.set_aspect("equal")
        ax.set_title(f"{label}: dx {1e3 * dx:.2f} mm")
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("y [mm]")
        h = read_history_csv(out / "history.csv")
        reaction = -h["support_reaction_y"]
        force_ax.plot(1e3 * h["time"], 1e-3 * reaction, label=f"support, {label}")
        force_ax.plot(1e3 * h["time"], 1e-3 * h["load_reaction_y"], ls=":", lw=0.8,
                      label=f"loaded end, {label}")
        i = int(np.argmax(reaction))
        angle, reach = crack_path(x0, d, dx)
        summary = json.loads((out / "summary.json").read_text())
        rows.append((label, dx, summary["particles"], summary["steps"], reaction[i],
                     h["time"][i], angle, reach, summary["energy_error_max_rel"]))
    fig.colorbar(sc, ax=fig.axes[1:4], shrink=0.8, label="damage")
    force_ax.set_xlabel("time [ms]")
    force_ax.set_ylabel("vertical reaction [kN]")
    force_ax.legend(fontsize=8, ncol=3)
    fig.suptitle("Concrete L-specimen at 2400 mm/s (thesis 5.2): damage at 1.5 ms, "
                 "front face, and reactions" + (f" ({', '.join(a.set)})" if a.set else ""))
    if a.tag:
        figure = ROOT / "out" / f"l_specimen_{a.tag}.png"
    else:
        figure = ROOT / "docs" / "figures" / "l_specimen.png"
    figure.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(figure, dpi=110)
    print("| model | dx [mm] | particles | steps | peak support reaction [kN] | at [ms] | "
          "crack angle [deg] | crack reach x [mm] | energy error (max, rel.) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for label, dx, n, steps, peak, t, angle, reach, err in rows:
        print(f"| {label} | {1e3 * dx:.2f} | {n} | {steps} | {1e-3 * peak:.1f} | "
              f"{1e3 * t:.3f} | {angle:.1f} | {1e3 * reach:.0f} | {err:.4f} |")


if __name__ == "__main__":
    main()
