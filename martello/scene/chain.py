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

from ..binding import native
from ..binding.native import constant
from ..errors import SceneError
from .fields import MAX_GENERATED, check_fields, kind_ok
from .items import Names, Numbered, Rule, _number, key_for  # noqa: F401 (Names: for results)

class Alternating(Rule):
    """``<prefix><i>.<a>`` for every i of first ... first + count - 1, each followed by
    ``<prefix><i>.<b>`` where second[i] is true: a chain's springs and dampers, in the
    order the chain makes them."""
    KEY = "alternate"

    def __init__(self, prefix, a, b, first, second):
        self.prefix, self.a, self.b, self.first = prefix, a, b, first
        self.second = np.asarray(second, bool)
        self.count = len(self.second) + int(self.second.sum())

    @cached_property
    def start(self):
        """Position of item i's first name: i plus the second names before it (made when a
        name is first asked for by position or found)."""
        return np.arange(len(self.second)) + np.concatenate(
            ([0], np.cumsum(self.second[:-1]))).astype(np.int64)

    def __len__(self):
        return self.count

    def name(self, j):
        if not 0 <= j < self.count:
            raise IndexError(j)
        i = int(self.start.searchsorted(j, side="right")) - 1
        return f"{self.prefix}{self.first + i}.{self.a if j == self.start[i] else self.b}"

    def find(self, name):
        if not isinstance(name, str) or not name.startswith(self.prefix):
            return -1
        head, dot, tail = name[len(self.prefix):].partition(".")
        k = _number(head)
        if not dot or k is None or tail not in (self.a, self.b):
            return -1
        i = k - self.first
        if not 0 <= i < len(self.second) or (tail == self.b and not self.second[i]):
            return -1
        return int(self.start[i]) + (tail == self.b)

    def literal(self):
        return self.prefix, ""

    def spec(self, arrays):
        key = key_for(arrays)
        arrays[key] = self.second
        return {"prefix": self.prefix, "first": self.first, "alternate": [self.a, self.b],
                "second": key}

    @classmethod
    def from_spec(cls, s, arrays):
        return cls(s["prefix"], *s["alternate"], s["first"], arrays[s["second"]])


class Neighbours(Rule):
    """``<prefix><i>-<prefix><i+1>`` for i = first ... first + count - 1: a chain's contacts."""
    KEY = "neighbours"

    def __init__(self, prefix, first, count):
        self.prefix, self.first, self.count = prefix, first, count

    def __len__(self):
        return self.count

    def name(self, j):
        if not 0 <= j < self.count:
            raise IndexError(j)
        i = self.first + j
        return f"{self.prefix}{i}-{self.prefix}{i + 1}"

    def find(self, name):
        if not isinstance(name, str) or not name.startswith(self.prefix):
            return -1
        rest = name[len(self.prefix):]
        head = rest.split("-", 1)[0]
        k = _number(head)
        if k is None or rest != f"{k}-{self.prefix}{k + 1}":
            return -1
        j = k - self.first
        return j if 0 <= j < self.count else -1

    def literal(self):
        return self.prefix, ""

    def spec(self, arrays):
        return {"prefix": self.prefix, "first": self.first, "neighbours": self.count}

    @classmethod
    def from_spec(cls, s, arrays):
        return cls(s["prefix"], s["first"], s["neighbours"])


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
        # int32: a million oscillators keep 4 MB of it through the run, not 8
        self.dampers = (np.flatnonzero(self.zeta > 0).astype(np.int32) if self.zeta is not None
                        else np.zeros(0, np.int32))

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

    def arrays(self):
        """(mass, u0, v0, fixed) of its nodes, for the run layer."""
        b = self.block
        return b.mass, b.u0, b.v0, np.zeros(b.n, np.int32)


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

    def chunks(self, size):
        """(kind, a, b, par) arrays of its links for the library's bulk door, size oscillators
        (and their dampers) at a time, in the order of the links."""
        b = self.block
        spring, damper = self.spring, self.damper
        kind_spring = native.value("links", "spring" if b.fy is None else "bilinear")
        for i0 in range(0, b.n, size):
            i1 = min(i0 + size, b.n)
            d0, d1 = np.searchsorted(b.dampers, (i0, i1))
            at = spring[i0]
            s, d = spring[i0:i1] - at, damper[d0:d1] - at
            m = (i1 - i0) + (d1 - d0)
            kind = np.empty(m, np.int32)
            a = np.empty(m, np.int32)
            par = np.zeros((m, constant("NPAR_LINK")))
            kind[s] = kind_spring
            a[s] = b.node0 + np.arange(i0, i1)
            par[s, constant("L_STIFF")] = b.k[i0:i1]
            if b.fy is not None:
                par[s, constant("L_YIELD")] = b.fy[i0:i1]
                par[s, constant("L_HARDENING")] = b.hardening[i0:i1]
            kind[d] = native.value("links", "dashpot")
            a[d] = b.node0 + b.dampers[d0:d1]
            par[d, constant("L_DAMP")] = b.c[d0:d1]
            yield kind, a, np.full(m, -1, np.int32), par

    def codes(self, key, at):
        """Its links' codes in a category column (at: category -> code): the springs', then
        the dampers' where it has them, for "type"."""
        b = self.block
        codes = np.full(len(self), -1, np.int8)
        if key == "type":
            codes[:] = at["spring" if b.fy is None else "bilinear"]
            codes[self.damper] = at["dashpot"]
        return codes


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

    @property
    def template(self):
        """The validated fields every contact of the chain shares (its parameters' one row)."""
        return self.block.template

    def chunks(self, size):
        """(a, b, gap) arrays of its contacts for the library's bulk door, size at a time."""
        b = self.block
        for j0 in range(0, len(self), size):
            j1 = min(j0 + size, len(self))
            a = (b.node0 + np.arange(j0, j1)).astype(np.int32)
            yield a, a + 1, b.gap[j0:j1]

    def codes(self, key, at):
        """Its contacts' codes in a category column: the template's for all."""
        return np.full(len(self), at.get(self.block.template.get(key), -1), np.int8)
