"""Write the independent engine's references (docs/independent-reference.md) for P2, P7-P11
into reference/independent/<name>.json: strict JSON, each with its trusted digits.

    .venv/bin/python benchmarks/independent/make_references.py [NAME ...]

Each entry is a catalogue scene, optionally with every contact replaced (the law variants
of P7's two oscillators). P8's records make 2000 restarts per run: a few minutes each."""

from __future__ import annotations

import datetime
import hashlib
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from martello import independent  # noqa: E402
from martello.reference.store import physics_digest  # noqa: E402
from martello.scene.loader import load  # noqa: E402

OUT = ROOT / "reference" / "independent"
TWO = "benchmarks/p7/p7_two_oscillators.toml"
HERTZ_K = 3.0e6          # N/m^1.5: the P7 Hunt–Crossley variant's stiffness (reference/references.toml)

REFERENCES = {
    "p7_two_oscillators_kelvin": (TWO, None),
    "p7_two_oscillators_kelvin_clipped": (TWO, {"scheme": "penalty", "law": "kelvin", "stiffness": 1.0e5,
                                               "restitution": 0.65, "clipped": True}),
    "p7_two_oscillators_linear": (TWO, {"scheme": "penalty", "law": "linear", "stiffness": 1.0e5}),
    "p7_two_oscillators_hertz": (TWO, {"scheme": "penalty", "law": "hertz", "stiffness": HERTZ_K}),
    **{f"p7_two_oscillators_{law.replace('-', '_')}": (TWO, {"scheme": "penalty", "law": law, "stiffness": HERTZ_K,
                                                             "restitution": 0.65})
       for law in ("hunt-crossley", "lankarani-nikravesh", "flores", "gonthier", "hertzdamp", "jankowski")},
    "p7_two_oscillators_restitution": (TWO, {"scheme": "restitution", "restitution": 0.65}),
    "p7_chain_10": ("benchmarks/p7/p7_chain_10.toml", None),
    "p7_row_3": ("benchmarks/p7/p7_row_3.toml", None),
    # P2's plane with every law (one physics each; the scenes on three integrators share it)
    **{f"p2_{law.replace('-', '_')}": (f"benchmarks/p2/laws/p2_{law.replace('-', '_')}_newmark.toml", None)
       for law in ("linear", "hertz", "kelvin_clipped", "hunt-crossley", "lankarani-nikravesh",
                   "flores", "gonthier", "hertzdamp", "jankowski")},
    # the unclipped Kelvin plane runs on the event-locating integrators only (no Newmark scene)
    "p2_kelvin": ("benchmarks/p2/laws/p2_kelvin_rk8pd.toml", None),
    # P7's two oscillators with every law but the unclipped Kelvin one, as catalogue scenes
    # (benchmarks/p7/make_law_sweep.py; one physics each, shared by its four integrators)
    **{f"p7_two_{law}": (f"benchmarks/p7/laws/p7_two_{law}_rk8pd.toml", None)
       for law in ("linear", "hertz", "kelvin_clipped", "hunt_crossley", "lankarani_nikravesh",
                   "flores", "gonthier", "hertzdamp", "jankowski", "kelvin")},
    # P9's forced oscillator on a Kelvin barrier, 60 forcing periods (its own converged
    # reference: the rigid orbit of davis_period1_damped is another model)
    "p9_davis_penalty_kelvin": ("benchmarks/p9/p9_davis_penalty_kelvin.toml", None),
    "p8_bare": ("benchmarks/p8/p8_bare.toml", None),
    "p8_A": ("benchmarks/p8/p8_A.toml", None),
    "p8_B": ("benchmarks/p8/p8_B.toml", None),
    # P10's planar frames (the engine's own frame model, martello/independent/frame.py), 20 s
    # of record 1: linear frames, two linear gaps, fluid dampers (A, B)
    "p10_bare": ("benchmarks/p10/p10_bare.toml", None),
    "p10_A": ("benchmarks/p10/p10_A.toml", None),
    "p10_B": ("benchmarks/p10/p10_B.toml", None),
    # P11's shear-type buildings on rigid floors (the engine's own storeys and plan-point
    # rows, martello/independent/building.py), 4 s of a sine: eccentric gaps, dampers between
    # plan points
    "p11_shear_pounding": ("benchmarks/p11/p11_shear_pounding.toml", None),
}
# stored, but not used by `martello check` (docs/independent-reference.md): the P7 Kelvin
# pair of p7_two_oscillators.toml (p7_two_kelvin, of the same physics, serves the catalogue's
# scenes) and the three-building row (its r1-r2 graze is ambiguous)
NOT_IN_CATALOGUE = {"p7_two_oscillators_kelvin", "p7_row_3"}
# a reference that serves only the scenes it names: p7_two_kelvin has the physics of
# p7_two_oscillators.toml, whose Newmark run at Δt = 1e-4 without event split keeps its
# regression rows (docs/coverage.md); so does p7_chain_10.toml at Δt = 2e-4 (plain Newmark
# steps put its second impacts 4.7e-4 s off, the unclipped Kelvin force jumping inside them),
# while the same chain with event_split at 2e-5 is verified against p7_chain_10
SERVES = {"p7_chain_10": ["benchmarks/p7/p7_chain_10_split.toml"],
          "p7_two_kelvin": [f"benchmarks/p7/laws/p7_two_kelvin_{i}.toml" for i in
                            ("rkf45", "rk8pd", "msbdf", "ida", "cvode", "arkode", "newmark", "hht",
                             "generalized_alpha")]}
# the rtol of the primary integration (the second is at 100 × rtol); P8's records restart
# the integration every 10 ms, where 1e-10 already gives ≥ 6 trusted digits (P8 B: at
# 1e-10 its second integration, at 1e-8, puts the slow 8th phase's separation 1.9e-6 s off
# and confirms only 4.6 digits of its e; at 1e-11 the 1e-9 run agrees to 1e-8); P7's Flores
# contact at 1e-11 confirms only 5.7 digits of e at its slow phases (v_in 0.08 – 0.1 m/s,
# χ = a/v_in ≈ 10 s/m), at 1e-12 8.6; Gonthier 6.5 and 8.5 (Jankowski, whose damping goes as
# δ^(1/4) at first touch, is 6.5 at 1e-11 and 6.2 at 1e-12: it stays at 1e-11)
RTOL = {"p8_bare": 1e-10, "p8_A": 1e-10, "p8_B": 1e-11, "p7_two_flores": 1e-12, "p7_two_gonthier": 1e-12,
        "p9_davis_penalty_kelvin": 1e-12, "p10_bare": 1e-10, "p10_A": 1e-10, "p10_B": 1e-10}


def build(name):
    scene, contact = REFERENCES[name]
    t0 = time.perf_counter()
    ref = independent.solve(ROOT / scene, rtol=RTOL.get(name, 1e-11), contact=contact)
    out = ref.to_json()
    out.pop("events")            # kept short: the phases carry the contact events
    out["name"] = name
    out["scene"] = scene
    out["scene_sha256"] = hashlib.sha256((ROOT / scene).read_bytes()).hexdigest()
    out["contact_override"] = contact
    # the key `martello check` finds it by: the physics of the scene as martello reads it
    # (a variant with a contact override is another physics, never matched to the file)
    out["physics_sha256"] = None if contact else physics_digest(load(ROOT / scene))
    out["catalogue"] = name not in NOT_IN_CATALOGUE
    if name in SERVES:
        out["scenes"] = SERVES[name]
    out["t_end"] = load(ROOT / scene).analysis["t_end"]
    out["date"] = datetime.date.today().isoformat()
    out["command"] = f"benchmarks/independent/make_references.py {name}"
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / f"{name}.json").write_text(independent.dumps(out) + "\n")
    print(f"{name}: trusted digits {ref.trusted_digits:.1f}, ambiguous {ref.ambiguous}, "
          f"{time.perf_counter() - t0:.1f} s", flush=True)


if __name__ == "__main__":
    for name in sys.argv[1:] or REFERENCES:
        build(name)
