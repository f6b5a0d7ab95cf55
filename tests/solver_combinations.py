#!/usr/bin/env python3
"""Every combination of the solver's settings runs every particle deck cleanly.

For each deck given (default: the decks of input/ with a [particles] section), each
combination of `[solver] method` (nlgs, block, coarse), `criterion` (lmgc90, siconos),
`cold_start` (zero, hydrostatic), `anderson` (0, 5) and `sweep_order` (alternating,
forward), 48 in all, is written into a copy of the deck (replacing the deck's own values of
those keywords) and run for 20 steps (`--end` = 20 times its `[time] step`). A run must exit
0 and write only finite reals. Steps that stop at the sweep cap are allowed (plain sweeps
cannot solve some bonded decks within it: that is what `method = block` is for); they are
counted per deck. Any other exit code, a run-time error or backtrace of the compiler's
run-time library or a non-finite result is a finding: they are listed and the exit code is
1. Checks the settings of issue 8 over decks they were not tuned on. The ctest
solver_combinations (label long, Release build: `./test.sh`) runs it on the decks of the
repository, about 30 s on 2 cores; by hand:

    .venv/bin/python tests/solver_combinations.py [--exe build/src/multicor] [--jobs 2] [--verbose]
        [deck.dat ...]
"""
import concurrent.futures
import itertools
import pathlib
import re
import shutil
import sys
import tempfile

try:
    import h5py
    import numpy as np
except ImportError as missing:  # ctest reports the test as skipped, with the reason
    print(f"skipped: {missing.name} is not installed for this Python (postproc/requirements.txt)")
    sys.exit(77)

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from fuzz_decks import CRASH, ROOT, copy_auxiliaries, non_finite, parser_for, run  # noqa: E402

SETTINGS = {"method": ["nlgs", "block", "coarse"], "criterion": ["lmgc90", "siconos"],
            "cold_start": ["zero", "hydrostatic"], "anderson": ["0", "5"],
            "sweep_order": ["alternating", "forward"]}
STEPS = 20


def variant(text, values):
    """The deck text with the [solver] keywords of `values` set (a [solver] section is added
    when the deck has none)."""
    lines, section = [], None
    for line in text.split("\n"):
        stripped = line.split("#")[0].strip()
        if stripped.startswith("["):
            section = stripped
        key = stripped.split("=")[0].strip() if "=" in stripped else None
        if section == "[solver]" and key in values:
            continue
        lines.append(line)
    block = "\n".join(f"{k} = {v}" for k, v in values.items())
    text = "\n".join(lines)
    if re.search(r"^\s*\[solver\]", text, re.M):
        return re.sub(r"^\s*\[solver\]", "[solver]\n" + block, text, count=1, flags=re.M)
    return text + "\n[solver]\n" + block + "\n"


def unconverged(folder):
    """Steps of the run that stopped at the sweep cap (from /dem/solver/converged)."""
    n = 0
    for path in pathlib.Path(folder).glob("*.h5"):
        with h5py.File(path, "r") as results:
            if "dem/solver/converged" in results:
                n += int(np.count_nonzero(results["dem/solver/converged"][()] == 0))
    return n


def check(job):
    """(finding or None, unconverged steps) of one combination."""
    exe, folder, n, deck, values = job
    text = deck.read_text()
    path = folder / f"combination_{n}.dat"
    path.write_text(variant(text, values))
    where = f"{deck.name} ({', '.join(f'{k} = {v}' for k, v in values.items())})"
    out = folder / f"out_{n}"
    args = ["-q", "--output", str(out), str(path)]
    step = re.search(r"^\s*step\s*=\s*(\S+)", text, re.M)
    if step:
        args = ["--end", repr(STEPS * float(step.group(1)))] + args
    try:
        code, output = run(exe, args, 600)
        last = output.strip().split("\n")[-1] if output.strip() else ""
        if code != 0:
            return f"{where}: exit {code}: {last}", 0
        if any(s in output for s in CRASH):
            return f"{where}: crashed: {last}", 0
        bad = non_finite(out)
        if bad:
            return f"{where}: non-finite results: {bad[:3]}", 0
        return None, unconverged(out)
    finally:
        shutil.rmtree(out, ignore_errors=True)
        path.unlink()


def main():
    parser = parser_for(__doc__.split("\n")[0])
    parser.add_argument("--verbose", action="store_true", help="list the runs with steps at the cap")
    opts = parser.parse_args()
    decks = opts.decks or [d for d in sorted((ROOT / "input").glob("*.dat"))
                           if re.search(r"^\s*\[particles\]", d.read_text(), re.M)]
    decks = [d.resolve() for d in decks]
    combinations = [dict(zip(SETTINGS, v)) for v in itertools.product(*SETTINGS.values())]
    with tempfile.TemporaryDirectory() as tmp:
        scratch = pathlib.Path(tmp)
        copy_auxiliaries(decks, scratch)
        jobs = [(opts.exe, scratch / deck.parent.name, n, deck, values)
                for n, (deck, values) in enumerate(itertools.product(decks, combinations))]
        with concurrent.futures.ThreadPoolExecutor(opts.jobs) as pool:
            results = list(pool.map(check, jobs))
    findings = [f for f, _ in results if f]
    for deck in decks:
        mine = [(job, r) for job, r in zip(jobs, results) if job[3] == deck]
        capped = [(job[4], steps) for job, (_, steps) in mine if steps]
        by_method = ", ".join(f"{m} {sum(1 for v, _ in capped if v['method'] == m)}"
                              for m in SETTINGS["method"])
        print(f"{deck.name}: {len(mine)} runs, {len(capped)} with steps at the sweep cap ({by_method})")
        if opts.verbose:
            for values, steps in capped:
                print(f"    {steps} of {STEPS} steps: {', '.join(f'{k} = {v}' for k, v in values.items())}")
    for finding in findings:
        print("FINDING:", finding)
    print(f"{len(jobs)} runs of {len(decks)} decks: {len(findings)} findings")
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main())
