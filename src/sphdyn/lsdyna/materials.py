"""The material keywords of a keyword deck (``*MAT_``, ``*EOS_``,
``*MAT_ADD_EROSION``) as sphdyn's [[material]] tables: the readers of
:class:`~sphdyn.lsdyna.convert.Converter` for them (docs/lsdyna.md has the
table of what becomes of each field)."""

from __future__ import annotations

import numpy as np

from .fields import integer, name_of, number, quantity
from .scan import KeywordError

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



class MaterialKeywords:
    """Readers of the material keywords; mixed into the converter, whose
    state (``materials``, ``density``, ``eos``, ``erosion_rules``, ``u``,
    ``drop``) they fill."""

    def _material(self, kw, values: dict) -> None:
        mid = int(kw.obj.mid)
        self.density[mid] = float(kw.obj.ro) * self.u.density
        title = getattr(kw.obj, "title", None) if "TITLE" in kw.block.title.upper() else None
        self.materials[mid] = {"name": name_of(title, f"mat{mid}"), **values}

    def mat_elastic(self, kw):
        o = kw.obj
        if number(o.da) or number(o.db):
            self.drop(kw, "DA / DB (axial and bending damping of beams)", "none")
        self._material(kw, {"model": "elastic", "density": quantity(o.ro * self.u.density,
                                                              "kg/m^3"),
                            "E": quantity(o.e * self.u.stress, "Pa"), "nu": float(o.pr)})

    def mat_plastic_kinematic(self, kw):
        o = kw.obj
        beta = number(o.beta, 0.0)
        if beta != 1.0:
            self.drop(kw, f"BETA = {beta:g} (kinematic hardening)", "isotropic "
                      "hardening (sphdyn's j2 is BETA = 1)")
        if number(o.src) or number(o.srp):
            self.drop(kw, "SRC / SRP (Cowper-Symonds rate effects)", "no rate effects")
        if number(o.fs):
            self.drop(kw, "FS (failure strain)", "no failure")
        E, Et = o.e * self.u.stress, number(o.etan) * self.u.stress
        self._material(kw, {"model": "j2", "density": quantity(o.ro * self.u.density,
                                                         "kg/m^3"),
                            "E": quantity(E, "Pa"), "nu": float(o.pr),
                            "yield_stress": quantity(o.sigy * self.u.stress, "Pa"),
                            # the plastic modulus H of the bilinear curve whose
                            # slope past yield is ETAN: Et = E H / (E + H)
                            "hardening_modulus": quantity(E * Et / (E - Et), "Pa")})

    def mat_piecewise_linear_plasticity(self, kw):
        """``*MAT_PIECEWISE_LINEAR_PLASTICITY`` (MAT_024) as j2: SIGY and ETAN,
        the plastic hardening modulus (Altair's reference of the LS-DYNA
        keyword: "ETAN: plastic hardening modulus"), or the yield stress
        against effective plastic strain (the curve LCSS or EPS1-8 / ES1-8)
        when it is a straight line; sphdyn's j2 hardens linearly, so a curve
        of several slopes is listed and its first segment kept."""
        o = kw.obj
        if number(o.c) and number(o.p):
            self.drop(kw, "C, P (Cowper-Symonds rate effects)", "no rate effects")
        if integer(o.lcsr) or integer(o.vp):
            self.drop(kw, "LCSR / VP (strain-rate scaling, viscoplastic form)",
                      "no rate effects")
        if 0.0 < number(o.fail, 1e21) < 1e20:
            self.drop(kw, f"FAIL = {number(o.fail):g} (failure strain)", "no failure")
        E = o.e * self.u.stress
        m = {"model": "j2", "density": quantity(o.ro * self.u.density, "kg/m^3"),
             "E": quantity(E, "Pa"), "nu": float(o.pr),
             "yield_stress": quantity(number(o.sigy) * self.u.stress, "Pa"),
             "hardening_modulus": quantity(number(o.etan) * self.u.stress, "Pa")}
        self._material(kw, m)
        eps = [number(getattr(o, f"eps{k}"), None) for k in range(1, 9)]
        es = [number(getattr(o, f"es{k}"), None) for k in range(1, 9)]
        n = sum(1 for e, s_ in zip(eps, es) if e is not None and s_ is not None
                and (e or s_))
        if integer(o.lcss):
            self.yield_curves.append((int(o.mid), integer(o.lcss), kw))
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
        self.materials[mid]["yield_stress"] = quantity(y0 * self.u.stress, "Pa")
        self.materials[mid]["hardening_modulus"] = quantity(H * self.u.stress, "Pa")

    def mat_cscm_concrete(self, kw):
        """``*MAT_CSCM_CONCRETE``: the parameters generated from FPC and DAGG."""
        o = kw.obj
        units = integer(o.units, 0)
        if CSCM_UNITS.get(units) != self.u.name:
            raise KeywordError(f"{kw.block.where()}: UNITS = {units} "
                               f"({CSCM_UNITS.get(units, 'inch-pound')}) disagrees with "
                               f"--units {self.u.name}: FPC and DAGG are read in UNITS; "
                               "give --units as the deck's consistent system")
        self._material(kw, {**self._cscm_switches(kw),
                            "fc": quantity(o.fpc * self.u.stress, "Pa"),
                            "aggregate_size": quantity(o.dagg * self.u.length, "m")})

    def mat_cscm(self, kw):
        """``*MAT_CSCM`` (MAT_159 with every parameter given): each field in
        the deck's units; a blank one is listed (sphdyn would generate it
        from its own fc = 30 MPa, which this form does not give)."""
        o = kw.obj
        m = self._cscm_switches(kw)
        for field_, key, stress, length in CSCM_FIELDS:
            v = number(getattr(o, field_), None)
            if v is None:
                self.drop(kw, f"{field_.upper()} blank", f"{key} generated from sphdyn's "
                          "default fc")
                continue
            m[key] = v * self.u.stress ** stress * self.u.length ** length
        for field_, key, power in (("eta0c", "eta0c", "nc"), ("etaot", "eta0t", "nt")):
            v, n = number(getattr(o, field_), None), number(getattr(o, power), 0.0)
            if v is not None:  # the fluidity eta = eta0 / rate^n is a time
                m[key] = v * self.u.time ** (1.0 - n)
        for field_, what in (("nh", "NH, CH (pre-peak hardening)"),
                             ("ch", "NH, CH (pre-peak hardening)"),
                             ("pmod", "PMOD (moderate-pressure softening)")):
            if number(getattr(o, field_)):
                self.drop(kw, f"{field_.upper()} = {number(getattr(o, field_)):g}: {what}",
                          "not in sphdyn's CSCM (docs/cscm.md): as if 0")
        self._material(kw, m)

    def _cscm_switches(self, kw) -> dict:
        """The fields both CSCM keywords share: RO, IRATE, ERODE, RECOV,
        ITRETRC, INCRE, PRED."""
        o = kw.obj
        m = {"model": "cscm", "density": quantity(o.ro * self.u.density, "kg/m^3"),
             "rate_effects": integer(o.irate) == 1}
        erode = number(o.erode)
        if erode >= 1.0:
            m["erode"], m["erode_strain"] = True, float(f"{erode - 1.0:.12g}")
            if erode > 1.0:  # its elements erode by the same rule
                self.erosion_rules.setdefault(int(o.mid), {})["erode"] = erode
        if number(o.recov):
            m["recovery"] = number(o.recov)
        if integer(o.itretrc):
            m["cap_retraction"] = True
        if number(o.incre):
            m["incre"] = number(o.incre)
        if number(o.pred):
            self.drop(kw, "PRED (pre-existing damage)", "none")
        return m

    def mat_high_explosive_burn(self, kw):
        """``*MAT_HIGH_EXPLOSIVE_BURN`` (MAT_008) with its part's ``*EOS_JWL``:
        ``model = "high_explosive"``, D, PCJ, BETA as the burn."""
        o = kw.obj
        beta = integer(o.beta)
        if beta not in BURN:
            raise KeywordError(f"{kw.block.where()}: BETA = {beta} is not 0, 1 or 2")
        if number(o.k) or number(o.g) or number(o.sigy):
            self.drop(kw, "K, G, SIGY (the unreacted explosive's strength)",
                      "the explosive carries pressure only")
        self._material(kw, {"model": "high_explosive",
                            "density": quantity(o.ro * self.u.density, "kg/m^3"),
                            "D": quantity(o.d * self.u.velocity, "m/s"),
                            "P_CJ": quantity(o.pcj * self.u.stress, "Pa"), "burn": BURN[beta]})

    def mat_null(self, kw):
        """``*MAT_NULL`` (MAT_009) with its part's ``*EOS_LINEAR_POLYNOMIAL``:
        ``model = "gas"``; PC as the pressure cutoff."""
        o = kw.obj
        if number(o.mu):
            self.drop(kw, "MU (viscosity)", "no viscosity but the artificial one")
        if number(o.terod) or number(o.cerod):
            self.drop(kw, "TEROD / CEROD (erosion by relative volume)", "no erosion")
        self._material(kw, {"model": "gas", "density": quantity(o.ro * self.u.density, "kg/m^3"),
                            "pressure_cutoff": quantity(min(number(o.pc), 0.0) * self.u.stress,
                                                  "Pa")})

    def eos_jwl(self, kw):
        o = kw.obj
        S = self.u.stress
        self._eos(kw, "JWL", o.vo, {"A": quantity(o.a * S, "Pa"), "B": quantity(o.b * S, "Pa"),
                                    "R1": float(o.r1), "R2": float(o.r2),
                                    "omega": float(o.omeg), "E0": quantity(o.e0 * S, "Pa")})

    def eos_linear_polynomial(self, kw):
        o = kw.obj
        S = self.u.stress
        keys = {"eos": "linear_polynomial"}
        keys |= {f"C{k}": quantity(number(getattr(o, f"c{k}")) * S, "Pa") for k in range(4)}
        keys |= {f"C{k}": number(getattr(o, f"c{k}")) for k in range(4, 7)}
        keys["E0"] = quantity(number(o.e0) * S, "Pa")
        self._eos(kw, "LINEAR_POLYNOMIAL", o.v0, keys)

    def _eos(self, kw, kind: str, v0, keys: dict) -> None:
        if number(v0, 1.0) not in (0.0, 1.0):
            self.drop(kw, f"V0 = {number(v0):g} (an initial relative volume)", "1")
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
        excl = number(o.excl)

        def rule(field_):
            v = number(getattr(o, field_))
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
