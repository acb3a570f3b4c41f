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
from .scan import KeywordError, id_list, solid_elements, sph_elements
from .units import Units

#: MAT_CSCM_CONCRETE's UNITS field -> the unit system it means
CSCM_UNITS = {0: "mm-ms-kg", 1: "mm-ms-g", 2: "mm-s-t", 4: "m-s-kg"}

#: *MAT_CSCM's fields (ansys-dyna-core's names) -> (sphdyn's key, the field's
#: unit as powers of the deck's stress and length units). ETA0C and ETA0T
#: (time^(1 - NC), time^(1 - NT)) are converted apart.
CSCM_FIELDS = (("g", "G", 1, 0), ("k", "K", 1, 0),
               ("alpha", "alpha", 1, 0), ("theta", "theta", 0, 0),
               ("lamda", "lamda", 1, 0), ("beta", "beta", -1, 0),
               ("alpha1", "alpha1", 0, 0), ("theta1", "theta1", -1, 0),
               ("lamda1", "lamda1", 0, 0), ("beta1", "beta1", -1, 0),
               ("alpha2", "alpha2", 0, 0), ("theta2", "theta2", -1, 0),
               ("lamda2", "lamda2", 0, 0), ("beta2", "beta2", -1, 0),
               ("r", "R", 0, 0), ("xd", "X0", 1, 0), ("w", "W", 0, 0),
               ("d1", "D1", -1, 0), ("d2", "D2", -2, 0),
               ("b", "B", 0, 0), ("gfc", "GFC", 1, 1), ("d", "D", 0, 0),
               ("gft", "GFT", 1, 1), ("gfs", "GFS", 1, 1),
               ("pwrc", "pwrc", 0, 0), ("pwrt", "pwrt", 0, 0),
               ("nc", "nc", 0, 0), ("nt", "nt", 0, 0),
               ("overc", "overc", 1, 0), ("overt", "overt", 1, 0),
               ("srate", "srate", 0, 0), ("rep0w", "repow", 0, 0))

#: MAT_HIGH_EXPLOSIVE_BURN's BETA -> the explosive's burn
BURN = {0: "both", 1: "beta", 2: "programmed"}

#: The material models that take their pressure from a part's *EOS_ and the
#: EOS keyword each needs
EOS_OF = {"high_explosive": "JWL", "gas": "LINEAR_POLYNOMIAL"}

#: BOUNDARY_PRESCRIBED_MOTION's VAD -> [[boundary]] type
VAD = {0: "velocity", 2: "displacement"}

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
            self.parts[pid] = {"title": row.heading, "secid": _int(row.secid),
                               "mid": _int(row.mid), "eosid": _int(row.eosid), "kw": kw}
            if _int(row.hgid):
                self.drop(kw, f"part {pid}: HGID (an hourglass card)",
                          "[[mesh]]'s hourglass control")

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

    def mat_piecewise_linear_plasticity(self, kw):
        """``*MAT_PIECEWISE_LINEAR_PLASTICITY`` (MAT_024) as j2: SIGY and ETAN,
        the plastic hardening modulus (Altair's reference of the LS-DYNA
        keyword: "ETAN: plastic hardening modulus"), or the yield stress
        against effective plastic strain (the curve LCSS or EPS1-8 / ES1-8)
        when it is a straight line; sphdyn's j2 hardens linearly, so a curve
        of several slopes is listed and its first segment kept."""
        o = kw.obj
        if _num(o.c) and _num(o.p):
            self.drop(kw, "C, P (Cowper-Symonds rate effects)", "no rate effects")
        if _int(o.lcsr) or _int(o.vp):
            self.drop(kw, "LCSR / VP (strain-rate scaling, viscoplastic form)",
                      "no rate effects")
        if 0.0 < _num(o.fail, 1e21) < 1e20:
            self.drop(kw, f"FAIL = {_num(o.fail):g} (failure strain)", "no failure")
        E = o.e * self.u.stress
        m = {"model": "j2", "density": _q(o.ro * self.u.density, "kg/m^3"),
             "E": _q(E, "Pa"), "nu": float(o.pr),
             "yield_stress": _q(_num(o.sigy) * self.u.stress, "Pa"),
             "hardening_modulus": _q(_num(o.etan) * self.u.stress, "Pa")}
        self._material(kw, m)
        eps = [_num(getattr(o, f"eps{k}"), None) for k in range(1, 9)]
        es = [_num(getattr(o, f"es{k}"), None) for k in range(1, 9)]
        n = sum(1 for e, s_ in zip(eps, es) if e is not None and s_ is not None
                and (e or s_))
        if _int(o.lcss):
            self.yield_curves.append((int(o.mid), _int(o.lcss), kw))
        elif n:
            self._yield_line(kw, int(o.mid), np.array(eps[:n]), np.array(es[:n]))

    def _yield_line(self, kw, mid: int, eps: np.ndarray, sig: np.ndarray) -> None:
        """j2's yield stress and hardening modulus from a yield curve (effective
        plastic strain, stress in the deck's units): the line through its
        first two points, listed unless every point lies on it (1e-9)."""
        if len(eps) < 2 or not np.all(np.diff(eps) > 0.0):
            raise KeywordError(f"{kw.block.where()}: the yield curve needs two or more "
                               "points of rising plastic strain")
        H = (sig[1] - sig[0]) / (eps[1] - eps[0])
        y0 = sig[0] - H * eps[0]
        line = y0 + H * eps
        if np.any(np.abs(line - sig) > 1e-9 * np.abs(sig).max()):
            self.drop(kw, f"a yield curve of {len(eps) - 1} segments of different slope",
                      "the line through its first two points (sphdyn's j2 hardens "
                      "linearly)")
        self.materials[mid]["yield_stress"] = _q(y0 * self.u.stress, "Pa")
        self.materials[mid]["hardening_modulus"] = _q(H * self.u.stress, "Pa")

    def mat_high_explosive_burn(self, kw):
        """``*MAT_HIGH_EXPLOSIVE_BURN`` (MAT_008) with its part's ``*EOS_JWL``:
        ``model = "high_explosive"``, D, PCJ, BETA as the burn."""
        o = kw.obj
        beta = _int(o.beta)
        if beta not in BURN:
            raise KeywordError(f"{kw.block.where()}: BETA = {beta} is not 0, 1 or 2")
        if _num(o.k) or _num(o.g) or _num(o.sigy):
            self.drop(kw, "K, G, SIGY (the unreacted explosive's strength)",
                      "the explosive carries pressure only")
        self._material(kw, {"model": "high_explosive",
                            "density": _q(o.ro * self.u.density, "kg/m^3"),
                            "D": _q(o.d * self.u.velocity, "m/s"),
                            "P_CJ": _q(o.pcj * self.u.stress, "Pa"), "burn": BURN[beta]})

    def mat_null(self, kw):
        """``*MAT_NULL`` (MAT_009) with its part's ``*EOS_LINEAR_POLYNOMIAL``:
        ``model = "gas"``; PC as the pressure cutoff."""
        o = kw.obj
        if _num(o.mu):
            self.drop(kw, "MU (viscosity)", "no viscosity but the artificial one")
        if _num(o.terod) or _num(o.cerod):
            self.drop(kw, "TEROD / CEROD (erosion by relative volume)", "no erosion")
        self._material(kw, {"model": "gas", "density": _q(o.ro * self.u.density, "kg/m^3"),
                            "pressure_cutoff": _q(min(_num(o.pc), 0.0) * self.u.stress,
                                                  "Pa")})

    def eos_jwl(self, kw):
        o = kw.obj
        S = self.u.stress
        self._eos(kw, "JWL", o.vo, {"A": _q(o.a * S, "Pa"), "B": _q(o.b * S, "Pa"),
                                    "R1": float(o.r1), "R2": float(o.r2),
                                    "omega": float(o.omeg), "E0": _q(o.e0 * S, "Pa")})

    def eos_linear_polynomial(self, kw):
        o = kw.obj
        S = self.u.stress
        keys = {"eos": "linear_polynomial"}
        keys |= {f"C{k}": _q(_num(getattr(o, f"c{k}")) * S, "Pa") for k in range(4)}
        keys |= {f"C{k}": _num(getattr(o, f"c{k}")) for k in range(4, 7)}
        keys["E0"] = _q(_num(o.e0) * S, "Pa")
        self._eos(kw, "LINEAR_POLYNOMIAL", o.v0, keys)

    def _eos(self, kw, kind: str, v0, keys: dict) -> None:
        if _num(v0, 1.0) not in (0.0, 1.0):
            self.drop(kw, f"V0 = {_num(v0):g} (an initial relative volume)", "1")
        self.eos[int(kw.obj.eosid)] = (kind, keys, kw)

    def _with_eos(self, pids: list[int]) -> None:
        """Each part's *EOS_ into its material: JWL for an explosive, a linear
        polynomial for a null material; an EOS on another material, or one
        material with two EOS, is listed."""
        given: dict[int, int] = {}
        for pid in pids:
            part = self.parts[pid]
            mid, eosid = part["mid"], part["eosid"]
            m = self.materials.get(mid)
            if m is None:
                continue
            need = EOS_OF.get(m["model"])
            if need is None:
                if eosid:
                    self.drop(part["kw"], f"part {pid}: EOSID {eosid} on a material with "
                              "its own pressure", "the material's own pressure")
                continue
            if eosid not in self.eos or self.eos[eosid][0] != need:
                raise KeywordError(f"{part['kw'].block.where()}: part {pid}'s material "
                                   f"{mid} needs an *EOS_{need} (EOSID {eosid})")
            if given.setdefault(mid, eosid) != eosid:
                self.drop(part["kw"], f"part {pid}: material {mid} with a second EOS",
                          f"EOS {given[mid]} for every part of it")
                continue
            m.update(self.eos[eosid][1])

    def mat_add_erosion(self, kw):
        """``*MAT_ADD_EROSION``: MXEPS and EFFEPS as the principal and effective
        strain rules of material MID's [material.erosion] (a value of 0 or EXCL
        is no rule); the other criteria are listed."""
        o = kw.obj
        excl = _num(o.excl)

        def rule(field_):
            v = _num(getattr(o, field_))
            return None if v in (0.0, excl) else v

        rules = {key: v for field_, key in (("mxeps", "principal_strain"),
                                             ("effeps", "effective_strain"))
                 if (v := rule(field_)) is not None}
        others = [f.upper() for f in ("mxpres", "mneps", "voleps", "mnpres", "sigp1",
                                      "sigvm", "epssh", "sigth", "impulse", "failtm",
                                      "dtmin") if rule(f) is not None]
        if others:
            self.drop(kw, f"{', '.join(others)} (failure criteria)", "not used: sphdyn's "
                      "rules are the principal and effective strain, MAT_159's ERODE and "
                      "a minimum time step")
        self.erosion_rules.setdefault(int(o.mid), {}).update(rules)

    def define_adaptive_solid_to_sph(self, kw):
        """``*DEFINE_ADAPTIVE_SOLID_TO_SPH``: the eroded elements of part (set)
        IPID become particles (NQ 1: one, 2: eight per element) coupled to the
        rest (ICPL 1) from their failure (IOPT 1): ``[mesh.erosion] to =
        "particles"``."""
        o = kw.obj
        nq = _int(o.nq, 1)
        if nq not in (1, 2):
            self.drop(kw, f"NQ = {nq}", "eight particles per element (NQ = 2)")
        if _int(o.icpl, 1) != 1:
            self.drop(kw, f"ICPL = {_int(o.icpl)} (debris not coupled)", "the particles "
                      "meet the elements by penalty (ICPL = 1)")
        if _int(o.iopt, 1) != 1:
            self.drop(kw, "IOPT = 0 (particles in the elements from the start)",
                      "particles made when an element erodes (IOPT = 1)")
        self.adaptive.append((_int(o.ipid), _int(o.itype), 8 if nq >= 2 else 1, kw))

    def initial_detonation(self, kw):
        """``*INITIAL_DETONATION``: a [[detonation]] at X, Y, Z, lit at LT, of
        part PID's explosive (0: every explosive)."""
        o = kw.obj
        pid = _int(o.pid)
        if pid < 0:
            self.drop(kw, f"PID = {pid} (a part set, or an acoustic boundary)",
                      "no detonation from it")
            return
        self.detonations.append((pid, [_q(_num(getattr(o, a)) * self.u.length, "m")
                                       for a in "xyz"],
                                 _num(o.lt) * self.u.time, kw))

    def mat_cscm_concrete(self, kw):
        """``*MAT_CSCM_CONCRETE``: the parameters generated from FPC and DAGG."""
        o = kw.obj
        units = _int(o.units, 0)
        if CSCM_UNITS.get(units) != self.u.name:
            raise KeywordError(f"{kw.block.where()}: UNITS = {units} "
                               f"({CSCM_UNITS.get(units, 'inch-pound')}) disagrees with "
                               f"--units {self.u.name}: FPC and DAGG are read in UNITS; "
                               "give --units as the deck's consistent system")
        self._material(kw, {**self._cscm_switches(kw),
                            "fc": _q(o.fpc * self.u.stress, "Pa"),
                            "aggregate_size": _q(o.dagg * self.u.length, "m")})

    def mat_cscm(self, kw):
        """``*MAT_CSCM`` (MAT_159 with every parameter given): each field in
        the deck's units; a blank one is listed (sphdyn would generate it
        from its own fc = 30 MPa, which this form does not give)."""
        o = kw.obj
        m = self._cscm_switches(kw)
        for field_, key, stress, length in CSCM_FIELDS:
            v = _num(getattr(o, field_), None)
            if v is None:
                self.drop(kw, f"{field_.upper()} blank", f"{key} generated from sphdyn's "
                          "default fc")
                continue
            m[key] = v * self.u.stress ** stress * self.u.length ** length
        for field_, key, power in (("eta0c", "eta0c", "nc"), ("etaot", "eta0t", "nt")):
            v, n = _num(getattr(o, field_), None), _num(getattr(o, power), 0.0)
            if v is not None:  # the fluidity eta = eta0 / rate^n is a time
                m[key] = v * self.u.time ** (1.0 - n)
        for field_, what in (("nh", "NH, CH (pre-peak hardening)"),
                             ("ch", "NH, CH (pre-peak hardening)"),
                             ("pmod", "PMOD (moderate-pressure softening)")):
            if _num(getattr(o, field_)):
                self.drop(kw, f"{field_.upper()} = {_num(getattr(o, field_)):g}: {what}",
                          "not in sphdyn's CSCM (docs/cscm.md): as if 0")
        self._material(kw, m)

    def _cscm_switches(self, kw) -> dict:
        """The fields both CSCM keywords share: RO, IRATE, ERODE, RECOV,
        ITRETRC, INCRE, PRED."""
        o = kw.obj
        m = {"model": "cscm", "density": _q(o.ro * self.u.density, "kg/m^3"),
             "rate_effects": _int(o.irate) == 1}
        erode = _num(o.erode)
        if erode >= 1.0:
            m["erode"], m["erode_strain"] = True, float(f"{erode - 1.0:.12g}")
            if erode > 1.0:  # its elements erode by the same rule
                self.erosion_rules.setdefault(int(o.mid), {})["erode"] = erode
        if _num(o.recov):
            m["recovery"] = _num(o.recov)
        if _int(o.itretrc):
            m["cap_retraction"] = True
        if _num(o.incre):
            m["incre"] = _num(o.incre)
        if _num(o.pred):
            self.drop(kw, "PRED (pre-existing damage)", "none")
        return m

    def _material(self, kw, values: dict) -> None:
        mid = int(kw.obj.mid)
        self.density[mid] = float(kw.obj.ro) * self.u.density
        title = getattr(kw.obj, "title", None) if "TITLE" in kw.block.title.upper() else None
        self.materials[mid] = {"name": _name(title, f"mat{mid}"), **values}

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
        if _int(getattr(o, "cid", 0)):
            self.drop(kw, "CID (a local coordinate system)", "the global axes")
        return tuple(a for a in "xyz" if _int(getattr(o, f"dof{a}")))

    def initial_velocity_generation(self, kw):
        o = kw.obj
        if _num(o.omega):
            self.drop(kw, "OMEGA (an initial rotation)", "no rotation")
        v = tuple(_num(getattr(o, f"v{a}")) * self.u.velocity for a in "xyz")
        styp, ident = _int(o.styp, 2), _int(o.id)
        what = {1: "part_set", 2: "part", 3: "node_set"}.get(styp) if ident else "all"
        if what is None:
            self.drop(kw, f"STYP = {styp}", "no initial velocity from it (STYP 1, 2, 3)")
            return
        self.velocities.append((what, ident, v, kw))

    def initial_velocity(self, kw):
        """``*INITIAL_VELOCITY``: the nodes of set NSID (0: every node and
        particle); an exempted set or a box is listed."""
        o = kw.obj
        if _int(o.nsidex) or _int(o.boxid):
            self.drop(kw, "NSIDEX / BOXID (nodes exempted, or a box)",
                      "no initial velocity from it")
            return
        if any(_num(getattr(o, f"v{a}r")) for a in "xyz"):
            self.drop(kw, "VXR / VYR / VZR (rotational velocities of beam nodes)", "none")
        v = tuple(_num(getattr(o, f"v{a}")) * self.u.velocity for a in "xyz")
        nsid = _int(o.nsid)
        self.velocities.append(("node_set" if nsid else "all", nsid, v, kw))

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
        self.t_end = kw.obj.endtim * self.u.time
        self.run["t_end"] = _q(self.t_end, "s")

    def define_curve(self, kw):
        """``*DEFINE_CURVE``: the points, abscissae times SFA and ordinates
        times SFO; a curve with offsets (OFFA, OFFO) or a dynamic-relaxation
        flag (SIDR) is kept as the reason it cannot be used."""
        o = kw.obj
        lcid = int(o.lcid)
        if _num(o.offa) or _num(o.offo):
            self.curves[lcid] = f"curve {lcid} has OFFA / OFFO offsets ({kw.block.where()})"
            return
        if _int(o.sidr):
            self.curves[lcid] = (f"curve {lcid} is a dynamic-relaxation curve (SIDR = "
                                 f"{_int(o.sidr)}; {kw.block.where()})")
            return
        pts = o.curves  # SFA, SFO: 0 means 1; in the deck's units
        a = np.asarray(pts.iloc[:, 0], float) * (_num(o.sfa, 1.0) or 1.0)
        self.curves[lcid] = (a, np.asarray(pts.iloc[:, 1], float) * (_num(o.sfo, 1.0) or 1.0))

    def load_body(self, kw):
        """``*LOAD_BODY_X``, ``_Y``, ``_Z``: a base acceleration SF times the
        curve; the model's body force acts against it ("positive body load
        acts in the negative direction", LS-DYNA Keyword Manual Vol. I,
        *LOAD_BODY), so [run] gravity = -SF curve along the axis."""
        o = kw.obj
        if _int(o.lciddr):
            self.drop(kw, "LCIDDR (a dynamic-relaxation curve)", "no dynamic relaxation")
        if _int(o.cid):
            self.drop(kw, "CID (a local coordinate system)", "the global axes")
        axis = "XYZ".index(kw.name[-1])
        self.body_loads.append((axis, _int(o.lcid), _num(o.sf, 1.0), kw))

    def boundary_prescribed_motion_set(self, kw):
        """``*BOUNDARY_PRESCRIBED_MOTION_SET``: a velocity (VAD = 0) or a
        displacement (VAD = 2) along x, y or z (DOF 1-3) of a node set,
        whose curve is constant, or rises linearly from zero and is then
        constant (a [[boundary]] with its ramp_time)."""
        self._prescribed(kw, _int(kw.obj.nsid))

    def boundary_prescribed_motion_node(self, kw):
        """``*BOUNDARY_PRESCRIBED_MOTION_NODE``: the same for one node."""
        self._prescribed(kw, [_int(kw.obj.nid)])

    def _prescribed(self, kw, ref) -> None:
        o = kw.obj
        dof, vad = _int(o.dof), _int(o.vad)
        if dof not in (1, 2, 3) or vad not in VAD:
            self.drop(kw, f"DOF = {dof}, VAD = {vad}", "no motion from it (DOF 1-3 with "
                      "VAD 0, a velocity, or 2, a displacement, is imported)")
            return
        span = (_num(o.birth) * self.u.time, (_num(o.death) or 1e28) * self.u.time)
        self.motions.append((ref, dof - 1, VAD[vad], _int(o.lcid),
                             _num(o.sf, 1.0), span, kw))

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
        if _int(kw.obj.deriv):
            self.drop(kw, f"DERIV = {_int(kw.obj.deriv)} (h from the cube root of the "
                      "divergence)", "dh/dt = h div(v) / d (DERIV = 0)")

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
            d = {"point": point, "time": _q(lt, "s")}
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
        return _name(self.parts[pid]["title"], f"part{pid}")

    def _velocity(self, pid: int) -> tuple[float, float, float] | None:
        return self.initial_v.get(pid)

    def _part_nodes(self) -> dict[int, set[int]]:
        """The nodes (particles) of each part."""
        nodes: dict[int, set[int]] = {}
        for n, pid, _ in self.sph:
            nodes.setdefault(pid, set()).add(n)
        for _, pid, ns in self.solids:
            nodes.setdefault(pid, set()).update(ns)
        return nodes

    def _initial_velocities(self) -> dict[int, tuple[float, float, float]]:
        """Each part's initial velocity from the velocity keywords in deck
        order: every part, a part, the parts of a part set, or the parts
        whose nodes make up a node set exactly (sphdyn gives a body or a mesh
        one velocity; any other node set is listed). A part given two
        different velocities keeps the first (the second is listed)."""
        part_nodes = self._part_nodes()
        given: dict[int, tuple[float, float, float]] = {}
        for what, ident, v, kw in self.velocities:
            if what == "all":
                pids = list(part_nodes)
            elif what == "part":
                pids = [ident]
            elif what == "part_set":
                if ident not in self.part_sets:
                    raise KeywordError(f"{kw.block.where()}: part set {ident}, which no "
                                       "*SET_PART_LIST defines")
                pids = self.part_sets[ident]
            else:
                if ident not in self.node_sets:
                    raise KeywordError(f"{kw.block.where()}: node set {ident}, which no "
                                       "*SET_NODE_LIST defines")
                nodes = set(self.node_sets[ident])
                pids = [p for p, ns in part_nodes.items() if ns <= nodes]
                if set().union(*(part_nodes[p] for p in pids)) != nodes:
                    self.drop(kw, f"node set {ident} is not the nodes of whole parts",
                              "no initial velocity from it (sphdyn gives each body and "
                              "mesh one velocity)")
                    continue
            for p in pids:
                if given.setdefault(p, v) != v:
                    self.drop(kw, f"part {p}: a second initial velocity",
                              "the first one given for it")
        return given

    def _curve_shape(self, lcid: int, kw, what: str) -> tuple[float, float] | None:
        """``(value, ramp time [s])`` of curve ``lcid`` over the run: constant
        (ramp 0), or rising linearly from 0 at t = 0 to its second point's
        value and constant after it. Any other shape, or a curve that does
        not span 0 to the end time, is listed and gives None."""
        curve = self.curves.get(lcid)
        if curve is None:
            raise KeywordError(f"{kw.block.where()}: curve {lcid}, which no "
                               "*DEFINE_CURVE defines")
        if isinstance(curve, str):
            self.drop(kw, curve, f"no {what} from it")
            return None
        a, o = curve[0] * self.u.time, curve[1]
        if a[0] > 0.0 or a[-1] < self.t_end * (1.0 - 1e-12):
            self.drop(kw, f"curve {lcid} spans {a[0]:g} to {a[-1]:g} s, not the run's "
                      f"0 to {self.t_end:g} s", f"no {what} from it")
            return None
        if np.all(o == o[0]):
            return float(o[0]), 0.0
        if len(a) >= 2 and a[0] == 0.0 and o[0] == 0.0 and a[1] > 0.0 \
                and np.all(o[1:] == o[1]):
            return float(o[1]), float(a[1])
        self.drop(kw, f"curve {lcid} is neither constant nor a linear rise to a "
                  "constant", f"no {what} from it (sphdyn's are constant or ramped)")
        return None

    def _gravity(self) -> None:
        """[run] gravity from the body loads: -SF times the curve's value along
        each axis (:meth:`load_body` says why the sign)."""
        g = np.zeros(3)
        for axis, lcid, sf, kw in self.body_loads:
            shape = self._curve_shape(lcid, kw, "body load")
            if shape is None:
                continue
            value, ramp = shape
            if ramp:
                self.drop(kw, f"curve {lcid} ramps the load up over {ramp:g} s",
                          "gravity at its full value from the start")
            g[axis] -= sf * value * self.u.length / self.u.time ** 2
        if g.any():
            self.run["gravity"] = [_q(c, "m/s^2") for c in g]

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

    def _motion(self, nsid, axis, kind, lcid, sf, span, kw) -> dict | None:
        """A prescribed motion as a [[boundary]]'s keys (without its set), or
        None when it cannot be carried over (listed)."""
        if span[0] > 0.0 or span[1] < self.t_end:
            self.drop(kw, f"BIRTH / DEATH ({span[0]:g} to {span[1]:g} s: acting part "
                      "of the run)", "it acts from the start to the end")
        shape = self._curve_shape(lcid, kw, "motion")
        if shape is None:
            return None
        value, ramp = shape
        if kind == "displacement" and ramp == 0.0:
            self.drop(kw, f"curve {lcid}: a displacement reached at once",
                      "no motion from it (a displacement boundary needs a ramp)")
            return None
        unit, factor = (("m/s", self.u.velocity) if kind == "velocity"
                        else ("m", self.u.length))
        vec = [0.0, 0.0, 0.0]
        vec[axis] = sf * value * factor
        b = {"type": kind, kind: [_q(c, unit) for c in vec], "components": ["xyz"[axis]]}
        if ramp:
            b["ramp_time"] = _q(ramp, "s")
        return b

    def contact_automatic_nodes_to_surface(self, kw):
        """``*CONTACT_AUTOMATIC_NODES_TO_SURFACE`` with SPH particles on side
        A and solid parts on side B: [mesh.contact] (sphdyn's penalty spring,
        paper eq. 8; LS-DYNA's segment stiffness is not reproduced, the same
        difference as the rigid wall's); FS as the friction coefficient."""
        o = kw.obj
        fs, fd = _num(o.fs), _num(o.fd)
        if fd and fd != fs or _num(o.dc) or _num(o.vc):
            self.drop(kw, "FD / DC / VC (dynamic friction, its decay, viscous "
                      "friction)", f"Coulomb friction FS = {fs:g}")
        for field_ in ("sfsa", "sfsb"):
            if _num(getattr(o, field_), 1.0) not in (0.0, 1.0):
                self.drop(kw, f"{field_.upper()} = {_num(getattr(o, field_)):g}",
                          "sphdyn's penalty stiffness ([mesh.contact] alpha)")
        if _int(getattr(o, "soft", 0)):
            self.drop(kw, f"SOFT = {_int(o.soft)}", "sphdyn's penalty stiffness "
                      "([mesh.contact] stiffness = \"mass\": alpha m / dt^2)")
        self.contacts.append(((_int(o.surfa), _int(o.surfatyp)),
                              (_int(o.surfb), _int(o.surfbtyp)), fs, kw))

    def _side_parts(self, side: tuple[int, int], kw) -> set[int] | None:
        """The parts of a contact side (a part, a part set, or everything;
        None for other side types, listed)."""
        ident, typ = side
        if typ == 3:
            return {ident}
        if typ == 2:
            if ident not in self.part_sets:
                raise KeywordError(f"{kw.block.where()}: part set {ident}, which no "
                                   "*SET_PART_LIST defines")
            return set(self.part_sets[ident])
        if typ == 5:
            return set(self.parts)
        self.drop(kw, f"a contact side of type {typ}", "no contact from it (a part, "
                  "3, a part set, 2, or everything, 5, is imported)")
        return None

    def _contact(self, solid_pids: list[int]) -> dict | None:
        """[mesh.contact] of the contact keywords: side A must hold every SPH
        part (sphdyn's contact acts on every body's particles) and side B
        every solid part (the solids are one mesh); otherwise listed."""
        table = None
        sph_pids = {pid for _, pid, _ in self.sph}
        for a, b, fs, kw in self.contacts:
            slaves, masters = self._side_parts(a, kw), self._side_parts(b, kw)
            if slaves is None or masters is None:
                continue
            if not sph_pids or not sph_pids <= slaves or masters & sph_pids \
                    or not set(solid_pids) <= masters:
                self.drop(kw, "a contact whose side A is not every SPH part or whose "
                          "side B is not every solid part", "no contact from it "
                          "(sphdyn's [mesh.contact]: every body's particles against "
                          "the mesh's faces)")
                continue
            if table is not None and table["friction"] != fs:
                self.drop(kw, "a second contact with another FS", "the first one's")
            table = table or {"friction": fs}
        return table

    def _erosion(self, solid_pids: list[int]) -> dict | None:
        """[mesh.erosion] when a solid part's material has erosion rules:
        LS-DYNA deletes eroded elements (``to = "nothing"``), or with
        *DEFINE_ADAPTIVE_SOLID_TO_SPH on every solid part turns them into
        particles (the solids are one mesh: adaptivity on some parts only
        is listed)."""
        eroding = [p for p in solid_pids if self.parts[p]["mid"] in self.erosion_rules
                   and self.erosion_rules[self.parts[p]["mid"]]]
        table = None
        for ipid, itype, per, kw in self.adaptive:
            if itype:
                if ipid not in self.part_sets:
                    raise KeywordError(f"{kw.block.where()}: part set {ipid}, which no "
                                       "*SET_PART_LIST defines")
                pids = set(self.part_sets[ipid])
            else:
                pids = {ipid}
            if not set(solid_pids) <= pids:
                self.drop(kw, "adaptivity on some of the solid parts", "on none (the "
                          "solids are one mesh; name every solid part)")
            else:
                table = {"to": "particles", "particles_per_element": per}
        if table is not None and not eroding:
            self.drop(self.adaptive[0][-1], "adaptivity without an erosion rule on the "
                      "solids' materials", "no element erodes")
            return None
        if eroding:
            return table or {"to": "nothing"}
        return None

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
