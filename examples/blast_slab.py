"""Thesis ch. 9 (Figs. 9.4-9.7): a TNT charge detonated 100 mm above an RC slab.

Runs examples/blast_slab_coarse.toml (slab dx 10 mm) without and with the
CSCM rate effects into out/blast_slab_coarse and out/blast_slab_coarse_rate
(``--full``: also examples/blast_slab.toml, dx 5 mm, into out/blast_slab;
``--reuse`` only reads), and writes

* docs/figures/blast_slab.png: the gauges over time, the strain at the
  bottom surface (Fig. 9.4) and the displacement at the bottom centre
  (Fig. 9.5), of every run found; the damage of the top and the bottom face
  at the end of the first run (Fig. 9.6);
* docs/figures/blast_slab_detonation.png: cross-sections through the
  charge's axis (y = 250 mm) at 10, 30 and 60 us, particles coloured by
  material (Fig. 9.7), from a short run of the coarse model with a frame
  every 10 us (out/blast_slab_early);
* a table (stdout, markdown): peak displacement and strain, when they occur,
  the released chemical energy, steps, wall time, energy error.

``--standoff`` compares the explicit charge with the empirical load
(examples/blast_slab_empirical.toml: LS-DYNA's LOAD_BLAST_ENHANCED, the
Kingery-Bulmash free-air fits, on the slab's exposed faces) at stand-offs of
100, 200 and 300 mm (0.6 ms runs of the coarse decks, a frame every 20 us,
into out/blast_standoff), and writes docs/figures/blast_slab_empirical.png:
the concrete's momentum over time at 100 mm, its peak against the stand-off,
and the top face's damage of the two 3 ms runs; and a table.

``--orientation`` runs the thesis's sensitivity study instead, as an
ensemble of the coarse deck over the charge's tilt from upright (about y
through its centre, the detonator turning with it):
``sphdyn ensemble examples/blast_slab_coarse.toml --samples 1 --vary
body.charge.geometry.tilt=0,45,90`` into out/blast_slab_coarse-ensemble,
and writes docs/figures/blast_slab_orientation.png (the gauges of each tilt)
and a table.

    python examples/blast_slab.py [--reuse] [--full] [--orientation | --standoff]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
#: run name: (deck, overrides, label)
RUNS = {
    "blast_slab_coarse": ("blast_slab_coarse.toml", [], "dx 10 mm, no rate effects"),
    "blast_slab_coarse_rate": ("blast_slab_coarse.toml", ["material.0.rate_effects=true"],
                               "dx 10 mm, rate effects"),
    "blast_slab": ("blast_slab.toml", [], "dx 5 mm, no rate effects"),
    "blast_slab_empirical": ("blast_slab_empirical.toml", [],
                             "dx 10 mm, Kingery-Bulmash load, no charge"),
}
#: the first 60 us of the coarse model with a frame every 10 us (the
#: detonation's cross-sections; the products leave the box within 0.3 ms)
EARLY = ("blast_slab_coarse.toml", ["run.t_end=6e-5", "output.every=1e-5"])
#: material indices of the decks
CONCRETE, TNT = 0, 3
CENTRE_Y = 0.25  # the charge's axis, x = y = 0.25 m (the slab's centre)
CONCRETE_DENSITY = 2400.0  # [kg/m^3]
SLAB_TOP = 0.07  # [m]
#: the stand-offs of the comparison with the empirical load [m]
STANDOFFS = (0.1, 0.2, 0.3)
CHARGE = 0.08098  # the charge's mass in the lattice, as blast_slab_empirical.toml [kg]


def _frame(path: Path) -> dict:
    """Positions, displacements, damage and material of a frame's particles."""
    import h5py

    with h5py.File(path, "r") as f:
        return {k: f[k][:] for k in ("position", "displacement", "damage", "material")}


def face_damage(out: Path) -> tuple[np.ndarray, np.ndarray, float]:
    """The damage of the concrete's top and bottom particle layers at the last
    frame as (ny, nx) images, and the lattice spacing [m]."""
    from sphdyn.analysis.fragments import projected_max

    fr = _frame(sorted((out / "frames").glob("frame_*.h5"))[-1])
    concrete = fr["material"] == CONCRETE
    x0 = (fr["position"] - fr["displacement"])[concrete]
    d = fr["damage"][concrete]
    z = np.round(x0[:, 2], 6)
    dx = float(np.min(np.diff(np.unique(z))))
    top, bottom = z == z.max(), z == z.min()
    return (projected_max(x0[top], d[top], dx, (0, 1)),
            projected_max(x0[bottom], d[bottom], dx, (0, 1)), dx)


def draw_damage(fig, ax, img: np.ndarray, dx: float, title: str) -> None:
    """A face's damage image (ny, nx) of lattice spacing ``dx`` [m] on ``ax``,
    with its colour bar."""
    im = ax.imshow(img, origin="lower", cmap="inferno_r", vmin=0, vmax=1,
                   extent=(0, img.shape[1] * dx * 1e3, 0, img.shape[0] * dx * 1e3))
    ax.set_title(title)
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    fig.colorbar(im, ax=ax, shrink=0.8, label="damage")


def centre_deflection(out: Path, layer: int = 0, radius: float = 0.02):
    """The mean vertical displacement [m] of the concrete particles of the
    ``layer``-th lattice layer from the bottom within ``radius`` [m] of the
    slab's centre, at each frame (times [s])."""
    import h5py

    from sphdyn.io.hdf5 import read_frame_header

    times, w = [], []
    for path in sorted((out / "frames").glob("frame_*.h5")):
        with h5py.File(path, "r") as f:
            concrete = f["material"][:] == CONCRETE
            u = f["displacement"][:][concrete]
            x0 = f["position"][:][concrete] - u
        z = np.round(x0[:, 2], 6)
        near = (np.hypot(x0[:, 0] - CENTRE_Y, x0[:, 1] - CENTRE_Y) < radius) & (
            z == np.unique(z)[layer])
        times.append(read_frame_header(path)[0])
        w.append(u[near, 2].mean())
    return np.array(times), np.array(w)


def concrete_momentum(out: Path) -> tuple[np.ndarray, np.ndarray]:
    """The concrete's vertical momentum [N s] at each frame (times [s]): the
    sum of its particles' velocities times their mass (rho0 dx^3, one
    spacing for the whole slab)."""
    import h5py

    from sphdyn.io.hdf5 import read_frame_header

    frames = sorted((out / "frames").glob("frame_*.h5"))
    times, pz = [], []
    for path in frames:
        with h5py.File(path, "r") as f:
            concrete = f["material"][:] == CONCRETE
            v = f["velocity"][:][concrete]
            x0 = (f["position"][:] - f["displacement"][:])[concrete]
        dx = float(np.min(np.diff(np.unique(np.round(x0[:, 2], 6)))))
        times.append(read_frame_header(path)[0])
        pz.append(CONCRETE_DENSITY * dx ** 3 * v[:, 2].sum())
    return np.array(times), np.array(pz)


def cross_sections(out: Path, times: tuple[float, ...], band: float = 0.01):
    """Particles within ``band`` [m] of the plane y = 250 mm at the frames
    nearest ``times`` [s] (a slice of the products' cloud, and the slab's
    rows there): list of (time, x (n, 3), material (n,))."""
    from sphdyn.io.hdf5 import read_frame_header

    frames = sorted((out / "frames").glob("frame_*.h5"))
    stamps = np.array([read_frame_header(p)[0] for p in frames])
    found = []
    for t in times:
        k = int(np.argmin(np.abs(stamps - t)))
        fr = _frame(frames[k])
        near = np.abs(fr["position"][:, 1] - CENTRE_Y) < band
        found.append((stamps[k], fr["position"][near], fr["material"][near]))
    return found


TILTS = (0, 45, 90)


def plot_gauges(ax_s, ax_d, out: Path, label: str) -> dict:
    """Draw a run's bottom strain and bottom-centre displacement on ``ax_s``,
    ``ax_d``; their peaks and times as table columns."""
    from sphdyn.io import read_history_csv

    strain = read_history_csv(out / "gauges" / "bottom_strain.csv")
    disp = read_history_csv(out / "gauges" / "bottom_centre.csv")
    ax_s.plot(1e3 * strain["time"], 1e6 * strain["strain"], label=label)
    ax_d.plot(1e3 * disp["time"], 1e3 * disp["displacement_z"], label=label)
    i, j = np.argmin(disp["displacement_z"]), np.argmax(strain["strain"])
    return {"peak displacement [mm]": f"{1e3 * disp['displacement_z'][i]:.2f}",
            "at [ms]": f"{1e3 * disp['time'][i]:.2f}",
            "largest bottom strain [µm/m]": f"{1e6 * strain['strain'][j]:.0f}",
            "at [ms] ": f"{1e3 * strain['time'][j]:.2f}"}


def finish_gauge_axes(ax_s, ax_d) -> None:
    """Labels, grid and legends of the two gauge panels."""
    ax_s.set_ylabel("bottom-surface strain [µm/m]")
    ax_d.set_ylabel("displacement [mm]")
    ax_d.set_xlabel("time [ms]")
    for ax in (ax_s, ax_d):
        ax.grid(alpha=0.3)
        ax.legend()


def orientation(reuse: bool) -> None:
    """The charge-orientation study (module docstring): ensemble, figure, table."""
    import matplotlib.pyplot as plt

    from sphdyn.ensemble import run_ensemble
    from sphdyn.io.plots import markdown_table

    out = ROOT / "out" / "blast_slab_coarse-ensemble"
    if not (reuse and (out / "ensemble.csv").exists()):
        run_ensemble(ROOT / "examples" / "blast_slab_coarse.toml", 1,
                     [f"body.charge.geometry.tilt={','.join(map(str, TILTS))}"], out)
    fig, (ax_s, ax_d) = plt.subplots(2, 1, figsize=(9, 7), sharex=True,
                                     layout="constrained")
    rows = [{"tilt [deg]": tilt,
             **plot_gauges(ax_s, ax_d, out / f"sample_{k:04d}", f"tilt {tilt} deg")}
            for k, tilt in enumerate(TILTS)]
    finish_gauge_axes(ax_s, ax_d)
    fig.suptitle("Charge orientation: the coarse slab's gauges, the charge tilted about y "
                 "(0 = upright)")
    fig.savefig(ROOT / "docs" / "figures" / "blast_slab_orientation.png", dpi=110)
    print(markdown_table(rows))


def standoff(reuse: bool) -> None:
    """The explicit charge against the empirical load (module docstring)."""
    import matplotlib.pyplot as plt

    from sphdyn.io.plots import markdown_table
    from sphdyn.simulation import run_deck

    short = ["run.t_end=6e-4", "output.every=2e-5"]
    peaks, rows = {"explicit": [], "empirical": []}, []
    fig = plt.figure(figsize=(12, 9), layout="constrained")
    grid = fig.add_gridspec(2, 2)
    ax_t, ax_s = fig.add_subplot(grid[0, 0]), fig.add_subplot(grid[0, 1])
    for s in STANDOFFS:
        centre = SLAB_TOP + s + 0.035  # the charge's centre (70 mm long)
        runs = {
            "explicit": ("blast_slab_coarse.toml", [
                f"body.charge.geometry.centre=[0.25, 0.25, {centre:.4f}]",
                f"detonation.0.point=[0.25, 0.25, {centre + 0.033:.4f}]"]),
            "empirical": ("blast_slab_empirical.toml", [
                f"blast.0.point=[0.25, 0.25, {centre:.4f}]"]),
        }
        row = {"stand-off [mm]": f"{1e3 * s:.0f}",
               "Z top centre [m/kg^(1/3)]": f"{(s + 0.035) / CHARGE ** (1 / 3):.2f}"}
        for kind, (deck, over) in runs.items():
            out = ROOT / "out" / "blast_standoff" / f"{kind}_{1e3 * s:.0f}"
            run_deck(ROOT / "examples" / deck, out, over + short, reuse=reuse)
            t, pz = concrete_momentum(out)
            peaks[kind].append(-pz.min())
            row[f"{kind}: peak momentum [N s]"] = f"{-pz.min():.1f}"
            if s == STANDOFFS[0]:
                ax_t.plot(1e3 * t, -pz, "o-", ms=3, label=f"{kind} ({RUNS_LABEL[kind]})")
        row["ratio"] = f"{peaks['empirical'][-1] / peaks['explicit'][-1]:.2f}"
        rows.append(row)
    ax_t.set_title(f"Downward momentum of the concrete, stand-off {1e3 * STANDOFFS[0]:.0f} mm")
    ax_t.set_xlabel("time [ms]")
    ax_t.set_ylabel("momentum [N s]")
    for kind, marker in (("explicit", "o-"), ("empirical", "s-")):
        ax_s.plot([1e3 * s for s in STANDOFFS], peaks[kind], marker, label=RUNS_LABEL[kind])
    ax_s.set_title("Peak downward momentum of the concrete against the stand-off")
    ax_s.set_xlabel("stand-off (charge's bottom to the slab) [mm]")
    ax_s.set_ylabel("momentum [N s]")
    for ax in (ax_t, ax_s):
        ax.grid(alpha=0.3)
        ax.legend()
    for col, (kind, name) in enumerate((("explicit", "blast_slab_coarse"),
                                        ("empirical", "blast_slab_empirical"))):
        out = ROOT / "out" / name
        if not (out / "summary.json").exists():
            continue
        top, _, dx = face_damage(out)
        draw_damage(fig, fig.add_subplot(grid[1, col]), top, dx,
                    f"Top-face damage at 3 ms, 100 mm: {kind}")
    fig.suptitle("The explicit charge (SPH, no air) against the empirical load "
                 "(Kingery-Bulmash, free air) of the same 81 g of TNT, coarse slab")
    fig.savefig(ROOT / "docs" / "figures" / "blast_slab_empirical.png", dpi=110)
    print(markdown_table(rows))


#: labels of the comparison's two models
RUNS_LABEL = {"explicit": "SPH charge, products in vacuum",
              "empirical": "Kingery-Bulmash load"}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reuse", action="store_true", help="only read out/blast_slab*")
    ap.add_argument("--full", action="store_true", help="also run the dx 5 mm deck")
    ap.add_argument("--orientation", action="store_true",
                    help="the charge-orientation ensemble instead")
    ap.add_argument("--standoff", action="store_true",
                    help="the explicit charge against the empirical load instead")
    a = ap.parse_args()

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if a.orientation:
        orientation(a.reuse)
        return
    if a.standoff:
        standoff(a.reuse)
        return

    from sphdyn.io import read_history_csv
    from sphdyn.io.plots import markdown_table
    from sphdyn.simulation import run_examples

    outs = run_examples(ROOT, RUNS, "blast_slab", reuse=a.reuse, include_full=a.full)

    fig = plt.figure(figsize=(11, 11), layout="constrained")
    grid = fig.add_gridspec(3, 2, height_ratios=[1, 1, 1.1])
    ax_s, ax_d = fig.add_subplot(grid[0, :]), fig.add_subplot(grid[1, :])
    rows = []
    for name, out in outs.items():
        label = RUNS[name][2]
        peaks = plot_gauges(ax_s, ax_d, out, label)
        h = read_history_csv(out / "history.csv")
        summary = json.loads((out / "summary.json").read_text())
        rows.append({
            "model": label, **peaks,
            "chemical energy [kJ]": (f"{1e-3 * h['E_chemical'][-1]:.1f}"
                                     if "E_chemical" in h else "-"),
            "steps": summary["steps"], "wall [s]": f"{summary['wall_seconds']:.0f}",
            "energy error (max, rel.)": f"{summary['energy_error_max_rel']:.4f}",
            "status": summary["status"]})
    ax_s.set_title("Strain at the bottom surface, x = 200-300 mm at the centre line "
                   "(thesis Fig. 9.4)")
    ax_d.set_title("Vertical displacement at the bottom centre (thesis Fig. 9.5)")
    if "blast_slab" in outs:  # its bottom layer spalls under the gauge
        t, w = centre_deflection(outs["blast_slab"], layer=1)
        ax_d.plot(1e3 * t, 1e3 * w, "--", color="tab:green",
                  label="dx 5 mm, one layer up (frames; the bottom layer spalls there)")
    finish_gauge_axes(ax_s, ax_d)
    # the damage of the finest run found (the thesis's 5 mm if run)
    first = "blast_slab" if "blast_slab" in outs else next(iter(outs))
    top, bottom, dx = face_damage(outs[first])
    for col, (img, face) in enumerate(((top, "top"), (bottom, "bottom"))):
        draw_damage(fig, fig.add_subplot(grid[2, col]), img, dx,
                    f"Damage of the {face} face at the end (thesis Fig. 9.6)")
    fig.suptitle(f"TNT 100 mm above an RC slab (thesis ch. 9): {RUNS[first][2]} and "
                 "the runs found")
    figures = ROOT / "docs" / "figures"
    figures.mkdir(parents=True, exist_ok=True)
    fig.savefig(figures / "blast_slab.png", dpi=110)

    from sphdyn.simulation import run_deck

    early = ROOT / "out" / "blast_slab_early"
    run_deck(ROOT / "examples" / EARLY[0], early, EARLY[1], reuse=a.reuse)
    sections = cross_sections(early, (1e-5, 3e-5, 6e-5))
    fig, axes = plt.subplots(1, len(sections), figsize=(14, 4.6), layout="constrained")
    for ax, (t, x, mat) in zip(axes, sections):
        for m, colour, label in ((CONCRETE, "0.6", "concrete"), (TNT, "tab:orange",
                                                                 "detonation products")):
            sel = mat == m
            ax.scatter(1e3 * x[sel, 0], 1e3 * x[sel, 2], s=2, c=colour, label=label)
        ax.set_xlim(-100, 600)
        ax.set_ylim(-60, 540)
        ax.set_aspect("equal")
        ax.set_title(f"t = {1e6 * t:.0f} us")
        ax.set_xlabel("x [mm]")
    axes[0].set_ylabel("z [mm]")
    axes[0].legend(loc="upper left", markerscale=4)
    fig.suptitle("Slice through the charge's axis, 240 mm < y < 260 mm (thesis Fig. 9.7), "
                 "dx 10 mm, charge 3 mm")
    fig.savefig(figures / "blast_slab_detonation.png", dpi=110)

    print(markdown_table(rows))


if __name__ == "__main__":
    main()
