"""Scalar results of a finished sample: forces, energies, damage, main cracks."""

from __future__ import annotations

import numpy as np

from ..analysis.fragments import window_mean_force

#: Damage at and above which a particle counts as failed (fully damaged).
FAILED_DAMAGE = 0.9


def count_main_cracks(x0, damage, mass, dx: float, normal=(0.0, 1.0, 0.0),
                      threshold: float = FAILED_DAMAGE, min_size: int | None = None,
                      dim: int = 3) -> int:
    r"""Number of main cracks: failed bands crossing the body's mid-section.

    Definition (reference configuration): the *mid-section* is the plane
    through the centroid of the particles with mass, normal to ``normal``
    (the impact direction, the wall normal). Take the particles with mass
    within one spacing of it (about two rows) that have failed (damage >=
    ``threshold``), link those closer than 1.5 dx, and count the connected
    groups of at least ``min_size`` particles (default 2 in 2D, 4 in 3D, so
    an isolated failed particle is not a crack). A crack running through
    the body from the crushed contact zone crosses the mid-section once; two
    separate crossings are two main cracks even if they join in the contact
    zone (the paper's "multiple main cracks", Fig. 8); the crushed zone
    itself is not counted unless it reaches the mid-section.

    Parameters
    ----------
    x0 : (N, 3) initial positions [m]; damage, mass : (N,).
    dx : particle spacing [m]; normal : (3,) impact direction.
    """
    from ..analysis.fragments import fragment_labels, fragment_sizes

    x0 = np.asarray(x0, float)
    solid = np.asarray(mass) > 0
    n = np.asarray(normal, float) / np.linalg.norm(normal)
    c = x0[solid].mean(axis=0)
    s = (x0 - c) @ n
    band = solid & (np.abs(s) <= dx * (1 + 1e-9)) & (np.asarray(damage) >= threshold)
    if not band.any():
        return 0
    labels = fragment_labels(x0, 1.5 * dx, mask=band)
    sizes = fragment_sizes(labels)
    size = (2 if dim == 2 else 4) if min_size is None else min_size
    return int((sizes >= size).sum())


def sample_metrics(sim) -> dict:
    """Scalar results of one finished sample (a :class:`Simulation`).

    * ``peak_contact_force``: maximum over the history of the summed normal
      wall forces [N] (N/m in 2D); NaN without walls;
    * ``peak_contact_force_mean``: maximum of the same force averaged over
      ``[output] force_window`` (:func:`sphdyn.analysis.fragments.window_mean_force`),
      free of the spikes of first contact;
    * ``dissipated_energy``: internal energy at the end [J]: plastic and
      damage work, artificial-viscosity heat (also given alone as
      ``viscous_energy``) and the elastic energy still stored (small after
      the rebound);
    * ``damaged_volume_fraction``: volume (m / rho0) of failed particles
      (damage >= :data:`FAILED_DAMAGE`) over the volume of the body;
    * ``main_cracks``: :func:`count_main_cracks` of each body, summed;
    * ``final_kinetic_energy``, ``initial_kinetic_energy`` [J].
    """
    model, p = sim.model, sim.particles
    h = sim.history.as_arrays()
    walls = [w.name for w in model.walls]
    peak = peak_mean = float("nan")
    if walls and len(h.get("time", ())):
        peak = float(np.max(np.sum([h[f"F_wall_{w}"] for w in walls], axis=0)))
        impulse = np.sum([h[f"I_wall_{w}"] for w in walls], axis=0)
        peak_mean = float(np.max(window_mean_force(h["time"], impulse,
                                                   sim.deck.output.force_window)))
    vol = np.where(p.m > 0, p.m / p.rho0, 0.0)
    failed = p.damage >= FAILED_DAMAGE
    normal = model.walls[0].normal if model.walls else np.array([0.0, 1.0, 0.0])
    cracks = 0
    for b in range(len(model.body_names)):
        sel = p.body == b
        dx = float(np.median(p.vol0[sel]) ** (1.0 / p.dim))
        cracks += count_main_cracks(p.x0[sel], p.damage[sel], p.m[sel], dx, normal,
                                    dim=p.dim)
    last = {k: float(v[-1]) for k, v in h.items() if len(v)}
    return {
        "peak_contact_force": peak,
        "peak_contact_force_mean": peak_mean,
        "dissipated_energy": last.get("E_internal", float("nan")),
        "viscous_energy": last.get("E_viscous", float("nan")),
        "damaged_volume_fraction": float(vol[failed].sum() / vol.sum()),
        "main_cracks": cracks,
        "final_kinetic_energy": float(0.5 * np.sum(p.m * np.sum(p.v * p.v, axis=1))),
        "initial_kinetic_energy": float(h["E_kinetic"][0]) if "E_kinetic" in h
        and len(h["E_kinetic"]) else float("nan"),
        "zero_mass_particles": int((p.m == 0).sum()),
        "steps": sim.stepper.step_count,
    }
