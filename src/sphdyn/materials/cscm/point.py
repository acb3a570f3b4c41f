"""CSCM update of one material point and the group kernel.

:func:`cscm_point` runs the sub-stepped elastic trial, return, rate effects,
cap hardening and damage of one point (algorithm in
:mod:`sphdyn.materials.cscm`); :func:`cscm_update` applies it to a group of
particles (common kernel signature).
"""

import math

from numba import njit, prange

from ..base import (P_G, P_K, ddot6, energy_increment, jaumann_rotate, load_sym6,
                    p_wave_speed, rate_split, scale6, store_sym6, young_modulus)
from ..elastic import elastic_increment
from .damage import (DMAX, brittle_softening_c, ductile_softening_a, logistic_damage,
                     max_principal, max_principal_bound, power, transition)
from .layout import (H_DB, H_DD, H_EPS, H_ERODED, H_EV, H_KAPPA, H_R0C, H_R0T, H_RATE,
                     H_RF, H_RFMAX, H_SVP, H_TC, H_TT, P_ALPHA, P_BB, P_DD,
                     P_DMAX_POWER, P_ERODE, P_ERODE_STRAIN, P_ETA0C, P_ETA0T, P_GFC,
                     P_GFS, P_GFT, P_GROW_ON_LOADING, P_INCRE, P_IRATE, P_J1APEX, P_LI2B,
                     P_NC, P_NT, P_OVERC, P_OVERT, P_PWRC, P_PWRT, P_RATE_R0, P_RECOV,
                     P_RECOV_VOL, P_REPOW, P_RETRACT, P_SRATE, P_WAVE_UNDAMAGED)
from .projection import project_from_trial, yield_fraction
from .surface import (cap_from_compaction, invariants, j1_radius, kappa_from_cap, meridian,
                      meridian_radius_curvature, surely_elastic)

N_STRIPES = 64  # interleaved work stripes of the group kernel (load balance)
STRIPE_RUN = 32  # consecutive particles per visit of a stripe (memory locality)


@njit(cache=True, error_model="numpy")
def cscm_point(h, deps, dt, p, size):
    """CSCM update of one material point (state in the history row ``h``).

    Parameters
    ----------
    h : float64[:]
        History row (:data:`HISTORY_NAMES`), in/out; holds the undamaged
        stress (already Jaumann-rotated by the caller) and the total strain.
    deps : 6-tuple
        Strain increment ``D dt`` [-].
    dt : float
        Time step [s] (rate effects only).
    p : float64[:]
        Packed parameters (SI).
    size : float
        Particle size L [m] for the fracture-energy regularisation.

    Returns
    -------
    sig : 6-tuple
        Damaged stress ``(1 - d) s_vp`` [Pa], tension positive.
    d : float
        Total damage (1 for an eroded point).
    """
    K = p[P_K]
    G = p[P_G]
    E = young_modulus(K, G)
    svp = (h[H_SVP], h[H_SVP + 1], h[H_SVP + 2], h[H_SVP + 3], h[H_SVP + 4], h[H_SVP + 5])
    eps = (h[H_EPS], h[H_EPS + 1], h[H_EPS + 2], h[H_EPS + 3], h[H_EPS + 4], h[H_EPS + 5])
    if h[H_ERODED] > 0.0:
        # eroded: no deviatoric and no tensile stress, mass kept; the
        # (compressive) mean stress follows the bulk modulus.
        m = (svp[0] + svp[1] + svp[2]) / 3.0 + K * (deps[0] + deps[1] + deps[2])
        m = m if m < 0.0 else 0.0
        svp = (m, m, m, 0.0, 0.0, 0.0)
        eps = (eps[0] + deps[0], eps[1] + deps[1], eps[2] + deps[2],
               eps[3] + deps[3], eps[4] + deps[4], eps[5] + deps[5])
        for k in range(6):
            h[H_SVP + k] = svp[k]
            h[H_EPS + k] = eps[k]
        return svp, 1.0

    nrm = math.sqrt(ddot6(deps, deps))
    n = 1
    if nrm > p[P_INCRE]:
        n = min(int(nrm / p[P_INCRE]) + 1, 10000)
    de = scale6(deps, 1.0 / n)
    dts = dt / n
    irate = p[P_IRATE] > 0.0
    rate = 0.0
    if dt > 0.0:
        rate = math.sqrt(2.0 / 3.0 * ddot6(deps, deps)) / dt
    h[H_RATE] = rate
    viscous = irate and rate > 1e-12
    # fluidities (constant over the step), formed at the step's first
    # plastic sub-step: most points are elastic and need none
    eta_t = eta_c = eta_s = -1.0
    rf = 1.0
    for _ in range(n):
        eps = (eps[0] + de[0], eps[1] + de[1], eps[2] + de[2],
               eps[3] + de[3], eps[4] + de[4], eps[5] + de[5])
        svp_old = svp
        trial = elastic_increment(svp, de, K, G)
        kappa = h[H_KAPPA]
        # yield check f = J2' - F^2 <= tol (as yield_function, with the
        # invariants and meridian constants reused by the return), after a
        # cheaper sufficient test that most elastic points pass
        elastic = surely_elastic(trial, kappa, p)
        if not elastic:
            J1t, rt, bhat, dev = invariants(trial)
            mer = meridian(bhat, kappa, p)
            # the meridian's value (and slope and curvature, which the
            # return starts from) at the trial's J1
            ft_slopes = meridian_radius_curvature(J1t, mer, p)
            ft = ft_slopes[0]
            elastic = (p[P_J1APEX] <= J1t <= mer[3]
                       and rt * rt - ft * ft <= 1e-12 * (p[P_ALPHA] ** 2))
        if elastic:
            svp = trial
        else:
            J1p, rp = project_from_trial(J1t, rt, ft_slopes, mer, K, G, p)
            fac = rp / rt if rt > 0.0 else 0.0
            mp = -J1p / 3.0
            sP = (fac * dev[0] + mp, fac * dev[1] + mp, fac * dev[2] + mp,
                  fac * dev[3], fac * dev[4], fac * dev[5])
            gam = 1.0
            over = 0.0
            if viscous:
                if eta_t < 0.0:
                    # eta_t = eta0t/rate^nt, eta_c = eta0c/rate^nc,
                    # eta_s = srate eta_t (notes 1.11 [R])
                    eta_t = p[P_ETA0T] / rate ** p[P_NT]
                    eta_c = p[P_ETA0C] / rate ** p[P_NC]
                    eta_s = p[P_SRATE] * eta_t
                # Duvaut-Lions fluidity, interpolated with trans (notes 1.11 [R])
                # (eta_t, eta_c, eta_s depend on the step's rate only)
                if J1t < 0.0:
                    tr = transition(J1t, rt, p[P_PWRT])
                    eta = eta_s + tr * (eta_t - eta_s)
                    over = p[P_OVERT]
                else:
                    tr = transition(J1t, rt, p[P_PWRC])
                    eta = eta_s + tr * (eta_c - eta_s)
                    over = p[P_OVERC]
                # overstress limit E rate eta <= OVER (notes 1.11 [R], choice [D])
                eta_max = over / (E * rate)
                if eta > eta_max:
                    eta = eta_max
                x = dts / eta
                gam = x / (1.0 + x)
            if gam < 1.0:
                # overstress s_vp - s_P = (1 - g)(s_T - s_P); its Frobenius
                # norm (= the axial overstress in uniaxial stress) is also
                # clipped at OVER: choice [D], a hard form of the bound
                ov = (trial[0] - sP[0], trial[1] - sP[1], trial[2] - sP[2],
                      trial[3] - sP[3], trial[4] - sP[4], trial[5] - sP[5])
                ovn = (1.0 - gam) * math.sqrt(ddot6(ov, ov))
                g1 = 1.0 - gam
                if ovn > over:
                    g1 *= over / ovn
                svp = (sP[0] + g1 * ov[0], sP[1] + g1 * ov[1], sP[2] + g1 * ov[2],
                       sP[3] + g1 * ov[3], sP[4] + g1 * ov[4], sP[5] + g1 * ov[5])
                J1v, rv = j1_radius(svp)
                # dynamic-to-static strength ratio sqrt(J2'_vp / J2'_P), the
                # shear-strength ratio of the J2'-based surface: choice [D]
                # for the "dynamic/static strength" of notes sec. 1.10 (the
                # ratio of full-tensor norms was tried: it hardly rises under
                # confinement and lets ductile damage start early in the disc,
                # see docs/cscm.md)
                rf = rv / rp if rp > 0.0 and rv > rp else 1.0
            else:
                svp = sP
                J1v = J1p
            # plastic compaction (compression positive) and cap hardening:
            # X = X(ev) of the compaction law. ITRETRC = 0 (default): the cap
            # never retracts (X only grows); ITRETRC = 1: X follows ev both
            # ways, so dilation pulls the cap back, never inside X0 (notes
            # sec. 1.3/1.7 [V flag text], mechanism [R/D])
            h[H_EV] += (J1t - J1v) / (3.0 * K)
            if h[H_EV] > 0.0 or p[P_RETRACT] > 0.0:
                X = cap_from_compaction(h[H_EV], p)
                Xold = mer[3]
                if X > Xold or (p[P_RETRACT] > 0.0 and X < Xold):
                    h[H_KAPPA] = kappa_from_cap(X, kappa, p)
            # damage thresholds: the damage state variable at first yield
            # (notes sec. 1.9 [R]), evaluated at the yield-onset point inside
            # the sub-step so that it does not depend on the increment size
            if (J1v < 0.0 and h[H_R0T] <= 0.0) or (J1v >= 0.0 and h[H_R0C] <= 0.0):
                s0 = elastic_increment(svp_old, scale6(de, 0.0), K, G)
                fr = yield_fraction(s0, trial, kappa, p)
                e_on = (eps[0] - (1.0 - fr) * de[0], eps[1] - (1.0 - fr) * de[1],
                        eps[2] - (1.0 - fr) * de[2], eps[3] - (1.0 - fr) * de[3],
                        eps[4] - (1.0 - fr) * de[4], eps[5] - (1.0 - fr) * de[5])
                s_on = (s0[0] + fr * (trial[0] - s0[0]), s0[1] + fr * (trial[1] - s0[1]),
                        s0[2] + fr * (trial[2] - s0[2]), s0[3] + fr * (trial[3] - s0[3]),
                        s0[4] + fr * (trial[4] - s0[4]), s0[5] + fr * (trial[5] - s0[5]))
                if J1v < 0.0:
                    h[H_R0T] = max(math.sqrt(E) * max_principal(e_on), 1e-30)
                else:
                    h[H_R0C] = max(math.sqrt(max(0.5 * ddot6(s_on, e_on), 0.0)), 1e-30)
        # damage evolution. logistic_damage is 0 while the damage state
        # variable has not passed its threshold, so the softening
        # parameters (transition, pow, log) are formed only past it, and the
        # largest principal strain only where its bound could raise tau_t:
        # the same results, with the transcendental functions skipped
        if h[H_R0T] > 0.0 or h[H_R0C] > 0.0:
            J1v, rv = j1_radius(svp)
            # rate-enhanced thresholds (choice [D]; notes sec. 1.9 [R] only
            # say that they increase with rate): r0 x the largest dynamic-to-
            # static strength ratio reached, so that damage starts at the
            # viscoplastic (dynamic) strength; never decreasing, like a
            # damage threshold. In uniaxial stress tau = rf r0 at the dynamic
            # peak for both tau_t = sqrt(E) eps and tau_c = sqrt(s:eps/2).
            # damage_growth (docs/cscm.md): "state" (0) evaluates the damage at
            # every step past the threshold, "loading" (1) only in a step that
            # raises tau past its largest value so far
            on_loading = p[P_GROW_ON_LOADING]
            rscale = 1.0
            if irate and p[P_RATE_R0] > 0.0:
                if rf > h[H_RFMAX]:
                    h[H_RFMAX] = rf
                rscale = h[H_RFMAX]
            if J1v < 0.0 and h[H_R0T] > 0.0:
                sqrt_e = math.sqrt(E)
                grew = False
                if sqrt_e * max_principal_bound(eps) > h[H_TT]:
                    tau = sqrt_e * max(max_principal(eps), 0.0)
                    if tau > h[H_TT]:
                        h[H_TT] = tau
                        grew = True
                r0 = h[H_R0T] * rscale
                if h[H_TT] > r0 and (grew or on_loading == 0.0):
                    tr = transition(J1v, rv, p[P_PWRT])
                    gf = (p[P_GFS] + tr * (p[P_GFT] - p[P_GFS])) * damage_scale(rf, irate, p)
                    cc = brittle_softening_c(r0, size, gf, p[P_DD])
                    db = logistic_damage(h[H_TT], r0, cc, p[P_DD], DMAX)
                    if db > h[H_DB]:
                        h[H_DB] = db
            elif J1v >= 0.0 and h[H_R0C] > 0.0:
                tau = math.sqrt(max(0.5 * ddot6(svp, eps), 0.0))
                grew = tau > h[H_TC]
                if grew:
                    h[H_TC] = tau
                r0 = h[H_R0C] * rscale
                if h[H_TC] > r0 and (grew or on_loading == 0.0):
                    tr = transition(J1v, rv, p[P_PWRC])
                    gf = (p[P_GFS] + tr * (p[P_GFC] - p[P_GFS])) * damage_scale(rf, irate, p)
                    aa = ductile_softening_a(r0, size, gf, p[P_BB], p[P_LI2B])
                    # maximum ductile damage vs confinement: choice [D] (formula
                    # not retrieved, notes sec. 1.9): DMAX (sqrt(3 J2')/J1)^power
                    ratio = math.sqrt(3.0) * rv / J1v if J1v > 0.0 else 1.0
                    dmax = DMAX * power(min(ratio, 1.0), p[P_DMAX_POWER])
                    dd = logistic_damage(h[H_TC], r0, aa, p[P_BB], dmax)
                    if dd > h[H_DD]:
                        h[H_DD] = dd
    h[H_RF] = rf
    for k in range(6):
        h[H_SVP + k] = svp[k]
        h[H_EPS + k] = eps[k]
    # applied damage and recovery (notes sec. 1.9 [V flag / R mechanism]):
    # brittle damage is recovered to RECOV d_b under compressive pressure
    # (option 1, RECOV 0-1) and, for option 2 (RECOV 10-11), only if the
    # volumetric strain is compressive as well
    J1v = -(svp[0] + svp[1] + svp[2])
    compressed = J1v > 0.0
    if p[P_RECOV_VOL] > 0.0 and eps[0] + eps[1] + eps[2] >= 0.0:
        compressed = False
    if compressed:
        d = max(p[P_RECOV] * h[H_DB], h[H_DD])
    else:
        d = max(h[H_DB], h[H_DD])
    # erosion (notes sec. 1.9 ERODE [V text, R reading]): d > 0.99 and max
    # principal strain > erode_strain (= ERODE - 1)
    if p[P_ERODE] > 0.0 and d > 0.99 and max_principal(eps) > p[P_ERODE_STRAIN]:
        h[H_ERODED] = 1.0
        m = (svp[0] + svp[1] + svp[2]) / 3.0
        m = m if m < 0.0 else 0.0
        for k in range(3):
            h[H_SVP + k] = m
            h[H_SVP + 3 + k] = 0.0
        return (m, m, m, 0.0, 0.0, 0.0), 1.0
    return scale6(svp, 1.0 - d), d


@njit(cache=True, error_model="numpy")
def damage_scale(rf, irate, p):
    """Fracture-energy scale ``rf^REPOW`` of the rate effects (1 without them):
    the softening's ``GF`` grows with the dynamic-to-static strength ratio
    ``rf`` (notes sec. 1.10 [V name, R form])."""
    return power(rf, p[P_REPOW]) if irate else 1.0


@njit(cache=True, error_model="numpy", parallel=True)
def cscm_update(idx, L, dt, rho, sig, e, c, damage, hist, params, size):
    """Group kernel of the CSCM model (common kernel signature).

    For each ``i`` in ``idx``: Jaumann rotation of the damaged stress (for the
    energy balance), of the stored undamaged stress and of the total strain;
    :func:`cscm_point`; energy increment; ``damage[i]`` = total damage;
    ``c[i] = sqrt((1-d)(K + 4G/3)/rho)`` with the damaged moduli (``sqrt(K/rho)``
    with the undamaged K for an eroded point, which keeps a compressive
    pressure), or ``sqrt((K + 4G/3)/rho)`` with the switch ``wave_speed =
    "undamaged"`` (``P_WAVE_UNDAMAGED``; eroded points as before).
    Shapes/units: ``base.KERNEL_SIGNATURE_DOC``.

    The particles are dealt round-robin, in runs of ``STRIPE_RUN``
    consecutive ones, to ``N_STRIPES`` interleaved stripes (stripe ``t``
    takes ``idx[32 t : 32 t + 32]``, then the run ``64 x 32`` further on,
    ...) and the stripes to the threads: plastic points cost ten times more
    than elastic ones and cluster in space (the contact zone), which a
    contiguous split of ``idx`` would give to one thread. The runs keep the
    history rows (24 doubles each) read in order, which the hardware
    prefetches; particle by particle (a stride of 64 rows) every row was a
    cache miss (BENCHMARKS.md, 2026-11-27 later). Each particle writes only
    its own rows, so the order changes no result.
    """
    n = idx.shape[0]
    for t in prange(N_STRIPES):
        for k0 in range(t * STRIPE_RUN, n, N_STRIPES * STRIPE_RUN):
            for k in range(k0, min(k0 + STRIPE_RUN, n)):
                _update_particle(idx[k], L, dt, rho, sig, e, c, damage, hist, params, size)


@njit(cache=True, error_model="numpy")
def _update_particle(i, L, dt, rho, sig, e, c, damage, hist, params, size):
    """One particle of :func:`cscm_update`."""
    K = params[P_K]
    G = params[P_G]
    d, w = rate_split(L, i)
    s_old = jaumann_rotate(load_sym6(sig, i), w, dt)
    h = hist[i]
    svp = jaumann_rotate((h[H_SVP], h[H_SVP + 1], h[H_SVP + 2],
                          h[H_SVP + 3], h[H_SVP + 4], h[H_SVP + 5]), w, dt)
    ep = jaumann_rotate((h[H_EPS], h[H_EPS + 1], h[H_EPS + 2],
                         h[H_EPS + 3], h[H_EPS + 4], h[H_EPS + 5]), w, dt)
    for j in range(6):
        h[H_SVP + j] = svp[j]
        h[H_EPS + j] = ep[j]
    s_new, dmg = cscm_point(h, scale6(d, dt), dt, params, size[i])
    store_sym6(sig, i, s_new)
    damage[i] = dmg
    e[i] += energy_increment(s_old, s_new, d, dt, rho[i])
    if h[H_ERODED] > 0.0:
        c[i] = p_wave_speed(K, 0.0, rho[i])
    elif params[P_WAVE_UNDAMAGED] > 0.0:
        c[i] = p_wave_speed(K, G, rho[i])
    else:
        c[i] = p_wave_speed((1.0 - dmg) * K, (1.0 - dmg) * G, rho[i])
