"""Study 2: resolution study of the main job, examples/disc_impact.toml.

The paper's CSCM concrete disc (100 mm diameter, 20 mm deep, 3D) striking a
rigid base at 15 m/s is run unchanged except for the particle spacing
(``--set body.disc.dx=...``, spacings that divide the 20 mm depth and the
100 mm diameter) and run to 300 us instead of 200 us (``run.t_end``: at
200 us the disc is still on the base, so neither its rebound nor the total
impulse is known there), with ``sphdyn run`` in a subprocess, one at a time
(``--threads``, default 1). From each run:

* peak wall force: raw (``peak_F_wall_base`` of summary.json) and the peak
  of the mean over ``output.force_window`` = 5 us
  (``peak_F_wall_base_mean``);
* force plateau: mean wall force from 10 to 50 us after first contact,
  (I(t_c + 50 us) - I(t_c + 10 us)) / 40 us from the impulse column
  ``I_wall_base`` (exact, however sparse the history); t_c is the first
  record with a wall force;
* total impulse I_wall_base at 300 us, and the wall force left then;
* mean body velocity at 300 us (the rebound velocity once the contact is
  over): sum m v_y / sum m over the last frame (checked against
  -15 m/s + I / M, momentum balance with the wall the only external force);
* the energy the disc absorbed, KE(0) - KE(300 us), and the internal and
  artificial-viscosity energies at 300 us (history columns);
* damaged volume at 200 us (the deck's end time, the figure in
  docs/examples.md) and at 300 us: sum of m / rho over the particles with
  damage > 0.9 (the threshold the docs use for "failed"), and its fraction
  of the body's volume.

The table gives each quantity per spacing, the relative change between
the two finest spacings (a quantity is called converged when that change is
below ``CONVERGED_PCT``) and a Richardson estimate from the three finest
(:func:`richardson`). Run ``PYTHONPATH=src python studies/disc_resolution.py``
(``--dx 5,4,2.5`` to choose spacings in mm, ``--reuse`` to read finished
runs from ``--runs``); it writes ``docs/figures/disc_resolution.csv`` and
``docs/figures/disc_resolution.png`` and prints the table.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

from sphdyn.io.frames import list_frames
from sphdyn.io.hdf5 import read_frame, read_frame_header
from sphdyn.io.history import History

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
DECK = ROOT / "examples" / "disc_impact.toml"
FIGURES = ROOT / "docs" / "figures"
SPACINGS_MM = (5.0, 4.0, 10.0 / 3.0, 2.5, 2.0, 5.0 / 3.0, 10.0 / 7.0, 1.25)
IMPACT_SPEED = 15.0            # m/s, the deck's body velocity
DAMAGE_THRESHOLD = 0.9
PLATEAU = (10e-6, 50e-6)       # s after first contact
T_END = 300e-6                 # s, run end (the deck's is 200 us)
T_DAMAGE = 200e-6              # s, the deck's end time: damage also measured there
CONVERGED_PCT = 3.0
WALL = "base"


def run_dir(runs: Path, dx_mm: float) -> Path:
    """Output directory of the run at spacing ``dx_mm``."""
    return runs / f"dx_{dx_mm:.3f}mm"


def run_one(dx_mm: float, out: Path, threads: int, sets: tuple[str, ...] = ()) -> None:
    """``sphdyn run`` of the main deck at spacing ``dx_mm`` into ``out`` (the
    frames also hold the particle masses; no VTK copy), with the user's
    ``sets`` (``KEY=VALUE`` overrides) after the study's own."""
    cmd = [sys.executable, "-m", "sphdyn", "run", str(DECK), "--out", str(out),
           "--threads", str(threads), "-q",
           "--set", f"body.disc.dx={dx_mm * 1e-3!r}",
           "--set", f"run.t_end={T_END!r}",
           "--set", "output.vtk=false",
           "--set", 'output.fields=["velocity","damage","density","mass"]']
    for kv in sets:
        cmd += ["--set", kv]
    subprocess.run(cmd, check=True, env=os.environ.copy())


def facet(dx_mm: float) -> dict:
    """The flat facet the square lattice leaves at the point of the rim that
    strikes: particles per layer in the lowest row, its width [mm] (their
    span plus one spacing), and the force of its first contact [kN],
    ``rho c v w t`` (a flat face of width w and depth t striking at v; c the
    longitudinal wave speed sqrt((K + 4G/3)/rho) of the deck's concrete)."""
    from sphdyn.deck import load_deck
    from sphdyn.geometry import lattice_from_shape

    deck = load_deck(DECK)
    body, mat = deck.body[0], deck.material[0]
    x = lattice_from_shape(body.geometry.model_dump(), dx_mm * 1e-3, 3)
    low = x[np.abs(x[:, 1] - x[:, 1].min()) < 1e-9]
    layers = np.unique(np.round(low[:, 2] / (dx_mm * 1e-3), 6)).size
    width = np.ptp(low[:, 0]) + dx_mm * 1e-3
    c = np.sqrt((mat.K + 4.0 * mat.G / 3.0) / mat.density)
    return {"facet_particles": int(len(low) // layers), "facet_mm": 1e3 * width,
            "facet_force_kN": 1e-3 * mat.density * c * IMPACT_SPEED * width
            * body.geometry.length, "wave_speed_ms": float(c)}


def measure(out: Path, dx_mm: float) -> dict:
    """The study's quantities of the finished run at spacing ``dx_mm`` in ``out``."""
    summary = json.loads((out / "summary.json").read_text())
    if summary["status"] != "completed":
        raise RuntimeError(f"{out}: run {summary['status']}")
    h = History.from_csv(out / "history.csv").as_arrays()
    t, force, impulse = h["time"], h[f"F_wall_{WALL}"], h[f"I_wall_{WALL}"]
    t_contact = t[np.flatnonzero(force > 0)[0]]
    i0, i1 = np.interp(t_contact + np.array(PLATEAU), t, impulse)
    kinetic = h["E_kinetic"]
    frames = list_frames(out)
    _, _, fields, _ = read_frame(frames[-1])
    m = fields["mass"]
    mass = m.sum()
    at_damage_time = min(frames, key=lambda f: abs(read_frame_header(f)[0] - T_DAMAGE))
    _, _, early, _ = read_frame(at_damage_time)
    return {
        "dx_mm": dx_mm,
        "particles": summary["particles"],
        "steps": summary["steps"],
        "seconds": summary["wall_seconds"],
        "peak_force_kN": 1e-3 * summary[f"peak_F_wall_{WALL}"],
        "peak_force_5us_kN": 1e-3 * summary[f"peak_F_wall_{WALL}_mean"],
        "plateau_force_kN": 1e-3 * (i1 - i0) / (PLATEAU[1] - PLATEAU[0]),
        "impulse_Ns": float(impulse[-1]),
        "end_force_kN": 1e-3 * float(force[-1]),
        "end_velocity_ms": float((m * fields["velocity"][:, 1]).sum() / mass),
        "end_velocity_momentum_ms": -IMPACT_SPEED + float(impulse[-1]) / mass,
        **facet(dx_mm),
        "absorbed_energy_J": float(kinetic[0] - kinetic[-1]),
        "internal_energy_J": float(h["E_internal"][-1]),
        "viscous_energy_J": float(h["E_viscous"][-1]),
        **_damaged("_200us", early),
        **_damaged("_300us", fields),
        "_t": t, "_F": force,
    }


def _damaged(suffix: str, fields: dict) -> dict:
    """Volume [cm^3] and volume fraction [%] with damage above the threshold."""
    vol = fields["mass"] / fields["density"]
    failed = vol[fields["damage"] > DAMAGE_THRESHOLD].sum()
    return {f"damaged_volume{suffix}_cm3": 1e6 * float(failed),
            f"damaged_fraction{suffix}_pct": 100.0 * float(failed / vol.sum())}


QUANTITIES = (  # key, label
    ("facet_particles", "particles per layer in the lattice's lowest row"),
    ("facet_mm", "width of that flat facet [mm]"),
    ("facet_force_kN", "its first-contact force rho c v w t [kN]"),
    ("peak_force_kN", "peak wall force, raw [kN]"),
    ("peak_force_5us_kN", "peak wall force, 5 us mean [kN]"),
    ("plateau_force_kN", "force plateau, 10-50 us after contact [kN]"),
    ("impulse_Ns", "total impulse at 300 us [N s]"),
    ("end_force_kN", "wall force left at 300 us [kN]"),
    ("end_velocity_ms", "mean body velocity (rebound) at 300 us [m/s]"),
    ("absorbed_energy_J", "energy absorbed by the disc, KE(0) - KE(300 us) [J]"),
    ("internal_energy_J", "internal energy at 300 us [J]"),
    ("viscous_energy_J", "artificial viscosity's dissipation at 300 us [J]"),
    ("damaged_volume_200us_cm3", "damaged volume at 200 us, damage > 0.9 [cm^3]"),
    ("damaged_fraction_200us_pct", "damaged volume fraction at 200 us [%]"),
    ("damaged_volume_300us_cm3", "damaged volume at 300 us, damage > 0.9 [cm^3]"),
    ("damaged_fraction_300us_pct", "damaged volume fraction at 300 us [%]"),
)


def _relative_change_pct(coarse: float, fine: float) -> float:
    """100 (fine / coarse - 1); 0 when both are 0 (e.g. no wall force left)."""
    if coarse == 0.0:
        return 0.0 if fine == 0.0 else float("inf")
    return 100.0 * (fine / coarse - 1.0)


def richardson(h, f) -> tuple[float, float] | None:
    """Richardson extrapolation from the three finest spacings: (f0, p) with
    ``f = f0 + C h^p`` through the three points (h may be unevenly spaced:
    p solves ``(f2 - f1) / (f3 - f2) = (h2^p - h1^p) / (h3^p - h2^p)``,
    h1 < h2 < h3); None unless the values change monotonically and by less
    at the finer step (converging), or p falls outside 0.25-8."""
    from scipy.optimize import brentq

    (h1, f1), (h2, f2), (h3, f3) = sorted(zip(h, f))[:3]
    d21, d32 = f2 - f1, f3 - f2
    if d21 == 0.0 or d32 == 0.0 or (d21 > 0) != (d32 > 0):
        return None

    def gap(p):
        return (h2**p - h1**p) / (h3**p - h2**p) - d21 / d32

    try:
        p = brentq(gap, 0.25, 8.0)
    except ValueError:  # no root: not converging at an order in range
        return None
    return f1 - d21 * h1**p / (h2**p - h1**p), p


def table_rows(results: list[dict]) -> list[dict]:
    """One row per quantity: its value per spacing, the relative change
    between the two finest spacings and the Richardson estimate (where the
    three finest are monotone and converging)."""
    rows = []
    h = [r["dx_mm"] for r in results]
    for key, label in QUANTITIES:
        values = [r[key] for r in results]
        change = _relative_change_pct(values[-2], values[-1]) if len(values) > 1 \
            else float("nan")
        extrapolated = richardson(h, values) if len(values) > 2 else None
        rows.append({"quantity": label, **{f"dx={r['dx_mm']:.3g} mm": v
                                           for r, v in zip(results, values)},
                     "change_finest_pct": change,
                     "converged": abs(change) < CONVERGED_PCT,
                     "richardson": extrapolated})
    return rows


def write_csv(results: list[dict], path: Path) -> None:
    """Per-run quantities, one line per spacing."""
    keys = [k for k in results[0] if not k.startswith("_")]
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys)
        w.writeheader()
        for r in results:
            w.writerow({k: (f"{r[k]:.5g}" if isinstance(r[k], float) else r[k]) for k in keys})


def print_table(results: list[dict], rows: list[dict]) -> None:
    """Markdown tables: the runs, then the quantities with their change."""
    print("| dx [mm] | particles | steps | wall s |")
    print("|---|---|---|---|")
    for r in results:
        print(f"| {r['dx_mm']:.3g} | {r['particles']} | {r['steps']} | {r['seconds']:.0f} |")
    heads = [k for k in rows[0] if k.startswith("dx=")]
    print()
    print("| quantity | " + " | ".join(heads) + " | change between the two finest | "
          "converged | Richardson (order) |")
    print("|---|" + "---|" * len(heads) + "---|---|---|")
    for row in rows:
        vals = " | ".join(f"{row[h]:.4g}" for h in heads)
        rich = row["richardson"]
        rich = f"{rich[0]:.4g} ({rich[1]:.2g})" if rich else "not monotone"
        print(f"| {row['quantity']} | {vals} | {row['change_finest_pct']:+.1f} % | "
              f"{'yes' if row['converged'] else 'no'} | {rich} |")


def plot(results: list[dict], path: Path) -> None:
    """Wall force histories (left) and the quantities against dx, normalised by
    the finest run's value (right)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_f, ax_q) = plt.subplots(1, 2, figsize=(12, 4.6))
    for r in results:
        ax_f.plot(1e6 * r["_t"], 1e-3 * r["_F"], lw=0.9, label=f"dx = {r['dx_mm']:.3g} mm")
    ax_f.axvspan(1e6 * (r["_t"][np.flatnonzero(r["_F"] > 0)[0]] + PLATEAU[0]),
                 1e6 * (r["_t"][np.flatnonzero(r["_F"] > 0)[0]] + PLATEAU[1]),
                 color="0.9", label="plateau window")
    ax_f.set(xlabel="t [us]", ylabel="wall force [kN]", title="disc_impact: wall force")
    ax_f.legend(fontsize=8)
    dx = np.array([r["dx_mm"] for r in results])
    for key, label in QUANTITIES:
        if "fraction" in key or key == "end_force_kN" or key.startswith("facet"):
            continue
        v = np.array([r[key] for r in results])
        ax_q.plot(dx, v / v[-1], "o-", label=label)
    ax_q.axhspan(1 - CONVERGED_PCT / 100, 1 + CONVERGED_PCT / 100, color="0.9")
    ax_q.set(xlabel="particle spacing dx [mm]", ylabel="value / value at the finest dx",
             title="quantities against resolution")
    ax_q.invert_xaxis()
    ax_q.legend(fontsize=7)
    for ax in (ax_f, ax_q):
        ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--dx", default=",".join(f"{d:.4g}" for d in SPACINGS_MM),
                    help="particle spacings in mm, comma-separated")
    ap.add_argument("--runs", type=Path, default=ROOT / "out" / "studies" / "disc_resolution",
                    help="directory of the run outputs")
    ap.add_argument("--reuse", action="store_true", help="keep completed runs in --runs")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--out", type=Path, default=FIGURES, help="directory of the CSV and PNG")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="a deck override added to every run (e.g. "
                         "material.concrete.damage_growth=state)")
    args = ap.parse_args(argv)
    spacings = sorted((float(d) for d in args.dx.split(",")), reverse=True)
    results = []
    for dx_mm in spacings:
        out = run_dir(args.runs, dx_mm)
        done = (out / "summary.json").exists() and \
            json.loads((out / "summary.json").read_text())["status"] == "completed"
        if not (args.reuse and done):
            run_one(dx_mm, out, args.threads, tuple(args.set))
        results.append(measure(out, dx_mm))
        r = results[-1]
        print(f"  dx = {dx_mm:.3g} mm: {r['particles']} particles, {r['steps']} steps, "
              f"{r['seconds']:.0f} s", flush=True)
    rows = table_rows(results)
    args.out.mkdir(parents=True, exist_ok=True)
    write_csv(results, args.out / "disc_resolution.csv")
    plot(results, args.out / "disc_resolution.png")
    print_table(results, rows)


if __name__ == "__main__":
    main()
