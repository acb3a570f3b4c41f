"""Monitors: what watches the step from outside it (guards, history, output cadence).

A monitor has any of the hooks the :class:`~sphdyn.stepper.Stepper` calls:
``before_step(stepper, dt, k, part)`` with the step about to be taken,
``after_kick(stepper)`` with the state at the kick's time :math:`t^n`, and
``after_step(stepper)`` at :math:`t^{n+1}`. They are attached in this order
by :class:`~sphdyn.simulation.Simulation`: the thread tuner
(:mod:`sphdyn.watchers.threads`, when the thread count is automatic), guards, history
(with probes), the energy guard (after the history, so that the row that
broke the limit is kept), frames, checkpoints, progress, the history flush.
"""

from __future__ import annotations

import math
import time
from contextlib import contextmanager

import numpy as np

from .guards import EnergyError, check_particles, check_time_step, energy_diagnosis
from ..io.plots import energy_columns
from .probes import record as probe_record


class Guards:
    """Stop the run with a diagnosis: time-step collapse, NaN, particles leaving
    the domain box ``[lo, hi]`` (see :mod:`sphdyn.watchers.guards`)."""

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
            check_particles(q, self.lo, self.hi, s.t, s.step_count, q.guard_work,
                            getattr(part, "items_label", ""))


class HistoryRecorder:
    """Append a history row (the stepper's record and the probes) every
    ``every`` steps, taken at the kick's time and kept once the step has
    passed the guards; ``particles`` the state the particle probes read."""

    def __init__(self, history, every: int, probes=(), particles=None):
        self.history, self.every, self.probes = history, every, list(probes)
        self.particles = particles
        self._row = None

    def row(self, s, **kw) -> dict:
        rec = s.record(**kw)
        rec.update(probe_record(self.particles, self.probes,
                                meshes={q.name: q.kin for q in s.parts}))
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
    ``action`` ``"stop"`` raises :class:`~sphdyn.watchers.guards.EnergyError` with
    :func:`~sphdyn.watchers.guards.energy_diagnosis` (after the row is kept),
    ``"warn"`` prints that diagnosis once and keeps it in ``warning``.
    ``history`` (the rows of a restarted run) gives the first row and the
    largest term so far.

    The error must stay past the limit for ``persist`` steps (every history
    row in between past it too) before the guard acts: a penalty contact that
    engages a whole face at once books a transient that returns (the
    leapfrog's half-step booking of a stiff spring, of order alpha: a block
    of 4 x 4 x 4 hexes on a wall at 20 m/s peaks at +7.2 % for about 20
    steps and ends at -0.3 %, tests/test_erosion.py), while energy made by an
    instability or a wrong formula stays made.
    """

    #: steps the error must stay past the limit (see the class docstring)
    PERSIST = 100

    def __init__(self, recorder, history, limit: float, action: str = "stop",
                 persist: int = PERSIST):
        self.recorder, self.limit, self.action = recorder, float(limit), action
        self.persist = int(persist)
        self._since: int | None = None  # first step of the current excursion
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
        if error <= self.limit:
            self._since = None
            return
        if self._since is None:
            self._since = s.step_count
        if (s.step_count - self._since < self.persist
                or (self.action == "warn" and self.warning is not None)):
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


#: the progress bar's word while Numba compiles (a cold cache: the first run)
COMPILING = "compiling kernels (first run only)"


class CompileWatch:
    """Count Numba's compilations while entered (a context manager).

    Numba announces each compilation of a kernel, one not found in its cache,
    as a ``"numba:compile"`` event (``numba.core.event``); loading a cached
    kernel raises none. ``on_start()`` is called when a compilation starts
    (nested ones included), so a caller can say what the wait is for.
    """

    def __init__(self, on_start=None):
        self.count = 0
        self._on_start = on_start
        self._listener = None

    def __enter__(self) -> "CompileWatch":
        from numba.core import event

        watch = self

        class Listener(event.Listener):
            def on_start(self, ev) -> None:
                watch.count += 1
                if watch._on_start is not None:
                    watch._on_start()

            def on_end(self, ev) -> None:
                pass

        self._listener = Listener()
        event.register("numba:compile", self._listener)
        return self

    def __exit__(self, *exc) -> None:
        from numba.core import event

        event.unregister("numba:compile", self._listener)


@contextmanager
def compile_notice(write):
    """Within: ``write(text)`` once, when Numba starts compiling a kernel, so a
    first run's wait (building the model compiles kernels too) is explained;
    ``write=None`` says nothing."""
    said = []

    def start() -> None:
        if write is not None and not said:
            said.append(True)
            write(f"sphdyn: {COMPILING}: this may take minutes; later runs load them "
                  "from Numba's cache")

    with CompileWatch(start):
        yield


class RemainingTime:
    """Wall time left in a run, from the rate of its recent steady steps.

    A step's wall time and simulated time go in with :meth:`add`. The first
    ``skip`` steps and every step during which Numba compiled are left out
    (their seconds are compilation, not stepping), and so are steps older
    than ``horizon`` seconds of counted wall time or than the last
    ``max_steps`` (the rate follows the run: contact, rebuilds).
    :meth:`seconds` is ``None`` until ``min_steps`` steps are counted: no
    estimate rather than one extrapolated from compilation.
    """

    def __init__(self, skip: int = 1, min_steps: int = 5, horizon: float = 30.0,
                 max_steps: int = 5000):
        from collections import deque

        self.skip, self.min_steps, self.horizon = skip, min_steps, horizon
        self.max_steps = max_steps
        self._seen = 0
        self._steps = deque()
        self._wall = self._sim = 0.0

    def add(self, wall: float, sim: float, compiled: bool = False) -> None:
        """One step: ``wall`` [s] it took, ``sim`` [s] it advanced the run;
        ``compiled``: Numba compiled during it."""
        self._seen += 1
        if self._seen <= self.skip or compiled:
            return
        self._steps.append((wall, sim))
        self._wall += wall
        self._sim += sim
        while len(self._steps) > self.max_steps or (
                len(self._steps) > self.min_steps
                and self._wall - self._steps[0][0] >= self.horizon):
            w, t = self._steps.popleft()
            self._wall -= w
            self._sim -= t

    def seconds(self, sim_left: float) -> float | None:
        """Wall seconds to advance ``sim_left`` [s] more, or None (too few
        steady steps timed yet)."""
        if len(self._steps) < self.min_steps or not (self._sim > 0 and self._wall > 0):
            return None
        return max(sim_left, 0.0) * self._wall / self._sim


class Progress:
    """A progress bar in simulated time (tqdm) with an ETA from the steady steps.

    While Numba compiles kernels (the first run's first steps, or a kernel
    first needed later in the run) the bar says so instead of an ETA; the ETA (:class:`RemainingTime`) appears once enough steps have been
    timed without compilation.
    """

    def __init__(self, t: float, t_end: float, clock=time.perf_counter):
        from tqdm import tqdm

        self.t_end, self.clock = t_end, clock
        self.bar = tqdm(total=t_end, initial=t, unit="s(sim)", unit_scale=True,
                        bar_format="{l_bar}{bar}| t={n:.3e}/{total:.3e} s "
                                   "[{elapsed}{postfix}]", mininterval=0.5)
        self.eta = RemainingTime()
        self.watch = CompileWatch(self._compiling).__enter__()
        self._t, self._last, self._compiles = t, clock(), 0
        self._shown = 0.0

    def _compiling(self) -> None:
        if self.bar.postfix != COMPILING:
            self.bar.set_postfix_str(COMPILING)  # refreshes now: the step may take long

    def after_step(self, s) -> None:
        now = self.clock()
        compiled = self.watch.count != self._compiles
        self.eta.add(now - self._last, s.t - self._t, compiled)
        self._t, self._last, self._compiles = s.t, now, self.watch.count
        if compiled or now - self._shown >= 0.5:  # tqdm redraws twice a second at most
            left = self.eta.seconds(self.t_end - s.t)
            self.bar.set_postfix_str("" if left is None else
                                     f"ETA {self.bar.format_interval(left)}",
                                     refresh=False)
            self._shown = now
        self.bar.update(s.t - self.bar.n)

    def close(self) -> None:
        self.watch.__exit__(None, None, None)
        self.bar.close()
