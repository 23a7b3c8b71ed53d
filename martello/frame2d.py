"""Planar frames of Euler–Bernoulli beam-columns (docs/problems.md P10): the regular grid of
`storeys` x `bays` a [[frame]] table describes, its direct-stiffness assembly with 3 DOF per
joint (u along x, w along y, rotation θ counterclockwise), the static condensation to the
lateral DOFs that carry mass, and the recovery operator that gives every member's end forces
from those lateral displacements.

Condensation is exact for massless vertical and rotational DOFs (Guyan reduction without
inertia; Clough & Penzien, Dynamics of Structures, §11-2): with the lateral DOFs r and the
others c, K* = K_rr − K_rc K_cc⁻¹ K_cr and u_c = −K_cc⁻¹ K_cr u_r. Member end forces are the
direct-stiffness ones, f_e = k_e T_e u_e (McGuire, Gallagher & Ziemian, Matrix Structural
Analysis, ch. 4–5): in the member's axes, the end forces the joints apply to it, [N_i, V_i,
M_i, N_j, V_j, M_j], moments counterclockwise positive, end i the bottom of a column and the
left end of a beam.

Mass models: "diaphragm" (a rigid floor: one lateral DOF per floor, beams axially rigid, so
their axial forces are not recovered) or "joints" (every joint keeps its own lateral DOF,
carrying the floor mass by tributary width). Gravity is not modelled: the frame is linear,
its seismic response superposes on the gravity state."""

from dataclasses import dataclass, field

import numpy as np

from .modes import frequencies, modes

# Local end-force components of a member, in recovery rows 6e + k.
END_FORCES = ("N_i", "V_i", "M_i", "N_j", "V_j", "M_j")


@dataclass
class Member:
    name: str            # "C<storey>.<line>" or "B<floor>.<bay>" (1-based storey/floor/bay)
    kind: str            # "column" or "beam"
    ends: tuple          # the joints (line, level) of end i and end j
    E: float
    A: float
    I: float
    length: float
    cos: float           # direction of end i -> end j
    sin: float


@dataclass
class PlanarFrame:
    """A regular planar frame: heights[s] of storey s + 1 (bottom up), widths[b] of bay b + 1
    (left to right), columns[s][line] and beams[s][bay] as (E, A, I), floor masses[s] (with
    mass_model "joints" also a list of the bays + 1 joint masses of the floor)."""
    heights: list
    widths: list
    columns: list
    beams: list
    masses: list
    base: str = "fixed"          # "fixed" or "pinned"
    mass_model: str = "diaphragm"  # "diaphragm" or "joints"
    members: list = field(init=False)

    def __post_init__(self):
        ns, nb = len(self.heights), len(self.widths)
        self.x = np.concatenate([[0.0], np.cumsum(self.widths)])
        self.y = np.concatenate([[0.0], np.cumsum(self.heights)])
        self.members = []
        for s in range(ns):
            for i in range(nb + 1):
                E, A, I = self.columns[s][i]
                self.members.append(Member(f"C{s + 1}.{i}", "column", ((i, s), (i, s + 1)),
                                           E, A, I, self.heights[s], 0.0, 1.0))
        for s in range(ns):
            for b in range(nb):
                E, A, I = self.beams[s][b]
                self.members.append(Member(f"B{s + 1}.{b + 1}", "beam", ((b, s + 1), (b + 1, s + 1)),
                                           E, A, I, self.widths[b], 1.0, 0.0))

    @property
    def storeys(self):
        return len(self.heights)

    @property
    def bays(self):
        return len(self.widths)

    # --- the lateral DOFs (the scene's nodes) ------------------------------------------------
    def lateral_names(self, prefix):
        """Names of the lateral DOFs: <prefix><floor> for a diaphragm, <prefix><floor>.<line>
        for joint masses (floor 1 = the first above the base, line 0 = the left column)."""
        if self.mass_model == "diaphragm":
            return [f"{prefix}{s + 1}" for s in range(self.storeys)]
        return [f"{prefix}{s + 1}.{i}" for s in range(self.storeys) for i in range(self.bays + 1)]

    def lateral_masses(self):
        """The mass of each lateral DOF: the floor's mass, or its share by tributary width,
        or (joint masses: masses[s] a list of bays + 1 values) each joint's own."""
        if self.mass_model == "diaphragm":
            return np.asarray(self.masses, float)
        w = np.asarray(self.widths, float)
        trib = (np.concatenate([[0.0], w]) + np.concatenate([w, [0.0]])) / 2 / w.sum()
        return np.concatenate([np.asarray(m, float) if np.ndim(m) else m * trib for m in self.masses])

    def lateral_index(self, floor, line):
        """The lateral DOF (0-based) of the joint (line, floor), floor >= 1."""
        if self.mass_model == "diaphragm":
            return floor - 1
        return (floor - 1) * (self.bays + 1) + line

    # --- assembly ----------------------------------------------------------------------------
    def _numbering(self):
        """Generalised coordinates: the lateral ones first (nr), then w and θ of every free
        joint. Returns (nr, ncoord, dof) with dof[(line, level)] = (iu, iw, iθ), -1 where
        restrained."""
        nr = self.storeys if self.mass_model == "diaphragm" else self.storeys * (self.bays + 1)
        dof, k = {}, nr
        for j in range(self.storeys + 1):
            for i in range(self.bays + 1):
                if j == 0:
                    if self.base == "fixed":
                        dof[(i, j)] = (-1, -1, -1)
                    else:
                        dof[(i, j)] = (-1, -1, k); k += 1
                    continue
                dof[(i, j)] = (self.lateral_index(j, i), k, k + 1); k += 2
        return nr, k, dof

    def element_stiffness(self, m):
        """The member's stiffness in its own axes (6 x 6) and its rotation T (local = T global)."""
        L, EA, EI = m.length, m.E * m.A, m.E * m.I
        a, b, c, d = EA / L, 12 * EI / L**3, 6 * EI / L**2, EI / L
        k = np.array([[a, 0, 0, -a, 0, 0],
                      [0, b, c, 0, -b, c],
                      [0, c, 4 * d, 0, -c, 2 * d],
                      [-a, 0, 0, a, 0, 0],
                      [0, -b, -c, 0, b, -c],
                      [0, c, 2 * d, 0, -c, 4 * d]])
        r = np.array([[m.cos, m.sin, 0], [-m.sin, m.cos, 0], [0, 0, 1]])
        T = np.zeros((6, 6)); T[:3, :3] = r; T[3:, 3:] = r
        return k, T

    def _element_dofs(self, m, dof):
        return [q for end in m.ends for q in dof[end]]

    def stiffness(self):
        """K on the generalised coordinates (lateral first) and the count nr of lateral ones."""
        nr, n, dof = self._numbering()
        K = np.zeros((n, n))
        for m in self.members:
            k, T = self.element_stiffness(m)
            kg = T.T @ k @ T
            idx = self._element_dofs(m, dof)
            for p, ip in enumerate(idx):
                if ip < 0:
                    continue
                for q, iq in enumerate(idx):
                    if iq >= 0:
                        K[ip, iq] += kg[p, q]
        return K, nr

    def condensed(self):
        """(K*, G): the lateral stiffness K* (nr x nr, symmetrised) and G with the generalised
        coordinates q = G u_r (G = [I; −K_cc⁻¹ K_cr])."""
        K, nr = self.stiffness()
        Kcc, Kcr = K[nr:, nr:], K[nr:, :nr]
        X = -np.linalg.solve(Kcc, Kcr) if Kcc.size else np.zeros((0, nr))
        Ks = K[:nr, :nr] + K[:nr, nr:] @ X
        G = np.vstack([np.eye(nr), X])
        return 0.5 * (Ks + Ks.T), G

    def recovery(self, G=None):
        """R (6·members x nr): the local end forces of member e, f_e = R[6e:6e+6] u_r, in the
        order of END_FORCES."""
        if G is None:
            G = self.condensed()[1]
        nr, n, dof = self._numbering()
        R = np.zeros((6 * len(self.members), nr))
        for e, m in enumerate(self.members):
            k, T = self.element_stiffness(m)
            idx = self._element_dofs(m, dof)
            Ue = np.array([G[i] if i >= 0 else np.zeros(nr) for i in idx])   # 6 x nr
            R[6 * e:6 * e + 6] = k @ T @ Ue
        return R

    def storey_drift_operator(self):
        """D (storeys·(bays+1) x nr): the drift of every column, u(top) − u(bottom), row
        s·(bays+1) + line."""
        nr = self._numbering()[0]
        D = np.zeros((self.storeys * (self.bays + 1), nr))
        for s in range(self.storeys):
            for i in range(self.bays + 1):
                row = s * (self.bays + 1) + i
                D[row, self.lateral_index(s + 1, i)] += 1.0
                if s > 0:
                    D[row, self.lateral_index(s, i)] -= 1.0
        return D

    def storey_shear_operator(self, R=None):
        """S (storeys x nr): the storey shear, the horizontal force the columns of a storey
        carry, positive when it pushes the floor above along +u (the sum over the storey's
        columns of the global x component of their top-end force)."""
        if R is None:
            R = self.recovery()
        S = np.zeros((self.storeys, R.shape[1]))
        for e, m in enumerate(self.members):
            if m.kind != "column":
                continue
            s = m.ends[0][1]
            # top end (j): global x = cos·N − sin·V, with cos = 0, sin = 1 for a column
            S[s] += m.cos * R[6 * e + 3] - m.sin * R[6 * e + 4]
        return S


def rayleigh_coefficients(K, M, zeta, modes=(1, 2)):
    """(a0, a1) of C = a0 M + a1 K with the damping ratio zeta at the two given modes
    (Chopra, Dynamics of Structures, §11.4): a0 = 2ζωᵢωⱼ/(ωᵢ+ωⱼ), a1 = 2ζ/(ωᵢ+ωⱼ). With a
    single mode (one DOF, or both modes the same) a0 = ζω, a1 = ζ/ω: ζ at ω exactly."""
    w = natural_frequencies(K, M)
    i, j = (min(modes[0], len(w)) - 1, min(modes[1], len(w)) - 1)
    if i == j:
        return zeta * w[i], zeta / w[i]
    return 2 * zeta * w[i] * w[j] / (w[i] + w[j]), 2 * zeta / (w[i] + w[j])


def modal_damping(K, M, zeta):
    """C = M Φ diag(2ζω) Φᵀ M with Φ the mass-normalised modes of K φ = ω² M φ (M diagonal,
    given as its diagonal): the damping ratio zeta in every mode (Chopra, Dynamics of
    Structures, §11.5), symmetrised to round-off."""
    m = np.asarray(M, float)
    w, phi = modes(K, m)                                   # Φᵀ M Φ = I
    mp = m[:, None] * phi
    C = mp @ np.diag(2 * zeta * w) @ mp.T
    return 0.5 * (C + C.T)


def natural_frequencies(K, M):
    """ω (rad/s, ascending) of K φ = ω² M φ for a diagonal M (given as its diagonal); an ω²
    computed <= 0 or not finite raises LinAlgError (martello.modes)."""
    return frequencies(K, np.asarray(M, float))


# --- interface links across a joint (seed §4, after Muthukumar & DesRoches 2006) ----------

def beam_axial_stiffness(frame, floor, bay):
    """EA/L of the beam of `bay` (1-based, 1 at the left) at `floor` (1-based)."""
    E, A, _ = frame.beams[floor - 1][bay - 1]
    return E * A / frame.widths[bay - 1]


def gap_stiffness_aligned(frame_a, frame_b, floor, combine="mean"):
    """The seed's rule for a gap element between floors at the same level: the axial
    stiffness of the two beams it connects — the last bay of frame_a (on the left of the
    joint) and the first bay of frame_b (on the right) at `floor`. combine: "mean" (their
    harmonic mean 2/(1/k_a + 1/k_b), which is their common EA/L when the beams are equal, as
    docs/p8-case-study.md reads the rule), "series" (1/(1/k_a + 1/k_b): the two beams
    compressed one after the other) or "sum" (k_a + k_b)."""
    ka = beam_axial_stiffness(frame_a, floor, frame_a.bays)
    kb = beam_axial_stiffness(frame_b, floor, 1)
    rules = {"mean": 2 / (1 / ka + 1 / kb), "series": 1 / (1 / ka + 1 / kb), "sum": ka + kb}
    if combine not in rules:
        raise ValueError(f"combine: unknown value {combine!r} (valid: mean, series, sum)")
    return rules[combine]


def gap_stiffness_offset(frame, storey, line, factor=2.0):
    """The seed's rule for floors at different levels, where a slab strikes a column
    mid-height: factor (1.5–2) times the lateral stiffness of the struck column, taken as
    fixed–fixed 12EI/h³ (the column between two floors of its frame)."""
    if not 1.5 <= factor <= 2.0:
        raise ValueError(f"factor: {factor!r} is outside the seed's 1.5–2 "
                         "(the rule is 1.5–2 times the column's lateral stiffness)")
    E, _, I = frame.columns[storey - 1][line]
    return factor * 12 * E * I / frame.heights[storey - 1] ** 3
