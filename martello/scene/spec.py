"""The scene format's vocabulary: the keys of every table with their kinds, checks and
defaults, the contact schemes and laws, the time functions, the integrators and their
parameters (docs/scene-format.md). Which integrators run which contact scheme is in
martello.scene.compatibility."""

from .fields import ANY, NONNEG, POSITIVE, unit_interval

GROUND = "ground"

NODE_KEYS = {
    "name": ("str", True, None, None),
    "mass": ("float", True, None, None),        # > 0 unless fixed: the loader checks it
    "u0": ("float", False, ANY, 0.0),
    "v0": ("float", False, ANY, 0.0),
    "fixed": ("bool", False, None, False),
}

LINK_COMMON = {"name": ("str", False, None, None), "type": ("str", True, None, None),
               "a": ("str", True, None, None), "b": ("str", True, None, None)}
LINK_TYPES = {
    "spring": {"k": ("float", True, POSITIVE, None)},
    "dashpot": {"c": ("float", False, POSITIVE, None),
                "zeta": ("float", False, (lambda x: 0 < x < 10, "a number in (0, 10)"), None)},
    "bilinear": {"k": ("float", True, POSITIVE, None), "fy": ("float", True, POSITIVE, None),
                 "hardening": ("float", False, unit_interval(hi_open=True), 0.0)},
    "fluid_damper": {"c": ("float", True, POSITIVE, None),
                     "alpha": ("float", False, (lambda x: 0 < x <= 2, "a number in (0, 2]"), 1.0),
                     "v_reg": ("float", False, NONNEG, 1e-6)},
    "bar": {"EA": ("float", True, POSITIVE, None), "L": ("float", True, POSITIVE, None)},
}

SCHEMES = ("penalty", "lagrange", "augmented-lagrange", "restitution")
LAWS = ("linear", "hertz", "kelvin", "hunt-crossley", "lankarani-nikravesh", "flores",
        "gonthier", "hertzdamp", "jankowski")
FIXED_EXPONENT = {"linear": 1, "kelvin": 1, "hertzdamp": 1.5, "jankowski": 1.5}
CONTACT_COMMON = {"name": ("str", True, None, None), "a": ("str", True, None, None),
                  "b": ("str", True, None, None), "gap": ("float", False, ANY, 0.0),
                  "scheme": ("str", True, None, None)}
CONTACT_SCHEMES = {
    "penalty": {"law": ("str", False, None, "linear"),
                "stiffness": ("float", True, POSITIVE, None),
                "exponent": ("float", False, POSITIVE, None),
                "damping": ("float", False, NONNEG, None),
                "restitution": ("float", False, unit_interval(), None),
                "clipped": ("bool", False, None, False)},
    "lagrange": {"restitution": ("float", False, unit_interval(), None)},
    "augmented-lagrange": {"stiffness": ("float", True, POSITIVE, None)},
    "restitution": {"restitution": ("float", True, unit_interval(), None)},
}

FUNCTION_TYPES = {
    "constant": {"value": ("float", True, ANY, None)},
    "sine": {"amplitude": ("float", True, ANY, None), "omega": ("float", True, POSITIVE, None),
             "phase": ("float", False, ANY, 0.0), "t_start": ("float", False, NONNEG, 0.0),
             "t_end": ("float", False, POSITIVE, 1e300)},
    "rectangular": {"amplitude": ("float", True, ANY, None),
                    "t_start": ("float", False, NONNEG, 0.0), "t_end": ("float", True, POSITIVE, None)},
    "half_sine": {"amplitude": ("float", True, ANY, None),
                  "t_start": ("float", False, NONNEG, 0.0), "t_end": ("float", True, POSITIVE, None)},
    "table": {"t": ("list", True, None, None), "values": ("list", True, None, None),
              "scale": ("float", False, ANY, 1.0)},
    "record": {"file": ("str", True, None, None), "format": ("str", False, None, None),
               "units": ("str", False, None, None), "scale": ("float", False, ANY, 1.0)},
}

INTEGRATORS = ("newmark", "hht", "generalized-alpha", "central-difference", "moreau-jean",
               "newmark-lagrange", "rkf45", "rk8pd", "msbdf", "ida")
STRUCTURAL = ("newmark", "hht", "generalized-alpha", "central-difference")
ADAPTIVE = ("rkf45", "rk8pd", "msbdf", "ida")
NEWMARK_PRESETS = {"average-acceleration": (0.25, 0.5), "linear-acceleration": (1.0 / 6.0, 0.5)}
ANALYSIS_TYPES = {
    "static": {"tol": ("float", False, POSITIVE, 1e-14),
               "max_iter": ("int", False, POSITIVE, 500)},
    "dynamic": {"integrator": ("str", True, None, None),
                "dt": ("float", True, POSITIVE, None),
                "t_end": ("float", True, POSITIVE, None),
                "preset": ("str", False, None, None),
                "beta": ("float", False, (lambda x: x > 0, "a number > 0 (beta = 0 is central-difference)"), None),
                "gamma": ("float", False, (lambda x: x >= 0.5, "a number >= 0.5"), None),
                "alpha": ("float", False, (lambda x: -1 / 3 <= x <= 0, "a number in [-1/3, 0]"), None),
                "rho_inf": ("float", False, (lambda x: 0 <= x <= 1, "a number in [0, 1]"), None),
                "tol_residual": ("float", False, POSITIVE, 1e-9),
                "tol_increment": ("float", False, POSITIVE, 1e-11),
                "max_newton": ("int", False, POSITIVE, 30),
                "check_stability": ("bool", False, None, True),
                "divergence_factor": ("float", False, (lambda x: x > 1, "a number > 1"), 10.0),
                "rtol": ("float", False, POSITIVE, 1e-8),
                "atol": ("float", False, POSITIVE, 1e-12),
                "theta": ("float", False, (lambda x: 0.5 <= x <= 1, "a number in [0.5, 1]"), 0.5),
                "event_tol": ("float", False, POSITIVE, 1e-12),
                "h_max": ("float", False, NONNEG, 0.0),
                "output": ("table", False, None, None)},
}
OUTPUT_KEYS = {"every": ("int", False, POSITIVE, 1), "nodes": ("list", False, None, None),
               "contacts": ("list", False, None, None), "links": ("list", False, None, [])}
INTEGRATOR_KEYS = {"newmark": {"preset", "beta", "gamma"}, "hht": {"alpha"},
                   "generalized-alpha": {"rho_inf"}, "central-difference": {"check_stability"},
                   "moreau-jean": {"theta"}, "newmark-lagrange": set(),
                   **{k: {"rtol", "atol", "event_tol", "h_max"} for k in ADAPTIVE}}
IMPLICIT_KEYS = {"tol_residual", "tol_increment", "max_newton"}
ALL_SPECIFIC = set().union(*INTEGRATOR_KEYS.values()) | IMPLICIT_KEYS

TOP_KEYS = {"title", "problem", "description", "node", "link", "contact", "loads", "analysis",
            "check", "chain", "bar", "mass_coupling"}

