r"""Gauges: measurements at material points, each sampled at its own rate.

A ``[[gauge]]`` of the deck is one of

* **strain**: the engineering strain between two material points a and b,
  :math:`\varepsilon = |\mathbf x_b - \mathbf x_a| / |\mathbf X_b - \mathbf X_a| - 1`
  (a strain gauge glued between two points; thesis Fig. 8.3), column
  ``strain``;
* **point**: the displacement :math:`\mathbf x - \mathbf X` or the velocity of a
  material point (a displacement transducer; thesis Fig. 8.4), a column per
  quantity;
* **section**: the force the items in front of a plane (on its normal's side
  at the start) exert on those behind it, :math:`\mathbf F = \sum_{i\,\in\,
  \text{behind}} m_i (\mathbf a_i - \mathbf a^{ext}_i)`: the sum of the internal
  forces on the items behind, where the pairs (or elements) within them cancel,
  leaves the pairs and elements that straddle the plane (LS-DYNA's
  DATABASE_CROSS_SECTION). External loads (contact, gravity, couplings) are
  left out; a constraint's reaction is not in the accelerations. Columns
  ``force_x|y|z``; along the normal, positive is tension across the plane.

A material point is the particle or node nearest to the given point at the
start (of every part, or of the ``body`` or ``mesh`` named), which must lie
within one spacing of it. :math:`\mathbf X` are the items' initial positions.
The velocity is the one at the kick's time (the mid-kick velocity the
stepper books energies with). Each gauge samples at the first kick at or after
each multiple of its interval ``every``, at the history's time, and writes
``gauges/<name>.csv`` (time first); a restart continues the files.

The model and its tests: docs/theory.md, "Gauges".
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..deck import DeckError
from ..deck.errors import format_problem
from ..io.history import History
from .monitors import next_multiple
from ..state import BC_SLAVE


@dataclass
class Gauge:
    """One gauge: its items as (part index, item index) pairs and its columns.

    ``kind`` strain, point or section; ``items`` the material points (strain:
    a and b; point: one); ``side`` (section) per part the items behind the
    plane; ``quantities`` (point).
    """

    name: str
    kind: str
    every: float
    items: list = field(default_factory=list)
    length0: float = 0.0
    quantities: tuple = ()
    side: list = field(default_factory=list)
    history: History = field(default_factory=History)
    next_time: float = 0.0

    def values(self, parts) -> dict[str, float]:
        """The gauge's columns now."""
        if self.kind == "strain":
            (pa, a), (pb, b) = self.items
            xa, xb = parts[pa].kin.x[a], parts[pb].kin.x[b]
            return {"strain": float(np.linalg.norm(xb - xa) / self.length0 - 1.0)}
        if self.kind == "point":
            (pk, i), = self.items
            q = parts[pk].kin
            out = {}
            for name in self.quantities:
                what, axis = name.rsplit("_", 1)
                c = "xyz".index(axis)
                if what == "displacement":
                    out[name] = float(q.x[i, c] - q.x0[i, c])
                else:
                    v = q.v_mid if "v_mid" in q.names() else q.v
                    out[name] = float(v[i, c])
            return out
        f = np.zeros(3)
        for pk, idx in self.side:
            q = parts[pk].kin
            keep = idx[q.bc[idx] != BC_SLAVE]
            f += (q.inertia()[keep, None] * (q.a[keep] - q.a_ext[keep])).sum(axis=0)
        return {"force_x": float(f[0]), "force_y": float(f[1]), "force_z": float(f[2])}


def _candidates(deck, parts, spec):
    """(part index, item indices) the gauge may use: every part's items, or
    those of the body or mesh it names."""
    out = []
    for pk, part in enumerate(parts):
        q = part.kin
        if spec.mesh is not None:
            if part.name == spec.mesh:
                out.append((pk, np.arange(q.n)))
        elif spec.body is not None:
            if "body" in q.names():  # items labelled by body: the particles
                from ..build.model import particle_body_names

                k = particle_body_names(deck).index(spec.body)
                out.append((pk, np.flatnonzero(q.body == k)))
        else:
            out.append((pk, np.arange(q.n)))
    return out


def _nearest(deck, parts, spec, where: str, point) -> tuple[int, int]:
    """The item nearest to ``point`` at the start, within one spacing of it."""
    best = (math.inf, -1, -1, None)
    for pk, idx in _candidates(deck, parts, spec):
        if not idx.size:
            continue
        d = np.linalg.norm(parts[pk].kin.x0[idx] - np.asarray(point), axis=1)
        k = int(np.argmin(d))
        if d[k] < best[0]:
            best = (float(d[k]), pk, int(idx[k]), idx)
    dist, pk, i, idx = best
    if pk >= 0:
        # the spacing among the gauge's own items (a bar's sublayer particles
        # beside a concrete particle are not the concrete's spacing)
        x0 = parts[pk].kin.x0
        others = idx[idx != i]
        spacing = float(np.min(np.linalg.norm(x0[others] - x0[i], axis=1))) \
            if others.size else math.inf
        if dist <= spacing:
            return pk, i
    scope = f"body '{spec.body}'" if spec.body else (
        f"mesh '{spec.mesh}'" if spec.mesh else "the model")
    raise DeckError([format_problem(
        where, f"{tuple(point)} is not in {scope}: the nearest particle or node is "
        f"{dist:.3g} m away, more than the spacing there",
        "place the point inside the body or mesh (in the resolved deck's SI units)")])


def build_gauges(deck, parts) -> list[Gauge]:
    """The deck's gauges on the stepper's ``parts`` (``DeckError`` for a point
    outside the model or a section with nothing behind it)."""
    gauges = []
    for k, spec in enumerate(deck.gauge):
        every = spec.every if spec.every is not None else deck.run.t_end / 1000.0
        g = Gauge(spec.name, spec.type, every)
        where = f"gauge[{k}] '{spec.name}'"
        if spec.type == "strain":
            g.items = [_nearest(deck, parts, spec, f"{where}.points", p) for p in spec.points]
            (pa, a), (pb, b) = g.items
            g.length0 = float(np.linalg.norm(parts[pb].kin.x0[b] - parts[pa].kin.x0[a]))
            if g.length0 == 0.0:
                raise DeckError([format_problem(
                    f"{where}.points", "both ends are the same material point",
                    "put the ends at least one spacing apart")])
        elif spec.type == "point":
            g.items = [_nearest(deck, parts, spec, f"{where}.point", spec.point)]
            g.quantities = tuple(spec.quantities)
        else:
            n, p0 = np.asarray(spec.normal), np.asarray(spec.point)
            for pk, idx in _candidates(deck, parts, spec):
                behind = idx[(parts[pk].kin.x0[idx] - p0) @ n < 0.0]
                if behind.size:
                    g.side.append((pk, behind))
            if not g.side:
                raise DeckError([format_problem(
                    f"{where}.point", "no particle or node lies behind the plane",
                    "move the point or turn the normal so that the plane cuts the "
                    "model")])
        gauges.append(g)
    return gauges


class GaugeRecorder:
    """The monitor that samples the gauges: at the kick's time, each gauge
    whose next sample time has come (kept once the step has passed the
    guards, as the history rows)."""

    def __init__(self, gauges: list[Gauge]):
        self.gauges = gauges
        self._rows: list = []

    def after_kick(self, s) -> None:
        self._rows = []
        for g in self.gauges:
            if s.t >= g.next_time - 1e-9 * g.every:
                row = {"time": s.t}
                row.update(g.values(s.parts))
                self._rows.append((g, row))
                g.next_time = next_multiple(s.t, g.every)

    def after_step(self, s) -> None:
        for g, row in self._rows:
            g.history.append(row)
        self._rows = []

    def final(self, s) -> None:
        """A last sample of every gauge at the run's end (unless it has one)."""
        for g in self.gauges:
            last = g.history.as_arrays()["time"][-1] if len(g.history) else -math.inf
            if s.t > last:
                row = {"time": s.t}
                row.update(g.values(s.parts))
                g.history.append(row)

    def write(self, outdir: Path) -> None:
        """``gauges/<name>.csv`` of every gauge (atomic writes)."""
        for g in self.gauges:
            if len(g.history):
                (Path(outdir) / "gauges").mkdir(exist_ok=True)
                g.history.write_csv(Path(outdir) / "gauges" / f"{g.name}.csv")

    def resume(self, outdir: Path, t: float) -> None:
        """Continue the files of a run restarted at ``t``."""
        for g in self.gauges:
            path = Path(outdir) / "gauges" / f"{g.name}.csv"
            if path.exists():
                g.history = History.from_csv(path)
                g.history.truncate_after(np.nextafter(t, -np.inf))
            if len(g.history):  # the next sample as the run would have taken it
                g.next_time = next_multiple(g.history.as_arrays()["time"][-1], g.every)
