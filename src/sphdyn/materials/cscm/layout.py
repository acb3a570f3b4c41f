"""Layout of the CSCM parameter vector and history row.

Parameter vector: the common block ``[density, K, G]``, then
:data:`~sphdyn.materials.cscm.defaults.PARAM_NAMES`, then the switches and
derived values ``P_IRATE`` ... ``P_R0_ELASTIC`` (``N_PARAMS`` in all). History
row: :data:`HISTORY_NAMES`, indexed by the ``H_*`` constants.
"""

from ..registry import N_COMMON, P_DENSITY, P_G, P_K  # noqa: F401  (the common block)
from .defaults import PARAM_NAMES

PARAM_INDEX = {name: N_COMMON + k for k, name in enumerate(PARAM_NAMES)}
P_ALPHA, P_THETA, P_LAMDA, P_BETA = (PARAM_INDEX[n] for n in ("alpha", "theta", "lamda", "beta"))
P_A1, P_T1, P_L1, P_B1 = (PARAM_INDEX[n] for n in ("alpha1", "theta1", "lamda1", "beta1"))
P_A2, P_T2, P_L2, P_B2 = (PARAM_INDEX[n] for n in ("alpha2", "theta2", "lamda2", "beta2"))
P_R, P_X0, P_W, P_D1, P_D2 = (PARAM_INDEX[n] for n in ("R", "X0", "W", "D1", "D2"))
P_BB, P_DD, P_GFC, P_GFT, P_GFS = (PARAM_INDEX[n] for n in ("B", "D", "GFC", "GFT", "GFS"))
P_PWRC, P_PWRT, P_PMOD = (PARAM_INDEX[n] for n in ("pwrc", "pwrt", "pmod"))
P_ETA0C, P_NC, P_ETA0T, P_NT = (PARAM_INDEX[n] for n in ("eta0c", "nc", "eta0t", "nt"))
P_OVERC, P_OVERT, P_SRATE, P_REPOW = (PARAM_INDEX[n] for n in ("overc", "overt", "srate", "repow"))
_NEXT = N_COMMON + len(PARAM_NAMES)
P_IRATE = _NEXT          # 1.0: rate effects on
P_ERODE = _NEXT + 1      # 1.0: erosion on
P_ERODE_STRAIN = _NEXT + 2
P_RECOV = _NEXT + 3
P_INCRE = _NEXT + 4
P_DMAX_POWER = _NEXT + 5
P_KAPPA0 = _NEXT + 6     # derived: X0 = kappa0 + R Ff(kappa0)
P_J1APEX = _NEXT + 7     # derived: Ff(J1_apex) = 0, J1_apex < 0
P_LI2B = _NEXT + 8       # derived: Li2(-B)
P_RECOV_VOL = _NEXT + 9  # 1.0: RECOV option 2 (10-11), recovery needs compressive volume strain too
P_RETRACT = _NEXT + 10   # 1.0: the cap retracts with dilation (ITRETRC = 1)
P_RATE_R0 = _NEXT + 11   # 1.0: damage thresholds raised by the rate factor (with IRATE)
P_WAVE_UNDAMAGED = _NEXT + 12  # 1.0: wave speed from the undamaged moduli
P_R0_ELASTIC = _NEXT + 13  # derived: sqrt(J2') below which J1 >= 0 is surely elastic
P_GROW_ON_LOADING = _NEXT + 14  # 1.0: damage grows only while its variable tau grows
N_PARAMS = _NEXT + 15

HISTORY_NAMES = (
    "kappa", "plastic_vol_strain", "damage_brittle", "damage_ductile",
    "tau_t_max", "tau_c_max", "r0_brittle", "r0_ductile", "eroded",
    "strain_xx", "strain_yy", "strain_zz", "strain_xy", "strain_yz", "strain_xz",
    "sigvp_xx", "sigvp_yy", "sigvp_zz", "sigvp_xy", "sigvp_yz", "sigvp_xz",
    "strain_rate", "rate_factor", "rate_factor_max",
)
H_KAPPA, H_EV, H_DB, H_DD, H_TT, H_TC, H_R0T, H_R0C, H_ERODED = range(9)
H_EPS = 9
H_SVP = 15
H_RATE = 21
H_RF = 22
H_RFMAX = 23
