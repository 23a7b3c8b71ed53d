"""Per-item results (nodes, links, contacts) as arrays: what a large scene writes to
results.npz beside a small summary.json (docs/results.md, "Results as arrays").

The run layer (martello.run) builds an ``ItemArrays`` from the library's result arrays, column
by column, for every dynamic run: a small scene's summary entries are made from it item by
item, a large scene's (more than ``ARRAY_ITEMS`` nodes, links and contacts together) are kept
as the arrays and written as results.npz, numpy's own format: exact doubles, written and read
at the speed of the disk, no new dependency, and each array loads alone.

An ``ItemArrays`` is a dict, the JSON-ready description summary.json holds under
``"arrays"`` (file, and per kind: count, the rule of its names, its columns and the names of
its categories); its arrays travel with it as attributes. ``read_summary(folder)`` gives back
the summary of a run folder with its ``"arrays"`` holding the arrays again (loaded when first
used), and ``lookup`` finds ``nodes.<name>.u_max`` in either form.

A column holds float64 (or int64 counts, or int8 category codes). NaN means "does not exist"
where the JSON form has no key or null: a node's ``u_peak``/``t_peak`` without a local
maximum, a link value the integrator does not report, the first/last phase of a contact that
never closed (and the separation of a phase still open). Every other value is finite: the
writer refuses anything else, naming the item, and writes nothing."""

import json
from pathlib import Path

import numpy as np

from .errors import ResultError
from .scene.chain import Names      # with the chain's name rules known (Names.from_spec)
from .scene.spec import ARRAY_ITEMS

ARRAYS_FILE = "results.npz"

KINDS = ("nodes", "links", "contacts")
# The fields of a contact's first and last phase (docs/results.md, "Contacts").
PHASE_FIELDS = ("impact_time", "separation_time", "approach_speed", "separation_speed",
                "max_penetration", "max_force")
# Where NaN is allowed: column -> the column whose NaN marks the item that has no value (the
# two may then be NaN only together), or True (NaN anywhere: null in JSON). Columns not
# named here are finite everywhere.
ABSENT = {"nodes": {"u_peak": "t_peak", "t_peak": "t_peak"},
          "links": {"max_abs_force": True, "max_abs_elongation": True},
          "contacts": {f"{p}.{f}": (True if f.startswith("separation") else f"{p}.impact_time")
                       for p in ("first", "last") for f in PHASE_FIELDS}}


def is_large(scene):
    return len(scene.nodes) + len(scene.links) + len(scene.contacts) > ARRAY_ITEMS


class ItemArrays(dict):
    """The per-item results of one run (module docstring). ``names[kind]`` are
    martello.scene.items.Names; ``columns[kind]`` maps a column to its array, or to a function
    that makes it (a large column is then made only while it is written); ``categories[kind]``
    maps a category column to the names its codes index (code −1: none, null in JSON)."""

    def __init__(self, names, columns, categories, npz=None):
        self.names, self.columns, self.categories, self.npz = names, columns, categories, npz
        self.extra = {}                       # arrays the name rules need (Names.spec)
        super().__init__({"file": ARRAYS_FILE} | {
            kind: {"count": len(names[kind]), "names": names[kind].spec(self.extra),
                   "columns": list(columns[kind]), "categories": categories.get(kind, {})}
            for kind in KINDS})

    def column(self, kind, name):
        c = self.columns[kind][name]
        return c() if callable(c) else c

    def table(self, kind):
        """{"name": Names, column: array, ...} of one kind (category columns as their codes)."""
        return {"name": self.names[kind]} | {c: self.column(kind, c) for c in self.columns[kind]}

    def entries(self, kind, index):
        """{name: the entry summary.json has for it} of the items at `index` (positions),
        built column by column (docs/results.md)."""
        index = np.asarray(index, np.int64)
        names = [self.names[kind][i] for i in index.tolist()]
        cols, phases = {}, {}
        for c in self.columns[kind]:
            values = self.column(kind, c)[index]
            if c in self.categories.get(kind, {}):
                cats = self.categories[kind][c]
                cols[c] = [cats[v] if v >= 0 else None for v in values.tolist()]
            elif "." in c:                                   # first.impact_time, ...
                phases.setdefault(c.partition(".")[0], {})[c.partition(".")[2]] = values.tolist()
            else:
                cols[c] = values.tolist()
        absent = ABSENT.get(kind, {})
        # NaN where a value may be absent: no key (its presence column NaN) or null;
        # elsewhere NaN stays, for the finite check to refuse
        rules = {c: absent.get(c) for c in cols}
        rules_phase = {k: absent.get(f"first.{k}") for k in PHASE_FIELDS}
        out = {}
        for j, nm in enumerate(names):
            e = {}
            for c, v in cols.items():
                x, rule = v[j], rules[c]
                if x != x and rule is not None:
                    if rule is True:
                        e[c] = None
                        continue
                    there = cols[rule][j]
                    if there != there:
                        continue
                e[c] = x
            for p, f in phases.items():
                on = f["impact_time"][j]
                e[f"{p}_phase"] = None if on != on else {
                    k: (None if f[k][j] != f[k][j] and rules_phase[k] is True else f[k][j])
                    for k in PHASE_FIELDS}
            out[nm] = e
        return out

    def item(self, kind, name):
        """The entry of one item by name (KeyError if there is none)."""
        i = self.names[kind].position(name)
        if i < 0:
            raise KeyError(name)
        return next(iter(self.entries(kind, [i]).values()))

    def check_finite(self):
        """ResultError naming the first item whose value is not finite where it must be."""
        for kind in KINDS:
            absent = ABSENT.get(kind, {})
            for c in self.columns[kind]:
                x = self.column(kind, c)
                if x.dtype.kind != "f":
                    continue
                rule = absent.get(c)
                if rule is True:
                    bad = np.isinf(x)
                elif rule is not None:
                    bad = ~np.isfinite(x) & ~np.isnan(self.column(kind, rule))
                else:
                    bad = ~np.isfinite(x)
                if bad.any():
                    i = int(np.flatnonzero(bad)[0])
                    raise ResultError(f"the run's result {kind}.{self.names[kind][i]}.{c} is "
                                      f"{x[i]}: a result must be finite (nothing written)")

    def write(self, folder):
        """results.npz into folder, one array at a time (a column made by a function exists
        only while it is written); the caller checked them (check_finite)."""
        import zipfile                      # only a large scene's run writes one
        with zipfile.ZipFile(Path(folder) / ARRAYS_FILE, "w", zipfile.ZIP_STORED,
                             allowZip64=True) as zf:
            for key, value in self.extra.items():
                _put(zf, key, value)
            for kind in KINDS:
                for c in self.columns[kind]:
                    _put(zf, f"{kind}.{c}", self.column(kind, c))

    @classmethod
    def read(cls, description, folder):
        """The ItemArrays a summary.json describes, its arrays read from folder when used."""
        import zipfile
        path = Path(folder) / description.get("file", ARRAYS_FILE)
        try:
            npz = np.load(path, allow_pickle=False)
        except (OSError, ValueError, zipfile.BadZipFile) as exc:
            raise ResultError(f"{path}: cannot be read ({exc}): the run folder is incomplete "
                              "(run the scene again)") from None
        names = {kind: Names.from_spec(description[kind]["names"], npz) for kind in KINDS}
        columns = {kind: {c: (lambda key=f"{kind}.{c}": npz[key]) for c in description[kind]["columns"]}
                   for kind in KINDS}
        categories = {kind: description[kind].get("categories", {}) for kind in KINDS}
        return cls(names, columns, categories, npz)


def _put(zf, key, value):
    """One array into an open .npz (what numpy.savez does per array)."""
    with zf.open(key + ".npy", "w", force_zip64=True) as fh:
        np.lib.format.write_array(fh, np.ascontiguousarray(value), allow_pickle=False)


def read_summary(folder):
    """summary.json of a run folder, with its "arrays" (a large scene's) readable again."""
    folder = Path(folder)
    summary = json.loads((folder / "summary.json").read_text())
    if isinstance(summary.get("arrays"), dict):
        summary["arrays"] = ItemArrays.read(summary["arrays"], folder)
    return summary


def lookup_item(summary, kind, name):
    """The entry of one node, link or contact, from summary[kind] or, for a large scene, its
    arrays; KeyError if the run has none of that name."""
    entries = summary.get(kind) or {}
    if name in entries:
        return entries[name]
    arrays = summary.get("arrays")
    if isinstance(arrays, ItemArrays):
        return arrays.item(kind, name)
    raise KeyError(name)
