"""The two-building scene of benchmarks/opensees/two_buildings.scene built in OpenSeesPy by hand,
without martello's exporter (docs/opensees.md, "Exported against hand-built"): its own node
numbers, the bilinear columns as `Hardening` materials (not the exporter's Steel01), the
dashpots' c = 2ζ√(k m) worked out here, the ground motion as a Trig series, the history
taken by Node recorders at full precision. Runs under a Python with openseespy:

    python benchmarks/opensees/hand_built.py OUTDIR      # OUTDIR/disp.out, OUTDIR/vel.out

The scene (kept beside this file with the extension .scene, so the catalogue does not take it
as a problem): left m = 1.2e5 kg, column k = 4.7e7 N/m, F_y = 3e5 N, ρ = 0.05; right
m = 2e5 kg, k = 2.2e7 N/m, F_y = 4e5 N, ρ = 0.02; ζ = 5 % each; a 10 mm joint with a
hertzdamp contact, K = 4e9 N/m^1.5, target e = 0.6 (a = 3(1 − e²)/4, Muthukumar & DesRoches
2006); ground 4 sin(7t) m/s² for 3 s; Newmark average acceleration, Δt = 5e-4 s, 6 s."""

import math
import sys
from pathlib import Path


def build_and_run(out):
    import openseespy.opensees as ops
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    m_l, k_l, fy_l, rho_l = 1.2e5, 4.7e7, 3.0e5, 0.05
    m_r, k_r, fy_r, rho_r = 2.0e5, 2.2e7, 4.0e5, 0.02
    zeta, gap, kh, e = 0.05, 0.01, 4.0e9, 0.6
    ops.wipe()
    ops.model("basic", "-ndm", 1, "-ndf", 1)
    ops.node(101, 0.0)          # left storey
    ops.node(102, 0.0)          # right storey
    ops.node(201, 0.0)          # left foundation
    ops.node(202, 0.0)          # right foundation
    ops.fix(201, 1)
    ops.fix(202, 1)
    ops.mass(101, m_l)
    ops.mass(102, m_r)
    # Hardening(E, sigmaY, H_iso, H_kin): post-yield tangent E·H/(E + H) = ρE for H = ρE/(1 − ρ)
    ops.uniaxialMaterial("Hardening", 11, k_l, fy_l, 0.0, rho_l * k_l / (1.0 - rho_l))
    ops.uniaxialMaterial("Hardening", 12, k_r, fy_r, 0.0, rho_r * k_r / (1.0 - rho_r))
    ops.uniaxialMaterial("Viscous", 21, 2.0 * zeta * math.sqrt(k_l * m_l), 1.0)
    ops.uniaxialMaterial("Viscous", 22, 2.0 * zeta * math.sqrt(k_r * m_r), 1.0)
    # the joint: compression when u_left − u_right > gap, i.e. u_right − u_left < −gap
    ops.uniaxialMaterial("Hertzdamp", 31, kh, 0.75 * (1.0 - e * e), -gap, 1.5)
    ops.element("zeroLength", 1, 201, 101, "-mat", 11, 21, "-dir", 1, 1)
    ops.element("zeroLength", 2, 202, 102, "-mat", 12, 22, "-dir", 1, 1)
    ops.element("zeroLength", 3, 101, 102, "-mat", 31, "-dir", 1)
    ops.timeSeries("Trig", 7, 0.0, 3.0, 2.0 * math.pi / 7.0, "-factor", 4.0)
    ops.pattern("UniformExcitation", 3, 1, "-accel", 7)
    ops.recorder("Node", "-file", str(out / "disp.out"), "-time", "-precision", 17,
                 "-node", 101, 102, "-dof", 1, "disp")
    ops.recorder("Node", "-file", str(out / "vel.out"), "-time", "-precision", 17,
                 "-node", 101, 102, "-dof", 1, "vel")
    ops.constraints("Transformation")
    ops.numberer("Plain")
    ops.system("FullGeneral")
    ops.test("NormDispIncr", 1.0e-12, 200)
    ops.algorithm("Newton")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")
    if ops.analyze(12000, 5.0e-4) != 0:
        raise SystemExit("hand_built.py: OpenSees failed")
    ops.wipe()


if __name__ == "__main__":
    build_and_run(sys.argv[1] if len(sys.argv) > 1 else "out/opensees-hand-built")
