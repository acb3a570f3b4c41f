"""Value types of the deck: quantities, bounds, vectors, names and files.

The annotations built here (:func:`real`, :func:`quantity`,
:func:`vector`, :func:`name_of`, ...) carry their checks as pydantic
validators; the marker classes (:class:`Quantity`, :class:`Bounds`, ...)
are also read by :mod:`sphdyn.deck.docgen` to write the type, unit and
allowed-values columns of the reference. :class:`Section` is the base of
every deck table.
"""

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, ClassVar, Literal, Optional

from pydantic import (AfterValidator, BaseModel, BeforeValidator, ConfigDict,
                      Strict, ValidationInfo)

from .messages import problem, show, show_number, show_vector, suggest
from .scope import MESH_BODY, SCOPE, dimension
from .units import (ACCELERATION, LENGTH, PRESSURE, TIME, VELOCITY, Dimension,
                    QuantityError, to_bytes, to_si)


class Section(BaseModel):
    """Base of all deck tables: frozen, unknown keys rejected.

    ``moved`` names keys a table no longer has and where they went (a key of
    this table or another table's ``[t] key``): a deck using one is refused
    with that fix.
    """

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)
    moved: ClassVar[dict[str, str]] = {}


@dataclass(frozen=True)
class Quantity:
    """Before-validator converting a number or unit string to SI."""

    dim: Dimension

    def __call__(self, value: Any) -> float:
        try:
            return to_si(value, self.dim)
        except QuantityError as exc:
            raise problem(exc.what, exc.fix) from None


def memory_size(value: Any) -> float:
    """Before-validator: a memory size (``"8 GiB"`` or bytes) in bytes."""
    try:
        return to_bytes(value)
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
        lo = "-inf" if self.lo is None else show_number(self.lo)
        hi = "inf" if self.hi is None else show_number(self.hi)
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
                      f"give a {self.noun} {side} {show_number(limit)}")


@dataclass(frozen=True)
class Reference:
    """After-validator: the value must be the name of a ``[[section]]``."""

    section: str
    #: also a particle body made from a mesh (``body`` references:
    #: :func:`~sphdyn.deck.scope.mesh_body_names`)
    mesh_bodies: bool = False
    #: further sections whose names are accepted too
    also: tuple = ()

    def __call__(self, name: str) -> str:
        scope = SCOPE.get()
        if scope is None:
            return name
        known = scope.names.get(self.section, [])
        if self.mesh_bodies:
            known = known + scope.names.get(MESH_BODY, [])
        for other in self.also:
            known = known + scope.names.get(other, [])
        known = list(dict.fromkeys(known))
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
    """After-validator: a non-empty name without slashes, unique among its
    ``[[section]]``."""

    section: str

    def __call__(self, name: str) -> str:
        if not name.strip():
            raise problem("the name is empty",
                          f"give each [[{self.section}]] a non-empty name")
        if "/" in name or "\\" in name:
            raise problem(f"the name '{name}' has a slash (names become output groups, "
                          "folders and history columns)",
                          "use letters, digits, '_' or '-'")
        scope = SCOPE.get()
        count = scope.names.get(self.section, []).count(name) if scope else 1
        if count > 1:
            raise problem(
                f"the name '{name}' is used by {count} [[{self.section}]] tables",
                f"give each [[{self.section}]] a different name")
        return name


@dataclass(frozen=True)
class Vector:
    """Before-validator: 3 entries, or 2 entries padded with ``z = 0``, or (in
    a 1D deck) 1 entry padded with ``y = z = 0``.

    Two entries are refused only when the deck is known to be 3D.
    """

    def __call__(self, value: Any) -> Any:
        dim = dimension()
        fix = "give 3 entries [x, y, z]" + (
            "" if dim == 3 else " (or [x, y] in a 2D deck)" if dim == 2 else
            " (or [x, y] in a 2D deck, [x] in a 1D deck)")
        if not isinstance(value, (list, tuple)):
            raise problem(f"{show(value)} is not a vector", fix)
        if len(value) == 2 and dim != 3:
            return (*value, 0.0)
        if len(value) == 1 and dim in (1, None):
            return (*value, 0.0, 0.0)
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


def flat_in_2d(vec: tuple[float, float, float]) -> tuple[float, float, float]:
    """After-validator: in a 2D deck the z-component must be zero, in a 1D deck
    the y- and z-components."""
    if dimension() == 1 and (vec[1] != 0.0 or vec[2] != 0.0):
        raise problem(f"the y- or z-component is not 0 but the deck is 1D "
                      "(run.dimension = 1, along x)", "give only [x]")
    if dimension() == 2 and vec[2] != 0.0:
        raise problem(f"the z-component is {show_number(vec[2])} but the deck is 2D "
                      "(run.dimension = 2)",
                      "set z to 0 or give only [x, y]")
    return vec


def unit_vector(vec: tuple[float, float, float]) -> tuple[float, float, float]:
    """After-validator: a non-zero direction, scaled to unit length."""
    norm = math.sqrt(sum(c * c for c in vec))
    if norm == 0.0:
        raise problem("the direction is the zero vector",
                      "give a non-zero vector such as [0, 1, 0]")
    if abs(norm - 1.0) <= 1e-12:  # keep already normalised input unchanged
        return vec
    return tuple(c / norm for c in vec)


def existing_file(value: Any, info: ValidationInfo) -> Path:
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
    checks = [AfterValidator(flat_in_2d)] if planar else []
    return Annotated[tuple[element, element, element],
                     BeforeValidator(Vector()), *checks]


def name_of(section: str) -> Any:
    """The ``name`` of a ``[[section]]`` table (unique, non-empty)."""
    return Annotated[str, Strict(), AfterValidator(UniqueName(section))]


def reference_to(section: str, mesh_bodies: bool = False, also: tuple = ()) -> Any:
    """The name of an existing ``[[section]]`` table (with ``mesh_bodies``,
    or of a particle body made from a mesh: :func:`~sphdyn.deck.scope.mesh_body_names`;
    or of a table of the sections ``also``)."""
    return Annotated[str, Strict(), AfterValidator(Reference(section, mesh_bodies,
                                                             tuple(also)))]


Position = vector(quantity(LENGTH))
#: A point whose z may be non-zero in 2D (corners of selection boxes).
Corner = vector(quantity(LENGTH), planar=False)
VelocityVector = vector(quantity(VELOCITY))
AccelerationVector = vector(quantity(ACCELERATION))
Direction = Annotated[vector(real()), AfterValidator(unit_vector)]
PositiveLength = quantity(LENGTH, lo=0, lo_open=True)
PositivePressure = quantity(PRESSURE, lo=0, lo_open=True)
Axis = Literal["x", "y", "z"]

#: A path to an existing file; relative paths are taken from the deck's
#: folder (validation context key ``base_dir``), stored absolute.
ExistingFile = Annotated[Path, BeforeValidator(existing_file)]


def above_lo(hi, info: ValidationInfo):
    """After-validator of an upper corner: ``hi > lo`` in the first ``dimension``
    components (``lo`` the table's other corner)."""
    lo = info.data.get("lo")
    if lo is None or hi is None:
        return hi
    n = dimension()
    if n is None:  # dimension unknown: a flat box is taken as 2D
        n = 2 if lo[2] == hi[2] == 0.0 else 3
    if any(h <= l for l, h in zip(lo[:n], hi[:n])):
        raise problem(
            f"hi = {show_vector(hi[:n])} is not above lo = {show_vector(lo[:n])} "
            "in every component",
            f"make each of the first {n} entries of hi greater than those of lo")
    return hi


#: The upper corner ``hi`` of a box whose lower corner is ``lo``.
UpperPosition = Annotated[Position, AfterValidator(above_lo)]
#: Likewise for a selection box (:data:`Corner`).
UpperCorner = Annotated[Corner, AfterValidator(above_lo)]


@dataclass(frozen=True)
class CurvePoints:
    """Before-validator of a time curve: a list of at least two ``[time, factor]``
    pairs (the time a quantity, the factor a number)."""

    def __call__(self, value: Any) -> Any:
        example = "curve = [[0, 0], [\"1 ms\", 1]]"
        if not isinstance(value, (list, tuple)) or len(value) < 2:
            raise problem(f"{show(value)} is not a curve of at least two points",
                          f"give [time, factor] pairs, e.g. {example} (for a "
                          "constant load leave curve out)")
        for k, point in enumerate(value):
            if not isinstance(point, (list, tuple)) or len(point) != 2:
                raise problem(f"point {k} ({show(point)}) is not a [time, factor] pair",
                              f"write each point as [time, factor], e.g. {example}")
        return value


def increasing_times(points: tuple) -> tuple:
    """After-validator of a time curve: the times strictly increase."""
    for k in range(1, len(points)):
        if points[k][0] <= points[k - 1][0]:
            raise problem(
                f"the curve's times are not increasing: point {k} at "
                f"{show_number(points[k][0])} s follows {show_number(points[k - 1][0])} s",
                "sort the points by time, each later than the one before (a step: "
                "two points a short time apart)")
    return points


#: A time curve ``[[t, factor], ...]`` (times in s, strictly increasing),
#: interpolated linearly and held at its end values.
TimeCurve = Annotated[tuple[tuple[quantity(TIME), real("factor")], ...],
                      BeforeValidator(CurvePoints()), AfterValidator(increasing_times)]
