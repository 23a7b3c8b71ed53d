"""What studies and the atlas write besides their numbers: a progress bar, CSV cells, file
name slugs and palette PNGs."""

from __future__ import annotations

import math
import sys
import time


class Progress:
    """A plain-text progress bar on stderr (a line per 10 % when stderr is not a terminal)."""

    def __init__(self, total, label="runs", stream=None, width=30):
        self.total, self.label, self.width = max(total, 1), label, width
        self.stream = stream or sys.stderr
        self.done, self.bad, self.t0, self.last = 0, 0, time.perf_counter(), -1
        self.not_run = 0          # specs not run: a combination that does not apply, no reference
        self.tty = hasattr(self.stream, "isatty") and self.stream.isatty()

    def update(self, ok=True, not_run=False):
        self.done += 1
        self.not_run += 1 if not_run else 0
        self.bad += 0 if ok or not_run else 1
        frac = self.done / self.total
        el = time.perf_counter() - self.t0
        eta = el / frac - el if frac > 0 else 0.0
        bar = "#" * int(self.width * frac) + "." * (self.width - int(self.width * frac))
        line = (f"[{bar}] {self.done}/{self.total} {self.label}, {el:5.1f} s elapsed, "
                f"~{eta:5.1f} s left, {self.bad} not ok"
                + (f", {self.not_run} not run" if self.not_run else ""))
        if self.tty:
            self.stream.write("\r" + line)
            if self.done == self.total:
                self.stream.write("\n")
        elif int(10 * frac) != self.last or self.done == self.total:
            self.last = int(10 * frac)
            self.stream.write(line + "\n")
        self.stream.flush()


def csv_cell(v):
    if v is None:
        return ""
    if isinstance(v, float):
        return "" if math.isnan(v) else repr(v)
    return v


def md_cell(text):
    """Text for one cell of a Markdown table: a | would end the cell (a case label is
    "scene | scheme"), so it is escaped as \\|, which GitHub-flavoured Markdown shows as |
    (GFM spec, "Tables"); a line break would end the row, so it becomes a space."""
    return str(text).replace("|", "\\|").replace("\r", " ").replace("\n", " ")


def slug(text):
    keep = "".join(ch if ch.isalnum() else "_" for ch in text.lower())
    while "__" in keep:
        keep = keep.replace("__", "_")
    return keep.strip("_")


def palette_png(path, colors=64):
    """Rewrite a PNG with an adaptive palette (Pillow ships with matplotlib)."""
    try:
        from PIL import Image
    except ImportError:
        return
    with Image.open(path) as im:
        q = im.convert("RGB").quantize(colors=colors, method=Image.Quantize.MEDIANCUT)
    q.save(path, optimize=True)
