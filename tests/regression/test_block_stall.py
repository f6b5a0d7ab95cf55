#!/usr/bin/env python3
"""The bonded block ([solver] method = block) releases bonds when, held, they leave the
problem without a solution (doc/theory.md 7.10, "Stall").

A wall of imposed velocity pushes a bonded stack held on the floor by its bonds. With the
bonds held as one block the stack cannot move while the wall's contact asks it to: the
problem of the pass has no solution, and its block Gauss-Seidel grew the reactions by the
same step at every iteration, the relative error falling only as they grew (1/iterations).
No pass converged, so the outer check never ran: every step from the first contact on ended
at the cap of 20 000 iterations, no bond broke and the wall went through the disks by its
own motion, 5e-5 m per step (2.3e-4 m after 8 steps), 2 356 J/m of its work booked as
dissipated. A pass now stops when its norm has the signature of that growth and a bond lies
outside its cone; the bond is released and the step solved again.

Checks, deck tests/regression/decks/dem_bonded_wall_push.dat (8 steps), against the same deck
with method = nlgs (independent: every contact swept, each bond projected onto its cone):
  - every step converged with both methods;
  - bonds break, and the same ones in the same mode at the same step as with nlgs (the
    ruptures of this stack are decided by the wall's load at its first contact);
  - the wall does not go through the disks: the overlap is at most the (1 - theta) h v_wall
    a contact made within a step leaves (the disks take the wall's velocity at its end, their
    positions advance with theta of it), and stays that of the contact step afterwards;
  - energy: the balance closes, the wall's work, the dissipated and the kinetic energies are
    those of nlgs, and the work is at most 2 M v_wall^2 (M the stack's mass: an inelastic
    push at v_wall costs M v_wall^2, the floor's friction and the bonds over a few steps a
    fraction of it);
  - with max_sweeps = 64 the first pass of step 4 stalls at its first test (64 iterations)
    with no iteration left: the step's warning says why and that more iterations help.
Usage (ctest does this): test_block_stall.py --exe multicor --work DIR --source REPO
"""
import sys

import h5py
import numpy as np

from checks import arguments, check, multicor, summary, with_solver_lines

DECK = "dem_bonded_wall_push.dat"
THETA = 0.5  # [time] theta, the default
H = 5.0e-4  # [time] step of the deck
V_WALL = 0.1  # the moving wall's speed [m/s]
CONTACT_STEP = 4  # the wall, 0.17 mm away at 0.05 mm per step, reaches the stack in step 4


def variant(src, work, name, extra, cap=20000):
    """The deck with extra [solver] lines and max_sweeps = cap."""
    deck = with_solver_lines(src / "tests" / "regression" / "decks" / DECK, work / f"{name}.dat", extra)
    deck.write_text(deck.read_text().replace("max_sweeps = 20000\n", f"max_sweeps = {cap}\n", 1))
    return deck


def results(path):
    with h5py.File(path, "r") as f:
        d = f["dem"]
        r = d["particles/radius"][...]
        pos, walls = d["position"][...], d["walls/position"][...]
        # overlap of the moving (last, vertical) wall with the disks, per output (every step)
        overlap = (pos[:, :, 0] + r[None, :] - walls[:, -1, 0][:, None]).max(axis=1)
        e = d["energy"]
        b = d["bonds"]
        return dict(converged=d["solver/converged"][...].astype(bool), sweeps=d["solver/sweeps"][...],
                    overlap=overlap, mass=d["particles/mass"][...].sum(),
                    drive=e["drive_work"][-1], dissipated=e["dissipated"][-1], kinetic=e["kinetic"][-1],
                    balance=e["balance"][-1],
                    bonds=sorted(zip(b["i"][...].tolist(), b["j"][...].tolist(), b["mode"][...].tolist(),
                                     b["step"][...].tolist())))


def main():
    exe, work, src = arguments(fresh=True)
    blk = results(multicor(exe, variant(src, work, "block", []), work)[0])
    ngs = results(multicor(exe, variant(src, work, "nlgs", ["method = nlgs"]), work)[0])
    for name, res in (("block", blk), ("nlgs", ngs)):
        check(f"{name}: every step converged", res["converged"].all(),
              f"unconverged steps {np.flatnonzero(~res['converged']) + 1}, iterations {res['sweeps'].tolist()}")
    check("bonds break at the wall's first contact", len(blk["bonds"]) > 0
          and all(s == CONTACT_STEP for *_, s in blk["bonds"]), f"block {blk['bonds']} (i, j, mode, step)")
    check("block and nlgs break the same bonds", blk["bonds"] == ngs["bonds"],
          f"block {blk['bonds']}, nlgs {ngs['bonds']}")
    # the bound of a contact made within a step, plus the drift of a velocity solved to a
    # relative 1e-12 (|u_n| <= 1e-13 m/s over 4 steps of 5e-4 s: 2e-16 m) and the rounding of
    # positions near 0.13 m (1e-17 m per step): 1e-14 m is far above both and far below the
    # 5e-5 m the wall went through the stack per step
    bound = (1.0 - THETA) * H * V_WALL
    ov = blk["overlap"]
    check("block: the wall does not go through the disks",
          ov.max() <= bound + 1e-14 and abs(ov[-1] - ov[CONTACT_STEP]) <= 1e-14,
          f"overlap per step {np.array2string(ov, precision=3)} m, bound {bound:.2e} m")
    # the energies of a run are sums of rounded terms of up to 1 J/m (the potential energy)
    # over 8 steps: 1e-12 J/m is above their rounding
    check("block: energy balance", abs(blk["balance"]) <= 1e-12, f"residual {blk['balance']:.2e} J/m")
    # both methods solve each step to a relative 1e-12: their energies agree to about that
    # (measured 1.6e-12), 1e-8 leaves room for the order of the operations
    rel = max(abs(blk[k] - ngs[k]) / abs(ngs[k]) for k in ("drive", "dissipated", "kinetic"))
    check("block: the wall's work, the dissipated and the kinetic energies of nlgs", rel <= 1e-8,
          f"wall's work {blk['drive']:.6e} / {ngs['drive']:.6e}, dissipated {blk['dissipated']:.6e} / "
          f"{ngs['dissipated']:.6e}, kinetic {blk['kinetic']:.6e} / {ngs['kinetic']:.6e} J/m (largest relative "
          f"difference {rel:.1e})")
    check("block: the wall's work is that of a push", blk["drive"] <= 2.0 * blk["mass"] * V_WALL**2,
          f"{blk['drive']:.4e} J/m, 2 M v^2 = {2.0 * blk['mass'] * V_WALL**2:.4e} J/m")
    _, proc = multicor(exe, variant(src, work, "cap", [], cap=64), work)
    line = next((ln for ln in proc.stderr.splitlines() + proc.stdout.splitlines()
                 if ln.startswith(f"warning: step {CONTACT_STEP} ")), "")
    check("max_sweeps = 64: the warning of the stalled step", "had no solution" in line
          and line.endswith("raise [solver] max_sweeps"), line or "no warning for step 4")
    return summary()


if __name__ == "__main__":
    sys.exit(main())
