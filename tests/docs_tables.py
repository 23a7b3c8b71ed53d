"""The machine-readable tables of the documentation.

A registry table is a plain markdown table between two markers in a page of docs/:

    <!-- registry:NAME -->
    | header | ... |
    |---|---|
    | value | ... |
    <!-- /registry:NAME -->

Each NAME appears once in all of docs/. ``read_table(NAME)`` returns its rows as dicts
(header -> cell text, stripped; a cell written in backticks loses them). ``registry_tables()``
maps every NAME to (page, rows). Nothing here imports martello."""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"

_OPEN = re.compile(r"^<!--\s*registry:([A-Za-z0-9_-]+)\s*-->\s*$")
_CLOSE = re.compile(r"^<!--\s*/registry:([A-Za-z0-9_-]+)\s*-->\s*$")


def _cells(line):
    line = line.strip()
    if not (line.startswith("|") and line.endswith("|")):
        raise ValueError(f"not a table row: {line!r}")
    cells = [c.strip() for c in line[1:-1].split("|")]
    return [c[1:-1] if len(c) >= 2 and c[0] == c[-1] == "`" else c for c in cells]


def parse_table(lines, where="table"):
    """Rows of a markdown table given as its lines (header, separator, rows)."""
    lines = [l for l in lines if l.strip()]
    if len(lines) < 2:
        raise ValueError(f"{where}: a table needs a header and a separator line")
    header = _cells(lines[0])
    if not all(re.fullmatch(r":?-{3,}:?", c) for c in _cells(lines[1])):
        raise ValueError(f"{where}: the second line must separate the header (|---|...|)")
    rows = []
    for line in lines[2:]:
        cells = _cells(line)
        if len(cells) != len(header):
            raise ValueError(f"{where}: {len(cells)} cells under {len(header)} headers: {line!r}")
        rows.append(dict(zip(header, cells)))
    return rows


def registry_blocks(pages=None):
    """[(name, page, first line number, lines)] of every marked block, in page order."""
    pages = sorted(DOCS.glob("*.md")) if pages is None else pages
    blocks = []
    for page in pages:
        open_name, start, body = None, 0, []
        for i, line in enumerate(page.read_text().splitlines(), 1):
            m_open, m_close = _OPEN.match(line), _CLOSE.match(line)
            if m_open:
                if open_name is not None:
                    raise ValueError(f"{page.name}:{i}: registry:{m_open[1]} opens inside registry:{open_name}")
                open_name, start, body = m_open[1], i, []
            elif m_close:
                if m_close[1] != open_name:
                    raise ValueError(f"{page.name}:{i}: /registry:{m_close[1]} closes registry:{open_name}")
                blocks.append((open_name, page, start, body))
                open_name = None
            elif open_name is not None:
                body.append(line)
        if open_name is not None:
            raise ValueError(f"{page.name}:{start}: registry:{open_name} is never closed")
    return blocks


def registry_tables():
    """{NAME: (page, rows)}; a NAME marked twice is an error (each table appears once)."""
    tables = {}
    for name, page, line, body in registry_blocks():
        if name in tables:
            raise ValueError(f"registry:{name} appears twice: {tables[name][0].name} and {page.name}")
        tables[name] = (page, parse_table(body, f"{page.name}:{line} registry:{name}"))
    return tables


def read_table(name):
    """The rows of registry table NAME: a list of {header: cell} dicts."""
    tables = registry_tables()
    if name not in tables:
        raise KeyError(f"no registry:{name} table in docs/ (have: {', '.join(sorted(tables))})")
    return tables[name][1]
