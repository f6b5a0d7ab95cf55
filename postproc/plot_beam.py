#!/usr/bin/env python3
"""Plot a MULTICOR beam results file to PNG files and print their paths.

    plot_beam.py results.h5 [--time T] [--node ID] [--out DIR] [--scale S]

Writes, depending on what the run stored: <name>_deflection.png (deflection along a straight
beam, or the deformed shape of a frame, at the stored time nearest to T; default the last),
<name>_history_node<ID>.png (w(t) and u(t) of node ID; default the tip), <name>_energy.png,
<name>_static.png and <name>_modes.png (along a straight beam w, and u of an axial mode,
marked '(axial)'). Exit code 1 with a message on a missing or invalid
file, or one with no stored output or solution (a run stopped before writing it); a note on
stderr for a --time outside the stored outputs or given for a static or modal run (ignored),
and for a --scale that no figure uses (a straight beam's deflection is in length units).
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from multicor_post.beam import uses_scale, write_all  # noqa: E402
from multicor_post.results import (READ_ERRORS, ResultsError, file_contents, finite_float,  # noqa: E402
                                   report_read_error,
                                   load_results, outside_time_note, scale_factor,
                                   unused_scale_note, unused_time_note)


def main(argv=None):
    parser = argparse.ArgumentParser(prog="plot_beam.py",
                                     description=" ".join(__doc__.split("\n\n")[0].split()))
    parser.add_argument("results", help="results file (.h5) written by multicor")
    parser.add_argument("--time", type=finite_float, default=None,
                        help="time [s] of the deflection plot (nearest stored output; "
                             "default: the last one)")
    parser.add_argument("--node", type=int, default=None,
                        help="deck id of the node whose history is plotted (default: the tip)")
    parser.add_argument("--out", default=None,
                        help="folder for the PNG files (default: the results file's folder)")
    parser.add_argument("--scale", type=scale_factor, default=None,
                        help="displacement scale factor of deformed-shape plots (default: auto)")
    args = parser.parse_args(argv)
    out = args.out if args.out is not None else (os.path.dirname(args.results) or ".")
    try:
        has_beam, has_particles, _, has_continuum = file_contents(args.results)
        if not has_beam and (has_particles or has_continuum):
            what = "particles (/dem)" if has_particles else "a 2D continuum (/continuum)"
            raise ResultsError(f"'{args.results}' holds no beam (/fem/mesh) but {what}: plot it "
                               "with plot_results.py")
        res = load_results(args.results)
        paths = write_all(res, out, time=args.time, node_id=args.node, scale=args.scale)
    except READ_ERRORS as exc:
        return report_read_error("plot_beam.py", exc, args.results)
    for note in (outside_time_note(args.time, None if res.dynamic is None else res.dynamic.time),
                 unused_time_note(args.time, res.analysis),
                 unused_scale_note(args.scale, args.results, uses_scale(res))):
        if note:
            print(f"plot_beam.py: note: {note}", file=sys.stderr)
    for path in paths:
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
