"""The divergence suite: every scene of tests/divergence_cases.py (each integrator past its
stability limit, near it with contacts that create energy, stiff penalties on coarse steps,
Newton capped, runaway states, budgets too small) run by `martello run`, in process. Each
must end as one line on stderr naming the failure, exit code 1, and no output folder.

Evidence: the expected outcome is physics or arithmetic, not the code's own output — an
elastic plane cannot give back more energy than it took (realised e <= 1), Newmark's and
central difference's stability limits are closed forms (Hughes 1987, section 9.1), 1e300 N on
1 kg overflows a double within a step, and a grid of t_end/dt points needs t_end/dt steps."""

import re

import pytest

from martello import cli
from benchmarks.fuzz.mutations import to_toml
from divergence_cases import CASES


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
