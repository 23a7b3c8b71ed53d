"""Out of memory is an error the user can read (docs/behaviour.md "When memory runs out"): a
scene whose arrays do not fit ends as one line naming what could not be allocated, how much
and the fix, exit status 1, nothing written — not a runtime abort.

The memory is really taken away: the run is a subprocess whose address space is capped
(RLIMIT_AS), so the allocation in the kernel fails as it would on a machine that is too
small. Under AddressSanitizer (scripts/sanitize preloads it) an address-space cap would stop
the sanitizer itself, which reserves terabytes of shadow memory at start: there the cap is
ASan's own, max_allocation_size_mb with allocator_may_return_null, and the kernel sees the
same NULL from malloc.

Kind of evidence: behaviour checks (status, message, files), not numerical verification.
The amounts in the messages are checked against the array sizes counted here by hand."""

import os
import re
import resource
import subprocess
import sys

import pytest


# The cap is the peak address space of the same command on a small scene (everything loaded;
# measured in the test, as /proc/self/status VmPeak: 170 MB for the Release build on the
# reference machine, both integrators) plus MARGIN_MB. The large scene (n = 12 000) needs
# little more than the small one before its first large array: its loader, model and
# observer arrays are O(n) (a whole Newmark run of it peaks at 176 MB against the small
# scene's 170 MB, measured the same way), while that array alone is 1.15 GB (n² doubles:
# fast-nonlinear's K_L; the event-driven columns M⁻¹ B_jᵀ of n − 1 contacts), more than twice
# MARGIN_MB. So the allocation that fails is that one, on any machine.
MARGIN_MB = 512
N = 12_000

# The small run reports its peak address space (Linux /proc) on its last stderr line.
PROBE = ("import sys\nfrom martello.cli import main\nrc = main(sys.argv[1:])\n"
         "peak = [l for l in open('/proc/self/status') if l.startswith('VmPeak:')][0]\n"
         "print('peak', peak.split()[1], file=sys.stderr)\nsys.exit(rc)\n")


def scene(n, integrator, chain_extra=""):
    return f"""title = "a chain of {n} oscillators"
[[chain]]
prefix = "s"
n = {n}
mass = 1.0
k = 100.0
u0 = 0.001
{chain_extra}
[analysis]
type = "dynamic"
integrator = "{integrator}"
dt = 1.0e-3
t_end = 1.0e-3
[analysis.output]
nodes = ["s1"]
contacts = []
"""


# AddressSanitizer's report of an allocation it refused (allocator_may_return_null)
ASAN_REFUSED = r"==\d+==WARNING: AddressSanitizer failed to allocate 0x([0-9a-f]+) bytes"


def under_asan():
    return "libasan" in os.environ.get("LD_PRELOAD", "")


def run(args, cwd, cap_mb=None):
    """martello in a subprocess; cap_mb: the memory it may take (see the module's docstring)."""
    env = dict(os.environ)
    preexec = None
    if cap_mb is not None:
        if under_asan():
            env["ASAN_OPTIONS"] = (env.get("ASAN_OPTIONS", "") + ":allocator_may_return_null=1"
                                   f":max_allocation_size_mb={MARGIN_MB}").lstrip(":")
        else:
            cap = cap_mb * 2**20

            def preexec():
                resource.setrlimit(resource.RLIMIT_AS, (cap, resource.getrlimit(resource.RLIMIT_AS)[1]))
    return subprocess.run(args, cwd=cwd, env=env, capture_output=True, text=True, timeout=600,
                          stdin=subprocess.DEVNULL, preexec_fn=preexec)


@pytest.mark.parametrize("integrator, chain_extra, first_failed, expected", [
    # fortran/fast_nonlinear.f90: K_L (the first to fail), C_L, M and the modes, n × n doubles
    # each, and 20 n modal and 5 (n + 1) node vectors: 4.6 GB in one allocate
    ("fast-nonlinear", "", 8 * N * N,
     r"out of memory allocating the modal matrices of fast-nonlinear for 12000 free nodes "
     r"\(4\.6 GB\): .*use fewer nodes"),
    # c/event_driven.c: the columns M⁻¹ B_jᵀ of the 11 999 Lagrange contacts, n × 11 999
    # doubles (1.152 GB)
    ("rkf45", 'gap = 0.01\ncontact = { scheme = "lagrange", restitution = 0.5 }', 8 * N * (N - 1),
     r"out of memory allocating an array of the event-driven state for a scene of 12000 nodes "
     r"and 11999 contacts \(1\.2 GB\): use a smaller scene"),
])
def test_a_scene_too_large_for_memory_is_one_line_exit_1_nothing_written(
        tmp_path, integrator, chain_extra, first_failed, expected):
    small, large = tmp_path / "small.toml", tmp_path / "large.toml"
    small.write_text(scene(100, integrator, chain_extra))
    large.write_text(scene(N, integrator, chain_extra))

    r = run([sys.executable, "-c", PROBE, "run", small, "-o", tmp_path / "small"], tmp_path)
    assert r.returncode == 0, r.stderr
    peak_mb = int(r.stderr.split()[-1]) // 1024
    assert (tmp_path / "small" / "summary.json").is_file()

    out = tmp_path / "large"
    r = run([sys.executable, "-m", "martello", "run", large, "-o", out], tmp_path,
            cap_mb=peak_mb + MARGIN_MB)
    lines = r.stderr.splitlines()
    if under_asan():
        # the sanitizer reports the NULL it returned (allocator_may_return_null): its line,
        # not ours, and it shows which allocation failed
        refused = [ln for ln in lines if re.fullmatch(ASAN_REFUSED, ln)]
        assert [int(re.fullmatch(ASAN_REFUSED, ln)[1], 16) for ln in refused] == [first_failed]
        lines = [ln for ln in lines if ln not in refused]
    assert r.returncode == 1, r.stderr[-2000:]
    assert len(lines) == 1, r.stderr[-2000:]
    assert re.fullmatch(r"martello: error: MARTELLO_ERR_MEMORY \(-2\): dynamic run: " + expected
                        + r".*", lines[0]), lines[0]
    assert r.stdout == ""
    assert not out.exists() or not any(out.iterdir())


def test_the_c_integrators_and_the_kernels_say_it_alike():
    """One wording: the C integrators' line is the kernels' (martello_memory_message), the
    amount in the largest unit that keeps it >= 1, or left out when not known."""
    from martello.binding.native import memory_message
    assert memory_message("the columns of 3 contacts", 1.5e9) == \
        "out of memory allocating the columns of 3 contacts (1.5 GB): use a smaller scene " \
        "(fewer nodes, links or contacts)"
    assert memory_message("x", 2.5e6, "record less") == "out of memory allocating x (2.5 MB): record less"
    assert memory_message("x", 999) .startswith("out of memory allocating x (999 bytes): ")
    assert memory_message("the GSL driver", -1, "use less") == \
        "out of memory allocating the GSL driver: use less"


def test_a_ground_motion_function_out_of_memory_says_the_same_line():
    """c/ground_motion.c returns MARTELLO_ERR_MEMORY without a message (its public API has
    none): the binding says the library's line for the record's workspace. A mapping check
    (the status given, not memory taken away)."""
    from martello.binding.ground_motion import check_status
    from martello.binding.native import constant
    from martello.errors import SolverError
    with pytest.raises(SolverError) as e:
        check_status(constant("MARTELLO_ERR_MEMORY"), "response spectrum", 4096)
    assert str(e.value) == ("MARTELLO_ERR_MEMORY (-2): out of memory allocating the workspace of "
                            "the response spectrum of a record of 4096 samples: use a shorter "
                            "record (fewer samples)")
    assert check_status(0, "response spectrum", 4096) == 0


# The library call a test takes memory away from: the run is martello itself, in a process
# whose address space is capped right before that call at what the process holds then
# (VmSize, /proc/self/status: measured, not guessed) plus AT_CALL_MB, far less than the
# arrays the call needs, and given back when it returns, so the front end writes its line.
AT_CALL_MB = 1
CAPPED_CALL = ("import resource, sys\nimport martello.binding.native as native\n"
               "name = sys.argv[1]\nlib = native.lib()\nreal = getattr(lib, name)\n"
               "def capped(*args):\n"
               "    size = [l for l in open('/proc/self/status') if l.startswith('VmSize:')][0]\n"
               "    cap = int(size.split()[1]) * 1024 + " + str(AT_CALL_MB) + " * 2**20\n"
               "    hard = resource.getrlimit(resource.RLIMIT_AS)[1]\n"
               "    resource.setrlimit(resource.RLIMIT_AS, (cap, hard))\n"
               "    try:\n        return real(*args)\n"
               "    finally:\n        resource.setrlimit(resource.RLIMIT_AS, (hard, hard))\n"
               "setattr(lib, name, capped)\n"
               "from martello.cli import main\nsys.exit(main(sys.argv[2:]))\n")


# Under AddressSanitizer (scripts/sanitize) an address-space cap cannot work: ASan reserves
# terabytes of shadow memory at start (VmSize ~21 TB), and a cap set past that left the run
# asleep for good. There the cap is ASan's own (max_allocation_size_mb with
# allocator_may_return_null): asan_mb, a size between the largest other allocation of the
# process (front end and library: a few MB at these n) and the one that is to fail. The chain
# door's arrays are n doubles each, the size of the front end's own numpy arrays of the chain,
# so no allocation cap singles them out: scripts/sanitize deselects that case
# (-k "not martello_model_add_chain"); without the sanitizer it runs like the others.
@pytest.mark.parametrize("call, analysis, n, asan_mb, expected", [
    # fortran/model.f90 model_add_chain: the chain's k and gap, 2 n doubles (16 MB)
    ("martello_model_add_chain", "", 1_000_000, None,
     r"out of memory allocating a chain of 1000000 nodes \(16\.0 MB\): use a smaller scene"),
    # fortran/statics.f90: the dense stiffness of the free nodes, (n + 1) n doubles (80 MB)
    ("martello_static_solve", 'type = "static"', 3_000, 32,
     r"out of memory allocating the stiffness matrix of the static solve for 3000 free nodes "
     r"\(72\.0 MB\): the static solve uses dense matrices"),
    # fortran/observer.f90 observer_init: the history's first 4096 rows of 1 + 3 n + 2 (n − 1)
    # + NENERGY columns (every node and contact recorded)
    ("martello_dynamic_run", "history", 20_000, 512,
     r"out of memory allocating the history of a run \(4096 rows of 1000\d\d columns\) "
     r"\(3\.3 GB\): record less"),
])
def test_the_door_the_static_solve_and_the_observer_out_of_memory(tmp_path, call, analysis, n, asan_mb,
                                                                 expected):
    body = scene(n, "newmark", "gap = 0.01\ncontact = { scheme = \"penalty\", law = \"linear\", stiffness = 1.0e5 }")
    if analysis == 'type = "static"':
        body = body.replace('type = "dynamic"\nintegrator = "newmark"\ndt = 1.0e-3\nt_end = 1.0e-3\n',
                            'type = "static"\n').split("[analysis.output]")[0]
    if analysis == "history":
        body = body.replace("t_end = 1.0e-3", "t_end = 5.0").replace(
            'nodes = ["s1"]\ncontacts = []', f"nodes = {[f's{i}' for i in range(1, n + 1)]}\n"
            f"contacts = {[f's{i}-s{i + 1}' for i in range(1, n)]}".replace("'", '"'))
    path = tmp_path / "scene.toml"
    path.write_text(body)
    out = tmp_path / "out"
    env = dict(os.environ)
    if under_asan():
        assert asan_mb is not None, "under ASan, run with -k 'not martello_model_add_chain' (see above)"
        env["ASAN_OPTIONS"] = (env.get("ASAN_OPTIONS", "") + ":allocator_may_return_null=1"
                               f":max_allocation_size_mb={asan_mb}").lstrip(":")
        args = [sys.executable, "-m", "martello"]
    else:
        args = [sys.executable, "-c", CAPPED_CALL, call]
    r = subprocess.run(args + ["run", path, "-o", out, "--force"], cwd=tmp_path, env=env,
                       capture_output=True, text=True, timeout=600, stdin=subprocess.DEVNULL)
    if under_asan():
        # the sanitizer's line for the one allocation it refused, larger than its cap
        refused = [int(m[1], 16) for m in map(re.compile(ASAN_REFUSED).fullmatch, r.stderr.splitlines()) if m]
        assert len(refused) == 1 and refused[0] > asan_mb * 2**20, r.stderr[-2000:]
    # the front end's estimate of what a run writes comes first (a warning, not a failure)
    lines = [ln for ln in r.stderr.splitlines() if not re.fullmatch(ASAN_REFUSED, ln)
             and not ln.startswith("warning: the run will write up to about")]
    assert r.returncode == 1, r.stderr[-2000:]
    assert len(lines) == 1, r.stderr[-2000:]
    assert re.fullmatch(r"martello: error: MARTELLO_ERR_MEMORY \(-2\): .*" + expected + r".*", lines[0]), lines[0]
    assert r.stdout == ""
    assert not out.exists() or not any(out.iterdir())
