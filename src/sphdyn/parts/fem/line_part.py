r"""Line elements as a part: co-rotational beams and trusses (rebar).

A :class:`LinePart` is a set of 2-node elements of one element type, one
section (:class:`BeamSection`) and one material:

* ``element="beam"``: the elastic co-rotational resultant beam of
  :mod:`.beam` (6 degrees of freedom per node: the nodes carry a rotation
  table ``kin.rot`` and a triad each);
* ``element="truss"``: axial force only (3 degrees of freedom per node), the
  stress of one material point per element from the material's group
  kernel, kept in the bar's co-rotating frame with the lateral stresses
  iterated to zero (``lateral_rtol``, ``lateral_iterations``), so every
  registered model (elastic, j2, ...) works.

Lumped masses :math:`\rho A L_0/2` per node and the isotropic rotary inertia
:math:`s\,\rho I_{max} L_0/2` (``rotary_inertia_scale`` s = 3: the beam runs
at the bar's step); ``energies()`` the strain energy plus what the optional
mass-proportional ``damping`` dissipated. The model and its tests:
docs/theory.md, "Beams and trusses".
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...integrate import drift, ordered_sum
from ...materials import get_model
from ...materials.base import young_modulus
from ...state import Elements, MaterialPoints, Nodes
from ...state.store import STATE
from ..base import register_part
from .beam import (N_RES, RES_L, RES_MY_A, RES_MY_B, RES_MZ_A, RES_MZ_B, RES_N, RES_T,
                   RES_VY, RES_VZ, beam_element_steps, beam_forces, beam_stable_dt,
                   drift_rotations, lateral_ratio, lateral_secant, mass_damping,
                   truss_element_steps, truss_forces, truss_gradient, truss_kinematics,
                   truss_stable_dt)
from .gather import gather_loads, node_element_list
from .solid_part import DEFAULTS
from .output import mesh_frame, mesh_summary


@dataclass(frozen=True)
class BeamSection:
    """Cross-section properties (SI units) in the section's local axes.

    ``area`` A [m^2]; ``iy`` = integral of z^2 dA and ``iz`` = integral of
    y^2 dA [m^4] (bending about the local y and z axes); ``j`` the torsion
    constant [m^4]; ``shear_factor`` kappa (shear area kappa A). Trusses use
    only ``area``.
    """

    area: float
    iy: float = 0.0
    iz: float = 0.0
    j: float = 0.0
    shear_factor: float = 5.0 / 6.0

    @classmethod
    def rectangle(cls, b: float, h: float, shear_factor: float = 5.0 / 6.0) -> "BeamSection":
        r"""Solid rectangle, width ``b`` along local y, height ``h`` along local z [m].

        :math:`A = bh`, :math:`I_y = bh^3/12`, :math:`I_z = hb^3/12`; the
        Saint-Venant torsion constant from the series solution of the Prandtl
        stress function (Timoshenko & Goodier 1970, *Theory of Elasticity*,
        sec. 109), ``a`` the long and ``c`` the short side:

        .. math:: J = \frac{a c^3}{3}\Big(1 - \frac{192}{\pi^5}\frac{c}{a}
                  \sum_{n = 1, 3, 5, \ldots} \frac{1}{n^5}
                  \tanh\frac{n\pi a}{2c}\Big)

        (terms to n = 199: truncation below 1e-11). Shear factor 5/6
        (Timoshenko 1921; Cowper 1966 gives :math:`10(1+\nu)/(12+11\nu)`,
        0.85 at :math:`\nu = 0.3`).
        """
        if b <= 0 or h <= 0:
            raise ValueError(f"rectangle sides must be > 0, got b={b}, h={h}")
        a, c = max(b, h), min(b, h)
        series = sum(math.tanh(n * math.pi * a / (2.0 * c)) / n ** 5 for n in range(1, 200, 2))
        j = a * c ** 3 / 3.0 * (1.0 - 192.0 / math.pi ** 5 * (c / a) * series)
        return cls(b * h, b * h ** 3 / 12.0, h * b ** 3 / 12.0, j, shear_factor)

    @classmethod
    def circle(cls, d: float, shear_factor: float = 0.9) -> "BeamSection":
        r"""Solid circle of diameter ``d`` [m]: :math:`A = \pi d^2/4`,
        :math:`I_y = I_z = \pi d^4/64`, :math:`J = \pi d^4/32`. Shear factor 0.9
        (Cowper 1966: :math:`6(1+\nu)/(7+6\nu)` = 0.886 at :math:`\nu` = 0.3, 6/7
        at 0; 0.9 is the common rounded value, e.g. Hutchinson 2001)."""
        if d <= 0:
            raise ValueError(f"circle diameter must be > 0, got {d}")
        return cls(math.pi * d * d / 4.0, math.pi * d ** 4 / 64.0, math.pi * d ** 4 / 64.0,
                   math.pi * d ** 4 / 32.0, shear_factor)


def element_frames(x: np.ndarray, conn: np.ndarray, orientation) -> np.ndarray:
    """Initial element frames (E, 3, 3), columns e1 (node a to b), e2, e3.

    e2 is the part of the orientation vector (3,) or (E, 3) normal to e1 (the
    section's local y axis, like the third node of LS-DYNA beams), e3 = e1 x e2.
    """
    d = x[conn[:, 1]] - x[conn[:, 0]]
    e1 = d / np.linalg.norm(d, axis=1)[:, None]
    o = np.broadcast_to(np.asarray(orientation, float), e1.shape)
    e2 = o - np.sum(o * e1, axis=1)[:, None] * e1
    n2 = np.linalg.norm(e2, axis=1)
    bad = np.flatnonzero(n2 <= 1e-8 * np.linalg.norm(o, axis=1))
    if bad.size:
        raise ValueError(f"the orientation vector is parallel to element(s) {bad[:5].tolist()}"
                         "; give one normal to the beam")
    e2 /= n2[:, None]
    e3 = np.cross(e1, e2)
    return np.ascontiguousarray(np.stack([e1, e2, e3], axis=2))


@register_part("line")
class LinePart:
    """Beams or trusses of one section and one material.

    Parameters
    ----------
    name : the part's name (history columns are prefixed with it).
    nodes : (N, 3) initial nodal coordinates [m].
    conn : (E, 2) node indices of the elements.
    element : ``"beam"`` (co-rotational elastic beam) or ``"truss"``.
    section : :class:`BeamSection`.
    material : ``(model, params)``: a registered model (or its name) and its
        packed parameter vector (or the dict its ``pack`` takes). Beams need
        the ``"elastic"`` model (their resultants are elastic); E = 9KG/(3K+G).
    orientation : (3,) or (E, 3), the section's local y direction (beams).
    rotary_inertia_scale : ``s`` of the lumped rotary inertia (module docstring).
    damping : mass-proportional damping coefficient [1/s] (0: none).
    dt_scale : safety factor on the element stable step.
    lateral_rtol, lateral_iterations : the truss's uniaxial-stress search.

    Boundary conditions: ``kin.bc``/``kin.bc_v`` (translations) and
    ``kin.rot.bc``/``kin.rot.bc_v`` (rotations), as for particles.
    """

    def __init__(self, name: str, nodes, conn, *, element: str = "beam",
                 section: BeamSection, material, orientation=(0.0, 0.0, 1.0),
                 rotary_inertia_scale: float = 3.0,
                 damping: float = DEFAULTS["damping"].default,
                 dt_scale: float = DEFAULTS["cfl"].default, lateral_rtol: float = 1e-10,
                 lateral_iterations: int = 8):
        if element not in ("beam", "truss"):
            raise ValueError(f"element must be 'beam' or 'truss', got {element!r}")
        self.name, self.element, self.section = name, element, section
        self.beam = element == "beam"
        xyz = np.ascontiguousarray(nodes, dtype=np.float64)
        conn = np.ascontiguousarray(conn, dtype=np.int64)
        if xyz.ndim != 2 or xyz.shape[1] != 3 or conn.ndim != 2 or conn.shape[1] != 2:
            raise ValueError("nodes must be (N, 3) and conn (E, 2)")
        if conn.size and (conn.min() < 0 or conn.max() >= xyz.shape[0]):
            raise ValueError("conn refers to nodes that do not exist")
        model, params = material
        self.model = get_model(model) if isinstance(model, str) else model
        self.params = (self.model.pack(params) if isinstance(params, dict)
                       else np.asarray(params, np.float64))
        if self.beam and not self.model.linear_elastic:
            raise ValueError(f"beams are elastic resultant beams; material model "
                             f"{self.model.name!r} is not 'elastic' (use a truss)")
        rho = self.model.density(self.params)
        K, G = self.model.bulk_modulus(self.params), self.model.shear_modulus(self.params)
        self.rho, self.G = rho, G
        self.E = young_modulus(K, G)
        self.k_lateral = 2.0 * (K + G / 3.0)  # d sigma_lat / d eps_lat (both lateral)
        self.nu = (3.0 * K - 2.0 * G) / (2.0 * (3.0 * K + G))
        A = section.area
        if A <= 0:
            raise ValueError(f"section area must be > 0, got {A}")
        if self.beam and min(section.iy, section.iz, section.j, section.shear_factor) <= 0:
            raise ValueError("a beam section needs iy, iz, j and shear_factor > 0")
        self.damping, self.dt_scale = float(damping), float(dt_scale)
        self.inertia_scale = float(rotary_inertia_scale)
        self.lateral_rtol, self.lateral_iterations = lateral_rtol, int(lateral_iterations)

        n, ne = xyz.shape[0], conn.shape[0]
        kin = self.kin = Nodes(n, 3, rotations=self.beam)
        kin.x = xyz
        kin.x0 = xyz
        el = self.elements = Elements(ne, 2)
        el.conn = conn
        L0 = np.linalg.norm(xyz[conn[:, 1]] - xyz[conn[:, 0]], axis=1)
        if ne and L0.min() <= 0:
            raise ValueError("elements of zero length")
        for nm, tail in (("L0", ()), ("l_prev", ()), ("energy", ()), ("res", (N_RES,))):
            el.add(nm, tail, kind=STATE)
        el.add("fe", (2, 6))
        el.L0 = L0
        el.l_prev = L0
        el.res[:, RES_L] = L0
        el.vol0 = A * L0
        el.vol = A * L0
        el.m = rho * A * L0
        np.add.at(kin.m, conn[:, 0], 0.5 * el.m)
        np.add.at(kin.m, conn[:, 1], 0.5 * el.m)
        self.ptr, self.ent = node_element_list(conn, n)
        kin.add("damp_power", ())
        self.e_damp = 0.0  # energy dissipated by the damping [J]
        if self.beam:
            self.frame0 = element_frames(xyz, conn, orientation)
            self.triad = np.tile(np.eye(3), (n, 1, 1))
            ir = self.inertia_scale * 0.5 * rho * max(section.iy, section.iz) * L0
            self.inertia_e = ir
            np.add.at(kin.rot.m, conn[:, 0], ir)
            np.add.at(kin.rot.m, conn[:, 1], ir)
            kappa_ga = section.shear_factor * G * A
            self.coef = {
                "EA": np.full(ne, self.E * A), "GJ": np.full(ne, G * section.j),
                "EIy": np.full(ne, self.E * section.iy), "EIz": np.full(ne, self.E * section.iz),
                "phi_y": 12.0 * self.E * section.iy / (kappa_ga * L0 ** 2),
                "phi_z": 12.0 * self.E * section.iz / (kappa_ga * L0 ** 2)}
        else:
            mp = self.points = MaterialPoints(ne, self.model.n_history)
            mp.hist_names = list(self.model.history_names)
            mp.elem = np.arange(ne)
            mp.rho0[:] = rho
            mp.rho[:] = rho
            mp.size = L0
            mp.c[:] = self.model.wave_speed(self.params, rho)
            mp.hist[:, :self.model.n_history] = self.model.initial_history(self.params)
            mp.add("ratio", (), kind=STATE, fill=-self.nu)  # lateral / axial rate
            for nm in ("eps_rate", "lat", "lat_old", "res_old", "l_now"):
                mp.add(nm, ())
            mp.add("done", (), np.int8)
            for nm in ("sig", "e", "hist", "damage", "c"):  # saved point state
                arr = getattr(mp, nm)
                mp.add("saved_" + nm, arr.shape[1:], arr.dtype)
            self.idx = np.arange(ne, dtype=np.int64)
            self.c_bar = math.sqrt(self.E / rho)
            self.lateral_unconverged = 0

    # ----------------------------------------------------------- protocol
    def stable_dt(self) -> tuple[float, int]:
        """Element-frequency bound (beams, :func:`.beam.beam_stable_dt`) or
        ``l / sqrt(E/rho)`` (trusses), times ``dt_scale``; and the element."""
        el, s = self.elements, self.section
        if self.beam:
            return beam_stable_dt(self.kin.x, el.conn, el.L0, self.rho, s.area, self.E,
                                  self.G, s.iy, s.iz, s.j, s.shear_factor, self.inertia_e,
                                  self.dt_scale, el.dt_mass)
        return truss_stable_dt(self.kin.x, el.conn, self.c_bar, self.dt_scale, el.dt_mass)

    def scale_mass(self, target: float, mask=None) -> dict[str, np.ndarray]:
        r"""Selective mass scaling (:mod:`sphdyn.mass_scaling`): each element whose
        own step :math:`\Delta t_e` (:func:`.beam.beam_element_steps`,
        :func:`.beam.truss_element_steps`) is below ``target`` gets the step factor
        :math:`g_e = \Delta t^*/\Delta t_e` (``dt_mass``) and :math:`g_e^2 - 1`
        times its share of the lumped masses, :math:`m_e/2` per node, and (beams)
        of the rotary inertias: every frequency of the element falls by
        :math:`g_e`. Returns the added masses per node [kg] and rotary inertias
        [kg m^2] (N,), by table name (``kin``, ``rot``). ``mask``
        is not used: a mesh is scaled whole."""
        el, s, kin = self.elements, self.section, self.kin
        dt = np.empty(el.n)
        if self.beam:
            beam_element_steps(kin.x, el.conn, el.L0, self.rho, s.area, self.E, self.G,
                               s.iy, s.iz, s.j, s.shear_factor, self.inertia_e,
                               self.dt_scale, dt)
        else:
            truss_element_steps(kin.x, el.conn, self.c_bar, self.dt_scale, dt)
        g = np.where(dt < (1.0 - 1e-9) * target, target / dt, 1.0)  # (1e-9: at it)
        el.dt_mass = g
        f = g * g - 1.0
        added = {"kin": np.zeros(kin.n)}
        for side in (0, 1):
            np.add.at(added["kin"], el.conn[:, side], 0.5 * f * el.m)
        if self.beam:
            added["rot"] = np.zeros(kin.n)
            for side in (0, 1):
                np.add.at(added["rot"], el.conn[:, side], f * self.inertia_e)
        return added

    @property
    def items_label(self) -> str:
        """What its items are called in a diagnosis (:mod:`sphdyn.watchers.monitors`)."""
        return f"node(s) of mesh '{self.name}'"

    def describe_limit(self, k: int) -> str:
        """What element ``k`` of :meth:`stable_dt` is, for a diagnosis."""
        centre = self.kin.x[self.elements.conn[k]].mean(axis=0)
        return (f"element {k} of line mesh '{self.name}' at "
                f"({', '.join(f'{c:.4g}' for c in centre)})")

    def start(self, dt: float) -> None:
        """Accelerations of the initial state (no material update)."""
        self._loads(update=False, dt=dt)

    def drift(self, dt: float) -> None:
        """Positions and (beams) triads to the end of the step."""
        kin = self.kin
        drift(kin.x, kin.v, dt)
        if self.beam:
            drift_rotations(self.triad, kin.rot.v, kin.rot.x, dt)

    def update_geometry(self, t: float, dt: float) -> None:
        """Trusses: chord length, strain rate and density of the new positions."""
        if not self.beam:
            el, mp = self.elements, self.points
            truss_kinematics(self.kin.x, el.conn, el.l_prev, el.L0, self.rho, dt, mp.l_now,
                             mp.eps_rate, mp.rho)

    def internal_forces(self, t: float, dt: float) -> None:
        """Resultants (beams) or material update (trusses), then ``kin.a`` and
        ``kin.rot.a`` (overwritten), and the damping's dissipation."""
        self._loads(update=True, dt=dt)
        if self.damping > 0.0:
            self.e_damp += dt * ordered_sum(self.kin.damp_power)

    def energies(self) -> tuple[float, float]:
        """Strain or material internal energy plus the damping's dissipation, and
        that dissipation [J]."""
        el = self.elements
        if self.beam:
            u = ordered_sum(el.energy)
        else:
            u = ordered_sum(el.m * self.points.e) if el.n else 0.0
        return u + self.e_damp, self.e_damp

    def columns(self) -> dict[str, float]:
        """``<name>_axial_force_max`` / ``_min`` [N] (tension positive) and, for
        beams, ``<name>_moment_max`` [N m], the largest end-moment magnitude;
        for trusses ``<name>_lateral_unconverged``, points whose lateral stress
        search did not converge in the last step."""
        res, p = self.elements.res, self.name
        if self.elements.n == 0:
            return {}
        out = {f"{p}_axial_force_max": float(res[:, RES_N].max()),
               f"{p}_axial_force_min": float(res[:, RES_N].min())}
        if self.beam:
            out[f"{p}_moment_max"] = float(np.sqrt(np.maximum(
                res[:, RES_MY_A] ** 2 + res[:, RES_MZ_A] ** 2,
                res[:, RES_MY_B] ** 2 + res[:, RES_MZ_B] ** 2)).max())
        else:
            out[f"{p}_lateral_unconverged"] = float(self.lateral_unconverged)
        return out

    def frame(self, fields=None):
        """The part's picture in an output frame, with the cell ``fields``
        named (:func:`.output.mesh_frame`)."""
        return mesh_frame(self, self.elements, "line2", fields)

    def summary(self) -> dict:
        """The part's entry in the run's summary (:func:`.output.mesh_summary`)."""
        return mesh_summary(self, self.elements)

    def fields(self) -> dict:
        """Cell fields: ``axial_force`` (E,) [N], ``axial_stress`` (E,) [Pa]
        (N/A for beams); beams: ``torque`` (E,), ``moment_y``, ``moment_z``
        (E, 2) end moments [N m], ``shear_y``, ``shear_z`` (E,) [N]; trusses:
        ``lateral_stress`` (E,) [Pa] and the material's history columns."""
        res, A = self.elements.res, self.section.area
        out = {"axial_force": lambda: res[:, RES_N].copy(),
               "axial_stress": lambda: res[:, RES_N] / A}
        if self.beam:
            out.update({"torque": lambda: res[:, RES_T].copy(),
                        "moment_y": lambda: res[:, [RES_MY_A, RES_MY_B]].copy(),
                        "moment_z": lambda: res[:, [RES_MZ_A, RES_MZ_B]].copy(),
                        "shear_y": lambda: res[:, RES_VY].copy(),
                        "shear_z": lambda: res[:, RES_VZ].copy()})
        else:
            mp = self.points
            out["lateral_stress"] = lambda: 0.5 * (mp.sig[:, 1, 1] + mp.sig[:, 2, 2])
            for k, nm in enumerate(self.model.history_names):
                out[nm] = (lambda k=k: mp.hist[:, k].copy())
        return out

    def state(self) -> tuple[dict, dict[str, np.ndarray]]:
        """Triads (beams), element data and material points (trusses)."""
        arrays = {f"el_{k}": v for k, v in self.elements.arrays().items()}
        if self.beam:
            arrays["triad"] = self.triad
        else:
            arrays.update({f"mp_{k}": v for k, v in self.points.arrays().items()})
        return {"e_damp": self.e_damp}, arrays

    def restore(self, scalars: dict, arrays: dict[str, np.ndarray]) -> None:
        """Continue from :meth:`state` (bitwise identical continuation)."""
        self.e_damp = float(scalars["e_damp"])
        for k, v in arrays.items():
            if k == "triad":
                self.triad[...] = v
            elif k.startswith("el_"):
                setattr(self.elements, k[3:], v)
            elif k.startswith("mp_"):
                setattr(self.points, k[3:], v)

    # ------------------------------------------------------------- passes
    def _loads(self, update: bool, dt: float) -> None:
        kin, el = self.kin, self.elements
        if self.beam:
            c = self.coef
            beam_forces(kin.x, self.triad, el.conn, self.frame0, el.L0, c["EA"], c["GJ"],
                        c["EIy"], c["EIz"], c["phi_y"], c["phi_z"], el.fe, el.res, el.energy)
        else:
            if update:
                self._uniaxial_update(dt)
                el.l_prev = self.points.l_now
            truss_forces(kin.x, el.conn, self.points.sig, self.section.area, el.fe, el.res)
        gather_loads(el.fe, 0, self.ptr, self.ent, kin.m, kin.a)
        if self.beam:
            gather_loads(el.fe, 3, self.ptr, self.ent, kin.rot.m, kin.rot.a)
        if self.damping > 0.0:
            kin.damp_power[:] = 0.0
            mass_damping(kin.v, kin.m, self.damping, kin.a, kin.damp_power)
            if self.beam:
                mass_damping(kin.rot.v, kin.rot.m, self.damping, kin.rot.a, kin.damp_power)

    def _uniaxial_update(self, dt: float) -> None:
        """Material update of the truss points under uniaxial stress (module docstring)."""
        mp, m = self.points, self.model
        names = ("sig", "e", "hist", "damage", "c")
        for nm in names:
            np.copyto(getattr(mp, "saved_" + nm), getattr(mp, nm))
        np.multiply(mp.ratio, mp.eps_rate, out=mp.lat)
        left = 0
        for it in range(self.lateral_iterations):
            if it:
                for nm in names:
                    np.copyto(getattr(mp, nm), getattr(mp, "saved_" + nm))
            truss_gradient(mp.eps_rate, mp.lat, mp.L)
            m.update(self.idx, mp.L, dt, mp.rho, mp.sig, mp.e, mp.c, mp.damage, mp.hist,
                     self.params, mp.size)
            left = lateral_secant(mp.sig, mp.eps_rate, mp.lat, mp.lat_old, mp.res_old,
                                  it == 0, self.k_lateral, dt, self.lateral_rtol, mp.done)
            if left == 0:
                break
        if left:  # the last update stands: its rates, not the next trials, are kept
            np.copyto(mp.lat, mp.lat_old, where=mp.done == 0)
        self.lateral_unconverged = left
        lateral_ratio(mp.lat, mp.eps_rate, mp.ratio)
