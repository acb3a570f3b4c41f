"""``sphdyn validate``: run each case, measure, compare, write the table.

Each case runs as ``sphdyn run`` in a subprocess (one at a time, its own
memory) into ``OUT/<case>/``; a finished run is kept and, with ``--reuse``,
only measured again. The quick version adds the case's ``quick`` overrides
(coarser spacing) and writes into ``OUT/<case>-quick/``.
"""

from __future__ import annotations

import datetime
import json
import os
import subprocess
import sys
from pathlib import Path

from ..deck import DeckError, load_deck
from .cases import CASES, Case, resolved_deck
from .report import compare


def root_problem(root: Path, names: list[str]) -> str | None:
    """Why ``root`` cannot run the cases ``names`` (None if it can)."""
    if not (root / "validation" / "data").is_dir():
        return (f"{root.resolve()} has no validation/data/ folder. Fix: run from the sphdyn "
                "source tree (git clone) or give --root PATH_TO_IT")
    for name in names:
        deck = root / CASES[name].deck
        if not deck.is_file():
            return f"case {name!r}: its deck {deck} is missing. Fix: restore it from git"
    return None


def run_dir(out: Path, case: Case, quick: bool) -> Path:
    return out / (case.name + ("-quick" if quick else ""))


def case_overrides(case: Case, quick: bool) -> tuple[str, ...]:
    """The case's own deck overrides, and its quick ones for ``quick``."""
    return case.overrides + (case.quick if quick else ())


def completed(run: Path) -> bool:
    summary = run / "summary.json"
    return summary.is_file() and json.loads(summary.read_text())["status"] == "completed"


def run_case(case: Case, root: Path, out: Path, quick: bool, threads: int | None,
             reuse: bool, sets: tuple[str, ...] = ()) -> dict:
    """Run (unless ``reuse`` finds it done), measure and compare one case;
    ``sets`` are the user's overrides, applied after the case's own."""
    run = run_dir(out, case, quick)
    overrides = case_overrides(case, quick) + tuple(sets)
    if not (reuse and completed(run)):
        cmd = [sys.executable, "-m", "sphdyn", "run", str(root / case.deck), "--out",
               str(run), "-q"]
        for override in overrides:
            cmd += ["--set", override]
        if threads:
            cmd += ["--threads", str(threads)]
        subprocess.run(cmd, env=os.environ.copy(), check=False)
    summary_path = run / "summary.json"
    summary = json.loads(summary_path.read_text()) if summary_path.is_file() else \
        {"status": "failed", "diagnosis": "no summary.json: the run did not start"}
    result = {"case": case.name, "title": case.title, "quick": quick,
              "deck": case.deck, "overrides": list(overrides),
              "status": summary["status"], "diagnosis": summary.get("diagnosis"),
              "wall_seconds": summary.get("wall_seconds"), "steps": summary.get("steps"),
              "items": summary.get("items"), "run": str(run),
              "date": datetime.date.today().isoformat(), "rows": []}
    if summary["status"] == "completed":
        refs = case.references(root / "validation" / "data")
        values = case.measure(run, resolved_deck(run))
        result["rows"] = compare(refs, values)
        case.figure(run, case, result["rows"], run / "validation.png",
                    root / "validation" / "data")
    return result


def _commit(root: Path) -> str:
    """The source tree's commit (short hash), or '' outside a git checkout."""
    try:
        out = subprocess.run(["git", "-C", str(root), "rev-parse", "--short", "HEAD"],
                             capture_output=True, text=True, check=False)
    except OSError:
        return ""
    return out.stdout.strip() if out.returncode == 0 else ""


def page_block(results: list[dict], root: Path, figures: dict[str, str]) -> str:
    """The generated part of docs/validation.md: how it was made, the table,
    the sources and each case's figure."""
    from .report import sources_markdown, table_markdown

    commit = _commit(root)
    lines = [f"Made by `sphdyn validate --docs` on {results[0]['date']}"
             + (f" at commit {commit}" if commit else "") + ". Each case's run:", ""]
    for res in results:
        secs = res.get("wall_seconds")
        lines.append(f"* `{res['case']}`: {res['deck']}, {res.get('items')} particles and "
                     f"mesh nodes, {res.get('steps')} steps, "
                     + (f"{secs / 60:.1f} min, " if secs else "") + f"status {res['status']}"
                     + (f" ({res['diagnosis'].splitlines()[0].rstrip('.')}; the whole "
                        "diagnosis in its summary.json)" if res.get("diagnosis") else "")
                     + ".")
    lines += ["", table_markdown(results), "", "Where the measured values come from:", "",
              sources_markdown(results)]
    for res in results:
        if res["case"] in figures:
            lines += ["", f"![{res['title']}](figures/{figures[res['case']]})"]
    return "\n".join(lines)


def validate(names: list[str], quick: bool, out: Path, root: Path, threads: int | None,
             reuse: bool, docs: bool, sets: tuple[str, ...] = ()) -> int:
    """The ``sphdyn validate`` command (module docstring); exit status 0 when
    every case ran to its end, 1 otherwise. ``sets`` (``--set``) override
    deck values in every case: a sensitivity study, kept off the docs page."""
    import shutil

    from .report import table_markdown, update_page, write_results

    names = list(names) or list(CASES)
    unknown = [n for n in names if n not in CASES]
    if unknown:
        raise ValueError(f"unknown validation case(s) {', '.join(unknown)}. Fix: use one "
                         f"of {', '.join(CASES)}")
    if docs and quick:
        raise ValueError("--docs writes docs/validation.md, which shows the full cases. "
                         "Fix: drop --quick (or --docs)")
    if docs and sets:
        raise ValueError("--docs writes docs/validation.md, which shows the cases as they "
                         "are. Fix: drop --set (a sensitivity study prints its own table "
                         "and writes OUT/validation.md)")
    problem = root_problem(root, names)
    if problem:
        raise ValueError(problem)
    for name in names:  # every case's deck with its overrides, before anything runs
        case = CASES[name]
        try:
            load_deck(root / case.deck, [*case_overrides(case, quick), *sets])
        except DeckError as exc:
            raise ValueError(f"case {name!r}: {exc}") from None
    results = []
    for name in names:
        print(f"validate: {name}{' (quick)' if quick else ''} ...", flush=True)
        res = run_case(CASES[name], root, out, quick, threads, reuse, sets)
        results.append(res)
        for row in res["rows"]:
            print(f"  {row['quantity']}: measured {row['measured']:.3g}, sphdyn "
                  f"{row['sphdyn']:.3g} ({row['difference_pct']:+.0f} %, {row['verdict']})")
        if res["status"] != "completed":
            print(f"  run {res['status']}: not compared (its diagnosis is above and in "
                  f"{res['run']}/summary.json)")
    write_results(results, out)
    print(table_markdown(results))
    print(out / "validation.md")
    if docs:
        figures = {}
        for res in results:
            png = Path(res["run"]) / "validation.png"
            if png.is_file():
                figures[res["case"]] = f"validation_{res['case']}.png"
                shutil.copyfile(png, root / "docs" / "figures" / figures[res["case"]])
        update_page(root / "docs" / "validation.md", page_block(results, root, figures))
    return 0 if all(r["status"] == "completed" for r in results) else 1
