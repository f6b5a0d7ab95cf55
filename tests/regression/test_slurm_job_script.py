#!/usr/bin/env python3
"""scripts/multicor.slurm without a Slurm daemon: `srun` and `scontrol` are stand-ins on the
PATH (srun runs the command, and can kill it after a delay; scontrol only logs), so the
script's own decisions are tested: which start continues with --restart, which starts
afresh. (test_slurm_sweep.py and test_slurm_requeue.py run the scripts on a real Slurm.)

Deck: input/incline.dat at a step of 2e-5 s (25 000 steps, about a second).
1. A run to the end: finished results and its final checkpoint.
2. The job submitted again, killed outright (SIGKILL, as a node failure or scancel) before
   its first checkpoint: its partial file lies next to the finished run's checkpoint.
3. Submitted again: a fresh run (no --restart), exit 0, finished. Before, the script passed
   --restart with the old checkpoint, which multicor refuses (its end is reached), and every
   resubmission failed the same way.
4. A run stopped by SIGUSR1 (the signal before the time limit) writes its checkpoint and
   exits 138; the next start continues it with --restart and finishes with the results of
   the uninterrupted run, bit for bit.
Usage (ctest does this): test_slurm_job_script.py --exe multicor --work DIR --source REPO
"""
import os
import re
import subprocess
import sys

import h5py
import numpy as np

from checks import arguments, check, summary

SRUN = """#!/bin/bash
# stand-in for srun: drop its options, run the command; FAKE_SIGNAL_AFTER=s sends FAKE_SIGNAL
# (default KILL) to it after s seconds
while [[ "$1" == --* ]]; do shift; done
if [ -n "${FAKE_SIGNAL_AFTER:-}" ]; then
    "$@" & pid=$!
    sleep "$FAKE_SIGNAL_AFTER"
    kill -"${FAKE_SIGNAL:-KILL}" "$pid" 2>/dev/null
    wait "$pid"
    exit $?
fi
exec "$@"
"""
SCONTROL = """#!/bin/bash
echo "scontrol $*" >> "$FAKE_LOG"
"""


def job(src, exe, work, deck, out, **extra):
    """Run the job script once as a Slurm start would; its output and exit code."""
    env = dict(os.environ, PATH=f"{work / 'bin'}:{os.environ['PATH']}", MULTICOR_EXE=str(exe),
               FAKE_LOG=str(work / "scontrol.log"), OMP_NUM_THREADS="1", SLURM_JOB_ID="1")
    env.update({k: str(v) for k, v in extra.items()})
    proc = subprocess.run(["bash", str(src / "scripts" / "multicor.slurm"), str(deck), str(out)],
                          capture_output=True, text=True, env=env, cwd=work)
    return proc.stdout + proc.stderr, proc.returncode


def start_line(log):
    """The script's line that shows the command it starts."""
    lines = [ln for ln in log.splitlines() if re.search(r" start \(restart count", ln)]
    return lines[-1] if lines else "no start line"


def main():
    exe, work, src = arguments(fresh=True)
    (work / "bin").mkdir()
    for name, text in (("srun", SRUN), ("scontrol", SCONTROL)):
        (work / "bin" / name).write_text(text)
        (work / "bin" / name).chmod(0o755)
    text = (src / "input" / "incline.dat").read_text()
    text = re.sub(r"^step(\s*)=.*$", "step = 2e-5", text, count=1, flags=re.M)
    deck = work / "incline.dat"
    deck.write_text(text)
    check("deck: step set", "step = 2e-5" in text, "")
    out = work / "out"

    log, rc = job(src, exe, work, deck, out)
    check("1. first job: exit 0, finished, with its checkpoint",
          rc == 0 and (out / "incline.h5").exists() and (out / "checkpoint.h5").exists(), f"exit {rc}")
    reference = {k: v[...] for k, v in h5py.File(out / "incline.h5", "r")["dem"].items()
                 if isinstance(v, h5py.Dataset)}

    # killed after 0.2 s: the run (about 1 s) has no checkpoint of its own yet
    log, rc = job(src, exe, work, deck, out, FAKE_SIGNAL_AFTER=0.2)
    check("2. job killed outright: exit 137, partial file next to the old checkpoint",
          rc == 137 and (out / "incline.h5.partial").exists() and (out / "checkpoint.h5").exists(),
          f"exit {rc}; {start_line(log)}")

    log, rc = job(src, exe, work, deck, out)
    check("3. submitted again: a fresh run, not a restart from the finished run's checkpoint",
          "--restart" not in start_line(log), start_line(log))
    check("3. submitted again: exit 0, finished", rc == 0 and (out / "incline.h5").exists()
          and not (out / "incline.h5.partial").exists(), f"exit {rc}")

    stopped = work / "stopped"
    log, rc = job(src, exe, work, deck, stopped, FAKE_SIGNAL_AFTER=0.3, FAKE_SIGNAL="USR1")
    check("4. SIGUSR1: exit of the scontrol requeue path (0), checkpoint written",
          rc == 0 and (stopped / "checkpoint.h5").exists() and "requeued" in log, f"exit {rc}")
    log, rc = job(src, exe, work, deck, stopped, SLURM_RESTART_COUNT=1)
    check("4. the requeued start continues with --restart", "--restart" in start_line(log), start_line(log))
    check("4. and finishes", rc == 0 and (stopped / "incline.h5").exists(), f"exit {rc}")
    if (stopped / "incline.h5").exists():
        f = h5py.File(stopped / "incline.h5", "r")["dem"]
        differ = [k for k, v in reference.items() if not np.array_equal(v, f[k][...])]
        check("4. the continued run's /dem datasets equal the uninterrupted run's, bit for bit",
              not differ and reference, f"{len(reference)} datasets; differ: {differ}")
    return summary()


if __name__ == "__main__":
    sys.exit(main())
