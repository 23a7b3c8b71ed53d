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
            "status-codes"}


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


def fortran_name_cases(function):
    """{CONSTANT: 'name'} of a Fortran `select case` that returns names (integrator_name,
    scheme_name, ...)."""
    text = fortran_text()
    m = re.search(rf"function\s+{function}\b(.*?)end\s+function", text, re.S | re.I)
    assert m, f"Fortran function {function} not found"
    return dict(re.findall(r"case\s*\((\w+)\)\s*;?\s*\n?\s*name\s*=\s*'([^']+)'", m[1]))


def fortran_type_defaults(type_name):
    """{component: value} of a derived type's default initialisations."""
    text = fortran_text()
    m = re.search(rf"type\s*::\s*{type_name}\b(.*?)end\s+type", text, re.S)
    assert m, f"Fortran type {type_name} not found"
    out = {}
    for decl in re.findall(r"::\s*([^!\n]*)", m[1]):
        for name, value in re.findall(r"(\w+)\s*=\s*([^,]+)", decl):
            value = value.strip()
            if value in (".true.", ".false."):
                out[name] = value == ".true."
            elif re.fullmatch(r"-?[\d.]+(e-?\d+)?(_dp|_i8)?", value):
                out[name] = float(value.replace("_dp", "").replace("_i8", ""))
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


def test_integrators_table_is_the_code():
    ns, _ = python_namespace("INTEGRATORS", "STRUCTURAL", "ADAPTIVE")
    rows = read_table("integrators")
    assert [r["integrator"] for r in rows] == list(ns["INTEGRATORS"])
    c = c_constants()
    fortran_values = fortran_parameters(r"INT_[A-Z0-9_]+")
    fortran_names = fortran_name_cases("integrator_name")
    for r in rows:
        name = r["integrator"]
        assert c[r["constant"]] == int(r["value"]), name
        internal = r["constant"].removeprefix("MARTELLO_")
        assert fortran_names[internal] == name and fortran_values[internal] == int(r["value"]), name
        assert (r["family"] == "structural") == (name in ns["STRUCTURAL"]), name
        assert (r["family"] in ("event-driven", "dae")) == (name in ns["ADAPTIVE"]), name
        assert r["dt is"] == ("output interval" if name in ns["ADAPTIVE"] else "step"), name
        assert (DOCS / r["described in"]).exists(), name
    ns_run, _ = python_namespace("INTEGRATOR_CONST")
    assert {k: "MARTELLO_" + v for k, v in ns_run["INTEGRATOR_CONST"].items()} == \
        {r["integrator"]: r["constant"] for r in rows}


def test_schemes_table_is_the_code():
    ns, _ = python_namespace("SCHEMES", "CONTACT_SCHEMES")
    ns_run, _ = python_namespace("SCHEME_CONST")
    rows = read_table("schemes")
    assert [r["scheme"] for r in rows] == list(ns["SCHEMES"])
    c = c_constants()
    fortran_values = fortran_parameters(r"SCHEME_[A-Z]+")
    fortran_names = fortran_name_cases("scheme_name")
    for r in rows:
        name, internal = r["scheme"], r["constant"].removeprefix("MARTELLO_")
        assert ns_run["SCHEME_CONST"][name] == internal, name
        assert c[r["constant"]] == int(r["value"]) == fortran_values[internal], name
        assert fortran_names[internal] == name, name
        assert set(_split(r["keys"])) == set(ns["CONTACT_SCHEMES"][name]), name


def test_laws_table_is_the_code():
    ns, _ = python_namespace("LAWS", "FIXED_EXPONENT")
    scene_src = martello_source()
    ns_run, _ = python_namespace("LAW_CONST", "LAW_EXPONENT")
    elastic = ast.literal_eval(re.search(
        r'c\["law"\] in (\([^)]*\)) and \(c\["damping"\] is not None', scene_src)[1])
    divide_by_e = ast.literal_eval(re.search(
        r'c\["law"\] in (\([^)]*\)) and c\["restitution"\] == 0', scene_src)[1])
    rows = read_table("laws")
    assert [r["law"] for r in rows] == list(ns["LAWS"])
    c = c_constants()
    fortran_values = fortran_parameters(r"LAW_[A-Z_]+")
    for r in rows:
        law, internal = r["law"], r["constant"].removeprefix("MARTELLO_")
        assert ns_run["LAW_CONST"][law] == internal, law
        assert c[r["constant"]] == int(r["value"]) == fortran_values[internal], law
        if law in ns["FIXED_EXPONENT"]:
            assert r["exponent"] == f"{ns['FIXED_EXPONENT'][law]:g} (fixed)", law
            assert ns_run["LAW_EXPONENT"][law] == ns["FIXED_EXPONENT"][law], law
        else:
            assert r["exponent"] == f"key, default {ns_run['LAW_EXPONENT'][law]:g}", law
        assert (r["damping"] == "refused") == (law in elastic), law
        expected = "refused" if law in elastic else "(0, 1]" if law in divide_by_e else "[0, 1]"
        assert r["restitution"] == expected, law


def test_link_kinds_table_is_the_code():
    ns, _ = python_namespace("LINK_TYPES")
    ns_run, _ = python_namespace("LINK_CONST")
    rows = read_table("link-kinds")
    assert [r["link"] for r in rows] == list(ns["LINK_TYPES"])
    c = c_constants()
    fortran_values = fortran_parameters(r"LINK_[A-Z_]+")
    for r in rows:
        link, internal = r["link"], r["constant"].removeprefix("MARTELLO_")
        assert ns_run["LINK_CONST"][link] == internal, link
        assert c[r["constant"]] == int(r["value"]) == fortran_values[internal], link
        assert _split(r["keys"]) == list(ns["LINK_TYPES"][link]), link


def _fortran_scheme_supported():
    """The compatibility rule of the Fortran library, evaluated from its source: each
    `case (SCHEME...)` sets `ok = <expression in kind>`, then `if (scheme == S) ok = ...`."""
    text = fortran_text()
    m = re.search(r"function\s+scheme_supported\b(.*?)end\s+function", text, re.S)
    assert m, "Fortran function scheme_supported not found"
    body = m[1]
    ints = fortran_parameters(r"INT_[A-Z0-9_]+")
    schemes = fortran_parameters(r"SCHEME_[A-Z]+")

    def py(expr):
        expr = expr.split("!")[0].strip()
        for f, p in ((".false.", "False"), (".true.", "True"), (".and.", " and "),
                     (".or.", " or "), (".not.", " not "), ("/=", "!=")):
            expr = expr.replace(f, p)
        return expr

    cases = re.findall(r"case\s*\(([^)]*)\)\s*(?:!.*)?\n\s*ok\s*=\s*(.+)", body)
    default = re.search(r"case\s+default.*\n\s*ok\s*=\s*(.+)", body)
    overrides = re.findall(r"if\s*\(scheme\s*==\s*(\w+)\)\s*ok\s*=\s*(.+)", body)

    def supported(kind, scheme):
        env = dict(ints, kind=kind)
        result = None
        for names, expr in cases:
            if scheme in [schemes[n.strip()] for n in names.split(",")]:
                result = eval(py(expr), {}, env)
        if result is None:
            result = eval(py(default[1]), {}, env)
        for name, expr in overrides:
            if scheme == schemes[name]:
                result = eval(py(expr), {}, env)
        return bool(result)
    return supported, ints, schemes


def test_compatibility_table_is_the_code():
    ns, _ = python_namespace("INTEGRATORS", "COMPATIBLE")
    ns_run, _ = python_namespace("INTEGRATOR_CONST", "SCHEME_CONST")
    rows = read_table("compatibility")
    assert list(rows[0]) == ["scheme"] + list(ns["INTEGRATORS"])
    assert {r["scheme"] for r in rows} == set(ns["COMPATIBLE"])
    supported, ints, schemes = _fortran_scheme_supported()
    for r in rows:
        for integ in ns["INTEGRATORS"]:
            assert r[integ] in ("yes", "no"), (r["scheme"], integ)
            yes = r[integ] == "yes"
            assert yes == (integ in ns["COMPATIBLE"][r["scheme"]]), (r["scheme"], integ)
            kind = ints[ns_run["INTEGRATOR_CONST"][integ]]
            scheme = schemes[ns_run["SCHEME_CONST"][r["scheme"]]]
            assert yes == supported(kind, scheme), ("fortran", r["scheme"], integ)


def test_integrator_parameters_table_is_the_code():
    scene_src = martello_source()
    ns, _ = python_namespace("ANALYSIS_TYPES", "OUTPUT_KEYS", "INTEGRATOR_KEYS",
                                     "IMPLICIT_KEYS", "INTEGRATORS", "NEWMARK_PRESETS")
    implicit = ast.literal_eval(re.search(
        r"implicit = IMPLICIT_KEYS if integ in (\([^)]*\))", scene_src)[1])
    # keys the integrator check requires (hht: alpha, generalized-alpha: rho_inf)
    required_by_integrator = set(re.findall(r'raise SceneError\(src, "analysis\.(\w+)", "missing"', scene_src))
    spec = {k: v for k, v in ns["ANALYSIS_TYPES"]["dynamic"].items() if k not in ("integrator", "output")}
    spec["output.every"] = ns["OUTPUT_KEYS"]["every"]
    rows = read_table("integrator-parameters")
    assert [r["key"] for r in rows if r["key"] in spec] == [r["key"] for r in rows]
    assert {r["key"] for r in rows} == set(spec)
    c = c_constants()
    fortran = fortran_type_defaults("integrator_settings_t")
    slots = {k for k in c if k.startswith("MARTELLO_R_")}
    assert {r["slot"] for r in rows} - {"—"} == slots
    assert c["MARTELLO_NPAR_INTEGRATOR"] == len(slots)
    kinds = {"float": "float", "int": "int", "bool": "bool", "str": "string"}
    for r in rows:
        key = r["key"]
        kind, required, check, default = spec[key]
        short = key.split(".")[-1]
        if short in set().union(*ns["INTEGRATOR_KEYS"].values()) | ns["IMPLICIT_KEYS"]:
            expected = [i for i in ns["INTEGRATORS"] if short in ns["INTEGRATOR_KEYS"][i]
                        or (short in ns["IMPLICIT_KEYS"] and i in implicit)]
            assert _split(r["integrators"]) == expected, key
        else:
            assert r["integrators"] == "all", key
        assert r["type"] == kinds[kind], key
        if default is not None:
            cell = r["default"]
            if kind == "bool":
                assert cell == str(default).lower(), key
            else:
                assert float(cell) == default, key
                if short in fortran:
                    assert fortran[short] == default, ("fortran default", key)
        elif required or short in required_by_integrator:
            assert r["default"] == "required", key
        else:
            assert r["default"] in {"from preset", *ns["NEWMARK_PRESETS"]}, key
        if check is not None:
            assert r["valid"] == check[1].removeprefix("a number "), key
        elif key == "preset":
            assert _split(r["valid"]) == list(ns["NEWMARK_PRESETS"]), key
        else:
            assert r["valid"] == "—", key
        slot = f"MARTELLO_R_{short.upper()}"
        assert r["slot"] == (slot if slot in c else "—"), key


def test_counters_table_is_the_code():
    ns, _ = python_namespace("COUNTER_NAMES")
    rows = read_table("counters")
    fortran = fortran_parameters(r"C_[A-Z_]+|NCOUNTERS")
    assert [r["counter"] for r in rows] == list(ns["COUNTER_NAMES"])
    assert [int(r["index"]) for r in rows] == list(range(len(rows)))
    assert [fortran[r["fortran"]] - 1 for r in rows] == list(range(len(rows)))
    assert c_constants()["MARTELLO_NCOUNTERS"] == fortran["NCOUNTERS"] == len(rows)


def test_energy_terms_table_is_the_code():
    ns, _ = python_namespace("ENERGY_NAMES")
    rows = read_table("energy-terms")
    fortran = fortran_parameters(r"E_[A-Z_]+|NENERGY")
    assert [r["term"] for r in rows] == list(ns["ENERGY_NAMES"])
    assert [int(r["index"]) for r in rows] == list(range(len(rows)))
    assert [fortran[r["fortran"]] - 1 for r in rows] == list(range(len(rows)))
    assert c_constants()["MARTELLO_NENERGY"] == fortran["NENERGY"] == len(rows)


def test_history_columns_table_is_the_code():
    rows = read_table("history-columns")
    run_src = martello_source()
    columns_stmt = re.search(r"columns = \[\"t\"\](.*?)\n\s*from ", run_src, re.S)
    assert columns_stmt, "the history column list of the run module was not found"
    prefixes = re.findall(r'f"([a-z_]+):\{', columns_stmt[1])
    assert [r["columns"].split(":")[0] for r in rows] == ["t"] + prefixes
    per = {"row": 0, "output node": 0, "output contact": 0, "output link": 0, "energy term": 0}
    for r in rows:
        per[r["one per"]] += 1
    ncol = re.search(r"ncol = 1 \+ (\d)\*size\(out_nodes\) \+ (\d)\*size\(out_contacts\) \+ "
                     r"(\d)\*size\(r%out_links\) \+ NENERGY", fortran_text())
    assert ncol, "the history width of the Fortran results was not found"
    assert (per["row"], per["output node"], per["output contact"], per["output link"], per["energy term"]) == \
        (1, int(ncol[1]), int(ncol[2]), int(ncol[3]), 1)


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
