r"""Ensembles: many samples of one deck on Dask distributed.

``sphdyn ensemble DECK --samples N [--vary key=v1,v2,...] [--scheduler ADDR]``
runs N random samples of a deck (for each point of the ``--vary`` grid) as
independent tasks on a Dask cluster: a :class:`distributed.LocalCluster` of
worker *processes* by default, or any running scheduler (so the same command
scales to a batch system through dask-jobqueue or to MPI through dask-mpi).

Layout of the output directory ``OUT`` (default ``out/<deck>-ensemble``)::

    OUT/ensemble.json             the plan: deck, overrides, grid, seeds
    OUT/sample_0000/              one directory per sample: a normal run
        deck.resolved.toml        directory (frames, history, summary.json)
        result.json               written last and atomically: the marker
        plots/mass_histogram.png  the mass field's histogram (paper Fig. 5)
    OUT/ensemble.csv              one row per sample (see :data:`COLUMNS`)
    OUT/ensemble_damage.png       final damage of every sample (paper Figs. 8-10)

Seeds. Sample ``s`` of every grid point gets the run seed
:func:`sample_seed` (base seed, s) with the base seed the deck's
``run.seed``; so the grid points share their random fields (common random
numbers: a kappa study compares the same mass fields). Everything a sample
does is a function of its resolved deck, so results do not depend on the
number of workers or on the order in which they finish.

Resuming. A sample whose ``result.json`` says ``completed`` for the same
overrides is skipped; any other sample (never started, interrupted, failed)
is run again from scratch in its directory. A failing sample (invalid deck,
a guard stopping the run, an exception, a lost worker) is recorded with its
error and does not stop the others.

Workers. Each sample is one task on a one-thread Dask worker; the Numba
threads of a sample are ``cores // workers``. The default is one worker per
core with one Numba thread each (pair loops scale by only 1.45-1.6x from 1 to
2 threads here, see BENCHMARKS.md, so independent samples use the cores
better), or fewer workers with more threads when there are fewer samples
than cores.
"""

from __future__ import annotations

import csv
import io
import itertools
import json
import math
import os
import shutil
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from .analysis import window_mean_force
from .io.atomic import atomic_write_text
from .io.plots import save_figure

__all__ = ["COLUMNS", "SampleSpec", "count_main_cracks", "parse_vary", "plan_samples",
           "plot_damage_grid", "run_ensemble", "run_sample", "sample_metrics",
           "sample_seed", "write_report"]

RESULT = "result.json"
PLAN = "ensemble.json"
TABLE = "ensemble.csv"
FIGURE = "ensemble_damage.png"

#: Damage at and above which a particle counts as failed (fully damaged).
FAILED_DAMAGE = 0.9

#: Columns of ``ensemble.csv`` after the sample, replicate, seed and vary keys.
COLUMNS = ("status", "peak_contact_force", "peak_contact_force_mean", "dissipated_energy",
           "viscous_energy", "damaged_volume_fraction", "main_cracks", "final_kinetic_energy",
           "initial_kinetic_energy", "zero_mass_particles", "steps", "wall_seconds",
           "cpu_seconds", "error", "dir")


# ------------------------------------------------------------------ planning

def sample_seed(base: int, replicate: int) -> int:
    """Run seed of replicate ``replicate``: ``SeedSequence([base, replicate])``.

    A 32-bit integer, the same on every machine and independent of how many
    samples are run.
    """
    ss = np.random.SeedSequence([int(base), int(replicate)])
    return int(ss.generate_state(1, dtype=np.uint32)[0])


def parse_vary(items) -> list[tuple[str, list[str]]]:
    """``["sph.support_scale=0.7,1.0,1.5"]`` -> ``[("sph.support_scale", [...])]``.

    Values are kept as text and applied as deck overrides (TOML values, or
    strings such as ``"2 mm"``); a value cannot contain a comma.
    """
    grid = []
    for item in items or ():
        key, sep, values = item.partition("=")
        vals = [v.strip() for v in values.split(",") if v.strip()]
        if not sep or not key.strip() or not vals:
            raise ValueError(f"--vary {item!r}: write KEY=V1,V2,... e.g. "
                             "sph.support_scale=0.7,1.0,1.5")
        if key.strip() in [k for k, _ in grid]:
            raise ValueError(f"--vary: the key {key.strip()!r} is given twice")
        grid.append((key.strip(), vals))
    return grid


def _base_seed(deck: Path, overrides, grid) -> int:
    """``run.seed`` of the deck with ``overrides`` and the first grid point.

    The deck may need a ``--vary`` key to be valid (e.g. a parameter of a
    mass law given only by ``--vary``), so the first grid point is applied;
    if that is still invalid, the seed is read from the TOML (default 0) and
    the invalid samples are recorded when they run.
    """
    import tomllib

    from .deck import DeckError, load_deck

    first = [f"{k}={v[0]}" for k, v in grid]
    try:
        return load_deck(deck, [*overrides, *first]).run.seed
    except DeckError:
        seeds = [o.partition("=")[2] for o in overrides if o.startswith("run.seed=")]
        if seeds:
            return int(seeds[-1])
        raw = tomllib.loads(deck.read_text(encoding="utf-8"))
        return int(raw.get("run", {}).get("seed", 0))


@dataclass(frozen=True)
class SampleSpec:
    """Everything a worker needs to run one sample (plain data, picklable)."""

    index: int
    replicate: int
    seed: int
    vary: dict = field(default_factory=dict)
    overrides: tuple = ()
    deck: str = ""
    outdir: str = ""
    threads: int = 1

    @property
    def name(self) -> str:
        return f"sample_{self.index:04d}"


def plan_samples(deck: str | Path, samples: int, vary=(), out: str | Path = "out",
                 overrides=(), base_seed: int | None = None,
                 threads: int = 1) -> list[SampleSpec]:
    """The samples of an ensemble: the ``vary`` grid times ``samples`` replicates.

    ``base_seed`` defaults to the deck's ``run.seed`` (after ``overrides``).
    Sample indices run over the grid points (outer) and replicates (inner).
    """
    if samples < 1:
        raise ValueError(f"--samples {samples}: give at least 1 sample")
    deck = Path(deck).resolve()
    grid = parse_vary(vary) if vary and isinstance(vary[0], str) else list(vary)
    if base_seed is None:
        base_seed = _base_seed(deck, overrides, grid)
    keys = [k for k, _ in grid]
    specs = []
    combos = itertools.product(*[v for _, v in grid]) if grid else [()]
    for point in combos:
        for r in range(samples):
            k = len(specs)
            seed = sample_seed(base_seed, r)
            var = dict(zip(keys, point))
            ov = (*overrides, *(f"{a}={b}" for a, b in var.items()), f"run.seed={seed}")
            specs.append(SampleSpec(k, r, seed, var, ov, str(deck),
                                    str(Path(out).resolve() / f"sample_{k:04d}"),
                                    threads))
    return specs


# ------------------------------------------------------------------ metrics

def count_main_cracks(x0, damage, mass, dx: float, normal=(0.0, 1.0, 0.0),
                      threshold: float = FAILED_DAMAGE, min_size: int | None = None,
                      dim: int = 3) -> int:
    r"""Number of main cracks: failed bands crossing the body's mid-section.

    Definition (reference configuration): the *mid-section* is the plane
    through the centroid of the particles with mass, normal to ``normal``
    (the impact direction, the wall normal). Take the particles with mass
    within one spacing of it (about two rows) that have failed (damage >=
    ``threshold``), link those closer than 1.5 dx, and count the connected
    groups of at least ``min_size`` particles (default 2 in 2D, 4 in 3D, so
    an isolated failed particle is not a crack). A crack running through
    the body from the crushed contact zone crosses the mid-section once; two
    separate crossings are two main cracks even if they join in the contact
    zone (the paper's "multiple main cracks", Fig. 8); the crushed zone
    itself is not counted unless it reaches the mid-section.

    Parameters
    ----------
    x0 : (N, 3) initial positions [m]; damage, mass : (N,).
    dx : particle spacing [m]; normal : (3,) impact direction.
    """
    from .analysis import fragment_labels, fragment_sizes

    x0 = np.asarray(x0, float)
    solid = np.asarray(mass) > 0
    n = np.asarray(normal, float) / np.linalg.norm(normal)
    c = x0[solid].mean(axis=0)
    s = (x0 - c) @ n
    band = solid & (np.abs(s) <= dx * (1 + 1e-9)) & (np.asarray(damage) >= threshold)
    if not band.any():
        return 0
    labels = fragment_labels(x0, 1.5 * dx, mask=band)
    sizes = fragment_sizes(labels)
    size = (2 if dim == 2 else 4) if min_size is None else min_size
    return int((sizes >= size).sum())


def sample_metrics(sim) -> dict:
    """Scalar results of one finished sample (a :class:`Simulation`).

    * ``peak_contact_force``: maximum over the history of the summed normal
      wall forces [N] (N/m in 2D); NaN without walls;
    * ``peak_contact_force_mean``: maximum of the same force averaged over
      ``[output] force_window`` (:func:`sphdyn.analysis.window_mean_force`),
      free of the spikes of first contact;
    * ``dissipated_energy``: internal energy at the end [J]: plastic and
      damage work, artificial-viscosity heat (also given alone as
      ``viscous_energy``) and the elastic energy still stored (small after
      the rebound);
    * ``damaged_volume_fraction``: volume (m / rho0) of failed particles
      (damage >= :data:`FAILED_DAMAGE`) over the volume of the body;
    * ``main_cracks``: :func:`count_main_cracks` of each body, summed;
    * ``final_kinetic_energy``, ``initial_kinetic_energy`` [J].
    """
    s = sim.solver
    p = s.p
    h = sim.history.as_arrays()
    walls = [w.name for w in s.model.walls]
    peak = peak_mean = float("nan")
    if walls and len(h.get("time", ())):
        peak = float(np.max(np.sum([h[f"F_wall_{w}"] for w in walls], axis=0)))
        impulse = np.sum([h[f"I_wall_{w}"] for w in walls], axis=0)
        peak_mean = float(np.max(window_mean_force(h["time"], impulse,
                                                   sim.deck.output.force_window)))
    vol = np.where(p.m > 0, p.m / p.rho0, 0.0)
    failed = p.damage >= FAILED_DAMAGE
    normal = s.model.walls[0].normal if s.model.walls else np.array([0.0, 1.0, 0.0])
    cracks = 0
    for b in range(len(s.model.body_names)):
        sel = p.body == b
        dx = float(np.median(p.vol0[sel]) ** (1.0 / p.dim))
        cracks += count_main_cracks(p.x0[sel], p.damage[sel], p.m[sel], dx, normal,
                                    dim=p.dim)
    last = {k: float(v[-1]) for k, v in h.items() if len(v)}
    return {
        "peak_contact_force": peak,
        "peak_contact_force_mean": peak_mean,
        "dissipated_energy": last.get("E_internal", float("nan")),
        "viscous_energy": last.get("E_viscous", float("nan")),
        "damaged_volume_fraction": float(vol[failed].sum() / vol.sum()),
        "main_cracks": cracks,
        "final_kinetic_energy": float(0.5 * np.sum(p.m * np.sum(p.v * p.v, axis=1))),
        "initial_kinetic_energy": float(h["E_kinetic"][0]) if "E_kinetic" in h
        and len(h["E_kinetic"]) else float("nan"),
        "zero_mass_particles": int((p.m == 0).sum()),
        "steps": s.step_count,
    }


# ------------------------------------------------------------------ one sample

def _set_threads(n: int) -> None:
    import numba

    numba.set_num_threads(max(1, min(int(n), numba.config.NUMBA_NUM_THREADS)))


def _record(spec: SampleSpec, status: str, error: str = "", **values) -> dict:
    rec = {"sample": spec.index, "replicate": spec.replicate, "seed": spec.seed,
           "vary": spec.vary, "overrides": list(spec.overrides), "status": status,
           "error": error, "dir": spec.outdir}
    rec.update(values)
    return rec


def _write_record(spec: SampleSpec, rec: dict) -> None:
    Path(spec.outdir).mkdir(parents=True, exist_ok=True)
    atomic_write_text(Path(spec.outdir) / RESULT, json.dumps(rec, indent=2))


def _mass_histograms(sim, outdir: Path) -> None:
    """``plots/mass_histogram.png`` of every body with a random mass field."""
    from .heterogeneity.cracks import crack_mask
    from .heterogeneity.mass import body_rng, distribution, mass_field
    from .heterogeneity.plots import plot_mass_histogram

    p, deck = sim.solver.p, sim.deck
    for b, body in enumerate(deck.body):
        if body.mass is None:
            continue
        sel = p.body == b
        spec = body.mass.model_dump()
        solid = ~crack_mask(p.x0[sel], [c.model_dump() for c in body.crack], body.dx)
        m0 = float(p.rho0[sel][0] * p.vol0[sel][0])
        m, scale = mass_field(m0, spec, solid, body_rng(deck.run.seed, b))
        name = "mass_histogram.png" if b == 0 else f"mass_histogram_{body.name}.png"
        plot_mass_histogram(m[solid], outdir / "plots" / name, law=distribution(spec),
                            m0=m0, scale=scale,
                            title=f"{body.name}: {spec['distribution']} masses, "
                                  f"seed {deck.run.seed}")


def run_sample(spec: SampleSpec) -> dict:
    """Run one sample from scratch in ``spec.outdir``; return and store its record.

    Never raises: an invalid deck, a guard stopping the run or any other
    exception is recorded (``status`` = ``invalid``, ``failed``, ``error``).
    ``result.json`` is written atomically as the last file.
    """
    from .deck import DeckError, load_deck
    from .guards import SimulationFailed
    from .simulation import Simulation

    t0, c0 = time.perf_counter(), time.process_time()
    out = Path(spec.outdir)
    try:
        deck = load_deck(spec.deck, list(spec.overrides))
    except DeckError as exc:
        rec = _record(spec, "invalid", str(exc))
        _write_record(spec, rec)
        return rec
    try:
        _set_threads(spec.threads)
        if out.exists():
            shutil.rmtree(out)  # an interrupted or failed attempt: start afresh
        sim = Simulation.from_deck(deck, out)
        status, error = "completed", ""
        try:
            sim.run(progress=False)
        except SimulationFailed as exc:
            status, error = "failed", exc.diagnosis
        values = sample_metrics(sim)
        try:
            _mass_histograms(sim, out)
        except Exception as exc:  # a plot must never lose a sample
            error = error or f"mass histogram not drawn: {exc}"
        rec = _record(spec, status, error, **values)
    except Exception as exc:  # recorded, the ensemble goes on
        rec = _record(spec, "error", f"{type(exc).__name__}: {exc}")
    rec["wall_seconds"] = time.perf_counter() - t0
    rec["cpu_seconds"] = time.process_time() - c0  # all threads of the worker process
    _write_record(spec, rec)
    return rec


def _done(spec: SampleSpec) -> bool:
    """True if the sample completed earlier with the same overrides."""
    path = Path(spec.outdir) / RESULT
    if not path.exists():
        return False
    try:
        rec = json.loads(path.read_text())
    except (OSError, ValueError):
        return False
    return rec.get("status") == "completed" and rec.get("overrides") == list(
        spec.overrides)


# ------------------------------------------------------------------ the runner

def _local_cluster(workers: int):
    import logging

    from distributed import LocalCluster

    return LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                        dashboard_address=None, silence_logs=logging.ERROR,
                        memory_limit=0)


def default_layout(n_tasks: int, cores: int | None = None,
                   workers: int | None = None) -> tuple[int, int]:
    """(workers, Numba threads per sample) of a local cluster on ``cores`` cores.

    One worker per core with one thread each, or fewer workers with more
    threads when there are fewer tasks than cores; workers x threads <=
    cores.
    """
    cores = cores or os.cpu_count() or 1
    w = workers or max(1, min(cores, n_tasks))
    return w, max(1, cores // w)


def run_ensemble(deck: str | Path, samples: int, vary=(), out: str | Path | None = None,
                 scheduler: str | None = None, workers: int | None = None,
                 threads: int | None = None, overrides=(), progress: bool = True,
                 log=print) -> Path:
    """Run (or resume) an ensemble; write the table and figure; return the CSV path.

    Parameters
    ----------
    deck : the deck file; samples : replicates per grid point.
    vary : ``--vary`` strings ``"key=v1,v2"`` (a grid over all keys).
    out : output directory (default ``out/<deck stem>-ensemble``).
    scheduler : address of a running Dask scheduler (None: a local cluster).
    workers, threads : local workers and Numba threads per sample (default
        :func:`default_layout`); with ``scheduler``, threads default to 1.
    overrides : deck overrides applied to every sample (``--set``).
    """
    deck = Path(deck)
    out = Path(out) if out else Path("out") / f"{deck.stem}-ensemble"
    specs = plan_samples(deck, samples, vary, out, overrides)
    todo = [s for s in specs if not _done(s)]
    if scheduler is None:
        n_workers, n_threads = default_layout(len(todo), workers=workers)
        n_threads = threads or n_threads
    else:
        n_workers, n_threads = None, threads or 1
    specs = [SampleSpec(**{**asdict(s), "threads": n_threads}) for s in specs]
    todo = [s for s in specs if not _done(s)]
    out.mkdir(parents=True, exist_ok=True)
    atomic_write_text(out / PLAN, json.dumps({
        "deck": str(deck.resolve()), "samples": samples, "vary": parse_vary(vary)
        if vary and isinstance(vary[0], str) else list(vary),
        "overrides": list(overrides),
        "seeds": sorted({s.seed for s in specs})}, indent=2))
    log(f"sphdyn ensemble: {len(specs)} samples, {len(specs) - len(todo)} already "
        f"done, {len(todo)} to run -> {out}")
    if todo:
        _run_on_dask(todo, scheduler, n_workers, n_threads, progress, log)
    csv_path = write_report(out)
    return csv_path


def _run_on_dask(todo, scheduler, n_workers, n_threads, progress, log) -> None:
    from distributed import Client, as_completed

    cluster = None
    if scheduler is None:
        os.environ.setdefault("OMP_NUM_THREADS", "1")
        cluster = _local_cluster(n_workers)
        client = Client(cluster)
        log(f"  local Dask cluster: {n_workers} worker process(es) x {n_threads} "
            "Numba thread(s)")
    else:
        client = Client(scheduler)
        log(f"  Dask scheduler {scheduler}: "
            f"{len(client.scheduler_info().get('workers', {}))} worker(s), "
            f"{n_threads} Numba thread(s) per sample")
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=len(todo), unit="sample")
    try:
        futures = {client.submit(run_sample, s, key=f"sphdyn-{s.name}-{time.time_ns()}",
                                 pure=False, retries=0): s for s in todo}
        for fut in as_completed(futures):
            spec = futures[fut]
            try:
                rec = fut.result()
            except Exception as exc:  # the worker died (segfault, memory, killed)
                rec = _record(spec, "error", f"worker lost: {type(exc).__name__}: {exc}")
                _write_record(spec, rec)
            if bar is not None:
                bar.update(1)
                bar.set_postfix_str(f"{spec.name} {rec['status']}")
            if rec["status"] != "completed":
                log(f"  {spec.name}: {rec['status']}: {rec['error'].splitlines()[0]}"
                    if rec["error"] else f"  {spec.name}: {rec['status']}")
    finally:
        if bar is not None:
            bar.close()
        client.close()
        if cluster is not None:
            cluster.close()


# ------------------------------------------------------------------ reporting

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
    from .io import read_frame
    from .io.frames import list_frames

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

    from .io.snapshots import particle_spacing

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
