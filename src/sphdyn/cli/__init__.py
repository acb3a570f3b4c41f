"""Command line: ``sphdyn run|check|import|restart|ensemble|plot|ucs|export|info|bench|material-test``.

Each subcommand is a thin function over the Python API. Exit codes: 0 success,
1 a failed run (guard stopped it; all output kept), 2 bad input (deck or
arguments).
"""

from __future__ import annotations

import argparse
import sys

from .args import _duration, _positive, _whole
from .commands import (cmd_airblast, cmd_bench, cmd_check, cmd_ensemble, cmd_export, cmd_import, cmd_info, cmd_mesostructure, cmd_plot, cmd_restart, cmd_run, cmd_ucs, cmd_validate)
from .material_test import cmd_material_test


#: what -q leaves out of a run
QUIET = "print only warnings and errors: no progress bar, no summary (summary.json has it)"


def build_parser() -> argparse.ArgumentParser:
    from .. import __version__

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
    r.add_argument("--units", help="an LS-DYNA keyword deck's units (DECK.k, .key or "
                   ".dyn: imported into OUT/imported/ first, docs/lsdyna.md)")
    r.add_argument("--allow-partial", action="store_true", help="a keyword deck: run "
                   "even when items left out by the import change the result")
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

    from ..lsdyna.units import help_text

    im = sub.add_parser("import", help="an LS-DYNA keyword deck (.k) as a sphdyn deck, "
                        "then check it (docs/lsdyna.md)")
    im.add_argument("model", help="the keyword deck (its *INCLUDE files are followed)")
    im.add_argument("-o", "--out", help="the sphdyn deck to write (default MODEL.toml; "
                    "its mesh and particle files beside it)")
    im.add_argument("--units", required=True, help="the keyword deck's consistent "
                    "units, length-time-mass: " + help_text())
    im.add_argument("--allow-partial", action="store_true", help="write the deck even "
                    "when items left out change the result (they are listed at its top)")
    im.set_defaults(func=cmd_import)

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
    from ..deck import DeckError
    from ..watchers.guards import SimulationFailed

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
