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
#: Side of a particle's square in the damage grid, in particle spacings.
SQUARE = 1.15
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
    """Write :func:`damage_grid_figure` to ``path`` (default
    ``OUT/ensemble_damage.png``); None if no sample has a frame."""
    fig = damage_grid_figure(out, recs, keys)
    if fig is None:
        return None
    return save_figure(fig, Path(path) if path else Path(out) / FIGURE)


def damage_grid_figure(out: str | Path, recs: list[dict] | None = None,
                       keys: list[str] | None = None):
    """Final damage of every sample, one panel each (paper Figs. 8-10, 13).

    Rows are the points of the ``--vary`` grid, columns the replicates.
    Particles at their final positions (x-y plane; in 3D all particles,
    the most damaged drawn on top, so a crack through the depth shows), each
    a filled square :data:`SQUARE` particle spacings wide (so the small
    openings of a jittered or heterogeneous lattice do not draw white lines
    that look like cracks), grey intact to black failed as in the paper, on
    one colour bar; zero-mass particles (initial cracks) are left out, so
    they show as gaps. All panels share their x and y axes [mm].
    Needs ``damage`` among the output fields. Returns the (unsaved) figure,
    or None if no sample has a frame.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.collections import PolyCollection
    from matplotlib.colors import LinearSegmentedColormap, Normalize
    from matplotlib.figure import Figure

    from ..io.plots import time_unit
    from ..io.frame_data import particle_spacing
    from ..io.snapshots import particle_squares

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
    panels = {}  # (row, col) -> (time, xy [mm], damage, square side [mm])
    for i, items in enumerate(rows.values()):
        for j, r in enumerate(items):
            frame = _final_frame(out / Path(r.get("dir", "")).name)
            if frame is None or "damage" not in frame[2]:
                continue
            t, _, f, _ = frame
            keep = f["mass"] > 0 if "mass" in f else np.ones(len(f["damage"]), bool)
            order = np.argsort(f["damage"][keep], kind="stable")
            dim = 2 if np.ptp(f["position"][:, 2]) == 0 else 3
            panels[i, j] = (t, f["position"][keep][order, :2] * 1e3,
                            f["damage"][keep][order],
                            SQUARE * particle_spacing(f["position"][keep], dim) * 1e3)
    if not panels:
        return None
    allxy = np.concatenate([p[1] for p in panels.values()])
    pad = 0.5 * max(p[3] for p in panels.values()) + 0.03 * np.ptp(allxy, axis=0).max()
    lo, hi = allxy.min(axis=0) - pad, allxy.max(axis=0) + pad
    t_factor, t_unit = time_unit(max(p[0] for p in panels.values()))

    cmap = LinearSegmentedColormap.from_list("damage", [(0.72, 0.72, 0.72), (0, 0, 0)])
    norm = Normalize(0.0, 1.0)
    size = 2.4
    panel_h = size * (hi[1] - lo[1]) / (hi[0] - lo[0])
    fig = Figure(figsize=(size * ncol + 1.6, (panel_h + 0.55) * len(rows) + 0.4),
                 dpi=110, layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(len(rows), ncol, sharex=True, sharey=True, squeeze=False)
    collection = None
    for i, (point, items) in enumerate(rows.items()):
        label = "\n".join(f"{k} = {v}" for k, v in zip(keys, point))
        for j in range(ncol):
            ax = axes[i, j]
            if j >= len(items):
                ax.set_visible(False)
                continue
            r = items[j]
            ax.set_xlim(lo[0], hi[0])
            ax.set_ylim(lo[1], hi[1])
            ax.set_aspect("equal")
            title = f"#{r.get('sample')} seed {r.get('seed', '?')}"
            status = r.get("status", "?")
            if (i, j) not in panels:
                ax.set_title(f"{title}\n{status}", fontsize=7)
                continue
            t, xy, damage, side = panels[i, j]
            collection = PolyCollection(particle_squares(xy, side), cmap=cmap,
                                        norm=norm, edgecolors="face", linewidths=0.4)
            collection.set_array(damage)
            ax.add_collection(collection)
            ax.set_title(f"{title}, {r.get('main_cracks', '?')} main\n"
                         f"{status} t = {t * t_factor:.4g} {t_unit}", fontsize=7)
            ax.tick_params(labelsize=7)
        axes[i, 0].set_ylabel((label + "\n" if label else "") + "y [mm]", fontsize=8)
    for j in range(ncol):  # x label under the lowest visible panel of each column
        visible = [i for i in range(len(rows)) if axes[i, j].get_visible()]
        axes[visible[-1], j].set_xlabel("x [mm]", fontsize=8)
        axes[visible[-1], j].xaxis.set_tick_params(labelbottom=True)
    if collection is not None:
        fig.colorbar(collection, ax=axes.ravel().tolist(), label="damage [-]",
                     shrink=0.8, aspect=30)
    return fig


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
            dimension=sim.deck.run.dimension,
            title=f"{body.name}: {draw.spec['distribution']} masses, seed {seed}"))
    return paths
