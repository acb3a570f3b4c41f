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
element exposes its neighbours' faces (:meth:`.penalty_coupling.PenaltyCoupling.mesh_changed`);
a surface given as faces keeps those of them whose elements remain.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ..algebra3 import load3
from .penalty_geometry import closest_point, face_point, face_shapes
from .wall_contact import (STIFFNESS_MASS, contact_thickness, keep_spring_energy,
                           spring_acceleration)

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
    w0, w1, w2 = load3(vp, i)
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


@njit(cache=True, error_model="numpy", inline="always")
def _nearest_face(i, xp, xn, faces, offsets, cand):
    """The candidate face nearest to particle ``i`` (a tie to the lower face
    index, so the result does not depend on the candidates' order) and its
    closest point (:func:`~.penalty_geometry.closest_point`): ``(face, xi,
    eta, cx, cy, cz, nx, ny, nz, clamped)``; face -1 if it has none."""
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
    return bf, xi, eta, cx, cy, cz, nx, ny, nz, clamped


@njit(cache=True, error_model="numpy", inline="always")
def _gap_and_direction(i, xp, cx, cy, cz, nx, ny, nz, clamped, tp):
    r"""``(touching, gap, e0, e1, e2)`` of particle ``i`` against its face's
    closest point ``c`` (normal ``n``): inside the face's outline (or within
    ``_INSIDE_RTOL tp`` of it) the gap along the normal, :math:`g = (\mathbf
    x - \mathbf c)\cdot\mathbf n - t_p`, direction :math:`\mathbf n`; beyond
    an edge, in front of the face's plane, the distance to the edge point
    and its direction; behind the plane beyond an edge, no contact
    (``touching`` False)."""
    r0 = xp[i, 0] - cx
    r1 = xp[i, 1] - cy
    r2 = xp[i, 2] - cz
    rn = r0 * nx + r1 * ny + r2 * nz
    l0 = r0 - rn * nx
    l1 = r1 - rn * ny
    l2 = r2 - rn * nz
    lat = np.sqrt(l0 * l0 + l1 * l1 + l2 * l2)
    if (not clamped) or lat <= _INSIDE_RTOL * tp:
        return True, rn - tp, nx, ny, nz
    if rn > 0.0:
        dist = np.sqrt(r0 * r0 + r1 * r1 + r2 * r2)
        return True, dist - tp, r0 / dist, r1 / dist, r2 / dist
    return False, 0.0, 0.0, 0.0, 0.0


@njit(cache=True, error_model="numpy", inline="always")
def _extension(i, bf, gap, pen, tp, vp, vn, face, N, motion_dt, pen0, last_face, d_last):
    r"""The spring's extension :math:`\delta - \delta_0` of particle ``i`` at
    face ``bf`` (nodes ``face``, shape values ``N``), penetration ``pen`` =
    :math:`\max(-g, 0)`, after the allowance :math:`\delta_0` (``pen0``)
    takes what the motion cannot explain: at a switch of face any excess of
    the depth's growth over the approach :math:`|\mathbf v_r|`
    ``motion_dt``, on the same face an excess beyond ``JUMP_FRACTION`` of
    the thickness ``tp`` (module docstring); the face and depth kept for the
    next evaluation."""
    leap = 0.0 if bf != last_face[i] else JUMP_FRACTION * tp
    if last_face[i] != -1 and -gap - d_last[i] > leap:  # (else the excess is less)
        w0, w1, w2 = _relative_velocity(vp, vn, i, face, N)
        excess = -gap - d_last[i] - motion_dt * np.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
        if excess > leap:  # deeper than the motion can take it: geometry
            pen0[i] = min(pen0[i] + excess, pen)
    if pen < pen0[i]:
        pen0[i] = pen
    last_face[i] = bf
    d_last[i] = -gap
    return pen - pen0[i]


@njit(cache=True, error_model="numpy", inline="always")
def _with_friction(f0, f1, f2, fn, e0, e1, e2, friction, dt, inv_meff, vp, vn, i, face,
                   N):
    r"""The force ``f`` with Coulomb friction added against the tangential
    relative velocity :math:`\mathbf v_t`: :math:`\min(\mu F_n, |\mathbf
    v_t| / (\Delta t\, m_{eff}^{-1}))`, the second bound stopping the
    sliding within the step (``inv_meff`` :math:`1/m_p + 1/m_f`)."""
    w0, w1, w2 = _relative_velocity(vp, vn, i, face, N)
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
    return f0, f1, f2


@njit(cache=True, error_model="numpy", inline="always")
def _accelerate(i, c0, c1, c2, accel, a_p):
    """Particle ``i``'s contact acceleration ``c`` kept in ``accel`` and added to ``a_p``."""
    accel[i, 0] = c0
    accel[i, 1] = c1
    accel[i, 2] = c2
    a_p[i, 0] += accel[i, 0]
    a_p[i, 1] += accel[i, 1]
    a_p[i, 2] += accel[i, 2]


@njit(cache=True, error_model="numpy", inline="always")
def _add_shares(face, share, mn, a_n, sign=1.0):
    """One particle's forces on the nodes of its ``face`` (nf,), ``share``
    (4, 3) [N] (rows past nf unused), added to ``a_n`` (M, 3) [m/s^2] times
    ``sign`` (-1: taken back, bitwise the inverse of adding them); massless
    nodes skipped."""
    for a in range(face.shape[0]):
        node = face[a]
        if mn[node] > 0.0:
            for c in range(3):
                a_n[node, c] += sign * share[a, c] / mn[node]


@njit(cache=True, error_model="numpy")
def _gather_shares(face_of, faces, shares, mn, a_n):
    """The face nodes' shares of the contact forces into ``a_n`` (M, 3)
    [m/s^2]: serial, in particle order (deterministic on any number of
    threads)."""
    for i in range(face_of.shape[0]):
        if face_of[i] >= 0:
            _add_shares(faces[face_of[i]], shares[i], mn, a_n)


@njit(cache=True, error_model="numpy", parallel=True)
def penalty_coupling_forces(particles, nodes, dim, faces, offsets, cand, law, skip,
                            motion_dt, a_p, a_n, face_of, shares, force, normal_force, accel,
                            pen0, last_face, d_last, k_last):
    r"""Particle-face penalty forces (module docstring) into the particles' and nodes' ``a``.

    Parameters
    ----------
    particles : ``(xp, vp, mp, vol0, rho0, kbulk)``: (N, 3) positions [m] and
        mid-step velocities [m/s]; (N,) mass [kg], nominal volume [m^dim],
        reference density [kg/m^3], bulk modulus [Pa] (kg/m, m^2 per unit
        depth in 2D).
    nodes : ``(xn, vn, mn)``: (M, 3), (M, 3), (M,) node positions,
        velocities, masses.
    dim : 2 or 3.
    faces : (F, nf) master faces (4 nodes in 3D, 2 in 2D).
    offsets, cand : CSR candidate faces of each particle
        (:func:`~.penalty_geometry.candidate_pairs`).
    law : ``(thickness_factor, method, alpha, friction, dt)``: the contact
        law (:func:`~.wall_contact.spring_acceleration`, Coulomb coefficient,
        stable step [s]).
    skip : (N,) bool, particles left out (those tied by :func:`tie_forces`).
    motion_dt : time [s] the particles moved since the last evaluation (the
        step; 0 when the faces changed under unmoved particles).
    a_p, a_n : (N, 3) and (M, 3) in/out, the particles' and the nodes'
        accelerations are **added** [m/s^2].
    face_of, shares, force, normal_force, accel : out: ``face_of`` (N,) the
        face each particle touches (-1: none); ``shares`` (N, 4, 3) the force
        on each node of that face [N] (:math:`-N_a \mathbf F_p`; rows past nf
        unused); ``force`` (N, 3) the force on each particle [N] (N/m in 2D);
        ``normal_force`` (N,) its component along the contact direction [N];
        ``accel`` (N, 3) the acceleration added to each particle [m/s^2]
        (:func:`withdraw_contact` takes it back).
    pen0, last_face, d_last, k_last : in/out: ``pen0`` (N,) the
        penetration each particle is allowed without force [m] (a particle
        born or exposed inside the contact thickness): the spring acts on
        :math:`\delta - \delta_0`, and :math:`\delta_0` only shrinks, to the
        smallest penetration seen (LS-DYNA's IGNORE = 2). ``last_face``,
        ``d_last`` (N,) the face each particle faced at the last evaluation
        (-1: none, so no switch is checked; -2: unknown, a particle born
        since or faces renumbered, so any face is a switch) and its signed
        penetration there :math:`d = -g` [m] (:math:`-\infty` with -2 for a
        particle that faced none: its whole penetration is allowed); at a
        switch of face the spring's extension grows by at most the approach
        the motion allows (:func:`_extension`). ``k_last`` (N,) each
        particle's spring stiffness :math:`k` [N/m] (:math:`F_n = k(\delta -
        \delta_0)`) at the last evaluation (0: not loaded); when it changes
        under load (the face point's mass, the step, a new face) the
        extension is scaled so that the spring's energy :math:`\tfrac12
        k(\delta - \delta_0)^2` stays what it was (module docstring, "A
        spring's stiffness changes").

    The inputs come grouped in tuples, the arrays it writes one by one:
    Numba's parallel loops drop the writes into an array unpacked from a
    tuple argument (docs/architecture.md, "Numba conventions").

    Returns
    -------
    n_contact : int, particles in contact.

    The particle loop is parallel and writes only its own rows; the nodes'
    share is then gathered serially, in particle order (4 adds per contact;
    deterministic on any number of threads).
    """
    xp, vp, mp, vol0, rho0, kbulk = particles
    xn, vn, mn = nodes
    thickness_factor, method, alpha, friction, dt = law
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
        bf, xi, eta, cx, cy, cz, nx, ny, nz, clamped = _nearest_face(i, xp, xn, faces,
                                                                     offsets, cand)
        if bf < 0:
            pen0[i] = 0.0
            last_face[i] = -1
            k_last[i] = 0.0
            continue
        tp = contact_thickness(vol0[i], dim, thickness_factor)
        touching, gap, e0, e1, e2 = _gap_and_direction(i, xp, cx, cy, cz, nx, ny, nz,
                                                       clamped, tp)
        if not touching:  # behind the plane of a face's boundary: no contact and no
            # depth to measure, so the allowance and the last face's depth are kept
            k_last[i] = 0.0
            continue
        pen = max(-gap, 0.0)
        N = face_shapes(xi, eta, nf)
        ext = _extension(i, bf, gap, pen, tp, vp, vn, faces[bf], N, motion_dt, pen0,
                         last_face, d_last)
        if ext <= 0.0:
            k_last[i] = 0.0
            continue
        count += 1
        # the spring's acceleration per metre of extension [1/s^2]
        a1 = spring_acceleration(1.0, method, alpha, dt, kbulk[i], vol0[i], rho0[i], dim)
        if mp[i] <= 0.0:  # pushed out, no force of its own
            k_last[i] = 0.0
            an = a1 * ext
            _accelerate(i, an * e0, an * e1, an * e2, accel, a_p)
            continue
        inv_f = face_inverse_mass(mn, faces[bf], N)
        kk = a1 * (spring_mass(mp[i], inv_f) if method == STIFFNESS_MASS else mp[i])
        ext = keep_spring_energy(i, pen, ext, kk, pen0, k_last)
        fn = kk * ext
        f0 = fn * e0
        f1 = fn * e1
        f2 = fn * e2
        if friction > 0.0:
            f0, f1, f2 = _with_friction(f0, f1, f2, fn, e0, e1, e2, friction, dt,
                                        1.0 / mp[i] + inv_f, vp, vn, i, faces[bf], N)
        _accelerate(i, f0 / mp[i], f1 / mp[i], f2 / mp[i], accel, a_p)
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
    _gather_shares(face_of, faces, shares, mn, a_n)
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
        if face_of[i] >= 0:
            _add_shares(faces[face_of[i]], shares[i], mn, a_n, -1.0)


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
        total += np.sqrt(force[k, 0] ** 2 + force[k, 1] ** 2 + force[k, 2] ** 2)
        _add_shares(faces[tie_face[k]], shares[k], mn, a_n)
    return total


@njit(cache=True, error_model="numpy", parallel=True)
def max_shift(x, x_ref, rows):
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
