r"""Central-difference (leapfrog) time integration and time-step control.

The stepper knows no physics: it advances arrays given accelerations. With
velocities stored at half steps,

.. math::
    \mathbf v^{n+1/2} = \mathbf v^{n-1/2} + \Delta t^{n} \,\mathbf a^{n},\qquad
    \mathbf x^{n+1} = \mathbf x^{n} + \Delta t^{n+1/2} \,\mathbf v^{n+1/2},

with :math:`\Delta t^{n} = (\Delta t^{n-1/2} + \Delta t^{n+1/2})/2` (the
first kick is a half step, :math:`\mathbf v^{1/2} = \mathbf v^0 +
\tfrac12\Delta t\, \mathbf a^0`). The scheme is second-order accurate and
symplectic for constant steps (Belytschko, Liu & Moran 2000, sec. 6.2;
LS-DYNA Theory Manual, central difference).

Energy bookkeeping is fused into the kick: the kinetic energy at the integer
time :math:`t^n` uses :math:`\mathbf v^n = (\mathbf v^{n-1/2} + \mathbf
v^{n+1/2})/2`, and the work of contact and boundary forces over the kick is
:math:`\sum_i m_i \mathbf a^c_i\cdot\mathbf v^n_i \Delta t^n`, which makes the
discrete work-energy balance exact for the kick.

The model and its tests: docs/theory.md, "Time integration".
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from .state import BC_COMPONENTS, BC_FIXED, BC_SLAVE


#: particles per block of the kick's energy sums: the sums are taken block by
#: block in a fixed order, so they do not depend on the number of threads
KICK_BLOCK = 1024


def kick_scratch(n: int) -> np.ndarray:
    """Scratch (blocks, 3) for :func:`kick`'s per-block energy sums of ``n`` particles."""
    return np.zeros((n // KICK_BLOCK + 1, 3))


@njit(cache=True, error_model="numpy", parallel=True)
def kick(v, a, a_contact, m, bc, bc_v, dt_kick, v_out_mean, sums):
    r"""Velocity kick with boundary conditions and energy bookkeeping.

    ``v`` (N, 3) is advanced in place from :math:`n-1/2` to :math:`n+1/2`;
    ``a`` (N, 3) is the total acceleration (including ``a_contact``, the part
    from contact, (N, 3)). ``bc``/``bc_v`` impose fixed or prescribed
    velocities, on every component or (``BC_COMPONENTS | mask``) on the
    masked ones only, the others free. ``v_out_mean`` (N, 3) receives
    :math:`\mathbf v^n`. ``sums`` is
    the (blocks, 3) scratch of :func:`kick_scratch`: each block of
    :data:`KICK_BLOCK` particles is summed in order, then the blocks in order,
    so the energies are the same bits on any number of threads.
    ``BC_SLAVE`` items (the slaves of a tied or hybrid coupling) are left as
    they are and booked nowhere: their masters carry their mass, and the
    coupling sets their velocity after the kick.

    Returns
    -------
    kinetic : float, :math:`\tfrac12 \sum m |\mathbf v^n|^2` [J]
    contact_work : float, work done by contact forces on the particles over
        the kick [J]
    external_work : float, work done by the boundary-condition reactions [J]
    """
    n = v.shape[0]
    nb = (n + KICK_BLOCK - 1) // KICK_BLOCK
    for b in prange(nb):
        ke = 0.0
        wc = 0.0
        we = 0.0
        for i in range(b * KICK_BLOCK, min(n, (b + 1) * KICK_BLOCK)):
            if bc[i] == BC_SLAVE:
                v_out_mean[i, 0] = v[i, 0]
                v_out_mean[i, 1] = v[i, 1]
                v_out_mean[i, 2] = v[i, 2]
                continue
            mi = m[i]
            n0 = v[i, 0] + dt_kick * a[i, 0]
            n1 = v[i, 1] + dt_kick * a[i, 1]
            n2 = v[i, 2] + dt_kick * a[i, 2]
            if bc[i] != 0:
                if bc[i] == BC_FIXED:
                    t0 = 0.0
                    t1 = 0.0
                    t2 = 0.0
                elif bc[i] >= BC_COMPONENTS:  # the masked components only
                    mask = bc[i] - BC_COMPONENTS
                    t0 = bc_v[i, 0] if mask & 1 else n0
                    t1 = bc_v[i, 1] if mask & 2 else n1
                    t2 = bc_v[i, 2] if mask & 4 else n2
                else:
                    t0 = bc_v[i, 0]
                    t1 = bc_v[i, 1]
                    t2 = bc_v[i, 2]
                # reaction impulse m (v_target - v_free) does work on the particle
                mm0 = 0.5 * (v[i, 0] + t0)
                mm1 = 0.5 * (v[i, 1] + t1)
                mm2 = 0.5 * (v[i, 2] + t2)
                we += mi * ((t0 - n0) * mm0 + (t1 - n1) * mm1 + (t2 - n2) * mm2)
                n0 = t0
                n1 = t1
                n2 = t2
            m0 = 0.5 * (v[i, 0] + n0)
            m1 = 0.5 * (v[i, 1] + n1)
            m2 = 0.5 * (v[i, 2] + n2)
            ke += 0.5 * mi * (m0 * m0 + m1 * m1 + m2 * m2)
            wc += mi * dt_kick * (a_contact[i, 0] * m0 + a_contact[i, 1] * m1
                                  + a_contact[i, 2] * m2)
            v_out_mean[i, 0] = m0
            v_out_mean[i, 1] = m1
            v_out_mean[i, 2] = m2
            v[i, 0] = n0
            v[i, 1] = n1
            v[i, 2] = n2
        sums[b, 0] = ke
        sums[b, 1] = wc
        sums[b, 2] = we
    kinetic = 0.0
    contact_work = 0.0
    external_work = 0.0
    for b in range(nb):
        kinetic += sums[b, 0]
        contact_work += sums[b, 1]
        external_work += sums[b, 2]
    return kinetic, contact_work, external_work


@njit(cache=True, error_model="numpy", parallel=True)
def drift(x, v, dt):
    """Position update ``x += dt * v`` (in place); ``x``, ``v`` (N, 3)."""
    n = x.shape[0]
    for i in prange(n):
        x[i, 0] += dt * v[i, 0]
        x[i, 1] += dt * v[i, 1]
        x[i, 2] += dt * v[i, 2]


@njit(cache=True, error_model="numpy", inline="always")
def _cfl_step(i, h, c, v, signal, viscous, factor, r, scale):
    """Particle ``i``'s CFL step before the Courant number (:func:`cfl_time_step`),
    with the wave-speed factor ``r``; with ``r = 1`` the bits of the step without
    mass scaling."""
    sp = np.sqrt(v[i, 0] ** 2 + v[i, 1] ** 2 + v[i, 2] ** 2)
    return factor[i] * (scale * h[i] / (r * c[i] + sp + viscous[i] * (r * signal[i])
                                        + 1e-300))


@njit(cache=True, error_model="numpy")
def cfl_time_step(h, c, v, signal, viscous, factor, c_mass, scale, cfl):
    r"""CFL-limited time step.

    .. math:: \Delta t = C \min_i \frac{f_i\, s\, h_i}
              {r_i\,(c_i + w_i\, v^{sig}_i) + |\mathbf v_i|},
              \quad s = \min(1, \kappa)

    (Monaghan 1992; LS-DYNA SPH time step), with ``factor`` :math:`f_i`
    (a material's time-step factor) and, for the particles of fluid
    materials, the artificial viscosity's signal speed ``signal``
    :math:`v^{sig}_i = \max_j(\bar\alpha_{ij} \bar c_{ij} + \bar\beta_{ij}
    |\mu_{ij}|)` of the last force pass weighted by ``viscous``
    :math:`w_i` (1.2, Monaghan 1992, sec. 10; 0 for solids). ``c_mass``
    :math:`r_i = \sqrt{m_i / (m_i + \Delta m_i)}` is the wave-speed factor of
    selective mass scaling (:mod:`sphdyn.mass_scaling`; 1 without it): added
    inertia slows the particle's waves, not its own motion. Zero-mass
    particles are included (they move with the body). ``h``, ``c``,
    ``signal``, ``viscous``, ``factor``, ``c_mass`` (N,), ``v`` (N, 3). A
    serial O(N) loop without allocation (its cost is far below one pair pass).
    Returns the step [s] and the index of the controlling particle.
    """
    best = np.inf
    k = 0
    for i in range(h.shape[0]):
        t = _cfl_step(i, h, c, v, signal, viscous, factor, c_mass[i], scale)
        if t < best:
            best = t
            k = i
    return cfl * best, k


@njit(cache=True, error_model="numpy")
def cfl_mass_factors(h, c, v, signal, viscous, factor, scale, cfl, target, c_mass):
    r"""The wave-speed factors that bring each particle's CFL step up to ``target``.

    :func:`cfl_time_step`'s particle step solved for :math:`r_i`:
    :math:`C f_i s h_i / (r_i W_i + |\mathbf v_i|) = \Delta t^*` gives
    :math:`r_i = (C f_i s h_i / \Delta t^* - |\mathbf v_i|) / W_i`, taken as 1
    where the step is above the target already (:math:`W_i = c_i + w_i
    v^{sig}_i`; within 1e-9 of the target counts as at it). The mass that does
    it is :math:`\Delta m_i = m_i (1/r_i^2 - 1)` (the particle's wave speed is
    :math:`\sqrt{K/\rho}` of its stiffness over its inertia). :math:`r_i \le 0`
    means the particle's own speed alone limits its step below the target: no
    mass helps (the caller refuses it).
    Out ``c_mass`` (N,).
    """
    for i in range(h.shape[0]):
        if cfl * _cfl_step(i, h, c, v, signal, viscous, factor, 1.0, scale) \
                >= (1.0 - 1e-9) * target:  # at the target to round-off: left alone
            c_mass[i] = 1.0
        else:
            sp = np.sqrt(v[i, 0] ** 2 + v[i, 1] ** 2 + v[i, 2] ** 2)
            wave = c[i] + viscous[i] * signal[i]
            c_mass[i] = (cfl * factor[i] * scale * h[i] / target - sp) / (wave + 1e-300)


@njit(cache=True, error_model="numpy")
def ordered_sum(values):
    """Sum of ``values`` (N,) in index order (the same bits on any thread count
    and any BLAS)."""
    s = 0.0
    for i in range(values.shape[0]):
        s += values[i]
    return s


@njit(cache=True, error_model="numpy")
def internal_energies(m, e, e_av):
    """Total internal energy and its artificial-viscosity part [J]."""
    s = 0.0
    s_av = 0.0
    for i in range(m.shape[0]):
        s += m[i] * e[i]
        s_av += m[i] * e_av[i]
    return s, s_av


@njit(cache=True, error_model="numpy")
def add_heat(e, e_av, dedt_av, dt):
    """Add viscous heating ``dt * dedt_av`` to ``e`` and ``e_av`` (N,) in place."""
    for i in range(e.shape[0]):
        q = dt * dedt_av[i]
        e[i] += q
        e_av[i] += q
