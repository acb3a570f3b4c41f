"""The subcommands but ``material-test``: each a thin function over the Python
API, returning the exit code (0 success, 1 a failed run, 2 bad input)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

from .args import _si, _writable_dir


def cmd_run(args) -> int:
    from ..deck import load_deck
    from ..watchers.monitors import compile_notice
    from ..simulation import Simulation

    out = Path(args.out) if args.out else Path("out") / Path(args.deck).stem
    deck_path = args.deck
    if Path(args.deck).suffix.lower() in KEYWORD_SUFFIXES:
        _writable_dir(out, "--out")
        deck_path = _import_for_run(args, out)
        if deck_path is None:
            return 2
    deck = load_deck(deck_path, args.set)
    _writable_dir(out, "--out")
    with compile_notice(None if args.quiet else _note):
        sim = Simulation.from_deck(deck, out)
    _warn_thin_members(deck, sim.model)
    if not args.quiet:
        print(f"sphdyn: {sim.particles.n} particles{_mesh_counts(sim.model)}, "
              f"{deck.run.dimension}D, "
              f"t_end = {deck.run.t_end:g} s, initial dt = {sim.stepper.dt0:.3e} s -> {out}")
    return _finish(sim.run(max_steps=args.max_steps, progress=not args.quiet and None,
                           threads=args.threads), out, args.quiet)


#: file suffixes ``sphdyn run`` takes for LS-DYNA keyword decks
KEYWORD_SUFFIXES = (".k", ".key", ".dyn")


def _import_for_run(args, out: Path):
    """``sphdyn run MODEL.k``: the keyword deck imported into ``out/imported/``
    (the deck and its data files, kept with the run so that it can restart);
    the deck's path, or None when items left out change the result."""
    from ..lsdyna import import_deck, write_import

    if not args.units:
        raise ValueError(f"{args.deck} is an LS-DYNA keyword deck: give its units. Fix: "
                         "add --units (e.g. --units mm-ms-kg; docs/lsdyna.md)")
    deck_path = out / "imported" / (Path(args.deck).stem + ".toml")
    imported = import_deck(args.deck, args.units, stem=deck_path.stem)
    if not _report_dropped(imported, args.allow_partial):
        return None
    write_import(imported, deck_path)
    return deck_path


def _report_dropped(imported, allow_partial: bool) -> bool:
    """Print what an import left out; False when that changes the result and
    ``--allow-partial`` was not given."""
    for d in imported.dropped:
        print(f"not imported: {d.line()}", file=sys.stderr)
    physics = [d for d in imported.dropped if d.physics]
    if physics and not allow_partial:
        print(f"sphdyn: {len(physics)} item(s) above would change the result; nothing "
              "written. Fix: remove them from the keyword deck, or give "
              "--allow-partial to go on without them (listed at the written deck's "
              "top)", file=sys.stderr)
        return False
    return True


def _warn_thin_members(deck, model) -> None:
    """``warning: ...`` on stderr for each member too thin for its formulation
    (:func:`sphdyn.checks.thin_members.thin_member_warnings`); not an error."""
    from ..checks.thin_members import thin_member_warnings

    for text in thin_member_warnings(deck, model):
        print(f"warning: {text}", file=sys.stderr, flush=True)


def _note(text: str) -> None:
    """A line for the person waiting (stderr, at once)."""
    print(text, file=sys.stderr, flush=True)


def _mesh_counts(model) -> str:
    """``", 2 meshes (1200 elements, 1500 nodes)"``, or nothing without meshes."""
    if not model.meshes:
        return ""
    ne = sum(m.cells.shape[0] for m in model.meshes)
    nn = sum(m.points.shape[0] for m in model.meshes)
    k = len(model.meshes)
    return f", {k} mesh{'es' if k > 1 else ''} ({ne} elements, {nn} nodes)"


def cmd_restart(args) -> int:
    from ..watchers.monitors import compile_notice
    from ..simulation import Simulation

    if Path(args.dir).is_dir():  # a missing one is reported by from_directory
        _writable_dir(args.dir, "DIR")
    with compile_notice(None if args.quiet else _note):
        sim = Simulation.from_directory(args.dir)
    t = sim.stepper.t
    if args.t_end is not None and args.t_end <= t * (1 + 1e-12):
        raise ValueError(f"--t-end {args.t_end:g} s is not after the checkpoint's time "
                         f"t = {t:.6g} s in {args.dir}. Fix: give a --t-end later than "
                         f"{t:.6g} s")
    if not args.quiet:
        print(f"sphdyn: restarting {args.dir} at t = {t:.6e} s "
              f"(step {sim.stepper.step_count})")
    return _finish(sim.run(t_end=args.t_end, max_steps=args.max_steps,
                           progress=not args.quiet and None,
                           threads=args.threads), args.dir, args.quiet)


def _finish(summary: dict, out, quiet: bool = False) -> int:
    """Print the run's summary for a person (not with ``-q``; all of it is in
    summary.json); the exit code (128 + signal if interrupted)."""
    from ..simulation import summary_text

    if not quiet:
        print(summary_text(summary, out))
    if summary.get("status") == "interrupted":
        import signal

        from ..watchers.interrupt import SIGNALS

        sig = signal.Signals[summary["signal"]]
        print(f"sphdyn: interrupted by {sig.name} at t = {summary['time']:.6e} s "
              f"(step {summary['steps']}); checkpoint, history and summary written. "
              f"Resume with: sphdyn restart {out}", file=sys.stderr)
        return SIGNALS[sig]
    return 0


def cmd_ensemble(args) -> int:
    from ..ensemble import run_ensemble, write_report

    out = Path(args.out) if args.out else Path("out") / f"{Path(args.deck).stem}-ensemble"
    if args.report:
        print(write_report(out))
        return 0
    _writable_dir(out, "--out")  # the --vary grid is checked by the plan, before Dask
    path = run_ensemble(args.deck, args.samples, vary=args.vary or (), out=out,
                        scheduler=args.scheduler, workers=args.workers,
                        threads=args.threads, overrides=args.set or (),
                        progress=not args.quiet)
    print(path)
    return 0


def cmd_import(args) -> int:
    """``sphdyn import MODEL.k``: the sphdyn deck of an LS-DYNA keyword deck,
    then ``sphdyn check`` on it; exit 2 when an item left out changes the
    result (unless ``--allow-partial``)."""
    from ..lsdyna import import_deck, write_import

    src = Path(args.model)
    out = Path(args.out) if args.out else src.with_suffix(".toml")
    if out.resolve() == src.resolve():
        raise ValueError(f"-o {out} would overwrite the keyword deck. Fix: give "
                         "another -o")
    imported = import_deck(src, args.units, stem=out.stem)
    if not _report_dropped(imported, args.allow_partial):
        return 2
    paths = write_import(imported, out)
    print(f"sphdyn import: {src} ({args.units}) -> " + ", ".join(str(p) for p in paths))
    args.deck, args.set, args.resolved = str(out), None, None
    return cmd_check(args)


def cmd_check(args) -> int:
    from ..deck import load_deck
    from ..build.model import build_model
    from ..checks.size import estimate_size, memory_limit, show_bytes

    deck = load_deck(args.deck, args.set)
    model = build_model(deck)  # refuses a model over the memory limit before building
    estimate = estimate_size(deck, model)
    p = model.particles
    limit, source = memory_limit(deck)
    stepper = None
    if deck.gauge or deck.time.mass_scaling is not None:
        from ..build import build_stepper

        # gauges are placed on the stepper's parts, as a run places them; the
        # mass scaling is worked out on its started parts (and may be refused)
        stepper = build_stepper(deck, model)
    if deck.gauge:
        from ..watchers.gauges import build_gauges

        build_gauges(deck, stepper.parts)
    print(f"{args.deck}: OK")
    print(f"  {deck.run.dimension}D, t_end = {deck.run.t_end:g} s, {p.n} particles in "
          f"{len(model.body_names)} bodies{_mesh_counts(model)}, "
          f"{len(deck.material)} materials, "
          f"{len(model.walls)} walls, sets {sorted(model.sets) + sorted(model.mesh_sets) or '-'}"
          f"{f', {len(deck.gauge)} gauges' if deck.gauge else ''}")
    print(f"  estimate: {estimate.summary()}; memory limit {show_bytes(limit)} "
          f"({source})")
    if stepper is not None and stepper.mass_scaling is not None:
        print(stepper.mass_scaling.describe())
    _warn_thin_members(deck, model)
    if args.resolved:
        from ..deck import dump_resolved

        dump_resolved(deck, args.resolved)
        print(f"  resolved deck written to {args.resolved}")
    return 0


def cmd_plot(args) -> int:
    if not args.snapshots:
        from ..io import plot_history

        for d in args.dir:
            summary = Path(d) / "summary.json"  # the run's window, if it wrote one
            window = (json.loads(summary.read_text()).get("force_window")
                      if summary.exists() else None)
            for p in plot_history(Path(d) / "history.csv", Path(d) / "plots", window):
                print(p)
        return 0

    from ..deck.units import TIME
    from ..io import plot_snapshots

    fields = [f.strip() for item in args.snapshots for f in item.split(",") if f.strip()]
    times = None
    if args.times is not None:  # "1e-4,0.5 ms": plain numbers are seconds
        items = [t.strip() for t in args.times.split(",") if t.strip()]
        if not items:
            raise ValueError(f"--times {args.times!r} gives no time")
        times = [_si(item, TIME) for item in items]
    fields = list(dict.fromkeys(fields))
    if args.out and len(fields) > 1:
        raise ValueError("--out takes one --snapshots field; run once per field")
    for field in fields:
        print(plot_snapshots(args.dir, field, times=times, n=args.n, out=args.out,
                             vmin=args.vmin, vmax=args.vmax))
    return 0


def cmd_mesostructure(args) -> int:
    from ..deck import load_deck
    from ..heterogeneity.mesostructure import phase_statistics, save_phase_slices
    from ..build.model import build_model

    deck = load_deck(args.deck, args.set or [])
    model = build_model(deck)
    p = model.particles
    out = Path(args.out) if args.out else Path("out") / f"{Path(args.deck).stem}-phases"
    shown = 0
    for b, body in enumerate(deck.body):
        if body.mesostructure is None:
            continue
        sel = p.body == b
        st = phase_statistics(model.phase[sel], body.dx, x=p.x[sel])
        png = save_phase_slices(model.phase[sel], out / f"phases_{body.name}.png",
                                body.dx, x=p.x[sel],
                                title=f"{body.name}: seed {deck.run.seed}")
        print(f"{body.name}: {st.summary()}")
        if body.name in model.photo_targets:  # the photo's statistics next to them
            print(f"{body.name}: {model.photo_targets[body.name].summary()}")
        print(png)
        shown += 1
    if not shown:
        print("no [body.mesostructure] in this deck")
        return 1
    return 0


def cmd_ucs(args) -> int:
    from ..analysis.compression import ensemble_report

    stats = ensemble_report(args.dirs, args.wall, args.out, homogeneous=args.homogeneous)
    ps, es = stats["peak_stress"], stats["strain_at_peak"]
    print(f"{ps['n']} runs ({stats['skipped']} skipped): peak stress "
          f"{ps['mean'] * 1e-6:.2f} MPa (CoV {100 * ps['cov']:.1f} %), strain at peak "
          f"{es['mean'] * 1e3:.3f} permille (CoV {100 * es['cov']:.1f} %)")
    if "homogeneous" in stats:
        h = stats["homogeneous"]
        print(f"homogeneous: {h['peak_stress'] * 1e-6:.2f} MPa at "
              f"{h['strain_at_peak'] * 1e3:.3f} permille")
    print(Path(args.out) / "ucs_curves.png")
    return 0


def cmd_export(args) -> int:
    from ..io import export_csv, export_vtk

    if args.format == "vtk" and args.frame is not None:
        raise ValueError("--frame selects the frame of --format csv; the VTK export "
                         "writes every frame. Fix: add --format csv or drop --frame")

    if args.format == "vtk":
        print(export_vtk(args.dir))
    else:
        print(export_csv(args.dir, frame=-1 if args.frame is None else args.frame))
    return 0


def cmd_validate(args) -> int:
    from ..validation.runner import validate

    return validate(args.cases, quick=args.quick, out=Path(args.out), root=Path(args.root),
                    threads=args.threads, reuse=args.reuse, docs=args.docs,
                    sets=tuple(args.set))


def cmd_info(args) -> int:
    import h5py
    import numba
    import numpy
    import scipy

    from .. import __version__

    cache = Path(__file__).parent / "__pycache__"
    n_cached = len(list(cache.glob("*.nbi"))) + len(list(Path(__file__).parent.glob(
        "*/__pycache__/*.nbi")))
    info = {
        "sphdyn": __version__, "python": sys.version.split()[0],
        "numpy": numpy.__version__, "numba": numba.__version__,
        "scipy": scipy.__version__, "h5py": h5py.__version__,
        "threads": numba.get_num_threads(), "threading_layer_default":
        numba.config.THREADING_LAYER, "numba_cache_entries": n_cached,
        "numba_cache_dir": str(numba.config.CACHE_DIR or "next to the package sources"),
    }
    for k, v in info.items():
        print(f"{k:>24}: {v}")
    return 0


def cmd_bench(args) -> int:
    from ..bench import main_json

    if args.particles is not None and args.case != "block3d":
        raise ValueError(f"--particles: the case {args.case} has a fixed particle count "
                         "(the rings of Gray et al. 2001). Fix: drop --particles, or "
                         "use it with block3d")
    if args.elements is not None and args.case != "hex3d":
        raise ValueError(f"--elements: the case {args.case} has no elements. Fix: use it "
                         "with hex3d")
    if args.coarse and args.case != "hvi":
        raise ValueError("--coarse: only the hvi case has a coarse deck. Fix: drop --coarse")
    print(main_json(case=args.case, steps=args.steps, threads=args.threads,
                    particles=args.particles, elements=args.elements, coarse=args.coarse))
    return 0


def cmd_airblast(args) -> int:
    from ..io.plots import markdown_table
    from ..interactions.kingery_bulmash import Z_RANGE, BURSTS, blast_parameters

    w, ranges = args.charge, args.distance
    lo, hi = Z_RANGE[BURSTS[args.burst]]
    rows = []
    for r in ranges:
        z = r / w ** (1.0 / 3.0)
        if not lo <= z <= hi:
            raise ValueError(f"--distance {r:g} m: scaled distance {z:.4g} m/kg^(1/3) is "
                             f"outside the fits' range {lo}-{hi}. Fix: a distance between "
                             f"{lo * w ** (1 / 3):.4g} and {hi * w ** (1 / 3):.4g} m")
        p = blast_parameters(z, w, args.burst)
        rows.append({"R [m]": f"{r:g}", "Z [m/kg^(1/3)]": f"{z:.4g}",
                     "Pso [kPa]": f"{1e-3 * p['Pso']:.4g}", "Pr [kPa]": f"{1e-3 * p['Pr']:.4g}",
                     "ta [ms]": f"{1e3 * p['ta']:.4g}", "t0 [ms]": f"{1e3 * p['t0']:.4g}",
                     "is [kPa ms]": f"{p['is']:.4g}", "ir [kPa ms]": f"{p['ir']:.4g}"})
    print(f"Kingery-Bulmash, {args.burst.replace('_', ' ')} burst, {w:g} kg TNT "
          "(docs/theory.md \"Empirical blast loads\")")
    print(markdown_table(rows))
    return 0
