#!/usr/bin/env python3
"""The bonded block ([solver] method = block) bounds the iterations of a step by max_sweeps and
never ends a step on reactions that create energy (doc/theory.md 7.10, "Energy guard").

Deck tests/regression/decks/dem_bonded_lattice_throw.dat (an audit's case, reduced): a bonded
hexagonal lattice thrown at 4 m/s and spinning into the corner of a floor and a wall, max_sweeps
= 100. Before: the impact step released its overloaded bonds one per pass, each pass with a cap
of its own (1 465 iterations at step 5); at step 6 the passes, each at the tolerance, raised the
kinetic energy from 1.3 to 2.5e7 J/m (the block's self-stresses set free as bonds were released)
and the run stopped on a disk through the floor with 4.6e8 J/m created.

Checks:
  - the run ends (exit 0) with every record finite;
  - every step takes at most max_sweeps block iterations over all its passes, or, when the
    energy guard gave the block up, max_sweeps more of the plain sweeps (2 max_sweeps);
  - the mechanical energy (kinetic + gravity potential) never exceeds its initial value plus
    the work of the loads and of the driven wall.
Usage (ctest does this): test_block_energy.py --exe multicor --work DIR --source REPO
"""
import subprocess
import sys

import h5py
import numpy as np

from checks import arguments, check, summary

MAX_SWEEPS = 100


def main():
    exe, work, src = arguments(fresh=True)
    deck = src / "tests" / "regression" / "decks" / "dem_bonded_lattice_throw.dat"
    out = work / deck.stem
    proc = subprocess.run([str(exe), str(deck), "--output", str(out), "--quiet"], capture_output=True, text=True)
    if not check("the run ends", proc.returncode == 0, f"exit {proc.returncode}: {proc.stderr.strip()[-400:]}"):
        return summary()
    with h5py.File(out / f"{deck.stem}.h5", "r") as f:
        sweeps = f["dem/solver/sweeps"][...]
        e = {k: f["dem/energy"][k][...] for k in ("kinetic", "potential", "external_work", "drive_work")}
    check("every record finite", all(np.isfinite(v).all() for v in e.values()), "")
    check(f"at most 2 x max_sweeps = {2 * MAX_SWEEPS} iterations per step", sweeps.max() <= 2 * MAX_SWEEPS,
          f"sweeps per step {sweeps.tolist()}")
    # the impact step, where the block releases bonds pass after pass and whose passes dissipate
    # (the guard keeps the block): the cap is that of the whole step
    check(f"step 5 (the impact): at most max_sweeps = {MAX_SWEEPS}", sweeps[4] <= MAX_SWEEPS, f"{sweeps[4]}")
    mech = e["kinetic"] + e["potential"]
    supplied = mech[0] + e["external_work"] + e["drive_work"]
    # every contact law here dissipates (e = 0, friction, cohesion; doc/theory.md 2.5): the
    # mechanical energy can only fall below what was there and what the loads and drives gave.
    # Unconverged steps err on the contacts' dissipation by the load they carry times the gaps
    # the unconverged velocities open or close (doc/output.md, `dissipated`), either sign; here
    # the energy falls at every step (largest excess 0). 1e-3 of the initial energy (6.9e-3
    # J/m) leaves room for that error and is 11 orders below the audit's 4.6e8 J/m
    excess = mech - supplied
    check("mechanical energy at most the initial energy plus the work supplied (+ 1e-3 of it)",
          np.all(excess <= 1e-3 * mech[0]), f"largest excess {excess.max():.3e} J/m of {mech[0]:.3e} J/m")
    return summary()


if __name__ == "__main__":
    sys.exit(main())
