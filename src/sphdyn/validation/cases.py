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
from dataclasses import dataclass, replace
from functools import partial
from pathlib import Path
from typing import Callable

import numpy as np

from ..geometry.mesh_blocks import graded_nodes
from . import data
from .figures import deflection_figure, load_figure, section_figure
from .measures import (depth_of_penetration, largest_deflection, lost_face_diameter,
                       peak_load)


@dataclass(frozen=True)
class Reference:
    """One compared quantity: the experiment's value and scatter, or an
    estimate's value (``kind = "estimate"``, no scatter), in ``unit``;
    ``peer`` another code's answer on the same test where its authors
    published one (a row of a data file, never data: the table shows it
    beside sphdyn's), ``peer_label`` which code and model."""

    key: str
    label: str
    unit: str
    value: float
    low: float
    high: float
    source: str
    kind: str = "measured"
    scatter: str = ""
    peer: float | None = None
    peer_label: str = ""


@dataclass(frozen=True)
class Case:
    """A validation case (module docstring)."""

    name: str
    title: str
    deck: str
    quick: tuple[str, ...]
    references: Callable[[Path], list[Reference]]
    measure: Callable[[Path, dict], dict[str, float]]
    overrides: tuple[str, ...] = ()
    mesh: str = ""
    figure: Callable[..., None] = section_figure


#: display unit -> factor from SI
UNITS = {"mm": 1e3, "ms": 1e3, "m/s": 1.0, "kN": 1e-3, "J": 1.0}


def resolved_deck(run: Path) -> dict:
    """The run's resolved deck (SI units, every default filled in)."""
    return tomllib.loads((Path(run) / "deck.resolved.toml").read_text(encoding="utf-8"))


def _named(items: list[dict], name: str) -> dict:
    return next(i for i in items if i["name"] == name)


def block_spacing(deck: dict, mesh: str) -> tuple[float, float, float]:
    """Element sizes (hx, hy, hz) [m] of a ``[[mesh]]`` block: the smallest on
    each axis of a graded one (:func:`~sphdyn.geometry.mesh_blocks.graded_nodes`)."""
    b = _named(deck["mesh"], mesh)["block"]
    grading = b.get("grading") or [{"ratio": 1.0, "smallest": "lo"}] * len(b["divisions"])
    return tuple(float(np.diff(graded_nodes(lo, hi, n, g["ratio"], g.get("smallest", "lo")))
                       .min())
                 for lo, hi, n, g in zip(b["lo"], b["hi"], b["divisions"], grading))


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


# --------------------------------------------------------------------------
# Lozano Mendoza & Makdesi Aphram (2017): drop weight on small RC beams
# --------------------------------------------------------------------------

LOZANO = "lozano2017_dropweight_rc_beams.csv"
LOZANO_HISTORY = "lozano2017_dropweight_deflection_history.csv"
LOZANO_PREDICTIONS = "lozano2017_reference_predictions.csv"
#: the authors' LS-DYNA model shown beside sphdyn: MAT_273 (CDPM2) on 5 mm
#: hexahedra, their base model (tetrahedra needed a changed softening
#: parameter and stopped early at 5.0 m)
LOZANO_PEER = "LS-DYNA hexa 5 mm"


def _with_peer(ref: Reference, data_dir: Path, drop_height: str, quantity: str) -> Reference:
    """``ref`` with the authors' LS-DYNA answer for ``quantity`` at
    ``drop_height`` (blank: the static test) from LOZANO_PREDICTIONS."""
    row = data.read(data_dir / LOZANO_PREDICTIONS).row(
        model=LOZANO_PEER, drop_height_m=drop_height, quantity=quantity)
    return replace(ref, peer=data.number(row, "value"),
                   peer_label=f"the authors' LS-DYNA, CDPM2 on 5 mm hexahedra ({row['where']})")


def _series_rows(data_dir: Path, series: str) -> list[dict[str, str]]:
    return [r for r in data.read(data_dir / LOZANO).rows if r["series"] == series]


def _series_reference(rows: list[dict[str, str]], series: str, tables: str, key: str,
                      label: str, unit: str, column: str) -> Reference:
    """The mean of ``column`` over a series' beams, their range as the scatter."""
    v = [data.number(r, column) for r in rows]
    return Reference(key, label, unit, sum(v) / len(v), min(v), max(v),
                     f"{LOZANO}: mean of the {len(rows)} beams of Series {series} ({tables})",
                     scatter=f"beams {', '.join(r['beam_id'] for r in rows)}")


def _lozano_references(series: str, drop_height: str):
    def references(data_dir: Path) -> list[Reference]:
        rows = _series_rows(data_dir, series)
        return [_with_peer(_series_reference(rows, series, "Tables 9.1/9.2, 9.5/9.6", key,
                                             label, unit, column), data_dir, drop_height, key)
                for key, label, unit, column in (
                    ("umax", "largest mid-span deflection", "mm", "umax_mm"),
                    ("t_umax", "time of the largest deflection", "ms", "t_umax_ms"))]
    return references


def _lozano_measure(run: Path, deck: dict) -> dict[str, float]:
    u, t = largest_deflection(run, "midspan", "rod")
    return {"umax": u, "t_umax": t}


#: the load cell's averaging window of the static test: 1 ms, a sixth of the
#: beam's first bending period (6 ms: uncracked, f = pi/(2 L^2) sqrt(E I/m)
#: = 170 Hz for L = 1 m, E = 33.9 GPa, I = b h^3/12, m = 24 kg/m), long
#: against the contact's spikes (tens of steps) and short against the test
#: (tens of ms)
STATIC_WINDOW = 1e-3


def _lozano_static_references(data_dir: Path) -> list[Reference]:
    ref = _series_reference(_series_rows(data_dir, "3"), "3", "Table 9.7", "peak_load",
                            "peak load of the static test", "kN", "F_static_max_kN")
    return [_with_peer(ref, data_dir, "", "F_static_max")]


def _lozano_static_measure(run: Path, deck: dict) -> dict[str, float]:
    peak, _ = peak_load(run, "rod", "midspan", STATIC_WINDOW)
    return {"peak_load": peak}


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
    # the quick mesh's elements are 4 mm instead of 2.5: the crushed-element
    # rule keeps its fraction of the initial step (60 ns x 4 / 2.5)
    quick=("mesh.block.block.divisions=[40,40,25]", "body.fragment.dx=0.0013333333333333333",
           "material.concrete.erosion.min_time_step=9.6e-08", "run.t_end=4e-05"),
    references=_leppanen_references,
    measure=_leppanen_measure,
    mesh="block",
))


# --------------------------------------------------------------------------
# Forrestal et al. (1994): an ogive-nose steel projectile into plain concrete
# --------------------------------------------------------------------------

FORRESTAL = "forrestal1994_ogive_penetration.csv"


def _forrestal_references(data_dir: Path) -> list[Reference]:
    row = data.read(data_dir / FORRESTAL).row(v_s_m_per_s="277")
    dop = data.number(row, "dop_m") * UNITS["mm"]  # tabulated in metres
    return [Reference("dop", "depth of penetration", "mm", dop, dop, dop,
                      f"{FORRESTAL}: the 277 m/s shot (Leppanen 2002, Table 6.2, p. 55)",
                      scatter="one shot")]


def _forrestal_measure(run: Path, deck: dict) -> dict[str, float]:
    dx = _named(deck["body"], "projectile")["dx"]
    return {"dop": depth_of_penetration(run, "projectile", face=0.0, dx=dx)}


register(Case(
    name="forrestal1994_ogive",
    title="Ogive-nose steel projectile (0.906 kg, 26.9 mm) at 277 m/s into plain "
          "concrete (Forrestal et al. 1994)",
    deck="validation/cases/forrestal1994_ogive.toml",
    # the quick target's elements are 15 mm (6 mm in the full one), the
    # projectile's particles 6.7 mm (4 across; 2.69 mm, 10 across); the
    # crushed-element rule keeps its fraction of the initial step (150 ns x
    # 15 / 6)
    quick=("mesh.target.block.divisions=[20,20,24]", "body.projectile.dx=0.006725",
           "material.concrete.erosion.min_time_step=3.75e-07"),
    references=_forrestal_references,
    measure=_forrestal_measure,
    mesh="target",
))


_BARS = tuple(f"mesh.bar_{b}.line.element_length=0.01" for b in ("b1", "b2", "t1", "t2"))
#: the drop-weight beams' variants: (name's infix, the concrete's words in the
#: title, deck, quick overrides). The concrete as particles; or meshed (hex8,
#: 5 mm as the authors' LS-DYNA model, the bars embedded): what MAT_159 does
#: without the particles. The meshed quick version's elements are 10 mm, its
#: contact thickness factor halved to keep the meshes' 2.5 mm thickness, so
#: the rod and the supports stand where they are.
_LOZANO_VARIANTS = (
    ("", "", "validation/cases/lozano2017_dropweight.toml", ("body.beam.dx=0.01", *_BARS)),
    ("fem_", " of hexahedra", "validation/cases/lozano2017_dropweight_fem.toml",
     ("mesh.beam.block.divisions=[118,10,10]",
      *(f"mesh.{m}.contact.thickness_factor=0.25"
        for m in ("rod", "support_left", "support_right")), *_BARS)),
)
# run to 9 and 11 ms: past the measured maxima (at most 6.4 and 8.2 ms after
# the impact, which comes 0.3 ms after the start)
for _infix, _words, _deck, _quick in _LOZANO_VARIANTS:
    for _series, _height, _v, _t in (("1", "2.5", None, 0.009), ("2", "5.0", 9.8, 0.011)):
        register(Case(
            name=f"lozano2017_dropweight_{_infix}{_height}m",
            title=(f"10.1 kg drop weight from {_height} m on a 100 x 100 mm RC beam"
                   f"{_words} (Lozano Mendoza & Makdesi Aphram 2017)"),
            deck=_deck,
            overrides=(f"run.t_end={_t!r}",
                       *(() if _v is None else (f"mesh.rod.velocity.2={-_v!r}",))),
            quick=_quick,
            references=_lozano_references(_series, _height),
            measure=_lozano_measure,
            figure=partial(deflection_figure, history=LOZANO_HISTORY, drop_height=_height),
        ))


register(Case(
    name="lozano2017_static",
    title=("Static three-point test of a 100 x 100 mm RC beam "
           "(Lozano Mendoza & Makdesi Aphram 2017, Series 3)"),
    deck="validation/cases/lozano2017_static.toml",
    # the quick version also presses twice as fast, to 8 mm in 11 ms (the
    # load's plateau starts at 5-6 mm; at dx 10 mm the peak is 12.1 kN at
    # 0.5 m/s to 19 mm, 12.3 kN at 1 m/s to 8 mm and 12.4 to 12 mm)
    quick=("body.beam.dx=0.01", *_BARS, "boundary.0.velocity.2=-1.0", "run.t_end=0.011"),
    references=_lozano_static_references,
    measure=_lozano_static_measure,
    figure=partial(load_figure, loader="rod", midspan="midspan", window=STATIC_WINDOW),
))
