"""The number of threads on a shared machine: measure, then keep the faster.

Why: every parallel loop (``prange``) ends at a barrier, so a step is as slow
as its slowest thread. When another process takes a core, one of our two
threads waits for its turn at every barrier, dozens of times per step, while
the other spins in OpenMP's wait loop. On this project's 2-core machine with
one competing CPU-bound process the disc impact ran at 0.74x its 1-thread
speed on 2 threads (BENCHMARKS.md, "Threads on a loaded machine"). A passive
wait policy (``OMP_WAIT_POLICY=passive``) removes the loss under load but
costs a quarter of the idle 2-thread speed, so it is not the default.

:class:`ThreadTuner` is a monitor that, when the user gave no thread count,
times the run's own steps on all threads and on half of them (one thread on
2 cores) in turn and keeps the faster, trying the other again from time to
time (loads come and go). The results do not depend on the choice: every loop writes only its own
rows and the sums are taken in a fixed order (:data:`sphdyn.integrate.KICK_BLOCK`),
so 1 and 2 threads give the same bits (tests/test_threads.py).
"""

from __future__ import annotations

import time


def machine_load() -> float:
    """Runnable processes beyond the cores this process may use: the 1-minute
    load average minus the usable cores (negative when cores are free)."""
    import os

    try:
        cores = len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        cores = os.cpu_count() or 1
    try:
        return os.getloadavg()[0] - cores
    except OSError:  # no load average: take the machine as free
        return -float(cores)


def _numba_threads(n: int | None = None) -> int:
    import numba

    if n is not None:
        numba.set_num_threads(n)
    return numba.get_num_threads()


class ThreadTuner:
    """Monitor keeping the faster of ``n_max`` threads and ``n_max // 2``.

    The alternative is one thread on a 2-core machine. (On a big node the best
    count under load is ``n_max`` minus the competing processes; half of the
    cores gets most of that without guessing the load.) The run starts on the
    alternative when the load average says other processes already use the
    cores (``load``: runnable processes beyond the usable cores, see
    :func:`machine_load`; more than ``-n_max + 0.75`` means at least most of
    one core is taken), so a loaded machine does not pay for the first
    reference window on the slow count.

    A *window* is at least ``window`` seconds and ``min_steps`` steps of
    stepping only (the tuner's ``before_step`` to its ``after_step``; output
    written by later monitors is not counted). The window just before a
    trial is the reference; the trial window runs on the other count, and the
    trial count is kept only if it was faster by more than ``margin``
    (relative), so noise does not make it flip back and forth. The first trial
    comes after ``warmup`` steps and one reference window; the next after
    ``period`` seconds of stepping, a period that doubles after every trial
    that changed nothing (up to ``max_period``) and starts again from
    ``period`` after a switch. These times stretch with the windows: steps
    longer than ``window / min_steps`` make a window ``s`` times longer than
    ``window`` (with steps of a second, eight of them make an 8-second window,
    ``s`` = 32), and the next trial comes ``s`` times later, so a trial on
    the slower count costs the same share of the stepping whatever the step:
    one window at its speed per 40-320 windows, and a long run loses well
    under 1 %.

    ``clock`` and ``set_threads`` (``n -> None``) are injectable for tests.
    """

    def __init__(self, n_max: int, window: float = 0.25, period: float = 10.0,
                 min_steps: int = 8, warmup: int = 5, margin: float = 0.03,
                 max_period: float = 80.0, clock=time.perf_counter,
                 set_threads=None, load: float | None = None) -> None:
        if n_max < 2:
            raise ValueError("ThreadTuner needs at least 2 threads to choose from")
        self.n_max, self.window, self.period = n_max, window, period
        self.max_period = max_period
        self._wait = period  # seconds of stepping until the next trial
        self.min_steps, self.warmup, self.margin = min_steps, warmup, margin
        self.clock = clock
        self.set_threads = set_threads or _numba_threads
        self.other = max(1, n_max // 2)  # the count tried against n_max
        load = machine_load() if load is None else load
        self.start = self.other if load > -n_max + 0.75 else n_max
        self.current = self.start  # the count in use outside trials
        self.trial: int | None = None  # the count under trial, if any
        self.reference = 0.0  # particle-steps/s of the window before the trial
        self.switches = 0
        self.trials = 0
        self.seconds = {self.other: 0.0, n_max: 0.0}  # stepping time on each count
        self._steps_seen = 0
        self._since_trial = 0.0
        self._t0 = 0.0
        self._win_time = 0.0
        self._win_work = 0.0
        self._win_steps = 0
        self._stretch = 1.0  # min_steps of the last trial's steps over ``window`` (>= 1)
        self.set_threads(self.current)

    @property
    def active(self) -> int:
        """The thread count the next step runs on."""
        return self.current if self.trial is None else self.trial

    def before_step(self, s, dt, k, part) -> None:
        self._t0 = self.clock()

    def after_step(self, s) -> None:
        elapsed = self.clock() - self._t0
        self.seconds[self.active] += elapsed
        self._steps_seen += 1
        if self._steps_seen <= self.warmup:  # first calls load the compiled code
            return
        self._win_time += elapsed
        self._win_work += sum(part.kin.n for part in s.parts)
        self._win_steps += 1
        if self._win_time < self.window or self._win_steps < self.min_steps:
            return
        rate = self._win_work / max(self._win_time, 1e-12)
        # the length min_steps of this window's steps take, over ``window``
        stretch = self.min_steps * self._win_time / (self._win_steps * self.window)
        self._since_trial += self._win_time
        self._win_time = self._win_work = 0.0
        self._win_steps = 0
        if self.trial is not None:  # a trial window ended: keep the faster
            if rate > self.reference * (1.0 + self.margin):
                self.current = self.trial
                self.switches += 1
                self._wait = self.period
            else:
                self._wait = min(2.0 * self._wait, self.max_period)
            # steps longer than window / min_steps make longer windows: the
            # schedule stretches with them (the trials' share stays the same)
            self._stretch = max(1.0, stretch)
            self.trial = None
            self.set_threads(self.current)
            self._since_trial = 0.0
        elif self.trials == 0 or self._since_trial >= self._wait * self._stretch:
            self.reference = rate
            self.trial = self.other if self.current == self.n_max else self.n_max
            self.trials += 1
            self.set_threads(self.trial)

    def summary(self) -> dict:
        """What the tuner did, for ``summary.json``."""
        return {"mode": "auto", "max": self.n_max, "start": self.start,
                "final": self.current,
                "trials": self.trials, "switches": self.switches,
                "stepping_seconds": {str(k): round(v, 3) for k, v in self.seconds.items()}}

    def close(self) -> None:
        """Leave the thread count as it was found (all threads)."""
        self.set_threads(self.n_max)
