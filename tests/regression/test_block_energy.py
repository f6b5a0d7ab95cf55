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
    the work of the loads and of the driven wall;
  - /dem/solver/block_given_up marks exactly the steps whose block was given up, steps 6 and 7
    (doc/theory.md 7.10), among them every step with more than max_sweeps iterations (the block
    passes of a step take at most max_sweeps: only the plain sweeps of a step given up add
    more), and /dem/solver@block_given_up_steps is their number; the run warns once, at step
    6, and its summary counts 2 of 10 steps;
  - stopped after step 6 and restarted, the run records the same steps and does not warn again
    (the count is in the checkpoint);
  - the same deck with anderson = 0, with criterion = siconos and with max_sweeps = 100000
    (doc/theory.md 7.10) never gives the block up: the dataset holds zeros, the attribute is 0,
    no warning, no summary line;
  - a lattice pulled apart (dem_bonded_pull_lattice.dat: rigid bonds under an imposed pull, the
    block's equalities without a solution at step 1, its reactions of order 1/eps until every
    bond is released) is not given up: the guard judges only blocks that have a solution;
  - a lattice at rest after its load is removed (dem_bonded_unloaded_lattice.dat: no gravity,
    its velocities and the energy its reactions create round-off alone) is not given up and
    creates no energy: the guard allows for the round-off of the energies it compares;
  - the same lattice solved by the plain sweeps (method = nlgs, every step converged): the time
    loop reports no energy created, its allowance covering velocities in error by the sweeps'
    tolerance times the sizes of their terms (the self-stress's cancelling impulses).
  - a hexagonal stack of 10 x 10 disks on a floor without cohesion, so without bonds, at
    max_sweeps = 2 (every step unconverged; an audit's deck): method = block gives the same
    results as method = nlgs, bit for bit (doc/input.md, [solver] method: a step without
    intact bonds is the same sweeps with both), and no 'bonded block' warning or summary
    line. The guard judged the steps of an empty block too: at step 16 a pass of the plain
    sweeps, unconverged, created energy, and the step was solved again from zero reactions
    where nlgs keeps its warm start, with a warning about the self-stresses of a bonded
    lattice the deck does not have.
  - a bonded column jerked to 2 m/s by the wall it hangs from (the bond to the wall holds the
    wall's velocity, a shift of the solver): the column's kinetic energy and the wall's work
    from the closed form; the guard never gives the block up.
Usage (ctest does this): test_block_energy.py --exe multicor --work DIR --source REPO
"""
import re
import subprocess
import sys

import h5py
import numpy as np

from checks import arguments, check, datasets, summary

MAX_SWEEPS = 100
GIVEN_UP_STEPS = [6, 7]
WARNING = "the bonded block ([solver] method = block) was given up"
SUMMARY = "bonded block given up (energy guard, solved by plain sweeps):"


def run(exe, deck, out, *extra):
    return subprocess.run([str(exe), str(deck), "--output", str(out), "--quiet", *extra], capture_output=True,
                          text=True)


def given_up_record(path):
    """Per-step flags (steps from 1 where set), their attribute, and the sweeps per step."""
    with h5py.File(path, "r") as f:
        s = f["dem/solver"]
        flags = s["block_given_up"][...]
        return flags, int(s.attrs["block_given_up_steps"]), s["sweeps"][...]


def check_given_up(exe, deck, out, proc):
    """The record, warning and summary of the steps given up on the deck."""
    flags, total, sweeps = given_up_record(out / f"{deck.stem}.h5")
    marked = (np.flatnonzero(flags) + 1).tolist()
    check("/dem/solver/block_given_up holds 0 or 1 per step", set(flags.tolist()) <= {0, 1} and
          flags.size == sweeps.size, f"{flags.tolist()}")
    check(f"block_given_up marks steps {GIVEN_UP_STEPS}", marked == GIVEN_UP_STEPS, f"marked {marked}")
    over = (np.flatnonzero(sweeps > MAX_SWEEPS) + 1).tolist()
    check(f"every step with more than max_sweeps = {MAX_SWEEPS} iterations is marked",
          over and set(over) <= set(marked), f"steps over the cap {over}, sweeps {sweeps.tolist()}")
    check("block_given_up_steps is the number of steps marked", total == len(marked), f"{total}")
    warnings = [line for line in proc.stdout.splitlines() if WARNING in line]
    check("one warning, at step 6, naming the cause and the settings",
          len(warnings) == 1 and warnings[0].startswith("warning: step 6 ") and "self-stresses" in warnings[0] and
          "doc/theory.md 7.10" in warnings[0] and "max_sweeps" in warnings[0] and "criterion = siconos" in warnings[0]
          and "anderson = 0" in warnings[0], "\n".join(warnings))
    line = [line for line in proc.stdout.splitlines() if line.startswith(SUMMARY)]
    check("the summary counts 2 of 10 steps", len(line) == 1 and re.search(r": 2 of 10 steps", line[0]), f"{line}")
    return flags


def restarted(exe, deck, work, flags):
    """Stopped after step 6 (the first given up), then restarted to the end."""
    out = work / "restarted"
    first = run(exe, deck, out, "--end", "1.2e-4")
    if not check("stopped after step 6: exit 0", first.returncode == 0, first.stderr.strip()[-300:]):
        return
    check("the first part warns at step 6", sum(WARNING in x for x in first.stdout.splitlines()) == 1, "")
    second = run(exe, deck, out, "--restart", out / "checkpoint.h5")
    if not check("restart: exit 0", second.returncode == 0, second.stderr.strip()[-300:]):
        return
    again, total, _ = given_up_record(out / f"{deck.stem}.h5")
    check("restarted: the same steps marked", np.array_equal(again, flags), f"{again.tolist()}")
    check("restarted: block_given_up_steps 2", total == 2, f"{total}")
    check("restarted: no second warning (step 7 is only counted)", WARNING not in second.stdout, second.stdout[-600:])
    check("restarted: the summary counts 2 of 10 steps", f"{SUMMARY} 2 of 10 steps" in second.stdout, "")


def never_given_up(exe, deck, work, setting):
    """The deck with one [solver] setting changed (doc/theory.md 7.10): the block kept."""
    key = setting.split("=")[0].strip()
    text = deck.read_text()
    lines = [x for x in text.splitlines() if not x.startswith(key + " ")]
    variant = work / f"lattice_{key}.dat"
    variant.write_text("\n".join(lines).replace("[solver]", f"[solver]\n{setting}") + "\n")
    out = work / variant.stem
    proc = run(exe, variant, out)
    if not check(f"{setting}: the run ends", proc.returncode == 0, proc.stderr.strip()[-300:]):
        return
    flags, total, _ = given_up_record(out / f"{variant.stem}.h5")
    check(f"{setting}: no step given up, no warning, no summary line",
          not flags.any() and total == 0 and WARNING not in proc.stdout and SUMMARY not in proc.stdout,
          f"{flags.tolist()}, attribute {total}")


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
    flags = check_given_up(exe, deck, out, proc)
    restarted(exe, deck, work, flags)
    for setting in ("anderson = 0", "criterion = siconos", "max_sweeps = 100000"):
        never_given_up(exe, deck, work, setting)
    pulled(exe, src, work)
    unloaded(exe, src, work)
    bond_free(exe, work)
    wall_pull(exe, work)
    return summary()


# three bonded disks (R = 0.125 m, 1000 kg/m3) hanging from a wall that moves down at 2 m/s
# from t = 0 (a mutation audit's deck): the bond to the wall carries the solver's shift of
# the wall's velocity
WALL_PULL_DECK = """[run]
analysis = dynamic
[particles]
material = 1 1000
disk = 0 -0.125 0.125 1
disk = 0 -0.375 0.125 1
disk = 0 -0.625 0.125 1
gravity = 0 -9.81
[walls]
wall = -0.5 0 0.5 0 1 0 -2 1
[contacts]
law = 1 1 0.3 0 1e6
bond = 1 1 0.5
alert = 0.00125
[functions]
function = 1 step 0.0
[time]
step = 1e-3
end = 0.02
[solver]
tolerance = 1e-12
max_sweeps = 10000
[output]
interval = 1
"""


def wall_pull(exe, work):
    """A bonded column jerked to 2 m/s by the wall it hangs from: the energy guard stays silent.
    The column takes K = 3 (1/2) m v^2 = 294.5 J/m; the wall's bond, holding the jump of
    velocity, does about twice that work (drive_work) and dissipates the other half: the
    reactions create no energy, and the block is kept at every step (1 iteration each). The guard counts
    the work of the shift the wall's velocity puts into the bond (r . shift); with its sign
    flipped the guard saw 2 K created and gave the block up at step 1 (149 sweeps)."""
    deck = work / "wall_pull.dat"
    deck.write_text(WALL_PULL_DECK)
    out = work / deck.stem
    proc = run(exe, deck, out)
    if not check("wall pull: the run ends", proc.returncode == 0, proc.stderr.strip()[-300:]):
        return
    flags, total, sweeps = given_up_record(out / f"{deck.stem}.h5")
    with h5py.File(out / f"{deck.stem}.h5", "r") as f:
        kinetic = f["dem/energy/kinetic"][...]
        drive = f["dem/energy/drive_work"][...]
    m, v, g, h = 1000.0 * np.pi * 0.125 ** 2, 2.0, 9.81, 1e-3
    k_jump = 3 * 0.5 * m * v ** 2
    # the bonds hold the column to the wall: from step 1 on it moves at the wall's 2 m/s, and
    # the wall's impulse in step 1 is the momentum 3 m v less what gravity gave (3 m g h),
    # its work that times v. Solves to 1e-12 relative on impulses of order m v: 1e-9 leaves
    # a margin.
    drive_1 = v * (3 * m * v - 3 * m * g * h)
    check("wall pull: the column takes 3 (1/2) m v^2 at step 1, the wall's work v (3 m v - 3 m g h)",
          abs(kinetic[1] - k_jump) <= 1e-9 * k_jump and abs(drive[1] - drive_1) <= 1e-9 * drive_1,
          f"K {kinetic[1]:.10e} ({k_jump:.10e}), drive work {drive[1]:.10e} ({drive_1:.10e})")
    check("wall pull: the block never given up, 1 iteration per step, no warning",
          not flags.any() and total == 0 and sweeps.max() == 1 and WARNING not in proc.stdout,
          f"given up {flags.tolist()}, sweeps {sweeps.tolist()}")


BOND_FREE_DECK = """[run]
analysis = dynamic
[particles]
material = 1 2500
hex_lattice = 10 10 0 0.01 0.01 1
gravity = 0 -9.81
[walls]
wall = -1 0 1 0
wall = -0.02 0 -0.02 1
wall = 0.2 0 0.2 1
[contacts]
law = 1 1 0.5 0 0
[time]
step = 1e-3
end = 0.05
[solver]
max_sweeps = 2
tolerance = 1e-12
"""


def bond_free(exe, work):
    """A stack without bonds, every step unconverged: method = block is method = nlgs, bit for bit.
    50 steps (the audit's deck ran 200): the guard that judged an empty block gave it up at
    step 16 (checked with that guard put back: the results differ and step 16 is marked at 30
    and 50 steps as at 200)."""
    results = {}
    for method in ("block", "nlgs"):
        deck = work / f"bond_free_{method}.dat"
        deck.write_text(BOND_FREE_DECK.replace("[solver]", f"[solver]\nmethod = {method}"))
        out = work / deck.stem
        proc = run(exe, deck, out)
        if not check(f"bond-free stack, method = {method}: the run ends", proc.returncode == 0,
                     proc.stderr.strip()[-300:]):
            return
        # every dataset of /dem (the results of the steps: no timings are stored there)
        results[method] = datasets(out / f"{deck.stem}.h5", "dem"), proc.stdout
    (block, said), (nlgs, _) = results["block"], results["nlgs"]
    check("bond-free stack: no bond, every step unconverged (the guard's path with an empty block)",
          block["bonds/i"].size == 0 and block["solver/converged"].size == 50 and not block["solver/converged"].any(),
          f"bonds {block['bonds/i'].size}, converged steps {int(block['solver/converged'].sum())}")
    # bit for bit: the same sweeps from the same warm start in the same order
    differ = sorted(name for name in nlgs if name not in block or not np.array_equal(block[name], nlgs[name]))
    check("bond-free stack: method = block gives method = nlgs's results bit for bit", not differ,
          f"differing datasets {differ}")
    check("bond-free stack: no step given up, no 'bonded block' warning, no summary line",
          not block["solver/block_given_up"].any() and WARNING not in said and SUMMARY not in said,
          f"marked {(np.flatnonzero(block['solver/block_given_up']) + 1).tolist()}")


def pulled(exe, src, work):
    """The pulled lattice: its block has no solution at step 1 and releases every bond; the
    guard, judging that pass's reactions (of order 1/eps), gave the block up instead."""
    deck = src / "tests" / "regression" / "decks" / "dem_bonded_pull_lattice.dat"
    out = work / deck.stem
    proc = run(exe, deck, out)
    if not check("pulled lattice: the run ends", proc.returncode == 0, proc.stderr.strip()[-300:]):
        return
    flags, total, _ = given_up_record(out / f"{deck.stem}.h5")
    check("pulled lattice: no step given up", not flags.any() and total == 0, f"{flags.tolist()}")


def unloaded(exe, src, work):
    """The lattice at rest after its load is removed: the round-off of its velocities, 1e-60 J/m
    of kinetic energy from 1e-66 J/m free, exceeded 0.1 of the kinetic energy, and the block was
    given up at steps 14, 20 and 26 (the plain sweeps from zero reactions then created 3e-28
    J/m, a second warning)."""
    deck = src / "tests" / "regression" / "decks" / "dem_bonded_unloaded_lattice.dat"
    out = work / deck.stem
    proc = run(exe, deck, out)
    if not check("unloaded lattice: the run ends", proc.returncode == 0, proc.stderr.strip()[-300:]):
        return
    flags, total, _ = given_up_record(out / f"{deck.stem}.h5")
    check("unloaded lattice: no step given up, no warning, no summary line",
          not flags.any() and total == 0 and WARNING not in proc.stdout and SUMMARY not in proc.stdout,
          f"marked {(np.flatnonzero(flags) + 1).tolist()}")
    check("unloaded lattice: no energy created (no warning, no summary line)",
          "created" not in proc.stdout, proc.stdout[-600:])
    unloaded_sweeps(exe, deck, work)


def unloaded_sweeps(exe, deck, work):
    """The same lattice solved by the plain sweeps (method = nlgs; max_sweeps = 100000, with
    which every step converges, so that the time loop judges every step's energy). At rest its
    self-stress, 0.014 N/m in the bonds, gives the disks 3.6e-6 m/s each that cancel but for
    the sweeps' tolerance: 3e-10 m/s are left, 8e-19 J/m, and a step changes that by about as
    much either way. The time loop's allowance (1e-3 of the kinetic energy, round-off of the run
    totals) did not cover it: 'the contacts created 1.2e-19 J/m' at step 15, 11 of the 30 steps
    counted. The allowance now adds the kinetic energy of velocities in error by the tolerance
    times the sizes of their terms, 5e-18 J/m here (doc/theory.md 2.5)."""
    text = deck.read_text().replace("[time]", "[solver]\nmethod = nlgs\nmax_sweeps = 100000\n[time]")
    variant = work / "unloaded_sweeps.dat"
    variant.write_text(text)
    out = work / variant.stem
    proc = run(exe, variant, out)
    if not check("unloaded lattice, plain sweeps: the run ends", proc.returncode == 0, proc.stderr.strip()[-300:]):
        return
    with h5py.File(out / f"{variant.stem}.h5", "r") as f:
        converged = f["dem/solver/converged"][...]
    check("unloaded lattice, plain sweeps: every step converged (the time loop judges each)",
          converged.all() and converged.size == 30, f"{converged.tolist()}")
    check("unloaded lattice, plain sweeps: no energy created (no warning, no summary line)",
          "created" not in proc.stdout, proc.stdout[-600:])


if __name__ == "__main__":
    sys.exit(main())
