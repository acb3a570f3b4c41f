"""Shapes of the deck: body geometries and selection regions ([set.region])."""

from typing import Annotated, Literal, Optional, Union

import numpy as np
from pydantic import AfterValidator, Field, ValidationInfo, field_validator, model_validator

from ...geometry.lattice import ogive_nose_length, polygon_area, read_points
from ..messages import problem, show_number
from ..scope import dimension
from ..units import LENGTH
from ..values import (Axis, Corner, Direction, ExistingFile, Position, PositiveLength,
                      Section, UpperCorner, UpperPosition, quantity, real)


class Box(Section):
    """Axis-aligned box."""

    shape: Literal["box"] = Field(description="Kind of shape.")
    lo: Position = Field(description="Lower corner.")
    hi: UpperPosition = Field(description="Upper corner, above lo in the first "
                                     "`dimension` components.")


class Sphere(Section):
    """Sphere (a disc in 2D)."""

    shape: Literal["sphere"] = Field(description="Kind of shape.")
    centre: Position = Field(description="Centre.")
    radius: PositiveLength = Field(description="Radius.")


def _axis_in_plane(axis: str) -> str:
    if dimension() == 2 and axis != "z":
        raise problem(f"axis '{axis}' is not allowed in 2D",
                      "use axis = \"z\" (the shape is a disc in the x-y plane)")
    return axis


def _length_in_3d(length: Optional[float]) -> Optional[float]:
    """A cylinder's or ring's length: required in 3D, refused in 2D."""
    dim = dimension()
    if length is None and dim == 3:
        raise problem("a cylinder, ring or prism in a 3D deck needs a length",
                      "add length = \"100 mm\" (or a number in metres)")
    if length is not None and dim == 2:
        raise problem("this key means nothing in a 2D deck (run.dimension = 2; a "
                      "cylinder, ring or prism is then a disc, annulus or polygon "
                      "in the x-y plane, per unit depth)",
                      "remove it, or set run.dimension = 3")
    return length


PlanarAxis = Annotated[Axis, AfterValidator(_axis_in_plane)]
AxialLength = Annotated[Optional[PositiveLength], AfterValidator(_length_in_3d)]


class Cylinder(Section):
    """Solid circular cylinder (a disc in 2D)."""

    shape: Literal["cylinder"] = Field(description="Kind of shape.")
    centre: Position = Field(description="Centre (mid-length on the axis).")
    radius: PositiveLength = Field(description="Radius.")
    length: AxialLength = Field(
        None, validate_default=True,
        description="Length along the axis; required in 3D, not allowed in 2D.")
    axis: PlanarAxis = Field("z", description="Axis direction; must be z "
                                              "in 2D.")
    tilt: Optional[real("tilt angle", lo=-180, hi=180)] = Field(
        None, description="3D: the cylinder (and its lattice) turned by this angle in "
        "degrees about tilt_axis through its centre (right-handed), e.g. a charge "
        "tilted from upright; a [[detonation]] point with rotate_with = this body "
        "turns with it.")
    tilt_axis: Axis = Field("y", description="Axis of the tilt (through the centre).")

    @field_validator("tilt")
    @classmethod
    def _tilt_in_3d(cls, tilt):
        if tilt is not None and dimension() in (1, 2):
            raise problem("tilt turns a cylinder in 3D only",
                          "remove tilt, or set run.dimension = 3")
        return tilt


class Ring(Section):
    """Hollow circular cylinder (an annulus in 2D)."""

    shape: Literal["ring"] = Field(description="Kind of shape.")
    centre: Position = Field(description="Centre (mid-length on the axis).")
    inner_radius: quantity(LENGTH, "radius", lo=0) = Field(
        description="Inner radius.")
    outer_radius: PositiveLength = Field(
        description="Outer radius, greater than inner_radius.")
    length: AxialLength = Field(
        None, validate_default=True,
        description="Length along the axis; required in 3D, not allowed in 2D.")
    axis: PlanarAxis = Field("z", description="Axis direction; must be z "
                                              "in 2D.")

    @field_validator("outer_radius")
    @classmethod
    def _above_inner(cls, outer, info: ValidationInfo):
        inner = info.data.get("inner_radius")
        if inner is not None and outer <= inner:
            raise problem(f"outer_radius {show_number(outer)} is not greater than "
                          f"inner_radius {show_number(inner)}",
                          "give an outer_radius greater than inner_radius")
        return outer


def _simple_polygon(points: tuple) -> tuple:
    """A prism's polygon: three or more vertices, no zero area, no crossing edges."""
    if len(points) < 3:
        raise problem(f"a prism's polygon needs at least 3 points, got {len(points)}",
                      "list the vertices in order, e.g. points = [[0, 0], [0.5, 0], "
                      "[0.5, 0.25], [0, 0.25]]")
    p = np.asarray(points, dtype=float)
    q = np.roll(p, -1, axis=0)
    area = polygon_area(p)
    size = float(np.max(p.max(axis=0) - p.min(axis=0)))
    if abs(area) <= 1e-12 * max(size, 1e-300) ** 2:
        raise problem("a prism's polygon has zero area (all points on a line)",
                      "give the vertices of the cross-section in order")
    k = len(p)

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    for i in range(k):
        for j in range(i + 2, k):
            if i == 0 and j == k - 1:
                continue  # adjacent through the closing edge
            a, b, c, d = p[i], q[i], p[j], q[j]
            if (cross(a, b, c) * cross(a, b, d) < 0 and
                    cross(c, d, a) * cross(c, d, b) < 0):
                raise problem(f"a prism's polygon crosses itself (edges {i + 1} and "
                              f"{j + 1})", "list the vertices in order around the "
                              "cross-section")
    return points


class PrismKeys(Section):
    """The keys of a prism: a polygon, its plane and the extrusion."""

    points: Annotated[tuple[tuple[quantity(LENGTH), quantity(LENGTH)], ...],
                      AfterValidator(_simple_polygon)] = Field(
        description="Polygon vertices [u, v] in order (either sense), in the plane "
                    "normal to axis: (x, y) for z, (y, z) for x, (z, x) for y. "
                    "Vertices on multiples of dx from the polygon's bounding box "
                    "give an exact volume.")
    axis: PlanarAxis = Field("z", description="Extrusion direction; must be z in 2D.")
    base: quantity(LENGTH) = Field(
        0.0, description="Start of the extrusion along the axis (3D).")
    length: AxialLength = Field(
        None, validate_default=True,
        description="Length of the extrusion; required in 3D, not allowed in 2D.")


class Prism(PrismKeys):
    """A polygon extruded along an axis (the polygon itself in 2D): an
    L-specimen, an I- or T-section."""

    shape: Literal["prism"] = Field(description="Kind of shape.")


def _in_3d(value):
    if dimension() in (1, 2):
        raise problem("an ogive projectile is a 3D shape",
                      "set run.dimension = 3, or use a cylinder or sphere")
    return value


class Ogive(Section):
    """A projectile: a circular cylinder with a tangent-ogive nose (3D), as in
    Forrestal et al.'s penetration tests."""

    shape: Literal["ogive"] = Field(description="Kind of shape.")
    tip: Annotated[Position, AfterValidator(_in_3d)] = Field(
        description="The nose's tip.")
    radius: PositiveLength = Field(description="Shank radius a.")
    length: PositiveLength = Field(description="Overall length, tip to tail.")
    crh: real("calibre-radius-head", lo=0.5) = Field(
        description="Calibre-radius-head psi = s/(2a), s the radius of the nose's "
        "arc (0.5: a hemispherical nose); the nose is a sqrt(4 psi - 1) long.")
    nose: Literal["+x", "-x", "+y", "-y", "+z", "-z"] = Field(
        "-z", description="The direction the nose points (the flight direction).")

    @field_validator("crh")
    @classmethod
    def _nose_fits(cls, crh, info: ValidationInfo):
        a, length = info.data.get("radius"), info.data.get("length")
        if a is not None and length is not None:
            nose = ogive_nose_length(a, crh)
            if nose > length * (1.0 + 1e-9):
                raise problem(f"the nose ({show_number(nose)} m long for crh = {crh:g}) "
                              f"is longer than the projectile ({show_number(length)} m)",
                              "give a longer length or a smaller crh")
        return crh


class Points(Section):
    """Particles at given positions (LS-DYNA's ``*ELEMENT_SPH``; ``sphdyn
    import`` writes them): a CSV file whose header names the columns ``x, y``
    (2D) or ``x, y, z`` (3D), one particle per row; other columns are
    ignored, lines starting with ``#`` too. Each particle stands for the
    volume ``dx**dimension`` of its body, as on a lattice. Bodies of points
    are not checked for overlapping other bodies (they have no closed
    shape); the domain and wall checks apply."""

    shape: Literal["points"] = Field(description="Kind of shape.")
    file: ExistingFile = Field(description="The CSV file of the positions.")
    length_unit: quantity(LENGTH, "length unit", lo=0, lo_open=True) = Field(
        1.0, description="Length of one file coordinate unit (\"1 mm\" for a file in "
                         "millimetres).")

    @model_validator(mode="after")
    def _readable(self):
        try:
            read_points(self.file, dimension() or 3, self.length_unit)
        except ValueError as e:
            raise problem(str(e), "write the file as a CSV with a header line x,y,z "
                          "(x,y in 2D) and one particle per row") from None
        return self


Geometry = Annotated[Union[Box, Cylinder, Ring, Sphere, Prism, Ogive, Points],
                     Field(discriminator="shape")]


class RegionBox(Section):
    """Axis-aligned selection box; in 2D its z-range may be any range
    containing z = 0, so the same box works in 2D and 3D decks."""

    shape: Literal["box"] = Field(description="Kind of shape.")
    lo: Corner = Field(description="Lower corner.")
    hi: UpperCorner = Field(description="Upper corner, above lo in the first "
                                   "`dimension` components.")

    @field_validator("hi")
    @classmethod
    def _z_range_holds_the_plane(cls, hi, info: ValidationInfo):
        lo = info.data.get("lo")
        if lo is not None and dimension() == 2 and not lo[2] <= 0 <= hi[2]:
            raise problem(f"the z-range [{show_number(lo[2])}, {show_number(hi[2])}] does "
                          "not contain the plane z = 0 of this 2D deck",
                          "give z-components with lo <= 0 <= hi, e.g. 0 and 0")
        return hi


class CylinderRegion(Section):
    """Circular cylinder region, infinite unless a length is given."""

    shape: Literal["cylinder"] = Field(description="Kind of shape.")
    centre: Position = Field(description="Centre (mid-length on the axis).")
    radius: PositiveLength = Field(description="Radius.")
    axis: Axis = Field("z", description="Axis direction.")
    length: Optional[PositiveLength] = Field(
        None, description="Length along the axis (absent: infinite); not allowed "
                          "with axis = \"z\" in 2D.")

    @field_validator("length")
    @classmethod
    def _length_along_a_plane_axis(cls, length, info: ValidationInfo):
        if length is not None and dimension() == 2 and info.data.get("axis") == "z":
            raise problem("a length along axis z means nothing in a 2D deck (every "
                          "particle lies in the plane z = 0)",
                          "remove length, or use axis = \"x\" or \"y\" to cut the "
                          "region along the plane")
        return length


class HalfSpace(Section):
    """Half-space: points with (x - point) . normal >= 0."""

    shape: Literal["halfspace"] = Field(description="Kind of shape.")
    point: Position = Field(description="A point on the bounding plane.")
    normal: Direction = Field(description="Normal pointing into the "
                                          "selected side (normalised).")


Region = Annotated[Union[RegionBox, Sphere, HalfSpace, CylinderRegion],
                   Field(discriminator="shape")]
