"""Problem messages of the deck: ``<what is wrong>. Fix: <what to write>``.

Every deck validator raises :func:`problem` errors; :func:`show` and
friends write values roughly as they appear in TOML, and :func:`suggest`
adds "did you mean ...?" for misspelt names.
"""

import difflib
from typing import Any

from pydantic_core import PydanticCustomError


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


def show_number(x: float) -> str:
    """A number in messages: ``%g``."""
    return f"{x:g}"


def show_vector(values) -> str:
    """A vector in messages: ``[1, 2, 0]``."""
    return "[" + ", ".join(show_number(v) for v in values) + "]"


def suggest(word: str, choices: list[str], advice: str) -> str:
    """Prefix ``advice`` with "did you mean ...?" if a choice is close."""
    near = difflib.get_close_matches(word, choices, n=1, cutoff=0.6)
    near = near or [c for c in choices if len(word) >= 3 and c.startswith(word)]
    return f"did you mean '{near[0]}'? Otherwise {advice}" if near else advice


def choices(options) -> str:
    """``"a" or "b"`` as TOML values, for messages."""
    shown = [f'"{o}"' if isinstance(o, str) else str(o) for o in options]
    return " or ".join([", ".join(shown[:-1]), shown[-1]] if len(shown) > 2
                       else shown)
