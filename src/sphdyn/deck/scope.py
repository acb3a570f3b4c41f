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
    names[MESH_BODY] = mesh_body_names(get_key(data, "mesh"))
    return Scope(None if dim is None else int(dim), names)


#: The key of :attr:`Scope.names` listing the particle bodies made from
#: meshes, which a reference to a body may name besides the [[body]]s.
MESH_BODY = "mesh body"


def mesh_body_names(meshes: Any) -> list[str]:
    """Names of the particle bodies that [[mesh]] tables make and that exist
    from the start: the converted particles of a ``[mesh.convert]`` (named as
    the mesh) and a bar's ``[mesh.sublayer]`` particles (``<mesh>_sublayer``).
    (The ``<mesh>_debris`` of erosion starts empty, so nothing can select it.)"""
    out = []
    for table in meshes if isinstance(meshes, (list, tuple)) else []:
        name = get_key(table, "name")
        if not isinstance(name, str):
            continue
        if get_key(table, "convert") is not None:
            out.append(name)
        if get_key(table, "sublayer") is not None:
            out.append(f"{name}_sublayer")
    return out


def dimension() -> Optional[int]:
    """The dimension of the deck being validated (None if unknown)."""
    scope = SCOPE.get()
    return scope.dimension if scope else None
