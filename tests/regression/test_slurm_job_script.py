#!/usr/bin/env python3
"""scripts/multicor.slurm without a Slurm daemon: `srun` and `scontrol` are stand-ins on the
PATH (srun runs the command, and can kill it after a delay; scontrol only logs), so the
script's own decisions are tested: which start continues with --restart, which starts
afresh. (test_slurm_sweep.py and test_slurm_requeue.py run the scripts on a real Slurm.)

Deck: input/incline.dat at a step of 2e-5 s (25 000 steps, a run the signals below reach
mid-way) with an output every 500 steps (50 records; at the deck's 10, 2 500 records made
each run 3.5 s of CPU in the Debug build instead of 0.6 s). The runs whose results are
not compared (6 and 7: names and executables) end at 0.01 s.
1. A run to the end: finished results and its final checkpoint.
2. The job submitted again, killed outright (SIGKILL, as a node failure or scancel) before
   its first checkpoint: its partial file lies next to the finished run's checkpoint.
3. Submitted again: a fresh run (no --restart), exit 0, finished. Before, the script passed
   --restart with the old checkpoint, which multicor refuses (its end is reached), and every
   resubmission failed the same way.
4. A run stopped by SIGUSR1 (the signal before the time limit) writes its checkpoint and
   exits 138; the next start continues it with --restart and finishes with the results of
   the uninterrupted run, bit for bit.
5. The same with a deck named incline.v2.txt, in the default folder ($SCRATCH/multicor/
   incline.v2): the results are named as multicor names them, so the requeued start finds
   the partial file and continues. 6. A deck named .incline (results .incline.h5).
7. The executable: multicor on the PATH, build/src/multicor under the submission folder;
   none found, or MULTICOR_EXE wrong: exit 2 with a message, before any results folder.
Usage (ctest does this): test_slurm_job_script.py --exe multicor --work DIR --source REPO
"""
import os
import re
import subprocess
import sys

import numpy as np

from checks import arguments, check, datasets, summary

SRUN = """#!/bin/bash
# stand-in for srun: drop its options, run the command; FAKE_SIGNAL_AFTER=s sends FAKE_SIGNAL
# (default KILL) to it after s seconds, counted from the moment the file FAKE_SIGNAL_WAIT_FOR
# exists when that is set (the run's results file: a signal before it opens stops the run
# without a checkpoint, and a fixed delay from the start reached a run still in its set-up on
# a loaded machine)
while [[ "$1" == --* ]]; do shift; done
if [ -n "${FAKE_SIGNAL_AFTER:-}" ]; then
    "$@" & pid=$!
    if [ -n "${FAKE_SIGNAL_WAIT_FOR:-}" ]; then
        while [ ! -e "$FAKE_SIGNAL_WAIT_FOR" ] && kill -0 "$pid" 2>/dev/null; do sleep 0.01; done
    fi
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
    """Run the job script once as a Slurm start would; its output and exit code. `out` None:
    the script's default folder; an `extra` variable None: removed from the environment."""
    env = dict(os.environ, PATH=f"{work / 'bin'}:{os.environ['PATH']}", MULTICOR_EXE=str(exe),
               FAKE_LOG=str(work / "scontrol.log"), OMP_NUM_THREADS="1", SLURM_JOB_ID="1")
    env.pop("SLURM_SUBMIT_DIR", None)
    for k, v in extra.items():
        if v is None:
            env.pop(k, None)
        else:
            env[k] = str(v)
    args = [str(deck)] + ([] if out is None else [str(out)])
    proc = subprocess.run(["bash", str(src / "scripts" / "multicor.slurm")] + args,
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
    text = re.sub(r"^interval(\s*)=.*$", "interval = 500", text, count=1, flags=re.M)
    deck = work / "incline.dat"
    deck.write_text(text)
    check("deck: step and output interval set", "step = 2e-5" in text and "interval = 500" in text, "")
    out = work / "out"

    log, rc = job(src, exe, work, deck, out)
    check("1. first job: exit 0, finished, with its checkpoint",
          rc == 0 and (out / "incline.h5").exists() and (out / "checkpoint.h5").exists(), f"exit {rc}")
    # every dataset of /dem: the 51 stored states and each step's solver record (25 000)
    reference = datasets(out / "incline.h5", "dem")

    # killed 0.05 s after its results file opened: the run (25 000 steps) has no checkpoint of
    # its own yet (it writes one only at its end or on a stop signal)
    log, rc = job(src, exe, work, deck, out, FAKE_SIGNAL_AFTER=0.05,
                  FAKE_SIGNAL_WAIT_FOR=str(out / "incline.h5.partial"))
    check("2. job killed outright: exit 137, partial file next to the old checkpoint",
          rc == 137 and (out / "incline.h5.partial").exists() and (out / "checkpoint.h5").exists(),
          f"exit {rc}; {start_line(log)}")

    log, rc = job(src, exe, work, deck, out)
    check("3. submitted again: a fresh run, not a restart from the finished run's checkpoint",
          "--restart" not in start_line(log), start_line(log))
    check("3. submitted again: exit 0, finished", rc == 0 and (out / "incline.h5").exists()
          and not (out / "incline.h5.partial").exists(), f"exit {rc}")

    stopped = work / "stopped"
    log, rc = job(src, exe, work, deck, stopped, FAKE_SIGNAL_AFTER=0.05, FAKE_SIGNAL="USR1",
                  FAKE_SIGNAL_WAIT_FOR=str(stopped / "incline.h5.partial"))
    check("4. SIGUSR1: exit of the scontrol requeue path (0), checkpoint written",
          rc == 0 and (stopped / "checkpoint.h5").exists() and "requeued" in log, f"exit {rc}")
    log, rc = job(src, exe, work, deck, stopped, SLURM_RESTART_COUNT=1)
    check("4. the requeued start continues with --restart", "--restart" in start_line(log), start_line(log))
    check("4. and finishes", rc == 0 and (stopped / "incline.h5").exists(), f"exit {rc}")
    if (stopped / "incline.h5").exists():
        f = datasets(stopped / "incline.h5", "dem")
        differ = [k for k, v in reference.items() if k not in f or not np.array_equal(v, f[k])]
        check("4. the continued run's /dem datasets equal the uninterrupted run's, bit for bit",
              not differ and reference, f"{len(reference)} datasets; differ: {differ}")
    other_names(src, exe, work, text, reference)
    # the runs of 6 and 7 check names and executables, not results: 500 steps
    short = re.sub(r"^end(\s*)=.*$", "end = 0.01", text, count=1, flags=re.M)
    check("deck: end set for the runs of 6 and 7", "end = 0.01" in short, "")
    short_deck = work / "short" / "incline.dat"
    short_deck.parent.mkdir()
    short_deck.write_text(short)
    dot_deck(src, exe, work, short)
    executable(src, exe, work, short_deck)
    return summary()


def other_names(src, exe, work, text, reference):
    """Decks not named *.dat: the script names the results as multicor does (the file name
    without its last extension), so a requeued start continues its run. Before, it dropped
    only '.dat': it never found <name>.h5.partial, and every requeued start began again at
    step 0 while the log said it continued. The default folder is named the same way."""
    scratch = work / "scratch"
    deck = work / "incline.v2.txt"
    deck.write_text(text)
    out = scratch / "multicor" / "incline.v2"
    log, rc = job(src, exe, work, deck, None, SCRATCH=scratch, FAKE_SIGNAL_AFTER=0.05,
                  FAKE_SIGNAL="USR1", FAKE_SIGNAL_WAIT_FOR=str(out / "incline.v2.h5.partial"))
    check("5. incline.v2.txt stopped by SIGUSR1: requeued, default folder multicor/incline.v2",
          rc == 0 and (out / "checkpoint.h5").exists() and (out / "incline.v2.h5.partial").exists()
          and "requeued" in log, f"exit {rc}; {sorted(p.name for p in scratch.rglob('*'))}")
    log, rc = job(src, exe, work, deck, None, SCRATCH=scratch, SLURM_RESTART_COUNT=1)
    check("5. the requeued start of incline.v2.txt continues with --restart",
          "--restart" in start_line(log), start_line(log))
    check("5. and finishes", rc == 0 and (out / "incline.v2.h5").exists(), f"exit {rc}")
    if (out / "incline.v2.h5").exists():
        f = datasets(out / "incline.v2.h5", "dem")
        differ = [k for k, v in reference.items() if k not in f or not np.array_equal(v, f[k])]
        check("5. incline.v2.txt continued = the uninterrupted run, bit for bit",
              not differ and reference, f"differ: {differ}")


def dot_deck(src, exe, work, text):
    """A name whose only dot is its first: multicor keeps it whole (.incline.h5)."""
    scratch = work / "scratch"
    deck = work / ".incline"
    deck.write_text(text)
    log, rc = job(src, exe, work, deck, None, SCRATCH=scratch)
    check("6. deck .incline: results multicor/.incline/.incline.h5",
          rc == 0 and (scratch / "multicor" / ".incline" / ".incline.h5").exists(),
          f"exit {rc}; {sorted(p.name for p in (scratch / 'multicor').iterdir())}")


def executable(src, exe, work, deck):
    """The executable as multicor-sweep finds it: $MULTICOR_EXE, build/src/multicor under
    the submission folder, multicor on the PATH; none: a clear error before any folder."""
    path_bin = work / "path_bin"
    path_bin.mkdir()
    (path_bin / "multicor").symlink_to(exe)
    log, rc = job(src, exe, work, deck, work / "exe_path", MULTICOR_EXE=None,
                  PATH=f"{work / 'bin'}:{path_bin}:/usr/bin:/bin")
    check("7. multicor on the PATH (no MULTICOR_EXE, no build/)", rc == 0
          and f"{path_bin / 'multicor'} --quiet" in start_line(log), f"exit {rc}; {log[-300:]}")
    submit_dir = work / "submit_dir"
    (submit_dir / "build" / "src").mkdir(parents=True)
    (submit_dir / "build" / "src" / "multicor").symlink_to(exe)
    log, rc = job(src, exe, work, deck, work / "exe_build", MULTICOR_EXE=None,
                  SLURM_SUBMIT_DIR=submit_dir, PATH=f"{work / 'bin'}:{path_bin}:/usr/bin:/bin")
    check("7. build/src/multicor under the submission folder, before the PATH's", rc == 0
          and f"{submit_dir}/build/src/multicor --quiet" in start_line(log),
          f"exit {rc}; {log[-300:]}")
    out = work / "exe_none"
    log, rc = job(src, exe, work, deck, out, MULTICOR_EXE=None, PATH=f"{work / 'bin'}:/usr/bin:/bin")
    check("7. no executable: exit 2, the places tried named, no results folder",
          rc == 2 and "no multicor executable" in log and "MULTICOR_EXE" in log
          and f"{work}/build/src/multicor" in log and "on the PATH" in log and not out.exists(),
          f"exit {rc}; {log.strip()}")
    log, rc = job(src, exe, work, deck, out, MULTICOR_EXE=work / "nothing")
    check("7. MULTICOR_EXE not a file: exit 2, named, no results folder",
          rc == 2 and f"MULTICOR_EXE={work / 'nothing'} is not an executable file" in log
          and not out.exists(), f"exit {rc}; {log.strip()}")


if __name__ == "__main__":
    sys.exit(main())
