"""The item tables of a scene (nodes, links, contacts) stored by segment, so that a generator's
items are arrays, never one Python dict each (docs/scene-input.md, "Generators"). A scene with
no generator has one listed segment per table: lists of dicts.

A table is a sequence of segments in the order of the expanded scene: a *listed* segment holds
validated dicts (the items written in the file, and those of the small generators), a
*generated* one (a [[chain]]'s nodes, links or contacts: martello.scene.chain; a rod's:
martello.scene.bars) holds arrays and gives an item's dict only when asked, and its arrays to
the run layer (``arrays()`` of nodes, ``chunks(size)`` of links and contacts, ``codes(key,
at)`` of a category column): the run layer knows no generator. Everything else may go on
treating the table as a list of dicts (``len``, indexing, iteration), which for a generated
item builds the dict the loader used to make. Such a dict is a copy: changing it does not
change the scene.

Names are stored the same way (``Names``): a listed segment keeps its strings, a generated one
its rule (``<prefix><i>`` here; a chain's ``<prefix><i>.spring`` and ``<prefix><i>-<prefix><i+1>``
in martello.scene.chain), which finds an index from a name by parsing it. ``Names.spec()``
writes the rules as JSON-ready data and ``Names.from_spec`` reads them back, each rule from the
key that marks its spec (``Rule.KEY``): that is how results.npz names its rows without a string
per item (docs/results.md)."""

from bisect import bisect_right
from collections.abc import Mapping, Sequence


def key_for(arrays):
    """A new key for an array a name rule needs."""
    return f"names.{sum(k.startswith('names.') for k in arrays)}"


def _number(text):
    """The integer a canonical decimal (no sign, no leading zero) spells, else None."""
    if not text or not text.isascii() or not text.isdigit() or (text[0] == "0" and text != "0"):
        return None
    return int(text)


class Rule:
    """A kind of names segment; its spec (``spec``) is marked by the key KEY, from which
    ``Names.from_spec`` reads it back (``from_spec``). Every subclass is known by its KEY."""
    KEY = None
    KINDS = {}

    def __init_subclass__(cls, **kw):
        super().__init_subclass__(**kw)
        Rule.KINDS[cls.KEY] = cls


class Listed(Rule):
    """Names given one by one."""
    KEY = "names"

    def __init__(self, names=()):
        self.names = list(names)
        self.at = {}
        for i, nm in enumerate(self.names):
            self.at.setdefault(nm, i)

    def __len__(self):
        return len(self.names)

    def name(self, i):
        return self.names[i]

    def find(self, name):
        return self.at.get(name, -1)

    def append(self, name):
        self.at.setdefault(name, len(self.names))
        self.names.append(name)

    def literal(self):
        return None                       # any string: compared name by name

    def spec(self, arrays):
        return {"names": list(self.names)}

    @classmethod
    def from_spec(cls, s, arrays):
        return cls(s["names"])


class Numbered(Rule):
    """``<prefix><number><suffix>`` for numbers first, first + 1, ... (count of them), or for
    the increasing numbers of an array."""
    KEY = "prefix"              # the key every rule has: the fallback

    def __init__(self, prefix, suffix="", first=1, count=0, numbers=None):
        self.prefix, self.suffix, self.first = prefix, suffix, first
        self.numbers = numbers            # None: the range first ... first + count - 1
        self.count = count if numbers is None else len(numbers)

    def __len__(self):
        return self.count

    def number(self, i):
        return self.first + i if self.numbers is None else int(self.numbers[i])

    def name(self, i):
        if not 0 <= i < self.count:
            raise IndexError(i)
        return f"{self.prefix}{self.number(i)}{self.suffix}"

    def find(self, name):
        if not (isinstance(name, str) and name.startswith(self.prefix)
                and name.endswith(self.suffix)):
            return -1
        k = _number(name[len(self.prefix):len(name) - len(self.suffix)])
        if k is None:
            return -1
        if self.numbers is None:
            return k - self.first if self.first <= k < self.first + self.count else -1
        j = bisect_right(self.numbers, k) - 1     # numbers increase (a sorted array)
        return j if j >= 0 and self.numbers[j] == k else -1

    def literal(self):
        return self.prefix, self.suffix

    def spec(self, arrays):
        out = {"prefix": self.prefix, "suffix": self.suffix}
        if self.numbers is None:
            return out | {"first": self.first, "count": self.count}
        key = key_for(arrays)
        arrays[key] = self.numbers
        return out | {"numbers": key}

    @classmethod
    def from_spec(cls, s, arrays):
        if "numbers" in s:
            return cls(s["prefix"], s["suffix"], numbers=arrays[s["numbers"]])
        return cls(s["prefix"], s["suffix"], s["first"], s["count"])


def _comparable(x, y):
    return x.startswith(y) or y.startswith(x)


def _may_share(s, t):
    """Whether two rule segments could make a common name: only if the literal prefix of one
    starts the other's and likewise for the suffixes (a cheap test; a yes is checked name by
    name)."""
    ls, lt = s.literal(), t.literal()
    return _comparable(ls[0], lt[0]) and (_comparable(ls[1][::-1], lt[1][::-1]))


class _Segmented(Sequence):
    """A sequence kept as consecutive segments (``segments``, their first positions
    ``offsets``, ``size`` in all); ``_at(segment, j)`` gives the j-th entry of a segment."""

    def __len__(self):
        return self.size

    def _segment(self, i):
        k = bisect_right(self.offsets, i) - 1
        return self.segments[k], i - self.offsets[k]

    def __getitem__(self, i):
        if isinstance(i, slice):
            return [self[j] for j in range(*i.indices(self.size))]
        if i < 0:
            i += self.size
        if not 0 <= i < self.size:
            raise IndexError(i)
        return self._at(*self._segment(i))


class Names(_Segmented):
    """The names of one kind of item, segment by segment (module docstring)."""

    def __init__(self, segments=()):
        self.segments, self.offsets, self.size = [], [], 0
        self.listed = {}                  # every listed name -> its first position
        for seg in segments:
            self.extend(seg)

    @staticmethod
    def _at(seg, j):
        return seg.name(j)

    def __iter__(self):
        for seg in self.segments:
            for j in range(len(seg)):
                yield seg.name(j)

    def position(self, name):
        """The position of name, -1 if there is none (the first, should it repeat)."""
        at = self.listed.get(name)
        if at is not None:
            return at
        for seg, off in zip(self.segments, self.offsets):
            if not isinstance(seg, Listed):
                j = seg.find(name)
                if j >= 0:
                    return off + j
        return -1

    def __contains__(self, name):
        return self.position(name) >= 0

    def index(self, name, *args):
        i = self.position(name)
        if i < 0:
            raise ValueError(f"{name!r} is not a name here")
        return i

    def add(self, name):
        """Append one listed name; the position it had already, or -1 if it is new."""
        before = self.position(name)
        if not self.segments or not isinstance(self.segments[-1], Listed):
            self.offsets.append(self.size)
            self.segments.append(Listed())
        self.segments[-1].append(name)
        self.listed.setdefault(name, self.size)
        self.size += 1
        return before

    def extend(self, seg):
        """Append a segment; the index in it of its first name that is already here (-1 if
        none): the duplicate the loader reports."""
        if isinstance(seg, Listed):
            first = -1
            for j, nm in enumerate(seg.names):
                if self.add(nm) >= 0 and first < 0:
                    first = j
            return first
        first = len(seg)
        for nm, at in self.listed.items():      # listed names the rule would make
            j = seg.find(nm)
            if 0 <= j < first:
                first = j
        for other in self.segments:
            if not isinstance(other, Listed) and _may_share(seg, other):
                for j in range(first):
                    if other.find(seg.name(j)) >= 0:
                        first = j
                        break
        self.offsets.append(self.size)
        self.segments.append(seg)
        self.size += len(seg)
        return first if first < len(seg) else -1

    def spec(self, arrays):
        """JSON-ready rules; arrays they need go into `arrays` (key -> array)."""
        return [seg.spec(arrays) for seg in self.segments]

    @classmethod
    def from_spec(cls, spec, arrays):
        """Names from their spec (``spec``): each rule by the key that marks it, among the
        rules loaded (a generator's module registers its own: martello.scene.chain)."""
        segs = []
        for s in spec:
            kind = next((Rule.KINDS[k] for k in s if k in Rule.KINDS and k != Numbered.KEY),
                        Numbered)
            segs.append(kind.from_spec(s, arrays))
        return cls(segs)


class NameIndex(Mapping):
    """name -> position, over a Names (what Scene.index was as a dict)."""

    def __init__(self, names):
        self.names = names

    def __getitem__(self, name):
        i = self.names.position(name)
        if i < 0:
            raise KeyError(name)
        return i

    def __contains__(self, name):
        return self.names.position(name) >= 0

    def __iter__(self):
        return iter(self.names)

    def __len__(self):
        return len(self.names)


class ItemTable(_Segmented):
    """Items of one kind, segment by segment: a segment is a list of dicts (listed) or an
    object with ``__len__`` and ``item(j)`` (generated; martello.scene.chain)."""

    def __init__(self, segments, names):
        self.segments = [s for s in segments if len(s)]
        self.offsets, n = [], 0
        for s in self.segments:
            self.offsets.append(n)
            n += len(s)
        self.size, self.names = n, names

    @staticmethod
    def _at(s, j):
        return s[j] if isinstance(s, list) else s.item(j)

    def __iter__(self):
        for s in self.segments:
            if isinstance(s, list):
                yield from s
            else:
                for j in range(len(s)):
                    yield s.item(j)

    def __eq__(self, other):
        if isinstance(other, (ItemTable, list, tuple)):
            return len(self) == len(other) and all(a == b for a, b in zip(self, other))
        return NotImplemented

    def __repr__(self):
        return f"<{len(self)} items in {len(self.segments)} segments>"

    def generated(self):
        """Whether any segment is generated (stored as arrays)."""
        return any(not isinstance(s, list) for s in self.segments)
