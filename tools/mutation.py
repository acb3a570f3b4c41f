"""Mutation check of the test suite: does a small wrong change in the source fail its tests?

Each mutant names one file under ``src/``, an exact source snippet, its
replacement and the test node ids that must catch it. For every mutant the
script copies ``src/`` to a temporary directory, applies the one change
there (the working tree is never touched), and runs only the named tests
with ``PYTHONPATH`` pointing at the copy and a fresh ``NUMBA_CACHE_DIR``
inside the temporary directory (so a cached compilation of the unchanged
source cannot hide the change). The mutant is

* ``caught``   if pytest reports failing tests (exit status 1) or the run
  exceeds the time limit (an endless loop is a wrong program too),
* ``survived`` if the tests pass,
* ``error``    for any other outcome (a test id that does not exist, a
  collection error, a copy that is not the one imported).

A mutant whose snippet is not found exactly once in today's source is
refused (the list cannot rot silently); ``tests/test_mutation_script.py``
checks this for every mutant without running any.

Usage (from the repository root; run it alone, it compiles the Numba
kernels afresh for every mutant)::

    python tools/mutation.py                 # baseline, then every mutant
    python tools/mutation.py --list          # the mutants, nothing run
    python tools/mutation.py --only wall_mass_alpha kick_contact_work_halved
    python tools/mutation.py --no-baseline --markdown result.md

The baseline runs all named tests once on an unchanged copy; a mutant
whose tests already fail there could not be judged, so the script stops.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src"


@dataclass(frozen=True)
class Mutant:
    """One wrong change: ``old`` (found exactly once in ``src/<path>``) -> ``new``."""

    name: str
    area: str  # what it belongs to (kernels, neighbours, ..., issue 14 item)
    path: str  # relative to src/
    old: str
    new: str
    tests: tuple[str, ...]  # pytest node ids, relative to the repository root
    what: str  # the change in words


MUTANTS: tuple[Mutant, ...] = (
    # ------------------------------------------------------------------ core
    Mutant("kernel_cubic_2d_norm", "kernels", "sphdyn/kernels.py",
           "(1.0 / 6.0, 5.0 / (14.0 * _PI), 1.0 / (4.0 * _PI))",
           "(1.0 / 6.0, 15.0 / (14.0 * _PI), 1.0 / (4.0 * _PI))",
           ("tests/test_kernels.py::test_zeroth_moment",),
           "cubic spline 2D normalisation 5/(14 pi) -> the literature's 15/(14 pi)"),
    Mutant("kernel_cubic_gradient", "kernels", "sphdyn/kernels.py",
           "return 9.0 * q - 12.0", "return 9.0 * q - 11.0",
           ("tests/test_kernels.py::test_grad_factor_and_second_derivative_vs_fd",),
           "cubic spline w'(q)/q on q < 1: constant 12 -> 11"),
    Mutant("moment_matrix_sign", "issue 17 speed", "sphdyn/parts/sph/gradient.py",
           "m01 -= d0 * g1\n                m02 -= d0 * g2",
           "m01 += d0 * g1\n                m02 -= d0 * g2",
           ("tests/test_sph_passes.py::test_correction_is_the_inverse_moment_matrix_of_the_stored_factors",),
           "Randles-Libersky moment matrix: an off-diagonal entry with the wrong sign"),
    Mutant("moment_inverse_entry", "issue 17 speed", "sphdyn/algebra3.py",
           "q12 = (m02 * m01 - m00 * m12) * inv", "q12 = (m02 * m01 + m00 * m12) * inv",
           ("tests/test_sph_passes.py::test_correction_is_the_inverse_moment_matrix_of_the_stored_factors",
            "tests/test_algebra3.py::test_symmetric_inverse_is_numpys"),
           "the symmetric 3x3 inverse: a cofactor with the wrong sign"),
    Mutant("inverse3_entry", "issue 54", "sphdyn/algebra3.py",
           "out[1, 2] = (a02 * a10 - a00 * a12) * inv", "out[1, 2] = (a02 * a10 + a00 * a12) * inv",
           ("tests/test_algebra3.py::test_general_inverse_and_determinant_are_numpys",),
           "the general 3x3 inverse (total-Lagrangian F^-1, M^-1): a cofactor with the wrong sign"),
    Mutant("wall_far_margin", "issue 17 speed", "sphdyn/interactions/wall_contact.py",
           "far = 1.000001 * thickness_factor ** dim", "far = 0.9999 * thickness_factor ** dim",
           ("tests/test_walls.py::test_contact_decided_at_the_thickness_edge_as_the_formula_says",),
           "wall contact's rootless far test rejects particles just inside the thickness"),
    Mutant("contact_switch_motion", "erosion", "sphdyn/interactions/penalty_kernels.py",
           "excess = -gap - d_last[i] - motion_dt", "excess = -gap - d_last[i] + motion_dt",
           ("tests/test_erosion.py::test_a_switch_of_face_allows_what_the_motion_cannot_explain",),
           "a switch of face: the motion's approach added to the excess, not taken from it"),
    Mutant("contact_withdraw_nodes", "erosion", "sphdyn/interactions/penalty_kernels.py",
           "_add_shares(faces[face_of[i]], shares[i], mn, a_n, -1.0)",
           "_add_shares(faces[face_of[i]], shares[i], mn, a_n, -0.5)",
           ("tests/test_erosion.py::test_debris_inherits_no_contact_force_and_the_contact_moves_to_the_new_surface",),
           "contact forces withdrawn before erosion: half the nodes' share left for the debris"),
    Mutant("erosion_withdrawn_work", "erosion", "sphdyn/parts/fem/solid_part.py",
           "work = dt_half * np.sum(", "work = -dt_half * np.sum(",
           ("tests/test_erosion.py::test_a_withdrawn_load_returns_its_half_step_work",),
           "a degenerate element's withdrawn loads: their half-step work taken from its energy"),
    Mutant("sph_crack_band", "materials", "sphdyn/parts/sph/part.py",
           "p.band[rows] = s.crack_band * p.size[rows]", "p.band[rows] = p.size[rows]",
           ("tests/test_fracture_energy.py::test_an_sph_crack_dissipates_the_fracture_energy_over_two_particle_layers",),
           "an SPH crack's fracture-energy length: the particle size, not the crack band"),
    Mutant("neighbours_stencil", "neighbours", "sphdyn/neighbours/grid.py",
           "return (max(cx - k, 0), min(cx + k, nx - 1)",
           "return (max(cx - k + 1, 0), min(cx + k, nx - 1)",
           ("tests/test_neighbours.py::test_random_cloud_matches_brute_force_and_kdtree",),
           "cell stencil misses the cells on the -x side"),
    Mutant("neighbours_ties", "neighbours", "sphdyn/neighbours/rows.py",
           "hit = d0 * d0 + d1 * d1 + d2 * d2 < r * r",
           "hit = d0 * d0 + d1 * d1 + d2 * d2 <= r * r",
           ("tests/test_neighbours.py::test_cubic_lattice_ties_are_excluded",),
           "3D pair test collects pairs exactly at the radius ('<' -> '<=')"),
    Mutant("neighbours_coarse_grid", "neighbours", "sphdyn/neighbours/build.py",
           "coarse, _ = _make_grid(x, h, big, float(h[big].max())",
           "coarse, _ = _make_grid(x, h, big, float(h_cut)",
           ("tests/test_neighbours.py::test_many_large_h_particles_use_coarse_grid",),
           "coarse grid's cells sized by the fine grid's largest h, not its own"),
    Mutant("j2_hardening", "J2", "sphdyn/materials/j2.py",
           "d_gamma = f / (3.0 * G + H)", "d_gamma = f / (3.0 * G)",
           ("tests/test_materials.py::test_j2_uniaxial_stress_bilinear_and_unloading",),
           "radial return without the hardening modulus in the consistency condition"),
    Mutant("cscm_shear_surface", "CSCM", "sphdyn/materials/cscm/surface.py",
           "math.exp(-p[P_BETA] * J1) + p[P_THETA] * J1",
           "math.exp(-p[P_BETA] * J1) - p[P_THETA] * J1",
           ("tests/test_cscm.py::test_uniaxial_compression_peak",),
           "TXC shear surface: sign of the linear theta J1 term"),
    Mutant("cscm_brittle_softening", "CSCM", "sphdyn/materials/cscm/damage.py",
           "math.log(1.0 + D) / (D * gf)", "math.log(1.0 + D) / (2.0 * D * gf)",
           ("tests/test_cscm.py::test_tension_fracture_energy_regularised",),
           "brittle softening C with the fracture energy doubled"),
    Mutant("cscm_meridian_curvature", "CSCM", "sphdyn/materials/cscm/surface.py",
           "- 2.0 * d2w * y - 4.0 * dw * dy", "- 2.0 * d2w * y - 2.0 * dw * dy",
           ("tests/test_cscm.py::test_meridian_slope_and_curvature_are_the_derivatives_"
            "of_the_meridian",),
           "meridian curvature: a root's second derivative with half its w' y' term"),
    Mutant("cscm_newton_slope", "CSCM", "sphdyn/materials/cscm/projection.py",
           "(dF * dF + (F - rt) * d2F) / G", "(dF * dF - (F - rt) * d2F) / G",
           ("tests/test_cscm.py::test_newton_return_equals_the_bracketing_one",),
           "return's Newton step: sign of the meridian curvature term in g'"),
    Mutant("cscm_newton_taylor", "issue 17 speed", "sphdyn/materials/cscm/projection.py",
           "F + dx * (dF + 0.5 * dx * d2F)", "F + dx * dF",
           ("tests/test_cscm.py::test_newton_return_equals_the_bracketing_one",),
           "return's Newton exit on the predicted step: F to first order only"),
    Mutant("cscm_newton_first_step", "issue 17 speed", "sphdyn/materials/cscm/projection.py",
           "last = step if it > 0 else -1.0", "last = step",
           ("tests/test_cscm.py::test_newton_return_equals_the_bracketing_one",),
           "return's Newton exit predicted from the first step (from the trial)"),
    Mutant("verlet_common_shift", "issue 17 speed", "sphdyn/neighbours/verlet.py",
           "0.5 * (lo0 + hi0)", "0.0 * (lo0 + hi0)",
           ("tests/test_neighbours.py::test_a_body_moving_as_a_whole_needs_no_rebuild",),
           "rebuild criterion: the common displacement's x component left in"),
    Mutant("verlet_zero_shift", "issue 17 speed", "sphdyn/neighbours/verlet.py",
           "math.sqrt(min(dc2, d02))", "math.sqrt(dc2)",
           ("tests/test_neighbours.py::test_a_body_moving_as_a_whole_needs_no_rebuild",),
           "rebuild criterion: the box's centre even where no shift bounds better"),
    Mutant("cscm_tension_rubin", "issue 17 speed", "sphdyn/materials/cscm/surface.py",
           "return rub * ff, rub * dff, rub * d2ff", "return rub * ff, rub * dff, rub * dff",
           ("tests/test_cscm.py::test_meridian_slope_and_curvature_are_the_derivatives_"
            "of_the_meridian",),
           "meridian in tension (Rubin ratios held): curvature with the slope's factor"),
    Mutant("gradient_buffer_factors", "issue 17 speed", "sphdyn/parts/sph/gradient.py",
           "for t in range(c0 + end - own):", "for t in range(c0 + end - own - 1):",
           ("tests/test_sph_passes.py::test_buffered_gradient_rows_give_the_pair_by_pair_bits",),
           "buffered gradient rows: the last pair's kernel factor not formed"),
    Mutant("own_pairs_rank", "issue 17 speed", "sphdyn/parts/sph/colouring.py",
           "if rank[j] > rank[i]:", "if rank[j] < rank[i]:",
           ("tests/test_pair_colouring.py::test_own_pairs_first_puts_each_pair_in_one_row_head",),
           "own pairs first: the pairs of lower rank put first"),
    Mutant("balanced_slab_width", "issue 17 speed", "sphdyn/parts/sph/colouring.py",
           "if np.all(np.diff(b) >= width):", "if np.all(np.diff(b) >= 0.5 * width):",
           ("tests/test_pair_colouring.py::test_balanced_bounds_split_the_weight_evenly_or_give_up",
            "tests/test_pair_colouring.py::test_slabs_share_the_pairs_evenly_where_the_body_allows"),
           "balanced slabs thinner than the longest pair (a pair could skip a slab)"),
    Mutant("cscm_elastic_bound", "CSCM", "sphdyn/materials/cscm/surface.py",
           "r0 = 0.999 * min(q1, q2, 1.0) * shear_surface(0.0, p)",
           "r0 = 0.999 * min(q1, 1.0) * shear_surface(0.0, p)",
           ("tests/test_cscm.py::test_pressure_free_elastic_bound",),
           "pressure-free elastic bound without the TXE ratio Q2 (too large)"),
    Mutant("checkpoint_float32", "checkpoints", "sphdyn/io/hdf5.py",
           "g_scalars.attrs[name] = np.float64(value)",
           "g_scalars.attrs[name] = np.float32(value)",
           ("tests/test_io.py::TestHdf5::test_checkpoint_bitwise_round_trip",),
           "checkpoint scalars stored in single precision"),
    Mutant("checkpoint_wall_impulse", "checkpoints", "sphdyn/interactions/wall.py",
           'self.impulse[...] = arrays["impulse"]', "self.impulse[...] = 0.0",
           ("tests/test_run.py::test_restart_continues_to_the_same_result[updated_lagrangian]",),
           "restart does not restore the wall impulse"),
    # ------------------------------------------------------- issue 18: fluids
    Mutant("jwl_sound_speed_omega", "issue 18", "sphdyn/materials/eos/jwl.py",
           "c2 = (-V * (dpc - w * E / (V * V)) + w * p) / rho",
           "c2 = (-V * (dpc - w * E / (V * V)) - w * p) / rho",
           ("tests/test_explosive.py::test_jwl_sound_speed_is_the_isentrope_slope",),
           "JWL sound speed: sign of the energy term"),
    Mutant("burn_width_dropped", "issue 18", "sphdyn/materials/explosive.py",
           "clock * D / (width * size)", "clock * D / size",
           ("tests/test_explosive.py::test_burn_fraction_programmed_beta_and_both",),
           "programmed burn without its width"),
    Mutant("chemical_release_total", "issue 18", "sphdyn/materials/explosive.py",
           "fluid_energy(e[i], (f - f_old) * q,", "fluid_energy(e[i], f * q,",
           ("tests/test_explosive.py::test_chemical_energy_released_and_the_balance_closes",),
           "the whole burned energy released again every step"),
    Mutant("polynomial_c2_in_tension", "issue 18", "sphdyn/materials/eos/polynomial.py",
           "if mu < 0.0:", "if mu > 0.0:",
           ("tests/test_explosive.py::"
            "test_polynomial_drops_c2_c6_in_tension_and_its_sound_speed_is_the_slope",),
           "polynomial EOS: C2, C6 dropped in compression instead of tension"),
    Mutant("fluid_energy_half_work", "issue 18", "sphdyn/materials/fluid.py",
           "k = 0.5 * dt * tr_d / rho", "k = 0.25 * dt * tr_d / rho",
           ("tests/test_explosive.py::test_fluid_energy_solves_its_equation_and_keeps_the_cutoff",
            "tests/test_explosive.py::test_sod_shock_tube_against_the_exact_solution"),
           "fluid energy equation with half the pdV work"),
    Mutant("blast_oblique_reflection", "issue 18", "sphdyn/interactions/kingery_bulmash.py",
           "return pr * c2 + ps * (1.0 + c2 - 2.0 * cos_theta)",
           "return pr * c2 + ps * (1.0 + c2 - cos_theta)",
           ("tests/test_blast_load.py::test_angle_of_incidence_and_timing",),
           "blast load: the incident term's -2 cos(theta) halved"),
    Mutant("blast_duration_not_lengthened", "issue 18", "sphdyn/interactions/kingery_bulmash.py",
           "t0 = max(t0, 2.0 * i_s / pso, 2.0 * i_r / pr)", "t0 = max(t0, 2.0 * i_s / pso)",
           ("tests/test_blast_load.py::test_a_fitted_pulse_carries_its_impulse",),
           "blast pulse: t0 not lengthened for the reflected impulse close in"),
    Mutant("blast_impulse_scaling", "issue 18", "sphdyn/interactions/kingery_bulmash.py",
           "i_r = PSI * ms * 10.0 ** fit(", "i_r = PSI * MS_LB * 10.0 ** fit(",
           ("tests/test_blast_load.py::test_parameters_scale_with_the_cube_root_of_the_charge",),
           "reflected impulse not scaled by the cube root of the charge"),
    Mutant("hex_lanes_viscous_quarter", "issue 15", "sphdyn/parts/fem/hourglass.py",
           "return qh * rho * c * face / 4.0",
           "return qh * rho * c * face / 2.0",
           ("tests/test_fem_solid.py::test_hourglass_force_of_a_cube_matches_its_formula"
            "[viscous-3]",),
           "hex8 (both passes): viscous hourglass coefficient Q rho c V^(2/3) / 4 -> / 2"),
    Mutant("element_step_hourglass_damping_half", "issue 53", "sphdyn/parts/fem/solid.py",
           "Qe = Q + overlap * 0.5 * a_h * ell", "Qe = Q + overlap * 0.25 * a_h * ell",
           ("tests/test_fem_solid.py::test_element_step_with_hourglass_terms_is_the_"
            "damped_oscillator_limit",),
           "element step: the hourglass damping rate's share A_h l / 2 -> l / 4"),
    Mutant("hourglass_rate_no_half", "issue 53", "sphdyn/parts/fem/hourglass.py",
           "return 0.5 * coef * lam / m_share, 0.0", "return coef * lam / m_share, 0.0",
           ("tests/test_fem_solid.py::test_the_hourglass_bound_and_rates",),
           "hourglass damping rate a_h lambda / (2 m) -> a_h lambda / m"),
    Mutant("hourglass_overlap_dimension", "issue 53", "sphdyn/parts/fem/hourglass.py",
           "mu = t / (V * V) - (dim - 1)", "mu = t / (V * V) - dim",
           ("tests/test_fem_solid.py::test_the_overlap_bounds_the_angle_between_stiffness_"
            "and_hourglass_subspaces[3]",),
           "subspace overlap: mu = tr(Gx Gb) - (d - 1) -> - d (below the true angle)"),
    Mutant("overlap_roundoff_wide", "issue 53", "sphdyn/parts/fem/hourglass.py",
           "OVERLAP_ROUNDOFF = 1e-10", "OVERLAP_ROUNDOFF = 1e-4",
           ("tests/test_fem_solid.py::test_the_overlap_bounds_the_angle_between_stiffness_"
            "and_hourglass_subspaces[3]",),
           "subspace overlap: the round-off threshold on mu - 1 widened to 1e-4"),
    Mutant("nrb_lagged", "issue 53", "sphdyn/interactions/non_reflecting.py",
           "        b0 = v[i, 0] + 0.5 * dt * a_int[i, 0]\n"
           "        b1 = v[i, 1] + 0.5 * dt * a_int[i, 1]\n"
           "        b2 = v[i, 2] + 0.5 * dt * a_int[i, 2]\n",
           "        b0 = v[i, 0]\n        b1 = v[i, 1]\n        b2 = v[i, 2]\n"
           "        s = 0.0\n        a00 = a11 = a22 = 1.0\n        a01 = a02 = a12 = 0.0\n",
           ("tests/test_non_reflecting.py::test_the_ends_absorb_at_the_courant_number_one_"
            "along_the_bar[hex8]",),
           "non-reflecting boundary: the dashpots on v^(n+1/2) (lagged) instead of the "
           "centred v^(n+1)"),
    Mutant("nrb_shear_impedance", "issue 53", "sphdyn/interactions/non_reflecting.py",
           "C[r, i, i] += z_s[f] * area", "C[r, i, i] += z_d[f] * area",
           ("tests/test_non_reflecting.py::test_flat_face_gives_each_corner_a_quarter_of_"
            "its_area_times_the_impedances",
            "tests/test_non_reflecting.py::test_a_plane_pulse_leaves_through_the_absorbing_"
            "ends[S-hex8]"),
           "non-reflecting boundary: the shear dashpot with rho c_d instead of rho c_s"),
    Mutant("nrb_shear_speed", "issue 53", "sphdyn/interactions/non_reflecting.py",
           "z_s[rows] = math.sqrt(rho0 * g.model.shear_modulus(g.params))",
           "z_s[rows] = math.sqrt(g.model.shear_modulus(g.params))",
           ("tests/test_non_reflecting.py::test_a_plane_pulse_leaves_through_the_absorbing_"
            "ends[S-quad4]",),
           "non-reflecting boundary: rho c_s = sqrt(rho G) -> sqrt(G)"),
    Mutant("exterior_twin_kept", "issue 53", "sphdyn/interactions/penalty_geometry.py",
           "| ((twins >= 0) & ~kept[np.maximum(twins, 0)]))",
           "| ((twins >= 0) & kept[np.maximum(twins, 0)]))",
           ("tests/test_penalty_coupling.py::test_exterior_faces_of_kept_elements_from_the_"
            "twins[3]",),
           "erosion's master surface: a face exterior when its twin's element is kept "
           "instead of dropped"),
    Mutant("hex_lanes_node_share", "issue 53", "sphdyn/parts/fem/hex_lanes.py",
           "S[MSH_ * LANES + l] = m_el[e] / 8", "S[MSH_ * LANES + l] = m_el[e] / 4",
           ("tests/test_fem_solid.py::test_an_element_distorted_into_its_hourglass_shape_"
            "takes_the_joint_step[viscous-3]",),
           "vectorised hex8: each node's share of the element mass m / 8 -> m / 4"),
    Mutant("hourglass_bound_trace_only", "issue 53", "sphdyn/parts/fem/hex_lanes.py",
           "lam = min(S[TR_ * LANES + l], S[ROW_ * LANES + l])",
           "lam = S[TR_ * LANES + l]",
           ("tests/test_fem_solid.py::test_an_element_distorted_into_its_hourglass_shape_"
            "takes_the_joint_step[viscous-3]",),
           "vectorised hex8: the Gram bound the trace alone (4x too high undistorted)"),
    Mutant("hex_lanes_gamma_reversed", "issue 15", "sphdyn/parts/fem/hex_lanes.py",
           "f += S[(QA_ + 3 * a + i) * LANES + l] * GAMMA[a, I]",
           "f += S[(QA_ + 3 * a + i) * LANES + l] * GAMMA[a, 7 - I]",
           ("tests/test_fem_solid.py::test_hourglass_forces_of_a_distorted_element_follow_"
            "the_shape_vectors[stiffness-3]",),
           "vectorised hex8: hourglass forces on the nodes in reverse order"),
    Mutant("hex_lanes_end_geometry_rate", "issue 15", "sphdyn/parts/fem/hex_lanes.py",
           "gather_nodes(x, v, 0.5 * dt, conn, lo, nl, S)",
           "gather_nodes(x, v, 0.0 * dt, conn, lo, nl, S)",
           ("tests/test_fem_solid.py::test_rigid_rotation_of_90_degrees_gives_no_stress[3]",),
           "vectorised hex8: velocity gradient on the end-of-step geometry, not mid-step"),
    Mutant("blast_mesh_share", "issue 18", "sphdyn/interactions/blast.py",
           "a_out[faces[f, a], k] += force[f, k] / (nf * m[faces[f, a]])",
           "a_out[faces[f, a], k] += force[f, k] / m[faces[f, a]]",
           ("tests/test_blast_load.py::test_blast_impulse_momentum_and_work_on_particles_and_mesh",),
           "blast on a mesh face: each node takes the whole force"),
    Mutant("blast_particle_face_area", "issue 18", "sphdyn/interactions/blast.py",
           "return item, np.concatenate(normals), half, (2.0 * half) ** (dim - 1)",
           "return item, np.concatenate(normals), half, half ** (dim - 1)",
           ("tests/test_blast_load.py::test_blast_impulse_momentum_and_work_on_particles_and_mesh",),
           "blast on particles: a face's area from the half spacing"),
    # ------------------------------------------------------- issue 14, items 1-6
    Mutant("ul_viscosity_beta_sign", "issue 14.1", "sphdyn/parts/sph/passes.py",
           "pi_ij = (-aij * mu + bij * mu * mu)",
           "pi_ij = (-aij * mu - bij * mu * mu)",
           ("tests/test_sph_passes.py::test_pair_stress_and_viscosity_match_their_formulas",),
           "updated-Lagrangian artificial viscosity: sign of the beta term"),
    Mutant("wall_mass_alpha", "issue 14.2", "sphdyn/interactions/wall_contact.py",
           "return alpha * pen / (dt * dt)", "return pen / (dt * dt)",
           ("tests/test_walls.py::test_spring_acceleration_and_force_match_the_paper",
            "tests/test_walls.py::test_mass_spring_in_numbers"),
           "mass-based wall spring (eq. 8) without alpha (10x stiffer)"),
    Mutant("wall_bulk_alpha", "issue 14.2", "sphdyn/interactions/wall_contact.py",
           "k = alpha * kbulk * vol0 ** ((dim - 2.0) / dim)\n    return k * pen",
           "k = kbulk * vol0 ** ((dim - 2.0) / dim)\n    return k * pen",
           ("tests/test_walls.py::test_spring_acceleration_and_force_match_the_paper",),
           "bulk-modulus wall spring (eq. 9) without alpha"),
    Mutant("wall_alpha_not_passed", "issue 14.2", "sphdyn/interactions/wall.py",
           "w.alpha, w.friction, dt, a_out, p.wall_force",
           "1.0, w.friction, dt, a_out, p.wall_force",
           ("tests/test_walls.py::test_wall_interaction_passes_its_spring_to_the_kernel",),
           "the Wall interaction passes alpha = 1 instead of the deck's"),
    Mutant("tl_hourglass_doubled", "issue 14.3", "sphdyn/parts/sph/total_lagrangian.py",
           "hgk[k] = -0.25 * alpha", "hgk[k] = -0.5 * alpha",
           ("tests/test_total_lagrangian.py::test_hourglass_coefficients_match_their_formula",),
           "total-Lagrangian hourglass coefficient doubled"),
    Mutant("kick_contact_work_halved", "issue 14.4", "sphdyn/integrate.py",
           "wc += mi * dt_kick * (a_contact", "wc += 0.5 * mi * dt_kick * (a_contact",
           ("tests/test_integrate.py::"
            "test_kick_books_the_contact_work_and_energies_over_several_blocks",),
           "the kick's contact work halved"),
    Mutant("drift_y_uses_x_velocity", "integration", "sphdyn/integrate.py",
           "x[i, 1] += dt * v[i, 1]", "x[i, 1] += dt * v[i, 0]",
           ("tests/test_integrate.py::test_leapfrog_is_second_order",),
           "the drift moves y with the x velocity"),
    Mutant("restart_work_external", "issue 14.5", "sphdyn/stepper.py",
           'self.work_external = float(scalars["work_external"])',
           "self.work_external = 0.0",
           ("tests/test_run.py::test_restart_restores_the_external_work",),
           "restart does not restore the external work"),
    Mutant("ensemble_population_std", "issue 14.6", "sphdyn/analysis/compression.py",
           "np.std(values, ddof=1)", "np.std(values, ddof=0)",
           ("tests/test_compression.py::test_curve_of_an_elastic_column",),
           "ensemble CoV with the population instead of the sample std"),
    Mutant("artificial_stress_rho", "issue 14.6",
           "sphdyn/parts/sph/artificial_stress.py",
           "f = -eps[i] / (rho[i] * rho[i])", "f = -eps[i] / rho[i]",
           ("tests/test_artificial_stress.py::test_epsilon_per_body",),
           "artificial stress divided by rho instead of rho^2"),
    Mutant("artificial_stress_exponent", "issue 14.6",
           "sphdyn/parts/sph/artificial_stress.py",
           "fn = fij ** n_exp", "fn = fij ** int(n_exp)",
           ("tests/test_artificial_stress.py::"
            "test_pair_force_is_repulsive_with_the_stated_magnitude",),
           "non-integer exponent n truncated to an integer"),
    Mutant("sublayer_corrected_own_pairs", "issue 16.2", "sphdyn/interactions/sublayer.py",
           "if member[j] or fac[q] == 0.0:", "if fac[q] == 0.0:",
           ("tests/test_sublayer.py::"
            "test_the_bars_own_pairs_are_out_of_its_velocity_gradient[True]",),
           "corrected bar particle: its bar's own pairs back in both sums"),
    Mutant("sublayer_corrected_moment_entry", "issue 16.2", "sphdyn/interactions/sublayer.py",
           "M[a, b] += (x[j, a] - x[i, a]) * g", "M[a, b] += (x[j, b] - x[i, b]) * g",
           ("tests/test_sublayer.py::"
            "test_corrected_concrete_is_exact_around_a_bonded_bar_in_affine_motion",),
           "corrected bar particle: the moment sum with the wrong component of x_j - x_i"),
    Mutant("interaction_work_born_rows", "issue 16.1", "sphdyn/watchers/interaction_work.py",
           "acc[n0:] = q.a_ext[n0:]", "acc[n0:] = 0.0",
           ("tests/test_interaction_work.py::"
            "test_the_sources_add_up_to_the_interactions_work_through_erosion",),
           "the loads of particles born in an erosion left out of the events' work"),
    Mutant("interaction_work_dt", "issue 16.1", "sphdyn/watchers/interaction_work.py",
           "    return w * dt_kick", "    return w",
           ("tests/test_interaction_work.py::"
            "test_kick_work_is_the_mass_weighted_power_over_the_kick",),
           "a source's work over a kick without the kick's length"),
    Mutant("penalty_largest_step", "issue 16.1", "sphdyn/interactions/penalty_coupling.py",
           "dt_k = self._dt_k if self.largest_step else dt", "dt_k = dt",
           ("tests/test_penalty_coupling.py::"
            "test_the_mass_spring_keeps_the_stiffness_of_the_largest_step[largest]",),
           "stiffness_step = largest: the springs take the current step after all"),
    Mutant("penalty_spring_energy", "issue 16.1", "sphdyn/interactions/wall_contact.py",
           "ext = min(ext * np.sqrt(k_last[i] / k), pen)", "ext = min(ext, pen)",
           ("tests/test_penalty_coupling.py::"
            "test_a_spring_slid_to_a_heavier_point_of_its_face_keeps_its_energy",
            "tests/test_walls.py::test_a_wall_spring_keeps_its_energy_when_the_step_changes"),
           "a spring's stiffness change keeps its extension, not its energy (the rule "
           "the coupling and the wall share)"),
    Mutant("penalty_allowance_negative", "issue 16.1", "sphdyn/interactions/wall_contact.py",
           "ext = min(ext * np.sqrt(k_last[i] / k), pen)", "ext = ext * np.sqrt(k_last[i] / k)",
           ("tests/test_penalty_coupling.py::"
            "test_a_spring_slid_back_takes_its_extension_back_from_the_allowance",
            "tests/test_walls.py::test_a_wall_spring_gives_back_what_it_took_and_never_more"),
           "a softening spring's extension beyond the penetration (a negative allowance)"),
    Mutant("wall_spring_energy", "issue 16.1", "sphdyn/interactions/wall_contact.py",
           "ext = keep_spring_energy(i, pen, ext, k1, pen0, k_last)", "k_last[i] = k1",
           ("tests/test_walls.py::test_a_wall_spring_gives_back_what_it_took_and_never_more",
            "tests/test_walls.py::test_a_bounce_with_the_step_halved_under_load_makes_no_energy"),
           "the wall's spring takes the current step's stiffness as it is (energy made as "
           "the step drops under load)"),
    Mutant("wall_born_allowance", "issue 16.1", "sphdyn/interactions/wall_contact.py",
           "if pen < pen0[i] or k_last[i] == BORN:", "if pen < pen0[i]:",
           ("tests/test_walls.py::"
            "test_a_particle_born_inside_the_wall_thickness_is_allowed_its_penetration",),
           "a particle born inside the wall's thickness feels its whole penetration"),
    Mutant("wall_restore_springs", "issue 16.1", "sphdyn/interactions/wall.py",
           'setattr(p, self._pen0, arrays["allowance"])\n        setattr(p, self._k_last, '
           'arrays["stiffness"])', "pass",
           ("tests/test_walls.py::test_a_wall_springs_state_survives_a_restart",),
           "a restart forgets the wall springs' allowances and stiffnesses"),
    Mutant("penalty_behind_edge", "issue 16.1", "sphdyn/interactions/penalty_kernels.py",
           "            k_last[i] = 0.0\n            continue\n        pen = max(-gap, 0.0)",
           "            gap = 0.0\n        pen = max(-gap, 0.0)",
           ("tests/test_penalty_coupling.py::"
            "test_a_particle_behind_a_faces_edge_keeps_its_allowance",),
           "a particle behind a face's edge loses its allowance"),
    Mutant("restore_refresh_state", "issue 16.1", "sphdyn/stepper.py",
           '            inter.restore(*_own_state(scalars, groups, f"interaction.{inter.name}"))\n',
           "",
           ("tests/test_erosion.py::"
            "test_a_restore_leaves_the_springs_state_as_the_checkpoint_has_it",),
           "the restore's evaluation for the columns keeps what it did to the springs"),
)


class MutantRefused(ValueError):
    """The mutant's snippet is not found exactly once in the source."""


def apply_mutant(mutant: Mutant, src_root: Path) -> None:
    """Replace ``mutant.old`` by ``mutant.new`` in ``src_root/mutant.path`` (in place).

    Raises :class:`MutantRefused` unless the snippet occurs exactly once.
    """
    path = Path(src_root) / mutant.path
    text = path.read_text(encoding="utf-8")
    count = text.count(mutant.old)
    if count != 1:
        raise MutantRefused(f"{mutant.name}: snippet found {count} times in {mutant.path} "
                            f"(must be exactly once): {mutant.old!r}")
    path.write_text(text.replace(mutant.old, mutant.new), encoding="utf-8")


def check_mutants(mutants=MUTANTS, src_root: Path = SRC) -> list[str]:
    """Problems of the mutant list against today's source (empty: all usable)."""
    problems = []
    names = [m.name for m in mutants]
    if len(set(names)) != len(names):
        problems.append("duplicate mutant names")
    for m in mutants:
        path = Path(src_root) / m.path
        if not path.is_file():
            problems.append(f"{m.name}: no file {m.path}")
            continue
        count = path.read_text(encoding="utf-8").count(m.old)
        if count != 1:
            problems.append(f"{m.name}: snippet found {count} times in {m.path}")
        if m.new == m.old:
            problems.append(f"{m.name}: the replacement equals the snippet")
        if not m.tests:
            problems.append(f"{m.name}: no tests named")
    return problems


def _copy_source(dest: Path) -> Path:
    """Copy ``src/`` to ``dest/src`` without caches; return the copy's path."""
    out = dest / "src"
    shutil.copytree(SRC, out, ignore=shutil.ignore_patterns(
        "__pycache__", "*.pyc", "*.nbi", "*.nbc", "*.egg-info"))
    return out


def _environment(src_copy: Path, cache: Path) -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(src_copy)
    env["NUMBA_CACHE_DIR"] = str(cache)
    env.pop("PYTEST_ADDOPTS", None)
    return env


def _imported_from(env: dict[str, str]) -> Path:
    """The directory ``sphdyn`` is imported from under ``env``."""
    out = subprocess.run([sys.executable, "-c", "import sphdyn; print(sphdyn.__file__)"],
                         env=env, cwd=ROOT, capture_output=True, text=True, check=True)
    return Path(out.stdout.strip()).resolve().parent


def run_tests(tests, mutant: Mutant | None, timeout: float) -> tuple[str, float, str]:
    """Run ``tests`` against a copy of ``src/`` with ``mutant`` applied (None: unchanged).

    Returns (outcome, seconds, last lines of the output); outcome is
    ``passed``, ``failed``, ``timeout`` or ``error: <why>``.
    """
    with tempfile.TemporaryDirectory(prefix="sphdyn-mutant-") as tmp:
        tmp = Path(tmp)
        src_copy = _copy_source(tmp)
        if mutant is not None:
            apply_mutant(mutant, src_copy)
        env = _environment(src_copy, tmp / "numba_cache")
        where = _imported_from(env)
        if where != (src_copy / "sphdyn").resolve():
            return f"error: sphdyn imported from {where}, not the copy", 0.0, ""
        cmd = [sys.executable, "-m", "pytest", "-q", "-x", "-p", "no:cacheprovider",
               f"--basetemp={tmp / 'pytest'}", *tests]
        t0 = time.perf_counter()
        try:
            proc = subprocess.run(cmd, env=env, cwd=ROOT, capture_output=True, text=True,
                                  timeout=timeout)
        except subprocess.TimeoutExpired:
            return "timeout", time.perf_counter() - t0, ""
        seconds = time.perf_counter() - t0
        lines = (proc.stdout + proc.stderr).strip().splitlines()
        # the failing tests of the short summary (-ra), else the last lines
        failed = [ln for ln in lines if ln.startswith(("FAILED ", "ERROR "))]
        tail = "\n".join(failed or lines[-5:])
        outcome = {0: "passed", 1: "failed"}.get(proc.returncode,
                                                  f"error: pytest exit {proc.returncode}")
        return outcome, seconds, tail


def judge(outcome: str) -> str:
    """Mutant verdict from the outcome of its tests."""
    if outcome in ("failed", "timeout"):
        return "caught"
    if outcome == "passed":
        return "survived"
    return outcome


def markdown_table(results) -> str:
    """The results as a Markdown table plus the catch rate."""
    lines = ["| mutant | area | change | tests | result | time [s] |",
             "|---|---|---|---|---|---|"]
    for m, verdict, seconds in results:
        tests = "<br>".join(f"`{t.removeprefix('tests/')}`" for t in m.tests)
        lines.append(f"| `{m.name}` | {m.area} | {m.what} | {tests} | {verdict} | "
                     f"{seconds:.0f} |")
    caught = sum(v == "caught" for _, v, _ in results)
    lines.append("")
    lines.append(f"Catch rate: {caught} of {len(results)} "
                 f"({100.0 * caught / max(len(results), 1):.0f} %).")
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    """Command line: see the module docstring. Exit status 0 if every mutant is caught."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="+", metavar="NAME", help="run only these mutants")
    ap.add_argument("--list", action="store_true", help="list the mutants and exit")
    ap.add_argument("--no-baseline", action="store_true",
                    help="skip the run of all named tests on the unchanged source")
    ap.add_argument("--timeout", type=float, default=1800.0,
                    help="seconds per mutant before it counts as caught (default 1800)")
    ap.add_argument("--markdown", type=Path, help="also write the table to this file")
    args = ap.parse_args(argv)

    mutants = list(MUTANTS)
    if args.only:
        unknown = set(args.only) - {m.name for m in mutants}
        if unknown:
            ap.error(f"unknown mutants: {', '.join(sorted(unknown))}")
        mutants = [m for m in mutants if m.name in args.only]
    if args.list:
        for m in mutants:
            print(f"{m.name:28s} {m.area:12s} {m.path}: {m.what}")
        return 0
    problems = check_mutants(mutants)
    if problems:
        print("refused:\n  " + "\n  ".join(problems), file=sys.stderr)
        return 2

    if not args.no_baseline:
        tests = list(dict.fromkeys(t for m in mutants for t in m.tests))
        print(f"baseline: {len(tests)} tests on the unchanged source ...", flush=True)
        outcome, seconds, tail = run_tests(tests, None, args.timeout)
        print(f"baseline: {outcome} ({seconds:.0f} s)", flush=True)
        if outcome != "passed":
            print(tail, file=sys.stderr)
            return 2

    results = []
    for m in mutants:
        outcome, seconds, tail = run_tests(m.tests, m, args.timeout)
        verdict = judge(outcome)
        results.append((m, verdict, seconds))
        print(f"{m.name:28s} {verdict:9s} ({seconds:.0f} s)", flush=True)
        if verdict != "survived":  # which test caught it (or why it could not run)
            print("  " + tail.replace("\n", "\n  "), flush=True)
    table = markdown_table(results)
    print()
    print(table)
    if args.markdown:
        args.markdown.write_text(table, encoding="utf-8")
    return 0 if all(v == "caught" for _, v, _ in results) else 1


if __name__ == "__main__":
    sys.exit(main())
