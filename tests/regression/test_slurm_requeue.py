#!/usr/bin/env python3
"""A sweep point stopped before its time limit requeues itself on a real Slurm and completes
from its checkpoint (scripts/multicor-sweep, tests/regression/slurm_local.py).

A 2-point sweep of input/incline.dat over the time step (1e-3 s: 500 steps; the long point
as many steps as this build runs in about 1.5 s, from a timed run of 10 000 steps, at least
20 000 and at most 500 000; outputs every 100 steps). 0.2 s after the long point opened its
results file, the test sends it SIGUSR1 with `scancel --signal=USR1 <job>_2`: the signal that `#SBATCH --signal=USR1@<s>`
makes slurmctld send to the job steps <s> seconds before the time limit, by the same route
(slurmctld -> slurmd -> the step's tasks), only sent now instead of at the clock's time (a
real time limit is a minute at least, and slurmctld checks limits every 30 s). multicor
writes its checkpoint and exits with 138; the job script requeues the task (`scontrol
requeue`, allowed by `--requeue`), and Slurm starts it again, which continues with
`--restart runs/p002/checkpoint.h5`. The test checks: two starts of the point in its log,
the second with --restart; the point finished; its final velocity equals the closed form
of the deck and, bit for bit, a local uninterrupted run of the same deck (run while Slurm
holds the requeued task back, AuthInfo cred_expire = 5 s, the least Slurm accepts).

Skips (exit 77, reason printed) when `multicor --help` does not list --restart (restart not
built in), when not root, or when slurm-wlm / munge are missing.
Usage (ctest does this): test_slurm_requeue.py --exe multicor --work DIR --source REPO
"""
import argparse
import csv
import math
import re
import pathlib
import shutil
import subprocess
import sys
import time

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from slurm_local import ClusterError, LocalSlurm  # noqa: E402

from checks import check, summary

SIN_PHI, COS_PHI, T_END, G, MU2 = 0.6, 0.8, 0.5, 9.81, 0.1     # input/incline.dat


def sweep_tool(src, args, env=None):
    cmd = [sys.executable, str(src / "scripts" / "multicor-sweep")] + [str(a) for a in args]
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if proc.returncode != 0:
        print(proc.stdout, proc.stderr)
        raise SystemExit(f"{' '.join(cmd)}: exit {proc.returncode}")
    return proc


def steps_lasting(exe, src, work, seconds):
    """Steps of input/incline.dat (outputs every 100) that `exe` runs in about `seconds`, from a
    timed local run of 10 000 steps; a multiple of 10 000, at least 20 000 and at most 500 000.
    (A fixed 50 000 steps, which a Release build runs in about 0.6 s: the signal, sent 0.5 s
    after the point started, arrived after its end, and the point finished once, never
    stopped.) The timed run is the shorter: its start-up and fewer outputs make the long
    point last longer than the estimate, not shorter."""
    n = 10000
    text = (src / "input" / "incline.dat").read_text()
    text = re.sub(r"^step\s*=.*$", f"step = {0.5 / n!r}", text, count=1, flags=re.M)
    text = re.sub(r"^interval\s*=.*$", "interval = 100", text, count=1, flags=re.M)
    deck = work / "timing.dat"
    deck.write_text(text)
    t0 = time.monotonic()
    subprocess.run([str(exe), "--quiet", str(deck), "--output", str(work / "timing")], check=True,
                   capture_output=True)
    elapsed = time.monotonic() - t0
    return int(min(max(round(n * seconds / elapsed, -4), 20000), 500000))


def wait_for(what, test, timeout, cluster):
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout:
        if test():
            return True
        time.sleep(0.1)
    print(f"timeout ({timeout} s) waiting for {what}\n{cluster.query(['squeue'])}")
    return False


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--exe", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--source", required=True)
    ap.add_argument("--real-time-limit", action="store_true",
                    help="not in ctest (2-3 min): no scancel; the long point (3e6 steps) "
                    "gets --time=1 (minute) and --signal=USR1@50, so slurmctld's own "
                    "time-limit warning stops it, once or several times")
    args = ap.parse_args()
    real = args.real_time_limit
    exe = pathlib.Path(args.exe).resolve()
    src = pathlib.Path(args.source).resolve()
    work = pathlib.Path(args.work).resolve()
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)

    usage = subprocess.run([str(exe), "--help"], capture_output=True, text=True).stdout
    if "--restart" not in usage:
        print(f"skipped: {exe} --help does not list --restart: checkpoint/restart is not in "
              "this build yet, so a requeued point cannot continue")
        return 77
    cluster = LocalSlurm(work / "cluster")
    reason = cluster.unavailable()
    if reason:
        print(f"skipped: {reason}")
        return 77

    t0 = time.monotonic()
    try:
        # first: its scheduler's first pass comes about 3 s after slurmctld starts, while
        # the timed run and `create` below run
        cluster.start()
    except ClusterError as e:
        print(f"skipped: the Slurm daemons did not start: {e}")
        return 77
    reference = None
    try:
        print(f"cluster up in {time.monotonic() - t0:.1f} s ({cluster.dir})")
        steps = 3000000 if real else steps_lasting(exe, src, work, 1.5)
        print(f"the long point: {steps} steps")
        folder = work / "sweep"
        limits = ["--time", "1", "--signal-seconds", "50"] if real else ["--time", "00:05:00"]
        sweep_tool(src, ["create", src / "input" / "incline.dat", "--exe", exe,
                         "--set", f"time.step=1e-3,{0.5 / steps!r}", "--set", "output.interval=100",
                         "--scalar", "v2x=dem/velocity[-1,1,0]", "--dir", folder] + limits)
        out = sweep_tool(src, ["submit", folder], env=cluster.env).stdout
        job = out.strip().splitlines()[-1]
        partial = folder / "runs" / "p002" / "p002.h5.partial"
        # the long point runs (its results file is open): 0.2 s later, the "time-limit" signal
        running = wait_for("point 2 to run", partial.exists, 30, cluster)
        check("point 2 runs under Slurm", running, "")
        time.sleep(0.2)
        t_signal = time.monotonic()
        if not real:
            sent = subprocess.run(["scancel", "--signal=USR1", f"{job}_2"], env=cluster.env,
                                  capture_output=True, text=True)
            check("scancel --signal=USR1 reached the running point", sent.returncode == 0,
                  sent.stderr.strip())
            print(f"SIGUSR1 sent to {job}_2 {t_signal - t0:.1f} s after the cluster started")
        # the same deck run without interruption, locally, while Slurm holds the requeued task
        # back (cred_expire, 5 s): compared bit for bit below
        ref = work / "uninterrupted"
        reference = subprocess.Popen([str(exe), "--quiet", str(folder / "decks" / "p002.dat"),
                                      "--output", str(ref)], stdout=subprocess.PIPE,
                                     stderr=subprocess.STDOUT, text=True)
        log = folder / "runs" / "p002" / "job.log"
        # "requeued:" (the job script's line), not "requeue": the log's paths contain
        # the test's folder name, test_slurm_requeue
        requeued = wait_for("the requeue", lambda: log.exists() and "requeued:"
                            in log.read_text(), 90 if real else 30, cluster)
        check("point 2 stopped with exit 138 and requeued itself", requeued
              and "exit 138" in log.read_text(), log.read_text() if log.exists() else "")
        done = wait_for("the end of every job", lambda: not cluster.query(
            ["squeue", "-h", "-o", "%i"]).strip(), 400 if real else 120, cluster)
        print(f"requeued point finished {time.monotonic() - t_signal:.1f} s after the "
              f"{'start' if real else 'signal'}")
        check("every job ended", done, "")
    finally:
        cluster.stop()
        reference_output = reference.communicate()[0] if reference is not None else ""

    stop = []
    for out in sorted((folder / "logs").glob("*_2.out")):
        stop += re.findall(r"^stopped: signal SIGUSR1 at step (\d+)", out.read_text(), flags=re.M)
    stop = [int(s) for s in stop]
    check("point 2 stopped mid-run", (len(stop) >= 1 if real else len(stop) == 1)
          and all(0 < s < steps for s in stop) and stop == sorted(stop),
          f"checkpoints at steps {stop} of {steps}")
    text = log.read_text() if log.exists() else ""
    print(text)
    starts = [line for line in text.splitlines() if " start " in line]
    exits = re.findall(r" exit (\d+)$", text, flags=re.M)
    check("point 2 started again from its checkpoint after each stop (exit 138)",
          len(starts) == len(stop) + 1 and "--restart" not in starts[0]
          and all("--restart" in s and "checkpoint.h5" in s for s in starts[1:])
          and exits == ["138"] * len(stop) + ["0"], f"{len(starts)} starts, exits {exits}")
    table = folder / "results.csv"
    if not table.exists():
        check("the collect job wrote results.csv", False, "")
        return 1
    print(table.read_text())
    rows = {r["point"]: r for r in csv.DictReader(open(table, newline=""))}
    ref_vx = COS_PHI * G * (SIN_PHI - MU2 * COS_PHI) * T_END   # slipping disk 2
    for name in ("p001", "p002"):
        r = rows.get(name, {})
        vx = float(r.get("v2x") or "nan")
        # constant acceleration: exact up to round-off (<= 500000 steps: 1e-10 relative)
        check(f"{name}: finished, closed-form velocity", r.get("summary.finished") == "1"
              and math.isclose(vx, ref_vx, rel_tol=1e-10), f"vx={vx!r} closed form {ref_vx!r}")
    check("the table counts the starts of p002", rows.get("p002", {}).get("starts")
          == str(len(starts)), "")
    # Its wall time is that of the whole analysis: every start continued the count from the
    # checkpoint written at its stop (doc/cluster.md), so it covers the last start's and the
    # time in detection and in the solver, which also count every start (1e-9 s for the
    # rounding of their sums over the steps).
    r = rows.get("p002", {})
    wall = float(r.get("summary.wall_seconds") or "nan")
    last = float(r.get("summary.wall_seconds_last_run") or "nan")
    import h5py
    with h5py.File(folder / "runs" / "p002" / "p002.h5", "r") as f:
        solver = f["dem/solver"].attrs
        in_solver = float(solver["detection_seconds"]) + float(solver["solver_seconds"])
    check("p002: summary.wall_seconds covers every start (summary.runs = starts)",
          r.get("summary.runs") == str(len(starts)) and wall >= last
          and wall + 1e-9 >= in_solver,
          f"runs {r.get('summary.runs')}, wall {wall} s, last start {last} s, "
          f"detection + solver {in_solver} s")

    # the same deck run without interruption (started after the signal): the same numbers,
    # bit for bit
    if reference.returncode != 0:
        raise SystemExit(f"uninterrupted run failed: {reference_output}")
    import numpy as np
    with h5py.File(ref / "p002.h5", "r") as a, \
            h5py.File(folder / "runs" / "p002" / "p002.h5", "r") as b:
        names = []
        a["dem"].visititems(lambda k, o: names.append(k) if isinstance(o, h5py.Dataset) else None)
        differ = [k for k in names if k not in b["dem"]
                  or not np.array_equal(a["dem"][k][...], b["dem"][k][...])]
    check("requeued point = uninterrupted run, bit for bit (every dataset of /dem)",
          names and not differ, f"{len(names) - len(differ)} of {len(names)} equal; "
          f"differ: {differ}")
    return summary()


if __name__ == "__main__":
    sys.exit(main())
