"""Exceptions the command line reports as one clear message, without a traceback.

Anything else that reaches the command line is a bug; it is reported in one line too, with a
request to report it (martello.cli.main; the traceback with --debug). `debug` is set by
--debug, for the layers that catch errors of their own (martello check, per scene)."""

debug = False
# Set by the `martello` command's first SIGINT handler (martello.__main__): a Ctrl-C while
# modules load may come back as another exception (numpy turns it into an ImportError that
# does not chain it), which the command line then reports as the interrupt it was.
sigint_seen = False


def record_sigint(signum, frame):
    """The `martello` command's SIGINT handler until a layer installs its own: Python's
    default (KeyboardInterrupt), the signal recorded in sigint_seen."""
    global sigint_seen
    sigint_seen = True
    import signal
    signal.default_int_handler(signum, frame)


def forget_handled_interrupts():
    """Tell the interpreter that no KeyboardInterrupt went unhandled: the `martello` command
    handles every one. CPython up to 3.13 marks a KeyboardInterrupt that leaves code run from
    a string (the exec/eval by which namedtuple and dataclasses build methods while modules
    load) as unhandled even when it is caught, and under `python -m` the process then ends by
    SIGINT instead of with its exit code 130; running code from a string clears the mark there
    (later versions mark only one that reaches the top). docs/behaviour.md, "A Ctrl-C at any
    moment"."""
    try:
        exec("pass", {})
    except KeyboardInterrupt:       # a second Ctrl-C just now: leave it to end the process
        pass


class MartelloError(Exception):
    """Base class: anything the user can fix (bad input, impossible request, failed run)."""


class SceneError(MartelloError):
    """A scene file is invalid. The message names the file, the field and what would be valid."""

    def __init__(self, file, field, problem, fix=None):
        self.file, self.field, self.problem, self.fix = str(file), field, problem, fix
        msg = f"{self.file}: {field}: {problem}"
        if fix:
            msg += f" ({fix})"
        super().__init__(msg)


class StudyError(MartelloError):
    """A study or atlas file is invalid: the message names the file, the field and what is
    valid."""

    def __init__(self, file, field, problem, fix=None):
        msg = f"{file}: {field}: {problem}" + (f" ({fix})" if fix else "")
        super().__init__(msg)


class RecordError(MartelloError):
    """A ground-motion record (CSV or PEER AT2) is unreadable or inconsistent."""

    def __init__(self, file, problem, line=None, fix=None):
        self.file, self.problem, self.line, self.fix = str(file), problem, line, fix
        where = f"{self.file}:{line}" if line is not None else self.file
        msg = f"{where}: {problem}"
        if fix:
            msg += f" ({fix})"
        super().__init__(msg)

    def within(self, scene, field, given):
        """The same error, naming the scene, its field and the record's path as the scene
        gives it (relative to the scene's folder) instead of the path as resolved."""
        return RecordError(f"{scene}: {field}: {given}", self.problem, self.line, self.fix)


class ResultError(MartelloError):
    """A run's results cannot be written: a number that is not finite, or an output folder
    that cannot take them. Nothing is written."""


class ExportError(MartelloError):
    """A scene cannot be written for another code (martello export): the message names what
    the other code cannot express and why. Nothing is written."""


class SolverError(MartelloError):
    """The native library returned a failure status."""

    def __init__(self, status, name, message):
        self.status, self.name = status, name
        super().__init__(f"{name} ({status}): {message}")


class DivergenceError(SolverError):
    """A run diverged (NaN, energy growth beyond the input, step past the stability limit).

    Its partial results are never written out as if they were a result."""


class Interrupted(SolverError):
    """The run was stopped by the user (Ctrl-C, through the native loop's progress callback):
    nothing it computed is a result. The command line exits 130."""


class Stopped(Exception):
    """A sweep (a study, an atlas) stopped by SIGINT or SIGTERM, its finished rows kept in its
    output folder marked partial (martello.study.resume): the message says how many and where.
    Not a MartelloError: the command line exits 130 with the message, not 1 with an error."""
