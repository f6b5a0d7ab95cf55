#!/usr/bin/env python3
"""Figures of the reference experiments (doc/experiments.md), PNG and PDF, and a summary of
the measured figures.

    plot_experiments.py [--results DIR] [--out DIR] [--time T] [--track ID ...]

Reads DIR/<case>/<case>.h5 for the cases bending_case1, bending_case2 and bending_stack
(the layout `./run.sh --experiments` writes; default DIR results/experiments) and writes
into --out (default DIR):
- <case>_profiles: vertical displacement and velocity along x at t = T (default 5e-3 s),
  beam nodes and disks on the same axes, overlap shaded (one per case);
- <case>_configuration: deformed beam, disks as circles, overlap shaded, at t = T;
- history_case1_case2_disk<ID>: displacement and velocity history of the tracked disk
  (the same disk at the same abscissa) in case 1 and case 2 (default disks 7, 11 and 17);
- stack_vs_row: displacement and velocity profiles of the stack against the single row;
- experiments_summary.txt: constraint residuals, energy balance, wall times, rigid fits.
With DIR/interface (postproc/run_interface_experiment.py; skipped when absent), the
interface experiment (multicor_post.interface):
- interface_friction_mu, interface_friction_cohesion, interface_friction_width: apparent
  friction (top band T / N) against slip, one curve per local friction, per cohesion and per
  band width, with the curve of disks sliding over disks for each mu;
- interface_configuration: deformed mesh, disks and contact forces at the end of the base run;
- interface_stress_xy, interface_stress_vm: sigma_xy and von Mises in the blocks at the end;
- interface_summary.txt: peak and residual apparent friction, slip, energy balances per run.
Prints the paths written. Exit code 1 with a message when a results file is missing.
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from multicor_post import coupled, interface  # noqa: E402
from multicor_post.results import (ResultsError, finite_float, make_out_dir,  # noqa: E402
                                   save_figure)

CASES = ("bending_case1", "bending_case2", "bending_stack")
LABELS = {"bending_case1": "case 1 (overlap 6 layers)",
          "bending_case2": "case 2 (overlap 3 layers)",
          "bending_stack": "stack (3 layers of disks)"}


def save(fig, out, name, written):
    """Save a figure as PNG and PDF."""
    for ext in ("png", "pdf"):
        path = os.path.join(out, f"{name}.{ext}")
        save_figure(fig, path, 150)
        written.append(path)


def summary_lines(runs, time):
    """Measured figures of each run (text)."""
    lines = [f"{'case':<15} {'steps':>6} {'max|q-Cu| [m]':>14} {'max|x-Cu| [m]':>14} "
             f"{'max|bal| [J]':>12} {'ext. work [J]':>13} {'wall [s]':>9}"]
    def of(series, name, value):
        """value(series[name]), NaN when the file lacks the dataset."""
        return value(series[name]) if name in series else np.nan

    for name, r in runs.items():
        s, e = r.coupling.steps, r.coupling.energy
        wall = float(r.summary.get("wall_seconds", np.nan))
        n_steps = next((v.size for v in s.values()), 0)
        lines.append(f"{name:<15} {n_steps:>6d} {of(s, 'position_residual', np.max):>14.3e} "
                     f"{of(s, 'coordinate_residual', np.max):>14.3e} "
                     f"{of(e, 'balance', lambda b: np.abs(b).max()):>12.3e} "
                     f"{of(e, 'external_work', lambda w: w[-1]):>13.4e} {wall:>9.2f}")
    lines.append("")
    lines.append(f"profiles at the stored output nearest t = {time:g} s (vertical displacement; rigid fit "
                 "= straight line through the disks beyond the overlap):")
    for name, r in runs.items():
        k = r.nearest_index(time)
        p = coupled.profile(r, k)
        if abs(float(r.time[k]) - time) > 1e-9 * max(abs(time), float(np.abs(r.time).max()), 1e-300):
            lines.append(f"  {name}: no output at t = {time:g} s; the nearest, t = {float(r.time[k]):g} s:")
        beyond = p.disk_x > r.overlap.max() + 1e-9
        on_axis = np.abs(p.disk_y) < 1e-9
        sel = beyond & on_axis
        fit, dev = coupled.rigid_fit(p.disk_x[sel], p.disk_d[sel, 1])
        tip_beam = p.node_d[np.argmax(p.node_x), 1]
        lines.append(f"  {name} at t = {float(r.time[k]):g} s: beam end w = {tip_beam:.4e} m, loaded disk dy = "
                     f"{p.disk_d[np.argmax(np.where(on_axis, p.disk_x, -np.inf)), 1]:.4e} m, "
                     f"rigid fit slope {fit[0]:.4e}, max deviation {dev:.3e} m "
                     f"({dev / max(np.abs(p.disk_d[sel, 1]).max(initial=0.0), 1e-300):.2e} "
                     "of the largest)")
    return lines


def interface_runs(folder):
    """{label: InterfaceRun} of the interface sweeps (run_interface_experiment.py)."""
    def point(sweep, name):
        return interface.InterfaceRun(os.path.join(folder, sweep, "runs", name, f"{name}.h5"))
    return {"mu 0.1": point("mu", "p001"), "mu 0.3": point("mu", "p002"), "mu 0.5": point("mu", "p003"),
            "cohesion 10 MPa": point("cohesion", "p001"), "bands 0.05 m": point("width", "p001")}


def interface_figures(folder, out, written):
    """Figures and summary lines of the interface experiment."""
    runs = interface_runs(folder)
    base = runs["mu 0.3"]
    radius = float(base.radius.max())
    save(interface.plot_friction([(k, runs[k]) for k in ("mu 0.1", "mu 0.3", "mu 0.5")],
                                 "local friction mu (cohesion 0, bands 0.025 m)", (0.1, 0.3, 0.5), radius),
         out, "interface_friction_mu", written)
    save(interface.plot_friction([("cohesion 0", base), ("cohesion 10 MPa", runs["cohesion 10 MPa"])],
                                 "cohesion (mu 0.3, bands 0.025 m)", (0.3,), radius),
         out, "interface_friction_cohesion", written)
    save(interface.plot_friction([("bands 0.025 m", base), ("bands 0.05 m", runs["bands 0.05 m"])],
                                 "overlap band width (mu 0.3, cohesion 0)", (0.3,), radius),
         out, "interface_friction_width", written)
    last = len(base.time) - 1
    save(interface.plot_configuration(base, last), out, "interface_configuration", written)
    save(interface.plot_stress(base, last, "xy"), out, "interface_stress_xy", written)
    save(interface.plot_stress(base, last, "vm"), out, "interface_stress_vm", written)
    lines = [f"{'run':<16} {'max T/N':>8} {'T/N at 1 mm':>12} {'at 3 mm':>8} {'sliding 1 mm':>13} "
             f"{'3 mm':>6} {'end':>7} {'slip [mm]':>10} {'max|bal| [J]':>13} {'FE audit [J]':>13} "
             f"{'W_reaction [J]':>15}"]
    mus = {"mu 0.1": 0.1, "mu 0.5": 0.5}
    for name, r in runs.items():
        s, mu = r.apparent_friction()
        order = np.argsort(s)
        at = np.interp([1e-3, 3e-3], s[order], mu[order])
        theory = interface.sliding_over_disks(mus.get(name, 0.3), np.array([1e-3, 3e-3]), radius)
        lines.append(f"{name:<16} {mu.max():>8.3f} {at[0]:>12.3f} {at[1]:>8.3f} {theory[0]:>13.3f} "
                     f"{theory[1]:>6.3f} {mu[-1]:>7.3f} {r.slip()[-1] * 1e3:>10.3f} "
                     f"{np.abs(r.balance).max():>13.3e} {np.abs(r.fe_balance).max():>13.3e} "
                     f"{r.reaction_work[-1]:>15.4f}")
    lines.append("max: over the run, rate-step transients included; sliding: tan(atan mu - asin(s/2R)) at "
                 "1 and 3 mm; end: T/N at the last output; max|bal|: coupled audit; FE audit: the "
                 "continuum's balance with the reactions' work (moves at the drive's rate steps)")
    return lines


def main(argv=None):
    parser = argparse.ArgumentParser(prog="plot_experiments.py",
                                     description=" ".join(__doc__.split("\n\n")[0].split()))
    parser.add_argument("--results", default="results/experiments",
                        help="folder holding <case>/<case>.h5 (default results/experiments)")
    parser.add_argument("--out", default=None, help="folder of the figures (default: --results)")
    parser.add_argument("--time", type=finite_float, default=5e-3,
                        help="time of the snapshots [s] (nearest stored output; default 5e-3)")
    parser.add_argument("--track", type=int, nargs="+", default=[7, 11, 17],
                        help="disks (1-based) whose histories are compared (default 7 11 17: "
                             "the last disk of the overlap of case 1, a disk of the particle "
                             "zone, the loaded disk)")
    parser.add_argument("--interface", default=None,
                        help="folder of the interface sweeps (default: <results>/interface; skipped "
                             "when absent)")
    args = parser.parse_args(argv)
    out = args.out or args.results
    written = []
    try:
        runs = {}
        for name in CASES:
            path = os.path.join(args.results, name, f"{name}.h5")
            runs[name] = coupled.load_coupled(path)
        # the tracked disks before any figure: a mistyped --track replaced the profiles and
        # configurations of the folder before it was refused
        for disk in args.track:
            for r in (runs["bending_case1"], runs["bending_case2"]):
                if not 1 <= disk <= r.n_disks:
                    raise ResultsError(f"{r.path}: no disk {disk} (the run has disks 1..{r.n_disks})")
        make_out_dir(out)  # once the runs load: a mistyped --results creates no folder
        for name, r in runs.items():
            save(coupled.plot_profiles(r, args.time), out, f"{name}_profiles", written)
            save(coupled.plot_configuration(r, args.time), out, f"{name}_configuration", written)
        rows = [runs["bending_case1"], runs["bending_case2"]]
        for disk in args.track:
            save(coupled.plot_histories(rows, disk - 1, [LABELS[c] for c in CASES[:2]]), out,
                 f"history_case1_case2_disk{disk}", written)
        save(coupled.plot_compare_profiles([runs["bending_case1"], runs["bending_stack"]],
                                           ["single row (case 1)", "stack"], args.time,
                                           zoom_run=1),
             out, "stack_vs_row", written)
    except ResultsError as exc:
        print(f"plot_experiments.py: error: {exc}", file=sys.stderr)
        return 1
    text = "\n".join(summary_lines(runs, args.time)) + "\n"
    folder = args.interface or os.path.join(args.results, "interface")
    if os.path.isdir(folder):
        try:
            lines = interface_figures(folder, out, written)
        except ResultsError as exc:
            print(f"plot_experiments.py: error: {exc}", file=sys.stderr)
            return 1
        path = os.path.join(out, "interface_summary.txt")
        with open(path, "w") as f:
            f.write("\n".join(lines) + "\n")
        written.append(path)
        text += "\ninterface experiment (apparent friction = top band T / N):\n" + "\n".join(lines) + "\n"
    path = os.path.join(out, "experiments_summary.txt")
    with open(path, "w") as f:
        f.write(text)
    written.append(path)
    print(text, end="")
    for p in written:
        print(p)
    return 0


if __name__ == "__main__":
    sys.exit(main())
