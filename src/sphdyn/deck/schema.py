"""The deck schema: frozen pydantic models holding SI floats.

The deck is assembled here from its sections (:mod:`sphdyn.deck.sections`)
and the parameter tables of the registered material models
(:mod:`sphdyn.materials.registry`): :func:`deck_model` builds the
:class:`Deck` model whose ``material`` entries are a union of those tables,
chosen by their ``model`` key, when it is first asked for and again after a
model has been registered. ``Deck`` (module attribute) is that model.

Quantities accept a plain SI number or a unit string (see
:mod:`sphdyn.deck.units`); vectors are stored as 3-tuples even in 2D
(``z = 0``). Every validator raises :func:`~sphdyn.deck.messages.problem`
errors, whose message reads ``<what is wrong>. Fix: <what to write>``;
:func:`~sphdyn.deck.errors.explain` turns a pydantic ``ValidationError``
into one such line per problem. Checks that need the whole deck (the
dimension, names of other tables) read the :mod:`~sphdyn.deck.scope` that
the Deck publishes while it validates.
"""

import functools
from typing import Annotated, Union

from pydantic import BeforeValidator, Field, create_model, model_validator

from ..materials import get_model
from .introspect import field_annotation, metadata, strip_optional, variants
from .scope import SCOPE, scope_of
from .sections.bodies import Body, Crack, MassField, Mesostructure, Variation
from .messages import problem
from .sections.blast import Blast
from .sections.detonation import Detonation
from .sections.gauges import Gauge
from .sections.material import MaterialSection, parameter_clashes
from .sections.output import Output, Probe
from .sections.run import Domain, Run, Time
from .sections.meshes import BeamSection, BlockMesh, Convert, LineMesh, Mesh, MeshGroup
from .sections.sets import Boundary, Load, ParticleSet
from .sections.shapes import Geometry, Region
from .sections.sph import BodyContact, Sph
from .sections.walls import Wall
from .values import ExistingFile, NonEmpty, Section

__all__ = [
    "BeamSection", "Blast", "BlockMesh", "Body", "Boundary", "Convert", "Detonation",
    "LineMesh", "Load", "Mesh",
    "MeshGroup", "BodyContact", "Crack", "Deck", "DeckSections", "Domain",
    "ExistingFile", "Gauge", "Geometry", "MassField", "MaterialSection", "Mesostructure",
    "Output", "ParticleSet", "Probe", "Region", "Run", "Section", "Sph", "Time",
    "Variation", "Wall", "deck_model", "field_annotation", "metadata",
    "strip_optional", "variants",
]


def _bodies_or_meshes(value):
    """Before-validator of ``body``: no body is fine when the deck has meshes."""
    scope = SCOPE.get()
    if scope is not None and scope.names.get("mesh"):
        return value
    if isinstance(value, (list, tuple)) and not value:
        raise problem("there is no [[body]] table (and no [[mesh]])",
                      "add at least one [[body]] (particles) or [[mesh]] "
                      "(finite elements)")
    return value


class DeckSections(Section):
    """A complete, validated input deck (SI units).

    The ``material`` entries are narrowed by :func:`deck_model` to the
    tables of the registered material models.
    """

    run: Run = Field(description="What is simulated and for how long.")
    sph: Sph = Field(default_factory=Sph, description="SPH discretisation.")
    time: Time = Field(default_factory=Time, description="Time stepping.")
    domain: Domain = Field(default_factory=Domain, description="Guard box.")
    material: tuple[MaterialSection, ...] = Field(
        description="Materials (at least one).")
    body: Annotated[tuple[Body, ...], BeforeValidator(_bodies_or_meshes)] = Field(
        (), validate_default=True,
        description="Bodies of particles (at least one body or mesh).")
    mesh: tuple[Mesh, ...] = Field((), description="Finite-element parts.")
    contact: BodyContact = Field(default_factory=BodyContact,
                             description="Contact between bodies.")
    wall: tuple[Wall, ...] = Field((), description="Rigid walls.")
    set: tuple[ParticleSet, ...] = Field((), description="Particle sets.")
    boundary: tuple[Boundary, ...] = Field((), description="Boundary "
                                                           "conditions.")
    load: tuple[Load, ...] = Field(
        (), description="Forces on sets, pressures on mesh faces.")
    probe: tuple[Probe, ...] = Field((), description="Time histories of "
                                                     "particle sets.")
    gauge: tuple[Gauge, ...] = Field((), description="Strain, displacement and "
                                     "section-force gauges at material points.")
    detonation: tuple[Detonation, ...] = Field(
        (), description="Detonation points of high explosives.")
    blast: tuple[Blast, ...] = Field(
        (), description="Empirical air-blast loads (Kingery-Bulmash) on sets.")
    output: Output = Field(default_factory=Output, description="Output.")

    @model_validator(mode="wrap")
    @classmethod
    def _with_scope(cls, data, handler):
        token = SCOPE.set(scope_of(data))
        try:
            return handler(data)
        finally:
            SCOPE.reset(token)

    @model_validator(mode="after")
    def _materials_fit_together(self):
        """Each material's values are accepted together by its model (checked
        after every table is valid, so a missing key is reported as such)."""
        clashes = parameter_clashes(self.material)
        if clashes:
            k, message = clashes[0]
            raise problem(f"material[{k}] '{self.material[k].name}': the parameters do "
                          f"not fit together ({message})",
                          "change the values named there; docs/deck-reference.md "
                          "gives each key's meaning and range")
        return self

    @model_validator(mode="after")
    def _one_dimensional(self):
        """A 1D deck: particles only, updated-Lagrangian."""
        if self.run.dimension != 1:
            return self
        if self.mesh:
            raise problem("a 1D deck (run.dimension = 1) has no finite elements",
                          "remove the [[mesh]] tables, or use run.dimension = 2 or 3")
        if self.sph.formulation == "total_lagrangian" and any(
                b.formulation is None for b in self.body):
            raise problem("sph.formulation = \"total_lagrangian\" in a 1D deck",
                          "use \"updated_lagrangian\" (the total-Lagrangian passes "
                          "are 2D and 3D only)")
        return self

    @model_validator(mode="after")
    def _explosives_lit(self):
        """Every detonation lights a high explosive; every explosive with a
        programmed burn has a detonation that lights it."""
        he = [m.name for m in self.material if get_model(m.model).explosive]
        for k, d in enumerate(self.detonation):
            if d.material is not None and d.material not in he:
                raise problem(f"detonation[{k}].material '{d.material}' is not a high "
                              "explosive", "name a material with model = "
                              "\"high_explosive\"" + (f" ({', '.join(he)})" if he else ""))
        if self.detonation and not he:
            raise problem("there are [[detonation]] points but no high explosive",
                          "add a material with model = \"high_explosive\", or remove "
                          "the [[detonation]] tables")
        for k, m in enumerate(self.material):
            if not get_model(m.model).explosive or m.burn == "beta":
                continue
            if not any(d.material in (None, m.name) for d in self.detonation):
                raise problem(f"material[{k}] '{m.name}' has a programmed burn but no "
                              "[[detonation]] lights it",
                              "add [[detonation]] point = [x, y, z] in the charge, or "
                              "set burn = \"beta\" (lit by compression only)")
        return self

    def frame_interval(self) -> float:
        """Return the time between output frames [s]."""
        return self.output.every if self.output.every else self.run.t_end / 50


def deck_model() -> type[DeckSections]:
    """The Deck model for the material models and builders registered now.

    Asking loads the models and builders of other packages (entry points)
    the first time; the model is built once per set of material tables and
    builders' own tables (:func:`sphdyn.build.registry.extension_tables`).
    """
    from ..build.registry import extension_tables
    from ..materials.registry import material_schemas

    return _deck_for(material_schemas(), extension_tables())


@functools.cache
def _deck_for(materials: tuple[type[MaterialSection], ...],
              extensions: tuple = ()) -> type[DeckSections]:
    """The Deck model whose ``material`` entries are one of ``materials``, with
    a table per ``(name, schema, many)`` of ``extensions``: ``[[name]]`` (a
    tuple, default empty) if ``many``, else ``[name]`` (default None).
    ``ValueError`` if an extension's name is one of the deck's own tables."""
    choice = Annotated[Union[materials], Field(discriminator="model")]
    entries = Annotated[tuple[choice, ...], BeforeValidator(NonEmpty("material"))]
    info = DeckSections.model_fields["material"]
    tables = {}
    for name, schema, many in extensions:
        if name in DeckSections.model_fields:
            raise ValueError(f"a builder's table [{name}] would replace the deck's own")
        doc = (schema.__doc__ or name).strip().split("\n")[0]
        tables[name] = ((tuple[schema, ...], Field((), description=doc)) if many
                        else (schema | None, Field(None, description=doc)))
    return create_model("Deck", __base__=DeckSections, __module__=__name__,
                        __doc__=DeckSections.__doc__.split("\n")[0],
                        material=(entries, Field(description=info.description)), **tables)


def __getattr__(name: str):
    """``Deck``: the current :func:`deck_model` (built on first use)."""
    if name == "Deck":
        return deck_model()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
