"""The placement of a deck's bodies and meshes, on the built lattices:
:func:`placement_problems` finds bodies that overlap, bodies that start through
a wall or outside the [domain] box and bodies of a single particle;
:func:`check_meshes_in_domain` meshes outside the box or starting inside a
wall's contact thickness: decks that validate but would die mid-run or be
launched at their first step. Errors: :class:`~sphdyn.deck.DeckError`, one
``<path>: <what>. Fix: <what to write>`` line per problem.
"""

from __future__ import annotations

import numpy as np

from ..deck import DeckError
from ..deck.errors import format_problem
from ..geometry.lattice import ogive_profile, rotate_about
from .size import shape_volume

#: A particle of one body closer than this many of its spacings inside another
#: body's geometry (or behind a wall) counts as overlapping (round-off margin).
_TOLERANCE = 1e-6


def depth_inside(geometry, x: np.ndarray, dim: int) -> np.ndarray:
    """(n,) distance of points ``x`` (n, 3) inside a body geometry [m].

    Positive inside (the distance to the nearest face), negative or zero
    outside (only the sign and the depth inside are used).
    """
    g = geometry
    if g.shape == "points":  # no closed shape: nothing lies inside it
        return np.full(x.shape[0], -np.inf)
    if g.shape == "box":
        lo, hi = np.asarray(g.lo)[:dim], np.asarray(g.hi)[:dim]
        return np.min(np.minimum(x[:, :dim] - lo, hi - x[:, :dim]), axis=1)
    if g.shape == "ogive":  # distance to the axis' profile, the tip and the tail
        ax, sign = "xyz".index(g.nose[1]), (1.0 if g.nose[0] == "+" else -1.0)
        zeta = sign * (g.tip[ax] - x[:, ax])
        rel = x - np.asarray(g.tip)
        r = np.hypot(*(rel[:, a] for a in range(3) if a != ax))
        return np.minimum(np.minimum(ogive_profile(zeta, g.radius, g.crh) - r, zeta),
                          g.length - zeta)
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


def _count_and_depth(depth: np.ndarray, tol: float) -> tuple[int, float]:
    """How many depths exceed ``tol`` and the largest."""
    bad = depth > tol
    return int(bad.sum()), float(depth[bad].max()) if bad.any() else 0.0


def placement_problems(deck, positions: list[np.ndarray]) -> list[str]:
    """Problems of the bodies' placement, from their lattices ``positions[b]``.

    A body of fewer than two particles (smaller than dx); a body whose
    particles lie inside another body's geometry (overlap); a body with
    particles outside the [domain] box; a body with particles behind a
    wall's plane (starting through the wall).
    """
    dim = deck.run.dimension
    problems = []
    for b, (body, x) in enumerate(zip(deck.body, positions)):
        if x.shape[0] < 2 and body.geometry.shape != "points":
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
    for b, (body, x) in enumerate(zip(deck.body, positions)):
        line = outside_problem(deck, f"body[{b}].geometry", f"body '{body.name}'", x)
        if line:
            problems.append(line)
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


def domain_box(deck) -> tuple[np.ndarray, np.ndarray] | None:
    """The deck's [domain] box ``(lo, hi)`` (3,) each, -inf/inf for an absent
    corner and for the axes beyond the dimension; None without lo and hi."""
    d, dim = deck.domain, deck.run.dimension
    if d.lo is None and d.hi is None:
        return None
    lo = np.full(3, -np.inf) if d.lo is None else np.asarray(d.lo, float).copy()
    hi = np.full(3, np.inf) if d.hi is None else np.asarray(d.hi, float).copy()
    lo[dim:], hi[dim:] = -np.inf, np.inf
    return lo, hi


def _box_text(lo: np.ndarray, hi: np.ndarray, dim: int) -> str:
    return (f"[{', '.join(f'{v:g}' for v in lo[:dim])}] .. "
            f"[{', '.join(f'{v:g}' for v in hi[:dim])}] m")


def outside_problem(deck, where: str, what: str, x: np.ndarray,
                    items: str = "particles") -> str | None:
    """The problem line of items ``x`` (n, 3) [m] outside the [domain] box
    (outside as the run's guard sees it: below lo or above hi on an axis),
    or None. ``where`` is the deck path named, ``what`` the thing
    (``"body 'disc'"``), ``items`` what its points are."""
    box = domain_box(deck)
    if box is None or not x.size:
        return None
    lo, hi = box
    depth = np.max(np.maximum(lo - x, x - hi), axis=1)  # > 0 outside
    out = depth > 0.0
    if not out.any():
        return None
    dim = deck.run.dimension
    how = "wholly" if out.all() else "partly"
    return format_problem(
        where, f"{what} lies {how} outside the domain box {_box_text(lo, hi, dim)} "
        f"([domain] lo, hi): {int(out.sum())} of its {x.shape[0]} {items}, up to "
        f"{float(depth.max()):.3g} m outside, would stop the run at its first step",
        "move it into the box, or enlarge [domain] lo/hi (or remove them: the box then "
        "follows the model, widened by [domain] margin)")


def node_sizes(points: np.ndarray, cells: np.ndarray, kind: str, dim: int) -> np.ndarray:
    """(N,) [m] the size a wall sees of each node of a solid mesh
    (:func:`~sphdyn.parts.fem.solid_part.node_contact_items`: the mean of
    its elements' sizes ``V_e^(1/d)``), with ``V_e`` the mean corner
    ``det J`` times ``2^d`` (exact for parallelepipeds); 0 for a node of no
    element."""
    from ..geometry.mesh import element_jacobians
    from ..parts.fem.solid_part import node_contact_items

    vol = np.abs(element_jacobians(points, cells, kind).mean(axis=1)) * 2.0 ** dim
    zero = np.zeros(vol.shape[0])
    vol0, _, _ = node_contact_items(cells, vol, zero, zero, points.shape[0], dim)
    return vol0 ** (1.0 / dim)


def mesh_wall_problems(deck, meshes) -> list[str]:
    """Solid meshes that start inside a wall's contact: nodes behind the
    wall's plane or closer to it than its contact thickness
    ``thickness_factor`` times the node's size (:func:`node_sizes`). The
    contact would push them out in the first steps with the whole depth's
    spring (issue 57: a mesh placed on a wall was launched)."""
    problems = []
    dim = deck.run.dimension
    for w, wall in enumerate(deck.wall):
        normal = np.asarray(wall.normal, float) / np.linalg.norm(wall.normal)
        for mm in meshes:
            if mm.element != "solid" or not mm.points.shape[0]:
                continue
            gap = (mm.points - np.asarray(wall.point, float)) @ normal
            reach = wall.thickness_factor * node_sizes(mm.points, mm.cells, mm.kind, dim)
            depth = reach - gap
            size = float(reach.max()) / max(wall.thickness_factor, 1e-300)
            count, deep = _count_and_depth(depth, _TOLERANCE * max(size, 1e-300))
            if not count:
                continue
            behind = int((gap < -_TOLERANCE * size).sum())
            where = (f"{behind} lie behind the wall's plane" if behind else
                     "none behind the plane, but within its contact thickness "
                     f"({wall.thickness_factor:g} x the elements' size)")
            problems.append(format_problem(
                f"wall[{w}].thickness_factor" if not behind else f"wall[{w}].point",
                f"mesh '{mm.name}' starts inside wall '{wall.name}''s contact: {count} "
                f"of its {mm.points.shape[0]} nodes are closer to the plane than the "
                f"contact thickness ({where}; up to {deep:.3g} m deep), and would be "
                "pushed out at once",
                f"move mesh '{mm.name}' at least {deep:.3g} m further along the "
                f"wall's normal, or give wall '{wall.name}' thickness_factor = 0 "
                "(contact at the plane: a mesh resting on a support)"))
    return problems


def check_meshes_in_domain(deck, meshes) -> None:
    """DeckError for meshes (:class:`~sphdyn.build.mesh_model.MeshModel`) whose
    nodes or converted particles lie outside the [domain] box, or that start
    inside a wall's contact (:func:`mesh_wall_problems`)."""
    problems = []
    for mm in meshes:
        x = mm.points if mm.converted is None else np.concatenate(
            [mm.points, mm.converted.x])
        line = outside_problem(deck, f"mesh[{mm.index}] '{mm.name}'", f"mesh '{mm.name}'", x,
                               "nodes" if mm.converted is None else "nodes and particles")
        if line:
            problems.append(line)
    problems += mesh_wall_problems(deck, meshes)
    if problems:
        raise DeckError(problems)


def check_placement(deck, positions: list[np.ndarray]) -> None:
    """Raise :class:`DeckError` listing :func:`placement_problems`, if any."""
    problems = placement_problems(deck, positions)
    if problems:
        raise DeckError(problems)
