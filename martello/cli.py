"""The `martello` command line (git-like subcommands; exit code non-zero on any failure)."""

import argparse
import json
import os
import re
import sys
from pathlib import Path

from . import errors
from .errors import MartelloError

# Only the standard library and martello.errors here: each command imports what it needs when
# it runs (inside run_command's error handling), so that `martello --help` and a usage error
# need neither numpy nor the native library, and a missing or unloadable library, or a
# Ctrl-C while the modules load, is one line like every other failure.

DESCRIPTION = """\
martello: verification and benchmark suite for contact and impact in structural dynamics.

A scene (TOML, see docs/scene-input.md) describes a small 1D mechanical network: nodes
(lumped masses), links (springs, dampers, bars), contacts (lagrange, penalty,
augmented-lagrange, restitution), loads, and the analysis to run. The catalogue in
benchmarks/ holds the canonical problems with their closed-form references.

examples:
  martello list                               the catalogue, one line per scene
  martello run benchmarks/p1/p1_static_lagrange.toml -o out/p1
                                              run one scene, write summary.json
  martello check                              run the catalogue against its closed forms
"""


def cmd_list(args):
    from .scene import catalogue
    from .scene.loader import load
    files = catalogue.scene_files()
    if not files:
        print("the catalogue is empty")
        return 0
    width = max(len(str(f.relative_to(catalogue.ROOT.parent))) for f in files)
    for f in files:
        s = load(f)
        schemes = ",".join(sorted({c["scheme"] for c in s.contacts})) or "-"
        print(f"{str(f.relative_to(catalogue.ROOT.parent)):<{width}}  {s.problem or '-':<4} "
              f"{s.analysis['type']:<8} {schemes:<22} {s.title}")
    return 0


def cmd_run(args):
    from .binding import native
    from .checks.measures import run_measured
    from .scene import catalogue
    from .scene.loader import load
    from .run import write_results
    from .run import check_budget
    from .errors import ResultError
    from .paths import check_output_folder
    s = load(catalogue.find(args.scene))   # a file, or a path in the catalogue
    for w in check_budget(s, force=args.force):     # steps and output size, before running
        print(f"warning: {w}", file=sys.stderr)
    out = Path(args.output) if args.output else Path("out") / Path(args.scene).stem
    check_output_folder(out, "summary.json", ResultError)   # refused before the run, not after it
    # default: on a terminal the line in place, in a log the sparse lines; --progress: a line
    # every few seconds in a log too; --no-progress: none
    line = None if args.progress is False else ProgressLine(sys.stderr, sparse=args.progress is None)
    pace = None if args.force or s.analysis["type"] != "dynamic" else PaceLimit(
        s, s.analysis["integrator"] in native.adaptive_integrators())
    reporters = [r for r in (pace, line) if r is not None]

    def report(t, t_end, steps, elapsed):
        for r in reporters:
            r(t, t_end, steps, elapsed)
    try:
        with native.reporting(report if reporters else None):
            summary, history = run_measured(s)   # with the problem's measures (P4), as check does
    finally:
        if line:
            line.close()
    path = write_results(summary, out, history)
    for w in summary.get("warnings", []):
        print(f"warning: {w}", file=sys.stderr)
    files = [path] + ([path.parent / "history.csv"] if history is not None else []) \
        + ([path.parent / summary["arrays"]["file"]] if "arrays" in summary else [])
    written = ", ".join(map(str, files[:-1])) + " and " + str(files[-1]) if len(files) > 1 else str(path)
    print(f"{s.title}: {summary['status']} -> {written}")
    if args.print:
        print(json.dumps(summary, indent=2, default=float))
    return 0


class PaceLimit:
    """The estimate of a dynamic run's time from its pace, the budget of `martello run` that
    no count of steps gives up front for an adaptive integrator (its steps are its own) nor
    for a costly step: once a run has gone PILOT_S seconds, the time it would take at its
    pace so far (elapsed x t_end / t) is checked once; past BUDGET_S the run is stopped with
    a SceneError naming the setting to change, unless --force (then this is not called)."""

    PILOT_S, BUDGET_S = 10.0, 3600.0

    def __init__(self, scene, adaptive):
        self.scene, self.adaptive, self.checked, self.last = scene, adaptive, False, -1.0

    def __call__(self, t, t_end, steps, elapsed):
        if elapsed < self.last:          # the next run of the same command (P4's measures)
            self.checked = False
        self.last = elapsed
        if self.checked or elapsed < self.PILOT_S:
            return
        self.checked = True
        projected = elapsed * t_end / t if t > 0 else float("inf")
        if projected <= self.BUDGET_S:
            return
        key = "rtol" if self.adaptive else "dt"
        fix = ("loosen rtol, cap the step (h_max) or take another integrator"
               if self.adaptive else "raise dt, shorten t_end or take a cheaper integrator")
        raise errors.SceneError(
            self.scene.source, f"analysis.{key}",
            f"at its pace over its first {elapsed:.0f} s (t = {t:.4g} of {t_end:.4g} s, "
            f"{steps} steps) the run would take about {_duration(projected)}, more than the "
            f"{_duration(self.BUDGET_S)} a run may take without --force",
            f"{fix}; --force runs it anyway")


class ProgressLine:
    """The progress of a running dynamic run on a stream: simulated time, share of t_end,
    steps, rate and ETA. On a terminal, once the run has taken a second, one line rewritten in
    place (cleared when the run returns). Else (a log: nohup, a batch system) lines of their
    own with the time spent: every EVERY_PLAIN seconds when asked for (--progress), or, by
    default (sparse), at 30 s, 1, 2, 4 and 8 min, then every 5 min: a long run says it is alive
    and when it should end without filling the log (15 lines in its first hour), a run under
    30 s says nothing. It only reads the reports: the run is the same with or without it."""

    START, EVERY_PLAIN = 1.0, 5.0
    SPARSE_FIRST, SPARSE_CAP = 30.0, 300.0

    def __init__(self, stream, sparse=False):
        self.stream, self.tty = stream, stream.isatty()
        self.sparse = sparse and not self.tty
        self.shown, self.last = False, -1.0
        self.next = self.SPARSE_FIRST if self.sparse else self.START

    def __call__(self, t, t_end, steps, elapsed):
        if elapsed < self.last:          # the next run of the same command (P4's measures)
            self.next = self.SPARSE_FIRST if self.sparse else self.START
        self.last = elapsed
        if elapsed < self.next:
            return
        if self.sparse:                  # the gap doubles, up to SPARSE_CAP
            self.next = elapsed + min(elapsed, self.SPARSE_CAP)
        elif not self.tty:
            self.next = elapsed + self.EVERY_PLAIN
        share = min(max(t / t_end, 0.0), 1.0) if t_end > 0 else 0.0
        rate = steps / elapsed if elapsed > 0 else 0.0
        eta = elapsed * (1.0 - share) / share if share > 0 else float("inf")
        line = (f"t = {t:.4g} of {t_end:.4g} s ({100 * share:.1f} %), {steps:.3g} steps, "
                f"{rate:.3g} steps/s, ETA {_duration(eta)}")
        if self.tty:
            self.stream.write("\r\033[K" + line)
            self.shown = True
        else:
            self.stream.write(f"{line} ({_duration(elapsed)} so far)\n")
        self.stream.flush()

    def close(self):
        if self.shown:
            self.stream.write("\r\033[K")
            self.stream.flush()


def _duration(s):
    if s != s or s == float("inf"):
        return "unknown"
    return f"{s:.0f} s" if s < 120 else f"{s / 60:.0f} min" if s < 7200 else f"{s / 3600:.1f} h"


def cmd_study(args):
    from .study import atlas, study_file, sweep
    return (atlas if study_file.file_kind(args.study) == "atlas" else sweep).main(args)


def cmd_compare(args):
    from . import compare
    return compare.main(args)


def cmd_plot(args):
    from . import plot
    return plot.main(args)


def cmd_reference(args):
    from .reference import cache
    return cache.main(args)


def cmd_check(args):
    from .report import check_catalogue
    from .scene import catalogue
    files = [catalogue.find(p) for p in args.scenes] if args.scenes else catalogue.scene_files()
    # a scene named on the command line must have something to verify
    ok = check_catalogue(files, Path(args.output), plots=not args.no_plots,
                         require_checks=bool(args.scenes))
    return 0 if ok else 1


def cmd_export(args):
    from . import export
    _check_export_flags(args)
    return export.main(args)


# The [analysis] keys `martello export` overrides, each with the integrator whose own key it
# is (None: every integrator's): checked against the scene spec's own domains (a scene with
# that value would be refused the same way), and not given to another integrator.
EXPORT_OVERRIDES = {"dt": None, "t_end": None, "beta": "newmark", "gamma": "newmark",
                    "alpha": "hht", "rho_inf": "generalized-alpha"}


def _check_export_flags(args):
    """The overrides of `martello export` one by one: finite, in the range a scene's
    [analysis] key has, for the integrator --integrator names; --tol > 0."""
    import math
    from .scene.spec import ANALYSIS_TYPES
    dynamic = ANALYSIS_TYPES["dynamic"]
    for key, owner in EXPORT_OVERRIDES.items():
        value = getattr(args, key)
        if value is None:
            continue
        flag = "--" + key.replace("_", "-")
        check, text = dynamic[key][2]
        if not (math.isfinite(value) and check(value)):
            raise errors.ExportError(f"{flag}: invalid value {value!r} (must be {text}, as "
                                     f"analysis.{key} of a scene)")
        if owner and args.integrator is not None and args.integrator != owner:
            raise errors.ExportError(f"{flag}: applies to --integrator {owner}, not "
                                     f"{args.integrator} (remove it, or give --integrator {owner})")
    if args.tol is not None and not (math.isfinite(args.tol) and args.tol > 0):
        raise errors.ExportError(f"--tol: invalid value {args.tol!r} (must be a number > 0: "
                                 "OpenSees' NormDispIncr tolerance in m)")


def cmd_testset(args):
    from . import testset
    return testset.main(args)


def _print_version(args):
    from .binding import native
    print(f"martello {native.version()} ({native.library_versions()})")
    return 0


REPORT = ("this is a bug in martello: please report it with the command and its input files; "
          "--debug shows the traceback")
MAX_JOBS = 256


class _Parser(argparse.ArgumentParser):
    """Usage errors in one line, exit code 1, like every other error."""

    def error(self, message):
        self.exit(1, f"{self.prog}: error: {_one_line(message)}{_dash_hint(message)} "
                     f"(see {self.prog} --help)\n")


_ARGV = []       # the command line main() parses, for _dash_hint


def _dash_hint(message):
    """`--columns -u:a` (a documented value: a leading - flips the sign) reads to argparse as
    an option with no value: say how to write it."""
    m = re.match(r"argument (\S+): expected one argument", message)
    if not m:
        return ""
    names = m.group(1).split("/")
    for flag, value in zip(_ARGV, _ARGV[1:]):
        # a value, not another option (-o, --force): -u:a, -1e-3
        if flag in names and re.match(r"-[^-]", value) and not re.fullmatch(r"-[A-Za-z]", value):
            return f" (a value that starts with '-' is written {names[-1]}={value})"
    return ""


def _one_line(text):
    return " ".join(str(text).split())


def _jobs(text):
    """-j/--jobs: 0 (all cores) to MAX_JOBS."""
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if not 0 <= n <= MAX_JOBS:
        raise argparse.ArgumentTypeError(f"{n} is not in 0 to {MAX_JOBS} (0: all cores)")
    return n


def _path(text):
    """A path argument (-o and the like): not empty (an empty -o used to mean the default)."""
    if not text:
        raise argparse.ArgumentTypeError("is empty (give a path, or leave the option out for "
                                         "the default)")
    return text


def _caused_by_interrupt(exc):
    if errors.sigint_seen:       # the exception came while a Ctrl-C was being delivered
        return True
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return True
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return False


def run_command(args):
    """Run the parsed command. Every failure ends as one line on stderr and exit code 1: the
    message of a MartelloError (input the user can fix, a failed run), a system error (a
    file that cannot be read or written, out of memory), or, for anything else, the
    exception with a request to report it (a bug); --debug raises it with its traceback."""
    errors.debug = args.debug
    try:
        code = args.func(args)
        sys.stdout.flush()       # here, not at exit: a reader that went away shows below
        return code
    except errors.Stopped as exc:
        print(f"martello: {_one_line(exc)}", file=sys.stderr)
        return 130
    except errors.Interrupted as exc:
        text = _one_line(exc)
        print(f"martello: {text[text.find('interrupted at'):]}: nothing written", file=sys.stderr)
        return 130
    except MartelloError as exc:
        print(f"martello: error: {_one_line(exc)}", file=sys.stderr)
    except KeyboardInterrupt:
        print("martello: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # the reader went away (`martello list | head`): stop quietly, as a tool killed by
        # SIGPIPE does (exit 128 + 13); stdout goes to devnull so that the flush at exit
        # cannot fail again (Python docs, signal module, "Note on SIGPIPE")
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    except Exception as exc:
        if args.debug:
            raise
        if _caused_by_interrupt(exc):
            # a Ctrl-C inside code that wraps what it catches (a class's __set_name__ while
            # a module loads turns it into a RuntimeError)
            print("martello: interrupted", file=sys.stderr)
            return 130
        if isinstance(exc, MemoryError):
            print("martello: error: out of memory (the scene asks for more than this machine "
                  "has: record less, or use fewer nodes)", file=sys.stderr)
        elif isinstance(exc, OSError) and exc.strerror:
            where = f": {exc.filename}" if exc.filename else ""
            print(f"martello: error: {exc.strerror}{where}", file=sys.stderr)
        else:
            print(f"martello: internal error: {type(exc).__name__}: {_one_line(exc)} ({REPORT})",
                  file=sys.stderr)
    return 1


def main(argv=None):
    parser = _Parser(prog="martello", description=DESCRIPTION,
                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="store_true",
                        help="print the versions of martello and the libraries it links")
    parser.add_argument("--debug", action="store_true",
                        help="show the traceback of an internal error (a bug to report)")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    p = sub.add_parser("list", help="list the benchmark catalogue, one line per scene")
    p.set_defaults(func=cmd_list)

    p = sub.add_parser("run", help="run one scene and write summary.json (and history.csv)",
                       description="Run the analysis a scene asks for and write its results: "
                       "summary.json (displacements, contact forces, penetrations, cost, "
                       "conditioning, provenance) and, for dynamic runs, history.csv.")
    p.add_argument("scene", help="scene file (TOML)")
    p.add_argument("-o", "--output", type=_path, help="output folder (default: out/<scene name>)")
    p.add_argument("--print", action="store_true", help="also print the summary")
    p.add_argument("--force", action="store_true",
                   help="run even if it needs more than 1e9 node-steps, writes more than 1 GB, or "
                   "at its pace over its first 10 s would take more than an hour")
    p.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                   help="a progress line on stderr for a run longer than a second, a line every 5 s "
                   "when stderr is not a terminal (default: on a terminal; in a log, such as "
                   "nohup's, a line at 30 s, 1, 2, 4, 8 min, then every 5 min)")
    p.set_defaults(func=cmd_run)

    p = sub.add_parser("check", help="verify scenes against their closed forms",
                       description="Run scenes (default: the whole catalogue), compare each "
                       "with the closed form named in its [check] table, print the "
                       "verification table and write report.md, verification.csv and plots. "
                       "Exit code 1 if any check fails.")
    p.add_argument("scenes", nargs="*", help="scene files (default: the catalogue)")
    p.add_argument("-o", "--output", type=_path, default="out/check", help="report folder (default: out/check)")
    p.add_argument("--no-plots", action="store_true", help="skip the PNG plots")
    p.set_defaults(func=cmd_check)

    p = sub.add_parser("study", help="run a sweep (scenes x integrators x steps) and plot it",
                       description="Run a study file (benchmarks/studies/*.toml): every scene x "
                       "scheme x integrator x step/tolerance it lists, in parallel, with a progress "
                       "bar; write a tidy CSV (one row per run) and work-precision and "
                       "error-vs-step plots with the measured orders.")
    p.add_argument("study", help="study file (TOML)")
    p.add_argument("-o", "--output", type=_path, help="output folder (default: out/studies/<name>)")
    p.add_argument("-j", "--jobs", type=_jobs, default=0,
                   help=f"parallel runs, 0 to {MAX_JOBS} (default 0: all cores)")
    p.add_argument("--scheduler", metavar="ADDRESS", help="run on the Dask cluster whose scheduler "
                   "is at ADDRESS (tcp://host:8786, or a scheduler file .json) instead of local "
                   "processes (docs/studies.md)")
    p.add_argument("--no-plots", action="store_true", help="skip the PNG plots")
    p.add_argument("--use-study-scheduler", action="store_true",
                   help="run on the Dask scheduler the study file names (its `scheduler`): "
                   "without this flag that key is not used, since Dask exchanges pickled objects "
                   "with the scheduler and a study file may come from anyone")
    p.set_defaults(func=cmd_study)

    p = sub.add_parser("compare", help="score another code's time history against a scene",
                       description="Score a foreign time history (CSV, columns documented in "
                       "docs/compare.md, or OpenSees recorder output) against martello's reference for a scene, with the same "
                       "metrics as the studies (max error, significant digits, peak and impact "
                       "errors).")
    p.add_argument("history", nargs="+", help="the other code's history: a CSV (docs/compare.md), "
                   "or OpenSees recorder files (whitespace-separated, time first), one or more")
    p.add_argument("--against", required=True, help="scene file (TOML) it claims to solve; without a "
                   "closed form or stored data its reference is computed and cached (martello reference)")
    p.add_argument("--columns", action="append", metavar="NAMES",
                   help="names of a recorder file's value columns, e.g. u:s1,-u:s2 (a leading - flips "
                   "the sign); once per recorder file, in order (default: u of the scene's free nodes)")
    p.add_argument("-o", "--output", type=_path, help="write the scores as JSON here")
    p.set_defaults(func=cmd_compare)

    p = sub.add_parser("plot", help="pictures of a run or a study folder (PNG and SVG)",
                       description="Plot a run folder (martello run: displacement and contact-force "
                       "histories, phase portraits, force against penetration, hysteresis loops of "
                       "the links it wrote, energy terms) or a study folder (martello study: error "
                       "against the step and work-precision, per case). See docs/plot.md.")
    p.add_argument("folder", help="a folder written by martello run or martello study")
    p.add_argument("-o", "--output", type=_path, help="folder for the pictures (default: FOLDER/plots)")
    p.add_argument("--format", default="png,svg", help="png, svg or png,svg (default)")
    p.add_argument("--nodes", help="nodes to plot, e.g. s1,s2 (default: the first six)")
    p.add_argument("--contacts", help="contacts to plot (default: the first six)")
    p.add_argument("--metric", help="study error to plot (default: max_rel_error)")
    p.set_defaults(func=cmd_plot)

    p = sub.add_parser("reference", help="compute (or take from the cache) a scene's reference history",
                       description="Compute a reference history for any dynamic scene with the most "
                       "accurate methods that run it (rk8pd with event location, the independent "
                       "scipy engine, Newmark at a small step), state the digits it can be trusted "
                       "to (refinement and a second method) and its provenance, and cache it per "
                       "scene physics in $MARTELLO_CACHE_DIR (default $XDG_CACHE_HOME/martello or "
                       "~/.cache/martello). See docs/reference.md.")
    p.add_argument("scene", help="scene file (TOML)")
    p.add_argument("-o", "--output", type=_path, help="folder for history.csv and reference.json "
                   "(default: out/reference/<scene name>)")
    p.add_argument("--every", type=float, help="spacing of the stored samples in s "
                   "(default: the scene's output interval, 1000 to 20000 samples)")
    p.add_argument("--refresh", action="store_true", help="recompute even if the cache has it")
    p.add_argument("-j", "--jobs", type=int, default=0, help="parallel runs (default: all cores)")
    p.set_defaults(func=cmd_reference)

    p = sub.add_parser("export", help="write a scene as a model for another code (OpenSees)",
                       description="Write a standalone OpenSeesPy script DIR/model.py (and with --tcl "
                       "DIR/model.tcl) that rebuilds the scene in OpenSees and, run inside DIR, writes "
                       "DIR/history.csv in the format martello compare reads (a [[building]] also "
                       "DIR/members.csv, its members' M2, M3; `python model.py --periods` writes "
                       "DIR/periods.csv instead). What OpenSees cannot "
                       "express is refused naming what and why; each mapping and its differences are "
                       "in the script's header and docs/opensees.md.")
    p.add_argument("scene", help="scene file (TOML), or a path in the catalogue")
    p.add_argument("--to", default="opensees", help="the other code (default and only: opensees)")
    p.add_argument("-o", "--output", type=_path, required=True, help="folder for model.py (replaced whole)")
    p.add_argument("--tcl", action="store_true", help="also write model.tcl for OpenSees' Tcl interpreter")
    p.add_argument("--integrator", help="override the scene's integrator (newmark, hht, "
                   "generalized-alpha, central-difference)")
    p.add_argument("--dt", type=float, help="override the step [s]")
    p.add_argument("--t-end", type=float, help="override the end time [s]")
    p.add_argument("--beta", type=float, help="Newmark beta (with --integrator newmark)")
    p.add_argument("--gamma", type=float, help="Newmark gamma (with --integrator newmark)")
    p.add_argument("--alpha", type=float, help="HHT alpha in [-1/3, 0] (with --integrator hht)")
    p.add_argument("--rho-inf", type=float, help="generalized-alpha rho_inf in [0, 1]")
    p.add_argument("--material", action="append", metavar="LAW=MATERIAL",
                   help="map a law onto another OpenSees material (docs/opensees.md), e.g. "
                   "kelvin=JankowskiImpact; a change of law is stated on stderr")
    p.add_argument("--tol", type=float, help="NormDispIncr tolerance in m (default: the scene's "
                   "tol_increment x 0.1 m)")
    p.add_argument("--force", action="store_true", help="write a model of more steps than the "
                   "budget of martello run (1e9 node-steps)")
    p.set_defaults(func=cmd_export)

    p = sub.add_parser("testset", help="write the pounding test set: a JSON file and a page per problem",
                       description="Write the machine-readable pounding test set (docs/testset.md): for "
                       "every catalogue scene with a closed-form [check], DIR/<id>.json (the model in "
                       "neutral terms, parameters and units, reference values with trusted digits, "
                       "tolerance kinds, provenance) and DIR/<id>.md (its page), plus index.json and "
                       "README.md, versioned with martello.")
    p.add_argument("scenes", nargs="*", help="scene files (default: the catalogue)")
    p.add_argument("-o", "--output", type=_path, required=True, help="folder of the set (replaced whole)")
    p.add_argument("--run", action="store_true", help="also run each scene and add martello's own "
                   "values as regression tolerances")
    p.set_defaults(func=cmd_testset)

    p = sub.add_parser("version", help="versions of martello and the libraries it links")
    p.set_defaults(func=_print_version)

    for p in sub.choices.values():      # --debug after the command too
        p.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                       help=argparse.SUPPRESS)
    _ARGV[:] = sys.argv[1:] if argv is None else list(argv)
    args = parser.parse_args(argv)
    if args.version:
        args.command, args.func = "version", _print_version
    if not args.command:
        parser.print_help()
        return 2
    return run_command(args)


if __name__ == "__main__":
    sys.exit(main())
