"""The pounding test set, machine-readable (docs/testset.md): `martello testset -o DIR` writes,
for every catalogue scene whose [check] names a closed form, DIR/<id>.json (the model in
neutral terms, parameters and units, reference values with trusted digits, the tolerance kinds
and provenance) and DIR/<id>.md (a page like the IVP Test Set's), plus DIR/index.json and
DIR/README.md. The set is versioned with the package: every file names the martello version
and the digest of the scene it was made from.

Tolerance kinds (after LAMMPS' granular unit tests): `analytic`, the closed form and the
tolerance the catalogue justifies for it (its `why`); with --run also `regression`, martello's
own value at the scene's settings, to be met to 1e-9 relative (drift, not verification)."""

import dataclasses
import json
import math
from pathlib import Path

from .errors import MartelloError
from .independent.laws import contact_law
from .independent.scene import effective_mass
from .scene.rows import element_terms

SCHEMA = 1
REGRESSION_RTOL = 1e-9
# closed forms that are semi-analytic (docs/problems.md, martello.oracles): the digits their
# values are trusted to; every other closed form is an explicit formula (double precision)
SEMI_ANALYTIC = {"bouncing_kelvin_events": 12, "two_body_impact": 12, "davis_period1_damped": 12}
EXPLICIT_DIGITS = 15
UNITS = {"length": "m", "mass": "kg", "time": "s", "force": "N", "stiffness": "N/m (N/m^n for a law of exponent n)",
         "damping": "N s/m (kelvin), dimensionless (Hunt-Crossley family: a = chi v_in; jankowski: xi)",
         "acceleration": "m/s^2"}


class TestSetError(MartelloError):
    """The test set cannot be written (the output folder, a scene of the catalogue)."""


def _num(x):
    x = float(x)
    return x if math.isfinite(x) else None


def _digits(value, half):
    """Significant digits of a number printed with `half` half a unit of its last digit:
    0.071982 (half 5e-7) has 5, 11.8e6 (half 5e4) has 3."""
    return math.floor(math.log10(abs(value) / (2.0 * half))) + 1 if value and half else None


def model(scene):
    """The scene's mechanics in neutral terms (no martello names): nodes, links, contacts with
    their laws resolved, stiffness blocks, loads, the time interval."""
    nodes = [{"name": n["name"], "mass": n["mass"], "u0": n["u0"], "v0": n["v0"], "fixed": n["fixed"]}
             for n in scene.nodes]
    name = lambda i: "ground" if i < 0 else scene.nodes[i]["name"]      # noqa: E731
    links = []
    for lk in scene.links:
        d = {k: v for k, v in lk.items() if k not in ("name", "type", "a", "b", "terms", "direction")
             and v is not None}
        sides = ({"a": name(lk["a"]), "b": name(lk["b"])} if lk.get("terms") is None else
                 {"terms": [{"node": name(i), "coef": cf} for i, cf in lk["terms"]]})
        links.append({"name": lk["name"], "type": lk["type"], **sides, **{k: _num(v) for k, v in d.items()}})
    mass = [n["mass"] for n in scene.nodes]
    fixed = [n["fixed"] for n in scene.nodes]
    contacts = []
    for c in scene.contacts:
        # a node pair by its sides; a row (plan points of rigid floors) by its terms
        # (docs/buildings.md): δ = Σ coef u(node) − gap
        terms = element_terms(c)
        d = ({"name": c["name"], "a": name(c["a"]), "b": name(c["b"])} if c.get("terms") is None else
             {"name": c["name"], "terms": [{"node": name(i), "coef": cf} for i, cf in terms]})
        d.update(gap=c["gap"], scheme=c["scheme"])
        if c["scheme"] == "penalty":
            mstar = effective_mass(mass, fixed, terms)
            # the target e resolved by the law's published formula, as the kernel does
            law = contact_law({k: v for k, v in c.items() if v is not None}, terms, mstar)
            d.update(law=law.law, stiffness=law.K, exponent=law.n, damping=law.c,
                     clipped=law.clipped, effective_mass=_num(mstar) if math.isfinite(mstar) else None,
                     target_restitution=c.get("restitution"))
        elif c.get("restitution") is not None:
            d["restitution"] = c["restitution"]
        contacts.append(d)
    blocks = [{"name": b["name"], "nodes": [name(i) for i in b["nodes"]],
               "stiffness": [[float(x) for x in row] for row in b["k"]],
               "damping": [[float(x) for x in row] for row in b["c"]]} for b in scene.blocks]
    couplings = [{"a": name(m["a"]), "b": name(m["b"]), "value": m["value"]} for m in scene.couplings]
    an = scene.analysis
    out = {"nodes": nodes, "links": links, "contacts": contacts, "mass_couplings": couplings,
           "stiffness_blocks": blocks,
           "loads": {"gravity": scene.gravity, "ground_acceleration": scene.ground,
                     "forces": [{"node": name(f["node"]), "function": f["function"]} for f in scene.forces]},
           "analysis": {"type": an["type"]}}
    if an["type"] == "dynamic":
        out["analysis"].update(t_end=an["t_end"])
    return out


def references(scene):
    """The [check] rows as reference values: the closed form's value at its parameters, the
    digits it is trusted to, and the analytic tolerance with its reason."""
    from .checks.oracle_names import closed_form
    chk = scene.check
    fn = closed_form(chk["closed_form"])
    if fn is None:
        raise TestSetError(f"{scene.source}: closed form {chk['closed_form']!r} is unknown")
    res = fn(**chk["params"])
    get = (lambda k: res[k]) if isinstance(res, dict) else (lambda k: getattr(res, k))
    printed = {}
    if chk["closed_form"] == "vm65_reference":
        from .oracles.vendor import vm65_printed
        printed = vm65_printed()
    elif chk["closed_form"] == "abaqus_1_3_15_reference":
        from .oracles.vendor import abaqus_1_3_15_printed
        printed = abaqus_1_3_15_printed()
    rows = []
    for row in chk["compare"]:
        field = row["oracle"]
        value = get(field)
        if isinstance(value, bool):
            value = float(value)
        key = field[len("printed_"):] if field.startswith("printed_") else None
        if key in printed:
            digits, source = _digits(*printed[key]), "printed by the vendor's manual"
        elif key is not None:
            digits, source = None, "derived from a printed value"
        else:
            digits = SEMI_ANALYTIC.get(chk["closed_form"], EXPLICIT_DIGITS)
            source = "semi-analytic closed form" if chk["closed_form"] in SEMI_ANALYTIC else "closed form"
        rows.append({"quantity": row["result"], "value": _num(value), "trusted_digits": digits,
                     "source": source, "oracle": f"{chk['closed_form']}.{field}",
                     "tolerance": {"analytic": {"rtol": row.get("rtol", 0.0), "atol": row.get("atol", 0.0),
                                                "why": row["why"]}}})
    return rows


def problem(scene, root, version, run=False):
    """One problem of the set as a dict (the JSON file's content)."""
    rel = Path(scene.source).resolve().relative_to(root.resolve()) if root else Path(scene.source)
    pid = str(rel.with_suffix("")).replace("/", ".")
    refs = references(scene)
    if run:
        from .checks.measures import run_measured
        from .checks.verify import lookup
        summary, _ = run_measured(scene)
        for r in refs:
            got = lookup(summary, r["quantity"])
            r["tolerance"]["regression"] = {"value": _num(got), "rtol": REGRESSION_RTOL,
                                            "made_with": f"martello {version}, the scene's own settings"}
    an = scene.analysis
    return {"schema": SCHEMA, "id": pid, "title": scene.title, "problem": scene.problem,
            "description": scene.description.strip(), "units": UNITS, "model": model(scene),
            "solver_settings": {k: v for k, v in an.items() if k != "output" and v is not None},
            "references": refs,
            "provenance": {"martello": version, "scene": str(rel), "scene_sha256": scene.digest,
                           "closed_form": scene.check["closed_form"], "params": scene.check["params"],
                           "oracles": "martello/oracles (docs/problems.md), independent of the solvers"}}


def page(p):
    """A problem's page, in the manner of the IVP Test Set's (Mazzia & Magherini)."""
    m = p["model"]
    lines = [f"# {p['title']}", "",
             f"`{p['id']}` · problem {p['problem'] or '-'} · martello {p['provenance']['martello']} · "
             f"scene `{p['provenance']['scene']}`", "",
             "## General information", "",
             f"* type: {m['analysis']['type']}" + (f", 0 <= t <= {m['analysis']['t_end']:g} s"
                                                  if "t_end" in m["analysis"] else ""),
             f"* dimension: {sum(not n['fixed'] for n in m['nodes'])} free degrees of freedom, "
             f"{len(m['links'])} links, {len(m['contacts'])} contacts",
             f"* reference: {p['provenance']['closed_form']} (martello/oracles)", "",
             "## Description", "", p["description"] or "(none)", "",
             "## Mathematical description", "",
             "M ü + f_links(u, u̇) + f_contacts(δ, δ̇) = M·1·(g − ü_g(t)) + f(t), with δ = u_a − u_b − gap "
             "> 0 in contact (a contact given as a row: δ = Σ coef·u(node) − gap, its force −coef·P "
             "on each node, docs/buildings.md) and the contact laws below (docs/problems.md; SI units).", "",
             "| node | mass [kg] | u0 [m] | v0 [m/s] | fixed |", "|---|---|---|---|---|"]
    shown = m["nodes"][:20]
    lines += [f"| {n['name']} | {n['mass']:.10g} | {n['u0']:g} | {n['v0']:g} | {n['fixed']} |" for n in shown]
    if len(m["nodes"]) > 20:
        lines.append(f"| … {len(m['nodes']) - 20} more (the JSON file lists all) | | | | |")
    if m["contacts"]:
        lines += ["", "| contact | a | b | gap [m] | scheme | law | stiffness | exponent | damping |",
                  "|---|---|---|---|---|---|---|---|---|"]
        for c in m["contacts"][:20]:
            a, b = (c["a"], c["b"]) if "terms" not in c else \
                (" ".join(f"{t['coef']:+g}·u({t['node']})" for t in c["terms"]), "(the row)")
            lines.append(f"| {c['name']} | {a} | {b} | {c['gap']:g} | {c['scheme']} | "
                         f"{c.get('law', '-')} | {c.get('stiffness', '-')} | {c.get('exponent', '-')} | "
                         f"{c.get('damping', '-')} |")
    if m["links"]:
        lines += ["", f"Links: {len(m['links'])} ("
                  + ", ".join(sorted({lk['type'] for lk in m['links']})) + "; the JSON file gives each)."]
    ld = m["loads"]
    lines += ["", f"Loads: gravity {ld['gravity']:g} m/s²; ground acceleration "
              f"{json.dumps(ld['ground_acceleration']) if ld['ground_acceleration'] else 'none'}; "
              f"{len(ld['forces'])} nodal forces.", "",
              "## Reference solution", "",
              "| quantity | value | trusted digits | source | analytic tolerance | why |",
              "|---|---|---|---|---|---|"]
    for r in p["references"]:
        tol = r["tolerance"]["analytic"]
        t = (f"rtol {tol['rtol']:g}" if tol["rtol"] else "") + (f" atol {tol['atol']:g}" if tol["atol"] else "")
        lines.append(f"| `{r['quantity']}` | {r['value']!r} | {r['trusted_digits'] or '-'} | {r['source']} | "
                     f"{t.strip() or 'exact'} | {r['tolerance']['analytic']['why']} |")
    lines += ["", "## How to use it", "",
              f"Solve the model in your code, write its history (docs/compare.md), and score it: "
              f"`martello compare history.csv --against {p['provenance']['scene']}`; or compare your "
              "values with the table. The JSON file beside this page has all of it "
              f"(schema {p['schema']}).", "",
              "## Provenance", "",
              f"martello {p['provenance']['martello']}; scene sha256 {p['provenance']['scene_sha256'][:16]}…; "
              f"closed form `{p['provenance']['closed_form']}` with parameters "
              f"`{json.dumps(p['provenance']['params'])}`.", ""]
    return "\n".join(lines)


def build(out, scenes, root, version, run=False):
    """Write the set into out (replaced whole). Returns the index."""
    from .paths import folder_replaced
    problems = [problem(s, root, version, run=run) for s in scenes]
    index = {"schema": SCHEMA, "martello": version, "problems": len(problems),
             "reference_values": sum(len(p["references"]) for p in problems),
             "digits": _digit_counts(problems),
             "files": [{"id": p["id"], "json": f"{p['id']}.json", "page": f"{p['id']}.md",
                        "title": p["title"], "references": len(p["references"])} for p in problems]}
    with folder_replaced(Path(out), "index.json", TestSetError) as tmp:
        for p in problems:
            (tmp / f"{p['id']}.json").write_text(json.dumps(p, indent=1, default=_json) + "\n")
            (tmp / f"{p['id']}.md").write_text(page(p))
        (tmp / "index.json").write_text(json.dumps(index, indent=1) + "\n")
        (tmp / "README.md").write_text(_readme(index))
    return index


def _json(x):
    if dataclasses.is_dataclass(x):
        return dataclasses.asdict(x)
    return str(x)


def _digit_counts(problems):
    out = {}
    for p in problems:
        for r in p["references"]:
            key = str(r["trusted_digits"]) if r["trusted_digits"] else "derived"
            out[key] = out.get(key, 0) + 1
    return dict(sorted(out.items()))


def _readme(index):
    lines = [f"# The martello pounding test set (martello {index['martello']})", "",
             f"{index['problems']} problems, {index['reference_values']} reference values "
             f"(trusted digits: {', '.join(f'{k}: {v}' for k, v in index['digits'].items())}). "
             "One JSON file and one page per problem; docs/testset.md in martello describes the format.", "",
             "| id | title | reference values |", "|---|---|---|"]
    lines += [f"| [{f['id']}]({f['page']}) | {f['title']} | {f['references']} |" for f in index["files"]]
    return "\n".join(lines) + "\n"


def main(args):
    """martello testset (martello.cli)."""
    from .binding import native
    from .scene import catalogue
    from .scene.loader import load
    files = [catalogue.find(p) for p in args.scenes] if args.scenes else catalogue.scene_files()
    scenes = [s for s in map(load, files) if s.check is not None]
    if not scenes:
        raise TestSetError("no scene with a [check] closed form among those given")
    root = catalogue.ROOT if not args.scenes else None
    index = build(args.output, scenes, root, native.version(), run=args.run)
    print(f"{index['problems']} problems, {index['reference_values']} reference values -> "
          f"{args.output}/ (index.json, README.md, <id>.json and <id>.md per problem)")
    return 0


__all__ = ["build", "problem", "page", "model", "references", "main", "TestSetError", "SCHEMA"]
