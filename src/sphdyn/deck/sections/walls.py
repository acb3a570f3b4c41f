"""Deck section [[wall]]: rigid planar walls with penalty contact."""

from typing import Literal, Optional

from pydantic import Field, ValidationInfo, field_validator

from ..messages import problem
from ..units import TIME
from ..values import (Direction, Position, PositivePressure, Section, VelocityVector,
                      name_of, quantity, real)


class Wall(Section):
    """[[wall]]: rigid planar wall with penalty contact."""

    name: name_of("wall") = Field(description="Name of the wall.")
    point: Position = Field(description="A point on the wall plane.")
    normal: Direction = Field(
        description="Normal pointing into the half-space where the bodies "
                    "are (normalised).")
    stiffness: Literal["mass", "bulk"] = Field(
        "mass", description="Penalty stiffness: mass: k = alpha m/dt^2 at the "
                            "current step (a spring whose k changes under load "
                            "keeps its energy: docs/theory.md); bulk: k = alpha "
                            "K A/L (works for zero-mass particles).")
    alpha: real("penalty factor", lo=0, lo_open=True) = Field(
        0.1, description="Penalty factor alpha.")
    bulk_modulus: Optional[PositivePressure] = Field(
        None, description="K of the bulk method (absent: the particle's "
                          "own material K); only with stiffness = \"bulk\".")
    friction: real("friction coefficient", lo=0) = Field(
        0.0, description="Coulomb friction coefficient.")
    thickness_factor: real("thickness factor", lo=0) = Field(
        0.5, description="Contact starts when a particle centre is closer "
                         "than thickness_factor times its spacing (a mesh node: "
                         "times the mean size of its elements). A solid mesh "
                         "starting closer than that is refused by check: move it, "
                         "or give 0 (contact at the plane) for a mesh resting on "
                         "the wall.")
    velocity: VelocityVector = Field(
        (0.0, 0.0, 0.0), description="Constant velocity of the wall (e.g. a "
        "platen of a compression test): the plane passes through point + "
        "velocity * t. The history then also records the wall's displacement "
        "along its normal, d_wall_<name>.")
    ramp_time: quantity(TIME, "ramp time", lo=0) = Field(
        0.0, description="The wall accelerates linearly from rest to velocity "
                         "over this time (0 = moves at once); a ramp avoids the "
                         "impact wave of a platen started at full speed.")

    @field_validator("bulk_modulus")
    @classmethod
    def _only_for_bulk(cls, k, info: ValidationInfo):
        if k is not None and info.data.get("stiffness") == "mass":
            raise problem("bulk_modulus is not used with stiffness = \"mass\"",
                          "remove bulk_modulus or set stiffness = \"bulk\"")
        return k
