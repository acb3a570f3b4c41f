"""Deck section [[mesh]]: finite-element parts and the regions turned into particles.

A mesh is a generated block of hexahedra (3D) or plane-strain quadrilaterals
(2D) ([mesh.block]), a generated prism of them (a polygon section extruded,
[mesh.prism]), a generated line of beams or trusses ([mesh.line]), or a
Gmsh / Abaqus file (``file``). Its elements use the deck's materials through
the same point functions as particles (docs/theory.md, "Solid finite elements").
[mesh.convert] replaces the elements of a region by SPH particles (one per
element, at its centroid, with its volume and mass; thesis ch. 4) and couples
them to the remaining mesh. [mesh.erosion] lets elements erode during the
run by their material's [material.erosion] rules, deleted or turned into SPH
particles (thesis 5.3). [mesh.contact] makes the particles of every body
meet the mesh's faces (an SPH projectile on a finite-element target).
"""

from typing import Literal, Optional

from pydantic import Field, model_validator

from ..messages import problem
from ..units import LENGTH, RATE
from ..values import (Direction, ExistingFile, Position, PositiveLength, Section,
                      UpperPosition, VelocityVector, integer, name_of, quantity, real,
                      reference_to)
from ..scope import dimension
from .shapes import PrismKeys, Region

#: Elements of a generated block or a file, by dimension.
SOLID_ELEMENTS = {3: "hex8", 2: "quad4"}
LINE_ELEMENTS = ("beam", "truss")


class AxisGrading(Section):
    """One axis of [mesh.block] grading: element sizes growing geometrically
    away from where they are smallest (a bias, as LS-DYNA's and Gmsh's
    progressions)."""

    ratio: real("size ratio", lo=1) = Field(
        description="Largest element size over the smallest on this axis (1: equal).")
    smallest: Literal["lo", "hi", "centre"] = Field(
        "lo", description="Where the smallest elements are: at lo, at hi, or in the "
                          "middle (sizes growing towards both ends).")


class BlockMesh(Section):
    """[mesh.block]: a structured block of hexahedra (3D) or quadrilaterals (2D)."""

    lo: Position = Field(description="Lower corner.")
    hi: UpperPosition = Field(description="Upper corner, above lo in every used "
                                          "component.")
    divisions: tuple[integer("element count", lo=1), ...] = Field(
        description="Elements along x, y (and z in 3D), e.g. [40, 4, 4].")
    grading: Optional[tuple[AxisGrading, ...]] = Field(
        None, description="Element sizes graded along each axis (absent: equal "
                          "elements): one { ratio, smallest } per axis, the "
                          "sizes growing by a constant factor away from where "
                          "they are smallest, the largest ratio times the "
                          "smallest, e.g. a target refined about its shot line "
                          "and under its face: [{ ratio = 3, smallest = "
                          "\"centre\" }, { ratio = 3, smallest = \"centre\" }, "
                          "{ ratio = 3, smallest = \"hi\" }].")

    @model_validator(mode="after")
    def _one_per_axis(self):
        dim = dimension()
        if dim is not None and len(self.divisions) != dim:
            raise problem(f"divisions has {len(self.divisions)} entries in a {dim}D deck",
                          f"give {dim} element counts, one per axis")
        if dim is not None and self.grading is not None and len(self.grading) != dim:
            raise problem(f"grading has {len(self.grading)} entries in a {dim}D deck",
                          f"give {dim}, one per axis ({{ ratio = 1 }} for an equal axis)")
        return self

    @property
    def axis_grading(self):
        """(ratio, smallest) per axis, or None (equal elements)."""
        return None if self.grading is None else [(g.ratio, g.smallest)
                                                  for g in self.grading]


class PrismMesh(PrismKeys):
    """[mesh.prism]: a polygon extruded along an axis, meshed by a grid of hexahedra
    (3D; quadrilaterals of the polygon in 2D): an I-, T- or L-section member.

    The elements of the grid over the polygon's bounding box whose centres
    lie in the polygon; with element_size equal to a prism body's dx (and
    the polygon's extents multiples of it) the element centres are that
    body's particles, so an SPH model and its FEM reference share the
    geometry (thesis 6.1)."""

    element_size: PositiveLength = Field(
        description="Element edge: each direction gets the nearest whole number of "
                    "equal elements.")


class LineMesh(Section):
    """[mesh.line]: beam or truss elements along a straight line (start, end) or a
    polyline through points (a bent bar; closed: a stirrup), optionally repeated
    at a constant step (stirrups along a beam)."""

    start: Optional[Position] = Field(None, description="First node (a straight line; "
                                                        "or give points).")
    end: Optional[Position] = Field(None, description="Last node (a straight line).")
    points: Optional[tuple[Position, ...]] = Field(
        None, description="Corners of a polyline, at least 2 (3 if closed), instead of "
                          "start and end.")
    closed: bool = Field(False, description="Join the last point to the first (a "
                                            "closed stirrup; points only).")
    divisions: Optional[integer("element count", lo=1)] = Field(
        None, description="Number of elements on each segment (or give element_length).")
    element_length: Optional[PositiveLength] = Field(
        None, description="Element length: each segment gets the nearest whole number "
                          "of equal elements (or give divisions).")
    repeat: integer("copy count", lo=1) = Field(
        1, description="Number of copies of the line, each shifted by step from the "
                       "last (stirrups along a beam).")
    step: Optional[Position] = Field(
        None, description="Shift between copies (with repeat > 1).")

    @model_validator(mode="after")
    def _has_length(self):
        straight = self.start is not None or self.end is not None
        if straight == (self.points is not None):
            raise problem("a line needs start and end, or points (one of them)",
                          "give start = [...] and end = [...] for a straight bar, or "
                          "points = [[...], [...], ...] for a polyline")
        if straight and (self.start is None or self.end is None):
            raise problem("a straight line needs both start and end",
                          f"add {'end' if self.end is None else 'start'} = [...]")
        if straight and self.closed:
            raise problem("closed joins the points of a polyline",
                          "give points = [[...], ...] or remove closed")
        corners = self.corners
        need = 3 if self.closed else 2
        if len(corners) < need:
            raise problem(f"a {'closed ' if self.closed else ''}polyline needs at least "
                          f"{need} points, got {len(corners)}",
                          f"give {need} or more points")
        for k, (p, q) in enumerate(self.segments_ends):
            if p == q:
                raise problem("start and end are the same point" if straight else
                              f"points {k} and {(k + 1) % len(corners)} are the same",
                              "give distinct consecutive points" if not straight else
                              "give two different end points of the line")
        if (self.divisions is None) == (self.element_length is None):
            raise problem("a line needs divisions or element_length (one of them)",
                          "give divisions = 20 or element_length = \"25 mm\"")
        if self.repeat > 1 and (self.step is None or not any(self.step)):
            raise problem(f"repeat = {self.repeat} needs a nonzero step between the copies",
                          "add step = [\"100 mm\", 0, 0]")
        if self.repeat == 1 and self.step is not None:
            raise problem("step means nothing without repeat > 1",
                          "remove step or give repeat = 2 or more")
        return self

    @property
    def corners(self) -> list:
        """The polyline's points (start and end for a straight line)."""
        return list(self.points) if self.points is not None else [self.start, self.end]

    @property
    def segments_ends(self) -> list:
        """(first, last) point of each segment."""
        c = self.corners
        return [(c[k], c[(k + 1) % len(c)]) for k in range(len(c) if self.closed else
                                                             len(c) - 1)]

    @property
    def counts(self) -> list[int]:
        """Elements on each segment."""
        if self.divisions is not None:
            return [self.divisions] * len(self.segments_ends)
        return [max(1, round(sum((a - b) ** 2 for a, b in zip(p, q)) ** 0.5
                             / self.element_length)) for p, q in self.segments_ends]

    @property
    def count(self) -> int:
        """The number of elements, copies included."""
        return self.repeat * sum(self.counts)


class BeamSection(Section):
    """[mesh.section]: the cross-section of beams and trusses."""

    shape: Literal["rectangle", "circle"] = Field(description="Section shape.")
    width: Optional[PositiveLength] = Field(
        None, description="Rectangle: side along the section's local y (the "
                          "orientation vector).")
    height: Optional[PositiveLength] = Field(
        None, description="Rectangle: side along the section's local z "
                          "(line direction x orientation).")
    diameter: Optional[PositiveLength] = Field(None, description="Circle: diameter.")
    orientation: Direction = Field(
        (0.0, 0.0, 1.0), description="The section's local y direction (beams); "
                                     "must not be parallel to the line.")

    @model_validator(mode="after")
    def _dimensions_of_shape(self):
        need = {"rectangle": ("width", "height"), "circle": ("diameter",)}[self.shape]
        other = [k for k in ("width", "height", "diameter")
                 if k not in need and getattr(self, k) is not None]
        missing = [k for k in need if getattr(self, k) is None]
        if missing:
            example = " and ".join(f'{k} = "100 mm"' for k in missing)
            raise problem(f"a {self.shape} section needs {' and '.join(missing)}",
                          f"add {example}")
        if other:
            raise problem(f"{', '.join(other)} means nothing for a {self.shape} section",
                          f"remove {', '.join(other)}")
        return self


class MeshGroup(Section):
    """[[mesh.group]]: the material of a physical group / element set of the file."""

    name: str = Field(description="Name of the group in the file (Gmsh physical "
                                  "group, Abaqus ELSET).")
    material: reference_to("material") = Field(description="Its material.")


class PenaltyKeys(Section):
    """The penalty coupling's keys of [mesh.convert] and [mesh.erosion]: particles
    against the element faces with the wall's spring."""

    stiffness: Literal["mass", "bulk"] = Field(
        "mass", description="Penalty stiffness: mass: k = alpha m/dt^2 (paper eq. 8, m "
                            "the smaller of the particle's and the face point's mass); "
                            "bulk: k = alpha K A/L (eq. 9).")
    alpha: real("penalty factor", lo=0, lo_open=True) = Field(
        0.1, description="Penalty factor alpha.")
    friction: real("friction coefficient", lo=0) = Field(
        0.0, description="Coulomb friction coefficient of the penalty coupling.")
    thickness_factor: real("thickness factor", lo=0, lo_open=True) = Field(
        0.5, description="Penalty contact thickness in units of the particle size "
                         "V^(1/d).")
    stiffness_step: Literal["current", "largest"] = Field(
        "current", description="The step dt of the mass stiffness k = alpha m/dt^2: "
                               "current: the step of each evaluation (a spring that "
                               "stiffens as the step drops pushes harder but keeps its "
                               "energy); largest: the largest stable step so far, so a "
                               "spring never stiffens when the step drops (as elements "
                               "crush). docs/theory.md, 'SPH-FEM coupling by penalty', "
                               "has what each did in the 800 m/s penetration run.")


class MeshContact(PenaltyKeys):
    """[mesh.contact]: the particles of every body meet the mesh's exterior faces
    by penalty (an SPH projectile or impactor on a finite-element target).

    Particles are slave nodes, the element faces the master surface, which
    follows erosion (the faces an eroded element exposes take part); the
    debris of [mesh.erosion] meets the mesh through it too. With ``meshes``
    the nodes of other solid meshes meet the faces as well (node-to-surface
    contact between meshes, as LS-DYNA's *CONTACT_AUTOMATIC_NODES_TO_SURFACE
    with those meshes as the slave side): a drop weight meshed on a meshed
    beam. A node is a slave as a particle is, with the size of its elements
    for the contact thickness (``thickness_factor`` times it: the meshes meet
    that far apart) and the mass spring of the smaller of the node's and the
    face point's masses.
    """

    meshes: tuple[reference_to("mesh"), ...] = Field(
        (), description="Solid meshes whose nodes meet this mesh's faces too "
                        "(node-to-surface contact, the listed meshes as slaves; history "
                        "columns F_<mesh>_contact_<slave>). Make the finer mesh the slave.")


class Convert(PenaltyKeys):
    """[mesh.convert]: elements of a region become SPH particles, coupled to the rest.

    One particle per element, at its centroid, with the element's volume and
    mass (thesis ch. 4); the particles form a body named like the mesh, with
    the [sph] settings; h = sph.h_factor times V^(1/d).
    """

    region: Region = Field(description="Elements whose centroid lies in this region "
                                        "become particles.")
    coupling: Literal["penalty", "tied", "hybrid", "none"] = Field(
        "penalty", description="How the particles meet the remaining mesh (thesis ch. 4): "
        "penalty: particles against the element faces with the wall's spring (with "
        "tie_factor the first layer tied by bilateral springs); tied: the particles "
        "within tie_factor sizes of a face move with it (constraint: their mass and "
        "force go to the face's nodes); hybrid: the first layer of remaining elements "
        "gets particles at its integration points that move with it and meet the "
        "other particles through the kernel; none.")
    tie_factor: real("tie distance factor", lo=0) | None = Field(
        None, description="Particles within tie_factor sizes V^(1/d) of a face at the "
                          "start are tied to it. Penalty coupling: default 0 = contact "
                          "only (the interface opens under tension); > 0 ties by "
                          "bilateral springs (tension and shear carried, as LS-DYNA's "
                          "tied offset contact). Tied coupling: default 1.0, the first "
                          "particle layer (half a size from the face).")

    @model_validator(mode="after")
    def _coupling_keys(self):
        own = {"penalty": ("stiffness", "alpha", "friction", "thickness_factor",
                           "stiffness_step", "tie_factor"),
               "tied": ("tie_factor",), "hybrid": (), "none": ()}[self.coupling]
        given = [k for k in ("stiffness", "alpha", "friction", "thickness_factor",
                             "stiffness_step", "tie_factor")
                 if k not in own and getattr(self, k) != type(self).model_fields[k].default]
        if given:
            raise problem(f"{', '.join(given)} do not belong to coupling = "
                          f"\"{self.coupling}\"",
                          f"remove {', '.join(given)}, or choose the coupling they belong "
                          "to (tie_factor: penalty or tied; the others: penalty)")
        if self.coupling == "tied" and self.tie_factor == 0.0:
            raise problem("tie_factor = 0 ties no particle in the tied coupling",
                          "give tie_factor > 0 (1.0 ties the first particle layer) or "
                          "leave it out")
        return self


class Sublayer(Section):
    """[mesh.sublayer]: the bar's nodes are also SPH particles in the concrete (thesis 6.1).

    Every node of the line becomes a particle of the bar's material that
    moves with it (one degree of freedom); the particles meet the concrete
    particles through their overlapping supports. They form a body named
    ``<mesh>_sublayer`` (updated-Lagrangian) with h = sph.h_factor times the
    element length, or ``smoothing_length``.
    """

    mass_ratio: real("mass ratio", lo=0, hi=1, lo_open=True, hi_open=True) = Field(
        0.5, description="The particles' share of the bar's mass (0 < r < 1; the "
                         "elements carry 1 - r). Equal (0.5) by default, as the thesis "
                         "found best.")
    smoothing_length: Optional[PositiveLength] = Field(
        None, description="The particles' smoothing length h (default: sph.h_factor "
                          "times the bar's mean element length, as LS-DYNA sizes an "
                          "SPH part from its own spacing). A pair with a concrete "
                          "particle takes the mean of the two h, so this sets how far "
                          "into the concrete the bar reaches (docs/validation.md, "
                          "\"The full 5.0 m beam is punched through\").")
    body: Optional[reference_to("body", mesh_bodies=True)] = Field(
        None, description="The concrete body the bar lies in (a [[body]] or a "
                          "[mesh.convert]'s particles, named as the mesh; default: any "
                          "[[body]]): every "
                          "node must have one of its particles within its support.")
    stiffness: Literal["material", "split", "axial", "none"] = Field(
        "material", description="material: the particles carry their material's "
        "stress, so the bar's stiffness also acts through the kernel (each line of "
        "particles is a second bar of area mass_ratio A rho_steel / rho_concrete); "
        "split: the bar's stiffness and strength are split as its mass, the elements "
        "carry 1 - mass_ratio of them and the particles mass_ratio (their stresses "
        "scaled by rho_concrete / rho_steel), so the bar counts once; "
        "axial: split, and the particles' stress acts along the bar only (a uniaxial "
        "stress from the strain rate along the bar, as the elements': no transverse "
        "or shear stiffness of steel in the concrete); "
        "none: coupling only, the particles carry no stress and the bar's stiffness "
        "is counted once, in the elements (docs/examples.md, \"igirder\").")


class MeshErosion(PenaltyKeys):
    """[mesh.erosion]: elements erode by their material's [material.erosion] rules.

    ``to = "particles"``: each eroded element becomes SPH particles with its
    mass, momentum, energy, stress and history (thesis 5.3), in a body named
    ``<mesh>_debris`` (updated-Lagrangian, the [sph] settings), which meets the
    remaining elements through a penalty coupling (that of [mesh.contact] or
    the [mesh.convert] penalty coupling if there is one: then this table's
    penalty keys are not used). ``to = "nothing"``: LS-DYNA's plain
    erosion; the mass and energy lost are in the history.
    """

    to: Literal["particles", "nothing"] = Field(
        "particles", description="What an eroded element becomes: SPH particles, or "
                                 "nothing (deleted).")
    particles_per_element: Literal[1, 8] = Field(
        1, description="Particles per eroded element: 1 at its centre or 8 at the "
                       "octants' centres (4 quadrants in 2D).")
    every: integer("step interval", lo=1) = Field(
        1, description="Check the rules every this many steps.")

    @model_validator(mode="after")
    def _coupling_keys(self):
        if self.to == "nothing":
            given = [k for k in ("particles_per_element", "stiffness", "alpha", "friction",
                                 "thickness_factor", "stiffness_step")
                     if getattr(self, k) != type(self).model_fields[k].default]
            if given:
                raise problem(f"{', '.join(given)} mean nothing with to = \"nothing\"",
                              f"remove {', '.join(given)}, or set to = \"particles\"")
        return self


class Mesh(Section):
    """[[mesh]]: a finite-element part."""

    name: name_of("mesh") = Field(description="Name of the mesh (output block, "
                                              "history columns).")
    material: Optional[reference_to("material")] = Field(
        None, description="Material of the elements (of those not in a "
                          "[[mesh.group]]). Required unless groups cover the file.")
    block: Optional[BlockMesh] = Field(None, description="A generated block of solid "
                                                         "elements.")
    prism: Optional[PrismMesh] = Field(
        None, description="A generated prism (I-, T-, L-section) of solid elements.")
    line: Optional[LineMesh] = Field(None, description="A generated line of beams or "
                                                       "trusses.")
    file: Optional[ExistingFile] = Field(
        None, description="A mesh file: Gmsh .msh (2.2 or 4.1) or Abaqus .inp, "
                          "relative to the deck; hex8 in 3D, quad4 in 2D.")
    length_unit: quantity(LENGTH, "length unit", lo=0, lo_open=True) = Field(
        1.0, description="Length of one file coordinate unit (\"1 mm\" for a file "
                         "in millimetres).")
    translate: Position = Field(
        (0.0, 0.0, 0.0), description="Shift of a file's nodes, after length_unit "
                                     "(LS-DYNA's *PART_MOVE): places a mesh file "
                                     "in the model without rewriting it.")
    group: tuple[MeshGroup, ...] = Field(
        (), description="Materials of the file's element groups.")
    element: Optional[Literal["beam", "truss"]] = Field(
        None, description="Element of a [mesh.line]: beam (co-rotational, elastic) "
                          "or truss (any material, uniaxial stress).")
    section: Optional[BeamSection] = Field(None, description="Cross-section of a "
                                                             "[mesh.line].")
    integration: Literal["one_point", "selective_reduced"] = Field(
        "one_point", description="Solid elements: one_point (uniform strain with "
                                 "hourglass control, LS-DYNA's default) or "
                                 "selective_reduced (fully integrated, B-bar).")
    hourglass: Literal["viscous", "stiffness"] = Field(
        "viscous", description="Flanagan-Belytschko hourglass control form "
                               "(one_point).")
    hourglass_coefficient: real("hourglass coefficient", lo=0, hi=0.15) = Field(
        0.1, description="Hourglass coefficient Q_hg (LS-DYNA QH; 0 = off). At most "
                         "0.15 (LS-DYNA's advice for its viscous forms). The element "
                         "step includes its damping or stiffness: none in an "
                         "undistorted element up to 0.15, a joint step in a "
                         "distorted one (docs/theory.md).")
    q1: real("quadratic bulk viscosity", lo=0) = Field(
        1.5, description="Quadratic bulk-viscosity coefficient.")
    q2: real("linear bulk viscosity", lo=0) = Field(
        0.06, description="Linear bulk-viscosity coefficient.")
    cfl: real("element step factor", lo=0, hi=1, lo_open=True) = Field(
        0.9, description="Factor on the element stable step (LS-DYNA TSSFAC; the "
                         "particles have theirs: [sph] cfl).")
    velocity: VelocityVector = Field((0.0, 0.0, 0.0),
                                     description="Initial velocity of the nodes.")
    damping: quantity(RATE, "damping coefficient", lo=0) = Field(
        0.0, description="Mass-proportional damping c [1/s] on every node "
                         "(a = -c v; 2 omega damps a mode of angular frequency "
                         "omega critically): for quasi-static loading.")
    convert: Optional[Convert] = Field(
        None, description="A region of elements replaced by SPH particles.")
    erosion: Optional[MeshErosion] = Field(
        None, description="Elements erode during the run ([mesh.erosion]).")
    contact: Optional[MeshContact] = Field(
        None, description="Particles of every body meet this mesh's faces by penalty "
                          "([mesh.contact]; solid meshes).")
    embed: Optional[reference_to("mesh")] = Field(
        None, description="A bar embedded in this solid mesh: each node moves with "
                          "the element it lies in (perfect bond, LS-DYNA's "
                          "CONSTRAINED_BEAM_IN_SOLID); line meshes.")
    sublayer: Optional[Sublayer] = Field(
        None, description="A bar inside SPH concrete, coupled by its nodes' particles "
                          "([mesh.sublayer], line meshes).")

    @model_validator(mode="after")
    def _one_source(self):
        given = [k for k in ("block", "prism", "line", "file") if getattr(self, k) is not None]
        if len(given) != 1:
            raise problem(
                "a mesh needs exactly one source" + (
                    f" (got {', '.join(given)})" if given else ""),
                "give one of [mesh.block], [mesh.prism], [mesh.line] or "
                "file = \"part.msh\"")
        if self.line is not None:
            if self.element is None or self.section is None:
                raise problem("a [mesh.line] needs element and [mesh.section]",
                              "add element = \"beam\" (or \"truss\") and a "
                              "[mesh.section] table")
            if self.convert is not None:
                raise problem("only solid elements can be converted to particles",
                              "remove [mesh.convert] from the line mesh")
            if self.erosion is not None:
                raise problem("only solid elements erode",
                              "remove [mesh.erosion] from the line mesh")
            if self.contact is not None:
                raise problem("particles meet the faces of solid elements",
                              "remove [mesh.contact] from the line mesh")
        elif self.sublayer is not None or self.embed is not None:
            raise problem("a sublayer or an embedding couples bars (a [mesh.line] of "
                          "beams or trusses)", "remove [mesh.sublayer] and embed, or make "
                          "the mesh a [mesh.line]")
        else:
            extra = [k for k in ("element", "section") if getattr(self, k) is not None]
            if extra:
                raise problem(f"{', '.join(extra)} belong to a [mesh.line]",
                              f"remove {', '.join(extra)} (solid elements: hex8 in 3D, "
                              "quad4 in 2D)")
        if self.sublayer is not None and self.embed is not None:
            raise problem("a bar is either in SPH concrete ([mesh.sublayer]) or in "
                          "solid elements (embed)", "keep one of them")
        if self.file is None and any(self.translate):
            raise problem("translate moves a mesh file's nodes",
                          "give a generated mesh its coordinates directly, or remove "
                          "translate")
        if self.group and self.file is None:
            raise problem("[[mesh.group]] names groups of a mesh file",
                          "remove [[mesh.group]] or read the mesh from a file")
        if self.material is None and not self.group:
            raise problem("the mesh has no material", "add material = \"<name>\"")
        if (self.contact is not None and self.convert is not None
                and self.convert.coupling == "penalty"):
            raise problem("[mesh.convert]'s penalty coupling already makes every particle "
                          "meet the mesh's faces", "remove [mesh.contact] (give its keys "
                          "in [mesh.convert])")
        if self.contact is not None and self.erosion is not None:
            given = [k for k in PenaltyKeys.model_fields
                     if getattr(self.erosion, k) != PenaltyKeys.model_fields[k].default]
            if given:
                raise problem(f"erosion's {', '.join(given)}: the debris meets the mesh "
                              "through [mesh.contact]", f"give {', '.join(given)} in "
                              "[mesh.contact] and remove them from [mesh.erosion]")
        if (self.erosion is not None and self.erosion.to == "particles"
                and self.convert is not None and self.convert.coupling in ("tied", "hybrid")):
            raise problem(f"erosion into particles with coupling = "
                          f"\"{self.convert.coupling}\" of [mesh.convert]",
                          "use coupling = \"penalty\" (the debris meets the mesh by "
                          "penalty), or erosion to = \"nothing\"")
        return self
