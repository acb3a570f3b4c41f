r"""Kingery-Bulmash air-blast parameters and the pressure they put on a face.

The fits of Kingery and Bulmash (1984, *Air Blast Parameters from TNT
Spherical Air Burst and Hemispherical Surface Burst*, ARBRL-TR-02555), the
curves of UFC 3-340-02 (Figs. 2-7 and 2-15) and the load of LS-DYNA's
LOAD_BLAST and LOAD_BLAST_ENHANCED (Randers-Pehrson and Bannister 1997,
*Airblast Loading Model for DYNA2D and DYNA3D*, ARL-TR-1310, which lists
them). Each parameter :math:`Y` of a TNT charge of mass :math:`W` at the
range :math:`R` is a polynomial in the log of the scaled distance
:math:`Z = R/W^{1/3}`:

.. math::
    U = a + b\log_{10} Z, \qquad \log_{10} Y = \sum_k c_k U^k,

in the report's units (Z in ft/lb^(1/3), pressures in psi, times and
impulses scaled by :math:`W^{1/3}` in ms/lb^(1/3) and psi ms/lb^(1/3)),
piecewise in Z for the incident impulse and the positive-phase duration.
The coefficients below are those of ARL-TR-1310 (Appendix A); this module
converts to and from SI. Two bursts: ``FREE_AIR`` (a spherical charge far
from the ground) and ``SURFACE`` (a hemispherical charge on the ground, the
reflection off the ground included).

Parameters (:func:`parameters`): the incident (side-on) peak overpressure
:math:`P_{so}`, the normally reflected one :math:`P_r`, the arrival time
:math:`t_a`, the positive-phase duration :math:`t_0` and the incident and
reflected positive impulses :math:`i_s`, :math:`i_r`.

Pulse (:func:`friedlander`): the modified Friedlander form
:math:`p(\tau) = P\,(1 - \tau/t_0)\,e^{-A\tau/t_0}` for
:math:`0 \le \tau \le t_0` after arrival, whose decay coefficient
:math:`A` (:func:`decay_coefficient`) gives the fitted impulse,
:math:`i = P t_0\,[1/A - (1 - e^{-A})/A^2]` (ARL-TR-1310 eq. 5); the
negative phase is left out. Where :math:`P t_0 / i < 2` (close in, where the
fitted duration is too short for the fitted impulse), :math:`t_0` is
lengthened to :math:`2 i / P` and the pulse is the triangle :math:`A = 0`,
so the impulse is always the fit's (ARL-TR-1310 lengthens it to a ratio of
2.5 or 2 by range; the fit's impulse is kept here instead).

Angle of incidence (:func:`face_pressure`): with :math:`\theta` the angle
between a face's outward normal and the direction to the charge
(ARL-TR-1310 eq. 7),

.. math::
    p = p_r \cos^2\theta + p_s (1 + \cos^2\theta - 2\cos\theta)
    \quad (\cos\theta \ge 0), \qquad p = p_s \quad (\cos\theta < 0).

The model and its tests: docs/theory.md, "Empirical blast loads".
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

#: burst kinds
FREE_AIR, SURFACE = 0, 1
BURSTS = {"free_air": FREE_AIR, "surface": SURFACE}
#: the parameters, in the order of the coefficient tables
PSO, PR, TA, IS, IR, T0 = range(6)

#: scaled distance: ft/lb^(1/3) per m/kg^(1/3)
Z_TO_IMPERIAL = (1.0 / 0.3048) / (1.0 / 0.45359237) ** (1.0 / 3.0)
#: Pa per psi
PSI = 6894.757293168361
#: kg^(1/3) per lb^(1/3) in the scaled times: t [s] = MS_LB * t_fit * W[kg]^(1/3)
MS_LB = 1e-3 * 0.45359237 ** (-1.0 / 3.0)
#: the fits' range of scaled distance [m/kg^(1/3)] (UN IATG 01.80 and AASTP-4
#: give the fits from 0.0531 (free air) and 0.0674 (surface) to 40)
Z_RANGE = ((0.0531, 40.0), (0.0674, 40.0))

_INF = math.inf
# Segments: (upper bound of log10 Z [ft/lb^(1/3)], a, b, c_0 ... c_n), ARL-TR-1310.
# A segment with a = b = 0 is a constant log10 Y = c_0.
_TABLE = {
    (FREE_AIR, PSO): [(_INF, -0.756579301809, 1.35034249993, [
        1.77284970457, -1.69012801396, 0.00804973591951, 0.336743114941,
        -0.00516226351334, -0.0809228619888, -0.00478507266747, 0.00793030472242,
        0.0007684469735])],
    (SURFACE, PSO): [(_INF, -0.756579301809, 1.35034249993, [
        1.9422502013, -1.6958988741, -0.154159376846, 0.514060730593,
        0.0988534365274, -0.293912623038, -0.0268112345019, 0.109097496421,
        0.00162846756311, -0.0214631030242, 0.0001456723382, 0.00167847752266])],
    (FREE_AIR, PR): [(_INF, -0.756579301809, 1.35034249993, [
        2.39106134946, -2.21400538997, 0.035119031446, 0.657599992109,
        0.0141818951887, -0.243076636231, -0.0158699803158, 0.0492741184234,
        0.00227639644004, -0.00397126276058])],
    (SURFACE, PR): [(_INF, -0.789312405513, 1.36637719229, [
        2.56431321138, -2.21030870597, -0.218536586295, 0.895319589372,
        0.24989009775, -0.569249436807, -0.11791682383, 0.224131161411,
        0.0245620259375, -0.0455116002694, -0.00190930738887, 0.00361471193389])],
    (FREE_AIR, TA): [(_INF, -0.80501734056, 1.37407043777, [
        -0.0423733936826, 1.36456871214, -0.0570035692784, -0.182832224796,
        0.0118851436014, 0.0432648687627, -0.0007997367834, -0.00436073555033])],
    (SURFACE, TA): [(_INF, -0.755684472698, 1.37784223635, [
        -0.173607601251, 1.35706496258, 0.052492798645, -0.196563954086,
        -0.0601770052288, 0.0696360270891, 0.0215297490092, -0.0161658930785,
        -0.00232531970294, 0.00147752067524])],
    (FREE_AIR, IS): [
        (0.30103, 1.04504877747, 3.24299066475, [
            1.43534136453, -0.443749377691, 0.168825414684, 0.0348138030308,
            -0.010435192824]),
        (_INF, -2.67912519532, 2.30629231803, [
            0.599008468099, -0.40463292088, -0.0142721946082, 0.00912366316617,
            -0.0006750681404, -0.00800863718901, 0.00314819515931, 0.00152044783382,
            -0.0007470265899])],
    (SURFACE, IS): [
        (0.382017, 0.832468843425, 3.0760329666, [
            1.57159240621, -0.502992763686, 0.171335645235, 0.0450176963051,
            -0.0118964626402]),
        (_INF, -2.91358616806, 2.40697745406, [
            0.719852655584, -0.384519026965, -0.0280816706301, 0.00595798753822,
            0.014544526107, -0.00663289334734, -0.00284189327204, 0.0013644816227])],
    (FREE_AIR, IR): [(_INF, -0.757659920369, 1.37882996018, [
        1.60579280091, -0.903118886091, 0.101771877942, -0.0242139751146])],
    (SURFACE, IR): [(_INF, -0.781951689212, 1.33422049854, [
        1.75291677799, -0.949516092853, 0.112136118689, -0.0250659183287])],
    (FREE_AIR, T0): [
        (-0.34, 0.0, 0.0, [-0.824]),
        (0.350248, 0.209440059933, 5.11588554305, [
            -0.801052722864, 0.164953518069, 0.127788499497, 0.00291430135946,
            0.00187957449227, 0.0173413962543, 0.00269739758043, -0.00361976502798,
            -0.00100926577934]),
        (0.7596678, -5.06778493835, 9.2996288611, [
            0.115874238335, -0.0297944268969, 0.0306329542941, 0.018340557407,
            -0.0173964666286, -0.00106321963576, 0.0056206003128, 0.0001618217499,
            -0.0006860188944]),
        (_INF, -4.39590184126, 3.1524725264, [
            0.50659210403, 0.0967031995552, -0.00801302059667, 0.00482705779732,
            0.00187587272287, -0.00246738509321, -0.000841116668, 0.0006193291052])],
    (SURFACE, T0): [
        (-0.34, 0.0, 0.0, [-0.725]),
        (0.4048337, -0.1790217052, 5.25099193925, [
            -0.728671776005, 0.130143717675, 0.134872511954, 0.0391574276906,
            -0.00475933664702, -0.00428144598008]),
        (0.845098, -5.85909812338, 9.2996288611, [
            0.20096507334, -0.0297944268976, 0.030632954288, 0.0183405574086,
            -0.0173964666211, -0.00106321963633, 0.00562060030977, 0.0001618217499,
            -0.0006860188944]),
        (_INF, -4.92699491141, 3.46349745571, [
            0.572462469964, 0.0933035304009, -0.0005849420883, -0.00226884995013,
            -0.00295908591505, 0.00148029868929])],
}


def _pack():
    """The tables as arrays for the compiled functions: ``bound`` (2, 6, S),
    ``ab`` (2, 6, S, 2), ``coef`` (2, 6, S, C) with zeros past the last term."""
    segs = max(len(v) for v in _TABLE.values())
    terms = max(len(s[3]) for v in _TABLE.values() for s in v)
    bound = np.full((2, 6, segs), _INF)
    ab = np.zeros((2, 6, segs, 2))
    coef = np.zeros((2, 6, segs, terms))
    for (burst, q), rows in _TABLE.items():
        for s, (hi, a, b, c) in enumerate(rows):
            bound[burst, q, s] = hi
            ab[burst, q, s] = a, b
            coef[burst, q, s, :len(c)] = c
    return bound, ab, coef


BOUND, AB, COEF = _pack()


@njit(cache=True, error_model="numpy")
def fit(bound, ab, coef, burst, q, zlog):
    r""":math:`\log_{10} Y` of parameter ``q`` at :math:`\log_{10} Z` = ``zlog``
    (Z in ft/lb^(1/3)), in the report's units: the first segment whose upper
    bound exceeds ``zlog``, :math:`\sum_k c_k U^k` by Horner's rule with
    :math:`U = a + b\,\mathrm{zlog}`."""
    s = 0
    while zlog >= bound[burst, q, s]:
        s += 1
    u = ab[burst, q, s, 0] + ab[burst, q, s, 1] * zlog
    c = coef[burst, q, s]
    y = 0.0
    for k in range(c.shape[0] - 1, -1, -1):
        y = y * u + c[k]
    return y


@njit(cache=True, error_model="numpy")
def decay_coefficient(ratio):
    r"""The decay coefficient :math:`A \ge 0` of a Friedlander pulse with
    :math:`P t_0 / i` = ``ratio`` (>= 2): the root of
    :math:`A^2 - \mathrm{ratio}\,(A + e^{-A} - 1) = 0` (the impulse
    :math:`i = P t_0 [1/A - (1 - e^{-A})/A^2]`; 0 at ratio 2, the triangle).
    Newton's method from :math:`A = \mathrm{ratio} - 1`, which lies right of
    the root (the function is convex there), so the iterates fall
    monotonically onto it."""
    if ratio <= 2.0:
        return 0.0
    a = ratio - 1.0
    for _ in range(60):
        e = math.exp(-a)
        f = a * a - ratio * (a + e - 1.0)
        df = 2.0 * a - ratio * (1.0 - e)
        step = f / df
        a -= step
        if abs(step) <= 1e-13 * a:
            break
    return a


@njit(cache=True, error_model="numpy")
def parameters(z, w13, burst, bound, ab, coef, out, decays=True):
    r"""The blast parameters of a TNT charge at scaled distance ``z``
    [m/kg^(1/3)] (clamped to :data:`Z_RANGE`), ``w13`` = :math:`W^{1/3}`
    [kg^(1/3)]; written to ``out`` (8,): :math:`P_{so}`, :math:`P_r` [Pa],
    :math:`t_a`, :math:`t_0` [s] (t_0 lengthened to :math:`2\max(i_s/P_{so},
    i_r/P_r)` where shorter), :math:`i_s`, :math:`i_r` [Pa s] and (if
    ``decays``) the decay coefficients :math:`A_s`, :math:`A_r` of the two
    pulses (:func:`face_pressure` finds them itself, only during the pulse)."""
    z = min(max(z, Z_RANGE[burst][0]), Z_RANGE[burst][1])
    zlog = math.log10(z * Z_TO_IMPERIAL)
    ms = MS_LB * w13
    pso = PSI * 10.0 ** fit(bound, ab, coef, burst, PSO, zlog)
    pr = PSI * 10.0 ** fit(bound, ab, coef, burst, PR, zlog)
    ta = ms * 10.0 ** fit(bound, ab, coef, burst, TA, zlog)
    i_s = PSI * ms * 10.0 ** fit(bound, ab, coef, burst, IS, zlog)
    i_r = PSI * ms * 10.0 ** fit(bound, ab, coef, burst, IR, zlog)
    t0 = ms * 10.0 ** fit(bound, ab, coef, burst, T0, zlog)
    t0 = max(t0, 2.0 * i_s / pso, 2.0 * i_r / pr)
    out[0] = pso
    out[1] = pr
    out[2] = ta
    out[3] = t0
    out[4] = i_s
    out[5] = i_r
    if decays:
        out[6] = decay_coefficient(pso * t0 / i_s)
        out[7] = decay_coefficient(pr * t0 / i_r)


@njit(cache=True, error_model="numpy")
def friedlander(peak, t0, decay, tau):
    r"""Overpressure :math:`P (1 - \tau/t_0) e^{-A\tau/t_0}` at the time
    ``tau`` [s] after arrival (0 before arrival and after :math:`t_0`)."""
    if tau < 0.0 or tau > t0:
        return 0.0
    s = tau / t0
    return peak * (1.0 - s) * math.exp(-decay * s)


@njit(cache=True, error_model="numpy")
def face_pressure(par, cos_theta, tau):
    r"""Pressure on a face [Pa] at ``tau`` [s] after the detonation from the
    parameters ``par`` (the first 6 of :func:`parameters`) and the cosine of
    the angle of incidence (module docstring, ARL-TR-1310 eq. 7). The decay
    coefficients are found here, only while the pulse lasts."""
    s = tau - par[2]
    if s < 0.0 or s > par[3]:
        return 0.0
    ps = friedlander(par[0], par[3], decay_coefficient(par[0] * par[3] / par[4]), s)
    if cos_theta < 0.0:
        return ps
    pr = friedlander(par[1], par[3], decay_coefficient(par[1] * par[3] / par[5]), s)
    c2 = cos_theta * cos_theta
    return pr * c2 + ps * (1.0 + c2 - 2.0 * cos_theta)


def blast_parameters(z: float, charge: float, burst: str = "free_air") -> dict[str, float]:
    """The parameters of :func:`parameters` by name, for a charge of ``charge``
    kg TNT at scaled distance ``z`` [m/kg^(1/3)] (the tests and the docs)."""
    out = np.zeros(8)
    parameters(float(z), float(charge) ** (1.0 / 3.0), BURSTS[burst], BOUND, AB, COEF, out)
    return dict(zip(("Pso", "Pr", "ta", "t0", "is", "ir", "decay_s", "decay_r"),
                    map(float, out)))
