"""Particle state: kinematics plus the SPH fields, struct of flat arrays in SI units.

Every physics pass is a Numba function over these arrays. Conventions (see
``docs/theory.md``):

* vectors are ``(N, 3)`` even in 2D (plane strain, ``z = 0``, quantities per
  unit depth: mass in kg/m, volume in m^2/m);
* stress is the Cauchy stress ``(N, 3, 3)``, **positive in tension**;
* ``h`` is the smoothing length; the kernel is evaluated with
  ``support_scale * h`` (the paper's kappa), so the support radius is
  ``kernel_support * support_scale * h``.

The arrays live in an :class:`~sphdyn.state.store.ArrayStore`, so particles
can be added during a run (:meth:`ArrayStore.grow`): every array, the state
listed here and the work arrays the passes register, grows in one call.
"""

from __future__ import annotations

import numpy as np

from .store import STATE, ArrayStore

# Boundary-condition flags stored in ``bc``.
BC_FREE = 0
BC_FIXED = 1
BC_VELOCITY = 2
#: an item whose position and velocity another part's items set (a tied or
#: hybrid coupling's slave particle): the kick leaves it alone and books
#: neither its kinetic energy nor work (its mass is carried by its masters)
BC_SLAVE = 3
#: ``BC_COMPONENTS | mask`` (mask 1..6, bits x = 1, y = 2, z = 4): the
#: components in the mask take ``bc_v``, the others move freely (a support
#: that holds one direction: LS-DYNA's SPC with DOFX/DOFY/DOFZ)
BC_COMPONENTS = 8

#: name -> (tail shape, dtype) of the kinematics every part has (particles now,
#: mesh nodes later). ``a_ext`` is the part of ``a`` from interactions (walls,
#: contact, couplings); the kick books its work separately.
KINEMATICS = {
    "x": ((3,), np.float64), "v": ((3,), np.float64), "a": ((3,), np.float64),
    "a_ext": ((3,), np.float64), "m": ((), np.float64), "bc": ((), np.int8),
    "bc_v": ((3,), np.float64), "active": ((), np.int8),
}

#: name -> (tail shape, dtype) of the particle fields; ``hist`` gets its width
#: from the materials.
PARTICLE_FIELDS = {
    "x0": ((3,), np.float64), "vol0": ((), np.float64), "rho": ((), np.float64),
    "rho0": ((), np.float64), "h": ((), np.float64), "h0": ((), np.float64),
    "e": ((), np.float64), "e_av": ((), np.float64), "sig": ((3, 3), np.float64),
    "L": ((3, 3), np.float64), "c": ((), np.float64), "damage": ((), np.float64),
    "body": ((), np.int32), "mat": ((), np.int32),
}


class Kinematics(ArrayStore):
    """Positions, velocities, accelerations, masses and boundary flags of n items.

    Attributes (N items)
    ----------
    x, v, a : (N, 3) float64
        Position [m], velocity [m/s] (mid-step in the leapfrog scheme),
        acceleration [m/s^2] (all terms).
    a_ext : (N, 3) float64
        The part of ``a`` from interactions [m/s^2] (its work is booked apart).
    m : (N,) float64
        Mass [kg] (kg/m in 2D). May be zero (initial cracks).
    bc : (N,) int8
        ``BC_FREE``, ``BC_FIXED``, ``BC_VELOCITY``, ``BC_SLAVE`` or
        ``BC_COMPONENTS | mask``.
    bc_v : (N, 3) float64
        Prescribed velocity for ``BC_VELOCITY`` items and the masked
        components of ``BC_COMPONENTS`` items [m/s].
    active : (N,) int8
        1 for items taking part in the run (erosion will clear it).
    """

    def __init__(self, n: int, dim: int):
        if dim not in (1, 2, 3):
            raise ValueError(f"dim must be 1, 2 or 3, got {dim}")
        super().__init__(n)
        self.dim = dim
        for name, (tail, dtype) in KINEMATICS.items():
            self.add(name, tail, dtype, kind=STATE, fill=1 if name == "active" else 0)

    def inertia(self) -> np.ndarray:
        """The masses that resist acceleration (N,): ``m`` plus the mass added by
        selective mass scaling (``m_inertia``, :mod:`sphdyn.mass_scaling`), or
        ``m`` itself without it. The kick and everything that turns a final
        acceleration back into a force (reactions, section forces) use it."""
        return self.m_inertia if "m_added" in self._full else self.m


class Particles(Kinematics):
    """All particle fields of a model (kinematics plus the fields below).

    Attributes (N particles, ``nh`` history slots)
    ----------
    x0 : (N, 3) float64
        Initial (reference) position [m].
    vol0 : (N,) float64
        Initial (nominal) volume [m^3] (m^2 in 2D), ``dx**dim`` on a lattice.
    rho, rho0 : (N,) float64
        Current and initial density [kg/m^3].
    h, h0 : (N,) float64
        Current and initial smoothing length [m].
    e : (N,) float64
        Specific internal energy [J/kg].
    e_av : (N,) float64
        Specific energy dissipated by artificial viscosity [J/kg]; already
        included in ``e``, kept apart for the energy balance.
    sig : (N, 3, 3) float64
        Cauchy stress [Pa], tension positive.
    L : (N, 3, 3) float64
        Velocity gradient dv_a/dx_b [1/s] of the last step.
    c : (N,) float64
        Longitudinal wave speed [m/s] written by the material update.
    damage : (N,) float64
        Scalar damage in [0, 1] (0 for models without damage).
    hist : (N, nh) float64
        Material history variables (plastic strain, cap position, ...).
    body, mat : (N,) int32
        Body and material index.
    hist_names : list of str
        Names of the history columns, for output.
    """

    def __init__(self, n: int, dim: int, n_history: int = 0):
        super().__init__(n, dim)
        for name, (tail, dtype) in PARTICLE_FIELDS.items():
            self.add(name, tail, dtype, kind=STATE)
        self.add("hist", (max(n_history, 1),), np.float64, kind=STATE)
        self.hist_names: list[str] = []

    @classmethod
    def allocate(cls, n: int, dim: int, n_history: int = 0) -> "Particles":
        """Zero-initialised particles (density, h etc. must be set by the caller)."""
        return cls(n, dim, n_history)

    def place(self, rows, *, x, v, m, vol0, rho0, h, mat, body, rho=None) -> None:
        """Give the particles ``rows`` (a slice or an index array, k of them)
        their birth state: the one recipe of every particle (a body's
        lattice, a bar's sublayer, a mesh's converted elements, eroded
        elements).

        ``x`` (k, 3) [m], also the reference ``x0``; velocity ``v`` ((3,) or
        (k, 3)) [m/s]; mass ``m`` [kg, kg/m in 2D]; nominal volume ``vol0``
        [m^3, m^2 in 2D]; initial density ``rho0`` and current density ``rho``
        (``rho0`` if None) [kg/m^3]; smoothing length ``h``, also ``h0`` [m];
        material and body indices. Scalars broadcast. The rest (stress,
        energies, history, flags) is left as it is.
        """
        self.x[rows] = x
        self.x0[rows] = x
        self.v[rows] = v
        self.m[rows] = m
        self.vol0[rows] = vol0
        self.rho0[rows] = rho0
        self.rho[rows] = rho0 if rho is None else rho
        self.h[rows] = h
        self.h0[rows] = h
        self.mat[rows] = mat
        self.body[rows] = body

    @classmethod
    def concatenate(cls, parts: list["Particles"]) -> "Particles":
        """Join several particle sets (bodies) into one."""
        nh = max(p.hist.shape[1] for p in parts)
        out = cls(sum(p.n for p in parts), parts[0].dim, nh)
        k = 0
        for p in parts:
            for name in p.names(STATE):
                if name != "hist":
                    getattr(out, name)[k:k + p.n] = getattr(p, name)
            out.hist[k:k + p.n, : p.hist.shape[1]] = p.hist
            k += p.n
        out.hist_names = list(max((p.hist_names for p in parts), key=len))
        return out

    @classmethod
    def from_arrays(cls, dim: int, arrays: dict[str, np.ndarray],
                    hist_names: list[str] | None = None) -> "Particles":
        """Inverse of :meth:`arrays` (``a_ext`` and ``active`` may be absent)."""
        names = [k for k in list(KINEMATICS) + list(PARTICLE_FIELDS) + ["hist"]
                 if k not in ("a_ext", "active")]
        missing = [k for k in names if k not in arrays]
        if missing:
            raise KeyError(f"missing particle arrays: {missing}")
        p = cls(arrays["x"].shape[0], dim, arrays["hist"].shape[1])
        for name in p.names(STATE):
            if name in arrays:
                setattr(p, name, arrays[name])
        p.hist_names = list(hist_names or [])
        return p
