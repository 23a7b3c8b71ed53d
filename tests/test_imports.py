"""The package's structure: every module imports on its own, in a fresh interpreter, and the
imports between the package's modules form no cycle (read from the source with ast, imports
inside functions included). Also the layering the package is cut by: the oracles know no
solver, the run layer knows no oracle, and only the binding touches ctypes."""

import ast
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "martello"


def module_name(path):
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


FILES = {module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}
# martello.__main__ runs the command line only as a script (python -m martello), so it
# imports like any other module.
MODULES = sorted(FILES)


def imports_of(name):
    """The package's modules that module `name` imports, anywhere in its source."""
    path = FILES[name]
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - (node.level - 1)]
                base = ".".join(base + ([node.module] if node.module else []))
            else:
                base = node.module or ""
            # `from X import y` imports the module X.y if there is one, else names of X
            targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in FILES else base
                       for a in node.names]
        else:
            continue
        for t in targets:
            while t and t not in FILES:          # import a.b.c of a module a.b? not here
                t = t.rpartition(".")[0]
            if t.startswith("martello") and t != name:
                found.add(t)
    return found


def find_cycle(graph):
    """A cycle of the directed graph {node: successors} as a list of nodes, or None."""
    state, stack = {}, []

    def visit(n):
        state[n] = "open"
        stack.append(n)
        for m in sorted(graph.get(n, ())):
            if state.get(m) == "open":
                return stack[stack.index(m):] + [m]
            if m not in state:
                cycle = visit(m)
                if cycle:
                    return cycle
        stack.pop()
        state[n] = "done"
        return None

    for n in sorted(graph):
        if n not in state:
            cycle = visit(n)
            if cycle:
                return cycle
    return None


@pytest.mark.parametrize("module", MODULES)
def test_every_module_imports_on_its_own(module):
    r = subprocess.run([sys.executable, "-c", f"import {module}"], cwd=ROOT,
                       capture_output=True, text=True)
    assert r.returncode == 0, f"import {module} fails in a fresh interpreter:\n{r.stderr}"


def test_the_import_graph_has_no_cycle():
    graph = {m: imports_of(m) for m in FILES}
    cycle = find_cycle(graph)
    assert cycle is None, "import cycle: " + " -> ".join(cycle)


def test_the_cycle_finder_finds_a_cycle():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": set(), "c": {"a", "b"}}) is None


# The layers of the package (martello/__init__.py), bottom up: a module imports modules of
# its own unit (subpackage or top-level module) or of a lower layer, never of a higher one.
# The package's own __init__ ("martello") is its face: it gives the API's names lazily
# (PEP 562), so it sits on top; test_import_martello_loads_nothing_else keeps it cheap.
LAYERS = [("martello.errors", "martello.paths", "martello.history", "martello.independent",
           "martello.modes"),
          ("martello.binding", "martello.oracles"), ("martello.closed_forms", "martello.frame2d", "martello.building3d"),
          ("martello.scene", "martello.ground_motion"), ("martello.results",),
          ("martello.run",), ("martello.batch",),
          ("martello.metrics",), ("martello.reference",),
          ("martello.checks",),
          ("martello.study", "martello.compare", "martello.report", "martello.export",
           "martello.testset"),
          ("martello.plot",), ("martello.api",), ("martello.cli",), ("martello.__main__", "martello")]


def unit(module):
    """The top-level module or subpackage a module belongs to."""
    return ".".join(module.split(".")[:2])


RANK = {u: i for i, layer in enumerate(LAYERS) for u in layer}


def test_every_module_has_a_layer():
    assert sorted({unit(m) for m in FILES} - set(RANK)) == []


def test_each_layer_imports_only_the_layers_below():
    upward = [f"{m} -> {t}" for m in FILES for t in imports_of(m)
              if unit(t) != unit(m) and RANK[unit(t)] >= RANK[unit(m)]]
    assert not upward, "imports against the layering:\n" + "\n".join(sorted(upward))


def loaded_after(module):
    """The package's modules loaded in a fresh interpreter by `import module`."""
    r = subprocess.run([sys.executable, "-c", f"import sys, {module}; "
                        "print(' '.join(m for m in sys.modules if m.startswith('martello')))"],
                       cwd=ROOT, capture_output=True, text=True, check=True)
    return set(r.stdout.split())


def test_import_martello_loads_nothing_else():
    # `import martello` is cheap: the API's names load on first use (martello/__init__.py)
    r = subprocess.run([sys.executable, "-c", "import sys, martello; print(' '.join(sorted("
                        "m for m in sys.modules if m.startswith(('martello', 'numpy', 'scipy', "
                        "'ctypes')))))"], cwd=ROOT, capture_output=True, text=True, check=True)
    assert r.stdout.split() == ["martello"]


def test_a_plain_run_loads_no_heavy_package():
    # `martello run` on a scene without a ground-motion record: what its command imports, and
    # nothing of scipy, matplotlib or pandas (their imports alone cost more than a small run;
    # docs/performance.md)
    r = subprocess.run([sys.executable, "-c", "import sys, martello.cli, martello.run, "
                        "martello.checks.measures; print(' '.join(sys.modules))"],
                       cwd=ROOT, capture_output=True, text=True, check=True)
    loaded = set(r.stdout.split())
    heavy = {m for m in loaded if m.partition(".")[0] in ("scipy", "matplotlib", "pandas")}
    assert not heavy and "martello.ground_motion" not in loaded, sorted(heavy)


def test_oracles_know_no_solver():
    # the closed forms are written from the mathematics: no run layer, no native library
    for m in (m for m in MODULES if m.startswith("martello.oracles")):
        bad = {x for x in loaded_after(m)
               if x == "martello.run" or x.startswith("martello.binding")}
        assert not bad, f"{m} loads {sorted(bad)}"


def test_the_independent_engine_is_a_leaf():
    # the independent reference shares no code with what it checks (docs/independent-reference.md):
    # no other martello module, and outside the standard library numpy and scipy only
    for m in (m for m in MODULES if m.startswith("martello.independent")):
        other = {x for x in loaded_after(m) if not x.startswith("martello.independent") and x != "martello"}
        assert not other, f"{m} loads {sorted(other)}"
        ext = external_imports(m) - set(sys.stdlib_module_names) - {"numpy", "scipy", "__future__"}
        assert not ext, f"{m} imports {sorted(ext)}"


def test_the_run_layer_knows_no_oracle():
    # a run computes what the solver gives; oracles and measures come in at the check layer
    bad = {x for x in loaded_after("martello.run")
           if x.startswith(("martello.oracles", "martello.checks", "martello.reference"))}
    assert not bad, f"martello.run loads {sorted(bad)}"


def external_imports(name):
    """Top-level names of the absolute imports of module `name` (numpy, ctypes, ...)."""
    out = set()
    for node in ast.walk(ast.parse(FILES[name].read_text())):
        if isinstance(node, ast.Import):
            out.update(a.name.partition(".")[0] for a in node.names)
        elif isinstance(node, ast.ImportFrom) and not node.level:
            out.add(node.module.partition(".")[0])
    return out


def test_only_the_binding_calls_ctypes():
    users = sorted(m for m in FILES if "ctypes" in external_imports(m))
    assert users and all(m.startswith("martello.binding.") for m in users), users
