#!/usr/bin/env python3
"""The takeover of a stale lock of a results folder by runs that start at once (doc/output.md,
the lock): never two live runs in one folder.

- The race a review found in the takeover by renaming (never seen before this test): a stale
  lock S (left by a dead run of this host); runs A and B both read S's line; A renamed S
  aside, removed it and made its lock L_A; B then renamed L_A aside (taking it for S), saw
  another line, and before it linked L_A back a run C made its lock at the free name; B's
  link back failed (EEXIST) and B removed L_A: A and C both ran in the folder, A without its
  lock. strace holds B with delays at entry of two calls on the lock's name: D1 at its first
  rename or removal of it (before: the rename that sets S aside; now: the removal of S, while
  B holds `.break`), D2 at its second link to it (before: the link back; now: the link of its
  own lock). A starts while B waits in D1, C while B waits in D2. A run seen holding the folder
  (its line in the lock) is stopped (SIGSTOP) until B has ended, then continued: each run
  that got the folder holds it, alive, past the others' starts, so one run at most may run
  (exit 0), the others must be refused (exit 1). Before the fix A and C both ran; now A is
  refused (B holds `.break`), C takes the lock B freed, B is refused.
- Without hard links (every link(2) fails with EPERM, injected by strace: FAT, some network
  shares) the lock and `.break` are created exclusively: a stale lock is still taken over,
  a stale `.break` broken, nothing left behind.
Usage (ctest does this): test_lock_takeover.py --exe multicor --work DIR --source REPO
"""
import os
import signal
import socket
import subprocess
import sys
import time

from checks import arguments, check, have_strace, summary

# Each delay of B, in seconds (the test waits through both). What must fit in one: a run's
# start up to its lock's decision (read the deck, build the cantilever, try the lock), 0.04
# to 0.16 s measured on the 2-core test machine with the Debug build at a load average of 8
# to 12 (other builds and tests), 0.04 to 0.29 s in 14 at a load average of 5; 2.5 s is 15 times
# the 0.16 s, 8.6 times the 0.29 s, and a missed window is a failed check (the checks
# "decided while B waited" print the time), never a pass.
DELAY = 2.5
# pid 2^22 + 1 is above Linux's largest pid (pid_max <= 2^22): no such process, a dead run
DEAD = 4194305
CALLS_RM = ["rename", "renameat", "renameat2", "unlink", "unlinkat"]
CALLS_LINK = ["link", "linkat"]


def delayed_call(log, calls, n):
    """'begun' when the strace log `log` shows the `n`-th call of `calls` begun and not yet
    returned (held by a delay), 'ended' when it returned, '' when not yet made."""
    text = log.read_text() if log.exists() else ""
    seen = 0
    for line in text.splitlines():
        words = line.split(None, 1)
        if len(words) == 2 and any(words[1].startswith(c + "(") for c in calls):
            seen += 1
            if seen == n:
                return "ended" if " = " in words[1] else "begun"
    return ""


def wait_for(what, timeout=60.0):
    """Poll `what()` every 2 ms until it is true or `timeout` seconds have passed; its last
    value. (A run holds the folder for at least the 0.1 s of its time loop, 50 times that.)"""
    end = time.monotonic() + timeout
    while True:
        value = what()
        if value or time.monotonic() > end:
            return value
        time.sleep(0.002)


def lock_pid(lock):
    """The pid of the lock's line (None without a readable lock)."""
    try:
        words = lock.read_text().split()
    except OSError:
        return None
    return int(words[1]) if len(words) >= 2 and words[1].isdigit() else None


def start_and_hold(cmd, lock):
    """Start multicor with `cmd` and wait until it holds the folder (its pid in the lock: it is
    then stopped, SIGSTOP, and keeps the folder) or has ended; (process, held, seconds it took)."""
    start = time.monotonic()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    wait_for(lambda: lock_pid(lock) == proc.pid or proc.poll() is not None)
    held = lock_pid(lock) == proc.pid and proc.poll() is None
    if held:
        os.kill(proc.pid, signal.SIGSTOP)
    return proc, held, time.monotonic() - start


def three_runs(exe, src, work):
    """A stale lock, run B held by strace at its takeover, A and C started in B's windows."""
    if not have_strace("the takeover race of three runs"):
        return
    host = socket.gethostname()
    folder = work / "three_runs"
    folder.mkdir()
    lock = folder / ".multicor.lock"
    lock.write_text(f"{host} {DEAD} 2026-01-01T00:00:00\n")
    cmd = [str(exe), str(src / "input" / "cantilever.dat"), "--output", str(folder), "--quiet", "--end", "0.05"]
    log = work / "three_runs_b.strace"
    us = int(DELAY * 1e6)
    b = subprocess.Popen(["strace", "-f", "-qq", "-e", "signal=none", "-o", str(log), "-P", str(lock),
                          "-e", "trace=" + ",".join(CALLS_RM + CALLS_LINK),
                          "-e", f"inject={','.join(CALLS_RM)}:delay_enter={us}:when=1",
                          "-e", f"inject={','.join(CALLS_LINK)}:delay_enter={us}:when=2"] + cmd,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    runs = {"B": b}
    held = {}
    in_d1 = wait_for(lambda: delayed_call(log, CALLS_RM, 1) == "begun" or b.poll() is not None) and b.poll() is None
    check("B held by strace as it removes or sets aside the stale lock (D1)", in_d1, log.read_text()[-400:])
    runs["A"], held["A"], seconds = start_and_hold(cmd, lock)
    check("A decided (took the folder or was refused) while B waited in D1",
          delayed_call(log, CALLS_RM, 1) == "begun",
          f"held {held['A']}, exit {runs['A'].poll()}, in {seconds:.2f} s of the {DELAY} s")
    in_d2 = wait_for(lambda: delayed_call(log, CALLS_LINK, 2) == "begun" or b.poll() is not None) and b.poll() is None
    check("B held by strace at its second link to the lock's name (D2)", in_d2, log.read_text()[-400:])
    runs["C"], held["C"], seconds = start_and_hold(cmd, lock)
    check("C decided while B waited in D2", delayed_call(log, CALLS_LINK, 2) == "begun",
          f"held {held['C']}, exit {runs['C'].poll()}, in {seconds:.2f} s of the {DELAY} s")
    out = {}
    out["B"] = b.communicate(timeout=300)
    for name in ("A", "C"):
        if held[name]:
            os.kill(runs[name].pid, signal.SIGCONT)
        out[name] = runs[name].communicate(timeout=300)
    codes = {name: runs[name].returncode for name in runs}
    refused = {n: codes[n] == 1 and f"results folder '{folder}' is in use by another run" in out[n][1] for n in runs}
    detail = "; ".join(f"{n}: held {held.get(n, '-')}, exit {codes[n]}, {out[n][1].strip()[-300:]!r}"
                       for n in sorted(runs))
    # A and C were seen holding the folder (their line in the lock, alive: stopped) or not;
    # B, not stopped, held it unless it was refused
    holders = [n for n in ("A", "C") if held[n]] + ([] if refused["B"] else ["B"])
    check("never two live runs in the folder: one run at most held it", len(holders) <= 1,
          f"held by {holders}; {detail}")
    ran = [n for n in sorted(runs) if not refused[n]]
    check("one run ran (exit 0), the others were refused (exit 1, the folder in use)",
          len(ran) == 1 and codes[ran[0]] == 0, detail)
    left = sorted(p.name for p in folder.iterdir() if p.name.startswith(".multicor.lock"))
    check("no lock nor lock file left", left == [], str(left))


def without_hard_links(exe, src, work):
    """A stale lock and a stale `.break`, taken over where link(2) fails (EPERM)."""
    if not have_strace("the takeover without hard links"):
        return
    host = socket.gethostname()
    folder = work / "no_hard_links"
    folder.mkdir()
    lock = folder / ".multicor.lock"
    lock.write_text(f"{host} {DEAD} 2026-01-01T00:00:00\n")
    (folder / ".multicor.lock.break").write_text(f"{host} {DEAD + 1} 2026-01-01T00:00:00\n")
    proc = subprocess.run(["strace", "-f", "-qq", "-e", "signal=none", "-o", os.devnull, "-e", "trace=link,linkat",
                           "-e", "inject=link,linkat:error=EPERM", str(exe), str(src / "input" / "cantilever.dat"),
                           "--output", str(folder), "--quiet", "--end", "0.01"], capture_output=True, text=True,
                          timeout=300)
    left = sorted(p.name for p in folder.iterdir() if p.name.startswith(".multicor.lock"))
    check("no hard links: the stale lock taken over (exit 0, the warning), the stale .break broken, nothing left",
          proc.returncode == 0 and "taking over the stale lock" in proc.stdout and left == []
          and (folder / "cantilever.h5").is_file(), f"exit {proc.returncode}, {left}, {proc.stderr.strip()[-300:]}")
    # a live run's lock is still respected
    lock.write_text(f"{host} {os.getpid()} 2026-01-01T00:00:00\n")
    proc = subprocess.run(["strace", "-f", "-qq", "-e", "signal=none", "-o", os.devnull, "-e", "trace=link,linkat",
                           "-e", "inject=link,linkat:error=EPERM", str(exe), str(src / "input" / "cantilever.dat"),
                           "--output", str(folder), "--quiet", "--end", "0.01"], capture_output=True, text=True,
                          timeout=300)
    check("no hard links: a live run's lock refuses the run and stays",
          proc.returncode == 1 and "is in use by another run" in proc.stderr and lock_pid(lock) == os.getpid(),
          f"exit {proc.returncode}, {proc.stderr.strip()[-300:]}")
    lock.unlink()


def main():
    exe, work, src = arguments(fresh=True)
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    three_runs(exe, src, work)
    without_hard_links(exe, src, work)
    sys.exit(summary())


if __name__ == "__main__":
    main()
