"""The folders of the checkout that the package reads (the repository root, the benchmark
catalogue in benchmarks/, the stored reference data in reference/) and how the package reads
an input file and replaces an output file.

An input file (scene, record, history, study) must be a regular file of bounded size: a
directory, a FIFO, a socket or a device is refused from its stat(2) mode without being
opened for reading (opening a FIFO blocks until a writer comes; /dev/zero never ends), and
so is a file larger than its reader's limit (docs/behaviour.md, "Failures and limits")."""

import os
import stat
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
BENCHMARKS = REPO / "benchmarks"
REFERENCE_ROOT = REPO / "reference"

MiB = 1 << 20

_KINDS = ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
          (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
          (stat.S_ISSOCK, "a socket"))


class UnreadableFile(Exception):
    """An input file that cannot be read: `problem` says why, `fix` what to do. Callers turn
    it into their own error (SceneError, RecordError, ...), which names the field too."""

    def __init__(self, problem, fix=None):
        self.problem, self.fix = problem, fix
        super().__init__(problem + (f" ({fix})" if fix else ""))


def _not_regular(mode):
    for test, kind in _KINDS:
        if test(mode):
            return kind
    return None if stat.S_ISREG(mode) else "not a regular file"


def check_regular(path):
    """Raise UnreadableFile unless path names an existing regular file (stat only)."""
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise UnreadableFile("does not exist") from None
    except NotADirectoryError:
        raise UnreadableFile("does not exist (a part of the path is a file, not a folder)") from None
    except OSError as exc:
        raise UnreadableFile(f"cannot be examined: {exc.strerror or exc}") from None
    except ValueError:               # a NUL byte, which no path may hold
        raise UnreadableFile("is no valid path (it holds a NUL character)") from None
    kind = _not_regular(st.st_mode)
    if kind:
        raise UnreadableFile(f"is {kind}, not a regular file", "give the path of a file")
    return st


def read_input(path, limit):
    """The bytes of a regular file of at most `limit` bytes; UnreadableFile otherwise."""
    st = check_regular(path)
    if st.st_size > limit:
        raise UnreadableFile(f"is {st.st_size / MiB:.1f} MiB, more than the {limit / MiB:g} MiB "
                             "such a file may have", "is it the right file?")
    try:
        # O_NONBLOCK: should the path have become a FIFO since stat, open does not wait
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except OSError as exc:
        raise UnreadableFile(f"cannot be read: {exc.strerror or exc}",
                             "check the file's permissions") from None
    try:
        kind = _not_regular(os.fstat(fd).st_mode)
        if kind:
            raise UnreadableFile(f"is {kind}, not a regular file", "give the path of a file")
        chunks, size = [], 0
        while True:
            b = os.read(fd, 1 << 20)
            if not b:
                break
            size += len(b)
            if size > limit:
                raise UnreadableFile(f"is more than the {limit / MiB:g} MiB such a file may have",
                                     "is it the right file?")
            chunks.append(b)
        return b"".join(chunks)
    except OSError as exc:
        raise UnreadableFile(f"cannot be read: {exc.strerror or exc}") from None
    finally:
        os.close(fd)


def write_text_atomic(path, text):
    """Write text to path through a temporary file in the same folder and rename(2) it into
    place: a reader sees the old file or the new one, never a part of it. OSError on failure
    (the temporary file is removed)."""
    path = Path(path)
    if path.is_dir():
        raise IsADirectoryError(21, "is a directory", str(path))
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        with open(tmp, "w", encoding="utf-8") as fh:
            fh.write(text)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
