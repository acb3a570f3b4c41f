"""The main loop: solver steps, then output, checkpoints, guards and progress.

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
import math
import time
from pathlib import Path

import numpy as np

from . import __version__
from .deck import dump_resolved, load_deck
from .guards import SimulationFailed
from .io import (FrameWriter, History, atomic_write_text, particle_fields,
                 plot_history, read_checkpoint, write_checkpoint)
from .analysis import window_mean_force
from .io.plots import energy_columns, relative_drift
from .model import build_model
from .neighbours import max_neighbours, mean_neighbours
from .solver import Solver

RESOLVED = "deck.resolved.toml"
CHECKPOINT = "checkpoint.h5"


class Simulation:
    """A deck, its model and solver, and the output directory.

    Use :meth:`from_deck` for a new run and :meth:`from_directory` to restart.
    """

    def __init__(self, deck, outdir: Path, solver: Solver, history: History,
                 frames: FrameWriter, next_frame: float):
        self.deck = deck
        self.outdir = Path(outdir)
        self.solver = solver
        self.history = history
        self.frames = frames
        self.next_frame = next_frame
        out = deck.output
        self.frame_every = deck.frame_interval()
        self.fields = list(out.fields)
        self.wall_seconds = 0.0

    # ---------------------------------------------------------------- set-up
    @classmethod
    def from_deck(cls, deck, outdir) -> "Simulation":
        outdir = Path(outdir)
        outdir.mkdir(parents=True, exist_ok=True)
        dump_resolved(deck, outdir / RESOLVED)
        solver = Solver(build_model(deck), deck)
        sim = cls(deck, outdir, solver, History(), FrameWriter(outdir, vtk=deck.output.vtk),
                  next_frame=0.0)
        return sim

    @classmethod
    def from_directory(cls, outdir) -> "Simulation":
        """Restart from ``DIR/checkpoint.h5`` with the deck saved in ``DIR``."""
        outdir = Path(outdir)
        ck = outdir / CHECKPOINT
        if not ck.exists():
            raise FileNotFoundError(f"{ck} not found: restart needs a run directory "
                                    "written with output.checkpoint_every > 0 or an "
                                    "interrupted run")
        deck = load_deck(outdir / RESOLVED)
        arrays, scalars, groups = read_checkpoint(ck)
        solver = Solver(build_model(deck), deck)
        solver.restore(scalars, groups["solver"], groups["particles"])
        t = solver.t
        hist_path = outdir / "history.csv"
        history = History.from_csv(hist_path) if hist_path.exists() else History()
        history.truncate_after(np.nextafter(t, -np.inf))  # the next step records t
        frames = FrameWriter(outdir, vtk=deck.output.vtk, start_after=t)
        return cls(deck, outdir, solver, history, frames,
                   next_frame=float(scalars["next_frame"]))

    # ------------------------------------------------------------------- run
    def run(self, t_end: float | None = None, max_steps: int | None = None,
            progress: bool | None = None) -> dict:
        """Run to ``t_end`` (default the deck's) or for ``max_steps`` steps.

        Returns the run summary. Raises :class:`SimulationFailed` after writing
        all output when a guard stops the run.
        """
        deck, s = self.deck, self.solver
        t_end = deck.run.t_end if t_end is None else t_end
        show = deck.output.progress if progress is None else progress
        every_hist = deck.output.history_every
        every_ck = deck.output.checkpoint_every
        bar = _progress(show, s.t, t_end)
        start_step = s.step_count
        failure = None
        t0 = time.perf_counter()
        try:
            if s.step_count == 0 and not self.frames.frames_on_disk():
                self._write_frame()
            while s.t < t_end * (1 - 1e-12):
                if max_steps is not None and s.step_count - start_step >= max_steps:
                    break
                record = s.step(t_stop=t_end)
                if (s.step_count - 1) % every_hist == 0:
                    self.history.append(record)
                if s.t >= self.next_frame - 1e-12 * t_end:
                    self._write_frame()
                if every_ck and s.step_count % every_ck == 0:
                    self._checkpoint()
                if bar is not None:
                    bar.update(s.t - bar.n)
        except SimulationFailed as exc:
            failure = exc
        finally:
            self.wall_seconds += time.perf_counter() - t0
            if bar is not None:
                bar.close()
        if failure is None and s.t >= t_end * (1 - 1e-12) and (
                not self.frames.frames_on_disk()
                or abs(self.frames.last_time - s.t) > 1e-12 * t_end):
            self._write_frame()
        if failure is not None:
            self._write_frame()
        if failure is None and s.t >= t_end * (1 - 1e-12):
            self.history.append(s.energies(self._kinetic_now(), s.dt_prev))
        self.history.write_csv(self.outdir / "history.csv")
        if failure is None:
            self._checkpoint()
        try:
            plot_history(self.outdir / "history.csv", self.outdir / "plots",
                         self.deck.output.force_window)
        except Exception as exc:  # plots must never lose a run
            print(f"warning: plotting failed: {exc}")
        summary = self._summary(start_step, failure)
        atomic_write_text(self.outdir / "summary.json", json.dumps(summary, indent=2))
        if failure is not None:
            raise failure
        return summary

    # --------------------------------------------------------------- helpers
    def _kinetic_now(self) -> float:
        p = self.solver.p
        return float(0.5 * np.sum(p.m * np.sum(p.v * p.v, axis=1)))

    def _write_frame(self):
        s = self.solver
        fields = particle_fields(s.p, self.fields, s.output_fields())
        self.frames.write(s.t, s.step_count, fields)
        k = math.floor(s.t / self.frame_every + 1e-9) + 1
        self.next_frame = k * self.frame_every

    def _checkpoint(self):
        s = self.solver
        scalars = dict(s.state_scalars(), next_frame=self.next_frame,
                       version=__version__)
        groups = {"particles": s.p.arrays(), "solver": s.state_arrays()}
        write_checkpoint(self.outdir / CHECKPOINT, {}, scalars, groups)
        self.history.write_csv(self.outdir / "history.csv")

    def _summary(self, start_step: int, failure) -> dict:
        s, deck = self.solver, self.deck
        steps = s.step_count - start_step
        h = self.history.as_arrays() if len(self.history.columns) else {}
        summary = {
            "sphdyn": __version__, "title": deck.run.title, "status":
            "completed" if failure is None and s.t >= deck.run.t_end * (1 - 1e-12)
            else ("failed" if failure is not None else "stopped"),
            "diagnosis": None if failure is None else failure.diagnosis,
            "particles": s.p.n, "dimension": s.dim, "time": s.t, "steps": s.step_count,
            "steps_this_run": steps, "wall_seconds": self.wall_seconds,
            "particle_steps_per_s": s.p.n * steps / max(self.wall_seconds, 1e-12),
            "initial_dt": s.dt0, "neighbours_mean": mean_neighbours(s.nl),
            "neighbours_max": max_neighbours(s.nl), "neighbour_builds": s.nl.n_builds,
        }
        if "E_total" in h and h["E_total"].size:
            # the drift drawn in plots/energies.png: relative to the largest
            # energy term, not to E_kinetic (tiny in a quasi-static test)
            drift = relative_drift(h["E_total"], [h[c] for c in energy_columns(list(h))])
            summary["energy_error_max_rel"] = float(np.max(np.abs(drift)))
        window = deck.output.force_window
        for w in s.model.walls:
            col = f"F_wall_{w.name}"
            if col in h and h[col].size:
                summary[f"peak_{col}"] = float(np.max(h[col]))
                impulse = h.get(f"I_wall_{w.name}")  # absent before 2026-11-23
                if impulse is not None:
                    summary[f"peak_{col}_mean"] = float(np.max(window_mean_force(
                        h["time"], impulse, window)))
        if s.model.walls:
            summary["force_window"] = window
        return summary


def _progress(show: bool, t: float, t_end: float):
    if not show:
        return None
    from tqdm import tqdm

    return tqdm(total=t_end, initial=t, unit="s(sim)", unit_scale=True,
                bar_format="{l_bar}{bar}| t={n:.3e}/{total:.3e} s [{elapsed}<{remaining}]",
                mininterval=0.5)


def run_deck(path, outdir=None, overrides=None, **kw) -> dict:
    """Load, validate and run a deck; the Python equivalent of ``sphdyn run``."""
    deck = load_deck(path, overrides)
    outdir = Path(outdir) if outdir else Path("out") / Path(path).stem
    return Simulation.from_deck(deck, outdir).run(**kw)
