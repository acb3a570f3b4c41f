"""Deck sections [[set]], [[boundary]] and [[load]]: named selections and their conditions.

A set holds particles (of one [[body]] or all bodies) or the nodes of one
[[mesh]] (by region, by a group of the mesh file, or both).
"""

from typing import Literal, Optional

from pydantic import Field, ValidationInfo, field_validator, model_validator

from ..messages import problem
from ..units import FORCE, PRESSURE, TIME
from ..values import (Position, Section, TimeCurve, VelocityVector, name_of, quantity,
                      reference_to, vector)
from .shapes import Region

#: A force vector [N] (N/m in 2D); z must be 0 in 2D decks.
ForceVector = vector(quantity(FORCE))


class ParticleSet(Section):
    """[[set]]: a named selection of particles or of mesh nodes."""

    name: name_of("set") = Field(description="Name of the set.")
    body: Optional[reference_to("body", mesh_bodies=True)] = Field(
        None, description="Restrict the set to this [[body]], or to the particles of "
                          "a [mesh.convert] (the mesh's name) or a [mesh.sublayer] "
                          "(<mesh>_sublayer) (absent, and no mesh: all bodies).")
    mesh: Optional[reference_to("mesh")] = Field(
        None, description="A set of this [[mesh]]'s nodes instead of particles.")
    group: Optional[str] = Field(
        None, description="With mesh: the nodes of this group of the mesh file "
                          "(Gmsh physical group, Abaqus NSET or ELSET).")
    region: Optional[Region] = Field(
        None, description="Region selecting particles (or nodes) by initial position "
                          "(absent: all of the body, mesh or model).")

    @model_validator(mode="after")
    def _one_owner(self):
        if self.body is not None and self.mesh is not None:
            raise problem("a set holds particles of a body or nodes of a mesh, not both",
                          "remove body or mesh")
        if self.group is not None and self.mesh is None:
            raise problem("group names a group of a mesh file",
                          "add mesh = \"<name>\" or remove group")
        return self


class Boundary(Section):
    """[[boundary]]: kinematic condition on a set, or a non-reflecting boundary on
    a solid mesh's faces."""

    set: reference_to("set") = Field(description="Name of a [[set]].")
    type: Literal["fixed", "velocity", "displacement", "non_reflecting"] = Field(
        description="fixed: zero velocity; velocity: prescribed velocity; "
                    "displacement: prescribed displacement reached over ramp_time, "
                    "then held (a support moved, e.g. a beam end moved down); "
                    "non_reflecting: viscous dashpots on the exterior faces of a "
                    "solid mesh whose nodes all lie in the set, which let waves "
                    "leave the model (Lysmer & Kuhlemeyer 1969; LS-DYNA's "
                    "BOUNDARY_NON_REFLECTING): for a model cut out of a larger "
                    "body. The set must be a [[set]] of a solid mesh's nodes.")
    velocity: Optional[VelocityVector] = Field(
        None, validate_default=True,
        description="Prescribed velocity; required for type = \"velocity\", "
                    "not allowed otherwise.")
    displacement: Optional[Position] = Field(
        None, validate_default=True,
        description="Prescribed displacement; required for type = \"displacement\", "
                    "not allowed otherwise.")
    ramp_time: quantity(TIME, "ramp time", lo=0) = Field(
        0.0, description="The velocity (or displacement) grows from 0 to its value "
                         "over this time (0: at once). A displacement with "
                         "ramp_time = 0 is refused (an infinite velocity).")
    ramp: Literal["linear", "smooth"] = Field(
        "linear", description="Ramp shape: linear, or smooth (s - sin(2 pi s)/(2 pi) "
                              "with s = t/ramp_time: a displacement starts and ends "
                              "at rest, less ringing).")
    components: tuple[Literal["x", "y", "z"], ...] = Field(
        ("x", "y", "z"), description="The directions the condition holds; the others "
                                     "stay free (a roller support: components = "
                                     "[\"z\"]; LS-DYNA's SPC DOFX/DOFY/DOFZ). "
                                     "Conditions on different components of the same "
                                     "set combine.")
    rotations: Literal["free", "fixed"] = Field(
        "free", description="Beam nodes: also fix their rotations (a clamped or "
                            "rotation-free moved end).")

    @field_validator("velocity", "displacement")
    @classmethod
    def _matches_type(cls, value, info: ValidationInfo):
        kind = info.data.get("type")
        key = info.field_name
        if kind == key and value is None:
            example = "[\"1 m/s\", 0, 0]" if key == "velocity" else "[0, \"-5 mm\", 0]"
            raise problem(f"a {kind} boundary needs a {key}", f"add {key} = {example}")
        if kind is not None and kind != key and value is not None:
            raise problem(f"a {kind} boundary takes no {key}",
                          f"remove {key} or set type = \"{key}\"")
        return value

    @model_validator(mode="after")
    def _ramped_displacement(self):
        if self.type == "displacement" and self.ramp_time == 0.0:
            raise problem("a displacement boundary needs a ramp_time > 0",
                          "add ramp_time = \"10 ms\" (the time to reach the "
                          "displacement)")
        if self.type in ("fixed", "non_reflecting") and self.ramp_time != 0.0:
            raise problem(f"a {self.type} boundary has no ramp", "remove ramp_time")
        if self.type == "non_reflecting":
            # by value, not by whether it was written: a resolved deck
            # (deck.resolved.toml, every default filled) must load again
            if sorted(self.components) != ["x", "y", "z"]:
                raise problem("a non_reflecting boundary acts in every direction "
                              "(the dilatational wave along the face's normal, the "
                              "shear waves across it)", "remove components")
            if self.rotations != "free":
                raise problem("a non_reflecting boundary acts on solid faces, which "
                              "have no rotations", "remove rotations")
        if not self.components or len(set(self.components)) != len(self.components):
            raise problem(f"components {list(self.components)} must name each direction "
                          "at most once, and at least one",
                          "give e.g. components = [\"z\"] or leave it out (all three)")
        value = self.velocity if self.type == "velocity" else self.displacement
        if value is not None:
            free = [c for k, c in enumerate("xyz") if value[k] != 0.0
                    and c not in self.components]
            if free:
                raise problem(f"the {self.type} has a {' and '.join(free)} component, but "
                              f"components = {list(self.components)} leaves "
                              f"{' and '.join(free)} free",
                              f"add {' and '.join(free)} to components, or give 0 there")
        return self

    @property
    def axes(self) -> tuple[int, ...]:
        """The held components as axis indices."""
        return tuple(sorted("xyz".index(c) for c in self.components))


class Load(Section):
    """[[load]]: a force on a set, shared evenly by its nodes or particles, or a
    pressure on the faces of a solid mesh's node set.

    A ``force`` is split evenly among the set's members; the history reports the
    force applied now as ``<set>_force``. A ``pressure`` acts on every exterior
    face of the mesh whose nodes all belong to the set (LS-DYNA's
    LOAD_SEGMENT_SET): consistent nodal forces from the face's shape functions,
    on the face as it deforms; positive pushes into the body (against the
    outward normal). Its history columns are ``<set>_pressure`` and the
    resultant ``<set>_force_x|y|z``. Either load's work so far is ``W_<set>``,
    external work (part of ``W_external``)."""

    set: reference_to("set") = Field(description="Name of a [[set]] (for a pressure: "
                                                 "a set of a solid [[mesh]]'s nodes).")
    force: Optional[ForceVector] = Field(
        None, description="Total force on the set [N] (N/m in 2D), split evenly among "
                          "its members. Give force or pressure.")
    pressure: Optional[quantity(PRESSURE)] = Field(
        None, description="Pressure on the exterior faces whose nodes all lie in the "
                          "set (edges in 2D); positive pushes into the body. Give force "
                          "or pressure.")
    ramp_time: quantity(TIME, "ramp time", lo=0) = Field(
        0.0, description="The load grows from 0 over this time (0: at once).")
    ramp: Literal["linear", "smooth"] = Field("linear", description="Ramp shape.")
    curve: Optional[TimeCurve] = Field(
        None, description="Time curve [[t, factor], ...] instead of a ramp: the load is "
                          "force or pressure times the factor, interpolated linearly "
                          "between the points (times strictly increasing) and held at "
                          "the first and last factor outside them, e.g. [[0, 0], "
                          "[\"1 ms\", 1], [\"3 ms\", 0]].")

    @model_validator(mode="after")
    def _one_load(self):
        if (self.force is None) == (self.pressure is None):
            raise problem("a load gives either a force or a pressure" + (
                          ", not both" if self.force is not None else ""),
                          "give force = [0, 0, \"-1 kN\"] (shared by the set) or "
                          "pressure = \"2 MPa\" (on the set's faces)")
        # (ramp = "linear", the default, is written out by the resolved deck)
        if self.curve is not None and (self.ramp_time != 0.0 or self.ramp != "linear"):
            raise problem("a load takes a ramp (ramp_time, ramp) or a curve, not both",
                          "remove ramp_time and ramp (start the curve at [0, 0] for a "
                          "ramp)")
        return self
