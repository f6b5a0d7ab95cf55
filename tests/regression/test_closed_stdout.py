#!/usr/bin/env python3
"""A run whose standard output is a pipe without reader (`multicor deck.dat | head -1`, a
`tee` that died): the printed lines are progress, not results, so the run goes on without
printing and ends as it would have (doc/output.md, "Interrupted runs"): exit 0, the finished
results file, the checkpoint of a dynamic run, no lock left; a stop signal then stops it as
usual (exit 128 + signal, its partial file and checkpoint, the lock released).

Before: SIGPIPE killed the program at its first write after the reader had gone (exit 141
in the shell), leaving `<name>.h5.partial` and the folder's `.multicor.lock`.
Usage (ctest does this): test_closed_stdout.py --exe multicor --work DIR --source REPO
"""
import os
import signal
import subprocess
import sys
import time

import h5py

from checks import arguments, check, summary

BEAM = """[beam]
section = 1 2.1e11 7800 2.0e-4 1.6666666666666667e-9
line = 1 0 0 1 0 10 1
fix = 1 all
load = 11 w -10
"""

STATIC = "[run]\nanalysis = static\n" + BEAM

# 4000 steps with a progress line every 10 ms of wall time: lines go on being written long
# after the first one has been read (the run lasts about 0.1 s or more)
DYNAMIC = ("[run]\nanalysis = dynamic\n" + BEAM + "[time]\nstep = 1e-4\nend = {end}\n"
           "[output]\ninterval = 100\nprogress = 0.01\n")


def closed_pipe():
    """A pipe whose reading end is closed: a write to the other end fails (EPIPE, SIGPIPE)."""
    r, w = os.pipe()
    os.close(r)
    return w


def finished_folder(name, folder, stem, dynamic):
    """The folder of a run that ended: its finished results, its checkpoint for a dynamic
    run, no partial file, no lock."""
    results = folder / f"{stem}.h5"
    done = False
    if results.exists():
        with h5py.File(results, "r") as f:
            done = int(f["summary"].attrs["finished"]) == 1
    left = sorted(p.name for p in folder.iterdir())
    expected = sorted([f"{stem}.h5", f"{stem}.xdmf"] + (["checkpoint.h5"] if dynamic else []))
    return check(f"{name}: finished results, no partial file, no lock", done and left == expected, f"folder {left}")


def closed_from_the_start(exe, work):
    """Standard output (and, second, standard error too) a pipe closed before the run."""
    for name, text, dynamic in (("static", STATIC, False), ("dynamic", DYNAMIC.format(end="0.05"), True)):
        for streams in ("stdout", "stdout+stderr"):
            deck = work / f"{name}.dat"
            deck.write_text(text)
            folder = work / f"closed_{name}_{streams.replace('+', '_')}"
            w = closed_pipe()
            proc = subprocess.run([str(exe), str(deck), "--output", str(folder)], stdout=w,
                                  stderr=w if streams == "stdout+stderr" else subprocess.PIPE, timeout=300)
            os.close(w)
            err = (proc.stderr or b"").decode(errors="replace")
            check(f"{name}, {streams} closed: exit 0, nothing on stderr", proc.returncode == 0 and not err,
                  f"exit {proc.returncode}, stderr {err.strip()[-300:]!r}")
            finished_folder(f"{name}, {streams} closed", folder, name, dynamic)


def reader_leaves(exe, work):
    """`multicor deck.dat | head -1`: the first line is read, then the reader goes."""
    deck = work / "dynamic_long.dat"
    deck.write_text(DYNAMIC.format(end="0.4"))
    folder = work / "head"
    proc = subprocess.Popen([str(exe), str(deck), "--output", str(folder)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE)
    first = proc.stdout.readline().decode()
    proc.stdout.close()
    start = time.monotonic()
    err = proc.stderr.read().decode(errors="replace")
    proc.wait(timeout=300)
    check("head -1: the first line is a progress line of the run", first.startswith("step ") and "/4000 " in first,
          repr(first))
    check("head -1: exit 0, nothing on stderr", proc.returncode == 0 and not err,
          f"exit {proc.returncode} {time.monotonic() - start:.2f} s after the reader left, stderr {err[-300:]!r}")
    finished_folder("head -1", folder, "dynamic_long", True)


def stopped_after_reader_left(exe, work, sig=signal.SIGTERM):
    """Standard output and error closed, then SIGTERM: the documented stop (exit 143, the
    partial file and the checkpoint of the stop step, the lock released). SIGHUP, the
    terminal of an interactive run closed, stops it the same way (exit 129), where it killed
    the program before (exit -1 to Python: no checkpoint of the stop step, the lock left)."""
    deck = work / "dynamic_stop.dat"
    deck.write_text(DYNAMIC.format(end="100.0"))
    folder = work / f"stop_{sig.name}"
    partial = folder / "dynamic_stop.h5.partial"
    w = closed_pipe()
    proc = subprocess.Popen([str(exe), str(deck), "--output", str(folder)], stdout=w, stderr=w)
    os.close(w)
    deadline = time.monotonic() + 60
    # the partial file exists once the stop signals are caught; wait for a few progress
    # lines (each one a failed write) before the signal
    while not partial.exists() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.01)
    time.sleep(0.1)
    proc.send_signal(sig)
    proc.wait(timeout=300)
    left = sorted(p.name for p in folder.iterdir()) if folder.exists() else []
    step, status = -1, ""
    if (folder / "checkpoint.h5").exists():
        with h5py.File(folder / "checkpoint.h5", "r") as f:
            step = int(f["loop"].attrs["step"])
    if partial.exists():
        with h5py.File(partial, "r") as f:
            status = f["summary"].attrs["status"]
            status = status.decode() if isinstance(status, bytes) else status
    check(f"stopped by {sig.name} with stdout closed: exit {128 + sig.value}, partial file and checkpoint of "
          "the stop step, no lock",
          proc.returncode == 128 + sig.value and left == ["checkpoint.h5", "dynamic_stop.h5.partial"] and step > 0
          and status.startswith(f"signal {sig.name} at step {step},"),
          f"exit {proc.returncode}, folder {left}, checkpoint step {step}, status {status!r}")


def nohup(exe, work):
    """Under `nohup` (SIGHUP ignored when the program starts) a SIGHUP does not stop the run:
    the program leaves an ignored SIGHUP ignored (a run meant to outlive its terminal). The
    run (4 000 steps to 0.4 s) then ends as it would have."""
    deck = work / "dynamic_nohup.dat"
    deck.write_text(DYNAMIC.format(end="0.4"))
    folder = work / "nohup"
    w = closed_pipe()
    proc = subprocess.Popen([str(exe), str(deck), "--output", str(folder)], stdout=w, stderr=w,
                            preexec_fn=lambda: signal.signal(signal.SIGHUP, signal.SIG_IGN))
    os.close(w)
    deadline = time.monotonic() + 60
    while not (folder / "dynamic_nohup.h5.partial").exists() and proc.poll() is None \
            and time.monotonic() < deadline:
        time.sleep(0.01)
    proc.send_signal(signal.SIGHUP)
    proc.wait(timeout=300)
    check("nohup: SIGHUP ignored, exit 0", proc.returncode == 0, f"exit {proc.returncode}")
    finished_folder("nohup", folder, "dynamic_nohup", True)


def main():
    exe, work, _ = arguments(fresh=True)
    closed_from_the_start(exe, work)
    reader_leaves(exe, work)
    stopped_after_reader_left(exe, work)
    stopped_after_reader_left(exe, work, signal.SIGHUP)
    nohup(exe, work)
    return summary()


if __name__ == "__main__":
    sys.exit(main())
