"""A keyword deck as a sphdyn deck: each keyword's fields onto the deck's
tables, the rest reported.

Which keyword becomes what, and the differences a user must know:
docs/lsdyna.md (its table is this module's :data:`HANDLED`). Numbers are
converted to SI with the deck's unit system (:mod:`sphdyn.lsdyna.units`)
and written with their SI units, so the written deck reads without the
keyword file. Every keyword, option or field that is not mapped is one
:class:`Dropped` item: ``physics`` says whether leaving it out changes the
result (``sphdyn import`` then fails unless ``--allow-partial``).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

import numpy as np

from .reader import Keyword, KeywordDeck
from .scan import KeywordError, node_list, solid_elements, sph_elements
from .units import Units

#: MAT_CSCM_CONCRETE's UNITS field -> the unit system it means
CSCM_UNITS = {0: "mm-ms-kg", 1: "mm-ms-g", 2: "mm-s-t", 4: "m-s-kg"}

#: SECTION_SOLID ELFORM -> [[mesh]] integration
ELFORM = {1: "one_point", 2: "selective_reduced"}

#: Keywords that only control LS-DYNA's own output or bookkeeping: read,
#: nothing to map, not reported
SILENT = ("DATABASE_GLSTAT", "DATABASE_MATSUM", "DATABASE_EXTENT_BINARY",
          "CONTROL_ENERGY", "CONTROL_OUTPUT", "CONTROL_HOURGLASS")


@dataclass
class Dropped:
    """A keyword or field not carried over: where, what it means, what
    sphdyn does instead, whether the result changes."""

    where: str
    what: str
    instead: str
    physics: bool

    def line(self) -> str:
        mark = "changes the result" if self.physics else "no effect on the result"
        return f"{self.where}: {self.what}; {self.instead} ({mark})"


@dataclass
class Imported:
    """The deck as a dictionary (TOML tables), the data files to write beside
    it (name -> contents: an (n, 3) array of points for ``.csv``, a
    ``meshio.Mesh`` for ``.inp``) and what was dropped."""

    deck: dict
    files: dict = field(default_factory=dict)
    dropped: list[Dropped] = field(default_factory=list)


def _name(text, fallback: str) -> str:
    """A deck name from a part or material title: letters, digits and ``_``."""
    text = text if isinstance(text, str) else ""  # a blank heading reads as NaN
    s = re.sub(r"[^A-Za-z0-9_]+", "_", text.strip()).strip("_")
    return s if s and not s[0].isdigit() else fallback


def _q(value: float, unit: str) -> str:
    """A quantity string with all the value's digits."""
    return f"{float(value)!r} {unit}"


def _num(value, default=0.0) -> float:
    """A field as a float, a blank one as ``default``."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        return default
    return default if math.isnan(v) else v


def _int(value, default=0) -> int:
    v = _num(value, float(default))
    return int(v)


def _round_spacing(dx: float) -> float:
    """A spacing recovered from a mass, rounded to 12 significant digits (a
    keyword file prints masses with at most 16; the rounding gives back the
    spacing the particles were made with)."""
    return float(f"{dx:.12g}")


class Converter:
    """One pass over the keywords, then the deck (:meth:`deck`)."""

    def __init__(self, kd: KeywordDeck, units: Units, stem: str):
        self.kd, self.u, self.stem = kd, units, stem
        self.dropped: list[Dropped] = []
        self.nodes: dict[int, tuple[float, float, float]] = {}
        self.solids: list[tuple[int, int, tuple[int, ...]]] = []  # eid, pid, nodes
        self.sph: list[tuple[int, int, float]] = []                # nid, pid, mass
        self.parts: dict[int, dict] = {}
        self.sections: dict[int, dict] = {}
        self.materials: dict[int, dict] = {}
        self.density: dict[int, float] = {}  # mid -> [kg/m^3]
        self.node_sets: dict[int, list[int]] = {}
        self.spcs: list[tuple[str, list[int] | int, tuple[str, ...]]] = []
        self.velocities: list[tuple[int, int, tuple[float, float, float]]] = []  # STYP, ID, v
        self.walls: list[dict] = []
        self.run: dict = {"title": kd.title, "dimension": 3}
        self.output: dict = {}
        self.tssfac: float | None = None

    # -- reading ---------------------------------------------------------------
    def drop(self, kw: Keyword, what: str, instead: str, physics: bool = True) -> None:
        self.dropped.append(Dropped(kw.block.where(), what, instead, physics))

    def read(self) -> None:
        for kw in self.kd.keywords:
            handler = HANDLED.get(re.sub(r"_TITLE$", "", kw.name))
            if handler is not None:
                handler(self, kw)
            elif kw.name not in SILENT:
                self.drop(kw, "a keyword sphdyn does not import yet",
                          "ignored (docs/lsdyna.md lists what is imported)",
                          physics=not kw.name.startswith(("DATABASE_", "COMMENT")))

    def node(self, kw):
        for row in kw.obj.nodes.itertuples(index=False):
            self.nodes[int(row.nid)] = (row.x * self.u.length, row.y * self.u.length,
                                        row.z * self.u.length)

    def element_solid(self, kw):
        for eid, pid, ns in solid_elements(kw.block, self.kd.long):
            if len(set(ns)) != 8:
                raise KeywordError(f"{kw.block.where()}: element {eid} is not an "
                                   "eight-node hexahedron (repeated nodes: a "
                                   "tetrahedron, pentahedron or collapsed element); "
                                   "sphdyn's solids are hexahedra")
            self.solids.append((eid, pid, ns))

    def element_sph(self, kw):
        self.sph.extend(sph_elements(kw.block, self.kd.long))

    def part(self, kw):
        for row in kw.obj.parts.itertuples(index=False):
            pid = int(row.pid)
            self.parts[pid] = {"title": row.heading, "secid": _int(row.secid),
                               "mid": _int(row.mid), "kw": kw}
            if _int(row.eosid) or _int(row.hgid):
                self.drop(kw, f"part {pid}: EOSID / HGID (an equation of state or an "
                          "hourglass card)", "the material's own pressure and "
                          "[[mesh]]'s hourglass control are used")

    def section_solid(self, kw):
        o = kw.obj
        elform = _int(o.elform, 1)
        self.sections[int(o.secid)] = {"kind": "solid", "elform": elform, "kw": kw}
        if elform not in ELFORM:
            self.drop(kw, f"ELFORM = {elform}", "sphdyn's hexahedra are ELFORM 1 "
                      "(one point) or 2 (selective reduced); taken as 1")

    def section_sph(self, kw):
        o = kw.obj
        if _num(o.sphini):
            self.drop(kw, "SPHINI (a given initial smoothing length)",
                      "h = CSLH times the particle spacing")
        self.sections[int(o.secid)] = {"kind": "sph", "cslh": _num(o.cslh, 1.2),
                                       "hmin": _num(o.hmin, 0.2),
                                       "hmax": _num(o.hmax, 2.0), "kw": kw}

    def mat_elastic(self, kw):
        o = kw.obj
        if _num(o.da) or _num(o.db):
            self.drop(kw, "DA / DB (axial and bending damping of beams)", "none")
        self._material(kw, {"model": "elastic", "density": _q(o.ro * self.u.density,
                                                              "kg/m^3"),
                            "E": _q(o.e * self.u.stress, "Pa"), "nu": float(o.pr)})

    def mat_plastic_kinematic(self, kw):
        o = kw.obj
        beta = _num(o.beta, 0.0)
        if beta != 1.0:
            self.drop(kw, f"BETA = {beta:g} (kinematic hardening)", "isotropic "
                      "hardening (sphdyn's j2 is BETA = 1)")
        if _num(o.src) or _num(o.srp):
            self.drop(kw, "SRC / SRP (Cowper-Symonds rate effects)", "no rate effects")
        if _num(o.fs):
            self.drop(kw, "FS (failure strain)", "no failure")
        E, Et = o.e * self.u.stress, _num(o.etan) * self.u.stress
        self._material(kw, {"model": "j2", "density": _q(o.ro * self.u.density,
                                                         "kg/m^3"),
                            "E": _q(E, "Pa"), "nu": float(o.pr),
                            "yield_stress": _q(o.sigy * self.u.stress, "Pa"),
                            # the plastic modulus H of the bilinear curve whose
                            # slope past yield is ETAN: Et = E H / (E + H)
                            "hardening_modulus": _q(E * Et / (E - Et), "Pa")})

    def mat_cscm_concrete(self, kw):
        o = kw.obj
        units = _int(o.units, 0)
        if CSCM_UNITS.get(units) != self.u.name:
            raise KeywordError(f"{kw.block.where()}: UNITS = {units} "
                               f"({CSCM_UNITS.get(units, 'inch-pound')}) disagrees with "
                               f"--units {self.u.name}: FPC and DAGG are read in UNITS; "
                               "give --units as the deck's consistent system")
        m = {"model": "cscm", "density": _q(o.ro * self.u.density, "kg/m^3"),
             "fc": _q(o.fpc * self.u.stress, "Pa"),
             "aggregate_size": _q(o.dagg * self.u.length, "m"),
             "rate_effects": _int(o.irate) == 1}
        erode = _num(o.erode)
        if erode >= 1.0:
            m["erode"], m["erode_strain"] = True, float(f"{erode - 1.0:.12g}")
        if _num(o.recov):
            m["recovery"] = _num(o.recov)
        if _int(o.itretrc):
            m["cap_retraction"] = True
        if _num(o.incre):
            m["incre"] = _num(o.incre)
        if _num(o.pred):
            self.drop(kw, "PRED (pre-existing damage)", "none")
        self._material(kw, m)

    def _material(self, kw, values: dict) -> None:
        mid = int(kw.obj.mid)
        self.density[mid] = float(kw.obj.ro) * self.u.density
        title = getattr(kw.obj, "title", None) if "TITLE" in kw.block.title.upper() else None
        self.materials[mid] = {"name": _name(title, f"mat{mid}"), **values}

    def set_node_list(self, kw):
        sid, nodes = node_list(kw.block, self.kd.long)
        self.node_sets[sid] = nodes

    def boundary_spc_set(self, kw):
        o = kw.obj
        self.spcs.append((kw.block.where(), int(o.nsid), self._dofs(kw, o)))

    def boundary_spc_node(self, kw):
        for row in kw.obj.nodes.itertuples(index=False):
            self.spcs.append((kw.block.where(), [int(row.nid)], self._dofs(kw, row)))

    def _dofs(self, kw, o) -> tuple[str, ...]:
        if _int(getattr(o, "cid", 0)):
            self.drop(kw, "CID (a local coordinate system)", "the global axes")
        return tuple(a for a in "xyz" if _int(getattr(o, f"dof{a}")))

    def initial_velocity_generation(self, kw):
        o = kw.obj
        if _num(o.omega):
            self.drop(kw, "OMEGA (an initial rotation)", "no rotation")
        v = tuple(_num(getattr(o, f"v{a}")) * self.u.velocity for a in "xyz")
        styp, ident = _int(o.styp, 2), _int(o.id)
        if ident and styp != 2:
            self.drop(kw, f"STYP = {styp} (a {'part' if styp == 1 else 'node'} set)",
                      "no initial velocity from it (a part, STYP = 2, or ID = 0 is "
                      "imported)")
            return
        self.velocities.append((styp, ident, v))

    def initial_velocity(self, kw):
        """``*INITIAL_VELOCITY``: with NSID = 0 every node and particle (the
        same as ``*INITIAL_VELOCITY_GENERATION`` with ID = 0); a node set, an
        exempted set or a box is listed."""
        o = kw.obj
        if _int(o.nsid) or _int(o.nsidex) or _int(o.boxid):
            self.drop(kw, "NSID / NSIDEX / BOXID (a velocity for some nodes)",
                      "no initial velocity from it (NSID = 0, every node, is imported)")
            return
        if any(_num(getattr(o, f"v{a}r")) for a in "xyz"):
            self.drop(kw, "VXR / VYR / VZR (rotational velocities of beam nodes)", "none")
        v = tuple(_num(getattr(o, f"v{a}")) * self.u.velocity for a in "xyz")
        self.velocities.append((2, 0, v))

    def rigidwall_planar(self, kw):
        o = kw.obj
        tail = np.array([_num(o.xt), _num(o.yt), _num(o.zt)])
        head = np.array([_num(o.xh), _num(o.yh), _num(o.zh)])
        fric = _num(o.fric)
        if _int(o.nsid) or _int(o.nsidex) or _int(o.boxid):
            self.drop(kw, "NSID / NSIDEX / BOXID (the nodes the wall acts on)",
                      "the wall acts on every particle")
        if fric >= 1.0:
            self.drop(kw, f"FRIC = {fric:g} (sticking or welding)", "no friction")
            fric = 0.0
        self.walls.append({"name": f"wall{len(self.walls) + 1}",
                           "point": [_q(c * self.u.length, "m") for c in tail],
                           "normal": [float(c) for c in head - tail],
                           "friction": fric})

    def control_termination(self, kw):
        self.run["t_end"] = _q(kw.obj.endtim * self.u.time, "s")

    def control_timestep(self, kw):
        o = kw.obj
        if _num(o.tssfac):
            self.tssfac = _num(o.tssfac)
        if _num(o.dt2ms):
            self.drop(kw, "DT2MS (mass scaling)", "none ([time.mass_scaling] is "
                      "sphdyn's selective form)")

    def control_sph(self, kw):
        form = _int(kw.obj.form)
        if form:
            self.drop(kw, f"FORM = {form}", "sphdyn's default formulation (the "
                      "updated-Lagrangian kernel, FORM = 0)")

    def database_binary_d3plot(self, kw):
        if _num(kw.obj.dt):
            self.output["every"] = _q(kw.obj.dt * self.u.time, "s")

    def parameter(self, kw):
        """Read by the library, which substitutes the values."""

    # -- the deck --------------------------------------------------------------
    def deck(self) -> Imported:
        if "t_end" not in self.run:
            raise KeywordError(f"{self.kd.path}: no *CONTROL_TERMINATION with ENDTIM "
                               "(the end time)")
        out = Imported({"run": self.run})
        used = sorted({self.parts[p]["mid"] for p in self._pids()})
        missing = [m for m in used if m not in self.materials]
        if missing:
            raise KeywordError(f"{self.kd.path}: material {missing[0]} is used by a part "
                               "but not defined by a *MAT_ keyword sphdyn imports")
        out.deck["material"] = [dict(self.materials[m]) for m in used]
        self._bodies(out)
        self._meshes(out)
        if self.walls:
            out.deck["wall"] = self.walls
        if self.output:
            out.deck["output"] = self.output
        out.dropped = self.dropped
        return out

    def _pids(self) -> list[int]:
        pids = {pid for _, pid, _ in self.solids} | {pid for _, pid, _ in self.sph}
        for pid in sorted(pids):
            if pid not in self.parts:
                raise KeywordError(f"{self.kd.path}: elements of part {pid}, which no "
                                   "*PART defines")
        return sorted(pids)

    def _section(self, pid: int, kind: str) -> dict:
        p = self.parts[pid]
        sec = self.sections.get(p["secid"])
        if sec is None or sec["kind"] != kind:
            raise KeywordError(f"{p['kw'].block.where()}: part {pid} has no "
                               f"*SECTION_{kind.upper()} {p['secid']} (its elements are "
                               f"{'solids' if kind == 'solid' else 'SPH particles'})")
        return sec

    def _mat_name(self, pid: int) -> str:
        return self.materials[self.parts[pid]["mid"]]["name"]

    def _part_name(self, pid: int) -> str:
        return _name(self.parts[pid]["title"], f"part{pid}")

    def _velocity(self, pid: int) -> tuple[float, float, float] | None:
        for styp, ident, v in self.velocities:
            if ident == 0 or (styp == 2 and ident == pid):
                return v
        return None

    def _bodies(self, out: Imported) -> None:
        pids = sorted({pid for _, pid, _ in self.sph})
        if not pids:
            return
        nid = np.array([n for n, _, _ in self.sph])
        pid_of = np.array([p for _, p, _ in self.sph])
        mass = np.array([m for _, _, m in self.sph])
        unknown = [n for n in nid if n not in self.nodes]
        if unknown:
            raise KeywordError(f"{self.kd.path}: *ELEMENT_SPH names node {unknown[0]}, "
                               "which no *NODE defines")
        bodies, cslh = [], set()
        for pid in pids:
            sec = self._section(pid, "sph")
            cslh.add((sec["cslh"], sec["hmin"], sec["hmax"]))
            rho = self.density[self.parts[pid]["mid"]]
            sel = pid_of == pid
            m = np.where(mass[sel] < 0, -mass[sel] * self.u.length ** 3 * rho,
                         mass[sel] * self.u.mass)
            vol = m / rho
            if np.ptp(vol) > 1e-9 * vol.max():
                self.drop(self.parts[pid]["kw"], f"part {pid}: particles of "
                          f"{vol.min():.4g} to {vol.max():.4g} m^3 (unequal masses)",
                          "every particle of a body has the mean volume")
            dx = _round_spacing(float(np.mean(vol)) ** (1.0 / 3.0))
            name = self._part_name(pid)
            file = f"{self.stem}_{name}.csv"
            x = np.array([self.nodes[n] for n in nid[sel]])
            out.files[file] = x
            body = {"name": name, "material": self._mat_name(pid), "dx": _q(dx, "m"),
                    "geometry": {"shape": "points", "file": file}}
            v = self._velocity(pid)
            if v is not None:
                body["velocity"] = [_q(c, "m/s") for c in v]
            bodies.append(body)
        out.deck["body"] = bodies
        (cs, hmin, hmax), *more = sorted(cslh)
        if more:
            self.drop(self.parts[pids[0]]["kw"], "different CSLH, HMIN or HMAX per "
                      "part", f"the first part's for all ({cs:g}, {hmin:g}, {hmax:g})")
        out.deck["sph"] = {"h_factor": cs,
                           "smoothing_length": {"min_factor": hmin, "max_factor": hmax}}

    def _meshes(self, out: Imported) -> None:
        if not self.solids:
            return
        import meshio

        pids = sorted({pid for _, pid, _ in self.solids})
        forms = {pid: ELFORM.get(self._section(pid, "solid")["elform"], "one_point")
                 for pid in pids}
        if len(set(forms.values())) > 1:
            self.drop(self.parts[pids[0]]["kw"], "solid parts of different ELFORM",
                      f"{forms[pids[0]]} for all (one mesh)")
        conn = np.array([ns for _, _, ns in self.solids])
        used = np.unique(conn)
        unknown = [n for n in used if n not in self.nodes]
        if unknown:
            raise KeywordError(f"{self.kd.path}: *ELEMENT_SOLID names node {unknown[0]}, "
                               "which no *NODE defines")
        index = {int(n): k for k, n in enumerate(used)}
        points = np.array([self.nodes[int(n)] for n in used])
        cells = np.vectorize(index.__getitem__)(conn)
        pid_of = np.array([pid for _, pid, _ in self.solids])
        cell_sets = {f"part{pid}": [np.flatnonzero(pid_of == pid)] for pid in pids}
        point_sets = {}
        name = "solids"
        sets, boundaries = [], []
        for k, (where, ref, dofs) in enumerate(self.spcs, start=1):
            nodes = self.node_sets.get(ref) if isinstance(ref, int) else ref
            if nodes is None:
                raise KeywordError(f"{where}: node set {ref}, which no *SET_NODE_LIST "
                                   "defines")
            on = [index[n] for n in nodes if n in index]
            if len(on) != len(nodes):
                self.dropped.append(Dropped(where, "constraints on nodes that are not "
                                            "a solid element's (SPH particles)",
                                            "those nodes are free", True))
            if not on or not dofs:
                continue
            group = f"spc{k}"
            point_sets[group] = np.array(on)
            sets.append({"name": group, "mesh": name, "group": group})
            boundaries.append({"set": group, "type": "fixed", "components": list(dofs)})
        file = f"{self.stem}_{name}.inp"
        out.files[file] = meshio.Mesh(points, [("hexahedron", cells)],
                                      cell_sets=cell_sets, point_sets=point_sets)
        mesh = {"name": name, "file": file, "integration": forms[pids[0]],
                "group": [{"name": f"part{pid}", "material": self._mat_name(pid)}
                          for pid in pids]}
        if self.tssfac is not None:
            mesh["cfl"] = self.tssfac
        vs = {self._velocity(pid) for pid in pids}
        if len(vs) > 1:
            self.drop(self.parts[pids[0]]["kw"], "different initial velocities of the "
                      "solid parts", "the first part's for the mesh")
        v = self._velocity(pids[0])
        if v is not None:
            mesh["velocity"] = [_q(c, "m/s") for c in v]
        out.deck["mesh"] = [mesh]
        if sets:
            out.deck["set"] = sets
            out.deck["boundary"] = boundaries


#: keyword (without options) -> its reader
HANDLED = {
    "NODE": Converter.node,
    "ELEMENT_SOLID": Converter.element_solid,
    "ELEMENT_SPH": Converter.element_sph,
    "PART": Converter.part,
    "SECTION_SOLID": Converter.section_solid,
    "SECTION_SPH": Converter.section_sph,
    "MAT_ELASTIC": Converter.mat_elastic,
    "MAT_001": Converter.mat_elastic,
    "MAT_PLASTIC_KINEMATIC": Converter.mat_plastic_kinematic,
    "MAT_003": Converter.mat_plastic_kinematic,
    "MAT_CSCM_CONCRETE": Converter.mat_cscm_concrete,
    "SET_NODE_LIST": Converter.set_node_list,
    "BOUNDARY_SPC_SET": Converter.boundary_spc_set,
    "BOUNDARY_SPC_NODE": Converter.boundary_spc_node,
    "INITIAL_VELOCITY_GENERATION": Converter.initial_velocity_generation,
    "INITIAL_VELOCITY": Converter.initial_velocity,
    "RIGIDWALL_PLANAR": Converter.rigidwall_planar,
    "CONTROL_TERMINATION": Converter.control_termination,
    "CONTROL_TIMESTEP": Converter.control_timestep,
    "CONTROL_SPH": Converter.control_sph,
    "DATABASE_BINARY_D3PLOT": Converter.database_binary_d3plot,
    "PARAMETER": Converter.parameter,
}


def convert(kd: KeywordDeck, units: Units, stem: str) -> Imported:
    """The sphdyn deck of a keyword deck read by
    :func:`~sphdyn.lsdyna.reader.read_keyword_deck`."""
    c = Converter(kd, units, stem)
    c.read()
    return c.deck()
