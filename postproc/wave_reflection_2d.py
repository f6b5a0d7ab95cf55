#!/usr/bin/env python3
"""Wave reflection across a 2D Arlequin band (doc/verification.md, "Wave reflection across a
continuum band"): a longitudinal pulse runs along a plane-stress strip into an overlap band
where a bonded disk lattice takes over, and is reflected. Reflected energy fraction R against
the band width and the weight shape, measured and against the closed form of a bar with a
rigid end mass (the 2D counterpart of the beam study, tests/regression/test_wave_reflection.py).

Physics. Intact bonds in Contact Dynamics are perfect constraints: the bonded lattice is one
rigid body. The disks sit on the nodes of the band (one column per element, two rows across
the one-element-high strip), so the coupling fixes both nodes of every band column to the
body: the band is rigid too. With nu = 0 a uniform end traction drives a purely axial wave
(u_y = 0), and the FE-only strip is a bar of impedance Z = rho c H t ending on a rigid mass

    M = rho t int(alpha dA) over the band + sum_coupled (1 - alpha_j) m_d t_c + sum_free m_d t_c

(m_d: the disks' mass per unit thickness, t_c the coupling thickness), driven as
M dv/dt = Z (2 v_inc - v). At a time t after the incident pulse has entered the band and
before the reflection comes back, the energy left in the FE-only strip is the reflected
energy: R(t) = 1 - M v(t)^2 / (2 E_inc).

Measured: R as the energy (consistent Q4 mass and stiffness, from the stored fields) of the
FE-only elements over the work of the end traction, at t_a + T (the pulse has just entered
the band); the body's velocity (mean of the disks) against the closed form; the spread of the
disks' and band nodes' velocities about it (rigidity).

Usage (one command; the Release build is faster):
    .venv/bin/python postproc/wave_reflection_2d.py --exe build/src/multicor --work /tmp/wave2d [--refine]
prints the table of doc/verification.md (band widths 4, 8, 16 elements = 10, 20, 40 mm x
weights constant, linear, cubic), and with --refine the 20 mm band at three resolutions. tests/regression/test_wave_reflection_2d.py runs a subset and asserts against the
closed form.
"""
import argparse
import math
import os
import pathlib
import subprocess
import sys
import time

import h5py
import numpy as np

# Data set: steel strip H = 5 mm high, t = 1 cm thick, nu = 0; Q4 of 2.5 mm x 5 mm (one
# element high); disks R = 1.25 mm (pitch 2.5 mm, one column per band node), 2 rows, bonded.
# `set_resolution` scales H, dx, R and h together (--refine).
E, NU, RHO, THICK = 2.1e11, 0.0, 7800.0, 0.01
S_FE = 0.25                   # end of the FE-only zone (100 elements of 2.5 mm)
N_FREE = 4                    # disk columns beyond the band
C_BAR = math.sqrt(E / RHO)
TRACTION = 1.0e6              # end traction amplitude [Pa]
T_PULSE = 20.0e-6             # sin^2 pulse duration: c T = 0.104 m, 42 elements of 2.5 mm
ALPHA_MIN = 1.0e-3


def set_resolution(scale):
    """Element size dx = 2.5 mm, step h = 0.25 us (80 steps per pulse, Courant number c h / dx
    = 0.52), disk radius 1.25 mm and strip height 5 mm, all times `scale`; the traction and so
    V = traction / (rho c) stay. The end mass changes with it (Z and the strip's share scale
    as `scale`, the 4 free columns and the band's end columns of disks as `scale`^2), so each
    resolution is compared with its own closed form."""
    global H, DX, RADIUS, STEP, Z, M_DISK, P0
    H, DX, RADIUS, STEP = 0.005 * scale, 0.0025 * scale, 0.00125 * scale, 2.5e-7 * scale
    Z = RHO * C_BAR * H * THICK
    M_DISK = RHO * math.pi * RADIUS**2 * THICK
    P0 = TRACTION * H * THICK       # end force amplitude [N]


set_resolution(1.0)


def hann_table(duration, points=81):
    """sin^2(pi t / T) as a table of `points` points."""
    return " ".join(f"{i * duration / (points - 1):.6e} {math.sin(math.pi * i / (points - 1)) ** 2:.12f}"
                    for i in range(points))


def deck(n_band, shape, constant=None):
    """Strip [0, S_FE + n_band DX] x [0, H], the band [S_FE, S_FE + n_band DX], disks on its
    nodes' columns (2 rows at y = R, 3R) and N_FREE columns beyond."""
    s_p = S_FE + n_band * DX
    n_el = round(s_p / DX)
    t_a = S_FE / C_BAR
    end = t_a + T_PULSE + 1.0e-5
    weight = f"weight = {shape}" + (f"\nconstant = {constant}" if constant is not None else "")
    return f"""[run]
title = axial pulse across a continuum band into a bonded disk lattice
analysis = dynamic
[functions]
function = 1 table {hann_table(T_PULSE)}
[continuum]
mesh = rectangle 0 0 {s_p:.6g} {H} {n_el} 1 q4
material = {E} {NU} {RHO} {THICK} plane_stress
traction = left {TRACTION:.6g} 0 uniform 1
[particles]
material = 1 {RHO}
square_lattice = {n_band + 1 + N_FREE} 2 {S_FE} {RADIUS} {RADIUS} 1
[contacts]
law = 1 1 0 0 1.0e8
bond = 1 1 1.0
[solver]
tolerance = 1.0e-10
[coupling]
region = box {S_FE} {s_p:.6g} 0 {H} left right
{weight}
alpha_min = {ALPHA_MIN}
thickness = {THICK}
[time]
step = {STEP}
end = {end:.6g}
[output]
interval = 2
progress = 0
contacts = no
"""


def run(exe, text, name, work):
    """Write and run a deck; return the results file's path."""
    work.mkdir(parents=True, exist_ok=True)
    path = work / f"{name}.dat"
    path.write_text(text)
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    proc = subprocess.run([str(exe), str(path), "--output", str(work / name), "--quiet"],
                          capture_output=True, text=True, env=env)
    if proc.returncode != 0:
        raise SystemExit(f"multicor failed on {path} (exit {proc.returncode}):\n{proc.stdout}{proc.stderr}")
    return work / name / f"{name}.h5"


def weight(x, s_fe, s_p, shape, constant=0.5):
    """alpha of the FE side in the band (doc/theory.md 6.1, floored)."""
    xi = (x - s_fe) / (s_p - s_fe)
    r = {"constant": np.full_like(xi, constant), "linear": 1.0 - xi, "cubic": 1.0 - 3.0 * xi**2 + 2.0 * xi**3}[shape]
    return np.clip(r, ALPHA_MIN, 1.0 - ALPHA_MIN)


def rigid_mass(n_band, shape, constant, x_disks):
    """M of the closed form: the weighted strip over the band (Simpson on 2e5 intervals: the
    floor's kinks cost below 1e-10), the coupled disks weighted by 1 - alpha, the free disks."""
    s_p = S_FE + n_band * DX
    s = np.linspace(S_FE, s_p, 200001)
    a = weight(s, S_FE, s_p, shape, constant if constant is not None else 0.5)
    ds = s[1] - s[0]
    int_alpha = ds / 3.0 * (a[0] + a[-1] + 4.0 * a[1:-1:2].sum() + 2.0 * a[2:-1:2].sum())
    inside = (x_disks >= S_FE - 1e-12) & (x_disks <= s_p + 1e-12)
    a_d = np.where(inside, weight(x_disks, S_FE, s_p, shape, constant if constant is not None else 0.5), 0.0)
    return RHO * THICK * H * int_alpha + float(np.sum(1.0 - a_d)) * M_DISK


def closed_form(mass, t):
    """Velocity of the end mass for the incident velocity v_inc(t - t_a) = (P0/Z) sin^2 (the
    deck's piecewise-linear table, solved exactly piece by piece), and E_inc = Z int v_inc^2."""
    tau = mass / Z
    t_a = S_FE / C_BAR
    tab = np.array([float(v) for v in hann_table(T_PULSE).split()])
    knots, vin = tab[0::2] + t_a, P0 / Z * tab[1::2]
    v_knot = [0.0]
    for k in range(len(knots) - 1):
        dt = knots[k + 1] - knots[k]
        b = (vin[k + 1] - vin[k]) / dt
        vp0, vp1 = 2 * vin[k] - 2 * tau * b, 2 * vin[k + 1] - 2 * tau * b
        v_knot.append(vp1 + (v_knot[-1] - vp0) * math.exp(-dt / tau))
    v = np.zeros_like(t)
    for i, ti in enumerate(t):
        if ti <= knots[0]:
            continue
        if ti >= knots[-1]:
            v[i] = v_knot[-1] * math.exp(-(ti - knots[-1]) / tau)
            continue
        k = int(np.searchsorted(knots, ti)) - 1
        dt = ti - knots[k]
        b = (vin[k + 1] - vin[k]) / (knots[k + 1] - knots[k])
        v[i] = 2 * (vin[k] + b * dt) - 2 * tau * b + (v_knot[k] - (2 * vin[k] - 2 * tau * b)) * math.exp(-dt / tau)
    e_inc = sum(Z * (knots[k + 1] - knots[k]) * (vin[k] ** 2 + vin[k] * vin[k + 1] + vin[k + 1] ** 2) / 3.0
                for k in range(len(knots) - 1))
    return v, e_inc, tau


def element_energies(x, conn, u, v):
    """Kinetic and strain energy of each Q4 (consistent mass, 2 x 2 Gauss, plane stress) at
    every stored state: u, v of shape (n_out, n_nodes, 2); returns (n_out, n_elements) each."""
    d = E / (1 - NU**2) * np.array([[1, NU, 0], [NU, 1, 0], [0, 0, (1 - NU) / 2]])
    g = 1 / math.sqrt(3)
    kin = np.zeros((u.shape[0], conn.shape[0]))
    strain = np.zeros_like(kin)
    for e, nodes in enumerate(conn):
        xe = x[nodes]
        ue, ve = u[:, nodes, :], v[:, nodes, :]
        for r, s in [(-g, -g), (g, -g), (g, g), (-g, g)]:
            n = 0.25 * np.array([(1 - r) * (1 - s), (1 + r) * (1 - s), (1 + r) * (1 + s), (1 - r) * (1 + s)])
            dn = 0.25 * np.array([[-(1 - s), -(1 - r)], [1 - s, -(1 + r)], [1 + s, 1 + r], [-(1 + s), 1 - r]])
            jac = dn.T @ xe
            det = np.linalg.det(jac)
            dndx = dn @ np.linalg.inv(jac).T
            vq = np.einsum("a,kac->kc", n, ve)
            kin[:, e] += 0.5 * RHO * THICK * det * (vq**2).sum(axis=1)
            grad = np.einsum("ai,kac->kci", dndx, ue)
            eps = np.stack([grad[:, 0, 0], grad[:, 1, 1], grad[:, 0, 1] + grad[:, 1, 0]], axis=1)
            strain[:, e] += 0.5 * THICK * det * np.einsum("ki,ij,kj->k", eps, d, eps)
    return kin, strain


def measure(h5, n_band, shape, constant=None):
    """Figures of one run."""
    with h5py.File(h5, "r") as f:
        x = f["continuum/mesh/coordinates"][...]
        conn = f["continuum/mesh/connectivity"][...] - 1
        t = f["continuum/time"][...]
        u = f["continuum/displacement"][...]
        v = f["continuum/velocity"][...]
        en = f["coupling/energy"]
        work = en["external_work"][...]
        balance = float(np.abs(en["balance"][...]).max() / work.max())
        fe_total = f["continuum/energy/kinetic"][...] + f["continuum/energy/strain"][...]
        vd = f["dem/velocity"][:, :, :2]
        x_disks = f["dem/position"][0, :, 0]
    kin, strain = element_energies(x, conn, u, v)
    xc = x[conn, 0].mean(axis=1)
    fe_only = (kin + strain)[:, xc < S_FE].sum(axis=1)
    mass = rigid_mass(n_band, shape, constant, x_disks)
    v_cf, e_inc, tau = closed_form(mass, t)
    t_a = S_FE / C_BAR
    k = int(np.argmin(np.abs(t - (t_a + T_PULSE))))
    k0 = int(np.argmin(np.abs(t - 0.8 * t_a)))
    vmax = P0 / Z
    v_body = vd[:, :, 0].mean(axis=1)
    band = x[:, 0] >= S_FE - 1e-12
    spread = max(np.abs(vd[:, :, 0] - v_body[:, None]).max(), np.abs(vd[:, :, 1]).max(),
                 np.abs(v[:, band, 0] - v_body[:, None]).max(), np.abs(v[:, band, 1]).max()) / vmax
    return dict(
        mass=mass, tau=tau, t_m=t[k],
        r_meas=fe_only[k] / work[k], r_cf=1.0 - 0.5 * mass * v_cf[k] ** 2 / e_inc,
        r_end=fe_only[-1] / work[-1], r_end_cf=1.0 - 0.5 * mass * v_cf[-1] ** 2 / e_inc,
        v_err=float(np.abs(v_body - v_cf).max() / vmax), spread=float(spread), balance=balance,
        # before the pulse reaches the band (t = 0.8 t_a) the FE-only energy is all of the
        # stored continuum energy: checks the Q4 energies computed here
        energy_check=float(abs(fe_only[k0] - fe_total[k0]) / fe_total[k0]),
        work_check=float(abs(work[k0] - fe_total[k0]) / work[k0]))


CASES = [(n, s) for n in (4, 8, 16) for s in ("constant", "linear", "cubic")]


def study(exe, work, cases=CASES):
    """Run the cases; return (n_band, shape, figures) rows."""
    rows = []
    for n_band, shape in cases:
        name = f"wave2d_b{n_band}_{shape}"
        h5 = run(exe, deck(n_band, shape), name, work)
        rows.append((n_band, shape, measure(h5, n_band, shape)))
    return rows


def table(rows):
    lines = ["| band (elements, mm) | weight | M [g] | tau [us] | R(t_a + T) measured | closed form | "
             "R(end) measured | closed form | max abs(v - v_cf) / V | rigidity (velocity spread / V) |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for n_band, shape, m in rows:
        lines.append(f"| {n_band} ({n_band * DX * 1e3:.0f}) | {shape} | {1e3 * m['mass']:.3f} | {1e6 * m['tau']:.2f} | "
                     f"{m['r_meas']:.5f} | {m['r_cf']:.5f} | {m['r_end']:.5f} | {m['r_end_cf']:.5f} | "
                     f"{m['v_err']:.1e} | {m['spread']:.1e} |")
    return "\n".join(lines)


def refine(exe, work):
    """The 20 mm band (cubic) at dx = 5, 2.5, 1.25 mm with h = 0.5, 0.25, 0.125 us: the
    departure from the closed form against the resolution."""
    lines = ["| dx [mm] | h [us] | R(t_a + T) measured | closed form | difference | max abs(v - v_cf) / V |",
             "|---|---|---|---|---|---|"]
    for scale in (2.0, 1.0, 0.5):
        set_resolution(scale)
        n_band = round(0.02 / DX)
        name = f"wave2d_refine_{DX * 1e3:g}mm"
        m = measure(run(exe, deck(n_band, "cubic"), name, work), n_band, "cubic")
        lines.append(f"| {DX * 1e3:g} | {STEP * 1e6:g} | {m['r_meas']:.5f} | {m['r_cf']:.5f} | "
                     f"{m['r_meas'] - m['r_cf']:+.1e} | {m['v_err']:.1e} |")
    set_resolution(1.0)
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=" ".join(__doc__.split("\n\n")[0].split()))
    ap.add_argument("--exe", required=True, help="the multicor executable")
    ap.add_argument("--work", required=True, help="folder for the decks and results")
    ap.add_argument("--refine", action="store_true", help="also the 20 mm band at dx = 5, 2.5, 1.25 mm")
    args = ap.parse_args()
    exe, work = pathlib.Path(args.exe).resolve(), pathlib.Path(args.work).resolve()
    if not (exe.is_file() and os.access(exe, os.X_OK)):
        raise SystemExit(f"wave_reflection_2d.py: error: --exe {exe}: not an executable file")
    if work.exists() and not work.is_dir():
        raise SystemExit(f"wave_reflection_2d.py: error: --work {work}: a file, not a folder")
    start = time.perf_counter()
    rows = study(exe, work)
    print(f"Z = {Z:.2f} kg/s, c = {C_BAR:.1f} m/s, T = {T_PULSE * 1e6:.0f} us, t_a = {S_FE / C_BAR * 1e6:.2f} us, "
          f"m_d t = {M_DISK * 1e3:.4f} g; {len(rows)} runs in {time.perf_counter() - start:.1f} s")
    print(table(rows))
    worst = max(max(m["energy_check"], m["balance"]) for _, _, m in rows)
    print(f"Q4 energies against the stored ones before the band, and energy audit: worst {worst:.1e}")
    if args.refine:
        print(refine(exe, work))
    return 0


if __name__ == "__main__":
    sys.exit(main())
