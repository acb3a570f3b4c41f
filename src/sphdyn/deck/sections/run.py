"""Deck sections [run], [time] and [domain]: what is simulated, how it steps."""

from typing import Annotated, ClassVar, Literal, Optional

from pydantic import AfterValidator, BeforeValidator, Field, StrictStr

from ..units import TIME
from ..values import (AccelerationVector, Bounds, Position, Section, UpperPosition,
                      integer, memory_size, quantity, real, reference_to)


class Run(Section):
    """[run]: what is simulated and for how long."""

    title: StrictStr = Field("", description="Free text naming the run; "
                             "copied into the outputs.")
    dimension: Literal[1, 2, 3] = Field(
        description="1 = uniaxial strain along x, quantities per unit cross-section "
                    "(masses in kg/m^2; box bodies, no meshes, updated-Lagrangian: "
                    "shock tubes, detonation fronts, flyer plates); 2 = plane "
                    "strain, quantities per unit depth (masses in kg/m); 3 = "
                    "three-dimensional.")
    t_end: quantity(TIME, "end time", lo=0, lo_open=True) = Field(
        description="Simulated end time.")
    gravity: Optional[AccelerationVector] = Field(
        None, description="Acceleration of gravity, a body load on every particle and "
                          "node with mass, e.g. [0, 0, \"-9.81 m/s^2\"] (absent: none). "
                          "Its work is external work (W_external, and W_gravity in the "
                          "history); no initial stress from it is computed: the bodies "
                          "start unloaded and settle (add mesh damping for a static "
                          "start).")
    seed: integer("seed", lo=0) = Field(
        0, description="Seed of the random number generator (lattice "
                       "jitter, random material properties).")
    memory_limit: Optional[Annotated[float, BeforeValidator(memory_size), AfterValidator(
        Bounds(lo=0, lo_open=True, noun="memory size"))]] = Field(
        None, description="Largest model the deck may build, e.g. \"8 GiB\" (decimal "
                          "kB, MB, GB or binary KiB, MiB, GiB; a number is bytes). "
                          "The particle count and memory are estimated from the "
                          "geometry before any particle is made (`sphdyn check` "
                          "prints them); a larger model is refused. Absent: half "
                          "of this machine's memory.")
    energy_error_limit: real("energy error limit", lo=0, hi=1, lo_open=True) = Field(
        0.05, description="Largest energy the run may make from nothing: E_total - "
                          "E_total(0) over the largest energy term so far (kinetic, "
                          "internal, contact, external work; summary.json's "
                          "energy_error_max_rel, for a gain), checked at every history "
                          "row. Past it for 100 steps (a stiff contact's booking "
                          "transient passes) "
                          "the run does energy_error_action, naming the part that "
                          "gained the most energy beyond the work done on it, its "
                          "element or particle of the largest specific internal "
                          "energy, and the interactions acting on it.")
    energy_error_action: Literal["stop", "warn", "off"] = Field(
        "stop", description="Past energy_error_limit: stop (the run ends with status "
                            "\"energy_error\", the diagnosis in summary.json, exit "
                            "status 1, the output so far kept), warn (print the "
                            "diagnosis once, keep running; summary.json's "
                            "energy_warning) or off.")


class MassScaling(Section):
    """[time.mass_scaling]: selective mass scaling (LS-DYNA's ``DT2MS < 0``).

    At the start of the run every particle, element or bar element whose
    stable step is below ``target`` gets the mass that raises its step to
    ``target`` (a particle's own mass, an element's shared by its nodes;
    a tied, hybrid, embedded or sublayer slave's goes to the nodes it
    follows). The added mass has inertia only: it changes no density,
    stress, weight or contact stiffness. The summary and the history
    (``mass_added_<part>``) report it per part. What it costs in accuracy
    is the user's to check: a wave crosses the scaled items slower, by
    sqrt(1 + added / mass) (docs/theory.md, "Selective mass scaling").
    """

    target: quantity(TIME, "time step", lo=0, lo_open=True) = Field(
        description="The step to bring the scaled items to (the step the run takes, "
                    "the CFL factors included), e.g. \"0.6 us\". Items whose step is "
                    "above it get nothing; an interaction's own step limit (particle "
                    "contact, walls) is not raised.")
    parts: Optional[tuple[reference_to("body", mesh_bodies=True, also=("mesh",)), ...]] = \
        Field(None, description="The bodies and meshes whose items may take mass "
                                "(absent: all). Leave out an impactor: mass added to it "
                                "adds to the energy it brings. A bar's sublayer "
                                "particles are the body <mesh>_sublayer; their mass goes "
                                "to the bar's nodes.")
    max_added: real("mass fraction", lo=0, lo_open=True) = Field(
        0.02, description="Largest mass the scaling may add, as a fraction of the "
                          "model's mass (2 % by default); a target needing more is "
                          "refused before the run, naming the part given the most and "
                          "the largest target within the limit.")


class Time(Section):
    """[time]: explicit time stepping."""

    moved: ClassVar[dict[str, str]] = {
        "cfl": "[sph] cfl (each part kind has its own: [sph] cfl for particles, "
               "[[mesh]] cfl for elements)"}
    dt_max: Optional[quantity(TIME, "time step", lo=0, lo_open=True)] = Field(
        None, description="Upper bound on the time step (absent: no bound).")
    collapse_ratio: real("ratio", lo=0, hi=1, lo_open=True, hi_open=True) = \
        Field(1e-4, description="The run stops when dt < collapse_ratio * "
                                "initial dt.")
    mass_scaling: Optional[MassScaling] = Field(
        None, description="Selective mass scaling to a target step (absent: none).")


class Domain(Section):
    """[domain]: guard box; a particle leaving it stops the run, or (outside =
    "remove") leaves the calculation. Every body and mesh must start inside it
    (``sphdyn check`` refuses one that does not)."""

    lo: Optional[Position] = Field(
        None, description="Lower corner (absent: from the bodies and margin).")
    hi: Optional[UpperPosition] = Field(
        None, description="Upper corner (absent: from the bodies and margin).")
    margin: real("margin", lo=0) = Field(
        1.0, description="For an absent corner: the initial bounding box of "
                         "the bodies expanded on each side by margin times its "
                         "largest side (the same distance in every direction).")
    outside: Literal["stop", "remove"] = Field(
        "stop", description="What a particle leaving the box does: stop the run with "
        "a diagnosis, or be removed from the calculation (LS-DYNA's SPH box: fixed "
        "where it left, out of the neighbour search, its kinetic and internal energy "
        "booked as E_left_domain; for blast products flying off). Total-Lagrangian "
        "particles and mesh nodes always stop the run.")
