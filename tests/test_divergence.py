"""The divergence suite: every scene of tests/divergence_cases.py (each integrator past its
stability limit, near it with contacts that create energy, stiff penalties on coarse steps,
Newton capped, runaway states, budgets too small) run by `martello run`, in process. Each
must end as one line on stderr naming the failure, exit code 1, and no output folder.

Evidence: the expected outcome is physics or arithmetic, not the code's own output — an
elastic plane cannot give back more energy than it took (realised e <= 1), Newmark's and
central difference's stability limits are closed forms (Hughes 1987, section 9.1), 1e300 N on
1 kg overflows a double within a step, and a grid of t_end/dt points needs t_end/dt steps."""

import re
from pathlib import Path

import pytest

from martello import cli
from benchmarks.fuzz.mutations import to_toml
from divergence_cases import CASES

ROOT = Path(__file__).resolve().parent.parent


def test_the_suite_has_at_least_forty_cases_on_every_integrator():
    assert len(CASES) >= 40
    integrators = {d["analysis"]["integrator"] for _, d, _, _ in CASES}
    assert integrators == {"newmark", "hht", "generalized-alpha", "central-difference",
                           "moreau-jean", "newmark-lagrange", "rkf45", "rk8pd", "msbdf", "ida"}


@pytest.mark.parametrize("name,scene,status,pattern", CASES, ids=[c[0] for c in CASES])
def test_divergent_case_is_one_line_exit_1_and_nothing_written(tmp_path, capsys, name, scene,
                                                              status, pattern):
    f = tmp_path / "scene.toml"
    f.write_text(to_toml(scene))
    out = tmp_path / "out"
    code = cli.main(["run", str(f), "-o", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 1
    assert len(err) == 1, err
    assert err[0].startswith("martello: error: ") and status in err[0], err[0]
    assert re.search(pattern, err[0]), err[0]
    assert not out.exists() and list(tmp_path.iterdir()) == [f]


def test_a_state_at_rest_to_round_off_is_no_divergence():
    # P9's mass starts held against its barrier by the load (F cos ηt > 0 until t = π/3):
    # nothing has been put in, and the energies are round-off (~1e-41 J), whose growth the
    # bound E > 10 (E0 + Σ|ΔW|) alone would call a divergence; the observer's floor (1e-30 J)
    # lets the run go on, and it then leaves the barrier and bounces as it should.
    import tomllib
    from martello.scene.loader import from_dict
    from martello.run import run_full
    d = tomllib.loads((ROOT / "benchmarks/p9/p9_davis_restitution.toml").read_text())
    d["analysis"].update(integrator="ida", dt=0.1, t_end=3.0)
    s, _ = run_full(from_dict(d), raise_on_failure=False)
    assert s["status"] == "MARTELLO_OK", s.get("message")
    assert s["contacts"]["barrier"]["impacts"] >= 1
