"""A sweep that stops when asked and resumes where it stopped (docs/studies.md, "Stop and
resume"): the studies and the atlas run through run_resumable.

While a sweep runs, each finished row is appended to a journal (resume.jsonl: one JSON object
a line, flushed at once) in the temporary folder that becomes its output
(martello.paths.folder_replaced). SIGINT (Ctrl-C, which a terminal sends to the whole
process group) or SIGTERM, to the group or to the main process, stops it: the rows already
finished are kept, the runs in flight are ended (martello.batch.run_specs), and the output
folder gets the rows so far, marked partial (the journal beside them), within about a
second. The same command then resumes: every row of the journal whose key matches a run of
the sweep is taken as it is, and only the other runs are run, so each row is computed once.
A sweep killed outright (SIGKILL, the out-of-memory killer) leaves its temporary folder with
its journal; the next run of the same command takes the rows from it, and removes it.

A row's key digests everything its values depend on (the run's scene and settings, the
case's labels and reference, the scoring, the martello version): a study file edited in
between keeps the rows it did not change and reruns the others. Every row, kept or new, is
the JSON round trip of the row as computed, so a resumed sweep writes the same bytes as an
uninterrupted one (tests/test_study_resume.py)."""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import signal
import sys
import threading
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from ..errors import MartelloError, Stopped
from ..paths import MiB, UnreadableFile, check_output_folder, folder_replaced, read_input, \
    stale_temporaries

JOURNAL = "resume.jsonl"
FORMAT = 1
JOURNAL_LIMIT = 1024 * MiB           # a journal larger than this is not read (not ours)


def row_key(*parts):
    """The key of a row: a digest of everything its values depend on."""
    text = json.dumps(parts, sort_keys=True, default=str, allow_nan=True)
    return hashlib.sha256(text.encode()).hexdigest()[:32]


def _plain(value):
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.floating):
        return float(value)
    if isinstance(value, (np.ndarray, tuple)):
        return list(value)
    raise TypeError(f"a row holds a {type(value).__name__}")


def plain(row):
    """The row as the journal gives it back (numpy scalars become Python numbers; NaN and
    inf are kept): what a resumed sweep has of a kept row, so what every row is."""
    return json.loads(json.dumps(row, default=_plain, allow_nan=True))


def read_journal(path, keys):
    """{key: row} of a journal, for the keys in `keys`; a line cut short (a sweep killed
    while writing it) ends the reading; a file that is not a journal gives nothing."""
    try:
        lines = read_input(path, JOURNAL_LIMIT).decode("utf-8", "replace").split("\n")
    except UnreadableFile:
        return {}
    try:
        head = json.loads(lines[0])
    except ValueError:
        return {}
    if not (isinstance(head, dict) and head.get("martello_journal") == FORMAT):
        return {}
    rows = {}
    for line in lines[1:]:
        try:
            item = json.loads(line)
            key, row = item["key"], item["row"]
        except (ValueError, TypeError, KeyError):
            break
        if key in keys and isinstance(row, dict):
            rows[key] = row
    return rows


def kept_rows(outdir, marker, keys):
    """{key: row} of earlier runs of the same sweep: the journal of a partial output in
    outdir, and those of the temporary folders beside it whose sweep was killed."""
    outdir = Path(outdir)
    found = {}
    for folder in stale_temporaries(outdir):
        found.update(read_journal(folder / JOURNAL, keys))
    if (outdir / marker).is_file():
        found.update(read_journal(outdir / JOURNAL, keys))
    return found


@contextmanager
def _signals(on_signal):
    """SIGINT and SIGTERM call on_signal(name) within the block (main thread only: elsewhere
    Python takes no handlers, and the defaults stay)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    old = {}
    handler = lambda signum, frame: on_signal(signal.Signals(signum).name)  # noqa: E731
    for sig in (signal.SIGINT, signal.SIGTERM):
        old[sig] = signal.signal(sig, handler)
    try:
        yield
    finally:
        for sig, h in old.items():
            signal.signal(sig, h)


def run_resumable(outdir, marker, keys, run, finish, partial, stream=None, what="runs"):
    """Run a sweep into outdir (martello.paths.folder_replaced, whose marker file tells an
    earlier output of the same kind), resumably.

    keys: {run id: key} of every run of the sweep, in order; run(ids, stop) yields
    (run id, row) as the runs of `ids` finish, and returns early once the threading.Event
    `stop` is set; finish(folder, rows) writes the complete output; partial(folder, rows)
    the rows of a sweep stopped before its end (rows: sorted by run id). Returns the rows;
    raises Stopped (after writing the partial output, if a row is finished) when a signal
    stopped the sweep, and writes the partial output before raising any other exception
    that ends it."""
    stream = stream or sys.stderr
    outdir = check_output_folder(outdir, marker, MartelloError)
    kept = kept_rows(outdir, marker, set(keys.values()))
    rows, stop, signalled, phase = {}, threading.Event(), [], ["run"]
    ordered = lambda: [rows[r] for r in sorted(rows)]               # noqa: E731

    def on_signal(name):
        signalled.append(name)
        stop.set()
        if phase[0] == "finish":     # past the runs: what is being written is not wanted
            raise KeyboardInterrupt

    def record(journal, rid, row):
        journal.write(json.dumps({"key": keys[rid], "row": row}, allow_nan=True) + "\n")
        rows[rid] = row

    completed, failure = False, None
    # the handlers span the folder's replacement too: a signal there cannot cut it short
    with _signals(on_signal), folder_replaced(outdir, marker, MartelloError) as tmp:
        with open(tmp / JOURNAL, "w", encoding="utf-8") as journal:
            journal.write(json.dumps({"martello_journal": FORMAT, "runs": len(keys)}) + "\n")
            for rid, key in keys.items():
                if key in kept:
                    record(journal, rid, dict(kept[key], run=rid))
            journal.flush()
            todo = [rid for rid in keys if rid not in rows]
            if rows:
                print(f"resuming: {len(rows)} of {len(keys)} {what} kept from an interrupted "
                      f"run of this command in {outdir}; {len(todo)} to run", file=stream)
            try:
                for rid, row in run(todo, stop):
                    record(journal, rid, plain(dict(row, run=rid)))
                    journal.flush()         # a kill a moment later keeps it
                if not stop.is_set():
                    phase[0] = "finish"
                    finish(tmp, ordered())
                    completed = True
            except KeyboardInterrupt:       # a signal while the output was being written
                stop.set()
            except Exception as exc:        # noqa: BLE001 - kept rows first, raised below
                failure = exc
            phase[0] = "saving"             # another Ctrl-C no longer interrupts
        if not completed:
            if not rows:
                raise failure or Stopped(f"interrupted ({signalled[0] if signalled else 'SIGINT'}) "
                                         f"before any of the {len(keys)} {what} finished: "
                                         "nothing written")
            for p in tmp.iterdir():         # what finish() may have begun
                if p.name != JOURNAL:
                    shutil.rmtree(p) if p.is_dir() else p.unlink()
            partial(tmp, ordered())
        else:
            os.unlink(tmp / JOURNAL)
    if completed:
        return ordered()
    left = len(keys) - len(rows)
    kept_text = (f"{len(rows)} of {len(keys)} {what} kept in {outdir}, marked partial (the same "
                 f"command runs the other {left})")
    if failure is not None:
        print(f"note: {kept_text}", file=stream)
        raise failure
    raise Stopped(f"interrupted ({signalled[0] if signalled else 'SIGINT'}): {kept_text}")
