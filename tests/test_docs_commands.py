"""Every deck and command shown in README.md and docs/*.md runs, shortened.

* Fenced ```toml blocks: a complete deck (it has ``[run]``) is checked and run
  for a few steps; a fragment is merged into the example deck named for it in
  :data:`FRAGMENT_HOSTS` (tables by name, as a user would paste it) and the
  result checked and run the same way.
* Fenced ```python blocks run as they stand, in a scratch directory.
* Shell commands: the lines of fenced ```bash blocks and of indented code
  blocks, and inline code spans, that start with ``sphdyn``. They run in
  document order in one scratch directory (``examples/`` linked in), through
  :func:`sphdyn.cli.main` in this process, shortened:

  - every simulation stops after :data:`MAX_STEPS` steps (``Simulation.run``
    capped: plain runs, restarts and ensemble samples alike);
  - ``--samples N`` becomes ``--samples 1`` and the Dask cluster of an
    ensemble is replaced by a loop over its samples in this process (the
    cluster itself is tested in tests/test_ensemble.py);
  - ``material-test`` takes 20 load steps;
  - ``plot --times T1,...`` drops ``--times``: the shortened runs end long
    before the documented times, which ``plot`` refuses (tests/test_snapshots.py
    tests ``--times``);
  - a command reading ``out/NAME`` that no earlier command wrote first runs
    ``examples/NAME.toml``.

  Usage synopses are not commands: spans with placeholders (``DECK``, ``DIR``,
  ``N``, ``<seed>``, ``OUT/case``), optional parts (``[...]``) or elisions (``...``), and bare
  command names (```sphdyn ucs```). Anything else that cannot run here is in
  :data:`SKIP`, with the reason.
"""

from __future__ import annotations

import glob
import re
import shlex
import tomllib
from pathlib import Path

import pytest
import tomli_w

from sphdyn.cli import main

ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
MAX_STEPS = 3

#: Commands shown in the documents that cannot run in a test, and why.
SKIP = {
    # installs the package: the test runs the installed tree already
    "pip install .": "installs the package",
    "pip install '.[test]'": "installs the package",
    "pip install 'sphdyn[lsdyna]'": "installs the package with its LS-DYNA extra",
    # the whole test suite, from inside the test suite
    "pytest": "runs the test suite",
    # a remote Dask scheduler (SLURM through dask-jobqueue) that does not exist here
    "sphdyn ensemble examples/disc_impact_random_mass.toml --samples 100 "
    "--scheduler tcp://10.0.0.5:8786 --threads 1 --out /scratch/kappa":
        "needs a Dask scheduler at tcp://10.0.0.5:8786",
    # the mutation check: 19 mutants, each a fresh compile (about 7 minutes)
    "python tools/mutation.py --markdown mutation-result.md":
        "runs the mutation check (minutes); tests/test_mutation_script.py checks its list",
    # the full drop-weight model: 280,000 particles, about a minute and 0.8 GB to
    # build; tests/test_run.py runs the case on the coarse deck
    "sphdyn bench hvi --steps 20": "builds the 280,000-particle drop-weight model",
    # the validation cases: tests/test_validation_quick.py runs the quick ones
    # and holds their numbers; the full ones take hours
    "sphdyn validate --quick": "runs the quick validation cases (about 24 minutes)",
    "sphdyn validate --docs": "runs the full validation cases (hours)",
    "sphdyn plot out/validation/lozano2017_dropweight_2.5m-quick --snapshots damage":
        "needs the quick validation run (tests/test_validation_quick.py makes it)",
    # the paper's disc as a keyword deck: the script writes its 0.9 MB particle
    # include into examples/lsdyna/; tests/test_lsdyna_import.py runs the same
    # script's text, imports it and runs 60 steps against the TOML deck
    "python examples/lsdyna/disc_impact.py":
        "writes the disc's particle include (tests/test_lsdyna_import.py runs it)",
    "sphdyn run examples/lsdyna/disc_impact.k --units mm-ms-kg":
        "needs the include the script above writes (tests/test_lsdyna_import.py)",
    # starts an MPI job of 34 ranks
    "mpirun -np 34 dask-mpi --scheduler-file sched.json --nthreads 1 &":
        "starts an MPI job",
}

#: The example deck each TOML fragment is pasted into, by (document, number
#: of the ```toml block in it, from 0).
FRAGMENT_HOSTS = {
    ("heterogeneity.md", 0): "examples/disc_impact_random_mass.toml",
    ("heterogeneity.md", 1): "examples/disc_impact_crack.toml",
    ("mesostructure.md", 0): "examples/ucs_mesostructure.toml",
    ("mesostructure.md", 1): "examples/ucs_mesostructure.toml",
    ("mesostructure.md", 2): "examples/ucs_mesostructure.toml",
    ("tensile-instability.md", 0): "examples/rings_gray2001.toml",
}

_FENCE = re.compile(r"^```(\w*)\n(.*?)^```", re.S | re.M)
_PLACEHOLDER = re.compile(r"(^|[\s=,/])([A-Z][A-Z0-9_]*)([\s,.\]/]|$)|<\w+>|\.\.\.|\[|\|")


# -------------------------------------------------------------------- extraction

def fenced_blocks(language: str) -> list[tuple[str, int, str]]:
    """(document name, block number, text) of every fenced block of ``language``."""
    found = []
    for doc in DOCS:
        blocks = [m.group(2) for m in _FENCE.finditer(doc.read_text(encoding="utf-8"))
                  if m.group(1) == language]
        found += [(doc.name, k, text) for k, text in enumerate(blocks)]
    return found


def toml_blocks() -> list[tuple[str, int, str]]:
    """(document name, block number, text) of every fenced TOML block."""
    return fenced_blocks("toml")


def _logical_lines(text: str) -> list[str]:
    """Shell lines with backslash continuations joined and comments dropped."""
    text = re.sub(r"\\\n\s*", " ", text)
    return [" ".join(line.split()) for line in text.splitlines()
            if line.strip() and not line.strip().startswith("#")]


def _is_synopsis(command: str) -> bool:
    words = command.split()
    return len(words) <= 2 or bool(_PLACEHOLDER.search(" ".join(words[2:])))


def shell_commands(doc: Path) -> list[str]:
    """The commands of ``doc`` in order: fenced bash blocks, indented code
    blocks and inline ``sphdyn`` spans; synopses left out."""
    text = doc.read_text(encoding="utf-8")
    found = []  # (offset, command)
    for m in _FENCE.finditer(text):
        if m.group(1) == "bash":
            for line in _logical_lines(m.group(2)):
                found += [(m.start(), part.strip()) for part in line.split("&&")]
    prose = _FENCE.sub(lambda m: " " * len(m.group(0)), text)
    for m in re.finditer(r"(?:^    .*\n)+", prose, re.M):  # indented code blocks
        block = "\n".join(line[4:] for line in m.group(0).splitlines())
        found += [(m.start(), line) for line in _logical_lines(block)
                  if line.startswith("sphdyn ")]
    for m in re.finditer(r"`(sphdyn [^`]+)`", prose):
        found.append((m.start(), " ".join(m.group(1).split())))
    commands = [c for _, c in sorted(found, key=lambda f: f[0])]
    return [c for c in dict.fromkeys(commands)
            if c in SKIP or not (c.startswith("sphdyn ") and _is_synopsis(c))]


# ------------------------------------------------------------------- running

@pytest.fixture
def scratch(tmp_path, monkeypatch):
    """A scratch working directory with examples/ and validation/ linked in;
    every simulation capped at MAX_STEPS; ensembles run their samples in this
    process."""
    from sphdyn.ensemble import run as ensemble_run
    from sphdyn.simulation import Simulation

    (tmp_path / "examples").symlink_to(ROOT / "examples")
    (tmp_path / "validation").symlink_to(ROOT / "validation")
    monkeypatch.chdir(tmp_path)
    real_run = Simulation.run

    def short_run(self, t_end=None, max_steps=None, **kwargs):
        steps = MAX_STEPS if max_steps is None else min(max_steps, MAX_STEPS)
        return real_run(self, t_end=t_end, max_steps=steps, **kwargs)

    monkeypatch.setattr(Simulation, "run", short_run)
    monkeypatch.setattr(ensemble_run, "_run_on_dask",
                        lambda todo, *args: [ensemble_run.run_sample(s) for s in todo])
    return tmp_path


def shortened(command: str) -> list[str]:
    """The arguments of ``sphdyn ...`` as run here (see the module docstring)."""
    args = []
    for word in shlex.split(command)[1:]:
        args += sorted(glob.glob(word)) or [word] if "*" in word else [word]
    if "--samples" in args:
        args[args.index("--samples") + 1] = "1"
    if args[0] in ("run", "restart", "ensemble"):
        args.append("-q")
    if args[0] == "material-test" and "--steps" not in args:
        args += ["--steps", "20"]
    if args[0] == "plot" and "--times" in args:
        k = args.index("--times")
        del args[k:k + 2]
    return args


def _prerequisites(args: list[str]) -> None:
    """Run ``examples/NAME.toml`` for any ``out/NAME`` read that is not there."""
    reads = [a for k, a in enumerate(args) if k == 0 or args[k - 1] != "--out"]
    for arg in reads:
        m = re.match(r"out/([\w-]+)$", arg)
        if m and not Path(arg).exists() and (ROOT / "examples" / f"{m[1]}.toml").exists():
            assert main(["run", f"examples/{m[1]}.toml", "-q"]) == 0


def _check_and_run(deck: Path) -> None:
    assert main(["check", str(deck)]) == 0, deck.read_text()
    assert main(["run", str(deck), "--out", str(deck.with_suffix("")), "-q"]) == 0


def _implied(table: dict) -> bool:
    """True for a table only named on the way to its sub-tables (``sph`` in
    ``[sph.artificial_stress]``): it holds nothing but tables."""
    return all(isinstance(v, dict) or isinstance(v, list) and v and all(
        isinstance(i, dict) for i in v) for v in table.values())


def _merge(host, fragment):
    """``fragment`` pasted into ``host`` as a user would: every table the
    fragment writes replaces the host's table of that name (``[[material]]``
    by its ``name``, else appended); tables only implied by a dotted header
    are merged; a table given for an array (``[[body.crack]]`` alone) goes
    into the array's last table."""
    if isinstance(host, list) and isinstance(fragment, dict):
        return host[:-1] + [_merge(host[-1], fragment)]
    if isinstance(host, dict) and isinstance(fragment, dict) and _implied(fragment):
        return {**host, **{k: _merge(host[k], v) if k in host else v
                           for k, v in fragment.items()}}
    if isinstance(host, list) and isinstance(fragment, list) and all(
            isinstance(v, dict) and "name" in v for v in host + fragment):
        out = list(host)
        for item in fragment:
            same = [k for k, h in enumerate(out) if h["name"] == item["name"]]
            if same:
                out[same[0]] = item
            else:
                out.append(item)
        return out
    return fragment


def _write_section_photo(folder: Path) -> None:
    """A synthetic section photo for the photo fragment (tests/data generator)."""
    import importlib.util

    import numpy as np
    from PIL import Image

    spec = importlib.util.spec_from_file_location(
        "make_section_image", ROOT / "tests" / "data" / "make_section_image.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    grey, _ = module.synthetic_section(shape=(600, 600), fraction=0.35, r_min=20.0,
                                       r_max=70.0, seed=1)  # pieces 4-14 mm at 0.1 mm/px
    Image.fromarray(np.round(grey * 255).astype(np.uint8)).save(folder / "section.png")


def test_the_documents_show_decks_and_commands():
    """The extraction finds what the documents show (guards against a regex
    that silently finds nothing)."""
    names = {name for name, _, _ in toml_blocks()}
    assert {"README.md", "deck-reference.md", "mesostructure.md"} <= names
    assert "mesostructure.md" in {name for name, _, _ in fenced_blocks("python")}
    commands = [c for doc in DOCS for c in shell_commands(doc)]
    assert "sphdyn run examples/disc_impact.toml" in commands
    assert any(c.startswith("sphdyn ucs out/ucs_mesostructure-ensemble/sample_*")
               for c in commands)
    assert not any("DECK" in c for c in commands if c not in SKIP)
    # a placeholder directory with a real case under it is a synopsis too
    assert _is_synopsis("sphdyn restart OUT/lozano2017_dropweight_5.0m --t-end 11ms")
    assert not _is_synopsis("sphdyn plot out/disc_impact --snapshots damage")
    assert set(SKIP) <= set(commands), "SKIP lists commands the documents no longer show"


@pytest.mark.parametrize("doc, number, text", toml_blocks(),
                         ids=[f"{d}-{k}" for d, k, _ in toml_blocks()])
def test_toml_block_checks_and_runs(doc, number, text, scratch):
    deck = tomllib.loads(text)
    if "run" not in deck:
        host = FRAGMENT_HOSTS.get((doc, number))
        assert host, (f"{doc}: TOML fragment #{number} has no host deck; add it to "
                      "FRAGMENT_HOSTS")
        with open(ROOT / host, "rb") as f:
            deck = _merge(tomllib.load(f), deck)
        if "photo" in text:
            _write_section_photo(scratch)
    path = scratch / f"{Path(doc).stem}-{number}.toml"
    path.write_text(tomli_w.dumps(deck))
    _check_and_run(path)


@pytest.mark.parametrize("doc, number, text", fenced_blocks("python"),
                         ids=[f"{d}-{k}" for d, k, _ in fenced_blocks("python")])
def test_python_block_runs(doc, number, text, scratch):
    """A Python snippet of the documents runs as a user would paste it (the
    mesostructure snippet once used ``x`` and ``dx`` without making them)."""
    exec(compile(text, f"{doc} python block #{number}", "exec"), {"__name__": "__main__"})


def test_documented_commands_run(scratch, capsys):
    ran = 0
    for doc in DOCS:
        for command in shell_commands(doc):
            if command in SKIP:
                continue
            assert command.startswith("sphdyn "), (
                f"{doc.name}: {command!r} is not a sphdyn command; run it or add it "
                "to SKIP with the reason")
            args = shortened(command)
            _prerequisites(args)
            code = main(args)
            assert code == 0, (f"{doc.name}: {command!r} exited {code}:\n"
                               f"{capsys.readouterr().err[-2000:]}")
            ran += 1
    assert ran >= 15


def test_package_summary_and_docstring_do_not_call_existing_parts_planned():
    """pyproject's description and the package docstring (shown by pip and
    help()) name the finite elements, rebar and blast that exist, not as
    "planned" (they did after all three were in)."""
    import sphdyn

    with open(ROOT / "pyproject.toml", "rb") as f:
        summary = tomllib.load(f)["project"]["description"]
    for text in (summary, sphdyn.__doc__):
        assert "planned" not in text.lower()
        for part in ("FEM" if text is summary else "finite elements", "rebar", "blast"):
            assert part in text, (part, text)


#: a repository path to a script, deck or page: ``examples/gurney.py``
_REPO_PATH = re.compile(
    r"\b((?:examples|tools|benchmarks|studies|tests|docs)/[\w./-]*\.(?:py|toml|md))\b")


def referenced_paths() -> list[tuple[str, str]]:
    """(file, path) of every script, deck or page path named in the example
    decks, README.md and docs/*.md (placeholders such as ``NAME`` left out)."""
    sources = [*sorted((ROOT / "examples").glob("*.toml")), *DOCS]
    return [(src.name, m.group(1)) for src in sources
            for m in _REPO_PATH.finditer(src.read_text(encoding="utf-8"))
            if not re.search(r"[A-Z]{2,}", m.group(1))]


def test_every_script_and_deck_named_in_the_decks_and_docs_exists():
    """The decks' comments and the docs point at files that exist (two decks
    once named examples/shock_tube.py and examples/gurney.py, which never
    did; both cases are run by examples/explosives_1d.py)."""
    found = referenced_paths()
    assert len({p for _, p in found if p.endswith(".py")}) >= 10
    missing = sorted({f"{src}: {path}" for src, path in found if not (ROOT / path).exists()})
    assert not missing, "\n".join(missing)


def test_readme_says_how_long_the_suite_takes_and_how_to_shorten_it():
    """README: the suite's duration and the quick options, each of which works
    with the test extras (the "slow" marker is registered, pytest-xdist is in
    the extras); the two setup commands stay as they are."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    # .ci/run, 2026-11-29 (stop 61): 38 min 24 s with three quick validation
    # cases; the fourth (lozano2017_static) adds about 10 minutes serial
    assert "about 50 minutes on 2 cores" in text
    assert '`pytest -m "not slow"`' in text and "`pytest -n 2`" in text
    with open(ROOT / "pyproject.toml", "rb") as f:
        project = tomllib.load(f)
    assert any(m.startswith("slow:") for m in project["tool"]["pytest"]["ini_options"]["markers"])
    assert any(d.startswith("pytest-xdist") for d in project["project"]["optional-dependencies"]["test"])
    blocks = [b for lang, _, b in [(m.group(1), 0, m.group(2)) for m in _FENCE.finditer(text)]
              if lang == "bash"]
    assert blocks[:2] == ["pip install . && sphdyn run examples/disc_impact.toml\n",
                          "pip install '.[test]' && pytest\n"]
