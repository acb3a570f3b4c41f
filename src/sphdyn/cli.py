"""Command line: ``sphdyn run|check|restart|ensemble|plot|ucs|export|info|bench|material-test``.

Each subcommand is a thin function over the Python API. Exit codes: 0 success,
1 a failed run (guard stopped it; all output kept), 2 bad input (deck or
arguments).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path


def _threads(n):
    """Set the Numba thread count; ``None`` leaves the automatic choice."""
    if n is not None:
        import numba

        numba.set_num_threads(n)


def _whole(lo: int):
    """An argparse type: a whole number of at least ``lo``."""
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = None
        if value is None or value < lo:
            raise argparse.ArgumentTypeError(
                f"{text!r} is not a whole number >= {lo}; give e.g. {max(lo, 1) * 2}")
        return value
    parse.__name__ = f"whole number >= {lo}"
    return parse


def _si(text: str, dim) -> float:
    """A quantity on the command line: a plain number is SI (as in decks),
    else a string with units ("250 us"); raises QuantityError."""
    from .deck.units import to_si

    try:
        return float(text)
    except ValueError:
        return to_si(text, dim)


def _positive(dim_name: str):
    """An argparse type: a positive finite quantity of the deck dimension
    ``dim_name`` (``TIME``, ``MASS``, ...), plain numbers in SI."""
    from .deck import units

    dim = getattr(units, dim_name)

    def parse(text: str) -> float:
        try:
            value = _si(text, dim)
        except units.QuantityError as exc:
            raise argparse.ArgumentTypeError(f"{exc.what}; {exc.fix}") from None
        if not value > 0 or value == float("inf"):
            raise argparse.ArgumentTypeError(
                f"{text!r} is not a positive finite {dim.name}; give e.g. "
                f"{dim.si_example:g} ({dim.si_name}) or '{dim.example}'")
        return value
    return parse


#: an argparse type: a time, plain numbers in seconds or with units ("250 us")
_duration = _positive("TIME")


def _writable_dir(path, flag: str) -> Path:
    """Check that directory ``path`` can be made and written, without making it.

    The path must not be a file or lie under one, and its nearest existing
    directory (itself, or the ancestor it would be made in) must take a new
    file. Raises a ValueError naming ``flag`` (the option that gave the path).
    """
    import tempfile

    path = Path(path)
    probe = path
    while not probe.exists() and probe != probe.parent:
        probe = probe.parent
    if not probe.is_dir():
        what = "this is a file" if probe == path else f"{probe} is a file"
        raise ValueError(f"{flag} {path}: {what}, not a directory. "
                         f"Fix: give {flag} a directory (new or existing)")
    try:
        with tempfile.TemporaryFile(dir=probe):
            pass
    except OSError as exc:
        raise ValueError(f"{flag} {path}: cannot write there ({exc.strerror or exc}). "
                         f"Fix: give {flag} a directory you may write to") from None
    return path


def cmd_run(args) -> int:
    from .deck import load_deck
    from .watchers.monitors import compile_notice
    from .simulation import Simulation

    deck = load_deck(args.deck, args.set)
    out = Path(args.out) if args.out else Path("out") / Path(args.deck).stem
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


def _warn_thin_members(deck, model) -> None:
    """``warning: ...`` on stderr for each member too thin for its formulation
    (:func:`sphdyn.checks.thin_members.thin_member_warnings`); not an error."""
    from .checks.thin_members import thin_member_warnings

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
    from .watchers.monitors import compile_notice
    from .simulation import Simulation

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
    from .simulation import summary_text

    if not quiet:
        print(summary_text(summary, out))
    if summary.get("status") == "interrupted":
        import signal

        from .watchers.interrupt import SIGNALS

        sig = signal.Signals[summary["signal"]]
        print(f"sphdyn: interrupted by {sig.name} at t = {summary['time']:.6e} s "
              f"(step {summary['steps']}); checkpoint, history and summary written. "
              f"Resume with: sphdyn restart {out}", file=sys.stderr)
        return SIGNALS[sig]
    return 0


def cmd_ensemble(args) -> int:
    from .ensemble import run_ensemble, write_report

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


def cmd_check(args) -> int:
    from .deck import load_deck
    from .build.model import build_model
    from .checks.preflight import estimate_size, memory_limit, show_bytes

    deck = load_deck(args.deck, args.set)
    model = build_model(deck)  # refuses a model over the memory limit before building
    estimate = estimate_size(deck, model)
    p = model.particles
    limit, source = memory_limit(deck)
    stepper = None
    if deck.gauge or deck.time.mass_scaling is not None:
        from .build import build_stepper

        # gauges are placed on the stepper's parts, as a run places them; the
        # mass scaling is worked out on its started parts (and may be refused)
        stepper = build_stepper(deck, model)
    if deck.gauge:
        from .watchers.gauges import build_gauges

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
        from .deck import dump_resolved

        dump_resolved(deck, args.resolved)
        print(f"  resolved deck written to {args.resolved}")
    return 0


def cmd_plot(args) -> int:
    if not args.snapshots:
        from .io import plot_history

        for d in args.dir:
            summary = Path(d) / "summary.json"  # the run's window, if it wrote one
            window = (json.loads(summary.read_text()).get("force_window")
                      if summary.exists() else None)
            for p in plot_history(Path(d) / "history.csv", Path(d) / "plots", window):
                print(p)
        return 0

    from .deck.units import TIME
    from .io import plot_snapshots

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
    from .deck import load_deck
    from .heterogeneity.mesostructure import phase_statistics, save_phase_slices
    from .build.model import build_model

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
    from .analysis.compression import ensemble_report

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
    from .io import export_csv, export_vtk

    if args.format == "vtk" and args.frame is not None:
        raise ValueError("--frame selects the frame of --format csv; the VTK export "
                         "writes every frame. Fix: add --format csv or drop --frame")

    if args.format == "vtk":
        print(export_vtk(args.dir))
    else:
        print(export_csv(args.dir, frame=-1 if args.frame is None else args.frame))
    return 0


def cmd_validate(args) -> int:
    from .validation.runner import validate

    return validate(args.cases, quick=args.quick, out=Path(args.out), root=Path(args.root),
                    threads=args.threads, reuse=args.reuse, docs=args.docs,
                    sets=tuple(args.set))


def cmd_info(args) -> int:
    import h5py
    import numba
    import numpy
    import scipy

    from . import __version__

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
    from .bench import main_json

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


def _param_value(text: str):
    """``true``/``false`` -> bool, a number -> float (SI units), else the text
    (a word such as ``linear_polynomial``, or a quantity with units, which
    the material's table checks)."""
    low = text.strip().lower()
    if low in ("true", "false"):
        return low == "true"
    try:
        return float(text)
    except ValueError:
        return text.strip()


def _material_params(name: str, params: dict, given: dict | None = None) -> dict:
    """Check ``--param`` values against the material's deck table.

    ``given``: the command line's text of each value (for the messages).
    Returns the values with the table's defaults filled in (SI, None
    dropped); raises ValueError with one ``--param`` line per problem, its
    fix written as ``--param key=value``.
    """
    from pydantic import ValidationError

    from .deck.errors import explain
    from .deck.introspect import is_model, strip_optional
    from .deck.sections.material import NOT_PARAMETERS
    from .materials import available_models, get_model

    if name not in available_models():
        raise ValueError(f"MODEL {name!r} is not a registered material model. Fix: use "
                         f"one of {', '.join(available_models())}, or --deck DECK "
                         f"--material {name}")
    schema = get_model(name).schema
    if schema is None:
        return params
    keys = tuple(k for k, info in schema.model_fields.items()
                 if k not in NOT_PARAMETERS and not is_model(strip_optional(info.annotation)))
    raw = {"name": "material-test", "model": name, **params}
    try:
        table = schema.model_validate(raw)
    except ValidationError as exc:
        lines = []
        for line in explain(exc, raw, schema, params=keys):
            key = line.split(":", 1)[0]
            shown = f" {key}={given[key]}" if given and key in given else (
                "" if key == "deck" else f" {key}")  # "deck": the values together
            lines.append(f"--param{shown}{line[len(key):]}")
        raise ValueError("\n".join(lines)) from None
    return table.values()


def _test_density(name: str, params: dict) -> float | None:
    """The material test's density when ``params`` give none: the model's
    ``test_density`` (:class:`~sphdyn.materials.registry.MaterialModel`;
    None for a fluid, whose state needs its own), else None."""
    from .materials import available_models, get_model

    if "density" in params or name not in available_models():
        return None
    return get_model(name).test_density


def cmd_material_test(args) -> int:
    from .materials import get_model  # noqa: F401  (registers the models)
    from .materials.driver import COMPONENTS, drive

    _threads(1 if args.threads is None else args.threads)
    if (args.confinement is None) == (args.path == "triaxial"):
        raise ValueError("--confinement is required by --path triaxial and used by no "
                         "other path. Fix: give --confinement PRESSURE [Pa] with "
                         "--path triaxial only")
    if args.confinement is not None and not 0 <= args.confinement < float("inf"):
        raise ValueError(f"--confinement {args.confinement:g}: the confining pressure "
                         "must be >= 0. Fix: give a compressive pressure in Pa, e.g. 1e7")
    params = {}
    name = args.model
    if args.deck:
        from .deck import load_deck

        deck = load_deck(args.deck, None)
        mats = {m.name: m for m in deck.material}
        if args.material not in mats:
            raise ValueError(f"--material: the deck has no material {args.material!r}; "
                             f"materials: {', '.join(mats)}")
        mat = mats[args.material]
        params = mat.values()
        if name and name != mat.model:
            raise ValueError(f"MODEL {name!r} differs from the deck material's "
                             f"model {mat.model!r}")
        name = mat.model
    if not name:
        raise ValueError("give MODEL or --deck DECK --material NAME")
    given = {}
    for item in args.param or []:
        key, sep, value = item.partition("=")
        if not sep:
            raise ValueError(f"--param {item!r}: write KEY=VALUE (SI units). Fix: e.g. "
                             "--param density=2400")
        params[key.strip()] = _param_value(value)
        given[key.strip()] = value
    rho = None if args.deck else _test_density(name, params)
    params = _material_params(name, params if rho is None else {**params, "density": rho},
                              given)
    if rho is not None:
        print(f"sphdyn: no density given; {rho:g} kg/m^3 assumed (a strain-driven "
              "material point's stress does not depend on it; --param density=... to "
              "change)", file=sys.stderr)
    _writable_dir(args.out, "--out")
    res = drive(name, params, args.path, strain=args.strain, rate=args.rate,
                n_steps=args.steps, confinement=args.confinement or 0.0, size=args.size,
                out=args.out)
    # the CSV's own columns and signs (tension positive), not the plot's axes
    strain_col, stress_col = res["columns"]
    y = res["stress"][:, COMPONENTS.index(stress_col)]
    k = int(abs(y).argmax())
    print(json.dumps({"model": name, "path": args.path, "peak_stress_Pa": float(y[k]),
                      "at_strain": float(res["strain"][k, COMPONENTS.index(strain_col)]),
                      "stress_column": f"stress_{stress_col}_Pa",
                      "strain_column": f"strain_{strain_col}",
                      "final_damage": float(res["damage"][-1]),
                      "files": [str(f) for f in res["files"]]}))
    return 0


def cmd_airblast(args) -> int:
    from .io.plots import markdown_table
    from .interactions.kingery_bulmash import Z_RANGE, BURSTS, blast_parameters

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


#: what -q leaves out of a run
QUIET = "print only warnings and errors: no progress bar, no summary (summary.json has it)"


def build_parser() -> argparse.ArgumentParser:
    from . import __version__

    ap = argparse.ArgumentParser(prog="sphdyn", description=__doc__.splitlines()[0])
    ap.add_argument("--version", action="version", version=f"sphdyn {__version__}")
    sub = ap.add_subparsers(dest="command", required=True)

    r = sub.add_parser("run", help="validate and run a deck")
    r.add_argument("deck")
    r.add_argument("--out", help="output directory (default out/<deck name>)")
    r.add_argument("--threads", type=_whole(1), default=None,
                   help="Numba threads (default: automatic)")
    r.add_argument("--set", action="append", metavar="KEY=VALUE",
                   help="override a deck value, e.g. --set run.t_end=1e-4")
    r.add_argument("--max-steps", type=_whole(0), help="stop after this many steps")
    r.add_argument("-q", "--quiet", action="store_true", help=QUIET)
    r.set_defaults(func=cmd_run)

    en = sub.add_parser("ensemble", help="run N random samples of a deck (and a grid "
                        "of --vary values) on Dask; resumable; CSV table + damage figure")
    en.add_argument("deck")
    en.add_argument("--samples", type=_whole(1), default=1, help="replicates per grid point, "
                    "seeds derived from run.seed and the replicate index (default 1)")
    en.add_argument("--vary", action="append", metavar="KEY=V1,V2,...",
                    help="a deck key and its values, e.g. sph.support_scale=0.7,1.0,1.5; "
                    "repeatable (the grid is the product)")
    en.add_argument("--scheduler", metavar="ADDRESS", help="a running Dask scheduler, "
                    "e.g. tcp://host:8786 (default: a local cluster of processes)")
    en.add_argument("--workers", type=_whole(1), help="local worker processes (default: one "
                    "per core, at most one per sample)")
    en.add_argument("--threads", type=_whole(1), default=None,
                    help="Numba threads per sample (default: cores / workers locally, 1 on "
                    "a scheduler)")
    en.add_argument("--out", help="output directory (default out/<deck>-ensemble)")
    en.add_argument("--set", action="append", metavar="KEY=VALUE",
                    help="override a deck value in every sample")
    en.add_argument("--report", action="store_true", help="run nothing: rewrite "
                    "ensemble.csv and ensemble_damage.png from the samples in --out")
    en.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    en.set_defaults(func=cmd_ensemble)

    c = sub.add_parser("check", help="validate a deck and build its model, run nothing")
    c.add_argument("deck")
    c.add_argument("--set", action="append", metavar="KEY=VALUE")
    c.add_argument("--resolved", help="also write the resolved deck here")
    c.set_defaults(func=cmd_check)

    s = sub.add_parser("restart", help="continue a run from DIR/checkpoint.h5")
    s.add_argument("dir")
    s.add_argument("--t-end", type=_duration, help="new end time, later than the "
                   "checkpoint's: seconds or with units, e.g. 2.5e-4 or '250 us' "
                   "(default the deck's)")
    s.add_argument("--threads", type=_whole(1), default=None,
                   help="Numba threads (default: automatic)")
    s.add_argument("--max-steps", type=_whole(0), help="stop after this many steps")
    s.add_argument("-q", "--quiet", action="store_true", help=QUIET)
    s.set_defaults(func=cmd_restart)

    p = sub.add_parser("plot", help="plot DIR/history.csv (or particle snapshots) "
                       "into DIR/plots")
    p.add_argument("dir", nargs="+",
                   help="run directory; with --snapshots several runs give one row each "
                   "(e.g. a case with and without a remedy)")
    p.add_argument("--snapshots", action="append", metavar="FIELD",
                   help="instead of the history plots, panels of the particles coloured "
                   "by FIELD (von_mises, damage, speed, stress_yy, ...; 1D runs: FIELD "
                   "along x, one line per time) into DIR/plots/snapshots_FIELD.png; "
                   "repeatable or a comma list")
    p.add_argument("--out", metavar="PNG",
                   help="snapshots: the PNG to write (one field only)")
    p.add_argument("--times", metavar="T1,T2,...",
                   help="snapshot times (the nearest frames), seconds or with units, "
                   "e.g. 1e-4,2e-4 or '0.1 ms,0.2 ms'")
    p.add_argument("--n", type=int, default=4,
                   help="without --times: N frames evenly spaced from first to last "
                   "(default 4)")
    p.add_argument("--vmin", type=float,
                   help="snapshot colour-scale minimum, SI (negative: --vmin=-1e6)")
    p.add_argument("--vmax", type=float, help="snapshot colour-scale maximum, SI")
    p.set_defaults(func=cmd_plot)

    ms = sub.add_parser("mesostructure", help="generate the [body.mesostructure] phases "
                        "of a deck without running it: statistics and slice images")
    ms.add_argument("deck")
    ms.add_argument("--set", action="append", metavar="KEY=VALUE",
                    help="override a deck value, e.g. --set run.seed=7")
    ms.add_argument("--out", help="directory for phases_<body>.png "
                    "(default out/<deck>-phases)")
    ms.set_defaults(func=cmd_mesostructure)

    u = sub.add_parser("ucs", help="stress-strain curves of compression runs between "
                       "platens (one or an ensemble): peak statistics and a figure")
    u.add_argument("dirs", nargs="+", help="run directories (e.g. OUT/sample_*)")
    u.add_argument("--wall", required=True, help="name of the moving platen [[wall]]")
    u.add_argument("--homogeneous", metavar="DIR", help="run of the homogeneous model, "
                   "drawn in black")
    u.add_argument("--out", default="out/ucs_report", help="directory for "
                   "ucs_samples.csv, ucs_statistics.json, ucs_curves.png")
    u.set_defaults(func=cmd_ucs)

    e = sub.add_parser("export", help="convert native frames (VTK series or CSV)")
    e.add_argument("dir")
    e.add_argument("--format", choices=("vtk", "csv"), default="vtk")
    e.add_argument("--frame", type=int, help="frame for CSV, Python style: 0 the "
                   "first, -1 the last (default)")
    e.set_defaults(func=cmd_export)

    va = sub.add_parser("validate", help="run the validation cases against measured "
                        "data (validation/), print the table; --docs writes "
                        "docs/validation.md")
    va.add_argument("cases", nargs="*", help="case names (default: all)")
    va.add_argument("--quick", action="store_true", help="the coarse versions (minutes)")
    va.add_argument("--out", default="out/validation", help="run folders and results.json")
    va.add_argument("--root", default=".", help="the sphdyn source tree holding "
                    "validation/ (default: the current directory)")
    va.add_argument("--threads", type=_whole(1), default=None,
                    help="Numba threads per run (default: automatic)")
    va.add_argument("--reuse", action="store_true", help="measure completed runs again "
                    "instead of rerunning them")
    va.add_argument("--docs", action="store_true", help="write the table and figures "
                    "into docs/validation.md (full versions only)")
    va.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="override a deck value in every case run, after the case's "
                    "own (a sensitivity study; use its own --out), e.g. --set "
                    "material.concrete.rate_effects=false")
    va.set_defaults(func=cmd_validate)

    i = sub.add_parser("info", help="versions, threads, Numba cache")
    i.set_defaults(func=cmd_info)

    b = sub.add_parser("bench", help="run a built-in benchmark, print one JSON line")
    b.add_argument("case", choices=("rings2d", "rings2d_tl", "block3d", "hex3d", "hvi"))
    b.add_argument("--steps", type=_whole(1), default=1000)
    b.add_argument("--threads", type=_whole(1), default=None,
                   help="Numba threads (default: automatic)")
    b.add_argument("--particles", type=_whole(8), help="block3d: approximate particle "
                   "count (the rings cases have a fixed count)")
    b.add_argument("--elements", type=_whole(1), help="hex3d: approximate element count")
    b.add_argument("--coarse", action="store_true", help="hvi: the coarse drop-weight deck "
                   "(dx 12 mm) instead of the full one (dx 6 mm)")
    b.set_defaults(func=cmd_bench)
    mt = sub.add_parser("material-test", help="drive one material point along a load "
                        "path; CSV + plot into --out")
    mt.add_argument("model", nargs="?", help="registered model (elastic, j2, cscm, ...)")
    mt.add_argument("--param", action="append", metavar="KEY=VALUE",
                    help="material value in SI units (repeatable), e.g. density=2400 "
                    "fc=43.1e6 aggregate_size=0.008 rate_effects=true")
    mt.add_argument("--deck", help="take the material from this deck ...")
    mt.add_argument("--material", help="... with this name")
    mt.add_argument("--path", default="uniaxial-compression",
                    choices=("uniaxial-compression", "uniaxial-tension", "hydrostatic",
                             "triaxial", "shear", "cyclic"))
    mt.add_argument("--rate", type=float, default=1e-5,
                    help="controlling strain rate [1/s] (default 1e-5)")
    mt.add_argument("--strain", type=float, help="controlling strain magnitude "
                    "(default per path)")
    mt.add_argument("--steps", type=_whole(1), default=400, help="load steps (default 400)")
    mt.add_argument("--confinement", type=float,
                    help="confining pressure [Pa] of --path triaxial (required there)")
    mt.add_argument("--size", type=float, default=0.01,
                    help="particle size for fracture-energy regularisation [m]")
    mt.add_argument("--out", default="out/material-test", help="output directory")
    mt.add_argument("--threads", type=_whole(1), default=None,
                    help="Numba threads (default 1: one material point)")
    mt.set_defaults(func=cmd_material_test)
    ab = sub.add_parser("airblast", help="Kingery-Bulmash blast parameters of a TNT "
                        "charge at given distances (as ConWep)")
    ab.add_argument("--charge", required=True, type=_positive("MASS"),
                    help="TNT mass, e.g. '75 g' or 0.075")
    ab.add_argument("--distance", required=True, nargs="+", type=_positive("LENGTH"),
                    help="distances from the charge's centre, e.g. '1 m' '2 m'")
    ab.add_argument("--burst", default="free_air", choices=("free_air", "surface"),
                    help="free_air (spherical, default) or surface (hemispherical)")
    ab.set_defaults(func=cmd_airblast)
    return ap


def main(argv=None) -> int:
    from .deck import DeckError
    from .watchers.guards import SimulationFailed

    try:
        args = build_parser().parse_args(argv)
    except SystemExit as exc:  # --help, --version, or a bad argument (usage printed)
        return exc.code if isinstance(exc.code, int) else 2
    try:
        return args.func(args)
    except DeckError as exc:
        print(f"sphdyn: the deck is not valid:\n{exc}", file=sys.stderr)
        return 2
    except (FileNotFoundError, ValueError) as exc:
        print(f"sphdyn: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:  # the environment: permissions, a missing device, ...
        where = f" {exc.filename}" if exc.filename else ""
        print(f"sphdyn: cannot access{where}: {exc.strerror or exc}. Fix: check that "
              "the path exists and may be written", file=sys.stderr)
        return 2
    except SimulationFailed as exc:
        print(f"sphdyn: {exc.diagnosis}\nAll output written so far is kept.",
              file=sys.stderr)
        return 1
    except KeyboardInterrupt:  # Ctrl-C before stepping, or a second one during a run
        print("sphdyn: interrupted (a run's checkpoint, if it wrote one, is kept; "
              "resume with sphdyn restart DIR)", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
