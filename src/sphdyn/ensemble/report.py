"""Reports of an ensemble: the table, the damage grid, the mass histograms.

:func:`write_report` (re)writes ``ensemble.csv`` and ``ensemble_damage.png``
from the sample directories alone (:func:`plot_damage_grid`);
:func:`plot_mass_histograms` draws a sample's mass histograms (paper Fig. 5)
from the mass fields its model drew.
"""

from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path

import numpy as np

from ..io.atomic import atomic_write_text
from ..io.plots import save_figure
from .plan import RESULT

TABLE = "ensemble.csv"
FIGURE = "ensemble_damage.png"

#: Columns of ``ensemble.csv`` after the sample, replicate, seed and vary keys.
COLUMNS = ("status", "peak_contact_force", "peak_contact_force_mean", "dissipated_energy",
           "viscous_energy", "damaged_volume_fraction", "main_cracks", "final_kinetic_energy",
           "initial_kinetic_energy", "zero_mass_particles", "steps", "wall_seconds",
           "cpu_seconds", "error", "dir")


def _records(out: Path) -> list[dict]:
    recs = []
    for d in sorted(Path(out).glob("sample_*")):
        path = d / RESULT
        if path.exists():
            recs.append(json.loads(path.read_text()))
        else:
            recs.append({"sample": int(d.name.split("_")[1]), "status": "not run",
                         "dir": str(d)})
    return recs


def write_report(out: str | Path) -> Path:
    """(Re)write ``OUT/ensemble.csv`` and ``OUT/ensemble_damage.png`` from the samples.

    Reads only the sample directories, so it can be called at any time, e.g.
    while an ensemble is running on a cluster.
    """
    out = Path(out)
    recs = _records(out)
    keys = list(dict.fromkeys(k for r in recs for k in r.get("vary", {})))
    header = ["sample", "replicate", "seed", *keys, *COLUMNS]
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(header)
    for r in recs:
        row = {**r, **{k: r.get("vary", {}).get(k, "") for k in keys}}
        row["dir"] = Path(r.get("dir", "")).name
        row["error"] = (r.get("error") or "").replace("\n", " | ")
        w.writerow(["" if row.get(c) is None else _fmt(row.get(c, "")) for c in header])
    path = atomic_write_text(out / TABLE, buf.getvalue())
    try:
        plot_damage_grid(out, recs, keys)
    except Exception as exc:  # the table matters more than the figure
        print(f"warning: damage grid not drawn: {exc}")
    return path


def _fmt(v) -> str:
    if isinstance(v, float):
        return "nan" if math.isnan(v) else repr(v)
    return str(v)


def _final_frame(sample_dir: Path):
    from ..io import read_frame
    from ..io.frames import list_frames

    frames = list_frames(sample_dir)
    return read_frame(frames[-1]) if frames else None


def plot_damage_grid(out: str | Path, recs: list[dict] | None = None,
                     keys: list[str] | None = None, path: str | Path | None = None
                     ) -> Path | None:
    """Final damage of every sample, one panel each (paper Figs. 8-10, 13).

    Rows are the points of the ``--vary`` grid, columns the replicates.
    Particles at their final positions (x-y plane; in 3D all particles,
    the most damaged drawn on top, so a crack through the depth shows),
    grey intact to black failed as in the paper; zero-mass particles (initial
    cracks) are left out, so they show as gaps. Needs ``damage`` among the
    output fields. Returns None if no sample has a frame.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.colors import LinearSegmentedColormap
    from matplotlib.figure import Figure

    from ..io.snapshots import particle_spacing

    out = Path(out)
    recs = _records(out) if recs is None else recs
    keys = list(dict.fromkeys(k for r in recs for k in r.get("vary", {}))) \
        if keys is None else keys
    rows: dict[tuple, list[dict]] = {}
    for r in recs:
        rows.setdefault(tuple(r.get("vary", {}).get(k) for k in keys), []).append(r)
    ncol = max(len(v) for v in rows.values()) if rows else 0
    if not ncol:
        return None
    cmap = LinearSegmentedColormap.from_list("damage", [(0.72, 0.72, 0.72), (0, 0, 0)])
    size = 2.4
    fig = Figure(figsize=(size * ncol + 0.8, size * len(rows) + 0.4), dpi=110)
    FigureCanvasAgg(fig)
    drawn = 0
    squares = []  # (axes, scatter, spacing [mm]): squares sized once laid out
    for i, (point, items) in enumerate(rows.items()):
        label = ", ".join(f"{k} = {v}" for k, v in zip(keys, point))
        for j, r in enumerate(items):
            ax = fig.add_subplot(len(rows), ncol, i * ncol + j + 1)
            ax.set_xticks([])
            ax.set_yticks([])
            ax.set_aspect("equal")
            frame = _final_frame(Path(out) / Path(r.get("dir", "")).name)
            status = r.get("status", "?")
            title = f"#{r.get('sample')} seed {r.get('seed', '?')}"
            if frame is None or "damage" not in frame[2]:
                ax.set_title(f"{title}\n{status}", fontsize=7)
                continue
            t, _, f, _ = frame
            keep = f["mass"] > 0 if "mass" in f else np.ones(len(f["damage"]), bool)
            order = np.argsort(f["damage"][keep], kind="stable")
            xy = f["position"][keep][order] * 1e3
            ext = max(np.ptp(xy[:, 0]), np.ptp(xy[:, 1]), 1e-9)
            dim = 2 if np.ptp(f["position"][:, 2]) == 0 else 3
            dots = ax.scatter(xy[:, 0], xy[:, 1], c=f["damage"][keep][order], cmap=cmap,
                              vmin=0, vmax=1, marker="s", linewidths=0)
            squares.append((ax, dots, particle_spacing(f["position"][keep], dim) * 1e3))
            ax.set_xlim(xy[:, 0].min() - 0.05 * ext, xy[:, 0].max() + 0.05 * ext)
            ax.set_ylim(xy[:, 1].min() - 0.05 * ext, xy[:, 1].max() + 0.05 * ext)
            cracks = r.get("main_cracks", "?")
            ax.set_title(f"{title}, {cracks} main\n"
                         f"{status} t = {t * 1e6:.0f} us", fontsize=7)
            if j == 0 and label:
                ax.set_ylabel(label, fontsize=8)
            drawn += 1
    if not drawn:
        return None
    fig.tight_layout()
    for ax, dots, spacing in squares:
        # one particle spacing in points, from the axes' final size, so the
        # squares tile the lattice without gaps or overlap
        ax.apply_aspect()
        width_pt = ax.get_position().width * fig.get_figwidth() * 72
        side = spacing * width_pt / np.ptp(ax.get_xlim())
        dots.set_sizes([side ** 2])
    path = Path(path) if path else out / FIGURE
    return save_figure(fig, path)


def plot_mass_histograms(sim, outdir: str | Path) -> list[Path]:
    """``plots/mass_histogram.png`` of every body with a random mass field.

    ``plots/mass_histogram.png`` for the first body,
    ``plots/mass_histogram_<body>.png`` for the others. Plots the field the
    model drew (``sim.model.mass_draws``), never a new draw: the masses
    ``m0 * f * scale`` of the solid particles (initial-crack particles are
    left out), on the axes of the requested law. Without a mesostructure
    these are the particles' masses; with one, a particle's mass is that
    times its phase's density over the body material's. Returns the paths.
    """
    from ..heterogeneity.mass import distribution
    from ..heterogeneity.plots import plot_mass_histogram

    draws = sim.model.mass_draws
    seed = sim.deck.run.seed
    paths = []
    for b, body in enumerate(sim.deck.body):
        draw = draws.get(body.name)
        if draw is None:
            continue
        name = "mass_histogram.png" if b == 0 else f"mass_histogram_{body.name}.png"
        paths.append(plot_mass_histogram(
            draw.m0 * draw.factors * draw.scale, Path(outdir) / "plots" / name,
            law=distribution(draw.spec), m0=draw.m0, scale=draw.scale,
            title=f"{body.name}: {draw.spec['distribution']} masses, seed {seed}"))
    return paths
