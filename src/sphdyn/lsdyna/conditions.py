"""The loads, conditions and couplings of a keyword deck: initial
velocities, curves, body loads, prescribed motions, contact, detonations and
element erosion, as sphdyn's deck tables (the readers of
:class:`~sphdyn.lsdyna.convert.Converter` for them; docs/lsdyna.md has the
table)."""

from __future__ import annotations

import numpy as np

from .fields import integer, number, quantity
from .scan import KeywordError

#: BOUNDARY_PRESCRIBED_MOTION's VAD -> [[boundary]] type
VAD = {0: "velocity", 2: "displacement"}


class ConditionKeywords:
    """Readers of the load, condition and coupling keywords, and their
    resolution once every keyword is read; mixed into the converter."""

    def initial_velocity_generation(self, kw):
        o = kw.obj
        if number(o.omega):
            self.drop(kw, "OMEGA (an initial rotation)", "no rotation")
        v = tuple(number(getattr(o, f"v{a}")) * self.u.velocity for a in "xyz")
        styp, ident = integer(o.styp, 2), integer(o.id)
        what = {1: "part_set", 2: "part", 3: "node_set"}.get(styp) if ident else "all"
        if what is None:
            self.drop(kw, f"STYP = {styp}", "no initial velocity from it (STYP 1, 2, 3)")
            return
        self.velocities.append((what, ident, v, kw))

    def initial_velocity(self, kw):
        """``*INITIAL_VELOCITY``: the nodes of set NSID (0: every node and
        particle); an exempted set or a box is listed."""
        o = kw.obj
        if integer(o.nsidex) or integer(o.boxid):
            self.drop(kw, "NSIDEX / BOXID (nodes exempted, or a box)",
                      "no initial velocity from it")
            return
        if any(number(getattr(o, f"v{a}r")) for a in "xyz"):
            self.drop(kw, "VXR / VYR / VZR (rotational velocities of beam nodes)", "none")
        v = tuple(number(getattr(o, f"v{a}")) * self.u.velocity for a in "xyz")
        nsid = integer(o.nsid)
        self.velocities.append(("node_set" if nsid else "all", nsid, v, kw))

    def _part_set(self, sid: int, kw) -> set[int]:
        """The parts of part set ``sid``, named by keyword ``kw``; an error if
        no *SET_PART_LIST defines it."""
        if sid not in self.part_sets:
            raise KeywordError(f"{kw.block.where()}: part set {sid}, which no "
                               "*SET_PART_LIST defines")
        return set(self.part_sets[sid])

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
                pids = self._part_set(ident, kw)
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

    def define_curve(self, kw):
        """``*DEFINE_CURVE``: the points, abscissae times SFA and ordinates
        times SFO; a curve with offsets (OFFA, OFFO) or one for the stress
        initialisation by dynamic relaxation only (SIDR = 1) is kept as the
        reason it cannot be used; SIDR = 2 (that initialisation and the run)
        is used for the run, its initialisation listed."""
        o = kw.obj
        lcid = int(o.lcid)
        if number(o.offa) or number(o.offo):
            self.curves[lcid] = f"curve {lcid} has OFFA / OFFO offsets ({kw.block.where()})"
            return
        if integer(o.sidr) == 1:
            self.curves[lcid] = (f"curve {lcid} drives only the dynamic-relaxation "
                                 f"initialisation (SIDR = 1; {kw.block.where()})")
            return
        if integer(o.sidr) == 2:
            self.drop(kw, f"curve {lcid}: SIDR = 2 (also a stress initialisation by "
                      "dynamic relaxation)", "no initialisation: the run starts unloaded")
        pts = o.curves  # SFA, SFO: 0 means 1; in the deck's units
        a = np.asarray(pts.iloc[:, 0], float) * (number(o.sfa, 1.0) or 1.0)
        self.curves[lcid] = (a, np.asarray(pts.iloc[:, 1], float) * (number(o.sfo, 1.0) or 1.0))

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

    def load_body(self, kw):
        """``*LOAD_BODY_X``, ``_Y``, ``_Z``: a base acceleration SF times the
        curve; the model's body force acts against it ("positive body load
        acts in the negative direction", LS-DYNA Keyword Manual Vol. I,
        *LOAD_BODY), so [run] gravity = -SF curve along the axis."""
        o = kw.obj
        if integer(o.lciddr):
            self.drop(kw, "LCIDDR (a dynamic-relaxation curve)", "no dynamic relaxation")
        if integer(o.cid):
            self.drop(kw, "CID (a local coordinate system)", "the global axes")
        axis = "XYZ".index(kw.name[-1])
        self.body_loads.append((axis, integer(o.lcid), number(o.sf, 1.0), kw))

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
            self.run["gravity"] = [quantity(c, "m/s^2") for c in g]
        for psid, kw in self.body_load_parts:
            if not set(self._pids()) <= self._part_set(psid, kw) and g.any():
                self.drop(kw, f"body loads on the parts of set {psid} only",
                          "gravity on every part (sphdyn's [run] gravity)")

    def load_body_parts(self, kw):
        """``*LOAD_BODY_PARTS``: the body loads act on part set PSID only;
        sphdyn's gravity acts on every part, so a set without some part is
        listed."""
        self.body_load_parts.append((integer(kw.obj.psid), kw))

    def boundary_prescribed_motion_set(self, kw):
        """``*BOUNDARY_PRESCRIBED_MOTION_SET``: a velocity (VAD = 0) or a
        displacement (VAD = 2) along x, y or z (DOF 1-3) of a node set,
        whose curve is constant, or rises linearly from zero and is then
        constant (a [[boundary]] with its ramp_time)."""
        self._prescribed(kw, integer(kw.obj.nsid))

    def boundary_prescribed_motion_node(self, kw):
        """``*BOUNDARY_PRESCRIBED_MOTION_NODE``: the same for one node."""
        self._prescribed(kw, [integer(kw.obj.nid)])

    def _prescribed(self, kw, ref) -> None:
        o = kw.obj
        dof, vad = integer(o.dof), integer(o.vad)
        if dof not in (1, 2, 3) or vad not in VAD:
            self.drop(kw, f"DOF = {dof}, VAD = {vad}", "no motion from it (DOF 1-3 with "
                      "VAD 0, a velocity, or 2, a displacement, is imported)")
            return
        span = (number(o.birth) * self.u.time, (number(o.death) or 1e28) * self.u.time)
        self.motions.append((ref, dof - 1, VAD[vad], integer(o.lcid),
                             number(o.sf, 1.0), span, kw))

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
        b = {"type": kind, kind: [quantity(c, unit) for c in vec], "components": ["xyz"[axis]]}
        if ramp:
            b["ramp_time"] = quantity(ramp, "s")
        return b

    def contact_automatic_nodes_to_surface(self, kw):
        """``*CONTACT_AUTOMATIC_NODES_TO_SURFACE`` with SPH particles on side
        A and solid parts on side B: [mesh.contact] (sphdyn's penalty spring,
        paper eq. 8; LS-DYNA's segment stiffness is not reproduced, the same
        difference as the rigid wall's); FS as the friction coefficient."""
        o = kw.obj
        fs, fd = number(o.fs), number(o.fd)
        if fd and fd != fs or number(o.dc) or number(o.vc):
            self.drop(kw, "FD / DC / VC (dynamic friction, its decay, viscous "
                      "friction)", f"Coulomb friction FS = {fs:g}")
        for field_ in ("sfsa", "sfsb"):
            if number(getattr(o, field_), 1.0) not in (0.0, 1.0):
                self.drop(kw, f"{field_.upper()} = {number(getattr(o, field_)):g}",
                          "sphdyn's penalty stiffness ([mesh.contact] alpha)")
        if integer(getattr(o, "soft", 0)):
            self.drop(kw, f"SOFT = {integer(o.soft)}", "sphdyn's penalty stiffness "
                      "([mesh.contact] stiffness = \"mass\": alpha m / dt^2)")
        self.contacts.append(((integer(o.surfa), integer(o.surfatyp)),
                              (integer(o.surfb), integer(o.surfbtyp)), fs, kw))

    def _side_parts(self, side: tuple[int, int], kw) -> set[int] | None:
        """The parts of a contact side (a part, a part set, or everything;
        None for other side types, listed)."""
        ident, typ = side
        if typ == 3:
            return {ident}
        if typ == 2:
            return self._part_set(ident, kw)
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

    def define_adaptive_solid_to_sph(self, kw):
        """``*DEFINE_ADAPTIVE_SOLID_TO_SPH``: the eroded elements of part (set)
        IPID become particles (NQ 1: one, 2: eight per element) coupled to the
        rest (ICPL 1) from their failure (IOPT 1): ``[mesh.erosion] to =
        "particles"``."""
        o = kw.obj
        nq = integer(o.nq, 1)
        if nq not in (1, 2):
            self.drop(kw, f"NQ = {nq}", "eight particles per element (NQ = 2)")
        if integer(o.icpl, 1) != 1:
            self.drop(kw, f"ICPL = {integer(o.icpl)} (debris not coupled)", "the particles "
                      "meet the elements by penalty (ICPL = 1)")
        if integer(o.iopt, 1) != 1:
            self.drop(kw, "IOPT = 0 (particles in the elements from the start)",
                      "particles made when an element erodes (IOPT = 1)")
        self.adaptive.append((integer(o.ipid), integer(o.itype), 8 if nq >= 2 else 1, kw))

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
            pids = self._part_set(ipid, kw) if itype else {ipid}
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

    def initial_detonation(self, kw):
        """``*INITIAL_DETONATION``: a [[detonation]] at X, Y, Z, lit at LT, of
        part PID's explosive (0: every explosive)."""
        o = kw.obj
        pid = integer(o.pid)
        if pid < 0:
            self.drop(kw, f"PID = {pid} (a part set, or an acoustic boundary)",
                      "no detonation from it")
            return
        self.detonations.append((pid, [quantity(number(getattr(o, a)) * self.u.length, "m")
                                       for a in "xyz"],
                                 number(o.lt) * self.u.time, kw))
