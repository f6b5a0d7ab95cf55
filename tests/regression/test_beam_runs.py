#!/usr/bin/env python3
"""Regression runs of the multicor executable on beam decks, checked against closed forms.

Each check reads the results back from the HDF5 file written by the run. The decks live in
tests/regression/decks/ (their headers state the reference) and input/.
Usage (ctest does this): test_beam_runs.py --exe multicor --work DIR --source REPO
"""
import math
import re
import sys
import time

import h5py
import numpy as np

from checks import arguments, check, check_summary_without_steps, multicor, summary


def run(exe, deck, work):
    return h5py.File(multicor(exe, deck, work)[0], "r")


def static_cantilever(exe, decks, work):
    E, A, I, L, P, N = 7.0e10, 3.0e-4, 2.5e-9, 0.8, 25.0, 1000.0
    with run(exe, decks / "cantilever_static.dat", work) as f:
        d = f["static/displacement"][...]          # (n_nodes, 3): u, w, theta
        r = f["static/reactions"][...]
        assert f.attrs["code_name"] == "MULTICOR"
        assert "cantilever" in f.attrs["deck_text"].lower()
    tip = d[-1]
    # Hermite elements are nodally exact: round-off only (banded Cholesky), rel. 1e-8.
    w_ref, t_ref, u_ref = -P * L**3 / (3 * E * I), -P * L**2 / (2 * E * I), N * L / (E * A)
    check("static tip deflection", abs(tip[1] / w_ref - 1) < 1e-8, f"{tip[1]:.10e} vs {w_ref:.10e}")
    check("static tip rotation", abs(tip[2] / t_ref - 1) < 1e-8, f"{tip[2]:.10e} vs {t_ref:.10e}")
    check("static axial extension", abs(tip[0] / u_ref - 1) < 1e-8, f"{tip[0]:.10e} vs {u_ref:.10e}")
    # Support reactions balance the loads: Fy = +P, M = +P L at the clamp (rel. round-off).
    check("clamp reaction force", abs(r[0, 1] / P - 1) < 1e-8, f"{r[0, 1]:.10e} vs {P}")
    check("clamp reaction moment", abs(r[0, 2] / (P * L) - 1) < 1e-8, f"{r[0, 2]:.10e} vs {P * L}")


def static_lframe(exe, decks, work):
    E, A, I, H, L, P = 2.1e11, 4.0e-4, 3.0e-8, 1.5, 1.0, 500.0
    with run(exe, decks / "lframe_static.dat", work) as f:
        d = f["static/displacement"][...]
        ids = f["fem/mesh/node_id"][...]
    tip = d[list(ids).index(23)]
    w_ref = -(P * L**3 / (3 * E * I) + P * L * H * L / (E * I) + P * H / (E * A))
    u_ref = P * L * H**2 / (2 * E * I)
    # Exact for Hermite frames up to round-off: rel. 1e-8.
    check("L-frame vertical tip deflection", abs(tip[1] / w_ref - 1) < 1e-8, f"{tip[1]:.10e} vs {w_ref:.10e}")
    check("L-frame horizontal tip displacement", abs(tip[0] / u_ref - 1) < 1e-8, f"{tip[0]:.10e} vs {u_ref:.10e}")


def static_distributed(exe, decks, work):
    E, I, L, q, q0 = 2.1e11, 8.0e-8, 2.0, -1500.0, -3000.0
    with run(exe, decks / "beam_distributed_static.dat", work) as f:
        d = f["static/displacement"][...]
        ids = list(f["fem/mesh/node_id"][...])
        r = f["static/reactions"][...]

    def at(node):
        return d[ids.index(node)]

    # Consistent nodal forces make Hermite elements nodally exact for any load: round-off of
    # the banded Cholesky only, rel. 1e-8.
    cases = [
        ("cantilever uniform: tip w", at(9)[1], q * L**4 / (8 * E * I)),
        ("cantilever uniform: tip theta", at(9)[2], q * L**3 / (6 * E * I)),
        ("cantilever triangular: tip w", at(109)[1], 11 * q0 * L**4 / (120 * E * I)),
        ("cantilever triangular: tip theta", at(109)[2], q0 * L**3 / (8 * E * I)),
        ("simply supported uniform: mid w", at(205)[1], 5 * q * L**4 / (384 * E * I)),
        ("simply supported uniform: theta A", at(201)[2], q * L**3 / (24 * E * I)),
        ("simply supported uniform: theta B", at(209)[2], -q * L**3 / (24 * E * I)),
        ("simply supported triangular: mid w", at(305)[1], 5 * q0 * L**4 / (768 * E * I)),
        ("simply supported triangular: theta A", at(301)[2], 7 * q0 * L**3 / (360 * E * I)),
        ("simply supported triangular: theta B", at(309)[2], -8 * q0 * L**3 / (360 * E * I)),
    ]
    for name, got, ref in cases:
        check(name, abs(got / ref - 1) < 1e-8, f"{got:.10e} vs {ref:.10e}")
    # Supports of the triangular simply supported beam carry q0 L/6 and q0 L/3 (rel. 1e-8).
    check("triangular load: reaction A", abs(r[ids.index(301), 1] / (-q0 * L / 6) - 1) < 1e-8,
          f"{r[ids.index(301), 1]:.8e} vs {-q0 * L / 6:.8e}")
    check("triangular load: reaction B", abs(r[ids.index(309), 1] / (-q0 * L / 3) - 1) < 1e-8,
          f"{r[ids.index(309), 1]:.8e} vs {-q0 * L / 3:.8e}")


def static_self_weight(exe, decks, work):
    E, rho, A, I, L, g, phi = 2.1e11, 7800.0, 1.0e-3, 8.0e-8, 3.0, 9.81, math.radians(30.0)
    with run(exe, decks / "beam_gravity_static.dat", work) as f:
        d = f["static/displacement"][...]
        r = f["static/reactions"][...]
        xy = f["fem/mesh/coordinates"][...]
    p = rho * A * g
    c, s = math.cos(phi), math.sin(phi)
    qa, qt = -p * s, -p * c
    ua, wt, th = qa * L**2 / (2 * E * A), qt * L**4 / (8 * E * I), qt * L**3 / (6 * E * I)
    ref = [ua * c - wt * s, ua * s + wt * c, th]
    # Nodally exact (consistent loads), round-off only: rel. 1e-8.
    for k, name in enumerate(["x", "y", "theta"]):
        check(f"self-weight: tip {name}", abs(d[-1, k] / ref[k] - 1) < 1e-8, f"{d[-1, k]:.10e} vs {ref[k]:.10e}")
    check("self-weight: clamp carries the weight", abs(r[0, 1] / (p * L) - 1) < 1e-8, f"{r[0, 1]:.8e} vs {p * L:.8e}")
    check("self-weight: clamp moment", abs(r[0, 2] / (p * L**2 * c / 2) - 1) < 1e-8,
          f"{r[0, 2]:.8e} vs {p * L**2 * c / 2:.8e}")
    # Polar line: the last node is at (x1, y1) + L (cos 30, sin 30); 1e-12 L: rounding of cos/sin.
    end = [0.5 + L * c, 0.2 + L * s]
    check("polar_line end", bool(np.all(np.abs(xy[-1, :2] - end) < 1e-12 * L)), f"{xy[-1]} vs {end}")


def rigid_spin(exe, decks, work):
    rho_a, L, vx, vy, om, xc, yc = 7800.0 * 1.0e-3, 2.0, 0.5, -0.3, 2.0, 0.7, 0.1
    with run(exe, decks / "beam_rigid_spin.dat", work) as f:
        v0 = f["fem/velocity"][0]
        xy = f["fem/mesh/coordinates"][...]
        kin0 = f["energy/kinetic"][0]
    ref = np.stack([vx - om * (xy[:, 1] - yc), vy + om * (xy[:, 0] - xc), np.full(len(xy), om)], axis=1)
    # Velocities copied from the rigid field: rounding of one product, 1e-14 m/s.
    check("rigid spin: nodal velocities", bool(np.allclose(v0, ref, rtol=0, atol=1e-14)),
          f"max dev {np.abs(v0 - ref).max():.2e}")
    vg = np.array([vx - om * (0.0 - yc), vy + om * (1.0 - xc)])
    k_ref = 0.5 * rho_a * L * vg @ vg + 0.5 * rho_a * L**3 / 12 * om**2
    # Consistent mass: exact for rigid fields; round-off of v.M v, rel. 1e-12.
    check("rigid spin: kinetic energy", abs(kin0 / k_ref - 1) < 1e-12, f"{kin0:.12e} vs {k_ref:.12e}")


def modal_cantilever(exe, decks, work):
    E, rho, A, I, L = 1.1e11, 8900.0, 1.2e-4, 1.0e-9, 0.6
    with run(exe, decks / "cantilever_modal.dat", work) as f:
        omega = f["modal/omega"][...]
        freq = f["modal/frequency"][...]
        shapes = f["modal/shapes"][...]
    bl = np.array([1.875104069, 4.694091133, 7.854757438])
    ref = bl**2 * math.sqrt(E * I / (rho * A * L**4))
    err = np.abs(omega[:3] / ref - 1)
    # 24 consistent-mass Hermite elements: discretisation error ~1e-6 for these modes; 0.5 %
    # is the requirement, 1e-4 shows the convergence is as expected.
    check("modal frequencies", bool(np.all(err < 1e-4)), f"relative errors {err}")
    check("modal Hz = rad/s / 2pi", bool(np.allclose(freq, omega / (2 * math.pi), rtol=1e-14)), "")
    check("modal shapes stored", shapes.shape == (4, 25, 3), f"shape {shapes.shape}")
    # The same cantilever with E = 1e300 (omega ~ 1e146): exited 3 ('internal error') as the
    # eigensolver squared entries of ~1e300. omega scales as sqrt(E): the closed form to the
    # same discretisation error as above, and the ratio to the run at E = 1.1e11 to 1e-8: the
    # solver scales K and M by powers of 2 (exact), but the assembly rounds differently, and
    # the eigenvalues are accurate to ~eps times the largest one (~1e-9 relative for mode 1,
    # omega_max/omega_1 ~ 1e3-1e4 on 24 elements).
    big = work / "cantilever_modal_young_1e300.dat"
    big.write_text((decks / "cantilever_modal.dat").read_text().replace("1.1e11", "1e300"))
    with run(exe, big, work) as f:
        omega_big = f["modal/omega"][...]
    err_big = np.abs(omega_big[:3] / (ref * math.sqrt(1e300 / E)) - 1)
    check("modal frequencies with E = 1e300", bool(np.all(err_big < 1e-4)), f"relative errors {err_big}")
    ratio = omega_big / omega / math.sqrt(1e300 / E)
    check("modal frequencies with E = 1e300 scale as sqrt(E)", bool(np.all(np.abs(ratio - 1) < 1e-8)),
          f"ratio - 1 = {ratio - 1}")


def modal_kinds(exe, decks, work):
    E, rho, A, I, L = 1.1e11, 8900.0, 1.2e-4, 1.0e-9, 0.6
    with run(exe, decks / "beam_modal_kinds.dat", work) as f:
        omega = f["modal/omega"][...]
        frac = f["modal/axial_fraction"][...]
        kinds = f["modal/axial_fraction"].attrs["kind"]
        kinds = (kinds.decode() if isinstance(kinds, bytes) else str(kinds)).split()
    w_axial = math.pi / 2 * math.sqrt(E / rho) / L
    # 24 linear axial elements, consistent mass: discretisation error ~ (k h)^2/24 ~ 2e-4.
    check("modal kinds: mode 7 is the first axial mode", abs(omega[6] / w_axial - 1) < 1e-3,
          f"{omega[6]:.6e} vs {w_axial:.6e}")
    check("modal kinds: labels", kinds == ["bending"] * 6 + ["axial", "bending"], f"{kinds}")
    # A straight beam's axial and bending motions decouple exactly: shares 0 and 1 up to the
    # rounding of the eigenvectors (rel. 1e-10 of the energy).
    check("modal kinds: axial share of mode 7 is 1", abs(frac[6] - 1) < 1e-10, f"{frac[6]:.3e}")
    others = np.delete(frac, 6)
    check("modal kinds: bending modes carry no axial energy", bool(np.all(np.abs(others) < 1e-10)),
          f"max {np.abs(others).max():.3e}")


def dynamic_cantilever(exe, src, work):
    E, rho, A, I, L, P = 2.1e11, 7800.0, 2.0e-4, 1.0 / 6.0e8, 1.0, 10.0
    h5, proc = multicor(exe, src / "input" / "cantilever.dat", work, quiet=False)
    with h5py.File(h5, "r") as f:
        t = f["fem/time"][...]
        w = f["fem/displacement"][:, -1, 1]
        bal = f["energy/balance"][...]
        kin = f["energy/kinetic"][...]
    w_s = -P * L**3 / (3 * E * I)
    T1 = 2 * math.pi / (1.875104069**2 * math.sqrt(E * I / (rho * A * L**4)))
    # Step load: each mode oscillates about its static share, so the time mean over whole
    # first-mode periods is the static deflection; higher modes (3 % of the tip static
    # deflection, periods T1/6 and shorter) average out to well under 1 %.
    n_per = int(t[-1] // T1)
    sel = t <= n_per * T1
    trapezoid = getattr(np, "trapezoid", None) or np.trapz
    mean = trapezoid(w[sel], t[sel]) / t[sel][-1]
    check("dynamic mean tip deflection = static", abs(mean / w_s - 1) < 1e-2, f"{mean:.6e} vs {w_s:.6e}")
    # Period from upward crossings of the static level (linear interpolation).
    s = w - w_s
    up = np.where((s[:-1] < 0) & (s[1:] >= 0))[0]
    tc = t[up] - s[up] * (t[up + 1] - t[up]) / (s[up + 1] - s[up])
    period = np.mean(np.diff(tc))
    # 600 steps per period: average acceleration period error (omega h)^2/12 = (pi^2/3)(h/T)^2 ~ 9e-6, plus
    # higher-mode ripple on the crossings: 1 %.
    check("dynamic period = first cantilever period", abs(period / T1 - 1) < 1e-2, f"{period:.6f} s vs {T1:.6f} s")
    # Average acceleration conserves energy exactly for a linear undamped system: balance
    # residual at round-off relative to the energy in play.
    scale = max(np.max(np.abs(kin)), 1e-30)
    check("dynamic energy balance", np.max(np.abs(bal)) / scale < 1e-9, f"max |balance|/max kinetic = {np.max(np.abs(bal)) / scale:.2e}")
    # The summary line gives the last residual with its unit, joules as in the continuum's and the
    # coupled runs' lines (the beam's energies are whole, not per unit thickness): printed with
    # 4 significant digits, so it equals the stored value to half a unit of the 4th digit.
    line = next((x for x in proc.stdout.splitlines() if "energy balance residual" in x), "")
    said = re.search(r"energy balance residual +(\S+) J\b", line)
    check("summary's energy balance residual, in J", said is not None
          and abs(float(said.group(1)) - bal[-1]) <= 5e-4 * abs(bal[-1]), f"{line.strip()}; stored {bal[-1]:.4e}")


def summary_without_steps(exe, decks, work):
    """A static and a modal analysis write /summary as a time loop does: steps (0),
    wall_seconds and ended (a sweep over them gets its wall-time column)."""
    for deck in ("cantilever_static.dat", "cantilever_modal.dat"):
        start = time.monotonic()
        h5, _ = multicor(exe, decks / deck, work / "summary")
        check_summary_without_steps(deck, h5, time.monotonic() - start)


def main():
    exe, work, src = arguments()
    decks = src / "tests" / "regression" / "decks"
    static_cantilever(exe, decks, work)
    static_lframe(exe, decks, work)
    static_distributed(exe, decks, work)
    static_self_weight(exe, decks, work)
    rigid_spin(exe, decks, work)
    modal_cantilever(exe, decks, work)
    modal_kinds(exe, decks, work)
    summary_without_steps(exe, decks, work)
    dynamic_cantilever(exe, src, work)
    return summary()


if __name__ == "__main__":
    sys.exit(main())
