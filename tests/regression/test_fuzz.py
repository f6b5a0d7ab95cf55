#!/usr/bin/env python3
"""Deterministic fuzz test of the deck reader, the checks and the first steps of a run.

A fixed seed draws a few hundred mutations of the example decks in input/: deleted,
duplicated and swapped lines, numbers replaced by garbage, +-1e300, nan, 0, -1 or 1e-320,
files cut short (one to three mutations each). Each mutated deck goes through
`multicor --check`; when the check passes, a copy whose [time] end is cut to three steps is
run. The test fails on any signal (crash), any 'Fortran runtime error', any exit code other
than 0 and 1, a run longer than its time limit, and any non-finite value written into an
HDF5 file (datasets and attributes). It prints the counts.

Kept within about a minute on 2 cores with the Debug build (two runs at a time).
Usage (ctest does this): test_fuzz.py --exe multicor --work DIR --source REPO [--count N]
"""
import argparse
import concurrent.futures
import pathlib
import random
import re
import shutil
import subprocess
import sys

import h5py
import numpy as np

SEED = 20261123
REPLACEMENTS = ["x1.2.3", "=", "#", "[run]", "1e300", "-1e300", "nan", "0", "-1", "1e-320",
                "1e-300", "2147483648", "", "abc"]
NUMBER = re.compile(r"(?<![\w.])[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?(?![\w.])")
TIME_LIMIT = 60  # seconds per multicor call (a hang is a failure)


def mutate(text, rng):
    """One to three mutations of the deck text; returns (text, description)."""
    done = []
    for _ in range(rng.randint(1, 3)):
        lines = text.split("\n")
        kind = rng.choice(["delete", "duplicate", "swap", "number", "number", "number", "cut"])
        if kind == "delete" and len(lines) > 1:
            k = rng.randrange(len(lines))
            done.append(f"delete line {k + 1}")
            del lines[k]
        elif kind == "duplicate":
            k = rng.randrange(len(lines))
            done.append(f"duplicate line {k + 1}")
            lines.insert(k, lines[k])
        elif kind == "swap" and len(lines) > 1:
            a, b = rng.sample(range(len(lines)), 2)
            done.append(f"swap lines {a + 1} and {b + 1}")
            lines[a], lines[b] = lines[b], lines[a]
        elif kind == "number":
            spots = [(k, m) for k, line in enumerate(lines)
                     if not line.lstrip().startswith("#")
                     for m in NUMBER.finditer(line.split("#")[0])]
            if spots:
                k, m = rng.choice(spots)
                new = rng.choice(REPLACEMENTS)
                done.append(f"line {k + 1}: {m.group(0)!r} -> {new!r}")
                lines[k] = lines[k][:m.start()] + new + lines[k][m.end():]
        elif kind == "cut":
            joined = "\n".join(lines)
            cut = rng.randrange(len(joined) + 1)
            done.append(f"cut at byte {cut}")
            lines = joined[:cut].split("\n")
        text = "\n".join(lines)
    return text, "; ".join(done)


def three_steps(text):
    """The deck with [time] end set to three steps (when the step reads as a number)."""
    section, step = "", None
    for line in text.split("\n"):
        s = line.split("#")[0].strip()
        if s.startswith("["):
            section = s
        elif section == "[time]" and re.match(r"step\s*=", s):
            try:
                step = float(s.split("=", 1)[1].split()[0])
            except (ValueError, IndexError):
                return text
    if step is None:
        return text
    out, section = [], ""
    for line in text.split("\n"):
        s = line.split("#")[0].strip()
        if s.startswith("["):
            section = s
        if section == "[time]" and re.match(r"end\s*=", s):
            line = f"end = {3 * step!r}"
        out.append(line)
    return "\n".join(out)


def non_finite_in(path):
    """Names of datasets or attributes with a non-finite value in an HDF5 file (every one of
    a floating-point type). Through h5py's low-level calls: its Group, Dataset and attribute
    objects took twice the time, a tenth of the test's CPU."""
    bad = []

    def attributes(oid, name):
        for k in range(h5py.h5a.get_num_attrs(oid)):
            aid = h5py.h5a.open(oid, index=k)
            if aid.dtype.kind == "f" and aid.shape is not None:
                value = np.empty(aid.shape, aid.dtype)
                aid.read(value)
                if not np.all(np.isfinite(value)):
                    bad.append(f"{name}@{aid.name.decode()}")

    def visit(name):
        oid = h5py.h5o.open(f.id, name)
        attributes(oid, name.decode())
        if isinstance(oid, h5py.h5d.DatasetID) and oid.dtype.kind == "f" and oid.shape is not None:
            value = np.empty(oid.shape, oid.dtype)
            if value.size:
                oid.read(h5py.h5s.ALL, h5py.h5s.ALL, value)
            if not np.all(np.isfinite(value)):
                bad.append(name.decode())

    with h5py.File(path, "r") as f:
        attributes(f.id, "/")
        h5py.h5o.visit(f.id, visit)
    return bad


def call(exe, args):
    try:
        proc = subprocess.run([str(exe), *map(str, args)], capture_output=True, text=True,
                              timeout=TIME_LIMIT, errors="replace")
    except subprocess.TimeoutExpired:
        return None
    return proc


def problems_of(proc, what):
    """Failures of one multicor call."""
    if proc is None:
        return [f"{what}: no answer within {TIME_LIMIT} s"]
    found = []
    text = proc.stdout + proc.stderr
    if proc.returncode < 0:
        found.append(f"{what}: killed by signal {-proc.returncode}")
    elif proc.returncode not in (0, 1):
        found.append(f"{what}: exit code {proc.returncode}")
    for marker in ("Fortran runtime error", "Program received signal", "Backtrace"):
        if marker in text:
            found.append(f"{what}: '{marker}'")
    if found:
        found.append(text.strip()[-600:])
    return found


def one_case(exe, work, k, name, text):
    """Check, then run (when valid) one mutated deck; returns (check rc, run rc, problems)."""
    folder = work / f"case{k:04d}"
    shutil.rmtree(folder, ignore_errors=True)
    folder.mkdir(parents=True)
    deck = folder / f"{name}.dat"
    deck.write_bytes(text.encode("utf-8", errors="replace"))
    proc = call(exe, ["--check", deck])
    problems = problems_of(proc, "--check")
    check_rc = None if proc is None else proc.returncode
    run_rc = None
    if check_rc == 0:
        deck.write_bytes(three_steps(text).encode("utf-8", errors="replace"))
        out = folder / "results"
        proc = call(exe, [deck, "--output", out, "--quiet"])
        problems += problems_of(proc, "run")
        run_rc = None if proc is None else proc.returncode
        for h5 in list(out.glob("*.h5")) + list(out.glob("*.h5.partial")):
            try:
                bad = non_finite_in(h5)
            except Exception as exc:  # noqa: BLE001 (h5py raises OSError, KeyError, ...)
                bad = [f"cannot read: {exc}"] if run_rc == 0 else []
            if bad:
                problems.append(f"non-finite values in {h5.name}: {bad[:5]}")
    if not problems:
        shutil.rmtree(folder, ignore_errors=True)
    return check_rc, run_rc, problems


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--exe", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--source", required=True)
    ap.add_argument("--count", type=int, default=600)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--seed", type=int, default=SEED)
    args = ap.parse_args()
    exe, work, src = pathlib.Path(args.exe), pathlib.Path(args.work), pathlib.Path(args.source)
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    decks = sorted((src / "input").glob("*.dat"))
    rng = random.Random(args.seed)
    cases = []
    for k in range(args.count):
        deck = decks[k % len(decks)]
        text, what = mutate(deck.read_text(), rng)
        cases.append((k, deck.stem, text, what))
    counts = {"check 0": 0, "check 1": 0, "run 0": 0, "run 1": 0}
    failures = 0
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futures = {pool.submit(one_case, exe, work, k, name, text): (k, name, what)
                   for k, name, text, what in cases}
        for future in concurrent.futures.as_completed(futures):
            k, name, what = futures[future]
            check_rc, run_rc, problems = future.result()
            if check_rc in (0, 1):
                counts[f"check {check_rc}"] += 1
            if run_rc in (0, 1):
                counts[f"run {run_rc}"] += 1
            if problems:
                failures += 1
                print(f"FAILED case {k} ({name}.dat: {what}):")
                for p in problems:
                    print("    " + p.replace("\n", "\n    "))
    print(f"fuzz (seed {args.seed}): {args.count} mutations of {len(decks)} decks; --check exit 0: "
          f"{counts['check 0']}, exit 1: {counts['check 1']}; short runs exit 0: {counts['run 0']}, "
          f"exit 1: {counts['run 1']}; {failures} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
