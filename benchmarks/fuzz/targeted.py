"""The targeted campaign (campaign.py --targeted): the bad inputs reviews found, each as a
command line with the outcome it must have — "ok", "clean error" (exit 1, one line, nothing
written) or "interrupted" (exit 130, one line) — and, for some, a pattern the message must not
hold (a Fortran ES edit's exponent without its E, "1.99-303"). Every case ends within its
timeout or counts as a hang. Run with `scripts/fuzz --targeted`."""

from __future__ import annotations

import json
from dataclasses import dataclass, field

if __package__:
    from . import mutations
else:
    import mutations  # noqa: E402 (campaign.py put this folder on the path)

BENCH = mutations.BENCHMARKS
RECORD = (mutations.ROOT / "tests" / "data" / "records" / "peer_fixed.AT2").read_text().splitlines()
# an exponent of 3 digits written without its E (what gfortran's ESw.d gives)
NO_E = r"\d[+-]\d{3}\b"


@dataclass
class Targeted:
    label: str
    argv: list
    expect: str                             # "ok", "clean error" or "interrupted"
    files: dict = field(default_factory=dict)
    output: str | None = None
    env: dict = field(default_factory=dict)
    timeout: float = 60.0
    sigint_after: float | None = None       # seconds after the start, to the process group
    forbid: str | None = None               # a regex the stderr must not match


def _scene(name, **edits):
    d = mutations.scene_dict(name)
    d.pop("check", None)
    for path, value in edits.items():
        node = d
        keys = path.split(".")
        for k in keys[:-1]:
            node = node[int(k)] if isinstance(node, list) else node[k]
        node[keys[-1]] = value
    return mutations.to_toml(d).encode()


def _sdof(record):
    d = {"node": [{"name": "m", "mass": 1.0}],
         "link": [{"type": "spring", "a": "m", "b": "ground", "k": 100.0}],
         "loads": {"ground_acceleration": {"type": "record", "file": record}},
         "analysis": {"type": "dynamic", "integrator": "newmark", "dt": 0.01, "t_end": 0.04}}
    return mutations.to_toml(d).encode()


def _study(reference=None, extra=""):
    text = (f'title = "targeted"\n{extra}[[scene]]\nfile = "{BENCH / "p2" / "p2_penalty_linear.toml"}"\n'
            + (f'reference = {reference}\n' if reference else "")
            + 't_end = 0.1\n[[integrator]]\nname = "newmark"\ndt = [1e-3, 5e-4]\n')
    return text.encode()


def _reference_case(label, meta, history):
    files = {"st.toml": _study('{ data = "ref" }'), "ref/reference.json": meta,
             "ref/history.csv": history}
    return Targeted(label, ["study", "st.toml", "-o", "out", "--no-plots"], "clean error",
                    files, "out")


GOOD_HISTORY = b"t,u:mass\n" + b"".join(f"{i * 0.01:.6g},{0.05 - 1e-4 * i:.6g}\n".encode()
                                        for i in range(101))
RUN = {"summary.json": json.dumps(mutations.RUN_SUMMARY).encode(),
       "history.csv": mutations.RUN_HISTORY.encode()}


def _plot_case(label, name, data):
    files = {f"f/{k}": v for k, v in RUN.items()}
    files[f"f/{name}"] = data
    return Targeted(label, ["plot", "f", "-o", "pics", "--format", "png"], "clean error", files, "pics")


def _frame(width):
    return _scene("p10/p10_bare", **{"frame.0.bay_width": width})


def _chain():
    text = (BENCH / "p7" / "p7_chain_10.toml").read_text()
    return "\n".join("k = 1e308" if ln.startswith("k = [") else ln
                     for ln in text.splitlines() if not ln.startswith("[check")).encode()


def _msbdf_rod():
    text = (BENCH / "p4" / "p4_equal_rods_rk8pd_restitution_e0.toml").read_text()
    return text.replace('integrator = "rk8pd"', 'integrator = "msbdf"').split("[check]")[0].encode()


STIFF_IDA = mutations.to_toml({
    "node": [{"name": "m", "mass": 1.0, "u0": 0.01}],
    "link": [{"type": "spring", "a": "m", "b": "ground", "k": 1e14}],
    "analysis": {"type": "dynamic", "integrator": "ida", "dt": 1e-3, "t_end": 10.0}}).encode()


def cases():
    meta = json.dumps({"t_end": 1.0}).encode()
    at2 = lambda line4: ("\n".join(RECORD[:3] + [line4] + RECORD[4:]) + "\n").encode()  # noqa: E731
    out = [
        _reference_case("study reference: {} (was KeyError 't_end')", b"{}", GOOD_HISTORY),
        _reference_case("study reference: a list (was TypeError)", b"[1, 2]", GOOD_HISTORY),
        _reference_case("study reference: a non-number in history.csv (was ValueError)", meta,
                        GOOD_HISTORY.replace(b"0.0499", b"x.0499", 1)),
        _reference_case("study reference: history.csv cut short", meta,
                        GOOD_HISTORY[:GOOD_HISTORY.index(b",", 300) + 1]),
        _reference_case("study reference: reference.json is /dev/zero (no size cap)", "->/dev/zero",
                        GOOD_HISTORY),
        _plot_case("plot: summary.json cut short (was JSONDecodeError)", "summary.json",
                   RUN["summary.json"][:40]),
        _plot_case("plot: history.csv cut short (was ValueError)", "history.csv",
                   RUN["history.csv"][:RUN["history.csv"].index(b",", 500) + 1]),
        _plot_case("plot: history.csv edited (was ValueError)", "history.csv",
                   RUN["history.csv"].replace(b"\n0.002,", b"\nzero,", 1)),
        Targeted("frame: bay_width = 1e300 (was OverflowError)", ["run", "s.toml", "-o", "out"],
                 "clean error", {"s.toml": _frame(1e300)}, "out"),
        Targeted("frame: bay_width = 1e-300 (was ZeroDivisionError)", ["run", "s.toml", "-o", "out"],
                 "clean error", {"s.toml": _frame(1e-300)}, "out"),
        # session 5: buildings, export, compare's recorder columns
        Targeted("building: storey_height = 1e-300 (was ZeroDivisionError)", ["run", "s.toml", "-o", "out"],
                 "clean error", {"s.toml": _scene("p11/p11_eccentric_storey", **{"building.0.storey_height": 1e-300})},
                 "out"),
        Targeted("building: a floor of 1e-12 kg (zero frequency, NaN damping, numpy warnings)",
                 ["run", "s.toml", "-o", "out"], "clean error",
                 {"s.toml": _scene("p11/p11_shear_pounding", **{"building.0.mass": [1e-12, 1.5e5]})},
                 "out", forbid="RuntimeWarning"),
        Targeted("export --dt 0 (was ZeroDivisionError)", ["export", str(BENCH / "p5" / "p5_linear.toml"),
                                                           "--dt", "0", "-o", "ex"], "clean error", output="ex"),
        Targeted("export --integrator hht --alpha 5 (was written)",
                 ["export", str(BENCH / "p5" / "p5_linear.toml"), "--integrator", "hht", "--alpha", "5",
                  "-o", "ex"], "clean error", output="ex"),
        Targeted("export --tol -1 (was written)", ["export", str(BENCH / "p5" / "p5_linear.toml"),
                                                   "--tol", "-1", "-o", "ex"], "clean error", output="ex"),
        Targeted("chain: k = 1e308, mass = 1e5 (numpy warnings, no field)", ["run", "s.toml", "-o", "out"],
                 "clean error", {"s.toml": _chain()}, "out", forbid="RuntimeWarning"),
        Targeted("a 3-digit exponent in a library message (was 7.000+299 steps)",
                 ["run", "s.toml", "-o", "out", "--force"], "clean error",
                 {"s.toml": _scene("p5/p5_linear", **{"analysis.t_end": 7e299})}, "out", forbid=NO_E),
        Targeted("-o '' (was the default folder)", ["run", str(BENCH / "p1" / "p1_static_lagrange.toml"),
                                                     "-o", ""], "clean error"),
        Targeted("PEER AT2 with a subnormal DT (was accepted)", ["run", "s.toml", "-o", "out"],
                 "clean error", {"s.toml": _sdof("r.AT2"), "r.AT2": at2("    23    5e-324    NPTS, DT")},
                 "out"),
        Targeted("record starting before t = 0 (was accepted)", ["run", "s.toml", "-o", "out"],
                 "clean error", {"s.toml": _sdof("r.csv"), "r.csv": b"-1.0, 0.5\n0.0, 0.5\n0.01, 0\n"},
                 "out"),
        Targeted("record starting after t_end (was accepted)", ["run", "s.toml", "-o", "out"],
                 "clean error", {"s.toml": _sdof("r.csv"), "r.csv": b"0.05, 0.5\n0.06, 0.5\n"}, "out"),
        Targeted("-o a symlink to a folder (was 'not a folder')",
                 ["run", str(BENCH / "p1" / "p1_static_lagrange.toml"), "-o", "link"], "ok",
                 {"real": "dir", "link": "->real"}),
        Targeted("--help without the library (was a traceback)", ["--help"], "ok",
                 env={"MARTELLO_LIB": "/nonexistent/libmartello.so"}),
        Targeted("a command without the library", ["list"], "clean error",
                 env={"MARTELLO_LIB": "/nonexistent/libmartello.so"}),
        Targeted("an unloadable library", ["list"], "clean error", {"lib.so": b"not a library"},
                 env={"MARTELLO_LIB": "lib.so"}),
        Targeted("study file naming a scheduler, no flag (was connected to)",
                 ["study", "st.toml", "-o", "out", "--no-plots", "-j", "1"], "ok",
                 {"st.toml": _study(extra='scheduler = "tcp://127.0.0.1:9"\n')}),
        Targeted("study file naming a scheduler, --use-study-scheduler, nothing there",
                 ["study", "st.toml", "-o", "out", "--no-plots", "--use-study-scheduler"],
                 "clean error", {"st.toml": _study(extra='scheduler = "tcp://127.0.0.1:9"\n')}, "out",
                 timeout=120),
        Targeted("msbdf on the 100-element P4 rod (was 300 s without a word)",
                 ["run", "s.toml", "-o", "out", "--progress"], "clean error", {"s.toml": _msbdf_rod()},
                 "out", timeout=120),
        Targeted("IDA on a 1e14 N/m spring, no step cap (was 300 s without a word)",
                 ["run", "s.toml", "-o", "out", "--progress"], "clean error", {"s.toml": STIFF_IDA},
                 "out", timeout=120),
    ]
    # Ctrl-C at moments spread over a command's start (the imports, the library, the run)
    for t in (0.3, 0.5, 0.8, 1.2):
        out.append(Targeted(f"Ctrl-C {t} s after the start (was a traceback in the first 0.8 s)",
                            ["run", "s.toml", "-o", "out", "--force"], "interrupted",
                            {"s.toml": _scene("p2/p2_restitution_e08", **{"analysis.dt": 1e-7})},
                            "out", sigint_after=t))
    for t in (3.0, 6.0):
        out.append(Targeted(f"Ctrl-C {t} s into a study (SIGINT to its group)",
                            ["study", "st.toml", "-o", "out", "--no-plots", "-j", "2"],
                            "interrupted", {"st.toml": _study().replace(
                                b"dt = [1e-3, 5e-4]", b"dt = { from = 1e-4, to = 1e-7, per_decade = 8 }"
                            ).replace(b"t_end = 0.1", b"t_end = 0.7")},
                            None, sigint_after=t))
    return out
