"""Buildings in 3D (docs/problems.md P11, docs/buildings.md): floors as rigid diaphragms with
three DOFs each (ux, uy of a reference point and rz about it) or flexible floors, vertical
members (columns, walls, cores) at their plan positions, beams in frame mode, and the static
condensation of the whole 3D beam-column model to the DOFs that carry mass.

The structure is a 3D frame of Timoshenko beam-columns (six DOFs per node; the 12 x 12
element of Przemieniecki, Theory of Matrix Structural Analysis, §5.6, shear deformation by
phi = 12 EI/(G A_s L^2), none where no shear area is given). Two models:

* "shear": shear-type storeys. Every member end at a floor is restrained against rotation
  about the horizontal axes and against vertical motion, there are no beams, so a member
  of storey height h adds a lateral spring 12 EI/(h^3 (1 + phi)) along each principal axis
  and a torsional spring GJ/h at its plan position (the issue's definition, and the
  classical storey model of Kan & Chopra 1977).
* "frame": a full 3D frame: columns, walls, cores and the beams of every floor, with uz, θx,
  θy of every node free; the floor constraint ties ux, uy, θz of the nodes of a rigid floor.

Rigid floor s with reference point O_s = (x_o, y_o): a point (x, y) of the floor moves by
ux(P) = U_x − (y − y_o) R_z, uy(P) = U_y + (x − x_o) R_z and turns by θz = R_z (Wilson,
Three-Dimensional Static and Dynamic Analysis of Structures, ch. 12). Nodes that carry no
mass (uz, θx, θy, the θz of flexible floors, the nodes of members off a flexible floor's grid)
are condensed exactly, as in martello.frame2d: with the kept DOFs r and the others c,
K* = K_rr − K_rc K_cc⁻¹ K_cr and q_c = −K_cc⁻¹ K_cr q_r (Guyan reduction without inertia;
Clough & Penzien, Dynamics of Structures, §11-2).

Member end forces are the direct-stiffness ones in the member's axes, f_e = k_e T_e d_e
(McGuire, Gallagher & Ziemian, Matrix Structural Analysis, ch. 4): the forces the nodes apply
to the member, [N, V2, V3, T, M2, M3] at end i then end j. Local axis 1 runs from end i to
end j (a vertical member: upwards); a vertical member's axis 2 lies in plan at `angle` from
x (angle 0: axis 2 = x, axis 3 = y), a beam's axis 2 is vertical (up) and axis 3 = 1 × 2.
I3 resists displacement along axis 2 (bending about axis 3, moment M3), I2 along axis 3.

Mass: a rigid floor's mass m at its centre C with rotational inertia J_C about C; about the
reference point O (d = C − O) M = [[m, 0, −m d_y], [0, m, m d_x], [−m d_y, m d_x,
J_C + m |d|^2]]; the reference defaults to the mass centre (M diagonal). Points kept on a
column between floors (splits, the nodes an offset floor strikes) carry their own mass.
Gravity is not in the model: it is linear, the seismic response superposes on it."""

from dataclasses import dataclass, field

import numpy as np

from .modes import modes

# Local end-force components of a member; recovery rows 12e + 6·end + k.
END_FORCES = ("N", "V2", "V3", "T", "M2", "M3")
# A plan position matches a member's within this distance [m] (beams, splits, contacts).
POSITION_TOL = 1e-6
# The default Poisson ratio of G = E / (2 (1 + nu)) where a section gives no G (concrete).
NU_DEFAULT = 0.2


@dataclass(frozen=True)
class Section:
    """A member's section: E, G [Pa], A [m²], I2, I3 (about local axes 2 and 3), J [m⁴];
    As2, As3 the shear areas for shear along axes 2 and 3 (None: no shear deformation)."""
    E: float
    G: float
    A: float
    I2: float
    I3: float
    J: float
    As2: float | None = None
    As3: float | None = None


def torsion_constant_rectangle(a, b):
    """St Venant's J of an a x b rectangle (Roark's Formulas for Stress and Strain, table
    10.7, case 4: J = a b³ (1/3 − 0.21 (b/a)(1 − (b/a)⁴/12)) with a >= b), within 4 % of the
    series solution at every aspect ratio."""
    a, b = max(a, b), min(a, b)
    r = b / a
    return a * b**3 * (1.0 / 3.0 - 0.21 * r * (1.0 - r**4 / 12.0))


def column_section(E, b2, b3, G=None, cracked=1.0, shear=False):
    """A b2 x b3 rectangle (b2 along local axis 2): I3 = b3 b2³/12 resists displacement along
    axis 2; flexural stiffness times `cracked`; shear areas 5/6 A if shear."""
    G = E / (2 * (1 + NU_DEFAULT)) if G is None else G
    A = b2 * b3
    As = 5.0 / 6.0 * A if shear else None
    return Section(E, G, A, cracked * b2 * b3**3 / 12, cracked * b3 * b2**3 / 12,
                   torsion_constant_rectangle(b2, b3), As, As)


def beam_section(E, b, h, G=None, cracked=1.0):
    """A beam of width b and depth h: I3 = b h³/12 (vertical bending, moment M3)."""
    G = E / (2 * (1 + NU_DEFAULT)) if G is None else G
    return Section(E, G, b * h, cracked * h * b**3 / 12, cracked * b * h**3 / 12,
                   torsion_constant_rectangle(b, h))


@dataclass
class Line:
    """A vertical member line at (x, y): sections[s] the section in storey s + 1 (None:
    absent there), its local axis 2 at `angle` degrees from x in plan."""
    name: str
    x: float
    y: float
    sections: list
    angle: float = 0.0
    kind: str = "column"      # "column" (from the grid) or "member" (walls, cores, ...)


@dataclass
class Beam:
    name: str
    floor: int               # 1-based
    a: tuple                 # plan points (x, y) of its ends: member lines of that floor
    b: tuple
    section: Section


@dataclass
class Split:
    """A node kept on member line `line` in storey `storey` at `height` above the storey's
    floor: its ux, uy are DOFs of the model (with `mass` on each), e.g. where a slab of the
    neighbour strikes the column between floors."""
    name: str
    line: str
    storey: int
    height: float
    mass: float


@dataclass
class Slab:
    """The in-plane slab panel of a flexible floor over the rectangle x0..x1 × y0..y1 of the
    plan grid, its corners member ends at that floor: a membrane of `thickness`, E and ν in
    plane stress on the corners' ux, uy."""
    floor: int
    x: tuple                 # (x0, x1)
    y: tuple                 # (y0, y1)
    thickness: float
    E: float
    nu: float


@dataclass
class Floor:
    mass: float
    centre: tuple            # mass centre (x, y)
    inertia: float           # rotational inertia about the mass centre [kg m²]
    rigid: bool = True


@dataclass
class Element:
    name: str
    kind: str                # "column", "member", "beam"
    ends: tuple              # node ids
    section: Section
    length: float
    R: np.ndarray            # 3 x 3: rows the local axes in global components
    storey: int = 0          # vertical: its storey; beam: its floor
    line: str = ""


@dataclass
class Node:
    x: float
    y: float
    z: float
    floor: int | None        # 0 base, s a floor, None a split point
    split: str | None = None


@dataclass
class Building:
    heights: list                     # storey heights, bottom up
    floors: list                      # Floor per floor 1..storeys
    lines: list                       # Line
    beams: list = field(default_factory=list)
    splits: list = field(default_factory=list)
    model: str = "shear"              # "shear" or "frame"
    base: str = "fixed"               # "fixed" or "pinned"
    reference: tuple | None = None    # one plan point for every rigid floor; None: mass centres
    grid_masses: dict | None = None   # flexible floors: {floor: {line name: mass}}
    slabs: list = field(default_factory=list)   # Slab panels of flexible floors

    def __post_init__(self):
        if self.model not in ("shear", "frame"):
            raise ValueError(f"model: {self.model!r} (valid: shear, frame)")
        if self.base not in ("fixed", "pinned"):
            raise ValueError(f"base: {self.base!r} (valid: fixed, pinned)")
        self.z = np.concatenate([[0.0], np.cumsum(self.heights)])
        self._build_nodes_and_elements()
        self._number()

    @property
    def storeys(self):
        return len(self.heights)

    # --- geometry ------------------------------------------------------------------------
    def reference_point(self, s):
        """O_s of rigid floor s (1-based)."""
        return tuple(self.reference) if self.reference is not None else tuple(self.floors[s - 1].centre)

    def _line(self, name):
        for ln in self.lines:
            if ln.name == name:
                return ln
        raise ValueError(f"no member line {name!r}")

    def _build_nodes_and_elements(self):
        ns = self.storeys
        self.nodes, self.elements = [], []
        at = {}                                     # (floor, line name) -> node id

        def node_of(floor, ln):
            key = (floor, ln.name)
            if key not in at:
                at[key] = len(self.nodes)
                self.nodes.append(Node(ln.x, ln.y, float(self.z[floor]), floor))
            return at[key]
        splits = {(sp.line, sp.storey): sp for sp in self.splits}
        for ln in self.lines:
            if len(ln.sections) != ns:
                raise ValueError(f"line {ln.name}: {len(ln.sections)} sections for {ns} storeys")
            c, s_ = np.cos(np.radians(ln.angle)), np.sin(np.radians(ln.angle))
            R = np.array([[0.0, 0.0, 1.0], [c, s_, 0.0], [-s_, c, 0.0]])
            prefix = "C" if ln.kind == "column" else ""
            for s in range(1, ns + 1):
                sec = ln.sections[s - 1]
                if sec is None:
                    continue
                name = f"{prefix}{s}.{ln.name}" if ln.kind == "column" else f"{ln.name}.{s}"
                lo, hi = node_of(s - 1, ln), node_of(s, ln)
                sp = splits.pop((ln.name, s), None)
                if sp is None:
                    self.elements.append(Element(name, ln.kind, (lo, hi), sec, self.heights[s - 1],
                                                 R, s, ln.name))
                    continue
                if not 0 < sp.height < self.heights[s - 1]:
                    raise ValueError(f"split {sp.name}: height {sp.height} outside (0, "
                                     f"{self.heights[s - 1]}) of storey {s}")
                mid = len(self.nodes)
                self.nodes.append(Node(ln.x, ln.y, float(self.z[s - 1] + sp.height), None, sp.name))
                self.elements.append(Element(name + ".a", ln.kind, (lo, mid), sec, sp.height, R, s, ln.name))
                self.elements.append(Element(name + ".b", ln.kind, (mid, hi), sec,
                                             self.heights[s - 1] - sp.height, R, s, ln.name))
        if splits:
            (ln, s), sp = next(iter(splits.items()))
            raise ValueError(f"split {sp.name}: line {ln} has no member in storey {s}")
        for sl in self.slabs:
            if self.floors[sl.floor - 1].rigid:
                raise ValueError(f"slab at floor {sl.floor}: a rigid floor's slab is the diaphragm")
            for p in ((sl.x[0], sl.y[0]), (sl.x[1], sl.y[0]), (sl.x[1], sl.y[1]), (sl.x[0], sl.y[1])):
                self._node_at(sl.floor, p, at)
        if self.model == "shear" and self.beams:
            raise ValueError("beams: a shear-type building has none (model = \"frame\")")
        for bm in self.beams:
            ends = [self._node_at(bm.floor, p, at) for p in (bm.a, bm.b)]
            d = np.array([self.nodes[ends[1]].x - self.nodes[ends[0]].x,
                          self.nodes[ends[1]].y - self.nodes[ends[0]].y, 0.0])
            L = float(np.hypot(d[0], d[1]))
            if L <= POSITION_TOL:
                raise ValueError(f"beam {bm.name}: its ends are one point")
            e1 = d / L
            e2 = np.array([0.0, 0.0, 1.0])
            self.elements.append(Element(bm.name, "beam", tuple(ends), bm.section, L,
                                         np.array([e1, e2, np.cross(e1, e2)]), bm.floor))
        self._at = at

    def _node_at(self, floor, p, at):
        for (f, name), i in at.items():
            nd = self.nodes[i]
            if f == floor and abs(nd.x - p[0]) <= POSITION_TOL and abs(nd.y - p[1]) <= POSITION_TOL:
                return i
        raise ValueError(f"no member ends at floor {floor}, point ({p[0]:g}, {p[1]:g})")

    def floor_nodes(self, s):
        """Node ids at floor s (member ends)."""
        return [i for i, nd in enumerate(self.nodes) if nd.floor == s]

    # --- generalised coordinates ---------------------------------------------------------
    def _number(self):
        """The kept coordinates first (per floor: ux, uy, rz of a rigid floor or ux, uy of each
        massive node of a flexible one; then every split's ux, uy), then the condensed ones.
        self.rows[node] = six dicts {coordinate: coefficient} for (ux, uy, uz, θx, θy, θz)."""
        self.kept, rows = [], {}
        grid = self.grid_masses or {}
        for s in range(1, self.storeys + 1):
            fl = self.floors[s - 1]
            if fl.rigid:
                base = len(self.kept)
                self.kept += [(s, None, "ux"), (s, None, "uy"), (s, None, "rz")]
                xo, yo = self.reference_point(s)
                for i in self.floor_nodes(s):
                    nd = self.nodes[i]
                    rows[i] = [{base: 1.0, base + 2: -(nd.y - yo)}, {base + 1: 1.0, base + 2: nd.x - xo},
                               None, None, None, {base + 2: 1.0}]
            else:
                masses = grid.get(s, {})
                for i in self.floor_nodes(s):
                    name = self._line_of_node(i)
                    if masses.get(name, 0.0) > 0:
                        base = len(self.kept)
                        self.kept += [(s, name, "ux"), (s, name, "uy")]
                        rows[i] = [{base: 1.0}, {base + 1: 1.0}, None, None, None, None]
                    else:
                        rows[i] = [None] * 6
        for i, nd in enumerate(self.nodes):
            if nd.split is not None:
                base = len(self.kept)
                self.kept += [(None, nd.split, "ux"), (None, nd.split, "uy")]
                rows[i] = [{base: 1.0}, {base + 1: 1.0}, None, None, None, None]
        n = len(self.kept)
        restrained = {"shear": (2, 3, 4), "frame": ()}[self.model]
        for i, nd in enumerate(self.nodes):
            if nd.floor == 0:
                r = [{} for _ in range(6)]
                if self.base == "pinned":
                    r[3] = r[4] = None               # free rotations about x, y
            else:
                r = rows[i]
                if nd.split is None:
                    r = [({} if k in restrained and x is None else x) for k, x in enumerate(r)]
                else:
                    r = [({} if k == 2 and self.model == "shear" else x) for k, x in enumerate(r)]
            for k in range(6):
                if r[k] is None:
                    r[k] = {n: 1.0}
                    n += 1
            rows[i] = r
        self.rows = [rows[i] for i in range(len(self.nodes))]
        self.ncoord = n

    def _line_of_node(self, i):
        for (f, name), j in self._at.items():
            if j == i:
                return name
        return None

    @property
    def nkept(self):
        return len(self.kept)

    def kept_names(self, prefix):
        """Node names of the kept coordinates: <prefix><floor>.ux|uy|rz for rigid floors,
        <prefix><floor>.<line>.ux|uy for flexible ones, <prefix>.<split>.ux|uy for splits."""
        out = []
        for floor, where, c in self.kept:
            if floor is None:
                out.append(f"{prefix}.{where}.{c}")
            elif where is None:
                out.append(f"{prefix}{floor}.{c}")
            else:
                out.append(f"{prefix}{floor}.{where}.{c}")
        return out

    # --- elements -------------------------------------------------------------------------
    @staticmethod
    def element_stiffness(e):
        """k (12 x 12) in the member's axes, DOFs (u1, u2, u3, θ1, θ2, θ3) at end i then j,
        and T (12 x 12) with d_local = T d_global."""
        s, L = e.section, e.length
        k = np.zeros((12, 12))
        ea, gj = s.E * s.A / L, s.G * s.J / L
        k[0, 0] = k[6, 6] = ea; k[0, 6] = k[6, 0] = -ea
        k[3, 3] = k[9, 9] = gj; k[3, 9] = k[9, 3] = -gj

        def bend(I, As, dof_w, dof_t, sign):
            phi = 12 * s.E * I / (s.G * As * L**2) if As else 0.0
            c = s.E * I / (L**3 * (1 + phi))
            w1, t1, w2, t2 = dof_w, dof_t, dof_w + 6, dof_t + 6
            m = c * np.array([[12, sign * 6 * L, -12, sign * 6 * L],
                              [sign * 6 * L, (4 + phi) * L**2, -sign * 6 * L, (2 - phi) * L**2],
                              [-12, -sign * 6 * L, 12, -sign * 6 * L],
                              [sign * 6 * L, (2 - phi) * L**2, -sign * 6 * L, (4 + phi) * L**2]])
            idx = [w1, t1, w2, t2]
            k[np.ix_(idx, idx)] += m
        bend(s.I3, s.As2, 1, 5, +1.0)     # displacement along 2, rotation about 3
        bend(s.I2, s.As3, 2, 4, -1.0)     # displacement along 3, rotation about 2
        T = np.zeros((12, 12))
        for b in range(4):
            T[3 * b:3 * b + 3, 3 * b:3 * b + 3] = e.R
        return k, T

    def _element_map(self, e):
        """(coords, A): the coordinates an element's 12 global DOFs depend on, and A (12 x
        len(coords)) with d_global = A q[coords]."""
        rows = [r for nd in e.ends for r in self.rows[nd]]
        coords = sorted({c for r in rows for c in r})
        pos = {c: i for i, c in enumerate(coords)}
        A = np.zeros((12, len(coords)))
        for p, r in enumerate(rows):
            for c, v in r.items():
                A[p, pos[c]] = v
        return coords, A

    def stiffness(self):
        """K on all generalised coordinates (the kept ones first)."""
        K = np.zeros((self.ncoord, self.ncoord))
        for e in self.elements:
            k, T = self.element_stiffness(e)
            coords, A = self._element_map(e)
            B = T @ A
            K[np.ix_(coords, coords)] += B.T @ k @ B
        for sl in self.slabs:
            k = membrane_stiffness(sl.x[1] - sl.x[0], sl.y[1] - sl.y[0], sl.thickness, sl.E, sl.nu)
            corners = [self._node_at(sl.floor, p, self._at) for p in
                       ((sl.x[0], sl.y[0]), (sl.x[1], sl.y[0]), (sl.x[1], sl.y[1]), (sl.x[0], sl.y[1]))]
            rows = [self.rows[nd][d] for nd in corners for d in (0, 1)]
            coords = sorted({c for r in rows for c in r})
            pos = {c: i for i, c in enumerate(coords)}
            A = np.zeros((8, len(coords)))
            for p, r in enumerate(rows):
                for c, v in r.items():
                    A[p, pos[c]] = v
            K[np.ix_(coords, coords)] += A.T @ k @ A
        return K

    def condensed(self):
        """(K*, G): K* on the kept coordinates (symmetrised) and G = [I; −K_cc⁻¹ K_cr] with
        q = G q_kept."""
        K, nr = self.stiffness(), self.nkept
        Kcc, Kcr = K[nr:, nr:], K[nr:, :nr]
        X = -np.linalg.solve(Kcc, Kcr) if Kcc.size else np.zeros((0, nr))
        Ks = K[:nr, :nr] + K[:nr, nr:] @ X
        return 0.5 * (Ks + Ks.T), np.vstack([np.eye(nr), X])

    def recovery(self, G=None):
        """R (12·elements x kept): f_e = R[12e:12e+12] q_kept, in the order of END_FORCES at
        end i then end j."""
        if G is None:
            G = self.condensed()[1]
        R = np.zeros((12 * len(self.elements), self.nkept))
        for i, e in enumerate(self.elements):
            k, T = self.element_stiffness(e)
            coords, A = self._element_map(e)
            R[12 * i:12 * i + 12] = k @ T @ A @ G[coords]
        return R

    # --- mass ------------------------------------------------------------------------------
    def mass_matrix(self):
        """M on the kept coordinates (dense; diagonal where every reference is its floor's
        mass centre)."""
        M = np.zeros((self.nkept, self.nkept))
        grid = self.grid_masses or {}
        for i, (floor, where, c) in enumerate(self.kept):
            if floor is None:
                sp = next(sp for sp in self.splits if sp.name == where)
                M[i, i] = sp.mass
            elif where is not None:
                M[i, i] = grid[floor][where]
            elif c == "ux":
                fl = self.floors[floor - 1]
                xo, yo = self.reference_point(floor)
                dx, dy = fl.centre[0] - xo, fl.centre[1] - yo
                m = fl.mass
                M[i:i + 3, i:i + 3] = [[m, 0.0, -m * dy], [0.0, m, m * dx],
                                       [-m * dy, m * dx, fl.inertia + m * (dx * dx + dy * dy)]]
        return M

    def influence(self, angle=0.0):
        """ι of a ground motion along `angle` degrees from x in plan (the kept coordinates
        move by ι per unit of ground displacement: translations cos, sin; rotations 0)."""
        c, s = np.cos(np.radians(angle)), np.sin(np.radians(angle))
        return np.array([{"ux": c, "uy": s, "rz": 0.0}[k] for _, _, k in self.kept])

    # --- operators on the kept coordinates ---------------------------------------------------
    def point_operator(self, floor, x, y):
        """P (2 x kept): (ux, uy) of plan point (x, y) of rigid floor `floor`."""
        P = np.zeros((2, self.nkept))
        i = self.kept.index((floor, None, "ux"))
        xo, yo = self.reference_point(floor)
        P[0, i], P[0, i + 2] = 1.0, -(y - yo)
        P[1, i + 1], P[1, i + 2] = 1.0, x - xo
        return P

    def storey_operator(self, R=None):
        """S (3·storeys x kept): storey s's shear along x and y and its torque about the
        reference point of floor s (rows 3(s−1) + 0, 1, 2): the sums over the storey's members
        of their top-end forces (what the floor above applies to them), k·drift in a shear
        storey."""
        if R is None:
            R = self.recovery()
        S = np.zeros((3 * self.storeys, self.nkept))
        for i, e in enumerate(self.elements):
            if e.kind == "beam":
                continue
            top = self.nodes[e.ends[1]]
            if top.floor is None:
                continue                   # the lower half of a split member
            s = top.floor
            F = e.R.T @ R[12 * i + 6:12 * i + 9]          # global force at end j
            Mz = (e.R.T @ R[12 * i + 9:12 * i + 12])[2]
            xo, yo = self.reference_point(s) if self.floors[s - 1].rigid else (0.0, 0.0)
            S[3 * (s - 1)] += F[0]
            S[3 * (s - 1) + 1] += F[1]
            S[3 * (s - 1) + 2] += (top.x - xo) * F[1] - (top.y - yo) * F[0] + Mz
        return S


# --- slabs -------------------------------------------------------------------------------------

def membrane_stiffness(lx, ly, t, E, nu):
    """The 8 x 8 in-plane stiffness of an lx × ly rectangular slab panel of thickness t in plane
    stress, on (ux, uy) of its corners counterclockwise from (x0, y0): the bilinear element with
    Wilson's incompatible modes 1 − ξ², 1 − η² condensed (Q6: Wilson, Taylor, Doherty &
    Ghaboussi, Incompatible displacement models, 1973; Cook, Malkus, Plesha & Witt, Concepts and
    Applications of Finite Element Analysis, §6.7), 2 × 2 Gauss points. On a rectangle it
    passes the patch test and is exact in pure in-plane bending, which the bilinear element
    alone (shear locking) is not: one panel per bay models a slab bending in its plane."""
    D = E / (1 - nu * nu) * np.array([[1.0, nu, 0.0], [nu, 1.0, 0.0], [0.0, 0.0, (1 - nu) / 2]])
    hx, hy = lx / 2, ly / 2
    xi_n, eta_n = (-1.0, 1.0, 1.0, -1.0), (-1.0, -1.0, 1.0, 1.0)
    g = 1 / np.sqrt(3.0)
    K = np.zeros((12, 12))                     # 8 corner DOFs, then 4 incompatible ones
    for xi in (-g, g):
        for eta in (-g, g):
            dx = [xn * (1 + eta * en) / 4 / hx for xn, en in zip(xi_n, eta_n)] + [-2 * xi / hx, 0.0]
            dy = [en * (1 + xi * xn) / 4 / hy for xn, en in zip(xi_n, eta_n)] + [0.0, -2 * eta / hy]
            B = np.zeros((3, 12))
            for a in range(6):
                B[0, 2 * a] = dx[a]
                B[1, 2 * a + 1] = dy[a]
                B[2, 2 * a], B[2, 2 * a + 1] = dy[a], dx[a]
            K += t * hx * hy * B.T @ D @ B     # Gauss weights 1, |J| = hx hy
    Kcc, Kci, Kii = K[:8, :8], K[:8, 8:], K[8:, 8:]
    Ks = Kcc - Kci @ np.linalg.solve(Kii, Kci.T)
    return 0.5 * (Ks + Ks.T)


# --- modes ------------------------------------------------------------------------------------

def modal_table(building, K, M, count=None):
    """Per mode: period, effective-mass ratios along x and y (Chopra, Dynamics of Structures,
    §13.2: Γ² / Σ ιᵀMι) and the torsional share — the fraction of the mode's kinetic energy
    in the floors' rotation about their mass centres."""
    w, Phi = modes(K, M)
    ix, iy = building.influence(0.0), building.influence(90.0)
    tx, ty = ix @ M @ ix, iy @ M @ iy
    rot = np.zeros(len(w))
    for s in range(1, building.storeys + 1):
        fl = building.floors[s - 1]
        if not fl.rigid:
            continue
        i = building.kept.index((s, None, "rz"))
        rot += fl.inertia * Phi[i] ** 2             # Φᵀ M Φ = 1: the mode's kinetic energy
    out = []
    for k in range(len(w) if count is None else min(count, len(w))):
        out.append({"mode": k + 1, "period": float(2 * np.pi / w[k]) if w[k] > 0 else float("inf"),
                    "omega": float(w[k]),
                    "mass_ratio_x": float((Phi[:, k] @ M @ ix) ** 2 / tx),
                    "mass_ratio_y": float((Phi[:, k] @ M @ iy) ** 2 / ty),
                    "torsional_share": float(rot[k])})
    return out


def rayleigh_coefficients(K, M, zeta, modes_=(1, 2)):
    """(a0, a1) of C = a0 M + a1 K with ζ at the two modes (Chopra §11.4); M dense or diagonal."""
    w = modes(K, M)[0]
    i, j = (min(modes_[0], len(w)) - 1, min(modes_[1], len(w)) - 1)
    if i == j:
        return zeta * w[i], zeta / w[i]
    return 2 * zeta * w[i] * w[j] / (w[i] + w[j]), 2 * zeta / (w[i] + w[j])


def modal_damping(K, M, zeta):
    """C = M Φ diag(2ζω) Φᵀ M (Chopra §11.5): ζ in every mode; M dense or diagonal."""
    w, Phi = modes(K, M)
    M = np.asarray(M, float)
    MP = (M[:, None] * Phi) if M.ndim == 1 else M @ Phi
    C = MP @ np.diag(2 * zeta * w) @ MP.T
    return 0.5 * (C + C.T)


# --- the seed's interface stiffness (seed §4, Muthukumar & DesRoches 2006) ----------------

def gap_stiffness_offset(section, height, factor=2.0):
    """The seed's rule where a slab strikes a column between floors: factor (1.5–2) times
    the struck column's lateral stiffness, fixed–fixed 12 E I3/h³ along its axis 2."""
    if not 1.5 <= factor <= 2.0:
        raise ValueError(f"factor: {factor!r} is outside the seed's 1.5–2")
    return factor * 12 * section.E * section.I3 / height**3
