"""Checks of a deck's model before it is built or run: its size and its placement.

* :func:`estimate_size` counts the particles of every body from the closed-form
  volume of its geometry over ``dx**dim`` and the neighbour-list pairs from the
  kernel support, before a single particle is made; :func:`check_size` refuses
  a model over ``run.memory_limit`` (default: half of this machine's memory),
  so a mistyped ``dx`` cannot hang ``sphdyn check`` and end in a MemoryError.
* :func:`placement_problems` finds, on the built lattices, bodies that
  overlap, bodies that start through a wall and bodies of a single particle:
  decks that validate but would die mid-run.

Both raise :class:`~sphdyn.deck.DeckError` (exit status 2 on the command line),
one ``<path>: <what>. Fix: <what to write>`` line per problem.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np

from .deck import DeckError
from .deck.errors import format_problem
from .geometry.lattice import polygon_area, rotate_about

#: Bytes of per-particle state and work arrays (besides history variables and
#: neighbour lists): about 850 measured for block3d at 1M particles
#: (BENCHMARKS.md), rounded up.
PARTICLE_BYTES = 1000
#: Bytes per neighbour pair: index and two float32 factors (12), rounded up
#: for the lists being rebuilt beside the old ones.
PAIR_BYTES = 16
#: Bytes per hex8 element of a generated mesh, node and point arrays included:
#: 1.12 kB marginal peak RSS measured for one-point hex3d (BENCHMARKS.md),
#: rounded up. (The selective-reduced variant's eight points need about 3 kB
#: more per element; the estimate does not count them yet.)
ELEMENT_BYTES = 1600
#: Share of the machine's memory a deck may use without ``run.memory_limit``.
DEFAULT_MEMORY_SHARE = 0.5
#: A particle of one body closer than this many of its spacings inside another
#: body's geometry (or behind a wall) counts as overlapping (round-off margin).
_TOLERANCE = 1e-6


def _power(x: float, n: int) -> float:
    """``x**n`` that overflows to inf instead of raising (float ``**`` raises)."""
    return math.prod([float(x)] * n)


def ball_volume(radius: float, dim: int) -> float:
    """Length of a segment (1D), area of a disc (2D) or volume of a ball (3D)
    of ``radius``."""
    if dim == 1:
        return 2.0 * radius
    return math.pi * _power(radius, 2) if dim == 2 else 4.0 / 3.0 * math.pi * _power(radius, 3)


def lattice_neighbours(radius: float, dim: int) -> int:
    """Points of the unit cubic (square, 1D) lattice within ``radius`` of a
    lattice point, itself not counted: ``#{p in Z^dim, 0 < |p| < radius}``
    (strictly inside, as the neighbour lists exclude ties). The list of an
    interior particle of a regular lattice of spacing dx at the build, for
    a Verlet radius of ``radius`` dx; its ball's volume differs by the
    points near the sphere (80 against 77 for the disc's 2.64 dx)."""
    k = int(math.ceil(radius))
    axis = np.arange(-k, k + 1, dtype=float) ** 2
    r2 = axis
    for _ in range(dim - 1):
        r2 = np.add.outer(r2, axis)
    return int(np.count_nonzero(r2 < radius * radius)) - 1


def support_radius(sph) -> float:
    """The support radius in units of h for the deck's [sph] section ``sph``:
    the kernel's times ``support_scale``."""
    from .kernels import kernel_id, support

    return support(kernel_id(sph.kernel)) * sph.support_scale


def prism_volume(prism, dim: int) -> float:
    """Volume of a prism (a body's or a [mesh.prism]) [m^3], its area [m^2] in 2D."""
    area = abs(polygon_area(prism.points))
    return area if dim == 2 else area * prism.length


def shape_volume(geometry, dim: int) -> float:
    """Closed-form volume of a body geometry [m^3], or area [m^2] in 2D."""
    g = geometry
    if g.shape == "box":
        return math.prod(h - l for l, h in zip(g.lo[:dim], g.hi[:dim]))
    if g.shape == "sphere":
        return ball_volume(g.radius, dim)
    if g.shape == "prism":
        return prism_volume(g, dim)
    outer = g.radius if g.shape == "cylinder" else g.outer_radius
    inner = 0.0 if g.shape == "cylinder" else g.inner_radius
    area = ball_volume(outer, 2) - ball_volume(inner, 2)
    return area if dim == 2 else area * g.length


def lattice_count(volume: float, dx: float, dim: int) -> float:
    """Particles of spacing ``dx`` in ``volume``; inf when it overflows."""
    cell = _power(dx, dim)
    n = volume / cell if cell > 0 else math.inf
    return n if math.isfinite(n) else math.inf


def depth_inside(geometry, x: np.ndarray, dim: int) -> np.ndarray:
    """(n,) distance of points ``x`` (n, 3) inside a body geometry [m].

    Positive inside (the distance to the nearest face), negative or zero
    outside (only the sign and the depth inside are used).
    """
    g = geometry
    if g.shape == "box":
        lo, hi = np.asarray(g.lo)[:dim], np.asarray(g.hi)[:dim]
        return np.min(np.minimum(x[:, :dim] - lo, hi - x[:, :dim]), axis=1)
    if getattr(g, "tilt", None):  # into the upright cylinder's frame
        x = rotate_about(x, g.centre, g.tilt_axis, -g.tilt)
    rel = x - np.asarray(g.centre)
    if g.shape == "sphere":
        return g.radius - np.linalg.norm(rel[:, :dim], axis=1)
    ax = "xyz".index(g.axis)
    u, v = (rel[:, a] for a in range(3) if a != ax)
    r = np.hypot(u, v)
    if g.shape == "cylinder":
        d = g.radius - r
    else:
        d = np.minimum(g.outer_radius - r, r - g.inner_radius)
    if dim == 3:
        d = np.minimum(d, 0.5 * g.length - np.abs(rel[:, ax]))
    return d


def machine_memory() -> float | None:
    """Physical memory of this machine (or the cgroup limit if lower) [bytes]."""
    sizes = []
    try:
        sizes.append(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        pass
    try:  # a container's limit ("max" when unlimited)
        with open("/sys/fs/cgroup/memory.max") as fh:
            sizes.append(int(fh.read().strip()))
    except (OSError, ValueError):
        pass
    sizes = [s for s in sizes if s > 0]
    return float(min(sizes)) if sizes else None


def memory_limit(deck) -> tuple[float, str]:
    """``(bytes, where it comes from)`` of the deck's memory limit."""
    if deck.run.memory_limit is not None:
        return deck.run.memory_limit, "run.memory_limit"
    ram = machine_memory()
    if ram is None:
        return 8.0 * 2**30, "the default when the machine's memory is unknown"
    return DEFAULT_MEMORY_SHARE * ram, "half of this machine's memory"


def show_bytes(n: float) -> str:
    """A memory size in messages: ``12.3 MB``, ``7.1 TB`` (decimal units)."""
    for unit, scale in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n >= scale:
            return f"{n / scale:.3g} {unit}"
    return f"{n:.0f} B"


def show_count(n: float) -> str:
    """A particle count in messages: ``10,053`` or ``1.57e+14``."""
    return f"{n:,.0f}" if n < 1e9 else f"{n:.3g}"


@dataclass(frozen=True)
class SizeEstimate:
    """Particles and memory of a deck's model, estimated from its geometry."""

    #: body name -> estimated particle count
    bodies: dict
    particles: float
    pairs_per_particle: float
    bytes_particles: float
    bytes_neighbours: float
    #: mesh name -> element count of the generated meshes (files: not counted)
    meshes: dict = None

    @property
    def bytes_meshes(self) -> float:
        return ELEMENT_BYTES * float(sum((self.meshes or {}).values()))

    @property
    def bytes(self) -> float:
        """Estimated memory of the model [bytes]."""
        return self.bytes_particles + self.bytes_neighbours + self.bytes_meshes

    def summary(self) -> str:
        """One line: particles, neighbours and memory."""
        meshes = (f" + {show_count(sum(self.meshes.values()))} elements "
                  f"{show_bytes(self.bytes_meshes)}" if self.meshes else "")
        return (f"about {show_count(self.particles)} particles, {self.pairs_per_particle:.0f} "
                f"neighbours each, {show_bytes(self.bytes)} (particles "
                f"{show_bytes(self.bytes_particles)} + neighbour lists "
                f"{show_bytes(self.bytes_neighbours)}{meshes})")


def history_models(deck) -> list:
    """The material models whose history columns the model's items share: the
    deck's materials in order, and the uniaxial bar when a sublayer's
    particles carry the bar axially (``stiffness = "axial"``)."""
    from .materials import UNIAXIAL, get_model

    models = [get_model(m.model) for m in deck.material]
    if any(m.sublayer is not None and m.sublayer.stiffness == "axial" for m in deck.mesh):
        models.append(UNIAXIAL)
    return models


def history_width(deck) -> int:
    """Columns of the particles' one history array: :func:`history_models`
    laid side by side as the parts lay them
    (:func:`~sphdyn.materials.history_layout`; every material counted, an
    upper bound where a mesh has its own), at least one."""
    from .materials import history_layout

    models = history_models(deck)
    try:
        width = len(history_layout(models)[0])
    except ValueError:  # models that cannot share one array: the build names them
        width = sum(len(m.history_names) for m in models)
    return max(width, 1)


def estimate_size(deck) -> SizeEstimate:
    """Estimate the model of a validated deck without building it.

    Particles per body: the closed-form volume of its geometry over
    ``dx**dim``. Neighbours per particle: the lattice points in the Verlet
    radius ``q_max * support_scale * h_factor * (1 + skin_factor) * dx``
    (:func:`lattice_neighbours`).
    Memory: :data:`PARTICLE_BYTES` plus 8 bytes per history variable per
    particle and :data:`PAIR_BYTES` per neighbour pair.
    """
    dim = deck.run.dimension
    sph = deck.sph
    bodies = {b.name: lattice_count(shape_volume(b.geometry, dim), b.dx, dim)
              for b in deck.body}
    n = float(sum(bodies.values()))
    radius = support_radius(sph) * sph.h_factor * (1.0 + sph.neighbours.skin_factor)
    pairs = float(lattice_neighbours(radius, dim))
    per_particle = PARTICLE_BYTES + 8 * history_width(deck)
    meshes = {m.name: _element_count(m, dim) for m in deck.mesh if m.file is None}
    return SizeEstimate(bodies, n, pairs, n * per_particle,
                        n * pairs * PAIR_BYTES if n and pairs else 0.0, meshes)


def _element_count(mesh, dim: int) -> float:
    """Elements of a generated [[mesh]] (the prism's by its volume)."""
    if mesh.block is not None:
        return float(np.prod(mesh.block.divisions))
    if mesh.prism is not None:
        return lattice_count(prism_volume(mesh.prism, dim), mesh.prism.element_size, dim)
    return float(mesh.line.count)


def _mesh_source(mesh) -> str:
    """The deck key that sets a generated mesh's size."""
    if mesh.prism is not None:
        return "prism.element_size"
    return f"{'block' if mesh.block is not None else 'line'}.divisions"


def check_size(deck) -> SizeEstimate:
    """Refuse a deck whose model would exceed its memory limit; return the estimate."""
    est = estimate_size(deck)
    limit, source = memory_limit(deck)
    if not est.bytes <= limit:  # nan (inf * 0) counts as too large
        if est.meshes and est.bytes_meshes >= est.bytes_particles:
            k = max(range(len(deck.mesh)), key=lambda j: est.meshes.get(deck.mesh[j].name, 0))
            m = deck.mesh[k]
            raise DeckError([format_problem(
                f"mesh[{k}].{_mesh_source(m)}",
                f"the model needs {est.summary()}, over the memory limit of "
                f"{show_bytes(limit)} ({source}); mesh '{m.name}' alone has "
                f"{show_count(est.meshes[m.name])} elements",
                "use fewer divisions, or raise run.memory_limit above "
                f"{show_bytes(est.bytes)} if the machine has that memory")])
        b = max(range(len(deck.body)), key=lambda k: est.bodies[deck.body[k].name])
        big = deck.body[b]
        raise DeckError([format_problem(
            f"body[{b}].dx",
            f"the model needs {est.summary()}, over the memory limit of "
            f"{show_bytes(limit)} ({source}); body '{big.name}' alone has about "
            f"{show_count(est.bodies[big.name])} particles at dx = {big.dx:g} m",
            f"make dx larger or the bodies smaller, or raise run.memory_limit above "
            f"{show_bytes(est.bytes)} if the machine has that memory")])
    return est


def _count_and_depth(depth: np.ndarray, tol: float) -> tuple[int, float]:
    """How many depths exceed ``tol`` and the largest."""
    bad = depth > tol
    return int(bad.sum()), float(depth[bad].max()) if bad.any() else 0.0


def placement_problems(deck, positions: list[np.ndarray]) -> list[str]:
    """Problems of the bodies' placement, from their lattices ``positions[b]``.

    A body of fewer than two particles (smaller than dx); a body whose
    particles lie inside another body's geometry (overlap); a body with
    particles behind a wall's plane (starting through the wall).
    """
    dim = deck.run.dimension
    problems = []
    for b, (body, x) in enumerate(zip(deck.body, positions)):
        if x.shape[0] < 2:
            size = shape_volume(body.geometry, dim) ** (1.0 / dim)
            problems.append(format_problem(
                f"body[{b}].dx",
                f"body '{body.name}' ({size:.3g} m across) is smaller than its "
                f"dx = {body.dx:g} m and gets {x.shape[0]} particle(s)",
                "make dx a small fraction of the body's size (e.g. a tenth), or the "
                "geometry larger"))
    for a, (body_a, xa) in enumerate(zip(deck.body, positions)):
        for b, body_b in enumerate(deck.body):
            if b <= a or not xa.size:
                continue
            tol = _TOLERANCE * min(body_a.dx, body_b.dx)
            n_ab, deep_ab = _count_and_depth(depth_inside(body_b.geometry, xa, dim), tol)
            n_ba, deep_ba = _count_and_depth(
                depth_inside(body_a.geometry, positions[b], dim), tol)
            if n_ab or n_ba:
                problems.append(format_problem(
                    f"body[{b}].geometry",
                    f"bodies '{body_a.name}' and '{body_b.name}' overlap: {n_ab} "
                    f"particles of '{body_a.name}' and {n_ba} of '{body_b.name}' lie "
                    f"inside the other's geometry (up to {max(deep_ab, deep_ba):.3g} m "
                    "deep)",
                    f"move '{body_b.name}' or '{body_a.name}' apart so that their "
                    "geometries at most touch"))
    for w, wall in enumerate(deck.wall):
        normal = np.asarray(wall.normal) / np.linalg.norm(wall.normal)
        for body, x in zip(deck.body, positions):
            behind = -((x - np.asarray(wall.point)) @ normal)
            count, deep = _count_and_depth(behind, _TOLERANCE * body.dx)
            if count:
                problems.append(format_problem(
                    f"wall[{w}].point",
                    f"body '{body.name}' starts through wall '{wall.name}': {count} of "
                    f"its {x.shape[0]} particles lie behind the wall's plane (up to "
                    f"{deep:.3g} m)",
                    f"move the body to the side wall '{wall.name}''s normal points "
                    "to, or move the wall's point (or flip its normal)"))
    return problems


def check_placement(deck, positions: list[np.ndarray]) -> None:
    """Raise :class:`DeckError` listing :func:`placement_problems`, if any."""
    problems = placement_problems(deck, positions)
    if problems:
        raise DeckError(problems)


def checked_lattices(deck) -> tuple[SizeEstimate, list[np.ndarray]]:
    """The size estimate and the bodies' lattices, after every check of this module.

    :func:`check_size` first (before any particle is made), then
    :func:`check_placement` on the lattices (n_b, 3) of the bodies.
    """
    from .geometry import lattice_from_shape

    estimate = check_size(deck)
    dim = deck.run.dimension
    lattices = [lattice_from_shape(b.geometry.model_dump(), b.dx, dim) for b in deck.body]
    check_placement(deck, lattices)
    return estimate, lattices
