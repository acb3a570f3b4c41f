"""Deck sections [sph] (the SPH discretisation, with its sub-tables) and [contact].

[contact] is the penalty contact between particles of different bodies, which
total-Lagrangian bodies need because they see no other body through the SPH
sums.
"""

from typing import ClassVar, Literal, Optional

from pydantic import Field, StrictBool

from ..values import Section, integer, real


class Viscosity(Section):
    """[sph.viscosity]: Monaghan artificial viscosity."""

    alpha: real("viscosity coefficient", lo=0) = Field(
        1.0, description="Linear (bulk) coefficient alpha.")
    beta: real("viscosity coefficient", lo=0) = Field(
        2.0, description="Quadratic (von Neumann-Richtmyer) coefficient beta.")


class SmoothingLength(Section):
    """[sph.smoothing_length]: evolution of h."""

    mode: Literal["constant", "benz"] = Field(
        "constant", description="constant: h = h0; benz: dh/dt = h div(v)/d "
                                "(Benz 1989), d = dimension.")
    min_factor: real("factor", lo=0, hi=1, lo_open=True) = Field(
        0.5, description="Lower bound on h as a fraction of h0.")
    max_factor: real("factor", lo=1) = Field(
        2.0, description="Upper bound on h as a multiple of h0.")
    initial: Literal["nominal", "adaptive"] = Field(
        "nominal", description="h0 of each particle. nominal: h_factor times its "
        "body's dx (or its element's size); adaptive: h_factor times the local "
        "spacing (the distance to the dimension-th nearest particle), within "
        "[min_factor, max_factor] times the nominal h, for clustered or irregular "
        "particles (LS-DYNA's HMIN/HMAX idea; docs/theory.md). A lattice keeps its "
        "nominal h.")


class Neighbours(Section):
    """[sph.neighbours]: Verlet neighbour lists."""

    skin_factor: real("skin factor", lo=0) = Field(
        0.1, description="Verlet skin as a fraction of the initial support "
                         "radius; a list is rebuilt when its particles have "
                         "moved half the skin relative to their common "
                         "displacement (a body flying as a whole keeps its "
                         "list), or h has grown.")


class ArtificialStress(Section):
    """[sph.artificial_stress]: Monaghan (2000) artificial stress."""

    epsilon: real("artificial-stress factor", lo=0) = Field(
        0.0, description="epsilon: the repulsive stress is -epsilon times the "
                         "tensile principal stresses (0 = off; Gray et al. "
                         "2001 use 0.3). See docs/tensile-instability.md.")
    n: real("artificial-stress exponent", lo=0, lo_open=True) = Field(
        4.0, description="Exponent n of f = W(r)/W(dx) (Gray et al. 2001 "
                         "use 4).")


class Sph(Section):
    """[sph]: discretisation."""

    formulation: Literal["updated_lagrangian", "total_lagrangian"] = Field(
        "updated_lagrangian", description="Kernel formulation of every body "
        "that does not set its own: updated_lagrangian is the thesis's "
        "'Eulerian kernel' (neighbours and kernel gradients from current "
        "positions); total_lagrangian fixes neighbours and corrected kernel "
        "gradients in the initial configuration (no tensile instability; "
        "separate bodies then interact only through [contact]). See "
        "docs/tensile-instability.md.")
    moved: ClassVar[dict[str, str]] = {
        "hourglass": "hourglass_coefficient (as in [[mesh]], where hourglass "
                     "names the control's form)"}

    cfl: real("CFL number", lo=0, hi=1, lo_open=True) = Field(
        0.3, description="Factor on the particles' stable step (Courant number): "
        "dt = cfl * min(h / (c + |v|)) over the particles (the elements of a mesh "
        "have theirs: [[mesh]] cfl).")
    hourglass_coefficient: real("hourglass coefficient", lo=0) = Field(
        10.0, description="Ganzenmueller (2015) hourglass coefficient alpha "
                          "of total-Lagrangian bodies (0 = off; 10-50 "
                          "recommended). Unused by updated-Lagrangian bodies.")
    reference_update_every: integer("step count", lo=0) = Field(
        0, description="Total-Lagrangian bodies: make the current configuration "
                       "the new reference every this many steps (0 = never; "
                       "for large deformations; costs one neighbour build).")
    kernel: Literal["cubic_spline", "quintic_spline", "wendland_c2",
                    "wendland_c4", "gaussian", "quadratic"] = Field(
        "cubic_spline", description="Smoothing kernel.")
    h_factor: real("smoothing-length factor", lo=0, lo_open=True) = Field(
        1.2, description="Initial smoothing length h0 = h_factor * dx of the "
                         "body.")
    crack_band: real("crack band", lo=0, lo_open=True) = Field(
        1.0, description="Width of a crack in particle sizes: the length L = "
        "crack_band * dx over which a softening material (cscm) spreads its "
        "fracture energy, G_F = L * (the area under its post-peak stress-strain "
        "curve). 1 (the default): the particle size, as in the paper and the "
        "thesis, whose results the examples reproduce. An SPH tension crack "
        "softens two particle layers (h = 1.2 dx, 2D and 3D, any dx), so L = dx "
        "dissipates twice G_F per crack area and crack_band = 2 gives G_F (1.05-1.1 "
        "G_F measured, as a mesh's one element row): the choice where SPH "
        "concrete that cracks in tension is compared with a mesh (the I-girder). "
        "Crushing is spread over the same length and was not measured "
        "(docs/theory.md, 'Fracture energy of an SPH crack'). Mesh elements use "
        "their own size.")
    support_scale: real("support scale", lo=0, lo_open=True) = Field(
        1.0, description="kappa: the kernel is evaluated with kappa*h, so the "
                         "support radius is q_max * kappa * h.")
    correction: StrictBool = Field(
        False, description="Randles-Libersky renormalisation of kernel "
                           "gradients.")
    xsph: real("XSPH factor", lo=0, hi=1) = Field(
        0.0, description="XSPH velocity smoothing factor epsilon "
                         "(0 = off).")
    viscosity: Viscosity = Field(default_factory=Viscosity,
                                 description="Artificial viscosity.")
    smoothing_length: SmoothingLength = Field(
        default_factory=SmoothingLength,
        description="Evolution of the smoothing length.")
    neighbours: Neighbours = Field(default_factory=Neighbours,
                                   description="Neighbour search.")
    artificial_stress: ArtificialStress = Field(
        default_factory=ArtificialStress,
        description="Artificial stress against the tensile instability.")


class BodyContact(Section):
    """[contact]: penalty contact between particles of different bodies."""

    enabled: Optional[StrictBool] = Field(
        None, description="Particle-particle contact between bodies, for pairs with "
        "a total-Lagrangian particle (those see no other body through the SPH "
        "sums; updated-Lagrangian bodies meet through the kernel); default: on "
        "when the model has two or more bodies and one of them is "
        "total-Lagrangian.")
    distance_factor: real("contact distance factor", lo=0, lo_open=True) = Field(
        1.0, description="Particles of different bodies touch below "
        "distance_factor * (s_i + s_j)/2, s = initial particle size V0^(1/dim).")
    alpha: real("penalty factor", lo=0, lo_open=True) = Field(
        1.0, description="Penalty factor of the spring stiffness "
        "k = alpha * K * s^(dim-2) (K the pair's mean bulk modulus).")
