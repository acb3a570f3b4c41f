"""Issue 18's 1D verification cases as decks: Sod's shock tube against the
exact Riemann solution, and Gurney's open-faced sandwich (TNT on steel)
against Gurney's formula.

Runs examples/sod_shock_tube.toml and examples/gurney_1d.toml (or reuses
out/sod_shock_tube and out/gurney_1d with --reuse) and writes

* docs/figures/sod_shock_tube.png: density, velocity and pressure at
  t = 0.2 against the exact solution (:mod:`sphdyn.analysis.riemann`);
* docs/figures/gurney_1d.png: the plate's mean velocity over time against
  Gurney's terminal velocity;
* a table (stdout, markdown): the Sod L1 density error and shock position,
  the plate's velocity at 30 us against Gurney's.

    python examples/explosives_1d.py [--reuse]
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SOD_LEFT, SOD_RIGHT, GAMMA = (1.0, 0.0, 1.0), (0.125, 0.0, 0.1), 1.4
SQRT_2E_TNT = 2440.0  # Gurney velocity of TNT [m/s]


def gurney_open_face(m_over_c: float, sqrt_2e: float = SQRT_2E_TNT) -> float:
    """Gurney's terminal velocity of a plate on an open-faced charge [m/s]:
    ``sqrt(2E) [((1 + 2 M/C)^3 + 1) / (6 (1 + M/C)) + M/C]^(-1/2)``
    (Gurney 1943; Cooper, *Explosives Engineering*, 1996, ch. 27)."""
    r = m_over_c
    return sqrt_2e / math.sqrt(((1 + 2 * r) ** 3 + 1) / (6 * (1 + r)) + r)


def run(name: str, reuse: bool) -> Path:
    """Run ``examples/<name>.toml`` (unless ``reuse`` finds it); its output folder."""
    from sphdyn.simulation import run_deck

    out = ROOT / "out" / name
    run_deck(ROOT / "examples" / f"{name}.toml", out, reuse=reuse)
    return out


def sod_result(out: Path) -> dict:
    """The last frame against the exact solution: positions, fields, L1 error of
    the density over [-0.5, 0.5] and the shock position (half way up its jump)."""
    from sphdyn.io import list_frames, read_frame
    from sphdyn.analysis.riemann import sample, shock_speed

    t, _, f, _ = read_frame(list_frames(out)[-1])
    o = np.argsort(f["position"][:, 0])
    x = f["position"][o, 0]
    rho, u, p = f["density"][o], f["velocity"][o, 0], f["pressure"][o]
    sel = (x > -0.5) & (x < 0.5)
    exact = sample(x[sel], t, SOD_LEFT, SOD_RIGHT, GAMMA)[0]
    l1 = float(np.trapezoid(np.abs(rho[sel] - exact), x[sel]))
    behind = sample(np.array([0.3]), 0.2, SOD_LEFT, SOD_RIGHT, GAMMA)[0, 0]
    mid = 0.5 * (behind + SOD_RIGHT[0])
    k = int(np.flatnonzero((x > 0.25) & (rho > mid)).max())
    x_shock = x[k] + (x[k + 1] - x[k]) * (rho[k] - mid) / (rho[k] - rho[k + 1])
    return {"t": t, "x": x, "rho": rho, "u": u, "p": p, "l1": l1, "x_shock": x_shock,
            "x_shock_exact": t * shock_speed(SOD_LEFT, SOD_RIGHT, GAMMA)}


def gurney_result(out: Path) -> dict:
    """The plate's mean velocity over time (history probe) and Gurney's value."""
    from sphdyn.io import read_history_csv

    h = read_history_csv(out / "history.csv")
    m_over_c = 2.0764e-3 * 7850.0 / (10e-3 * 1630.0)
    return {"t": h["time"], "v": h["probe_plate_velocity_x"],
            "gurney": gurney_open_face(m_over_c), "m_over_c": m_over_c}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reuse", action="store_true", help="reuse out/<deck> folders")
    a = ap.parse_args()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from sphdyn.analysis.riemann import sample

    sod = sod_result(run("sod_shock_tube", a.reuse))
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8), layout="constrained")
    xe = np.linspace(-0.5, 0.5, 2001)
    ex = sample(xe, sod["t"], SOD_LEFT, SOD_RIGHT, GAMMA)
    for ax, key, row, label in zip(axes, ("rho", "u", "p"), ex,
                                   ("density", "velocity", "pressure")):
        ax.plot(xe, row, "k-", lw=1, label="exact (Toro)")
        near = np.abs(sod["x"]) < 0.55
        ax.plot(sod["x"][near], sod[key][near], ".", ms=3, label="sphdyn")
        ax.set_xlim(-0.5, 0.5)
        ax.set_xlabel("x")
        ax.set_title(label)
    axes[0].legend()
    fig.suptitle(f"Sod shock tube at t = {sod['t']:.2f}: L1(density) = {sod['l1']:.4f}")
    fig.savefig(ROOT / "docs" / "figures" / "sod_shock_tube.png", dpi=120)

    g = gurney_result(run("gurney_1d", a.reuse))
    fig, ax = plt.subplots(figsize=(6.5, 4), layout="constrained")
    ax.plot(g["t"] * 1e6, g["v"], label="plate, mean velocity (sphdyn)")
    ax.axhline(g["gurney"], color="k", ls="--",
               label=f"Gurney, M/C = {g['m_over_c']:.2f}: {g['gurney']:.0f} m/s")
    ax.set_xlabel("time [us]")
    ax.set_ylabel("velocity [m/s]")
    ax.legend(loc="lower right")
    ax.set_title("Open-faced sandwich, 10 mm TNT on 2.08 mm steel (1D)")
    fig.savefig(ROOT / "docs" / "figures" / "gurney_1d.png", dpi=120)

    print("| case | result | reference | difference |")
    print("|---|---|---|---|")
    print(f"| Sod, L1 density error over [-0.5, 0.5] | {sod['l1']:.4f} | 0 | |")
    print(f"| Sod, shock position | {sod['x_shock']:.4f} | {sod['x_shock_exact']:.4f} | "
          f"{100 * (sod['x_shock'] / sod['x_shock_exact'] - 1):+.1f} % |")
    print(f"| Gurney, plate velocity at {g['t'][-1] * 1e6:.0f} us | {g['v'][-1]:.0f} m/s | "
          f"{g['gurney']:.0f} m/s | {100 * (g['v'][-1] / g['gurney'] - 1):+.1f} % |")


if __name__ == "__main__":
    main()
