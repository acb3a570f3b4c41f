"""Snapshot panels: the particles of selected frames coloured by a field.

What is drawn (the frames, the slab, the field's values) comes from
:mod:`.frame_data`.

:func:`plot_snapshots` draws one panel per selected frame of a run directory
(``outdir/frames/frame_*.h5``), all on one colour scale with one colour bar,
like the ring and disc figures of the thesis and the paper:

* 1D runs: the field along x, one line per frame (one axes per run);
* 2D runs: the particles at their x-y positions;
* 3D runs: the particles of a slab around the mid-plane of ``slice_axis``,
  in the other two coordinates.

Each particle is drawn as a filled square whose side is the particle spacing
(median nearest-neighbour distance in the first frame), in data units, so an
intact body looks solid and cracks or separated particles show as gaps.
Coordinates are shown in mm.

Figures are drawn with Matplotlib's object-oriented API on the Agg canvas (no
pyplot, no global state) and saved atomically.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from ..geometry.lattice import axis_index
from .frame_data import (field_values, particle_spacing, run_info, run_labels,
                         select_frames, slab_mask)
from .plots import save_figure, time_unit
from .frames import frames_of_run
from .hdf5 import read_frame, read_frame_header

__all__ = ["plot_snapshots", "particle_squares"]


_DAMAGE_COLOURS = ((0.72, 0.72, 0.72), (0.0, 0.0, 0.0))  # intact grey, failed black


# ------------------------------------------------------------------ selection


# --------------------------------------------------------------------- fields


# --------------------------------------------------------------------- drawing

def _length_scale(extent: float) -> tuple[float, str]:
    """Factor and unit of coordinates spanning ``extent`` [m]: mm below 1 m."""
    return (1e3, "mm") if extent < 1.0 else (1.0, "m")


def _line_figure(loaded, field: str, row_labels, out, runs, vmin, vmax, dpi) -> Path:
    """The 1D snapshots: for each run (one axes per run, stacked) the field
    against x, one line per selected frame coloured by its time."""
    from matplotlib import colormaps
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    panels = [pan for run in loaded for pan in run[0]]
    unit, title = loaded[0][1], loaded[0][3]
    values = np.concatenate([v[np.isfinite(v)] for _, _, v in panels])
    magnitude = float(np.abs(values).max()) if values.size else 1.0
    factor, shown_unit = _display_scale(unit, magnitude)
    xs = np.concatenate([xy[:, 0] for _, xy, _ in panels])
    x_factor, x_unit = _length_scale(float(np.ptp(xs)) if xs.size else 0.0)
    t_max = max(t for t, _, _ in panels)
    fig = Figure(figsize=(8.0, 1.0 + 2.8 * len(loaded)), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(len(loaded), 1, sharex=True, squeeze=False)[:, 0]
    cmap = colormaps["viridis"]
    for ax, run, label in zip(axes, loaded, row_labels):
        frames = run[0]
        for k, (t, xy, v) in enumerate(frames):
            order = np.argsort(xy[:, 0], kind="stable")
            colour = cmap(k / max(len(frames) - 1, 1))
            ax.plot(xy[order, 0] * x_factor, v[order] * factor, color=colour, lw=1.2,
                    marker="." if len(order) <= 200 else None, ms=3,
                    label=_time_label(t, t_max))
        name = field if not shown_unit else f"{field} [{shown_unit}]"
        ax.set_ylabel(f"{label}\n{name}" if len(runs) > 1 else name,
                      fontsize=10 if len(runs) == 1 else 8)
        if vmin is not None or vmax is not None:
            ax.set_ylim(None if vmin is None else vmin * factor,
                        None if vmax is None else vmax * factor)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="best")
    axes[-1].set_xlabel(f"x [{x_unit}]")
    fig.suptitle(f"{field}: {title}" if len(runs) == 1 else field, fontsize=11)
    dest = Path(out) if out is not None else runs[0] / "plots" / f"snapshots_{field}.png"
    return save_figure(fig, dest, dpi)


def _display_scale(unit: str, magnitude: float) -> tuple[float, str]:
    """Factor and unit in which values of ``unit`` are shown."""
    if unit == "Pa":
        for factor, name in ((1e-9, "GPa"), (1e-6, "MPa"), (1e-3, "kPa")):
            if magnitude * factor >= 1.0:
                return factor, name
        return 1.0, "Pa"
    if unit == "m":
        return 1e3, "mm"
    return 1.0, unit


def _time_label(t: float, t_max: float) -> str:
    factor, unit = time_unit(t_max)
    return f"t = {t * factor:.4g} {unit}"


def _grid(n_panels: int, box_w: float, box_h: float) -> tuple[int, int]:
    """(rows, cols) making a figure about 2.5 times as wide as high, few empty cells."""
    best, best_score = (1, n_panels), math.inf
    for ncols in range(1, n_panels + 1):
        nrows = math.ceil(n_panels / ncols)
        if (nrows - 1) * ncols >= n_panels:
            continue
        ratio = (nrows * box_h) / (ncols * box_w)
        score = abs(math.log(ratio / 0.4)) + 0.5 * (nrows * ncols - n_panels)
        if score < best_score - 1e-12:
            best, best_score = (nrows, ncols), score
    return best


def particle_squares(xy: np.ndarray, side: float) -> np.ndarray:
    """Vertices ``(N, 4, 2)`` of axis-aligned squares centred on ``xy``."""
    h = 0.5 * side
    corners = np.array([[-h, -h], [h, -h], [h, h], [-h, h]])
    return xy[:, None, :] + corners[None, :, :]


def _run_panels(outdir: Path, field: str, times, n: int, k_slice: int,
                slice_width: float | None):
    """Frames of one run for :func:`plot_snapshots`.

    Returns ``(panels, unit, spacing, title, plane, slab)`` with ``panels`` a
    list of ``(time [s], xy [m] (n, 2), values [SI] (n,))``; in 1D ``plane``
    is ``(0,)`` and ``xy`` is ``(n, 1)``, the x coordinates.
    """
    frame_files = frames_of_run(outdir)
    frame_times = [read_frame_header(f)[0] for f in frame_files]
    try:
        chosen = select_frames(frame_times, times=times, n=n)
    except ValueError as exc:
        raise ValueError(f"{outdir}: {exc}") from None

    # Spacing and slab from the first frame of the run.
    _, _, first, _ = read_frame(frame_files[0])
    x0 = np.asarray(first["position"], dtype=float)
    dimension, title = run_info(outdir)
    if dimension is None:
        flat = [np.ptp(x0[:, k]) == 0.0 for k in (1, 2)] if x0.size else [True, True]
        dimension = 1 if all(flat) else 2 if flat[1] else 3
    spacing = particle_spacing(x0, dimension)
    if dimension == 1:  # the field along x: no plane, no slab
        plane = (0,)
        slab = None
    elif dimension == 2:
        plane = (0, 1)
        slab = None
    else:
        plane = tuple(k for k in range(3) if k != k_slice)
        width = 1.5 * spacing if slice_width is None else float(slice_width)
        c = x0[:, k_slice]
        slab = (width, 0.5 * (c.min() + c.max()))

    panels = []
    unit = ""
    for i in chosen:
        t, _, fields, _ = read_frame(frame_files[i])
        values, unit = field_values(fields, field)
        x = np.asarray(fields["position"], dtype=float)
        if slab is not None:
            keep = slab_mask(x, k_slice, slab[0], slab[1])
            x, values = x[keep], values[keep]
        panels.append((t, x[:, plane], values))
    return panels, unit, spacing, title or outdir.name, plane, slab


def plot_snapshots(outdir, field: str = "von_mises",
                   times=None, n: int = 4, out: str | os.PathLike | None = None,
                   slice_axis: str = "z", slice_width: float | None = None,
                   cmap=None, vmin: float | None = None, vmax: float | None = None,
                   marker_size: float | None = None, dpi: int = 110) -> Path:
    """Panel figure of the particles of selected frames coloured by a field
    (1D runs: the field along x, one line per frame).

    Parameters
    ----------
    outdir : str or os.PathLike, or a list of them
        Output directory of a run (with ``frames/frame_*.h5``). With several
        runs (e.g. the same case with different remedies) the figure has one
        row per run, labelled by :func:`run_labels` (directory name and the
        deck values that differ between the runs), and one column per
        selected time; colour scale and axes are shared.
    field : str, optional
        What to colour by: any scalar field in the frames (``von_mises``,
        ``pressure``, ``damage``, ``plastic_strain``, ...), a vector field
        (its magnitude) or component (``velocity_y``), a tensor component
        (``stress_xx`` ... ``stress_zz``, tension positive) or ``speed``
        (``|velocity|``). See :func:`field_values`.
    times : sequence of float, optional
        Times [s]; the frame nearest to each is shown.
    n : int, optional
        Without ``times``: this many frames evenly spaced in time, first and
        last included (default 4).
    out : str or os.PathLike, optional
        PNG to write; default ``outdir/plots/snapshots_<field>.png`` (of the
        first run).
    slice_axis : {'x', 'y', 'z'}, optional
        3D runs: normal of the slab shown (default ``z``: x-y view; ``y``:
        x-z view; ``x``: y-z view). Ignored in 2D.
    slice_width : float, optional
        3D runs: slab thickness [m] around the mid-plane of the first frame's
        extent along ``slice_axis``; default 1.5 x the particle spacing.
        Particles are selected by their current position in each frame.
    cmap : str or matplotlib colormap, optional
        Default: grey (intact) to black (failed) for ``damage``; ``RdBu_r``
        centred on zero for fields with both signs; ``viridis`` otherwise.
    vmin, vmax : float, optional
        Colour-scale limits in SI units; default the range over all panels
        (symmetric about zero for fields with both signs; 0..1 for damage).
    marker_size : float, optional
        Side of the square drawn per particle [m]; default the particle
        spacing (median nearest-neighbour distance in the first frame).
    dpi : int, optional
        Resolution of the PNG.

    Returns
    -------
    pathlib.Path
        The PNG written.

    Raises
    ------
    FileNotFoundError
        If ``outdir`` has no frames.
    ValueError
        If ``field`` is not available (the message lists what is), or for
        bad ``times``, ``n``, ``slice_axis`` or ``slice_width``.
    """
    runs = [Path(d) for d in outdir] if isinstance(outdir, (list, tuple)) else [
        Path(outdir)]
    if not runs:
        raise ValueError("no run directory given")
    k_slice = axis_index(slice_axis)
    loaded = [_run_panels(d, field, times, n, k_slice, slice_width) for d in runs]
    panels = [pan for run in loaded for pan in run[0]]
    unit = loaded[0][1]
    spacing = loaded[0][2]
    plane, slab = loaded[0][4], loaded[0][5]
    title = loaded[0][3]
    row_labels = run_labels(runs) if len(runs) > 1 else [""]
    if vmin is not None and vmax is not None and not float(vmax) > float(vmin):
        raise ValueError(f"vmax ({vmax}) must be greater than vmin ({vmin})")
    if len(plane) == 1:
        return _line_figure(loaded, field, row_labels, out, runs, vmin, vmax, dpi)
    side = float(marker_size) if marker_size is not None else spacing

    # Shared colour scale.
    finite = np.concatenate([v[np.isfinite(v)] for _, _, v in panels])
    lo = float(finite.min()) if finite.size else 0.0
    hi = float(finite.max()) if finite.size else 1.0
    is_damage = field == "damage"
    signed = lo < 0.0 < hi and not is_damage
    if is_damage:
        dlo, dhi = 0.0, 1.0
    elif signed:
        dhi = max(-lo, hi)
        dlo = -dhi
    else:
        dlo, dhi = lo, hi
    vlo = dlo if vmin is None else float(vmin)
    vhi = dhi if vmax is None else float(vmax)
    if not vhi > vlo:
        vhi = vlo + (abs(vlo) * 1e-6 or 1.0)
    factor, shown_unit = _display_scale(unit, max(abs(vlo), abs(vhi)))
    extend = {(False, False): "neither", (True, False): "min",
              (False, True): "max", (True, True): "both"}[(lo < vlo, hi > vhi)]

    from matplotlib import colormaps
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.collections import PolyCollection
    from matplotlib.colors import LinearSegmentedColormap, Normalize
    from matplotlib.figure import Figure

    if cmap is None:
        if is_damage:
            cmap = LinearSegmentedColormap.from_list("sphdyn_damage", _DAMAGE_COLOURS)
        else:
            cmap = "RdBu_r" if signed else "viridis"
    if isinstance(cmap, str):
        cmap = colormaps[cmap]
    norm = Normalize(vlo * factor, vhi * factor)

    # Shared limits [mm]: everything shown, plus half a square.
    allxy = np.concatenate([xy for _, xy, _ in panels]) * 1e3
    if allxy.size:
        pad = 0.5 * side * 1e3 + 0.02 * max(np.ptp(allxy[:, 0]), np.ptp(allxy[:, 1]),
                                           spacing * 1e3)
        xlim = (allxy[:, 0].min() - pad, allxy[:, 0].max() + pad)
        ylim = (allxy[:, 1].min() - pad, allxy[:, 1].max() + pad)
    else:  # empty slab
        xlim = ylim = (-1.0, 1.0)
    box_w, box_h = xlim[1] - xlim[0], ylim[1] - ylim[0]
    if len(runs) > 1:  # one row per run
        ncols = max(len(run[0]) for run in loaded)
        nrows = len(runs)
        slots = [(r, c) for r, run in enumerate(loaded) for c in range(len(run[0]))]
    else:
        nrows, ncols = _grid(len(panels), box_w, box_h)
        slots = [divmod(k, ncols) for k in range(len(panels))]

    # Figure size [in] from the panels' aspect: room for the y labels and
    # colour bar on the side, panel titles and tick labels on each row.
    fig_w = 10.0
    panel_w = (fig_w - 1.9 - 0.2 * (ncols - 1)) / ncols
    panel_h = panel_w * box_h / box_w
    fig_h = min(max(nrows * (panel_h + 0.45) + 0.75, 2.5), 14.0)
    fig = Figure(figsize=(fig_w, fig_h), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(nrows, ncols, sharex=True, sharey=True, squeeze=False)
    t_max = max(t for t, _, _ in panels)
    names = "xyz"
    collection = None
    used = set(slots)
    for row in range(nrows):
        for col in range(ncols):
            if (row, col) not in used:
                axes[row, col].set_visible(False)
    for idx, (row, col) in enumerate(slots):
        ax = axes[row, col]
        t, xy, values = panels[idx]
        collection = PolyCollection(particle_squares(xy * 1e3, side * 1e3), cmap=cmap,
                                    norm=norm, edgecolors="face", linewidths=0.5,
                                    antialiaseds=True)
        collection.set_array(values * factor)
        ax.add_collection(collection)
        ax.set_xlim(*xlim)
        ax.set_ylim(*ylim)
        ax.set_aspect("equal")
        ax.set_title(_time_label(t, t_max), fontsize=10 if len(runs) == 1 else 9)
        if row == nrows - 1 or (row + 1, col) not in used:
            ax.set_xlabel(f"{names[plane[0]]} [mm]")
            ax.xaxis.set_tick_params(labelbottom=True)
        if col == 0:
            run_label = row_labels[row] + "\n" if len(runs) > 1 else ""
            ax.set_ylabel(f"{run_label}{names[plane[1]]} [mm]",
                          fontsize=10 if len(runs) == 1 else 8)
    label = field if not shown_unit else f"{field} [{shown_unit}]"
    if collection is not None:
        fig.colorbar(collection, ax=axes.ravel().tolist(), label=label,
                     extend=extend, shrink=0.9)
    heading = f"{field}: {title}" if len(runs) == 1 else f"{field}"
    if slab is not None:
        heading += (f"  (slab |{names[k_slice]} - {slab[1] * 1e3:.3g} mm| "
                    f"≤ {0.5 * slab[0] * 1e3:.3g} mm)")
    fig.suptitle(heading, fontsize=11)

    dest = Path(out) if out is not None else runs[0] / "plots" / f"snapshots_{field}.png"
    return save_figure(fig, dest, dpi)
