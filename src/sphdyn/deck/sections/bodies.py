"""Deck sections of the solids: [[body]] and the numerical heterogeneity.

[[body]] with its geometry and initial cracks ([[body.crack]]); the random
structure of bodies and materials: [body.mesostructure], [body.mass] and
[material.variation] (thesis sec. 7.2; docs/heterogeneity.md).
"""

from typing import Annotated, Literal, Optional, Union

from pydantic import BeforeValidator, Field, field_validator, model_validator

from ..expressions import ExpressionError, check_expression
from ..messages import problem, show, show_number
from ..scope import dimension
from ..units import LENGTH, RATE
from ..values import (Corner, Direction, ExistingFile, Position, PositiveLength, Section,
                      UpperCorner, Vector, VelocityVector, integer, name_of, quantity,
                      real, reference_to)
from .shapes import Geometry, PlanarAxis


#: Parameters of each mass law (the others must be absent).
_MASS_PARAMS = {"uniform": ("low", "high"), "normal": ("mean", "std"),
                "lognormal": ("sigma",), "poisson": ("lam",),
                "histogram": ("edges", "weights")}


class Mesostructure(Section):
    """[body.mesostructure]: concrete phases from fractal coherent noise.

    Aggregate, mortar and interfacial transition zone (ITZ) are generated
    on the body's particles (thesis sec. 7.2; docs/mesostructure.md) and
    each phase takes its own [[material]] (e.g. CSCM with different fc or
    density, or elastic aggregate in CSCM mortar). The field is seeded by run.seed and
    the body's index, so ensembles vary it through run.seed.
    """

    aggregate_fraction: Optional[real("volume fraction", lo=0, hi=1, lo_open=True,
                                      hi_open=True)] = Field(
        None, description="Target aggregate volume fraction (hit on the "
                          "particles to within one voxel). Required unless "
                          "photo is given (then measured from the photo).")
    max_aggregate_size: Optional[PositiveLength] = Field(
        None, description="Largest aggregate (equivalent diameter). Required "
                          "unless photo is given (then fitted to the photo).")
    photo: Optional[ExistingFile] = Field(
        None, description="Image of a concrete section (PNG, JPEG; relative "
                          "to the deck) from which aggregate_fraction and "
                          "max_aggregate_size are measured: Otsu segmentation, "
                          "area fraction = volume fraction, D_max fitted so "
                          "that sections of the generated structure have the "
                          "photo's 95th-percentile piece size "
                          "(docs/mesostructure.md).")
    pixel_size: Optional[PositiveLength] = Field(
        None, description="Size of one photo pixel (required with photo).")
    photo_aggregate: Literal["bright", "dark"] = Field(
        "bright", description="Whether aggregate is the bright or the dark "
                              "class of the photo.")
    itz_thickness: quantity(LENGTH, "thickness", lo=0) = Field(
        0.0, description="Thickness of the ITZ band around aggregate (0 = no "
                         "ITZ; at least about one particle spacing to be "
                         "resolved).")
    shape: Literal["rounded", "crushed"] = Field(
        "rounded", description="Aggregate shape: rounded (gravel) or "
                               "crushed (angular).")
    octaves: integer("octave count", lo=1, hi=8) = Field(
        3, description="Octaves of the fractional Brownian motion.")
    persistence: real("persistence", lo=0, hi=1, lo_open=True) = Field(
        0.5, description="Amplitude ratio of successive octaves.")
    lacunarity: real("lacunarity", lo=1, lo_open=True) = Field(
        2.0, description="Frequency ratio of successive octaves.")
    mortar: Optional[reference_to("material")] = Field(
        None, description="Material of the mortar (default: the body's).")
    aggregate: Optional[reference_to("material")] = Field(
        None, description="Material of the aggregate (default: the body's).")
    itz: Optional[reference_to("material")] = Field(
        None, description="Material of the ITZ (default: the mortar's).")

    @model_validator(mode="after")
    def _photo_or_targets(self):
        targets = [k for k in ("aggregate_fraction", "max_aggregate_size")
                   if getattr(self, k) is not None]
        if self.photo is not None:
            if self.pixel_size is None:
                raise problem("photo is given without pixel_size",
                              "add pixel_size = \"0.1 mm\" (the size of one pixel)")
            if targets:
                raise problem(f"{' and '.join(targets)} given together with photo",
                              "give either photo (the targets are measured from "
                              "it) or aggregate_fraction and max_aggregate_size")
            return self
        if self.pixel_size is not None:
            raise problem("pixel_size is given without photo",
                          "add photo = \"section.png\" or remove pixel_size")
        missing = [k for k in ("aggregate_fraction", "max_aggregate_size")
                   if getattr(self, k) is None]
        if missing:
            raise problem(f"{' and '.join(missing)} missing",
                          "give aggregate_fraction and max_aggregate_size, or "
                          "photo and pixel_size")
        return self


class MassField(Section):
    """[body.mass]: random particle masses (Husek et al. 2017, sec. 4).

    Mass factors f >= 0 (multiples of the homogeneous particle mass rho
    dx^d) are drawn from the distribution and rescaled so that the body's
    total mass is exactly the homogeneous one; density, lattice and
    smoothing length stay those of the homogeneous body, so the particle
    volume m/rho varies. Give exactly the parameters of the chosen
    distribution. The draw is seeded by run.seed and the body's index.
    """

    distribution: Literal["uniform", "normal", "lognormal", "poisson",
                          "histogram"] = Field(
        description="Law of the mass factors: uniform U[low, high]; normal "
                    "N(mean, std^2) truncated at 0; lognormal with ln f ~ "
                    "N(-sigma^2/2, sigma^2); poisson k/lam with k ~ "
                    "Poisson(lam); histogram: piecewise-constant density.")
    low: Optional[real("mass factor", lo=0)] = Field(
        None, description="uniform: lower bound (0 allows massless "
                          "particles, as in the paper).")
    high: Optional[real("mass factor", lo=0)] = Field(
        None, description="uniform: upper bound, at least low (low = high "
                          "gives the homogeneous body).")
    mean: Optional[real("mass factor", lo=0, lo_open=True)] = Field(
        None, description="normal: mean before truncation.")
    std: Optional[real("standard deviation", lo=0)] = Field(
        None, description="normal: standard deviation before truncation "
                          "(0 = homogeneous).")
    sigma: Optional[real("standard deviation", lo=0)] = Field(
        None, description="lognormal: standard deviation of ln f "
                          "(0 = homogeneous).")
    lam: Optional[real("Poisson mean", lo=0, lo_open=True)] = Field(
        None, description="poisson: mean count lambda; f = k/lambda, so "
                          "the coefficient of variation is lambda^-1/2.")
    edges: Optional[tuple[real("mass factor", lo=0), ...]] = Field(
        None, description="histogram: increasing bin edges of f.")
    weights: Optional[tuple[real("weight", lo=0), ...]] = Field(
        None, description="histogram: relative frequency of each bin "
                          "(one fewer than edges, not all zero).")

    @model_validator(mode="after")
    def _parameters_of_the_law(self):
        law = self.distribution
        need = _MASS_PARAMS[law]
        missing = [k for k in need if getattr(self, k) is None]
        extra = [k for p in _MASS_PARAMS.values() for k in p
                 if k not in need and getattr(self, k) is not None]
        if missing or extra:
            raise problem(
                f"distribution = \"{law}\" takes {' and '.join(need)}"
                + (f"; missing {', '.join(missing)}" if missing else "")
                + (f"; not used: {', '.join(extra)}" if extra else ""),
                f"give exactly {', '.join(need)} for a {law} distribution")
        if law == "uniform" and self.high < self.low:
            raise problem(f"high = {show_number(self.high)} is below low = "
                          f"{show_number(self.low)}", "give high >= low")
        if law == "histogram":
            e, w = self.edges, self.weights
            if len(e) < 2 or any(b <= a for a, b in zip(e[:-1], e[1:])):
                raise problem("the histogram edges are not an increasing list "
                              "of at least 2 values",
                              "give edges = [0, 0.5, 1, 1.5, 2] (increasing)")
            if len(w) != len(e) - 1 or sum(w) <= 0:
                raise problem(f"{len(w)} weights for {len(e) - 1} bins, or all "
                              "weights zero",
                              "give one non-negative weight per bin, not all zero")
        return self


class Variation(Section):
    """[material.variation]: random scatter of one parameter of a material.

    Thesis sec. 7.2: CSCM as the base material with the strength varied in
    the ITZ. The parameter is multiplied by a random factor of mean 1 and
    coefficient of variation cov (lognormal or normal), drawn once per run
    (scope = "sample") or per particle (scope = "particle", independent or
    correlated over correlation_length); per-particle factors are grouped
    into equal-probability classes, each refitted as a whole material (so
    varying CSCM fc also varies the fitted moduli, surfaces and fracture
    energies). Seeded by run.seed and the material's index;
    docs/mesostructure.md.
    """

    parameter: str = Field(
        description="Name of the varied parameter of this material, e.g. "
                    "\"fc\" (CSCM) or \"yield_stress\" (j2); it must be given "
                    "in the material (not density: use [body.mass]).")
    cov: real("coefficient of variation", lo=0, hi=1) = Field(
        description="Coefficient of variation of the factor (0 = no scatter).")
    distribution: Literal["lognormal", "normal"] = Field(
        "lognormal", description="Law of the factor, mean 1: lognormal, or "
                                 "normal kept above 0.05.")
    scope: Literal["sample", "particle"] = Field(
        "particle", description="One factor per run (sample) or one per "
                                "particle.")
    correlation_length: quantity(LENGTH, "correlation length", lo=0) = Field(
        0.0, description="scope = particle: correlation length l of a Gaussian "
                         "random field, correlation exp(-(r/l)^2); 0 = "
                         "independent particles.")
    classes: integer("class count", lo=2, hi=256) = Field(
        16, description="scope = particle: number of equal-probability "
                        "parameter classes (material groups) the factors are "
                        "rounded to.")

    @model_validator(mode="after")
    def _scope_options(self):
        if self.scope == "sample" and self.correlation_length > 0.0:
            raise problem("correlation_length is given with scope = \"sample\"",
                          "remove correlation_length (one factor per run has no "
                          "spatial structure) or use scope = \"particle\"")
        return self


class CrackPlane(Section):
    """[[body.crack]] shape = "plane": a planar crack (zero-mass particles).

    Particles closer than rows*dx/2 to the plane get zero mass (Husek et
    al. 2017, sec. 5.2); with radius, only those within radius of point.
    """

    shape: Literal["plane"] = Field(description="Kind of crack.")
    point: Position = Field(description="A point on the crack plane.")
    normal: Direction = Field(description="Normal of the crack plane.")
    rows: integer("row count", lo=1) = Field(
        1, description="Thickness in particle rows (half-width rows*dx/2).")
    radius: Optional[PositiveLength] = Field(
        None, description="Extent around point within the plane (absent: "
                          "the whole plane).")


class CrackPolyline(Section):
    """[[body.crack]] shape = "polyline": a crack along a polyline.

    Particles closer than rows*dx/2 to the polyline (distance measured in
    the plane normal to axis) get zero mass; in 3D the crack runs through
    the body along axis.
    """

    shape: Literal["polyline"] = Field(description="Kind of crack.")
    points: tuple[Position, ...] = Field(
        description="Corner points, at least 2 (their axis component is "
                    "ignored).")
    rows: integer("row count", lo=1) = Field(
        1, description="Thickness in particle rows (half-width rows*dx/2).")
    axis: PlanarAxis = Field("z", description="Direction along which the "
                                              "crack is extruded; z in 2D.")

    @field_validator("points")
    @classmethod
    def _two_points(cls, points):
        if len(points) < 2:
            raise problem(f"the polyline has {len(points)} point(s)",
                          "give at least 2 points")
        return points


class CrackBox(Section):
    """[[body.crack]] shape = "box": pre-fractured material in a box.

    Every particle inside the axis-aligned box gets zero mass.
    """

    shape: Literal["box"] = Field(description="Kind of crack.")
    lo: Corner = Field(description="Lower corner.")
    hi: UpperCorner = Field(description="Upper corner, above lo.")


Crack = Annotated[Union[CrackPlane, CrackPolyline, CrackBox],
                  Field(discriminator="shape")]


# Bodies, walls, sets, boundaries ----------------------------------------

def expression(value):
    """Before-validator: a number or an expression of x, y, z (SI result)."""
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise problem(f"{show(value)} is not an expression",
                      "give a number or a string such as \"2.0 * sin(pi * x / 0.4)\"")
    text = repr(float(value)) if not isinstance(value, str) else value
    try:
        check_expression(text)
    except ExpressionError as exc:
        raise problem(str(exc), "see [body.initial] in docs/deck-reference.md") from None
    return text


Expression = Annotated[str, BeforeValidator(expression)]
#: the stress components of [body.initial] stress
STRESS_COMPONENTS = ("xx", "yy", "zz", "xy", "xz", "yz")
#: the columns a [body.initial] file may hold, besides x, y, z
FILE_COLUMNS = ("vx", "vy", "vz") + tuple(f"s{c}" for c in STRESS_COMPONENTS)


class InitialFields(Section):
    """[body.initial]: initial velocity and stress that vary with position.

    Expressions of x, y, z [m] with SI results (velocity in m/s, stress in
    Pa, tension positive), or a CSV file of points with a header row naming
    x, y[, z] and any of vx, vy, vz, sxx, syy, szz, sxy, sxz, syz, taken at
    each particle from the nearest point or by linear interpolation. Applied
    before boundary conditions (a fixed set stays at rest). An expression may
    use x, y, z, numbers, pi, e, + - * / ** %, comparisons inside where(c, a,
    b), and sin, cos, tan, arcsin, arccos, arctan, arctan2, sinh, cosh, tanh,
    exp, log, log10, sqrt, abs, sign, floor, ceil, minimum, maximum, clip,
    hypot (NumPy's); nothing else, so a deck cannot run code.
    """

    velocity: Optional[Annotated[tuple[Expression, Expression, Expression],
                                 BeforeValidator(Vector())]] = Field(
        None, description="Initial velocity [m/s] as 3 expressions of x, y, z "
                          "(2 in a 2D deck), e.g. [\"0\", \"0.5 * sin(pi * x / "
                          "0.2)\", \"0\"]; replaces the body's velocity.")
    stress: Optional[dict[Literal["xx", "yy", "zz", "xy", "xz", "yz"], Expression]] = \
        Field(None, description="Initial Cauchy stress [Pa] by component "
                                "(xx, yy, zz, xy, xz, yz; absent components 0), "
                                "e.g. { yy = \"-2400 * 9.81 * (0.3 - y)\" }. "
                                "Updated-Lagrangian bodies of elastic or j2 "
                                "material.")
    file: Optional[ExistingFile] = Field(
        None, description="CSV file of points: header x, y[, z] and any of vx, vy, "
                          "vz, sxx, syy, szz, sxy, sxz, syz (SI). Its columns "
                          "must not repeat a velocity or stress given above.")
    interpolation: Literal["nearest", "linear"] = Field(
        "nearest", description="From the file's points to the particles: the "
                               "nearest point (within max_distance), or linear "
                               "interpolation on their Delaunay triangulation "
                               "(particles outside it are refused).")
    max_distance: Optional[PositiveLength] = Field(
        None, description="Nearest interpolation: the farthest a particle may be "
                          "from its point (default: the body's dx).")

    @model_validator(mode="after")
    def _something_given(self):
        if self.velocity is None and self.stress is None and self.file is None:
            raise problem("[body.initial] gives neither velocity, stress nor file",
                          "give at least one of them, or remove the table")
        return self


class Body(Section):
    """[[body]]: a solid filled with particles on a lattice."""

    name: name_of("body") = Field(description="Name of the body.")
    material: reference_to("material") = Field(
        description="Name of a [[material]].")
    dx: quantity(LENGTH, "particle spacing", lo=0, lo_open=True) = Field(
        description="Particle spacing of the lattice.")
    velocity: VelocityVector = Field(
        (0.0, 0.0, 0.0), description="Initial velocity.")
    geometry: Geometry = Field(description="Shape filled with particles.")
    formulation: Optional[Literal["updated_lagrangian", "total_lagrangian"]] = \
        Field(None, description="Kernel formulation of this body; default: "
                                "[sph] formulation.")
    artificial_stress: Optional[real("artificial-stress factor", lo=0)] = Field(
        None, description="Artificial-stress epsilon of this body (0 = off "
                          "for it); default: [sph.artificial_stress] epsilon. "
                          "Updated-Lagrangian bodies only.")
    mesostructure: Optional[Mesostructure] = Field(
        None, description="Aggregate / mortar / ITZ phases with their own "
                          "materials (absent: one material).")
    mass: Optional[MassField] = Field(
        None, description="Random particle masses (absent: homogeneous, "
                          "m = rho dx^d); see docs/heterogeneity.md.")
    crack: tuple[Crack, ...] = Field(
        (), description="Initial cracks: their particles get zero mass; "
                        "use a wall with stiffness = \"bulk\".")
    initial: Optional[InitialFields] = Field(
        None, description="Initial velocity and stress varying with position "
                          "(expressions or a file).")
    damping: quantity(RATE, "damping coefficient", lo=0) = Field(
        0.0, description="Mass-proportional damping c [1/s] of the body's particles "
                         "(a = -c v) for quasi-static loading, as [[mesh]] damping.")

    @model_validator(mode="after")
    def _one_dimensional(self):
        """A 1D deck fills boxes (segments along x) and updates its particles'
        reference (the total-Lagrangian passes are 2D and 3D only)."""
        if dimension() != 1:
            return self
        if self.geometry.shape != "box":
            raise problem(f"geometry.shape '{self.geometry.shape}' in a 1D deck "
                          "(run.dimension = 1)", "use shape = \"box\" with lo = [x0], "
                          "hi = [x1]")
        if self.formulation == "total_lagrangian" or self.mesostructure is not None:
            raise problem("a 1D deck has updated-Lagrangian bodies without "
                          "mesostructure", "remove formulation and mesostructure, or "
                          "use run.dimension = 2 or 3")
        return self

    @model_validator(mode="after")
    def _mesostructure_resolved(self):
        """The aggregate and the ITZ must be resolved by the body's dx."""
        ms = self.mesostructure
        if ms is None:
            return self
        if ms.max_aggregate_size is not None and ms.max_aggregate_size < 2 * self.dx:
            raise problem(f"mesostructure.max_aggregate_size "
                          f"{show_number(ms.max_aggregate_size)} m is below 2 dx = "
                          f"{show_number(2 * self.dx)} m",
                          "refine dx or give a larger max_aggregate_size")
        if 0 < ms.itz_thickness < self.dx * (1 - 1e-9):
            raise problem(f"mesostructure.itz_thickness {show_number(ms.itz_thickness)} "
                          f"m is below dx = {show_number(self.dx)} m",
                          "give itz_thickness = 0 (no ITZ) or at least dx, or refine dx")
        return self
