"""The scenes of the divergence suite (tests/test_divergence.py): each one diverges, creates
energy, breaks a stability limit, a Newton cap, a tolerance or a budget on some integrator,
and must end as a one-line failure with nothing written. Each case: (id, scene dict, the
status expected, a pattern of the message). The physics is P2 of docs/problems.md (a mass on
a spring bouncing on a penalty plane under gravity) and two free bodies meeting."""

import math

K, EPS = 100.0, 1e6
W_MAX = math.sqrt((K + EPS) / 1.0)          # rad/s: the closed contact's frequency, m = 1 kg
CD_CRIT = 2.0 / W_MAX                       # central difference: dt_crit = 2/omega_max


def newmark_crit(beta, gamma):
    """Newmark with 2 beta < gamma: stable for omega h <= 1/sqrt(gamma/2 - beta)."""
    return 1.0 / math.sqrt(gamma / 2 - beta) / W_MAX


def p2(integrator="newmark", eps=EPS, law="linear", scheme="penalty", **an):
    d = {"node": [{"name": "m", "mass": 1.0}],
         "link": [{"type": "spring", "a": "m", "b": "ground", "k": K}],
         "contact": [{"name": "plane", "a": "m", "b": "ground", "gap": 0.05, "scheme": scheme}],
         "loads": {"gravity": 9.81},
         "analysis": {"type": "dynamic", "integrator": integrator, "dt": 1e-3, "t_end": 0.5,
                      "output": {"every": 10}}}
    if scheme == "penalty":
        d["contact"][0].update(stiffness=eps, law=law)
    d["analysis"].update(an)
    return d


def runaway(integrator, **an):
    """A free mass pushed by 1e300 N: its state overflows (a non-finite state)."""
    d = {"node": [{"name": "m", "mass": 1.0}],
         "loads": {"force": [{"node": "m", "function": {"type": "constant", "value": 1e300}}]},
         "analysis": {"type": "dynamic", "integrator": integrator, "dt": 1e-2, "t_end": 1e3,
                      "output": {"every": 1000}}}
    d["analysis"].update(an)
    return d


DIVERGED, UNSTABLE, LIMIT = "MARTELLO_ERR_DIVERGED", "MARTELLO_ERR_UNSTABLE", "MARTELLO_ERR_LIMIT"
NOT_CONVERGED = "MARTELLO_ERR_NOT_CONVERGED"
CREATED = "created energy at its contacts"
GROWTH = "diverged at t = |created energy"

CASES = []


def case(name, scene, status, pattern):
    CASES.append((name, scene, status, pattern))


# central difference: past its limit (refused, or with check_stability = false run and
# caught), and near it (onsets not located: e > 1 at the elastic plane)
for r in (1.01, 1.5, 3.0):
    case(f"cd-refused-{r}", p2("central-difference", dt=r * CD_CRIT), UNSTABLE, "exceeds dt_crit")
for r in (1.05, 1.2, 1.5, 2.0, 4.0):
    case(f"cd-unchecked-{r}", p2("central-difference", dt=r * CD_CRIT, check_stability=False),
         DIVERGED, GROWTH)
for r in (0.8, 0.9, 0.95, 0.99):
    case(f"cd-near-limit-{r}", p2("central-difference", dt=r * CD_CRIT), DIVERGED, CREATED)
# Newmark with 2 beta < gamma: refused past its limit, caught when unchecked
for beta, gamma in ((0.1, 0.5), (0.0625, 0.5), (0.15, 0.6)):
    crit = newmark_crit(beta, gamma)
    case(f"newmark-refused-{beta}-{gamma}", p2(dt=1.5 * crit, beta=beta, gamma=gamma),
         UNSTABLE, "beta = .* < gamma/2")
    case(f"newmark-unchecked-{beta}-{gamma}",
         p2(dt=2.0 * crit, beta=beta, gamma=gamma, check_stability=False), DIVERGED, GROWTH)
case("newmark-below-limit-creates", p2(dt=0.77 * newmark_crit(0.1, 0.5), beta=0.1, gamma=0.5),
     DIVERGED, CREATED)
# Newton capped at one iteration on stiff, nonlinear contacts
for integ, extra in (("newmark", {}), ("hht", {"alpha": -0.1}), ("hht", {"alpha": -0.3}),
                     ("generalized-alpha", {"rho_inf": 0.8}),
                     ("generalized-alpha", {"rho_inf": 0.0})):
    case(f"newton-cap-{integ}-{list(extra.values())}",
         p2(integ, eps=1e9, law="hertz", max_newton=1, dt=1e-4, **extra), NOT_CONVERGED,
         "Newton did not converge")
# a runaway force: the state overflows on every kind of integrator
for integ in ("newmark", "hht", "generalized-alpha", "central-difference", "moreau-jean",
              "rkf45", "rk8pd", "msbdf", "ida"):
    extra = {"hht": {"alpha": -0.1}, "generalized-alpha": {"rho_inf": 0.8}}.get(integ, {})
    case(f"overflow-{integ}", runaway(integ, **extra), DIVERGED, "non-finite|diverged")
# budgets: the output grid alone past max_steps (refused before the run), and an adaptive
# integrator on a stiff contact running out of steps
for integ in ("newmark", "central-difference", "moreau-jean", "newmark-lagrange", "rkf45", "ida"):
    scheme = "lagrange" if integ == "newmark-lagrange" else "penalty"
    case(f"grid-past-max-steps-{integ}", p2(integ, scheme=scheme, dt=1e-6, max_steps=1e4,
                                            output={"every": 1000}),
         LIMIT, "more than max_steps")
# (P2 on a 1e12 N/m plane takes 43 (rk8pd) to 726 (msbdf) accepted adaptive steps to t = 0.5 s)
for integ in ("rkf45", "rk8pd", "msbdf", "ida"):
    case(f"adaptive-past-max-steps-{integ}", p2(integ, eps=1e12, dt=0.1, max_steps=10),
         LIMIT, "took max_steps")
