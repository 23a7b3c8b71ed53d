"""The folders the package reads: the catalogue (benchmarks/), the stored reference data
(reference/) and the native library, and how the package reads an input file and
replaces an output file.

Two layouts (docs/install.md):

* a checkout of the repository (also an editable install of it): the repository's
  benchmarks/ and reference/, and the CMake build tree's build/libmartello.so;
* an installed wheel: the same folders as package data, martello/data/benchmarks and
  martello/data/reference, and the library in martello/_native/lib/.

``REPO`` is the folder that holds benchmarks/ and reference/ in either layout: paths in the
catalogue and in reference/references.toml (``benchmarks/p2/...``) are relative to it.

An input file (scene, record, history, study) must be a regular file of bounded size: a
directory, a FIFO, a socket or a device is refused from its stat(2) mode without being
opened for reading (opening a FIFO blocks until a writer comes; /dev/zero never ends), and
so is a file larger than its reader's limit (docs/behaviour.md, "Failures and limits")."""

import fcntl
import os
import shutil
import stat
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent
_DATA = PACKAGE / "data"
INSTALLED = (_DATA / "benchmarks").is_dir()
REPO = _DATA if INSTALLED else PACKAGE.parent
BENCHMARKS = REPO / "benchmarks"
REFERENCE_ROOT = REPO / "reference"
# A study's `output` folder is relative to the repository in a checkout, to the working
# directory when installed (never inside site-packages).
OUTPUT_ROOT = Path(".") if INSTALLED else REPO
# The native library, the first that exists: the wheel's, then the checkout's build tree.
LIBRARIES = (PACKAGE / "_native" / "lib" / "libmartello.so",
             PACKAGE.parent / "build" / "libmartello.so")

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


def check_output_folder(outdir, marker, refuse):
    """What folder_replaced will demand of outdir, checked before the work that fills it (a
    run of an hour must not end in "-o names a file"): outdir is absent, or a folder that is
    empty or holds `marker`; its first existing ancestor is a folder we may write in.
    A symbolic link to a folder stands for that folder (the output replaces the folder and
    the link keeps pointing at it). Returns outdir made absolute (a link resolved);
    refuse(text) otherwise. Nothing is created."""
    outdir = Path(os.path.abspath(outdir))
    if outdir.is_symlink() and outdir.is_dir():
        outdir = outdir.resolve()        # a link to a folder: the folder is the output's
    if not outdir.name:
        raise refuse(f"{outdir}: cannot be an output folder (give a folder to create)")
    if outdir.is_symlink():
        raise refuse(f"{outdir}: is a symbolic link to no folder (-o names the folder the "
                     "results go to: give a new folder, or an earlier one of the same command)")
    if outdir.exists():
        if not outdir.is_dir():
            raise refuse(f"{outdir}: is not a folder (-o names the folder the results go to: "
                         "give a new folder, or an earlier one of the same command)")
        held = sorted(p.name for p in outdir.iterdir())
        if held and marker not in held:
            shown = ", ".join(held[:3]) + (", ..." if len(held) > 3 else "")
            raise refuse(f"{outdir}: holds files of something else ({shown}): the output "
                         "replaces its whole folder (give a new or empty folder, or an earlier "
                         "one of the same command)")
    above = outdir.parent
    while not (above.exists() or above.is_symlink()) and above != above.parent:
        above = above.parent
    if not above.is_dir():
        raise refuse(f"{outdir}: cannot create the output folder: {above} is not a folder "
                     "(give -o a path under a folder)")
    if not os.access(above, os.W_OK | os.X_OK):
        raise refuse(f"{outdir}: cannot create the output folder: {above} is not writable")
    return outdir


# A temporary folder is held by its writer with flock(2) on the folder while it writes; one
# that nobody holds is stale: its writer was killed (SIGKILL, the out-of-memory killer, a
# crash). The `.old` folder of the final swap is never held: it exists for the moment of two
# renames, so one that is an hour old is stale.
OLD_STALE_S = 3600.0


def _locked(path):
    """An open descriptor of the folder `path` holding an exclusive flock, or None if another
    process holds it (or it cannot be opened)."""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0) | getattr(os, "O_CLOEXEC", 0))
    except OSError:
        return None
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        os.close(fd)
        return None
    return fd


def stale_temporaries(outdir):
    """The temporary folders beside outdir (folder_replaced's `.NAME.*.tmp` and `.NAME.*.old`)
    whose writer is gone, oldest first."""
    outdir = Path(outdir)
    try:
        found = [p for p in outdir.parent.iterdir()
                 if p.name.startswith(f".{outdir.name}.") and p.name.endswith((".tmp", ".old"))
                 and p.is_dir() and not p.is_symlink()]
    except OSError:
        return []
    stale = []
    for p in found:
        if p.name.endswith(".old"):
            try:
                if time.time() - p.stat().st_mtime > OLD_STALE_S:
                    stale.append(p)
            except OSError:
                pass
            continue
        fd = _locked(p)
        if fd is not None:
            os.close(fd)
            stale.append(p)
    return sorted(stale, key=lambda p: p.stat().st_mtime if p.exists() else 0.0)


@contextmanager
def folder_replaced(outdir, marker, refuse):
    """Fill a folder that replaces outdir whole, atomically: the block gets a temporary folder
    beside outdir to write into; when it ends without an exception the temporary folder is
    renamed into place (an earlier outdir, stale files included, goes), so outdir holds one
    complete output or none; on an exception it is removed and outdir stays as it was.

    outdir may exist only as a folder that is empty or holds the file `marker` (an earlier
    output of the same kind); else, or if the folders cannot be made or renamed, refuse(text)
    is raised (an exception class taking the one-line message). Temporary folders of earlier
    writers that were killed (stale_temporaries) are removed first."""
    outdir = check_output_folder(outdir, marker, refuse)
    for stale in stale_temporaries(outdir):       # of writers killed before they finished
        shutil.rmtree(stale, ignore_errors=True)
    try:
        outdir.parent.mkdir(parents=True, exist_ok=True)
        tmp = Path(tempfile.mkdtemp(prefix=f".{outdir.name}.", suffix=".tmp", dir=outdir.parent))
    except OSError as exc:
        raise refuse(f"{outdir}: cannot create the output folder: {exc.strerror or exc}") from None
    held = _locked(tmp)          # ours until it is in place (stale_temporaries)
    try:
        try:
            yield tmp
        except BaseException:
            shutil.rmtree(tmp, ignore_errors=True)
            raise
        _into_place(tmp, outdir, refuse)
    finally:
        if held is not None:
            os.close(held)


def _into_place(tmp, outdir, refuse):
    """Rename the filled folder tmp to outdir, atomically replacing an earlier outdir."""
    old = None
    try:
        mask = os.umask(0)
        os.umask(mask)
        os.chmod(tmp, 0o777 & ~mask)
        if outdir.is_dir():
            old = Path(tempfile.mkdtemp(prefix=f".{outdir.name}.", suffix=".old", dir=outdir.parent))
            os.replace(outdir, old)      # onto the empty folder just made: atomic
        os.replace(tmp, outdir)
    except OSError as exc:
        shutil.rmtree(tmp, ignore_errors=True)
        if old is not None and not outdir.exists():
            os.replace(old, outdir)      # put the earlier output back
            old = None
        raise refuse(f"{outdir}: cannot write the results: {exc.strerror or exc}") from None
    finally:
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
