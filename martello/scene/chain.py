"""[[chain]] tables: n oscillators in a row (docs/problems.md P7), validated as whole arrays
and kept as arrays: a ``ChainBlock`` per table, never a Python dict per node, link or contact.

``ChainBlock`` is the one place the layout is written down: per oscillator i (0-based) the
node ``<prefix><i+1>`` (mass, u0, v0), its spring to ground (k; bilinear with fy and
hardening), its dashpot to ground where ζ_i > 0 (c_i = 2ζ_i√(k_g m_i), filled in by the
loader once every link is known), and for i < n − 1 the contact with its right neighbour
(gap_i and the chain's one contact table). The links come in the order spring_0, damper_0,
spring_1, ... (a damper only where ζ_i > 0), the order the per-item expansion made, so the
model, its summation order and the physics digest of a scene are what they were. The block
is what the run layer hands to the library's bulk doors, in chunks (martello.run); a door
that takes a chain as per-node arrays would take these arrays as they are.

The three segments (``ChainNodes``, ``ChainLinks``, ``ChainContacts``) give the scene's item
tables (martello.scene.items) the block's items as dicts on demand, equal to those the loader
made from the expanded tables."""

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from ..errors import SceneError
from .fields import MAX_GENERATED, check_fields, kind_ok
from .items import Alternating, Neighbours, Numbered

# [[chain]]: scalars apply to every oscillator, lists give one value each (n for
# oscillators, n − 1 for gaps).
CHAIN_KEYS = {"prefix": ("str", True, None, None), "n": ("int", True, (lambda x: x > 0, "a number > 0"), None),
              "mass": ("any", True, None, None), "k": ("any", True, None, None),
              "fy": ("any", False, None, None), "hardening": ("any", False, None, None),
              "zeta": ("any", False, None, None), "gap": ("any", False, None, 0.0),
              "u0": ("any", False, None, None), "v0": ("any", False, None, None),
              "contact": ("table", False, None, None)}

# The valid values of the per-item keys, as array predicates and in words (the words of
# martello.scene.fields' scalar checks, so the messages are the loader's).
POSITIVE = (lambda x: x > 0, "a number > 0")
HARDENING = (lambda x: (x >= 0) & (x < 1), "a number in [0, 1)")
ZETA = (lambda x: (x >= 0) & (x < 10), "a number in [0, 10)")


def per_item_array(src, where, value, count, check=None):
    """A scalar for all (a broadcast view, no copy) or a list of exactly `count` numbers, as
    float64; the first bad entry is named as martello.scene.fields.per_item names it."""
    if not isinstance(value, list):
        if not kind_ok("float", value):
            raise SceneError(src, where, f"has the wrong type ({type(value).__name__})", "expected float")
        if check is not None and not check[0](np.float64(value)):
            raise SceneError(src, where, f"invalid value {value!r}", f"must be {check[1]}")
        return np.broadcast_to(np.float64(value), (count,))
    if len(value) != count:
        raise SceneError(src, where, f"has {len(value)} values", f"give one number or a list of {count}")
    bad = count                           # first entry of the wrong type
    if not set(map(type, value)) <= {float, int}:
        bad = next((i for i, v in enumerate(value) if not kind_ok("float", v)), count)
    x = np.array([float(v) for v in value[:bad]], np.float64) if bad < count else \
        np.array(value, np.float64)
    if check is not None:
        wrong = np.flatnonzero(~check[0](x))
        if len(wrong) and wrong[0] < bad:
            i = int(wrong[0])
            raise SceneError(src, f"{where}[{i}]", f"invalid value {value[i]!r}", f"must be {check[1]}")
    if bad < count:
        raise SceneError(src, f"{where}[{bad}]", f"has the wrong type ({type(value[bad]).__name__})",
                         "expected float")
    return x


@dataclass
class ChainBlock:
    """One [[chain]] as arrays (module docstring). Scalars of the table are broadcast views."""
    prefix: str
    n: int
    mass: np.ndarray
    k: np.ndarray
    fy: np.ndarray | None           # None: linear springs
    hardening: np.ndarray
    zeta: np.ndarray | None         # None: no dampers
    gap: np.ndarray                 # n − 1 values
    u0: np.ndarray
    v0: np.ndarray
    contact: dict | None            # the chain's contact table as given (None: no contacts)
    where: str                      # "chain[i]", for messages
    template: dict | None = None    # the contact's validated fields (set by the loader)
    c: np.ndarray | None = None     # dashpot coefficients of the dampers (set by the loader)
    node0: int = 0                  # positions of its first node, link and contact in the scene
    link0: int = 0
    contact0: int = 0
    dampers: np.ndarray = field(init=False)    # oscillators with a damper (ζ_i > 0)

    def __post_init__(self):
        self.dampers = (np.flatnonzero(self.zeta > 0) if self.zeta is not None
                        else np.zeros(0, np.int64))

    @property
    def n_links(self):
        return self.n + len(self.dampers)

    @property
    def n_contacts(self):
        return self.n - 1 if self.contact is not None else 0

    def node_names(self):
        return Numbered(self.prefix, "", 1, self.n)

    def link_names(self):
        second = np.zeros(self.n, bool)
        second[self.dampers] = True
        return Alternating(self.prefix, "spring", "damper", 1, second)

    def contact_names(self):
        return Neighbours(self.prefix, 1, self.n_contacts)

    def link_positions(self):
        """(spring, damper) positions of each oscillator's links within the block's links:
        the spring of oscillator i at i plus the dampers before it, its damper right after."""
        before = np.zeros(self.n, np.int64)
        if len(self.dampers):
            has = np.zeros(self.n, np.int64)
            has[self.dampers] = 1
            before[1:] = np.cumsum(has[:-1])
        spring = np.arange(self.n) + before
        return spring, spring[self.dampers] + 1


def expand_chains(src, data, made=0):
    """The scene dict without its [[chain]] tables, and a ChainBlock for each (validated: a
    chain error names the chain's field, as it always has)."""
    data = dict(data)
    chains = data.pop("chain")
    if not isinstance(chains, list):
        raise SceneError(src, "chain", "must be an array of tables", "write [[chain]]")
    blocks = []
    for ci, tab in enumerate(chains):
        w = f"chain[{ci}]"
        ch = check_fields(src, tab, w, CHAIN_KEYS)
        n, p = ch["n"], ch["prefix"]
        made += n
        if made > MAX_GENERATED:
            raise SceneError(src, f"{w}.n", f"invalid value {n!r}",
                             f"the generators of a scene make at most {MAX_GENERATED} nodes in all")
        mass = per_item_array(src, f"{w}.mass", ch["mass"], n, POSITIVE)
        k = per_item_array(src, f"{w}.k", ch["k"], n, POSITIVE)
        fy = per_item_array(src, f"{w}.fy", ch["fy"], n, POSITIVE) if ch["fy"] is not None else None
        rho = per_item_array(src, f"{w}.hardening", ch["hardening"] or 0.0, n, HARDENING)
        zeta = per_item_array(src, f"{w}.zeta", ch["zeta"], n, ZETA) if ch["zeta"] is not None else None
        gap = per_item_array(src, f"{w}.gap", ch["gap"], n - 1) if n > 1 else np.zeros(0)
        u0 = per_item_array(src, f"{w}.u0", ch["u0"], n) if ch["u0"] is not None else \
            np.broadcast_to(np.float64(0.0), (n,))
        v0 = per_item_array(src, f"{w}.v0", ch["v0"], n) if ch["v0"] is not None else \
            np.broadcast_to(np.float64(0.0), (n,))
        if ch["fy"] is None and ch["hardening"] is not None:
            raise SceneError(src, f"{w}.hardening", "given without fy", "give fy (yield force) for a bilinear spring")
        if n == 1 and (ch["contact"] is not None or tab.get("gap") is not None):
            raise SceneError(src, f"{w}.contact" if ch["contact"] is not None else f"{w}.gap",
                             "a chain of one oscillator has no neighbour contact", "remove it or set n > 1")
        for key in ("name", "a", "b", "gap"):
            if ch["contact"] is not None and key in ch["contact"]:
                raise SceneError(src, f"{w}.contact.{key}", "is generated by the chain",
                                 "remove it (set gaps with the chain's own gap key)")
        blocks.append(ChainBlock(prefix=p, n=n, mass=mass, k=k, fy=fy, hardening=rho, zeta=zeta,
                                 gap=gap, u0=u0, v0=v0,
                                 contact=ch["contact"] if n > 1 else None, where=w))
    return data, blocks


class ChainNodes:
    """A chain's nodes as a segment of the scene's node table."""

    def __init__(self, block):
        self.block = block

    def __len__(self):
        return self.block.n

    def place(self, pos):
        self.block.node0 = pos

    def names(self):
        return [self.block.node_names()]

    def item(self, i):
        b = self.block
        return {"name": f"{b.prefix}{i + 1}", "mass": float(b.mass[i]), "u0": float(b.u0[i]),
                "v0": float(b.v0[i]), "fixed": False}


class ChainLinks:
    """A chain's springs and dampers as a segment of the scene's link table."""

    def __init__(self, block):
        self.block = block

    @cached_property
    def positions(self):
        return self.block.link_positions()

    @property
    def spring(self):
        """Position of each oscillator's spring among the chain's links."""
        return self.positions[0]

    @property
    def damper(self):
        """Position of each damper among the chain's links."""
        return self.positions[1]

    def __len__(self):
        return self.block.n_links

    def place(self, pos):
        self.block.link0 = pos

    def names(self):
        return [self.block.link_names()]

    def item(self, j):
        b = self.block
        i = int(self.spring.searchsorted(j, side="right")) - 1
        name, node = f"{b.prefix}{i + 1}", b.node0 + i
        if j != self.spring[i]:
            d = int(np.searchsorted(b.dampers, i))
            return {"name": f"{name}.damper", "type": "dashpot", "a": node, "b": -1,
                    "c": float(b.c[d]), "zeta": float(b.zeta[i])}
        if b.fy is None:
            return {"name": f"{name}.spring", "type": "spring", "a": node, "b": -1, "k": float(b.k[i])}
        return {"name": f"{name}.spring", "type": "bilinear", "a": node, "b": -1, "k": float(b.k[i]),
                "fy": float(b.fy[i]), "hardening": float(b.hardening[i])}


class ChainContacts:
    """A chain's neighbour contacts as a segment of the scene's contact table."""

    def __init__(self, block):
        self.block = block

    def __len__(self):
        return self.block.n_contacts

    def item(self, j):
        b = self.block
        c = dict(b.template)
        c.update(name=f"{b.prefix}{j + 1}-{b.prefix}{j + 2}", a=b.node0 + j, b=b.node0 + j + 1,
                 gap=float(b.gap[j]))
        return c
