"""The measured tables of docs/performance.md, each kept with the record it was made from.

A timing cannot be made again to the bit, so a benchmark script's `--docs` keeps its run's
JSON results beside the page (docs/perf/<name>.json, a few kB) and writes the table it renders
from them between the page's fence for NAME; `--check` renders every record again and finds
the page's copy the same (tests/test_generated_docs.py). The table then cannot drift from
the measurement it reports, nor be edited by hand."""

import json
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DOC = ROOT / "docs" / "performance.md"
RECORDS = ROOT / "docs" / "perf"
END = "<!-- /generated -->"


def commit():
    """The checkout's commit, "-dirty" where the code measured (the library's sources, the
    front end, the benchmarks, the build) has uncommitted changes; None outside git."""
    head = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"],
                          capture_output=True, text=True).stdout.strip()
    changed = subprocess.run(["git", "-C", str(ROOT), "status", "--porcelain", "--", "fortran", "c",
                              "martello", "benchmarks/perf", "CMakeLists.txt", "cmake"],
                             capture_output=True, text=True).stdout.strip()
    return (head + ("-dirty" if changed else "")) or None


def fence(name):
    return f"<!-- generated from docs/perf/{name}.json by its script's --docs -->"


def _span(text, name, doc=DOC):
    start = text.find(fence(name))
    if start < 0:
        raise SystemExit(f"{doc.relative_to(ROOT)}: no fence for {name} ({fence(name)} ... {END})")
    i = start + len(fence(name))
    return i, text.index(END, i)


def record(name, result, table, doc=DOC):
    """Keep result as docs/perf/<name>.json and put table into the fence for NAME of the page
    doc (docs/performance.md unless said)."""
    RECORDS.mkdir(exist_ok=True)
    (RECORDS / f"{name}.json").write_text(json.dumps(result, indent=1) + "\n")
    text = doc.read_text()
    i, j = _span(text, name, doc)
    doc.write_text(text[:i] + "\n" + table + "\n" + text[j:])
    print(f"written: docs/perf/{name}.json, its table in {doc.relative_to(ROOT)}")


def check(name, render, doc=DOC):
    """None if the page's table for NAME is what render makes of docs/perf/<name>.json, else
    what differs."""
    path = RECORDS / f"{name}.json"
    if not path.exists():
        return f"docs/perf/{name}.json missing (the script's --docs writes it)"
    want = render(json.loads(path.read_text())).strip()
    text = doc.read_text()
    i, j = _span(text, name, doc)
    have = text[i:j].strip()
    if have != want:
        return (f"{doc.relative_to(ROOT)}: the table of {name} is not what docs/perf/{name}.json "
                f"renders to (run the script with --docs --from the record, or measure again)\n"
                f"--- page\n{have}\n--- record\n{want}")
    return None
