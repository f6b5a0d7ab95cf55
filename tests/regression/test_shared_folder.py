#!/usr/bin/env python3
"""A static or modal analysis run into a folder holding another deck's checkpoint: it writes
no checkpoint, so it neither warns that it replaces that checkpoint nor refuses to run when
that checkpoint's run is interrupted (doc/output.md, "Checkpoints and restart"). The
checkpoint stays byte for byte, and the run it belongs to is still extended (`--restart
--end`) or continued (the command it printed) from it. A dynamic run of another deck still
gets the warning (it does replace the checkpoint).

Before: every fresh run checked the folder's checkpoint, and a static beam run after a
particle run printed "warning: this run replaces shared/checkpoint.h5, the checkpoint of
another deck's run (dyn_disks.h5), which can then no longer be extended", which was false.
Usage (ctest does this): test_shared_folder.py --exe multicor --work DIR --source REPO
"""
import hashlib
import pathlib
import re
import signal
import subprocess
import sys
import time

import h5py

from checks import arguments, check, summary

PARTICLES = """[run]
analysis = dynamic
[particles]
material = 1 2500
row = 5 0 0.01 0.01 1
gravity = 0 -9.81
[walls]
wall = -1 0 1 0
[contacts]
law = 1 1 0.5 0 0
[time]
step = 1e-3
end = 0.01
"""

# The runs stopped or killed mid-way: 10 000 steps, which the test stops at their start, an
# output every 1 000 (at every step, the default, the 2 000 steps they had took 2.5 s of CPU in
# the Debug build and their continuations as much; now 0.5 s each)
LONG_PARTICLES = PARTICLES.replace("end = 0.01", "end = 10.0") + "[output]\ninterval = 1000\n"

BEAM = """[beam]
section = 1 2.1e11 7800 2.0e-4 1.6666666666666667e-9
line = 1 0 0 1 0 10 1
fix = 1 all
"""

CONTINUUM = """[continuum]
mesh = rectangle 0 -0.1 1 0.2 10 2 q4
material = 70e9 0.3 2700 0.1 plane_stress
fix = left x y
"""

# The four analyses without a time loop: beam and continuum, static and modal.
NO_TIME_LOOP = {
    "static_beam": "[run]\nanalysis = static\n" + BEAM + "load = 11 w -10\n",
    "modal_beam": "[run]\nanalysis = modal\n" + BEAM + "[modal]\nmodes = 2\n",
    "static_continuum": "[run]\nanalysis = static\n" + CONTINUUM + "traction = right 0 1000 uniform\n",
    "modal_continuum": "[run]\nanalysis = modal\n" + CONTINUUM + "[modal]\nmodes = 2\n",
}

DYNAMIC_BEAM = "[run]\nanalysis = dynamic\n" + BEAM + "load = 11 w -10\n[time]\nstep = 2e-4\nend = 2e-3\n"


def multicor(exe, *args):
    return subprocess.run([str(exe), *map(str, args)], capture_output=True, text=True, timeout=300)


def digest(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


def finished(path):
    with h5py.File(path, "r") as f:
        return int(f["summary"].attrs["finished"]) == 1


def after_finished_run(exe, work):
    """The folder's checkpoint is that of a finished particle run: each analysis without a
    time loop runs without the warning and leaves it; `--restart --end` then extends it."""
    folder = work / "finished"
    (work / "dyn_disks.dat").write_text(PARTICLES)
    first = multicor(exe, work / "dyn_disks.dat", "--output", folder, "--quiet")
    if not check("particle run", first.returncode == 0, first.stderr.strip()[-300:]):
        return
    checkpoint = folder / "checkpoint.h5"
    before = digest(checkpoint)
    for name, text in NO_TIME_LOOP.items():
        (work / f"{name}.dat").write_text(text)
        proc = multicor(exe, work / f"{name}.dat", "--output", folder)
        check(f"{name}: exit 0, no warning about the checkpoint",
              proc.returncode == 0 and "checkpoint" not in proc.stdout + proc.stderr
              and finished(folder / f"{name}.h5"),
              f"exit {proc.returncode}, {(proc.stdout + proc.stderr).strip()[:300]!r}")
        check(f"{name}: checkpoint unchanged", digest(checkpoint) == before, "")
    extend = multicor(exe, work / "dyn_disks.dat", "--output", folder, "--restart", checkpoint, "--end", "0.02",
                      "--quiet")
    with h5py.File(folder / "dyn_disks.h5", "r") as f:
        steps = int(f["summary"].attrs["steps"])
    check("the particle run is extended to 0.02 s", extend.returncode == 0 and steps == 20,
          f"exit {extend.returncode}, steps {steps}, {extend.stderr.strip()[-300:]!r}")
    # a run with a time loop does replace it: the warning stays
    (work / "dynamic_beam.dat").write_text(DYNAMIC_BEAM)
    proc = multicor(exe, work / "dynamic_beam.dat", "--output", folder, "--quiet")
    check("a dynamic beam run still warns", proc.returncode == 0 and "warning: this run replaces" in proc.stdout,
          f"exit {proc.returncode}, {proc.stdout.strip()[:300]!r}")


def after_interrupted_run(exe, work):
    """The folder's checkpoint is that of a particle run stopped by SIGTERM (its results
    still '.partial'): a static or modal run is not refused, leaves the checkpoint and the
    partial file, and the particle run is continued to its end from them."""
    folder = work / "interrupted"
    deck = work / "long_disks.dat"
    deck.write_text(LONG_PARTICLES)
    partial = folder / "long_disks.h5.partial"
    proc = subprocess.Popen([str(exe), str(deck), "--output", str(folder), "--quiet"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    while not partial.exists() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.01)
    proc.send_signal(signal.SIGTERM)
    out, err = proc.communicate(timeout=300)
    if not check("particle run stopped by SIGTERM", proc.returncode == 143 and partial.exists(),
                 f"exit {proc.returncode}, {err.strip()[-300:]!r}"):
        return
    checkpoint = folder / "checkpoint.h5"
    before = digest(checkpoint)
    for name in ("static_beam", "modal_continuum"):
        (work / f"{name}.dat").write_text(NO_TIME_LOOP[name])
        run = multicor(exe, work / f"{name}.dat", "--output", folder, "--quiet")
        check(f"{name} beside an interrupted run: exit 0, checkpoint and partial file kept",
              run.returncode == 0 and digest(checkpoint) == before and partial.exists(),
              f"exit {run.returncode}, {(run.stdout + run.stderr).strip()[:300]!r}")
    run = multicor(exe, deck, "--output", folder, "--restart", checkpoint, "--quiet")
    steps = -1
    if run.returncode == 0 and (folder / "long_disks.h5").exists():
        with h5py.File(folder / "long_disks.h5", "r") as f:
            steps = int(f["summary"].attrs["steps"])
    check("the interrupted particle run is continued to its end (10 000 steps)", steps == 10000,
          f"exit {run.returncode}, steps {steps}, {run.stderr.strip()[-300:]!r}")


def stop_by_sigterm(exe, deck, folder, cwd):
    """Run `deck` (relative to `cwd`) into `folder` without --output, the default
    results/<deck name>, and stop it by SIGTERM once its partial file exists; returns
    (exit code, standard output)."""
    partial = cwd / folder / f"{deck.stem}.h5.partial"
    proc = subprocess.Popen([str(exe), str(deck)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            cwd=cwd)
    deadline = time.monotonic() + 60
    while not partial.exists() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.01)
    proc.send_signal(signal.SIGTERM)
    out, _ = proc.communicate(timeout=300)
    return proc.returncode, out


def folder_digests(folder):
    return {p.name: digest(p) for p in folder.iterdir() if p.is_file()}


def same_file_name(exe, work):
    """Decks of the same file name share their default results folder, results/<deck name>
    (doc/output.md, "What a run replaces"). A fresh run into the folder of a run that can
    still be continued (stopped by SIGTERM; killed by kill -9 after a periodic checkpoint) is
    refused, whatever the deck: the same deck again, or another deck of the same file name
    (c2/deck.dat beside c1/deck.dat, another friction); the folder stays byte for byte, and the
    command the refusal gives continues the run. Removing the checkpoint, as it says, lets a
    fresh run start. Over the finished results of another deck of the same file name: a
    warning; over its own: no word. Before, every one of these runs went on silently and
    replaced the stopped run (its printed command then failed)."""
    base = work / "same_name"
    for case, mu in (("c1", "0.5"), ("c2", "0.4")):
        (base / case).mkdir(parents=True)
        (base / case / "deck.dat").write_text(LONG_PARTICLES.replace("1 1 0.5 0 0", f"1 1 {mu} 0 0"))
    folder = pathlib.Path("results") / "deck"
    code, out = stop_by_sigterm(exe, pathlib.Path("c1") / "deck.dat", folder, base)
    c = re.search(r"^to continue: (multicor .*)$", out, flags=re.M)
    if not check("same name: c1/deck.dat stopped by SIGTERM with the command to continue",
                 code == 143 and c is not None, f"exit {code}"):
        return
    before = folder_digests(base / folder)
    ckpt = folder / "checkpoint.h5"
    with h5py.File(base / ckpt, "r") as f:
        step = int(f["loop"].attrs["step"])
    for case, who in (("c1", "this deck"), ("c2", "another deck (c1/deck.dat) of the same file name")):
        proc = subprocess.run([str(exe), f"{case}/deck.dat", "--quiet"], capture_output=True, text=True, cwd=base,
                              timeout=300)
        check(f"same name: {case}/deck.dat afresh into the stopped run's folder refused, with the step and "
              "the command that continues it", proc.returncode == 1
              and f"holds an interrupted run of {who}, which can still be continued from its checkpoint at "
              f"step {step}," in proc.stderr and f"To continue it: multicor c1/deck.dat --restart {ckpt}" in proc.stderr
              and f"remove that checkpoint (rm {ckpt})" in proc.stderr, proc.stderr.strip()[-600:])
        check(f"same name: the refusal of {case}/deck.dat leaves the folder byte for byte",
              folder_digests(base / folder) == before, str(sorted(folder_digests(base / folder))))
    proc = subprocess.run([str(exe), *c.group(1).split()[1:], "--quiet"], capture_output=True, text=True,
                          cwd=base, timeout=300)
    check("same name: the stopped run's command continues it", proc.returncode == 0 and
          (base / folder / "deck.h5").exists(), proc.stderr.strip()[-300:])
    # over the finished results of another deck of the same file name: a warning, the run goes on
    proc = subprocess.run([str(exe), "c2/deck.dat", "--end", "0.01"], capture_output=True, text=True, cwd=base,
                          timeout=300)
    check("same name: c2/deck.dat over c1's finished results: exit 0 with a warning",
          proc.returncode == 0 and "warning: the folder results/deck holds the finished results of another deck "
          "of the same file name (c1/deck.dat)" in proc.stdout, (proc.stdout + proc.stderr).strip()[-400:])
    # the same deck over its own finished results: nothing to say
    proc = subprocess.run([str(exe), "c2/deck.dat", "--end", "0.01"], capture_output=True, text=True, cwd=base,
                          timeout=300)
    check("same name: c2/deck.dat again over its own finished results: exit 0, no warning",
          proc.returncode == 0 and "warning" not in proc.stdout + proc.stderr,
          (proc.stdout + proc.stderr).strip()[-400:])

    # kill -9 after a periodic checkpoint: the run can be continued, so refused the same way
    deck = work / "killed.dat"
    deck.write_text(LONG_PARTICLES + "checkpoint_interval = 20\n")
    folder = work / "killed"
    proc = subprocess.Popen([str(exe), str(deck), "--output", str(folder), "--quiet"], stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    while not (folder / "checkpoint.h5").exists() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.005)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    if not check("kill -9: killed after a periodic checkpoint, its partial file left",
                 proc.returncode == -signal.SIGKILL and (folder / "checkpoint.h5").exists()
                 and (folder / "killed.h5.partial").exists(), f"exit {proc.returncode}, {sorted(folder.iterdir())}"):
        return
    before = folder_digests(folder)
    proc = multicor(exe, deck, "--output", folder, "--quiet")
    check("kill -9: a fresh run of the same deck refused, the folder byte for byte",
          proc.returncode == 1 and "holds an interrupted run of this deck" in proc.stderr
          and folder_digests(folder) == {k: v for k, v in before.items() if k != ".multicor.lock"},
          proc.stderr.strip()[-300:])
    # a checkpoint of another code version: this build cannot continue it, the one that wrote
    # it can (a restart here is refused by version): refused too, the message says which build
    with h5py.File(folder / "checkpoint.h5", "r+") as f:
        f.attrs["code_version"] = "0.0.1-other"
    proc = multicor(exe, deck, "--output", folder, "--quiet")
    check("kill -9: a checkpoint of another code version: the fresh run refused, continued by the build that "
          "wrote it", proc.returncode == 1 and "To continue it: with the MULTICOR build that wrote it" in proc.stderr,
          proc.stderr.strip()[-300:])
    # as the refusal says: the checkpoint removed, the run starts afresh (no run can continue
    # the partial file then: it is replaced)
    (folder / "checkpoint.h5").unlink()
    proc = multicor(exe, deck, "--output", folder, "--quiet", "--end", "0.01")
    check("kill -9: the checkpoint removed, a fresh run goes on: exit 0, no warning",
          proc.returncode == 0 and "warning" not in proc.stdout and finished(folder / "killed.h5"),
          (proc.stdout + proc.stderr).strip()[-300:])


def same_name_without_time_loop(exe, work):
    """Static and modal runs of decks of the same file name share their default results
    folder, results/<deck name>, and have no checkpoint to tell them apart: another deck's
    results replaced are warned (from the deck the results record), the same deck again is
    silent. Before, both were silent."""
    for kind in ("static_beam", "modal_continuum"):
        base = work / f"same_name_{kind}"
        for case, extra in (("c1", ""), ("c2", "# another deck\n")):
            (base / case).mkdir(parents=True)
            (base / case / f"{kind}.dat").write_text(NO_TIME_LOOP[kind] + extra)
        results = base / "results" / kind / f"{kind}.h5"
        for case, warned in (("c1", False), ("c1", False), ("c2", True), ("c2", False)):
            proc = subprocess.run([str(exe), f"{case}/{kind}.dat", "--quiet"], capture_output=True, text=True,
                                  cwd=base, timeout=300)
            text = proc.stdout + proc.stderr
            expected = (f"warning: the folder results/{kind} holds the results of another deck of the same file "
                        f"name (c1/{kind}.dat): this run replaces them")
            check(f"same name, {kind}: {case}/{kind}.dat {'warned' if warned else 'silent'}, exit 0",
                  proc.returncode == 0 and finished(results)
                  and ((expected in proc.stdout) if warned else "warning" not in text), text.strip()[-400:])


def checkpoint_named_deck(exe, work):
    """A deck named checkpoint.dat would write its results as <folder>/checkpoint.h5, the
    folder's checkpoint: refused before anything is written (also Checkpoint.dat, the same file
    where the file system does not tell case apart). Before, its results overwrote the
    checkpoint and the printed --restart command failed ('is not a MULTICOR checkpoint')."""
    for name in ("checkpoint", "Checkpoint"):
        deck = work / "named" / f"{name}.dat"
        deck.parent.mkdir(exist_ok=True)
        deck.write_text(PARTICLES)
        proc = multicor(exe, deck, "--output", work / "named" / name)
        check(f"{name}.dat refused by name, nothing written", proc.returncode == 1
              and f"writes its results as '{name}.h5', the name of the results folder's checkpoint" in proc.stderr
              and "rename the deck" in proc.stderr and not (work / "named" / name).exists(),
              proc.stderr.strip()[-300:])
    proc = multicor(exe, work / "named" / "checkpoint.dat", "--check")
    check("checkpoint.dat refused by --check too", proc.returncode == 1 and "rename the deck" in proc.stderr,
          proc.stderr.strip()[-300:])


def main():
    exe, work, _ = arguments(fresh=True)
    after_finished_run(exe, work)
    after_interrupted_run(exe, work)
    same_file_name(exe, work)
    same_name_without_time_loop(exe, work)
    checkpoint_named_deck(exe, work)
    return summary()


if __name__ == "__main__":
    sys.exit(main())
