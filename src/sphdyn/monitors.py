"""Monitors: what watches the step from outside it (guards, history, output cadence).

A monitor has any of the hooks the :class:`~sphdyn.stepper.Stepper` calls:
``before_step(stepper, dt, k, part)`` with the step about to be taken,
``after_kick(stepper)`` with the state at the kick's time :math:`t^n`, and
``after_step(stepper)`` at :math:`t^{n+1}`. They are attached in this order
by :class:`~sphdyn.simulation.Simulation`: the thread tuner
(:mod:`sphdyn.threads`, when the thread count is automatic), guards, history
(with probes), the energy guard (after the history, so that the row that
broke the limit is kept), frames, checkpoints, progress, the history flush.
"""

from __future__ import annotations

import math
import time

import numpy as np

from .guards import EnergyError, check_particles, check_time_step, energy_diagnosis
from .io.plots import energy_columns
from .probes import record as probe_record


class Guards:
    """Stop the run with a diagnosis: time-step collapse, NaN, particles leaving
    the domain box ``[lo, hi]`` (see :mod:`sphdyn.guards`)."""

    def __init__(self, lo, hi, collapse_ratio: float, parts):
        self.lo, self.hi, self.collapse_ratio = lo, hi, collapse_ratio
        for part in parts:  # (N,) int8 scratch of the particle check, grows with them
            part.kin.add("guard_work", (), np.int8)

    def before_step(self, s, dt, k, part) -> None:
        check_time_step(dt, s.dt0, self.collapse_ratio, s.t, s.step_count, k, part.kin,
                        getattr(part, "describe_limit", None))

    def after_step(self, s) -> None:
        for part in s.parts:
            q = part.kin
            label = "" if part.kind == "sph" else f"node(s) of mesh '{part.name}'"
            check_particles(q, self.lo, self.hi, s.t, s.step_count, q.guard_work, label)


class HistoryRecorder:
    """Append a history row (the stepper's record and the probes) every
    ``every`` steps, taken at the kick's time and kept once the step has
    passed the guards."""

    def __init__(self, history, every: int, probes=()):
        self.history, self.every, self.probes = history, every, list(probes)
        self._row = None

    def row(self, s, **kw) -> dict:
        rec = s.record(**kw)
        rec.update(probe_record(s.particles, self.probes))
        return rec

    def after_kick(self, s) -> None:
        self._row = self.row(s) if s.step_count % self.every == 0 else None

    def after_step(self, s) -> None:
        if self._row is not None:
            self.history.append(self._row)
            self._row = None


class EnergyGuard:
    r"""Stop (or warn) when the run has made more than ``limit`` of its energy.

    At every history row of ``recorder`` the relative energy error
    :math:`(E_{total} - E_{total}^0) / E_{max}` is taken, :math:`E_{max}` the
    largest magnitude of any energy column (``E_*``, ``W_*``) of the rows so
    far: the measure of summary.json's ``energy_error_max_rel``
    (:func:`sphdyn.io.plots.relative_drift`), as the run goes, for a gain
    only. Energy made from nothing is the signature of an instability or a
    wrong formula; a loss beyond the books is dissipation not booked (a
    quasi-static ramp's first steps, with all energies still tiny, lose 19 %
    of them to the leapfrog's booking of the prescribed motion's work, a
    transient), reported by ``energy_error_max_rel`` alone. Past ``limit``,
    ``action`` ``"stop"`` raises :class:`~sphdyn.guards.EnergyError` with
    :func:`~sphdyn.guards.energy_diagnosis` (after the row is kept),
    ``"warn"`` prints that diagnosis once and keeps it in ``warning``.
    ``history`` (the rows of a restarted run) gives the first row and the
    largest term so far.
    """

    def __init__(self, recorder, history, limit: float, action: str = "stop"):
        self.recorder, self.limit, self.action = recorder, float(limit), action
        self.e0 = None
        self.scale = 0.0
        self.warning: str | None = None
        self._row = None
        h = history.as_arrays() if len(history) else {}
        if "E_total" in h and h["E_total"].size:
            self.e0 = float(h["E_total"][0])
            for c in energy_columns(list(h)):
                self.scale = max(self.scale, float(np.nanmax(np.abs(h[c]))))

    def after_kick(self, s) -> None:
        self._row = self.recorder._row

    def after_step(self, s) -> None:
        row, self._row = self._row, None
        if row is None or "E_total" not in row:
            return
        if self.e0 is None:
            self.e0 = row["E_total"]
        for c in energy_columns(list(row)):
            if math.isfinite(row[c]):
                self.scale = max(self.scale, abs(row[c]))
        growth = row["E_total"] - self.e0
        if self.scale <= 0.0 or not math.isfinite(growth):
            return  # (a non-finite state is the other guards' to report)
        error = growth / self.scale  # a gain: a loss is dissipation left unbooked
        if error <= self.limit or (self.action == "warn" and self.warning is not None):
            return
        diagnosis = energy_diagnosis(s, error, self.limit, self.scale, growth)
        if self.action == "stop":
            raise EnergyError(diagnosis)
        self.warning = diagnosis.replace("run stopped at", "warning: at", 1)
        print("sphdyn: " + self.warning, flush=True)


class HistoryFlush:
    """Write the history to disk every ``interval`` seconds of wall time, so the
    file is never more than that behind the run (a killed run keeps it).

    The interval stretches to ``20 x`` the last write's duration, so rewriting
    a long history never costs more than about 5 % of the run.
    """

    def __init__(self, write, interval: float = 5.0, clock=time.monotonic):
        self.write, self.interval, self.clock = write, interval, clock
        self._wait = interval
        self._last = clock()

    def after_step(self, s) -> None:
        now = self.clock()
        if now - self._last >= self._wait:
            self.write()
            done = self.clock()
            self._wait = max(self.interval, 20.0 * (done - now))
            self._last = done


def next_multiple(t: float, every: float) -> float:
    """The first multiple of ``every`` after the one ``t`` [s] is at or past
    (round-off below a multiple counts as reaching it)."""
    return (math.floor(t / every + 1e-9) + 1) * every


class FrameOutput:
    """Write a frame whenever the time passes the next multiple of ``every``."""

    def __init__(self, write, every: float, next_frame: float, t_end: float):
        self.write, self.every = write, every
        self.next_frame, self.t_end = next_frame, t_end

    def due(self, t: float) -> bool:
        return t >= self.next_frame - 1e-12 * self.t_end

    def written(self, t: float) -> None:
        self.next_frame = next_multiple(t, self.every)

    def after_step(self, s) -> None:
        if self.due(s.t):
            self.write()


class Checkpoints:
    """Write a checkpoint every ``every`` steps (0: never)."""

    def __init__(self, write, every: int):
        self.write, self.every = write, every

    def after_step(self, s) -> None:
        if self.every and s.step_count % self.every == 0:
            self.write()


class Progress:
    """A progress bar with an ETA in simulated time (tqdm)."""

    def __init__(self, t: float, t_end: float):
        from tqdm import tqdm

        self.bar = tqdm(total=t_end, initial=t, unit="s(sim)", unit_scale=True,
                        bar_format="{l_bar}{bar}| t={n:.3e}/{total:.3e} s "
                                   "[{elapsed}<{remaining}]", mininterval=0.5)

    def after_step(self, s) -> None:
        self.bar.update(s.t - self.bar.n)

    def close(self) -> None:
        self.bar.close()
