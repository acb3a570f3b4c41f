"""The validation cases: a deck, the measured numbers it is compared with, and
how each number is read off the run.

A :class:`Case` names its deck in ``validation/cases/`` and the overrides of
its quick version (``--quick``: coarser, for the test suite and a first
look), reads its reference values from ``validation/data/`` (never typed
here: a reference is a row of a data file, or a named estimate computed from
the deck's inputs), and measures the same quantities on the finished run.
Values are SI inside; each :class:`Reference` carries the unit the table
shows.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from . import data
from .measures import depth_of_penetration, lost_face_diameter


@dataclass(frozen=True)
class Reference:
    """One compared quantity: the experiment's value and scatter, or an
    estimate's value (``kind = "estimate"``, no scatter), in ``unit``."""

    key: str
    label: str
    unit: str
    value: float
    low: float
    high: float
    source: str
    kind: str = "measured"
    scatter: str = ""


@dataclass(frozen=True)
class Case:
    """A validation case (module docstring)."""

    name: str
    title: str
    deck: str
    quick: tuple[str, ...]
    references: Callable[[Path], list[Reference]]
    measure: Callable[[Path, dict], dict[str, float]]
    mesh: str = ""
    note: str = ""


#: display unit -> factor from SI
UNITS = {"mm": 1e3, "m/s": 1.0, "kN": 1e-3, "J": 1.0}


def resolved_deck(run: Path) -> dict:
    """The run's resolved deck (SI units, every default filled in)."""
    return tomllib.loads((Path(run) / "deck.resolved.toml").read_text(encoding="utf-8"))


def _named(items: list[dict], name: str) -> dict:
    return next(i for i in items if i["name"] == name)


def block_spacing(deck: dict, mesh: str) -> tuple[float, float, float]:
    """Element sizes (hx, hy, hz) [m] of a ``[[mesh]]`` block."""
    b = _named(deck["mesh"], mesh)["block"]
    return tuple((hi - lo) / n for lo, hi, n in zip(b["lo"], b["hi"], b["divisions"]))


# --------------------------------------------------------------------------
# Leppanen (2004): a steel sphere into a thick plain-concrete block
# --------------------------------------------------------------------------

LEPPANEN = "leppanen2004_fragment_impacts.csv"


def _leppanen_references(data_dir: Path) -> list[Reference]:
    f = data.read(data_dir / LEPPANEN)
    shot, series = f.row(shot="fig8_shot"), f.row(series="single", shot="range")
    where = f"{LEPPANEN}: the Fig. 8 shot (Paper IV p. 10)"
    scatter = (f"eight shots at {series['v_s_min_m_per_s']}-{series['v_s_max_m_per_s']} "
               "m/s (Paper IV pp. 9-10)")
    return [
        Reference("dop", "depth of penetration", "mm", data.number(shot, "dop_max_mm"),
                  data.number(series, "dop_min_mm"), data.number(series, "dop_max_mm"),
                  where, scatter=scatter),
        Reference("crater", "crater diameter", "mm", data.number(shot, "crater_max_mm"),
                  data.number(series, "crater_min_mm"),
                  data.number(series, "crater_max_mm"), where, scatter=scatter),
    ]


def _leppanen_measure(run: Path, deck: dict) -> dict[str, float]:
    hx, _, _ = block_spacing(deck, "block")
    dx = _named(deck["body"], "fragment")["dx"]
    return {"dop": depth_of_penetration(run, "fragment", face=0.0, dx=dx),
            "crater": lost_face_diameter(run, "block", face=0.0, normal=1.0, h=hx)}


CASES: dict[str, Case] = {}


def register(case: Case) -> Case:
    """Add ``case`` to :data:`CASES` (``ValueError`` if its name is taken)."""
    if case.name in CASES:
        raise ValueError(f"validation case {case.name!r} registered twice")
    CASES[case.name] = case
    return case


register(Case(
    name="leppanen2004_fragment",
    title="Steel sphere (r = 4 mm) at 1879 m/s into plain concrete (Leppänen 2004)",
    deck="validation/cases/leppanen2004_fragment.toml",
    quick=("mesh.block.block.divisions=[40,40,25]", "body.fragment.dx=0.0013333333333333333"),
    references=_leppanen_references,
    measure=_leppanen_measure,
    mesh="block",
))
