"""What a run's frames hold, for the pictures drawn of them.

:func:`select_frames` picks frames by time, :func:`slab_mask` the particles
of a 3D slab, :func:`particle_spacing` their spacing, :func:`field_values`
the values of a field, a component (``stress_xy``) or a magnitude
(``velocity``) with its unit from the field registry (:mod:`sphdyn.fields`),
:func:`available_fields` what a frame can show; :func:`run_labels` says how
runs shown side by side differ (their resolved decks). Read by
:mod:`.snapshots` (the panels) and the ensemble report.
"""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import numpy as np

from ..fields import FIELDS
from ..geometry.lattice import axis_index
from .plots import time_unit

__all__ = ["select_frames", "slab_mask", "particle_spacing", "field_values",
           "available_fields", "run_labels"]

_TENSOR = ("xx", "xy", "xz", "yx", "yy", "yz", "zx", "zy", "zz")
_TENSOR_RE = re.compile(r"^(.+)_(xx|xy|xz|yx|yy|yz|zx|zy|zz)$")
_VECTOR_RE = re.compile(r"^(.+)_([xyz])$")

#: SI unit of each output field (components and magnitudes share it), from
#: the field registry
_UNITS = {name: f.unit for name, f in FIELDS.items()}


def select_frames(frame_times, times=None, n: int = 4) -> list[int]:
    """Indices of the frames to show, in increasing time.

    Parameters
    ----------
    frame_times : array_like
        Times [s] of the frames, in frame order (non-decreasing).
    times : sequence of float, optional
        Wanted times [s]: the frame nearest to each is taken (the earlier one
        on a tie). Duplicates are dropped. A time more than half the largest
        frame interval before the first frame or after the last is refused
        (ValueError naming the run's time range): no frame shows it.
    n : int, optional
        Without ``times``: the number of frames, evenly spaced in time from
        the first frame to the last, both included (``n = 1``: the last
        frame). Fewer are returned if the run has fewer frames.

    Returns
    -------
    list of int
        Sorted, unique frame indices.
    """
    ft = np.asarray(frame_times, dtype=float)
    if ft.size == 0:
        raise ValueError("the run has no frames")
    if times is None:
        n = int(n)
        if n < 1:
            raise ValueError(f"n must be at least 1, not {n}")
        targets = [ft[-1]] if n == 1 else np.linspace(ft[0], ft[-1], n)
    else:
        targets = np.atleast_1d(np.asarray(times, dtype=float))
        if targets.size == 0:
            raise ValueError("times is empty")
        if not np.all(np.isfinite(targets)):
            raise ValueError(f"times must be finite, got {list(targets)}")
        gaps = np.diff(ft)
        slack = max(0.5 * float(gaps.max()) if gaps.size else 0.0,
                    1e-9 * max(abs(ft[0]), abs(ft[-1])))
        outside = targets[(targets < ft[0] - slack) | (targets > ft[-1] + slack)]
        if outside.size:
            factor, unit = time_unit(ft[-1] - ft[0] or ft[-1])
            show = ", ".join(f"{t:g} s" for t in outside)
            raise ValueError(
                f"time {show} is outside the run: its {ft.size} frame(s) span "
                f"{ft[0]:g} to {ft[-1]:g} s ({ft[0] * factor:.4g} to "
                f"{ft[-1] * factor:.4g} {unit}). Fix: give times from {ft[0]:g} to "
                f"{ft[-1]:g} s (a run stopped early has no later frames)")
    picked = {int(np.argmin(np.abs(ft - t))) for t in targets}
    return sorted(picked)


def slab_mask(position: np.ndarray, axis: str | int = "z",
              width: float | None = None, centre: float | None = None) -> np.ndarray:
    """Particles within ``|x_axis - centre| <= width / 2``.

    Parameters
    ----------
    position : ndarray, shape (N, 3)
        Particle positions [m].
    axis : {'x', 'y', 'z'} or int
        Normal of the slab.
    width : float
        Slab thickness [m].
    centre : float, optional
        Slab mid-plane [m]; default the middle of the positions' extent along
        ``axis``.

    Returns
    -------
    ndarray of bool, shape (N,)
    """
    k = axis_index(axis)
    if width is None or not width > 0:
        raise ValueError(f"slab width must be positive, not {width!r}")
    c = np.asarray(position, dtype=float)[:, k]
    if centre is None:
        centre = 0.5 * (c.min() + c.max()) if c.size else 0.0
    # A relative tolerance keeps lattice planes exactly on the boundary inside.
    return np.abs(c - centre) <= 0.5 * width * (1.0 + 1e-9)


def particle_spacing(position: np.ndarray, dimension: int = 3) -> float:
    """Median nearest-neighbour distance [m] (the lattice spacing dx).

    In 2D only the x-y coordinates are used.
    """
    from scipy.spatial import cKDTree

    x = np.asarray(position, dtype=float)[:, :dimension]
    if x.shape[0] < 2:
        raise ValueError("need at least two particles to measure their spacing")
    d, _ = cKDTree(x).query(x, k=2)
    nn = d[:, 1]
    nn = nn[nn > 0]
    if nn.size == 0:
        raise ValueError("all particles are at the same position")
    return float(np.median(nn))


def available_fields(fields: dict[str, np.ndarray]) -> list[str]:
    """Names :func:`field_values` accepts for a frame's ``fields``."""
    names: list[str] = []
    for name, data in fields.items():
        data = np.asarray(data)
        cols = data.reshape(data.shape[0], -1).shape[1] if data.ndim else 0
        if data.ndim == 1:
            names.append(name)
        elif cols == 3:
            names += [name] + [f"{name}_{c}" for c in "xyz"]
        elif cols == 9:
            names += [f"{name}_{c}" for c in _TENSOR]
    if "velocity" in fields and "speed" not in fields:
        names.append("speed")
    return names


def field_values(fields: dict[str, np.ndarray], name: str) -> tuple[np.ndarray, str]:
    """Scalar values of ``name`` for every particle of a frame.

    Accepted names: a scalar field of the frame (``von_mises``, ``damage``,
    ``plastic_strain``, ...); a vector field (its magnitude) or one of its
    components ``<vector>_x|y|z``; a tensor component ``<tensor>_xx ... _zz``
    (``stress_yy``: row-major index 4 of the 9 components, tension positive);
    ``speed`` (``|velocity|``).

    Returns
    -------
    values : ndarray, shape (N,)
    unit : str
        SI unit ("" if unknown, "-" if dimensionless).

    Raises
    ------
    ValueError
        If the name is not available; the message lists the names that are.
    """
    def unit(base: str) -> str:
        return _UNITS.get(base, "")

    data = fields.get(name)
    if data is not None:
        data = np.asarray(data)
        if data.ndim == 1:
            return data.astype(float), unit(name)
        flat = data.reshape(data.shape[0], -1)
        if flat.shape[1] == 3:
            return np.linalg.norm(flat.astype(float), axis=1), unit(name)
        if flat.shape[1] == 9:
            raise ValueError(f"{name!r} is a tensor: give a component such as "
                             f"'{name}_xx' or '{name}_yy' (or a scalar such as "
                             "'von_mises')")
    if name == "speed" and "velocity" in fields:
        v = np.asarray(fields["velocity"], dtype=float)
        return np.linalg.norm(v.reshape(v.shape[0], -1), axis=1), unit("speed")
    m = _TENSOR_RE.match(name)
    if m and m.group(1) in fields:
        t = np.asarray(fields[m.group(1)])
        t = t.reshape(t.shape[0], -1)
        if t.shape[1] == 9:
            return t[:, _TENSOR.index(m.group(2))].astype(float), unit(m.group(1))
    m = _VECTOR_RE.match(name)
    if m and m.group(1) in fields:
        v = np.asarray(fields[m.group(1)])
        v = v.reshape(v.shape[0], -1)
        if v.shape[1] == 3:
            return v[:, "xyz".index(m.group(2))].astype(float), unit(m.group(1))
    raise ValueError(f"field {name!r} is not in the frames; available: "
                     f"{available_fields(fields)}")


def _flat_deck(value, prefix: str = "", out: dict | None = None) -> dict:
    """A resolved deck as ``{dotted key: value}``; tables in arrays keyed by name."""
    out = {} if out is None else out
    if isinstance(value, dict):
        for k, v in value.items():
            _flat_deck(v, f"{prefix}.{k}" if prefix else str(k), out)
    elif isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
        for i, item in enumerate(value):
            _flat_deck(item, f"{prefix}.{item.get('name', i)}", out)
    else:
        out[prefix] = value
    return out


def _deck_value(value) -> str:
    if value is None:
        return "absent"
    if isinstance(value, float):
        return f"{value:.4g}"
    if isinstance(value, list):
        return "[" + ", ".join(_deck_value(v) for v in value) + "]"
    return str(value)


def run_labels(outdirs, max_keys: int = 3) -> list[str]:
    """Row labels of runs shown side by side: directory name, then the deck
    values that differ between the runs (``key = value``, at most ``max_keys``
    of them, then how many more).

    Reads each run's ``deck.resolved.toml``; the title is left out (runs made
    with ``--set`` share it). A run without that file shows only its name.
    """
    decks = []
    for d in outdirs:
        try:
            with open(Path(d) / "deck.resolved.toml", "rb") as f:
                flat = _flat_deck(tomllib.load(f))
        except (OSError, tomllib.TOMLDecodeError):
            flat = {}
        flat.pop("run.title", None)
        decks.append(flat)
    keys = sorted({k for flat in decks for k in flat})
    differ = [k for k in keys if len({repr(flat.get(k)) for flat in decks}) > 1]
    labels = []
    for d, flat in zip(outdirs, decks):
        lines = [Path(d).name] + [f"{k} = {_deck_value(flat.get(k))}"
                                  for k in differ[:max_keys]]
        if len(differ) > max_keys:
            lines.append(f"(+{len(differ) - max_keys} more differ)")
        labels.append("\n".join(lines))
    return labels


def run_info(outdir: Path) -> tuple[int | None, str]:
    """Dimension and title from ``deck.resolved.toml`` (None, "" if absent)."""
    try:
        with open(outdir / "deck.resolved.toml", "rb") as f:
            run = tomllib.load(f).get("run", {})
    except (OSError, tomllib.TOMLDecodeError):
        return None, ""
    dim = run.get("dimension")
    return (int(dim) if dim in (1, 2, 3) else None), str(run.get("title", "") or "")
