"""A keyword deck as a sphdyn deck: each keyword's fields onto the deck's
tables, the rest reported.

Which keyword becomes what, and the differences a user must know:
docs/lsdyna.md (its table is this module's :data:`HANDLED`). The model's
keywords (nodes, elements, parts, sections, sets, controls) are read here,
the materials in :mod:`.materials`, the loads, conditions, couplings and
erosion in :mod:`.conditions`. Numbers are
converted to SI with the deck's unit system (:mod:`sphdyn.lsdyna.units`)
and written with their SI units, so the written deck reads without the
keyword file. Every keyword, option or field that is not mapped is one
:class:`Dropped` item: ``physics`` says whether leaving it out changes the
result (``sphdyn import`` then fails unless ``--allow-partial``).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from .conditions import ConditionKeywords
from .fields import integer, name_of, number, quantity, round_spacing
from .materials import MaterialKeywords
from .reader import Keyword, KeywordDeck
from .scan import KeywordError, id_list, solid_elements, sph_elements
from .units import Units


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


class Converter(MaterialKeywords, ConditionKeywords):
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
        self.part_sets: dict[int, list[int]] = {}
        self.spcs: list[tuple[str, list[int] | int, tuple[str, ...]]] = []
        # (what: "all", "part", "part_set" or "node_set", its id, v [m/s], keyword)
        self.velocities: list[tuple[str, int, tuple[float, float, float], Keyword]] = []
        self.curves: dict[int, tuple[np.ndarray, np.ndarray] | str] = {}  # or why not
        self.yield_curves: list[tuple[int, int, Keyword]] = []  # MID, LCSS
        self.eos: dict[int, tuple[str, dict, Keyword]] = {}  # EOSID -> kind, keys
        self.detonations: list[tuple] = []  # PID, point, time [s], keyword
        self.erosion_rules: dict[int, dict] = {}  # MID -> [material.erosion]
        self.adaptive: list[tuple[int, int, int, Keyword]] = []  # IPID, ITYPE, per
        self.body_loads: list[tuple[int, int, float, Keyword]] = []  # axis, LCID, SF
        self.body_load_parts: list[tuple[int, Keyword]] = []  # PSID
        # NSID (or a list of nodes), axis, "velocity" or "displacement", LCID, SF,
        # (birth, death) [s], keyword
        self.motions: list[tuple] = []
        self.contacts: list[tuple[tuple[int, int], tuple[int, int], float, Keyword]] = []
        self.t_end = 0.0  # [s]
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
            self.parts[pid] = {"title": row.heading, "secid": integer(row.secid),
                               "mid": integer(row.mid), "eosid": integer(row.eosid), "kw": kw}
            if integer(row.hgid):
                self.drop(kw, f"part {pid}: HGID (an hourglass card)",
                          "[[mesh]]'s hourglass control")

    def section_solid(self, kw):
        o = kw.obj
        elform = integer(o.elform, 1)
        self.sections[int(o.secid)] = {"kind": "solid", "elform": elform, "kw": kw}
        if elform not in ELFORM:
            self.drop(kw, f"ELFORM = {elform}", "sphdyn's hexahedra are ELFORM 1 "
                      "(one point) or 2 (selective reduced); taken as 1")

    def section_sph(self, kw):
        o = kw.obj
        if number(o.sphini):
            self.drop(kw, "SPHINI (a given initial smoothing length)",
                      "h = CSLH times the particle spacing")
        self.sections[int(o.secid)] = {"kind": "sph", "cslh": number(o.cslh, 1.2),
                                       "hmin": number(o.hmin, 0.2),
                                       "hmax": number(o.hmax, 2.0), "kw": kw}

    def set_node_list(self, kw):
        sid, nodes = id_list(kw.block, self.kd.long)
        self.node_sets[sid] = nodes

    def set_part_list(self, kw):
        sid, pids = id_list(kw.block, self.kd.long)
        self.part_sets[sid] = pids

    def boundary_spc_set(self, kw):
        o = kw.obj
        self.spcs.append((kw.block.where(), int(o.nsid), self._dofs(kw, o)))

    def boundary_spc_node(self, kw):
        for row in kw.obj.nodes.itertuples(index=False):
            self.spcs.append((kw.block.where(), [int(row.nid)], self._dofs(kw, row)))

    def _dofs(self, kw, o) -> tuple[str, ...]:
        if integer(getattr(o, "cid", 0)):
            self.drop(kw, "CID (a local coordinate system)", "the global axes")
        return tuple(a for a in "xyz" if integer(getattr(o, f"dof{a}")))

    def rigidwall_planar(self, kw):
        o = kw.obj
        tail = np.array([number(o.xt), number(o.yt), number(o.zt)])
        head = np.array([number(o.xh), number(o.yh), number(o.zh)])
        fric = number(o.fric)
        if integer(o.nsid) or integer(o.nsidex) or integer(o.boxid):
            self.drop(kw, "NSID / NSIDEX / BOXID (the nodes the wall acts on)",
                      "the wall acts on every particle")
        if fric >= 1.0:
            self.drop(kw, f"FRIC = {fric:g} (sticking or welding)", "no friction")
            fric = 0.0
        self.walls.append({"name": f"wall{len(self.walls) + 1}",
                           "point": [quantity(c * self.u.length, "m") for c in tail],
                           "normal": [float(c) for c in head - tail],
                           "friction": fric})

    def control_termination(self, kw):
        self.t_end = kw.obj.endtim * self.u.time
        self.run["t_end"] = quantity(self.t_end, "s")

    def control_timestep(self, kw):
        o = kw.obj
        if number(o.tssfac):
            self.tssfac = number(o.tssfac)
        if number(o.dt2ms):
            self.drop(kw, "DT2MS (mass scaling)", "none ([time.mass_scaling] is "
                      "sphdyn's selective form)")

    def control_sph(self, kw):
        form = integer(kw.obj.form)
        if form:
            self.drop(kw, f"FORM = {form}", "sphdyn's default formulation (the "
                      "updated-Lagrangian kernel, FORM = 0)")
        if integer(kw.obj.deriv):
            self.drop(kw, f"DERIV = {integer(kw.obj.deriv)} (h from the cube root of the "
                      "divergence)", "dh/dt = h div(v) / d (DERIV = 0)")

    def database_binary_d3plot(self, kw):
        if number(kw.obj.dt):
            self.output["every"] = quantity(kw.obj.dt * self.u.time, "s")

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
        for mid, lcid, kw in self.yield_curves:
            curve = self.curves.get(lcid)
            if curve is None:
                raise KeywordError(f"{kw.block.where()}: curve {lcid}, which no "
                                   "*DEFINE_CURVE defines")
            if isinstance(curve, str):
                raise KeywordError(f"{kw.block.where()}: LCSS {lcid}: {curve}")
            self._yield_line(kw, mid, *curve)
        self._with_eos(self._pids())
        for mid, rules in self.erosion_rules.items():
            if mid in self.materials and rules:
                self.materials[mid]["erosion"] = dict(rules)
        out.deck["material"] = [dict(self.materials[m]) for m in used]
        for pid, point, lt, kw in self.detonations:
            d = {"point": point, "time": quantity(lt, "s")}
            if pid:
                if pid not in self.parts:
                    raise KeywordError(f"{kw.block.where()}: part {pid}, which no "
                                       "*PART defines")
                d["material"] = self._mat_name(pid)
            out.deck.setdefault("detonation", []).append(d)
        self.initial_v = self._initial_velocities()
        self._gravity()
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
        return name_of(self.parts[pid]["title"], f"part{pid}")

    def _velocity(self, pid: int) -> tuple[float, float, float] | None:
        return self.initial_v.get(pid)

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
            dx = round_spacing(float(np.mean(vol)) ** (1.0 / 3.0))
            name = self._part_name(pid)
            file = f"{self.stem}_{name}.csv"
            x = np.array([self.nodes[n] for n in nid[sel]])
            out.files[file] = x
            body = {"name": name, "material": self._mat_name(pid), "dx": quantity(dx, "m"),
                    "geometry": {"shape": "points", "file": file}}
            v = self._velocity(pid)
            if v is not None:
                body["velocity"] = [quantity(c, "m/s") for c in v]
            bodies.append(body)
        out.deck["body"] = bodies
        (cs, hmin, hmax), *more = sorted(cslh)
        if more:
            self.drop(self.parts[pids[0]]["kw"], "different CSLH, HMIN or HMAX per "
                      "part", f"the first part's for all ({cs:g}, {hmin:g}, {hmax:g})")
        out.deck["sph"] = {"h_factor": cs, "smoothing_length": self._smoothing(hmin, hmax)}

    def _smoothing(self, hmin: float, hmax: float) -> dict:
        """[sph.smoothing_length] of SECTION_SPH's HMIN, HMAX: LS-DYNA
        recomputes h every cycle from the velocity divergence, within HMIN
        and HMAX times the initial h, and keeps it constant with HMIN = HMAX
        = 1 (S. Bala, "Smoothing length in SPH", d3view, 2007): sphdyn's
        "benz" rule dh/dt = h div(v) / d, or "constant"."""
        if hmin == hmax == 1.0:
            return {"mode": "constant"}
        return {"mode": "benz", "min_factor": hmin, "max_factor": hmax}

    def _meshes(self, out: Imported) -> None:
        if not self.solids:
            for *_, kw in self.contacts:
                self.drop(kw, "a contact without solid elements", "none")
            for where, _, _ in self.spcs:
                self.dropped.append(Dropped(where, "constraints on SPH particles",
                                            "the particles are free", True))
            for *_, kw in self.motions:
                self.drop(kw, "a motion of SPH particles", "the particles are free")
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
        name = "solids"
        point_sets, sets, boundaries = {}, [], []

        def group(where: str, ref, label: str) -> str | None:
            """A [[set]] of the mesh's nodes in node set ``ref`` (or a list of
            nodes); nodes that are no solid element's are listed as free."""
            nodes = self.node_sets.get(ref) if isinstance(ref, int) else ref
            if nodes is None:
                raise KeywordError(f"{where}: node set {ref}, which no *SET_NODE_LIST "
                                   "defines")
            on = [index[n] for n in nodes if n in index]
            if len(on) != len(nodes):
                self.dropped.append(Dropped(where, "a condition on nodes that are not "
                                            "a solid element's (SPH particles)",
                                            "those nodes are free", True))
            if not on:
                return None
            point_sets[label] = np.array(on)
            sets.append({"name": label, "mesh": name, "group": label})
            return label

        for k, (where, ref, dofs) in enumerate(self.spcs, start=1):
            if dofs and (g := group(where, ref, f"spc{k}")):
                boundaries.append({"set": g, "type": "fixed", "components": list(dofs)})
        for k, motion in enumerate(self.motions, start=1):
            b = self._motion(*motion)
            if b is not None and (g := group(motion[-1].block.where(), motion[0],
                                             f"motion{k}")):
                boundaries.append({"set": g, **b})
        file = f"{self.stem}_{name}.inp"
        out.files[file] = meshio.Mesh(points, [("hexahedron", cells)],
                                      cell_sets=cell_sets, point_sets=point_sets)
        mesh = {"name": name, "file": file, "integration": forms[pids[0]],
                "group": [{"name": f"part{pid}", "material": self._mat_name(pid)}
                          for pid in pids]}
        if self.tssfac is not None:
            mesh["cfl"] = self.tssfac
        contact = self._contact(pids)
        if contact is not None:
            mesh["contact"] = contact
        erosion = self._erosion(pids)
        if erosion is not None:
            mesh["erosion"] = erosion
        vs = {self._velocity(pid) for pid in pids}
        if len(vs) > 1:
            self.drop(self.parts[pids[0]]["kw"], "different initial velocities of the "
                      "solid parts", "the first part's for the mesh")
        v = self._velocity(pids[0])
        if v is not None:
            mesh["velocity"] = [quantity(c, "m/s") for c in v]
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
    "MAT_PIECEWISE_LINEAR_PLASTICITY": Converter.mat_piecewise_linear_plasticity,
    "MAT_024": Converter.mat_piecewise_linear_plasticity,
    "MAT_CSCM_CONCRETE": Converter.mat_cscm_concrete,
    "MAT_HIGH_EXPLOSIVE_BURN": Converter.mat_high_explosive_burn,
    "MAT_008": Converter.mat_high_explosive_burn,
    "MAT_NULL": Converter.mat_null,
    "MAT_009": Converter.mat_null,
    "EOS_JWL": Converter.eos_jwl,
    "EOS_LINEAR_POLYNOMIAL": Converter.eos_linear_polynomial,
    "INITIAL_DETONATION": Converter.initial_detonation,
    "MAT_ADD_EROSION": Converter.mat_add_erosion,
    "DEFINE_ADAPTIVE_SOLID_TO_SPH": Converter.define_adaptive_solid_to_sph,
    "DEFINE_ADAPTIVE_SOLID_TO_SPH_ID": Converter.define_adaptive_solid_to_sph,
    "MAT_CSCM": Converter.mat_cscm,
    "MAT_159": Converter.mat_cscm,
    "SET_NODE_LIST": Converter.set_node_list,
    "SET_PART_LIST": Converter.set_part_list,
    "DEFINE_CURVE": Converter.define_curve,
    "LOAD_BODY_X": Converter.load_body,
    "LOAD_BODY_Y": Converter.load_body,
    "LOAD_BODY_Z": Converter.load_body,
    "LOAD_BODY_PARTS": Converter.load_body_parts,
    "BOUNDARY_PRESCRIBED_MOTION_SET": Converter.boundary_prescribed_motion_set,
    "BOUNDARY_PRESCRIBED_MOTION_NODE": Converter.boundary_prescribed_motion_node,
    "CONTACT_AUTOMATIC_NODES_TO_SURFACE": Converter.contact_automatic_nodes_to_surface,
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
