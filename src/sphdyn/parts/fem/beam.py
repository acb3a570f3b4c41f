r"""Numba kernels of the line elements: the co-rotational beam and the truss.

Beam (2 nodes, 6 degrees of freedom per node): a co-rotational resultant
Timoshenko beam (Belytschko & Schwer 1977; Crisfield 1991 for the element
frame and the local rotations :math:`\theta_i = \log(E^T R_i E^0)`), elastic
resultants :math:`N, T, M_a, M_b` of Przemieniecki (1968) and nodal forces in
equilibrium in the current configuration. Truss (2 nodes, 3 degrees of
freedom): :math:`N = A\sigma_{11}` along the chord, the logarithmic strain
rate :math:`\ln(l^{n+1}/l^n)/\Delta t`. The model, its equations and their
tests: docs/theory.md, "Beams and trusses".

Conventions: SI units; ``x`` (N, 3) [m]; ``triad`` (N, 3, 3); ``conn``
(E, 2); element nodal loads ``fe`` (E, 2, 6): force [N] and moment [N m]
*on* node ``a`` (row 0) and ``b`` (row 1), in global axes; every element
writes only its own row (no races), and :func:`.gather.gather_loads` sums
them per node (columns 0-2, then 3-5) through the node -> element list
(``ptr`` (N+1,), ``ent`` (2E,) = 2 element + end).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ...algebra3 import load9, matmul9, tmatmul9

#: columns of the beam's element resultants ``res`` (E, 9)
RES_N, RES_T, RES_MY_A, RES_MY_B, RES_MZ_A, RES_MZ_B, RES_VY, RES_VZ, RES_L = range(9)
N_RES = 9


# ----------------------------------------------------------------- rotations
@njit(cache=True, error_model="numpy")
def rotation_from_vector(p0, p1, p2):
    r"""Rotation matrix of the rotation vector ``p`` [rad] (Rodrigues' formula).

    .. math:: R = I + \frac{\sin\theta}{\theta}[p]_\times
              + \frac{1-\cos\theta}{\theta^2}[p]_\times^2,\qquad \theta = |p|

    (e.g. Crisfield 1997, vol. 2, eq. 16.14); the coefficients switch to
    their Taylor series below ``theta = 1e-4`` (error below 1e-24).
    Returns the 9-tuple of ``R`` row by row.
    """
    t2 = p0 * p0 + p1 * p1 + p2 * p2
    if t2 < 1e-8:
        a = 1.0 - t2 / 6.0 + t2 * t2 / 120.0
        b = 0.5 - t2 / 24.0 + t2 * t2 / 720.0
    else:
        t = math.sqrt(t2)
        a = math.sin(t) / t
        b = (1.0 - math.cos(t)) / t2
    return (1.0 + b * (p0 * p0 - t2), -a * p2 + b * p0 * p1, a * p1 + b * p0 * p2,
            a * p2 + b * p0 * p1, 1.0 + b * (p1 * p1 - t2), -a * p0 + b * p1 * p2,
            -a * p1 + b * p0 * p2, a * p0 + b * p1 * p2, 1.0 + b * (p2 * p2 - t2))


@njit(cache=True, error_model="numpy")
def rotation_vector(r):
    r"""Rotation vector [rad] of the rotation matrix ``r`` (9-tuple, row by row).

    .. math:: \cos\theta = \tfrac12(\mathrm{tr} R - 1),\quad
              w = \mathrm{axial}\big(\tfrac12(R - R^T)\big) = \sin\theta\,\hat n,
              \quad \theta\hat n = \frac{\theta}{\sin\theta}\, w

    (the inverse of :func:`rotation_from_vector`, valid for angles below pi;
    local beam rotations are far smaller). Returns a 3-tuple.
    """
    c = 0.5 * (r[0] + r[4] + r[8] - 1.0)
    w0 = 0.5 * (r[7] - r[5])
    w1 = 0.5 * (r[2] - r[6])
    w2 = 0.5 * (r[3] - r[1])
    s = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
    if s < 1e-6 and c > 0.0:
        f = 1.0 + s * s / 6.0  # theta / sin(theta), series
    else:
        f = math.atan2(s, c) / s
    return (f * w0, f * w1, f * w2)


@njit(cache=True, error_model="numpy", parallel=True)
def drift_rotations(triad, w, rot_x, dt):
    r"""Advance the nodal triads by the incremental rotation of one step.

    .. math:: R_i \leftarrow \exp([\omega_i \Delta t]_\times)\, R_i,\qquad
              \phi_i \leftarrow \phi_i + \omega_i\Delta t

    with the spatial (global-axes) angular velocity ``w`` (N, 3) [rad/s] at
    the half step (Simo & Vu-Quoc 1988, exponential update of the rotation;
    Crisfield 1997, sec. 16.4). ``triad`` (N, 3, 3) in place; ``rot_x``
    (N, 3) the accumulated rotation vector [rad] (output only); ``dt`` [s].
    """
    for i in prange(triad.shape[0]):
        q = rotation_from_vector(dt * w[i, 0], dt * w[i, 1], dt * w[i, 2])
        r = matmul9(q, load9(triad, i))
        for k in range(9):
            triad[i, k // 3, k % 3] = r[k]
        rot_x[i, 0] += dt * w[i, 0]
        rot_x[i, 1] += dt * w[i, 1]
        rot_x[i, 2] += dt * w[i, 2]


# --------------------------------------------------------------------- beam
@njit(cache=True, error_model="numpy", parallel=True)
def beam_forces(x, triad, conn, frame0, L0, EA, GJ, EIy, EIz, phi_y, phi_z, fe, res,
                energy):
    r"""Co-rotational elastic beam: element resultants, nodal loads, strain energy.

    Equations in the module docstring (Belytschko & Schwer 1977; Crisfield
    1991 for the frame; Przemieniecki 1968 for the Timoshenko stiffness).

    Parameters
    ----------
    x : (N, 3) nodal positions [m]; triad : (N, 3, 3) nodal rotations.
    conn : (E, 2) nodes a, b; frame0 : (E, 3, 3) initial element frame,
        columns :math:`e_1^0, e_2^0, e_3^0`.
    L0 : (E,) initial length [m]; EA [N], GJ [N m^2], EIy, EIz [N m^2] : (E,)
        rigidities; phi_y, phi_z : (E,) shear parameters
        :math:`\Phi = 12EI/(\kappa G A L_0^2)` of the two bending planes.
    fe : (E, 2, 6) out, force [N] and moment [N m] on nodes a, b (global).
    res : (E, 9) out, resultants ``N, T, My_a, My_b, Mz_a, Mz_b, Vy, Vz, l``
        [N, N m, m]: axial force (tension positive), torque, the end moments
        of the stiffness relation (local axes), the shear forces
        :math:`V_y = (M_{z,a}+M_{z,b})/l`, :math:`V_z = -(M_{y,a}+M_{y,b})/l`
        and the current length.
    energy : (E,) out, strain energy [J].
    """
    for e in prange(conn.shape[0]):
        a = conn[e, 0]
        b = conn[e, 1]
        d0 = x[b, 0] - x[a, 0]
        d1 = x[b, 1] - x[a, 1]
        d2 = x[b, 2] - x[a, 2]
        l = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        x0 = d0 / l
        x1 = d1 / l
        x2 = d2 / l
        f0 = load9(frame0, e)
        ma = matmul9(load9(triad, a), f0)  # material frames of the element at a, b
        mb = matmul9(load9(triad, b), f0)
        q0 = ma[1] + mb[1]
        q1 = ma[4] + mb[4]
        q2 = ma[7] + mb[7]
        z0 = x1 * q2 - x2 * q1
        z1 = x2 * q0 - x0 * q2
        z2 = x0 * q1 - x1 * q0
        zn = math.sqrt(z0 * z0 + z1 * z1 + z2 * z2)
        z0 /= zn
        z1 /= zn
        z2 /= zn
        y0 = z1 * x2 - z2 * x1
        y1 = z2 * x0 - z0 * x2
        y2 = z0 * x1 - z1 * x0
        fr = (x0, y0, z0, x1, y1, z1, x2, y2, z2)
        ta = rotation_vector(tmatmul9(fr, ma))
        tb = rotation_vector(tmatmul9(fr, mb))
        u = l - L0[e]
        n = EA[e] * u / L0[e]
        t = GJ[e] * (tb[0] - ta[0]) / L0[e]
        cy = EIy[e] / (L0[e] * (1.0 + phi_y[e]))
        cz = EIz[e] / (L0[e] * (1.0 + phi_z[e]))
        my_a = cy * ((4.0 + phi_y[e]) * ta[1] + (2.0 - phi_y[e]) * tb[1])
        my_b = cy * ((2.0 - phi_y[e]) * ta[1] + (4.0 + phi_y[e]) * tb[1])
        mz_a = cz * ((4.0 + phi_z[e]) * ta[2] + (2.0 - phi_z[e]) * tb[2])
        mz_b = cz * ((2.0 - phi_z[e]) * ta[2] + (4.0 + phi_z[e]) * tb[2])
        vy = (mz_a + mz_b) / l
        vz = -(my_a + my_b) / l
        # loads on node a in local axes (node b: the force reversed)
        fa0, fa1, fa2 = n, -vy, -vz
        for k in range(3):
            fe[e, 0, k] = fr[3 * k] * fa0 + fr[3 * k + 1] * fa1 + fr[3 * k + 2] * fa2
            fe[e, 1, k] = -fe[e, 0, k]
            fe[e, 0, 3 + k] = fr[3 * k] * t - fr[3 * k + 1] * my_a - fr[3 * k + 2] * mz_a
            fe[e, 1, 3 + k] = -fr[3 * k] * t - fr[3 * k + 1] * my_b - fr[3 * k + 2] * mz_b
        res[e, RES_N] = n
        res[e, RES_T] = t
        res[e, RES_MY_A] = my_a
        res[e, RES_MY_B] = my_b
        res[e, RES_MZ_A] = mz_a
        res[e, RES_MZ_B] = mz_b
        res[e, RES_VY] = vy
        res[e, RES_VZ] = vz
        res[e, RES_L] = l
        energy[e] = 0.5 * (n * u + t * (tb[0] - ta[0]) + my_a * ta[1] + my_b * tb[1]
                           + mz_a * ta[2] + mz_b * tb[2])


@njit(cache=True, error_model="numpy", inline="always")
def _beam_element_dt(e, x, conn, L0, rho, A, E, G, Iy, Iz, J, kappa, inertia_e):
    """Beam element ``e``'s step :math:`2/\\omega_{max}` (:func:`beam_stable_dt`)."""
    a = conn[e, 0]
    b = conn[e, 1]
    l = math.sqrt((x[b, 0] - x[a, 0]) ** 2 + (x[b, 1] - x[a, 1]) ** 2
                  + (x[b, 2] - x[a, 2]) ** 2)
    m = 0.5 * rho * A * L0[e]
    w2 = 2.0 * E * A / (l * m)
    ir = inertia_e[e]
    if ir > 0.0:
        for ii in (Iy, Iz):
            phi = 12.0 * E * ii / (kappa * G * A * l * l)
            c = E * ii / (l ** 3 * (1.0 + phi))
            w2 = max(w2, c * (24.0 / m + 6.0 * l * l / ir), 2.0 * E * ii / (l * ir))
        w2 = max(w2, 2.0 * G * J / (l * ir))
    return 2.0 / math.sqrt(w2)


@njit(cache=True, error_model="numpy")
def beam_stable_dt(x, conn, L0, rho, A, E, G, Iy, Iz, J, kappa, inertia_e, scale, dt_mass):
    r"""Stable step of the beam elements and the controlling element.

    :math:`\Delta t = s\, 2/\omega_{max}` with :math:`\omega_{max}` the
    largest frequency of the element alone with its share of the lumped
    masses, :math:`m = \rho A L_0/2` and rotary inertia :math:`I_r`
    (``inertia_e``) per node; it bounds the frequencies of the assembled mesh
    (Hughes 1987, *The Finite Element Method*, sec. 9.3, element eigenvalue
    inequality). With the current length :math:`l`:

    * axial: :math:`\omega^2 = 2EA/(l m)` (:math:`= 4E/(\rho l^2)`);
    * bending, mode :math:`(v, \theta, -v, \theta)` of each plane:
      :math:`\omega^2 = \frac{EI}{l^3(1+\Phi)}(24/m + 6l^2/I_r)` (the other
      eigenvalue of that mode pair is the rigid rotation);
    * bending, mode :math:`(v, \theta, v, -\theta)`: :math:`2EI/(l I_r)`;
    * torsion: :math:`2GJ/(l I_r)`.

    Units: lengths [m], rho [kg/m^3], A [m^2], E, G [Pa], I, J [m^4],
    inertia_e (E,) [kg m^2]; ``scale`` the safety factor; ``dt_mass`` (E,) the
    elements' mass-scaling step factors (1 without). Returns ``(dt [s],
    element)``.
    """
    best = np.inf
    k = 0
    for e in range(conn.shape[0]):
        dt = _beam_element_dt(e, x, conn, L0, rho, A, E, G, Iy, Iz, J, kappa,
                              inertia_e) * dt_mass[e]
        if dt < best:
            best = dt
            k = e
    return scale * best, k


@njit(cache=True, error_model="numpy")
def beam_element_steps(x, conn, L0, rho, A, E, G, Iy, Iz, J, kappa, inertia_e, scale, out):
    """Each beam element's own step (:func:`beam_stable_dt` before the minimum,
    without mass scaling) into ``out`` (E,) [s]."""
    for e in range(conn.shape[0]):
        out[e] = scale * _beam_element_dt(e, x, conn, L0, rho, A, E, G, Iy, Iz, J, kappa,
                                          inertia_e)


# -------------------------------------------------------------------- truss
@njit(cache=True, error_model="numpy", parallel=True)
def truss_kinematics(x, conn, l_prev, L0, rho0, dt, l_now, eps_rate, rho):
    r"""Chord length, logarithmic strain rate and density of the truss elements.

    :math:`\dot\varepsilon = \ln(l^{n+1}/l^{n})/\Delta t` [1/s] (exact for
    the logarithmic strain; 0 when ``dt <= 0``); :math:`\rho = \rho_0
    L_0/l` [kg/m^3] (mass per length conserved at the constant area ``A``,
    so that the stress power :math:`\sigma\dot\varepsilon\, m/\rho` equals the
    power :math:`N\dot l` of the nodal forces). ``x`` (N, 3), ``conn``
    (E, 2); ``l_prev``, ``L0`` (E,) [m]; out ``l_now``, ``eps_rate``, ``rho``
    (E,).
    """
    for e in prange(conn.shape[0]):
        a = conn[e, 0]
        b = conn[e, 1]
        l = math.sqrt((x[b, 0] - x[a, 0]) ** 2 + (x[b, 1] - x[a, 1]) ** 2
                      + (x[b, 2] - x[a, 2]) ** 2)
        l_now[e] = l
        eps_rate[e] = math.log(l / l_prev[e]) / dt if dt > 0.0 else 0.0
        rho[e] = rho0 * L0[e] / l


@njit(cache=True, error_model="numpy", parallel=True)
def truss_gradient(eps_rate, lat_rate, L):
    r"""Velocity gradient of each truss point in the bar's frame.

    :math:`L = \mathrm{diag}(\dot\varepsilon, \dot\varepsilon_{lat},
    \dot\varepsilon_{lat})` [1/s], axis 1 along the bar; symmetric, so the
    material's Jaumann rotation is the identity and the stress stays in the
    co-rotating frame. ``eps_rate``, ``lat_rate`` (P,); ``L`` (P, 3, 3) out.
    """
    for i in prange(L.shape[0]):
        for r in range(3):
            for s in range(3):
                L[i, r, s] = 0.0
        L[i, 0, 0] = eps_rate[i]
        L[i, 1, 1] = lat_rate[i]
        L[i, 2, 2] = lat_rate[i]


@njit(cache=True, error_model="numpy", parallel=True)
def lateral_secant(sig, eps_rate, lat_rate, lat_old, res_old, first, k_lat, dt, rtol, done):
    r"""One step of the per-point search for the uniaxial-stress lateral rate.

    The residual is the mean lateral stress :math:`r = (\sigma_{22} +
    \sigma_{33})/2` [Pa] after the material update with the trial
    ``lat_rate``. A point is converged when :math:`|r| \le r_{tol}
    (|\sigma_{11}| + k_{lat}|\dot\varepsilon|\Delta t)`; otherwise the next
    trial is the tangent step with the elastic lateral modulus
    :math:`\partial r/\partial(\dot\varepsilon_{lat}\Delta t) = k_{lat} =
    2(K + G/3)` on the first iteration (``first``), then the secant step
    :math:`x \leftarrow x - r (x - x_{old})/(r - r_{old})` (regula falsi
    without bracketing; e.g. Press et al., *Numerical Recipes*, sec. 9.2).
    ``sig`` (P, 3, 3) [Pa]; ``eps_rate``, ``lat_rate``, ``lat_old``,
    ``res_old`` (P,); ``done`` (P,) int8 out. Returns the number of points
    not converged.
    """
    left = 0
    for i in prange(sig.shape[0]):
        r = 0.5 * (sig[i, 1, 1] + sig[i, 2, 2])
        tol = rtol * (abs(sig[i, 0, 0]) + k_lat * abs(eps_rate[i]) * dt)
        if abs(r) <= tol:
            done[i] = 1
            continue
        done[i] = 0
        left += 1
        x = lat_rate[i]
        dr = r - res_old[i]
        if first or dr == 0.0 or x == lat_old[i]:
            nx = x - r / (k_lat * dt)
        else:
            nx = x - r * (x - lat_old[i]) / dr
        lat_old[i] = x
        res_old[i] = r
        lat_rate[i] = nx
    return left


@njit(cache=True, error_model="numpy")
def lateral_ratio(lat_rate, eps_rate, ratio):
    """``ratio = lat_rate / eps_rate`` (P,) where the bar deforms (the next
    step's first trial); kept where ``eps_rate`` is 0."""
    for i in range(ratio.shape[0]):
        if eps_rate[i] != 0.0:
            ratio[i] = lat_rate[i] / eps_rate[i]


@njit(cache=True, error_model="numpy", parallel=True)
def truss_forces(x, conn, sig, A, fe, res):
    r"""Nodal forces of the truss elements: :math:`N = A\sigma_{11}` along the chord.

    Force on node a :math:`+N e_1`, on node b :math:`-N e_1` (tension pulls
    the nodes together), :math:`e_1 = (x_b - x_a)/l`. ``sig`` (E, 3, 3) the
    points' stress in the bar frame [Pa]; ``A`` [m^2]; ``fe`` (E, 2, 6) out
    (moments zero); ``res`` (E, 9) out, column 0 the axial force [N], column
    8 the length [m].
    """
    for e in prange(conn.shape[0]):
        a = conn[e, 0]
        b = conn[e, 1]
        d0 = x[b, 0] - x[a, 0]
        d1 = x[b, 1] - x[a, 1]
        d2 = x[b, 2] - x[a, 2]
        l = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        n = A * sig[e, 0, 0]
        fe[e, 0, 0] = n * d0 / l
        fe[e, 0, 1] = n * d1 / l
        fe[e, 0, 2] = n * d2 / l
        for k in range(3):
            fe[e, 1, k] = -fe[e, 0, k]
            fe[e, 0, 3 + k] = 0.0
            fe[e, 1, 3 + k] = 0.0
        res[e, RES_N] = n
        res[e, RES_L] = l


@njit(cache=True, error_model="numpy", inline="always")
def _truss_length(e, x, conn):
    a = conn[e, 0]
    b = conn[e, 1]
    return math.sqrt((x[b, 0] - x[a, 0]) ** 2 + (x[b, 1] - x[a, 1]) ** 2
                     + (x[b, 2] - x[a, 2]) ** 2)


@njit(cache=True, error_model="numpy")
def truss_stable_dt(x, conn, c, scale, dt_mass):
    r"""Stable step :math:`s \min_e g_e l_e / c` of two lumped masses on a spring
    (:math:`\omega = 2c/l`, :math:`\Delta t_{crit} = 2/\omega`; Belytschko,
    Liu & Moran 2000, sec. 6.3) and the controlling element. ``c`` the bar
    wave speed :math:`\sqrt{E/\rho}` [m/s], ``dt_mass`` (E,) the elements'
    mass-scaling step factors :math:`g_e` (1 without)."""
    best = np.inf
    k = 0
    for e in range(conn.shape[0]):
        dt = _truss_length(e, x, conn) / c * dt_mass[e]
        if dt < best:
            best = dt
            k = e
    return scale * best, k


@njit(cache=True, error_model="numpy")
def truss_element_steps(x, conn, c, scale, out):
    r"""Each truss element's own step :math:`s\,l_e/c` into ``out`` (E,) [s]."""
    for e in range(conn.shape[0]):
        out[e] = scale * (_truss_length(e, x, conn) / c)


# ------------------------------------------------------------------- gather
@njit(cache=True, error_model="numpy", parallel=True)
def mass_damping(v, m, damping, a, power):
    r"""Mass-proportional damping :math:`\mathbf a_i \mathrel{-}= c\,\mathbf v_i`
    on the half-step velocities ``v`` (N, 3) and its power
    :math:`c\, m_i |\mathbf v_i|^2` [W] added to ``power`` (N,); ``m`` (N,)
    masses (or rotary inertias with angular velocities), ``c`` [1/s]; nothing
    for a massless node (its ``a`` is zero)."""
    for i in prange(m.shape[0]):
        if m[i] > 0.0:
            a[i, 0] -= damping * v[i, 0]
            a[i, 1] -= damping * v[i, 1]
            a[i, 2] -= damping * v[i, 2]
            power[i] += damping * m[i] * (v[i, 0] ** 2 + v[i, 1] ** 2 + v[i, 2] ** 2)
