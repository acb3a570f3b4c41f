"""The deck table of a CSCM material: ``[[material]]`` with ``model = "cscm"``.

Keys, defaults and checks of the CSCM parameters. A parameter left out
(None) is generated from fc and aggregate_size by
:func:`~sphdyn.materials.cscm.defaults.default_parameters`; the defaults
given here are read by :func:`~sphdyn.materials.cscm.packing.cscm_parameters`
too, so each is written once.
"""

from typing import Any, ClassVar, Literal, Optional

from pydantic import Field, StrictBool, field_validator

from ...deck.messages import problem
from ...deck.sections.material import Density, MaterialSection
from ...deck.units import PRESSURE
from ...deck.values import PositiveLength, PositivePressure, quantity, real
from .defaults import CONSTANT_DEFAULTS, GFC_PER_GFT, NU


def override(noun: str, dim: Any = None, **bounds: Any) -> Any:
    """Optional CSCM override: a quantity (with ``dim``) or a plain SI number."""
    kind = quantity(dim, noun, **bounds) if dim is not None else real(noun, **bounds)
    return Optional[kind]


def _default(key: str) -> str:
    """``(default <value>)`` of a generated parameter that does not depend on fc."""
    return f"(default {CONSTANT_DEFAULTS[key]:g})"


class CscmParams(MaterialSection):
    """[[material]] model = "cscm": concrete, Continuous Surface Cap Model.

    Re-implementation of LS-DYNA *MAT_CSCM_CONCRETE (MAT_159, Murray 2007,
    FHWA-HRT-05-062); every parameter is generated from fc and
    aggregate_size (the "short form") unless given explicitly. Numbers
    without units are SI (pascals, metres, J/m^2, seconds); see
    docs/cscm.md for the equations and the parameter table.
    """

    #: RECOV is a switch, not a varied parameter.
    unvaried: ClassVar[tuple[str, ...]] = ("recovery",)

    model: Literal["cscm"] = Field(description="Constitutive model.")
    density: Density = Field(description="Initial mass density (never generated).")
    fc: PositivePressure = Field(
        30e6, description="Unconfined compression strength f'c (LS-DYNA "
                          "FPC; defaults are fitted for 20-58 MPa).")
    aggregate_size: PositiveLength = Field(
        0.019, description="Maximum aggregate size (LS-DYNA DAGG); enters "
                           "the default fracture energies.")
    K: Optional[PositivePressure] = Field(
        None, description=f"Bulk modulus (default from fc, nu = {NU:g}).")
    G: Optional[PositivePressure] = Field(
        None, description=f"Shear modulus (default from fc, nu = {NU:g}).")
    alpha: override("TXC constant", PRESSURE) = Field(
        None, description="TXC shear surface: constant term alpha.")
    theta: override("TXC linear term") = Field(
        None, description="TXC shear surface: linear term theta [-].")
    lamda: override("TXC exponential term", PRESSURE) = Field(
        None, description="TXC shear surface: exponential term lambda.")
    beta: override("TXC exponent", lo=0) = Field(
        None, description="TXC shear surface: exponent beta [1/Pa].")
    alpha1: override("Q1 constant") = Field(
        None, description="TOR/TXC ratio Q1: constant term [-].")
    theta1: override("Q1 linear term") = Field(
        None, description="TOR/TXC ratio Q1: linear term [1/Pa].")
    lamda1: override("Q1 exponential term") = Field(
        None, description="TOR/TXC ratio Q1: exponential term [-].")
    beta1: override("Q1 exponent", lo=0) = Field(
        None, description="TOR/TXC ratio Q1: exponent [1/Pa].")
    alpha2: override("Q2 constant") = Field(
        None, description="TXE/TXC ratio Q2: constant term [-].")
    theta2: override("Q2 linear term") = Field(
        None, description="TXE/TXC ratio Q2: linear term [1/Pa].")
    lamda2: override("Q2 exponential term") = Field(
        None, description="TXE/TXC ratio Q2: exponential term [-].")
    beta2: override("Q2 exponent", lo=0) = Field(
        None, description="TXE/TXC ratio Q2: exponent [1/Pa].")
    R: override("cap aspect ratio", lo=0, lo_open=True) = Field(
        None, description="Cap aspect ratio R [-].")
    X0: override("cap location", PRESSURE, lo=0, lo_open=True) = Field(
        None, description="Initial cap location X0 (J1, compression positive).")
    W: override("compaction", lo=0, lo_open=True) = Field(
        None, description="Maximum plastic volume compaction W [-].")
    D1: override("compaction shape", lo=0, lo_open=True) = Field(
        None, description="Compaction law linear shape D1 [1/Pa].")
    D2: override("compaction shape", lo=0) = Field(
        None, description="Compaction law quadratic shape D2 [1/Pa^2].")
    B: override("softening shape", lo=0, lo_open=True) = Field(
        None, description=f"Ductile softening shape B [-] {_default('B')}.")
    D: override("softening shape", lo=0, lo_open=True) = Field(
        None, description=f"Brittle softening shape D [-] {_default('D')}.")
    GFC: override("fracture energy", lo=0, lo_open=True) = Field(
        None, description="Fracture energy in uniaxial compression [J/m^2] "
                          f"(default {GFC_PER_GFT:g} GFT).")
    GFT: override("fracture energy", lo=0, lo_open=True) = Field(
        None, description="Fracture energy in uniaxial tension [J/m^2] "
                          "(default: CEB-type fit of fc and aggregate_size, "
                          "unconfirmed, see docs/cscm.md).")
    GFS: override("fracture energy", lo=0, lo_open=True) = Field(
        None, description="Fracture energy in pure shear [J/m^2] (default GFT).")
    pwrc: override("transition power", lo=0) = Field(
        None, description="Shear-to-compression transition power "
                          f"{_default('pwrc')}.")
    pwrt: override("transition power", lo=0) = Field(
        None, description="Shear-to-tension transition power "
                          f"{_default('pwrt')}.")
    eta0c: override("fluidity", lo=0) = Field(
        None, description="Compression fluidity eta0c [s^(1-nc)].")
    nc: override("rate exponent", lo=0) = Field(
        None, description="Compression fluidity exponent nc [-].")
    eta0t: override("fluidity", lo=0) = Field(
        None, description="Tension fluidity eta0t [s^(1-nt)].")
    nt: override("rate exponent", lo=0) = Field(
        None, description="Tension fluidity exponent nt [-].")
    overc: override("overstress", PRESSURE, lo=0) = Field(
        None, description="Maximum overstress in compression.")
    overt: override("overstress", PRESSURE, lo=0) = Field(
        None, description="Maximum overstress in tension.")
    srate: override("fluidity ratio", lo=0) = Field(
        None, description="Shear-to-tension fluidity ratio "
                          f"{_default('srate')}.")
    repow: override("power", lo=0) = Field(
        None, description="Power of the rate increase of fracture energy "
                          f"{_default('repow')}.")
    rate_effects: StrictBool = Field(
        False, description="Viscoplastic rate effects (LS-DYNA IRATE = 1); "
                           "off by default as in LS-DYNA.")
    erode: StrictBool = Field(
        False, description="Erosion: a point with damage > 0.99 and maximum "
                           "principal strain > erode_strain keeps its mass "
                           "but carries no deviatoric or tensile stress.")
    erode_strain: real("strain", lo=0) = Field(
        0.05, description="Maximum principal strain for erosion (LS-DYNA "
                          "ERODE - 1).")
    recovery: real("recovery factor", lo=0, hi=11) = Field(
        0.0, description="RECOV: 0 = modulus recovered in compression, 1 = "
                         "brittle damage kept in compression (0-1 between); "
                         "10-11: the same, switched by the volumetric strain "
                         "instead of the pressure (LS-DYNA option 2).")
    cap_retraction: StrictBool = Field(
        False, description="ITRETRC: the cap may move back towards its initial "
                           "position (never inside it); see docs/cscm.md.")
    rate_thresholds: StrictBool = Field(
        False, description="With rate_effects: the damage thresholds rise with "
                           "the dynamic strength ratio (docs/cscm.md, choice "
                           "[D]). Not part of MAT_159, so off by default; the "
                           "decks that switch it on mark it as calibrated.")
    damage_growth: Literal["state", "loading"] = Field(
        "loading", description="When the damage is formed: loading (the "
                               "default): only in a step that raises tau past "
                               "its largest value so far, the loading condition "
                               "of strain-driven damage (Simo and Ju 1987); "
                               "state: at every step, as the logistic function "
                               "of the largest tau so far with the softening "
                               "rate of the current stress state and rate "
                               "factor (kept if larger), so it can grow while "
                               "the point unloads (sphdyn's rule before "
                               "2026-11-29). Which one LS-DYNA's MAT_159 uses "
                               "is not known (docs/cscm.md, 3a).")
    wave_speed: Literal["damaged", "undamaged"] = Field(
        "damaged", description="Wave speed of the time step and of the "
                               "viscosities (artificial, bulk, hourglass): "
                               "sqrt((1-d)(K+4G/3)/rho) of the damaged moduli, "
                               "or \"undamaged\" sqrt((K+4G/3)/rho), as LS-DYNA "
                               "takes a user material's elastic moduli (a failed "
                               "element keeps its hourglass and bulk viscosity; "
                               "docs/cscm.md).")
    incre: Optional[real("strain increment", lo=0, lo_open=True)] = Field(
        None, description="Maximum strain sub-increment (default a quarter "
                          "of the zero-pressure shear yield strain).")

    @field_validator("recovery")
    @classmethod
    def _recovery_range(cls, r):
        if 1.0 < r < 10.0:
            raise problem(f"recovery {r} is neither in [0, 1] nor in [10, 11]",
                          "give 0-1 (pressure switch) or 10-11 (volumetric "
                          "strain switch)")
        return r
