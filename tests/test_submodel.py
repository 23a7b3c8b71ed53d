"""Sub-models for local stepping (c/martello_internal.h martello_model_subset and
martello_eval_state_transfer; docs/run-layer.md, "Sub-models for local stepping"), through the
internal C doors by ctypes.

Every check here is an IDENTITY OF THE METHOD, not a verification: a sub-model's forces are the
parent's rows for its nodes because its nodes keep the parent's order and its elements the
parent's, so every sum is taken in the same order -- bit for bit, no tolerance. The scenes are
small (8 to 40 nodes): the family runs in about a second."""

import ctypes

import numpy as np
import pytest

from martello.binding import native
from martello.binding.native import constant as K

VP, DP, IP = ctypes.c_void_p, ctypes.POINTER(ctypes.c_double), ctypes.POINTER(ctypes.c_int)


class SubsetMap(ctypes.Structure):
    _fields_ = [("n_nodes", ctypes.c_int), ("n_links", ctypes.c_int), ("n_contacts", ctypes.c_int),
                ("node", IP), ("link", IP), ("contact", IP),
                ("n_blocks", ctypes.c_int), ("block", IP)]

    def arrays(self):
        def take(p, n):
            return np.array([p[k] for k in range(n)], dtype=int)
        return (take(self.node, self.n_nodes), take(self.link, self.n_links),
                take(self.contact, self.n_contacts), take(self.block, self.n_blocks))


def _lib():
    L = native.lib()
    protos = {
        "martello_model_subset": (ctypes.c_int, [VP, ctypes.c_int, IP, ctypes.POINTER(VP),
                                                 ctypes.POINTER(SubsetMap)]),
        "martello_subset_map_free": (None, [ctypes.POINTER(SubsetMap)]),
        "martello_model_expand_chains": (ctypes.c_int, [VP]),
        "martello_eval_state_transfer": (ctypes.c_int, [VP, VP, ctypes.POINTER(SubsetMap),
                                                        ctypes.c_int]),
        "martello_eval_create": (ctypes.c_int, [VP, ctypes.POINTER(VP)]),
        "martello_eval_free": (None, [ctypes.POINTER(VP)]),
        "martello_eval_acceleration": (ctypes.c_int, [VP, ctypes.c_double, DP, DP, DP]),
        "martello_eval_forces": (ctypes.c_int, [VP, ctypes.c_double, DP, DP, DP, DP]),
        "martello_eval_energy": (ctypes.c_int, [VP, DP, DP, DP, DP]),
        "martello_eval_power": (ctypes.c_int, [VP, DP]),
        "martello_eval_commit": (ctypes.c_int, [VP, DP, DP]),
        "martello_eval_use_branches": (ctypes.c_int, [VP, IP]),
        "martello_eval_use_smooth_branches": (ctypes.c_int, [VP, ctypes.c_int, IP, IP]),
        "martello_eval_switches": (ctypes.c_int, [VP, IP, DP, DP, DP]),
        "martello_eval_bandwidth": (ctypes.c_int, [VP, IP, IP]),
        "martello_eval_tangent": (ctypes.c_int, [VP, DP, DP, DP, DP]),
        "martello_model_topology": (ctypes.c_int, [VP, IP, IP, DP, IP, IP, DP, DP, IP]),
        "martello_model_elements": (ctypes.c_int, [VP, IP, IP, IP, IP, DP]),
        "martello_model_initial_state": (ctypes.c_int, [VP, DP, DP]),
    }
    for name, (res, args) in protos.items():
        fn = getattr(L, name)
        fn.restype, fn.argtypes = res, args
    return L


L = _lib()


def dp(x):
    return np.ascontiguousarray(x, dtype=np.float64).ctypes.data_as(DP)


class Handle:
    """A raw model handle of the internal doors (a sub-model: freed by martello_model_free)."""

    def __init__(self, h):
        self.h = h

    def free(self):
        if self.h.value:
            L.martello_model_free(ctypes.byref(self.h))


class Eval:
    """An evaluator of a model handle, with numpy views of the doors."""

    def __init__(self, model_h):
        self.model_h = model_h
        n, nc, ncp = ctypes.c_int(), ctypes.c_int(), ctypes.c_int()
        assert L.martello_model_topology(model_h, ctypes.byref(n), ctypes.byref(nc), None, None,
                                         None, None, None, ctypes.byref(ncp)) == 0
        self.n, self.nc = n.value, nc.value
        nl, nt = ctypes.c_int(), ctypes.c_int()
        assert L.martello_model_elements(model_h, ctypes.byref(nl), ctypes.byref(nt),
                                         None, None, None) == 0
        self.nl = nl.value
        self.h = VP()
        assert L.martello_eval_create(model_h, ctypes.byref(self.h)) == 0
        kd, lumped = ctypes.c_int(), ctypes.c_int()
        assert L.martello_eval_bandwidth(self.h, ctypes.byref(kd), ctypes.byref(lumped)) == 0
        self.kd = kd.value

    def free(self):
        L.martello_eval_free(ctypes.byref(self.h))

    def acceleration(self, t, u, v):
        a = np.zeros(self.n)
        assert L.martello_eval_acceleration(self.h, t, dp(u), dp(v), dp(a)) == 0
        return a

    def forces(self, t, u, v):
        fi, fe = np.zeros(self.n), np.zeros(self.n)
        assert L.martello_eval_forces(self.h, t, dp(u), dp(v), dp(fi), dp(fe)) == 0
        return fi, fe

    def energy(self, u, v):
        k, r = ctypes.c_double(), ctypes.c_double()
        assert L.martello_eval_energy(self.h, dp(u), dp(v), ctypes.byref(k), ctypes.byref(r)) == 0
        return k.value, r.value

    def power(self):
        p = np.zeros(5)
        assert L.martello_eval_power(self.h, dp(p)) == 0
        return p

    def commit(self, u, v):
        assert L.martello_eval_commit(self.h, dp(u), dp(v)) == 0

    def use_branches(self, smooth=False):
        nsw = ctypes.c_int()
        if smooth:
            cont = np.zeros(max(self.nc, 1), dtype=np.int32)
            # laws 1: MARTELLO_ACROSS_CONTINUOUS (c/martello_internal.h), CVODE's and IDA's class
            assert L.martello_eval_use_smooth_branches(self.h, 1, ctypes.byref(nsw),
                                                       cont.ctypes.data_as(IP)) == 0
        else:
            assert L.martello_eval_use_branches(self.h, ctypes.byref(nsw)) == 0
        assert nsw.value == 2 * self.nl + self.nc

    def switches(self):
        """Every slot of the model (2 per link, 1 per contact: the door writes them all)."""
        nsw = 2 * self.nl + self.nc
        el = np.zeros(max(nsw, 1), dtype=np.int32)
        abg = [np.zeros(max(nsw, 1)) for _ in range(3)]
        assert L.martello_eval_switches(self.h, el.ctypes.data_as(IP), *map(dp, abg)) == 0
        return el[:nsw], [x[:nsw] for x in abg]

    def tangent(self, u, v):
        """K_t and C_t as dense n x n matrices (from the band)."""
        ld = 3 * self.kd + 1
        kb, cb = np.zeros(ld * self.n), np.zeros(ld * self.n)
        assert L.martello_eval_tangent(self.h, dp(u), dp(v), dp(kb), dp(cb)) == 0
        dense = []
        for band in (kb, cb):
            A = np.zeros((self.n, self.n))
            for k in range(self.n):
                for i in range(max(0, k - self.kd), min(self.n, k + self.kd + 1)):
                    A[i, k] = band[(2 * self.kd + i - k) + k * ld]
            dense.append(A)
        return dense


def subset(model_h, nodes):
    """(status, sub Handle, SubsetMap) of the free nodes `nodes`."""
    sub, m = VP(), SubsetMap()
    arr = np.ascontiguousarray(nodes, dtype=np.int32)
    st = L.martello_model_subset(model_h, len(arr), arr.ctypes.data_as(IP), ctypes.byref(sub),
                                 ctypes.byref(m))
    return st, Handle(sub), m


def message(model_h):
    buf = ctypes.create_string_buffer(1024)
    L.martello_model_message(model_h, buf, len(buf))
    return buf.value.decode()


def transfer(parent, sub, m, to_sub):
    return L.martello_eval_state_transfer(parent.h, sub.h, ctypes.byref(m), int(to_sub))


NL, NC = K("NPAR_LINK"), K("NPAR_CONTACT")


def link_par(k=0.0, c=0.0, fy=0.0, rho=0.0, alpha=0.0, vreg=0.0):
    return [k, c, fy, rho, alpha, vreg]


def contact_par(k, exponent=0.0, damping=0.0, e=0.0, clip=0.0):
    return [k, exponent, damping, e, clip, 0, 0, 0]


def row_scene(n_free=10, couplings=(), block=None):
    """A row of n_free masses between two fixed walls (nodes 0 and n_free + 1): springs to
    ground (every third bilinear, hysteretic), dashpots, a fluid damper; penalty contacts
    between neighbours (linear, Kelvin clipped, Hertz) and against both walls; ground motion,
    gravity, an influence vector, two nodal forces (one on a wall)."""
    n = n_free + 2
    m = native.Model(n, 3 * n_free, n_free + 1, 2, len(couplings))
    m.set_node(0, 0.0, u0=0.01, fixed=True)
    m.set_node(n - 1, 0.0, fixed=True)
    for i in range(1, n - 1):
        m.set_node(i, 1.0e3 * (1 + 0.1 * i), u0=0.0, v0=0.05 * np.sin(i))
    for i in range(1, n - 1):
        if i % 3 == 0:
            m.add_link(K("LINK_BILINEAR"), i, -1, link_par(k=2e6, fy=1e3, rho=0.1))
        else:
            m.add_link(K("LINK_SPRING"), i, -1, link_par(k=1e6 * (1 + 0.2 * i)))
        m.add_link(K("LINK_DASHPOT"), i, -1, link_par(c=1e3))
    m.add_link(K("LINK_FLUID_DAMPER"), 2, 3, link_par(c=5e3, alpha=0.5, vreg=1e-3))
    laws = [(K("LAW_LINEAR"), contact_par(1e8)),
            (K("LAW_KELVIN"), contact_par(1e8, damping=1e4, clip=1.0)),
            (K("LAW_HERTZ"), contact_par(1e9, exponent=1.5))]
    for i in range(0, n - 1):
        law, par = laws[i % 3]
        m.add_contact(i, i + 1, 1e-3, K("SCHEME_PENALTY"), law, par)
    for a, b, val in couplings:
        m.add_mass_coupling(a, b, val)
    if block is not None:
        nodes = list(block)
        kb = 1e5 * (np.eye(len(nodes)) * 2 - np.eye(len(nodes), k=1) - np.eye(len(nodes), k=-1))
        m.add_stiffness_block(nodes, kb, 0.01 * kb)
    m.set_gravity(0.5)
    m.set_influence(np.linspace(0.5, 1.5, n))
    m.set_ground_acceleration(K("TF_SINE"), [2.0, 12.0, 0.3, 0.0, 10.0])
    m.add_nodal_force(3, K("TF_CONSTANT"), [250.0, 0, 0, 0, 0])
    m.add_nodal_force(n - 1, K("TF_CONSTANT"), [-7.0, 0, 0, 0, 0])
    return m


def state(n, seed, closed=(), opened=()):
    """A state (u, v): contacts i (between nodes i and i + 1, gap 1 mm) in `closed` penetrating
    by 2 mm, those in `opened` open by 1 mm, the rest as random (set left to right, so that
    each contact is as asked)."""
    rng = np.random.default_rng(seed)
    u = np.cumsum(rng.uniform(-1e-3, 1e-3, n)) * 0.3
    for i in range(n - 1):
        if i in closed:
            u[i + 1] = u[i] - 3e-3
        elif i in opened:
            u[i + 1] = u[i] + 2e-3
    v = rng.uniform(-0.2, 0.2, n)
    return u, v


def assert_open(u, contacts):
    """The contacts between neighbours i, i + 1 (gap 1 mm) are open at u: the premise of the
    identities that leave them out."""
    for i in contacts:
        assert u[i] - u[i + 1] - 1e-3 < 0, f"contact {i} is not open"


def assert_same(a, b, what):
    assert np.array_equal(np.asarray(a), np.asarray(b)), f"{what}: {a} != {b}"


def free_nodes(n):
    return list(range(1, n - 1))


def test_subset_of_every_free_node_is_the_parent_bit_for_bit():
    """Identity: the sub-model of every free node (both walls join as the fixed nodes their
    contacts touch) is the parent, renumbered by the identity: acceleration, forces, energies,
    powers, switches and tangents equal bit for bit at a state with contacts open and closed,
    on the whole laws and on branches."""
    with row_scene() as m:
        n = m.n_nodes
        st, sub, mp = subset(m.handle, free_nodes(n)[::-1])   # any order given
        assert st == 0, message(m.handle)
        try:
            node, link, contact, block = mp.arrays()
            assert_same(node, range(n), "nodes")
            assert_same(link, range(2 * (n - 2) + 1), "links")
            assert_same(contact, range(n - 1), "contacts")
            pe, se = Eval(m.handle), Eval(sub.h)
            u, v = state(n, 1, closed=(2, 5), opened=(1, 4))
            for smooth in (None, False, True):
                if smooth is not None:
                    pe.use_branches(smooth)
                    se.use_branches(smooth)
                for t in (0.0, 0.37):
                    assert_same(se.acceleration(t, u, v), pe.acceleration(t, u, v), "a")
                    assert_same(se.power(), pe.power(), "power")
                    for x, y in zip(se.forces(t, u, v), pe.forces(t, u, v)):
                        assert_same(x, y, "forces")
                    assert_same(se.energy(u, v), pe.energy(u, v), "energy")
                    for x, y in zip(se.tangent(u, v), pe.tangent(u, v)):
                        assert_same(x, y, "tangent")
                if smooth is not None:
                    for x, y in zip(se.switches(), pe.switches()):
                        assert_same(x, y, "switches")
            assert se.kd == pe.kd
            pe.free(); se.free()
        finally:
            L.martello_subset_map_free(ctypes.byref(mp))
            sub.free()


PARTITION = [[1, 2, 3], [4, 5], [6, 7, 8, 9, 10]]   # cut at contacts 3 and 5: opened


def test_partition_with_open_cross_contacts_gives_the_parent_rows():
    """Identity: clusters of a partition whose cross contacts are open each give the parent's
    rows of acceleration, internal and external force for their free nodes bit for bit (the
    open contacts add exact zeros in the parent's sums), and the clusters' kinetic and
    recoverable energies sum to the parent's (to a few ulps: the sum is regrouped)."""
    with row_scene() as m:
        n = m.n_nodes
        u, v = state(n, 2, closed=(1, 7, 8), opened=(3, 5))
        assert_open(u, (3, 5))
        pe = Eval(m.handle)
        pe.commit(u, v)            # energies are those of a committed state
        for smooth in (False, True):
            pe.use_branches(smooth)
            a, (fi, fe) = pe.acceleration(0.2, u, v), pe.forces(0.2, u, v)
            kin, rec = pe.energy(u, v)
            ks = rs = 0.0
            for cluster in PARTITION:
                st, sub, mp = subset(m.handle, cluster)
                assert st == 0, message(m.handle)
                node = mp.arrays()[0]
                se = Eval(sub.h)
                assert transfer(pe, se, mp, True) == 0
                free = np.isin(node, cluster)
                assert_same(se.acceleration(0.2, u[node], v[node])[free], a[node][free], "a")
                for x, y in zip(se.forces(0.2, u[node], v[node]), (fi, fe)):
                    assert_same(x[free], y[node][free], "forces")
                k, r = se.energy(u[node], v[node])
                ks, rs = ks + k, rs + r
                se.free()
                L.martello_subset_map_free(ctypes.byref(mp))
                sub.free()
            # the sums are regrouped: equal to the rounding of their n terms (n ulps at most)
            tol = n * np.finfo(float).eps
            assert ks == pytest.approx(kin, rel=tol) and rs == pytest.approx(rec, rel=tol)
        pe.free()


def trajectory(n, steps=6):
    """States far enough apart that bilinear springs yield and unload, contacts 3 and 5 open,
    the others closing and opening."""
    out = []
    for k in range(steps):
        u, v = state(n, 10 + k, closed=(1, 7) if k % 2 else (8,), opened=(3, 5))
        u[3] += 4e-3 * np.sin(k)          # node 3: bilinear spring, past its yield (1 mm)
        u[6] += 3e-3 * np.cos(1.3 * k)
        u[4] = u[3] + 2e-3; u[6] = max(u[6], u[5] + 2e-3)
        assert_open(u, (3, 5))
        out.append((u, v))
    return out


@pytest.mark.parametrize("smooth", [False, True])
def test_state_round_trip_through_sub_evaluators_equals_committing_on_the_parent(smooth):
    """Identity: the parent's committed state handed to each cluster's evaluator, committed
    there along a trajectory (bilinear springs yielding and unloading, contacts closing and
    opening inside the clusters, branches held) and handed back, leaves the parent as committing
    the same states on it: accelerations, energies, powers and switches at a later state equal
    bit for bit."""
    with row_scene() as m:
        n = m.n_nodes
        ref, par = Eval(m.handle), Eval(m.handle)
        for e in (ref, par):
            e.use_branches(smooth)
        traj = trajectory(n)
        for u, v in traj:
            ref.commit(u, v)
        subs = []
        for cluster in PARTITION:
            st, sub, mp = subset(m.handle, cluster)
            assert st == 0, message(m.handle)
            se = Eval(sub.h)
            se.use_branches(smooth)
            assert transfer(par, se, mp, True) == 0
            subs.append((sub, mp, se))
        for u, v in traj:
            for sub, mp, se in subs:
                node = mp.arrays()[0]
                se.commit(u[node], v[node])
        for sub, mp, se in subs:
            assert transfer(par, se, mp, False) == 0
            se.free()
            L.martello_subset_map_free(ctypes.byref(mp))
            sub.free()
        u, v = state(n, 99, opened=(3, 5))
        assert_open(u, (3, 5))
        assert_same(par.acceleration(0.1, u, v), ref.acceleration(0.1, u, v), "a")
        assert_same(par.power(), ref.power(), "power")
        assert_same(par.energy(*traj[-1]), ref.energy(*traj[-1]), "energy (the committed state)")
        for x, y in zip(par.switches(), ref.switches()):
            assert_same(x, y, "switches")
        ref.free(); par.free()


def test_one_cluster_of_everything_round_trip_is_exact():
    """Identity: with one cluster of every free node the sub evaluator's commits ARE the
    parent's: after the round trip the parent answers as the one that committed itself, and a
    sub evaluator made from it answers as the parent at once (transfer parent -> sub)."""
    with row_scene(couplings=[(2, 3, 50.0)], block=(4, 5, 6)) as m:
        n = m.n_nodes
        ref, par = Eval(m.handle), Eval(m.handle)
        ref.use_branches(True); par.use_branches(True)
        st, sub, mp = subset(m.handle, free_nodes(n))
        assert st == 0, message(m.handle)
        se = Eval(sub.h)
        assert transfer(par, se, mp, True) == 0    # the branch mode too: no use_branches on se
        traj = trajectory(n)
        for u, v in traj:
            ref.commit(u, v); se.commit(u, v)
        assert transfer(par, se, mp, False) == 0
        u, v = state(n, 5, closed=(2,))
        for e in (se, par):
            assert_same(e.acceleration(0.3, u, v), ref.acceleration(0.3, u, v), "a")
            assert_same(e.power(), ref.power(), "power")
            assert_same(e.energy(*traj[-1]), ref.energy(*traj[-1]), "energy (the committed state)")
            for x, y in zip(e.switches(), ref.switches()):
                assert_same(x, y, "switches")
        se.free(); ref.free(); par.free()
        L.martello_subset_map_free(ctypes.byref(mp))
        sub.free()


def test_chains_are_subset_on_the_expanded_model():
    """A model holding a chain per node (bilinear springs, dashpots, contacts between
    neighbours) is refused until expanded (martello_model_expand_chains); expanded, a cluster of
    it gives the parent's rows bit for bit, its fixed end (a wall) included."""
    n = 12
    with native.Model(n + 1, 0, 1, 0) as m:
        for i in range(n):
            m.set_node(i, 2e3, v0=0.1 * np.cos(i))
        m.set_node(n, 0.0, fixed=True)
        m.add_chain(0, np.full(n, 1e6), c=np.full(n, 50.0), fy=np.full(n, 5e2),
                    hardening=np.full(n, 0.05), gap=np.full(n - 1, 1e-3),
                    scheme=K("SCHEME_PENALTY"), law=K("LAW_LINEAR"), par=contact_par(1e8))
        m.add_contact(n - 1, n, 2e-3, K("SCHEME_PENALTY"), K("LAW_LINEAR"), contact_par(1e8))
        m.set_ground_acceleration(K("TF_SINE"), [1.0, 5.0, 0.0, 0.0, 5.0])
        st, sub, mp = subset(m.handle, [3, 4])
        assert st == K("MARTELLO_ERR_ARGUMENT") and "chains" in message(m.handle)
        assert "expand" in message(m.handle)
        L.martello_subset_map_free(ctypes.byref(mp))      # zeroed: freeing it is safe
        assert L.martello_model_expand_chains(m.handle) == 0
        u, v = state(n + 1, 3, closed=(8, 9), opened=(7,))
        u[n] = 0.0
        assert_open(u, (7,))
        pe = Eval(m.handle)
        a = pe.acceleration(0.05, u, v)
        st, sub, mp = subset(m.handle, [8, 9, 10, 11])
        assert st == 0, message(m.handle)
        node = mp.arrays()[0]
        assert_same(node, [8, 9, 10, 11, 12], "nodes (the wall joins)")
        se = Eval(sub.h)
        assert transfer(pe, se, mp, True) == 0
        assert_same(se.acceleration(0.05, u[node], v[node])[:4], a[8:12], "a")
        se.free(); pe.free()
        L.martello_subset_map_free(ctypes.byref(mp))
        sub.free()


def test_refusals_name_the_argument_and_the_fix():
    """Bad input gets a clear error: a node out of range, given twice or fixed, an empty
    cluster, a link, a mass coupling or a stiffness block cut by the cluster; a transfer with a map of
    another sub-model or a NULL array. The parent is left usable (its marks cleared)."""
    ARG = K("MARTELLO_ERR_ARGUMENT")
    with row_scene(couplings=[(4, 5, 50.0)], block=(6, 7, 8)) as m:
        n = m.n_nodes
        cases = [([1, n], f"nodes[1] = {n} is not a node"), ([1, -1], "is not a node"),
                 ([1, 2, 1], "node 1 is given twice"), ([0, 1], "nodes[0] = 0 is a fixed node"),
                 ([4], "mass coupling 0 between nodes 4 and 5 crosses the cut"),
                 ([1, 3], "link 20 has node 2 outside the cluster"),     # the fluid damper 2-3
                 ([6, 7], "stiffness block 0 has node 8 outside the cluster")]
        for nodes, says in cases:
            st, sub, mp = subset(m.handle, nodes)
            assert st == ARG and says in message(m.handle), (nodes, message(m.handle))
            assert not sub.h.value and mp.n_nodes == 0
            L.martello_subset_map_free(ctypes.byref(mp))
        sub, mp = VP(), SubsetMap()
        assert L.martello_model_subset(m.handle, 0, None, ctypes.byref(sub), ctypes.byref(mp)) == ARG
        assert "n must be >= 1" in message(m.handle)
        # after the refusals the marks are clear: a good subset is still the parent's rows
        st, sub, mp = subset(m.handle, [1, 2, 3, 4, 5])
        assert st == 0, message(m.handle)
        st2, sub2, mp2 = subset(m.handle, [6, 7, 8, 9, 10])
        assert st2 == 0, message(m.handle)
        pe, se, se2 = Eval(m.handle), Eval(sub.h), Eval(sub2.h)
        assert transfer(pe, se, mp2, True) == ARG
        assert "not that of the sub evaluator" in message(m.handle)
        bad = SubsetMap(mp.n_nodes, mp.n_links, mp.n_contacts, mp.node, None, mp.contact,
                        mp.n_blocks, mp.block)
        assert transfer(pe, se, bad, True) == ARG and "NULL" in message(m.handle)
        assert transfer(pe, se, mp, True) == 0
        for e in (se, se2, pe):
            e.free()
        for s, p in ((sub, mp), (sub2, mp2)):
            L.martello_subset_map_free(ctypes.byref(p))
            s.free()


L.martello_model_clusters.restype = ctypes.c_int
L.martello_model_clusters.argtypes = [VP, IP, IP, IP]


def clusters(model_h, n, joined):
    label, k = np.zeros(n, dtype=np.int32), ctypes.c_int()
    j = None if joined is None else np.ascontiguousarray(joined, dtype=np.int32)
    st = L.martello_model_clusters(model_h, None if j is None else j.ctypes.data_as(IP),
                                   label.ctypes.data_as(IP), ctypes.byref(k))
    return st, label, k.value


def components_by_search(n, fixed, rows):
    """Connected components of the free nodes by breadth-first search over the rows (lists of
    nodes) -- another algorithm than the library's union-find -- numbered in the order of their
    first node, -1 for a fixed node."""
    adj = [[] for _ in range(n)]
    for row in rows:
        free = [i for i in row if not fixed[i]]
        for a, b in zip(free, free[1:]):
            adj[a].append(b); adj[b].append(a)
    label, k = [-1] * n, 0
    for s in range(n):
        if fixed[s] or label[s] >= 0:
            continue
        label[s], todo = k, [s]
        while todo:
            i = todo.pop()
            for j in adj[i]:
                if label[j] < 0:
                    label[j] = k; todo.append(j)
        k += 1
    return label, k


def test_clusters_are_the_components_of_links_couplings_blocks_and_closed_contacts():
    """Identity of the method (union-find against a breadth-first search over the same rows):
    the clusters are the free nodes joined by links (the fluid damper between nodes 2 and 3),
    the mass coupling (4, 5), the stiffness block (7, 8, 9) and the contacts marked closed; the
    walls (fixed) join nothing. Each cluster's sub-model at a state where exactly those contacts
    are closed gives the parent's rows bit for bit: the driver's use of the two doors."""
    with row_scene(couplings=[(4, 5, 30.0)], block=(7, 8, 9)) as m:
        n = m.n_nodes
        fixed = [i in (0, n - 1) for i in range(n)]
        closed = (0, 5, 10)             # wall-1, 5-6, 10-wall
        joined = np.isin(np.arange(n - 1), closed).astype(np.int32)
        st, label, k = clusters(m.handle, n, joined)
        assert st == 0, message(m.handle)
        rows = [[2, 3], [4, 5], [7, 8, 9]] + [[i, i + 1] for i in closed]
        want, kw = components_by_search(n, fixed, rows)
        assert_same(label, want, "labels")
        assert k == kw == 5
        # by hand: {1}, {2, 3}, {4, 5, 6}, {7, 8, 9}, {10}
        assert_same(label, [-1, 0, 1, 1, 2, 2, 2, 3, 3, 3, 4, -1], "labels by hand")
        st, none, k0 = clusters(m.handle, n, None)
        # no contact closed: {1}, {2, 3}, {4, 5}, {6}, {7, 8, 9}, {10}
        assert st == 0 and k0 == 6
        assert_same(none, [-1, 0, 1, 1, 2, 2, 3, 4, 4, 4, 5, -1], "labels, no contact closed")
        cut = [i for i in range(n - 1) if i not in closed]
        u, v = state(n, 4, closed=closed, opened=cut)
        assert_open(u, cut)
        pe = Eval(m.handle)
        a = pe.acceleration(0.1, u, v)
        for c in range(k):
            st, sub, mp = subset(m.handle, np.flatnonzero(label == c))
            assert st == 0, message(m.handle)
            node = mp.arrays()[0]
            se = Eval(sub.h)
            free = label[node] == c
            assert_same(se.acceleration(0.1, u[node], v[node])[free], a[node][free], "a")
            se.free()
            L.martello_subset_map_free(ctypes.byref(mp))
            sub.free()
        pe.free()
