"""Registry of builders: one per deck table, built in or from other packages.

A :class:`Builder` turns one table of a validated deck into parts,
interactions or events (:class:`Built`), reading what earlier builders made
from the :class:`~sphdyn.build.context.BuildContext`. Builders run in the
order of their ``stage`` (then of registration); a builder of a ``[[mesh]]``
sub-table (``mesh=True``, a stage from :data:`MESH_STAGE` to 499) runs once
per mesh, inside the stage :data:`MESH_STAGE`, so each mesh's interactions
stay together, in the order of their stages. The stages of the built-in
builders:

======  ==========================================================
stage   tables
======  ==========================================================
100     ``[[body]]`` (the SPH part), then ``[[mesh]]`` (its parts)
200     ``[contact]``, ``[[wall]]`` on particles
300     ``[[boundary]]``, ``[[load]]``, ``[[blast]]``, body damping
400     per mesh: damping (410), ``[[wall]]`` on it (420),
        ``[mesh.convert]`` (430), ``[mesh.sublayer]`` (440),
        ``[mesh.contact]`` (450), ``[mesh.erosion]``'s debris coupling (460)
500     ``[mesh.embed]`` (passes on what the bars' nodes were given)
600     ``[run] gravity``
700     events: ``[mesh.erosion]``, ``[domain]``
======  ==========================================================

A builder from another package may bring its own deck table (``schema``: a
:class:`sphdyn.deck.values.Section`); the deck then accepts ``[[<table>]]``
(``many=True``) or ``[<table>]`` and hands the builder the validated
entries as ``deck.<table>``. It registers through an entry point in the group
:data:`ENTRY_POINT_GROUP` (``sphdyn.builders``), e.g.::

    [project.entry-points."sphdyn.builders"]
    spring = "toy_spring:BUILDER"

naming a :class:`Builder` (or a callable returning one, or registering it
and returning None). Entry points are loaded once, when the builders or the
extension tables are first asked for (:func:`sphdyn.plugins.load_group`).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any, Callable

from ..plugins import load_group

ENTRY_POINT_GROUP = "sphdyn.builders"

#: the stage in which the [[mesh]] sub-table builders run, mesh by mesh
MESH_STAGE = 400


@dataclass
class Built:
    """What a builder made: parts, interactions and events, in their order."""

    parts: list = field(default_factory=list)
    interactions: list = field(default_factory=list)
    events: list = field(default_factory=list)

    def extend(self, other: "Built") -> None:
        """Append ``other``'s items after this one's."""
        self.parts += other.parts
        self.interactions += other.interactions
        self.events += other.events


@dataclass(frozen=True)
class Builder:
    """One deck table's builder.

    ``table``: the table it reads (``"boundary"``, ``"mesh.contact"``);
    ``build``: ``build(ctx) -> Built``, or ``build(ctx, mesh) -> Built`` for a
    mesh sub-table (``mesh=True``; ``mesh`` a
    :class:`~sphdyn.build.mesh_model.MeshModel`); ``stage``: its place in the order
    (module docstring); ``schema``: the deck table it brings (extensions only;
    the built-in tables are the deck's own); ``many``: ``[[table]]`` (a list)
    rather than ``[table]``.
    """

    table: str
    build: Callable[..., Built]
    stage: int
    mesh: bool = False
    schema: Any = None
    many: bool = True

    @property
    def key(self) -> tuple[str, int]:
        return self.table, self.stage


#: (table, stage) -> builder, in registration order
REGISTRY: dict[tuple[str, int], Builder] = {}

_TABLE = re.compile(r"[a-z][a-z0-9_]*")


def register(builder: Builder, *, replace: bool = False) -> Builder:
    """Add ``builder`` to :data:`REGISTRY`.

    ``ValueError`` if a builder of the same table and stage is registered and
    ``replace`` is false, if a schema's table name is not a plain lower-case
    name, or if a mesh sub-table builder's stage is outside
    ``[MESH_STAGE, MESH_STAGE + 100)``.
    """
    if builder.key in REGISTRY and not replace:
        raise ValueError(f"a builder of table {builder.table!r} at stage "
                         f"{builder.stage} is already registered")
    if builder.schema is not None and not _TABLE.fullmatch(builder.table):
        raise ValueError(f"a builder's own deck table needs a plain lower-case name, "
                         f"not {builder.table!r}")
    if builder.mesh and not MESH_STAGE <= builder.stage < MESH_STAGE + 100:
        raise ValueError(f"the mesh sub-table builder of {builder.table!r} needs a "
                         f"stage from {MESH_STAGE} to {MESH_STAGE + 99}, not "
                         f"{builder.stage}")
    REGISTRY[builder.key] = builder
    return builder


def load_entry_points() -> None:
    """Register the builders of the ``sphdyn.builders`` entry points (once)."""
    load_group(ENTRY_POINT_GROUP, Builder,
               lambda b: None if REGISTRY.get(b.key) is b else register(b))


def builders(mesh: bool = False) -> list[Builder]:
    """The registered builders of the deck (``mesh=False``) or of one mesh's
    sub-tables (``mesh=True``), by stage, then in registration order."""
    load_entry_points()
    chosen = [b for b in REGISTRY.values() if b.mesh == mesh]
    return sorted(chosen, key=lambda b: b.stage)  # stable: registration order kept


def extension_tables() -> tuple[tuple[str, Any, bool], ...]:
    """``(table, schema, many)`` of the builders that bring a deck table."""
    load_entry_points()
    return tuple((b.table, b.schema, b.many) for b in REGISTRY.values()
                 if b.schema is not None)
