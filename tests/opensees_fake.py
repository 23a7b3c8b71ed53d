"""A recording stand-in for `openseespy.opensees`: every call is checked against the grammar of
the OpenSees command it names (the argument counts and kinds of OpenSees v3.7.1's parsers:
OPS_ElasticPPGap ... OPS_ZeroLength, docs/opensees.md) and against the domain built so far
(a node exists before an element uses it, a material before an element, tags are unique),
then recorded. The response commands return a displacement u_i(t) = tag·1e-3·sin(t) (and its
derivatives) so that the script's sampling can be checked number by number, and
basicForce returns −(tag + t)."""

import math
import types


class FakeOpenSees:
    MATERIALS = {            # name: (number of float arguments after the tag, allowed extra)
        "Elastic": (1, 2), "Viscous": (2, 1), "Steel01": (3, 4), "ElasticPPGap": (3, 2),
        "ImpactMaterial": (4, 0), "ViscoelasticGap": (3, 0), "Hertzdamp": (3, 1),
        "JankowskiImpact": (4, 1), "Hardening": (4, 1),
    }
    SERIES = ("Constant", "Trig", "Rectangular", "Path", "Linear")
    INTEGRATORS = {"Newmark": (2,), "HHT": (1, 3), "GeneralizedAlpha": (2, 4), "CentralDifference": (0,)}

    def __init__(self):
        self.calls, self.nodes, self.fixed, self.masses = [], {}, {}, {}
        self.materials, self.elements, self.series, self.patterns = {}, {}, {}, {}
        self.initial, self.time, self.steps, self.integ = {}, 0.0, 0, None
        self.ndm = self.ndf = None
        self.pattern_open = None

    def module(self):
        m = types.ModuleType("openseespy.opensees")
        for name in dir(self):
            if not name.startswith("_") and callable(getattr(self, name)) and name != "module":
                setattr(m, name, getattr(self, name))
        return m

    def _rec(self, name, *args):
        self.calls.append((name, args))

    @staticmethod
    def _num(x, what):
        assert isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x), \
            f"{what}: {x!r} is not a finite number"

    # --- model -----------------------------------------------------------------------------
    def wipe(self):
        self._rec("wipe")

    def model(self, kind, *args):
        assert kind == "basic" and args[0] == "-ndm" and args[2] == "-ndf", args
        self.ndm, self.ndf = args[1], args[3]
        self._rec("model", kind, *args)

    def node(self, tag, *coords):
        assert self.ndm is not None, "model before node"
        assert tag not in self.nodes, f"node {tag} defined twice"
        assert len(coords) == self.ndm, f"node {tag}: {len(coords)} coordinates in ndm = {self.ndm}"
        self.nodes[tag] = coords
        self._rec("node", tag, *coords)

    def fix(self, tag, *flags):
        assert tag in self.nodes and len(flags) == self.ndf and set(flags) <= {0, 1}, (tag, flags)
        self.fixed[tag] = flags
        self._rec("fix", tag, *flags)

    def mass(self, tag, *values):
        assert tag in self.nodes and len(values) == self.ndf, (tag, values)
        assert values[0] > 0
        self.masses[tag] = values
        self._rec("mass", tag, *values)

    def equalDOF(self, master, slave, *dofs):
        assert master in self.nodes and slave in self.nodes
        self._rec("equalDOF", master, slave, *dofs)

    def geomTransf(self, kind, tag, *vecxz):
        assert kind == "Linear" and len(vecxz) == (3 if self.ndm == 3 else 0), (kind, tag, vecxz)
        if vecxz:                          # a unit vector in the local x-z plane
            assert abs(math.hypot(*vecxz) - 1.0) < 1e-12, vecxz
        self._rec("geomTransf", kind, tag, *vecxz)

    def rigidDiaphragm(self, perp, master, *slaves):
        assert perp == 3 and self.ndm == 3 and slaves, (perp, master, slaves)
        assert master in self.nodes and all(t in self.nodes for t in slaves), (master, slaves)
        assert self.fixed.get(master, ())[2:5] == (1, 1, 1), "a master's uz, θx, θy are held"
        self._rec("rigidDiaphragm", perp, master, *slaves)

    def region(self, tag, *args):
        self._rec("region", tag, *args)

    def uniaxialMaterial(self, kind, tag, *args):
        assert kind in self.MATERIALS, f"uniaxialMaterial {kind}: not a material the exporter may use"
        assert tag not in self.materials, f"material {tag} defined twice"
        need, extra = self.MATERIALS[kind]
        assert need <= len(args) <= need + extra, f"{kind} {tag}: {len(args)} arguments"
        for x in args:
            self._num(x, f"{kind} {tag}")
        if kind in ("ViscoelasticGap", "Hertzdamp", "JankowskiImpact", "ImpactMaterial"):
            gap = args[{"ViscoelasticGap": 2, "Hertzdamp": 2, "JankowskiImpact": 3, "ImpactMaterial": 3}[kind]]
            # these materials turn a positive gap into a negative one: a clearance is <= 0
            assert gap <= 0, f"{kind} {tag}: gap {gap} > 0 would be flipped by OpenSees"
        self.materials[tag] = (kind, args)
        self._rec("uniaxialMaterial", kind, tag, *args)

    def element(self, kind, tag, i, j, *args):
        assert tag not in self.elements, f"element {tag} defined twice"
        assert i in self.nodes and j in self.nodes, f"element {tag}: nodes {i}, {j}"
        if kind == "zeroLength":
            assert args[0] == "-mat" and args[2] == "-dir" and args[3] == 1, args
            assert args[1] in self.materials, f"element {tag}: material {args[1]} undefined"
            assert len(args) == 4 or (args[4] == "-orient" and len(args) == 11), args
        elif kind == "ElasticTimoshenkoBeam":     # E G A Jx Iy Iz Avy Avz transf (3D)
            assert self.ndm == 3 and len(args) == 9, args
        else:                                     # A E I transf (2D); A E G J Iy Iz transf (3D)
            assert kind == "elasticBeamColumn" and len(args) == (7 if self.ndm == 3 else 4), args
        self.elements[tag] = (kind, i, j, args)
        self._rec("element", kind, tag, i, j, *args)

    def timeSeries(self, kind, tag, *args):
        assert kind in self.SERIES and tag not in self.series, (kind, tag)
        self.series[tag] = (kind, args)
        self._rec("timeSeries", kind, tag, *args)

    def pattern(self, kind, tag, *args):
        assert tag not in self.patterns
        if kind == "UniformExcitation":
            assert args[0] in ((1, 2) if self.ndm == 3 else (1,)) and args[1] == "-accel", args
            assert args[2] in self.series and len(args) in (3, 5), args
        else:
            assert kind == "Plain" and args[0] in self.series, args
        self.patterns[tag] = (kind, args)
        self.pattern_open = tag if kind == "Plain" else None
        self._rec("pattern", kind, tag, *args)

    def load(self, node, *values):
        assert self.pattern_open is not None and node in self.nodes and len(values) == self.ndf
        self._rec("load", node, *values)

    def setNodeDisp(self, tag, dof, value, flag):
        assert flag == "-commit" and tag in self.nodes
        self.initial[("u", tag)] = value
        self._rec("setNodeDisp", tag, dof, value, flag)

    def setNodeVel(self, tag, dof, value, flag):
        assert flag == "-commit" and tag in self.nodes
        self.initial[("v", tag)] = value
        self._rec("setNodeVel", tag, dof, value, flag)

    def setNodeAccel(self, tag, dof, value, flag):
        assert flag == "-commit" and tag in self.nodes
        self.initial[("a", tag)] = value
        self._rec("setNodeAccel", tag, dof, value, flag)

    # --- analysis --------------------------------------------------------------------------
    def constraints(self, kind):
        self._rec("constraints", kind)

    def numberer(self, kind):
        self._rec("numberer", kind)

    def system(self, kind):
        self._rec("system", kind)

    def test(self, kind, tol, iters):
        assert kind == "NormDispIncr" and tol > 0 and iters > 0
        self._rec("test", kind, tol, iters)

    def algorithm(self, kind):
        self._rec("algorithm", kind)

    def integrator(self, kind, *args):
        assert kind in self.INTEGRATORS and len(args) in self.INTEGRATORS[kind], (kind, args)
        self.integ = (kind, args)
        self._rec("integrator", kind, *args)

    def analysis(self, kind):
        assert kind == "Transient" and self.integ is not None
        self._rec("analysis", kind)

    def analyze(self, n, dt):
        assert n == 1
        self.steps += 1
        self.time = self.steps * dt
        return 0

    # --- responses -------------------------------------------------------------------------
    def nodeDisp(self, tag, dof):
        return tag * 1e-3 * math.sin(self.time)

    def nodeVel(self, tag, dof):
        return tag * 1e-3 * math.cos(self.time)

    def nodeAccel(self, tag, dof):
        return -tag * 1e-3 * math.sin(self.time)

    def eleResponse(self, tag, what):
        assert tag in self.elements
        if what == "localForce":                  # a beam-column's 12 end forces: tag + k + t
            assert self.elements[tag][0] != "zeroLength"
            return [tag + k + self.time for k in range(12)]
        assert what == "basicForce"
        return [-(tag + self.time)]

    def modalDamping(self, *factors):
        assert any(n == "eigen" for n, _ in self.calls), "modalDamping takes the last eigen's modes"
        assert not any(n == "analysis" for n, _ in self.calls) and factors
        assert all(isinstance(f, float) and 0 <= f < 1 for f in factors), factors
        self._rec("modalDamping", *factors)

    def eigen(self, *args):
        n = args[-1]
        assert isinstance(n, int) and n > 0 and args[:-1] in ((), ("-fullGenLapack",)), args
        self._rec("eigen", *args)
        return [float((k + 1) ** 2) for k in range(n)]     # ω = 1, 2, ... rad/s
