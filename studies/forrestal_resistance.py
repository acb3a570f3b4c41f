"""Study: the Forrestal target's resistance against the cavity-expansion force law (issue 53).

sphdyn's projectile stops at a third to a half of the measured 173 mm
(docs/validation.md, "Forrestal 1994"). Where does the extra resistance come
from: the static part (the concrete's confined strength, Forrestal's S f'c)
or a part that grows with the velocity? This reads runs of the case
(validation/cases/forrestal1994_ogive.toml, any resolution) and compares the
projectile's velocity against its depth with Forrestal et al.'s (1994)
two-stage force law for the same shot (:func:`sphdyn.validation.estimates.
forrestal_penetration`: F = c x in the crater, x <= 2 d; F = (pi d^2/4)
(S f'c + N* rho V^2) in the tunnel; S from their Eq. 12, N* of the crh-2
ogive):

* the mean resisting stress in velocity bands, sigma = (loss of kinetic
  energy) / (A x distance travelled) while the velocity falls through the
  band (no derivative of a noisy signal), sphdyn's and the law's;
* the effective S: the S for which the law stops the projectile where
  sphdyn does (its depth as `sphdyn validate` measures it);
* a figure, velocity against depth and the banded resistance against the
  velocity (``--figure``);
* with ``--carried`` (the runs' frames), the target mass moving ahead of the
  nose: below the tip (plus 5 mm) and downwards at more than half the
  projectile's speed, per frame while it moves (a plug of crushed concrete
  pushed ahead would show here);
* with ``--wall`` (frames), the live elements ahead of the nose: how deep
  the eroded debris lies between the tip and the first element on the axis,
  and the pressure, von Mises stress and damage of the most compressed
  elements there, beside MAT_159's TXC shear surface at that pressure with
  the run's concrete parameters (q = sqrt(3) Ff(3p), no rate effects,
  undamaged) and its slope at high pressure.

The projectile's velocity is its mean particle velocity (a ``[[probe]]`` of
velocity_z, mean, which the case has since 2026-11-30) or else the
derivative of its tip's depth (a Savitzky-Golay fit over 41 us). The
projectile's depth is its tip's (the deepest particle below the face at z =
0). Its mass, calibre and striking velocity, the concrete's strength and
density are the experiment's (validation/data/forrestal1994_ogive_penetration.csv).

    python studies/forrestal_resistance.py RUN[=LABEL] [...] [--figure PNG]

(RUN: a run folder, e.g. ``sphdyn validate forrestal1994_ogive --out OUT``
makes OUT/forrestal1994_ogive; validation/runs/ keeps the full and graded
runs' histories.)
"""

from __future__ import annotations

import argparse
import math
import tomllib
from pathlib import Path

import numpy as np
from scipy.optimize import brentq
from scipy.signal import savgol_filter

from sphdyn.io.history import History
from sphdyn.materials import cscm
from sphdyn.materials.cscm.layout import P_THETA
from sphdyn.validation import data
from sphdyn.validation.cases import CASES
from sphdyn.validation.estimates import (forrestal_penetration, forrestal_resistance_constant,
                                         ogive_nose_factor)

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "validation" / "data" / "forrestal1994_ogive_penetration.csv"
#: the velocities [m/s] that bound the bands of the mean resistance, below the
#: striking velocity (the first band starts there)
BAND_EDGES = (400.0, 277.0, 200.0, 100.0, 25.0)


def bands(velocity: float) -> tuple[tuple[float, float], ...]:
    """The velocity bands (upper, lower) [m/s] from the striking velocity down."""
    edges = [velocity] + [b for b in BAND_EDGES if b < velocity]
    return tuple(zip(edges[:-1], edges[1:]))


def shot(velocity: float = 277.0) -> dict:
    """The experiment's numbers for the shot at ``velocity`` (the data file's
    row; the calibre, the concrete's density and the ogive's crh from its
    set-up lines)."""
    row = data.read(DATA).row(v_s_m_per_s=f"{velocity:g}")
    return {"v": velocity, "m": data.number(row, "m_p_kg"),
            "fc": data.number(row, "fc_MPa") * 1e6, "d": 0.0269, "rho": 2370.0, "crh": 2.0,
            "dop": data.number(row, "dop_m")}


def resolved_deck(run: Path) -> dict:
    """The run's resolved deck."""
    with (run / "deck.resolved.toml").open("rb") as f:
        return tomllib.load(f)


def measured_depth(run: Path) -> float:
    """The depth [m] as `sphdyn validate` measures it (the case's own measure:
    the deepest the projectile's particles reached, plus half their spacing)."""
    return CASES["forrestal1994_ogive"].measure(run, resolved_deck(run))["dop"]


def trajectory(run: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray, str]:
    """Time [s], tip depth [m] below the face and velocity [m/s] (downwards
    positive) of the projectile in a run, and how the velocity was had."""
    h = History.from_csv(run / "history.csv").as_arrays()
    t, keep = np.unique(h["time"], return_index=True)  # a restart repeats a record
    depth = -h["probe_projectile_position_z"][keep]
    if "probe_projectile_velocity_z" in h:
        return t, depth, -h["probe_projectile_velocity_z"][keep], "mean particle velocity"
    grid = np.arange(t[0], t[-1], 1e-6)
    tip = np.interp(grid, t, depth)
    v = savgol_filter(tip, 41, 2, deriv=1, delta=1e-6)
    return grid, tip, v, "tip depth's derivative (Savitzky-Golay, 41 us)"


def banded_resistance(depth: np.ndarray, v: np.ndarray, mass: float, area: float,
                      bands) -> list[float]:
    """Mean resisting stress [Pa] while the velocity falls from each band's
    upper to its lower value: (1/2) m (V_hi^2 - V_lo^2) / (A dx), dx the
    depth travelled meanwhile (NaN where the run never reaches the band)."""
    out = []
    below = np.minimum.accumulate(v)  # the first time the velocity falls to a value
    for hi, lo in bands:
        if below[-1] > lo:
            out.append(math.nan)
            continue
        start = np.argmax(below <= hi) if below[0] > hi else 0
        v_hi = min(hi, v[start])
        end = np.argmax(below <= lo)
        travelled = depth[end] - depth[start]
        out.append(0.5 * mass * (v_hi ** 2 - lo ** 2) / (area * travelled)
                   if travelled > 0 else math.nan)
    return out


def effective_s(depth: float, s: dict, nose: float) -> float:
    """The S for which the force law stops the shot at ``depth`` [m]."""
    def miss(S):
        return forrestal_penetration([0.0], s["v"], s["m"], s["d"], s["fc"], s["rho"], nose,
                                     S)[1] - depth
    return brentq(miss, 0.01, 1e4, xtol=1e-6)


def projectile_frames(run: Path, mesh: str = "target"):
    """Each frame of a run with the projectile in the target (its tip below the
    face) and moving down: (time [s], the particles' mass, position and
    velocity, the projectile's mask, its velocity [m/s] and tip [m], and the
    mesh group of the frame, read while the file is open). The projectile's
    particles are those of the most common particle mass (its lattice's; the
    debris particles carry their elements' masses)."""
    import h5py

    from sphdyn.io.frames import list_frames

    for path in list_frames(run):
        with h5py.File(path, "r") as f:
            m, x, v = f["mass"][:], f["position"][:], f["velocity"][:]
            values, counts = np.unique(m, return_counts=True)
            proj = m == values[np.argmax(counts)]
            V = float((m[proj] * v[proj, 2]).sum() / m[proj].sum())
            tip = float(x[proj, 2].min())
            if V < 0.0 and tip < 0.0:
                yield float(f.attrs["time"]), m, x, v, proj, V, tip, f["meshes"][mesh]


def carried_mass(run: Path, ahead: float = 5e-3) -> list[tuple]:
    """Per frame (:func:`projectile_frames`): (time [s], the projectile's
    velocity [m/s], the target's mass [kg] below its tip (plus ``ahead`` [m])
    moving down at more than half its speed: the mesh nodes' and the eroded
    elements' particles')."""
    out = []
    for t, m, x, v, proj, V, tip, g in projectile_frames(run):
        xn = g["points"][:] + g["point_data/displacement"][:]
        vn, mn = g["point_data/velocity"][:], g["point_data/mass"][:]
        nodes = (vn[:, 2] < 0.5 * V) & (xn[:, 2] < tip + ahead)
        debris = ~proj & (v[:, 2] < 0.5 * V) & (x[:, 2] < tip + ahead)
        out.append((t, V, float(mn[nodes].sum()), float(m[debris].sum())))
    return out


def wall_states(run: Path, below: float = 15e-3, reach: float = 25e-3,
                count: int = 3) -> list[tuple]:
    """Per frame (:func:`projectile_frames`): (time [s], the depth [m] of the
    first live element's centre below the tip nearest the axis, and for the
    ``count`` live elements of highest pressure within ``below`` [m] under
    the tip (and 10 mm above it) and ``reach`` [m] of the axis: pressure p =
    -tr(sigma)/3 [Pa], von Mises q [Pa], damage). The stress is the
    element's (damaged) stress of the frame."""
    out = []
    for t, m, x, v, proj, V, tip, g in projectile_frames(run):
        xn = g["points"][:] + g["point_data/displacement"][:]
        cells, sig = g["cells"][:], g["cell_data/stress"][:]
        live, damage = g["cell_data/eroded"][:] == 0, g["cell_data/damage"][:]
        centre = xn[cells].mean(axis=1)
        r = np.hypot(centre[:, 0], centre[:, 1])
        below_tip = live & (centre[:, 2] < tip)
        # the elements nearest the axis (within 5 mm, or the innermost ring's)
        axis = below_tip & (r <= max(5e-3, 1.01 * float(r[below_tip].min(initial=np.inf))))
        gap = tip - float(centre[axis, 2].max()) if axis.any() else math.nan
        p = -np.trace(sig, axis1=1, axis2=2) / 3.0
        dev = sig + p[:, None, None] * np.eye(3)
        q = np.sqrt(1.5 * np.einsum("kij,kij->k", dev, dev))
        near = live & (r < reach) & (centre[:, 2] < tip + 10e-3) & (centre[:, 2] > tip - below)
        top = np.flatnonzero(near)[np.argsort(-p[near])[:count]]
        out.append((t, gap, [(float(p[k]), float(q[k]), float(damage[k])) for k in top]))
    return out


def concrete_parameters(run: Path) -> np.ndarray:
    """The packed CSCM parameters of the run's concrete (its resolved deck's
    material, overrides such as ``theta`` included)."""
    material = next(mat for mat in resolved_deck(run)["material"] if mat["name"] == "concrete")
    return cscm.pack_cscm({k: v for k, v in material.items()
                           if k not in ("name", "model", "erosion")})


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="+", metavar="RUN[=LABEL]",
                    help="a run folder, optionally with its label in the figure")
    ap.add_argument("--figure", type=Path, help="write the figure here (PNG)")
    ap.add_argument("--carried", action="store_true",
                    help="also print, per frame, the target mass carried ahead of the nose "
                         "(needs the runs' frames)")
    ap.add_argument("--wall", action="store_true",
                    help="also print, per frame, the stress states of the live elements "
                         "ahead of the nose against MAT_159's shear surface (needs frames)")
    ap.add_argument("--velocity", type=float, default=277.0,
                    help="the shot's striking velocity [m/s], a row of the data file (the "
                         "runs must be of that shot: --set body.projectile.velocity=...)")
    args = ap.parse_args(argv)
    s = shot(args.velocity)
    edges = bands(s["v"])
    nose = ogive_nose_factor(s["crh"])
    S = forrestal_resistance_constant(s["fc"])
    area = 0.25 * math.pi * s["d"] ** 2
    X_law = forrestal_penetration([0.0], s["v"], s["m"], s["d"], s["fc"], s["rho"], nose, S)[1]
    x = np.linspace(0.0, 1.2 * X_law, 40001)
    v_law = forrestal_penetration(x, s["v"], s["m"], s["d"], s["fc"], s["rho"], nose, S)[0]
    law = banded_resistance(x, v_law, s["m"], area, edges)
    print(f"Forrestal et al. (1994) force law: S = {S:.2f} (Eq. 12, f'c {s['fc'] / 1e6:g} MPa), "
          f"N* = {nose:.4f}, stops at {X_law * 1e3:.1f} mm (measured {s['dop'] * 1e3:.0f} mm)")
    head = " | ".join(f"sigma {hi:g}-{lo:g} m/s [MPa]" for hi, lo in edges)
    print(f"| run | velocity from | depth [mm] | effective S | {head} |")
    print("|---|---|---|---|" + "---|" * len(edges))
    print(f"| force law | - | {X_law * 1e3:.1f} | {S:.1f} | "
          + " | ".join(f"{b / 1e6:.0f}" for b in law) + " |")
    runs = []
    for given in args.runs:
        path, _, label = given.partition("=")
        run = Path(path)
        runs.append((run, label or (run.name if run.name != "forrestal1994_ogive"
                                    else run.parent.name)))
    curves = []
    for run, label in runs:
        t, depth, v, how = trajectory(run)
        deepest = measured_depth(run)
        sig = banded_resistance(depth, v, s["m"], area, edges)
        print(f"| {label} | {how} | {deepest * 1e3:.1f} | {effective_s(deepest, s, nose):.1f} | "
              + " | ".join(f"{b / 1e6:.0f}" for b in sig) + " |")
        curves.append((label, depth, v, sig))
    if args.carried:
        print("| run | time [us] | projectile velocity [m/s] | carried: nodes [g] | "
              "debris particles [g] |")
        print("|---|---|---|---|---|")
        for run, label in runs:
            for t, V, nodes, debris in carried_mass(run):
                print(f"| {label} | {t * 1e6:.0f} | {V:.1f} | {nodes * 1e3:.1f} | "
                      f"{debris * 1e3:.1f} |")
    if args.wall:
        print("MAT_159's TXC surface of each run's concrete: q = sqrt(3) Ff(3p), its slope q/p at "
              "high pressure sqrt(3) 3 theta. The elements' stresses are damaged, (1 - d) times "
              "the undamaged ones, so their q/p is the one to compare.")
        print("| run | time [us] | debris ahead [mm] | p [MPa] | von Mises q [MPa] | q/p | "
              "damage | TXC q at that p [MPa] | TXC slope |")
        print("|---|---|---|---|---|---|---|---|---|")
        for run, label in runs:
            c = concrete_parameters(run)
            slope = math.sqrt(3.0) * 3.0 * c[P_THETA]
            for t, gap, states in wall_states(run):
                for p, q, d in states:
                    txc = math.sqrt(3.0) * cscm.shear_surface(3.0 * p, c)
                    print(f"| {label} | {t * 1e6:.0f} | {gap * 1e3:.1f} | {p / 1e6:.0f} | "
                          f"{q / 1e6:.0f} | {q / p:.2f} | {d:.2f} | {txc / 1e6:.0f} | "
                          f"{slope:.2f} |")
    if args.figure:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2))
        a1.plot(x * 1e3, v_law, "k--", label=f"force law, S = {S:.1f} (Eq. 12)")
        a1.axvline(s["dop"] * 1e3, color="0.5", lw=0.8)
        a1.text(s["dop"] * 1e3, 5, " measured depth", color="0.4", fontsize=8)
        mids = [0.5 * (hi + lo) for hi, lo in edges]
        a2.plot(mids, [b / 1e6 for b in law], "k--o", label="force law")
        for label, depth, v, sig in curves:
            a1.plot(depth * 1e3, v, label=label)
            a2.plot(mids, [b / 1e6 for b in sig], "o-", label=label)
        a1.set(xlabel="tip depth below the face [mm]", ylabel="projectile velocity [m/s]",
               xlim=(0, max(200.0, 1.2e3 * s["dop"])), ylim=(0, 1.1 * s["v"]))
        a2.set(xlabel="velocity band's middle [m/s]",
               ylabel="mean resisting stress F / (pi d^2/4) [MPa]")
        for a in (a1, a2):
            a.grid(alpha=0.3)
            a.legend(fontsize=8)
        fig.suptitle(f"Forrestal et al. (1994), {s['v']:g} m/s: sphdyn's resistance against the "
                     "cavity-expansion force law", fontsize=10)
        fig.tight_layout()
        fig.savefig(args.figure, dpi=120)
        print(f"wrote {args.figure}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
