#!/usr/bin/python3
"""The deposit of issue 8 in Siconos 4.4, on the layout written by `bench_dem --siconos N --csv`.

Run with the system Python, which has Debian's python3-siconos (not the project's .venv):

    build-release/bench/bench_dem --siconos 200 --csv dep200.csv
    OMP_NUM_THREADS=1 /usr/bin/python3 bench/siconos_deposit.py dep200.csv

The model is Siconos' own 2D mechanics (siconos.mechanics.collision): one `Disk` per CSV row
(Lagrangian, q = (x, y, theta), mass m, inertia m r^2 / 2, checked against the CSV), gravity as
a constant external force, the floor y = 0 and the side walls x = 0 and x = width as the plane
rows of the native `SpaceFilter` (which creates `DiskDiskR` and `DiskPlanR` interactions with a
`NewtonImpactFrictionNSL`, e = 0, mu = 0.3), `MoreauJeanOSI` with theta = 1/2, h = 2 ms, a
`TimeStepping` with one Newton iteration (one frictional-contact solve per step, as in MULTICOR)
and the 2D friction-contact problem (`FrictionContact(2)`, sparse block storage) solved by
`SICONOS_FRICTION_2D_NSGS` with tolerance 1e-4 and at most 10 000 iterations, warm-started from
the previous step (`setKeepLambdaAndYState(True)`).

Timers (time.perf_counter around Siconos calls; nothing is written to disk):
- step: `computeOneStep()` + `nextStep()` (detection, integration, assembly, solve, update);
- osnsp: the one-step nonsmooth problem (`FrictionContact.compute`: W and q assembly, solve);
- solve: the numerics call alone (`FrictionContact.solve`: NSGS and its final error).
The per-step statistics are read from the solver options between the calls (untimed). With
--errors, the error of the returned (r, u) is also computed with numpy after each solve (untimed)
divided by max(|q|, |r|, |u|) (Siconos 4.4's normalisation, the same as MULTICOR's; it must
equal the residual NSGS returns) and by |q| alone (doc/performance.md, "Siconos 4.4 on the
same layout").
"""
import argparse
import math
import os
import re
import statistics
import sys
import time

# one core, like bench_dem with OMP_NUM_THREADS=1 (numpy's BLAS would otherwise start threads)
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402 (after the thread settings)

try:
    import siconos.kernel as sk
    import siconos.numerics as sn
    from siconos.mechanics.collision.bodies import Disk
    from siconos.mechanics.collision.native import SpaceFilter
except ImportError as exc:  # the caller (a test) may want to skip, not crash
    print(f"siconos_deposit.py: cannot import Siconos ({exc}); run with /usr/bin/python3 "
          "after `apt-get install python3-siconos`", file=sys.stderr)
    sys.exit(3)

GRAVITY = 9.81
DBL_EPS = 2.220446049250313e-16  # fc2d_compute_error divides only by a norm above DBL_EPSILON
DENSE_CHECK = 2000  # largest problem (rows) whose W is made dense to check u = W r + q


def read_layout(path):
    """Disks (x, y, radius, mass, inertia) and the box width from a bench_dem CSV."""
    try:
        with open(path, encoding="ascii") as f:
            head = [f.readline() for _ in range(3)]
    except (OSError, UnicodeDecodeError) as exc:
        sys.exit(f"siconos_deposit.py: {path}: {exc}")
    match = re.search(r"x = 0 and x =\s*([0-9.Ee+-]+) m", head[0])
    if not head[0].startswith("#") or not match or not head[2].startswith("x,y,radius"):
        sys.exit(f"siconos_deposit.py: {path}: not a layout written by bench_dem --csv "
                 "(line 1 must give the box, line 3 the column names)")
    try:
        disks = np.loadtxt(path, delimiter=",", skiprows=3, ndmin=2)
    except ValueError as exc:
        sys.exit(f"siconos_deposit.py: {path}: {exc}")
    if disks.shape[0] == 0 or disks.shape[1] != 5 or not np.all(np.isfinite(disks)) \
            or np.any(disks[:, 2:] <= 0):
        sys.exit(f"siconos_deposit.py: {path}: expected disks in 5 finite columns with positive "
                 "radius, mass and inertia")
    return disks, float(match.group(1))


class TimedFrictionContact(sk.FrictionContact):
    """Siconos' FrictionContact with its compute() written out as in the kernel
    (preCompute, updateMu, solve, postCompute), timed, and the per-solve figures kept."""

    def __init__(self, options, want_errors):
        super().__init__(2, options)
        self.options = options
        self.want_errors = want_errors
        self.reset_step()

    def reset_step(self):
        self.t_osnsp = 0.0
        self.t_solve = 0.0
        self.calls = 0
        self.iters = 0
        self.residual = 0.0
        self.info = 0
        self.contacts = 0
        self.errors = None
        self.t_errors = 0.0
        self.cpu_errors = 0.0

    def compute(self, time_):
        t0 = time.perf_counter()
        if not self.preCompute(time_):
            self.t_osnsp += time.perf_counter() - t0
            return 0
        self.updateMu()
        info = 0
        if self.getSizeOutput() != 0:
            t1 = time.perf_counter()
            info = self.solve()
            self.t_solve += time.perf_counter() - t1
            self.postCompute()
        self.t_osnsp += time.perf_counter() - t0
        if self.getSizeOutput() != 0:
            self.calls += 1
            self.iters += self.options.iparam[sn.SICONOS_IPARAM_ITER_DONE]
            self.residual = self.options.dparam[sn.SICONOS_DPARAM_RESIDU]
            self.info = info
            self.contacts = self.getSizeOutput() // 2
            if self.want_errors:
                t2, c2 = time.perf_counter(), time.process_time()
                self.errors = problem_errors(self.frictionContactProblemPtr(),
                                             np.array(self.z()), np.array(self.w()))
                self.t_errors += time.perf_counter() - t2
                self.cpu_errors += time.process_time() - c2
        return info


def problem_errors(problem, r, u):
    """Natural-map residual of (r, u) for the 2D Coulomb cone (rho = 1, as in Siconos'
    fc2d_unitary_compute_and_add_error), divided by max(|q|, |r|, |u|) (fc2d_compute_error in
    4.4, called by fc2d_nsgs with |q|; the same as MULTICOR's Siconos error, doc/theory.md) and,
    for comparison, by |q| alone (the normalisation of older Siconos releases). u is the
    solver's velocity, which the final full error evaluation of NSGS (the default,
    LIGHT_WITH_FULL_FINAL) overwrites with W r + q; on problems of at most DENSE_CHECK rows
    that is checked with W made dense."""
    q = np.array(problem.q, dtype=float)
    mu = np.array(problem.mu, dtype=float)
    u_gap = math.nan
    if len(q) <= DENSE_CHECK:
        u_gap = float(np.max(np.abs(sn.SBM_to_dense(problem.M.matrix1) @ r + q - u)))
    rn, rt, un, ut = r[0::2], r[1::2], u[0::2], u[1::2]
    # r - P_K(r - (u_n + mu |u_t|, u_t)), K = {|t| <= mu n}
    an = rn - (un + mu*np.abs(ut))
    at = rt - ut
    pn, pt = an.copy(), at.copy()
    polar = mu*np.abs(at) <= -an
    outside = ~polar & (np.abs(at) > mu*an)
    pn[polar] = 0.0
    pt[polar] = 0.0
    pn[outside] = (mu[outside]*np.abs(at[outside]) + an[outside])/(mu[outside]**2 + 1.0)
    pt[outside] = mu[outside]*pn[outside]*np.sign(at[outside])
    res = math.sqrt(float(np.sum((rn - pn)**2 + (rt - pt)**2)))
    nq, nr, nu = (float(np.linalg.norm(v)) for v in (q, r, u))
    scale = max(nq, nr, nu)
    return {"max": res/scale if scale > DBL_EPS else res,
            "q": res/nq if nq > DBL_EPS else res,
            "u_gap": u_gap}


def overlaps(x, y, r, width):
    """Overlaps (negative gaps) of the final state: disk-disk pairs and disk-wall contacts
    (count, mean and largest overlap in metres). Pairwise in blocks of rows (numpy only)."""
    depth = []
    for start in range(0, len(x), 500):
        sl = slice(start, start + 500)
        gap = np.hypot(x[sl, None] - x[None, :], y[sl, None] - y[None, :]) - (r[sl, None] + r[None, :])
        rows, cols = np.nonzero(gap < 0.0)
        keep = cols > rows + start
        depth.extend(-gap[rows[keep], cols[keep]])
    walls = np.concatenate([y - r, x - r, width - x - r])
    wall_depth = -walls[walls < 0.0]
    return [(len(d), float(np.mean(d)) if len(d) else 0.0, float(np.max(d)) if len(d) else 0.0)
            for d in (np.array(depth), wall_depth)]


def build(disks, width, args):
    """Siconos model, simulation and solver options for the layout, with lengths in units of
    1/args.unit m (kilograms and seconds unchanged: the same problem, scaled)."""
    nsds = sk.NonSmoothDynamicalSystem(0.0, args.steps*args.h)
    bodies = []
    L = args.unit
    for x, y, r, m, inertia in disks:
        body = Disk(float(r*L), float(m), [float(x*L), float(y*L), 0.0], [0.0, 0.0, 0.0])
        inertia = inertia*L*L
        if abs(np.array(body.mass())[2, 2] - inertia) > 1e-9*inertia:
            sys.exit(f"siconos_deposit.py: Siconos' Disk inertia {np.array(body.mass())[2, 2]} "
                     f"differs from the CSV's {inertia} (radius {r})")
        body.setFExtPtr(np.array([0.0, -m*GRAVITY*L, 0.0]))
        nsds.insertDynamicalSystem(body)
        bodies.append(body)
    # plane rows (A, B, C, x_centre, y_centre, width 0 = infinite): A x + B y + C = 0
    planes = np.array([[0.0, 1.0, 0.0, 0.0, 0.0, 0.0],
                       [1.0, 0.0, 0.0, 0.0, 0.0, 0.0],
                       [1.0, 0.0, -width*L, 0.0, 0.0, 0.0]])
    # bbox factor 3, cell size args.cell (SpaceFilter takes unsigned integers, in length units)
    manager = SpaceFilter(3, args.cell, planes)
    law = sk.NewtonImpactFrictionNSL(args.e, 0.0, args.mu, 2)
    manager.insertNonSmoothLaw(law, 0, 0)
    osi = sk.MoreauJeanOSI(args.theta)
    if args.gamma is not None:
        # activation of a contact when y + gamma h y' <= 0 (Siconos' default gamma 1/2)
        osi.setGamma(args.gamma)
        osi.setUseGamma(True)
    options = sk.solver_options_create(sn.SICONOS_FRICTION_2D_NSGS)
    options.iparam[sn.SICONOS_IPARAM_MAX_ITER] = args.max_iter
    options.dparam[sn.SICONOS_DPARAM_TOL] = args.tol
    osnspb = TimedFrictionContact(options, args.errors)
    osnspb.setMStorageType(sn.NM_SPARSE_BLOCK)
    osnspb.setKeepLambdaAndYState(True)
    osnspb.setNumericsVerboseMode(False)
    simulation = sk.TimeStepping(nsds, sk.TimeDiscretisation(0.0, args.h), osi, osnspb)
    simulation.insertInteractionManager(manager)
    simulation.setNewtonOptions(sk.SICONOS_TS_NONLINEAR)
    simulation.setNewtonMaxIteration(args.newton_iter)
    simulation.setNewtonTolerance(1e-10)
    return nsds, simulation, osnspb, bodies, manager


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("csv", help="layout from bench_dem --siconos N --csv FILE")
    ap.add_argument("--steps", type=int, default=500, help="time steps (default 500 = 1 s)")
    ap.add_argument("--h", type=float, default=2e-3, help="time step [s] (default 2e-3)")
    ap.add_argument("--theta", type=float, default=0.5, help="Moreau-Jean theta (default 1/2)")
    ap.add_argument("--gamma", type=float, default=None,
                    help="activation of a contact when its gap plus gamma h times its velocity "
                         "is <= 0 (default: Siconos' 1/2)")
    ap.add_argument("--mu", type=float, default=0.3, help="friction coefficient (default 0.3)")
    ap.add_argument("--e", type=float, default=0.0, help="Newton restitution (default 0)")
    ap.add_argument("--tol", type=float, default=1e-4, help="NSGS tolerance (default 1e-4)")
    ap.add_argument("--max-iter", type=int, default=10000, help="NSGS cap (default 10000)")
    ap.add_argument("--newton-iter", type=int, default=1,
                    help="Newton iterations per step, each one NSGS solve (default 1)")
    ap.add_argument("--cell", type=int, default=1,
                    help="SpaceFilter cell size, an integer in length units (default 1)")
    ap.add_argument("--unit", type=int, default=1,
                    help="length units per metre inside Siconos (default 1: metres; 100: "
                         "centimetres, so that a cell of 1 is 1 cm; results are printed in metres)")
    ap.add_argument("--errors", action="store_true",
                    help="also compute both error normalisations per step (untimed)")
    ap.add_argument("--verbose", action="store_true", help="one line per step")
    ap.add_argument("--final", metavar="FILE",
                    help="write the final state as CSV: x, y, theta, vx, vy, omega per disk")
    ap.add_argument("--trajectory", metavar="FILE",
                    help="write every step's positions (steps, disks, 3: x, y, theta) in metres and "
                         "whether its NSGS converged (steps,) as a numpy .npz (arrays q, converged)")
    args = ap.parse_args()
    if args.steps < 1 or args.h <= 0 or args.max_iter < 1 or args.newton_iter < 1 or args.cell < 1 \
            or args.unit < 1:
        ap.error("--steps, --max-iter, --newton-iter, --cell and --unit must be >= 1, --h > 0")

    disks, width = read_layout(args.csv)
    n = len(disks)
    t_build = time.perf_counter()
    nsds, simulation, osnspb, bodies, _ = build(disks, width, args)
    t_build = time.perf_counter() - t_build
    print(f"# Siconos 4.4 deposit: N = {n} from {args.csv}, box width {width:.4f} m, mu {args.mu}, "
          f"e {args.e}, theta {args.theta}, h {args.h*1e3:g} ms, {args.steps} steps")
    print(f"# FrictionContact(2) + SICONOS_FRICTION_2D_NSGS, tolerance {args.tol:.2e}, cap "
          f"{args.max_iter}, {args.newton_iter} Newton iteration(s) per step; native SpaceFilter "
          f"(cell {args.cell} length units of 1/{args.unit} m); model built in {t_build:.3f} s")
    if args.verbose:
        print("# step  contacts  interactions  iters  info  residual  step[ms]  solve[ms]  top[m]"
              + ("  err/max(|q|,|r|,|u|)  err/|q|" if args.errors else ""))

    t_step, t_osnsp, t_solve, iters, residuals = [], [], [], [], []
    n_conv = n_contacts = n_solves = 0
    err_s, err_m, err_d, u_gap = [], [], [], []
    wall_errors = cpu_errors = 0.0
    traj_q, traj_conv = [], []
    back = np.array([1.0/args.unit, 1.0/args.unit, 1.0])
    wall0, cpu0 = time.perf_counter(), time.process_time()
    for k in range(1, args.steps + 1):
        osnspb.reset_step()
        t0 = time.perf_counter()
        simulation.computeOneStep()
        simulation.nextStep()
        # --errors runs inside computeOneStep (after the solve): not part of the step
        t_step.append(time.perf_counter() - t0 - osnspb.t_errors)
        wall_errors += osnspb.t_errors
        cpu_errors += osnspb.cpu_errors
        t_osnsp.append(osnspb.t_osnsp)
        t_solve.append(osnspb.t_solve)
        iters.append(osnspb.iters)
        n_contacts += osnspb.contacts
        n_solves += osnspb.calls
        # a step without active contacts has no problem to solve: converged, 0 iterations
        if osnspb.calls == 0 or osnspb.info == 0:
            n_conv += 1
        if args.trajectory:
            traj_q.append(np.array([np.array(b.q()) for b in bodies])*back)
            traj_conv.append(osnspb.calls == 0 or osnspb.info == 0)
        if osnspb.calls:
            residuals.append(osnspb.residual)
        if osnspb.errors:
            err_m.append(osnspb.errors["max"])
            err_s.append(osnspb.errors["q"])
            err_d.append(abs(osnspb.errors["max"] - osnspb.residual))
            u_gap.append(osnspb.errors["u_gap"])
        if args.verbose:
            top = max(float(b.q()[1]) + b.getRadius() for b in bodies)/args.unit
            line = (f"{k:6d} {osnspb.contacts:9d} {nsds.getNumberOfInteractions():13d} "
                    f"{osnspb.iters:6d} {osnspb.info:5d} {osnspb.residual:9.2e} "
                    f"{t_step[-1]*1e3:9.3f} {t_solve[-1]*1e3:10.3f} {top:8.5f}")
            if osnspb.errors:
                line += f"  {osnspb.errors['max']:20.3e}  {osnspb.errors['q']:8.3e}"
            print(line, flush=True)
    wall = time.perf_counter() - wall0 - wall_errors
    cpu = time.process_time() - cpu0 - cpu_errors

    # back to metres (the angles and angular velocities are unchanged by the scaling)
    if args.trajectory:
        np.savez(args.trajectory, q=np.array(traj_q), converged=np.array(traj_conv))
    q = np.array([np.array(b.q()) for b in bodies])*back
    v = np.array([np.array(b.velocity()) for b in bodies])*back
    if args.final:
        np.savetxt(args.final, np.hstack([q, v]), delimiter=",", fmt="%.17e",
                   header="x,y,theta,vx,vy,omega", comments="")
    mass = disks[:, 3]
    top = float(np.max(q[:, 1] + disks[:, 2]))
    y_com = float(np.sum(mass*q[:, 1])/np.sum(mass))
    v_mean = float(np.mean(np.hypot(v[:, 0], v[:, 1])))
    steps = args.steps
    print("#      N  steps  step[ms](mean,median,best)  osnsp[ms](mean)  solve[ms](mean)  "
          "iters(mean,max)  conv  residual(mean,max)  top[m]  y_centre_of_mass[m]  v_mean[m/s]")
    print(f"{n:8d} {steps:6d} {1e3*sum(t_step)/steps:9.3f} {1e3*statistics.median(t_step):8.3f} "
          f"{1e3*min(t_step):8.3f} {1e3*sum(t_osnsp)/steps:9.3f} {1e3*sum(t_solve)/steps:9.3f} "
          f"{sum(iters)/steps:9.1f} {max(iters):6d} {n_conv/steps:6.3f} "
          f"{(sum(residuals)/len(residuals) if residuals else 0.0):9.2e} "
          f"{(max(residuals) if residuals else 0.0):9.2e} {top:9.5f} {y_com:11.6f} {v_mean:11.3e}")
    print(f"# {steps} steps: wall {wall:.2f} s, CPU {cpu:.2f} s (without --errors' own "
          f"{wall_errors:.2f} s); active contacts per step "
          f"{n_contacts/steps:.1f} (mean); NSGS solves {n_solves} (at most one per step and Newton "
          f"iteration); interactions at the end {nsds.getNumberOfInteractions()}")
    (n_dd, mean_dd, max_dd), (n_dw, mean_dw, max_dw) = overlaps(q[:, 0], q[:, 1], disks[:, 2], width)
    print(f"# overlaps at the end: {n_dd} disk-disk pairs (mean {mean_dd*1e3:.3f} mm, max "
          f"{max_dd*1e3:.3f} mm), {n_dw} disk-wall (mean {mean_dw*1e3:.3f} mm, max {max_dw*1e3:.3f} mm)")
    if err_s:
        gap = [g for g in u_gap if not math.isnan(g)]
        print(f"# error of the returned (r, u), {len(err_s)} steps with contacts: natural map / "
              f"max(|q|,|r|,|u|) (Siconos 4.4 = MULTICOR) mean {np.mean(err_m):.2e} max "
              f"{np.max(err_m):.2e} (differs from the solver's residual by at most "
              f"{np.max(err_d):.1e}); / |q| alone mean {np.mean(err_s):.2e} max {np.max(err_s):.2e}"
              + (f"; max |W r + q - u| {max(gap):.1e}" if gap else ""))

if __name__ == "__main__":
    main()
