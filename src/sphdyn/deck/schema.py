"""The deck schema: frozen pydantic models holding SI floats.

This module is the one place where deck keys, their defaults and their
allowed values are defined.  Quantities accept a plain SI number or a unit
string (see :mod:`sphdyn.deck.units`); vectors are stored as 3-tuples even
in 2D (``z = 0``).  Every validator raises :func:`problem` errors, whose
message reads ``<what is wrong>. Fix: <what to write>``; :func:`explain`
turns a pydantic ``ValidationError`` into one such line per problem,
prefixed with the dotted path of the offending key.

Checks that need the whole deck (the dimension, names of other tables) read
a :class:`_Scope` that :class:`Deck` publishes while it validates.
"""

import difflib
import math
import types
from contextvars import ContextVar
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Any, Literal, Optional, Union, get_args, get_origin

from pydantic import (AfterValidator, BaseModel, BeforeValidator, ConfigDict,
                      Field, Strict, StrictBool, StrictStr,
                      ValidationError, ValidationInfo, field_validator,
                      model_validator)
from pydantic_core import PydanticCustomError

from .units import (DENSITY, LENGTH, PRESSURE, TIME, VELOCITY, Dimension,
                    QuantityError, to_si)

#: Names accepted in ``output.fields``.  The solver may append the names of
#: further per-particle fields before decks are loaded.
ALLOWED_FIELDS: list[str] = [
    "velocity", "displacement", "stress", "pressure", "von_mises", "density",
    "mass", "smoothing_length", "damage", "internal_energy", "plastic_strain",
    "bc", "body", "material", "swegle", "phase", "variation",
]

DEFAULT_FIELDS = ("velocity", "displacement", "stress", "pressure", "von_mises",
                  "density", "mass", "smoothing_length", "damage",
                  "internal_energy")


# --------------------------------------------------------------------------
# Messages
# --------------------------------------------------------------------------

def problem(what: str, fix: str) -> PydanticCustomError:
    """Return a validation error whose message is ``what. Fix: fix``."""
    return PydanticCustomError("deck", "{what}. Fix: {fix}",
                               {"what": what, "fix": fix})


def show(value: Any) -> str:
    """Write a deck value roughly as it appears in TOML, for messages."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f"'{value}'"
    if isinstance(value, dict):
        return "a table"
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _num(x: float) -> str:
    return f"{x:g}"


def _vec(values) -> str:
    return "[" + ", ".join(_num(v) for v in values) + "]"


def suggest(word: str, choices: list[str], advice: str) -> str:
    """Prefix ``advice`` with "did you mean ...?" if a choice is close."""
    near = difflib.get_close_matches(word, choices, n=1, cutoff=0.6)
    near = near or [c for c in choices if len(word) >= 3 and c.startswith(word)]
    return f"did you mean '{near[0]}'? Otherwise {advice}" if near else advice


# --------------------------------------------------------------------------
# Deck-wide context
# --------------------------------------------------------------------------

@dataclass(frozen=True)
class _Scope:
    """What field validators may know about the deck being validated."""

    dimension: Optional[int] = None
    names: dict[str, list[str]] = field(default_factory=dict)


_SCOPE: ContextVar[Optional[_Scope]] = ContextVar("sphdyn_deck_scope",
                                                  default=None)
_NAMED_SECTIONS = ("material", "body", "set", "wall")


def _get(obj: Any, key: str) -> Any:
    """Read ``key`` from a raw table (dict) or an already built model."""
    if isinstance(obj, dict):
        return obj.get(key)
    return getattr(obj, key, None)


def _scope_of(data: Any) -> _Scope:
    """Collect the dimension and the table names from raw deck data."""
    dim = _get(_get(data, "run"), "dimension")
    if isinstance(dim, bool) or dim not in (2, 3):
        dim = None
    names = {}
    for section in _NAMED_SECTIONS:
        items = _get(data, section)
        items = items if isinstance(items, (list, tuple)) else []
        names[section] = [n for n in (_get(t, "name") for t in items)
                          if isinstance(n, str)]
    return _Scope(None if dim is None else int(dim), names)


def _dimension() -> Optional[int]:
    scope = _SCOPE.get()
    return scope.dimension if scope else None


# --------------------------------------------------------------------------
# Value types (the marker classes are also read by docgen)
# --------------------------------------------------------------------------

@dataclass(frozen=True)
class Quantity:
    """Before-validator converting a number or unit string to SI."""

    dim: Dimension

    def __call__(self, value: Any) -> float:
        try:
            return to_si(value, self.dim)
        except QuantityError as exc:
            raise problem(exc.what, exc.fix) from None


@dataclass(frozen=True)
class Bounds:
    """After-validator checking that a number lies in an interval.

    ``lo``/``hi`` of None mean unbounded; ``noun`` names the value in the
    advice ("give a Poisson ratio below 0.5").
    """

    lo: Optional[float] = None
    hi: Optional[float] = None
    lo_open: bool = False
    hi_open: bool = False
    noun: str = "value"

    def interval(self) -> str:
        """Return the interval in mathematical notation, e.g. ``(0, 1]``."""
        left = "(" if self.lo is None or self.lo_open else "["
        right = ")" if self.hi is None or self.hi_open else "]"
        lo = "-inf" if self.lo is None else _num(self.lo)
        hi = "inf" if self.hi is None else _num(self.hi)
        return f"{left}{lo}, {hi}{right}"

    def __call__(self, value: float) -> float:
        if self.lo is not None and (value < self.lo
                                    or (self.lo_open and value == self.lo)):
            side = "above" if self.lo_open else "of at least"
            limit = self.lo
        elif self.hi is not None and (value > self.hi
                                      or (self.hi_open and value == self.hi)):
            side = "below" if self.hi_open else "of at most"
            limit = self.hi
        else:
            return value
        raise problem(f"{show(value)} is out of range {self.interval()}",
                      f"give a {self.noun} {side} {_num(limit)}")


@dataclass(frozen=True)
class Reference:
    """After-validator: the value must be the name of a ``[[section]]``."""

    section: str

    def __call__(self, name: str) -> str:
        scope = _SCOPE.get()
        if scope is None:
            return name
        known = list(dict.fromkeys(scope.names.get(self.section, [])))
        if name in known:
            return name
        if not known:
            fix = f"add a [[{self.section}]] table with name = \"{name}\""
        else:
            fix = suggest(name, known, f"use one of the {self.section} "
                                       f"names: {', '.join(known)}")
        raise problem(f"there is no {self.section} named '{name}'", fix)


@dataclass(frozen=True)
class UniqueName:
    """After-validator: a non-empty name, unique among its ``[[section]]``."""

    section: str

    def __call__(self, name: str) -> str:
        if not name.strip():
            raise problem("the name is empty",
                          f"give each [[{self.section}]] a non-empty name")
        scope = _SCOPE.get()
        count = scope.names.get(self.section, []).count(name) if scope else 1
        if count > 1:
            raise problem(
                f"the name '{name}' is used by {count} [[{self.section}]] tables",
                f"give each [[{self.section}]] a different name")
        return name


@dataclass(frozen=True)
class Vector:
    """Before-validator: 3 entries, or 2 entries padded with ``z = 0``.

    Two entries are refused only when the deck is known to be 3D.
    """

    def __call__(self, value: Any) -> Any:
        dim = _dimension()
        fix = "give 3 entries [x, y, z]" + (
            "" if dim == 3 else " (or [x, y] in a 2D deck)")
        if not isinstance(value, (list, tuple)):
            raise problem(f"{show(value)} is not a vector", fix)
        if len(value) == 2 and dim != 3:
            return (*value, 0.0)
        if len(value) != 3:
            raise problem(f"the vector has {len(value)} entries", fix)
        return value


@dataclass(frozen=True)
class NonEmpty:
    """Before-validator: a list of tables with at least one entry.

    (A ``min_length`` constraint would also fire when every entry is
    invalid, adding a misleading problem.)
    """

    section: str

    def __call__(self, value: Any) -> Any:
        if isinstance(value, (list, tuple)) and not value:
            raise problem(f"there is no [[{self.section}]] table",
                          f"add at least one [[{self.section}]] table")
        return value


def _planar(vec: tuple[float, float, float]) -> tuple[float, float, float]:
    """After-validator: in a 2D deck the z-component must be zero."""
    if _dimension() == 2 and vec[2] != 0.0:
        raise problem(f"the z-component is {_num(vec[2])} but the deck is 2D "
                      "(run.dimension = 2)",
                      "set z to 0 or give only [x, y]")
    return vec


def _unit_vector(vec: tuple[float, float, float]) -> tuple[float, float, float]:
    """After-validator: a non-zero direction, scaled to unit length."""
    norm = math.sqrt(sum(c * c for c in vec))
    if norm == 0.0:
        raise problem("the direction is the zero vector",
                      "give a non-zero vector such as [0, 1, 0]")
    if abs(norm - 1.0) <= 1e-12:  # keep already normalised input unchanged
        return vec
    return tuple(c / norm for c in vec)


def _existing_file(value: Any, info: ValidationInfo) -> Path:
    """Before-validator: a path to an existing file, relative to the deck."""
    context = info.context or {}
    base = Path(context.get("base_dir", "."))
    if not isinstance(value, (str, Path)):
        raise problem(f"{show(value)} is not a file path",
                      "give a path in quotes, e.g. \"mesh/part.vtu\"")
    path = Path(value).expanduser()
    path = path if path.is_absolute() else base / path
    if not path.is_file():
        raise problem(f"the file '{value}' does not exist (looked for {path})",
                      "give the path of an existing file, absolute or relative "
                      "to the folder of the deck")
    return path.resolve()


def real(noun: str = "value", **bounds: Any) -> Any:
    """A float (ints accepted) with optional bounds, e.g. ``real(lo=0)``."""
    checks = [AfterValidator(Bounds(noun=noun, **bounds))] if bounds else []
    return Annotated[float, Strict(), *checks]


def integer(noun: str = "value", **bounds: Any) -> Any:
    """A strict integer with optional bounds."""
    checks = [AfterValidator(Bounds(noun=noun, **bounds))] if bounds else []
    return Annotated[int, Strict(), *checks]


def quantity(dim: Dimension, noun: Optional[str] = None, **bounds: Any) -> Any:
    """A physical quantity of dimension ``dim`` stored as an SI float."""
    checks = ([AfterValidator(Bounds(noun=noun or dim.name, **bounds))]
              if bounds else [])
    return Annotated[float, BeforeValidator(Quantity(dim)), *checks]


def vector(element: Any, planar: bool = True) -> Any:
    """A 3-vector of ``element``; 2 entries allowed in 2D.

    With ``planar`` the z-component must be 0 in 2D decks.
    """
    checks = [AfterValidator(_planar)] if planar else []
    return Annotated[tuple[element, element, element],
                     BeforeValidator(Vector()), *checks]


def name_of(section: str) -> Any:
    """The ``name`` of a ``[[section]]`` table (unique, non-empty)."""
    return Annotated[str, Strict(), AfterValidator(UniqueName(section))]


def reference_to(section: str) -> Any:
    """The name of an existing ``[[section]]`` table."""
    return Annotated[str, Strict(), AfterValidator(Reference(section))]


Position = vector(quantity(LENGTH))
#: A point whose z may be non-zero in 2D (corners of selection boxes).
Corner = vector(quantity(LENGTH), planar=False)
VelocityVector = vector(quantity(VELOCITY))
Direction = Annotated[vector(real()), AfterValidator(_unit_vector)]
PositiveLength = quantity(LENGTH, lo=0, lo_open=True)
PositivePressure = quantity(PRESSURE, lo=0, lo_open=True)
Axis = Literal["x", "y", "z"]

#: A path to an existing file; relative paths are taken from the deck's
#: folder (validation context key ``base_dir``), stored absolute.
ExistingFile = Annotated[Path, BeforeValidator(_existing_file)]


# --------------------------------------------------------------------------
# Models
# --------------------------------------------------------------------------

class Section(BaseModel):
    """Base of all deck tables: frozen, unknown keys rejected."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


class Run(Section):
    """[run]: what is simulated and for how long."""

    title: StrictStr = Field("", description="Free text naming the run; "
                             "copied into the outputs.")
    dimension: Literal[2, 3] = Field(
        description="2 = plane strain, quantities per unit depth (masses in "
                    "kg/m); 3 = three-dimensional.")
    t_end: quantity(TIME, "end time", lo=0, lo_open=True) = Field(
        description="Simulated end time.")
    seed: integer("seed", lo=0) = Field(
        0, description="Seed of the random number generator (lattice "
                       "jitter, random material properties).")


class Viscosity(Section):
    """[sph.viscosity]: Monaghan artificial viscosity."""

    alpha: real("viscosity coefficient", lo=0) = Field(
        1.0, description="Linear (bulk) coefficient alpha.")
    beta: real("viscosity coefficient", lo=0) = Field(
        2.0, description="Quadratic (von Neumann-Richtmyer) coefficient beta.")


class SmoothingLength(Section):
    """[sph.smoothing_length]: evolution of h."""

    mode: Literal["constant", "benz"] = Field(
        "constant", description="constant: h = h0; benz: dh/dt = h div(v)/d "
                                "(Benz 1989), d = dimension.")
    min_factor: real("factor", lo=0, hi=1, lo_open=True) = Field(
        0.5, description="Lower bound on h as a fraction of h0.")
    max_factor: real("factor", lo=1) = Field(
        2.0, description="Upper bound on h as a multiple of h0.")


class Neighbours(Section):
    """[sph.neighbours]: Verlet neighbour lists."""

    skin_factor: real("skin factor", lo=0) = Field(
        0.25, description="Verlet skin as a fraction of the initial support "
                          "radius; lists are rebuilt when a particle has "
                          "moved half the skin.")


class ArtificialStress(Section):
    """[sph.artificial_stress]: Monaghan (2000) artificial stress."""

    epsilon: real("artificial-stress factor", lo=0) = Field(
        0.0, description="epsilon: the repulsive stress is -epsilon times the "
                         "tensile principal stresses (0 = off; Gray et al. "
                         "2001 use 0.3). See docs/tensile-instability.md.")
    n: real("artificial-stress exponent", lo=0, lo_open=True) = Field(
        4.0, description="Exponent n of f = W(r)/W(dx) (Gray et al. 2001 "
                         "use 4).")


class Sph(Section):
    """[sph]: discretisation."""

    formulation: Literal["updated_lagrangian", "total_lagrangian"] = Field(
        "updated_lagrangian", description="Kernel formulation of every body "
        "that does not set its own: updated_lagrangian is the thesis's "
        "'Eulerian kernel' (neighbours and kernel gradients from current "
        "positions); total_lagrangian fixes neighbours and corrected kernel "
        "gradients in the initial configuration (no tensile instability; "
        "separate bodies then interact only through [contact]). See "
        "docs/tensile-instability.md.")
    hourglass: real("hourglass coefficient", lo=0) = Field(
        10.0, description="Ganzenmueller (2015) hourglass coefficient alpha "
                          "of total-Lagrangian bodies (0 = off; 10-50 "
                          "recommended). Unused by updated-Lagrangian bodies.")
    reference_update_every: integer("step count", lo=0) = Field(
        0, description="Total-Lagrangian bodies: make the current configuration "
                       "the new reference every this many steps (0 = never; "
                       "for large deformations; costs one neighbour build).")
    kernel: Literal["cubic_spline", "quintic_spline", "wendland_c2",
                    "wendland_c4", "gaussian", "quadratic"] = Field(
        "cubic_spline", description="Smoothing kernel.")
    h_factor: real("smoothing-length factor", lo=0, lo_open=True) = Field(
        1.2, description="Initial smoothing length h0 = h_factor * dx of the "
                         "body.")
    support_scale: real("support scale", lo=0, lo_open=True) = Field(
        1.0, description="kappa: the kernel is evaluated with kappa*h, so the "
                         "support radius is q_max * kappa * h.")
    correction: StrictBool = Field(
        False, description="Randles-Libersky renormalisation of kernel "
                           "gradients.")
    xsph: real("XSPH factor", lo=0, hi=1) = Field(
        0.0, description="XSPH velocity smoothing factor epsilon "
                         "(0 = off).")
    viscosity: Viscosity = Field(default_factory=Viscosity,
                                 description="Artificial viscosity.")
    smoothing_length: SmoothingLength = Field(
        default_factory=SmoothingLength,
        description="Evolution of the smoothing length.")
    neighbours: Neighbours = Field(default_factory=Neighbours,
                                   description="Neighbour search.")
    artificial_stress: ArtificialStress = Field(
        default_factory=ArtificialStress,
        description="Artificial stress against the tensile instability.")


class Contact(Section):
    """[contact]: penalty contact between particles of different bodies."""

    enabled: Optional[StrictBool] = Field(
        None, description="Particle-particle contact between bodies; default: "
        "on when the model has two or more bodies and one of them is "
        "total-Lagrangian (those see no other body through the SPH sums).")
    distance_factor: real("contact distance factor", lo=0, lo_open=True) = Field(
        1.0, description="Particles of different bodies touch below "
        "distance_factor * (s_i + s_j)/2, s = initial particle size V0^(1/dim).")
    alpha: real("penalty factor", lo=0, lo_open=True) = Field(
        1.0, description="Penalty factor of the spring stiffness "
        "k = alpha * K * s^(dim-2) (K the pair's mean bulk modulus).")


class Time(Section):
    """[time]: explicit time stepping."""

    cfl: real("CFL number", lo=0, hi=1, lo_open=True) = Field(
        0.3, description="Courant number: dt = cfl * min(h / (c + |v|)).")
    dt_max: Optional[quantity(TIME, "time step", lo=0, lo_open=True)] = Field(
        None, description="Upper bound on the time step (absent: no bound).")
    collapse_ratio: real("ratio", lo=0, hi=1, lo_open=True, hi_open=True) = \
        Field(1e-4, description="The run stops when dt < collapse_ratio * "
                                "initial dt.")


class Domain(Section):
    """[domain]: guard box; a particle leaving it stops the run."""

    lo: Optional[Position] = Field(
        None, description="Lower corner (absent: from the bodies and margin).")
    hi: Optional[Position] = Field(
        None, description="Upper corner (absent: from the bodies and margin).")
    margin: real("margin", lo=0) = Field(
        1.0, description="For an absent corner: the initial bounding box of "
                         "the bodies expanded on each side by margin times its "
                         "largest side (the same distance in every direction).")

    @field_validator("hi")
    @classmethod
    def _above_lo(cls, hi, info: ValidationInfo):
        _check_corners(info.data.get("lo"), hi, "lo")
        return hi


def _check_corners(lo, hi, lo_key: str) -> None:
    """Raise unless ``hi > lo`` in the first ``dimension`` components."""
    if lo is None or hi is None:
        return
    n = _dimension()
    if n is None:  # dimension unknown: a flat box is taken as 2D
        n = 2 if lo[2] == hi[2] == 0.0 else 3
    if any(h <= l for l, h in zip(lo[:n], hi[:n])):
        raise problem(
            f"hi = {_vec(hi[:n])} is not above {lo_key} = {_vec(lo[:n])} "
            "in every component",
            f"make each of the first {n} entries of hi greater than "
            f"those of {lo_key}")


# Materials ---------------------------------------------------------------

class Variation(Section):
    """[material.variation]: random scatter of one parameter of a material.

    Thesis sec. 7.2: CSCM as the base material with the strength varied in
    the ITZ. The parameter is multiplied by a random factor of mean 1 and
    coefficient of variation cov (lognormal or normal), drawn once per run
    (scope = "sample") or per particle (scope = "particle", independent or
    correlated over correlation_length); per-particle factors are grouped
    into equal-probability classes, each refitted as a whole material (so
    varying CSCM fc also varies the fitted moduli, surfaces and fracture
    energies). Seeded by run.seed and the material's index;
    docs/mesostructure.md.
    """

    parameter: str = Field(
        description="Name of the varied parameter of this material, e.g. "
                    "\"fc\" (CSCM) or \"yield_stress\" (j2); it must be given "
                    "in the material (not density: use [body.mass]).")
    cov: real("coefficient of variation", lo=0, hi=1) = Field(
        description="Coefficient of variation of the factor (0 = no scatter).")
    distribution: Literal["lognormal", "normal"] = Field(
        "lognormal", description="Law of the factor, mean 1: lognormal, or "
                                 "normal kept above 0.05.")
    scope: Literal["sample", "particle"] = Field(
        "particle", description="One factor per run (sample) or one per "
                                "particle.")
    correlation_length: quantity(LENGTH, "correlation length", lo=0) = Field(
        0.0, description="scope = particle: correlation length l of a Gaussian "
                         "random field, correlation exp(-(r/l)^2); 0 = "
                         "independent particles.")
    classes: integer("class count", lo=2, hi=256) = Field(
        16, description="scope = particle: number of equal-probability "
                        "parameter classes (material groups) the factors are "
                        "rounded to.")

    @model_validator(mode="after")
    def _scope_options(self):
        if self.scope == "sample" and self.correlation_length > 0.0:
            raise problem("correlation_length is given with scope = \"sample\"",
                          "remove correlation_length (one factor per run has no "
                          "spatial structure) or use scope = \"particle\"")
        return self


class _Varied(Section):
    """Check [material.variation] against the material's own parameters."""

    @model_validator(mode="after")
    def _varied_parameter(self):
        var = getattr(self, "variation", None)
        if var is None:
            return self
        fixed = {"name", "model", "density", "variation", "recovery"}
        numeric = [k for k, f in type(self).model_fields.items() if k not in fixed
                   and strip_optional(f.annotation) is float]
        if var.parameter not in numeric:
            raise problem(f"variation.parameter {var.parameter!r} is not a varied "
                          f"parameter of model {self.model!r}",
                          f"use one of {', '.join(numeric)}")
        if getattr(self, var.parameter) is None:
            raise problem(f"variation.parameter {var.parameter!r} is not given in "
                          "the material (its default is generated)",
                          f"give {var.parameter} explicitly to vary it")
        return self


class Elastic(_Varied):
    """[[material]] model = "elastic": isotropic linear elasticity.

    Give exactly one pair of elastic constants: E and nu, or K and G.
    """

    name: name_of("material") = Field(
        description="Name that bodies use to refer to the material.")
    model: Literal["elastic"] = Field(description="Constitutive model.")
    density: quantity(DENSITY, lo=0, lo_open=True) = Field(
        description="Initial mass density.")
    E: Optional[PositivePressure] = Field(
        None, description="Young's modulus (give with nu).")
    nu: Optional[real("Poisson ratio", lo=-1, hi=0.5, lo_open=True,
                      hi_open=True)] = Field(
        None, description="Poisson ratio (give with E).")
    K: Optional[PositivePressure] = Field(
        None, description="Bulk modulus (give with G).")
    G: Optional[PositivePressure] = Field(
        None, description="Shear modulus (give with K).")
    variation: Optional[Variation] = Field(
        None, description="Random scatter of one parameter ([material.variation]).")

    @model_validator(mode="after")
    def _one_pair(self):
        given = [k for k in ("E", "nu", "K", "G") if getattr(self, k) is not None]
        if set(given) in ({"E", "nu"}, {"K", "G"}):
            return self
        fix = "give either E and nu, or K and G"
        if not given:
            raise problem("no elastic constants are given", fix)
        if {"E", "nu"} & set(given) and {"K", "G"} & set(given):
            raise problem(f"{', '.join(given)} mix the two ways of giving "
                          "elastic constants", fix + ", not both")
        other = {"E": "nu", "nu": "E", "K": "G", "G": "K"}[given[0]]
        raise problem(f"{given[0]} is given without {other}",
                      f"add {other} ({fix})")

    def bulk_modulus(self) -> float:
        """Return the bulk modulus K [Pa]."""
        if self.K is not None:
            return self.K
        return self.E / (3.0 * (1.0 - 2.0 * self.nu))

    def shear_modulus(self) -> float:
        """Return the shear modulus G [Pa]."""
        if self.G is not None:
            return self.G
        return self.E / (2.0 * (1.0 + self.nu))


class J2(Elastic):
    """[[material]] model = "j2": von Mises plasticity, linear hardening.

    Elastic constants as for "elastic" (E and nu, or K and G).
    """

    model: Literal["j2"] = Field(description="Constitutive model.")
    yield_stress: PositivePressure = Field(
        description="Initial yield stress in uniaxial tension.")
    hardening_modulus: quantity(PRESSURE, "hardening modulus", lo=0) = Field(
        0.0, description="Plastic modulus H of linear isotropic hardening "
                         "(0 = perfect plasticity).")


def _cscm_override(noun: str, dim: Any = None, **bounds: Any) -> Any:
    """Optional CSCM override: a quantity (with ``dim``) or a plain SI number."""
    kind = quantity(dim, noun, **bounds) if dim is not None else real(noun, **bounds)
    return Optional[kind]


class Cscm(_Varied):
    """[[material]] model = "cscm": concrete, Continuous Surface Cap Model.

    Re-implementation of LS-DYNA *MAT_CSCM_CONCRETE (MAT_159, Murray 2007,
    FHWA-HRT-05-062); every parameter is generated from fc and
    aggregate_size (the "short form") unless given explicitly. Numbers
    without units are SI (pascals, metres, J/m^2, seconds); see
    docs/cscm.md for the equations and the parameter table.
    """

    name: name_of("material") = Field(
        description="Name that bodies use to refer to the material.")
    model: Literal["cscm"] = Field(description="Constitutive model.")
    density: quantity(DENSITY, lo=0, lo_open=True) = Field(
        description="Initial mass density (never generated).")
    fc: PositivePressure = Field(
        30e6, description="Unconfined compression strength f'c (LS-DYNA "
                          "FPC; defaults are fitted for 20-58 MPa).")
    aggregate_size: PositiveLength = Field(
        0.019, description="Maximum aggregate size (LS-DYNA DAGG); enters "
                           "the default fracture energies.")
    K: Optional[PositivePressure] = Field(
        None, description="Bulk modulus (default from fc, nu = 0.15).")
    G: Optional[PositivePressure] = Field(
        None, description="Shear modulus (default from fc, nu = 0.15).")
    alpha: _cscm_override("TXC constant", PRESSURE) = Field(
        None, description="TXC shear surface: constant term alpha.")
    theta: _cscm_override("TXC linear term") = Field(
        None, description="TXC shear surface: linear term theta [-].")
    lamda: _cscm_override("TXC exponential term", PRESSURE) = Field(
        None, description="TXC shear surface: exponential term lambda.")
    beta: _cscm_override("TXC exponent", lo=0) = Field(
        None, description="TXC shear surface: exponent beta [1/Pa].")
    alpha1: _cscm_override("Q1 constant") = Field(
        None, description="TOR/TXC ratio Q1: constant term [-].")
    theta1: _cscm_override("Q1 linear term") = Field(
        None, description="TOR/TXC ratio Q1: linear term [1/Pa].")
    lamda1: _cscm_override("Q1 exponential term") = Field(
        None, description="TOR/TXC ratio Q1: exponential term [-].")
    beta1: _cscm_override("Q1 exponent", lo=0) = Field(
        None, description="TOR/TXC ratio Q1: exponent [1/Pa].")
    alpha2: _cscm_override("Q2 constant") = Field(
        None, description="TXE/TXC ratio Q2: constant term [-].")
    theta2: _cscm_override("Q2 linear term") = Field(
        None, description="TXE/TXC ratio Q2: linear term [1/Pa].")
    lamda2: _cscm_override("Q2 exponential term") = Field(
        None, description="TXE/TXC ratio Q2: exponential term [-].")
    beta2: _cscm_override("Q2 exponent", lo=0) = Field(
        None, description="TXE/TXC ratio Q2: exponent [1/Pa].")
    R: _cscm_override("cap aspect ratio", lo=0, lo_open=True) = Field(
        None, description="Cap aspect ratio R [-].")
    X0: _cscm_override("cap location", PRESSURE, lo=0, lo_open=True) = Field(
        None, description="Initial cap location X0 (J1, compression positive).")
    W: _cscm_override("compaction", lo=0, lo_open=True) = Field(
        None, description="Maximum plastic volume compaction W [-].")
    D1: _cscm_override("compaction shape", lo=0, lo_open=True) = Field(
        None, description="Compaction law linear shape D1 [1/Pa].")
    D2: _cscm_override("compaction shape", lo=0) = Field(
        None, description="Compaction law quadratic shape D2 [1/Pa^2].")
    B: _cscm_override("softening shape", lo=0, lo_open=True) = Field(
        None, description="Ductile softening shape B [-] (default 100).")
    D: _cscm_override("softening shape", lo=0, lo_open=True) = Field(
        None, description="Brittle softening shape D [-] (default 0.1).")
    GFC: _cscm_override("fracture energy", lo=0, lo_open=True) = Field(
        None, description="Fracture energy in uniaxial compression [J/m^2] "
                          "(default 100 GFT).")
    GFT: _cscm_override("fracture energy", lo=0, lo_open=True) = Field(
        None, description="Fracture energy in uniaxial tension [J/m^2] "
                          "(default: CEB-type fit of fc and aggregate_size, "
                          "unconfirmed, see docs/cscm.md).")
    GFS: _cscm_override("fracture energy", lo=0, lo_open=True) = Field(
        None, description="Fracture energy in pure shear [J/m^2] (default GFT).")
    pwrc: _cscm_override("transition power", lo=0) = Field(
        None, description="Shear-to-compression transition power (default 5).")
    pwrt: _cscm_override("transition power", lo=0) = Field(
        None, description="Shear-to-tension transition power (default 1).")
    eta0c: _cscm_override("fluidity", lo=0) = Field(
        None, description="Compression fluidity eta0c [s^(1-nc)].")
    nc: _cscm_override("rate exponent", lo=0) = Field(
        None, description="Compression fluidity exponent nc [-].")
    eta0t: _cscm_override("fluidity", lo=0) = Field(
        None, description="Tension fluidity eta0t [s^(1-nt)].")
    nt: _cscm_override("rate exponent", lo=0) = Field(
        None, description="Tension fluidity exponent nt [-].")
    overc: _cscm_override("overstress", PRESSURE, lo=0) = Field(
        None, description="Maximum overstress in compression.")
    overt: _cscm_override("overstress", PRESSURE, lo=0) = Field(
        None, description="Maximum overstress in tension.")
    srate: _cscm_override("fluidity ratio", lo=0) = Field(
        None, description="Shear-to-tension fluidity ratio (default 1).")
    repow: _cscm_override("power", lo=0) = Field(
        None, description="Power of the rate increase of fracture energy "
                          "(default 1).")
    rate_effects: StrictBool = Field(
        False, description="Viscoplastic rate effects (LS-DYNA IRATE = 1); "
                           "off by default as in LS-DYNA.")
    erode: StrictBool = Field(
        False, description="Erosion: a point with damage > 0.99 and maximum "
                           "principal strain > erode_strain keeps its mass "
                           "but carries no deviatoric or tensile stress.")
    erode_strain: real("strain", lo=0) = Field(
        0.05, description="Maximum principal strain for erosion (LS-DYNA "
                          "ERODE - 1).")
    recovery: real("recovery factor", lo=0, hi=11) = Field(
        0.0, description="RECOV: 0 = modulus recovered in compression, 1 = "
                         "brittle damage kept in compression (0-1 between); "
                         "10-11: the same, switched by the volumetric strain "
                         "instead of the pressure (LS-DYNA option 2).")
    cap_retraction: StrictBool = Field(
        False, description="ITRETRC: the cap may move back towards its initial "
                           "position (never inside it); see docs/cscm.md.")
    rate_thresholds: StrictBool = Field(
        True, description="With rate_effects: the damage thresholds rise with "
                          "the dynamic strength ratio (docs/cscm.md, choice "
                          "[D]); false keeps them static.")

    @field_validator("recovery")
    @classmethod
    def _recovery_range(cls, r):
        if 1.0 < r < 10.0:
            raise problem(f"recovery {r} is neither in [0, 1] nor in [10, 11]",
                          "give 0-1 (pressure switch) or 10-11 (volumetric "
                          "strain switch)")
        return r
    incre: Optional[real("strain increment", lo=0, lo_open=True)] = Field(
        None, description="Maximum strain sub-increment (default a quarter "
                          "of the zero-pressure shear yield strain).")
    variation: Optional[Variation] = Field(
        None, description="Random scatter of one parameter ([material.variation]).")


Material = Annotated[Union[Elastic, J2, Cscm], Field(discriminator="model")]


# Shapes ------------------------------------------------------------------

class Box(Section):
    """Axis-aligned box."""

    shape: Literal["box"] = Field(description="Kind of shape.")
    lo: Position = Field(description="Lower corner.")
    hi: Position = Field(description="Upper corner, above lo in the first "
                                     "`dimension` components.")

    @field_validator("hi")
    @classmethod
    def _above_lo(cls, hi, info: ValidationInfo):
        _check_corners(info.data.get("lo"), hi, "lo")
        return hi


class Sphere(Section):
    """Sphere (a disc in 2D)."""

    shape: Literal["sphere"] = Field(description="Kind of shape.")
    centre: Position = Field(description="Centre.")
    radius: PositiveLength = Field(description="Radius.")


def _axis_in_plane(axis: str) -> str:
    if _dimension() == 2 and axis != "z":
        raise problem(f"axis '{axis}' is not allowed in 2D",
                      "use axis = \"z\" (the shape is a disc in the x-y plane)")
    return axis


def _length_in_3d(length: Optional[float]) -> Optional[float]:
    if length is None and _dimension() == 3:
        raise problem("a cylinder or ring in a 3D deck needs a length",
                      "add length = \"100 mm\" (or a number in metres)")
    return length


PlanarAxis = Annotated[Axis, AfterValidator(_axis_in_plane)]
AxialLength = Annotated[Optional[PositiveLength], AfterValidator(_length_in_3d)]


class Cylinder(Section):
    """Solid circular cylinder (a disc in 2D)."""

    shape: Literal["cylinder"] = Field(description="Kind of shape.")
    centre: Position = Field(description="Centre (mid-length on the axis).")
    radius: PositiveLength = Field(description="Radius.")
    length: AxialLength = Field(
        None, validate_default=True,
        description="Length along the axis; required in 3D, ignored in 2D.")
    axis: PlanarAxis = Field("z", description="Axis direction; must be z "
                                              "in 2D.")


class Ring(Section):
    """Hollow circular cylinder (an annulus in 2D)."""

    shape: Literal["ring"] = Field(description="Kind of shape.")
    centre: Position = Field(description="Centre (mid-length on the axis).")
    inner_radius: quantity(LENGTH, "radius", lo=0) = Field(
        description="Inner radius.")
    outer_radius: PositiveLength = Field(
        description="Outer radius, greater than inner_radius.")
    length: AxialLength = Field(
        None, validate_default=True,
        description="Length along the axis; required in 3D, ignored in 2D.")
    axis: PlanarAxis = Field("z", description="Axis direction; must be z "
                                              "in 2D.")

    @field_validator("outer_radius")
    @classmethod
    def _above_inner(cls, outer, info: ValidationInfo):
        inner = info.data.get("inner_radius")
        if inner is not None and outer <= inner:
            raise problem(f"outer_radius {_num(outer)} is not greater than "
                          f"inner_radius {_num(inner)}",
                          "give an outer_radius greater than inner_radius")
        return outer


Geometry = Annotated[Union[Box, Cylinder, Ring, Sphere],
                     Field(discriminator="shape")]


class HalfSpace(Section):
    """Half-space: points with (x - point) . normal >= 0."""

    shape: Literal["halfspace"] = Field(description="Kind of shape.")
    point: Position = Field(description="A point on the bounding plane.")
    normal: Direction = Field(description="Normal pointing into the "
                                          "selected side (normalised).")


class CylinderRegion(Section):
    """Circular cylinder region, infinite unless a length is given."""

    shape: Literal["cylinder"] = Field(description="Kind of shape.")
    centre: Position = Field(description="Centre (mid-length on the axis).")
    radius: PositiveLength = Field(description="Radius.")
    axis: Axis = Field("z", description="Axis direction.")
    length: Optional[PositiveLength] = Field(
        None, description="Length along the axis (absent: infinite).")


class RegionBox(Section):
    """Axis-aligned selection box; in 2D its z-range may be any range
    containing z = 0, so the same box works in 2D and 3D decks."""

    shape: Literal["box"] = Field(description="Kind of shape.")
    lo: Corner = Field(description="Lower corner.")
    hi: Corner = Field(description="Upper corner, above lo in the first "
                                   "`dimension` components.")

    @field_validator("hi")
    @classmethod
    def _above_lo(cls, hi, info: ValidationInfo):
        lo = info.data.get("lo")
        _check_corners(lo, hi, "lo")
        if lo is not None and _dimension() == 2 and not lo[2] <= 0 <= hi[2]:
            raise problem(f"the z-range [{_num(lo[2])}, {_num(hi[2])}] does "
                          "not contain the plane z = 0 of this 2D deck",
                          "give z-components with lo <= 0 <= hi, e.g. 0 and 0")
        return hi


Region = Annotated[Union[RegionBox, Sphere, HalfSpace, CylinderRegion],
                   Field(discriminator="shape")]


# Numerical heterogeneity (sphdyn.heterogeneity, docs/heterogeneity.md) ----

#: Parameters of each mass law (the others must be absent).
_MASS_PARAMS = {"uniform": ("low", "high"), "normal": ("mean", "std"),
                "lognormal": ("sigma",), "poisson": ("lam",),
                "histogram": ("edges", "weights")}


class Mesostructure(Section):
    """[body.mesostructure]: concrete phases from fractal coherent noise.

    Aggregate, mortar and interfacial transition zone (ITZ) are generated
    on the body's particles (thesis sec. 7.2; docs/mesostructure.md) and
    each phase takes its own [[material]] (e.g. CSCM with different fc or
    density; all of one model family). The field is seeded by run.seed and
    the body's index, so ensembles vary it through run.seed.
    """

    aggregate_fraction: Optional[real("volume fraction", lo=0, hi=1, lo_open=True,
                                      hi_open=True)] = Field(
        None, description="Target aggregate volume fraction (hit on the "
                          "particles to within one voxel). Required unless "
                          "photo is given (then measured from the photo).")
    max_aggregate_size: Optional[PositiveLength] = Field(
        None, description="Largest aggregate (equivalent diameter). Required "
                          "unless photo is given (then fitted to the photo).")
    photo: Optional[ExistingFile] = Field(
        None, description="Image of a concrete section (PNG, JPEG; relative "
                          "to the deck) from which aggregate_fraction and "
                          "max_aggregate_size are measured: Otsu segmentation, "
                          "area fraction = volume fraction, D_max fitted so "
                          "that sections of the generated structure have the "
                          "photo's 95th-percentile piece size "
                          "(docs/mesostructure.md).")
    pixel_size: Optional[PositiveLength] = Field(
        None, description="Size of one photo pixel (required with photo).")
    photo_aggregate: Literal["bright", "dark"] = Field(
        "bright", description="Whether aggregate is the bright or the dark "
                              "class of the photo.")
    itz_thickness: quantity(LENGTH, "thickness", lo=0) = Field(
        0.0, description="Thickness of the ITZ band around aggregate (0 = no "
                         "ITZ; at least about one particle spacing to be "
                         "resolved).")
    shape: Literal["rounded", "crushed"] = Field(
        "rounded", description="Aggregate shape: rounded (gravel) or "
                               "crushed (angular).")
    octaves: integer("octave count", lo=1, hi=8) = Field(
        3, description="Octaves of the fractional Brownian motion.")
    persistence: real("persistence", lo=0, hi=1, lo_open=True) = Field(
        0.5, description="Amplitude ratio of successive octaves.")
    lacunarity: real("lacunarity", lo=1, lo_open=True) = Field(
        2.0, description="Frequency ratio of successive octaves.")
    mortar: Optional[reference_to("material")] = Field(
        None, description="Material of the mortar (default: the body's).")
    aggregate: Optional[reference_to("material")] = Field(
        None, description="Material of the aggregate (default: the body's).")
    itz: Optional[reference_to("material")] = Field(
        None, description="Material of the ITZ (default: the mortar's).")

    @model_validator(mode="after")
    def _photo_or_targets(self):
        targets = [k for k in ("aggregate_fraction", "max_aggregate_size")
                   if getattr(self, k) is not None]
        if self.photo is not None:
            if self.pixel_size is None:
                raise problem("photo is given without pixel_size",
                              "add pixel_size = \"0.1 mm\" (the size of one pixel)")
            if targets:
                raise problem(f"{' and '.join(targets)} given together with photo",
                              "give either photo (the targets are measured from "
                              "it) or aggregate_fraction and max_aggregate_size")
            return self
        if self.pixel_size is not None:
            raise problem("pixel_size is given without photo",
                          "add photo = \"section.png\" or remove pixel_size")
        missing = [k for k in ("aggregate_fraction", "max_aggregate_size")
                   if getattr(self, k) is None]
        if missing:
            raise problem(f"{' and '.join(missing)} missing",
                          "give aggregate_fraction and max_aggregate_size, or "
                          "photo and pixel_size")
        return self


class MassField(Section):
    """[body.mass]: random particle masses (Husek et al. 2017, sec. 4).

    Mass factors f >= 0 (multiples of the homogeneous particle mass rho
    dx^d) are drawn from the distribution and rescaled so that the body's
    total mass is exactly the homogeneous one; density, lattice and
    smoothing length stay those of the homogeneous body, so the particle
    volume m/rho varies. Give exactly the parameters of the chosen
    distribution. The draw is seeded by run.seed and the body's index.
    """

    distribution: Literal["uniform", "normal", "lognormal", "poisson",
                          "histogram"] = Field(
        description="Law of the mass factors: uniform U[low, high]; normal "
                    "N(mean, std^2) truncated at 0; lognormal with ln f ~ "
                    "N(-sigma^2/2, sigma^2); poisson k/lam with k ~ "
                    "Poisson(lam); histogram: piecewise-constant density.")
    low: Optional[real("mass factor", lo=0)] = Field(
        None, description="uniform: lower bound (0 allows massless "
                          "particles, as in the paper).")
    high: Optional[real("mass factor", lo=0)] = Field(
        None, description="uniform: upper bound, at least low (low = high "
                          "gives the homogeneous body).")
    mean: Optional[real("mass factor", lo=0, lo_open=True)] = Field(
        None, description="normal: mean before truncation.")
    std: Optional[real("standard deviation", lo=0)] = Field(
        None, description="normal: standard deviation before truncation "
                          "(0 = homogeneous).")
    sigma: Optional[real("standard deviation", lo=0)] = Field(
        None, description="lognormal: standard deviation of ln f "
                          "(0 = homogeneous).")
    lam: Optional[real("Poisson mean", lo=0, lo_open=True)] = Field(
        None, description="poisson: mean count lambda; f = k/lambda, so "
                          "the coefficient of variation is lambda^-1/2.")
    edges: Optional[tuple[real("mass factor", lo=0), ...]] = Field(
        None, description="histogram: increasing bin edges of f.")
    weights: Optional[tuple[real("weight", lo=0), ...]] = Field(
        None, description="histogram: relative frequency of each bin "
                          "(one fewer than edges, not all zero).")

    @model_validator(mode="after")
    def _parameters_of_the_law(self):
        law = self.distribution
        need = _MASS_PARAMS[law]
        missing = [k for k in need if getattr(self, k) is None]
        extra = [k for p in _MASS_PARAMS.values() for k in p
                 if k not in need and getattr(self, k) is not None]
        if missing or extra:
            raise problem(
                f"distribution = \"{law}\" takes {' and '.join(need)}"
                + (f"; missing {', '.join(missing)}" if missing else "")
                + (f"; not used: {', '.join(extra)}" if extra else ""),
                f"give exactly {', '.join(need)} for a {law} distribution")
        if law == "uniform" and self.high < self.low:
            raise problem(f"high = {_num(self.high)} is below low = "
                          f"{_num(self.low)}", "give high >= low")
        if law == "histogram":
            e, w = self.edges, self.weights
            if len(e) < 2 or any(b <= a for a, b in zip(e[:-1], e[1:])):
                raise problem("the histogram edges are not an increasing list "
                              "of at least 2 values",
                              "give edges = [0, 0.5, 1, 1.5, 2] (increasing)")
            if len(w) != len(e) - 1 or sum(w) <= 0:
                raise problem(f"{len(w)} weights for {len(e) - 1} bins, or all "
                              "weights zero",
                              "give one non-negative weight per bin, not all zero")
        return self


class CrackPlane(Section):
    """[[body.crack]] shape = "plane": a planar crack (zero-mass particles).

    Particles closer than rows*dx/2 to the plane get zero mass (Husek et
    al. 2017, sec. 5.2); with radius, only those within radius of point.
    """

    shape: Literal["plane"] = Field(description="Kind of crack.")
    point: Position = Field(description="A point on the crack plane.")
    normal: Direction = Field(description="Normal of the crack plane.")
    rows: integer("row count", lo=1) = Field(
        1, description="Thickness in particle rows (half-width rows*dx/2).")
    radius: Optional[PositiveLength] = Field(
        None, description="Extent around point within the plane (absent: "
                          "the whole plane).")


class CrackPolyline(Section):
    """[[body.crack]] shape = "polyline": a crack along a polyline.

    Particles closer than rows*dx/2 to the polyline (distance measured in
    the plane normal to axis) get zero mass; in 3D the crack runs through
    the body along axis.
    """

    shape: Literal["polyline"] = Field(description="Kind of crack.")
    points: tuple[Position, ...] = Field(
        description="Corner points, at least 2 (their axis component is "
                    "ignored).")
    rows: integer("row count", lo=1) = Field(
        1, description="Thickness in particle rows (half-width rows*dx/2).")
    axis: PlanarAxis = Field("z", description="Direction along which the "
                                              "crack is extruded; z in 2D.")

    @field_validator("points")
    @classmethod
    def _two_points(cls, points):
        if len(points) < 2:
            raise problem(f"the polyline has {len(points)} point(s)",
                          "give at least 2 points")
        return points


class CrackBox(Section):
    """[[body.crack]] shape = "box": pre-fractured material in a box.

    Every particle inside the axis-aligned box gets zero mass.
    """

    shape: Literal["box"] = Field(description="Kind of crack.")
    lo: Corner = Field(description="Lower corner.")
    hi: Corner = Field(description="Upper corner, above lo.")

    @field_validator("hi")
    @classmethod
    def _above_lo(cls, hi, info: ValidationInfo):
        _check_corners(info.data.get("lo"), hi, "lo")
        return hi


Crack = Annotated[Union[CrackPlane, CrackPolyline, CrackBox],
                  Field(discriminator="shape")]


# Bodies, walls, sets, boundaries ----------------------------------------

class Body(Section):
    """[[body]]: a solid filled with particles on a lattice."""

    name: name_of("body") = Field(description="Name of the body.")
    material: reference_to("material") = Field(
        description="Name of a [[material]].")
    dx: quantity(LENGTH, "particle spacing", lo=0, lo_open=True) = Field(
        description="Particle spacing of the lattice.")
    velocity: VelocityVector = Field(
        (0.0, 0.0, 0.0), description="Initial velocity.")
    geometry: Geometry = Field(description="Shape filled with particles.")
    formulation: Optional[Literal["updated_lagrangian", "total_lagrangian"]] = \
        Field(None, description="Kernel formulation of this body; default: "
                                "[sph] formulation.")
    artificial_stress: Optional[real("artificial-stress factor", lo=0)] = Field(
        None, description="Artificial-stress epsilon of this body (0 = off "
                          "for it); default: [sph.artificial_stress] epsilon. "
                          "Updated-Lagrangian bodies only.")
    mesostructure: Optional[Mesostructure] = Field(
        None, description="Aggregate / mortar / ITZ phases with their own "
                          "materials (absent: one material).")
    mass: Optional[MassField] = Field(
        None, description="Random particle masses (absent: homogeneous, "
                          "m = rho dx^d); see docs/heterogeneity.md.")
    crack: tuple[Crack, ...] = Field(
        (), description="Initial cracks: their particles get zero mass; "
                        "use a wall with stiffness = \"bulk\".")


class Wall(Section):
    """[[wall]]: rigid planar wall with penalty contact."""

    name: name_of("wall") = Field(description="Name of the wall.")
    point: Position = Field(description="A point on the wall plane.")
    normal: Direction = Field(
        description="Normal pointing into the half-space where the bodies "
                    "are (normalised).")
    stiffness: Literal["mass", "bulk"] = Field(
        "mass", description="Penalty stiffness: mass: k = alpha m/dt^2; "
                            "bulk: k = alpha K A/L (works for zero-mass "
                            "particles).")
    alpha: real("penalty factor", lo=0, lo_open=True) = Field(
        0.1, description="Penalty factor alpha.")
    bulk_modulus: Optional[PositivePressure] = Field(
        None, description="K of the bulk method (absent: the particle's "
                          "own material K); only with stiffness = \"bulk\".")
    friction: real("friction coefficient", lo=0) = Field(
        0.0, description="Coulomb friction coefficient.")
    thickness_factor: real("thickness factor", lo=0) = Field(
        0.5, description="Contact starts when a particle centre is closer "
                         "than thickness_factor times its spacing.")
    velocity: VelocityVector = Field(
        (0.0, 0.0, 0.0), description="Constant velocity of the wall (e.g. a "
        "platen of a compression test): the plane passes through point + "
        "velocity * t. The history then also records the wall's displacement "
        "along its normal, d_wall_<name>.")
    ramp_time: quantity(TIME, "ramp time", lo=0) = Field(
        0.0, description="The wall accelerates linearly from rest to velocity "
                         "over this time (0 = moves at once); a ramp avoids the "
                         "impact wave of a platen started at full speed.")

    @field_validator("bulk_modulus")
    @classmethod
    def _only_for_bulk(cls, k, info: ValidationInfo):
        if k is not None and info.data.get("stiffness") == "mass":
            raise problem("bulk_modulus is not used with stiffness = \"mass\"",
                          "remove bulk_modulus or set stiffness = \"bulk\"")
        return k


class ParticleSet(Section):
    """[[set]]: a named selection of particles."""

    name: name_of("set") = Field(description="Name of the set.")
    body: Optional[reference_to("body")] = Field(
        None, description="Restrict the set to this [[body]] (absent: all "
                          "bodies).")
    region: Optional[Region] = Field(
        None, description="Region selecting particles by initial position "
                          "(absent: all particles of the body or model).")


class Boundary(Section):
    """[[boundary]]: kinematic condition on a set."""

    set: reference_to("set") = Field(description="Name of a [[set]].")
    type: Literal["fixed", "velocity"] = Field(
        description="fixed: zero velocity; velocity: prescribed velocity.")
    velocity: Optional[VelocityVector] = Field(
        None, validate_default=True,
        description="Prescribed velocity; required for type = \"velocity\", "
                    "not allowed for \"fixed\".")

    @field_validator("velocity")
    @classmethod
    def _matches_type(cls, velocity, info: ValidationInfo):
        kind = info.data.get("type")
        if kind == "fixed" and velocity is not None:
            raise problem("a fixed boundary takes no velocity",
                          "remove velocity or set type = \"velocity\"")
        if kind == "velocity" and velocity is None:
            raise problem("a velocity boundary needs a velocity",
                          "add velocity = [\"1 m/s\", 0, 0]")
        return velocity


PROBE_QUANTITIES = (
    "velocity_x", "velocity_y", "velocity_z", "speed",
    "displacement_x", "displacement_y", "displacement_z",
    "stress_xx", "stress_yy", "stress_zz", "stress_xy", "stress_yz", "stress_xz",
    "pressure", "von_mises", "density", "damage", "internal_energy",
    "smoothing_length", "plastic_strain",
)


class Probe(Section):
    """[[probe]]: time history of a quantity over a particle set."""

    set: reference_to("set") = Field(description="Name of a [[set]].")
    quantities: tuple[Literal[PROBE_QUANTITIES], ...] = Field(
        ("displacement_x", "displacement_y", "displacement_z", "velocity_x",
         "velocity_y", "velocity_z", "von_mises"),
        description="Quantities recorded (stress tension positive, pressure "
                    "positive in compression; plastic_strain needs a j2 "
                    "material).")
    reduce: Literal["mean", "min", "max"] = Field(
        "mean", description="Reduction over the set's particles; history "
                            "columns are named probe_<set>_<quantity>.")


def _known_field(name: str) -> str:
    if name not in ALLOWED_FIELDS:
        raise problem(f"'{name}' is not an output field",
                      suggest(name, ALLOWED_FIELDS, "use one of the known "
                              f"fields: {', '.join(ALLOWED_FIELDS)}"))
    return name


class Output(Section):
    """[output]: frames, histories and checkpoints."""

    every: Optional[quantity(TIME, "frame interval", lo=0, lo_open=True)] = \
        Field(None, description="Time between frames (absent: t_end / 50).")
    vtk: StrictBool = Field(True, description="Also write VTK (.vtu) frames "
                                              "for ParaView.")
    fields: tuple[Annotated[str, Strict(), AfterValidator(_known_field)],
                  ...] = Field(DEFAULT_FIELDS,
                               description="Particle fields written in "
                                           "frames.")
    history_every: integer("step count", lo=1) = Field(
        10, description="Steps between history records (energies, contact "
                        "forces).")
    checkpoint_every: integer("step count", lo=0) = Field(
        0, description="Steps between checkpoints (0 = off).")
    force_window: quantity(TIME, "force averaging window", lo=0, lo_open=True) = Field(
        5e-6, description="Window of the averaged wall force: summary.json and "
                          "the ensemble table report, next to the raw peak, the "
                          "peak of the mean force over this window (from the "
                          "wall impulse I_wall_<name>), which smooths the "
                          "spikes of first contact.")
    progress: StrictBool = Field(True, description="Show a progress bar.")


class Deck(Section):
    """A complete, validated input deck (SI units)."""

    run: Run = Field(description="What is simulated and for how long.")
    sph: Sph = Field(default_factory=Sph, description="SPH discretisation.")
    time: Time = Field(default_factory=Time, description="Time stepping.")
    domain: Domain = Field(default_factory=Domain, description="Guard box.")
    material: Annotated[tuple[Material, ...], BeforeValidator(NonEmpty("material"))] = \
        Field(description="Materials (at least one).")
    body: Annotated[tuple[Body, ...], BeforeValidator(NonEmpty("body"))] = Field(
        description="Bodies (at least one).")
    contact: Contact = Field(default_factory=Contact,
                             description="Contact between bodies.")
    wall: tuple[Wall, ...] = Field((), description="Rigid walls.")
    set: tuple[ParticleSet, ...] = Field((), description="Particle sets.")
    boundary: tuple[Boundary, ...] = Field((), description="Boundary "
                                                           "conditions.")
    probe: tuple[Probe, ...] = Field((), description="Time histories of "
                                                     "particle sets.")
    output: Output = Field(default_factory=Output, description="Output.")

    @model_validator(mode="wrap")
    @classmethod
    def _with_scope(cls, data, handler):
        token = _SCOPE.set(_scope_of(data))
        try:
            return handler(data)
        finally:
            _SCOPE.reset(token)

    def frame_interval(self) -> float:
        """Return the time between output frames [s]."""
        return self.output.every if self.output.every else self.run.t_end / 50


# --------------------------------------------------------------------------
# From pydantic errors to deck messages
# --------------------------------------------------------------------------

def strip_optional(annotation: Any) -> Any:
    """Remove ``Annotated`` wrappers and ``Optional`` from an annotation."""
    while True:
        origin = get_origin(annotation)
        if origin is Annotated:
            annotation = get_args(annotation)[0]
        elif origin in (Union, types.UnionType) and type(None) in get_args(
                annotation):
            rest = [a for a in get_args(annotation) if a is not type(None)]
            annotation = rest[0] if len(rest) == 1 else Union[tuple(rest)]
        else:
            return annotation


def variants(annotation: Any) -> dict[str, type[Section]]:
    """Return ``{tag: model}`` of a discriminated union, else ``{}``."""
    annotation = strip_optional(annotation)
    if get_origin(annotation) not in (Union, types.UnionType):
        return {}
    found = {}
    for member in get_args(annotation):
        for key in ("model", "shape"):
            info = getattr(member, "model_fields", {}).get(key)
            if info is not None:
                found[get_args(info.annotation)[0]] = member
    return found


def _is_model(annotation: Any) -> bool:
    return isinstance(annotation, type) and issubclass(annotation, BaseModel)


@dataclass
class _Where:
    """An error location resolved against the schema and the raw deck."""

    path: str = ""
    label: str = ""
    owner: Optional[type[BaseModel]] = None
    key: Optional[str] = None
    annotation: Any = None


def field_annotation(info: Any) -> Any:
    """The annotation of a field with its Annotated metadata put back."""
    if info is None:
        return None
    if info.metadata:
        return Annotated[info.annotation, *info.metadata]
    return info.annotation


def locate(loc: tuple, raw: Any, root: type[BaseModel] = Deck) -> _Where:
    """Resolve a pydantic error location.

    Union tags are dropped from the path, list indexes are written
    ``[i]``, and the name of the enclosing top-level table (if any) becomes
    the label.
    """
    where = _Where(annotation=root)
    data = raw
    for item in loc:
        ann = strip_optional(where.annotation)
        if isinstance(item, int):
            where.path += f"[{item}]"
            args = get_args(ann)
            where.annotation = args[0] if args else None
            ok = isinstance(data, (list, tuple)) and 0 <= item < len(data)
            data = data[item] if ok else None
            name = _get(data, "name") if isinstance(data, dict) else None
            if not where.label and isinstance(name, str):
                where.label = f"{where.path.split('[')[0]} '{name}'"
            continue
        members = variants(ann)
        if item in members:
            where.annotation = members[item]
            continue
        where.path = f"{where.path}.{item}" if where.path else str(item)
        where.owner = ann if _is_model(ann) else None
        where.key = item
        info = where.owner.model_fields.get(item) if where.owner else None
        where.annotation = field_annotation(info)
        data = data.get(item) if isinstance(data, dict) else None
    return where


def metadata(annotation: Any) -> list:
    """All Annotated metadata found while unwrapping ``annotation``."""
    found = []
    while True:
        origin = get_origin(annotation)
        if origin is Annotated:
            found.extend(annotation.__metadata__)
            annotation = get_args(annotation)[0]
        elif origin in (Union, types.UnionType) and type(None) in get_args(
                annotation):
            annotation = next(a for a in get_args(annotation)
                              if a is not type(None))
        else:
            return found


def _example(where: _Where) -> str:
    """A TOML snippet a user could write for the key at ``where``."""
    key, ann = where.key, where.annotation
    core = strip_optional(ann)
    if _is_model(core):
        return f"a [{where.path}] table"
    if get_origin(core) is tuple and get_args(core):
        element = get_args(core)[0]
        if _is_model(strip_optional(element)) or variants(element):
            return f"at least one [[{key}]] table"
    if get_origin(core) is Literal:
        return f"{key} = {_choices(get_args(core))}"
    for meta in metadata(ann):
        func = getattr(meta, "func", None)
        if isinstance(func, Quantity):
            return f"{key} = \"{func.dim.example}\""
        if isinstance(func, Vector):
            return f"{key} = [x, y, z]"
    if core is str:
        return f"{key} = \"...\""
    return f"{key} = <value>"


_TYPE_NAMES = {
    "int_type": ("an integer", "give a whole number such as 2"),
    "int_from_float": ("an integer", "give a whole number such as 2"),
    "float_type": ("a number", "give a number such as 0.5"),
    "bool_type": ("true or false", "write true or false (no quotes)"),
    "string_type": ("text", "give text in quotes, e.g. \"steel\""),
    "tuple_type": ("a list", "give a list in brackets, e.g. [1, 2, 3]"),
    "list_type": ("a list", "give a list in brackets, e.g. [1, 2, 3]"),
    "model_type": ("a table", "write it as a table: [section] or { k = v }"),
    "model_attributes_type": ("a table",
                              "write it as a table: [section] or { k = v }"),
    "dict_type": ("a table", "write it as a table: [section] or { k = v }"),
}


def _choices(options) -> str:
    """``"a" or "b"`` as TOML values, for messages."""
    shown = [f'"{o}"' if isinstance(o, str) else str(o) for o in options]
    return " or ".join([", ".join(shown[:-1]), shown[-1]] if len(shown) > 2
                       else shown)


def _explain_one(err: dict, where: _Where) -> tuple[str, str]:
    """Return ``(what, fix)`` for one pydantic error."""
    kind, ctx, value = err["type"], err.get("ctx") or {}, err.get("input")
    if kind == "deck":
        return ctx["what"], ctx["fix"]
    if kind == "missing":
        return "a required key is missing", f"add {_example(where)}"
    if kind == "extra_forbidden":
        valid = list(where.owner.model_fields) if where.owner else []
        return "unknown key", suggest(
            str(where.key), valid,
            f"remove or rename it; valid keys here: {', '.join(valid)}")
    if kind == "literal_error":
        options = get_args(strip_optional(where.annotation))
        return (f"{show(value)} is not allowed",
                suggest(str(value), [str(a) for a in options],
                        f"use one of {_choices(options)}"))
    if kind in ("union_tag_not_found", "union_tag_invalid"):
        key = ctx.get("discriminator", "").strip("'")
        tags = list(variants(where.annotation))
        choices = _choices(tags)
        if kind == "union_tag_not_found":
            return f"the key '{key}' is missing", f"add {key} = {choices}"
        tag = str(ctx.get("tag"))
        return (f"{key} = '{tag}' is not known",
                suggest(tag, tags, f"use {key} = {choices}"))
    if kind == "finite_number":
        return f"{show(value)} is not finite", "give a finite number"
    base_kind = kind.replace("_parsing", "_type")
    if base_kind in _TYPE_NAMES:
        name, fix = _TYPE_NAMES[base_kind]
        return f"{show(value)} is not {name}", fix
    return err["msg"], "see docs/deck-reference.md"


def format_problem(path: str, what: str, fix: str) -> str:
    """Join the parts of one problem line."""
    fix = fix if fix.endswith((".", "?", "!")) else fix + "."
    return f"{path or 'deck'}: {what}. Fix: {fix}"


def explain(exc: ValidationError, raw: Any,
            root: type[BaseModel] = Deck) -> list[str]:
    """Turn a ``ValidationError`` from validating ``raw`` into problem lines.

    Parameters
    ----------
    exc : ValidationError
        Raised by ``root.model_validate(raw)``.
    raw : Any
        The data that was validated (used to find names for the labels).
    root : type of BaseModel
        The model that was validated.

    Returns
    -------
    list of str
        ``<path>: <what is wrong>. Fix: <what to write>`` per problem.
    """
    lines = []
    for err in exc.errors(include_url=False):
        where = locate(err["loc"], raw, root)
        what, fix = _explain_one(err, where)
        if where.label and where.key != "name":
            what += f" in {where.label}"
        line = format_problem(where.path, what, fix)
        if line not in lines:
            lines.append(line)
    return lines
