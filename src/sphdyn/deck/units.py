"""Physical quantities in decks: plain SI numbers or strings with units.

A deck value such as ``"0.5 mm"`` or ``"43.1 MPa"`` is parsed with pint and
converted to SI; a plain number is taken as already SI.  pint is imported
only when the first unit string is seen, because its import and registry
construction are slow and most CLI commands never need them.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from functools import cache


class QuantityError(ValueError):
    """A deck value that is not a valid quantity of the expected dimension.

    Parameters
    ----------
    what : str
        What is wrong, e.g. ``"'3 MPa' is not a length"``.
    fix : str
        What to write instead.
    """

    def __init__(self, what: str, fix: str):
        super().__init__(f"{what}. Fix: {fix}")
        self.what = what
        self.fix = fix


@dataclass(frozen=True)
class Dimension:
    """A physical dimension a deck quantity must have.

    Attributes
    ----------
    name : str
        Noun used in messages ("length", "pressure").
    si_unit : str
        SI unit the value is stored in, written so pint can parse it.
    example : str
        A typical unit string for messages ("0.5 mm").
    si_example : float
        ``example`` in SI.
    si_name : str
        Spoken name of the SI unit ("metres").
    """

    name: str
    si_unit: str
    example: str
    si_example: float
    si_name: str

    def hint(self) -> str:
        """Return the advice used after ``Fix:`` for a bad value."""
        article = "an" if self.name[0] in "aeiou" else "a"
        number = f"{self.si_example:g}".replace("e+0", "e").replace("e-0", "e-")
        return (f"give {article} {self.name} such as '{self.example}' "
                f"or {number} ({self.si_name})")


LENGTH = Dimension("length", "m", "0.5 mm", 5e-4, "metres")
TIME = Dimension("time", "s", "1 ms", 1e-3, "seconds")
PRESSURE = Dimension("pressure", "Pa", "43.1 MPa", 4.31e7, "pascals")
DENSITY = Dimension("mass density", "kg/m^3", "2400 kg/m^3", 2400.0,
                    "kilograms per cubic metre")
VELOCITY = Dimension("velocity", "m/s", "15 m/s", 15.0, "metres per second")
FORCE = Dimension("force", "N", "10 kN", 1e4, "newtons")
RATE = Dimension("rate", "1/s", "100 1/s", 100.0, "per second")
MASS = Dimension("mass", "kg", "75 g", 0.075, "kilograms")
ACCELERATION = Dimension("acceleration", "m/s^2", "9.81 m/s^2", 9.81,
                         "metres per second squared")


@cache
def registry():
    """Return the one pint ``UnitRegistry``, created on first use."""
    import pint

    return pint.UnitRegistry()


_STARTS_WITH_NUMBER = re.compile(r"\s*[+-]?(\d|\.\d)")


def _significant(x: float, digits: int = 15) -> float:
    """Round ``x`` to ``digits`` significant digits (drops conversion noise)."""
    return float(f"{x:.{digits}g}")


def to_si(value: object, dim: Dimension) -> float:
    """Convert a deck value to an SI float of dimension ``dim``.

    Parameters
    ----------
    value : object
        A number (already SI) or a string with units such as ``"0.5 mm"``.
    dim : Dimension
        The dimension the value must have.

    Returns
    -------
    float
        The value in ``dim.si_unit``.  Converted strings are rounded to 15
        significant digits so that ``"43.1 MPa"`` gives exactly ``4.31e7``.

    Raises
    ------
    QuantityError
        If the value is not a finite number or a string of dimension ``dim``.
    """
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        shown = str(value).lower() if isinstance(value, bool) else repr(value)
        raise QuantityError(f"{shown} is not a {dim.name}", dim.hint())
    if isinstance(value, str):
        if not _STARTS_WITH_NUMBER.match(value):
            raise QuantityError(f"'{value}' does not start with a number",
                                dim.hint())
        ureg = registry()
        try:
            q = ureg.Quantity(value.strip())
        except Exception as exc:  # pint raises several unrelated types
            detail = str(exc) or type(exc).__name__
            raise QuantityError(
                f"'{value}' cannot be read as a quantity ({detail})",
                dim.hint()) from None
        if not isinstance(q, ureg.Quantity) or q.dimensionless:
            raise QuantityError(f"'{value}' has no unit", dim.hint()
                                + "; a number in quotes needs a unit")
        target = ureg.Unit(dim.si_unit)
        if q.dimensionality != target.dimensionality:
            raise QuantityError(f"'{value}' is not a {dim.name}", dim.hint())
        result = _significant(float(q.to(target).magnitude))
    else:
        result = float(value)
    if not math.isfinite(result):
        raise QuantityError(f"{value!r} is not finite", dim.hint())
    return result


#: Multipliers of the memory-size units accepted by :func:`to_bytes`.
BYTE_UNITS = {"": 1, "b": 1, "byte": 1, "bytes": 1,
              "kb": 10**3, "mb": 10**6, "gb": 10**9, "tb": 10**12,
              "kib": 2**10, "mib": 2**20, "gib": 2**30, "tib": 2**40}

_MEMORY = re.compile(r"\s*([+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)\s*([A-Za-z]*)\s*$")
MEMORY_HINT = "give a size such as '8 GiB', '500 MB' or a number of bytes"


def to_bytes(value: object) -> float:
    """Convert a memory size (``"8 GiB"``, ``"500 MB"`` or a number of bytes) to bytes.

    pint counts bytes as dimensionless, so sizes are read here: decimal
    (kB, MB, GB, TB) and binary (KiB, MiB, GiB, TiB) prefixes, any case.

    Raises
    ------
    QuantityError
        If the value is not a finite number or such a string.
    """
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise QuantityError(f"{value!r} is not a memory size", MEMORY_HINT)
    if isinstance(value, str):
        match = _MEMORY.match(value)
        unit = match.group(2).lower() if match else None
        if unit not in BYTE_UNITS:
            raise QuantityError(f"'{value}' is not a memory size", MEMORY_HINT)
        result = float(match.group(1)) * BYTE_UNITS[unit]
    else:
        result = float(value)
    if not math.isfinite(result):
        raise QuantityError(f"{value!r} is not finite", MEMORY_HINT)
    return result
