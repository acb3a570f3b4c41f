r"""SPH-FEM coupling by penalty contact: particles as slave nodes, element faces as master.

The thesis couples SPH and finite elements with "the penalty-based contact
algorithm with the nodal penetration detection in which the nodes would be
represented by SPH particles" (chapter 4, "Coupling SPH and FEM"). Here each
particle :math:`p` of an SPH part is a slave node; the master surface is a set
of boundary faces of a solid part (by default all exterior faces,
:func:`~.penalty_geometry.exterior_faces`).

Contact of one particle. For each candidate face the closest point
:math:`\mathbf x_c = \sum_a N_a(\xi,\eta)\,\mathbf x_a` and the outward
normal :math:`\mathbf n` there are found (:func:`~.penalty_geometry.closest_point`);
the particle takes the face with the closest point (ties: the lower face
index). With :math:`\mathbf r = \mathbf x_p - \mathbf x_c` and the contact
thickness :math:`t_p = f_t V_p^{1/d}` (as at the rigid wall,
:mod:`.wall_contact`) the gap and the contact direction are

* :math:`g = \mathbf r\cdot\mathbf n - t_p`, :math:`\hat{\mathbf e} =
  \mathbf n`, when the closest point is inside the face (the particle is in
  front of or behind the face itself);
* :math:`g = |\mathbf r| - t_p`, :math:`\hat{\mathbf e} = \mathbf r/|\mathbf r|`,
  when it is on the face's boundary and the particle is in front of the
  face's plane (the particle's sphere touches an edge or a corner: continuous
  with the first case); no contact when it is on the boundary and behind
  (a particle inside the body beside a crater's edge, say: its depth is not
  measured there, so its allowance, below, stays as it was).

If :math:`g < 0` the penetration :math:`\delta = -g` gives the particle the
normal force of the wall's spring, :func:`~.wall_contact.spring_acceleration`
(Hušek et al. 2017, eq. 9: :math:`k = \alpha K A/L` on the nominal inertia
:math:`\rho_0 V`, :math:`F_n = m_p a_n`; or eq. 8, :math:`k = \alpha
m/\Delta t^2`, with :math:`m` the smaller of the particle's mass and the mass
the face opposes at the contact point,

.. math:: m = \min(m_p, m_f),\qquad \frac{1}{m_f} = \sum_a \frac{N_a^2}{m_a},
          \qquad F_n = \alpha\,\frac{m}{\Delta t^2}\,\delta,

as LS-DYNA's SOFT = 1 takes the smaller of the slave's and the master's
masses: eq. 8 itself against a face at least as heavy as the particle (a
rigid wall: :math:`m_f \to \infty`), and for the two-mass spring
:math:`\omega^2\Delta t^2 = \alpha\,(1 + m_{min}/m_{max}) \le 2\alpha` whatever
the masses. With :math:`m_p` alone a heavy particle on the light corner node
of a mesh left by erosion, :math:`m_p/m_f \approx 26`, gives :math:`\omega
\Delta t = \sqrt{\alpha(1 + 26)} = 1.6` at :math:`\alpha = 0.1`, near the
central difference's limit of 2 (it pumped energy into the penetration
runs)), and the force

.. math:: \mathbf F_p = F_n \hat{\mathbf e} + \mathbf F_t,\qquad
          \mathbf F_a = -N_a(\xi, \eta)\,\mathbf F_p \quad (a \in \text{face}),

so the face nodes take the equal and opposite force shared with the face's
shape functions at the contact point: linear momentum is conserved exactly
(:math:`\sum_a N_a = 1`) and the normal part derives from the potential
:math:`\tfrac12 k\delta^2` (at the closest point :math:`\partial g/\partial
\mathbf x_a = -N_a \hat{\mathbf e}`), so the interface stores its energy
(``E_contact``) and gives it back.

Stiffness and the time step. Eq. 8's :math:`\Delta t` is by default the
step of the evaluation (``stiffness_step = "current"``); with ``"largest"``
it is the largest stable step so far, :math:`\Delta t_k = \max_{n' \le
n}\Delta t^{n'}`, so a spring's stiffness never grows while it is loaded.
Where elements crush the step drops (to half and less in the penetration
runs) and recovers when they erode. A spring at the largest step is stable
at every shorter one (:math:`\omega\Delta t \le \sqrt{2\alpha}\,\Delta
t/\Delta t_k`) and softer than eq. 8 at the current step by
:math:`(\Delta t/\Delta t_k)^2` while the step is down. What each did in
the 800 m/s erosion run is in docs/theory.md ("SPH-FEM coupling by
penalty").

A spring's stiffness changes. :math:`k` of one particle's spring changes
while it is loaded: with the step (``"current"``), with the mass the face
point opposes (:math:`1/m_f = \sum_a N_a^2/m_a` varies fourfold across a
face as the contact point slides, and drops as erosion takes the nodes'
element shares), and at a switch of face. Applied as it is, a spring whose
:math:`k` grows from :math:`k_1` to :math:`k_2` gives back :math:`\tfrac12
k_2 e^2` of the :math:`\tfrac12 k_1 e^2` it took (:math:`e = \delta -
\delta_0`, its extension): energy from nothing, four times the stored
energy at half the step. So at each evaluation the extension is scaled to
keep the spring's energy, :math:`e \leftarrow e\sqrt{k_1/k_2}` (the
allowance :math:`\delta_0` takes the difference, at least 0), and the
force is :math:`k_2 e`: a stiffer spring pushes harder by
:math:`\sqrt{k_2/k_1}` but stores no more energy; a softer one takes its
extension back from the allowance while there is one (else the difference
is lost, never made). The spring's force
remains the gradient of :math:`\tfrac12 k e^2` at fixed :math:`k`, so a
load-unload cycle at changing :math:`k` does no net work.

Friction (optional, coefficient :math:`\mu`) acts on the relative tangential
velocity :math:`\mathbf v_t` of the particle and the face point,
:math:`\mathbf v_r = \mathbf v_p - \sum_a N_a \mathbf v_a`,
:math:`\mathbf v_t = \mathbf v_r - (\mathbf v_r\cdot\hat{\mathbf e})\hat{\mathbf e}`:
:math:`\mathbf F_t = -\min(\mu |F_n|,\ m^\ast |\mathbf v_t|/\Delta t)\,
\mathbf v_t/|\mathbf v_t|` with the effective mass of the contact
:math:`1/m^\ast = 1/m_p + \sum_a N_a^2/m_a`: the regularised Coulomb law of
the wall, capped so that one step cannot reverse the relative sliding.

Zero-mass particles (initial cracks) are pushed out with the spring's
acceleration and exert no force, as at the wall.

Particles born during the run (eroded elements, :mod:`sphdyn.events.erosion`)
and particles that face a newly exposed face may start inside the contact
thickness. The spring then acts on the penetration beyond the one they had
at that moment, :math:`\delta - \delta_0`, with :math:`\delta_0` only
shrinking as they move out (LS-DYNA's IGNORE = 2): a spring that was never
loaded releases no energy. Particles present at the start have
:math:`\delta_0 = 0`.

A particle that switches from one face to another may find itself deeper
than its motion can have taken it: behind a warped or crushed face, or
facing a face that erosion has just exposed. Between two evaluations its
signed penetration :math:`d = -g` can grow by at most the approach of the
motion, :math:`|\mathbf v_r|\,\Delta t` (the particle's and the face
point's relative velocity over the step); at a switch of face the excess

.. math:: \Delta\delta_0 = \max(d' - d - |\mathbf v_r|\,\Delta t,\ 0)

is added to the allowance (at most up to :math:`\delta'`), so the spring's
extension, and its force, grow only by what the motion explains. On the
same face the same excess is allowed when it passes half the contact
thickness (``JUMP_FRACTION``): an element crushed through itself turns its
face over a particle beside it, whose depth then leaps by millimetres in one
step (a sphere's particle at 1879 m/s into concrete went from 2 mm outside
such a face's contact thickness to 3 mm inside it, and the spring threw it off at 5 km/s
with 450 J made from nothing); smaller excesses on the same face are the
motion's second-order terms and act as they are. When
erosion changes the master surface every particle meets its face again at
once, at the positions of the last evaluation (:math:`\Delta t = 0`): a
particle whose face eroded meets the face behind it with the force it had; a
particle that faced none may face a newly exposed face inside its thickness,
and is allowed that penetration. Without this, a projectile particle that had
touched a crushed, warped element lightly met the face behind it 2 mm deep
(a thousand times the force) and the 1000 m/s penetration run took kilojoules
of spurious work from such jumps.

The slaves may also be the nodes of another solid part (``[mesh.contact]
meshes``: node-to-surface contact between meshes, LS-DYNA's
*CONTACT_AUTOMATIC_NODES_TO_SURFACE with that mesh as the slave side). A node
is treated as a particle of its elements' mean size :math:`h_I`
(:func:`~sphdyn.parts.fem.solid_part.node_contact_items`, as at a wall): its
contact thickness is :math:`f_t h_I`, its mass spring takes the smaller of
the node's and the face point's masses. The contact is one-way: the master
mesh's nodes do not meet the slave's faces unless that mesh lists it too.

Limitations: one face per particle (at a concave corner of the master
surface a particle is held out of the nearer face only). With the default
master surface (all exterior faces) the faces follow erosion: an eroded
element exposes its neighbours' faces (:meth:`PenaltyCoupling.mesh_changed`);
a surface given as faces keeps those of them whose elements remain.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from .base import InteractionBase
from .penalty_geometry import (candidate_pairs, closest_point, exterior_faces, face_anchors,
                               face_nodes, face_point, face_shapes, face_twins)
from .wall import STIFFNESS
from .wall_contact import (STIFFNESS_BULK, STIFFNESS_MASS, contact_thickness,
                           keep_spring_energy, spring_acceleration)

#: relative lateral offset under which a clamped closest point counts as inside the face
_INSIDE_RTOL = 1e-9


@njit(cache=True, error_model="numpy")
def face_inverse_mass(mn, face, N):
    r""":math:`1/m_f = \sum_a N_a^2/m_a` [1/kg], the inverse of the mass the point
    of ``face`` (nf,) with shape values ``N`` (4,) opposes to a force (module
    docstring); nodes without mass (``mn`` (M,) [kg]) take no force and do not
    count."""
    inv = 0.0
    for a in range(face.shape[0]):
        node = face[a]
        if mn[node] > 0.0:
            inv += N[a] * N[a] / mn[node]
    return inv


@njit(cache=True, error_model="numpy")
def _relative_velocity(vp, vn, i, face, N):
    r""":math:`\mathbf v_p - \sum_a N_a \mathbf v_a` [m/s] (3 floats) of particle
    ``i`` (``vp`` (N, 3)) against the point of ``face`` (nf,) with shape values
    ``N`` (``vn`` (M, 3) node velocities)."""
    w0 = vp[i, 0]
    w1 = vp[i, 1]
    w2 = vp[i, 2]
    for a in range(face.shape[0]):
        w0 -= N[a] * vn[face[a], 0]
        w1 -= N[a] * vn[face[a], 1]
        w2 -= N[a] * vn[face[a], 2]
    return w0, w1, w2


@njit(cache=True, error_model="numpy")
def spring_mass(m_p, inv_f):
    r"""The mass of eq. 8's spring, :math:`\min(m_p, m_f)` [kg], of a particle of
    mass ``m_p`` [kg] on a face point of inverse mass ``inv_f``
    (:func:`face_inverse_mass`)."""
    return m_p if inv_f * m_p <= 1.0 else 1.0 / inv_f


#: On the same face, a depth that grows beyond the motion's approach by more
#: than this fraction of the contact thickness is geometry, not motion (the
#: face flipped or warped under the particle; module docstring): the excess
#: is allowed without force. Below it, the motion's second-order terms (a
#: face turning or bending under a sliding point) act as they are.
JUMP_FRACTION = 0.5


@njit(cache=True, error_model="numpy", parallel=True)
def penalty_coupling_forces(xp, vp, mp, vol0, rho0, kbulk, dim, xn, vn, mn, faces,
                            offsets, cand, thickness_factor, method, alpha, friction, dt,
                            a_p, a_n, face_of, shares, force, normal_force, accel, skip,
                            pen0, last_face, d_last, k_last, motion_dt):
    r"""Particle-face penalty forces (module docstring) into the particles' and nodes' ``a``.

    Parameters
    ----------
    xp, vp : (N, 3) particle positions [m] and mid-step velocities [m/s].
    mp, vol0, rho0, kbulk : (N,) mass [kg], nominal volume [m^dim], reference
        density [kg/m^3], bulk modulus [Pa] (kg/m, m^2 per unit depth in 2D).
    dim : 2 or 3.
    xn, vn, mn : (M, 3), (M, 3), (M,) node positions, velocities, masses.
    faces : (F, nf) master faces (4 nodes in 3D, 2 in 2D).
    offsets, cand : CSR candidate faces of each particle
        (:func:`~.penalty_geometry.candidate_pairs`).
    thickness_factor, method, alpha, friction, dt : the contact law
        (:func:`~.wall_contact.spring_acceleration`, Coulomb coefficient,
        stable step [s]).
    a_p : (N, 3) in/out, the particles' accelerations are **added** [m/s^2].
    a_n : (M, 3) in/out, the nodes' accelerations are **added** [m/s^2].
    face_of : (N,) out, the face each particle touches (-1: none).
    shares : (N, 4, 3) out, the force on each node of that face [N]
        (:math:`-N_a \mathbf F_p`; rows past nf unused).
    force : (N, 3) out, the force on each particle [N] (N/m in 2D).
    normal_force : (N,) out, its component along the contact direction [N].
    accel : (N, 3) out, the acceleration added to each particle [m/s^2]
        (:func:`withdraw_contact` takes it back).
    skip : (N,) bool, particles left out (those tied by :func:`tie_forces`).
    pen0 : (N,) in/out, penetration each particle is allowed without force
        [m] (a particle born or exposed inside the contact thickness): the
        spring acts on :math:`\delta - \delta_0`, and :math:`\delta_0` only
        shrinks, to the smallest penetration seen (LS-DYNA's IGNORE = 2).
    last_face, d_last : (N,) in/out, the face each particle faced at the last
        evaluation (-1: none, so no switch is checked; -2: unknown, a particle
        born since or faces renumbered, so any face is a switch) and its
        signed penetration there :math:`d = -g` [m] (:math:`-\infty` with -2
        for a particle that faced none: its whole penetration is allowed). At a
        switch of face the spring's extension grows
        by at most the approach the motion allows, :math:`|\mathbf v_r|`
        ``motion_dt``; the allowance takes the excess (module docstring); on
        the same face, an excess beyond ``JUMP_FRACTION`` of the contact
        thickness.
    k_last : (N,) in/out, each particle's spring stiffness :math:`k` [N/m]
        (:math:`F_n = k(\delta - \delta_0)`) at the last evaluation (0: not
        loaded).
        When it changes under load (the face point's mass, the step, a new
        face) the extension is scaled so that the spring's energy
        :math:`\tfrac12 k(\delta - \delta_0)^2` stays what it was
        (module docstring, "A spring's stiffness changes").
    motion_dt : time [s] the particles moved since the last evaluation (the
        step; 0 when the faces changed under unmoved particles).

    Returns
    -------
    n_contact : int, particles in contact.

    The particle loop is parallel and writes only its own rows; the nodes'
    share is then gathered serially, in particle order (4 adds per contact;
    deterministic on any number of threads).
    """
    n = xp.shape[0]
    nf = faces.shape[1]
    count = 0
    for i in prange(n):
        face_of[i] = -1
        force[i, 0] = 0.0
        force[i, 1] = 0.0
        force[i, 2] = 0.0
        normal_force[i] = 0.0
        accel[i, 0] = 0.0
        accel[i, 1] = 0.0
        accel[i, 2] = 0.0
        if skip[i]:
            continue
        best = np.inf
        bf = -1
        xi, eta, cx, cy, cz, nx, ny, nz, clamped = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, False
        for k in range(offsets[i], offsets[i + 1]):
            f = cand[k]
            res = closest_point(xp[i], xn, faces[f])
            r0 = xp[i, 0] - res[2]
            r1 = xp[i, 1] - res[3]
            r2 = xp[i, 2] - res[4]
            d2 = r0 * r0 + r1 * r1 + r2 * r2
            if d2 < best or (d2 == best and f < bf):
                best = d2
                bf = f
                xi, eta, cx, cy, cz, nx, ny, nz, clamped = res
        if bf < 0:
            pen0[i] = 0.0
            last_face[i] = -1
            k_last[i] = 0.0
            continue
        r0 = xp[i, 0] - cx
        r1 = xp[i, 1] - cy
        r2 = xp[i, 2] - cz
        rn = r0 * nx + r1 * ny + r2 * nz
        tp = contact_thickness(vol0[i], dim, thickness_factor)
        l0 = r0 - rn * nx
        l1 = r1 - rn * ny
        l2 = r2 - rn * nz
        lat = np.sqrt(l0 * l0 + l1 * l1 + l2 * l2)
        if (not clamped) or lat <= _INSIDE_RTOL * tp:
            gap = rn - tp
            e0, e1, e2 = nx, ny, nz
        elif rn > 0.0:
            dist = np.sqrt(r0 * r0 + r1 * r1 + r2 * r2)
            gap = dist - tp
            e0, e1, e2 = r0 / dist, r1 / dist, r2 / dist
        else:  # behind the plane of a face's boundary: no contact and no depth to
            # measure, so the allowance and the last face's depth are kept
            k_last[i] = 0.0
            continue
        pen = max(-gap, 0.0)
        N = face_shapes(xi, eta, nf)
        # the excess over the motion's approach that counts as geometry: any at
        # a switch of face, beyond JUMP_FRACTION of the thickness on the same face
        leap = 0.0 if bf != last_face[i] else JUMP_FRACTION * tp
        if last_face[i] != -1 and -gap - d_last[i] > leap:  # (else the excess is less)
            w0, w1, w2 = _relative_velocity(vp, vn, i, faces[bf], N)
            excess = -gap - d_last[i] - motion_dt * np.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
            if excess > leap:  # deeper than the motion can take it: geometry
                pen0[i] = min(pen0[i] + excess, pen)
        if pen < pen0[i]:
            pen0[i] = pen
        last_face[i] = bf
        d_last[i] = -gap
        ext = pen - pen0[i]
        if ext <= 0.0:
            k_last[i] = 0.0
            continue
        count += 1
        # the spring's acceleration per metre of extension [1/s^2]
        a1 = spring_acceleration(1.0, method, alpha, dt, kbulk[i], vol0[i], rho0[i], dim)
        if mp[i] <= 0.0:  # pushed out, no force of its own
            k_last[i] = 0.0
            an = a1 * ext
            accel[i, 0] = an * e0
            accel[i, 1] = an * e1
            accel[i, 2] = an * e2
            a_p[i, 0] += accel[i, 0]
            a_p[i, 1] += accel[i, 1]
            a_p[i, 2] += accel[i, 2]
            continue
        inv_f = face_inverse_mass(mn, faces[bf], N)
        kk = a1 * (spring_mass(mp[i], inv_f) if method == STIFFNESS_MASS else mp[i])
        ext = keep_spring_energy(i, pen, ext, kk, pen0, k_last)
        fn = kk * ext
        f0 = fn * e0
        f1 = fn * e1
        f2 = fn * e2
        if friction > 0.0:
            w0, w1, w2 = _relative_velocity(vp, vn, i, faces[bf], N)
            inv_meff = 1.0 / mp[i] + inv_f
            wn = w0 * e0 + w1 * e1 + w2 * e2
            t0 = w0 - wn * e0
            t1 = w1 - wn * e1
            t2 = w2 - wn * e2
            vt = np.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
            if vt > 0.0:
                ft = min(friction * fn, vt / (dt * inv_meff))
                f0 -= ft * t0 / vt
                f1 -= ft * t1 / vt
                f2 -= ft * t2 / vt
        accel[i, 0] = f0 / mp[i]
        accel[i, 1] = f1 / mp[i]
        accel[i, 2] = f2 / mp[i]
        a_p[i, 0] += accel[i, 0]
        a_p[i, 1] += accel[i, 1]
        a_p[i, 2] += accel[i, 2]
        force[i, 0] = f0
        force[i, 1] = f1
        force[i, 2] = f2
        normal_force[i] = fn
        face_of[i] = bf
        for a in range(4):
            s = N[a]
            shares[i, a, 0] = -s * f0
            shares[i, a, 1] = -s * f1
            shares[i, a, 2] = -s * f2
    for i in range(n):
        f = face_of[i]
        if f < 0:
            continue
        for a in range(nf):
            node = faces[f, a]
            if mn[node] > 0.0:
                a_n[node, 0] += shares[i, a, 0] / mn[node]
                a_n[node, 1] += shares[i, a, 1] / mn[node]
                a_n[node, 2] += shares[i, a, 2] / mn[node]
    return count


@njit(cache=True, error_model="numpy")
def withdraw_contact(face_of, faces, shares, accel, mn, a_p, a_n):
    """Take the contact accelerations of the last :func:`penalty_coupling_forces`
    out of ``a_p`` (N, 3) and ``a_n`` (M, 3) (its ``face_of``, ``faces``,
    ``shares``, ``accel``; node masses ``mn`` (M,) as then) [m/s^2]; serial,
    in the order they were added."""
    for i in range(face_of.shape[0]):
        for c in range(3):
            a_p[i, c] -= accel[i, c]
        f = face_of[i]
        if f < 0:
            continue
        for a in range(faces.shape[1]):
            node = faces[f, a]
            if mn[node] > 0.0:
                for c in range(3):
                    a_n[node, c] -= shares[i, a, c] / mn[node]


@njit(cache=True, error_model="numpy", parallel=True)
def tie_forces(tied, tie_face, tie_xi, tie_eta, tie_offset, xp, mp, vol0, rho0, kbulk, dim,
               xn, mn, faces, method, alpha, dt, a_p, a_n, shares, force):
    r"""Bilateral penalty springs of tied particles to their anchor points.

    A tied particle :math:`p` keeps its face, its parametric point
    :math:`(\xi, \eta)` and its normal offset :math:`g_0` from the start
    (the closest point then); its anchor moves with the face,
    :math:`\mathbf x_A = \sum_a N_a(\xi,\eta)\,\mathbf x_a + g_0\,\mathbf n`,
    and the spring of the contact law (:func:`~.wall_contact.spring_acceleration`,
    eq. 8 or 9, linear in the stretch) pulls it back in every direction:
    :math:`\mathbf F_p = -m_p\,\kappa\,(\mathbf x_p - \mathbf x_A)`,
    :math:`\kappa` the acceleration per metre of the law (for eq. 8 with the
    spring's mass :math:`\min(m_p, m_f)` of :func:`penalty_coupling_forces`,
    :math:`\kappa = \alpha \min(m_p, m_f)/(m_p\Delta t^2)`), and the face nodes take
    :math:`-N_a\mathbf F_p` (momentum conserved exactly; LS-DYNA's
    TIED_NODES_TO_SURFACE_OFFSET penalty option does the same with its own
    stiffness).

    Parameters
    ----------
    tied : (T,) particle indices; tie_face (T,) face index; tie_xi, tie_eta,
        tie_offset : (T,) parametric point and normal offset [m].
    xp, mp, vol0, rho0, kbulk, dim : the particles (as
        :func:`penalty_coupling_forces`).
    xn, mn, faces : node positions (M, 3), masses (M,), faces (F, nf).
    method, alpha, dt : the spring law.
    a_p : (N, 3) in/out, the particles' accelerations are **added**.
    a_n : (M, 3) in/out, the nodes' accelerations are **added**.
    shares : (T, 4, 3) out, force on each node of the face [N].
    force : (T, 3) out, force on each tied particle [N] (N/m in 2D).

    Returns
    -------
    The total force magnitude on the tied particles [N].
    """
    nt = tied.shape[0]
    nf = faces.shape[1]
    for k in prange(nt):
        i = tied[k]
        f = tie_face[k]
        cx, cy, cz, nx, ny, nz = face_point(xn, faces[f], tie_xi[k], tie_eta[k])
        d0 = xp[i, 0] - (cx + tie_offset[k] * nx)
        d1 = xp[i, 1] - (cy + tie_offset[k] * ny)
        d2 = xp[i, 2] - (cz + tie_offset[k] * nz)
        kappa = spring_acceleration(1.0, method, alpha, dt, kbulk[i], vol0[i], rho0[i], dim)
        N = face_shapes(tie_xi[k], tie_eta[k], nf)
        if method == STIFFNESS_MASS and mp[i] > 0.0:  # eq. 8 on the spring's mass
            kappa *= spring_mass(mp[i], face_inverse_mass(mn, faces[f], N)) / mp[i]
        a_p[i, 0] -= kappa * d0
        a_p[i, 1] -= kappa * d1
        a_p[i, 2] -= kappa * d2
        f0 = -mp[i] * kappa * d0
        f1 = -mp[i] * kappa * d1
        f2 = -mp[i] * kappa * d2
        force[k, 0] = f0
        force[k, 1] = f1
        force[k, 2] = f2
        for a in range(4):
            shares[k, a, 0] = -N[a] * f0
            shares[k, a, 1] = -N[a] * f1
            shares[k, a, 2] = -N[a] * f2
    total = 0.0
    for k in range(nt):
        f = tie_face[k]
        total += np.sqrt(force[k, 0] ** 2 + force[k, 1] ** 2 + force[k, 2] ** 2)
        for a in range(nf):
            node = faces[f, a]
            if mn[node] > 0.0:
                a_n[node, 0] += shares[k, a, 0] / mn[node]
                a_n[node, 1] += shares[k, a, 1] / mn[node]
                a_n[node, 2] += shares[k, a, 2] / mn[node]
    return total


@njit(cache=True, error_model="numpy", parallel=True)
def _max_shift(x, x_ref, rows):
    """Largest displacement [m] of the items ``rows`` (R,) since ``x_ref`` (N, 3)."""
    m = 0.0
    for k in prange(rows.shape[0]):
        i = rows[k]
        d0 = x[i, 0] - x_ref[i, 0]
        d1 = x[i, 1] - x_ref[i, 1]
        d2 = x[i, 2] - x_ref[i, 2]
        d = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if d != d:
            d = np.inf
        m = max(m, d)
    return m


def _extended(a: np.ndarray, n: int, fill) -> np.ndarray:
    """``a`` (rows, ...) with rows appended up to ``n``, each holding ``fill``."""
    out = np.full((n,) + a.shape[1:], fill, dtype=a.dtype)
    out[:a.shape[0]] = a
    return out


class PenaltyCoupling(InteractionBase):
    """Penalty contact of an SPH part's particles with a solid part's faces.

    Parameters
    ----------
    name : the interaction's name (history columns ``F_<name>``: total normal
        force on the interface [N] (N/m in 2D), ``contacts_<name>``: number
        of particles in contact).
    sph_part : the slave part: an SPH part (its particles are the slaves) or
        another solid part (its nodes are: node-to-surface contact between
        meshes); its ``p`` holds ``x, v, m, vol0, rho0, bulk_modulus`` (a
        solid part's nodes have them, with the size of their elements,
        :func:`~sphdyn.parts.fem.solid_part.node_contact_items`).
    solid_part : the solid part (its nodes carry the master faces).
    faces : (F, 4) quadrilaterals (3D) or (F, 2) segments (2D) of the solid
        part's node ids, oriented outward (:mod:`.penalty_geometry`);
        default: all exterior faces of the mesh.
    stiffness : ``"mass"`` (eq. 8) or ``"bulk"`` (eq. 9).
    alpha : penalty factor of the spring.
    thickness_factor : contact thickness in units of the particle size
        :math:`V^{1/d}` (0.5: particle cells touch the face).
    friction : Coulomb coefficient.
    skin_factor : Verlet skin of the candidate list in units of the largest
        contact thickness.
    stiffness_step : ``"current"`` (default): the mass springs' step is the
        step of each evaluation; ``"largest"``: the largest stable step so
        far, so a spring never stiffens as the step drops (module docstring,
        "Stiffness and the time step").
    tie_factor : 0 (default): contact only, the interface opens under
        tension. > 0: every particle whose closest point on a face lies inside
        the face and within ``tie_factor`` times its size :math:`V^{1/d}` at
        the start is tied there for good by a bilateral spring
        (:func:`tie_forces`), so the interface carries tension and shear as a
        continuous body would (the thesis's coupled beam, sec. 4.1); 1.0 ties
        the first layer of particles made from elements
        (:func:`~sphdyn.geometry.convert.elements_to_particles`, half a size
        from the face). Columns ``F_<name>_tie`` (sum of the tie forces'
        magnitudes [N]) and ``tied_<name>``.

    The candidate list holds the faces whose bounding box, grown by the reach
    :math:`2 t_{max}` plus the skin, holds a particle; it is built again when
    the largest particle displacement plus the largest face-node displacement
    since the build exceed the skin (then no pair within the reach can have
    been missed: a face point moves at most as far as its nodes).
    """

    def __init__(self, name: str, sph_part, solid_part, faces=None, stiffness: str = "mass",
                 alpha: float = 0.1, thickness_factor: float = 0.5, friction: float = 0.0,
                 skin_factor: float = 1.0, tie_factor: float = 0.0,
                 stiffness_step: str = "current"):
        if stiffness not in STIFFNESS:
            raise ValueError(f"{name}: stiffness must be one of {tuple(STIFFNESS)}, "
                             f"got {stiffness!r}")
        if alpha <= 0.0 or thickness_factor <= 0.0 or friction < 0.0 or skin_factor <= 0.0:
            raise ValueError(f"{name}: alpha, thickness_factor and skin_factor must be > 0 "
                             "and friction >= 0")
        if tie_factor < 0.0:
            raise ValueError(f"{name}: tie_factor must be >= 0")
        if stiffness_step not in ("largest", "current"):
            raise ValueError(f"{name}: stiffness_step must be 'largest' or 'current', "
                             f"got {stiffness_step!r}")
        self.largest_step = stiffness_step == "largest"
        self._dt_k = 0.0  # the largest step so far [s] (the springs' step when largest)
        self.name = name
        self.part = sph_part
        self.solid = solid_part
        self.method = STIFFNESS[stiffness]
        self.alpha, self.thickness_factor = float(alpha), float(thickness_factor)
        self.friction, self.skin_factor = float(friction), float(skin_factor)
        dim = solid_part.dim
        self.all_faces = faces is None  # the master surface follows erosion
        # each element face's twin, for the exterior faces after erosion
        # without a sort of the whole mesh's faces (1.2 s per event at 150,000
        # elements, most of a penetration run's step)
        self.twins = face_twins(solid_part.el.conn)
        faces = exterior_faces(solid_part.el.conn, twins=self.twins) if faces is None else faces
        self.faces = np.ascontiguousarray(faces, dtype=np.int64)
        if self.faces.ndim != 2 or self.faces.shape[1] != (4 if dim == 3 else 2):
            raise ValueError(f"{name}: faces must have shape (F, {4 if dim == 3 else 2}) "
                             f"in {dim}D, got {self.faces.shape}")
        self.master_nodes = face_nodes(self.faces, solid_part.nodes.n)
        # penetration allowed without force: particles born (or exposed to new
        # faces) inside the contact thickness (the kernel's pen0); the face each
        # particle faced at the last evaluation and its signed penetration there
        # (switches of face: the kernel's last_face / d_last)
        self.pen0 = np.zeros(sph_part.p.n)
        self.last_face = np.full(sph_part.p.n, -1, dtype=np.int64)
        self.d_last = np.zeros(sph_part.p.n)
        self.k_last = np.zeros(sph_part.p.n)  # each spring's stiffness [N/m] (the kernel's)
        self.count = 0
        self.n_builds = 0
        self.total_normal = 0.0
        self.total_tie = 0.0
        self._dt_step = 0.0  # the springs' step at the last force evaluation [s]
        self._allocate()
        self._tie(float(tie_factor))
        sph_part.p.on_grow(self._grown)

    # ------------------------------------------------------------- set-up
    def _grown(self, n_old: int, n_new: int) -> None:
        """Particles born (:meth:`ArrayStore.grow`): the arrays extended, the
        rows of the others kept (this step's contact of each, which
        :meth:`withdraw_forces` and the diagnostics read)."""
        self._allocate(keep=True)

    def _allocate(self, keep: bool = False) -> None:
        """Work arrays, the time-step limit and the candidate list for the particles
        (particles added since the last call take their allowance at their
        first contact evaluation). The last evaluation's per-particle results
        (face, shares, forces) are kept for the rows that exist when ``keep``
        (growth), and cleared otherwise (the faces were renumbered)."""
        p = self.part.p
        n = p.n
        old = self.pen0.size
        if n > old:
            self.pen0 = _extended(self.pen0, n, 0.0)
            # born: faced nothing known, so their whole penetration is allowed
            self.last_face = _extended(self.last_face, n, -2)
            self.d_last = _extended(self.d_last, n, -np.inf)
            self.k_last = _extended(self.k_last, n, 0.0)
        if keep:
            self.face_of = _extended(self.face_of, n, -1)
            self.shares = _extended(self.shares, n, 0.0)
            self.force = _extended(self.force, n, 0.0)
            self.normal_force = _extended(self.normal_force, n, 0.0)
            self.accel = _extended(self.accel, n, 0.0)
        else:
            self.face_of = np.full(n, -1, dtype=np.int64)
            self.shares = np.zeros((n, 4, 3))
            self.force = np.zeros((n, 3))
            self.normal_force = np.zeros(n)
            self.accel = np.zeros((n, 3))
        skip = np.zeros(n, dtype=np.bool_)
        if hasattr(self, "tied"):
            skip[self.tied] = True
        self.skip = skip
        self._all = np.arange(n, dtype=np.int64)
        t_max = float(np.max(self.thickness_factor * p.vol0 ** (1.0 / p.dim))) if n else 0.0
        self.reach = 2.0 * t_max
        self.skin = self.skin_factor * t_max
        self._dt = self._limit()
        self._build()

    def _limit(self) -> float:
        r"""Stable step of the bulk springs: :math:`1/\omega_{max}` (half the limit
        :math:`2/\omega`) with :math:`\omega^2 = k_{eff}(1/m_p + 1/m_{node})`,
        :math:`k_{eff} = k\,m_p/(\rho_0 V)`, the smallest master-node mass (the
        whole force on one node, the worst case); mass springs: inf, their
        :math:`\omega\Delta t` is fixed by alpha."""
        p = self.part.p
        if self.method != STIFFNESS_BULK or p.n == 0:
            return np.inf
        mn = self.solid.nodes.m[self.master_nodes]
        m_node = float(mn[mn > 0].min()) if np.any(mn > 0) else np.inf
        k = self.alpha * p.bulk_modulus * p.vol0 ** ((p.dim - 2.0) / p.dim)
        w2 = k / (p.rho0 * p.vol0) * (1.0 + p.m / m_node)
        return float(1.0 / np.sqrt(w2.max()))

    def _tie(self, factor: float) -> None:
        """Tie the particles within ``factor`` sizes of a face (see the class)."""
        p, q = self.part.p, self.solid.nodes
        (self.tied, self.tie_face, self.tie_xi, self.tie_eta,
         self.tie_offset) = face_anchors(p.x, p.vol0 ** (1.0 / p.dim), q.x, self.faces,
                                         factor, p.dim)
        self.tie_shares = np.zeros((self.tied.size, 4, 3))
        self.tie_force = np.zeros((self.tied.size, 3))
        self.skip[:] = False
        self.skip[self.tied] = True

    def _build(self) -> None:
        p, q = self.part.p, self.solid.nodes
        self.offsets, self.cand = candidate_pairs(p.x, q.x, self.faces,
                                                  self.reach + self.skin, p.dim)
        self.xp_ref = p.x.copy()
        self.xn_ref = q.x.copy()
        self.n_builds += 1

    def _surface_changed(self) -> None:
        """Elements of the solid part eroded: the master surface is that of the
        remaining elements (default surface), or the given faces that are
        still exterior faces of them; lists rebuilt."""
        el = self.solid.el
        live = exterior_faces(el.conn, active=el.active, twins=self.twins)
        if self.all_faces:
            faces = live
        else:
            keys = {tuple(sorted(f)) for f in live.tolist()}
            faces = self.faces[[tuple(sorted(f)) in keys for f in self.faces.tolist()]]
        faces = np.ascontiguousarray(faces, dtype=np.int64).reshape(-1, self.faces.shape[1])
        if self.tied.size:  # a tie follows its face (same nodes, same order) or ends
            index = {tuple(sorted(f)): i for i, f in enumerate(faces.tolist())}
            old = self.faces[self.tie_face].tolist()
            face = np.array([index.get(tuple(sorted(f)), -1) for f in old], dtype=np.int64)
            keep = face >= 0
            self.tied, self.tie_face = self.tied[keep], face[keep]
            self.tie_xi, self.tie_eta = self.tie_xi[keep], self.tie_eta[keep]
            self.tie_offset = self.tie_offset[keep]
            self.tie_shares = np.zeros((self.tied.size, 4, 3))
            self.tie_force = np.zeros((self.tied.size, 3))
        self.faces = faces
        self.master_nodes = face_nodes(self.faces, self.solid.nodes.n)
        self._allocate()

    def withdraw_forces(self) -> None:
        """Before elements erode (:class:`~sphdyn.events.ElementErosion`): take
        this step's contact forces out of the particles' and nodes'
        accelerations (``a`` and ``a_ext``); :meth:`mesh_changed` puts those of
        the new surface back. The particles of an eroded element then inherit
        no contact force from its nodes (a spring pressing on a crushed
        element's face, 1e11 m/s^2 on its nodes, launched its debris at
        5 km/s), and the forces of the step are those of the surface the kick
        acts on."""
        p, q = self.part.p, self.solid.nodes
        for a_p, a_n in ((p.a, q.a), (p.a_ext, q.a_ext)):
            withdraw_contact(self.face_of, self.faces, self.shares, self.accel, q.m, a_p, a_n)

    def mesh_changed(self) -> None:
        """Elements eroded (after :meth:`withdraw_forces`): the new master
        surface, and the contact forces on it at the positions of the last
        evaluation, added to the particles' and nodes' ``a`` and ``a_ext``.

        The faces were renumbered: every particle near them meets its face
        anew, as at a switch of face with no motion (module docstring): a
        spring keeps its extension (one whose face eroded meets the face
        behind it with the force it had); a particle out of contact facing a
        newly exposed face inside its thickness is allowed that penetration."""
        self._surface_changed()
        p, q = self.part.p, self.solid.nodes
        self.d_last[self.last_face == -1] = -np.inf  # faced none: any depth is new
        self.last_face[:] = -2
        a_p, a_n = np.zeros_like(p.a), np.zeros_like(q.a)
        self._contact(self._dt_step or self._dt, a_p, a_n, motion_dt=0.0)
        p.a += a_p
        p.a_ext += a_p
        q.a += a_n
        q.a_ext += a_n

    def _contact(self, dt: float, a_p: np.ndarray, a_n: np.ndarray, motion_dt: float) -> None:
        """The particle-face contact (:func:`penalty_coupling_forces`) added to
        ``a_p`` and ``a_n``; its count and total normal force kept."""
        p, q = self.part.p, self.solid.nodes
        self.count = int(penalty_coupling_forces(
            p.x, p.v, p.m, p.vol0, p.rho0, p.bulk_modulus, p.dim, q.x, q.v, q.m, self.faces,
            self.offsets, self.cand, self.thickness_factor, self.method, self.alpha,
            self.friction, dt, a_p, a_n, self.face_of, self.shares, self.force,
            self.normal_force, self.accel, self.skip, self.pen0, self.last_face, self.d_last,
            self.k_last, motion_dt))
        self.total_normal = float(self.normal_force.sum())

    # ----------------------------------------------------------- protocol
    def stable_dt(self) -> float:
        return self._dt

    def update_geometry(self, t: float) -> None:
        p, q = self.part.p, self.solid.nodes
        shift = (_max_shift(p.x, self.xp_ref, self._all)
                 + _max_shift(q.x, self.xn_ref, self.master_nodes))
        if not shift < self.skin:
            self._build()

    def forces(self, t: float, dt: float, a_out: np.ndarray) -> None:
        p, q = self.part.p, self.solid.nodes
        # the nodes' share goes to their a_ext, except when the caller asks
        # into a scratch array (the stepper's restore refreshes the columns)
        a_n = q.a_ext if a_out is p.a_ext else np.zeros_like(q.a_ext)
        self._dt_k = max(self._dt_k, dt)
        dt_k = self._dt_k if self.largest_step else dt  # the springs' step
        self._dt_step = dt_k
        self._contact(dt_k, a_out, a_n, motion_dt=dt)
        if self.tied.size:
            self.total_tie = float(tie_forces(
                self.tied, self.tie_face, self.tie_xi, self.tie_eta, self.tie_offset, p.x,
                p.m, p.vol0, p.rho0, p.bulk_modulus, p.dim, q.x, q.m, self.faces,
                self.method, self.alpha, dt_k, a_out, a_n, self.tie_shares, self.tie_force))

    def columns(self, t: float) -> dict[str, float]:
        out = {f"F_{self.name}": self.total_normal, f"contacts_{self.name}": float(self.count)}
        if self.tied.size:
            out[f"F_{self.name}_tie"] = self.total_tie
            out[f"tied_{self.name}"] = float(self.tied.size)
        return out

    def state(self) -> tuple[dict, dict[str, np.ndarray]]:
        return {"dt_k": self._dt_k}, {"offsets": self.offsets, "cand": self.cand,
                                      "xp_ref": self.xp_ref,
                    "xn_ref": self.xn_ref, "pen0": self.pen0,
                    "last_face": self.last_face, "d_last": self.d_last,
                    "k_last": self.k_last, "face_of": self.face_of}

    def restore(self, scalars: dict, arrays: dict) -> None:
        if np.any(self.solid.el.active == 0):  # eroded before the checkpoint
            self._surface_changed()
        # a checkpoint before 2026-11-27 (session 15): the step of the restart
        self._dt_k = float(scalars.get("dt_k", 0.0))
        for name in ("pen0", "face_of", "last_face", "d_last", "k_last"):
            if name in arrays:
                setattr(self, name, arrays[name].copy())
        if "fresh" in arrays and "last_face" not in arrays:  # a checkpoint before 2026-11-27
            self.last_face[arrays["fresh"]] = -2
            self.d_last[arrays["fresh"]] = -np.inf
        self.offsets = arrays["offsets"].copy()
        self.cand = arrays["cand"].copy()
        self.xp_ref = arrays["xp_ref"].copy()
        self.xn_ref = arrays["xn_ref"].copy()
