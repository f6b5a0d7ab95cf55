#!/usr/bin/env python3
"""scripts/multicor-sweep against a real Slurm (slurmctld + slurmd + munged started here on
localhost, tests/regression/slurm_local.py), and locally without Slurm.

A 2 x 2 sweep of input/incline.dat: friction of the lower disk mu in {0.1, 0.4} times
gravity gy in {-9.81, -4.905}. With mu = 0.1 < tan(phi)/3 = 0.25 the disk slips,
a = g (sin phi - mu cos phi); with mu = 0.4 it rolls, a = (2/3) g sin phi (the deck's header
derives both). The sweep is submitted as a job array plus the collect job that depends on
it; the table they write (results.csv) must hold the four points, finished, with the final
velocity of disk 2 equal to the closed form, and the same values as the same sweep run
locally (`run -j 2`); its folder has a space in its path. scripts/multicor.slurm runs one
deck as a job. A resubmission keeps the cap of --max-running and skips the points that an
earlier job holds pending; a point submitted twice (--force) while it runs is refused by the
folder lock without changing its exit_status; cancelled, the point keeps 'running' there.
The collect job goes to the partition given to submit, within the array's time limit.
(test_sweep.py tests
the tool without Slurm: keys refused, decks written, failures.)
Skips (exit 77, reason printed) when not root or when slurm-wlm / munge are missing.
Usage (ctest does this): test_slurm_sweep.py --exe multicor --work DIR --source REPO
"""
import csv
import math
import pathlib
import subprocess
import sys
import time

import h5py

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from slurm_local import ClusterError, LocalSlurm  # noqa: E402

from checks import arguments, check, summary

SIN_PHI, COS_PHI, T_END = 0.6, 0.8, 0.5      # input/incline.dat


def sweep_tool(src, args, env=None, expect=0):
    cmd = [sys.executable, str(src / "scripts" / "multicor-sweep")] + [str(a) for a in args]
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if expect is not None and proc.returncode != expect:
        print(proc.stdout, proc.stderr)
        raise SystemExit(f"{' '.join(cmd)}: exit {proc.returncode}, expected {expect}")
    return proc


def closed_form_vx(mu, gy):
    """x velocity of disk 2 at T_END: slipping (mu < tan(phi)/3) or rolling."""
    g = -gy
    a = g * (SIN_PHI - mu * COS_PHI) if mu < SIN_PHI / COS_PHI / 3 else 2 / 3 * g * SIN_PHI
    return COS_PHI * a * T_END


def read_table(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def check_table(name, rows):
    check(f"{name}: four points", len(rows) == 4, f"{len(rows)} rows")
    for r in rows:
        mu, gy = float(r["contacts.law[2].mu"]), float(r["particles.gravity.gy"])
        vx, ref = float(r["v2x"] or "nan"), closed_form_vx(mu, gy)
        # Constant acceleration from the first step on: Moreau-Jean integrates it exactly,
        # up to round-off over 500 steps (1e-12 relative is ~5000 ulps).
        check(f"{name}: {r['point']} mu={mu} gy={gy}",
              r["summary.finished"] == "1" and r["exit_status"] == "0"
              and math.isclose(vx, ref, rel_tol=1e-12),
              f"finished={r['summary.finished']} vx={vx!r} closed form {ref!r}")


def create(src, exe, folder):
    return sweep_tool(src, ["create", src / "input" / "incline.dat", "--exe", exe,
                            "--set", "contacts.law[2].mu=0.1,0.4",
                            "--set", "particles.gravity.gy=-9.81,-4.905",
                            "--scalar", "v2x=dem/velocity[-1,1,0]",
                            "--scalar", "balance=absmax(dem/energy/balance)",
                            "--time", "00:05:00", "--dir", folder])


def wait_idle(cluster, timeout):
    """Until no job is pending or running; False on timeout."""
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout:
        if not cluster.query(["squeue", "-h", "-o", "%i"]).strip():
            return True
        time.sleep(0.2)
    return False


def submit_on_slurm(src, exe, work, cluster):
    """Start the cluster and submit the sweep and scripts/multicor.slurm; None, or why the
    Slurm part cannot run here. The jobs run while the local sweep does (main)."""
    reason = cluster.unavailable()
    if reason:
        return reason
    # a folder with a space: its #SBATCH --output line (before: "Invalid directive")
    folder = work / "slurm sweep"
    create(src, exe, folder)
    script = (folder / "sweep.slurm").read_text()
    check("job script: array, USR1 before the limit, requeue",
          "#SBATCH --array=1-4" in script and "#SBATCH --signal=USR1@120" in script
          and "#SBATCH --requeue" in script and "--restart" in script, "")
    t0 = time.monotonic()
    try:
        cluster.start()
    except ClusterError as e:
        return f"the Slurm daemons did not start: {e}"
    print(f"cluster up in {time.monotonic() - t0:.1f} s ({cluster.dir})")
    proc = sweep_tool(src, ["submit", folder], env=cluster.env)
    print(proc.stdout.strip())
    env = dict(cluster.env, MULTICOR_EXE=str(exe))
    proc = subprocess.run(["sbatch", "--parsable", "--time=5", f"--output={work / 'single.out'}",
                           str(src / "scripts" / "multicor.slurm"),
                           str(src / "input" / "incline.dat"), str(work / "single")],
                          capture_output=True, text=True, env=env, cwd=src)
    check("scripts/multicor.slurm submitted", proc.returncode == 0, proc.stderr.strip())
    # (a task may have ended already: the logs and the table are checked below)
    print(cluster.query(["squeue", "-h", "-r", "-o", "%i %j %T"]).strip())
    return None


def on_slurm(src, exe, work, cluster, t0):
    """The end of the jobs submitted by submit_on_slurm, then the other Slurm checks; the
    Slurm table's rows (t0: the test's start, monotonic)."""
    folder = work / "slurm sweep"
    single = work / "single"
    env = dict(cluster.env, MULTICOR_EXE=str(exe))
    try:
        done = wait_idle(cluster, 120)
        print(f"array and collect job done {time.monotonic() - t0:.1f} s after the test's start")
        check("all jobs ended within 120 s", done, cluster.query(["squeue"]))
        # The same job submitted again once the run finished (its final checkpoint is in the
        # folder): a fresh run, not a restart with nothing to do (exit 1).
        first = (single / "incline.h5").stat().st_mtime_ns if (single / "incline.h5").exists() else None
        again = subprocess.run(["sbatch", "--parsable", "--time=5", f"--output={work / 'again.out'}",
                                str(src / "scripts" / "multicor.slurm"),
                                str(src / "input" / "incline.dat"), str(single)],
                               capture_output=True, text=True, env=env, cwd=src)
        check("scripts/multicor.slurm submitted again", again.returncode == 0, again.stderr.strip())
        done = wait_idle(cluster, 60)
        log = (work / "again.out").read_text() if (work / "again.out").exists() else "no job output"
        starts = [line for line in log.splitlines() if " start (restart count" in line]
        check("scripts/multicor.slurm again after the end: a fresh run (no --restart), exit 0, new results",
              done and "multicor exit 0" in log and len(starts) == 1 and "--restart" not in starts[0]
              and first is not None
              and (single / "incline.h5").stat().st_mtime_ns > first, log[-400:])
        resubmission(src, exe, work, cluster)
        duplicate(src, exe, work, cluster)
        empty_lock(src, exe, work, cluster)
        collect_partition(src, exe, work, cluster)
    finally:
        cluster.stop()
    try:
        with h5py.File(single / "incline.h5", "r") as f:
            finished = int(f["summary"].attrs["finished"])
    except OSError as e:
        finished = str(e)
    check("scripts/multicor.slurm ran input/incline.dat to its end", finished == 1,
          f"finished={finished}; " + ((work / "single.out").read_text()[-400:]
                                      if (work / "single.out").exists() else "no job output"))
    logs = sorted((folder / "logs").glob("*"))
    check("one Slurm log per task and the collect log", len(logs) == 5,
          " ".join(p.name for p in logs))
    table = folder / "results.csv"
    if not table.exists():
        check("the collect job wrote results.csv", False,
              "; ".join(p.read_text()[-300:] for p in logs if "collect" in p.name))
        return None
    print(table.read_text())
    rows = read_table(table)
    check_table("Slurm", rows)
    check("the collect job drew results.png", (folder / "results.png").stat().st_size > 1000
          if (folder / "results.png").exists() else False, "")
    return rows


def resubmission(src, exe, work, cluster):
    """A resubmission keeps the cap of --max-running (before, its --array=2-3 replaced the
    script's 1-3%1); a point that an earlier job holds pending is not submitted again, and
    status does not advise it. The array is held (--hold): nothing runs."""
    folder = work / "throttle"
    sweep_tool(src, ["create", src / "input" / "incline.dat", "--exe", exe,
                     "--set", "contacts.law[2].mu=0.1,0.2,0.3", "--max-running", "1",
                     "--time", "5", "--dir", folder])
    (folder / "runs" / "p001").mkdir(parents=True)
    (folder / "runs" / "p001" / "exit_status").write_text("0\n")    # as if finished
    job = sweep_tool(src, ["submit", "--no-collect", folder, "--hold"],
                     env=cluster.env).stdout.strip().splitlines()[-1]
    shown = cluster.query(["scontrol", "show", "job", job])
    check("resubmission of p002, p003 with --max-running 1: ArrayTaskId=2-3%1, throttle 1",
          "ArrayTaskId=2-3%1" in shown and "ArrayTaskThrottle=1" in shown, shown[:300])
    status = sweep_tool(src, ["status", folder], env=cluster.env).stdout
    check("status: p002, p003 pending; wait, no advice to submit", "p002 pending" in status
          and "p003 pending" in status and "wait for them" in status
          and "submit" not in status, status)
    again = sweep_tool(src, ["submit", "--no-collect", folder], env=cluster.env).stdout
    check("submit again: nothing (p002, p003 pending in the earlier job)",
          "nothing to submit" in again and f"p002 (pending, job {job})" in again, again)
    cluster.query(["scancel", job])
    wait_idle(cluster, 30)
    status = sweep_tool(src, ["status", folder], env=cluster.env).stdout
    check("status once the job is cancelled: advises submit", "continue the others" in status,
          status)


def duplicate(src, exe, work, cluster):
    """A point submitted again while it runs (submit --force): multicor's lock refuses the
    second start, which leaves exit_status to the running start (before: it wrote 1, and
    status called the running point failed, collect counted 2 starts). Cancelled, the point
    keeps 'running' in exit_status: status calls it started."""
    folder = work / "duplicate"
    sweep_tool(src, ["create", src / "input" / "incline.dat", "--exe", exe,
                     "--set", "time.step=1e-7", "--set", "output.interval=1000000",
                     "--time", "5", "--dir", folder])
    out = folder / "runs" / "p001"
    job = sweep_tool(src, ["submit", "--no-collect", folder], env=cluster.env).stdout.split()[-1]
    t0 = time.monotonic()
    while time.monotonic() - t0 < 30 and not (out / "p001.h5.partial").exists():
        time.sleep(0.2)
    second = sweep_tool(src, ["submit", "--force", "--no-collect", folder],
                        env=cluster.env).stdout.split()[-1]
    log = out / "job.log"
    t0 = time.monotonic()
    while time.monotonic() - t0 < 30 and " refused " not in (log.read_text() if log.exists() else ""):
        time.sleep(0.2)
    text = log.read_text() if log.exists() else ""
    status = (out / "exit_status").read_text().strip() if (out / "exit_status").exists() else ""
    check("the second start (submit --force) refused by the lock: logged, exit_status kept",
          f"p001 refused {second}" in text and status == "running", f"{status!r}\n{text}")
    state = sweep_tool(src, ["status", folder], env=cluster.env).stdout
    check("status: p001 running", "p001 running" in state, state)
    cluster.query(["scancel", job])
    wait_idle(cluster, 30)
    state = sweep_tool(src, ["status", folder], env=cluster.env).stdout
    # (scancel's SIGTERM: multicor may write a checkpoint before it stops)
    check("cancelled: exit_status stays 'running', status says started or checkpoint",
          ("p001 started" in state or "p001 checkpoint" in state)
          and (out / "exit_status").read_text().strip() == "running", state)
    sweep_tool(src, ["collect", "--no-plot", folder])
    rows = read_table(folder / "results.csv")
    check("collect: one start, exit_status running", rows and rows[0]["starts"] == "1"
          and rows[0]["exit_status"] == "running", str(rows))


def collect_partition(src, exe, work, cluster):
    """`submit SWEEP --partition=other` on a cluster whose default partition is inactive:
    the collect job must go to the array's partition, with a time limit the partition allows
    (the array's 3 minutes under MaxTime=5). Before: the collect job went to the default
    partition with --time=10, sbatch refused it ('Required partition not available'), and
    the array, submitted, was not recorded in sweep.json. Both jobs held: nothing runs."""
    folder = work / "collect partition"
    sweep_tool(src, ["create", src / "input" / "incline.dat", "--exe", exe,
                     "--set", "time.end=0.1,0.2", "--time", "3", "--dir", folder])
    cluster.query(["scontrol", "create", "PartitionName=other", f"Nodes={cluster.NODE}",
                   "MaxTime=5"],
                  check=True)
    cluster.query(["scontrol", "update", f"PartitionName={cluster.PARTITION}", "State=INACTIVE"],
                  check=True)
    try:
        proc = sweep_tool(src, ["submit", folder, "--partition=other", "--hold"], env=cluster.env,
                          expect=None)
        jobs = cluster.query(["squeue", "-h", "-o", "%i %j %P %l"])
        print(jobs.strip())
        collect = [line.split() for line in jobs.splitlines() if "multicor-collect" in line]
        check("submit --partition=other: the collect job in partition other, its time limit the "
              "array's (3:00, MaxTime 5)", proc.returncode == 0 and len(collect) == 1
              and collect[0][2:] == ["other", "3:00"], proc.stdout + proc.stderr + jobs)
    finally:
        cluster.query(["scancel", "--partition=other"])
        wait_idle(cluster, 30)
        cluster.query(["scontrol", "update", f"PartitionName={cluster.PARTITION}", "State=UP"])
        cluster.query(["scontrol", "delete", "PartitionName=other"])


def locally(src, exe, work):
    folder = work / "local"
    create(src, exe, folder)
    t0 = time.monotonic()
    proc = sweep_tool(src, ["run", folder, "-j", "2"])
    print(proc.stdout.strip())
    print(f"local run -j 2: {time.monotonic() - t0:.1f} s")
    rows = read_table(folder / "results.csv")
    check_table("local", rows)
    # (--no-collect: the table is the first run's; the points it would run are decided before)
    again = sweep_tool(src, ["run", folder, "-j", "2", "--no-collect"])
    check("a second local run has nothing to do", "4 points finished before, 0 to run"
          in again.stdout, again.stdout.strip().splitlines()[0])
    return rows


def empty_lock(src, exe, work, cluster):
    """A point whose folder holds an empty lock (left by an earlier multicor killed as it
    created it): multicor refuses it with the command to remove it (exit 1), and the job
    script records the failure (exit_status 1, 'exit 1' in job.log, status failed). Before,
    the script took any lock left after exit 1 for another run's: 'refused', exit_status left
    'running' for ever."""
    folder = work / "empty_lock"
    sweep_tool(src, ["create", src / "input" / "incline.dat", "--exe", exe, "--set", "time.end=0.1",
                     "--time", "5", "--dir", folder])
    out = folder / "runs" / "p001"
    out.mkdir(parents=True)
    (out / ".multicor.lock").write_text("")
    sweep_tool(src, ["submit", "--no-collect", folder], env=cluster.env)
    status_file = out / "exit_status"
    t0 = time.monotonic()
    while time.monotonic() - t0 < 30 and (not status_file.exists() or status_file.read_text().strip() == "running"):
        time.sleep(0.2)
    wait_idle(cluster, 30)
    text = (out / "job.log").read_text() if (out / "job.log").exists() else ""
    status = status_file.read_text().strip() if status_file.exists() else ""
    state = sweep_tool(src, ["status", folder], env=cluster.env).stdout
    check("an empty lock in the point's folder: exit_status 1, 'exit 1' logged, status failed",
          status == "1" and "p001 exit 1" in text and " refused " not in text and "p001 failed" in state,
          f"{status!r}\n{text}\n{state}")


def main():
    exe, work, src = arguments(fresh=True)
    t0 = time.monotonic()
    cluster = LocalSlurm(work / "cluster")
    try:
        reason = submit_on_slurm(src, exe, work, cluster)
        # the local sweep runs while Slurm starts its jobs (its scheduler's first pass comes
        # about 3 s after slurmctld starts) and runs them
        local_rows = locally(src, exe, work)
        slurm_rows = reason if reason else on_slurm(src, exe, work, cluster, t0)
    finally:
        cluster.stop()
    if isinstance(slurm_rows, list):
        same = [(a["point"], a["v2x"], b["v2x"]) for a, b in zip(local_rows, slurm_rows)
                if a["v2x"] != b["v2x"]]
        check("Slurm and local tables: same values (same executable and decks)",
              not same and len(slurm_rows) == 4, str(same))
    print(f"total {time.monotonic() - t0:.1f} s")
    if summary():
        return 1
    if isinstance(slurm_rows, str):
        print(f"skipped: the Slurm part: {slurm_rows} (the local part passed)")
        return 77
    return 0


if __name__ == "__main__":
    sys.exit(main())
