"""Reading a keyword's fields: numbers, blanks, names, quantities.

Shared by the keyword readers of :mod:`.convert`, :mod:`.materials` and
:mod:`.conditions`.
"""

from __future__ import annotations

import math
import re


def name_of(text, fallback: str) -> str:
    """A deck name from a part or material title: letters, digits and ``_``."""
    text = text if isinstance(text, str) else ""  # a blank heading reads as NaN
    s = re.sub(r"[^A-Za-z0-9_]+", "_", text.strip()).strip("_")
    return s if s and not s[0].isdigit() else fallback


def quantity(value: float, unit: str) -> str:
    """A quantity string with all the value's digits."""
    return f"{float(value)!r} {unit}"


def number(value, default=0.0) -> float:
    """A field as a float, a blank one as ``default``."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        return default
    return default if math.isnan(v) else v


def integer(value, default=0) -> int:
    """A field as an int, a blank one as ``default``."""
    v = number(value, float(default))
    return int(v)


def round_spacing(dx: float) -> float:
    """A spacing recovered from a mass, rounded to 12 significant digits (a
    keyword file prints masses with at most 16; the rounding gives back the
    spacing the particles were made with)."""
    return float(f"{dx:.12g}")
