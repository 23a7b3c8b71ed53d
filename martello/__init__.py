"""martello: verification and benchmark suite for contact and impact in structural dynamics.

The Python API (docs/python-api.md)::

    import martello
    scene = martello.load("p2/p2_restitution_e08.toml")   # a file, or a catalogue path
    result = martello.run(scene)                          # summary dict + history arrays
    result.summary["contacts"]["ground"]["impact_times"][:3]
    martello.closed_forms.newton_impact(1.0, 1.0, 1.0, 0.0, 0.5)

``load``, ``Scene`` (``Scene.from_dict``), ``run`` -> ``Result``, ``read``, ``reference``,
``compare``, ``study``, ``check``, ``plot``, ``catalogue``, ``closed_forms``, ``__version__``
and the exceptions
(``MartelloError``, ``SceneError``, ``SolverError``, ``DivergenceError``) are attributes of
the package, loaded the first time they are used: ``import martello`` itself loads no other
module of the package, nor numpy or scipy (tests/test_api.py).

The package by concern, from the bottom up; each layer imports only the layers below it
(tests/test_imports.py checks it):

0. ``errors``, ``paths``, ``history``: exceptions, where the folders are, time histories;
1. ``binding`` (the ctypes binding to libmartello, the only ctypes code) and ``oracles``
   (closed forms, written from the mathematics alone), then ``closed_forms`` (all of them
   by name), ``frame2d`` (planar frames: assembly, condensation, member-force recovery) and
   ``building3d`` (3D buildings on rigid or flexible floors: the same, with modes);
2. ``scene`` (scene files, their generators and variants) and ``ground_motion`` (records,
   spectra, synthetic accelerograms);
3. ``run`` (one scene), then ``batch`` (many, on the local cores);
4. ``metrics`` (scores), then ``reference`` (what a run is scored against);
5. ``checks``: runs verified against closed forms and reference data, the P4 measures;
6. ``study``, ``compare``, ``report``, then ``plot``, then ``api`` (the Python API), then
   ``cli``: the front ends; this file, the package's face, sits on top of them all and
   imports them lazily.
"""

import sys

# not `import types` nor `import importlib` here: they would double the cost of
# `import martello` (python -X importtime); importlib is imported when a name is first used
_ModuleType = type(sys)

__all__ = ["CheckResult", "DivergenceError", "MartelloError", "Result", "Scene", "SceneError",
           "SolverError", "StudyResult", "catalogue", "check", "closed_forms", "compare", "load",
           "plot", "read", "reference", "run", "study"]

# name -> (module, attribute); attribute None: the module itself
_LAZY = {"load": ("martello.api", "load"), "read": ("martello.api", "read"),
         "Scene": ("martello.api", "Scene"),
         "Result": ("martello.api", "Result"), "catalogue": ("martello.api", "catalogue"),
         "StudyResult": ("martello.api", "StudyResult"), "check": ("martello.api", "check"),
         "CheckResult": ("martello.api", "CheckResult"),
         "closed_forms": ("martello.closed_forms", None),
         "MartelloError": ("martello.errors", "MartelloError"),
         "SceneError": ("martello.errors", "SceneError"),
         "SolverError": ("martello.errors", "SolverError"),
         "DivergenceError": ("martello.errors", "DivergenceError")}


def __getattr__(name):
    """The API's names, imported on first use (PEP 562)."""
    if name == "__version__":
        from importlib.metadata import PackageNotFoundError, version
        try:
            v = version("martello")
        except PackageNotFoundError:          # a checkout used without installing it
            from .binding import native
            v = native.version()
        globals()["__version__"] = v
        return v
    if name not in _LAZY:
        raise AttributeError(f"module 'martello' has no attribute {name!r}")
    from importlib import import_module
    module, attr = _LAZY[name]
    value = import_module(module)
    return value if attr is None else getattr(value, attr)


def __dir__():
    return sorted(set(globals()) | set(__all__) | {"__version__"})


class _CallableModule(_ModuleType):
    """martello.run, .reference, .compare, .study, .plot: a module of the package that is
    also the API function of its name (martello.api.run, ...). The module is what it was
    (``from martello.run import run_full``); calling it calls the function."""

    def __call__(self, *args, **kwargs):
        return getattr(_api(), self.__name__.rpartition(".")[2])(*args, **kwargs)

    @property
    def __signature__(self):
        # inspect.signature(martello.run) is the function's (inspect reads __signature__)
        import inspect
        return inspect.signature(getattr(_api(), self.__name__.rpartition(".")[2]))


def _api():
    from . import api
    return api


def _callable_submodule(name):
    """The package attribute `name`: the submodule martello.<name>, made callable. A property
    of the package's class, not a plain attribute, because importing a submodule sets the
    attribute of its name on the package: a plain function martello.run would be replaced
    by the module martello/run.py as soon as anything imported it."""

    def get(package):
        value = package.__dict__.get(name)
        if value is None:
            from importlib import import_module
            value = import_module(f"{__name__}.{name}")
        if type(value) is _ModuleType and value.__name__ == f"{__name__}.{name}":
            value.__class__ = _CallableModule
        return value

    def put(package, value):                  # the import system's, or a test's monkeypatch
        package.__dict__[name] = value

    return property(get, put)


class _Package(_ModuleType):
    run = _callable_submodule("run")
    reference = _callable_submodule("reference")
    compare = _callable_submodule("compare")
    study = _callable_submodule("study")
    plot = _callable_submodule("plot")


sys.modules[__name__].__class__ = _Package
