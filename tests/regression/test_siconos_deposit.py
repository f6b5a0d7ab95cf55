#!/usr/bin/env python3
"""MULTICOR and Siconos 4.4 (bench/siconos_deposit.py) on the same small deposit, both against
its closed form: 10 equal disks (R = 1 cm) dropped from 0.5 mm apart into a triangle 4-3-2-1
in a box 8 R wide, whose bottom row fills the box. At rest, row j sits at y = R + j sqrt(3) R,
x unchanged. The layout is written once, as a deck for multicor and as the CSV that
`bench_dem --siconos N --csv` writes for bench/siconos_deposit.py, so this also checks that the
script rebuilds the problem of the CSV (radii, masses, box, gravity, law).

Siconos runs under the system Python (MULTICOR_SICONOS_PYTHON, default /usr/bin/python3,
Debian's python3-siconos); without it the test fails on Debian (scripts/bootstrap.sh installs
it) and reports as skipped (exit 77) elsewhere.
Usage (ctest does this): test_siconos_deposit.py --exe multicor --work DIR --source REPO
"""
import subprocess
import sys

import h5py
import numpy as np

from box_layout import write_box_layout
from checks import arguments, check, summary
from siconos_env import siconos_python

R = 0.01  # disk radius [m]
RHO = 2500.0
DELTA = 5.0e-4  # initial gap below every row [m]
H = 5.0e-4  # time step [s]
STEPS = 400  # 0.2 s: the last row lands after about 0.03 s
G = 9.81


def layout():
    """Start positions (rows 4, 3, 2, 1; each row DELTA above its resting height plus the
    gaps below) and the closed-form positions at rest."""
    x, y, y_rest = [], [], []
    for j in range(4):
        for i in range(4 - j):
            x.append(R * (1 + j + 2 * i))
            y.append(R + DELTA + j * (np.sqrt(3.0) * R + DELTA))
            y_rest.append(R + j * np.sqrt(3.0) * R)
    return np.array(x), np.array(y), np.array(y_rest), 8 * R


def write_inputs(work, x, y, width):
    disks = [(xi, yi, R) for xi, yi in zip(x, y)]
    csv, deck = write_box_layout(work, "triangle", disks, width, rho=RHO, g=G, mu=0.3, e=0, tol=1e-4,
                                 max_sweeps=10000, h=H, steps=STEPS, interval=STEPS,
                                 title="ten disks settling into a triangle (compared with Siconos)")
    return csv, deck


def compare(name, pos, x, y_rest, bound):
    dx = np.abs(pos[:, 0] - x).max()
    dy = pos[:, 1] - y_rest
    # Every disk ends at most `bound` below its closed-form height (the interpenetration that
    # Moreau-Jean leaves after the impacts, see main) and not above it (a disk at rest above its
    # supports would hang in the air; a wrong radius, box or layout shows as millimetres).
    # 1e-7 m above: a step converged to 1e-4 relative leaves velocities of at most
    # 1e-4 * 0.2 m/s, i.e. 1e-8 m per step of h = 5e-4 s.
    check(f"{name}: rows at rest at R + j sqrt(3) R", dy.min() >= -bound and dy.max() <= 1e-7,
          f"y - y_rest in [{dy.min() * 1e3:.4f}, {dy.max() * 1e3:.4f}] mm (bound -{bound * 1e3:.3f} mm)")
    # The triangle is symmetric and the bottom row cannot move sideways (walls and neighbours
    # touch): the same bound on the lateral drift.
    check(f"{name}: columns in place", dx <= bound, f"max |x - x0| {dx * 1e3:.4f} mm")


def main():
    exe, work, src = arguments()
    script = src / "bench" / "siconos_deposit.py"
    python, env = siconos_python("siconos.kernel, siconos.mechanics.collision.bodies")

    x, y, y_rest, width = layout()
    csv, deck = write_inputs(work, x, y, width)
    # Bound on the sinking. The disks reach at most v = sqrt(2 g 4 DELTA) (the top row falls
    # its own gap and the three below). With e = 0, theta = 1/2 and no position correction, an
    # impact leaves an overlap of at most h v_n on each contact (Siconos activates a contact when
    # g + h/2 v_n <= 0 on the output of the previous step, doc/theory.md 2.6, so it stops between
    # 0 and h |v_n| inside; MULTICOR's scheme within h/2 |v_n| either side). Row j rests on the floor and j hollows, and an
    # overlap d on both contacts of a hollow lowers the disk by d / cos 30 deg.
    v_max = np.sqrt(2 * G * 4 * DELTA)
    bound = H * v_max * (1 + 3 * 2 / np.sqrt(3.0))

    out = work / "multicor"
    proc = subprocess.run([str(exe), str(deck), "--output", str(out), "--quiet"],
                          capture_output=True, text=True)
    if proc.returncode != 0:
        print(proc.stdout, proc.stderr)
        raise SystemExit(f"multicor failed (exit {proc.returncode})")
    with h5py.File(out / "triangle.h5", "r") as f:
        mc = f["dem/position"][-1]
        conv = f["dem/solver/converged"][...]
    check("multicor: every step converged", conv.all(), f"{conv.sum()} of {len(conv)}")
    compare("multicor", mc, x, y_rest, bound)

    final = work / "siconos_final.csv"
    proc = subprocess.run([python, str(script), str(csv), "--h", str(H), "--steps", str(STEPS),
                           "--final", str(final)], capture_output=True, text=True, env=env)
    print(proc.stdout)
    if proc.returncode != 0:
        print(proc.stderr)
        raise SystemExit(f"siconos_deposit.py failed (exit {proc.returncode})")
    rows = [ln.split() for ln in proc.stdout.splitlines() if ln and not ln.startswith("#")]
    conv_fraction = float(rows[-1][9])  # N steps 3 step times osnsp solve 2 iters conv
    check("siconos: every step converged", conv_fraction == 1.0, f"fraction {conv_fraction}")
    sic = np.loadtxt(final, delimiter=",", skiprows=1)
    compare("siconos", sic[:, :2], x, y_rest, bound)
    # the two codes' centres of mass: each within the bound below the closed form
    com = [float(np.mean(p[:, 1])) for p in (mc, sic)]
    check("centres of mass agree", abs(com[0] - com[1]) <= bound,
          f"multicor {com[0]:.6f} m, siconos {com[1]:.6f} m, closed form {np.mean(y_rest):.6f} m")
    return summary()


if __name__ == "__main__":
    sys.exit(main())
