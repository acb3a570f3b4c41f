"""The common part of every [[material]] table: name, model, density, variation.

A material model owns the table of its parameters (see
:mod:`sphdyn.materials.registry`): a subclass of :class:`MaterialSection`
whose ``model`` key is ``Literal["<model name>"]``; the deck offers the
tables of all registered models, chosen by ``model``.
"""

from typing import ClassVar, Optional

from pydantic import Field, model_validator

from ..introspect import field_annotation, metadata, strip_optional
from ..messages import problem
from ..units import DENSITY, PRESSURE, TIME
from ..values import Quantity, Section, name_of, quantity, real
from .bodies import Variation

#: Keys of every material that are not parameters of its model: what it is
#: and how it varies or erodes, and the density limits the SPH part reads
#: (:class:`sphdyn.parts.sph.part.SPHSettings`).
NOT_PARAMETERS = ("name", "model", "variation", "erosion", "min_density_factor",
                  "max_density_factor", "viscosity", "time_step_factor")

#: Mass density of a material (required, > 0).
Density = quantity(DENSITY, lo=0, lo_open=True)


class MaterialErosion(Section):
    """[material.erosion]: when elements of this material erode (docs/theory.md,
    "Element erosion"); any rule that holds erodes the element. Used by the
    meshes with [mesh.erosion]; particles ignore it."""

    erode: Optional[real("ERODE", lo=1, lo_open=True)] = Field(
        None, description="LS-DYNA MAT_159's ERODE: the element erodes when its "
                          "damage exceeds 0.99 and its maximum principal strain "
                          "exceeds erode - 1 (e.g. 1.05). Only for a model with "
                          "damage (cscm).")
    principal_strain: Optional[real("principal strain", lo=0, lo_open=True)] = Field(
        None, description="Maximum principal (engineering) strain at erosion.")
    effective_strain: Optional[real("effective strain", lo=0, lo_open=True)] = Field(
        None, description="Effective strain at erosion: the von Mises equivalent "
                          "of the logarithmic strain (LS-DYNA's EFFEPS).")
    min_time_step: Optional[quantity(TIME, "time step", lo=0, lo_open=True)] = Field(
        None, description="The element erodes when its stable step (times the "
                          "mesh's cfl) falls below this.")

    @model_validator(mode="after")
    def _a_rule(self):
        if all(getattr(self, k) is None for k in type(self).model_fields):
            raise problem("[material.erosion] has no rule",
                          "give erode, principal_strain, effective_strain or "
                          "min_time_step")
        return self


class MaterialViscosity(Section):
    """[material.viscosity]: this material's artificial-viscosity coefficients
    (absent keys: [sph.viscosity]'s). A pair of particles of two materials uses
    the means of their coefficients."""

    alpha: Optional[real("viscosity coefficient", lo=0)] = Field(
        None, description="Linear (bulk) coefficient alpha.")
    beta: Optional[real("viscosity coefficient", lo=0)] = Field(
        None, description="Quadratic (von Neumann-Richtmyer) coefficient beta.")


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
    erosion: Optional[MaterialErosion] = Field(
        None, description="Erosion rules of elements of this material "
                          "([material.erosion]).")
    min_density_factor: real("minimum density factor", lo=0, hi=1, hi_open=True) = Field(
        0.2, description="Particles of this material keep a density of at least this "
                         "times their initial density (Autodyn's SPH minimum density "
                         "factor; 0: no limit). A safeguard for sparse particles, such as "
                         "the debris of eroded elements, whose density from the "
                         "continuity equation can otherwise run away; a sound solid never "
                         "reaches it. The history counts the particles held at a limit "
                         "(density_limited).")
    max_density_factor: real("maximum density factor", lo=1, lo_open=True) = Field(
        3.0, description="Particles of this material keep a density of at most this "
                         "times their initial density (Autodyn's SPH maximum density "
                         "factor).")
    viscosity: Optional[MaterialViscosity] = Field(
        None, description="Artificial viscosity of this material's particles "
                          "([material.viscosity]; absent: [sph.viscosity]).")
    time_step_factor: real("time-step factor", lo=0, hi=1, lo_open=True) = Field(
        1.0, description="The CFL step of this material's particles times this factor "
                         "(a stricter limit for one material). The particles of a fluid "
                         "(gas, high_explosive) also count the artificial viscosity's "
                         "signal speed, 1.2 (alpha c + beta mu_max) (Monaghan 1992).")

    @model_validator(mode="after")
    def _varied_parameter(self):
        var = self.variation
        if var is None:
            return self
        fixed = {"density", *NOT_PARAMETERS, *self.unvaried}
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
        but name, model, variation, erosion, the density limits, the viscosity
        and the time-step factor, absent (None) values left out."""
        return {key: v for key, v in self.model_dump().items()
                if key not in NOT_PARAMETERS and v is not None}

    @classmethod
    def stress_keys(cls) -> tuple[str, ...]:
        """The parameters with the dimension of a stress (moduli, strengths)."""
        return tuple(key for key, info in cls.model_fields.items()
                     if any(isinstance(getattr(m, "func", m), Quantity)
                            and getattr(m, "func", m).dim == PRESSURE
                            for m in metadata(field_annotation(info))))

    def stress_scaled(self, factor: float) -> dict:
        r""":meth:`values` with every stress parameter times ``factor``: for a
        model whose stress is homogeneous of degree one in them (elastic, J2:
        :math:`\sigma(\varepsilon; f E, f\sigma_y, f H) = f\,\sigma(\varepsilon; E,
        \sigma_y, H)`), the same material carrying ``factor`` of the stress at
        every strain (the sublayer split, docs/theory.md)."""
        keys = set(self.stress_keys())
        return {k: (v * factor if k in keys else v) for k, v in self.values().items()}


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
