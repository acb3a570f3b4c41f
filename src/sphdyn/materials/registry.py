"""Registry of material models, built in or from other packages.

A :class:`MaterialModel` bundles a model's group kernel, its parameter
packing and its deck table (``schema``: a subclass of
:class:`sphdyn.deck.sections.material.MaterialSection` whose ``model`` key is
``Literal["<name>"]``, owning the model's keys, defaults and checks). The
built-in models register when :mod:`sphdyn.materials` is imported; the deck
offers the tables of every registered model (:func:`material_schemas`).

Another package adds a model through an entry point in the group
:data:`ENTRY_POINT_GROUP` (``sphdyn.materials``), e.g. in its
``pyproject.toml``::

    [project.entry-points."sphdyn.materials"]
    toy = "toy_material:MODEL"

The entry point names a :class:`MaterialModel`, or a callable returning one
(or registering it and returning None). Entry points are loaded once, the
first time the registry is asked for a model (:func:`get_model`,
:func:`available_models`, :func:`material_schemas`); a failing one is
skipped with a ``RuntimeWarning``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable, get_args

import numpy as np

from ..plugins import load_group

# Common leading block of every parameter vector.
P_DENSITY = 0
P_K = 1
P_G = 2
N_COMMON = 3

ENTRY_POINT_GROUP = "sphdyn.materials"


@dataclass
class MaterialGroup:
    """Items sharing one material: the model's group kernel runs over ``idx``.

    The items are particles (of an SPH part) or integration points (of a
    finite-element part). ``material`` is the index in the deck's
    ``[[material]]`` list (a material with ``[material.variation]`` has one
    group per class).
    """

    name: str
    model: "MaterialModel"
    params: np.ndarray
    idx: np.ndarray  # int64 item indices
    material: int = 0
    column: int = 0  # first column of the model's history in the part's hist

    def history(self, hist: np.ndarray) -> np.ndarray:
        """The part's history (N, width) as the kernel sees it: its columns from
        ``column`` on (a view; the array itself when ``column`` is 0)."""
        return hist if self.column == 0 else hist[:, self.column:]


def history_layout(models) -> tuple[list[str], dict[tuple[str, ...], int]]:
    """One history array for items of several material models.

    The models' column lists (``history_names``) are laid side by side: the
    longest first, at column 0; a list that is a run of the columns so far
    shares them (models of one family: j2's plastic strain is the first
    column of the uniaxial bar's); any other follows the last column.
    Returns the names of the columns and, per list of names, its first
    column (:attr:`MaterialGroup.column`). Each item's model sees its own
    columns from 0 (:meth:`MaterialGroup.history`), the others of its row
    stay at zero. ``ValueError`` if a name would sit in two columns.
    """
    layouts = []
    for m in models:
        if m.history_names not in layouts:
            layouts.append(m.history_names)
    names: list[str] = []
    first: dict[tuple[str, ...], int] = {}
    for layout in sorted(layouts, key=len, reverse=True):
        at = [s for s in range(len(names) - len(layout) + 1)
              if tuple(names[s:s + len(layout)]) == layout]
        if at:  # a run of the columns so far: shared
            first[layout] = at[0]
            continue
        clash = sorted(set(layout) & set(names))
        if clash:
            raise ValueError(f"history variables {clash} of two material models would "
                             "need two columns; use one of these models per run")
        first[layout] = len(names)
        names += layout
    return names, first


@dataclass(frozen=True)
class MaterialModel:
    """A registered constitutive model.

    Attributes
    ----------
    name : str
        Registry key (e.g. ``"elastic"``, ``"j2"``).
    history_names : tuple of str
        Names of the model's history columns ``hist[:, 0:nh]``.
    pack : callable
        ``pack(values: dict) -> float64 array``; values in SI units. Raises
        ``ValueError`` naming a missing or invalid key.
    update : numba dispatcher
        Group kernel with the common signature
        (:data:`sphdyn.materials.base.KERNEL_SIGNATURE_DOC`).
    history_init : callable or None
        ``history_init(params) -> (nh,) array`` of initial history values;
        ``None`` means all zeros.
    schema : pydantic model class or None
        The model's ``[[material]]`` table (keys, defaults, checks); None
        for a model the deck does not offer (e.g. one used only by the
        material driver).
    initial_stress : bool
        The model accepts a Cauchy stress given at t = 0 (``[body.initial]
        stress``) as its state: an incremental model with no other state tied
        to the stress. False (the default) refuses one in the deck.
    has_damage : bool
        The model writes a scalar damage (0 intact, 1 failed) into
        ``damage``: only then may elements of it erode by damage
        (:mod:`sphdyn.parts.fem.erosion_criteria`).
    softening : bool
        The model softens and spreads its fracture energy over the ``size``
        it is given (crack band): an SPH part then gives it the particles'
        crack-band length (``[sph] crack_band`` times their size) instead of
        their size (docs/theory.md, "Fracture energy of an SPH crack").
    fluid : bool
        A fluid (gas, detonation products): no shear stiffness, and its
        particles' time step includes the artificial viscosity's signal
        speed (:func:`sphdyn.integrate.cfl_time_step`).
    linear_elastic : bool
        Stress linear in strain with the moduli K and G and nothing else:
        a beam's stress resultants (:class:`~sphdyn.parts.fem.line_part.LinePart`)
        can be formed from it.
    stress_scalable : bool
        Its stress is homogeneous of degree one in its stress parameters
        (moduli, strengths), so scaling those scales the stress: a bar of it
        can share its stiffness between its elements and its sublayer
        particles (``[mesh.sublayer] stiffness = "split"``,
        :func:`sphdyn.build.model.build_model`).
    explosive : bool
        A high explosive: the material a ``[[detonation]]`` lights
        (:mod:`sphdyn.build.detonation`).
    test_density : float or None
        The density [kg/m^3] ``sphdyn material-test`` gives a point of the
        model when the user gives none: a point driven by strain has a
        stress independent of its density (it sets only the wave speed), so
        a typical one of the material class serves (normal-weight concrete
        2400, steel 7850). None: the test needs the user's (fluids, whose
        state depends on it).
    initial_state : callable or None
        ``initial_state(params) -> (e0, p0)``: the specific internal energy
        [J/kg] and pressure [Pa] of the material at rest at its initial
        density (a gas at its ambient pressure); None: both zero.
    released_energy : callable or None
        ``released_energy(params, hist, m) -> float``: the energy [J] the
        model has added to its items' internal energy from a source (an
        explosive's chemical energy, burned mass times ``E0 / rho0``), from
        their history rows ``hist`` (n, nh) and masses ``m`` (n,). The energy
        balance counts it as supplied (``E_chemical``).
    modulus : callable or None
        ``modulus(params) -> float``: the modulus M [Pa] of the model's wave
        speed ``sqrt(M / rho)``; None: the P-wave modulus ``K + 4G/3``.
    """

    name: str
    history_names: tuple[str, ...]
    pack: Callable[[dict], np.ndarray]
    update: Callable
    history_init: Callable[[np.ndarray], np.ndarray] | None = None
    schema: Any = None
    initial_stress: bool = False
    has_damage: bool = False
    softening: bool = False
    fluid: bool = False
    linear_elastic: bool = False
    stress_scalable: bool = False
    explosive: bool = False
    test_density: float | None = 2400.0
    initial_state: Callable[[np.ndarray], tuple[float, float]] | None = None
    released_energy: Callable[[np.ndarray, np.ndarray, np.ndarray], float] | None = None
    modulus: Callable[[np.ndarray], float] | None = None

    @property
    def n_history(self) -> int:
        """Number of history columns the model uses."""
        return len(self.history_names)

    def initial_history(self, params: np.ndarray) -> np.ndarray:
        """Initial history values, shape ``(nh,)``."""
        if self.history_init is None:
            return np.zeros(self.n_history)
        return np.asarray(self.history_init(params), dtype=np.float64)

    @staticmethod
    def density(params: np.ndarray) -> float:
        """Reference density [kg/m^3] stored in the parameter vector."""
        return float(params[P_DENSITY])

    @staticmethod
    def bulk_modulus(params: np.ndarray) -> float:
        """Elastic bulk modulus K [Pa]."""
        return float(params[P_K])

    @staticmethod
    def shear_modulus(params: np.ndarray) -> float:
        """Elastic shear modulus G [Pa]."""
        return float(params[P_G])

    def wave_speed(self, params: np.ndarray, rho: float) -> float:
        """Longitudinal (P-wave) speed ``c = sqrt((K + 4G/3) / rho)`` [m/s], or
        ``sqrt(M / rho)`` with the model's own ``modulus``.

        Parameters
        ----------
        params : float64 array
            Packed parameters.
        rho : float
            Density [kg/m^3], > 0.
        """
        if self.modulus is not None:
            return math.sqrt(self.modulus(params) / rho)
        return math.sqrt((params[P_K] + 4.0 * params[P_G] / 3.0) / rho)


REGISTRY: dict[str, MaterialModel] = {}


def register(model: MaterialModel, *, replace: bool = False) -> MaterialModel:
    """Add ``model`` to :data:`REGISTRY` under ``model.name``.

    Raises ``ValueError`` if the name is taken and ``replace`` is false, or
    if the model's schema does not have ``model: Literal[<name>]``.
    """
    if model.name in REGISTRY and not replace:
        raise ValueError(f"material model {model.name!r} is already registered")
    if model.schema is not None:
        info = model.schema.model_fields.get("model")
        if info is None or get_args(info.annotation) != (model.name,):
            raise ValueError(f"the schema {model.schema.__name__} of material model "
                             f"{model.name!r} needs model: Literal[{model.name!r}]")
    REGISTRY[model.name] = model
    return model


def load_entry_points() -> None:
    """Register the models of the ``sphdyn.materials`` entry points (once)."""
    load_group(ENTRY_POINT_GROUP, MaterialModel,
               lambda m: None if REGISTRY.get(m.name) is m else register(m))


def available_models() -> tuple[str, ...]:
    """Sorted names of the registered models."""
    load_entry_points()
    return tuple(sorted(REGISTRY))


def get_model(name: str) -> MaterialModel:
    """Registered model by name; ``KeyError`` listing the known names otherwise."""
    load_entry_points()
    try:
        return REGISTRY[name]
    except KeyError:
        raise KeyError(
            f"unknown material model {name!r}; registered models: "
            f"{', '.join(available_models()) or '(none)'}"
        ) from None


def material_schemas() -> tuple[type, ...]:
    """The deck tables of the registered models, in registration order."""
    load_entry_points()
    return tuple(m.schema for m in REGISTRY.values() if m.schema is not None)


def schema_defaults(schema) -> dict[str, Any]:
    """``{key: default}`` of the keys of ``schema`` with a default other than None."""
    return {k: f.default for k, f in schema.model_fields.items()
            if not f.is_required() and f.default_factory is None
            and f.default is not None}
