#!/usr/bin/env python3
"""The tangential phase of the interface experiment (input/interface_shear.dat) on a reduced
copy: blocks 0.2 m wide (8 x 8 Q4 each, meshed by gmsh from input/interface_shear.geo), 4 rows
of 8 disks, the same pressure, drive and laws, 6 ms (slip 1.9 mm).

- normal phase (t = 1 ms, before the drive): each band's multipliers carry p w t in y
  (mean of two successive outputs) and nothing in x;
- sliding phase (constant drive rate, slip > 0.5 mm): the tangential resultants of the two
  bands are equal and opposite (the disk layer's momentum hardly changes), and the apparent
  friction T / N of the top band follows disks sliding without rolling over the disks of the
  row below, tan(atan(mu) - asin(s / 2R)) (e_r = R: rolling never costs less than sliding);
- the energy audits: the coupled system's (whose FE terms are the continuum's audit of the
  whole body) differs from the continuum's by round-off only; the continuum's audit of the
  whole body (with the work of the reactions on the prescribed dofs) moves only in the steps
  where the drive's rate jumps (kinks of its table function at 1, 2 and 3 ms, whose impulse
  the scheme does not represent) and is constant to round-off after the last one.
Usage (ctest does this): test_interface_shear.py --exe multicor --work DIR --source REPO
"""
import pathlib
import shutil
import subprocess
import sys

import h5py
import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "postproc"))
from multicor_post.coupled import region_forces  # noqa: E402
from multicor_post.interface import InterfaceRun, pair_mean, sliding_over_disks  # noqa: E402

from checks import arguments, check, summary

P, WIDTH, THICK, MU, R = 1.0e6, 0.2, 0.01, 0.3, 0.0125


def reduced_case(exe, src, work):
    gmsh = shutil.which("gmsh")
    if gmsh is None:
        print("skipped: gmsh not found (Debian package gmsh)")
        sys.exit(77)
    geo = (src / "input" / "interface_shear.geo").read_text()
    geo = geo.replace("w = 0.5;", "w = 0.2;").replace("= 21;", "= 9;")
    (work / "small.geo").write_text(geo)
    proc = subprocess.run([gmsh, "-2", "-format", "msh41", str(work / "small.geo"), "-o", str(work / "small.msh")],
                          capture_output=True, text=True)
    if proc.returncode != 0:
        print(proc.stdout, proc.stderr)
        raise SystemExit("gmsh failed on the reduced interface geometry")
    deck = (src / "input" / "interface_shear.dat").read_text()
    for old, new in [("mesh = file interface_shear.msh", "mesh = file small.msh"),
                     ("square_lattice = 20 4", "square_lattice = 8 4"),
                     ("box 0 0.5", "box 0 0.2"), ("end = 10e-3", "end = 6e-3")]:
        if old not in deck:
            raise SystemExit(f"input/interface_shear.dat has no '{old}': update this test")
        deck = deck.replace(old, new)
    path = work / "interface_small.dat"
    path.write_text(deck)
    out = work / "interface_small"
    proc = subprocess.run([str(exe), str(path), "--output", str(out), "--quiet"], capture_output=True, text=True)
    if proc.returncode != 0:
        print(proc.stdout, proc.stderr)
        raise SystemExit(f"multicor failed on {path} (exit {proc.returncode})")
    return out / "interface_small.h5"


def main():
    exe, work, src = arguments()
    h5 = reduced_case(exe, src, work)
    run = InterfaceRun(h5)
    t_top, n_top, t_bot, n_bot = run.band_resultants()
    # /coupling/rows/region: region 1 is the bottom band (the deck's first region line),
    # region 2 the top one; the rows' regions are those the test finds by the disks' heights,
    # and region_forces sums the same multipliers as band_resultants (pair-averaged here): equal
    # to round-off (the same numbers added in another order: 1e-12 of p w t)
    with h5py.File(h5, "r") as f:
        region = f["coupling/rows/region"][...]
    check("rows/region: 2 for the top band's rows, 1 for the bottom's",
          np.array_equal(region, np.where(run.top_rows, 2, 1)), f"{np.bincount(region)}")
    _, forces = region_forces(h5)
    load = P * WIDTH * THICK
    same = max(np.abs(pair_mean(forces[:, 1, 0]) - t_top).max(), np.abs(pair_mean(forces[:, 1, 1]) - n_top).max(),
               np.abs(pair_mean(forces[:, 0, 0]) - t_bot).max(), np.abs(pair_mean(forces[:, 0, 1]) - n_bot).max())
    check("region_forces: the bands' resultants", same <= 1e-12 * load, f"largest difference {same:.2e} N")
    s = run.slip()
    load = P * WIDTH * THICK

    k = int(np.argmin(np.abs(run.time - 1.0e-3)))
    # Static under the pressure after 1 ms (damped at a1 = 5e-5 s, 25 periods of the blocks'
    # first vertical mode): 2e-4 measured on the pair mean; asserted at 1e-2 of p w t.
    for name, n, sign in (("top", n_top[k], -1.0), ("bottom", n_bot[k], 1.0)):
        check(f"normal phase: the {name} band carries p w t", abs(n - sign * load) <= 1e-2 * load,
              f"{n:.2f} N vs {sign * load:.2f} N")
    # No tangential load before the drive: the square lattice is symmetric in x but its
    # contacts' NLGS solution is not exactly (0.5 N measured); asserted at 1e-2 of p w t.
    check("normal phase: no tangential force", abs(t_top[k]) <= 1e-2 * load, f"T_top = {t_top[k]:.3f} N")

    # The rate's last jump (3 ms) sets the top block oscillating on the layer (the normal
    # force swings by 20 %); it has decayed 1.5 ms later (stiffness-proportional damping):
    # the quasi-static sliding phase is t >= 4.5 ms.
    sliding = run.time >= 4.5e-3
    check("the top block slides (slip > 1.5 mm at 6 ms)", s[-1] > 1.5e-3, f"slip {s[-1] * 1e3:.3f} mm")
    check("the sliding phase has outputs", sliding.sum() >= 10, f"{sliding.sum()}")
    # Equal and opposite on average: T_top + T_bot is the rate of the disks' x momentum. While
    # sliding at the drive's constant rate the layer's momentum hardly changes, so its mean over
    # the sliding phase is small against T_top (measured 0.01-0.56 % over the deck's solver
    # settings, the sweeps to 1e-6, a cap of 1000 sweeps, alternating or forward sweeps); asserted
    # at 2 %: a band missing its weight or sign would give tens of %. The instantaneous sum is
    # not small: rows slipping and sticking give spikes of up to 8 % of T_top.
    balance = abs(np.mean(t_top[sliding] + t_bot[sliding])) / np.mean(np.abs(t_top[sliding]))
    check("sliding: the two bands' tangential forces balance on average", balance <= 0.02,
          f"|mean(T_top + T_bot)| / mean|T_top| = {balance:.4f}")
    mu_app = t_top[sliding] / -n_top[sliding]
    theory = sliding_over_disks(MU, s[sliding], R)
    # Quasi-static at 0.5 m/s (the top block's inertia acts only through the small vertical
    # motion of the sliding row; the block's shear between band and edge is 1e-5 of the slip):
    # 0.006-0.008 measured; asserted at 0.02 (the curve is 0.05 to 0.08 below mu over the
    # range: a constant T / N = mu fails).
    err = np.abs(mu_app - theory).max()
    check("sliding: apparent friction = tan(atan mu - asin(s/2R))", err <= 0.02,
          f"max deviation {err:.4f} over slip {s[sliding].min() * 1e3:.2f}..{s[sliding].max() * 1e3:.2f} mm "
          f"(T/N {mu_app.max():.3f}..{mu_app.min():.3f})")

    with h5py.File(h5, "r") as f:
        cpl_bal = f["coupling/energy/balance"][...]
        scale = abs(f["coupling/energy/external_work"][-1]) + abs(f["continuum/energy/reaction_work"][-1])
        fe_bal = f["continuum/energy/balance"][...]
        t_fe = f["continuum/energy/time"][...]
        reaction_work = f["continuum/energy/reaction_work"][-1]
    # The coupled audit's FE terms are the continuum's audit of the whole body: the two
    # balances differ by the disks' audit and the net work of the glue, sums of O(scale) terms
    # over 300 steps: round-off ~1e-13 of the scale; asserted at 1e-9. (Both move at the
    # drive's kinks, checked below.)
    bal = np.abs(cpl_bal - fe_bal).max()
    check("coupled audit closes (apart from the continuum audit's kink terms)", bal <= 1e-9 * scale,
          f"max |balance - continuum balance| {bal:.2e} J, scale {scale:.2e} J")
    after = t_fe > 3.0e-3 + 1e-9
    drift = np.ptp(fe_bal[after])
    # After the last kink the prescribed motion is linear in every step: the audit's
    # trapezoidal works match the scheme's identity exactly, round-off only; the kinks
    # themselves move it by about 1/2 dv_p.M dv_p (1e-3 J here).
    check("continuum audit (with reaction work) constant after the last kink of the drive",
          drift <= 1e-9 * abs(reaction_work), f"spread {drift:.2e} J, reaction work {reaction_work:.3e} J, "
          f"balance {fe_bal[-1]:.3e} J")
    return summary()


if __name__ == "__main__":
    sys.exit(main())
