"""The time stepper: ordered SPH passes, material update and contact per step.

The solver holds the model's arrays and advances them; it writes no file.
Order of one step (state at :math:`t^n`: :math:`\\mathbf x^n,\\ \\mathbf
v^{n-1/2},\\ \\sigma^n,\\ \\mathbf a^n`):

1. time step from the CFL condition (and contact limit);
2. kick to :math:`\\mathbf v^{n+1/2}` with boundary conditions; energies at
   :math:`t^n` (see :mod:`sphdyn.integrate`);
3. drift to :math:`\\mathbf x^{n+1}` (XSPH-smoothed velocity if enabled);
4. neighbour list update (only when the Verlet skin is exhausted);
5. velocity gradient, density and smoothing length, material update
   (:math:`\\sigma^{n+1}`, internal energy); bodies with the
   total-Lagrangian formulation take L and the density from their
   deformation gradient (:mod:`sphdyn.sph.tl_scheme`) instead;
6. stress divergence and artificial viscosity (plus the artificial stress
   of :mod:`sphdyn.sph.artificial_stress` when ``epsilon > 0``; the
   first Piola-Kirchhoff form with hourglass control on total-Lagrangian
   bodies), then contact between bodies (:mod:`sphdyn.contact.particles`)
   and with rigid walls, giving :math:`\\mathbf a^{n+1}`;
7. (on demand, not every step) the Swegle indicator of the current state
   (:mod:`sphdyn.sph.swegle`): the output field ``swegle`` when a frame is
   written and the history column ``swegle_unstable`` for the records the
   Simulation keeps (every ``output.history_every`` steps).
"""

from __future__ import annotations

import numpy as np

from .contact.particles import contact_time_step, particle_contact
from .contact.wall import STIFFNESS_BULK, bulk_contact_time_step, wall_contact
from .guards import check_particles, check_time_step
from .integrate import add_heat, cfl_time_step, drift, internal_energies, kick
from .model import Model
from .probes import record as probe_record
from .neighbours import build_neighbours, update_neighbours
from .sph.artificial_stress import artificial_stress_forces, artificial_stress_tensor
from .sph.passes import (forces, particle_volumes, scaled_stress,
                         update_density_and_h, velocity_gradient, xsph_velocity)
from .sph.swegle import (FLAG_FRACTION, REL_STRESS_TOL, count_unstable, stress_scale,
                         swegle_indicator)
from .sph.tl_scheme import TotalLagrangian


def total_lagrangian_mask(deck, body: np.ndarray) -> np.ndarray:
    """(N,) bool: particles of bodies using the total-Lagrangian formulation.

    A body's ``formulation`` overrides ``[sph] formulation``.
    """
    tl_bodies = [k for k, b in enumerate(deck.body)
                 if (b.formulation or deck.sph.formulation) == "total_lagrangian"]
    return np.isin(body, tl_bodies)


class Solver:
    """Advance a :class:`~sphdyn.model.Model` in time.

    Parameters
    ----------
    model : the particle model.
    deck : the validated deck (reads the ``sph`` and ``time`` sections).
    """

    def __init__(self, model: Model, deck):
        self.model = model
        p = self.p = model.particles
        sph = deck.sph
        self.dim = p.dim
        self.kid = model.kernel_id
        self.sigma = model.kernel_sigma
        self.kscale = sph.support_scale
        self.correct = bool(sph.correction)
        self.alpha = sph.viscosity.alpha
        self.beta = sph.viscosity.beta
        self.xsph = sph.xsph
        self.benz = sph.smoothing_length.mode == "benz"
        self.hmin = sph.smoothing_length.min_factor
        self.hmax = sph.smoothing_length.max_factor
        self.cfl = deck.time.cfl
        self.dt_max = deck.time.dt_max if deck.time.dt_max is not None else np.inf
        self.collapse_ratio = deck.time.collapse_ratio
        n = p.n
        self.B = np.zeros((n, 3, 3))
        # artificial stress (Monaghan 2000): R/rho^2 and principal-axis work array
        # (epsilon per particle: a body may set its own, TL bodies need none)
        tl = total_lagrangian_mask(deck, p.body)
        eps_body = np.array([sph.artificial_stress.epsilon if b.artificial_stress is None
                             else b.artificial_stress for b in deck.body])
        self.as_eps = np.where(tl, 0.0, eps_body[p.body])
        self.as_n = sph.artificial_stress.n
        on = bool(np.any(self.as_eps > 0))
        self.R = np.zeros((n, 3, 3)) if on else None
        self.Q = np.zeros((n, 3, 3)) if on else None
        self.spacing = p.vol0 ** (1.0 / p.dim) if n else np.zeros(0)  # initial dx [m]
        # Swegle indicator per particle, evaluated on demand (history records
        # kept by the Simulation, output frames; see output_fields)
        self.history_every = deck.output.history_every
        self.swegle = np.zeros(n)
        self.swegle_unstable = 0
        self._swegle_step = -1
        self.S = np.zeros((n, 3, 3))
        self.vol = np.zeros(n)
        self.size = p.vol0 ** (1.0 / p.dim)  # particle size for regularisation [m]
        self.F = np.zeros(0)
        self.dedt_av = np.zeros(n)
        self.a_contact = np.zeros((n, 3))
        self.vmean = np.zeros((n, 3))
        self.vs = np.zeros((n, 3)) if self.xsph > 0 else None
        self.wall_force = np.zeros((n, 3))
        self.guard_work = np.zeros(n, dtype=np.int8)
        self.wall_totals = {w.name: np.zeros(3) for w in model.walls}
        self.wall_counts = {w.name: 0 for w in model.walls}
        # impulse each wall has given the bodies so far [N s] (N s/m in 2D):
        # the sum of F^n dt_kick over the kicks, so it equals the bodies'
        # momentum change through the wall to round-off
        self.wall_impulse = np.zeros((len(model.walls), 3))
        # contact stability limit of bulk-modulus springs (mass springs need none)
        self.dt_contact = np.inf
        for w in model.walls:
            if w.method == STIFFNESS_BULK and n:
                self.dt_contact = min(self.dt_contact, 0.5 * bulk_contact_time_step(
                    p.m, p.vol0, p.rho0, w.kbulk, self.dim, w.alpha))
        r0 = model.radius_factor * float(p.h.max()) if n else 0.0
        self.skin = sph.neighbours.skin_factor * r0
        # total-Lagrangian bodies: fixed reference neighbours; the updated-
        # Lagrangian list then holds the other particles only
        self.ul_active = ~tl if tl.any() else None
        self.has_ul = not tl.all()  # False: the updated-Lagrangian passes are skipped
        self.tl = None
        self.ref_every = sph.reference_update_every
        if tl.any():
            young = np.zeros(n)
            for g in model.groups:
                k, mu = g.model.bulk_modulus(g.params), g.model.shear_modulus(g.params)
                young[g.idx] = 9.0 * k * mu / (3.0 * k + mu)
            self.tl = TotalLagrangian(p, np.flatnonzero(tl), self.kid, self.sigma,
                                      model.radius_factor, self.kscale, young,
                                      sph.hourglass, self.alpha, self.beta)
        # particle-particle contact between bodies
        c = deck.contact
        n_bodies = len(np.unique(p.body)) if n else 0
        self.contact_on = bool(c.enabled) if c.enabled is not None else bool(
            n_bodies >= 2 and tl.any())
        self.contact_factor = c.distance_factor
        self.contact_alpha = c.alpha
        self.contact_count = 0
        self.cnl = None
        if self.contact_on and n:
            self.dt_contact = min(self.dt_contact, 0.5 * contact_time_step(
                p.m, self.size, model.bulk_modulus, self.dim, c.alpha))
            # the same absolute skin as the SPH list (or larger): a skin scaled
            # with the short contact radius alone forced a rebuild every few
            # steps in the rings benchmark (0.125 mm at 15 m/s closing speed)
            cskin = sph.neighbours.skin_factor * max(
                r0, c.distance_factor * float(self.size.max()))
            self.cnl = build_neighbours(p.x, self.size, c.distance_factor, cskin, self.dim)
        self.t = 0.0
        self.step_count = 0
        self.dt_prev = 0.0  # 0 before the first kick (half kick)
        self.work_contact = 0.0
        self.work_external = 0.0
        self.nl = build_neighbours(p.x, p.h, model.radius_factor, self.skin, self.dim,
                                   active=self.ul_active)
        self.dt0, _ = self._cfl()
        self.dt_contact_step = self.dt0  # the step the contact springs use
        self._gradients()
        self._accelerations(self.dt0)

    # ------------------------------------------------------------------ parts
    def _cfl(self):
        p = self.p
        dt, k = cfl_time_step(p.h, p.c, p.v, min(1.0, self.kscale), self.cfl)
        return min(dt, self.dt_max, self.dt_contact), k

    def _gradients(self):
        """Pair kernel gradients (once per step) and the velocity gradient L."""
        p, nl = self.p, self.nl
        if self.F.shape[0] != nl.idx.shape[0]:
            self.F = np.empty(nl.idx.shape[0])  # only after a neighbour rebuild
        if self.has_ul:
            particle_volumes(p.m, p.rho, self.vol)
            velocity_gradient(p.x, p.v, p.h, self.vol, nl.offsets, nl.idx, self.kid,
                              self.sigma, self.dim, self.kscale, self.correct, self.F,
                              p.L, self.B)
        if self.tl is not None:
            self.tl.velocity_gradient(p)

    def _accelerations(self, dt):
        """Stress divergence, artificial viscosity and contact at the current state.

        Uses the pair gradients of :meth:`_gradients` (smoothing length of the
        start of the step; h changes slowly, by design of the Benz update).
        """
        p, nl = self.p, self.nl
        if self.has_ul:
            scaled_stress(p.sig, p.rho, self.S)
            forces(p.x, p.v, p.m, p.rho, p.h, p.c, self.S, self.B, self.F, nl.offsets,
                   nl.idx, self.dim, self.kscale, self.correct, self.alpha, self.beta,
                   p.a, self.dedt_av)
        if self.R is not None:
            artificial_stress_tensor(p.sig, p.rho, self.as_eps, self.R, self.Q)
            artificial_stress_forces(p.x, p.m, p.h, self.R, self.F, nl.offsets, nl.idx,
                                     self.kid, self.dim, self.kscale, self.spacing,
                                     self.as_n, p.a, p.v, self.dedt_av)
        if self.tl is not None:
            self.tl.accelerations(p, self.dedt_av)
        self.a_contact[:] = 0.0
        self._contact(dt, self.a_contact)
        p.a += self.a_contact

    def _contact(self, dt, a_out) -> None:
        """Inter-body and wall contact accelerations added to ``a_out`` (N, 3);
        updates the contact counts and the wall force totals."""
        p = self.p
        if self.cnl is not None:
            self.contact_count = int(particle_contact(
                p.x, p.m, self.size, self.model.bulk_modulus, p.body, self.dim,
                self.cnl.offsets, self.cnl.idx, self.contact_alpha, self.contact_factor,
                a_out))
        for w in self.model.walls:
            cnt = wall_contact(p.x, p.v, p.m, p.vol0, p.rho0, w.kbulk, self.dim,
                               w.point_at(self.t), w.normal, w.velocity_at(self.t),
                               w.thickness_factor, w.method, w.alpha, w.friction, dt,
                               a_out, self.wall_force)
            self.wall_counts[w.name] = int(cnt)
            self.wall_totals[w.name] = self.wall_force.sum(axis=0)

    def output_fields(self) -> dict:
        """Output fields the solver evaluates on demand, for ``particle_fields``."""
        out = {"swegle": self.swegle_field}
        # the model's per-particle arrays; absent ones get io.fields' defaults
        if self.model.phase is not None:
            out["phase"] = lambda: self.model.phase
        if self.model.variation is not None:
            out["variation"] = lambda: self.model.variation
        return out

    def swegle_field(self) -> np.ndarray:
        """Swegle indicator (N,) of the current state (see :mod:`sphdyn.sph.swegle`).

        Computed at most once per step; also updates ``swegle_unstable``, the
        number of particles with more than ``FLAG_FRACTION`` unstable pairs.
        Returns the solver's array (not a copy).
        """
        if self._swegle_step != self.step_count:
            p, nl = self.p, self.nl
            tol = REL_STRESS_TOL * stress_scale(p.sig, p.m)
            swegle_indicator(p.x, p.m, p.h, p.sig, nl.offsets, nl.idx, self.kid,
                             self.sigma, self.dim, self.kscale, tol, self.swegle)
            self.swegle_unstable = int(count_unstable(self.swegle, p.m, FLAG_FRACTION))
            self._swegle_step = self.step_count
        return self.swegle

    # ------------------------------------------------------------------- step
    def step(self, t_stop: float | None = None) -> dict:
        """Advance one step; returns the energy/force record at the kick time t^n.

        ``t_stop`` shortens the step so that the run ends exactly there.
        """
        p, model = self.p, self.model
        dt, k = self._cfl()
        check_time_step(dt, self.dt0, self.collapse_ratio, self.t, self.step_count, k, p)
        # the contact springs use the stable step, not one shortened to end the
        # run: k = alpha m / dt^2 (paper eq. 8) would grow by (dt / dt_short)^2
        self.dt_contact_step = dt
        if t_stop is not None and self.t + dt > t_stop:
            dt = max(t_stop - self.t, 0.0)
        dt_kick = 0.5 * dt if self.step_count == 0 else 0.5 * (self.dt_prev + dt)
        ke, wc, we = kick(p.v, p.a, self.a_contact, p.m, p.bc, p.bc_v, dt_kick,
                          self.vmean)
        self.work_contact += wc
        self.work_external += we
        for k, w in enumerate(model.walls):
            self.wall_impulse[k] += self.wall_totals[w.name] * dt_kick
        # the Simulation keeps the records of steps 0, every, 2 every, ...
        record = self.energies(ke, dt,
                               swegle=self.step_count % self.history_every == 0)

        nl = self.nl
        if self.vs is not None:
            xsph_velocity(p.x, p.v, p.m, p.rho, p.h, nl.offsets, nl.idx, self.kid,
                          self.sigma, self.dim, self.kscale, self.xsph, self.vs)
            drift(p.x, self.vs, dt)
        else:
            drift(p.x, p.v, dt)
        self.t += dt
        self.step_count += 1
        self.dt_prev = dt

        self.nl = update_neighbours(nl, p.x, p.h, self.dim, self.ul_active)
        if (self.tl is not None and self.ref_every
                and self.step_count % self.ref_every == 0):
            self.tl.update_reference(p)
        if self.cnl is not None:
            self.cnl = update_neighbours(self.cnl, p.x, self.size, self.dim)
        self._gradients()
        if self.has_ul:
            update_density_and_h(p.L, dt, self.dim, self.benz, p.h0, self.hmin,
                                 self.hmax, p.rho, p.h)
        if self.tl is not None:
            self.tl.density(p)
        for g in model.groups:
            g.model.update(g.idx, p.L, dt, p.rho, p.sig, p.e, p.c, p.damage, p.hist,
                           g.params, self.size)
        self._accelerations(self.dt_contact_step)
        add_heat(p.e, p.e_av, self.dedt_av, dt)
        check_particles(p, model.domain_lo, model.domain_hi, self.t, self.step_count,
                        self.guard_work)
        return record

    def energies(self, kinetic: float, dt: float, swegle: bool = True) -> dict:
        """Energy balance at the last kick (J, J/m in 2D) and the step ``dt`` [s].

        ``swegle_unstable`` is the number of particles flagged by the Swegle
        criterion in the current state (re-evaluated only if ``swegle``; else
        the last value).
        """
        if swegle:
            self.swegle_field()
        ie, iav = internal_energies(self.p.m, self.p.e, self.p.e_av)
        e_contact = -self.work_contact
        rec = {
            "time": self.t, "step": float(self.step_count), "dt": dt,
            "E_kinetic": kinetic, "E_internal": ie, "E_viscous": iav,
            "E_contact": e_contact, "W_external": self.work_external,
            "E_total": kinetic + ie + e_contact - self.work_external,
            "swegle_unstable": float(self.swegle_unstable),
        }
        if self.cnl is not None:
            rec["contacts_bodies"] = float(self.contact_count)
        for k, w in enumerate(self.model.walls):
            f = self.wall_totals[w.name]
            fn = float(f @ w.normal)
            rec[f"F_wall_{w.name}"] = fn
            rec[f"I_wall_{w.name}"] = float(self.wall_impulse[k] @ w.normal)
            rec[f"F_wall_{w.name}_t"] = float(np.linalg.norm(f - fn * w.normal))
            rec[f"contacts_{w.name}"] = float(self.wall_counts[w.name])
            if w.velocity.any():
                rec[f"d_wall_{w.name}"] = float(w.velocity @ w.normal) * w.travel(self.t)
        rec.update(probe_record(self.p, self.model.probes))
        return rec

    # ------------------------------------------------------------- checkpoint
    def state_scalars(self) -> dict:
        return {"t": self.t, "step": self.step_count, "dt_prev": self.dt_prev,
                "dt0": self.dt0, "dt_contact_step": self.dt_contact_step,
                "work_contact": self.work_contact,
                "work_external": self.work_external}

    def state_arrays(self) -> dict:
        out = {"a_contact": self.a_contact, "B": self.B, "dedt_av": self.dedt_av,
               "wall_impulse": self.wall_impulse}
        if self.tl is not None:  # the reference configuration may have been updated
            out.update({"tl_X": self.tl.X, "tl_rho_ref": self.tl.rho_ref})
        lists = {"nl": self.nl} if self.cnl is None else {"nl": self.nl, "cnl": self.cnl}
        for key, nl in lists.items():
            out.update({f"{key}_offsets": nl.offsets, f"{key}_idx": nl.idx,
                        f"{key}_x_ref": nl.x_ref, f"{key}_h_ref": nl.h_ref})
        return out

    def restore(self, scalars: dict, arrays: dict, particle_arrays: dict) -> None:
        """Continue from a checkpoint (bitwise identical continuation)."""
        for name, arr in particle_arrays.items():
            getattr(self.p, name)[...] = arr
        self.t = float(scalars["t"])
        self.step_count = int(scalars["step"])
        self.dt_prev = float(scalars["dt_prev"])
        self.dt0 = float(scalars["dt0"])
        self.work_contact = float(scalars["work_contact"])
        self.work_external = float(scalars["work_external"])
        self.a_contact[...] = arrays["a_contact"]
        self.B[...] = arrays["B"]
        self.dedt_av[...] = arrays["dedt_av"]
        if "wall_impulse" in arrays:  # absent in checkpoints before 2026-11-23
            self.wall_impulse[...] = arrays["wall_impulse"]
        for key in ("nl", "cnl"):
            nl = getattr(self, key)
            if nl is not None:
                nl.offsets = arrays[f"{key}_offsets"].copy()
                nl.idx = arrays[f"{key}_idx"].copy()
                nl.x_ref = arrays[f"{key}_x_ref"].copy()
                nl.h_ref = arrays[f"{key}_h_ref"].copy()
        if self.tl is not None:
            if "tl_X" in arrays and not (np.array_equal(arrays["tl_X"], self.tl.X) and
                                         np.array_equal(arrays["tl_rho_ref"],
                                                        self.tl.rho_ref)):
                self.tl.rebuild(self.p, arrays["tl_X"].copy(),
                               arrays["tl_rho_ref"].copy())
            self.tl.velocity_gradient(self.p)  # F of the restored state
        self._swegle_step = -1
        # contact counts and wall totals of the restored state (they depend on
        # x, v and dt only; the accelerations themselves are in the checkpoint)
        self.dt_contact_step = float(scalars.get("dt_contact_step", 0.0)) or \
            self.dt_prev or self.dt0  # absent in checkpoints before 2026-11-23
        self._contact(self.dt_contact_step, np.zeros_like(self.a_contact))
