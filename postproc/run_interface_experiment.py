#!/usr/bin/env python3
"""Run the variants of the interface experiment (input/interface_shear.dat) for the figures of
doc/experiments.md.

    run_interface_experiment.py --exe EXE [--out DIR] [--deck DECK] [-j N]

Writes DIR (default results/experiments/interface, emptied first: refused, like an --exe or
--deck that is not a file, when it holds anything this script does not write): the base deck
with the absolute path of its mesh (interface_shear.dat), and three sweeps made from it by
scripts/multicor-sweep (`create`, then `run`), each point in <sweep>/runs/<point>/<point>.h5:
- mu: the local friction of the disks, contacts.law[1].mu = 0.1, 0.3, 0.5 (0.3: the base);
- cohesion: contacts.law[1].cohesion = 1e7 Pa (the base has 0; 1e6 Pa bonds break under the
  pressure already: the rigid bonds cannot follow the two blocks' different Poisson expansions);
and one more point, in the same layout:
- width: both bands 0.05 m deep instead of 0.025 m, [0.15, 0.2] and [0.25, 0.3] (the bands
  keep their side on the disk layer); the box bounds are values of the region's tail, which
  multicor-sweep keys cannot name: this deck is written by replacing the two region lines.
The two lanes (mu; cohesion then width) run side by side (-j 2, the default) or one after the
other (-j 1). plot_experiments.py draws the figures from DIR. Exit code 1 when a run fails.
"""
import argparse
import os
import pathlib
import shutil
import subprocess
import sys
import threading

ROOT = pathlib.Path(__file__).resolve().parent.parent
SWEEPS = {
    "mu": ["contacts.law[1].mu=0.1,0.3,0.5"],
    "cohesion": ["contacts.law[1].cohesion=1e7"],
}
#: What the script writes into --out (besides the base deck): the only entries it deletes.
OWN = set(SWEEPS) | {"width"}
REGIONS = [("region = box 0 0.5 0.175 0.2 bottom top", "region = box 0 0.5 0.15 0.2 bottom top"),
           ("region = box 0 0.5 0.25 0.275 top bottom", "region = box 0 0.5 0.25 0.3 top bottom")]


def sweep(python, exe, deck, folder, sets):
    tool = [python, str(ROOT / "scripts" / "multicor-sweep")]
    create = tool + ["create", str(deck), "--dir", str(folder), "--exe", str(exe)]
    for s in sets:
        create += ["--set", s]
    for cmd in (create, tool + ["run", str(folder), "--no-collect"]):
        proc = subprocess.run(cmd, capture_output=True, text=True)
        if proc.returncode != 0:
            sys.stderr.write(proc.stdout + proc.stderr)
            return f"{' '.join(cmd)}: exit {proc.returncode}"
        # the points run here: create's hints about the Slurm job array would mislead
        sys.stdout.writelines(line for line in proc.stdout.splitlines(keepends=True)
                              if not line.startswith(("Slurm job array:", "next: multicor-sweep")))
    return None


def width_point(exe, base, folder):
    """The deck with both bands 0.05 m deep, run into folder/runs/p001/p001.h5."""
    text = base.read_text()
    for old, new in REGIONS:
        if old not in text:
            return f"{base}: no line '{old}'"
        text = text.replace(old, new)
    (folder / "decks").mkdir(parents=True)
    deck = folder / "decks" / "p001.dat"
    deck.write_text(text)
    proc = subprocess.run([str(exe), "--quiet", str(deck), "--output", str(folder / "runs" / "p001")],
                          capture_output=True, text=True)
    if proc.returncode != 0:
        sys.stderr.write(proc.stdout + proc.stderr)
        return f"{exe} {deck}: exit {proc.returncode}"
    print(f"width p001 (bands 0.05 m): finished")
    return None


def check_arguments(exe, deck, out):
    """What is wrong with the command line before anything is deleted or run, or None: the
    executable and the deck must be files, and the folder --out, emptied first, must be new or
    hold only what this script writes (an earlier experiment): a typo such as --out results
    must not delete other runs."""
    if not (exe.is_file() and os.access(exe, os.X_OK)):
        return f"--exe {exe}: not an executable file"
    if not deck.is_file():
        return f"--deck {deck}: no such deck"
    if out.exists():
        if not out.is_dir():
            return f"--out {out}: a file, not a folder"
        strangers = sorted(p.name for p in out.iterdir() if p.name not in OWN | {deck.name})
        if strangers:
            return (f"--out {out}: holds {', '.join(strangers[:5])}"
                    f"{' ...' if len(strangers) > 5 else ''}, which this script did not write "
                    "(it empties the folder first): give a new folder or an earlier "
                    "experiment's")
    return None


def main(argv=None):
    ap = argparse.ArgumentParser(prog="run_interface_experiment.py",
                                 description=" ".join(__doc__.split("\n\n")[0].split()))
    ap.add_argument("--exe", required=True, help="multicor executable")
    ap.add_argument("--out", default="results/experiments/interface",
                    help="folder of the runs, replaced (default results/experiments/interface)")
    ap.add_argument("--deck", default=str(ROOT / "input" / "interface_shear.dat"),
                    help="the base deck (default input/interface_shear.dat)")
    ap.add_argument("-j", "--jobs", type=int, default=2, choices=(1, 2),
                    help="runs at a time (default 2)")
    args = ap.parse_args(argv)
    deck = pathlib.Path(args.deck).resolve()
    out = pathlib.Path(args.out).resolve()
    exe = pathlib.Path(args.exe).resolve()
    problem = check_arguments(exe, deck, out)
    if problem:
        print(f"run_interface_experiment.py: error: {problem}", file=sys.stderr)
        return 1
    if out.exists():
        shutil.rmtree(out)
    out.mkdir(parents=True)
    text = deck.read_text()
    mesh_line = "mesh = file interface_shear.msh"
    if mesh_line not in text:
        print(f"run_interface_experiment.py: error: {deck} has no line '{mesh_line}'", file=sys.stderr)
        return 1
    base = out / deck.name
    base.write_text(text.replace(mesh_line, f"mesh = file {deck.parent / 'interface_shear.msh'}"))
    lanes = [["mu"], ["cohesion", "width"]]
    errors = []

    def lane(names):
        for name in names:
            if name == "width":
                err = width_point(exe, base, out / name)
            else:
                err = sweep(sys.executable, exe, base, out / name, SWEEPS[name])
            if err:
                errors.append(err)

    if args.jobs == 1:
        for names in lanes:
            lane(names)
    else:
        threads = [threading.Thread(target=lane, args=(names,)) for names in lanes]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
    for err in errors:
        print(f"run_interface_experiment.py: error: {err}", file=sys.stderr)
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
