r"""Rigid planar wall with penalty contact (particles as slave nodes).

A particle touches the wall when its centre is closer than
:math:`t_i = f_t V_i^{1/d}` (``thickness_factor`` times its spacing). With the
signed distance :math:`g_i = (\mathbf x_i - \mathbf p)\cdot\mathbf n` and the
penetration :math:`\delta_i = t_i - g_i > 0`, the normal force is

.. math:: \mathbf F_i = k_i\, \delta_i\, \mathbf n

with the spring stiffness of Hušek et al. (2017):

* mass-based, paper eq. (8): :math:`k_i = \alpha m_i / \Delta t^2`, i.e. an
  acceleration :math:`\alpha \delta_i / \Delta t^2` that is the same for a
  zero-mass particle (the limit :math:`m \to 0`);
* bulk-modulus-based, paper eq. (9): :math:`k_i = \alpha K A_i / L_i` with
  :math:`A_i = V_i^{(d-1)/d}` and :math:`L_i = V_i^{1/d}` (the particle's
  face area and size; in 2D per unit depth, so :math:`k = \alpha K`). The
  acceleration uses the particle's nominal inertia :math:`\rho_{0i} V_i`
  (its mass in a homogeneous body), :math:`a = k\delta / (\rho_0 V)`, so
  zero-mass particles (initial cracks) and the light particles of a random
  mass field get the same, bounded acceleration and the stable time step
  :math:`2\sqrt{\rho_0 V/k}` does not collapse; the force a particle
  reports and exerts is :math:`m_i a` (a conservative spring of stiffness
  :math:`k\, m_i/(\rho_0 V)`; zero for zero mass).

A wall may move with a constant velocity :math:`\mathbf u` (a platen of a
compression test): the caller passes the current point
:math:`\mathbf p(t) = \mathbf p_0 + \mathbf u t`, and friction acts on the
velocity relative to the wall.

Optional Coulomb friction opposes the tangential velocity with magnitude
:math:`\mu |F_n|`, capped so that it cannot reverse the tangential velocity
within one step (a regularised stick condition).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

STIFFNESS_MASS = 0
STIFFNESS_BULK = 1


@njit(cache=True, error_model="numpy")
def contact_thickness(vol0, dim, thickness_factor):
    r"""Contact thickness :math:`t = f_t V^{1/d}` of one particle [m].

    ``vol0`` its nominal volume [m^dim], ``thickness_factor`` :math:`f_t`
    (0.5: the particle's cell touches the surface when its centre is half a
    spacing away).
    """
    return thickness_factor * vol0 ** (1.0 / dim)


@njit(cache=True, error_model="numpy")
def spring_acceleration(pen, method, alpha, dt, kbulk, vol0, rho0, dim):
    r"""Normal acceleration [m/s^2] of a particle pressed ``pen`` [m] into a surface.

    * mass-based, Hušek et al. (2017) eq. (8): :math:`k = \alpha m/\Delta t^2`,
      so :math:`a = \alpha\,\delta/\Delta t^2` whatever the mass;
    * bulk-based, eq. (9): :math:`k = \alpha K A/L = \alpha K V^{(d-2)/d}`
      acting on the nominal inertia :math:`\rho_0 V`:
      :math:`a = k\delta/(\rho_0 V)`.

    The force the particle feels and exerts is :math:`m a` (module
    docstring). ``kbulk`` [Pa], ``vol0`` [m^dim], ``rho0`` [kg/m^3] and
    ``dt`` [s] are the particle's bulk modulus, nominal volume, reference
    density and the stable step.
    """
    if method == STIFFNESS_MASS:
        return alpha * pen / (dt * dt)
    k = alpha * kbulk * vol0 ** ((dim - 2.0) / dim)
    return k * pen / (rho0 * vol0)


@njit(cache=True, error_model="numpy")
def column_sums(a, out):
    """``out[k] = sum_i a[i, k]`` for ``a`` (N, 3), row by row in order: the
    bits of NumPy's ``a.sum(axis=0)`` (which adds a C-ordered array's rows in
    turn), without its per-row inner-loop call (1 ms at 100k rows, a tenth
    of a hex3d step). ``out`` (3,) out."""
    s0 = 0.0
    s1 = 0.0
    s2 = 0.0
    for i in range(a.shape[0]):
        s0 += a[i, 0]
        s1 += a[i, 1]
        s2 += a[i, 2]
    out[0] = s0
    out[1] = s1
    out[2] = s2


@njit(cache=True, error_model="numpy", parallel=True)
def wall_contact(x, v, m, vol0, rho, kbulk, dim, point, normal, wall_v,
                 thickness_factor, method, alpha, friction, dt, a_contact, force):
    r"""Penalty contact accelerations of one rigid wall (gather form).

    Parameters
    ----------
    x, v : (N, 3) positions [m] and mid-step velocities [m/s].
    m, vol0, rho : (N,) mass [kg], nominal volume [m^dim], reference density
        [kg/m^3] (``rho * vol0`` is the nominal inertia of the bulk method).
    kbulk : (N,) bulk modulus [Pa] used by the bulk method.
    point, normal : (3,) a point of the wall (at the current time) and its
        unit normal (towards the bodies).
    wall_v : (3,) velocity of the wall [m/s] (friction acts on v - wall_v).
    thickness_factor, method, alpha, friction, dt : see module docstring.
    a_contact : (N, 3) in/out, contact acceleration is **added**.
    force : (N, 3) out, force on each particle [N] (N/m in 2D); zero for
        zero-mass particles and particles not in contact.

    Returns
    -------
    n_contact : int, number of particles in contact.
    """
    n = x.shape[0]
    count = 0
    # gap^d > f^d V (with a margin far above the root's rounding) means
    # gap > f V^(1/d): out of contact without the root (a libm call per
    # particle, most of the pass when few touch)
    far = 1.000001 * thickness_factor ** dim
    for i in prange(n):
        force[i, 0] = 0.0
        force[i, 1] = 0.0
        force[i, 2] = 0.0
        gap = ((x[i, 0] - point[0]) * normal[0] + (x[i, 1] - point[1]) * normal[1]
               + (x[i, 2] - point[2]) * normal[2])
        if gap > 0.0:
            gd = gap if dim == 1 else (gap * gap if dim == 2 else gap * gap * gap)
            if gd > far * vol0[i]:
                continue
        pen = contact_thickness(vol0[i], dim, thickness_factor) - gap
        if pen <= 0.0:
            continue
        count += 1
        an = spring_acceleration(pen, method, alpha, dt, kbulk[i], vol0[i], rho[i], dim)
        a0 = an * normal[0]
        a1 = an * normal[1]
        a2 = an * normal[2]
        if friction > 0.0:
            r0 = v[i, 0] - wall_v[0]
            r1 = v[i, 1] - wall_v[1]
            r2 = v[i, 2] - wall_v[2]
            vn = r0 * normal[0] + r1 * normal[1] + r2 * normal[2]
            t0 = r0 - vn * normal[0]
            t1 = r1 - vn * normal[1]
            t2 = r2 - vn * normal[2]
            vt = np.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
            if vt > 0.0:
                at = min(friction * an, vt / dt)
                a0 -= at * t0 / vt
                a1 -= at * t1 / vt
                a2 -= at * t2 / vt
        a_contact[i, 0] += a0
        a_contact[i, 1] += a1
        a_contact[i, 2] += a2
        force[i, 0] = m[i] * a0
        force[i, 1] = m[i] * a1
        force[i, 2] = m[i] * a2
    return count


def bulk_contact_time_step(m, vol0, rho, kbulk, dim, alpha):
    r"""Stability limit of the bulk-modulus spring, :math:`2\sqrt{m/k}`.

    The mass-based spring needs none (:math:`\omega\Delta t = \sqrt\alpha`).
    Returns the minimum over particles [s].
    """
    inertia = rho * vol0  # nominal inertia, see the module docstring
    k = alpha * kbulk * vol0 ** ((dim - 2.0) / dim)
    return float(np.min(2.0 * np.sqrt(inertia / k)))
