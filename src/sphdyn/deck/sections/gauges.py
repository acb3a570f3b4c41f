"""Deck section [[gauge]]: measurements at material points, sampled at their own rate.

The instruments of an experiment (thesis ch. 8: a strain gauge on the top
surface, a displacement transducer at mid-span), LS-DYNA's
DATABASE_HISTORY_NODE and DATABASE_CROSS_SECTION: see :mod:`sphdyn.watchers.gauges`.
"""

from typing import Literal, Optional

from pydantic import Field, model_validator

from ..messages import problem
from ..units import TIME
from ..values import Direction, Position, Section, name_of, quantity, reference_to

#: what a point gauge may record
POINT_QUANTITIES = ("displacement_x", "displacement_y", "displacement_z", "velocity_x",
                    "velocity_y", "velocity_z")


class Gauge(Section):
    """[[gauge]]: a measurement at material points, written to gauges/<name>.csv."""

    name: name_of("gauge") = Field(description="Name of the gauge (its file "
                                               "gauges/<name>.csv and columns).")
    type: Literal["strain", "point", "section"] = Field(
        description="strain: the engineering strain between two material points, "
                    "|x_b - x_a| / |X_b - X_a| - 1 (a strain gauge; column strain); "
                    "point: displacement or velocity of a material point (column per "
                    "quantity); section: the force the items on the normal's side "
                    "exert through a plane on those behind it (columns force_x|y|z, "
                    "N or N/m in 2D; positive along the normal = tension across the "
                    "plane).")
    points: Optional[tuple[Position, Position]] = Field(
        None, description="strain: the gauge's two ends; each is the particle or node "
                          "nearest to it at the start.")
    point: Optional[Position] = Field(
        None, description="point: where the material point is (the nearest particle "
                          "or node at the start); section: a point of the plane.")
    normal: Optional[Direction] = Field(
        None, description="section: the plane's normal.")
    quantities: tuple[Literal[POINT_QUANTITIES], ...] = Field(
        ("displacement_x", "displacement_y", "displacement_z"),
        description="point: what is recorded.")
    body: Optional[reference_to("body", mesh_bodies=True)] = Field(
        None, description="Only the particles of this body, a [[body]] or the "
                          "particles of a [mesh.convert] (the mesh's name) or a "
                          "[mesh.sublayer] (<mesh>_sublayer) (default: every particle "
                          "and node).")
    mesh: Optional[reference_to("mesh")] = Field(
        None, description="Only the nodes of this mesh (default: every particle "
                          "and node).")
    every: Optional[quantity(TIME, "sampling interval", lo=0, lo_open=True)] = Field(
        None, description="Time between samples (absent: t_end / 1000).")

    @model_validator(mode="after")
    def _keys_of_the_type(self):
        needs = {"strain": ("points",), "point": ("point",),
                 "section": ("point", "normal")}[self.type]
        missing = [k for k in needs if getattr(self, k) is None]
        if missing:
            raise problem(f"a {self.type} gauge needs {' and '.join(missing)}",
                          f"give {', '.join(missing)}")
        extra = [k for k in ("points", "point", "normal")
                 if k not in needs and getattr(self, k) is not None]
        if self.type != "point" and \
                self.quantities != type(self).model_fields["quantities"].default:
            extra.append("quantities")
        if extra:
            raise problem(f"{', '.join(extra)} mean nothing to a {self.type} gauge",
                          f"remove {', '.join(extra)}")
        if self.body is not None and self.mesh is not None:
            raise problem("a gauge takes body or mesh, not both",
                          "keep one of them (or neither: every particle and node)")
        if self.points is not None and self.points[0] == self.points[1]:
            raise problem("the strain gauge's two points coincide",
                          "give two different points")
        return self
