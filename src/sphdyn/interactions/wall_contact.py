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

A spring's energy is kept when its stiffness changes under load. The
mass-based :math:`k_i = \alpha m_i/\Delta t^2` follows the current step,
which drops as the bodies deform: applied as it is, a spring loaded at
:math:`k_1` and released at :math:`k_2 > k_1` gives back :math:`\tfrac12 k_2
e^2` of the :math:`\tfrac12 k_1 e^2` it took. So each particle keeps its
spring's stiffness per unit mass :math:`k_i/m_i` of the last evaluation and an
allowance :math:`\delta_{0i}` (penetration without force); the spring acts on
the extension :math:`e_i = \delta_i - \delta_{0i}`, and when :math:`k` has
changed from :math:`k_1` to :math:`k_2` the extension is scaled to keep the
spring's energy, :math:`e \leftarrow \min(e\sqrt{k_1/k_2},\ \delta)` (the
allowance takes the difference; :func:`keep_spring_energy`, the rule of the
SPH-FEM penalty coupling). The allowance only shrinks as the particle moves
out, and is zero for particles present at the start, so with a constant step
(and always with the bulk spring) the force is eq. 8 or 9 unchanged.
Particles born during the run (eroded elements, injected particles; their
stiffness marked :data:`BORN`) take their penetration at their first
evaluation as allowance (LS-DYNA's IGNORE = 2): a spring that was never
loaded releases no energy.

Optional Coulomb friction opposes the tangential velocity with magnitude
:math:`\mu |F_n|`, capped so that it cannot reverse the tangential velocity
within one step (a regularised stick condition).

The model and its tests: docs/theory.md, "Rigid wall with penalty contact".
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

STIFFNESS_MASS = 0
STIFFNESS_BULK = 1
#: a spring's stiffness marking a particle born since the last evaluation
BORN = -1.0


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
def keep_spring_energy(i, pen, ext, k, pen0, k_last):
    r"""The extension [m] of spring ``i`` after its stiffness became ``k``.

    A spring of extension :math:`e` stores :math:`\tfrac12 k_1 e^2`; when its
    stiffness changes from :math:`k_1` (``k_last[i]``, 0: not loaded at the
    last evaluation) to :math:`k_2` (``k``) the extension becomes
    :math:`e\sqrt{k_1/k_2}`, which keeps that energy, at most the
    penetration ``pen`` [m] (a softer spring takes its extension back from
    the allowance while there is one; beyond it the difference is lost, never
    made). ``pen0`` (N,) in/out, the allowance [m], takes ``pen - e``;
    ``k_last`` (N,) in/out, takes ``k``. ``k`` in any unit proportional to the
    stiffness (N/m, or N/m per kg of the particle): only the ratio counts.
    """
    if k_last[i] > 0.0 and k != k_last[i]:
        ext = min(ext * np.sqrt(k_last[i] / k), pen)
        pen0[i] = pen - ext
    k_last[i] = k
    return ext


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
                 thickness_factor, method, alpha, friction, dt, a_contact, force,
                 pen0, k_last):
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
    pen0 : (N,) in/out, each particle's allowance [m]: the penetration it
        has without force (module docstring); set to 0 out of contact.
    k_last : (N,) in/out, each spring's stiffness per unit mass of the last
        evaluation [1/s^2] (:math:`\alpha/\Delta t^2` for the mass spring);
        0 out of contact; :data:`BORN` for a particle born since the last
        evaluation (its penetration becomes its allowance).

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
                if pen0[i] != 0.0 or k_last[i] != 0.0:  # (most rows: read, not written)
                    pen0[i] = 0.0
                    k_last[i] = 0.0
                continue
        pen = contact_thickness(vol0[i], dim, thickness_factor) - gap
        if pen <= 0.0:
            pen0[i] = 0.0
            k_last[i] = 0.0
            continue
        if pen < pen0[i] or k_last[i] == BORN:
            pen0[i] = pen
        ext = pen - pen0[i]
        if ext <= 0.0:  # within its allowance
            k_last[i] = 0.0
            continue
        count += 1
        # the energy rule compares the stiffness per unit mass; the
        # acceleration itself is eq. 8 / 9 of the extension (the same bits as
        # of the penetration while there is no allowance)
        k1 = spring_acceleration(1.0, method, alpha, dt, kbulk[i], vol0[i], rho[i], dim)
        ext = keep_spring_energy(i, pen, ext, k1, pen0, k_last)
        an = spring_acceleration(ext, method, alpha, dt, kbulk[i], vol0[i], rho[i], dim)
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
