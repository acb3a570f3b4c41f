"""The size of a deck's model before it is built: :func:`estimate_size` counts
the particles of every body from the closed-form volume of its geometry over
``dx**dim`` (and those a mesh's elements make), the elements of generated
meshes and the neighbour-list pairs from the kernel support, before a single
particle is made; :func:`check_size` refuses a support holding no neighbour or
more than :data:`MAX_NEIGHBOURS`, and a model over ``run.memory_limit``
(default: half of this machine's memory), naming the key behind it, so a
mistyped ``dx``, ``divisions`` or ``h_factor`` cannot hang ``sphdyn check`` and
end in a MemoryError. Nothing here allocates more than the limit to find that
out. Errors: :class:`~sphdyn.deck.DeckError`, one ``<path>: <what>. Fix: <what
to write>`` line per problem.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np

from ..deck import DeckError
from ..deck.errors import format_problem
from ..geometry.lattice import ogive_volume, polygon_area, read_points

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


def _power(x: float, n: int) -> float:
    """``x**n`` that overflows to inf instead of raising (float ``**`` raises)."""
    return math.prod([float(x)] * n)


def ball_volume(radius: float, dim: int) -> float:
    """Length of a segment (1D), area of a disc (2D) or volume of a ball (3D)
    of ``radius``."""
    if dim == 1:
        return 2.0 * radius
    return math.pi * _power(radius, 2) if dim == 2 else 4.0 / 3.0 * math.pi * _power(radius, 3)


#: Largest radius [lattice spacings] whose points :func:`lattice_neighbours`
#: counts one by one: (2 * 40 + 1)^3 = 531,441 points, 4 MB; beyond it the
#: ball's volume (the count's relative error falls as 1 / radius).
ENUMERATED_RADIUS = 40.0


def lattice_neighbours(radius: float, dim: int) -> float:
    """Points of the unit cubic (square, 1D) lattice within ``radius`` of a
    lattice point, itself not counted: ``#{p in Z^dim, 0 < |p| < radius}``
    (strictly inside, as the neighbour lists exclude ties). The list of an
    interior particle of a regular lattice of spacing dx at the build, for
    a Verlet radius of ``radius`` dx; its ball's volume differs by the
    points near the sphere (80 against 77 for the disc's 2.64 dx).

    Counted point by point up to :data:`ENUMERATED_RADIUS`; beyond it (an
    absurd smoothing length) the ball's volume minus one, so that the count
    allocates nothing that grows with ``radius`` (inf when it overflows).
    """
    if not radius <= ENUMERATED_RADIUS:  # nan and inf too
        n = ball_volume(radius, dim) - 1.0
        return n if math.isfinite(n) else math.inf
    k = int(math.ceil(radius))
    axis = np.arange(-k, k + 1, dtype=float) ** 2
    r2 = axis
    for _ in range(dim - 1):
        r2 = np.add.outer(r2, axis)
    return int(np.count_nonzero(r2 < radius * radius)) - 1


def support_radius(sph) -> float:
    """The support radius in units of h for the deck's [sph] section ``sph``
    (:func:`sphdyn.kernels.radius_factor`)."""
    from ..kernels import kernel_id, radius_factor

    return radius_factor(kernel_id(sph.kernel), sph.support_scale)


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
    if g.shape == "ogive":
        return ogive_volume(g.radius, g.length, g.crh)
    outer = g.radius if g.shape == "cylinder" else g.outer_radius
    inner = 0.0 if g.shape == "cylinder" else g.inner_radius
    area = ball_volume(outer, 2) - ball_volume(inner, 2)
    return area if dim == 2 else area * g.length


def body_count(body, dim: int) -> float:
    """Particles of a ``[[body]]``: its geometry's volume over ``dx**dim``, or
    the rows of a ``points`` file."""
    g = body.geometry
    if g.shape == "points":
        return float(read_points(g.file, dim, g.length_unit).shape[0])
    return lattice_count(shape_volume(g, dim), body.dx, dim)


def lattice_count(volume: float, dx: float, dim: int) -> float:
    """Particles of spacing ``dx`` in ``volume``; inf when it overflows."""
    cell = _power(dx, dim)
    n = volume / cell if cell > 0 else math.inf
    return n if math.isfinite(n) else math.inf


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

    #: body name -> estimated particle count (the particles of a
    #: [mesh.convert] under the mesh's name)
    bodies: dict
    #: particles at the start, and those eroding elements may add later
    particles: float
    pairs_per_particle: float
    bytes_particles: float
    bytes_neighbours: float
    #: mesh name -> element count of the generated meshes (files: not counted
    #: before the build)
    meshes: dict = None
    #: debris body name -> the most particles its eroding mesh can make
    debris: dict = None
    #: deck path -> bytes of other arrays made from the deck's numbers
    #: (a photo's pixels)
    other: dict = None

    @property
    def bytes_meshes(self) -> float:
        return ELEMENT_BYTES * float(sum((self.meshes or {}).values()))

    @property
    def bytes_other(self) -> float:
        return float(sum((self.other or {}).values()))

    @property
    def bytes(self) -> float:
        """Estimated memory of the model [bytes]."""
        return (self.bytes_particles + self.bytes_neighbours + self.bytes_meshes
                + self.bytes_other)

    def summary(self) -> str:
        """One line: particles, neighbours and memory."""
        meshes = (f" + {show_count(sum(self.meshes.values()))} elements "
                  f"{show_bytes(self.bytes_meshes)}" if self.meshes else "")
        other = (f" + {', '.join(self.other)} {show_bytes(self.bytes_other)}"
                 if self.other else "")
        later = sum((self.debris or {}).values())
        start = self.particles - later
        born = f" (+ up to {show_count(later)} from eroding elements)" if later else ""
        return (f"about {show_count(start)} particles{born}, "
                f"{show_count(self.pairs_per_particle)} neighbours each, "
                f"{show_bytes(self.bytes)} (particles "
                f"{show_bytes(self.bytes_particles)} + neighbour lists "
                f"{show_bytes(self.bytes_neighbours)}{meshes}{other})")


def history_models(deck) -> list:
    """The material models whose history columns the model's items share: the
    deck's materials in order, and the uniaxial bar when a sublayer's
    particles carry the bar axially (``stiffness = "axial"``)."""
    from ..materials import UNIAXIAL, get_model

    models = [get_model(m.model) for m in deck.material]
    if any(m.sublayer is not None and m.sublayer.stiffness == "axial" for m in deck.mesh):
        models.append(UNIAXIAL)
    return models


def history_width(deck) -> int:
    """Columns of the particles' one history array: :func:`history_models`
    laid side by side as the parts lay them
    (:func:`~sphdyn.materials.history_layout`; every material counted, an
    upper bound where a mesh has its own), at least one."""
    from ..materials import history_layout

    models = history_models(deck)
    try:
        width = len(history_layout(models)[0])
    except ValueError:  # models that cannot share one array: the build names them
        width = sum(len(m.history_names) for m in models)
    return max(width, 1)


#: Bytes per pixel of a section photo while it is read and segmented (grey
#: levels, mask, labels and distance maps in float64 and int64), rounded up.
PHOTO_PIXEL_BYTES = 48


def verlet_radius(sph) -> float:
    """The Verlet radius of the deck's [sph] section ``sph`` in particle
    spacings: ``q_max * support_scale * h_factor * (1 + skin_factor)``."""
    return support_radius(sph) * sph.h_factor * (1.0 + sph.neighbours.skin_factor)


def estimate_size(deck, model=None) -> SizeEstimate:
    """Estimate the model of a validated deck; without ``model``, before
    building it, and allocating nothing that grows with the deck's numbers
    beyond its memory limit.

    Particles per body: the closed-form volume of its geometry over
    ``dx**dim``; the particles of a generated mesh's [mesh.convert] (one per
    converted element, and the hybrid layer's points) counted on the
    generated mesh when its elements fit in the memory limit; the debris of
    eroding elements at most ``particles_per_element`` per element. With a
    built ``model`` (:func:`sphdyn.build.model.build_model`) the counts are its
    own. Neighbours per particle: the lattice points in the Verlet radius
    (:func:`verlet_radius` dx, :func:`lattice_neighbours`), at most the
    other particles. Memory: :data:`PARTICLE_BYTES` plus 8 bytes per history
    variable per particle, :data:`PAIR_BYTES` per neighbour pair,
    :data:`ELEMENT_BYTES` per element, :data:`PHOTO_PIXEL_BYTES` per pixel
    of a section photo.
    """
    dim = deck.run.dimension
    if model is not None:
        counts = np.bincount(model.particles.body, minlength=len(model.body_names))
        bodies = {name: float(c) for name, c in zip(model.body_names, counts)}
        meshes = {mm.name: float(mm.cells.shape[0]) for mm in model.meshes}
    else:
        bodies = {b.name: body_count(b, dim) for b in deck.body}
        meshes = {m.name: _element_count(m, dim) for m in deck.mesh if m.file is None}
        if ELEMENT_BYTES * sum(meshes.values()) <= memory_limit(deck)[0]:
            bodies.update(_converted_counts(deck))
    debris = {f"{m.name}_debris": meshes.get(m.name, 0.0) * m.erosion.particles_per_element
              for m in deck.mesh if m.erosion is not None and m.erosion.to == "particles"}
    for name in debris:
        bodies.pop(name, None)
    n = float(sum(bodies.values())) + float(sum(debris.values()))
    pairs = min(lattice_neighbours(verlet_radius(deck.sph), dim), max(n - 1.0, 0.0))
    per_particle = PARTICLE_BYTES + 8 * history_width(deck)
    return SizeEstimate(bodies, n, pairs, n * per_particle,
                        n * pairs * PAIR_BYTES if n and pairs else 0.0, meshes, debris,
                        _photo_bytes(deck))


def _converted_counts(deck) -> dict:
    """mesh name -> particles of the [mesh.convert] of each generated mesh."""
    from ..build.mesh_model import converted_count

    dim = deck.run.dimension
    return {m.name: float(converted_count(m, k, dim)) for k, m in enumerate(deck.mesh)
            if m.convert is not None and m.file is None}


def _photo_bytes(deck) -> dict:
    """``body[b].mesostructure.photo`` -> bytes of reading and segmenting it
    (its pixel count from the file's header, nothing decoded)."""
    out = {}
    for b, body in enumerate(deck.body):
        ms = body.mesostructure
        if ms is None or ms.photo is None:
            continue
        try:
            from PIL import Image

            with Image.open(ms.photo) as im:
                w, h = im.size
        except Exception:  # noqa: BLE001 -- unreadable: the build names the file
            continue
        out[f"body[{b}].mesostructure.photo"] = PHOTO_PIXEL_BYTES * float(w) * float(h)
    return out


def _element_count(mesh, dim: int) -> float:
    """Elements of a generated [[mesh]] (the prism's by its volume); inf
    when the count overflows."""
    if mesh.block is not None:
        return math.prod(float(d) for d in mesh.block.divisions)
    if mesh.prism is not None:
        return lattice_count(prism_volume(mesh.prism, dim), mesh.prism.element_size, dim)
    line = mesh.line
    if line.divisions is not None:
        per = float(line.divisions) * len(line.segments_ends)
    else:
        per = sum(max(1.0, math.dist(p, q) / line.element_length)
                  for p, q in line.segments_ends)
    n = float(line.repeat) * per
    return n if math.isfinite(n) else math.inf


def _mesh_source(mesh) -> str:
    """The deck key that sets a generated mesh's size."""
    if mesh.prism is not None:
        return "prism.element_size"
    if mesh.file is not None:
        return "file"
    if mesh.line is not None and mesh.line.divisions is None:
        return "line.element_length"
    return f"{'block' if mesh.block is not None else 'line'}.divisions"


#: Neighbours per particle above which an estimate over the memory limit is
#: blamed on the smoothing length rather than on the particle count: a list
#: of a few hundred is the most any deck of the thesis uses (the 3D Verlet
#: ball of 2.64 dx holds 80).
TOO_MANY_NEIGHBOURS = 1000.0
#: Neighbours per particle of a regular lattice's interior (the Verlet ball,
#: :func:`lattice_neighbours`) above which a deck is refused whatever its
#: memory: 125 times the 3D default's 80 (a support radius of about 13 dx in
#: 3D, 56 dx in 2D, 5000 dx in 1D), which smooths a body over most of its
#: size and makes each step cost as much as 125 ordinary ones. No deck of
#: the thesis comes near it.
MAX_NEIGHBOURS = 1e4


def has_particles(deck) -> bool:
    """Whether the model has SPH particles now or later: bodies, or meshes
    converted, with a sublayer or eroding into particles."""
    return bool(deck.body) or any(
        m.convert is not None or m.sublayer is not None
        or (m.erosion is not None and m.erosion.to == "particles") for m in deck.mesh)


def _radius_field(sph, smallest: bool = False) -> tuple[str, float]:
    """The [sph] key that stretches the Verlet radius most over its
    default (``smallest``: shrinks it most), and its value."""
    from ..deck.sections.sph import Sph

    default = Sph()
    ratios = {"sph.h_factor": sph.h_factor / default.h_factor,
              "sph.support_scale": sph.support_scale / default.support_scale,
              "sph.neighbours.skin_factor": (1.0 + sph.neighbours.skin_factor)
              / (1.0 + default.neighbours.skin_factor)}
    key = (min if smallest else max)(ratios, key=lambda k: ratios[k])
    return key, {"sph.h_factor": sph.h_factor, "sph.support_scale": sph.support_scale,
                 "sph.neighbours.skin_factor": sph.neighbours.skin_factor}[key]


def check_size(deck) -> SizeEstimate:
    """Refuse a deck whose model would exceed its memory limit (naming the
    deck key that makes it large); return the estimate."""
    dim = deck.run.dimension
    radius = verlet_radius(deck.sph)
    per = lattice_neighbours(radius, dim)
    if has_particles(deck) and per == 0:
        key, value = _radius_field(deck.sph, smallest=True)
        raise DeckError([format_problem(
            key, f"{key} = {value:g} gives a Verlet radius of {radius:.3g} particle "
            "spacings: a particle has no neighbour on its lattice, so the particles "
            "would not interact", "use h_factor 1.2-2 (h = h_factor dx) and "
            "support_scale about 1 (a support of 2-3 spacings)")])
    if has_particles(deck) and not per <= MAX_NEIGHBOURS:
        key, value = _radius_field(deck.sph)
        raise DeckError([format_problem(
            key, f"{key} = {value:g} gives a Verlet radius of {radius:.3g} particle "
            f"spacings, about {show_count(per)} neighbours per particle in {dim}D (more "
            f"than {MAX_NEIGHBOURS:,.0f}: the kernel would smooth over the whole body)",
            "use h_factor 1.2-2 (h = h_factor dx), support_scale about 1 and "
            "skin_factor below 1 (a few dozen neighbours each)")])
    est = estimate_size(deck)
    _refuse_over_limit(deck, est)
    return est


def _refuse_over_limit(deck, est: SizeEstimate) -> None:
    """DeckError naming the key behind the largest share of an estimate over
    the memory limit: a body's dx, a mesh's divisions, the smoothing length
    (:data:`TOO_MANY_NEIGHBOURS`) or a photo."""
    limit, source = memory_limit(deck)
    if not est.bytes <= limit:  # nan (inf * 0) counts as too large
        shares = {"particles": est.bytes_particles, "neighbours": est.bytes_neighbours,
                  "meshes": est.bytes_meshes, "other": est.bytes_other}
        top = max(shares, key=lambda k: shares[k] if not math.isnan(shares[k]) else math.inf)
        if top == "neighbours" and not est.pairs_per_particle <= TOO_MANY_NEIGHBOURS:
            key, value = _radius_field(deck.sph)
            raise DeckError([format_problem(
                key, f"{key} = {value:g} gives each particle about "
                f"{show_count(est.pairs_per_particle)} neighbours (Verlet radius "
                f"{verlet_radius(deck.sph):.3g} dx): the model needs {est.summary()}, "
                f"over the memory limit of {show_bytes(limit)} ({source})",
                "use h_factor 1.2-2 (h = h_factor dx), support_scale about 1 and "
                "skin_factor below 1 (a few dozen neighbours each)")])
        if top == "other":
            key = max(est.other, key=lambda k: est.other[k])
            raise DeckError([format_problem(
                key, f"the photo needs {show_bytes(est.other[key])} to read and segment: "
                f"the model needs {est.summary()}, over the memory limit of "
                f"{show_bytes(limit)} ({source})",
                "scale the photo down (and its pixel_size up by the same factor), or "
                "raise run.memory_limit")])
        if est.meshes and (top == "meshes" or not deck.body):
            k = max(range(len(deck.mesh)), key=lambda j: est.meshes.get(deck.mesh[j].name, 0))
            m = deck.mesh[k]
            raise DeckError([format_problem(
                f"mesh[{k}].{_mesh_source(m)}",
                f"the model needs {est.summary()}, over the memory limit of "
                f"{show_bytes(limit)} ({source}); mesh '{m.name}' alone has "
                f"{show_count(est.meshes[m.name])} elements",
                "use fewer divisions, or raise run.memory_limit above "
                f"{show_bytes(est.bytes)} if the machine has that memory")])
        sources = {**est.bodies, **(est.debris or {})}
        name = max(sources, key=lambda k: sources[k]) if sources else None
        names = [b.name for b in deck.body]
        if name in names or not deck.mesh:
            b = names.index(name) if name in names else 0
            big = deck.body[b]
            raise DeckError([format_problem(
                f"body[{b}].dx",
                f"the model needs {est.summary()}, over the memory limit of "
                f"{show_bytes(limit)} ({source}); body '{big.name}' alone has about "
                f"{show_count(est.bodies.get(big.name, 0.0))} particles at dx = "
                f"{big.dx:g} m",
                f"make dx larger or the bodies smaller, or raise run.memory_limit above "
                f"{show_bytes(est.bytes)} if the machine has that memory")])
        k = next((j for j, m in enumerate(deck.mesh)
                  if name in (m.name, f"{m.name}_debris", f"{m.name}_sublayer")), 0)
        m = deck.mesh[k]
        raise DeckError([format_problem(
            f"mesh[{k}].{_mesh_source(m)}",
            f"the model needs {est.summary()}, over the memory limit of "
            f"{show_bytes(limit)} ({source}); mesh '{m.name}' makes about "
            f"{show_count(sources.get(name, 0.0))} particles",
            "use fewer or larger elements, or raise run.memory_limit above "
            f"{show_bytes(est.bytes)} if the machine has that memory")])
