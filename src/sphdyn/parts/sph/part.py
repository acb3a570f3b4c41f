"""The SPH part: particles, their material groups and the order of the SPH passes.

One step of the part (the stepper calls these in this order, state at
:math:`t^n`: :math:`\\mathbf x^n,\\ \\mathbf v^{n-1/2},\\ \\sigma^n,\\
\\mathbf a^n`):

1. :meth:`SPHPart.drift` to :math:`\\mathbf x^{n+1}` (XSPH-smoothed velocity
   if enabled);
2. :meth:`SPHPart.update_geometry`: neighbour list update (only when the
   Verlet skin is exhausted), total-Lagrangian reference update every
   ``reference_update_every`` steps, velocity gradient, density and
   smoothing length (total-Lagrangian bodies take L and the density from
   their deformation gradient, :mod:`.tl_scheme`);
3. :meth:`SPHPart.internal_forces`: material update of every group
   (:math:`\\sigma^{n+1}`, internal energy), stress divergence and artificial
   viscosity (plus the artificial stress of :mod:`.artificial_stress` when
   ``epsilon > 0``; the first Piola-Kirchhoff form with hourglass control on
   total-Lagrangian bodies) into ``a``, and the viscous heat.

The Swegle indicator (:mod:`.swegle`) is evaluated on demand: the output
field ``swegle`` and the history column ``swegle_unstable``.

Per-particle arrays the part derives (particle size, bulk modulus,
artificial-stress epsilon, the total-Lagrangian mask, the mesostructure
phase and the variation factor) and its work arrays live in the particles'
:class:`~sphdyn.state.ArrayStore`; when particles are added, :meth:`_grown`
refreshes them, the material groups and the neighbour lists.

The model and its tests: docs/theory.md, "Updated-Lagrangian SPH for solids".
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...watchers.guards import SimulationFailed
from ...integrate import (add_heat, cfl_mass_factors, cfl_time_step, drift,
                          internal_energies)
from ...kernels import KernelContext
from ...materials.base import young_modulus
from ...neighbours import (build_neighbours, max_neighbours, mean_neighbours,
                           update_neighbours)
from ...state import BC_FIXED, STATE, Particles
from ..base import register_part
from .artificial_stress import artificial_stress_forces, artificial_stress_tensor
from .colouring import colour_pairs
from .passes import forces, stress_terms, update_density_and_h, xsph_velocity
from .gradient import gradient_scratch, velocity_gradient
from .swegle import FLAG_FRACTION, count_unstable, stress_tolerance, swegle_indicator
from .tl_scheme import TotalLagrangian


#: Monaghan's (1992, sec. 10) weight of the viscous signal speed in the time
#: step of fluid particles: h / (c + 1.2 (alpha c + beta max mu))
VISCOUS_SIGNAL_WEIGHT = 1.2


@dataclass(frozen=True)
class SPHSettings:
    """The SPH scheme's settings, resolved from the deck by :mod:`sphdyn.build`
    (the defaults are the deck's, written there once).

    Per-body tuples are indexed by ``particles.body``.
    """

    correction: bool  # Randles-Libersky gradient correction
    alpha: float  # artificial viscosity (Monaghan 1992)
    beta: float
    xsph: float  # XSPH epsilon (0: off)
    benz: bool  # smoothing length from the density (else constant)
    h_min_factor: float  # h bounds in units of h0
    h_max_factor: float
    skin_factor: float  # Verlet skin in units of the support radius
    cfl: float
    stress_exponent: float  # artificial stress n (Monaghan 2000)
    epsilon: tuple  # artificial stress epsilon per body
    total_lagrangian: tuple  # per body
    hourglass_coefficient: float  # total-Lagrangian hourglass coefficient
    reference_update_every: int  # total-Lagrangian reference update (0: never)
    crack_band: float  # fracture-energy length of a particle, in particle sizes
    #: (min, max) density factors per material index (``particles.mat``): the
    #: updated-Lagrangian density is kept within them times ``rho0``; () no limits
    density_limits: tuple = ()
    #: (alpha, beta) of the artificial viscosity per material index; () all alpha, beta
    viscosity: tuple = ()
    #: time-step factor per material index; () all 1
    time_step_factor: tuple = ()


@register_part("sph")
class SPHPart:
    """SPH particles of one or more bodies and the passes that move them.

    Parameters
    ----------
    particles : the particle state.
    groups : material groups (:class:`~sphdyn.materials.MaterialGroup`), dispatched once each.
    kernel : the kernel context.
    settings : the scheme's settings.
    phase, variation : (N,) mesostructure phase (int8, -1 outside one) and
        material variation factor (1 without variation), or None for those
        values; kept as output fields.
    """

    name = "sph"

    def __init__(self, particles: Particles, groups: list, kernel: KernelContext,
                 settings: SPHSettings, phase=None, variation=None):
        p = self.p = self.kin = particles
        self.groups = groups
        self.kernel = kernel
        self.s = settings
        self.dim = p.dim
        p.add("phase", (), np.int8, fill=-1)
        p.add("variation", (), np.float64, fill=1.0)
        if phase is not None:
            p.phase = phase
        if variation is not None:
            p.variation = variation
        # S: sigma B / rho^2 of stress_terms
        # av_*: per-particle viscosity, dt_*: time-step factor and viscous
        # signal weight of its material; av_signal written by the force pass
        for name, tail in (("B", (3, 3)), ("dedt_av", ()), ("S", (3, 3)),
                           ("size", ()), ("band", ()), ("bulk_modulus", ()),
                           ("young", ()),
                           ("as_eps", ()), ("swegle", ()), ("av_alpha", ()),
                           ("av_beta", ()), ("av_signal", ()), ("dt_factor", ()),
                           ("dt_viscous", ())):
            p.add(name, tail)
        p.add("tl", (), np.bool_, fill=False)
        # the wave-speed factor of mass scaling (sphdyn.mass_scaling), 1 without
        p.add("c_mass", (), np.float64, kind=STATE, fill=1.0)
        # each row's own pairs within the support, at its head (velocity_gradient
        # counts them, forces visits them)
        p.add("n_support", (), np.int32)
        self.as_on = any(e > 0 for e, tl in zip(settings.epsilon, settings.total_lagrangian)
                         if not tl)
        if self.as_on:
            p.add("R", (3, 3))
            p.add("Q", (3, 3))
        if settings.xsph > 0:
            p.add("vs", (3,))
        #: (n_materials, 2) density factors of :func:`update_density_and_h`
        self.density_limits = np.array(settings.density_limits, float).reshape(-1, 2)
        # pair gradient factors of the current list (float32, see velocity_gradient)
        self.F = self._F_buf = np.zeros(0, dtype=np.float32)
        # row buffers of velocity_gradient, sized for the list they were made for
        self._scratch = None
        self._scratch_list = None
        # the force pass's slab colouring, made for the list it was made for
        self._colouring = None
        self._colouring_list = None
        #: callables run after every pass of :meth:`_gradients` (before the
        #: stress divergence): a coupling may zero pair factors ``F`` there
        self.pair_filters: list = []
        self.swegle_unstable = 0
        self._swegle_at = None  # (t, step) the indicator was evaluated at
        self._visc = None  # the force pass's viscosity arrays (_viscosity_arrays)
        self.step = 0
        self._derive(0, p.n)
        r0 = kernel.radius_factor * float(p.h.max()) if p.n else 0.0
        self.skin = settings.skin_factor * r0
        self.nl = build_neighbours(p.x, p.h, kernel.radius_factor, self.skin, self.dim,
                                   active=self.ul_active)
        self.tl = None
        if p.tl.any():
            self.tl = TotalLagrangian(p, np.flatnonzero(p.tl), kernel, p.young,
                                      settings.hourglass_coefficient, settings.alpha, settings.beta)
        p.on_grow(self._grown)

    # ------------------------------------------------------- derived arrays
    def _derive(self, lo: int, hi: int) -> None:
        """Per-particle data derived from body and material, rows ``lo:hi``."""
        p, s = self.p, self.s
        rows = slice(lo, hi)
        p.size[rows] = p.vol0[rows] ** (1.0 / p.dim)  # particle size, initial dx [m]
        # the length a crack spreads over, for the materials' fracture energy [m]
        p.band[rows] = s.crack_band * p.size[rows]
        tl_body = np.asarray(s.total_lagrangian, bool)
        p.tl[rows] = tl_body[p.body[rows]]
        eps = np.asarray(s.epsilon, float)
        p.as_eps[rows] = np.where(p.tl[rows], 0.0, eps[p.body[rows]])
        p.av_alpha[rows] = s.alpha
        p.av_beta[rows] = s.beta
        p.dt_factor[rows] = 1.0
        p.dt_viscous[rows] = 0.0
        for g in self.groups:
            sel = g.idx[(g.idx >= lo) & (g.idx < hi)]
            k, mu = g.model.bulk_modulus(g.params), g.model.shear_modulus(g.params)
            p.bulk_modulus[sel] = k
            p.young[sel] = young_modulus(k, mu)
            if s.viscosity:
                p.av_alpha[sel], p.av_beta[sel] = s.viscosity[g.material]
            if s.time_step_factor:
                p.dt_factor[sel] = s.time_step_factor[g.material]
            if g.model.fluid:  # Monaghan's (1992) viscous time-step condition
                p.dt_viscous[sel] = VISCOUS_SIGNAL_WEIGHT
        self.ul_active = self._active_mask()
        self.has_ul = not p.tl.all()  # False: the updated-Lagrangian passes are skipped
        self._visc = None

    def _grown(self, n_old: int, n_new: int) -> None:
        """Particles ``n_old:n_new`` were added: groups, derived data, neighbours.

        New particles join the first group of their material (``mat``) and,
        in total-Lagrangian bodies, take their birth configuration (``x0``,
        ``rho0``) as reference; the others keep theirs.
        Their accelerations are zero until the next step computes them.
        """
        p = self.p
        new = np.arange(n_old, n_new)
        for mat in np.unique(p.mat[new]):
            g = next((g for g in self.groups if g.material == mat), None)
            if g is None:
                raise ValueError(f"added particles of material {mat} have no group; "
                                 "add particles of a material the model already has")
            g.idx = np.concatenate([g.idx, new[p.mat[new] == mat]])
        self._derive(n_old, n_new)
        # rebuilt for the new count (the list's storage reused, its builds counted on)
        self.nl = update_neighbours(self.nl, p.x, p.h, self.dim, self.ul_active)
        if self.tl is None and p.tl.any():  # the first total-Lagrangian particles
            self.tl = TotalLagrangian(p, np.flatnonzero(p.tl), self.kernel, p.young,
                                      self.s.hourglass_coefficient, self.s.alpha, self.s.beta)
        elif self.tl is not None:
            self.tl.rows = np.flatnonzero(p.tl).astype(np.int64)
            self.tl.young = p.young
            self.tl.rebuild(p, np.concatenate([self.tl.X, p.x0[n_old:]]),
                            np.concatenate([self.tl.rho_ref, p.rho0[n_old:]]))
        self._swegle_at = None

    def _active_mask(self):
        """Particles of the updated-Lagrangian neighbour lists: not
        total-Lagrangian (those have their own) and not removed
        (:meth:`deactivate`); None when that is every particle."""
        p = self.p
        act = p.active == 1
        if p.tl.any():
            act &= ~p.tl
        return None if act.all() else act

    def deactivate(self, rows: np.ndarray) -> None:
        """Take updated-Lagrangian particles ``rows`` out of the calculation
        (LS-DYNA's SPH box): out of the neighbour lists from now on, fixed where
        they are (velocity and acceleration zero), their internal energy and
        stress zero (the caller books what they carried). Their mass stays."""
        p = self.p
        if np.any(p.tl[rows]):
            raise ValueError("total-Lagrangian particles cannot be removed")
        p.active[rows] = 0
        p.bc[rows] = BC_FIXED
        p.v[rows] = 0.0
        p.a[rows] = 0.0
        p.e[rows] = 0.0
        p.e_av[rows] = 0.0
        p.sig[rows] = 0.0
        p.dedt_av[rows] = 0.0
        p.av_signal[rows] = 0.0
        self.ul_active = self._active_mask()
        # rebuilt for the new active set (in place: a blast removes particles at
        # most steps, so its storage is reused and its builds counted on)
        self.nl = update_neighbours(self.nl, p.x, p.h, self.dim, self.ul_active)
        self._swegle_at = None

    # ----------------------------------------------------------- protocol
    def stable_dt(self) -> tuple[float, int]:
        """CFL step :math:`C \\min f h / (c + |v| + w v_{sig})` and the controlling
        particle (:func:`~sphdyn.integrate.cfl_time_step`)."""
        p = self.p
        return cfl_time_step(p.h, p.c, p.v, p.av_signal, p.dt_viscous, p.dt_factor,
                             p.c_mass, min(1.0, self.kernel.support_scale), self.s.cfl)

    def scale_mass(self, target: float, mask=None) -> dict[str, np.ndarray]:
        """Selective mass scaling (:mod:`sphdyn.mass_scaling`): the wave-speed
        factors ``c_mass`` that raise every particle's (of ``mask`` (N,) bool, if
        given) step to ``target``
        (:func:`~sphdyn.integrate.cfl_mass_factors`) and the mass that makes them,
        :math:`\\Delta m_i = m_i (1/r_i^2 - 1)` [kg] (N,), by table name."""
        p = self.p
        r = np.ones(p.n)
        cfl_mass_factors(p.h, p.c, p.v, p.av_signal, p.dt_viscous, p.dt_factor,
                         min(1.0, self.kernel.support_scale), self.s.cfl, target, r)
        if mask is not None:
            r[~mask] = 1.0
        fast = np.flatnonzero((r <= 0.0) & (p.m > 0.0))
        if fast.size:
            i = int(fast[0])
            raise ValueError(
                f"mass scaling: particle {i} of part '{self.name}' moves at "
                f"{np.linalg.norm(p.v[i]):.4g} m/s, which alone keeps its step below the "
                f"target {target:.4g} s (no mass raises it): lower time.mass_scaling.target")
        p.c_mass = r
        return {"kin": p.m * (1.0 / (r * r) - 1.0)}

    def start(self, dt: float) -> None:
        """Accelerations of the initial state (gradients and divergence, no update)."""
        self._gradients()
        self._accelerations()

    def drift(self, dt: float) -> None:
        p, k = self.p, self.kernel
        if self.s.xsph > 0:
            xsph_velocity(p.x, p.v, p.m, p.rho, p.h, self.nl.offsets, self.nl.idx, k.kid,
                          k.sigma, self.dim, k.support_scale, self.s.xsph, p.vs)
            drift(p.x, p.vs, dt)
        else:
            drift(p.x, p.v, dt)
        self.step += 1

    def update_geometry(self, t: float, dt: float) -> None:
        p, s = self.p, self.s
        try:
            self.nl = update_neighbours(self.nl, p.x, p.h, self.dim, self.ul_active)
        except ValueError as exc:  # positions or h went non-finite in this step
            bad = np.flatnonzero(~np.all(np.isfinite(p.x), axis=1) | ~np.isfinite(p.h))
            raise SimulationFailed(
                f"run stopped at t = {t:.6e} s: {exc} ({bad.size} particle(s), first "
                f"{bad[:5].tolist()}). Likely causes: a time step too large for the "
                "material (lower sph.cfl; check density and moduli) or too stiff "
                "contact.") from None
        if self.tl is not None and s.reference_update_every and \
                self.step % s.reference_update_every == 0:
            self.tl.update_reference(p)
        self._gradients()
        if self.has_ul:
            update_density_and_h(p.L, dt, self.dim, s.benz, p.h0, s.h_min_factor,
                                 s.h_max_factor, p.rho, p.h, p.rho0, p.mat,
                                 self.density_limits)
        if self.tl is not None:
            self.tl.density(p)

    def internal_forces(self, t: float, dt: float) -> None:
        p = self.p
        for g in self.groups:
            g.model.update(g.idx, p.L, dt, p.rho, p.sig, p.e, p.c, p.damage,
                           g.history(p.hist), g.params,
                           p.band if g.model.softening else p.size)
        self._accelerations()
        add_heat(p.e, p.e_av, p.dedt_av, dt)

    def energies(self) -> tuple[float, float]:
        """Internal energy and its artificial-viscosity part [J] (J/m in 2D)."""
        return internal_energies(self.p.m, self.p.e, self.p.e_av)

    def hotspot(self) -> str:
        """The particle of the largest specific internal energy (the energy
        guard's diagnosis, :func:`sphdyn.watchers.guards.energy_diagnosis`) and the
        fastest particle."""
        from ...watchers.guards import _fmt, fastest

        p = self.p
        e = np.where(p.active != 0, p.e, -np.inf)
        if e.size == 0:
            return "no particles"
        k = int(np.argmax(e))
        return (f"particle {k} at {_fmt(p.x[k])} has the largest specific internal "
                f"energy, {p.e[k]:.4g} J/kg; {fastest(p, 'particle')}")

    @property
    def energy_released(self) -> float | None:
        """Energy [J] the materials have released into the particles so far
        (:attr:`~sphdyn.materials.MaterialModel.released_energy`: an
        explosive's chemical energy); None if no material of the part releases
        any (the stepper's book ``E_chemical``)."""
        if all(g.model.released_energy is None for g in self.groups):
            return None
        p, total = self.p, 0.0
        for g in self.groups:
            if g.model.released_energy is not None and g.idx.size:
                total += g.model.released_energy(g.params, g.history(p.hist)[g.idx],
                                                 p.m[g.idx])
        return total

    def columns(self) -> dict[str, float]:
        """``swegle_unstable``: particles flagged by the Swegle criterion now;
        ``density_limited``: updated-Lagrangian particles held at a density limit."""
        self.swegle_field()
        return {"swegle_unstable": float(self.swegle_unstable),
                "density_limited": float(self.density_limited())}

    def density_limited(self) -> int:
        """Updated-Lagrangian particles whose density sits at a limit of their
        material ([material] min_density_factor, max_density_factor)."""
        p, lim = self.p, self.density_limits
        if not len(lim) or not p.n:
            return 0
        ul = ~p.tl
        f = lim[p.mat[ul]]
        rho, rho0 = p.rho[ul], p.rho0[ul]
        return int(np.count_nonzero((rho <= f[:, 0] * rho0 * (1 + 1e-12))
                                    | (rho >= f[:, 1] * rho0 * (1 - 1e-12))))

    def fields(self) -> dict:
        """Output fields the part evaluates on demand (for ``particle_fields``)."""
        p = self.p
        return {"swegle": self.swegle_field, "phase": lambda: p.phase,
                "variation": lambda: p.variation}

    def state(self) -> tuple[dict, dict[str, np.ndarray]]:
        p = self.p
        arrays = {"B": p.B, "dedt_av": p.dedt_av, "av_signal": p.av_signal,
                  "nl_offsets": self.nl.offsets,
                  "nl_idx": self.nl.idx, "nl_x_ref": self.nl.x_ref,
                  "nl_h_ref": self.nl.h_ref}
        if self.tl is not None:  # the reference configuration may have been updated
            arrays.update({"tl_X": self.tl.X, "tl_rho_ref": self.tl.rho_ref})
        return {"step": self.step}, arrays

    def restore(self, scalars: dict, arrays: dict) -> None:
        """Continue from a checkpoint (bitwise identical continuation)."""
        p = self.p
        self.step = int(scalars["step"])
        p.B = arrays["B"]
        p.dedt_av = arrays["dedt_av"]
        p.av_signal = arrays["av_signal"]
        self._visc = None  # it holds the replaced array
        nl = self.nl
        nl.offsets = arrays["nl_offsets"].copy()
        nl.idx = arrays["nl_idx"].copy()
        nl.x_ref = arrays["nl_x_ref"].copy()
        nl.h_ref = arrays["nl_h_ref"].copy()
        self._colouring_list = None  # the restored list's slabs
        # the lists were built without the particles removed by then
        self.ul_active = self._active_mask()
        nl.active_ref = None if self.ul_active is None else self.ul_active.copy()
        if self.tl is not None:
            if "tl_X" in arrays and not (np.array_equal(arrays["tl_X"], self.tl.X) and
                                         np.array_equal(arrays["tl_rho_ref"],
                                                        self.tl.rho_ref)):
                self.tl.rebuild(p, arrays["tl_X"].copy(), arrays["tl_rho_ref"].copy())
            self.tl.velocity_gradient(p)  # F of the restored state
        self._swegle_at = None

    # ------------------------------------------------------------- passes
    def _gradients(self) -> None:
        """Pair kernel gradients (once per step) and the velocity gradient L."""
        p, nl, k = self.p, self.nl, self.kernel
        need = nl.idx.shape[0]
        if self.F.shape[0] != need:  # only after a neighbour rebuild
            if self._F_buf.shape[0] < need:
                # the old factors are not needed (recomputed below): drop them
                # first, and keep spare capacity as the list does (its pages
                # are not resident until written)
                self.F = self._F_buf = None
                self._F_buf = np.empty(int(need * 1.1), dtype=np.float32)
            self.F = self._F_buf[:need]
        if self.has_ul:
            n_own = self._pair_colouring().n_own
            velocity_gradient(p.x, p.v, p.h, p.m, p.rho, nl.offsets, nl.idx, n_own, k.kid,
                              k.sigma, self.dim, k.support_scale, self.s.correction, self.F,
                              p.L, p.B, p.n_support, self._gradient_scratch())
        if self.tl is not None:
            self.tl.velocity_gradient(p)
        for f in self.pair_filters:
            f()

    def _accelerations(self) -> None:
        """Stress divergence and artificial viscosity (and stress) into ``a``.

        Uses the pair gradients of :meth:`_gradients` (smoothing length of the
        start of the step; h changes slowly, by design of the Benz update).
        """
        p, nl, k, s = self.p, self.nl, self.kernel, self.s
        if self.has_ul:
            stress_terms(p.sig, p.rho, p.B, p.S)
            alpha, beta, signal = self._viscosity_arrays()
            col = self._pair_colouring()
            forces(p.x, p.v, p.m, p.rho, p.h, p.c, p.S, self.F, nl.offsets, p.n_support,
                   nl.idx, col.order, col.start, self.dim, k.support_scale, alpha, beta, p.a,
                   p.dedt_av, signal)
        if self.as_on:
            artificial_stress_tensor(p.sig, p.rho, p.as_eps, p.R, p.Q)
            artificial_stress_forces(p.x, p.m, p.h, p.R, self.F, nl.offsets, nl.idx,
                                     k.kid, self.dim, k.support_scale, p.size,
                                     s.stress_exponent, p.a, p.v, p.dedt_av)
        if self.tl is not None:
            self.tl.accelerations(p, p.dedt_av)

    def _gradient_scratch(self):
        """The row buffers of :func:`.gradient.velocity_gradient`
        (:func:`.gradient.gradient_scratch`), widened after a neighbour rebuild
        that made a row longer."""
        nl = self.nl
        if self._scratch_list != (id(nl), nl.n_builds):
            self._scratch = gradient_scratch(nl.offsets, self._scratch)
            self._scratch_list = (id(nl), nl.n_builds)
        return self._scratch

    def _pair_colouring(self):
        """The :class:`.colouring.ListColouring` of :func:`.colouring.colour_pairs`
        for the current list, at the positions it was built from (the own pairs put
        first in each row); made again after a rebuild or a restore, before
        the gradient pass orders the rows (which keeps them first)."""
        nl = self.nl
        key = (id(nl), nl.n_builds)
        if self._colouring_list != key:
            self._colouring = colour_pairs(nl.x_ref, nl.offsets, nl.idx, nl.active_ref)
            self._colouring_list = key
        return self._colouring

    def _viscosity_arrays(self):
        """``(alpha, beta, signal)`` for :func:`.passes.forces`: the particles'
        coefficients, or one value each when all particles share them (the
        pass then forms no pair means), and the signal-speed array, or an empty
        one when no particle is of a fluid (the pass then skips it; the
        solids' step does not use it). Recomputed after particles are added."""
        if self._visc is None:
            p = self.p
            a, b = p.av_alpha, p.av_beta
            if p.n and np.all(a == a[0]) and np.all(b == b[0]):
                a, b = a[:1], b[:1]
            signal = p.av_signal if np.any(p.dt_viscous > 0.0) else p.av_signal[:0]
            self._visc = (a, b, signal)
        return self._visc

    def swegle_field(self) -> np.ndarray:
        """Swegle indicator (N,) of the current state (see :mod:`.swegle`).

        Computed at most once per state; also updates ``swegle_unstable``, the
        number of particles with more than ``FLAG_FRACTION`` unstable pairs.
        Returns the part's array (not a copy).
        """
        if self._swegle_at != self.step:
            p, nl, k = self.p, self.nl, self.kernel
            tol = stress_tolerance(p.sig, p.m, p.rho, p.c)
            swegle_indicator(p.x, p.m, p.h, p.sig, nl.offsets, nl.idx, k.kid, k.sigma,
                             self.dim, k.support_scale, tol, p.swegle)
            self.swegle_unstable = int(count_unstable(p.swegle, p.m, FLAG_FRACTION))
            self._swegle_at = self.step
        return self.p.swegle

    def summary(self) -> dict:
        """The current neighbour list's mean and largest neighbours per
        particle and how often it was built (the run's summary.json)."""
        return {"neighbours_mean": mean_neighbours(self.nl),
                "neighbours_max": max_neighbours(self.nl),
                "neighbour_builds": self.nl.n_builds}

    @property
    def mean_neighbours(self) -> float:
        """Mean neighbours per particle: of the total-Lagrangian reference lists
        if the part has total-Lagrangian bodies, else of the current list."""
        return self.tl.mean_neighbours if self.tl is not None else mean_neighbours(self.nl)
