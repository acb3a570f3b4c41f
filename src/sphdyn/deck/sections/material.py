"""The common part of every [[material]] table: name, model, density, variation.

A material model owns the table of its parameters (see
:mod:`sphdyn.materials.registry`): a subclass of :class:`MaterialSection`
whose ``model`` key is ``Literal["<model name>"]``; the deck offers the
tables of all registered models, chosen by ``model``.
"""

from typing import ClassVar, Optional

from pydantic import Field, model_validator

from ..introspect import strip_optional
from ..messages import problem
from ..units import DENSITY
from ..values import Section, name_of, quantity
from .bodies import Variation

#: Mass density of a material (required, > 0).
Density = quantity(DENSITY, lo=0, lo_open=True)


class MaterialSection(Section):
    """[[material]]: the keys every material model has.

    A subclass names its model, ``model: Literal["name"] = Field(...)``, and
    adds the model's parameters; a check of [material.variation] against
    them is inherited.
    """

    #: Float keys of the model that [material.variation] may not vary
    #: (besides name, model, density and variation).
    unvaried: ClassVar[tuple[str, ...]] = ()

    name: name_of("material") = Field(
        description="Name that bodies use to refer to the material.")
    model: str = Field(description="Constitutive model.")
    density: Density = Field(description="Initial mass density.")
    variation: Optional[Variation] = Field(
        None, description="Random scatter of one parameter ([material.variation]).")

    @model_validator(mode="after")
    def _varied_parameter(self):
        var = self.variation
        if var is None:
            return self
        fixed = {"name", "model", "density", "variation", *self.unvaried}
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

    def values(self) -> dict:
        """The model's parameters in SI units, as ``pack`` takes them: every key
        but name, model and variation, absent (None) values left out."""
        return {key: v for key, v in self.model_dump().items()
                if key not in ("name", "model", "variation") and v is not None}


def parameter_clashes(materials) -> list[tuple[int, str]]:
    """``(index, message)`` of validated materials whose model refuses the values
    together (``pack`` raises, e.g. CSCM surfaces that do not meet)."""
    from ...materials.registry import available_models, get_model

    clashes = []
    for k, mat in enumerate(materials):
        if mat.model not in available_models():
            continue
        try:
            get_model(mat.model).pack(mat.values())
        except ValueError as exc:
            clashes.append((k, str(exc)))
    return clashes
