"""Deck sections [[set]] and [[boundary]]: named particle selections and their conditions."""

from typing import Literal, Optional

from pydantic import Field, ValidationInfo, field_validator

from ..messages import problem
from ..values import Section, VelocityVector, name_of, reference_to
from .shapes import Region


class ParticleSet(Section):
    """[[set]]: a named selection of particles."""

    name: name_of("set") = Field(description="Name of the set.")
    body: Optional[reference_to("body")] = Field(
        None, description="Restrict the set to this [[body]] (absent: all "
                          "bodies).")
    region: Optional[Region] = Field(
        None, description="Region selecting particles by initial position "
                          "(absent: all particles of the body or model).")


class Boundary(Section):
    """[[boundary]]: kinematic condition on a set."""

    set: reference_to("set") = Field(description="Name of a [[set]].")
    type: Literal["fixed", "velocity"] = Field(
        description="fixed: zero velocity; velocity: prescribed velocity.")
    velocity: Optional[VelocityVector] = Field(
        None, validate_default=True,
        description="Prescribed velocity; required for type = \"velocity\", "
                    "not allowed for \"fixed\".")

    @field_validator("velocity")
    @classmethod
    def _matches_type(cls, velocity, info: ValidationInfo):
        kind = info.data.get("type")
        if kind == "fixed" and velocity is not None:
            raise problem("a fixed boundary takes no velocity",
                          "remove velocity or set type = \"velocity\"")
        if kind == "velocity" and velocity is None:
            raise problem("a velocity boundary needs a velocity",
                          "add velocity = [\"1 m/s\", 0, 0]")
        return velocity
