#!/usr/bin/env python3
"""`[time] contact_scheme = siconos` integrates the discrete problem of Siconos 4.4: the same
trajectory, step by step, as bench/siconos_deposit.py (Siconos' TimeStepping with MoreauJeanOSI,
one Newton iteration, NSGS) on the same layout, both solved to a tight tolerance.

Cases (the layouts are written as a deck for multicor and as the CSV of `bench_dem --csv`):
- a column of 3 disks, off centre, falling on the floor: the top disks roll off their supports
  (friction mu = 0.3, rotations), with e = 0 and with e = 1/2 (the restitution acts on the
  velocity of the previous step's output in Siconos, doc/theory.md 2.6), theta = 1/2, and with
  e = 0 and theta = 1;
- a staggered deposit of 30 disks with radii in [0.8 R, 1.2 R] falling into a pile.
MULTICOR's default scheme (`multicor`: detection on the mid configuration, activation on the
predicted gap, gap term) is run too: its trajectories must differ from Siconos', or the
comparison would not tell the schemes apart.

Siconos runs under the system Python (MULTICOR_SICONOS_PYTHON, default /usr/bin/python3,
Debian's python3-siconos); without it the test fails on Debian (scripts/bootstrap.sh installs
it) and reports as skipped (exit 77) elsewhere.
Usage (ctest does this): test_siconos_scheme.py --exe multicor --work DIR --source REPO
"""
import subprocess
import sys

import h5py
import numpy as np

from box_layout import write_box_layout
from checks import arguments, check, summary
from siconos_env import siconos_python

RHO = 2500.0
G = 9.81
H = 2.0e-3
MU = 0.3
WIDTH = 0.2625  # box [m]
# Compared: x, y and the arc r theta through which each disk turned [m]. Both codes solve every
# step to 1e-12 (column) and 1e-10 (deposit) relative errors; the velocities then differ by
# about that times |v| <= 1 m/s, the positions by h times that per step. Measured: 1e-14 m on
# the columns, 1.4e-10 m over the 120 steps of the deposit (the arcs: the spins are the least
# constrained unknowns); DIFF_MAX leaves two orders of magnitude of margin, while a different
# rule of activation or geometry moves disks by 1e-5 m or more within a few steps of the first
# contact (MULTICOR's default scheme: 3-5 mm on the columns, 2 cm on the deposit).
DIFF_MAX = 1.0e-8
# The default scheme must differ from Siconos' by much more than DIFF_MAX somewhere.
DIFF_OTHER = 1.0e-6


def column():
    """Three disks stacked off centre above the floor (x, y, r)."""
    return np.array([[0.1, 0.0125, 0.01], [0.1005, 0.0372, 0.012], [0.099, 0.07, 0.009]])


def deposit(n_row=5, n_rows=6, r=0.01, seed=3):
    """Staggered lattice of pitch 2.5 r, radii uniform in [0.8 r, 1.2 r]: no two disks touch."""
    rng = np.random.default_rng(seed)
    p = 2.5 * r
    out = []
    for j in range(n_rows):
        for i in range(n_row):
            out.append([p * (0.5 + i + 0.5 * (j % 2)), p / 2 + j * p * np.sqrt(3.0) / 2,
                        r * (0.8 + 0.4 * rng.random())])
    return np.array(out)


def write_inputs(work, name, disks, e, tol, steps, scheme, theta):
    """The layout as the CSV of bench_dem (for siconos_deposit.py) and as a deck."""
    csv, deck = write_box_layout(work, f"{name}_{scheme}", disks, WIDTH, rho=RHO, g=G, mu=MU, e=e, tol=tol,
                                 max_sweeps=1000000, h=H, steps=steps, interval=1,
                                 title=f"{name}: MULTICOR with the {scheme} contact scheme",
                                 time_extra=f"theta = {theta}\ncontact_scheme = {scheme}\n")
    return csv, deck


def run_multicor(exe, deck, out):
    proc = subprocess.run([str(exe), str(deck), "--output", str(out), "--quiet"], capture_output=True, text=True)
    if proc.returncode != 0:
        print(proc.stdout, proc.stderr)
        raise SystemExit(f"multicor failed on {deck.name} (exit {proc.returncode})")
    with h5py.File(out / (deck.stem + ".h5"), "r") as f:
        scheme = f["dem"].attrs["contact_scheme"]
        scheme = scheme.decode() if isinstance(scheme, bytes) else str(scheme)
        return f["dem/position"][1:], f["dem/solver/converged"][...], scheme


def run_siconos(python, env, script, csv, e, tol, steps, theta, traj):
    proc = subprocess.run([python, str(script), str(csv), "--h", str(H), "--steps", str(steps), "--e", str(e),
                           "--theta", str(theta),
                           "--mu", str(MU), "--tol", str(tol), "--max-iter", "100000", "--trajectory", str(traj)],
                          capture_output=True, text=True, env=env)
    if proc.returncode != 0:
        print(proc.stdout, proc.stderr)
        raise SystemExit(f"siconos_deposit.py failed on {csv.name} (exit {proc.returncode})")
    data = np.load(traj)
    return data["q"], data["converged"]


def case(exe, work, python, env, script, name, disks, e, tol, steps, min_compared, theta=0.5):
    csv, deck = write_inputs(work, name, disks, e, tol, steps, "siconos", theta)
    _, deck_default = write_inputs(work, name, disks, e, tol, steps, "multicor", theta)
    mc, mc_conv, scheme = run_multicor(exe, deck, work / f"{name}_siconos")
    other, _, _ = run_multicor(exe, deck_default, work / f"{name}_multicor")
    sic, sic_conv = run_siconos(python, env, script, csv, e, tol, steps, theta, work / f"{name}.npz")
    check(f"{name}: the results name the scheme", scheme == "siconos", f"contact_scheme = {scheme!r}")
    check(f"{name}: every MULTICOR step converged", mc_conv.all(), f"{mc_conv.sum()} of {len(mc_conv)}")
    # compare up to the first step where Siconos' NSGS stopped at its cap (after that the two
    # codes integrate from different states)
    n = int(np.argmin(sic_conv)) if not sic_conv.all() else steps
    check(f"{name}: Siconos converged on enough steps", n >= min_compared, f"{n} of {steps} (need {min_compared})")
    # x, y and the arc r theta each disk's surface turned through [m]
    scale = np.array([1.0, 1.0, 0.0])[None, :] + np.outer(disks[:, 2], [0.0, 0.0, 1.0])
    mc, other, sic = (a * scale[None, :, :] for a in (mc, other, sic))
    diff = np.abs(mc[:n] - sic[:n]).max() if n > 0 else np.inf
    check(f"{name}: the same trajectory as Siconos 4.4", diff <= DIFF_MAX,
          f"max |x, y, r theta (multicor - siconos)| over {n} steps: {diff:.2e} m (bound {DIFF_MAX:.0e})")
    diff_other = np.abs(other[:n] - sic[:n]).max() if n > 0 else 0.0
    check(f"{name}: the default scheme differs from Siconos'", diff_other >= DIFF_OTHER,
          f"max |x, y, r theta (multicor default - siconos)| over {n} steps: {diff_other:.2e} m")


def main():
    exe, work, src = arguments()
    script = src / "bench" / "siconos_deposit.py"
    python, env = siconos_python("siconos.kernel, siconos.mechanics.collision.bodies, numpy")
    # every step converges on the column (three contacts at most): all 100 compared
    case(exe, work, python, env, script, "column", column(), 0.0, 1e-12, 100, 100)
    case(exe, work, python, env, script, "column_e", column(), 0.5, 1e-12, 100, 100)
    case(exe, work, python, env, script, "column_theta1", column(), 0.0, 1e-12, 100, 100, theta=1.0)
    # the deposit: the pile forms from step 25 on; NSGS at 1e-10 may stop at its cap later
    case(exe, work, python, env, script, "deposit", deposit(), 0.0, 1e-10, 120, 60)
    return summary()


if __name__ == "__main__":
    sys.exit(main())
