#!/usr/bin/env python3
"""Plot a MULTICOR results file to PNG files and print their paths.

    plot_results.py results.h5 [--time T] [--out DIR] [--node ID] [--scale S]

Plots what the file holds: the beam (finite-element) plots of plot_beam.py when it has a
/fem/mesh, and the particle plots when it has a /dem group -- <name>_particles.png (disks,
walls and contact force network at the stored time nearest to T; default the last, plus
<name>_particles_start.png at t = 0), <name>_dem_energy.png (energy audit),
<name>_solver.png (contact solver statistics of every step) and, for up to 50 disks,
<name>_velocities.png; and, for a beam-coupled run (/coupling and /fem/mesh), both of these and
<name>_profiles.png (displacement and velocity along x of the beam nodes and the disks),
<name>_configuration.png (deformed beam, disks, overlap) and <name>_coupling.png (constraint
residuals, multipliers, energy audit). For a 2D continuum (a /continuum group, alone or
coupled to disks): <name>_stress.png (stress per element on the deformed mesh at the state
nearest to T), and for a dynamic run <name>_continuum_energy.png and <name>_history.png (the
node --node, a 1-based mesh index; default the node with the largest displacement), for a modal run
<name>_modes.png; coupled to disks (/coupling), <name>_coupling.png (the same diagnostics as a
beam-coupled run's) and the particle plots too. Exit code 1 with a message on a missing or
invalid file, or one with no stored output or solution (a run stopped before writing it); a
note on stderr for a --time outside the stored outputs or given for a static or modal run
(ignored), for a --node or --scale that no figure uses, for a figure left out because its
series is empty and for the per-step panels of <name>_coupling.png without a step.
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from multicor_post import beam, continuum, coupled, particles  # noqa: E402
from multicor_post.results import (READ_ERRORS, ResultsError, file_contents, finite_float,  # noqa: E402
                                   report_read_error,
                                   load_results, outside_time_note, scale_factor,
                                   unfinished_note, unused_scale_note, unused_time_note)


def contents(path):
    """(has beam results, has particle results, is a coupled run, has a 2D continuum) of a
    results file (multicor_post.results.file_contents)."""
    return file_contents(path)


def main(argv=None):
    parser = argparse.ArgumentParser(prog="plot_results.py",
                                     description=" ".join(__doc__.split("\n\n")[0].split()))
    parser.add_argument("results", help="results file (.h5) written by multicor")
    parser.add_argument("--time", type=finite_float, default=None,
                        help="time [s] of the snapshot plots (nearest stored output; default: "
                             "the last one)")
    parser.add_argument("--out", default=None,
                        help="folder for the PNG files (default: the results file's folder)")
    parser.add_argument("--node", type=int, default=None,
                        help="beam: deck id of the node whose history is plotted (default: the "
                             "tip); continuum: 1-based mesh node (default: the largest "
                             "displacement)")
    parser.add_argument("--scale", type=scale_factor, default=None,
                        help="beam and continuum: displacement scale factor of deformed shapes "
                             "(default: auto)")
    args = parser.parse_args(argv)
    out = args.out if args.out is not None else (os.path.dirname(args.results) or ".")
    notes = []      # what the figures do not show as asked, printed after them
    try:
        has_beam, has_particles, is_coupled, has_continuum = contents(args.results)
        if not (has_beam or has_particles or has_continuum):
            raise ResultsError(f"{args.results}: neither /fem/mesh, /continuum nor /dem: not a "
                               "MULTICOR results file")
        paths = []
        # printed with the figures (a file with nothing to plot gets its error alone)
        notes.append(unfinished_note(args.results))
        # a deformed shape that --scale magnifies: a continuum's, a beam-coupled run's
        # configuration, a frame's (beam.uses_scale)
        scaled = has_continuum or (is_coupled and has_beam)
        if has_continuum:
            res = continuum.load_continuum(args.results)
            notes.append(outside_time_note(args.time, res.time))
            notes.append(unused_time_note(args.time, res.analysis))
            paths += continuum.write_all(res, out, time=args.time, scale=args.scale, node=args.node)
            if is_coupled:
                paths += coupled.write_coupling(coupled.load_continuum_coupling(args.results), out,
                                                notes=notes)
        if is_coupled and has_beam:
            res = coupled.load_coupled(args.results)
            notes.append(outside_time_note(args.time, res.time))
            paths += coupled.write_all(res, out, time=args.time, scale=args.scale, notes=notes)
        if has_beam:
            res = load_results(args.results)
            notes.append(outside_time_note(args.time, None if res.dynamic is None
                                           else res.dynamic.time))
            notes.append(unused_time_note(args.time, res.analysis))
            scaled = scaled or beam.uses_scale(res)
            paths += beam.write_all(res, out, time=args.time, node_id=args.node, scale=args.scale)
        if has_particles:
            res = particles.load_dem(args.results)
            notes.append(outside_time_note(args.time, res.time))
            paths += particles.write_all(res, out, time=args.time, notes=notes)
    except READ_ERRORS as exc:
        return report_read_error("plot_results.py", exc, args.results)
    if args.node is not None and not any("_history" in os.path.basename(p) for p in paths):
        notes.append(f"--node {args.node} is not used: '{args.results}' has no node history to "
                     "plot (dynamic beam and continuum runs have one)")
    notes.append(unused_scale_note(args.scale, args.results, scaled))
    # the parts of a coupled run share their outputs: one note each
    for note in dict.fromkeys(n for n in notes if n):
        print(f"plot_results.py: note: {note}", file=sys.stderr)
    for path in paths:
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
