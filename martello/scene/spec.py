"""The scene format's vocabulary: the keys of every table with their kinds, checks and
defaults, the contact schemes and laws, the time functions, the integrators and their
parameters (docs/scene-input.md). Which integrators run which contact scheme is in
martello.scene.compatibility."""

from ..binding import native
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
               "a": ("any", False, None, None), "b": ("any", False, None, None),
               "direction": ("list", False, None, None), "terms": ("list", False, None, None)}
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

SCHEMES = native.names("schemes")
LAWS = native.names("laws")
FIXED_EXPONENT = {r.name: r.values["exponent"] for r in native.registry("laws")
                  if r.values["exponent_fixed"]}
CONTACT_COMMON = {"name": ("str", True, None, None), "a": ("any", False, None, None),
                  "b": ("any", False, None, None), "normal": ("list", False, None, None),
                  "terms": ("list", False, None, None),
                  "gap": ("float", False, ANY, 0.0),
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

# The integrators are the library's (its registry; tests/test_registry.py).
INTEGRATORS = native.integrators()
ADAPTIVE = native.adaptive_integrators()


# The methods of the SUNDIALS ODE integrators by integrator (the library's table methods;
# docs/sundials-ode.md): the names analysis.method takes.
METHODS = {i: tuple(r.name for r in native.registry("methods")
                    if int(r.values["integrator"]) == native.value("integrators", i))
           for i in INTEGRATORS}
# what method = 0 (none given) runs (c/sundials_ode.c, the registry's texts say "default")
DEFAULT_METHODS = {"cvode": "bdf", "arkode": "dormand-prince-7-4-5"}


def _setting(kind, name, required=False, default=True):
    """A key that is a native setting: the library's valid range and, unless required or
    default=False, its default (the registry's table settings)."""
    rng = native.settings_ranges()[name]
    return (kind, required, (lambda x: native.in_range(rng, x), rng.text),
            native.settings_defaults()[name] if default and not required else None)


def _whole(spec):
    """A float setting that must be a whole number (max_steps: up to 2^53, past a 64-bit
    int's TOML range for none of its values but past the library's 32-bit int for most)."""
    kind, required, (check, text), default = spec
    return kind, required, (lambda x: check(x) and float(x).is_integer(), text), default


NEWMARK_PRESETS = {"average-acceleration": (0.25, 0.5), "linear-acceleration": (1.0 / 6.0, 0.5)}
ANALYSIS_TYPES = {
    "static": {"tol": ("float", False, POSITIVE, 1e-14),
               "max_iter": ("int", False, POSITIVE, 500)},
    "dynamic": {"integrator": ("str", True, None, None),
                "dt": _setting("float", "dt", required=True),
                "t_end": _setting("float", "t_end", required=True),
                "preset": ("str", False, None, None),
                "beta": _setting("float", "beta", default=False),
                "gamma": _setting("float", "gamma", default=False),
                "alpha": _setting("float", "alpha", default=False),
                "rho_inf": _setting("float", "rho_inf", default=False),
                "tol_residual": _setting("float", "tol_residual"),
                "tol_increment": _setting("float", "tol_increment"),
                "max_newton": _setting("int", "max_newton"),
                "check_stability": _setting("bool", "check_stability"),
                "divergence_factor": _setting("float", "divergence_factor"),
                "rtol": _setting("float", "rtol"),
                "atol": _setting("float", "atol"),
                "theta": _setting("float", "theta"),
                "event_tol": _setting("float", "event_tol"),
                "h_max": _setting("float", "h_max"),
                "fused_chain": _setting("bool", "fused_chain"),
                "max_steps": _whole(_setting("float", "max_steps")),
                "max_wall": _setting("float", "max_wall"),
                "event_split": _setting("bool", "event_split"),
                "method": ("str", False, None, None),
                "modal_vectors": _setting("int", "modal_vectors"),
                "local_stepping": _setting("bool", "local_stepping"),
                "output": ("table", False, None, None)},
}
OUTPUT_KEYS = {"every": _setting("int", "every"), "nodes": ("list", False, None, None),
               "contacts": ("list", False, None, None), "links": ("list", False, None, []),
               "track": ("list", False, None, None)}
# What a run can track (the library's table "tracking", docs/c-api.md "What a run tracks"),
# and what a scene whose per-item results are written as arrays (docs/results.md "Results as
# arrays") tracks unless output.track says: the contact maxima (and every contact's number of
# phases, always counted), which keep a chain of 1e6 nodes within 200 B per node
# (docs/performance.md). A smaller scene tracks everything its summary lists.
TRACKABLE = tuple(n for n in native.names("tracking") if n != "all")
LARGE_SCENE_TRACKS = ("contact_peaks",)
# A scene with more nodes, links and contacts than this, together, is large: it has its
# per-item results written as arrays (martello.results; 1e4 items made a summary.json of
# ~5 MB; 1e6 of ~1 GB) and tracks LARGE_SCENE_TRACKS by default.
ARRAY_ITEMS = 10_000
# The analysis keys of one integrator or a group: the settings it reads beyond those every
# integrator reads (the library's table "reads"); Newmark also takes a preset.
_READ_BY_ALL = set.intersection(*(native.settings_read(i) for i in INTEGRATORS))
INTEGRATOR_KEYS = {i: native.settings_read(i) - _READ_BY_ALL | ({"preset"} if i == "newmark" else set())
                   for i in INTEGRATORS}
ALL_SPECIFIC = set().union(*INTEGRATOR_KEYS.values())

TOP_KEYS = {"title", "problem", "description", "node", "link", "contact", "loads", "analysis",
            "check", "chain", "bar", "mass_coupling", "frame", "building"}

