"""Planning an ensemble: seeds, the ``--vary`` grid and the samples.

:func:`plan_samples` turns a deck, a replicate count and ``--vary`` strings
into :class:`SampleSpec` s (plain, picklable data: everything a worker needs);
sample ``s`` of every grid point gets the run seed :func:`sample_seed` (base
seed, s), so the grid points share their random fields. Also the names of
the files of the output layout (see :mod:`sphdyn.ensemble`).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

#: A sample's record, written last and atomically (the "done" marker).
RESULT = "result.json"
#: The plan of the ensemble: deck, overrides, grid, seeds.
PLAN = "ensemble.json"


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


def validate_grid(deck: str | Path, grid, overrides=()) -> None:
    """Check every ``--vary`` value (and the ``--set`` overrides) against the schema.

    Each value of each key is validated with the other keys at their first
    value, so a misspelt key or a value out of range is refused before
    anything starts; raises :class:`~sphdyn.deck.DeckError` with one line per
    problem, each naming the ``--vary KEY=VALUE`` it came from.
    """
    from ..deck import DeckError, load_deck

    first = {k: v[0] for k, v in grid}
    trials = [(k, v) for k, values in grid for v in values] or [(None, None)]
    found = []  # (trial, problem) in order
    for key, value in trials:
        items = [f"{k}={v}" for k, v in first.items() if k != key]
        items += [f"{key}={value}"] if key is not None else []
        try:
            load_deck(deck, [*overrides, *items])
        except DeckError as exc:
            found += [((key, value), line) for line in exc.problems]
    problems = []
    for trial, line in found:  # a problem of every trial is the deck's own
        everywhere = all((t, line) in found for t in trials)
        keys = [k for k in first if line.startswith(f"{k}:")]  # the key itself is wrong
        if not everywhere and trial[0] is not None:
            text = f"--vary {trial[0]}={trial[1]}: {line}"
        else:
            text = f"--vary {keys[0]}: {line}" if keys else line
        if text not in problems:
            problems.append(text)
    if problems:
        raise DeckError(problems)


def _base_seed(deck: Path, overrides, grid) -> int:
    """``run.seed`` of the deck with ``overrides`` and the first grid point.

    The deck may need a ``--vary`` key to be valid (e.g. a parameter of a
    mass law given only by ``--vary``), so the first grid point is applied;
    if that is still invalid, the seed is read from the TOML (default 0) and
    the invalid samples are recorded when they run.
    """
    import tomllib

    from ..deck import DeckError, load_deck

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
        validate_grid(deck, grid, overrides)
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
