"""[[frame]] tables: planar frames of beam-columns (docs/problems.md P10, docs/scene-input.md
"Frames"), expanded into the lateral nodes that carry the floor masses and one stiffness block
between them (the frame statically condensed, martello.frame2d). The loader keeps what the
results need (the recovery operator of the member end forces, drifts and shears) in
scene.extras["frames"]."""

import math

import numpy as np

from ..errors import SceneError
from ..frame2d import PlanarFrame, modal_damping, rayleigh_coefficients
from .fields import MAX_GENERATED, POSITIVE, check_fields, choice, per_item

FRAME_KEYS = {"prefix": ("str", True, None, None),
              "storeys": ("int", True, POSITIVE, None),
              "bays": ("int", True, POSITIVE, None),
              "storey_height": ("any", True, None, None),
              "bay_width": ("any", True, None, None),
              "column": ("any", True, None, None),
              "beam": ("any", True, None, None),
              "mass": ("any", True, None, None),
              "mass_model": ("str", False, None, "diaphragm"),
              "base": ("str", False, None, "fixed"),
              "zeta": ("float", False, (lambda x: 0 <= x < 1, "a number in [0, 1)"), 0.0),
              "damping": ("str", False, None, "rayleigh"),
              "rayleigh_modes": ("list", False, None, [1, 2]),
              "histories": ("bool", False, None, False)}
SECTION_KEYS = {"E": ("float", True, POSITIVE, None), "A": ("float", True, POSITIVE, None),
                "I": ("float", True, POSITIVE, None)}
MASS_MODELS = ["diaphragm", "joints"]
DAMPING = ["rayleigh", "modal"]
BASES = ["fixed", "pinned"]
# The cap of a frame's lateral DOFs: its block is dense, n² doubles per evaluation.
MAX_LATERAL = 2000


def _sections(src, where, value, rows, per_row):
    """One section table for all, a list of `rows` (one per storey/floor), or a list of rows
    of `per_row` tables (one per member). Returns rows x per_row (E, A, I)."""
    def one(tab, path):
        s = check_fields(src, tab, path, SECTION_KEYS)
        return (s["E"], s["A"], s["I"])
    if isinstance(value, dict):
        s = one(value, where)
        return [[s] * per_row for _ in range(rows)]
    if not isinstance(value, list) or len(value) != rows:
        raise SceneError(src, where, "must be a section table or a list of one per storey",
                         f"e.g. {{ E = 2.5e10, A = 0.16, I = 2.1e-3 }} or a list of {rows}")
    out = []
    for r, item in enumerate(value):
        if isinstance(item, dict):
            out.append([one(item, f"{where}[{r}]")] * per_row)
        elif isinstance(item, list) and len(item) == per_row:
            out.append([one(t, f"{where}[{r}][{k}]") for k, t in enumerate(item)])
        else:
            raise SceneError(src, f"{where}[{r}]", f"must be a section table or a list of {per_row}",
                             "one section for the storey, or one per member left to right")
    return out


def _masses(src, where, value, storeys, bays, mass_model):
    """Floor masses (a scalar or one per floor) or, for mass_model "joints", a list of one
    list per floor of bays + 1 joint masses (left to right): any planar model written exactly."""
    if not (isinstance(value, list) and any(isinstance(v, list) for v in value)):
        return per_item(src, where, value, storeys, POSITIVE)
    if mass_model != "joints":
        raise SceneError(src, where, "joint masses need mass_model = \"joints\"",
                         "give one mass per floor, or set mass_model = \"joints\"")
    if len(value) != storeys:
        raise SceneError(src, where, f"has {len(value)} floors", f"give a list of {storeys} lists")
    out = []
    for s, row in enumerate(value):
        if not isinstance(row, list):
            raise SceneError(src, f"{where}[{s}]", "must be a list of joint masses",
                             f"{bays + 1} masses, left to right")
        out.append(per_item(src, f"{where}[{s}]", row, bays + 1, POSITIVE))
    return out


def expand_frames(src, data):
    """Replace [[frame]] tables by their lateral nodes; return (data, frames) with frames the
    list of what each frame stands for (PlanarFrame, node names, K, C, recovery operators)."""
    data = dict(data)
    tabs = data.pop("frame")
    if not isinstance(tabs, list):
        raise SceneError(src, "frame", "must be an array of tables", "write [[frame]]")
    nodes, frames, made = list(data.get("node", [])), [], 0
    for fi, tab in enumerate(tabs):
        w = f"frame[{fi}]"
        f = check_fields(src, tab, w, FRAME_KEYS)
        ns, nb = f["storeys"], f["bays"]
        choice(src, f"{w}.mass_model", f["mass_model"], MASS_MODELS)
        choice(src, f"{w}.base", f["base"], BASES)
        choice(src, f"{w}.damping", f["damping"], DAMPING)
        lateral = ns if f["mass_model"] == "diaphragm" else ns * (nb + 1)
        made += lateral
        if lateral > MAX_LATERAL or made > MAX_GENERATED:
            raise SceneError(src, f"{w}.storeys", f"{lateral} lateral DOFs",
                             f"a frame has at most {MAX_LATERAL} (its condensed block is dense)")
        modes = f["rayleigh_modes"]
        if (len(modes) != 2 or not all(isinstance(x, int) and not isinstance(x, bool) and x >= 1
                                       for x in modes)):
            raise SceneError(src, f"{w}.rayleigh_modes", f"invalid value {modes!r}",
                             "two mode numbers >= 1, e.g. [1, 2]")
        heights = per_item(src, f"{w}.storey_height", f["storey_height"], ns, POSITIVE)
        widths = per_item(src, f"{w}.bay_width", f["bay_width"], nb, POSITIVE)
        for key, lengths in (("storey_height", heights), ("bay_width", widths)):
            if not math.isfinite(sum(lengths)):
                raise SceneError(src, f"{w}.{key}", "the frame's height or width leaves the "
                                 "doubles", "lengths in m of a real frame")
        frame = PlanarFrame(
            heights=heights,
            widths=widths,
            columns=_sections(src, f"{w}.column", f["column"], ns, nb + 1),
            beams=_sections(src, f"{w}.beam", f["beam"], ns, nb),
            masses=_masses(src, f"{w}.mass", f["mass"], ns, nb, f["mass_model"]),
            base=f["base"], mass_model=f["mass_model"])
        if lateral > 1 and max(modes) > lateral:
            raise SceneError(src, f"{w}.rayleigh_modes", f"mode {max(modes)} of a frame with "
                             f"{lateral} lateral DOFs", f"mode numbers in [1, {lateral}]")
        names = frame.lateral_names(f["prefix"])
        mass = frame.lateral_masses()
        try:
            with np.errstate(all="ignore"):
                K, G = frame.condensed()
        except (np.linalg.LinAlgError, OverflowError, ZeroDivisionError):
            # a singular condensation, or lengths whose powers leave the doubles (a bay of
            # 1e300 m or 1e-300 m): refused just below, naming the frame
            K = G = np.array([[np.nan]])
        _check_stiffness(src, w, K, G, mass)
        R = frame.recovery(G)
        C = np.zeros_like(K)
        a0 = a1 = 0.0
        try:
            if f["zeta"] > 0 and f["damping"] == "modal":
                C = modal_damping(K, mass, f["zeta"])
            elif f["zeta"] > 0:
                a0, a1 = rayleigh_coefficients(K, mass, f["zeta"], tuple(modes))
                C = a0 * np.diag(mass) + a1 * K
        except np.linalg.LinAlgError:
            raise SceneError(src, f"{w}.mass", "the frequencies of the frame could not be "
                             "computed (masses and stiffness too disparate for double precision)",
                             "give storey masses in kg and sections in SI units of a real "
                             "frame") from None
        if not np.all(np.isfinite(C)):
            raise SceneError(src, f"{w}.zeta", "the damping matrix is not finite (masses and "
                             "stiffness too disparate for double precision)",
                             "give storey masses in kg and sections in SI units of a real frame")
        nodes += [{"name": n, "mass": float(m)} for n, m in zip(names, mass)]
        frames.append({"prefix": f["prefix"], "frame": frame, "nodes": names, "K": K, "C": C,
                       "rayleigh": (a0, a1), "zeta": f["zeta"], "recovery": R,
                       "drift": frame.storey_drift_operator(),
                       "shear": frame.storey_shear_operator(R), "histories": f["histories"]})
    data["node"] = nodes
    return data, frames


def _check_stiffness(src, where, K, G, mass):
    """The condensed frame must be a finite, positive definite stiffness over finite masses:
    sections or dimensions whose products overflow, or that leave a mechanism, are refused
    here (not as a failed eigen-solve or a NaN run later)."""
    if not (np.all(np.isfinite(K)) and np.all(np.isfinite(G)) and np.all(np.isfinite(mass))):
        raise SceneError(src, where, "the condensed stiffness is not finite (the products of "
                         "E, A, I and the dimensions overflow)",
                         "give sections and dimensions in SI units of a real frame")
    try:
        np.linalg.cholesky(K)
    except np.linalg.LinAlgError:
        raise SceneError(src, where, "the condensed stiffness is not positive definite (a "
                         "mechanism, or sections too disparate for double precision)",
                         "give sections and dimensions in SI units of a real frame") from None
    # the eigenproblem K phi = w^2 M phi (damping, frequencies) is solved on M^-1/2 K M^-1/2:
    # masses far from the stiffness's scale (a storey of 1e-300 kg) overflow it
    with np.errstate(all="ignore"):
        s = 1 / np.sqrt(np.asarray(mass, float))
        scaled = s[:, None] * K * s[None, :]
    if not np.all(np.isfinite(scaled)):
        raise SceneError(src, f"{where}.mass", "the stiffness over the masses (K/m, the "
                         "squared frequencies) leaves the double-precision range",
                         "give storey masses in kg of a real frame")


def frame_blocks(frames, index):
    """The stiffness blocks of the frames: dicts name, nodes (indices), k, c."""
    return [{"name": fr["prefix"], "nodes": [index[n] for n in fr["nodes"]], "k": fr["K"],
             "c": fr["C"]} for fr in frames]

