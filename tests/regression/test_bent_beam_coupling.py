#!/usr/bin/env python3
"""Disks glued to a bent beam across its corner (tests/regression/decks/coupled_bent_beam.dat,
an L-frame, a row going straight on past the corner, a disk beside the upright and one in
the outer corner): each disk's weight alpha, its selection and its glue to the beam come
from one projection, the nearest point of the beam's axis (fem_beam_projection).

Checked against the closed-form nearest point of the polyline (0, 0) - (0.23, 0) -
(0.23, 0.03), computed here segment by segment:
- the coupled disks are those whose nearest point has 0 < alpha < 1 (all 14);
- /coupling/abscissa and |/coupling/offset| are its abscissa and distance;
- /coupling/alpha (the glue's weight) and /coupling/alpha_disks (the disks' masses) agree,
  and equal the cubic weight with its floor at that abscissa;
- the off-section warning counts the disks farther than radius + sqrt(3 I / A) from the
  axis (8 of 14, the farthest disk 12 at 0.058 m), which are those of the stored offsets;
- the run keeps q = C u and its energy balance.
Before, the row past the corner got alpha at its x along the horizontal arm continued
(0.232 m for disk 5) while glued at the corner (0.23 m), and disk 14 was refused as 'not
over the beam'.

Usage (ctest does this): test_bent_beam_coupling.py --exe multicor --work DIR --source REPO
"""
import re
import subprocess
import sys

import h5py
import numpy as np

from checks import arguments, check, summary

#: The deck's beam (nodes of its polyline), overlap, section and disks.
POLYLINE = np.array([[0.0, 0.0], [0.23, 0.0], [0.23, 0.03]])
S_FE, S_PARTICLE, ALPHA_MIN = 0.20, 0.26, 1e-3
AREA, INERTIA = 1.0e-4, 8.333333333333333e-10
RADIUS = 0.004
CENTRES = np.array([[0.20 + 2 * RADIUS * k, 0.0] for k in range(12)] + [[0.236, 0.016], [0.25, -0.02]])


def nearest_point(p):
    """Abscissa of the nearest point of the polyline to p and the distance to it (every
    disk of the deck is nearer to a segment than to the continuations past the ends)."""
    best, start = (np.inf, 0.0), 0.0
    for a, b in zip(POLYLINE[:-1], POLYLINE[1:]):
        length = np.linalg.norm(b - a)
        t = min(max(np.dot(p - a, b - a) / length**2, 0.0), 1.0)
        d = np.linalg.norm(p - (a + t * (b - a)))
        if d < best[0]:
            best = (d, start + t * length)
        start += length
    return best[1], best[0]


def weight(s):
    """The cubic weight 1 - 3 xi^2 + 2 xi^3 of the overlap, kept within [alpha_min,
    1 - alpha_min] on it (its ends included); 1 before it, 0 beyond it."""
    xi = (s - S_FE) / (S_PARTICLE - S_FE)
    if xi < 0 or xi > 1:
        return 1.0 if xi < 0 else 0.0
    return min(max(1 - 3 * xi**2 + 2 * xi**3, ALPHA_MIN), 1 - ALPHA_MIN)


def main():
    exe, work, src = arguments()
    deck = src / "tests" / "regression" / "decks" / "coupled_bent_beam.dat"
    s_ref, d_ref = np.array([nearest_point(p) for p in CENTRES]).T
    alpha_ref = np.array([weight(s) for s in s_ref])
    coupled_ref = np.flatnonzero((alpha_ref > 0) & (alpha_ref < 1)) + 1
    reach = RADIUS + np.sqrt(3 * INERTIA / AREA)
    # the distances nearest the reach (0.006 and 0.010 m against 0.009 m) are far from it
    # against the rounding of the projection (1e-17 m)
    off_ref = coupled_ref[d_ref[coupled_ref - 1] > reach]
    check("closed form: 14 disks in the overlap, 8 off the section",
          len(coupled_ref) == 14 and len(off_ref) == 8, f"{coupled_ref}, off {off_ref}")

    out = work / deck.stem
    proc = subprocess.run([str(exe), str(deck), "--output", str(out)], capture_output=True, text=True)
    check("the run ends with exit 0", proc.returncode == 0, proc.stderr.strip()[-400:])
    if proc.returncode != 0:
        return summary()
    with h5py.File(out / f"{deck.stem}.h5", "r") as f:
        c = f["coupling"]
        particles = c["particles"][...]
        abscissa, offset, alpha = c["abscissa"][...], c["offset"][...], c["alpha"][...]
        alpha_disks = c["alpha_disks"][...]
        pos = c["position_residual"][...]
        balance = np.abs(c["energy/balance"][...]).max()
        work_done = np.abs(c["energy/external_work"][...]).max()
    check("coupled disks: those whose nearest point is in the overlap",
          np.array_equal(particles, coupled_ref), f"{particles} vs {coupled_ref}")
    if not np.array_equal(particles, coupled_ref):
        return summary()
    k = particles - 1
    # Sums and products of O(0.1 m) coordinates: a few roundings of 1e-17 m.
    check("glue abscissa = the nearest point's", bool(np.allclose(abscissa, s_ref[k], rtol=0, atol=1e-15)),
          f"max dev {np.abs(abscissa - s_ref[k]).max():.1e} m; {abscissa} vs {s_ref[k]}")
    check("|offset| = distance to the nearest point",
          bool(np.allclose(np.abs(offset), d_ref[k], rtol=0, atol=1e-15)),
          f"max dev {np.abs(np.abs(offset) - d_ref[k]).max():.1e} m; {offset} vs {d_ref[k]}")
    # The glue's alpha and the disks' alpha are the same numbers (one projection).
    check("alpha of the glue = alpha of the disks' masses", np.array_equal(alpha, alpha_disks[k]),
          f"{alpha} vs {alpha_disks[k]}")
    # The cubic of an O(1) argument: a few roundings of 1e-16.
    check("alpha = the weight at the nearest point's abscissa",
          bool(np.allclose(alpha, alpha_ref[k], rtol=0, atol=1e-14)),
          f"max dev {np.abs(alpha - alpha_ref[k]).max():.1e}; {alpha} vs {alpha_ref[k]}")
    far = int(particles[np.argmax(np.abs(offset))])
    warned = [ln for ln in proc.stdout.splitlines() if "coupled disks lie off the beam's section" in ln]
    stored_off = int(np.sum(np.abs(offset) > reach))
    expected = f"{len(off_ref)} of the {len(coupled_ref)} coupled disks lie off the beam's section; the farthest, disk {far} "
    check("the off-section warning counts the stored offsets beyond radius + half-height",
          len(warned) == 1 and expected in warned[0] and stored_off == len(off_ref)
          and re.search(r"is 0\.058 m from the beam axis", warned[0]) is not None,
          f"expected '{expected}' (stored offsets beyond {reach:.4f} m: {stored_off}); got {warned}")
    # As test_coupled_runs.py's `invariants`: rounding of the accumulated displacements
    # (measured 7e-24 m) and of the solves (measured 1e-11 of the work).
    check("|q - C u| < 1e-12 m at every step", bool(np.all(pos < 1e-12)), f"max {pos.max():.2e} m")
    check("energy balance closes", balance < 1e-9 * work_done, f"{balance:.2e} J vs {work_done:.2e} J")
    return summary()


if __name__ == "__main__":
    sys.exit(main())
