"""SPH-FEM coupling by penalty contact: the interaction.

:class:`PenaltyCoupling` keeps the candidate faces of each particle (a Verlet
list, :func:`~.penalty_geometry.candidate_pairs`), follows the master surface
through erosion, ties particles to faces (``tie_factor``) and checkpoints the
springs' state; the contact law, its springs and its equations are those of
:mod:`.penalty_kernels` (the thesis, chapter 4, "Coupling SPH and FEM").

The model and its tests: docs/theory.md, "SPH-FEM coupling by penalty".
"""

from __future__ import annotations

import numpy as np

from ..deck.sections.meshes import PenaltyKeys
from .base import InteractionBase
from .penalty_geometry import (candidate_pairs, exterior_faces, face_anchors, face_nodes,
                               face_twins)
from .penalty_kernels import max_shift, penalty_coupling_forces, tie_forces, withdraw_contact
from .wall import STIFFNESS
from .wall_contact import STIFFNESS_BULK


#: the keys' defaults, as the deck's [mesh.contact], [mesh.convert] and
#: [mesh.erosion] tables have them (one home: docs/deck-reference.md)
DEFAULTS = PenaltyKeys()


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

    def __init__(self, name: str, sph_part, solid_part, faces=None,
                 stiffness: str = DEFAULTS.stiffness, alpha: float = DEFAULTS.alpha,
                 thickness_factor: float = DEFAULTS.thickness_factor,
                 friction: float = DEFAULTS.friction, skin_factor: float = 1.0,
                 tie_factor: float = 0.0, stiffness_step: str = DEFAULTS.stiffness_step):
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
            (p.x, p.v, p.m, p.vol0, p.rho0, p.bulk_modulus), (q.x, q.v, q.m), p.dim,
            self.faces, self.offsets, self.cand,
            (self.thickness_factor, self.method, self.alpha, self.friction, dt), self.skip,
            motion_dt, a_p, a_n, self.face_of, self.shares, self.force, self.normal_force,
            self.accel, self.pen0, self.last_face, self.d_last, self.k_last))
        self.total_normal = float(self.normal_force.sum())

    # ----------------------------------------------------------- protocol
    def stable_dt(self) -> float:
        return self._dt

    def update_geometry(self, t: float) -> None:
        p, q = self.part.p, self.solid.nodes
        shift = (max_shift(p.x, self.xp_ref, self._all)
                 + max_shift(q.x, self.xn_ref, self.master_nodes))
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
        self._dt_k = float(scalars["dt_k"])
        for name in ("pen0", "face_of", "last_face", "d_last", "k_last"):
            setattr(self, name, arrays[name].copy())
        self.offsets = arrays["offsets"].copy()
        self.cand = arrays["cand"].copy()
        self.xp_ref = arrays["xp_ref"].copy()
        self.xn_ref = arrays["xn_ref"].copy()
