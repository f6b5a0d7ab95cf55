#!/usr/bin/env python3
"""Mutated copies of the decks: every bad one must end with a clear error, none with a crash.

For each deck given (default: input/*.dat and tests/regression/decks/*.dat), each `key =
values` line (the first two of each keyword per deck) is mutated one way at a time: each
value replaced by `x1`, `nan`, `1e999` and `-1`, the last value dropped, a value `7` added,
all values removed. Each mutant is written to a scratch folder, next to copies of the
deck's mesh and data files, and checked in two phases:
1. `multicor --check MUTANT`: exit 0 or 1. An error must name the mutant file with a line
   number (`file:N:`); a message without a line is listed as a note (a model error such as
   a mechanism, which belongs to no single line).
2. A mutant that passed the check runs for 5 steps (`--end` = 5 times its `[time] step`; a
   deck without one runs whole): exit 0 or 1, and every real dataset of the results finite.
Any exit code other than 0 and 1, a run-time error or backtrace of the compiler's run-time
library, an error that names no file, or a non-finite result is a finding: they are listed
and the exit code is 1. Checks one property of the input handling over many inputs; it is
run by hand, not by ctest (about a minute on 2 cores for the decks of the repository):

    .venv/bin/python tests/fuzz_decks.py [--exe build/src/multicor] [--jobs 2] [deck.dat ...]
"""
import argparse
import collections
import concurrent.futures
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile

import h5py
import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
LINE = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*=\s*(.*\S)\s*$")
CRASH = ("Backtrace", "runtime error", "Segmentation", "SIGSEGV", "Program received signal")
PER_KEYWORD = 2


def mutants(deck):
    """(line index, description, new line) of every mutant of one deck."""
    seen = collections.Counter()
    lines = deck.read_text().split("\n")
    for i, line in enumerate(lines):
        match = LINE.match(line.split("#")[0])
        if not match:
            continue
        key, values = match.group(1), match.group(2).split()
        seen[key] += 1
        if seen[key] > PER_KEYWORD:
            continue
        if key == "title":
            continue  # free text: any value is valid
        for t, value in enumerate(values):
            for new in ("x1", "nan", "1e999", "-1"):
                if value != new:
                    changed = values[:t] + [new] + values[t + 1:]
                    yield i, f"value {t + 1} -> {new}", f"{key} = {' '.join(changed)}"
        if len(values) > 1:
            yield i, "last value dropped", f"{key} = {' '.join(values[:-1])}"
        yield i, "value 7 added", f"{key} = {' '.join(values + ['7'])}"
        yield i, "no value", f"{key} ="


def non_finite(folder):
    """Real datasets of the HDF5 files in folder that hold a NaN or an infinity."""
    bad = []
    for path in sorted(pathlib.Path(folder).glob("*.h5")):
        with h5py.File(path, "r") as results:
            def visit(name, obj):
                if isinstance(obj, h5py.Dataset) and obj.dtype.kind == "f" and obj.size > 0:
                    if not np.all(np.isfinite(obj[()])):
                        bad.append(f"{path.name}:{name}")
            results.visititems(visit)
    return bad


def run(exe, args, timeout):
    try:
        done = subprocess.run([exe] + args, capture_output=True, text=True, timeout=timeout)
        return done.returncode, done.stderr + done.stdout
    except subprocess.TimeoutExpired:
        return "timeout", ""


def check(job):
    """Finding (str) or None, and a note (str) or None, for one mutant."""
    exe, scratch, n, deck, i, what, new = job
    lines = deck.read_text().split("\n")
    lines[i] = new
    folder = scratch / deck.parent.name
    path = folder / f"mutant_{n}.dat"
    path.write_text("\n".join(lines))
    where = f"{deck.name}:{i + 1} ({what}: '{new[:60]}')"
    try:
        code, text = run(exe, ["--check", str(path)], 60)
        last = text.strip().split("\n")[-1] if text.strip() else ""
        if code not in (0, 1):
            return f"{where}: --check exit {code}: {last}", None
        if any(s in text for s in CRASH):
            return f"{where}: --check crashed: {last}", None
        if code == 1:
            if path.name not in text:
                return f"{where}: the error names no file: {last}", None
            if not re.search(re.escape(path.name) + r":\d+:", text):
                return None, f"{where}: error without a line: {last}"
            return None, None
        step = re.search(r"^\s*step\s*=\s*(\S+)", "\n".join(lines), re.M)
        out = folder / f"out_{n}"
        args = ["-q", "--output", str(out), str(path)]
        if step:
            try:
                args = ["--end", repr(5.0 * float(step.group(1)))] + args
            except ValueError:
                pass
        code, text = run(exe, args, 300)
        last = text.strip().split("\n")[-1] if text.strip() else ""
        try:
            if code not in (0, 1, "timeout"):
                return f"{where}: run exit {code}: {last}", None
            if any(s in text for s in CRASH):
                return f"{where}: the run crashed: {last}", None
            bad = non_finite(out) if code == 0 else []
            if bad:
                return f"{where}: non-finite results with exit 0: {bad[:3]}", None
        finally:
            shutil.rmtree(out, ignore_errors=True)
        return None, None
    finally:
        path.unlink()


def parser_for(description):
    """The command line shared by the scripts that run many decks: decks, --exe, --jobs."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("decks", nargs="*", type=pathlib.Path)
    parser.add_argument("--exe", default=str(ROOT / "build" / "src" / "multicor"))
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    return parser


def copy_auxiliaries(decks, scratch):
    """Copy the mesh and data files next to each deck into scratch/<its folder's name>, where
    the variants of the decks are written, so that their relative paths still resolve."""
    for folder in {d.parent for d in decks}:
        target = scratch / folder.name
        target.mkdir(exist_ok=True)
        for aux in folder.iterdir():
            if aux.is_file() and aux.suffix != ".dat":
                shutil.copy(aux, target)


def main():
    opts = parser_for(__doc__.split("\n")[0]).parse_args()
    decks = opts.decks or sorted((ROOT / "input").glob("*.dat")) + \
        sorted((ROOT / "tests" / "regression" / "decks").glob("*.dat"))
    decks = [d.resolve() for d in decks]
    with tempfile.TemporaryDirectory() as tmp:
        scratch = pathlib.Path(tmp)
        copy_auxiliaries(decks, scratch)
        jobs = [(opts.exe, scratch, n, deck, i, what, new)
                for n, (deck, (i, what, new)) in enumerate(
                    (deck, m) for deck in decks for m in mutants(deck))]
        with concurrent.futures.ThreadPoolExecutor(opts.jobs) as pool:
            results = list(pool.map(check, jobs))
    findings = [f for f, _ in results if f]
    notes = [n for _, n in results if n]
    for note in notes:
        print("note:", note)
    for finding in findings:
        print("FINDING:", finding)
    print(f"{len(jobs)} mutants of {len(decks)} decks: {len(findings)} findings, "
          f"{len(notes)} errors without a line")
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main())
