"""Mesh state: nodes (kinematics, optional rotations), elements and integration points.

A finite-element part keeps three tables, each an
:class:`~sphdyn.state.store.ArrayStore` (struct of flat arrays, SI units):

* :class:`Nodes`: the kinematics every part has (x, v, a, a_ext, m, bc,
  bc_v, active) plus the reference position ``x0``; beam parts add a second
  kinematics table ``rot`` for the rotational degrees of freedom (angular
  velocity in ``rot.v``, angular acceleration in ``rot.a``, rotary inertia in
  ``rot.m``), which the stepper kicks like the translations;
* :class:`Elements`: connectivity and per-element data (mass, hourglass
  state and energy);
* :class:`MaterialPoints`: the integration points, with the same fields as
  particles (velocity gradient ``L``, density, Cauchy stress, specific
  internal energy, wave speed, damage, history, size), so every material
  model's group kernel (:mod:`sphdyn.materials.base`) updates elements and
  particles alike. One point per element for one-point integration, eight
  (four in 2D) for the selective-reduced variant; ``elem`` maps a point to
  its element.

Conventions are the particles': vectors ``(N, 3)`` even in 2D (plane strain,
``z = 0``, quantities per unit depth), stress positive in tension.
"""

from __future__ import annotations

import numpy as np

from .particles import Kinematics
from .store import STATE, ArrayStore


class Nodes(Kinematics):
    """Mesh nodes: kinematics plus ``x0`` (N, 3) reference position [m].

    With ``rotations=True`` the nodes also carry ``rot``, a
    :class:`~sphdyn.state.Kinematics` of the same length for the rotational
    degrees of freedom: ``rot.v`` angular velocity [rad/s], ``rot.a`` angular
    acceleration [rad/s^2], ``rot.m`` rotary inertia [kg m^2] (one value per
    node, a lumped isotropic inertia), ``rot.bc``/``rot.bc_v`` fixed or
    prescribed angular velocity, ``rot.x`` the accumulated rotation vector
    (sum of ``omega dt``, output only).
    """

    def __init__(self, n: int, dim: int, rotations: bool = False):
        super().__init__(n, dim)
        self.add("x0", (3,), np.float64, kind=STATE)
        self.rot = Kinematics(n, dim) if rotations else None
        if self.rot is not None:
            self.on_grow(lambda n_old, n_new: self.rot.grow(n_new - n_old))


class Elements(ArrayStore):
    """Elements of one mesh part.

    Attributes (E elements, ``nen`` nodes per element)
    ----------
    conn : (E, nen) int64
        Node indices (VTK / LS-DYNA node order).
    mat : (E,) int32
        Material index (the deck's ``[[material]]`` list).
    m : (E,) float64
        Element mass [kg] (kg/m in 2D), constant.
    vol0 : (E,) float64
        Initial volume [m^3] (area per unit depth in 2D).
    vol : (E,) float64
        Current volume (a work array: the part derives it from the nodes).
    e_hg : (E,) float64
        Work done against the hourglass forces [J] (part of the internal energy).
    hg : (E, 4, 3) float64
        Stiffness-form hourglass generalised forces [N] (one mode in 2D).
    active : (E,) int8
        1 for elements taking part (erosion clears it).
    dt_mass : (E,) float64
        Factor on the element's stable step from selective mass scaling,
        :math:`\\sqrt{1 + \\Delta m_e / m_e}` (:mod:`sphdyn.mass_scaling`; 1 without).
    """

    def __init__(self, n: int, nen: int):
        super().__init__(n)
        self.nen = nen
        self.add("conn", (nen,), np.int64, kind=STATE)
        self.add("mat", (), np.int32, kind=STATE)
        self.add("m", (), np.float64, kind=STATE)
        self.add("vol0", (), np.float64, kind=STATE)
        self.add("vol", (), np.float64)  # derived from the nodes' positions
        self.add("e_hg", (), np.float64, kind=STATE)
        self.add("hg", (4, 3), np.float64, kind=STATE)
        self.add("active", (), np.int8, kind=STATE, fill=1)
        # the step factor of mass scaling (sphdyn.mass_scaling), 1 without
        self.add("dt_mass", (), np.float64, kind=STATE, fill=1)


#: name -> (tail shape, dtype) of the integration-point fields (the particle
#: fields a material kernel reads and writes)
POINT_FIELDS = {
    "L": ((3, 3), np.float64), "rho": ((), np.float64), "rho0": ((), np.float64),
    "sig": ((3, 3), np.float64), "e": ((), np.float64), "e_av": ((), np.float64),
    "c": ((), np.float64), "damage": ((), np.float64), "size": ((), np.float64),
    "elem": ((), np.int64), "mat": ((), np.int32),
}


class MaterialPoints(ArrayStore):
    """Integration points: the arrays a material group kernel updates.

    Attributes (P points, ``nh`` history slots)
    ----------
    L : (P, 3, 3) velocity gradient [1/s]; rho, rho0 : (P,) density [kg/m^3];
    sig : (P, 3, 3) Cauchy stress [Pa]; e : (P,) specific internal energy
    [J/kg] (material work plus bulk-viscosity heat); e_av : (P,) the
    bulk-viscosity part of ``e``; c : (P,) wave speed [m/s]; damage : (P,);
    size : (P,) element size [m] (fracture-energy regularisation);
    hist : (P, nh) history; elem : (P,) element of the point; mat : (P,)
    material index. A part adds its work arrays (e.g. the solid part's point
    masses ``m``).
    """

    def __init__(self, n: int, n_history: int = 0):
        super().__init__(n)
        for name, (tail, dtype) in POINT_FIELDS.items():
            self.add(name, tail, dtype, kind=STATE)
        self.add("hist", (max(n_history, 1),), np.float64, kind=STATE)
        self.hist_names: list[str] = []
