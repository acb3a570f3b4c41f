"""Particle state: a struct of flat NumPy arrays in SI units.

Every physics pass is a Numba function over these arrays. Conventions (see
``docs/theory.md``):

* vectors are ``(N, 3)`` even in 2D (plane strain, ``z = 0``, quantities per
  unit depth: mass in kg/m, volume in m^2/m);
* stress is the Cauchy stress ``(N, 3, 3)``, **positive in tension**;
* ``h`` is the smoothing length; the kernel is evaluated with
  ``support_scale * h`` (the paper's kappa), so the support radius is
  ``kernel_support * support_scale * h``.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields

import numpy as np

# Boundary-condition flags stored in ``Particles.bc``.
BC_FREE = 0
BC_FIXED = 1
BC_VELOCITY = 2


@dataclass
class Particles:
    """All particle fields of a model, struct of arrays.

    Attributes (N particles, ``nh`` history slots)
    ----------
    x, v, a : (N, 3) float64
        Position [m], velocity [m/s] (mid-step in the leapfrog scheme),
        acceleration [m/s^2].
    x0 : (N, 3) float64
        Initial (reference) position [m].
    m : (N,) float64
        Mass [kg] (kg/m in 2D). May be zero (initial cracks).
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
    bc : (N,) int8
        ``BC_FREE``, ``BC_FIXED`` or ``BC_VELOCITY``.
    bc_v : (N, 3) float64
        Prescribed velocity for ``BC_VELOCITY`` particles [m/s].
    """

    dim: int
    x: np.ndarray
    v: np.ndarray
    a: np.ndarray
    x0: np.ndarray
    m: np.ndarray
    vol0: np.ndarray
    rho: np.ndarray
    rho0: np.ndarray
    h: np.ndarray
    h0: np.ndarray
    e: np.ndarray
    e_av: np.ndarray
    sig: np.ndarray
    L: np.ndarray
    c: np.ndarray
    damage: np.ndarray
    hist: np.ndarray
    body: np.ndarray
    mat: np.ndarray
    bc: np.ndarray
    bc_v: np.ndarray
    # Names of the history columns, for output.
    hist_names: list[str] = field(default_factory=list)

    @property
    def n(self) -> int:
        return self.x.shape[0]

    @classmethod
    def allocate(cls, n: int, dim: int, n_history: int = 0) -> "Particles":
        """Zero-initialised particles (density, h etc. must be set by the caller)."""
        if dim not in (2, 3):
            raise ValueError(f"dim must be 2 or 3, got {dim}")
        z3 = lambda: np.zeros((n, 3))  # noqa: E731
        z1 = lambda: np.zeros(n)  # noqa: E731
        return cls(
            dim=dim,
            x=z3(), v=z3(), a=z3(), x0=z3(),
            m=z1(), vol0=z1(), rho=z1(), rho0=z1(), h=z1(), h0=z1(),
            e=z1(), e_av=z1(),
            sig=np.zeros((n, 3, 3)), L=np.zeros((n, 3, 3)),
            c=z1(), damage=z1(),
            hist=np.zeros((n, max(n_history, 1))),
            body=np.zeros(n, dtype=np.int32), mat=np.zeros(n, dtype=np.int32),
            bc=np.zeros(n, dtype=np.int8), bc_v=z3(),
        )

    @classmethod
    def concatenate(cls, parts: list["Particles"]) -> "Particles":
        """Join several particle sets (bodies) into one."""
        dim = parts[0].dim
        nh = max(p.hist.shape[1] for p in parts)
        out = {}
        for f in fields(cls):
            if f.name in ("dim", "hist", "hist_names"):
                continue
            out[f.name] = np.concatenate([getattr(p, f.name) for p in parts])
        hist = np.zeros((sum(p.n for p in parts), nh))
        k = 0
        for p in parts:
            hist[k:k + p.n, : p.hist.shape[1]] = p.hist
            k += p.n
        names = max((p.hist_names for p in parts), key=len)
        return cls(dim=dim, hist=hist, hist_names=list(names), **out)

    def arrays(self) -> dict[str, np.ndarray]:
        """Every array field by name (for checkpoints)."""
        return {f.name: getattr(self, f.name) for f in fields(self)
                if isinstance(getattr(self, f.name), np.ndarray)}

    @classmethod
    def from_arrays(cls, dim: int, arrays: dict[str, np.ndarray],
                    hist_names: list[str] | None = None) -> "Particles":
        """Inverse of :meth:`arrays`."""
        names = [f.name for f in fields(cls) if f.name not in ("dim", "hist_names")]
        missing = [k for k in names if k not in arrays]
        if missing:
            raise KeyError(f"missing particle arrays: {missing}")
        return cls(dim=dim, hist_names=list(hist_names or []),
                   **{k: np.ascontiguousarray(arrays[k]) for k in names})
