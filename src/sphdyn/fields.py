"""Registry of output fields: what frames, the deck and probes may name.

Each :class:`OutputField` has a name, a shape per particle (``scalar``,
``vector`` (3), ``tensor`` (3x3, written as 9 row-major values) or
``history``, a column of the material history), a unit, a one-line
description and a getter ``getter(p, computed) -> ndarray``: ``p`` is the
:class:`~sphdyn.state.Particles` state and ``computed`` maps names to
zero-argument callables for fields a part evaluates itself (e.g.
``"swegle"``, ``"phase"``, ``"variation"``; ``SPHPart.fields()``).
Getters return fresh arrays for all particles, so the state can keep
evolving.

Fields marked ``cells`` are also (or only) cell fields of meshes: a mesh
frame writes those of ``output.fields`` its part has, with every history
column of its materials (:func:`sphdyn.parts.fem.output.mesh_frame`).

Readers: :func:`sphdyn.io.fields.particle_fields` (frames), the deck's
``output.fields`` check and default, the ``[[probe]]`` quantities
(:func:`probe_quantities`, :func:`probe_values`) and the generated deck
reference. Another package adds a field with :func:`register_field`.

Stress sign convention: ``sig`` is the Cauchy stress, tension positive. The
pressure is positive in compression, ``p = -tr(sig) / 3``; the von Mises
stress is ``sqrt(3/2 s:s)`` with ``s = sig + p I`` the deviatoric stress.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Literal, Mapping

import numpy as np

Getter = Callable[[Any, Mapping[str, Callable[[], np.ndarray]]], np.ndarray]

#: Components a probe may record of a vector or tensor field (``stress_xy``);
#: tensor components index the 9 row-major values.
COMPONENTS = {
    "vector": {"x": 0, "y": 1, "z": 2},
    "tensor": {"xx": 0, "yy": 4, "zz": 8, "xy": 1, "yz": 5, "xz": 2},
}


@dataclass(frozen=True)
class OutputField:
    """One per-particle field.

    Attributes
    ----------
    name : str
        The name in ``output.fields``, frames and probe quantities.
    shape : {"scalar", "vector", "tensor", "history"}
        Values per particle: 1, 3, 9 (row-major 3x3), or 1 history column.
    unit : str
        SI unit ("-" for dimensionless numbers and flags).
    description : str
        One line for the deck reference.
    getter : callable
        ``getter(p, computed) -> ndarray`` of shape ``(N,)``, ``(N, 3)`` or
        ``(N, 9)``, a fresh array.
    default : bool
        Written when the deck gives no ``output.fields``.
    always : bool
        Written in every frame (``position``; ``mass``, so that momentum
        can be summed from a frame); naming it in ``output.fields`` changes
        nothing.
    probe : bool
        A ``[[probe]]`` quantity (vector and tensor fields: each component,
        ``velocity_x``, ``stress_xy``).
    cells : bool
        Also a cell field of meshes: each mesh that has it writes its value
        per element (the part's own ``fields()``). A field of cells only has
        no getter (``None``) and shape ``pair`` for two values per element
        (a beam's end moments).
    """

    name: str
    shape: Literal["scalar", "vector", "tensor", "history", "pair"]
    unit: str
    description: str
    getter: Getter | None
    default: bool = False
    always: bool = False
    probe: bool = False
    cells: bool = False


FIELDS: dict[str, OutputField] = {}


def register_field(field: OutputField, *, replace: bool = False) -> OutputField:
    """Add ``field`` to :data:`FIELDS`; ``ValueError`` if the name is taken."""
    if field.name in FIELDS and not replace:
        raise ValueError(f"output field {field.name!r} is already registered")
    FIELDS[field.name] = field
    return field


def allowed_fields() -> list[str]:
    """Names that ``output.fields`` accepts (every registered field), in
    registry order."""
    return list(FIELDS)


def default_fields() -> tuple[str, ...]:
    """Names written when the deck gives no ``output.fields``."""
    return tuple(f.name for f in FIELDS.values() if f.default)


def probe_quantities() -> tuple[str, ...]:
    """Names a ``[[probe]]`` may record: scalar fields and field components."""
    names = []
    for f in FIELDS.values():
        if f.probe:
            parts = COMPONENTS.get(f.shape)
            names += [f"{f.name}_{c}" for c in parts] if parts else [f.name]
    return tuple(names)


def history_column(p, name: str) -> np.ndarray:
    """Column ``name`` of the material history ``p.hist`` (a copy)."""
    return p.hist[:, p.hist_names.index(name)].copy()


def probe_values(p, name: str, computed=None) -> np.ndarray:
    """(N,) values of probe quantity ``name`` for every particle.

    ``name`` is a scalar field, a component ``<field>_<c>`` of a vector or
    tensor field (:data:`COMPONENTS`), or a history column of ``p``
    (registered or not). ``ValueError`` if it is none of these.
    """
    computed = computed or {}
    field = FIELDS.get(name)
    if field is not None and field.shape == "scalar":
        return field.getter(p, computed)
    if name in p.hist_names:  # a registered history field or any other column
        return history_column(p, name)
    base, _, comp = name.rpartition("_")
    field = FIELDS.get(base)
    if field is not None and comp in COMPONENTS.get(field.shape, {}):
        return field.getter(p, computed)[:, COMPONENTS[field.shape][comp]]
    raise ValueError(f"probe quantity {name!r} is not available: no material of "
                     f"this model has it (history variables: {p.hist_names or 'none'})")


# --------------------------------------------------------------------------
# Built-in fields
# --------------------------------------------------------------------------


def pressure(sig: np.ndarray) -> np.ndarray:
    """Pressure ``-tr(sig)/3`` [Pa], positive in compression, of ``(N, 3, 3)`` stresses."""
    return -np.trace(sig, axis1=1, axis2=2) / 3.0


def von_mises(sig: np.ndarray) -> np.ndarray:
    """Von Mises equivalent stress ``sqrt(3/2 s:s)`` [Pa] of ``(N, 3, 3)`` stresses."""
    mean = np.trace(sig, axis1=1, axis2=2) / 3.0
    s = sig - mean[:, None, None] * np.eye(3)
    return np.sqrt(1.5 * np.einsum("nij,nij->n", s, s))


def _array(attr: str) -> Getter:
    """Getter of a copy of the particle array ``p.<attr>``."""
    return lambda p, computed: getattr(p, attr).copy()


def _computed_or(name: str, fallback: Callable[[Any], np.ndarray]) -> Getter:
    """Getter of a field a part computes (``computed[name]``), else ``fallback(p)``."""
    def get(p, computed):
        if name in computed:
            return np.array(computed[name](), copy=True)
        return fallback(p)
    return get


_BUILT_IN = (
    OutputField("position", "vector", "m", "Current position x.",
                _array("x"), always=True, probe=True),
    OutputField("velocity", "vector", "m/s", "Velocity v.",
                _array("v"), default=True, probe=True),
    OutputField("speed", "scalar", "m/s", "Magnitude of the velocity |v|.",
                lambda p, c: np.linalg.norm(p.v, axis=1), probe=True),
    OutputField("displacement", "vector", "m", "Displacement x - x0.",
                lambda p, c: p.x - p.x0, default=True, probe=True),
    OutputField("stress", "tensor", "Pa", "Cauchy stress, tension positive.",
                lambda p, c: p.sig.reshape(p.n, 9).copy(), default=True, probe=True,
                cells=True),
    OutputField("pressure", "scalar", "Pa", "Pressure -tr(sig)/3, positive in "
                "compression.", lambda p, c: pressure(p.sig), default=True, probe=True),
    OutputField("von_mises", "scalar", "Pa", "Von Mises stress sqrt(3/2 s:s), s "
                "the deviatoric stress.", lambda p, c: von_mises(p.sig), default=True,
                probe=True, cells=True),
    OutputField("density", "scalar", "kg/m^3", "Current density rho.",
                _array("rho"), default=True, probe=True, cells=True),
    OutputField("mass", "scalar", "kg", "Mass m (kg/m in 2D, kg/m^2 in 1D).",
                _array("m"), always=True),
    OutputField("smoothing_length", "scalar", "m", "Smoothing length h.",
                _array("h"), default=True, probe=True),
    OutputField("damage", "scalar", "-", "Scalar damage in [0, 1].",
                _array("damage"), default=True, probe=True, cells=True),
    OutputField("internal_energy", "scalar", "J/kg", "Specific internal energy e.",
                _array("e"), default=True, probe=True),
    OutputField("plastic_strain", "history", "-", "Equivalent plastic strain "
                "(history of j2 materials).",
                lambda p, c: history_column(p, "plastic_strain"), probe=True,
                cells=True),
    # the CSCM's two damage modes apart (LS-DYNA MAT_159's NPLOT = 2 and 3);
    # ``damage`` is the applied one (their maximum, brittle recovered in
    # compression)
    OutputField("damage_brittle", "history", "-", "Brittle (tensile) damage in [0, 1] "
                "(history of cscm materials).",
                lambda p, c: history_column(p, "damage_brittle"), probe=True,
                cells=True),
    OutputField("damage_ductile", "history", "-", "Ductile (compressive) damage in [0, 1] "
                "(history of cscm materials).",
                lambda p, c: history_column(p, "damage_ductile"), probe=True,
                cells=True),
    OutputField("bc", "scalar", "-", "Boundary-condition flag (int8).", _array("bc")),
    OutputField("body", "scalar", "-", "Body index (int32).", _array("body")),
    OutputField("material", "scalar", "-", "Material index (int32).", _array("mat")),
    OutputField("swegle", "scalar", "-", "Swegle tensile-instability indicator: "
                "fraction of neighbour pairs with W''(r) sigma_n > 0 (tension "
                "positive), in [0, 1]; NaN without a part to compute it; see "
                "docs/tensile-instability.md.",
                _computed_or("swegle", lambda p: np.full(p.n, np.nan))),
    OutputField("phase", "scalar", "-", "Mesostructure phase (int8): 0 mortar, 1 "
                "aggregate, 2 ITZ, -1 for bodies without [body.mesostructure].",
                _computed_or("phase", lambda p: np.full(p.n, -1, np.int8))),
    OutputField("variation", "scalar", "-", "Factor of the [material.variation] "
                "parameter (1 for materials without variation).",
                _computed_or("variation", lambda p: np.ones(p.n))),
    # cell fields of meshes only (their parts' fields())
    OutputField("hourglass_energy", "scalar", "J", "Hourglass energy of a solid element.",
                None, default=True, cells=True),
    OutputField("volume", "scalar", "m^3", "Current volume of a solid element (m^2 in "
                "2D).", None, default=True, cells=True),
    OutputField("axial_force", "scalar", "N", "Axial force of a bar or beam element, "
                "tension positive.", None, default=True, cells=True),
    OutputField("axial_stress", "scalar", "Pa", "Axial force over the section area of "
                "a bar or beam element.", None, default=True, cells=True),
    OutputField("lateral_stress", "scalar", "Pa", "Mean lateral stress of a truss "
                "element's material point.", None, default=True, cells=True),
    OutputField("torque", "scalar", "N m", "Torque of a beam element.", None,
                default=True, cells=True),
    OutputField("moment_y", "pair", "N m", "Bending moments about the section's y "
                "axis at a beam element's two ends.", None, default=True, cells=True),
    OutputField("moment_z", "pair", "N m", "Bending moments about the section's z "
                "axis at a beam element's two ends.", None, default=True, cells=True),
    OutputField("shear_y", "scalar", "N", "Shear force along the section's y axis of "
                "a beam element.", None, default=True, cells=True),
    OutputField("shear_z", "scalar", "N", "Shear force along the section's z axis of "
                "a beam element.", None, default=True, cells=True),
)

for _field in _BUILT_IN:
    register_field(_field)
