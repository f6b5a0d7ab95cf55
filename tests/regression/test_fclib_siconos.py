#!/usr/bin/env python3
"""The FCLIB export ([solver] fclib_step) cross-checked by another code: Siconos 4.4
(siconos.numerics, Debian's python3-siconos). Frictional problems without cohesion (two
components per contact), the ones Siconos' fc2d solvers take.

For each exported step, siconos_fc2d.py runs under the system Python that has Siconos (the
test environment does not see it, as with ParaView's pvpython in test_continuum_runs.py; set
MULTICOR_SICONOS_PYTHON to use another interpreter): it reads the file as FCLIB's reader does
(any departure from FCLIB's layout fails here; the optional /fclib_local/info must be
there, in fixed-length strings that FCLIB's reader reads), evaluates Siconos' own error function
(fc2d_compute_error) on MULTICOR's stored solution, and solves the problem with Siconos' fc2d
NSGS from zero. This script then asserts:
(a) Siconos' error of our solution equals the one multicor stored (/dem/solver/siconos_error),
    and Siconos 4.4 scales it as we do, by max(|q|, |r|, |u|);
(b) Siconos' solution and ours agree: reactions and velocities where the problem has one
    solution (W positive definite); for a hyperstatic stack (W singular, reactions not unique)
    the velocities and each solution's error under the other code's error function.
The cases: a deposit solved loosely and tightly, a hyperstatic stack, and a coupled step: the
interface experiment (continuum blocks glued to the disk layer by Arlequin rows), whose export
is the contact problem with the coupling rows condensed, without its rolling resistance so
that Siconos' fc2d takes it. Siconos solving that problem to the same reactions checks the
condensed W and q against a solver that knows nothing of the coupling.
Without Siconos on a Debian machine the test fails with the command that installs it
(scripts/bootstrap.sh lists python3-siconos and python3-h5py); elsewhere it skips (exit 77).
Usage (ctest does this): test_fclib_siconos.py --exe multicor --work DIR --source REPO
"""
import json
import pathlib
import re
import subprocess
import sys

import h5py
import numpy as np

from checks import arguments, check, multicor, summary
from siconos_env import siconos_python

HERE = pathlib.Path(__file__).resolve().parent

# A hyperstatic stack: 4 rows of 6 touching disks of 1 cm on a hexagonal lattice, on the floor
# between two walls, at rest under gravity (24 disks, 72 degrees of freedom, 63 contacts and
# 126 unknowns: W has rank 72). Exported at step 3, once the reactions carry the weight.
STACK = """[run]
analysis = dynamic
[particles]
material = 1 2500
hex_lattice = 6 4 0.01 0.01 0.01 1
gravity = 0 -9.81
[walls]
wall = 0 0 0.13 0
wall = 0 0 0 0.2
wall = 0.13 0 0.13 0.2
[contacts]
law = 1 1 0.3 0 0
[solver]
criterion = siconos
tolerance = 1e-10
max_sweeps = 100000
fclib_step = 3
[time]
step = 1e-3
end = 3e-3
"""


def with_solver(deck, work, name, solver_lines):
    """Copy of deck (which has no [solver] section) with a [solver] section of these lines."""
    lines = deck.read_text().splitlines()
    assert "[solver]" not in [ln.strip() for ln in lines], deck
    lines += ["[solver]", *solver_lines]
    out = work / name
    out.write_text("\n".join(lines) + "\n")
    return out


def run(exe, deck, work):
    return multicor(exe, deck, work)[0]


def case(exe, python, env, deck, step, work, sic_tol, hyperstatic=False):
    results = run(exe, deck, work)
    fclib = results.parent / f"{deck.stem}_fclib_{step}.h5"
    name = deck.stem
    with h5py.File(results, "r") as f:
        stored = float(f["dem/solver/siconos_error"][step - 1])
    with h5py.File(fclib, "r") as f:
        g = f["fclib_local/W"]
        m, p, i, x = int(g["m"][0]), g["p"][...], g["i"][...], g["x"][...]
        q, mu = f["fclib_local/vectors/q"][...], f["fclib_local/vectors/mu"][...]
        r, u = f["solution/r"][...], f["solution/u"][...]
    W = np.zeros((m, m))
    for col in range(m):
        W[i[p[col]:p[col + 1]], col] = x[p[col]:p[col + 1]]
    out = work / f"{name}_siconos.json"
    proc = subprocess.run([python, str(HERE / "siconos_fc2d.py"), str(fclib), str(out),
                           "--tolerance", str(sic_tol), "--max-iter", "100000"],
                          capture_output=True, text=True, env=env, timeout=600)
    if proc.returncode != 0:
        print(proc.stdout, proc.stderr)
        check(f"{name}: Siconos ran", False, f"exit {proc.returncode}")
        return
    s = json.loads(out.read_text())
    check(f"{name}: FCLIB layout (read as fclib_read_local, fclib_read_solution)", not s["layout"],
          "; ".join(s["layout"]) or f"{len(mu)} contacts, Siconos {s['siconos']}")
    if s["layout"]:
        return
    info = s["info"]
    check(f"{name}: FCLIB problem information (/fclib_local/info)",
          set(info) == {"title", "description", "math_info"} and info["title"].endswith(f"step {step}")
          and f"step {step} " in info["description"], f"title {info.get('title')!r}")
    lam = np.linalg.eigvalsh(W)
    rank = int(np.sum(lam > 1e-12 * lam[-1]))
    print(f"       {name}: {len(mu)} contacts, rank of W {rank} of {m}, eigenvalues "
          f"{lam[0]:.2e} .. {lam[-1]:.2e}; Siconos NSGS: info {s['nsgs_info']}, "
          f"{s['nsgs_iterations']} iterations, its residual {s['nsgs_residual']:.2e}")
    check(f"{name}: hyperstatic as built" if hyperstatic else f"{name}: W positive definite",
          (rank < m) if hyperstatic else (rank == m), f"rank {rank} of {m}")

    # (a) Siconos' fc2d_compute_error of our stored r against our stored error. Siconos forms
    # u = W r + q from the exported W (dense gemv), multicor from the body velocities: the two
    # differ by the round-off of sums of terms of size |q| (a few eps |q|), which the error's
    # numerator takes up to its sqrt(m) components (at most about 1e-15 of the scale
    # max(|q|, |r|, |u|) here): 1e-8 relative plus 1e-14 absolute leaves a margin of 10 to
    # 10^4 over that, and a different formula or scaling changes the error at O(1).
    u_sic = np.array(s["stored_u_by_siconos"])
    du = np.max(np.abs(u_sic - u)) / np.linalg.norm(q)
    check(f"{name}: Siconos' W r + q = the stored u", du < 1e-12, f"max diff / |q| = {du:.1e}")
    e_sic = s["stored_error_by_siconos"]
    check(f"{name}: Siconos' error of our solution = our stored error",
          abs(e_sic - stored) <= 1e-8 * stored + 1e-14,
          f"Siconos {e_sic:.10e}, multicor {stored:.10e}")
    # Siconos 4.4 (fc2d_compute_error.c) divides by max(norm, |r|, |W r + q|) with norm = |q|
    # from fc2d_nsgs; with norm = 1e30 the quotient is the numerator / 1e30, so
    # numerator / max(|q|, |r|, |u|) must give the same error again.
    scale = max(np.linalg.norm(q), np.linalg.norm(r), np.linalg.norm(u))
    e_back = s["stored_error_norm_1e30"] * 1e30 / scale
    check(f"{name}: Siconos' scaling is max(|q|, |r|, |u|)", abs(e_back - e_sic) <= 1e-12 * e_sic,
          f"{e_back:.10e} against {e_sic:.10e}")

    # (b) Siconos' solution against ours.
    r2, u2, e2 = np.array(s["r"]), np.array(s["u_from_r"]), s["error"]
    check(f"{name}: Siconos NSGS reached its tolerance", s["nsgs_info"] == 0 and e2 <= sic_tol,
          f"its error (fc2d_compute_error) {e2:.2e}, tolerance {sic_tol:.0e}")
    scale2 = max(np.linalg.norm(q), np.linalg.norm(r2), np.linalg.norm(u2))
    # Both solutions leave natural-map residuals |F| = E max(|q|, |r|, |u|). Where a contact
    # sticks, F = u_hat = (u_n + mu |u_t|, u_t), so |u| <= (1 + mu) |F| there and the two
    # velocity vectors differ by at most (1 + mu) (|F_1| + |F_2|) on those rows; at a sliding
    # or open contact u follows from W r + q and is not bounded so simply: factor 10 for them
    # (measured |u_siconos - u| / bound: 1.1 loose deposit, 0.7 tight, 1.9 stack).
    bound_u = (1 + mu.max()) * (stored * scale + e2 * scale2)
    dU = np.linalg.norm(u2 - u)
    check(f"{name}: velocities agree", dU <= 10 * bound_u,
          f"|u_siconos - u| = {dU:.2e}, (1 + mu)(|F_1| + |F_2|) = {bound_u:.2e}, |q| = {np.linalg.norm(q):.2e}")
    dR = np.linalg.norm(r2 - r)
    if not hyperstatic:
        # One solution: the natural map is piecewise linear, and on the piece of the solution
        # its Jacobian has the rows of W at sticking contacts (inverse 1 / lambda_min(W)),
        # identity rows at open ones and rows of W combined with the cone at sliding ones. The
        # bound takes (1 + mu) / min(lambda_min(W), 1) for its inverse (SI units: W in 1/kg,
        # lambda_min 0.13 and 0.25 here), an estimate for the sliding rows, hence a factor 10
        # (measured |r_siconos - r| / bound: 0.29 loose deposit, 0.65 tight).
        bound_r = (1 + mu.max()) / min(lam[0], 1.0) * (stored * scale + e2 * scale2)
        check(f"{name}: reactions agree", dR <= 10 * bound_r,
              f"|r_siconos - r| = {dR:.2e} ({dR / np.linalg.norm(r):.1e} of |r|), bound {bound_r:.2e}")
    else:
        # W singular: reactions along its null space change no velocity, and the two solvers
        # stop at different ones (asserted equal they would fail at 4 % of |r|, measured); the
        # velocities are pinned by the residuals at the sticking contacts (above), and each
        # solution must satisfy the other code's law. Siconos' error of ours is (a); ours of Siconos' solution: the
        # same definition (doc/theory.md 4.5) evaluated by numpy on Siconos' r.
        null = np.linalg.norm(W @ (r2 - r)) / (lam[-1] * dR)
        print(f"       {name}: |r_siconos - r| = {dR:.2e} ({dR / np.linalg.norm(r):.1e} of |r|), "
              f"|W (r_siconos - r)| / (lambda_max |r_siconos - r|) = {null:.1e}: along null(W)")
        # Same tolerance as in (a): the two evaluations differ by the round-off of W r + q.
        ours = natural_map_error(W, q, r2, mu)
        check(f"{name}: our error of Siconos' solution = Siconos' error of it",
              abs(ours - e2) <= 1e-8 * e2 + 1e-14, f"numpy {ours:.10e}, Siconos {e2:.10e}")
        check(f"{name}: Siconos' solution satisfies our law to its tolerance", ours <= sic_tol,
              f"{ours:.2e}")


def natural_map_error(W, q, r, mu):
    """Our Siconos error (doc/theory.md 4.5) of r for 2 components per contact."""
    u = W @ r + q
    num = 0.0
    for j, muj in enumerate(mu):
        rn, rt = r[2 * j:2 * j + 2]
        un, ut = u[2 * j:2 * j + 2]
        n, t = rn - (un + muj * abs(ut)), rt - ut
        if muj * abs(t) <= -n:
            pn, pt = 0.0, 0.0
        elif abs(t) <= muj * n:
            pn, pt = n, t
        else:
            pn = (n + muj * abs(t)) / (1 + muj * muj)
            pt = np.copysign(muj * pn, t)
        num += (rn - pn) ** 2 + (rt - pt) ** 2
    return np.sqrt(num) / max(np.linalg.norm(q), np.linalg.norm(r), np.linalg.norm(u))


def main():
    exe, work, src = arguments()
    python, env = siconos_python()
    deposit = src / "tests" / "regression" / "decks" / "dem_small_deposit.dat"
    # A loose solution (tolerance 1e-3 of the LMGC90 norm: Siconos error 1.4e-4), so that
    # the error compared in (a) is far above round-off; Siconos solves to 1e-14.
    case(exe, python, env, with_solver(deposit, work, "deposit_loose.dat",
                                       ["fclib_step = 276", "tolerance = 1e-3"]), 276, work, 1e-14)
    # Both solvers tight: ours to 1e-12 on the Siconos error at every step, Siconos to 1e-14.
    case(exe, python, env, with_solver(deposit, work, "deposit_tight.dat",
                                       ["fclib_step = 300", "criterion = siconos", "tolerance = 1e-12",
                                        "max_sweeps = 100000"]), 300, work, 1e-14)
    # Hyperstatic: Siconos' fc2d NSGS stalls on this singular W at a residual of 4.5e-10
    # (its light criterion; 10^5 iterations), so it is asked for 1e-8 (134 iterations).
    stack = work / "stack.dat"
    stack.write_text(STACK)
    case(exe, python, env, stack, 3, work, 1e-8, hyperstatic=True)
    # The interface experiment at its 12th step (66 contacts under the rising pressure), the
    # rows condensed; ours to 1e-10 on the Siconos error at every step, Siconos to 1e-12
    # (32 538 iterations of its NSGS, measured: the condensed W is dense over the layer).
    text = (src / "input" / "interface_shear.dat").read_text()
    text = re.sub(r"^end\s*=.*$", "end = 4e-4", text, count=1, flags=re.M)
    text = text.replace("mesh = file ", f"mesh = file {src / 'input'}/")
    text = text.replace("law = 1 1 0.3 0 0 0.0125", "law = 1 1 0.3 0 0")
    text = text.replace("[solver]\n", "[solver]\nfclib_step = 12\ncriterion = siconos\ntolerance = 1e-10\n")
    assert "fclib_step" in text and "law = 1 1 0.3 0 0\n" in text
    interface = work / "interface.dat"
    interface.write_text(text)
    case(exe, python, env, interface, 12, work, 1e-12)
    return summary()


if __name__ == "__main__":
    sys.exit(main())
