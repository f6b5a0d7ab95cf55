#!/usr/bin/env python3
"""The results folder's lock around a run's start and a restart (doc/output.md, the lock,
"Interrupted runs", "Checkpoints and restart"; doc/cluster.md).

- A stop signal between the lock's creation and the opening of the results file: the
  handlers were installed only after the checkpoint was read, and the signal killed the
  program holding the lock (exit -15), which then refused every later start on another host
  (a Slurm job requeued after a time limit). strace sends the signal as the lock is linked
  into place (every kind: beam static and modal, continuum static, beam and particle time
  loops, fresh and restarted), and as a restart opens its checkpoint (the audit's repro).
  Now the run stops there: exit 128 + the signal (SIGTERM 143, SIGINT 130, SIGUSR1 138,
  SIGHUP 129, SIGUSR2 140, SIGXCPU 152: LSF's warning and a CPU time limit's, which killed
  the run and left the lock before they were handled), no lock, the folder as it was (a folder the run made removed), and the same
  command then runs.
- A run killed (SIGKILL) between the creation of `.multicor.lock.<host>.<pid>` and its
  removal left it for ever: the next run that takes the lock removes it.
- A restart whose deck has another name (a copy of the same text), or whose --output is
  another folder, said the checkpoint's results were 'moved, deleted or replaced by another
  run' while they lay next to the checkpoint: the message names them and what to change.
- Another host's lock refuses a restart with the rm command of the lock (not 'choose
  another --output folder', which a restart cannot).
Usage (ctest does this): test_lock_and_restart.py --exe multicor --work DIR --source REPO
"""
import hashlib
import os
import shutil
import signal
import socket
import subprocess
import sys

from checks import arguments, check, have_strace, summary

EXIT = {"SIGTERM": 143, "SIGINT": 130, "SIGUSR1": 138, "SIGHUP": 129, "SIGUSR2": 140, "SIGXCPU": 152}


def run(exe, *args):
    """multicor with `args`."""
    return subprocess.run([str(exe)] + [str(a) for a in args], capture_output=True, text=True, timeout=300)


def under_strace(exe, path, calls, sig, *args):
    """multicor with `args`, sent `sig` by strace as it first enters one of `calls` on `path`
    (the call is done)."""
    trace = ",".join(calls)
    return subprocess.run(["strace", "-f", "-qq", "-o", os.devnull, "-P", str(path), "-e", f"trace={trace}",
                           "-e", f"inject={trace}:signal={sig}:when=1", str(exe)] + [str(a) for a in args],
                          capture_output=True, text=True, timeout=300)


def digests(folder):
    """Name -> SHA-256 of every file in `folder` (hidden ones too: the lock); {} when it does
    not exist."""
    if not folder.is_dir():
        return {}
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(folder.iterdir())}


def stopped_before_writing(exe, name, folder, proc, sig, before):
    """The checks of a run stopped by `sig` before it opened its results file."""
    err = proc.stderr.strip()
    check(f"{name}: stopped by {sig}, exit {EXIT[sig]}", proc.returncode == EXIT[sig],
          f"exit {proc.returncode}: {err[-200:]}")
    check(f"{name}: the message says it stopped before writing anything",
          f"run stopped by {sig} before it wrote anything" in err, err[-200:])
    after = digests(folder)
    check(f"{name}: no lock left, the folder as it was", after == before,
          f"before {sorted(before)}, after {sorted(after)}")


def signal_at_start(exe, src, work):
    """A stop signal as the lock is made, for every kind of run; and at a restart's reading of
    its checkpoint."""
    if not have_strace("signals at the lock's creation"):
        return
    decks = src / "tests" / "regression" / "decks"
    lock = ".multicor.lock"
    cases = [("beam_static", decks / "cantilever_static.dat", ()),
             ("beam_modal", decks / "cantilever_modal.dat", ()),
             ("continuum_static", src / "input" / "continuum_cantilever.dat", ()),
             ("beam_dynamic", src / "input" / "cantilever.dat", ("--end", "0.05")),
             ("particles_dynamic", src / "input" / "cohesive_row.dat", ("--end", "0.01"))]
    for name, deck, end in cases:
        # into a folder it makes (removed again), and into one with an earlier result (kept)
        folder = work / f"start_{name}"
        proc = under_strace(exe, folder / lock, ["link", "linkat"], "SIGTERM", deck, "--output", folder,
                            "--quiet", *end)
        stopped_before_writing(exe, f"{name}, fresh folder", folder, proc, "SIGTERM", {})
        proc = run(exe, deck, "--output", folder, "--quiet", *end)
        check(f"{name}: the same command then runs: exit 0", proc.returncode == 0, proc.stderr.strip()[-200:])
        before = digests(folder)
        proc = under_strace(exe, folder / lock, ["link", "linkat"], "SIGTERM", deck, "--output", folder,
                            "--quiet", *end)
        stopped_before_writing(exe, f"{name}, folder with a result", folder, proc, "SIGTERM", before)

    # restarts: each stop signal as the lock is made, SIGTERM as the checkpoint is opened
    deck = src / "input" / "cantilever.dat"
    folder = work / "restart"
    proc = run(exe, deck, "--output", folder, "--quiet", "--end", "0.05")
    check("restart: the first run to t = 0.05 s: exit 0", proc.returncode == 0, proc.stderr.strip()[-200:])
    before = digests(folder)
    restart = ["--output", folder, "--quiet", "--restart", folder / "checkpoint.h5", "--end", "0.1"]
    for sig in EXIT:
        proc = under_strace(exe, folder / lock, ["link", "linkat"], sig, deck, *restart)
        stopped_before_writing(exe, f"restart, {sig} as the lock is made", folder, proc, sig, before)
    proc = under_strace(exe, folder / "checkpoint.h5", ["open", "openat"], "SIGTERM", deck, *restart)
    stopped_before_writing(exe, "restart, SIGTERM as the checkpoint is opened", folder, proc, "SIGTERM", before)
    check("restart stopped: the message gives the command that continues",
          f"to continue: multicor {deck} --output {folder} --restart {folder}/checkpoint.h5 --end 0.1" in proc.stdout,
          proc.stdout.strip()[-300:])
    proc = run(exe, deck, *restart)
    check("restart: the same command then continues the run: exit 0",
          proc.returncode == 0 and (folder / "cantilever.h5").is_file() and not (folder / lock).exists(),
          proc.stderr.strip()[-200:])


def killed_at_link(exe, src, work):
    """SIGKILL between the creation of the lock's line file and its removal."""
    if not have_strace("a kill at the lock's link"):
        return
    deck = src / "input" / "cantilever.dat"
    folder = work / "killed_at_link"
    folder.mkdir()
    proc = subprocess.run(["strace", "-f", "-qq", "-o", os.devnull, "-P", str(folder / ".multicor.lock"),
                           "-e", "trace=link,linkat", "-e", "inject=link,linkat:signal=SIGKILL:when=1",
                           str(exe), str(deck), "--output", str(folder), "--quiet", "--end", "0.01"],
                          capture_output=True, text=True, timeout=300)
    left = sorted(p.name for p in folder.iterdir() if p.name.startswith(".multicor.lock."))
    check("killed at the lock's link: its line's file is left", proc.returncode in (-9, 137) and len(left) == 1,
          f"exit {proc.returncode}, {left}")
    # a live process's file and another host's stay
    alive = folder / f".multicor.lock.{socket.gethostname()}.1"
    other = folder / ".multicor.lock.nodeB01.4194305"
    alive.write_text("")
    other.write_text("")
    proc = run(exe, deck, "--output", folder, "--quiet", "--end", "0.01")
    names = sorted(p.name for p in folder.iterdir() if p.name.startswith(".multicor.lock"))
    check("the next run removes the dead run's file, keeps a live process's and another host's",
          proc.returncode == 0 and names == sorted([alive.name, other.name]), f"exit {proc.returncode}, {names}")


def results_elsewhere(exe, src, work):
    """A restart of a renamed copy of the deck, or into another --output folder."""
    folder = work / "renamed"
    folder.mkdir()
    shutil.copy(src / "input" / "cantilever.dat", folder / "cant.dat")
    shutil.copy(src / "input" / "cantilever.dat", folder / "cant_v2.dat")
    out = folder / "out"
    proc = run(exe, folder / "cant.dat", "--output", out, "--quiet", "--end", "0.05")
    check("renamed deck: the first run: exit 0", proc.returncode == 0, proc.stderr.strip()[-200:])
    before = digests(out)
    proc = run(exe, folder / "cant_v2.dat", "--quiet", "--restart", out / "checkpoint.h5", "--end", "0.1")
    err = proc.stderr.strip()
    check("renamed deck: refused, naming the checkpoint's results and the deck name to use",
          proc.returncode == 1 and f"the results of the checkpoint's run are '{out}/cant.h5'" in err and
          "the results file's name follows the deck's file name" in err and f"run the deck as {folder}/cant.dat" in err
          and "moved, deleted or replaced" not in err, err[-400:])
    proc = run(exe, folder / "cant.dat", "--quiet", "--restart", out / "checkpoint.h5", "--output",
               folder / "elsewhere", "--end", "0.1")
    err = proc.stderr.strip()
    check("other --output: refused, naming the checkpoint's results and its folder",
          proc.returncode == 1 and f"the results of the checkpoint's run are '{out}/cant.h5'" in err and
          f"the results folder is the checkpoint's ({out})" in err and "moved, deleted or replaced" not in err
          and not (folder / "elsewhere").exists(), err[-400:])
    check("both refusals leave the checkpoint's folder as it was", digests(out) == before, "")
    # the results really gone: the message stays the one of a moved file
    shutil.move(out / "cant.h5", folder / "moved.h5")
    proc = run(exe, folder / "cant.dat", "--quiet", "--restart", out / "checkpoint.h5", "--end", "0.1")
    check("results moved away: still 'moved, deleted or replaced'",
          proc.returncode == 1 and "moved, deleted or replaced" in proc.stderr, proc.stderr.strip()[-300:])


def another_hosts_lock(exe, src, work):
    """A lock left by a job killed with its node, found by the requeued job on another host."""
    deck = src / "input" / "cantilever.dat"
    folder = work / "other_host"
    proc = run(exe, deck, "--output", folder, "--quiet", "--end", "0.05")
    check("other host's lock: the first run: exit 0", proc.returncode == 0, proc.stderr.strip()[-200:])
    (folder / ".multicor.lock").write_text("nodeB01 22344 2026-11-28T05:50:58\n")
    proc = run(exe, deck, "--output", folder, "--quiet", "--restart", folder / "checkpoint.h5", "--end", "0.1")
    err = proc.stderr.strip()
    check("restart refused by another host's lock: the rm command, no other --output",
          proc.returncode == 1 and f"remove the lock (rm {folder}/.multicor.lock)" in err and
          "ps -p 22344" in err and "--output folder" not in err, err[-400:])
    proc = run(exe, deck, "--output", folder, "--quiet", "--end", "0.05")
    check("fresh run refused by it: the rm command, or another --output folder",
          proc.returncode == 1 and f"(rm {folder}/.multicor.lock)" in proc.stderr and
          "another --output folder" in proc.stderr, proc.stderr.strip()[-400:])


def main():
    exe, work, src = arguments(fresh=True)
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    # the stop signals' default actions in the runs (a test started under nohup ignores SIGHUP)
    for sig in (signal.SIGHUP, signal.SIGINT):
        signal.signal(sig, signal.SIG_DFL)
    signal_at_start(exe, src, work)
    killed_at_link(exe, src, work)
    results_elsewhere(exe, src, work)
    another_hosts_lock(exe, src, work)
    sys.exit(summary())


if __name__ == "__main__":
    main()
