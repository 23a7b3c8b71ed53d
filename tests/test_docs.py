"""The documentation cannot drift silently:

* every item of docs/behaviour.md names at least one test, and every named test exists;
  every test of tests/test_behaviour.py is named by an item;
* the registry tables of docs/ (tests/docs_tables.py) agree with what the code defines
  today, read from the source text (c/martello.h enums, the Fortran parameters and select
  cases, the Python tables of the loader and the binding), never by importing martello;
* the examples of docs/scene-input.md are the catalogue files, verbatim;
* every relative link between the pages, and its #anchor, exists;
* docs/problems.md keeps the section names code cites and the formulas code quotes."""

import ast
import importlib
import re
from pathlib import Path

import pytest

from tests.docs_tables import DOCS, ROOT, parse_table, registry_tables, read_table

REGISTRY = {"integrators", "schemes", "laws", "link-kinds", "compatibility",
            "integrator-parameters", "counters", "energy-terms", "history-columns",
            "status-codes", "families", "setting-types", "contact-parameters",
            "link-parameters", "time-functions", "events", "constants", "tracking", "methods"}


# --- reading the source text ---------------------------------------------------------------

def _text(paths):
    return "\n".join(p.read_text() for p in paths)


def c_constants():
    """Every `MARTELLO_X = value` of the C API header (enums)."""
    text = (ROOT / "c" / "martello.h").read_text()
    return {k: int(v) for k, v in re.findall(r"\b(MARTELLO_[A-Z0-9_]+)\s*=\s*(-?\d+)", text)}


def c_status_enum():
    text = (ROOT / "c" / "martello.h").read_text()
    body = re.search(r"enum\s+martello_status\s*\{(.*?)\}", text, re.S)
    assert body, "c/martello.h: enum martello_status not found"
    return [(k, int(v)) for k, v in re.findall(r"\b(MARTELLO_[A-Z_]+)\s*=\s*(-?\d+)", body[1])]


def fortran_text():
    return _text(sorted((ROOT / "fortran").rglob("*.f90")))


def fortran_parameters(pattern):
    """{NAME: int} of `integer, parameter :: ...` declarations whose names match pattern,
    over all Fortran sources (continuation lines included)."""
    text = re.sub(r"&\s*\n\s*", " ", fortran_text())
    out = {}
    for decl in re.findall(r"integer,\s*parameter\s*::(.*)", text):
        for name, value in re.findall(r"\b([A-Z][A-Z0-9_]*)\s*=\s*(-?\d+)\b", decl):
            if re.fullmatch(pattern, name):
                out[name] = int(value)
    return out


def python_namespace(*names):
    """The definitions of `names` in the martello package (each found by parsing the
    package's source for a module-level assignment, then taken from the imported module),
    and the source text of the modules that define them."""
    ns, texts = {}, []
    for path in sorted((ROOT / "martello").rglob("*.py")):
        tree = ast.parse(path.read_text())
        defined = {t.id for node in tree.body if isinstance(node, ast.Assign)
                   for t in node.targets if isinstance(t, ast.Name)} & set(names)
        if defined - set(ns):
            module = ".".join(path.relative_to(ROOT).with_suffix("").parts)
            mod = vars(importlib.import_module(module))
            ns.update({n: mod[n] for n in defined if n not in ns})
            texts.append(path.read_text())
    missing = [n for n in names if n not in ns]
    assert not missing, f"no module of martello/ defines {missing}"
    return ns, "\n".join(texts)


def martello_source():
    """The text of every module of the package, for rules written as code (a condition in
    the loader) rather than as a table."""
    return "\n".join(p.read_text() for p in sorted((ROOT / "martello").rglob("*.py")))


def _split(cell):
    return [x.strip() for x in cell.split(",") if x.strip()]


def _rows_by(name, key):
    return {r[key]: r for r in read_table(name)}


# --- behaviour.md: every item names tests that exist -----------------------------------------

def behaviour_items():
    """[(heading, item text)] of the bulleted items of docs/behaviour.md."""
    items, current, section = [], None, ""
    for line in (DOCS / "behaviour.md").read_text().splitlines():
        if line.startswith("## "):
            section = line[3:]
        if line.startswith("* "):
            current = [section, line[2:]]
            items.append(current)
        elif current is not None and line.startswith("  ") and line.strip():
            current[1] += " " + line.strip()
        elif not line.strip() or line.startswith("#"):
            current = None
    return items


def functions_of_tests(path):
    """Names of the test functions of a test file: module level, and Class::method."""
    tree = ast.parse(path.read_text())
    names = set()
    for node in tree.body:
        if isinstance(node, ast.FunctionDef) and node.name.startswith("test"):
            names.add(node.name)
        if isinstance(node, ast.ClassDef):
            names |= {f"{node.name}::{f.name}" for f in node.body
                      if isinstance(f, ast.FunctionDef) and f.name.startswith("test")}
    return names


def named_tests(item):
    m = re.search(r"\(tests: ([^()]*(?:\[[^\]]*\][^()]*)*)\)\s*$", item)
    return [t.strip() for t in m[1].split(",")] if m else []


def test_behaviour_page_has_items():
    items = behaviour_items()
    assert len(items) >= 20, [i[1][:40] for i in items]


@pytest.mark.parametrize("section,item", behaviour_items(), ids=lambda x: x[:40] if isinstance(x, str) else "")
def test_every_behaviour_item_names_tests_that_exist(section, item):
    tests = named_tests(item)
    assert tests, f"behaviour.md [{section}] item does not end with (tests: ...): {item[:80]}"
    for t in tests:
        file, sep, name = t.partition("::")
        assert sep and file.startswith("tests/") and file.endswith(".py"), f"malformed test name {t!r}"
        path = ROOT / file
        assert path.exists(), f"{t}: no file {file}"
        name = re.sub(r"\[.*\]$", "", name)          # a parametrized id names its function
        assert name in functions_of_tests(path), f"{t}: {file} has no test {name}"


def test_every_behaviour_test_is_named_by_an_item():
    named = {t.partition("::")[2] for _, item in behaviour_items() for t in named_tests(item)
             if t.startswith("tests/test_behaviour.py::")}
    orphans = functions_of_tests(ROOT / "tests" / "test_behaviour.py") - named
    assert not orphans, f"tests/test_behaviour.py tests no behaviour.md item names: {sorted(orphans)}"


# --- registry tables ------------------------------------------------------------------------

def test_registry_tables_are_marked_once_and_parse():
    assert set(registry_tables()) == REGISTRY


def test_read_table_reads_rows_by_header():
    rows = read_table("status-codes")
    assert rows[0] == {"status": "MARTELLO_OK", "value": "0", "meaning": "success"}
    assert parse_table(["| a | b |", "|---|---|", "| `x` | 2 |"]) == [{"a": "x", "b": "2"}]
    with pytest.raises(KeyError):
        read_table("no-such-table")
    with pytest.raises(ValueError):
        parse_table(["| a | b |", "|---|---|", "| 1 |"])


def test_status_codes_table_is_the_header_enum():
    rows = read_table("status-codes")
    assert [(r["status"], int(r["value"])) for r in rows] == c_status_enum()
    fortran = fortran_parameters(r"MARTELLO_(OK|ILL_CONDITIONED|ROOT_FOUND|ERR_[A-Z_]+)")
    assert {r["status"]: int(r["value"]) for r in rows} == fortran
    reg = _registry().registry("status")
    assert [(r["status"], int(r["value"])) for r in rows] == [(g.name, g.values["value"]) for g in reg]


def _registry():
    from martello.binding import native
    return native


def _constant(prefix, name):
    """The C constant of a registry row: its table's prefix and the name in capitals."""
    return prefix + name.upper().replace("-", "_")


def test_integrators_table_is_the_registry():
    native = _registry()
    reg = native.registry("integrators")
    families = {int(r.values["value"]): r.name for r in native.registry("families")}
    rows = read_table("integrators")
    assert [r["integrator"] for r in rows] == [r.name for r in reg]
    c = c_constants()
    for r, g in zip(rows, reg):
        name = r["integrator"]
        assert r["constant"] == _constant("MARTELLO_INT_", name), name
        assert int(r["value"]) == g.values["value"] == c[r["constant"]], name
        assert r["family"] == families[int(g.values["family"])], name
        assert r["dt is"] == ("output interval" if g.values["adaptive"] else "step"), name
        assert (DOCS / r["described in"]).exists(), name


def test_schemes_table_is_the_registry():
    native = _registry()
    ns, _ = python_namespace("CONTACT_SCHEMES")
    reg = native.registry("schemes")
    rows = read_table("schemes")
    assert [r["scheme"] for r in rows] == [r.name for r in reg]
    c = c_constants()
    for r, g in zip(rows, reg):
        name = r["scheme"]
        assert r["constant"] == _constant("MARTELLO_SCHEME_", name), name
        assert int(r["value"]) == g.values["value"] == c[r["constant"]], name
        assert set(_split(r["keys"])) == set(ns["CONTACT_SCHEMES"][name]), name


def test_laws_table_is_the_registry():
    native = _registry()
    # which laws refuse damping / e = 0 are rules of the loader, written as conditions
    scene_src = martello_source()
    elastic = ast.literal_eval(re.search(
        r'c\["law"\] in (\([^)]*\)) and \(c\["damping"\] is not None', scene_src)[1])
    divide_by_e = ast.literal_eval(re.search(
        r'c\["law"\] in (\([^)]*\)) and c\["restitution"\] == 0', scene_src)[1])
    reg = native.registry("laws")
    rows = read_table("laws")
    assert [r["law"] for r in rows] == [r.name for r in reg]
    c = c_constants()
    for r, g in zip(rows, reg):
        law = r["law"]
        assert r["constant"] == _constant("MARTELLO_LAW_", law), law
        assert int(r["value"]) == g.values["value"] == c[r["constant"]], law
        n = g.values["exponent"]
        assert r["exponent"] == (f"{n:g} (fixed)" if g.values["exponent_fixed"] else f"key, default {n:g}"), law
        assert (r["damping"] == "refused") == (law in elastic), law
        expected = "refused" if law in elastic else "(0, 1]" if law in divide_by_e else "[0, 1]"
        assert r["restitution"] == expected, law


def test_link_kinds_table_is_the_registry():
    native = _registry()
    ns, _ = python_namespace("LINK_TYPES")
    reg = native.registry("links")
    rows = read_table("link-kinds")
    assert [r["link"] for r in rows] == [r.name for r in reg] == list(ns["LINK_TYPES"])
    c = c_constants()
    for r, g in zip(rows, reg):
        link = r["link"]
        assert r["constant"] == _constant("MARTELLO_LINK_", link), link
        assert int(r["value"]) == g.values["value"] == c[r["constant"]], link
        assert _split(r["keys"]) == list(ns["LINK_TYPES"][link]), link


def test_compatibility_table_is_the_registry():
    native = _registry()
    reg = {r.name: r.values for r in native.registry("compatibility")}
    rows = read_table("compatibility")
    assert list(rows[0]) == ["scheme"] + list(reg)
    assert [r["scheme"] for r in rows] == [r.name for r in native.registry("schemes")]
    for r in rows:
        for integ, schemes in reg.items():
            assert r[integ] == ("yes" if schemes[r["scheme"]] else "no"), (r["scheme"], integ)


def test_integrator_parameters_table_is_the_registry():
    native = _registry()
    ns, _ = python_namespace("ANALYSIS_TYPES", "OUTPUT_KEYS", "NEWMARK_PRESETS")
    settings = {r.name: r for r in native.registry("settings")}
    types = {int(r.values["value"]): r.name for r in native.registry("setting_types")}
    integrators = native.integrators()
    reads = {i: native.settings_read(i) for i in integrators}
    rows = read_table("integrator-parameters")
    keys = {k for k in ns["ANALYSIS_TYPES"]["dynamic"] if k not in ("integrator", "output")}
    assert {r["key"] for r in rows} == keys | {"output.every"}
    assert {r["key"].removeprefix("output.") for r in rows} - {"preset"} == set(settings)
    kinds = {"double": "float", "int": "int", "bool": "bool"}
    for r in rows:
        key = r["key"]
        short = key.removeprefix("output.")
        if short == "preset":
            assert r["integrators"] == "newmark" and r["type"] == "string", key
            assert _split(r["valid"]) == list(ns["NEWMARK_PRESETS"]), key
            assert r["settings field"] == "—", key
            continue
        if short == "method":   # the scene names a row of the table methods; the field holds its value
            assert r["type"] == "string" and r["settings field"] == "method", key
            assert r["integrators"] == ", ".join(i for i in integrators if "method" in reads[i]), key
            continue
        g = settings[short]
        readers = [i for i in integrators if short in reads[i]]
        assert r["integrators"] == ("all" if readers == list(integrators) else ", ".join(readers)), key
        assert r["type"] == kinds[types[int(g.values["type"])]], key
        assert r["settings field"] == short, key
        assert r["valid"] == g.text.removeprefix("a number "), key
        spec = ns["OUTPUT_KEYS"]["every"] if key == "output.every" else ns["ANALYSIS_TYPES"]["dynamic"][key]
        kind, required, check, default = spec
        if default is not None:
            assert default == g.values["default"], ("loader default is the registry's", key)
            cell = r["default"]
            assert (cell == str(default).lower()) if kind == "bool" else float(cell) == default, key
        else:
            assert r["default"] in {"required", "from preset"}, key


def _named_table(doc_table, reg_table, name_col, prefix):
    native = _registry()
    reg = native.registry(reg_table)
    rows = read_table(doc_table)
    assert [r[name_col] for r in rows] == [r.name for r in reg]
    c = c_constants()
    for r, g in zip(rows, reg):
        assert int(r["index"]) == g.values["value"] == c[r["constant"]], r[name_col]
        assert r["constant"] == _constant(prefix, r[name_col]), r[name_col]


def test_counters_table_is_the_registry():
    _named_table("counters", "counters", "counter", "MARTELLO_COUNTER_")


def test_energy_terms_table_is_the_registry():
    _named_table("energy-terms", "energy", "term", "MARTELLO_ENERGY_")


def test_history_columns_table_is_the_registry():
    native = _registry()
    per = {int(r.values["value"]): r.name for r in native.registry("history_per")}
    docs_per = {"once": "row", "node": "output node", "contact": "output contact",
                "link": "output link", "energy_term": "energy term"}
    reg = native.registry("history")
    rows = read_table("history-columns")
    assert [r["columns"].split(":")[0] for r in rows] == [g.name for g in reg]
    for r, g in zip(rows, reg):
        assert r["one per"] == docs_per[per[int(g.values["per"])]], r["columns"]
    # and a real layout: what the binding builds from the registry for 2 nodes, 1 contact
    cols = native.history_columns(["n1", "n2"], ["c"], ["l"])
    assert cols[:7] == ["t", "u:n1", "u:n2", "v:n1", "v:n2", "a:n1", "a:n2"]
    assert cols[-len(native.energy_names()):] == [f"energy:{e}" for e in native.energy_names()]


# Where each registry table is documented: a docs table of its own, or the docs table that
# carries it as a column (settings and reads are the rows and the "integrators" column of
# integrator-parameters; history_per is the "one per" column of history-columns).
REGISTRY_DOCS = {
    "status": "status-codes", "integrators": "integrators", "families": "families",
    "compatibility": "compatibility", "settings": "integrator-parameters",
    "reads": "integrator-parameters", "setting_types": "setting-types", "schemes": "schemes",
    "laws": "laws", "links": "link-kinds", "contact_parameters": "contact-parameters",
    "link_parameters": "link-parameters", "time_functions": "time-functions",
    "counters": "counters", "energy": "energy-terms", "events": "events",
    "constants": "constants", "history": "history-columns", "history_per": "history-columns",
    "tracking": "tracking", "methods": "methods",
    "tables": None,   # the list of tables itself: docs/c-api.md's overview
}


def test_every_registry_table_is_documented():
    native = _registry()
    tables = [r.name for r in native.registry("tables")]
    assert set(tables) == set(REGISTRY_DOCS), "a registry table without a docs table (or gone)"
    documented = set(registry_tables())
    for t in tables:
        if REGISTRY_DOCS[t] is not None:
            assert REGISTRY_DOCS[t] in documented, (t, REGISTRY_DOCS[t])
    overview = (DOCS / "c-api.md").read_text()
    for t in tables:
        assert f"`{t}`" in overview, f"docs/c-api.md does not name the registry table {t}"


@pytest.mark.parametrize("table,label", [
    ("families", "families"), ("setting_types", "setting-types"),
    ("contact_parameters", "contact-parameters"), ("link_parameters", "link-parameters"),
    ("time_functions", "time-functions"), ("events", "events"), ("constants", "constants"),
    ("tracking", "tracking"), ("methods", "methods")])
def test_c_api_tables_are_the_registry(table, label):
    native = _registry()
    prefix = {r.name: r.text for r in native.registry("tables")}[table]
    reg = native.registry(table)
    rows = read_table(label)
    assert [r["name"] for r in rows] == [g.name for g in reg]
    c = c_constants()
    for r, g in zip(rows, reg):
        assert float(r["value"]) == g.values["value"], r["name"]
        assert r["meaning"] == g.text, r["name"]
        if prefix:
            assert r["constant"] == _constant(prefix, g.name), r["name"]
            if r["constant"] != "MARTELLO_GROUND":      # a #define, not an enum
                assert c[r["constant"]] == g.values["value"], r["name"]


# --- the examples are the catalogue files ------------------------------------------------------

def examples():
    text = (DOCS / "scene-input.md").read_text()
    return re.findall(r"<!-- example: (\S+) -->\n```toml\n(.*?)```", text, re.S)


def test_scene_input_has_examples():
    assert len(examples()) >= 5


@pytest.mark.parametrize("path,block", examples(), ids=lambda x: x if x.endswith(".toml") else "")
def test_examples_are_the_catalogue_files_verbatim(path, block):
    assert (ROOT / path).read_text() == block, f"docs/scene-input.md: the example of {path} differs from the file"


# --- links -------------------------------------------------------------------------------------

def github_anchor(heading):
    """The anchor GitHub gives a heading: lower case, punctuation (not '-' or '_') removed,
    spaces to hyphens."""
    h = re.sub(r"`|\*\*", "", heading.strip().lower())
    h = re.sub(r"[^\w\- ]", "", h)
    return h.replace(" ", "-")


def anchors(page):
    seen, out = {}, set()
    in_code = False
    for line in page.read_text().splitlines():
        if line.startswith("```"):
            in_code = not in_code
        if in_code or not line.startswith("#"):
            continue
        a = github_anchor(line.lstrip("#"))
        n = seen.get(a, 0)
        out.add(a if n == 0 else f"{a}-{n}")
        seen[a] = n + 1
    return out


def doc_pages():
    return sorted(DOCS.glob("*.md")) + [ROOT / "README.md"]


def test_relative_links_and_anchors_exist():
    broken = []
    for page in doc_pages():
        text = re.sub(r"```.*?```", "", page.read_text(), flags=re.S)
        for target in re.findall(r"\]\(([^)\s]+)\)", text):
            if re.match(r"[a-z]+:", target):
                continue
            file, _, anchor = target.partition("#")
            dest = (page.parent / file).resolve() if file else page
            if not dest.exists():
                broken.append(f"{page.name}: {target} (no file)")
            elif anchor and dest.suffix == ".md" and anchor not in anchors(dest):
                broken.append(f"{page.name}: {target} (no heading)")
    assert not broken, "\n".join(broken)


def test_no_page_points_to_the_old_scene_format_sections():
    for page in doc_pages():
        assert "scene-format.md#" not in page.read_text(), page.name


# --- problems.md ----------------------------------------------------------------------------

def test_problems_page_keeps_the_cited_sections():
    headings = [l[3:] for l in (DOCS / "problems.md").read_text().splitlines() if l.startswith("## ")]
    for i in range(1, 10):
        assert any(h.startswith(f"P{i} — ") for h in headings), f"## P{i} — ... missing"
    assert "Integrators" in headings and "Metrics" in headings


# Formulas that code comments and tests quote from the problem specification: each must be
# in docs/problems.md, written the same way.
QUOTED = [
    "γ(1 − α)/β − 1",                           # fortran/newmark_lagrange.f90, closed_forms
    "2.9432751843",                             # Hertz contact time, fortran tests, test_dynamics
    "(1 + e)·a = ln[(1 + a)/(1 − e a)]",        # exact Hunt–Crossley relation, contact_laws.f90
    "ξ = −ln e / √(π² + ln² e)",                # Kelvin, contact_laws.f90
    "F = c·sign(v)·|v|^α",                      # fluid-viscous damper, links.f90
    "t₁ = arccos(1 − h/u_s)/ω",                 # P2 first impact, closed_forms
    "τₙ = (2/ω)·arctan(e vₙ/(ω (u_s − h)))",    # P2 flight times
    "(2/ω)(π − arctan(e vₙ/(ω h)))",            # P2 without gravity
    "e_F0",                                     # clipped Kelvin, closed_forms
    "k/(k + ε)",                                # P1 penalty error, test_static
    "1/(1 + 3ε/r)",                             # P3 penalty error, test_static
    "h_crit = 2/ω",                             # central difference, test_atlas
    "ω²h²t/12",                                 # trapezoidal phase lag, test_newmark_lagrange
    "mescd",                                    # Metrics, martello/metrics.py
    "0.0504762376",                             # P1 penalty example, test_static
    "8.578949179",                              # free-fall Zeno time, test_closed_forms
    "0.6747514725",                             # clipped Kelvin targets, test_closed_forms
    "0.663", "0.488", "0.647",                  # HC floors and Jankowski, test_closed_forms
]


@pytest.mark.parametrize("formula", QUOTED)
def test_problems_page_carries_the_quoted_formulas(formula):
    assert formula in (DOCS / "problems.md").read_text()


# --- every docs/ path the code and the docs cite exists ---------------------------------------

CITED_DOC = re.compile(r"(?<![\w/.-])docs/[\w./-]*[\w-]\.(?:md|png|svg|txt|ipynb|csv|json|toml)\b")
SOURCES = ("martello", "c", "fortran", "tests", "benchmarks", "scripts", "docs", "reference", ".ci")


def cited_doc_paths():
    """{docs/... path: [files citing it]} over the sources, the docs and the top-level files
    (comments, messages and help texts cite docs/ paths from the repository root)."""
    files = [ROOT / n for n in ("README.md", "CHANGELOG.md", "CMakeLists.txt", "pyproject.toml")]
    for d in SOURCES:
        files += [p for p in (ROOT / d).rglob("*") if p.is_file() and p.suffix in
                  (".py", ".c", ".h", ".f90", ".md", ".toml", ".txt", ".sh", "") and "__pycache__" not in p.parts]
    cited = {}
    for f in files:
        try:
            text = f.read_text()
        except (UnicodeDecodeError, OSError):
            continue
        for m in CITED_DOC.findall(text):
            cited.setdefault(m, []).append(str(f.relative_to(ROOT)))
    return cited


def test_every_cited_docs_path_exists():
    cited = cited_doc_paths()
    assert len(cited) > 30                  # the scan finds the citations
    missing = {p: fs[:3] for p, fs in cited.items() if not (ROOT / p).exists()}
    assert not missing, missing


def test_no_code_cites_the_moved_scene_format_page():
    # docs/scene-format.md is a stub pointing to scene-input.md, results.md and behaviour.md
    cited = cited_doc_paths().get("docs/scene-format.md", [])
    assert [f for f in cited if not f.startswith("tests/test_docs.py")] == []
