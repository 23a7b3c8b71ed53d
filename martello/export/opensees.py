"""A scene as an OpenSees model (docs/opensees.md): the mapping from martello's nodes, links,
contacts, loads and integrators onto OpenSees nodes, zeroLength elements of uniaxial
materials, elasticBeamColumn frames, 3D buildings on rigid diaphragms (martello.export.building),
time series, load patterns and transient integrators.

The result is a list of OpenSees commands (`Command`: a name and its arguments, the same in
OpenSeesPy and Tcl) plus what the generated script records each output step (`Column`), so
the two languages are rendered from one model (martello.export.render). Whatever OpenSees
cannot express is refused here with an ExportError naming what and why; whatever it
expresses with a difference is stated in `OpenSeesModel.differences` (the script's header
and the command's output carry them: nothing is mapped silently). The laws of the materials
are those of OpenSees' own sources (v3.7.1), quoted in docs/opensees.md."""

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import ExportError
from ..independent.laws import contact_law
from ..independent.scene import effective_mass, time_function
from ..scene.rows import element_terms

NEWMARK_FAMILY = ("newmark", "hht", "generalized-alpha", "central-difference")
DISP_SCALE = 0.1          # m: the displacement that tol_increment is relative to (NormDispIncr is absolute)
MIN_NEWTON = 100          # rate terms without a damping tangent converge linearly (docs/opensees.md)
FILE_SAMPLES = 64         # tables longer than this go to a data file beside the script

# law -> the material it maps onto by default, exactly (docs/opensees.md "Contact laws")
DEFAULT_MATERIAL = {
    "linear": "ElasticPPGap", "hertz": "Hertzdamp", "hunt-crossley": "Hertzdamp",
    "lankarani-nikravesh": "Hertzdamp", "flores": "Hertzdamp", "gonthier": "Hertzdamp",
    "hertzdamp": "Hertzdamp", "kelvin": "ViscoelasticGap", "jankowski": "JankowskiImpact",
}
# (law, material) pairs a user may ask for that change the law: the difference is stated
MODEL_DIFFERENCE = {
    ("kelvin", "JankowskiImpact"): (
        "kelvin contact {name} as JankowskiImpact with n = 1: damped only while approaching "
        "(a half-Kelvin law), so the same c = {c:.6g} N s/m realises e = {e_half:.6g} instead "
        "of the full Kelvin law's {e_full:.6g} (docs/opensees.md \"Half-Kelvin\")"),
}
EXACT_ALTERNATIVES = {("linear", "ImpactMaterial"), ("linear", "ViscoelasticGap"),
                      ("hertz", "JankowskiImpact")}


@dataclass
class Command:
    name: str
    args: tuple

    def __iter__(self):
        return iter((self.name, self.args))


@dataclass
class Column:
    """One column of history.csv: `kind` u, v, a (node tag and DOF) or penetration (the
    contact's row [(tag, dof, coef)] and its gap: δ = Σ coef·u − gap) or force (the contact
    element: P = −basicForce)."""
    name: str
    kind: str
    args: tuple


@dataclass
class OpenSeesModel:
    title: str
    source: str
    ndm: int
    ndf: int
    commands: list            # the model and the analysis, in order
    columns: list             # Column
    dt: float
    steps: int
    every: int
    files: dict = field(default_factory=dict)     # data files the script reads: name -> text
    mapping: list = field(default_factory=list)   # (martello item, OpenSees object) lines
    differences: list = field(default_factory=list)
    contact_materials: list = field(default_factory=list)   # (contact, law, material)
    integrator: str = ""
    energy: dict = field(default_factory=dict)   # what energy:kinetic and energy:recoverable sum
    members: list = field(default_factory=list)  # a building's members: (prefix.name, element tag)
    modes: int = 0                               # a building's mass DOFs: the periods the script reports


def _kelvin_e(xi):
    """The full (unclipped) Kelvin law's e = exp(−ξπ/ν) (Anagnostopoulos 1988)."""
    return 0.0 if xi >= 1.0 else math.exp(-xi * math.pi / math.sqrt(1.0 - xi * xi))


def half_kelvin_e(xi):
    """e of a Kelvin contact damped only while approaching: e = exp(−(ξ/ν)·atan(ν/ξ)),
    ν = √(1 − ξ²), for 0 < ξ < 1 (docs/opensees.md "Half-Kelvin": the approach is a damped
    quarter cycle, δ_max = (v0/ω)·exp(−(ξ/ν)·atan(ν/ξ)), and the undamped restitution returns
    the speed ω·δ_max)."""
    if xi <= 0.0:
        return 1.0
    if xi >= 1.0:
        raise ValueError("half_kelvin_e: xi must be < 1 (an overdamped approach stops at "
                         "a different peak; not a closed form here)")
    nu = math.sqrt(1.0 - xi * xi)
    return math.exp(-(xi / nu) * math.atan(nu / xi))


def _law(c, mstar):
    """A penalty contact's law with its damping resolved from a target e by the law's
    published formula, as the kernel does (martello.independent.laws.contact_law)."""
    return contact_law({k: v for k, v in c.items() if v is not None}, [(c["a"], 1.0), (c["b"], -1.0)], mstar)


class _Builder:
    def __init__(self, scene, analysis=None, materials=None, tol=None, force=False):
        self.s = scene
        self.src = scene.source
        self.cmds, self.cols, self.files, self.map, self.diff = [], [], {}, [], []
        self.over = {k for k, v in (analysis or {}).items() if v is not None}
        self.an = _analysis(scene, dict(analysis or {}))
        self.materials = dict(materials or {})
        self.tol = tol
        self.force = force
        self.n_series = 0
        self.mat = 0
        self.ele = 0
        from .building import BuildingWriter
        self.bw = BuildingWriter(self)

    # --- refusals -------------------------------------------------------------------------
    def refuse(self, what, why, fix=None):
        exc = ExportError(f"{self.src}: {what}: cannot be exported to OpenSees ({why}"
                          + (f"; {fix}" if fix else "") + ")")
        exc.what, exc.why = what, why
        raise exc

    def check_scene(self):
        s, an = self.s, self.an
        if an["type"] != "dynamic":
            self.refuse("analysis.type = static", "the exporter writes a transient analysis; "
                        "the static problems have closed forms of their own")
        if an["integrator"] not in NEWMARK_FAMILY:
            self.refuse(f"analysis.integrator = {an['integrator']}",
                        "OpenSees' transient integrators are the Newmark family: it has no "
                        "event-driven, ODE or DAE (GSL, CVODE, ARKODE, IDA), Moreau–Jean or modal "
                        "(fast nonlinear) integrator",
                        "give --integrator newmark, hht, generalized-alpha or central-difference "
                        "and --dt")
        if s.extras.get("buildings"):
            self.bw.check()
        for kind, items in (("contact", s.contacts), ("link", s.links)):
            for i, it in enumerate(items):
                if it.get("terms") is not None and not s.extras.get("buildings"):
                    self.refuse(f"{kind}[{i}] ({it['name']}).terms",
                                "a row Σ c·u over several DOFs (plan points of rigid floors or "
                                "written terms): OpenSees' zeroLength acts between two nodes along "
                                "one direction", "give the element two nodes a and b")
        in_building = {s.index[n] for b in s.extras.get("buildings", []) for n in b["nodes"]}
        if any(not {c["a"], c["b"]} <= in_building for c in s.couplings):
            self.refuse("mass_coupling", "OpenSees nodal masses are diagonal and martello's "
                        "couplings are general off-diagonal terms",
                        "use lumped masses (bar mass = \"lumped\")")
        for i, c in enumerate(s.contacts):
            if c["scheme"] != "penalty":
                self.refuse(f"contact[{i}] ({c['name']}).scheme = {c['scheme']}",
                            "OpenSees' zeroLength materials are force laws: it has no Newton "
                            "restitution impacts and no Lagrange multipliers on a node pair",
                            "give the contact a penalty law")
            if c.get("clipped"):
                self.refuse(f"contact[{i}] ({c['name']}).clipped = true",
                            "no OpenSees material clips a Kelvin force at zero (ViscoelasticGap "
                            "is the unclipped law, JankowskiImpact damps only while approaching)",
                            "remove clipped to export the unclipped Kelvin law")
        for i, n in enumerate(s.nodes):
            if n["fixed"] and n["u0"] != 0.0:
                self.refuse(f"node[{i}] ({n['name']}): fixed with u0 = {n['u0']:g}",
                            "a prescribed non-zero displacement needs a non-homogeneous "
                            "constraint the exported script does not write", "set u0 = 0")
        frames = s.extras.get("frames", [])
        for fr in frames:
            if fr["zeta"] > 0 and not np.allclose(fr["C"], fr["rayleigh"][0] * np.diag(
                    fr["frame"].lateral_masses()) + fr["rayleigh"][1] * fr["K"]):
                self.refuse(f"frame {fr['prefix']}: damping = \"modal\"",
                            "OpenSees' Rayleigh damping is a0 M + a1 K; a modal damping matrix "
                            "is not exported", "use damping = \"rayleigh\"")
        if an["integrator"] == "central-difference":
            rate = [lk["name"] for lk in s.links if lk["type"] in ("dashpot", "fluid_damper")]
            rate += [c["name"] for c in s.contacts if c.get("law") in (
                "kelvin", "jankowski", "hunt-crossley", "lankarani-nikravesh", "flores",
                "gonthier", "hertzdamp") and (c.get("damping") or c.get("restitution") is not None)]
            rate += [fr["prefix"] for fr in frames if fr["zeta"] > 0]
            if rate:
                self.refuse("analysis.integrator = central-difference with velocity-dependent "
                            f"forces ({', '.join(rate[:4])})",
                            "OpenSees' CentralDifference hands a material the velocity "
                            "−u_{n−1}/(2Δt) while it forms the residual, so a rate law's force is "
                            "wrong there (martello uses v_n + Δt a_n)",
                            "give --integrator newmark")
            moving = [n["name"] for n in s.nodes if not n["fixed"] and n["v0"] != 0.0]
            if moving:
                self.refuse(f"analysis.integrator = central-difference with v0 != 0 "
                            f"({', '.join(moving[:4])})",
                            "OpenSees' CentralDifference starts from u_{-1} = u_0, which drops "
                            "the initial velocity", "give --integrator newmark")

    # --- numbering ------------------------------------------------------------------------
    def tag(self, i):
        return self.ground if i < 0 else self.node_tag[i]

    def add(self, name, *args):
        self.cmds.append(Command(name, tuple(args)))

    def material(self, kind, *args):
        self.mat += 1
        self.add("uniaxialMaterial", kind, self.mat, *args)
        return self.mat

    def zero_length(self, i, j, mat, n=None):
        """A zeroLength element whose deformation is u_j − u_i (OpenSees' ZeroLength), along
        the plan direction n = (nx, ny) where given (local x = n, local y = n turned by 90°)."""
        self.ele += 1
        orient = () if n is None else ("-orient", float(n[0]), float(n[1]), 0.0, float(-n[1]), float(n[0]), 0.0)
        self.add("element", "zeroLength", self.ele, i, j, "-mat", mat, "-dir", 1, *orient)
        return self.ele

    def ends(self, what, item, first, second):
        """(i, j, n, terms) of a link or contact: the zeroLength's nodes, i the node of side
        `first` ("a" or "b"), its plan direction (None: along x) and the element's row as
        [(tag, dof, coef)] for the script's bookkeeping. A building's elements go through their
        row (martello.export.building); a node pair is its two nodes."""
        terms = element_terms(item)
        if self.s.extras.get("buildings"):
            i, j, n = self.bw.row(what, terms)
            if first == "b":
                i, j = j, i
            return i, j, n, [(*self.dof_of(k), c) for k, c in terms]
        return (self.tag(item[first]), self.tag(item["b" if first == "a" else "a"]), None,
                [(*self.dof_of(k), c) for k, c in terms])

    def dof_of(self, i):
        """(tag, dof) of scene node i."""
        return self.bw.node_of.get(i, (self.node_tag[i], 1))

    # --- the model ------------------------------------------------------------------------
    def build(self):
        self.check_scene()
        self.check_options()
        s = self.s
        frames = s.extras.get("frames", [])
        self.ndm, self.ndf = (3, 6) if s.extras.get("buildings") else (2, 3) if frames else (1, 1)
        self.energy = {"kinetic": [], "couplings": [], "springs": [], "bilinear": [], "contacts": [],
                       "blocks": []}
        self.add("wipe")
        self.add("model", "basic", "-ndm", self.ndm, "-ndf", self.ndf)
        self.nodes(frames)
        self.links()
        self.contacts()
        self.loads()
        self.initial_state()
        self.analysis()
        return self.model()

    def check_options(self):
        """An option the model would be written without is refused, as an integrator's own key
        is (_analysis): --tol on an explicit integrator, --material for a law no contact has."""
        if self.tol is not None and self.an["integrator"] == "central-difference":
            raise ExportError("--tol: central-difference is explicit, OpenSees runs no Newton "
                              "test: it would be ignored (remove it)")
        laws = {_law(c, 1.0).law for c in self.s.contacts}      # the name does not depend on m*
        for law, mat in self.materials.items():
            if law not in laws:
                raise ExportError(f"--material {law}={mat}: no penalty contact of the scene has law "
                                  f"{law} ({', '.join(sorted(laws)) or 'it has none'}): it would be "
                                  "ignored (remove it)")

    def node_cmd(self, tag, x=0.0, y=0.0):
        self.add("node", tag, *((x,) if self.ndm == 1 else (x, y) if self.ndm == 2 else (x, y, 0.0)))
        if self.ndm == 3:           # where a building's contact to a plain node acts (along())
            self.bw.position[tag] = (float(x), float(y), 0.0)

    def fix_cmd(self, tag, lateral=True):
        self.add("fix", tag, (1 if lateral else 0), *(1,) * (self.ndf - 1))

    def vector(self, dof, value):
        """A nodal vector of ndf numbers with `value` at dof (1-based)."""
        return tuple(value if d == dof else 0.0 for d in range(1, self.ndf + 1))

    def nodes(self, frames):
        s = self.s
        self.node_tag = [0] * len(s.nodes)
        self.frame_nodes = {}
        in_frame = {n for fr in frames for n in fr["nodes"]}
        in_frame |= {n for b in s.extras.get("buildings", []) for n in b["nodes"]}
        tag = 0
        for i, n in enumerate(s.nodes):
            if n["name"] in in_frame:
                continue
            tag += 1
            self.node_tag[i] = tag
            self.node_cmd(tag)
            if n["fixed"]:
                self.fix_cmd(tag)
            elif self.ndm > 1:
                self.fix_cmd(tag, lateral=False)    # a line node: lateral DOF only
            if not n["fixed"]:
                self.add("mass", tag, *self.vector(1, n["mass"]))
        tag += 1
        self.ground = tag
        self.node_cmd(tag)
        self.fix_cmd(tag)
        self.map.append(("ground", f"node {tag}, fixed"))
        for i, n in enumerate(s.nodes):
            if self.node_tag[i]:
                self.map.append((f"node {n['name']} (m = {n['mass']:g} kg{', fixed' if n['fixed'] else ''})",
                                 f"node {self.node_tag[i]}"))
        # frames side by side, left to right in the scene's order: a joint between one
        # frame's last column line and the next one's first is a zero-length element
        self.x0 = 0.0
        for i, n in enumerate(s.nodes):
            if not n["fixed"] and self.node_tag[i]:
                self.energy["kinetic"].append((self.node_tag[i], 1, n["mass"]))
        for fr in frames:
            tag = self.frame(fr, tag)
            self.x0 += float(fr["frame"].x[-1])
        tag = self.bw.write(tag)
        self.tag_count = tag

    def frame(self, fr, tag):
        """A [[frame]]: every joint a 3-DOF node, members elasticBeamColumn on a Linear
        transformation, the lateral masses on the joints that carry them, a rigid floor as
        equalDOF of its joints' u, Rayleigh damping a0 M + a1 K by region (docs/opensees.md
        "Frames")."""
        s, pf = self.s, fr["frame"]
        joint, eles, free = {}, [], []
        for lev in range(pf.storeys + 1):
            for line in range(pf.bays + 1):
                tag += 1
                joint[(line, lev)] = tag
                self.node_cmd(tag, self.x0 + float(pf.x[line]), float(pf.y[lev]))
                if lev == 0:
                    self.add("fix", tag, 1, 1, 1 if pf.base == "fixed" else 0)
                else:
                    free.append(tag)
        self.transf = getattr(self, "transf", 0) + 1
        self.add("geomTransf", "Linear", self.transf)
        for m in pf.members:
            self.ele += 1
            self.add("element", "elasticBeamColumn", self.ele, joint[m.ends[0]], joint[m.ends[1]],
                     m.A, m.E, m.I, self.transf)
            eles.append(self.ele)
        masses = pf.lateral_masses()
        for k, name in enumerate(fr["nodes"]):
            i = s.index[name]
            if pf.mass_model == "diaphragm":
                floor = k + 1
                master = joint[(0, floor)]
                for line in range(1, pf.bays + 1):
                    self.add("equalDOF", master, joint[(line, floor)], 1)
                self.equal_dof = True
            else:
                floor, line = divmod(k, pf.bays + 1)
                floor += 1
                master = joint[(line, floor)]
            self.node_tag[i] = master
            self.energy["kinetic"].append((master, 1, float(masses[k])))
            self.add("mass", master, float(masses[k]), 0.0, 0.0)
            self.map.append((f"frame node {name} (m = {masses[k]:g} kg)", f"node {master}"))
        self.energy["blocks"].append(([(self.node_tag[s.index[nm]], 1) for nm in fr["nodes"]],
                                      [[float(x) for x in row] for row in fr["K"]]))
        a0, a1 = fr["rayleigh"]
        if fr["zeta"] > 0:
            self.region = getattr(self, "region", 0) + 1
            self.add("region", self.region, "-eleOnly", *eles, "-rayleigh", 0.0, a1, 0.0, 0.0)
            self.region += 1
            self.add("region", self.region, "-nodeOnly", *free, "-rayleigh", a0, 0.0, 0.0, 0.0)
        self.map.append((f"frame {fr['prefix']} ({pf.storeys} storeys x {pf.bays} bays, {pf.base} base, "
                         f"{pf.mass_model})", f"{len(eles)} elasticBeamColumn, Rayleigh a0 = {a0:.6g}, "
                         f"a1 = {a1:.6g}"))
        self.diff.append(f"frame {fr['prefix']}: OpenSees carries the joints' vertical and rotational "
                         "DOFs (massless) that martello condenses out: the same lateral dynamics up "
                         "to round-off (docs/opensees.md \"Frames\")")
        return tag

    def links(self):
        s = self.s
        for li, lk in enumerate(s.links):
            kind, name = lk["type"], lk["name"]
            # element deformation u_j − u_i = u_a − u_b = martello's elongation du
            i, j, n, terms = self.ends(f"link[{li}] ({name})", lk, "b", "a")
            if kind == "spring":
                mat = self.material("Elastic", lk["k"])
                what = f"Elastic E = {lk['k']:.17g}"
            elif kind == "bar":
                mat = self.material("Elastic", lk["EA"] / lk["L"])
                what = f"Elastic E = EA/L = {lk['EA'] / lk['L']:.17g}"
            elif kind == "dashpot":
                mat = self.material("Viscous", lk["c"], 1.0)
                what = f"Viscous C = {lk['c']:.17g}, alpha = 1"
            elif kind == "fluid_damper":
                mat = self.material("Viscous", lk["c"], lk["alpha"], lk["v_reg"] or 1e-21)
                what = f"Viscous C = {lk['c']:.6g}, alpha = {lk['alpha']:g}, minVel = {lk['v_reg']:g}"
                if lk["alpha"] != 1.0 and lk["v_reg"] > 0:
                    self.diff.append(
                        f"fluid damper {name}: below |dv| = v_reg = {lk['v_reg']:g} m/s martello uses "
                        "the secant c·v_reg^(α−1)·dv, OpenSees' Viscous the power law itself (its "
                        "minVel bounds only the tangent): the forces differ by at most "
                        f"c·v_reg^α = {lk['c'] * lk['v_reg'] ** lk['alpha']:.3g} N there")
            elif kind == "bilinear":
                mat = self.material("Steel01", lk["fy"], lk["k"], lk["hardening"])
                what = (f"Steel01 Fy = {lk['fy']:.6g}, E0 = {lk['k']:.6g}, b = {lk['hardening']:g} "
                        "(kinematic hardening, no isotropic terms: martello's return map)")
            else:                                    # pragma: no cover - the loader's kinds
                self.refuse(f"link {name}", f"link type {kind}")
            ele = self.zero_length(i, j, mat, n)
            self.map.append((f"link {name} ({kind})", f"zeroLength {ele}: {what}" + self.along(i, j, n)))
            if kind in ("spring", "bar"):
                self.energy["springs"].append((terms, lk["k"] if kind == "spring" else lk["EA"] / lk["L"]))
            elif kind == "bilinear":
                self.energy["bilinear"].append((ele, terms, lk["k"], lk["hardening"]))

    def along(self, i, j, n):
        """Where a building's element acts (its nodes and direction), for the mapping."""
        if n is None:
            return ""
        pi, pj = (self.bw.position.get(t) for t in (i, j))
        return (f" from node {i} ({pi[0]:g}, {pi[1]:g}, {pi[2]:g}) to node {j} ({pj[0]:g}, {pj[1]:g}, "
                f"{pj[2]:g}) along ({n[0]:g}, {n[1]:g}) on the row's line of action")

    def contacts(self):
        s = self.s
        self.contact_ele, self.contact_mat, self.contact_terms = [], [], []
        mass = [n["mass"] for n in s.nodes]
        fixed = [n["fixed"] for n in s.nodes]
        for ci, c in enumerate(s.contacts):
            mstar = effective_mass(mass, fixed, element_terms(c))
            law = _law(c, mstar)                     # the target e resolved by the published formula
            name, gap = c["name"], float(c["gap"])
            mat_kind = self.materials.get(law.law, DEFAULT_MATERIAL[law.law])
            if mat_kind != DEFAULT_MATERIAL[law.law] and (law.law, mat_kind) not in MODEL_DIFFERENCE \
                    and (law.law, mat_kind) not in EXACT_ALTERNATIVES:
                self.refuse(f"contact {name}: law {law.law} as {mat_kind}",
                            "not a material this law maps onto",
                            f"use {DEFAULT_MATERIAL[law.law]} (docs/opensees.md)")
            if gap < 0 and mat_kind != "ElasticPPGap":
                self.refuse(f"contact {name}: gap = {gap:g} (an initial overlap)",
                            f"{mat_kind} makes every gap a clearance (it flips the sign of a "
                            "positive one)", "give gap >= 0")
            # compression materials: element deformation u_j − u_i = u_b − u_a = −(δ + gap)
            i, j, n, terms = self.ends(f"contact[{ci}] ({name})", c, "a", "b")
            og = -gap if gap != 0 else 0.0
            if mat_kind == "ElasticPPGap":
                # a linear spring past the gap in compression; Fy far beyond any force
                mat = self.material("ElasticPPGap", law.K, -1.0e300, og)
                what = f"ElasticPPGap E = {law.K:.17g}, Fy = -1e300 (never yields), gap = {og:.17g}"
            elif mat_kind == "ImpactMaterial":
                mat = self.material("ImpactMaterial", law.K, law.K, -1.0, og)
                what = f"ImpactMaterial K1 = K2 = {law.K:.17g}, gap = {og:.17g}"
            elif mat_kind == "ViscoelasticGap":
                mat = self.material("ViscoelasticGap", law.K, law.c, og)
                what = f"ViscoelasticGap K = {law.K:.17g}, C = {law.c:.17g}, gap = {og:.17g}"
            elif mat_kind == "Hertzdamp":
                mat = self.material("Hertzdamp", law.K, law.c, og, law.n)
                what = (f"Hertzdamp Kh = {law.K:.17g}, xiNorm = a = {law.c:.17g}, gap = {og:.17g}, "
                        f"n = {law.n:g}")
                if law.c > 0:
                    self.diff.append(
                        f"contact {name} ({law.law}): OpenSees' Hertzdamp takes v_in as the rate at "
                        "the end of the first step in contact, martello at the located onset: "
                        "χ = a/v_in differs by O(Δt) per impact")
            elif mat_kind == "JankowskiImpact":
                if law.law == "kelvin":
                    xi = law.c / (2.0 * math.sqrt(law.K * mstar))
                    mat = self.material("JankowskiImpact", law.K, xi, mstar, og, 1.0)
                    what = f"JankowskiImpact Kh = {law.K:.17g}, xi = {xi:.17g}, mEff = {mstar:.17g}, n = 1"
                    self.diff.append(MODEL_DIFFERENCE[("kelvin", mat_kind)].format(
                        name=name, c=law.c, e_half=half_kelvin_e(xi), e_full=_kelvin_e(xi)))
                else:
                    meff = mstar if math.isfinite(mstar) else 0.0
                    mat = self.material("JankowskiImpact", law.K, law.c, meff, og, law.n)
                    what = (f"JankowskiImpact Kh = {law.K:.17g}, xi = {law.c:.17g}, mEff = {meff:.17g}, "
                            f"n = {law.n:g}")
            ele = self.zero_length(i, j, mat, n)
            self.contact_ele.append(ele)
            self.contact_terms.append(terms)
            self.contact_mat.append((name, law.law, mat_kind))
            self.energy["contacts"].append((terms, gap, law.K, law.n))
            self.map.append((f"contact {name} ({law.law}, K = {law.K:g}, n = {law.n:g}, damping = "
                             f"{law.c:g}, gap = {gap:g})", f"zeroLength {ele}: {what}" + self.along(i, j, n)))

    # --- loads ----------------------------------------------------------------------------
    def series(self, fn, label):
        """A time series for a time function of docs/scene-input.md (its value, not sampled)."""
        self.n_series += 1
        tag, k = self.n_series, fn["type"]
        if k == "constant":
            self.add("timeSeries", "Constant", tag, "-factor", fn["value"])
        elif k == "sine":
            # Trig: factor·sin(2π(t − tStart)/period + shift) on [tStart, tEnd], both included.
            # An open-ended sine ends two steps after the analysis (never evaluated later):
            # UniformExcitation integrates its series over [tStart, tEnd] when it is built, and
            # an end at 1e300 makes OpenSees print "Ran out of memory" there
            t1 = min(float(fn["t_end"]), float(self.an["t_end"]) + 2.0 * float(self.an.get("dt") or 0.0))
            self.add("timeSeries", "Trig", tag, fn["t_start"], t1, 2.0 * math.pi / fn["omega"],
                     "-factor", fn["amplitude"], "-shift", fn["phase"])
        elif k == "half_sine":
            self.add("timeSeries", "Trig", tag, fn["t_start"], fn["t_end"],
                     2.0 * (fn["t_end"] - fn["t_start"]), "-factor", fn["amplitude"])
        elif k == "rectangular":
            # martello's window is [t_start, t_end), Rectangular's [tStart, tEnd]: end it one
            # ulp earlier, so that a step landing on t_end sees 0 in both
            self.add("timeSeries", "Rectangular", tag, fn["t_start"], math.nextafter(fn["t_end"], -math.inf),
                     "-factor", fn["amplitude"])
        else:
            ts, vs = self.table(fn)
            if len(ts) <= FILE_SAMPLES:
                self.add("timeSeries", "Path", tag, "-time", *ts, "-values", *vs)
            else:
                ft, fv = f"{label}_time.txt", f"{label}_values.txt"
                self.files[ft] = "".join(f"{x!r}\n" for x in ts)
                self.files[fv] = "".join(f"{x!r}\n" for x in vs)
                self.add("timeSeries", "Path", tag, "-fileTime", _File(ft), "-filePath", _File(fv))
        return tag

    def table(self, fn):
        """(times, values) of a table or a record, values in m/s² (or N) times its scale: a
        Path series interpolates linearly between them and is 0 outside, as martello's table."""
        if fn["type"] == "table":
            return [float(x) for x in fn["t"]], [float(fn.get("scale", 1.0)) * float(x) for x in fn["values"]]
        from ..ground_motion.records import read_record
        rec = read_record(fn["file"], fmt=fn.get("format"), units=fn.get("units"))
        scale = float(fn.get("scale", 1.0))
        return [float(x) for x in rec.t], [scale * float(x) for x in rec.accel]

    def loads(self):
        s = self.s
        pattern = 0
        if s.ground is not None:
            tag = self.series(s.ground, "ground")
            # UniformExcitation loads −M·ι·ü_g and its displacements are relative: martello's u;
            # a building's ι is (cos α, sin α, 0) on ux, uy, rz (docs/buildings.md "Ground motion")
            buildings = s.extras.get("buildings", [])
            if buildings:
                iota = buildings[0]["influence"]
                names = [nm.rsplit(".", 1)[-1] for nm in buildings[0]["nodes"]]
                dirs = [(1, float(iota[names.index("ux")])), (2, float(iota[names.index("uy")]))]
            else:
                dirs = [(1, 1.0)]
            for dof, f in dirs:
                if f == 0.0:
                    continue
                pattern += 1
                self.add("pattern", "UniformExcitation", pattern, dof, "-accel", tag,
                         *(() if f == 1.0 else ("-fact", f)))
                self.map.append((f"ground acceleration ({s.ground['type']})" + (
                    f" x {f:.17g} along {'xy'[dof - 1]}" if buildings else ""),
                    f"timeSeries {tag}, pattern UniformExcitation {pattern} (direction {dof})"))
        loads = {}
        if s.gravity:
            for i, n in enumerate(s.nodes):
                if not n["fixed"]:
                    loads.setdefault(None, []).append((*self.dof_of(i), n["mass"] * s.gravity))
        for f in s.forces:
            loads.setdefault(id(f), []).append((*self.dof_of(f["node"]), 1.0, f["function"]))
        for key, items in loads.items():
            if key is None:
                self.n_series += 1
                tag = self.n_series
                self.add("timeSeries", "Constant", tag)
                what = f"gravity {s.gravity:g} m/s²: nodal loads m·g, Constant series {tag}"
            else:
                tag = self.series(items[0][3], f"force{len(self.files)}")
                what = f"nodal force ({items[0][3]['type']}), series {tag}"
            pattern += 1
            self.add("pattern", "Plain", pattern, tag)
            for node, dof, value, *_ in items:
                self.add("load", node, *self.vector(dof, value))
            self.add("endPattern")
            self.map.append((what, f"pattern Plain {pattern}"))

    # --- initial state --------------------------------------------------------------------
    def initial_state(self):
        """u0 and v0 as committed nodal values, and a0 = M⁻¹(f_ext(0) − f_int(u0, v0)): OpenSees'
        Newmark family takes the committed acceleration as a_0 and solves no initial
        equilibrium (docs/opensees.md "Initial state")."""
        s = self.s
        n = len(s.nodes)
        u = np.array([nd["u0"] for nd in s.nodes], float)
        v = np.array([0.0 if nd["fixed"] else nd["v0"] for nd in s.nodes], float)
        m = np.array([nd["mass"] for nd in s.nodes], float)
        f = np.zeros(n)
        row = lambda terms, x: sum(c * x[k] for k, c in terms)     # noqa: E731  (g·x; ground 0)

        def apply(terms, force):            # a tension force f on the row g: −g f (docs/buildings.md)
            for k, c in terms:
                f[k] -= c * force
        for lk in s.links:
            terms = element_terms(lk)
            du, dv = row(terms, u), row(terms, v)
            kind = lk["type"]
            if kind == "spring":
                force = lk["k"] * du
            elif kind == "bar":
                force = lk["EA"] / lk["L"] * du
            elif kind == "bilinear":
                rho, k, fy = lk["hardening"], lk["k"], lk["fy"]
                force = min(max(k * du, rho * k * du - (1 - rho) * fy), rho * k * du + (1 - rho) * fy)
            elif kind == "dashpot":
                force = lk["c"] * dv
            else:
                vr = lk["v_reg"]
                force = (lk["c"] * vr ** (lk["alpha"] - 1) * dv if abs(dv) < vr
                         else lk["c"] * math.copysign(abs(dv) ** lk["alpha"], dv))
            apply(terms, force)
        mass_l, fixed = list(m), [nd["fixed"] for nd in s.nodes]
        for c in s.contacts:
            terms = element_terms(c)
            law = _law(c, effective_mass(mass_l, fixed, terms))
            d = row(terms, u) - c["gap"]
            if d > 0:
                rate = row(terms, v)
                if law.law in ("linear", "kelvin"):
                    force = law.K * d + law.c * rate
                elif law.law == "jankowski":
                    force = law.K * d ** 1.5 + (2 * law.c * math.sqrt(law.K * math.sqrt(d) * law.mstar) * rate
                                                if rate > 0 else 0.0)
                else:
                    force = law.K * d ** law.n * max(0.0, 1.0 + (law.c / rate if rate > 0 else 0.0) * rate)
                apply(terms, force)         # compressive P: −g P
        for blk in s.blocks:
            idx = list(blk["nodes"])
            f[idx] -= np.asarray(blk["k"]) @ u[idx] + np.asarray(blk["c"]) @ v[idx]
        f += m * s.gravity
        # the mass matrix: diagonal, with a building's couplings (a floor referred off its centre)
        Mc = np.zeros((n, n)) if len(s.couplings) else None
        if Mc is not None:
            Mc[np.arange(n), np.arange(n)] = m
            for cp in s.couplings:
                Mc[cp["a"], cp["b"]] = Mc[cp["b"], cp["a"]] = cp["value"]
        if s.ground is not None:
            iota = np.ones(n) if s.influence is None else np.asarray(s.influence, float)
            f -= (m * iota if Mc is None else Mc @ iota) * self.value_at_zero(s.ground)
        for fo in s.forces:
            f[fo["node"]] += self.value_at_zero(fo["function"])
        free = [i for i, nd in enumerate(s.nodes) if not nd["fixed"]]
        acc = np.zeros(n)
        if Mc is None:
            acc[free] = f[free] / m[free]
        else:
            acc[free] = np.linalg.solve(Mc[np.ix_(free, free)], f[free])
        self.accelerated = []               # free nodes with a_0 ≠ 0 (central difference's start)
        for i in free:
            tag, dof = self.dof_of(i)
            a0 = acc[i]
            if a0 != 0.0:
                self.accelerated.append(s.nodes[i]["name"])
            if u[i] != 0.0:
                self.add("setNodeDisp", tag, dof, float(u[i]), "-commit")
            if v[i] != 0.0:
                self.add("setNodeVel", tag, dof, float(v[i]), "-commit")
            if a0 != 0.0:
                self.add("setNodeAccel", tag, dof, float(a0), "-commit")

    def value_at_zero(self, fn):
        if fn["type"] in ("table", "record"):
            ts, vs = self.table(fn)
            return float(np.interp(0.0, ts, vs)) if ts[0] <= 0.0 <= ts[-1] else 0.0
        return time_function(fn, None)(0.0)

    # --- analysis -------------------------------------------------------------------------
    def analysis(self):
        an = self.an
        name = an["integrator"]
        dt, t_end = float(an["dt"]), float(an["t_end"])
        if dt > t_end:
            self.refuse(f"dt = {dt:g}", f"longer than t_end = {t_end:g}")
        self.dt = dt
        # martello's grid: t_k = k·dt, k = 1 … ceil(t_end/dt (1 − 1e-12)), never a shortened step
        self.budget(t_end / dt * (1.0 - 1e-12))
        self.steps = max(1, math.ceil(t_end / dt * (1.0 - 1e-12)))
        self.every = int(an.get("output", {}).get("every", 1))
        handler = "Transformation" if getattr(self, "equal_dof", False) else "Plain"
        self.add("constraints", handler)
        self.add("numberer", "RCM")
        self.add("system", "BandGeneral" if self.ndm == 1 else "UmfPack")
        tol_inc = float(an.get("tol_increment", 1e-11))
        tol = self.tol if self.tol is not None else tol_inc * DISP_SCALE
        iters = max(int(an.get("max_newton", 30)), MIN_NEWTON)
        if name == "central-difference":
            self.add("algorithm", "Linear")
            self.add("integrator", "CentralDifference")
            what = "CentralDifference (explicit: no Newton iteration)"
            if self.accelerated:
                self.diff.append(
                    "central-difference: OpenSees starts from u_{-1} = u_0, i.e. from a_0 = 0 "
                    "(CentralDifference::domainChanged); here a_0 != 0 at "
                    f"{', '.join(self.accelerated[:4])} (gravity or a load at t = 0): its velocities "
                    "carry an error a_0·Δt/2 from the first step on, first order in Δt")
        else:
            self.add("test", "NormDispIncr", tol, iters)
            self.add("algorithm", "Newton")
            if name == "newmark":
                beta, gamma = an["beta"], an["gamma"]
                self.add("integrator", "Newmark", gamma, beta)
                what = f"Newmark gamma = {gamma:g}, beta = {beta:g}"
            elif name == "hht":
                al = an["alpha"]
                aos = 1.0 + al
                self.add("integrator", "HHT", aos, 0.5 - al, 0.25 * (1 - al) ** 2)
                what = f"HHT alpha = 1 + α = {aos:g} (OpenSees weighs the new state)"
            else:
                rho = an["rho_inf"]
                am, af = (2.0 - rho) / (1.0 + rho), 1.0 / (1.0 + rho)
                # the two-number form: its constructor sets Chung & Hulbert's γ = ½ + αM − αF,
                # β = ¼(1 + αM − αF)²; the four-number form hands "$gamma $beta" to a
                # constructor (αM, αF, β, γ), i.e. swapped (docs/opensees.md "Integrators")
                self.add("integrator", "GeneralizedAlpha", am, af)
                what = (f"GeneralizedAlpha alphaM = {am:.17g}, alphaF = {af:.17g} (ρ∞ = {rho:g}; γ, β "
                        "of Chung & Hulbert set by OpenSees)")
            if name == "generalized-alpha":
                self.diff.append(
                    "generalized-alpha: OpenSees' GeneralizedAlpha forms the inertia with a_{n+1} "
                    "while its tangent carries alphaM (GeneralizedAlpha::update sets the response "
                    "(u_{n+αF}, v_{n+αF}, a_{n+1})): its solution is first-order accurate, "
                    "martello's Chung–Hulbert second order (docs/opensees.md \"Integrators\")")
            if name in ("hht", "generalized-alpha"):
                self.diff.append(
                    f"{name}: OpenSees evaluates the internal and external forces at the "
                    "interpolated state and time t_n + α_f Δt; martello interpolates the forces "
                    "(Hilber et al. 1977): the same on a linear scene with linear loads, O(Δt²) "
                    "apart otherwise")
            self.map.append(("Newton test", f"NormDispIncr {tol:g} m (tol_increment {tol_inc:g} "
                             f"x {DISP_SCALE:g} m), at most {iters} iterations, Newton"))
        self.bw.modal_damping()
        self.add("analysis", "Transient")
        self.map.append((f"integrator {name}, dt = {dt:g} s, t_end = {t_end:g} s",
                         f"{what}; {self.steps} steps of {dt:g} s"))
        if an.get("event_split"):
            self.diff.append("event_split = true: OpenSees has no event-split steps; the exported "
                             "run takes plain steps (first order across a Kelvin force jump)")

    def budget(self, steps):
        """The step budget of `martello run` (martello.run.check_budget: MAX_WORK node-steps),
        unless force; never past 2^53 steps, where the grid t_k = k·dt is no longer exact in
        doubles (and t_end/dt = inf for a subnormal dt)."""
        from ..run import MAX_WORK, _g
        nodes = max(1, len(self.s.nodes))
        if steps <= 2.0 ** 53 and (self.force or steps * nodes <= MAX_WORK):
            return
        name = {k: (_flag(k) if k in self.over else f"analysis.{k}") for k in ("dt", "t_end")}
        lead = name["t_end"] if "t_end" in self.over and "dt" not in self.over else name["dt"]
        what = f"t_end/dt = {self.an['t_end']!r}/{self.an['dt']!r} = {_g(steps)} steps"
        fix = f"raise {name['dt']} or shorten {name['t_end']}"
        if steps > 2.0 ** 53:
            raise ExportError(f"{lead}: {what}, more than 2^53: the step grid k·dt is not exact "
                              f"in doubles past it ({fix})")
        raise ExportError(f"{lead}: {what}" + (f" of {nodes} nodes" if nodes > 1 else "")
                          + f", more than the {_g(MAX_WORK)} node-steps a run may take ({fix}; "
                          "--force writes it anyway)")

    def model(self):
        s = self.s
        out = s.analysis.get("output", {})
        names = [n["name"] for n in s.nodes]
        want_nodes = out.get("nodes")
        want_nodes = names if want_nodes is None else list(want_nodes)
        cnames = [c["name"] for c in s.contacts]
        want_contacts = out.get("contacts")
        want_contacts = cnames if want_contacts is None else list(want_contacts)
        cols = [Column("t", "t", ())]
        for nm in want_nodes:
            i = s.index[nm]
            if s.nodes[i]["fixed"]:
                continue
            for k in ("u", "v", "a"):
                cols.append(Column(f"{k}:{nm}", k, self.dof_of(i)))
        at = {c["name"]: ci for ci, c in enumerate(s.contacts)}
        for nm in want_contacts:
            ci = at[nm]
            c = s.contacts[ci]
            cols.append(Column(f"penetration:{nm}", "penetration", (self.contact_terms[ci], float(c["gap"]))))
            cols.append(Column(f"force:{nm}", "force", (self.contact_ele[ci],)))
        cols += [Column("energy:kinetic", "energy", ("kinetic",)),
                 Column("energy:recoverable", "energy", ("recoverable",))]
        return OpenSeesModel(title=s.title, source=str(s.source), ndm=self.ndm, ndf=self.ndf,
                             commands=self.cmds, columns=cols, dt=self.dt, steps=self.steps,
                             every=self.every, files=self.files, mapping=self.map,
                             differences=self.diff, contact_materials=self.contact_mat,
                             integrator=self.an["integrator"], energy=self.energy,
                             members=[(f"{pre}.{name}", ele) for pre, name, ele in self.bw.members],
                             modes=sum(len(b["nodes"]) for b in s.extras.get("buildings", [])))


class _File(str):
    """A data file beside the script: the Python script resolves it against its own folder."""


# the keys of [analysis] an integrator of the Newmark family reads beyond the common ones
OWN_KEYS = {"newmark": ("beta", "gamma"), "hht": ("alpha",), "generalized-alpha": ("rho_inf",),
            "central-difference": ()}
COMMON_KEYS = ("type", "dt", "t_end", "output", "tol_residual", "tol_increment", "max_newton",
               "event_split")


def _flag(key):
    return "--" + key.replace("_", "-")


def _analysis(scene, over):
    """The scene's [analysis] with `over` applied (integrator, dt, t_end, beta, gamma, alpha,
    rho_inf): another integrator drops the scene's integrator's own keys, Newmark's default
    to average acceleration, HHT's alpha and generalized-α's rho_inf must be given. A key
    that is another integrator's own (--alpha on a Newmark scene without --integrator hht)
    is refused: the model would be written without it."""
    an = dict(scene.analysis)
    over = {k: v for k, v in over.items() if v is not None}
    name = over.get("integrator", an.get("integrator"))
    for key in over:
        owner = next((o for o, keys in OWN_KEYS.items() if key in keys), None)
        if owner is not None and owner != name:
            whose = "--integrator" if "integrator" in over else "the scene's integrator"
            raise ExportError(f"{_flag(key)}: applies to integrator {owner}, not {name} ({whose}): "
                              f"it would be ignored (remove it, or give --integrator {owner})")
    if name != an.get("integrator"):
        an = {k: v for k, v in an.items() if k in COMMON_KEYS}
        an["integrator"] = name
    an.update({k: v for k, v in over.items() if v is not None})
    if name == "newmark":
        an["beta"] = 0.25 if an.get("beta") is None else an["beta"]
        an["gamma"] = 0.5 if an.get("gamma") is None else an["gamma"]
    for key in OWN_KEYS.get(name, ()):
        if an.get(key) is None:
            raise ExportError(f"{scene.source}: analysis.{key}: missing for integrator {name} "
                              f"(give {_flag(key)})")
    return an


def opensees_model(scene, analysis=None, materials=None, tol=None, force=False):
    """The scene as an OpenSeesModel. `analysis` overrides keys of the scene's [analysis]
    (integrator, dt, t_end, beta, gamma, alpha, rho_inf); `materials` maps a law to a material
    other than its default (docs/opensees.md "Contact laws"); `tol` is the NormDispIncr
    tolerance in m (default tol_increment x 0.1 m); `force` writes a model past the step
    budget of `martello run` (martello.run.MAX_WORK). ExportError names what cannot be
    exported and why."""
    return _Builder(scene, analysis, materials, tol, force).build()
