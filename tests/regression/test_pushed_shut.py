#!/usr/bin/env python3
"""Contacts shut within a step by the impulses of other contacts (doc/theory.md 2.4): the rule
of activation (`[time] contact_scheme = multicor`) re-checks after the solve the contacts it
left out, on the end-of-step velocities, and lets in those shut beyond the round-off
allowance; the step is solved again (`/dem/solver/solves`). Before, such a contact was never
in the solve and the disks overlapped for good.

- tests/regression/decks/dem_pushed_shut.dat (its header has the closed form): theta = 1 lets
  no contact overlap beyond the allowance; theta = 1/2 lets one go at most
  (1 - theta) h |u_n| farther in per step, u_n its normal velocity at the start of the step;
  the same with every `[solver] method`; Siconos' rule does not re-check (one solve per step,
  the floor contact left out of step 1 as in Siconos 4.4);
- columns of 8 and 12 disks 1e-5 m apart, hit from above at 1 m/s: the re-check lets in the
  contact shut and every contact within reach of the step, the whole column: 2 solves; with
  [solver] max_sweeps = 1, which bounds the sweeps of all the solves of a step, the contact
  shut stays out and the step is reported unconverged with a warning;
- three disks 3e-4 m apart, e = 1, the first at 1 m/s: sequential collisions at h = 0.1 ms;
  at h = 1 ms both impacts fall in step 1 and are solved together, a closed form; momentum
  kept, energy never created;
- tests/regression/decks/dem_column_drop.dat (three disks dropped at h = 2 ms): no overlap at
  theta = 1, the per-step bound at theta = 1/2, and a run stopped and restarted gives the
  same record, bit for bit (the re-check keeps no state of its own).
Usage (ctest does this): test_pushed_shut.py --exe multicor --work DIR --source REPO
"""
import re
import subprocess
import sys

import h5py
import numpy as np

from checks import arguments, check, multicor, summary

R = 0.05
# The activation's round-off allowance, [time] gap_allowance 1e-10 times the radius: a contact
# left out is let in when its end-of-step gap is below minus this.
ALLOW = 1e-10 * R


def variant(src, work, name, theta=None, solver=(), scheme=None):
    """Copy of deck `src` named `name`, with theta, [solver] lines or contact_scheme changed."""
    text = src.read_text()
    if theta is not None:
        text = re.sub(r"^theta\s*=.*$", f"theta = {theta}", text, count=1, flags=re.M)
    if scheme is not None:
        text = text.replace("[time]\n", f"[time]\ncontact_scheme = {scheme}\n", 1)
    if solver:
        text = text.replace("[solver]\n", "[solver]\n" + "\n".join(solver) + "\n", 1)
    out = work / f"{name}.dat"
    out.write_text(text)
    return out


def column_deck(work, n, theta):
    """n disks in a vertical column, 1e-5 m apart and above the floor, at rest; the top one
    falls at 1 m/s; no gravity, e = 0, h = 1 ms, three steps."""
    ys = [R + 1e-5 + k * (2 * R + 1e-5) for k in range(n)]
    disks = "".join(f"disk = 0 {y!r} {R} 1\n" for y in ys)
    out = work / f"column{n}_{theta}.dat"
    out.write_text("[run]\nanalysis = dynamic\n[particles]\nmaterial = 1 2500\n" + disks +
                   f"initial_velocity = {n} y -1.0\n[walls]\nwall = -1 0 1 0\n[contacts]\n"
                   "law = 1 1 0.3 0 0\n[time]\nstep = 1e-3\nend = 3e-3\n"
                   f"theta = {theta}\n[solver]\ntolerance = 1e-12\n[output]\ninterval = 1\n")
    return out


def record(path):
    """Gaps of a vertical column (floor-disk 1, then each pair of consecutive disks) and their
    normal velocities at every output, and the per-step solver record."""
    with h5py.File(path, "r") as f:
        y = f["dem/position"][:, :, 1]
        vy = f["dem/velocity"][:, :, 1]
        rec = {name: f[f"dem/solver/{name}"][...] for name in ("solves", "converged", "sweeps")}
        rec["unconverged_steps"] = int(f["dem/solver"].attrs["unconverged_steps"])
        rec["position"] = f["dem/position"][...]
        rec["velocity"] = f["dem/velocity"][...]
    rec["gap"] = np.c_[y[:, :1] - R, np.diff(y, axis=1) - 2 * R]
    rec["un"] = np.c_[vy[:, :1], np.diff(vy, axis=1)]
    rec["vy"] = vy
    return rec


def step_excess(rec, theta, h):
    """Largest amount by which a step took a contact farther in than the scheme allows: the end
    gap g+ >= min(g, 0) - (1 - theta) h max(-u_n, 0) - allowance, with g and u_n the gap and
    normal velocity at the start of the step (doc/theory.md 2.4: the gap term holds the end
    gap at >= 0 or at the mid gap, Newton at >= the mid gap g + (1 - theta) h u_n, the re-check
    a contact left out at >= -allowance). Exact for these vertical columns, whose gaps are
    linear in the motion."""
    g, un = rec["gap"], rec["un"]
    bound = np.minimum(g[:-1], 0) - (1 - theta) * h * np.maximum(-un[:-1], 0) - ALLOW
    return float((bound - g[1:]).max())


def pushed_pair(exe, decks, work):
    deck = decks / "dem_pushed_shut.dat"
    h = 1e-3
    for theta, v1 in ((1.0, -0.1), (0.5, -0.2)):
        name = f"theta {theta:g}"
        rec = record(multicor(exe, variant(deck, work, f"pushed_{theta}", theta=theta), work)[0])
        # the closed form of the deck's header (v1 = -g/(theta h)): two contacts solved to 1e-12
        # relative on velocities of 1 m/s, 1e-12 m/s
        check(f"pushed pair, {name}: both disks at {v1} m/s after step 1 (floor let in by the re-check)",
              np.abs(rec["vy"][1] - v1).max() < 1e-12, f"{rec['vy'][1]}")
        check(f"pushed pair, {name}: step 1 solved twice, the others once",
              rec["solves"].tolist() == [2, 1, 1, 1, 1] and rec["converged"].all(), f"{rec['solves'].tolist()}")
        excess = step_excess(rec, theta, h)
        check(f"pushed pair, {name}: no step takes a contact in by more than (1 - theta) h |u_n|",
              excess <= 0, f"worst excess {excess:.3g} m (before the re-check: 1.5e-4 m at theta 1/2, 4e-4 m at 1)")
    rec_1 = record(work / "pushed_1.0" / "pushed_1.0.h5")
    check("pushed pair, theta 1: no overlap beyond the allowance 1e-10 R at any output",
          rec_1["gap"].min() >= -ALLOW, f"min gap {rec_1['gap'].min():.3g} m (4e-4 m before)")
    rec_h = record(work / "pushed_0.5" / "pushed_0.5.h5")
    # at rest 1e-4 m inside: (1 - theta) h 0.2 m/s at step 2 (coordinates of 0.05 m: 1e-15 m)
    check("pushed pair, theta 1/2: disk 1 rests (1 - theta) h 0.2 m/s = 1e-4 m in the floor",
          abs(rec_h["gap"][-1, 0] + 1e-4) < 1e-15, f"{float(rec_h['gap'][-1, 0])!r} m (4e-4 m before)")
    # every strategy of the solve goes through the re-check
    for method in ("nlgs", "block", "coarse"):
        for theta, v1 in ((1.0, -0.1), (0.5, -0.2)):
            deck_m = variant(deck, work, f"pushed_{method}_{theta}", theta=theta, solver=(f"method = {method}",))
            rec = record(multicor(exe, deck_m, work)[0])
            check(f"pushed pair, method = {method}, theta {theta:g}: the floor let in, {v1} m/s after step 1",
                  np.abs(rec["vy"][1] - v1).max() < 1e-12 and rec["solves"][0] == 2 and rec["converged"].all(),
                  f"{rec['vy'][1]}, solves {rec['solves'].tolist()}")
    # Siconos' rule decides once per step, before the solve (doc/theory.md 2.6): one solve, the
    # floor out of step 1, disk 1 at -0.5 m/s ending 1e-4 - 5e-4 m from the floor
    rec = record(multicor(exe, variant(deck, work, "pushed_siconos", scheme="siconos"), work)[0])
    check("pushed pair, contact_scheme = siconos: one solve per step, floor left out of step 1",
          rec["solves"].tolist() == [1] * 5 and abs(rec["vy"][1, 0] + 0.5) < 1e-12 and
          abs(rec["gap"][1, 0] + 4e-4) < 1e-15, f"solves {rec['solves'].tolist()}, v {rec['vy'][1]}, "
          f"floor gap {float(rec['gap'][1, 0])!r} m")


def columns(exe, work):
    h = 1e-3
    for n in (8, 12):
        for theta in (1.0, 0.5):
            rec = record(multicor(exe, column_deck(work, n, theta), work)[0])
            # the first solve shuts the contact below the struck pair; the re-check lets it in
            # with every contact within reach of the step (gaps of 1e-5 m against 2 theta h
            # 0.5 m/s), the whole column: one more solve
            check(f"column of {n}, theta {theta:g}: step 1 solved twice (the column let in at once), converged",
                  rec["solves"][0] == 2 and rec["converged"].all(), f"solves {rec['solves'].tolist()}")
            excess = step_excess(rec, theta, h)
            check(f"column of {n}, theta {theta:g}: no step takes a contact in by more than (1 - theta) h |u_n|",
                  excess <= 0, f"worst excess {excess:.3g} m")
    # [solver] max_sweeps bounds the sweeps of all the solves of a step: with 1, the first solve
    # takes it, and the contact it shut stays out (counted, reported)
    deck = column_deck(work, 12, 1.0)
    capped = work / "column12_capped.dat"
    capped.write_text(deck.read_text().replace("[solver]\n", "[solver]\nmax_sweeps = 1\n", 1))
    out, proc = multicor(exe, capped, work, quiet=False)
    rec = record(out)
    warnings = [line for line in proc.stdout.splitlines() if line.startswith("warning: step 1 ")]
    check("column of 12, max_sweeps = 1: step 1 one solve, reported unconverged",
          rec["solves"][0] == 1 and rec["converged"][0] == 0 and rec["unconverged_steps"] >= 1,
          f"solves {rec['solves'].tolist()}, converged {rec['converged'].tolist()}")
    check("column of 12, max_sweeps = 1: the warning says why (a contact still shut, left out)",
          len(warnings) == 1 and "still shut 1 contact" in warnings[0] and "doc/theory.md 2.4" in warnings[0]
          and "max_sweeps" in warnings[0], "\n".join(warnings) or proc.stdout[-400:])

def cradle_deck(work, h, theta):
    """Three disks in a row along x, 3e-4 m apart, no gravity, e = 1, mu = 0; disk 1 at 1 m/s
    towards the others; 20 ms at step h."""
    xs = [k * (2 * R + 3e-4) for k in range(3)]
    disks = "".join(f"disk = {x!r} 0.2 {R} 1\n" for x in xs)
    out = work / f"cradle_{h:g}_{theta}.dat"
    out.write_text("[run]\nanalysis = dynamic\n[particles]\nmaterial = 1 2500\n" + disks +
                   "initial_velocity = 1 x 1.0\n[contacts]\nlaw = 1 1 0.0 1 0\n[time]\n"
                   f"step = {h!r}\nend = 0.02\ntheta = {theta}\n[solver]\ntolerance = 1e-12\n"
                   "[output]\ninterval = 1\n")
    return out


def cradle(exe, work):
    """Elastic impacts that one step chains (doc/theory.md 2.4). Two disks struck in turn, 3e-4 m
    apart, at 1 m/s: the impacts are 0.3 ms apart. At h = 0.1 ms each has its own steps and the
    row ends as the sequential collisions leave it, (0, 0, 1) m/s. At h = 1 ms both fall in the
    first step: the first contact closes by its free motion (Newton, u_n >= e 1 m/s), the second
    is shut by the first's impulse and let in by the re-check with the gap term
    u_n >= -g/(theta h); the solve of both gives, with a = -(1 + t)/3 and t = -g/(theta h),
    v = (a, a + 1, a + 1 + t) after step 1, and disks 2 and 3 then swap their velocities in an
    impact of their own: (a, a + 1 + t, a + 1) at the end. Momentum is kept, energy is lost,
    never created. (Before the re-check the second pair overlapped by 4e-4 m and bounced at
    the next step.)"""
    g = 3e-4
    for theta in (0.5, 1.0):
        for h in (1e-4, 1e-3):
            rec = record(multicor(exe, cradle_deck(work, h, theta), work)[0])
            vx = rec["velocity"][:, :, 0]
            if h == 1e-4:
                expect = {"end": np.array([0.0, 0.0, 1.0])}
                solves = "every step solved once"
                ok_solves = (rec["solves"] == 1).all()
            else:
                t = -g / (theta * h)
                a = -(1 + t) / 3
                expect = {"step 1": np.array([a, a + 1, a + 1 + t]), "end": np.array([a, a + 1 + t, a + 1])}
                solves = "step 1 solved twice (the re-check), the others once"
                ok_solves = rec["solves"][0] == 2 and (rec["solves"][1:] == 1).all()
            got = {"step 1": vx[1], "end": vx[-1]}
            # velocities of 1 m/s solved to 1e-12: 1e-12 m/s
            err = max(float(np.abs(got[k] - v).max()) for k, v in expect.items())
            check(f"cradle, h = {h:g}, theta {theta:g}: velocities {', '.join(expect)} the closed form",
                  err < 1e-12 and rec["converged"].all(), f"error {err:.3g} m/s, end {vx[-1]}")
            check(f"cradle, h = {h:g}, theta {theta:g}: {solves}", ok_solves, f"{rec['solves'][:5].tolist()}")
            # momentum 1 (unit masses, 1 m/s) and kinetic energy at most 1/2, to round-off
            momentum = np.abs(vx.sum(axis=1) - 1).max()
            energy = (vx**2).sum(axis=1).max() - 1
            check(f"cradle, h = {h:g}, theta {theta:g}: momentum kept, energy never created",
                  momentum < 1e-12 and energy < 1e-12, f"momentum error {momentum:.3g}, energy excess {energy:.3g}")


def column_drop(exe, decks, work):
    deck = decks / "dem_column_drop.dat"
    h = 2e-3
    rec = record(multicor(exe, deck, work)[0])
    check("column drop, theta 1: no overlap beyond the allowance at any of the 150 steps",
          rec["gap"].min() >= -ALLOW, f"min gap {rec['gap'].min():.3g} m (7.3e-4 m before)")
    check("column drop, theta 1: some landings solved twice, every step converged",
          (rec["solves"] > 1).any() and rec["converged"].all(),
          f"steps solved more than once {(np.flatnonzero(rec['solves'] > 1) + 1).tolist()}")
    rec_h = record(multicor(exe, variant(deck, work, "column_drop_half", theta=0.5), work)[0])
    excess = step_excess(rec_h, 0.5, h)
    check("column drop, theta 1/2: no step takes a contact in by more than (1 - theta) h |u_n|",
          excess <= 0 and rec_h["converged"].all(), f"worst excess {excess:.3g} m")
    # stopped at t = 0.1 s (before the landings), restarted from the checkpoint to the end
    out = work / "column_restart"
    first = subprocess.run([str(exe), str(deck), "--output", str(out), "--quiet", "--end", "0.1"],
                           capture_output=True, text=True)
    second = subprocess.run([str(exe), str(deck), "--output", str(out), "--quiet", "--restart",
                             str(out / "checkpoint.h5")], capture_output=True, text=True)
    if check("column drop restarted at t = 0.1 s: both parts exit 0", first.returncode == 0 and second.returncode == 0,
             (first.stderr + second.stderr).strip()[-300:]):
        again = record(out / "dem_column_drop.h5")
        same = all(np.array_equal(again[key], rec[key]) for key in ("position", "velocity", "solves", "sweeps"))
        check("column drop restarted: positions, velocities, solves and sweeps bit for bit", same, "")


def main():
    exe, work, src = arguments()
    decks = src / "tests" / "regression" / "decks"
    pushed_pair(exe, decks, work)
    columns(exe, work)
    cradle(exe, work)
    column_drop(exe, decks, work)
    return summary()


if __name__ == "__main__":
    sys.exit(main())
