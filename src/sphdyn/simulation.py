"""The main loop: stepper steps, watched by monitors (guards, output, checkpoints, progress).

Output directory layout::

    DIR/deck.resolved.toml   the fully resolved deck (every default filled, SI)
    DIR/frames/frame_*.h5    native particle frames (HDF5)
    DIR/vtk/frame_*.vtu      the same frames for ParaView, DIR/particles.pvd the series
    DIR/history.csv          energies, wall forces, time step per ``history_every`` steps
    DIR/plots/*.png          plots of the history
    DIR/checkpoint.h5        restart point (every ``checkpoint_every`` steps and at exit)
    DIR/summary.json         what ran, how fast, how it ended

Every file is written atomically (temporary file + rename), so an interrupted
or failed run leaves only complete files behind.
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path

import numpy as np

from . import __version__
from .deck import dump_resolved, load_deck
from .watchers.guards import SimulationFailed
from .io import (FrameWriter, History, MeshFrame, atomic_write_text, particle_fields,
                 plot_history, read_checkpoint, write_checkpoint)
from .io.frames import STOP_FRAME, list_frames
from .io.plots import (energy_columns, per_depth, plot_gauges, relative_drift, scaled_unit,
                       time_unit)
from .build import build_stepper
from .watchers.gauges import GaugeRecorder, build_gauges
from .build.model import Model, build_model
from .watchers.interrupt import StopRequests
from .watchers.monitors import (Checkpoints, EnergyGuard, FrameOutput, Guards,
                                HistoryFlush, HistoryRecorder, Progress)
from .watchers.threads import ThreadTuner
from .stepper import Stepper

RESOLVED = "deck.resolved.toml"
CHECKPOINT = "checkpoint.h5"


class Simulation:
    """A deck, its stepper (parts, interactions, events) and the output directory.

    Use :meth:`from_deck` for a new run and :meth:`from_directory` to restart.
    The run's output is written by monitors attached to the stepper
    (:mod:`sphdyn.watchers.monitors`): guards, history rows and probes, frames and
    checkpoints.
    """

    def __init__(self, deck, outdir: Path, model: Model, stepper: Stepper,
                 history: History, frames: FrameWriter, next_frame: float,
                 gauges: list | None = None):
        self.deck = deck
        self.outdir = Path(outdir)
        self.model = model
        self.stepper = stepper
        self.history = history
        self.frames = frames
        out = deck.output
        self.fields = list(out.fields)
        self.wall_seconds = 0.0
        self.output = FrameOutput(self._write_frame, deck.frame_interval(), next_frame,
                                  deck.run.t_end)
        self.recorder = HistoryRecorder(history, out.history_every, self.model.probes,
                                        self.model.particles)
        self.gauges = GaugeRecorder(build_gauges(deck, stepper.parts) if gauges is None
                                    else gauges)
        run = deck.run
        self.energy_guard = (None if run.energy_error_action == "off" else EnergyGuard(
            self.recorder, history, run.energy_error_limit, run.energy_error_action))
        for monitor in (Guards(self.model.domain_lo, self.model.domain_hi,
                               deck.time.collapse_ratio, stepper.parts),
                        self.recorder, self.energy_guard, self.gauges, self.output,
                        Checkpoints(self._checkpoint, out.checkpoint_every)):
            if monitor is not None:
                stepper.add_monitor(monitor)

    @property
    def particles(self):
        """The particles of the SPH part (none in a deck of meshes only)."""
        return self.model.particles

    # ---------------------------------------------------------------- set-up
    @classmethod
    def from_deck(cls, deck, outdir, events=()) -> "Simulation":
        """A new run of ``deck`` in ``outdir``; ``events`` are added to the deck's.

        The model is built (and checked: size, placement) before ``outdir`` is
        made, so a refused deck leaves nothing behind.
        """
        outdir = Path(outdir)
        model = build_model(deck)
        stepper = build_stepper(deck, model, events=events)
        gauges = build_gauges(deck, stepper.parts)  # (a point outside the model)
        outdir.mkdir(parents=True, exist_ok=True)
        dump_resolved(deck, outdir / RESOLVED)
        return cls(deck, outdir, model, stepper, History(),
                   FrameWriter(outdir, vtk=deck.output.vtk), next_frame=0.0,
                   gauges=gauges)

    @classmethod
    def from_directory(cls, outdir, events=()) -> "Simulation":
        """Restart from ``DIR/checkpoint.h5`` with the deck saved in ``DIR``
        (and the ``events`` the run was started with)."""
        outdir = Path(outdir)
        ck = outdir / CHECKPOINT
        if not ck.exists():
            raise FileNotFoundError(f"{ck} not found: restart needs a run directory "
                                    "written with output.checkpoint_every > 0 or an "
                                    "interrupted run")
        deck = load_deck(outdir / RESOLVED)
        _, scalars, groups = read_checkpoint(ck)
        model = build_model(deck)
        stepper = build_stepper(deck, model, events=events)
        stepper.restore(scalars, groups)
        t = stepper.t
        hist_path = outdir / "history.csv"
        history = History.from_csv(hist_path) if hist_path.exists() else History()
        history.truncate_after(np.nextafter(t, -np.inf))  # the next step records t
        frames = FrameWriter(outdir, vtk=deck.output.vtk, start_after=t)
        sim = cls(deck, outdir, model, stepper, history, frames,
                  next_frame=float(scalars["next_frame"]))
        sim.gauges.resume(outdir, t)
        return sim

    # ------------------------------------------------------------------- run
    def run(self, t_end: float | None = None, max_steps: int | None = None,
            progress: bool | None = None, threads: int | None = None) -> dict:
        """Run to ``t_end`` (default the deck's) or for ``max_steps`` steps.

        ``threads``: a fixed Numba thread count, or None to let a
        :class:`~sphdyn.watchers.threads.ThreadTuner` keep the faster of all threads
        and half of them (results are the same bits either way).

        SIGINT or SIGTERM (in the main thread) end the run after the current
        step with all output and a checkpoint written; the summary's status
        is then ``"interrupted"`` and ``signal`` names the signal. Returns the
        run summary. Raises :class:`SimulationFailed` after writing all output
        when a guard stops the run or the output cannot be written (a full
        disk): what was written before is kept.
        """
        deck, s = self.deck, self.stepper
        t_end = deck.run.t_end if t_end is None else t_end
        self.output.t_end = t_end
        show = deck.output.progress if progress is None else progress
        added = []
        tuner = self._thread_tuner(threads)
        if tuner is not None:
            added.append(tuner)
            s.monitors.insert(0, tuner)  # times the step alone, before any output
        if show:
            added.append(Progress(s.t, t_end))
        flush = HistoryFlush(self._flush_history)
        added.append(flush)
        s.monitors.extend(m for m in added if m is not tuner)
        start_step = s.step_count
        failure = None
        t0 = time.perf_counter()
        with StopRequests() as stop:
            try:
                if s.step_count == 0 and not self.frames.frames_on_disk():
                    self._write_frame()
                while s.t < t_end * (1 - 1e-12) and not stop.requested:
                    if max_steps is not None and s.step_count - start_step >= max_steps:
                        break
                    s.step(t_stop=t_end)
            except SimulationFailed as exc:
                failure = exc
            except OSError as exc:  # a full disk, a lost mount: keep what is written
                failure = SimulationFailed(_output_failure(exc, s))
            finally:
                self.wall_seconds += time.perf_counter() - t0
                for m in added:
                    if hasattr(m, "close"):
                        m.close()
                    s.monitors.remove(m)
            self._wind_up(t_end, failure)
            summary = self._summary(start_step, failure, stop.name, t_end)
            if tuner is not None:
                summary["threads"] = tuner.summary()
            try:
                atomic_write_text(self.outdir / "summary.json",
                                  json.dumps(summary, indent=2))
            except OSError as exc:
                print(f"warning: summary.json not written: {exc}")
        if failure is not None:
            raise failure
        return summary

    def _thread_tuner(self, threads: int | None):
        import numba

        if threads is not None:
            numba.set_num_threads(max(1, min(int(threads), numba.config.NUMBA_NUM_THREADS)))
            return None
        n = numba.get_num_threads()
        return ThreadTuner(n) if n > 1 else None

    def _wind_up(self, t_end: float, failure) -> None:
        """The end of a run: the last frame, history row, checkpoint and plots.

        However the run ends (at ``t_end``, by ``max_steps``, a signal or a
        failure), its last state is a frame unless one was written at that
        time; a run stopped early marks it as a stop frame, off the schedule,
        which a restart replaces by the scheduled ones. Each write is tried
        on its own, so a full disk loses only what did not fit (and a failed
        run still gets its history and summary).
        """
        s = self.stepper
        done = failure is None and s.t >= t_end * (1 - 1e-12)
        writes = []
        last = self.frames.last_time
        if last is None or abs(last - s.t) > 1e-12 * t_end:
            writes.append(self._write_frame if done else self._write_stop_frame)
        if done:
            self.history.append(self.recorder.row(s, kinetic=s.kinetic_now(),
                                                  dt=s.dt_prev))
            self.gauges.final(s)
        writes.append(self._flush_history)
        if failure is None:
            writes.append(self._checkpoint)
        for write in writes:
            try:
                write()
            except OSError as exc:
                print(f"warning: {exc}")
        try:
            plot_history(self.outdir / "history.csv", self.outdir / "plots",
                         self.deck.output.force_window, self.deck.run.dimension, t_end)
            plot_gauges(self.outdir / "gauges", self.outdir / "plots" / "gauges.png",
                        self.deck.run.dimension)
        except Exception as exc:  # plots must never lose a run
            print(f"warning: plotting failed: {exc}")

    # --------------------------------------------------------------- helpers
    def _write_frame(self, attrs: dict | None = None):
        s = self.stepper
        computed = {}
        for part in s.parts:
            if part.kin is self.particles:  # the others draw their own blocks
                computed.update(part.fields())
        fields = particle_fields(self.particles, self.fields, computed)
        self.frames.write(s.t, s.step_count, fields, meshes=mesh_frames(s.parts, self.fields),
                          attrs=attrs)
        if attrs is None:  # a stop frame leaves the schedule as it was
            self.output.written(s.t)

    def _write_stop_frame(self):
        self._write_frame({STOP_FRAME: True})

    def _checkpoint(self):
        scalars, groups = self.stepper.state()
        scalars.update(next_frame=self.output.next_frame, version=__version__)
        write_checkpoint(self.outdir / CHECKPOINT, {}, scalars, groups)
        self._flush_history()

    def _flush_history(self):
        self.history.write_csv(self.outdir / "history.csv")
        self.gauges.write(self.outdir)

    def _summary(self, start_step: int, failure, interrupted: str | None,
                 t_end: float) -> dict:
        s, deck = self.stepper, self.deck
        steps = s.step_count - start_step
        n = sum(part.kin.n for part in s.parts)
        particles = self.particles.n
        h = self.history.as_arrays() if len(self.history.columns) else {}
        if failure is not None:
            status = failure.status  # "failed", or "energy_error" (the energy guard)
        elif s.t >= t_end * (1 - 1e-12):  # the deck's end or a restart's --t-end
            status = "completed"
        else:
            status = "interrupted" if interrupted else "stopped"
        summary = {
            "sphdyn": __version__, "title": deck.run.title, "status": status,
            "signal": interrupted if status == "interrupted" else None,
            "diagnosis": None if failure is None else failure.diagnosis,
            # items: particles and mesh nodes (the rate below counts both)
            "particles": particles, "nodes": n - particles, "items": n,
            "dimension": deck.run.dimension, "time": s.t,
            "steps": s.step_count, "steps_this_run": steps,
            "wall_seconds": self.wall_seconds,
            "particle_steps_per_s": n * steps / max(self.wall_seconds, 1e-12),
            "initial_dt": s.dt0,
        }
        for part in s.parts:  # the parts that report themselves: the
            report = getattr(part, "summary", None)  # particles' at the top
            if report is None:
                continue
            if part.kin is self.particles:
                summary.update(report())
            else:
                summary.setdefault("meshes", {})[part.name] = report()
        if s.mass_scaling is not None:
            summary["mass_scaling"] = s.mass_scaling.summary()
        if self.energy_guard is not None and self.energy_guard.warning is not None:
            summary["energy_warning"] = self.energy_guard.warning
        if "E_total" in h and h["E_total"].size:
            # the drift drawn in plots/energies.png: relative to the largest
            # energy term, not to E_kinetic (tiny in a quasi-static test)
            drift = relative_drift(h["E_total"], [h[c] for c in energy_columns(list(h))])
            summary["energy_error_max_rel"] = float(np.max(np.abs(drift)))
        window = deck.output.force_window
        if h:
            for i in s.interactions:  # a wall's peak forces, a boundary's peak reaction
                summary.update(i.summary(h, window))
        if self.model.walls:
            summary["force_window"] = window
        return summary


def _clock(seconds: float) -> str:
    """Wall time as ``12.3 s``, ``4 min 05 s`` or ``2 h 07 min``."""
    if seconds < 60:
        return f"{seconds:.3g} s"
    m = int(seconds // 60)
    if m < 60:
        return f"{m} min {int(seconds % 60):02d} s"
    return f"{m // 60} h {m % 60:02d} min"


def summary_text(summary: dict, outdir) -> str:
    """A run's end for a person: how it ended, simulated time and steps, wall
    time, energy error, peak wall forces and reactions, and what to open in
    ``outdir`` (the ParaView series, the plots, ``summary.json``, which holds
    all of ``summary`` and more)."""
    outdir = Path(outdir)
    tf, tu = time_unit(summary["time"])
    dim = summary.get("dimension")
    ended = {"completed": "completed", "stopped": "stopped by --max-steps",
             "interrupted": f"interrupted by {summary.get('signal')}",
             "failed": "failed"}.get(summary["status"], summary["status"])
    steps = summary["steps"]
    lines = [f"sphdyn: {ended} at t = {summary['time'] * tf:.4g} {tu}, step {steps}"
             + (f" ({summary['steps_this_run']} in this run)"
                if summary.get("steps_this_run", steps) != steps else "")
             + f", in {_clock(summary['wall_seconds'])}"]
    if summary.get("energy_error_max_rel") is not None:
        lines.append(f"  energy error: {100 * summary['energy_error_max_rel']:.3g} % of the "
                     "largest energy (plots/energies.png)")

    def force(value: float) -> str:
        f, unit = scaled_unit(value, "N")
        return f"{value * f:.4g} {per_depth(unit, dim)}"

    for key, value in summary.items():
        if key.startswith("peak_F_wall_") and not key.endswith("_mean"):
            mean = summary.get(f"{key}_mean")
            window = summary.get("force_window")
            lines.append(f"  peak force on wall {key[len('peak_F_wall_'):]}: {force(value)}"
                         + (f" ({window * 1e6:g} µs mean {force(mean)})"
                            if mean is not None and window else ""))
        elif key.startswith("peak_") and key.endswith("_reaction"):
            lines.append(f"  peak reaction of {key[5:-len('_reaction')]}: {force(value)}")
    lines.append(f"  output in {outdir}{os.sep}:")
    n = len(list_frames(outdir))
    if (outdir / "particles.pvd").exists():
        lines.append(f"    particles.pvd    open in ParaView ({n} frames)")
    elif n:
        lines.append(f"    frames/          {n} frames (sphdyn export {outdir} makes a "
                     "ParaView series)")
    plots = sorted(p.name for p in (outdir / "plots").glob("*.png"))
    if plots:
        lines.append(f"    plots/           {', '.join(plots)}")
    lines.append("    summary.json     all of the above and more")
    if summary["status"] == "stopped":
        lines.append(f"  continue with: sphdyn restart {outdir}")
    return "\n".join(lines)


def mesh_frames(parts, fields=None) -> dict[str, MeshFrame]:
    """Each part's own picture in a frame, by part name: the parts that draw one
    (``frame(fields)``, :func:`sphdyn.parts.fem.output.mesh_frame`; ``fields``
    the deck's ``output.fields``); the particles are written as the frame's
    points instead."""
    return {part.name: part.frame(fields) for part in parts if hasattr(part, "frame")}


def _output_failure(exc: OSError, s) -> str:
    """The diagnosis of a run stopped because its output could not be written."""
    where = f" ({exc.filename})" if getattr(exc, "filename", None) else ""
    return (f"output could not be written at t = {s.t:.6e} s, step {s.step_count}: "
            f"{exc.strerror or exc}{where}. The run stopped; the files written "
            "before are complete. Free space (or fix the directory), then restart "
            "from the last checkpoint or run again.")


def run_examples(root, runs: dict, full: str, reuse: bool = False,
                 include_full: bool = False) -> dict:
    """The example scripts' runs: ``runs`` maps a name to ``(deck, overrides,
    label)``, the deck a file in ``root/examples``, each run into
    ``root/out/<name>``. With ``reuse`` only the runs found there are read;
    otherwise every run is made except ``full`` (the long one), which is made
    with ``include_full`` and else read if found. Returns {name: output folder}.
    """
    root = Path(root)
    found = {n for n in runs if (root / "out" / n / "summary.json").exists()}
    names = [n for n in runs if n in found] if reuse else \
        [n for n in runs if n != full or include_full or n in found]
    for n in names:
        deck, overrides = runs[n][0], runs[n][1]
        run_deck(root / "examples" / deck, root / "out" / n, overrides,
                 reuse=reuse or (n == full and not include_full), progress=True)
    return {n: root / "out" / n for n in names}


def run_deck(path, outdir=None, overrides=None, reuse: bool = False, **kw) -> dict:
    """Load, validate and run a deck; the Python equivalent of ``sphdyn run``.

    With ``reuse``, a run whose ``outdir`` already has a ``summary.json``
    is not run again: its summary is returned (the example scripts' redraws).
    """
    outdir = Path(outdir) if outdir else Path("out") / Path(path).stem
    if reuse and (outdir / "summary.json").exists():
        return json.loads((outdir / "summary.json").read_text())
    deck = load_deck(path, overrides)
    return Simulation.from_deck(deck, outdir).run(**kw)
