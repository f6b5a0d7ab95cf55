#!/usr/bin/env python3
"""Regression runs of the multicor executable on 2D continuum decks ([continuum]).

- static cantilever (input/continuum_cantilever.dat) against Timoshenko's elasticity solution,
  with the order-2 convergence of the tip deflection under mesh refinement;
- first frequencies of a thin plane-stress strip against the Euler-Bernoulli beam, the gap
  being the expected shear-deformation (Timoshenko) correction;
- rigid translation and rotation of a free block in dynamics: no strain energy, no stress;
- energy balance of the dynamic cantilever (input/continuum_cantilever_dynamic.dat), with and
  without Rayleigh damping;
- a Gmsh mesh (written by the real gmsh from tests/data/gmsh/two_blocks.geo) with physical
  groups as named sets: uniform tension reproduced exactly (patch test through the reader);
- time functions on loads: a bar (nu = 0) under an end traction ramped over its first period
  4 L / c sits at the static answer sigma L / E after the ramp (every mode's residual
  amplitude sin(omega t1 / 2) / (omega t1 / 2) vanishes), where a step load would swing it
  between 0 and twice that; a static run takes the functions' values at t = 0; an undefined
  function id is an input error;
- the XDMF file opened by ParaView (pvpython, the 'XDMF Reader') when installed, else meshio
  (static file only: meshio does not read XDMF hyperslabs);
- the support reactions of a static run (/continuum/static/reactions): a column's weight
  rho g W H t carried by its rollers, a bar stretched by a prescribed end displacement
  (E t D delta / L at each end), a prescribed rigid translation (no reaction); the materials
  stored (/continuum/materials, /continuum/mesh/material) and the summary's largest
  displacement (the nodal vector norm, as the large-displacement warning measures it);
- the reaction resultant of a dynamic run (/continuum/energy/reaction): a block falling on
  rollers, the mean of two successive states = its weight plus the inertia sum m_j dv_j / h;
- postproc/plot_results.py, as ./run.sh calls it, on the static, dynamic and modal files.
Usage (ctest does this): test_continuum_runs.py --exe multicor --work DIR --source REPO
"""
import math
import re
import shutil
import subprocess
import sys
import time

import h5py
import numpy as np

from checks import arguments, check, check_summary_without_steps, multicor, plots, plots_together, summary
from paraview_read import read_paraview


def run(exe, deck, work):
    return multicor(exe, deck, work)[0]


def write_deck(work, name, text):
    path = work / f"{name}.dat"
    path.write_text(text)
    return path


def tip_deflection(h5):
    with h5py.File(h5, "r") as f:
        x = f["continuum/mesh/coordinates"][...]          # (n_nodes, 2)
        u = f["continuum/static/displacement"][...]
    i = int(np.argmin(np.abs(x[:, 0] - 10.0) + np.abs(x[:, 1])))
    return u[i, 1]


def static_cantilever(exe, src, work):
    E, nu, t, D, L, P = 70e9, 0.3, 0.1, 1.0, 10.0, 1000.0
    I = t * D**3 / 12
    v_ref = P * L**3 / (3 * E * I) + (4 + 5 * nu) * P * D**2 * L / (24 * E * I)
    deck = src / "input" / "continuum_cantilever.dat"
    start = time.monotonic()
    h5_fine = run(exe, deck, work)
    # (its /summary: summary_without_steps, with the seconds the process took)
    static_cantilever.seconds = time.monotonic() - start
    coarse = write_deck(work, "cantilever_80x8",
                        deck.read_text().replace("rectangle 0 -0.5 10 1 160 16 q4", "rectangle 0 -0.5 10 1 80 8 q4"))
    v_fine, v_coarse = tip_deflection(h5_fine), tip_deflection(run(exe, coarse, work))
    # 160 x 16 Q4: measured -0.29 % (Q4 discretisation, order h^2, plus the fully clamped
    # root, stiffer than Timoshenko's point support: -0.09 % by extrapolation); 0.5 % bound.
    err = v_fine / v_ref - 1
    check("static tip deflection vs Timoshenko", -0.005 < err < 0, f"{v_fine:.6e} vs {v_ref:.6e} ({err:+.3%})")
    # Halving h divides the error by ~4 (order 2): Richardson's extrapolation removes it and
    # leaves the clamping effect (0.09 %, Saint-Venant) and an O(h^4) remainder: 0.2 %.
    v_extrap = v_fine + (v_fine - v_coarse) / 3
    e_extrap = v_extrap / v_ref - 1
    check("static extrapolated tip deflection", abs(e_extrap) < 0.002, f"{v_extrap:.6e} ({e_extrap:+.3%})")
    # Q4 converges from below (too stiff): the coarse mesh deflects less than the fine one.
    check("static convergence from below", v_coarse < v_fine < v_extrap,
          f"80x8 {v_coarse / v_ref - 1:+.3%}, 160x16 {err:+.3%}")
    with h5py.File(h5_fine, "r") as f:
        s = f["continuum/static/stress"][...]           # (n_elements, 3)
        c = f["continuum/mesh/coordinates"][...]
        conn = f["continuum/mesh/connectivity"][...]
        energy = f["continuum/static"].attrs["strain_energy"]
    # Clapeyron: strain energy = half the work of the end load on its own displacement; the
    # load is spread, so compare with P v_tip / 2 (exact profile: within 0.1 % of the tip).
    check("static strain energy ~ P v / 2", abs(energy / (0.5 * P * v_fine) - 1) < 2e-3,
          f"{energy:.6e} J vs {0.5 * P * v_fine:.6e} J")
    # Bending stress at mid-span, top row of elements: sigma = -P (L - x) y / I at the element
    # centre (x = L/2 - h/2 or L/2 + h/2, y = D/2 - h/2, h = 1/16). Far from the clamp and the
    # load (Saint-Venant), the Q4 centre stress of a linear bending field is exact up to the
    # h^2 error of the displacements (0.3 % at the tip): 1 % bound.
    h = 1.0 / 16
    centres = c[conn[:, :4] - 1].mean(axis=1)
    k = int(np.argmin(np.hypot(centres[:, 0] - (L / 2 + h / 2), centres[:, 1] - (D / 2 - h / 2))))
    s_ref = -P * (L - centres[k, 0]) * centres[k, 1] / I
    check("static mid-span bending stress", abs(s[k, 0] / s_ref - 1) < 0.01, f"{s[k, 0]:.5e} vs {s_ref:.5e} Pa")
    return h5_fine


def modal_strip(exe, work):
    E, nu, rho, t, D, L = 70e9, 0.3, 2700.0, 0.1, 0.2, 10.0
    I, A = t * D**3 / 12, t * D
    omega = {}
    for nx, ny in [(160, 4), (320, 8)]:
        deck = write_deck(work, f"strip_{nx}x{ny}", f"""[run]
analysis = modal
[continuum]
mesh = rectangle 0 -0.1 10 0.2 {nx} {ny} q4
material = 70e9 0.3 2700 0.1 plane_stress
fix = left x y
[modal]
modes = 4
""")
        with h5py.File(run(exe, deck, work), "r") as f:
            omega[nx] = f["continuum/modal/omega"][...]
            shapes = f["continuum/modal/shapes"][...]
    check("modal shapes stored", shapes.shape == (4, (321) * 9, 2), f"shape {shapes.shape}")
    bl = np.array([1.875104069, 4.694091133, 7.854757438])
    w_eb = bl**2 * math.sqrt(E * I / (rho * A * L**4))
    # Timoshenko's first-order correction: -(beta r)^2 (1 + E/(kappa G))/2, r^2 = I/A,
    # kappa = 5/6: 0.024 %, 0.15 %, 0.42 % for the first three modes.
    corr = (bl / L) ** 2 * (I / A) * (1 + 2 * (1 + nu) / (5 / 6)) / 2
    fine, coarse = omega[320][:3], omega[160][:3]
    # Q4 is stiff (parasitic shear, order h^2): above the Timoshenko value, by < 1 % at 320 x 8.
    gap = fine / (w_eb * (1 - corr)) - 1
    check("modal strip above Timoshenko, within 1 %", bool(np.all((gap > 0) & (gap < 0.01))), f"{gap}")
    # Richardson (order 2) removes the discretisation error; what is left below the beam is
    # the shear correction, within 0.1 % (clamped-root stiffening and O(h^4) remainder).
    extrap = fine + (fine - coarse) / 3
    drop = 1 - extrap / w_eb
    check("modal strip drop below the beam = shear correction", bool(np.all(np.abs(drop - corr) < 1e-3)),
          f"drop {drop}, predicted {corr}")


def rigid_motion(exe, work):
    for element in ["q4", "t3"]:
        deck = write_deck(work, f"rigid_{element}", f"""[run]
analysis = dynamic
[continuum]
mesh = rectangle 0 0 2 1 8 4 {element}
material = 2e11 0.3 7800 0.01 plane_strain
initial_velocity = 1.5 -0.5 2.0 1 0.5
[time]
step = 1e-3
end = 0.1
""")
        with h5py.File(run(exe, deck, work), "r") as f:
            kin = f["continuum/energy/kinetic"][...]
            strain = f["continuum/energy/strain"][...]
            stress = f["continuum/stress"][...]
        # A linear velocity field (translation + infinitesimal rotation) has no strain: K u = 0
        # up to rounding. Rounding leaves |K u| ~ eps |K| |u|, hence a strain energy
        # ~ eps E (|u|/h_e)^2 V; compared with the energy E (|u|/L)^2 V / 2 of a deformation of
        # the same size it is ~1e-14 (observed 1e-15); a missing rigid mode would give ~1.
        with h5py.File(work / f"rigid_{element}" / f"rigid_{element}.h5", "r") as f:
            u = f["continuum/displacement"][...]
        scale = 0.5 * 2e11 * (np.max(np.abs(u)) / 2.0) ** 2 * (2.0 * 1.0 * 0.01)
        ratio = np.max(strain) / scale
        check(f"rigid motion {element}: no strain energy", ratio < 1e-12, f"max strain energy / E-scale = {ratio:.1e}")
        # Stresses: rounding of E grad u (|grad u| ~ omega t = 0.2): 1e-16 * 2e11 * 0.2 * 1e3
        # (conditioning) ~ 1e-2 Pa at most, against E |grad u| = 4e10 Pa for a real strain.
        check(f"rigid motion {element}: no stress", np.max(np.abs(stress)) < 1e-2,
              f"max |stress| = {np.max(np.abs(stress)):.1e} Pa")
        # The same rounding forces change v by ~ h omega_max^2 |u| eps per step (omega_max^2 ~
        # E/(rho h_e^2) = 4e8 /s^2): a relative drift ~ omega_max^2 t^2 eps = 4e-10; 1e-8 bound.
        check(f"rigid motion {element}: kinetic energy kept", abs(kin[-1] / kin[0] - 1) < 1e-8,
              f"{kin[-1] / kin[0] - 1:.1e}")


def energy_balance(exe, src, work):
    deck = src / "input" / "continuum_cantilever_dynamic.dat"
    damped = write_deck(work, "cantilever_damped", deck.read_text().replace(
        "traction = right 0 10000 parabolic", "traction = right 0 10000 parabolic\nrayleigh = 0.5 1e-4"))
    shipped = None
    for path in [deck, damped]:
        # the shipped deck's run, not quiet, gives the summary line checked below too
        h5, proc = multicor(exe, path, work, quiet=path != deck)
        if path == deck:
            shipped = h5, proc
        with h5py.File(h5, "r") as f:
            e = {k: f["continuum/energy"][k][...] for k in f["continuum/energy"]}
            x = f["continuum/mesh/coordinates"][...]
            u = f["continuum/displacement"][...]
        scale = np.max(e["external_work"])
        # Average acceleration with the trapezoidal work and dissipation sums is exact for a
        # linear model: only rounding remains (1e-12 relative over 500 steps); 1e-9 bound.
        bal = np.max(np.abs(e["balance"])) / scale
        check(f"energy balance {path.stem}", bal < 1e-9, f"max |balance| / max work = {bal:.1e}")
        direct = e["kinetic"] + e["strain"] + e["damping"] - e["external_work"]
        check(f"energy terms add up {path.stem}", np.max(np.abs(direct)) / scale < 1e-9,
              f"{np.max(np.abs(direct)) / scale:.1e}")
        tip = u[:, int(np.argmin(np.abs(x[:, 0] - 10) + np.abs(x[:, 1]))), 1]
        if path == deck:
            # Undamped step response: the tip swings between 0 and about twice the static
            # deflection (5.75e-4 m, Timoshenko; the coarse 40 x 4 mesh is ~4 % stiffer and
            # the higher modes add a little): 1.7 to 2.1 times.
            check("dynamic tip overshoot", 1.7 * 5.75e-4 < tip.max() < 2.1 * 5.75e-4, f"max tip {tip.max():.4e} m")
        else:
            # Rayleigh damping with a0, a1 >= 0 dissipates at every step (trapezoidal sum of
            # v_avg.C v_avg h >= 0) and, at ~0.7 % of critical on mode 1 over four periods, a few
            # percent of the work at least.
            steps = np.diff(e["damping"])
            check("damped run dissipates", bool(np.all(steps >= 0)) and e["damping"][-1] > 0.01 * scale,
                  f"{e['damping'][-1]:.3e} J of {scale:.3e} J")
    # A dissipative Newmark scheme (gamma = 0.6 > 1/2, beta = (gamma + 1/2)^2 / 4) damps the
    # high modes by design: the balance, the same audit, is then minus that numerical
    # dissipation, well beyond round-off (measured -3.9 % of the work at the end; above 1e-3
    # of it), and the summary line says so; with gamma = 1/2 (the shipped deck, above) it does not.
    dissipative = write_deck(work, "cantilever_newmark_0.6", deck.read_text().replace(
        "[time]\n", "[time]\nscheme = newmark\nbeta = 0.3025\ngamma = 0.6\n"))
    for path, note in ((dissipative, True), (deck, False)):
        h5, proc = multicor(exe, path, work / "balance_label", quiet=False) if path != deck else shipped
        with h5py.File(h5, "r") as f:
            balance, work_ = f["continuum/energy/balance"][-1], np.max(f["continuum/energy/external_work"][...])
        line = next((x for x in proc.stdout.splitlines() if "energy balance residual" in x), "")
        said = "includes the numerical dissipation of Newmark gamma = 0.6 > 1/2" in line
        check(f"summary's energy balance of {path.stem}: {'names' if note else 'no'} numerical dissipation",
              said == note and (balance < -1e-3 * work_ if note else abs(balance) < 1e-9 * work_),
              f"{line.strip()}; balance {balance:.3e} J of {work_:.3e} J")


def gmsh_block(exe, src, work):
    gmsh = shutil.which("gmsh")
    if gmsh is None:
        check("gmsh available for the mesh test", False, "gmsh not found (Debian package gmsh)")
        return
    msh = work / "two_blocks.msh"
    subprocess.run([gmsh, "-2", "-format", "msh41", str(src / "tests" / "data" / "gmsh" / "two_blocks.geo"),
                    "-o", str(msh)], check=True, capture_output=True)
    E, nu, sigma = 1e9, 0.25, 2e6
    deck = write_deck(work, "gmsh_tension", f"""[run]
analysis = static
[continuum]
mesh = file two_blocks.msh
material = {E} {nu} 1000 0.5 plane_stress
fix = clamped x
fix = origin y
traction = loaded {sigma} 0
""")
    with h5py.File(run(exe, deck, work), "r") as f:
        s = f["continuum/static/stress"][...]
        x = f["continuum/mesh/coordinates"][...]
        u = f["continuum/static/displacement"][...]
        kinds = f["continuum/mesh/kind"][...]
        sets = sorted(f["continuum/sets/nodes"].keys())
    # Uniform tension is in the span of Q4 and T3: reproduced exactly up to rounding (1e-9).
    check("gmsh mesh has both element kinds", set(kinds.tolist()) == {1, 2}, f"kinds {sorted(set(kinds.tolist()))}")
    check("gmsh physical groups as sets", {"clamped", "loaded", "origin", "all"} <= set(sets), f"{sets}")
    check("gmsh tension: sigma_xx uniform", np.max(np.abs(s[:, 0] / sigma - 1)) < 1e-9, f"{np.max(np.abs(s[:, 0] / sigma - 1)):.1e}")
    check("gmsh tension: no other stress", np.max(np.abs(s[:, 1:])) / sigma < 1e-9, f"{np.max(np.abs(s[:, 1:])) / sigma:.1e}")
    exact = np.column_stack([sigma / E * x[:, 0], -nu * sigma / E * x[:, 1]])
    check("gmsh tension: displacement field", np.max(np.abs(u - exact)) < 1e-9 * sigma / E * 2,
          f"{np.max(np.abs(u - exact)):.1e} m")


RAMP_BAR = """[run]
title = bar under a ramped end traction
analysis = dynamic
[functions]
function = 1 ramp 4e-3
function = 2 constant 0.25
[continuum]
mesh = rectangle 0 0 1 0.1 40 2 q4
material = 1e9 0 1000 0.1 plane_stress
fix = left x
fix = bottom y
traction = right 1e6 0 uniform 1
[time]
step = 2e-5
end = 8e-3
[output]
interval = 5
"""


def timed_loads(exe, work):
    # E = 1 GPa, rho = 1000, nu = 0: c = 1000 m/s, L = 1 m; first period 4 L / c = 4 ms = t1.
    E, sigma, L, area = 1e9, 1e6, 1.0, 0.1 * 0.1
    u_static = sigma * L / E
    h5 = run(exe, write_deck(work, "ramp_bar", RAMP_BAR), work)
    with h5py.File(h5, "r") as f:
        x = f["continuum/mesh/coordinates"][...]
        tip = f["continuum/displacement"][:, np.isclose(x[:, 0], L), 0].mean(axis=1)
        t = f["continuum/energy/time"][...]
        strain = f["continuum/energy/strain"][-1]
        work_ext = f["continuum/energy/external_work"][-1]
    after = tip[t >= 4e-3 - 1e-12]
    dev = np.abs(after / u_static - 1).max()
    # 40 Q4 along the bar at 200 steps per period: the mesh and Newmark dispersion of the
    # higher modes leave 1.7e-4 of residual swing (measured; 3.2e-4 at 400 steps per period);
    # 1e-2 bound, against 1 (the swing of a step load) if the function were ignored.
    check("ramped traction: static tip displacement after the ramp", dev < 1e-2,
          f"max |u/u_static - 1| = {dev:.2e} over t >= t1 (u_static = {u_static:.3e} m)")
    # Quasi-static loading: work = strain energy = sigma^2 V / (2 E) (a step load: sigma A u_tip);
    # both to about the same 2e-4 as the displacement; 1e-2 bound.
    e_ref = sigma**2 * area * L / (2 * E)
    check("ramped traction: work and strain energy = sigma^2 V / (2 E)",
          abs(strain / e_ref - 1) < 1e-2 and abs(work_ext / e_ref - 1) < 1e-2,
          f"strain {strain:.6e} J, work {work_ext:.6e} J, expected {e_ref:.6e} J")
    # Static: the load times the function's value at t = 0 (0.25): u = 0.25 sigma L / E, exact
    # for Q4 (linear field); rounding of the sparse solve, 1e-9.
    static = RAMP_BAR.replace("analysis = dynamic", "analysis = static").replace("uniform 1", "uniform 2")
    # [time] and [output] interval have no effect in a static analysis: [time] is refused there
    static = static[:static.index("[time]")] + "[output]\ninterval = 10\n"
    h5 = run(exe, write_deck(work, "ramp_bar_static", static), work)
    with h5py.File(h5, "r") as f:
        x = f["continuum/mesh/coordinates"][...]
        u = f["continuum/static/displacement"][...]
    err = np.abs(u[:, 0] - 0.25 * u_static * x[:, 0] / L).max() / u_static
    check("static load times its function at t = 0", err < 1e-9, f"max error {err:.1e} of sigma L / E")
    # A load naming an undefined function: exit 1 naming file, line and keyword.
    bad = write_deck(work, "ramp_bar_bad", RAMP_BAR.replace("uniform 1", "uniform 7"))
    proc = subprocess.run([str(exe), "--check", str(bad)], capture_output=True, text=True)
    msg = proc.stdout + proc.stderr
    check("undefined function of a traction: input error", proc.returncode == 1 and "ramp_bar_bad.dat:12" in msg
          and "traction" in msg and "function 7" in msg, msg.strip().splitlines()[-1] if msg.strip() else "")


def xdmf_paraview(h5_static, h5_dynamic, work):
    """Open the XDMF files with ParaView's pvpython (XDMF Reader) or, without it, meshio."""
    xdmf_static, xdmf_dynamic = h5_static.with_suffix(".xdmf"), h5_dynamic.with_suffix(".xdmf")
    with h5py.File(h5_dynamic, "r") as f:
        n_out = f["continuum/time"].shape[0]
        last = f["continuum/displacement"][-1]
        last_stress = f["continuum/stress"][-1]
        dynamic_material = f["continuum/mesh/material"][...]
    with h5py.File(h5_static, "r") as f:
        static_stress = f["continuum/static/stress"][...]
        static_reactions = f["continuum/static/reactions"][...]
        static_material = f["continuum/mesh/material"][...]
    if shutil.which("pvpython") is not None:
        rows = read_paraview([xdmf_static, xdmf_dynamic], work, "ParaView (pvpython) opens both XDMF files")
        if rows is not None:
            (block,) = rows[str(xdmf_dynamic)]["blocks"].values()
            n_times = rows[str(xdmf_dynamic)]["times"]
            umax = max(u[1] for u in block["data"]["displacement"])
            check("ParaView reads every stored state", n_times == n_out, f"{n_times} vs {n_out}")
            # The last state's largest y displacement, through the hyperslab: same double.
            check("ParaView reads the last state", umax == float(last[:, 1].max()), f"{umax} vs {last[:, 1].max()}")
            # the stress components as three scalars (each a hyperslab of one column), equal to
            # the HDF5 columns bit for bit, static and at the last state
            (static_block,) = rows[str(xdmf_static)]["blocks"].values()
            names = ["sigma_xx", "sigma_yy", "sigma_xy"]
            same = all(block["cell_data"][n] == last_stress[:, c].tolist()
                       and static_block["cell_data"][n] == static_stress[:, c].tolist() for c, n in enumerate(names))
            check("ParaView reads the stresses as sigma_xx, sigma_yy, sigma_xy",
                  all(n in block["cell_data"] for n in names) and same, sorted(block["cell_data"]))
            # the static reactions (point vector, ParaView adds z = 0) and each element's
            # material (cell scalar), equal to the HDF5 datasets bit for bit
            reaction = [row[:2] for row in static_block["data"].get("reaction", [])]
            check("ParaView reads the static reactions and the elements' materials",
                  reaction == static_reactions.tolist() and static_block["cell_data"].get("material") ==
                  static_material.tolist() and block["cell_data"].get("material") == dynamic_material.tolist(),
                  f"{sorted(static_block['data'])}, {sorted(static_block['cell_data'])}, {sorted(block['cell_data'])}")
        return
    import meshio  # noqa: E402 (postproc/requirements.txt)
    m = meshio.read(xdmf_static)
    with h5py.File(h5_static, "r") as f:
        d = f["continuum/static/displacement"][...]
    check("meshio opens the static XDMF (no pvpython)", np.array_equal(m.point_data["displacement"], d), "meshio")


def static_reactions(exe, work):
    """Reactions of the supports in a static run, K u - f on the prescribed dofs (N, 0 on the
    free dofs), against closed forms; the materials stored; the summary's max |displacement|."""
    # A column W x H under its weight on rollers (bottom: y; left: x). Two material records on
    # the whole mesh, the second (plane strain) overriding the first: every element's material
    # is record 2, and /continuum/materials lists both in deck order.
    W, H, t, rho, g = 0.5, 3.0, 0.2, 2500.0, 9.81
    deck = write_deck(work, "column_weight", f"""[run]
analysis = static
[continuum]
mesh = rectangle 0 0 {W} {H} 3 12 q4
material = 30e9 0.3 2500 0.2 plane_stress
material = 25e9 0.2 {rho} {t} plane_strain
fix = bottom y
fix = left x
gravity = 0 -{g}
""")
    with h5py.File(run(exe, deck, work), "r") as f:
        x = f["continuum/mesh/coordinates"][...]
        r = f["continuum/static/reactions"][...] if "continuum/static/reactions" in f else None
        units = f["continuum/static/reactions"].attrs.get("units") if r is not None else None
        mat = {k: f["continuum/materials"][k][...].tolist() for k in f["continuum/materials"]} \
            if "continuum/materials" in f else {}
        index = f["continuum/mesh/material"][...] if "continuum/mesh/material" in f else None
    if not check("static reactions stored (n_nodes, 2) [N]", r is not None and r.shape == x.shape and units == "N",
                 f"{None if r is None else r.shape}, units {units}"):
        return
    weight = rho * g * W * H * t
    # Equilibrium of the whole body: the reactions carry the weight up to the solve's residual
    # (|K u - f| / |f| about 1e-16 here) and the round-off of the sum: 1e-9 relative.
    check("column: reactions carry the weight rho g W H t", abs(r[:, 1].sum() / weight - 1) < 1e-9
          and abs(r[:, 0].sum()) < 1e-9 * weight, f"{r.sum(axis=0)} N vs (0, {weight}) N")
    bottom, left = np.isclose(x[:, 1], 0.0), np.isclose(x[:, 0], 0.0)
    check("column: reactions only on the prescribed dofs", not r[~bottom, 1].any() and not r[~left, 0].any()
          and (r[bottom, 1] > 0).all(), f"{np.count_nonzero(r)} nonzero")
    check("materials stored in deck order, each element's the last record", mat == {
        "young": [30e9, 25e9], "poisson": [0.3, 0.2], "density": [2500.0, rho], "thickness": [0.2, t],
        "plane_strain": [0, 1]} and index is not None and (index == 2).all(), f"{mat}, {index}")
    # A bar (nu = 0) stretched by delta on its right side (rollers left and bottom): the
    # stress E delta / L is uniform, which Q4 represents exactly; each end carries E t D
    # delta / L (outward on the right, inward on the left) up to round-off: 1e-9 relative.
    E, L, D, delta = 2e11, 2.0, 0.4, 1e-4
    deck = write_deck(work, "bar_stretched", f"""[run]
analysis = static
[continuum]
mesh = rectangle 0 0 {L} {D} 8 2 q4
material = {E} 0 7800 {t} plane_stress
fix = left x
fix = bottom y
displacement = right x {delta}
""")
    with h5py.File(run(exe, deck, work), "r") as f:
        x = f["continuum/mesh/coordinates"][...]
        r = f["continuum/static/reactions"][...]
    force = E * t * D * delta / L
    right, left = np.isclose(x[:, 0], L), np.isclose(x[:, 0], 0.0)
    check("bar: end reactions E t D delta / L", abs(r[right, 0].sum() / force - 1) < 1e-9
          and abs(r[left, 0].sum() / force + 1) < 1e-9 and np.abs(r[:, 1]).max() < 1e-9 * force,
          f"{r[right, 0].sum()}, {r[left, 0].sum()} N vs +-{force} N")
    # A rigid translation (delta, delta) prescribed on the left side: no reaction (round-off of
    # K u against E t delta: 1e-9), and the summary's max |displacement| is the nodal vector
    # norm sqrt(2) delta, the measure of the large-displacement warning (the largest component,
    # delta, was printed before), to the printed 6 digits.
    deck = write_deck(work, "block_translated", f"""[run]
analysis = static
[continuum]
mesh = rectangle 0 0 {L} {D} 4 2 t3
material = {E} 0.25 7800 {t} plane_stress
displacement = left x {delta}
displacement = left y {delta}
""")
    h5, proc = multicor(exe, deck, work, quiet=False)
    with h5py.File(h5, "r") as f:
        r = f["continuum/static/reactions"][...]
    check("translation: no reaction", np.abs(r).max() < 1e-9 * E * t * delta, f"max |r| {np.abs(r).max():.3e} N")
    m = re.search(r"max \|displacement\| = +(\S+) m", proc.stdout)
    printed = float(m.group(1)) if m else math.nan
    check("summary max |displacement| is the largest nodal norm", abs(printed / (math.sqrt(2) * delta) - 1) < 1e-5,
          f"{printed} vs {math.sqrt(2) * delta:.6e}")


def dynamic_reaction(exe, work):
    """A block on rollers (y fixed along the bottom, x along the left side) falling onto them
    under gravity: /continuum/energy/reaction is the resultant of the supports' forces on all
    their dofs. Summed over all the y (x) dofs, K u vanishes (a rigid translation is in the
    kernel of the symmetric K), the free dofs are in balance and the mass matrix's row sums are
    the lumped masses m_j, so R = sum_j m_j a_j - (0, -M g). Average acceleration gives
    (a_n + a_n+1)/2 = (v_n+1 - v_n)/h, so the mean of two successive resultants is
    (sum_j m_j (v_n+1 - v_n)/h, M g + sum_j m_j (v_n+1 - v_n)_y/h), the weight carried and
    the block's inertia."""
    W, H, t, rho, g, h = 0.4, 1.0, 0.1, 1000.0, 9.81, 1e-3
    deck = write_deck(work, "block_on_rollers", f"""[run]
analysis = dynamic
[continuum]
mesh = rectangle 0 0 {W} {H} 2 4 q4
material = 1e6 0.3 {rho} {t} plane_stress
gravity = 0 -{g}
fix = bottom y
fix = left x
[time]
step = {h}
end = 0.05
[output]
interval = 1
""")
    with h5py.File(run(exe, deck, work), "r") as f:
        x, conn = f["continuum/mesh/coordinates"][...], f["continuum/mesh/connectivity"][...]
        v, r = f["continuum/velocity"][...], f["continuum/energy/reaction"][...]
    m = np.zeros(len(x))          # row sums of the Q4 mass: a quarter of each element's mass
    for e in conn:
        m[e - 1] += rho * t * (W / 2) * (H / 4) / 4
    weight = rho * t * W * H * g
    inertia = np.einsum("j,njc->nc", m, np.diff(v, axis=0)) / h
    want = inertia + [0.0, weight]
    got = 0.5 * (r[1:] + r[:-1])
    # round-off of the solve and of the sums against the weight (392 N; measured 7e-13 N): 1e-9 of it
    err = np.abs(got - want).max()
    check("block on rollers: reaction resultant (x, y) = the inertia + (0, M g)", len(r) == 51 and
          np.abs(inertia[:, 1]).max() > 1e-2 * weight and err < 1e-9 * weight,
          f"{len(r)} states, largest difference {err:.3e} N, weight {weight} N, "
          f"largest inertia {np.abs(inertia).max():.3e} N")


def summary_without_steps(exe, src, work, h5_static):
    """A static and a modal analysis write /summary as a time loop does: steps (0),
    wall_seconds and ended (a sweep over them gets its wall-time column). The static one is
    static_cantilever's run of input/continuum_cantilever.dat (timed there)."""
    static = src / "input" / "continuum_cantilever.dat"
    check_summary_without_steps(static.name, h5_static, static_cantilever.seconds)
    text = re.sub(r"^analysis\s*=\s*static", "analysis = modal\n[modal]\nmodes = 3", static.read_text(),
                  count=1, flags=re.M)
    modal = write_deck(work, "cantilever_modal", text)
    start = time.monotonic()
    h5, _ = multicor(exe, modal, work / "summary")
    check_summary_without_steps(modal.name, h5, time.monotonic() - start)


def main():
    exe, work, src = arguments()
    h5_static = static_cantilever(exe, src, work)
    modal_strip(exe, work)
    rigid_motion(exe, work)
    energy_balance(exe, src, work)
    gmsh_block(exe, src, work)
    timed_loads(exe, work)
    static_reactions(exe, work)
    dynamic_reaction(exe, work)
    summary_without_steps(exe, src, work, h5_static)
    h5_dynamic = work / "continuum_cantilever_dynamic" / "continuum_cantilever_dynamic.h5"
    xdmf_paraview(h5_static, h5_dynamic, work)
    # every dataset with a physical unit carries it (doc/output.md), static and modal too
    units = {}
    for h5, names in ((h5_static, ["continuum/static/displacement", "continuum/static/stress",
                                   "continuum/static/reactions", "continuum/materials/young"]),
                      (work / "strip_160x4" / "strip_160x4.h5",
                       ["continuum/modal/omega", "continuum/modal/frequency", "continuum/modal/shapes"])):
        with h5py.File(h5, "r") as f:
            units.update({n: f[n].attrs.get("units", b"").decode() if isinstance(f[n].attrs.get("units", ""), bytes)
                          else str(f[n].attrs.get("units", "")) for n in names})
    check("static and modal datasets carry their units",
          list(units.values()) == ["m", "Pa", "N", "Pa", "rad/s", "Hz", "kg^-1/2 (mass-normalised)"], str(units))
    # the plots ./run.sh draws after a continuum run: static (its own process, as ./run.sh
    # runs it), dynamic and modal (one process for both: Python and matplotlib start once)
    plots(src, h5_static, work / "png", ["stress"])
    plots_together(src, [(h5_dynamic, work / "png", ["stress", "continuum_energy", "history"]),
                         (work / "strip_160x4" / "strip_160x4.h5", work / "png", ["modes"])])
    return summary()


if __name__ == "__main__":
    sys.exit(main())
