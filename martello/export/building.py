"""A [[building]] written for OpenSees (docs/opensees.md "Buildings"): the 3D frame that
martello condenses (martello.building3d, docs/buildings.md) written uncondensed on 6-DOF
nodes — every member an elasticBeamColumn (ElasticTimoshenkoBeam where the section has shear
areas) on a Linear transformation whose vecxz is the member's local axis 3, a rigid floor a
rigidDiaphragm to a master node at the floor's reference point that carries its ux, uy, rz
(the floor's mass m, m and J_C on the master, or on a node at the mass centre tied to it when
the reference is elsewhere: the same coupled mass matrix), flexible floors' and split points'
masses on their own nodes, Rayleigh damping a0 M + a1 K by region (modal damping is refused:
OpenSees cannot damp every mode of such a model, see check()). The massless DOFs that martello condenses are
free DOFs of this model: static condensation is exact for them, so both model the same floor
dynamics (docs/buildings.md "Condensation").

A contact or link between plan points is a row n·(u(P_a) − u(P_b)) (docs/buildings.md
"Contacts between plan points"); it becomes a zeroLength element oriented along n between a
node of each side on the row's line of action (a rigid floor's side: a node tied to its
diaphragm; a split point or a flexible floor's joint: its own node), which applies the force
along n at each side's point, exactly the row's force and torques."""

import math

import numpy as np

DOF = {"ux": 1, "uy": 2, "rz": 6}
# a floor's master node and a diaphragm's extra nodes: uz, θx, θy held (they carry nothing)
PLANAR = (0, 0, 1, 1, 1, 0)
FREE_ROW = 4.0 * np.finfo(float).eps    # a plan point row's |n| is 1 up to the rounding of n/|n|
# modal damping: frequencies closer than this (relative) make the eigenvectors' error ε/1e-6
# ≈ 2e-10, above the cross-check's agreement (check_modal)
MODE_SEPARATION = 1e-6
# a rigid floor's master node: tagged above every other node. OpenSees' Transformation handler
# makes the DOF groups in node-tag order, and its modal damping (IncrementalIntegrator::
# setupModal) writes each group's eigenvector into the equations it holds, a slave's as Tᵀφ
# (TransformationDOF_Group::getEigenvectors) over its master's: the master, iterated last,
# writes φ itself (docs/opensees.md "Modal damping")
MASTER_TAG0 = 1_000_000_000


class BuildingWriter:
    """The buildings of a scene written into the builder's command list (martello.export.opensees
    _Builder: add, refuse, node numbering); after write(): node_of[scene node index] = (tag,
    dof), the floors' masters and the elements per building for damping and recorders."""

    def __init__(self, builder):
        self.bld = builder
        self.s = builder.s
        self.buildings = self.s.extras.get("buildings", [])
        self.node_of = {}                  # scene node index -> (tag, dof)
        self.position = {}                 # tag -> (x, y, z)
        self.master = {}                   # (prefix, floor) -> (master tag, reference (x, y), z)
        self.members = []                  # (prefix, member name, element tag)
        self.transf = {}
        self.n_master = 0                  # rigid floors written (their masters' tags)
        self.kept = {n for b in self.buildings for n in b["nodes"]}    # the buildings' own DOFs

    # --- refusals ---------------------------------------------------------------------------
    def check(self):
        b0 = self.bld
        s = self.s
        if s.extras.get("frames"):
            b0.refuse("[[frame]] with [[building]]", "the exporter writes a scene's frames on "
                      "planar 3-DOF nodes and its buildings on 6-DOF nodes, not both",
                      "export the frames and the buildings as two scenes")
        if s.gravity:
            b0.refuse(f"loads.gravity = {s.gravity:g} with [[building]]",
                      "martello's buildings are linear and take no gravity (docs/buildings.md: the "
                      "seismic response superposes on it)", "remove gravity")
        for b in self.buildings:
            bd, p = b["building"], b["prefix"]
            if bd.slabs:
                b0.refuse(f"building {p}: slab", "its membrane panels are Wilson's incompatible-mode "
                          "quadrilateral in plane stress on the joints' ux, uy; OpenSees' 3D "
                          "membranes (ShellMITC4, ShellDKGQ) carry bending and a drilling DOF: "
                          "another model", "remove slab (the beams hold the floor in its plane) "
                          "or set diaphragm = true")
            for e in bd.elements:
                if (e.section.As2 is None) != (e.section.As3 is None):
                    b0.refuse(f"building {p}: member {e.name}: one shear area (As2 or As3)",
                              "OpenSees' ElasticTimoshenkoBeam takes both shear areas",
                              "give both As2 and As3, or neither")
        angles = {float(b["ground_angle"]) for b in self.buildings}
        in_b = {n for b in self.buildings for n in b["nodes"]}
        plain = [n["name"] for n in s.nodes if n["name"] not in in_b]
        if s.ground is not None and (len(angles) > 1 or (plain and angles != {0.0})):
            b0.refuse("building.ground_angle = " + ", ".join(f"{a:g}" for a in sorted(angles))
                      + (f" with nodes along the scene's axis ({', '.join(plain[:3])})" if plain else ""),
                      "UniformExcitation moves every mass of the model along one direction",
                      "give every building the same ground_angle (0 with other nodes)")
        self.check_modal()

    def check_modal(self):
        """Modal damping is written as OpenSees' eigen (fullGenLapack, every mass DOF) and
        modalDamping ζ (docs/opensees.md "Modal damping"): the modes of the whole model must be
        the buildings' own, each damped by one ζ, and each one M-orthonormal as OpenSees takes it."""
        modal = [b for b in self.buildings if b["zeta"] > 0 and b["damping"] == "modal"]
        if not modal:
            return
        b0, fix = self.bld, "use damping = \"rayleigh\" (choose rayleigh_modes) for the export"
        zetas = {float(b["zeta"]) for b in self.buildings}
        if len(modal) != len(self.buildings) or len(zetas) > 1:
            b0.refuse("building damping = " + ", ".join(
                f"{b['prefix']}: {b['damping'] if b['zeta'] > 0 else 'none'} {b['zeta']:g}" for b in self.buildings),
                "OpenSees' modalDamping damps every mode of the model's last eigen by one list of "
                "factors, not one building's modes by its own rule", "give every building damping = "
                "\"modal\" with the same zeta, or " + fix[4:])
        stiff = [lk["name"] for lk in self.s.links if lk["type"] not in ("dashpot", "fluid_damper")]
        closed = [c["name"] for c in self.s.contacts if not float(c["gap"]) > 0]
        if stiff or closed:
            b0.refuse(f"building damping = \"modal\" with {'link' if stiff else 'contact'} "
                      f"{(stiff or closed)[0]}", "a spring or a closed contact enters the eigen "
                      "analysis at rest and couples the modes that martello damps building by building",
                      "remove it, or " + fix)
        for b in modal:
            bd = b["building"]
            for fs, fl in enumerate(bd.floors, start=1):
                if fl.rigid and tuple(bd.reference_point(fs)) != tuple(fl.centre):
                    # measured (OpenSees 3.7.1): a mass on a node tied to its floor's master comes
                    # out of eigen -fullGenLapack with vectors not M-normalised (the master's
                    # largest component exactly 1, dggev's own scaling), and modalDamping diverges
                    b0.refuse(f"building {b['prefix']}: damping = \"modal\" with floor {fs}'s "
                              "reference point off its mass centre", "the floor's mass sits on a node "
                              "tied to the master, and OpenSees' eigen does not M-normalise the modes "
                              "of such a model (docs/opensees.md \"Modal damping\")",
                              "remove reference, or " + fix)
        w = np.sort([m["omega"] for b in modal for m in b["modes"]])
        # a (near-)repeated frequency: LAPACK's dggev returns any basis of its eigenspace, each
        # vector M-normalised alone (FullGenEigenSolver::solve), not M-orthogonal to the others,
        # while modalDamping sums 2ζω (Mφ)(Mφ)ᵀ as over an M-orthonormal set; the vectors of
        # modes ω apart by δω carry an error of order ε/(δω/ω) (the eigenvector's condition)
        rel = np.diff(w) / w[1:]
        if rel.size and rel.min() < MODE_SEPARATION:
            k = int(np.argmin(rel))
            b0.refuse(f"building damping = \"modal\": two modes at {w[k]:.9g} and {w[k + 1]:.9g} rad/s",
                      f"frequencies closer than {MODE_SEPARATION:g} relative, whose eigenvectors "
                      "OpenSees' fullGenLapack does not make M-orthogonal", fix)

    # --- the model --------------------------------------------------------------------------
    def node(self, tag, x, y, z):
        self.bld.add("node", tag, float(x), float(y), float(z))
        self.position[tag] = (float(x), float(y), float(z))

    def write(self, tag):
        """Every building's nodes, members, floors and damping; returns the last node tag."""
        for b in self.buildings:
            tag = self.building(b, tag)
        return tag

    def building(self, b, tag):
        add, bd, pre = self.bld.add, b["building"], b["prefix"]
        node_tag = {}
        for k, nd in enumerate(bd.nodes):
            tag += 1
            node_tag[k] = tag
            self.node(tag, nd.x, nd.y, nd.z)
            if nd.floor == 0:
                add("fix", tag, 1, 1, 1, *((0, 0) if bd.base == "pinned" else (1, 1)), 1)
            elif bd.model == "shear":
                # a shear storey: member ends held against uz, θx, θy (docs/buildings.md)
                add("fix", tag, 0, 0, 1, *((0, 0) if nd.floor is None else (1, 1)), 0)
        eles = []
        for e in bd.elements:
            eles.append(self.member(pre, e, node_tag[e.ends[0]], node_tag[e.ends[1]]))
        massed = []
        names = b["nodes"]
        for s in range(1, bd.storeys + 1):
            fl = bd.floors[s - 1]
            if not fl.rigid:
                continue
            xo, yo = bd.reference_point(s)
            z = float(bd.z[s])
            self.n_master += 1
            master = MASTER_TAG0 + self.n_master
            self.node(master, xo, yo, z)
            add("fix", master, *PLANAR)
            slaves = [node_tag[k] for k in bd.floor_nodes(s)]
            if (xo, yo) == tuple(fl.centre):
                add("mass", master, fl.mass, fl.mass, 0.0, 0.0, 0.0, fl.inertia)
                massed.append(master)
                at = f"node {master} at the reference point ({xo:g}, {yo:g}) with m, m, J"
            else:
                tag += 1
                self.node(tag, fl.centre[0], fl.centre[1], z)
                add("fix", tag, *PLANAR)
                add("mass", tag, fl.mass, fl.mass, 0.0, 0.0, 0.0, fl.inertia)
                slaves.append(tag)
                massed.append(tag)
                at = (f"node {master} at the reference point ({xo:g}, {yo:g}); m, m, J_C on node {tag} "
                      f"at the mass centre ({fl.centre[0]:g}, {fl.centre[1]:g}) tied to it")
            add("rigidDiaphragm", 3, master, *slaves)
            self.bld.equal_dof = True       # multi-point constraints: the Transformation handler
            self.master[(pre, s)] = (master, (xo, yo), z)
            for c in ("ux", "uy", "rz"):
                self.node_of[self.bld.s.index[f"{pre}{s}.{c}"]] = (master, DOF[c])
            self.bld.map.append((f"floor {pre}{s} (m = {fl.mass:g} kg, J_C = {fl.inertia:g} kg m²)",
                                 f"rigidDiaphragm 3 over {len(slaves)} nodes; {at}"))
        for (floor, where, c), name in zip(bd.kept, names):
            if c == "rz" or (floor is not None and where is None):
                continue
            if floor is None:                  # a split point
                k = next(i for i, nd in enumerate(bd.nodes) if nd.split == where)
                m = next(sp.mass for sp in bd.splits if sp.name == where)
            else:                              # a massive joint of a flexible floor
                k = bd._at[(floor, where)]
                m = bd.grid_masses[floor][where]
            t = node_tag[k]
            self.node_of[self.bld.s.index[name]] = (t, DOF[c])
            if c == "ux":
                add("mass", t, m, m, 0.0, 0.0, 0.0, 0.0)
                massed.append(t)
                self.bld.map.append((f"{name[:-3]} (m = {m:g} kg on ux, uy)", f"node {t}"))
        self.damping(b, eles, massed)
        # the script's energies on the kept DOFs with martello's M and K* (docs/results.md)
        dofs = [self.node_of[self.bld.s.index[nm]] for nm in names]
        M = b["M"]
        self.bld.energy["kinetic"] += [(*dofs[i], float(M[i, i])) for i in range(len(names))]
        self.bld.energy["couplings"] += [(dofs[i], dofs[j], float(M[i, j])) for i in range(len(names))
                                         for j in range(len(names)) if i != j and M[i, j] != 0.0]
        self.bld.energy["blocks"].append((dofs, [[float(x) for x in r] for r in b["K"]]))
        n_beam = sum(e.kind == "beam" for e in bd.elements)
        self.bld.map.append((f"building {pre} ({bd.storeys} storeys, {bd.model} model, {bd.base} base, "
                             f"{len(bd.elements) - n_beam} vertical members, {n_beam} beams)",
                             f"{len(bd.nodes)} nodes, {len(eles)} beam-column elements"))
        self.bld.diff.append(
            f"building {pre}: OpenSees carries every joint's 6 DOFs (the massless ones free) where "
            "martello condenses them statically: the same floor dynamics up to round-off "
            "(docs/opensees.md \"Buildings\")")
        return tag

    def member(self, pre, e, i, j):
        """One member: its local axis 3 (e.R[2]) as vecxz, so OpenSees' y, z are martello's
        axes 2, 3 and Iy = I2, Iz = I3 (martello.building3d: I3 resists displacement along 2)."""
        add, sec = self.bld.add, e.section
        key = tuple(float(x) + 0.0 for x in e.R[2])      # + 0.0: no -0.0 in the script
        if key not in self.transf:
            self.transf[key] = len(self.transf) + 1
            add("geomTransf", "Linear", self.transf[key], *key)
        self.bld.ele += 1
        t = self.bld.ele
        if sec.As2 is None:
            add("element", "elasticBeamColumn", t, i, j, sec.A, sec.E, sec.G, sec.J, sec.I2, sec.I3,
                self.transf[key])
        else:
            add("element", "ElasticTimoshenkoBeam", t, i, j, sec.E, sec.G, sec.A, sec.J, sec.I2, sec.I3,
                sec.As2, sec.As3, self.transf[key])
        self.members.append((pre, e.name, t))
        return t

    def damping(self, b, eles, massed):
        if not b["zeta"] > 0 or b["damping"] == "modal":    # modal: modal_damping(), once
            return
        a0, a1 = b["rayleigh"]
        bld = self.bld
        bld.region = getattr(bld, "region", 0) + 1
        bld.add("region", bld.region, "-eleOnly", *eles, "-rayleigh", 0.0, float(a1), 0.0, 0.0)
        bld.region += 1
        bld.add("region", bld.region, "-nodeOnly", *massed, "-rayleigh", float(a0), 0.0, 0.0, 0.0)
        bld.map.append((f"building {b['prefix']} Rayleigh damping (zeta = {b['zeta']:g})",
                        f"a1 = {a1:.17g} on its elements, a0 = {a0:.17g} on its masses (region)"))

    def modal_damping(self):
        """Every building's modal damping (check_modal): OpenSees' eigen on every mass DOF of
        the model, then modalDamping ζ (its damping matrix enters the Newton tangent)."""
        modal = [b for b in self.buildings if b["zeta"] > 0 and b["damping"] == "modal"]
        if not modal:
            return
        n = sum(len(b["nodes"]) for b in self.buildings) + sum(
            1 for nd in self.s.nodes if nd["name"] not in {x for b in self.buildings for x in b["nodes"]}
            and not nd["fixed"])
        zeta = float(modal[0]["zeta"])
        self.bld.add("eigen", "-fullGenLapack", n)
        self.bld.add("modalDamping", zeta)
        self.bld.map.append((f"buildings' modal damping (zeta = {zeta:g})",
                             f"eigen -fullGenLapack {n} (every mass DOF), modalDamping {zeta:g}"))

    # --- rows: contacts and links between plan points ----------------------------------------
    def row(self, what, terms):
        """(i, j, n) of a row Σ c·u = n·(u(P_a) − u(P_b)): the element's nodes i (side a) and j
        (side b, a new fixed node for the ground) and the unit plan direction n. Refused where
        the row is no such difference (a written row). A plain [[node]] is an x-only node at
        the origin (martello.export.opensees nodes())."""
        masters = {m[0] for m in self.master.values()}
        bodies = {}                       # a floor's master ("floor", tag) or a node's tag -> [cx, cy, cr]
        # a plain [[node]] side is the term ±1 of its one DOF whatever the normal (martello.scene.rows
        # side_terms: its u counted along n); a fixed one's u is 0, so it is the ground here
        plain = [idx for idx, _ in terms if self.s.nodes[idx]["name"] not in self.kept]
        terms = [(idx, c) for idx, c in terms if not self.s.nodes[idx]["fixed"]]
        for idx, c in terms:
            tag, dof = self.bld.dof_of(idx)
            key = ("floor", tag) if tag in masters else tag
            acc = bodies.setdefault(key, [0.0, 0.0, 0.0])
            acc[{1: 0, 2: 1, 6: 2}[dof]] += c
        if len(bodies) > 2:
            self.bld.refuse(f"{what}: a row over {len(bodies)} bodies",
                            "a zeroLength element joins two nodes", "give the element two sides a and b")
        sides = list(bodies.items())
        t0 = np.array(sides[0][1][:2])
        scale = math.hypot(*t0)
        if len(sides) == 2 and not np.array_equal(np.array(sides[1][1][:2]), -t0) and plain and \
                abs(scale - 1.0) <= FREE_ROW:
            name = next(self.s.nodes[i]["name"] for i in plain if not self.s.nodes[i]["fixed"])
            self.bld.refuse(f"{what}: node {name} with normal ({t0[0]:g}, {t0[1]:g})",
                            f"martello counts a [[node]]'s u along the element's normal (its term is ±1 "
                            f"whatever the normal), while in the 3D model a plain node moves along x, the "
                            "axis its ground motion and loads act on: the two agree only where the normal "
                            "is +x from side a to side b", "write the contact with the node on the side "
                            "that makes the normal [1, 0] (swap a and b and flip the normal), or fix the node")
        if len(sides) == 2 and not np.array_equal(np.array(sides[1][1][:2]), -t0) or \
                not abs(scale - 1.0) <= FREE_ROW:
            self.bld.refuse(f"{what}.terms", "not a row n·(u(P_a) − u(P_b)) with a unit plan direction n "
                            "(the rows of plan points are): no zeroLength element deforms by it",
                            "give the sides a and b as plan points or nodes with normal / direction")
        n = t0 / scale
        nodes = []
        for key, (cx, cy, cr) in sides:
            if isinstance(key, tuple):
                master = key[1]
                (_, (xo, yo), z) = next(v for v in self.master.values() if v[0] == master)
                # the point P = O + r (t_y, −t_x) of this side's translation t = (cx, cy) (unit)
                # has t·u(P) = t_x ux + t_y uy + r rz: the side's terms (docs/buildings.md)
                foot = np.array([xo, yo]) + cr * np.array([cy, -cx])
                nodes.append(("floor", master, foot, z))
            else:
                if cr != 0.0:             # pragma: no cover - only rigid floors have rz
                    self.bld.refuse(f"{what}.terms", "a rotation term on a node without one")
                x, y, z = self.position[key]
                nodes.append(("node", key, np.array([x, y]), z))
        # both nodes on one line of action: the first side's point, the second projected on its line
        anchor = next((p for k, _, p, _ in nodes if k == "node"), nodes[0][2])
        tags = []
        for kind, ref, p, z in nodes:
            if kind == "node":
                tags.append(ref)
                continue
            q = p + float((anchor - p) @ n) * n
            self.bld.tag_count += 1
            t = self.bld.tag_count
            self.node(t, q[0], q[1], z)
            self.bld.add("fix", t, *PLANAR)
            self.bld.add("rigidDiaphragm", 3, ref, t)
            tags.append(t)
        if len(tags) == 1:
            self.bld.tag_count += 1
            g = self.bld.tag_count
            x, y, z = self.position[tags[0]]
            self.node(g, x, y, z)
            self.bld.add("fix", g, 1, 1, 1, 1, 1, 1)
            tags.append(g)
        # the first side's translation is n: it is side a of n·(u(P_a) − u(P_b))
        i, j = tags
        return i, j, n
