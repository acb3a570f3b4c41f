"""Running samples: one sample in a worker, the whole ensemble on Dask.

:func:`run_sample` runs one :class:`~.plan.SampleSpec` from scratch and
records it (never raises); :func:`run_ensemble` plans the samples, skips
those already done and runs the rest on a :class:`distributed.LocalCluster`
of worker processes (:func:`default_layout`) or on a running scheduler,
then writes the report.
"""

from __future__ import annotations

import json
import os
import shutil
import time
from dataclasses import asdict
from pathlib import Path

from ..io.atomic import atomic_write_text
from .metrics import sample_metrics
from .plan import PLAN, RESULT, SampleSpec, parse_vary, plan_samples
from .report import plot_mass_histograms, write_report


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


def run_sample(spec: SampleSpec) -> dict:
    """Run one sample from scratch in ``spec.outdir``; return and store its record.

    Never raises: an invalid deck, a guard stopping the run or any other
    exception is recorded (``status`` = ``invalid``, ``failed``, ``error``).
    ``result.json`` is written atomically as the last file.
    """
    from ..deck import DeckError, load_deck
    from ..watchers.guards import SimulationFailed
    from ..simulation import Simulation

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
            sim.run(progress=False, threads=spec.threads)
        except SimulationFailed as exc:
            status, error = "failed", exc.diagnosis
        values = sample_metrics(sim)
        try:
            plot_mass_histograms(sim, out)
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


#: Seconds to wait for a ``--scheduler`` to answer.
CONNECT_TIMEOUT = 5.0


def _connect(scheduler: str):
    """A Dask client of a running scheduler; a ValueError within
    :data:`CONNECT_TIMEOUT` seconds if none answers at that address."""
    from distributed import Client

    try:
        return Client(scheduler, timeout=CONNECT_TIMEOUT)
    except (OSError, TimeoutError, ValueError, TypeError) as exc:
        detail = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise ValueError(
            f"--scheduler {scheduler}: no Dask scheduler answered within "
            f"{CONNECT_TIMEOUT:g} s ({detail}). Fix: start one (`dask scheduler`) and "
            "give its address, e.g. tcp://host:8786, or leave out --scheduler for a "
            "local cluster") from None


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
        client = _connect(scheduler)
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
