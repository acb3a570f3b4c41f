"""Built-in benchmark cases for ``sphdyn bench``.

* ``rings2d``: the colliding rubber rings of Gray, Monaghan & Swift (2001),
  inner radius 30 mm, outer 40 mm, dx = 0.5 mm, h = 1.5 dx, cubic spline, 2D.
  Gray et al. give dimensionless data (E = 1e7, nu = 0.3975, rho = 1, each
  ring moving at 0.059 c0 with c0 = sqrt(K/rho)); we use the same ratios in
  SI: rho = 1000 kg/m^3, E = 10 MPa, so c0 = 127.5 m/s and v = 7.52 m/s.
* ``rings2d_tl``: the same rings with the total-Lagrangian kernel (fixed
  reference neighbours, hourglass control) and particle-particle contact.
* ``block3d``: an elastic 3D cube (concrete-like, E = 30 GPa) hitting a rigid
  wall at 10 m/s, with about ``--particles`` particles.
* ``hex3d``: the same cube as about ``--elements`` one-point hex8 elements
  with viscous hourglass control (LS-DYNA's default solid), the wall acting
  on the nodes.
* ``hvi``: the thesis's drop-weight impact on an RC beam (chapter 8), the
  deck ``examples/dropweight.toml`` of the repository (dx 6 mm, 281,000
  particles: CSCM concrete, sublayer rebar, FEM supports, a total-Lagrangian
  ram; about 40 s to build) or, with ``--coarse``, ``dropweight_coarse.toml``
  (dx 12 mm). The first steps are timed: the ram is still approaching (it
  meets the beam after about 1,100 steps at 6 mm, 1,760 at 12 mm), so they
  cost less than the impact's (``benchmarks/profile_step.py --start-steps``
  times those). Reports the stable step and the projected time of the whole
  event (``t_end / dt`` steps at the measured rate).

Each case is an ordinary deck (built in code), so the benchmark runs exactly
the code a user's deck runs. Timing excludes the first steps, which compile
the Numba kernels (reported separately as ``compile_seconds``).
"""

from __future__ import annotations

import json
import math
import resource
import time

import numba

from pathlib import Path

from .deck import load_deck, loads_deck

RINGS2D = """
[run]
title = "Gray et al. (2001) rubber rings, benchmark"
dimension = 2
t_end = 1.0
[sph]
kernel = "cubic_spline"
h_factor = 1.5
[[material]]
name = "rubber"
model = "elastic"
density = 1000.0
E = 1.0e7
nu = 0.3975
[[body]]
name = "left"
material = "rubber"
dx = 0.0005
velocity = [{v}, 0, 0]
geometry = {{ shape = "ring", centre = [-0.041, 0, 0], inner_radius = 0.03, outer_radius = 0.04 }}
[[body]]
name = "right"
material = "rubber"
dx = 0.0005
velocity = [-{v}, 0, 0]
geometry = {{ shape = "ring", centre = [0.041, 0, 0], inner_radius = 0.03, outer_radius = 0.04 }}
[output]
progress = false
vtk = false
"""

BLOCK3D = """
[run]
title = "elastic block on a rigid wall, benchmark"
dimension = 3
t_end = 1.0
[[material]]
name = "concrete"
model = "elastic"
density = 2400.0
E = 3.0e10
nu = 0.2
[[body]]
name = "block"
material = "concrete"
dx = {dx}
velocity = [0, 0, -10.0]
geometry = {{ shape = "box", lo = [0, 0, {gap}], hi = [0.1, 0.1, {top}] }}
[[wall]]
name = "floor"
point = [0, 0, 0]
normal = [0, 0, 1]
[output]
progress = false
vtk = false
"""


def rings_speed() -> float:
    """Impact speed of each ring: 0.059 c0, c0 = sqrt(K / rho) (Gray et al. 2001)."""
    e, nu, rho = 1.0e7, 0.3975, 1000.0
    k = e / (3 * (1 - 2 * nu))
    return 0.059 * math.sqrt(k / rho)


def hvi_deck_path(coarse: bool = False) -> Path:
    """The drop-weight deck of ``examples/`` (the ``hvi`` case): in the current
    directory (a clone of the repository, or the folder the examples were
    copied to), else in the repository this package was installed from."""
    name = "dropweight_coarse.toml" if coarse else "dropweight.toml"
    places = [Path.cwd() / "examples" / name,
              Path(__file__).resolve().parents[2] / "examples" / name]
    for path in places:
        if path.is_file():
            return path
    raise ValueError(f"bench hvi: examples/{name} not found in {places[0].parent.parent} "
                     f"or {places[1].parent.parent}; the case runs that deck of the "
                     "repository. Fix: run it from a clone of sphdyn (the folder "
                     "holding examples/)")


def case_deck(case: str, particles: int | None = None, coarse: bool = False):
    """The validated deck of a benchmark case."""
    if case == "hvi":
        return load_deck(hvi_deck_path(coarse))
    if case == "rings2d":
        return loads_deck(RINGS2D.format(v=rings_speed()))
    if case == "rings2d_tl":
        return loads_deck(RINGS2D.format(v=rings_speed()).replace(
            "[sph]", '[sph]\nformulation = "total_lagrangian"'))
    if case == "block3d":
        n = particles or 100_000
        side = max(2, round(n ** (1 / 3)))
        dx = 0.1 / side
        return loads_deck(BLOCK3D.format(dx=dx, gap=0.5 * dx, top=0.1 + 0.5 * dx))
    raise ValueError(f"unknown benchmark case {case!r}; choose rings2d, rings2d_tl, block3d "
                     "or hvi")


def hex3d_stepper(elements: int | None = None):
    """The ``hex3d`` case: the block3d cube as hex8 elements on a rigid wall."""
    import numpy as np

    from .geometry.mesh_blocks import block_mesh
    from .interactions import Wall, WallSpec
    from .interactions.wall_contact import STIFFNESS_MASS
    from .materials import get_model
    from .parts.fem import solid_part
    from .stepper import Stepper

    side = max(1, round((elements or 100_000) ** (1 / 3)))
    dx = 0.1 / side
    mesh = block_mesh([0, 0, 0.5 * dx], [0.1, 0.1, 0.1 + 0.5 * dx], (side,) * 3, 3)
    model = get_model("elastic")
    part = solid_part("block", mesh.points, mesh.cells, 3,
                      (model, model.pack({"density": 2400.0, "E": 3.0e10, "nu": 0.2})))
    part.nodes.v[:, 2] = -10.0
    wall = Wall(WallSpec("floor", np.zeros(3), np.array([0, 0, 1.0]), STIFFNESS_MASS,
                         alpha=0.1, friction=0.0, thickness_factor=0.5), part)
    return Stepper([part], [wall])


def run_bench(case: str, steps: int = 1000, threads: int | None = None,
              particles: int | None = None, warmup: int = 3,
              elements: int | None = None, coarse: bool = False) -> dict:
    """Run ``steps`` time steps of a case and time them (compilation excluded)."""
    from .build import build_stepper

    if threads:
        numba.set_num_threads(threads)
    t0 = time.perf_counter()
    deck = None
    if case == "hex3d":
        stepper = hex3d_stepper(elements)
    else:
        deck = case_deck(case, particles, coarse)
        stepper = build_stepper(deck)
    for _ in range(warmup):
        stepper.step()
    compile_s = time.perf_counter() - t0
    t1 = time.perf_counter()
    for _ in range(steps):
        stepper.step()
    seconds = time.perf_counter() - t1
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024  # Linux: KiB
    if case == "hex3d":
        part = stepper.parts[0]
        ne = part.el.n
        return {
            "case": case, "elements": ne, "nodes": part.nodes.n, "steps": steps,
            "threads": numba.get_num_threads(), "seconds": seconds,
            "compile_seconds": compile_s, "element_steps_per_s": ne * steps / seconds,
            "peak_rss_mb": peak / 2**20, "bytes_per_element": peak / ne,
        }
    sph = stepper.part("sph")
    n = sph.kin.n
    out = {
        "case": case, "particles": n, "steps": steps,
        "threads": numba.get_num_threads(), "seconds": seconds,
        "compile_seconds": compile_s,
        "particle_steps_per_s": n * steps / seconds,
        "neighbour_builds": sph.nl.n_builds,
        "neighbours_mean": sph.mean_neighbours,
        "peak_rss_mb": peak / 2**20,
        "bytes_per_particle": peak / n,
    }
    if case == "hvi":  # the whole event at this step and rate
        dt = stepper.dt_step
        out.update({"deck": str(hvi_deck_path(coarse)), "dt": dt, "t_end": deck.run.t_end,
                    "event_steps": deck.run.t_end / dt,
                    "projected_event_seconds": deck.run.t_end / dt * seconds / steps})
    return out


def main_json(**kw) -> str:
    return json.dumps(run_bench(**kw))
