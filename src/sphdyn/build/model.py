"""Deck -> model: particles of every body, material groups, sets, walls, guard box.

With :mod:`sphdyn.build` (parts, interactions, stepper) this is the only
place that reads the deck and turns deck objects into arrays; the parts and
interactions below it see settings, arrays and scalars only.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ..geometry import select
from ..geometry.spacing import adapted_smoothing_lengths
from ..heterogeneity.cracks import crack_mask
from ..heterogeneity.mass import body_rng, mass_field
from ..heterogeneity.mesostructure import AGGREGATE, ITZ, MORTAR, generate_phases
from ..heterogeneity.photo import photo_targets
from ..heterogeneity.variation import factor_of, quantise, standard_normal_field, variation_rng
from .initial import initial_fields
from ..interactions.wall import STIFFNESS, WallSpec
from ..deck import DeckError
from ..deck.errors import format_problem
from .detonation import light_explosives
from ..checks.preflight import checked_lattices
from ..checks.placement import check_meshes_in_domain
from ..checks.size import history_models, support_radius
from ..materials import MaterialGroup, available_models, get_model, history_layout
from ..materials.uniaxial import UNIAXIAL, uniaxial_params
from .mesh_model import MeshModel, build_meshes, mesh_node_set, pressure_faces, section_of
from ..watchers.probes import NODE_FIELDS, Probe, node_probe_field, quantity
from ..state import Particles


@dataclass
class Model:
    particles: Particles
    groups: list[MaterialGroup]
    walls: list[WallSpec]
    sets: dict[str, np.ndarray]
    body_names: list[str]
    domain_lo: np.ndarray
    domain_hi: np.ndarray
    probes: list[Probe] = field(default_factory=list)
    #: (N,) int8 mesostructure phase (0 mortar, 1 aggregate, 2 ITZ; -1 for
    #: bodies without [body.mesostructure])
    phase: np.ndarray = field(repr=False, default=None)
    #: body name -> PhotoTargets of bodies whose mesostructure comes from a photo
    photo_targets: dict = field(default_factory=dict)
    #: (N,) factor of the [material.variation] parameter (1 without variation)
    variation: np.ndarray = field(repr=False, default=None)
    #: body name -> MassDraw of bodies with a random mass field ([body.mass])
    mass_draws: dict = field(default_factory=dict)
    #: the [[mesh]] parts (read, checked, converted)
    meshes: list[MeshModel] = field(default_factory=list)
    #: set name -> (mesh name, (n,) node indices) of the [[set]]s with ``mesh``
    mesh_sets: dict = field(default_factory=dict)


@dataclass(frozen=True)
class MassDraw:
    """The random mass field a body was given (paper sec. 4.1), as drawn.

    ``rows`` (n,) particle indices of the body; ``solid`` (n,) bool (False
    for initial-crack particles); ``factors`` (n_solid,) the drawn factors
    :math:`f_j` of the solid particles; ``scale`` the rescaling factor
    :math:`s = N_s / \\sum f` of :func:`sphdyn.heterogeneity.mass.mass_field`;
    ``m0`` the homogeneous particle mass of the body's material,
    :math:`\\rho\\,\\Delta x^d` [kg] (kg/m in 2D). A solid particle's mass is
    ``m0 * scale * factor`` (times rho_phase / rho with a mesostructure).
    """

    rows: np.ndarray
    solid: np.ndarray
    factors: np.ndarray
    scale: float
    m0: float
    spec: dict


def wall_specs(deck) -> list[WallSpec]:
    """The ``[[wall]]`` tables as :class:`~sphdyn.interactions.wall.WallSpec`."""
    return [WallSpec(
        name=w.name, point=np.asarray(w.point, float),
        normal=np.asarray(w.normal, float) / np.linalg.norm(w.normal),
        method=STIFFNESS[w.stiffness], alpha=w.alpha, friction=w.friction,
        thickness_factor=w.thickness_factor, bulk_modulus=w.bulk_modulus,
        velocity=np.asarray(w.velocity, float), ramp_time=w.ramp_time)
        for w in deck.wall]


def _phase_materials(deck, b: int, body, x: np.ndarray, dim: int, mat_index: dict,
                     photos: dict) -> tuple[np.ndarray, np.ndarray | None]:
    """Material index (N,) and mesostructure phase (N,) int8 of a body's particles.

    Without ``[body.mesostructure]`` every particle has the body's material
    and the phase is None. Phases from
    :func:`sphdyn.heterogeneity.mesostructure.generate_phases`, seeded by
    ``run.seed`` and the body index; with ``photo`` the fraction and D_max
    come from :func:`sphdyn.heterogeneity.photo.photo_targets`, which are
    also stored in ``photos[body.name]`` (for the report).
    """
    ms = body.mesostructure
    if ms is None:
        return np.full(x.shape[0], mat_index[body.material], np.int32), None
    seed = int(np.random.SeedSequence([int(deck.run.seed), b, 0x6D65736F]).generate_state(1)[0])
    fraction, dmax = ms.aggregate_fraction, ms.max_aggregate_size
    if ms.photo is not None:
        t = photo_targets(ms.photo, pixel_size=ms.pixel_size, dx=body.dx, dim=dim,
                          aggregate=ms.photo_aggregate, itz_thickness=ms.itz_thickness,
                          aggregate_shape=ms.shape, seed=seed)
        fraction, dmax = t.aggregate_fraction, t.max_aggregate_size
        photos[body.name] = t
    phases = generate_phases(
        x, body.dx, aggregate_fraction=fraction,
        max_aggregate_size=dmax, itz_thickness=ms.itz_thickness,
        aggregate_shape=ms.shape, octaves=ms.octaves, persistence=ms.persistence,
        lacunarity=ms.lacunarity, seed=seed, dim=dim)
    mortar = ms.mortar or body.material
    table = np.zeros(3, np.int32)  # phase -> material index
    table[MORTAR] = mat_index[mortar]
    table[AGGREGATE] = mat_index[ms.aggregate or body.material]
    table[ITZ] = mat_index[ms.itz or mortar]
    return table[phases], phases


def _material_groups(deck, particles: Particles, models: dict, params: dict,
                     first: dict) -> tuple[list[MaterialGroup], np.ndarray]:
    """Material groups of the particles and the (N,) variation factor.

    ``first`` gives each model's first history column
    (:func:`~sphdyn.materials.history_layout`).

    One group per material, or, with ``[material.variation]``, one per
    class of the varied parameter: the parameter times the class factor
    and the material refitted from it (``model.pack``), see
    :mod:`sphdyn.heterogeneity.variation`. Factors are drawn from
    ``variation_rng(run.seed, material index)``.
    """
    factor = np.ones(particles.n)
    groups = []
    for k, m in enumerate(deck.material):
        idx = np.flatnonzero(particles.mat == k).astype(np.int64)
        if not idx.size:
            continue
        column = first[models[m.name].history_names]
        var = m.variation
        if var is None or var.cov == 0.0:
            groups.append(MaterialGroup(m.name, models[m.name], params[m.name], idx, k,
                                        column))
            continue
        rng = variation_rng(deck.run.seed, k)
        if var.scope == "sample":
            cls, mids = np.zeros(idx.size, np.int64), rng.standard_normal(1)
        else:
            z = standard_normal_field(particles.x[idx], var.correlation_length, rng)
            cls, mids = quantise(z, var.classes)
        f = factor_of(mids, var.cov, var.distribution)
        base = m.values()
        for c in np.unique(cls):
            sub = idx[cls == c]
            values = {**base, var.parameter: base[var.parameter] * f[c]}
            groups.append(MaterialGroup(f"{m.name}#{c}", models[m.name],
                                        models[m.name].pack(values), sub, k, column))
            factor[sub] = f[c]
    return groups, factor


def _apply_initial(deck, body, p: Particles, models: dict, mat_ids, dim: int) -> None:
    """Set the ``[body.initial]`` velocity and stress of one body's particles."""
    where = f"body {body.name!r} [body.initial]"
    vel, sig = initial_fields(body.initial, p.x, dim, body.dx, where)
    if vel is not None:
        if any(v != 0.0 for v in body.velocity):
            raise ValueError(f"{where}: velocity is given twice (the body's velocity "
                             "and [body.initial]); keep one")
        p.v[:] = vel
    if sig is not None:
        if (body.formulation or deck.sph.formulation) == "total_lagrangian":
            raise ValueError(f"{where}: a total-Lagrangian body computes its stress "
                             "from the deformation since t = 0, so it cannot start "
                             "stressed; use formulation = \"updated_lagrangian\"")
        names = {deck.material[k].name for k in np.unique(mat_ids)}
        refused = sorted(n for n in names if not models[n].initial_stress)
        if refused:
            raise ValueError(f"{where}: material {', '.join(refused)} (model "
                             f"{models[refused[0]].name}) cannot start from a given "
                             "stress (its state is tied to the loading history); "
                             "initial stress works with elastic and j2 materials")
        p.sig[:] = sig


def build_model(deck) -> Model:
    """Create the particle model described by a validated deck.

    Raises :class:`~sphdyn.deck.DeckError` before making any particle if the
    model would exceed ``run.memory_limit``, and before anything else if
    bodies overlap, start through a wall or outside the [domain] box or are
    smaller than their dx, and before making parts if a mesh lies outside
    the box (:mod:`sphdyn.checks.preflight`).
    """
    dim = deck.run.dimension
    _, lattices = checked_lattices(deck)
    meshes = build_meshes(deck)
    check_meshes_in_domain(deck, meshes)
    mats = {m.name: m for m in deck.material}
    mat_index = {m.name: k for k, m in enumerate(deck.material)}
    models = {m.name: get_model(m.model) for m in deck.material}
    params = {name: models[name].pack(m.values()) for name, m in mats.items()}
    hist_names, first = history_layout(history_models(deck))
    n_hist = len(hist_names)

    density_of = np.array([m.density for m in deck.material])
    parts, phase_parts = [], []
    photos, draws, start = {}, {}, 0
    for b, body in enumerate(deck.body):
        x = lattices[b]
        n = x.shape[0]
        mat = mats[body.material]
        mat_ids, ph = _phase_materials(deck, b, body, x, dim, mat_index, photos)
        phase_parts.append(np.full(n, -1, np.int8) if ph is None else ph)
        vol = body.dx ** dim
        rho0 = density_of[mat_ids]
        # numerical heterogeneity (paper sec. 4, 5.2): crack particles get zero
        # mass, the others a random mass field of the homogeneous total
        cracks = [c.model_dump() for c in body.crack]
        solid = ~crack_mask(x, cracks, body.dx, body.name)
        spec = None if body.mass is None else body.mass.model_dump()
        if ph is not None:  # phases of different densities: factors times rho_i dx^d
            factors, scale = mass_field(1.0, spec, solid, body_rng(deck.run.seed, b))
            m = factors * rho0 * vol
        else:
            m, scale = mass_field(mat.density * vol, spec, solid,
                                  body_rng(deck.run.seed, b))
            factors = m / (mat.density * vol)
        if spec is not None:
            draws[body.name] = MassDraw(np.arange(start, start + n), solid,
                                        factors[solid] / scale, scale,
                                        mat.density * vol, spec)
        start += n
        p = Particles.allocate(n, dim, n_hist)
        p.place(slice(None), x=x, v=np.asarray(body.velocity, dtype=float), m=m,
                vol0=vol, rho0=rho0, h=deck.sph.h_factor * body.dx, mat=mat_ids, body=b)
        if body.initial is not None:
            _apply_initial(deck, body, p, models, mat_ids, dim)
        parts.append(p)
    body_names = particle_body_names(deck)
    for mm in meshes:
        if mm.converted is not None:
            parts.append(_converted_particles(deck, mm, body_names.index(mm.name),
                                              density_of, n_hist))
            phase_parts.append(np.full(parts[-1].n, -1, np.int8))
    n_bodies = sum(p.n for p in parts)  # the particles of bodies and converted meshes
    for mm in sublayer_meshes(meshes):  # bars' nodes as particles (thesis 6.1)
        parts.append(_sublayer_particles(deck, mm, body_names.index(f"{mm.name}_sublayer"),
                                         n_hist))
        phase_parts.append(np.full(parts[-1].n, -1, np.int8))
    # the debris bodies (eroded elements) start empty
    particles = (Particles.concatenate(parts) if parts
                 else Particles.allocate(0, dim, n_hist))
    particles.hist_names = hist_names  # the joined parts' columns (history_layout)
    hs = deck.sph.smoothing_length
    if hs.initial == "adaptive" and n_bodies > dim:
        # support sized by the local spacing (geometry.spacing); a bar's
        # sublayer particles keep theirs (element length)
        particles.h[:n_bodies] = adapted_smoothing_lengths(
            particles.x[:n_bodies], particles.h[:n_bodies], deck.sph.h_factor, dim,
            hs.min_factor, hs.max_factor, support_radius(deck.sph))
        particles.h0[:n_bodies] = particles.h[:n_bodies]

    groups, factor = _material_groups(deck, particles, models, params, first)
    _seat_sublayers(deck, meshes, particles, body_names)
    groups = _sublayer_groups(deck, meshes, particles, body_names, groups, models, first)
    have = {g.material for g in groups}
    for k in sorted({int(k) for mm in debris_meshes(meshes) for k in np.unique(mm.mat)}
                    - have):  # an empty group for the debris of each eroding material
        m = deck.material[k]
        groups.append(MaterialGroup(m.name, models[m.name], params[m.name],
                                    np.zeros(0, np.int64), k,
                                    first[models[m.name].history_names]))

    for g in groups:
        if not g.idx.size:  # a debris group, filled during the run
            continue
        # one density per material
        particles.c[g.idx] = g.model.wave_speed(g.params, particles.rho0[g.idx[0]])
        h0 = g.model.initial_history(g.params)
        if len(h0):
            particles.hist[np.ix_(g.idx, g.column + np.arange(len(h0)))] = h0
        if g.model.initial_state is not None:  # a gas at its ambient pressure
            e0, p0 = g.model.initial_state(g.params)
            particles.e[g.idx] = e0
            particles.sig[g.idx] = -p0 * np.eye(3)
    light_explosives(deck, particles, groups)

    body_index = {name: k for k, name in enumerate(body_names)}
    sets: dict[str, np.ndarray] = {}
    mesh_sets: dict[str, tuple[str, np.ndarray]] = {}
    for k, s in enumerate(deck.set):
        if s.mesh is not None:
            mm, idx = mesh_node_set(meshes, s, k, dim)
            mesh_sets[s.name] = (mm.name, idx)
            continue
        cand = np.arange(particles.n) if s.body is None else np.flatnonzero(
            particles.body == body_index[s.body])
        region = None if s.region is None else s.region.model_dump()
        sel = select(particles.x[cand], region, dim)
        sets[s.name] = cand[sel].astype(np.int64)
        if not sets[s.name].size:
            where = f"body '{s.body}'" if s.body is not None else "the model"
            raise DeckError([format_problem(
                f"set[{k}] '{s.name}'", f"the set holds no particle of {where}",
                "enlarge the region (particles are selected by their initial "
                "centres, which lie half a spacing inside a body's faces; a box "
                "must contain them, edges included), or check the body")])
    for k, load in enumerate(deck.load):  # refused here, so that check refuses them
        if load.pressure is not None:
            pressure_faces(meshes, mesh_sets, load.set, f"load[{k}].set")
    for k, bnd in enumerate(deck.boundary):
        if bnd.type == "non_reflecting":
            pressure_faces(meshes, mesh_sets, bnd.set, f"boundary[{k}].set",
                           "a non-reflecting boundary")
    probes = []
    for k, pr in enumerate(deck.probe):
        if pr.set in mesh_sets:
            mesh, idx = mesh_sets[pr.set]
            # the default list (compared by value: a resolved deck writes it
            # out) keeps what mesh nodes have; a list the user gave is checked
            default = type(pr).model_fields["quantities"].default
            names = tuple(pr.quantities) if pr.quantities != default else tuple(
                q for q in pr.quantities if node_probe_field(q) is not None)
            probe = Probe(pr.set, idx, names, pr.reduce, mesh=mesh)
            for q in probe.quantities:
                if node_probe_field(q) is None:
                    raise DeckError([format_problem(
                        f"probe[{k}].quantities", f"'{q}' is not a quantity of mesh "
                        f"nodes (set '{pr.set}' holds nodes of mesh '{mesh}')",
                        f"name one of {', '.join(NODE_FIELDS)} or a component (_x, _y, "
                        "_z); a mesh's stresses and damage are in its frames")])
            probes.append(probe)
            continue
        probe = Probe(pr.set, sets[pr.set], tuple(pr.quantities), pr.reduce)
        for q in probe.quantities:
            try:
                quantity(particles, probe.idx, q)
            except ValueError as exc:
                raise ValueError(f"probe on set {pr.set!r}: {exc}") from None
        probes.append(probe)

    every = np.concatenate([particles.x] + [mm.points for mm in meshes])
    lo_b = every.min(axis=0)
    hi_b = every.max(axis=0)
    # the same distance on every side: a thin body (the paper's disc is 20 mm
    # deep) must not get a thin box, or debris squeezed out sideways stops it
    size = max(float(np.max(hi_b - lo_b)), float(particles.h.max(initial=0.0)))
    lo = lo_b - deck.domain.margin * size if deck.domain.lo is None else np.asarray(
        deck.domain.lo, float)
    hi = hi_b + deck.domain.margin * size if deck.domain.hi is None else np.asarray(
        deck.domain.hi, float)
    lo[dim:], hi[dim:] = -np.inf, np.inf  # 2D: z, 1D: y and z unbounded

    return Model(
        particles=particles, groups=groups, walls=wall_specs(deck), sets=sets,
        body_names=body_names, domain_lo=lo, domain_hi=hi,
        probes=probes, phase=np.concatenate(phase_parts + [np.zeros(0, np.int8)]),
        photo_targets=photos, variation=factor, mass_draws=draws, meshes=meshes,
        mesh_sets=mesh_sets)


def debris_meshes(meshes) -> list[MeshModel]:
    """The meshes whose eroded elements become particles ([mesh.erosion] to =
    "particles"), in deck order: their debris bodies follow the converted ones."""
    return [mm for mm in meshes
            if mm.spec.erosion is not None and mm.spec.erosion.to == "particles"]


def sublayer_meshes(meshes) -> list[MeshModel]:
    """The bars with [mesh.sublayer], in deck order: their bodies follow the
    converted ones."""
    return [mm for mm in meshes if mm.spec.sublayer is not None]


def mesh_bodies(deck) -> list[tuple[int, str, str]]:
    """The particle bodies made from meshes, in body-index order after the
    [[body]]s: ``(mesh index, deck key, body name)`` of every mesh's
    converted particles (``convert``, named as the mesh), then of every
    bar's sublayer particles (``sublayer``, ``<mesh>_sublayer``), then of
    the debris of elements eroding into particles (``erosion``,
    ``<mesh>_debris``)."""
    mesh = list(enumerate(deck.mesh))
    return ([(k, "convert", m.name) for k, m in mesh if m.convert is not None]
            + [(k, "sublayer", f"{m.name}_sublayer") for k, m in mesh
               if m.sublayer is not None]
            + [(k, "erosion", f"{m.name}_debris") for k, m in mesh
               if m.erosion is not None and m.erosion.to == "particles"])


def particle_body_names(deck) -> list[str]:
    """Names of the particle bodies by body index (``Particles.body``): the
    [[body]]s, then :func:`mesh_bodies`. A mesh body whose name a [[body]]
    has already is a DeckError."""
    names = [b.name for b in deck.body]
    for k, key, name in mesh_bodies(deck):
        if name in names:
            mesh = deck.mesh[k].name
            raise DeckError([format_problem(
                f"mesh[{k}] '{mesh}'.{key}", f"its particles form a body named "
                f"'{name}', and a [[body]] has that name", "rename the mesh or the body")])
        names.append(name)
    return names


def _sublayer_particles(deck, mm: MeshModel, b: int, n_hist: int) -> Particles:
    """One particle per node of a bar (:mod:`sphdyn.interactions.sublayer`): its
    share ``mass_ratio`` of the bar's lumped mass, the bar's material (its
    density and volume are the concrete's, set by :func:`_seat_sublayers`),
    h = sph.h_factor times the mean element length (or [mesh.sublayer]
    smoothing_length), body ``b``."""
    from ..interactions.sublayer import sublayer_masses

    mat = deck.material[int(mm.mat[0])]
    x, conn = mm.points, mm.cells
    m = sublayer_masses(x, conn, section_of(mm.spec).area, mat.density,
                        mm.spec.sublayer.mass_ratio)
    length = float(np.mean(np.linalg.norm(x[conn[:, 1]] - x[conn[:, 0]], axis=1)))
    h = mm.spec.sublayer.smoothing_length
    p = Particles.allocate(x.shape[0], deck.run.dimension, n_hist)
    # density and volume 0 until the bar is seated in its concrete
    p.place(slice(None), x=x, v=np.asarray(mm.spec.velocity, dtype=float), m=m,
            vol0=0.0, rho0=0.0, h=deck.sph.h_factor * length if h is None else h,
            mat=int(mm.mat[0]), body=b)
    return p


def _seat_sublayers(deck, meshes, particles: Particles, body_names: list[str]) -> None:
    """Seat every bar in its concrete: its particles take the density of the
    concrete around them (and the volume m / rho), so that they sample the
    concrete's strain rate (:mod:`sphdyn.interactions.sublayer`). A bar must meet the
    concrete: at least one of its nodes needs a particle of the
    [mesh.sublayer] body (or of any deck body) within its support radius
    (nodes of a bar that sticks out, as in a pull-out test, need not)."""
    from scipy.spatial import cKDTree

    for mm in sublayer_meshes(meshes):
        sub = mm.spec.sublayer
        own = body_names.index(f"{mm.name}_sublayer")
        hosts = ([body_names.index(sub.body)] if sub.body is not None
                 else list(range(len(deck.body))))
        host = np.flatnonzero(np.isin(particles.body, hosts))
        rows = np.flatnonzero(particles.body == own)
        where = f"mesh[{mm.index}] '{mm.name}'.line"
        radius = support_radius(deck.sph) * particles.h[rows]
        if host.size:
            dist, near = cKDTree(particles.x[host]).query(particles.x[rows])
        else:
            dist = np.full(rows.size, np.inf)
        if not np.any(dist <= radius):
            at = ", ".join(f"{c:.4g}" for c in particles.x[rows[0]])
            raise DeckError([format_problem(
                where, f"the bar lies outside the concrete: none of its {rows.size} "
                f"nodes (the first at ({at}) m) has a particle of "
                f"{'body ' + repr(sub.body) if sub.body else 'any body'} within its "
                f"support ({radius.max():.4g} m)",
                "move the bar into the concrete body (or name the body it is in: "
                "[mesh.sublayer] body)")])
        # the concrete's density: the weights m_j / rho_i of a bar particle's
        # velocity gradient are then the concrete's volumes (docs/theory.md,
        # "Sublayer coupling of rebar")
        rho = float(np.mean(particles.rho0[host[near]]))
        particles.rho[rows] = rho
        particles.rho0[rows] = rho
        particles.vol0[rows] = particles.m[rows] / rho


def _sublayer_groups(deck, meshes, particles: Particles, body_names: list[str],
                     groups: list, models: dict, first: dict) -> list:
    r"""The material groups with each bar's sublayer particles as its
    [mesh.sublayer] ``stiffness`` says (:mod:`sphdyn.interactions.sublayer`):

    * ``"material"``: in their material's group, as built;
    * ``"none"``: in no group (no stress, wave speed 0: coupling only);
    * ``"split"``: in a group of their own, ``<material>@<mesh>``, the
      material with its stresses times :math:`\rho_c/\rho_s` (the seated
      density over the steel's): a particle of SPH volume :math:`m_s/\rho_c =
      r A L_n \rho_s/\rho_c` then acts through the kernel as the steel volume
      :math:`r A L_n`, the bar's share ``mass_ratio`` = r, and the elements
      carry the rest (:func:`sphdyn.build.meshes.mesh_part`). The particles'
      wave speed is the steel's, :math:`\sqrt{(\rho_c/\rho_s) M/\rho_c}`.
    * ``"axial"``: as ``"split"``, with the uniaxial bar model
      (:mod:`sphdyn.materials.uniaxial`) on those scaled parameters: the
      stress acts along the bar only; wave speed :math:`\sqrt{E/\rho_s}`.
    """
    for mm in sublayer_meshes(meshes):
        stiffness = mm.spec.sublayer.stiffness
        if stiffness == "material":
            continue
        rows = np.flatnonzero(particles.body == body_names.index(f"{mm.name}_sublayer"))
        groups = [replace(g, idx=np.setdiff1d(g.idx, rows)) for g in groups]
        if stiffness in ("split", "axial"):
            k = int(mm.mat[0])
            mat = deck.material[k]
            model = models[mat.name]
            if not model.stress_scalable:
                split = " or ".join(m for m in available_models()
                                    if get_model(m).stress_scalable)
                raise DeckError([format_problem(
                    f"mesh[{mm.index}] '{mm.name}'.sublayer.stiffness",
                    f"\"{stiffness}\" scales the bar material's stresses, which model "
                    f"'{model.name}' does not allow", "use a bar material of model "
                    f"{split}, or stiffness = \"material\" or \"none\"")])
            ratio = float(particles.rho0[rows[0]]) / mat.density
            values = mat.stress_scaled(ratio)
            if not all(np.isfinite(v) for v in values.values() if isinstance(v, float)):
                raise DeckError([format_problem(
                    f"material[{k}] '{mat.name}'.density",
                    f"\"{stiffness}\" scales the bar's stresses by the concrete's "
                    f"density over the bar's, {ratio:.3g}, and they overflow",
                    "give the bar material its density (steel: 7850 kg/m^3)")])
            packed = model.pack(values)
            if stiffness == "axial":
                model, packed = UNIAXIAL, uniaxial_params(model.name, packed)
            groups.append(MaterialGroup(f"{mat.name}@{mm.name}", model, packed,
                                        rows.astype(np.int64), k,
                                        first[model.history_names]))
    return groups


def _converted_particles(deck, mm: MeshModel, b: int, density_of, n_hist: int) -> Particles:
    """Particles of a mesh's converted elements: one per element at its centroid,
    with its volume and mass :math:`\rho V_e` (thesis ch. 4), smoothing length
    ``sph.h_factor`` times :math:`V_e^{1/d}`, body index ``b``; then, with the
    hybrid coupling, one per integration point of the hybrid layer (its
    volume and mass; the smoothing length of its element's size)."""
    c, dim = mm.converted, deck.run.dimension
    x, vol, mat, size = c.x, c.vol, c.mat, c.vol ** (1.0 / dim)
    if c.hybrid is not None:
        hy = c.hybrid
        per = np.bincount(hy.elem)[hy.elem]  # points per element
        x = np.concatenate([x, hy.x])
        vol = np.concatenate([vol, hy.vol])
        mat = np.concatenate([mat, hy.mat])
        size = np.concatenate([size, (hy.vol * per) ** (1.0 / dim)])
    p = Particles.allocate(x.shape[0], dim, n_hist)
    p.place(slice(None), x=x, v=np.asarray(mm.spec.velocity, dtype=float),
            m=density_of[mat] * vol, vol0=vol, rho0=density_of[mat],
            h=deck.sph.h_factor * size, mat=mat, body=b)
    return p
