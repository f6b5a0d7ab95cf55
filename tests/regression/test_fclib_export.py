#!/usr/bin/env python3
"""The Siconos error that multicor stores per step (/dem/solver/siconos_error) against an
independent computation with numpy on the local problem of that step read back from the
FCLIB export ([solver] fclib_step, doc/theory.md "Siconos error").

The code computes the error from velocities (u = H^T (v_free + M^-1 H r) + shift); here W is
the exported sparse matrix and u = W r + q. Two decks: a frictional deposit (2 components per
contact, no cohesion; also at a step where |q| is the largest term of the denominator) and the
cohesive hanging row (bonds: cohesion and moments, 3 components).
And two coupled runs, whose export is the contact problem with the Arlequin coupling rows
condensed (W = H^T (M^-1 - P^T D C D P) H, dense among the contacts on coupled disks): the
interface experiment (continuum, rolling resistance: 3 components) and the bonded hinged row
of the reference work (beam, bonds with cohesion). There u comes from the velocities of the
joint solve, which keeps the rows satisfied at every contact update: u = W r + q checks the
condensed W and the free term with the rows held against the solver's own motion.
Two errors per file: the run's (/dem/solver/siconos_error, also the attribute
/multicor@solver_siconos_error), where a contact without a moment length has 2 components, and
the exported problem's (/multicor@siconos_error), every contact with the file's spacedim
components: they differ when spacedim is 3 and such a contact rotates (its w_r and q_3 enter
|u| and |q|). A mixed case checks this: the bonded row hit by a disk at its impact (bonds
without moment length, row-wall contacts with rolling resistance, the disk on the row without).
A step without active contacts writes no file and warns (FCLIB's reader refuses a problem
without contacts).
Usage (ctest does this): test_fclib_export.py --exe multicor --work DIR --source REPO
"""
import re
import shutil
import subprocess
import sys
import time

import h5py
import numpy as np

from checks import arguments, check, multicor, summary


def with_export(deck, step, work, extra=(), replace=None, name=None):
    """Copy of deck with [solver] fclib_step = step (and extra [solver] lines); replace =
    (old line, new lines) edits one line of the deck."""
    lines = deck.read_text().splitlines()
    if replace:
        stripped = [ln.strip() for ln in lines]
        assert replace[0] in stripped, f"{deck}: no line {replace[0]!r}"
        k = stripped.index(replace[0])
        lines[k:k + 1] = replace[1]
    add = [f"fclib_step = {step}", *extra]
    if "[solver]" in [ln.strip() for ln in lines]:
        k = [ln.strip() for ln in lines].index("[solver]")
        lines[k + 1:k + 1] = add
    else:
        lines += ["[solver]", *add]
    out = work / (name or deck.name)
    out.write_text("\n".join(lines) + "\n")
    return out


def run(exe, deck, work):
    return multicor(exe, deck, work)[0]


def proj_coulomb(t, mu):
    """Euclidean projection of (t_n, t_t) on |r_t| <= mu r_n."""
    n, s = t
    if mu * abs(s) <= -n:
        return np.zeros(2)
    if abs(s) <= mu * n:
        return np.array([n, s])
    rn = (n + mu * abs(s)) / (1 + mu * mu)
    return np.array([rn, np.copysign(mu * rn, s)])


def proj_rolling(t, mu, e):
    """Euclidean projection of (n, t, m) on |r_t| <= mu r_n, |M| <= e r_n (KKT active sets)."""
    n, s, m = t
    T, A = abs(s), abs(m)
    if mu * T + e * A <= -n:
        return np.zeros(3)
    if T <= mu * n and A <= e * n:
        return np.array([n, s, m])
    n1 = (n + mu * T + e * A) / (1 + mu * mu + e * e)
    if T > mu * n1 and A > e * n1:
        return np.array([n1, np.copysign(mu * n1, s), np.copysign(e * n1, m)])
    n2 = (n + mu * T) / (1 + mu * mu)
    if A <= e * n2:
        return np.array([n2, np.copysign(mu * n2, s), m])
    n3 = (n + e * A) / (1 + e * e)
    return np.array([n3, s, np.copysign(e * n3, m)])


def siconos_error(W, q, r, mu, rolling, dim, exported=False):
    """||r - P_K(r - u_hat)|| / max(||q||, ||r||, ||u||), u = W r + q. As the run computes it
    (exported False): the components M of contacts without a moment length are not part of
    their problem. The exported problem's (exported True): every contact has its dim
    components; for e = 0 the cone holds M = 0, so the residual's third component is M, and
    w_r and q_3 count in |u| and |q|."""
    u = W @ r + q
    num = nq = nr = nu = 0.0
    for j, (muj, ej) in enumerate(zip(mu, rolling)):
        s = slice(dim * j, dim * j + (dim if exported else 3 if ej > 0 else 2))
        rj, uj, qj = r[s], u[s], q[s]
        if ej > 0:
            uh = np.array([uj[0] + muj * abs(uj[1]) + ej * abs(uj[2]), uj[1], uj[2]])
            p = proj_rolling(rj - uh, muj, ej)
        else:
            uh = np.array([uj[0] + muj * abs(uj[1]), uj[1]])
            p = proj_coulomb(rj[:2] - uh, muj)
            if len(rj) == 3:
                p = np.append(p, 0.0)
        num += np.sum((rj - p) ** 2)
        nq += qj @ qj
        nr += rj @ rj
        nu += uj @ uj
    return np.sqrt(num) / np.sqrt(max(nq, nr, nu)), u


def case(exe, deck, step, work, expect_dim, extra=(), replace=None, name=None, end=None, q_largest=False):
    """Export step `step` of `deck` (run to `end` if given) and check it (see the module); with
    q_largest, check too that |q| is the largest term of the error's denominator."""
    folder = deck.parent
    deck = with_export(deck, step, work, extra, replace, name)
    if end is not None:
        # a shorter run, with the mesh file of the deck's folder
        text = re.sub(r"^end\s*=.*$", f"end = {end}", deck.read_text(), count=1, flags=re.M)
        deck.write_text(text.replace("mesh = file ", f"mesh = file {folder}/"))
    results, proc = multicor(exe, deck, work)
    fclib = results.parent / f"{deck.stem}_fclib_{step}.h5"
    with h5py.File(results, "r") as f:
        stored = f["dem/solver/siconos_error"][step - 1]
    with h5py.File(fclib, "r") as f:
        dim = int(f["fclib_local/spacedim"][0])
        g = f["fclib_local/W"]
        m, n, nz = int(g["m"][0]), int(g["n"][0]), int(g["nz"][0])
        p, i, x = g["p"][...], g["i"][...], g["x"][...]
        q = f["fclib_local/vectors/q"][...]
        mu = f["fclib_local/vectors/mu"][...]
        r, u_code = f["solution/r"][...], f["solution/u"][...]
        rolling = f["multicor/rolling"][...]
        cohesion = f["multicor/cohesion"][...]
        attr = float(f["multicor"].attrs["siconos_error"])
        attr_run = float(f["multicor"].attrs["solver_siconos_error"])
    name = deck.stem
    check(f"{name}: layout", nz == -1 and m == n == dim * len(mu) and len(p) == n + 1
          and p[-1] == len(i) == len(x) and dim == expect_dim,
          f"spacedim {dim}, {len(mu)} contacts, nnz {len(x)}")
    # a file with a moment per contact is not FCLIB's 3D problem: the run says so, and only then
    noted = f"note: '{fclib}' has spacedim = 3: the third component of each contact is its moment" in proc.stdout
    check(f"{name}: the note on spacedim 3 when, and only when, it is 3", noted == (dim == 3),
          f"spacedim {dim}, output {proc.stdout.strip()[-300:]!r}")
    W = np.zeros((m, n))
    for col in range(n):
        W[i[p[col]:p[col + 1]], col] = x[p[col]:p[col + 1]]
    # W = H^T M^-1 H is symmetric positive semi-definite; 1e-12 relative: the entries of both
    # triangles are the same products in another order. Condensed, the share of the rows
    # -U^T C U keeps both (C symmetric, M^-1 - P^T D C D P the mobility of the disks with the
    # rows held); its entries are sums in another order too.
    sym = np.max(np.abs(W - W.T)) / np.max(np.abs(W))
    eig = np.linalg.eigvalsh(0.5 * (W + W.T)).min() / np.max(np.abs(W))
    check(f"{name}: W symmetric, positive semi-definite", sym < 1e-12 and eig > -1e-12,
          f"asymmetry {sym:.1e}, smallest eigenvalue / max|W| {eig:.1e}")
    err, u = siconos_error(W, q, r, mu, rolling, dim)
    if q_largest:
        nq, nr, nu = np.linalg.norm(q), np.linalg.norm(r), np.linalg.norm(u)
        check(f"{name}: |q| the largest of |q|, |r|, |u|", nq > 1.1 * max(nr, nu),
              f"|q| {nq:.3e}, |r| {nr:.3e}, |u| {nu:.3e}")
    # u from W r + q against the code's u (from the body velocities): the same sum in another
    # order; both are sums of terms of size |q|, so they agree to a few eps * |q|.
    du = np.max(np.abs(u - u_code)) / np.linalg.norm(q)
    check(f"{name}: W r + q = u of the code", du < 1e-12, f"max diff / |q| = {du:.1e}")
    # The two errors differ by the round-off of u (a few eps |q|, above) over the denominator
    # (at least |q|), taken up to the numerator's sqrt(m) components: a few tens of eps in
    # absolute terms (36 eps on row_impact, whose error is 1e-10), hence atol 100 eps; rtol
    # 1e-8 covers the relative rounding of larger errors. Any mistake in the formula changes
    # the error at O(1).
    atol = 100 * np.finfo(float).eps
    check(f"{name}: Siconos error, code against numpy", abs(err - stored) <= 1e-8 * err + atol,
          f"numpy {err:.10e}, stored {stored:.10e}, file attribute {attr:.10e}")
    check(f"{name}: the file's solver_siconos_error is the stored error", attr_run == stored, "")
    # the exported problem's error against the attribute: the same rounding of u as above
    err_file, _ = siconos_error(W, q, r, mu, rolling, dim, exported=True)
    check(f"{name}: Siconos error of the exported problem, attribute against numpy",
          abs(err_file - attr) <= 1e-8 * err_file + atol, f"numpy {err_file:.10e}, attribute {attr:.10e}")
    return cohesion, rolling, stored, attr


def main():
    exe, work, src = arguments()
    src_input = src / "input"
    decks = src / "tests" / "regression" / "decks"
    # a loose tolerance, so that the error compared is well above round-off
    _, _, stored, attr = case(exe, decks / "dem_small_deposit.dat", 276, work, 2, ("tolerance = 1e-3",))
    # 2 components: the two problems are the same (up to the rounding of the two computations
    # of u, the same bound as above)
    check("deposit: file and run errors agree with 2 components", abs(stored - attr) <= 1e-8 * stored + 1e-14,
          f"run {stored:.10e}, file {attr:.10e}")
    # a step where the free term is the largest of |q|, |r|, |u| (the other cases have |r| or |u|
    # larger): the denominator max(|q|, |r|, |u|) is checked with |q| in it. |q| is 1.2 times the
    # next (measured |q| 0.289, |u| 0.237, |r| 0.074); 1.1 keeps the case meaningful against round-off.
    case(exe, decks / "dem_small_deposit.dat", 250, work, 2, ("tolerance = 1e-3",), name="deposit_free_term.dat",
         q_largest=True)
    # rolling resistance (e_r = 1 mm) on the pair 1-1, the one of every contact of that step
    _, rolling, stored, attr = case(exe, decks / "dem_small_deposit.dat", 291, work, 3, ("tolerance = 1e-3",),
                                    ("law = 1 1 0.4 0.2 0", ["law = 1 1 0.4 0.2 0 0.001"]), "deposit_rolling.dat")
    # every contact with a moment length: the file's problem is the run's
    check("deposit_rolling: file and run errors agree", abs(stored - attr) <= 1e-8 * stored + 1e-14,
          f"run {stored:.10e}, file {attr:.10e}")
    check("deposit_rolling: contacts with a moment", np.all(rolling == 0.001), f"{len(rolling)} contacts")
    # bonds (cohesion) that carry moments (e_b = R/2)
    cohesion, rolling, _, _ = case(exe, src / "input" / "cohesive_row.dat", 100, work, 3, (),
                             ("law      = 1          1          0.3  0            2.0e4",
                              ["law = 1 1 0.3 0 2.0e4", "bond = 1 1 0.3 0.0025"]), "bonded_row.dat")
    check("bonded_row: bonds exported with cohesion and moment length",
          np.all(cohesion > 0) and np.all(rolling > 0), f"{len(cohesion)} contacts")
    # Coupled runs (the rows condensed). The interface experiment at its 12th step (the layer
    # under the rising pressure, every disk in contact) and the hinged row of the reference
    # work, bonded and glued to the beam at both ends, solved by plain sweeps to a loose
    # tolerance so that the error compared is well above round-off.
    _, rolling, _, _ = case(exe, src_input / "interface_shear.dat", 12, work, 3, name="interface.dat", end="4e-4")
    check("interface: contacts with a moment (rolling resistance)", np.all(rolling > 0), f"{len(rolling)} contacts")
    cohesion, _, _, _ = case(exe, src_input / "bending_hinged_row.dat", 12, work, 2,
                       ("method = nlgs", "tolerance = 1e-4"), name="hinged_row.dat", end="2e-4",
                       replace=("tolerance  = 1.0e-8", []))
    check("hinged_row: bonds exported with their cohesion", np.all(cohesion > 0), f"{len(cohesion)} contacts")
    # Mixed moment lengths: the bonded row hit by a disk at the impact (step 187), plain sweeps.
    # The contact disk-row has no moment length and rotates (w_r = -46.7 rad/s): in the file's
    # problem it counts in |u|, which is then the largest term of the denominator, so that the
    # file's error is far below the run's (measured 2.8e-12 against 9.8e-11); a factor 10 keeps
    # the case meaningful, and any drop of the third components from the file's error fails it.
    cohesion, rolling, stored, attr = case(exe, decks / "dem_bonded_row_impact.dat", 187, work, 3,
                                           ("method = nlgs",), name="row_impact.dat")
    check("row_impact: contacts with and without a moment length, bonds",
          np.any(rolling > 0) and np.any(rolling == 0) and np.any(cohesion > 0), f"rolling {rolling}")
    check("row_impact: the file's error is below the run's (the rotation of a contact without moment)",
          attr < 0.1 * stored, f"run {stored:.4e}, file {attr:.4e}")
    # The criterion chosen by the deck stops the sweeps: with criterion = siconos every
    # converged step has a stored Siconos error at most the tolerance.
    deck = with_export(src / "tests" / "regression" / "decks" / "dem_small_deposit.dat", 250, work,
                       ("criterion = siconos", "tolerance = 1e-6", "max_sweeps = 100000"))
    with h5py.File(run(exe, deck, work), "r") as f:
        e = f["dem/solver/siconos_error"][...]
        conv = f["dem/solver/converged"][...]
        crit = f["dem/solver"].attrs["criterion"]
    crit = crit.decode() if isinstance(crit, bytes) else str(crit)
    check("criterion = siconos stops at the tolerance", crit == "siconos" and conv.all()
          and e.max() <= 1e-6, f"{len(e)} steps, max error {e.max():.2e}")
    # An export after the last step (300 steps: end 0.06 s, step 2e-4 s) writes nothing and
    # says so, even with --quiet; it used to pass unnoticed.
    deck = with_export(decks / "dem_small_deposit.dat", 301, work, name="export_after_end.dat")
    out = work / deck.stem
    proc = subprocess.run([str(exe), str(deck), "--output", str(out), "--quiet"],
                          capture_output=True, text=True)
    written = sorted(p.name for p in out.glob("*_fclib_*.h5")) if out.is_dir() else []
    check("fclib_step after the end: warned, nothing written", proc.returncode == 0 and not written
          and "warning: [solver] fclib_step = 301 is after the last step of the run (300)" in proc.stdout,
          f"exit {proc.returncode}, files {written}")
    # A step without active contacts (a disk falling alone): no file, a warning.
    deck = work / "no_contacts.dat"
    deck.write_text("[run]\nanalysis = dynamic\n[particles]\nmaterial = 1 2000\ndisk = 0 0.5 0.01 1\n"
                    "gravity = 0 -9.81\n[solver]\nfclib_step = 2\n[time]\nstep = 1e-3\nend = 3e-3\n")
    out = work / deck.stem
    proc = subprocess.run([str(exe), str(deck), "--output", str(out), "--quiet"], capture_output=True, text=True)
    written = sorted(p.name for p in out.glob("*_fclib_*")) if out.is_dir() else []
    check("fclib_step at a step without contacts: warned, nothing written", proc.returncode == 0 and not written
          and "warning: [solver] fclib_step = 2: the step has no active contact" in proc.stdout,
          f"exit {proc.returncode}, files {written}, output {proc.stdout.strip()!r}")
    # --check warns of an export after the end, as the run does
    deck = with_export(decks / "dem_small_deposit.dat", 301, work, name="check_after_end.dat")
    proc = subprocess.run([str(exe), "--check", str(deck)], capture_output=True, text=True)
    check("--check: fclib_step after the end warned", proc.returncode == 0
          and "warning: [solver] fclib_step = 301 is after the last step of the run (300)" in proc.stdout,
          f"exit {proc.returncode}, output {proc.stdout.strip()!r}")
    failed_run_keeps_export(exe, work)
    killed_run_export(exe, decks, work)
    return summary()


def killed_run_export(exe, decks, work):
    """A run killed by SIGKILL after its export of step 81 (the deposit's first contacts are at
    step 80; a step without contacts is not exported) and a checkpoint at step 100 leaves the
    export as '.partial' (renamed only when a run ends); the restart takes it over and gives it
    its name when it ends. It stayed '.partial' for good."""
    deck = with_export(decks / "dem_small_deposit.dat", 81, work, ("max_sweeps = 1000",), name="killed.dat")
    text = deck.read_text().replace("end = 0.06", "end = 1000").replace("[output]", "[output]\ncheckpoint_interval = 50")
    deck.write_text(text)
    out = work / "killed"
    # a fresh folder: a checkpoint left by an earlier run of this script would be read as this
    # run's before it reaches its export
    shutil.rmtree(out, ignore_errors=True)
    proc = subprocess.Popen([str(exe), str(deck), "--output", str(out), "--quiet"], stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    step, deadline = 0, time.monotonic() + 120
    while step < 100 and time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.1)
        try:
            with h5py.File(out / "checkpoint.h5", "r") as f:
                step = int(f["loop"].attrs["step"])
        except (OSError, KeyError):
            pass
    proc.kill()
    proc.wait()
    # the run may have written a later checkpoint between the last poll and the kill: the
    # restart continues from the one it left
    try:
        with h5py.File(out / "checkpoint.h5", "r") as f:
            step = int(f["loop"].attrs["step"])
    except (OSError, KeyError):
        pass
    left = sorted(p.name for p in out.iterdir())
    again = subprocess.run([str(exe), str(deck), "--output", str(out), "--quiet", "--restart",
                            str(out / "checkpoint.h5"), "--end", f"{(step + 20) * 2e-4!r}"],
                           capture_output=True, text=True)
    after = sorted(p.name for p in out.iterdir())
    check("killed after its export: the restart gives the export its name",
          step >= 100 and "killed_fclib_81.h5.partial" in left and again.returncode == 0
          and "killed_fclib_81.h5" in after and "killed_fclib_81.h5.partial" not in after,
          f"checkpoint at step {step}; before {left}; exit {again.returncode}; after {after}")


def failed_run_keeps_export(exe, work):
    """A run that fails after its export leaves the folder as it found it (doc/output.md,
    "What a run replaces"): an earlier run's export unchanged, none of its own; into a new
    folder, none of its export either. Its records alone are kept, as 'export.h5.failed' (its
    time loop failed in a step after storing outputs: "A time loop that fails in a step"). The failure: a force of 1e30 N switched on at 5 ms throws a disk
    out of the box, which the run's guard stops (exit 1); a second disk moving at the start
    makes its step-1 problem differ from the earlier run's."""
    text = """[run]
analysis = dynamic
[particles]
material = 1 2500
row = 5 0 0.01 0.01 1
disk = 0.2 0.2 0.01 1
gravity = 0 -9.81
initial_velocity = 1 x 0.5
{force}
[walls]
wall = -0.1 0 0.3 0
[contacts]
law = 1 1 0.3 0 0
[functions]
function = 1 step 5e-3
[time]
step = 1e-3
end = 1e-2
[solver]
fclib_step = 1
"""
    good, bad = work / "export_good", work / "export_bad"
    good.mkdir(exist_ok=True)
    bad.mkdir(exist_ok=True)
    (good / "export.dat").write_text(text.format(force=""))
    (bad / "export.dat").write_text(text.format(force="initial_velocity = 2 x 0.2\nforce = 6 y -1e30 1"))
    out = work / "export_folder"
    fresh = work / "export_fresh"
    for folder in (out, fresh):
        shutil.rmtree(folder, ignore_errors=True)
    first = subprocess.run([str(exe), "-q", "-o", str(out), str(good / "export.dat")], capture_output=True, text=True)
    before = {p.name: p.read_bytes() for p in out.iterdir()} if out.is_dir() else {}
    second = subprocess.run([str(exe), "-q", "-o", str(out), str(bad / "export.dat")], capture_output=True, text=True)
    after = {p.name: p.read_bytes() for p in out.iterdir() if p.name != "export.h5.failed"}
    check("a failed run leaves the earlier export as it was, its records apart",
          first.returncode == 0 and second.returncode == 1 and "export_fclib_1.h5" in before and after == before
          and (out / "export.h5.failed").exists(),
          f"exits {first.returncode}, {second.returncode}; files before {sorted(before)}, after {sorted(after)}")
    third = subprocess.run([str(exe), "-q", "-o", str(fresh), str(bad / "export.dat")], capture_output=True, text=True)
    left = sorted(p.name for p in fresh.iterdir()) if fresh.exists() else []
    check("a failed run into a new folder leaves its records alone, no export", third.returncode == 1
          and left == ["export.h5.failed"], f"exit {third.returncode}, left {left}")


if __name__ == "__main__":
    sys.exit(main())
