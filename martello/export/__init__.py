"""Scenes written for other codes (docs/opensees.md): `martello export SCENE --to opensees -o
DIR` writes a standalone OpenSeesPy script DIR/model.py (and, with --tcl, DIR/model.tcl) that
rebuilds the scene and, run inside DIR, writes DIR/history.csv in the format `martello
compare` reads. What the other code cannot express is refused (ExportError) naming what and
why; what it expresses with a difference is stated in the script and on stderr."""

import sys
from pathlib import Path

from ..errors import ExportError
from ..paths import folder_replaced
from .opensees import DEFAULT_MATERIAL, OpenSeesModel, half_kelvin_e, opensees_model
from .render import python_script, tcl_script

TARGETS = ("opensees",)
SCRIPT = "model.py"


def export(scene, out, to="opensees", analysis=None, materials=None, tcl=False, tol=None,
           scene_path=None, force=False):
    """Write the scene for code `to` into the folder out (replaced whole; an earlier export
    is replaced): model.py, model.tcl with tcl, and the data files of its tables. Returns the
    OpenSeesModel (its .differences say what the other code does differently)."""
    if to not in TARGETS:
        raise ExportError(f"--to {to}: unknown code (valid: {', '.join(TARGETS)})")
    from ..binding import native
    model = opensees_model(scene, analysis=analysis, materials=materials, tol=tol, force=force)
    shown = scene_path or scene.source
    version = native.version()
    with folder_replaced(Path(out), SCRIPT, ExportError) as tmp:
        (tmp / SCRIPT).write_text(python_script(model, version, shown))
        if tcl:
            (tmp / "model.tcl").write_text(tcl_script(model, version, shown))
        for name, text in model.files.items():
            (tmp / name).write_text(text)
    return model


def parse_materials(items):
    """--material LAW=MATERIAL, repeated: a dict law -> material."""
    out = {}
    for item in items or ():
        law, sep, mat = item.partition("=")
        if not sep or law not in DEFAULT_MATERIAL:
            raise ExportError(f"--material {item}: give LAW=MATERIAL with LAW one of "
                              f"{', '.join(DEFAULT_MATERIAL)}")
        out[law] = mat
    return out


def main(args):
    """martello export (martello.cli)."""
    from ..scene import catalogue
    from ..scene.loader import load
    path = catalogue.find(args.scene)
    scene = load(path)
    over = {"integrator": args.integrator, "dt": args.dt, "t_end": args.t_end,
            "beta": args.beta, "gamma": args.gamma, "alpha": args.alpha, "rho_inf": args.rho_inf}
    model = export(scene, args.output, to=args.to, analysis=over,
                   materials=parse_materials(args.material), tcl=args.tcl, tol=args.tol,
                   scene_path=str(path), force=args.force)
    for d in model.differences:
        print(f"note: {d}", file=sys.stderr)
    files = [SCRIPT] + (["model.tcl"] if args.tcl else []) + sorted(model.files)
    print(f"{scene.title}: {len(model.commands)} OpenSees commands, {model.steps} steps -> "
          f"{', '.join(str(Path(args.output) / f) for f in files)} (run: cd {args.output} && "
          f"python {SCRIPT}" + (f"; it also writes members.csv, and `python {SCRIPT} --periods` "
                                f"the periods of its {model.modes} modes" if model.members else "") + ")")
    return 0


__all__ = ["export", "opensees_model", "OpenSeesModel", "half_kelvin_e", "parse_materials",
           "TARGETS", "main"]
