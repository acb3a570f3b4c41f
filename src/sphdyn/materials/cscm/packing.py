"""CSCM parameters from deck values: generated defaults, checks, packed vector.

:func:`cscm_parameters` completes the deck values with the defaults of the
deck table (:class:`~sphdyn.materials.cscm.schema.CscmParams`) and the
short-form fits (:mod:`~sphdyn.materials.cscm.defaults`); :func:`pack_cscm`
writes them, with the derived cap and apex values, into the vector of
:mod:`~sphdyn.materials.cscm.layout`.
"""

from __future__ import annotations

import math

import numpy as np

from ..base import P_G, P_K, get_float
from ..registry import schema_defaults
from .defaults import PARAM_NAMES, default_parameters
from .layout import (H_KAPPA, H_RF, H_RFMAX, HISTORY_NAMES, N_PARAMS, P_DMAX_POWER,
                     P_ERODE, P_ERODE_STRAIN, P_GROW_ON_LOADING, P_INCRE, P_IRATE,
                     P_J1APEX, P_KAPPA0, P_LI2B, P_R0_ELASTIC, P_RATE_R0, P_RECOV,
                     P_RECOV_VOL, P_RETRACT, P_WAVE_UNDAMAGED, PARAM_INDEX)
from .schema import CscmParams
from .surface import elastic_radius_bound, kappa_from_cap, shear_surface


def dilog_neg(B: float) -> float:
    """``Li2(-B)`` for ``B >= 0`` (dilogarithm).

    Series ``Li2(z) = sum z^k/k^2`` for ``|z| <= 1/2``; for ``B > 1/2`` the
    inversion ``Li2(-x) = -pi^2/6 - ln(x)^2/2 - Li2(-1/x)`` (x > 1) and for
    ``1/2 < B <= 1`` the Landen-free direct series (alternating, converging).
    """
    def series(z: float) -> float:
        total, term, k = 0.0, z, 1
        while abs(term) / (k * k) > 1e-17 and k < 100000:
            total += term / (k * k)
            k += 1
            term *= z
        return total

    if B <= 1.0:
        return series(-B)
    return -math.pi ** 2 / 6.0 - 0.5 * math.log(B) ** 2 - series(-1.0 / B)


def _apex(p: np.ndarray) -> float:
    """``J1 < 0`` with ``Ff(J1) = 0`` (tensile apex of the shear surface), bisection."""
    lo, hi = -1.0, 0.0
    if float(shear_surface(0.0, p)) <= 0.0:
        raise ValueError("cscm: the shear surface Ff(0) = alpha - lamda must be > 0")
    while float(shear_surface(lo, p)) > 0.0:
        lo *= 2.0
        if lo < -1e15:
            raise ValueError("cscm: the shear surface has no tensile apex")
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if float(shear_surface(mid, p)) > 0.0:
            hi = mid
        else:
            lo = mid
    return hi


def cscm_parameters(values: dict) -> dict:
    """SI parameter dict of a CSCM material from deck-style values.

    Keys: ``density`` (required), ``fc`` [Pa], ``aggregate_size`` [m], any
    override of :func:`~sphdyn.materials.cscm.defaults.default_parameters`
    (``K``, ``G``, ``alpha``, ..., ``repow``), and the switches
    ``rate_effects`` (IRATE), ``erode``, ``erode_strain`` (ERODE - 1),
    ``recovery`` (RECOV in [0, 1]: LS-DYNA option 1 on the sign of the
    pressure, or [10, 11]: option 2 = RECOV - 10 on the signs of pressure
    and volume strain), ``cap_retraction`` (ITRETRC), ``rate_thresholds``
    (with rate effects the damage thresholds scale with the dynamic
    strength ratio, choice [D]), ``wave_speed`` ("damaged" or "undamaged"),
    ``damage_growth`` ("state" or "loading").
    An absent key takes the default of the deck table
    :class:`~sphdyn.materials.cscm.schema.CscmParams`. Two keys the
    deck does not offer: ``incre`` (sub-increment strain limit, default from
    the strength, see :func:`pack_cscm`) and ``dmax_power`` (default 1).
    """
    default = schema_defaults(CscmParams)
    fc = get_float(values, "fc", default=default["fc"], min_value=0.0,
                   min_inclusive=False)
    dagg = get_float(values, "aggregate_size", default=default["aggregate_size"],
                     min_value=0.0, min_inclusive=False)
    over = {k: values[k] for k in ("K", "G", *PARAM_NAMES)
            if k in values and values[k] is not None}
    for k in over:
        get_float(values, k)
    out = default_parameters(fc, dagg, **over)
    if "E" in values or "nu" in values:
        raise ValueError("cscm: give K and G (or neither, for the defaults), not E/nu")
    out["density"] = get_float(values, "density", min_value=0.0, min_inclusive=False)
    for switch in ("rate_effects", "erode", "cap_retraction", "rate_thresholds"):
        out[switch] = bool(values.get(switch, default[switch]))
    out["wave_speed"] = values.get("wave_speed", default["wave_speed"])
    if out["wave_speed"] not in ("damaged", "undamaged"):
        raise ValueError("material parameter 'wave_speed' must be \"damaged\" or "
                         f"\"undamaged\", got {out['wave_speed']!r}")
    out["damage_growth"] = values.get("damage_growth", default["damage_growth"])
    if out["damage_growth"] not in ("state", "loading"):
        raise ValueError("material parameter 'damage_growth' must be \"state\" or "
                         f"\"loading\", got {out['damage_growth']!r}")
    out["erode_strain"] = get_float(values, "erode_strain",
                                    default=default["erode_strain"], min_value=0.0)
    recov = get_float(values, "recovery", default=default["recovery"], min_value=0.0,
                      max_value=11.0)
    if 1.0 < recov < 10.0:
        raise ValueError(f"material parameter 'recovery' must be in [0, 1] (recovery "
                         f"on the pressure sign) or [10, 11] (pressure and volume "
                         f"strain signs, LS-DYNA RECOV option 2), got {recov}")
    out["recovery"] = recov
    out["dmax_power"] = get_float(values, "dmax_power", default=1.0, min_value=0.0)
    if values.get("incre") is not None:
        out["incre"] = get_float(values, "incre", min_value=0.0, min_inclusive=False)
    for k in ("K", "G", "R", "W", "D1", "B", "D", "GFC", "GFT", "GFS"):
        if not out[k] > 0.0:
            raise ValueError(f"cscm: parameter {k!r} must be > 0, got {out[k]}")
    return out


def pack_cscm(values: dict) -> np.ndarray:
    """Packed CSCM parameter vector from SI values (see :func:`cscm_parameters`).

    Layout ``[density, K, G] + PARAM_NAMES + [irate, erode, erode_strain,
    recovery, incre, dmax_power, kappa0, J1_apex, Li2(-B), recovery_mode,
    cap_retraction, rate_thresholds, wave_speed_undamaged, r0_elastic,
    grow_on_loading]``. The default
    sub-increment limit is ``incre = 0.25 (alpha - lamda) / (2 G)``, a quarter
    of the tensor shear strain at which the TXC surface is reached at zero
    pressure (LS-DYNA's INCRE default formula is not known, notes sec. 1.3:
    choice [D]).
    """
    v = cscm_parameters(values)
    p = np.zeros(N_PARAMS)
    p[0], p[P_K], p[P_G] = v["density"], v["K"], v["G"]
    for name in PARAM_NAMES:
        p[PARAM_INDEX[name]] = v[name]
    p[P_IRATE] = 1.0 if v["rate_effects"] else 0.0
    p[P_ERODE] = 1.0 if v["erode"] else 0.0
    p[P_ERODE_STRAIN] = v["erode_strain"]
    p[P_RECOV] = v["recovery"] - 10.0 if v["recovery"] >= 10.0 else v["recovery"]
    p[P_RECOV_VOL] = 1.0 if v["recovery"] >= 10.0 else 0.0
    p[P_RETRACT] = 1.0 if v["cap_retraction"] else 0.0
    p[P_RATE_R0] = 1.0 if v["rate_thresholds"] else 0.0
    p[P_WAVE_UNDAMAGED] = 1.0 if v["wave_speed"] == "undamaged" else 0.0
    p[P_GROW_ON_LOADING] = 1.0 if v["damage_growth"] == "loading" else 0.0
    p[P_DMAX_POWER] = v["dmax_power"]
    p[P_INCRE] = v.get("incre", 0.25 * (v["alpha"] - v["lamda"]) / (2.0 * v["G"]))
    p[P_J1APEX] = _apex(p)
    # kappa0 from X0 = kappa0 + R Ff(kappa0)
    p[P_KAPPA0] = -1e300
    p[P_KAPPA0] = float(kappa_from_cap(v["X0"], 0.0, p))
    if not p[P_KAPPA0] > p[P_J1APEX]:
        raise ValueError("cscm: X0 is too small (initial cap inside the tensile apex)")
    p[P_LI2B] = dilog_neg(v["B"])
    p[P_R0_ELASTIC] = elastic_radius_bound(p)
    return p


def initial_history(p: np.ndarray) -> np.ndarray:
    """Initial history: ``kappa = kappa0``, everything else 0.

    An all-zero row is also a valid initial state (``kappa = 0`` acts as
    ``kappa0`` since ``L = max(kappa, kappa0)``; a damage threshold of 0 means
    "not yet reached"), so callers that do not apply this function work too.
    """
    h = np.zeros(len(HISTORY_NAMES))
    h[H_KAPPA] = p[P_KAPPA0]
    h[H_RF] = 1.0
    h[H_RFMAX] = 1.0
    return h


def kappa0(p: np.ndarray) -> float:
    """Initial cap parameter kappa0 [Pa] (J1, compression positive)."""
    return float(p[P_KAPPA0])
