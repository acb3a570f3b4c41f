"""What the field validators may know about the whole deck being validated.

Checks that need the whole deck (the dimension, the names of other tables)
read the :class:`Scope` that the Deck model publishes in :data:`SCOPE`
while it validates (see :func:`scope_of`).
"""

from contextvars import ContextVar
from dataclasses import dataclass, field
from typing import Any, Optional

#: Sections whose tables have a ``name`` that others refer to.
NAMED_SECTIONS = ("material", "body", "mesh", "set", "wall", "blast")


@dataclass(frozen=True)
class Scope:
    """The dimension and the table names of the deck being validated."""

    dimension: Optional[int] = None
    names: dict[str, list[str]] = field(default_factory=dict)


SCOPE: ContextVar[Optional[Scope]] = ContextVar("sphdyn_deck_scope",
                                                default=None)


def get_key(obj: Any, key: str) -> Any:
    """Read ``key`` from a raw table (dict) or an already built model."""
    if isinstance(obj, dict):
        return obj.get(key)
    return getattr(obj, key, None)


def scope_of(data: Any) -> Scope:
    """Collect the dimension and the table names from raw deck data."""
    dim = get_key(get_key(data, "run"), "dimension")
    if isinstance(dim, bool) or dim not in (1, 2, 3):
        dim = None
    names = {}
    for section in NAMED_SECTIONS:
        items = get_key(data, section)
        items = items if isinstance(items, (list, tuple)) else []
        names[section] = [n for n in (get_key(t, "name") for t in items)
                          if isinstance(n, str)]
    return Scope(None if dim is None else int(dim), names)


def dimension() -> Optional[int]:
    """The dimension of the deck being validated (None if unknown)."""
    scope = SCOPE.get()
    return scope.dimension if scope else None
