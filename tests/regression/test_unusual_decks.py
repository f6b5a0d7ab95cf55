#!/usr/bin/env python3
"""Unusual but valid decks that must give closed-form answers: the smallest models the deck
language allows, where every number of the result is known.

- A lone disk in free fall (no wall, no contact), for theta = 1 and theta = 1/2: the
  Moreau-Jean step v+ = v + h g, q+ = q + h ((1 - theta) v + theta v+) (dem_moreau_jean),
  unrolled over n steps from (q0, v0):
      v_n = v0 + n h g,   q_n = q0 + n h v0 + h^2 g (n (n - 1)/2 + theta n),
  which for theta = 1/2 is the exact parabola q0 + v0 t + g t^2/2.
- Two disks of different masses colliding head-on with restitution e = 0 and no friction:
  the momentum of the pair at every output is the initial one (the contact impulses on the
  two disks are equal and opposite), and after the impact both move with the velocity of the
  centre of mass (m1 v1 + m2 v2)/(m1 + m2) (Newton's law with e = 0: no relative normal
  velocity).
- A cantilever of ONE beam element under a tip load P: Hermite elements are nodally exact for
  a point load at a node, so the tip deflection is P L^3/(3 E I) and the tip rotation
  P L^2/(2 E I), and the clamp reactions are P and P L.

Usage (ctest does this): test_unusual_decks.py --exe multicor --work DIR --source REPO
"""
import subprocess
import sys

import h5py
import numpy as np

from checks import arguments, check, summary


def run(exe, work, name, text):
    """Write the deck `name`.dat, run it; return the open results file (None on failure)."""
    deck = work / f"{name}.dat"
    deck.write_text(text)
    out = work / name
    proc = subprocess.run([str(exe), str(deck), "--output", str(out), "--quiet"],
                          capture_output=True, text=True, timeout=300)
    check(f"{name}: runs (exit 0)", proc.returncode == 0, proc.stderr.strip()[:400])
    if proc.returncode != 0:
        return None
    return h5py.File(out / f"{name}.h5", "r")


FREE_FALL = """[run]
analysis = dynamic
[particles]
material = 1 2500
disk = {x0} {y0} 0.01 1
gravity = 0 {g}
initial_velocity = 1 x {vx}
initial_velocity = 1 y {vy}
[contacts]
law = 1 1 0 0 0
[time]
step = {h}
end = {end}
theta = {theta}
[output]
progress = 0
"""


def free_fall(exe, work):
    x0, y0, vx, vy, g, h, n = 0.1, 0.2, 0.2, 0.3, -9.81, 1e-3, 100
    for theta in (1.0, 0.5):
        name = f"free_fall_theta_{theta:g}".replace(".", "_")
        f = run(exe, work, name, FREE_FALL.format(x0=x0, y0=y0, vx=vx, vy=vy, g=g, h=h, end=n * h,
                                                  theta=theta))
        if f is None:
            continue
        with f:
            t = f["dem/time"][...]
            q = f["dem/position"][:, 0, :2]
            v = f["dem/velocity"][:, 0, :2]
        k = np.arange(len(t))
        check(f"{name}: {n} steps stored", len(t) == n + 1 and np.allclose(t, k * h, rtol=1e-12, atol=0),
              f"{len(t)} outputs")
        y_ref = y0 + k * h * vy + h * h * g * (k * (k - 1) / 2 + theta * k)
        x_ref = x0 + k * h * vx
        v_ref = vy + k * h * g
        # Rounding only: each step adds at most half an ulp to q (n eps |q| ~ 1e-14 after 100
        # steps) and to v, whose error integrates to ~ n^2 h eps |v| / 2 ~ 4e-15 of |q|:
        # 1e-13 relative bounds both with a margin.
        err_y = np.max(np.abs(q[:, 1] - y_ref) / np.abs(y_ref))
        err_x = np.max(np.abs(q[:, 0] - x_ref) / np.abs(x_ref))
        err_v = np.max(np.abs(v[:, 1] - v_ref) / np.max(np.abs(v_ref)))
        check(f"{name}: height against the unrolled scheme", err_y < 1e-13, f"max rel. error {err_y:.2e}")
        check(f"{name}: x at constant speed", err_x < 1e-13, f"max rel. error {err_x:.2e}")
        check(f"{name}: vertical velocity v0 + n h g", err_v < 1e-13, f"max rel. error {err_v:.2e}")
        if theta == 0.5:
            # theta = 1/2 is the exact parabola (same formula, written in t).
            tn = k * h
            parabola = y0 + vy * tn + 0.5 * g * tn**2
            err_p = np.max(np.abs(q[:, 1] - parabola) / np.abs(parabola))
            check(f"{name}: exact parabola y0 + v0 t + g t^2/2", err_p < 1e-13, f"max rel. error {err_p:.2e}")
        else:
            # theta = 1 falls ahead of the parabola by g h t / 2 (first order in h).
            tn = n * h
            lag = q[-1, 1] - (y0 + vy * tn + 0.5 * g * tn**2)
            check(f"{name}: ahead of the parabola by g h t/2", abs(lag / (0.5 * g * h * tn) - 1) < 1e-9,
                  f"{lag:.6e} vs {0.5 * g * h * tn:.6e}")


COLLISION = """[run]
analysis = dynamic
[particles]
material = 1 2500
disk = 0 0 0.01 1
disk = 0.05 0 0.02 1
gravity = 0 0
initial_velocity = 1 x {v1}
initial_velocity = 2 x {v2}
[contacts]
law = 1 1 0 0 0
[time]
step = 1e-4
end = 0.03
theta = {theta}
[output]
progress = 0
"""


def collision(exe, work):
    v1, v2 = 1.0, -0.5
    for theta in (0.5, 1.0):
        name = f"collision_e0_theta_{theta:g}".replace(".", "_")
        f = run(exe, work, name, COLLISION.format(v1=v1, v2=v2, theta=theta))
        if f is None:
            continue
        with f:
            m = f["dem/particles/mass"][...]
            v = f["dem/velocity"][:, :, 0]        # (n_out, 2): vx of each disk
            vy = f["dem/velocity"][:, :, 1:]
            q = f["dem/position"][:, :, 0]
        p0 = m[0] * v1 + m[1] * v2
        scale = abs(m[0] * v1) + abs(m[1] * v2)
        p = v @ m
        # The two impulses of the one contact are equal and opposite: momentum changes by
        # rounding only, ~eps scale per step; 300 steps: 1e-12 of the momenta.
        err_p = np.max(np.abs(p - p0)) / scale
        check(f"{name}: momentum conserved at every output", err_p < 1e-12, f"max rel. change {err_p:.2e}")
        # The gap 0.05 - 0.03 closes at 1.5 m/s after 0.0133 s (output ~133); from the impact
        # on (the first output whose velocity differs from the initial one), e = 0: both disks
        # at the centre-of-mass velocity (one contact: the local solver is exact in one sweep,
        # so rounding only; 1e-12 of |v1|).
        vc = p0 / m.sum()
        moved = np.nonzero(v[:, 0] != v1)[0]
        check(f"{name}: impact near t = 0.0133 s", len(moved) > 0 and 120 <= moved[0] <= 145,
              f"first output after the impact: {moved[:1]}")
        if len(moved):
            dev = np.max(np.abs(v[moved[0]:] - vc)) / abs(v1)
            check(f"{name}: both at the centre-of-mass velocity after impact", dev < 1e-12,
                  f"max |v - vc|/|v1| = {dev:.2e} (vc = {vc:.6f})")
        # The contact is closed on the gap predicted for the step (end of step for theta = 1,
        # mid-step for 1/2): the disks stop within one step's approach h |v1 - v2| of touching,
        # and theta = 1 never lets them overlap (beyond rounding of the positions, 1e-15 m).
        gap = q[:, 1] - q[:, 0] - 0.03
        check(f"{name}: stopped within h |v1 - v2| of touching", abs(gap[-1]) <= 1e-4 * abs(v1 - v2),
              f"final gap {gap[-1]:.3e} m")
        if theta == 1.0:
            check(f"{name}: no overlap", bool(np.all(gap >= -1e-15)), f"min gap {gap.min():.3e} m")
        check(f"{name}: no vertical motion nor spin", bool(np.all(vy == 0.0)), "")


CANTILEVER = """[run]
analysis = static
[beam]
section = 1 {E} 7800 {A} {I}
line = 1 0 0 {L} 0 1 1
fix = 1 all
load = 2 w {P}
"""


def one_element_cantilever(exe, work):
    E, A, I, L, P = 2.1e11, 2.0e-4, 1.6666666666666667e-9, 1.5, -250.0
    f = run(exe, work, "one_element_cantilever", CANTILEVER.format(E=E, A=A, I=I, L=L, P=P))
    if f is None:
        return
    with f:
        d = f["static/displacement"][...]          # (n_nodes, 3): u, w, theta
        r = f["static/reactions"][...]
    check("one_element_cantilever: two nodes", d.shape == (2, 3), f"{d.shape}")
    w_ref, t_ref = P * L**3 / (3 * E * I), P * L**2 / (2 * E * I)
    # A 2 x 2 bending system (cond ~ 20 after the scaling of w and theta by L) solved by a
    # banded Cholesky: a few eps relative; 1e-12 leaves a wide margin.
    check("one_element_cantilever: tip deflection P L^3/(3 E I)", abs(d[1, 1] / w_ref - 1) < 1e-12,
          f"{d[1, 1]:.15e} vs {w_ref:.15e}")
    check("one_element_cantilever: tip rotation P L^2/(2 E I)", abs(d[1, 2] / t_ref - 1) < 1e-12,
          f"{d[1, 2]:.15e} vs {t_ref:.15e}")
    check("one_element_cantilever: no axial displacement", d[1, 0] == 0.0, f"{d[1, 0]:.3e}")
    # Clamp reactions balance the load (same rounding argument).
    check("one_element_cantilever: clamp force -P", abs(r[0, 1] / -P - 1) < 1e-12, f"{r[0, 1]:.15e}")
    check("one_element_cantilever: clamp moment -P L", abs(r[0, 2] / (-P * L) - 1) < 1e-12, f"{r[0, 2]:.15e}")


def main():
    exe, work, _ = arguments()
    free_fall(exe, work)
    collision(exe, work)
    one_element_cantilever(exe, work)
    return summary()


if __name__ == "__main__":
    sys.exit(main())
