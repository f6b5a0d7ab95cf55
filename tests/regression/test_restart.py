#!/usr/bin/env python3
"""Checkpoint and restart (doc/output.md, "Checkpoints and restart"): a run stopped and
continued from its checkpoint gives BITWISE the results of the uninterrupted run.

For a beam deck (input/cantilever.dat), a particle deck with contacts and bonds that break
(input/cohesive_row.dat: bonded row, two ruptures, one before and one after the stop; also
with [solver] method = block, whose factor is kept from step to step; a spinning bonded pair,
whose bond is made on the positions at t = 0; a deposit under a
driven wall with unconverged steps before and after the stop) and
coupled decks (input/bending_stack.dat, tests/regression/decks/coupled_rigid_translation.dat),
a 2D continuum deck (input/continuum_cantilever_dynamic.dat) and continuum-disk coupled decks
(tests/regression/decks/coupled2d_pushed.dat with one multiplier per disk and with the
mediator space; coupled2d_driven_edge.dat, an edge driven in time inside the overlap), the
run is stopped at step k in three
ways: by a shorter end time (--end, the stop not on an output step: its extra last output
must disappear at the restart), by a signal (SIGTERM / SIGUSR1: exit 128 + signal, then the
exact command the program prints is run), and by kill -9 after a periodic checkpoint
([output] checkpoint_interval). Every dataset of the continued file must be equal, byte for
byte, to that of the uninterrupted run, and so must every attribute except the wall-clock
ones (dates, wall and solver seconds); for the continuum runs the XDMF file next to the
results is equal byte for byte as well. Refusals: a checkpoint of another deck, of another
code version, of another kind of run, a restart with nothing left to do, a damaged checkpoint
(a value edited: NaN, a step, a count or a code out of range; bytes flipped on disk, which the
datasets' checksums catch). A new end time (--end)
continues a finished run; the earlier finished result stays untouched when the continued run
fails. A failing run leaves the folder as it found it: a finished result and its checkpoint,
an interrupted run's partial file and checkpoint (the printed command still continues it),
the checkpoint a failed restart started from. Another deck run into the folder of an
interrupted run is refused (it would replace that run's checkpoint). A run killed after
its final checkpoint, before its results file got its name (by strace at that rename or at the
opening of the XDMF file, and for every kind of run as the files such a kill leaves) is
finished by the same command: no step, the results and XDMF file bitwise the uninterrupted
run's, nothing else left. The partial file of an interrupted run set aside by a fresh run
that was then killed ('.partial.prev') is deleted by the next run that ends, unless it holds
the results of the folder's checkpoint (its run_id and at least its records): a restart then
continues it under its name; a static run (which writes no checkpoint) that ends gives the
checkpoint's partial file its name back, also one it set aside itself, and deletes a
'checkpoint.h5.tmp' (a checkpoint being written when a run was killed, made by hand: nothing
reads it, and before it was left in the folder for good by a run that writes no checkpoint). A finished run
continued, the continuation killed and its file set aside: the restart continues that file,
not the finished one (fewer records); an earlier copy of the finished file never replaces it.
The count of steps whose contacts created energy (two disks, each
hitting its inclined wall with e = 1 and friction, Kane's paradox, at steps 1 and 11) is in
the checkpoint: stopped at step 5 (--end), or killed by SIGKILL at the commit of its checkpoint
of step 10 (under strace) and restarted from that of step 5, the run warns once in all and its
summary counts 2 of 20 steps, as the uninterrupted run's; a checkpoint of the previous build
(no /loop@creating) is accepted and counts from the restart.
Usage (ctest does this): test_restart.py --exe multicor --work DIR --source REPO
"""
import argparse
import os
import hashlib
import pathlib
import re
import resource
import shutil
import signal
import subprocess
import sys

import h5py
import numpy as np

from checks import check, have_strace, summary

# Attributes that measure wall-clock time or dates: they differ between any two runs; and the
# count of runs that made the file (/summary@runs: 2 for a restarted run, 1 for the
# uninterrupted one).
CLOCK_ATTRIBUTES = {"created", "ended", "wall_seconds", "wall_seconds_last_run", "runs",
                    "detection_seconds", "solver_seconds", "run_id"}

# Two touching bonded disks spinning at 5 rad/s about their contact point (test_initial_bonds.py):
# the bond is made on the positions at t = 0, before the first step, and carried by the
# checkpoint.
SPIN = """[run]
analysis = dynamic
[particles]
material = 1 2500
disk = 0.0 0.0 0.01 1
disk = 0.02 0.0 0.01 1
initial_rigid = all 0 0 5.0 0.01 0.0
[contacts]
law = 1 1 0 0 1.0e6
bond = 1 1 1.0
[time]
step = 1e-3
end = 0.2
[output]
interval = 20
"""

# Disks settling under a piston (the fourth wall, driven down at 0.2 m/s) with at most 3
# sweeps per step: most steps end unconverged.
PISTON = """[run]
title    = Deposit under a piston
analysis = dynamic
[particles]
material = 1 2500
deposit  = 60 0 0.1 0 0.004 0.005 1 7
gravity  = 0 -9.81
[walls]
wall = 0 0 0.1 0
wall = 0 0 0 0.3
wall = 0.1 0 0.1 0.3
wall = 0.1 0.1 0 0.1 1 0 -0.2
[contacts]
law = 1 1 0.4 0.1 0
[solver]
max_sweeps = 3
[time]
step = 1e-3
end  = 0.2
[output]
interval = 10
progress = 0
"""

# Two disks held in x fall at 1 m/s, each onto its wall inclined at 45 degrees (R = 0.02 m, the
# second 1.05 mm higher): Newton's restitution e = 1 with friction mu = 0.5 sticks and creates
# energy (Kane's paradox, tests/regression/test_kane_paradox.py) at steps 1 and 11.
KANE_TWO = """[run]
analysis = dynamic
[particles]
material = 1 2500
disk = -0.0141421356237309 0.014142135623731 0.02 1
disk = 0.485857864376269 0.015192135623731 0.02 1
fix = 1:2 x
initial_velocity = 1:2 y -1.0
[walls]
wall = -0.0353553390593274 -0.0353553390593274 0.0353553390593274 0.0353553390593274
wall = 0.464644660940673 -0.0353553390593274 0.535355339059327 0.0353553390593274
[contacts]
law = 1 1 0.5 1 0
[solver]
tolerance = 1e-14
[time]
step = 1e-4
end = 2e-3
[output]
interval = 1
progress = 0
"""


def edit_deck(src, dst, end=None, extra_output=None, progress=None):
    """Copy a deck with another [time] end and extra [output] lines."""
    text = src.read_text()
    if end is not None:
        text = re.sub(r"^end\s*=.*$", f"end = {end!r}", text, count=1, flags=re.M)
    lines = list(extra_output or [])
    if progress is not None:
        text = re.sub(r"^progress\s*=.*$", "", text, flags=re.M)
        lines.append(f"progress = {progress!r}")
    if lines:
        if re.search(r"^\[output\]\s*$", text, flags=re.M):
            text = re.sub(r"^\[output\]\s*$", "[output]\n" + "\n".join(lines), text, count=1,
                          flags=re.M)
        else:
            text += "\n[output]\n" + "\n".join(lines) + "\n"
    dst.write_text(text)
    return dst


def run(exe, *args, **kw):
    return subprocess.run([str(exe)] + [str(a) for a in args], capture_output=True, text=True,
                          timeout=900, **kw)


def digest(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


def contents(path):
    """Every dataset (bytes, dtype, shape) and every attribute of a file."""
    data, attrs = {}, {}

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset):
            a = obj[...]
            data[name] = (a.dtype.str, a.shape, np.ascontiguousarray(a).tobytes())
        for k, v in obj.attrs.items():
            attrs[f"{name}@{k}"] = v

    with h5py.File(path, "r") as f:
        for k, v in f.attrs.items():
            attrs[f"/@{k}"] = v
        f.visititems(visit)
    return data, attrs


def compare(name, continued, reference):
    """Bitwise comparison of every dataset; attributes equal except the clock ones."""
    a, aa = contents(continued)
    b, ba = contents(reference)
    bad = [f"{k} missing in one file" for k in sorted(set(a) ^ set(b))]
    bad += [f"{k} differs {a[k][1]} vs {b[k][1]}" for k in sorted(set(a) & set(b)) if a[k] != b[k]]
    n_values = sum(int(np.prod(b[k][1])) for k in b)
    check(f"{name}: every dataset bitwise equal to the uninterrupted run", not bad,
          f"{len(b)} datasets, {n_values} values, {len(bad)} differ" if not bad
          else "; ".join(bad[:5]))
    abad = []
    for k in sorted(set(aa) | set(ba)):
        if k.rsplit("@", 1)[1] in CLOCK_ATTRIBUTES:
            continue
        x, y = aa.get(k), ba.get(k)
        if x is None or y is None or not np.array_equal(np.asarray(x), np.asarray(y)):
            abad.append(f"{k}: {x!r} vs {y!r}")
    check(f"{name}: every attribute equal (but dates and wall times)", not abad,
          f"{len(ba)} attributes" if not abad else "; ".join(abad[:4]))


def reference(exe, deck, work, name):
    folder = work / f"ref_{name}"
    proc = run(exe, deck, "--output", folder, "--quiet")
    if proc.returncode != 0:
        raise SystemExit(f"reference run of {deck} failed: {proc.stdout}{proc.stderr}")
    return folder / f"{deck.stem}.h5"


def by_end_time(exe, deck, work, name, t_stop):
    """Stop at t_stop (--end, not an output step), restart to the deck's end."""
    ref = reference(exe, deck, work, name)
    folder = work / name
    first = run(exe, deck, "--output", folder, "--quiet", "--end", t_stop)
    check(f"{name}: first part (--end {t_stop}) exit 0", first.returncode == 0,
          (first.stdout + first.stderr)[-300:])
    ckpt = folder / "checkpoint.h5"
    check(f"{name}: checkpoint at {ckpt.relative_to(work)}", ckpt.is_file(), "")
    if ckpt.is_file():
        shutil.copy(ckpt, work / f"{name}_first_checkpoint.h5")
    # no --output: the results are continued in the checkpoint's folder (the default folder,
    # results/<deck name> of the working directory, is not created)
    home = work / f"{name}_cwd"
    home.mkdir(exist_ok=True)
    second = run(exe, deck.resolve(), "--restart", ckpt.resolve(), cwd=home)
    check(f"{name}: restart exit 0", second.returncode == 0, (second.stdout + second.stderr)[-300:])
    check(f"{name}: restart without --output writes nothing in the working directory",
          not any(home.iterdir()), str(list(home.iterdir())))
    if second.returncode == 0:
        compare(name, folder / f"{deck.stem}.h5", ref)
        compare_xdmf(name, folder / f"{deck.stem}.xdmf", ref.with_suffix(".xdmf"))
    return ref


def compare_xdmf(name, continued, reference):
    """The XDMF file of a continuum run (one grid per stored state) is the same text."""
    if not reference.exists():
        return
    check(f"{name}: the XDMF file equals the uninterrupted run's", continued.exists() and
          continued.read_bytes() == reference.read_bytes(), str(continued))


# [output] progress of the runs stopped by a signal or a kill once they report a step: a line at
# every step (the value is the wall time between lines, below that of any step). Their output
# is read through a pipe of 4 KiB (`start`): a run whose line of step k has been read cannot
# get more than about 130 steps past k (4 KiB in the pipe and 8 KiB read ahead by Python hold
# that many lines of about 95 bytes) before it waits for the pipe, which is read again only
# after the signal is sent. So those runs are stopped before their end however late the
# signal comes, with decks of only a few hundred steps more than the step awaited (at least
# 240 here; they had thousands, 14 000 for the beam, for the signal to come in time).
EVERY_STEP = 1e-9


def start(exe, deck, folder, *args):
    """Start a run whose progress lines are read with `wait_for_step` (through a 4 KiB pipe:
    see EVERY_STEP)."""
    return subprocess.Popen([str(exe), str(deck), "--output", str(folder), *map(str, args)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, pipesize=4096)


def wait_for_step(proc, min_step, lines):
    for line in proc.stdout:
        lines.append(line)
        m = re.match(r"step (\d+)/", line)
        if m and int(m.group(1)) >= min_step:
            return True
    return False


def stopped_after(exe, deck, folder, min_step, name):
    """Start a run, stop it by SIGTERM once it reports step min_step: (exit code, its whole
    output), or None (a failed check) when it never gets there."""
    proc = start(exe, deck, folder)
    lines = []
    if not wait_for_step(proc, min_step, lines):
        check(f"{name}: run reached step {min_step}", False, proc.communicate()[1][-300:])
        return None
    proc.send_signal(signal.SIGTERM)
    out, _ = proc.communicate()
    return proc.returncode, "".join(lines) + out


def by_signal(exe, deck_src, work, name, sig, end, min_step):
    """A signal stops the run after step min_step; the command printed continues it."""
    deck = edit_deck(deck_src, work / f"{name}.dat", end=end, progress=EVERY_STEP)
    ref = reference(exe, deck, work, name)
    folder = work / name
    proc = start(exe, deck, folder)
    lines = []
    if not wait_for_step(proc, min_step, lines):
        check(f"{name}: run reached step {min_step}", False, proc.communicate()[1][-300:])
        return
    proc.send_signal(sig)
    out, err = proc.communicate()
    out = "".join(lines) + out
    signame = signal.Signals(sig).name
    check(f"{name}: {signame} gives exit 128 + {int(sig)}", proc.returncode == 128 + sig,
          f"exit {proc.returncode}")
    m = re.search(r"^checkpoint: (\d+) steps, t = \S+ s, in (\S+)$", out, flags=re.M)
    check(f"{name}: says where the checkpoint is", m is not None and
          pathlib.Path(m.group(2)) == folder / "checkpoint.h5", out.strip()[-300:])
    c = re.search(r"^to continue: (multicor .*)$", out, flags=re.M)
    check(f"{name}: prints the command to continue", c is not None, out.strip()[-300:])
    if c is None or m is None:
        return
    command = c.group(1).split()
    check(f"{name}: the command is the deck with --restart",
          command[1:] == [str(deck), "--output", str(folder), "--restart",
                          str(folder / "checkpoint.h5")], c.group(1))
    stopped = int(m.group(1))
    check(f"{name}: stopped before the end", min_step <= stopped, f"step {stopped}")
    second = run(exe, *command[1:])
    check(f"{name}: continued run exit 0", second.returncode == 0,
          (second.stdout + second.stderr)[-300:])
    check(f"{name}: continued from the step of the stop",
          f"restart from {folder / 'checkpoint.h5'} at step {stopped}" in second.stdout,
          second.stdout[:200])
    if second.returncode == 0:
        compare(name, folder / f"{deck.stem}.h5", ref)
        compare_xdmf(name, folder / f"{deck.stem}.xdmf", ref.with_suffix(".xdmf"))


def by_kill_9(exe, deck_src, work, name, end, every, min_step, seconds=None):
    """kill -9 after periodic checkpoints (every `every` steps, or every `seconds` of wall
    time); restart from the last one."""
    extra = [f"checkpoint_seconds = {seconds!r}"] if seconds else [f"checkpoint_interval = {every}"]
    deck = edit_deck(deck_src, work / f"{name}.dat", end=end, progress=EVERY_STEP, extra_output=extra)
    ref = reference(exe, deck, work, name)
    folder = work / name
    proc = start(exe, deck, folder)
    if not wait_for_step(proc, min_step, []):
        check(f"{name}: run reached step {min_step}", False, proc.communicate()[1][-300:])
        return
    proc.send_signal(signal.SIGKILL)
    proc.communicate()
    with h5py.File(folder / "checkpoint.h5", "r") as f:
        step = int(f["loop"].attrs["step"])
    if seconds:
        check(f"{name}: a checkpoint by wall time before the kill", 0 < step <= min_step + 1000,
              f"step {step}")
    else:
        check(f"{name}: periodic checkpoint at a multiple of {every}",
              step >= every and step % every == 0, f"step {step}")
    second = run(exe, deck, "--output", folder, "--restart", folder / "checkpoint.h5")
    check(f"{name}: restart after kill -9 exit 0", second.returncode == 0,
          (second.stdout + second.stderr)[-300:])
    if second.returncode == 0:
        compare(name, folder / f"{deck.stem}.h5", ref)


def refusals(exe, deck, work):
    """Another deck, another code version, nothing left to do: exit 1 with a clear message,
    nothing written."""
    folder = work / "refuse"
    first = run(exe, deck, "--output", folder, "--quiet", "--end", 0.05)
    assert first.returncode == 0, first.stderr
    ckpt = folder / "checkpoint.h5"
    result = folder / f"{deck.stem}.h5"
    before = digest(result)
    other = work / f"other_{deck.name}"
    other.write_text(deck.read_text().replace("-10.0", "-11.0"))
    proc = run(exe, other, "--output", folder, "--restart", ckpt, "--end", 0.1)
    check("another deck refused", proc.returncode == 1 and
          "was written for another deck" in proc.stderr, proc.stderr.strip())
    # Without --output the folder is the checkpoint's: a folder or a missing file given to
    # --restart is refused by name, before any folder is made from it (before: 'runX/' made
    # runX and called it 'not an HDF5 file'; the results folder itself blamed --output).
    for given, said in [(folder, f"'{folder}' is a folder: give the checkpoint file in it ('{ckpt}')"),
                        (f"{folder}/", f"is a folder: give the checkpoint file in it ('{ckpt}')"),
                        (f"{ckpt}/", f"no checkpoint '{ckpt}/'"),
                        (work / "no_such_run" / "checkpoint.h5", "no checkpoint '")]:
        proc = run(exe, deck, "--restart", given, "--end", 0.1, cwd=work)
        check(f"--restart {given} refused by name", proc.returncode == 1 and said in proc.stderr
              and not (work / "no_such_run").exists() and not (work / "results").exists(),
              proc.stderr.strip())
    proc = run(exe, deck, "--output", folder, "--restart", ckpt, "--end", 0.05)
    check("nothing left to do refused", proc.returncode == 1 and "nothing to do" in proc.stderr,
          proc.stderr.strip())
    proc = run(exe, deck, "--output", folder, "--restart", ckpt, "--end", 0.04)
    check("an end time before the checkpoint refused", proc.returncode == 1 and
          "nothing to do" in proc.stderr, proc.stderr.strip())
    old = work / "old_version.h5"
    shutil.copy(ckpt, old)
    with h5py.File(old, "r+") as f:
        f.attrs["code_version"] = "0.0.1"
    proc = run(exe, deck, "--output", folder, "--restart", old, "--end", 0.1)
    check("another code version refused", proc.returncode == 1 and
          "written by MULTICOR 0.0.1" in proc.stderr, proc.stderr.strip())
    # The same code version, an earlier layout (a build of the day before the particle writer
    # counted the steps whose bonded block was given up): refused by name, not as damaged.
    layout = work / "old_layout.h5"
    shutil.copy(ckpt, layout)
    with h5py.File(layout, "r+") as f:
        f.attrs["format"] = "MULTICOR checkpoint 1"
    proc = run(exe, deck, "--output", folder, "--restart", layout, "--end", 0.1)
    check("an earlier checkpoint layout refused by name", proc.returncode == 1 and
          "has the layout of an earlier build ('MULTICOR checkpoint 1'" in proc.stderr, proc.stderr.strip())
    beam_deck = work / "not_a_checkpoint.h5"
    shutil.copy(result, beam_deck)
    proc = run(exe, deck, "--output", folder, "--restart", beam_deck, "--end", 0.1)
    check("a results file is not a checkpoint", proc.returncode == 1 and
          "is not a MULTICOR checkpoint" in proc.stderr, proc.stderr.strip())
    # A damaged checkpoint counting more records than the results file holds: the restart
    # extended the series to 2^31 records (a results file no reader can load).
    damaged = work / "damaged_records.h5"
    shutil.copy(ckpt, damaged)
    with h5py.File(damaged, "r+") as f:
        f["results/records"][0] = 2**31 - 1
    proc = run(exe, deck, "--output", folder, "--restart", damaged, "--end", 0.1)
    check("a checkpoint counting records the results lack refused", proc.returncode == 1 and
          "records of" in proc.stderr and "the checkpoint is damaged" in proc.stderr, proc.stderr.strip())
    check("refusals leave the result untouched", digest(result) == before, "")
    check("refusals leave no partial file", not (folder / f"{deck.stem}.h5.partial").exists(), "")


def two_decks_one_folder(exe, src, work):
    """Another deck run afresh into the folder of an interrupted run would replace its
    checkpoint, and the command that run printed would no longer continue it: refused, the
    folder untouched, and the interrupted run continued afterwards. Into the folder of a
    finished run of another deck: a warning (that run only loses the checkpoint that would
    extend it)."""
    folder = work / "two_decks"
    beam = edit_deck(src / "input" / "cantilever.dat", work / "two_beam.dat", end=0.3, progress=EVERY_STEP)
    other = src / "input" / "continuum_cantilever_dynamic.dat"
    stopped = stopped_after(exe, beam, folder, 1000, "two decks")
    if stopped is None:
        return
    code, out = stopped
    c = re.search(r"^to continue: (multicor .*)$", out, flags=re.M)
    check("two decks: the beam run stopped with a checkpoint", code == 143 and c is not None, f"exit {code}")
    if c is None:
        return
    before = {p.name: digest(p) for p in folder.iterdir() if p.is_file()}
    second = run(exe, other, "--output", folder, "--quiet")
    check("two decks: another deck into the interrupted run's folder refused", second.returncode == 1
          and "interrupted run of another deck" in second.stderr, second.stderr.strip()[-300:])
    after = {p.name: digest(p) for p in folder.iterdir() if p.is_file()}
    check("two decks: the refusal leaves the folder as it was", before == after,
          f"{sorted(before)} / {sorted(after)}")
    third = run(exe, *c.group(1).split()[1:])
    check("two decks: the printed command still continues the beam run", third.returncode == 0,
          (third.stdout + third.stderr)[-300:])
    # (50 of its 500 steps: the warning comes before the first)
    fourth = run(exe, other, "--output", folder, "--quiet", "--end", 0.05)
    check("two decks: another deck into a finished run's folder: exit 0 with a warning",
          fourth.returncode == 0 and "the checkpoint of another deck's run (two_beam.h5)" in fourth.stdout,
          (fourth.stdout + fourth.stderr).strip()[-300:])


def damaged_bytes(exe, src, work):
    """A checkpoint whose data are damaged on disk (two bytes flipped inside a dataset's stored
    values, the file otherwise intact): its checksum (Fletcher-32, every dataset of a
    checkpoint) fails the read, and the restart is refused as a damaged file, exit 1, the
    results untouched. Before the checksums the flipped bytes were read as other finite
    values: an independent check flipped 2 bytes at random offsets and 6 of 24 restarts ended
    with exit 0 and results other than the uninterrupted run's."""
    deck = edit_deck(src / "input" / "cantilever.dat", work / "damaged_bytes.dat", end=0.1)
    folder = work / "damaged_bytes"
    first = run(exe, deck, "--output", folder, "--quiet", "--end", 0.05)
    assert first.returncode == 0, first.stderr
    ckpt = folder / "checkpoint.h5"
    result = folder / f"{deck.stem}.h5"
    before = digest(result)
    for name in ("fe/u", "fe/a"):
        damaged = work / f"damaged_bytes_{name.replace('/', '_')}.h5"
        shutil.copy(ckpt, damaged)
        with h5py.File(damaged, "r") as f:
            d = f[name]
            check(f"damaged bytes: {name} is checksummed", d.fletcher32, f"fletcher32 = {d.fletcher32}")
            offset = d.id.get_chunk_info(0).byte_offset if d.chunks else d.id.get_offset()
        with open(damaged, "r+b") as fh:
            fh.seek(offset + 40)
            two = fh.read(2)
            fh.seek(offset + 40)
            fh.write(bytes([two[0] ^ 0xFF, two[1] ^ 0x13]))
        proc = run(exe, deck, "--output", folder, "--restart", damaged, "--end", 0.1)
        check(f"damaged bytes in {name}: restart refused as a damaged file", proc.returncode == 1 and
              "the file is damaged" in proc.stderr and f"/{name}" in proc.stderr, proc.stderr.strip()[-300:])
    check("damaged bytes: the results untouched", digest(result) == before, "")


def damaged_values(exe, src, work):
    """A checkpoint with one value edited: a NaN time, energy reference, state entry or wall
    coordinate, a step that is negative or not the integrator's, a counter beyond the
    integers. Refused as damaged, naming the value, exit 1, the results untouched (they were
    accepted: NaN written with exit 0, a run past its end, an internal error)."""
    beam_deck = edit_deck(src / "input" / "cantilever.dat", work / "damaged_values.dat", end=0.1)
    folder = work / "damaged_values"
    first = run(exe, beam_deck, "--output", folder, "--quiet", "--end", 0.05)
    assert first.returncode == 0, first.stderr
    dem_deck = work / "damaged_walls.dat"
    dem_deck.write_text("""[run]
analysis = dynamic
[particles]
material = 1 2500
row = 5 0.05 0.011 0.01 1 0.001
gravity = 0 -9.81
[walls]
wall = 0 0 0.2 0
[contacts]
law = 1 1 0.3 0 0
[time]
step = 1e-4
end = 4e-3
[output]
interval = 5
""")
    dem_folder = work / "damaged_walls"
    first = run(exe, dem_deck, "--output", dem_folder, "--quiet", "--end", 2e-3)
    assert first.returncode == 0, first.stderr

    def scalar(index):
        def edit(f):
            a = f["fe"].attrs["scalars"]
            a[index] = np.nan
            f["fe"].attrs["scalars"] = a
        return edit

    def attribute(group, name, value):
        def edit(f):
            f[group].attrs[name] = value
        return edit

    def entry(path, value):
        def edit(f):
            a = f[path][...]
            a.flat[0] = value
            f[path][...] = a
        return edit

    cases = [
        (beam_deck, folder, "the time NaN", scalar(0), "/fe@scalars value 1 (time) is NaN"),
        (beam_deck, folder, "the start time NaN", scalar(2), "/fe@scalars value 3 (start time) is NaN"),
        (beam_deck, folder, "the energy reference NaN", attribute("results", "energy0", np.nan),
         "/results@energy0 is NaN"),
        (beam_deck, folder, "a displacement NaN", entry("fe/u", np.nan), "/fe/u value 1 is NaN"),
        (beam_deck, folder, "a negative step", attribute("loop", "step", np.int32(-5)),
         "/loop@step is -5"),
        (beam_deck, folder, "a step not the integrator's", attribute("loop", "step", np.int32(400)),
         "/fe@step_count"),
        (beam_deck, folder, "more steps that created energy than steps done",
         attribute("loop", "creating", np.int32(10**6)), "/loop@creating (at most the steps done)"),
        (beam_deck, folder, "a writer counter beyond the integers",
         attribute("results", "writer", np.array([-1.0, 1e30, 0.0])), "not a 32-bit integer"),
        (dem_deck, dem_folder, "a wall coordinate NaN", entry("dem/walls/x1", np.nan),
         "/dem/walls/x1 is NaN"),
        (dem_deck, dem_folder, "a disk velocity infinite", entry("dem/vy", np.inf),
         "/dem/vy value 1 is Infinity"),
    ]
    before = {d: digest(d / f"{deck.stem}.h5") for deck, d in [(beam_deck, folder), (dem_deck, dem_folder)]}
    # each edit on a copy of the original (a restart that wrongly runs replaces the folder's)
    original = {d: shutil.copy(d / "checkpoint.h5", work / f"{d.name}_original.h5") for d in before}
    for deck, out, name, edit, says in cases:
        damaged = work / "damaged_values.h5"
        shutil.copy(original[out], damaged)
        with h5py.File(damaged, "r+") as f:
            edit(f)
        proc = run(exe, deck, "--output", out, "--restart", damaged, "--end", 4e-3 if deck == dem_deck else 0.1)
        check(f"damaged values: {name} refused, naming it", proc.returncode == 1 and says in proc.stderr and
              "the checkpoint is damaged" in proc.stderr, f"exit {proc.returncode}: {proc.stderr.strip()[-300:]}")
    for d, h in before.items():
        check(f"damaged values: {d.name}: the result untouched, no partial file",
              digest(next(d.glob("*.h5"))) == h and not list(d.glob("*.partial*")), str(sorted(d.iterdir())))


def damaged_contacts(exe, src, work):
    """A checkpoint whose contact list names a body that does not exist, or lists two pairs
    out of the detection's order (the warm-start matching merges on that order): refused as
    damaged, exit 1, the results untouched (it was an out-of-bounds access, or a warm start
    that silently lost its reactions)."""
    deck = src / "input" / "cohesive_row.dat"
    folder = work / "damaged_contacts"
    first = run(exe, deck, "--output", folder, "--quiet", "--end", 0.01)
    assert first.returncode == 0, first.stderr
    ckpt = folder / "checkpoint.h5"
    result = folder / f"{deck.stem}.h5"
    before = digest(result)
    def no_such_body(i1, i2):
        i2[0] = 10**6

    def swapped(i1, i2):
        i1[[0, 1]], i2[[0, 1]] = i1[[1, 0]], i2[[1, 0]]

    def pairs(edit):
        def apply(g):
            i1, i2 = g["i1"][...], g["i2"][...]
            check("damaged contacts: the checkpoint has at least 2 contacts", len(i1) >= 2, f"{len(i1)}")
            edit(i1, i2)
            g["i1"][...], g["i2"][...] = i1, i2
        return apply

    def negative_count(g):
        g.attrs["n"] = np.int32(-3)

    def status(g):
        a = g["status"][...]
        a[0] = 7
        g["status"][...] = a

    def reaction(g):
        a = g["r"][...]
        a[0, 0] = np.nan
        g["r"][...] = a

    # status codes 0..4 (doc/output.md, /dem/contacts)
    for name, edit, says in [("a body that does not exist", pairs(no_such_body), "joins bodies"),
                             ("two pairs out of order", pairs(swapped), "are out of order"),
                             ("a negative number of contacts", negative_count, "/dem/contacts@n is -3"),
                             ("a status that is no code", status, "/dem/contacts/status value 1 is 7, outside 0..4"),
                             ("a reaction NaN", reaction, "/dem/contacts/r value 1 is NaN")]:
        damaged = work / "damaged_contacts.h5"
        shutil.copy(ckpt, damaged)
        with h5py.File(damaged, "r+") as f:
            edit(f["dem/contacts"])
        proc = run(exe, deck, "--output", folder, "--restart", damaged)
        check(f"damaged contacts: {name} refused", proc.returncode == 1 and says in proc.stderr and
              "the checkpoint is damaged" in proc.stderr, proc.stderr.strip())
    check("damaged contacts: the results untouched", digest(result) == before, "")


def changed_mesh(exe, src, work):
    """A continuum run on a Gmsh mesh, stopped by --end: restarting it after one node of the
    .msh moved (same node count, same deck) is refused like a changed deck, nothing written;
    with the mesh restored the restart runs (the hash covers the deck and its mesh)."""
    gmsh = shutil.which("gmsh")
    if gmsh is None:
        check("gmsh available for the changed-mesh restart", False, "gmsh not found (Debian package gmsh)")
        return
    folder = work / "mesh_restart"
    folder.mkdir()
    msh = folder / "two_blocks.msh"
    subprocess.run([gmsh, "-2", "-format", "msh41", str(src / "tests" / "data" / "gmsh" / "two_blocks.geo"),
                    "-o", str(msh)], check=True, capture_output=True)
    deck = folder / "mesh_restart.dat"
    deck.write_text("""[run]
analysis = dynamic
[continuum]
mesh = file two_blocks.msh
material = 1e9 0.25 1000 0.5 plane_stress
fix = clamped x y
traction = loaded 1e6 0
[time]
step = 1e-5
end = 2e-4
[output]
interval = 5
""")
    out = folder / "out"
    first = run(exe, deck, "--output", out, "--quiet", "--end", 1e-4)
    assert first.returncode == 0, first.stderr
    result = out / "mesh_restart.h5"
    before = digest(result)
    original = msh.read_text()
    # the first node line after the $Nodes block header of the first entity: "x y z"
    lines = original.split("\n")
    k = lines.index("$Nodes") + 2
    while len(lines[k].split()) != 1:
        k += 1
    n_block = int(lines[k - 1].split()[3])
    coordinate = k + n_block
    x, y, z = (float(v) for v in lines[coordinate].split())
    lines[coordinate] = f"{x + 1e-3} {y} {z}"
    msh.write_text("\n".join(lines))
    proc = run(exe, deck, "--output", out, "--restart", out / "checkpoint.h5")
    check("a restart with a changed mesh refused", proc.returncode == 1 and
          "was written for another deck" in proc.stderr and "mesh" in proc.stderr, proc.stderr.strip())
    check("the refused restart leaves the result untouched", digest(result) == before, "")
    msh.write_text(original)
    proc = run(exe, deck, "--output", out, "--restart", out / "checkpoint.h5", "--quiet")
    check("the restart with the mesh restored runs", proc.returncode == 0, proc.stderr.strip())


SMALL_BEAM = """[run]
analysis = dynamic
[beam]
section = 1 2.1e11 7800 2.0e-4 1.6666666666666667e-9
line = 1 0 0 1 0 10 1
fix = 1 all
load = 11 w {load} 1
[functions]
function = 1 step {load_from}
[time]
step = 2e-4
end = {end}
[output]
interval = 2
{extra}
"""


def small_beam(path, load=-10, load_from=0, end=2e-3, extra=""):
    """A 10-element cantilever; a load of -1e300 from t = load_from makes the run fail there
    (the guard on non-finite energies) in a run that writes a checkpoint every 2 steps."""
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(SMALL_BEAM.format(load=load, load_from=load_from, end=end, extra=extra))
    return path


def failed_runs_keep_state(exe, src, work):
    """A failing run leaves the results folder as it found it (doc/output.md, "Interrupted
    runs"): the finished result and its checkpoint, the partial file and checkpoint of a run
    stopped by SIGTERM (the command it printed still continues it), the checkpoint a failed
    restart started from (the next restart runs). Before, the failing run's own periodic
    checkpoints replaced them, and its failure deleted the earlier partial file. Each failing
    run here fails in a step after storing outputs: its records are kept beside them as
    'beam.h5.failed' ("A time loop that fails in a step"), left out of the state compared."""
    failing = dict(load=-1e300, extra="checkpoint_interval = 2")

    def state(folder):
        return {p.name: digest(p) for p in sorted(folder.iterdir()) if p.is_file() and p.suffix != ".failed"}

    def records_kept(name, folder, proc):
        check(f"{name}: its records kept as beam.h5.failed",
              (folder / "beam.h5.failed").exists() and "beam.h5.failed' (/summary status" in proc.stderr,
              proc.stderr.strip()[-200:])
        (folder / "beam.h5.failed").unlink(missing_ok=True)

    # (a) a finished run, then a failing run of another deck of the same name (fails at step 8)
    folder = work / "keep_finished"
    good = small_beam(work / "keep_good" / "beam.dat")
    assert run(exe, good, "--output", folder, "--quiet").returncode == 0
    before = state(folder)
    bad = small_beam(work / "keep_bad" / "beam.dat", load_from=1.5e-3, **failing)
    proc = run(exe, bad, "--output", folder, "--quiet")
    check("failing run after a finished one: exit 1", proc.returncode == 1, proc.stderr.strip()[-300:])
    check("failing run after a finished one: result and checkpoint as they were", state(folder) == before,
          f"{before} -> {state(folder)}")
    records_kept("failing run after a finished one", folder, proc)
    proc = run(exe, good, "--output", folder, "--quiet", "--restart", folder / "checkpoint.h5", "--end", 3e-3)
    check("failing run after a finished one: the finished run still continues", proc.returncode == 0,
          proc.stderr.strip()[-300:])

    # (b) a finished run to 2e-3 (step 10), continued to 4e-3: fails at step 15 (t = 3e-3),
    # after its checkpoints at steps 12 and 14
    folder = work / "keep_restart"
    late = small_beam(work / "keep_late" / "beam.dat", load_from=3e-3, **failing)
    assert run(exe, late, "--output", folder, "--quiet").returncode == 0
    before = state(folder)
    proc = run(exe, late, "--output", folder, "--quiet", "--restart", folder / "checkpoint.h5", "--end", 4e-3)
    check("failed restart: exit 1 at step 15", proc.returncode == 1 and "step 15" in proc.stderr,
          proc.stderr.strip()[-300:])
    check("failed restart: result and the checkpoint it started from as they were", state(folder) == before,
          f"{before} -> {state(folder)}")
    records_kept("failed restart", folder, proc)
    proc = run(exe, late, "--output", folder, "--restart", folder / "checkpoint.h5", "--end", 2.8e-3)
    check("failed restart: the next restart runs from step 10", proc.returncode == 0 and
          "at step 10" in proc.stdout, (proc.stdout + proc.stderr).strip()[-300:])

    # (c) a long run stopped by SIGTERM, then a failing run of another deck of the same name (refused)
    # (fails at step 8), then a restart from a damaged copy of the checkpoint
    folder = work / "keep_partial"
    long = small_beam(work / "keep_long" / "beam.dat", end=20, extra=f"progress = {EVERY_STEP!r}")
    stopped = stopped_after(exe, long, folder, 200, "keep_partial")
    if stopped is None:
        return
    code, out = stopped
    command = re.search(r"^to continue: multicor (.*)$", out, flags=re.M)
    check("keep_partial: SIGTERM stops the run with the command to continue", code == 143 and
          command is not None, f"exit {code}")
    if command is None:
        return
    before = state(folder)
    check("keep_partial: partial file and checkpoint", set(before) == {"beam.h5.partial", "checkpoint.h5"},
          str(before))
    # the stopped run can still be continued: a fresh run is refused before its first step
    # (test_shared_folder.py), so it leaves no records of a failure either
    proc = run(exe, bad, "--output", folder, "--quiet")
    check("failing run after a stopped one: exit 1", proc.returncode == 1, proc.stderr.strip()[-300:])
    check("failing run after a stopped one: refused as the stopped run can still be continued",
          "can still be continued" in proc.stderr, proc.stderr.strip()[-300:])
    check("failing run after a stopped one: partial file and checkpoint as they were, nothing added",
          state(folder) == before, f"{before} -> {state(folder)}")
    damaged = work / "keep_partial_damaged.h5"
    shutil.copy(folder / "checkpoint.h5", damaged)
    with h5py.File(damaged, "r+") as f:
        f["results"].attrs["energy0"] = np.nan
    proc = run(exe, long, "--output", folder, "--quiet", "--restart", damaged)
    check("damaged checkpoint of a stopped run: refused, the partial file not written to",
          proc.returncode == 1 and "the checkpoint is damaged" in proc.stderr and state(folder) == before,
          proc.stderr.strip()[-300:])
    proc = run(exe, *command.group(1).split(), "--end", 0.2)
    check("failing run after a stopped one: the printed command continues the run", proc.returncode == 0,
          proc.stderr.strip()[-300:])
    check("keep_partial: nothing set aside is left", not list(folder.glob("*.prev")), str(sorted(folder.iterdir())))


def files_in(folder):
    """The names of the files in a folder (hidden ones too: the lock)."""
    return sorted(p.name for p in folder.iterdir())


def killed_by_strace(exe, args, path, calls, name):
    """Run multicor under strace, which kills it (SIGKILL, no cleanup) when it first enters one
    of the system calls `calls` on `path`: the call is not done. True when the run was killed."""
    trace = ",".join(calls)
    proc = subprocess.run(["strace", "-f", "-o", os.devnull, "-P", str(path), "-e", f"trace={trace}",
                           "-e", f"inject={trace}:signal=SIGKILL:when=1", str(exe)] + [str(a) for a in args],
                          capture_output=True, text=True, timeout=300)
    # strace ends with the signal that killed its child (-9 here; 137 through a shell)
    return check(f"{name}: killed at {'/'.join(calls)} of {path.name}", proc.returncode in (-9, 128 + 9),
                 f"exit {proc.returncode} {proc.stderr.strip()[-200:]}")


def finish_after_kill(exe, deck, work, name, end, reference_file, args=()):
    """The command of a run killed after its final checkpoint, run again: the run is finished
    from the checkpoint with no step (doc/output.md, "Interrupted runs"), its results and XDMF
    file bitwise those of the run that was not killed, the folder holds the results, the XDMF
    file and the checkpoint, nothing else."""
    folder = work / name
    proc = run(exe, deck, "--output", folder, "--end", end, "--restart", folder / "checkpoint.h5", *args)
    check(f"{name}: the same command again finishes the run: exit 0", proc.returncode == 0,
          (proc.stdout + proc.stderr).strip()[-300:])
    check(f"{name}: no step done, the run finished from the checkpoint",
          "no step to do, the results are finished from the checkpoint" in proc.stdout and
          "(0 in this run)" in proc.stdout, proc.stdout.strip()[-300:])
    if proc.returncode != 0:
        return
    compare(name, folder / f"{deck.stem}.h5", reference_file)
    compare_xdmf(name, folder / f"{deck.stem}.xdmf", reference_file.with_suffix(".xdmf"))
    expected = sorted([f"{deck.stem}.h5", f"{deck.stem}.xdmf", "checkpoint.h5"])
    check(f"{name}: only the results, the XDMF file and the checkpoint are left", files_in(folder) == expected,
          str(files_in(folder)))
    again = run(exe, deck, "--output", folder, "--end", end, "--restart", folder / "checkpoint.h5")
    check(f"{name}: once finished, the same restart has nothing to do", again.returncode == 1 and
          "nothing to do" in again.stderr, again.stderr.strip()[-300:])


def killed_after_last_checkpoint(exe, src, work):
    """A run killed after its final checkpoint (the step of the end time), before its results
    file got its name: the end checkpoint and '<name>.h5.partial' are left, and the command of
    the run, or the printed command to continue it, was refused with 'nothing to do' (exit 1),
    the outputs stranded in the partial file. Now the restart does what the end of the last step
    did after its checkpoint (the extra last output, the summary, the XDMF file, the renames)."""
    beam = edit_deck(src / "input" / "cantilever.dat", work / "beam_last.dat", end=0.2)
    # 503 steps, outputs every 5: the end of the last step stores an extra output after the checkpoint
    end = 0.1006
    ref_folder = work / "ref_beam_last"
    proc = run(exe, beam, "--output", ref_folder, "--quiet", "--end", end)
    assert proc.returncode == 0, proc.stderr
    ref = ref_folder / "beam_last.h5"
    if have_strace("the kills at the renames and at the XDMF file of a run's end"):
        # (a) killed where the results file was to be renamed (the state the audit found: lock,
        # partial file, XDMF file '.partial', end checkpoint)
        folder = work / "last_rename"
        if killed_by_strace(exe, [beam, "--output", folder, "--quiet", "--end", end],
                            folder / "beam_last.h5.partial", ["rename", "renameat", "renameat2"], "last_rename"):
            check("last_rename: partial file, XDMF file and lock left", files_in(folder) == sorted(
                [".multicor.lock", "beam_last.h5.partial", "beam_last.xdmf.partial", "checkpoint.h5"]),
                str(files_in(folder)))
            finish_after_kill(exe, beam, work, "last_rename", end, ref)
        # (b) a finished run to 0.05 s continued to the end time, killed when it opened its XDMF
        # file: the partial file has every output, /summary finished = 0; the earlier finished
        # file, its XDMF file and the checkpoint it started from ('.prev') are still there
        folder = work / "last_continued"
        proc = run(exe, beam, "--output", folder, "--quiet", "--end", 0.05)
        assert proc.returncode == 0, proc.stderr
        if killed_by_strace(exe, [beam, "--output", folder, "--quiet", "--end", end, "--restart",
                                  folder / "checkpoint.h5"], folder / "beam_last.xdmf.partial",
                            ["open", "openat", "creat"], "last_continued"):
            with h5py.File(folder / "beam_last.h5.partial", "r") as f:
                finished = int(f["summary"].attrs["finished"])
            check("last_continued: partial file (finished = 0), the earlier result, both checkpoints",
                  finished == 0 and files_in(folder) == sorted(
                      [".multicor.lock", "beam_last.h5", "beam_last.h5.partial", "beam_last.xdmf",
                       "checkpoint.h5", "checkpoint.h5.prev"]), f"finished = {finished}, {files_in(folder)}")
            finish_after_kill(exe, beam, work, "last_continued", end, ref)
    # Without strace, for every kind of time loop: a run to its end, its results and XDMF files
    # renamed back to '.partial', which is what a kill at the rename of the results file leaves
    # (but the lock). Every end time here is not an output step.
    spin = work / "spin_last.dat"
    spin.write_text(SPIN)
    piston = work / "piston_last.dat"
    piston.write_text(PISTON)
    cases = [(beam, end, "beam"), (spin, 0.1033, "spin"), (piston, 0.125, "piston"),
             (edit_deck(src / "input" / "bending_stack.dat", work / "stack_last.dat", end=3.0e-4), 1.3e-4,
              "coupled"),
             (src / "input" / "continuum_cantilever_dynamic.dat", 0.2033, "continuum"),
             (src / "tests" / "regression" / "decks" / "coupled2d_pushed.dat", 4.43e-4, "coupled2d")]
    for deck, t_end, kind in cases:
        name = f"last_renamed_{kind}"
        folder = work / name
        proc = run(exe, deck, "--output", folder, "--quiet", "--end", t_end)
        assert proc.returncode == 0, proc.stderr
        ref_folder = work / f"ref_{name}"
        ref_folder.mkdir()
        for suffix in (".h5", ".xdmf"):
            done = folder / f"{deck.stem}{suffix}"
            shutil.copy(done, ref_folder / done.name)
            done.rename(done.with_name(done.name + ".partial"))
        finish_after_kill(exe, deck, work, name, t_end, ref_folder / f"{deck.stem}.h5", args=["--quiet"])


def stale_prev_of_the_same_run(exe, src, work):
    """A finished run X continued to a later end, that continuation killed after a checkpoint
    (its partial file holds X's run_id), then a fresh run of the same deck name killed before
    its first checkpoint: it set X's partial aside as '.prev' and left its own '.partial'. The
    state is made by copying files as those kills leave them (the partial of X's continuation:
    a copy of its finished file of an earlier end; the killed fresh run's: another run's file).
    Restarting X deletes the killed run's partial, resumes from the finished file and ends; the
    '.prev', an earlier copy of X itself, must then go: given its name back beside the finished
    file, it was what the next restart continued ('the checkpoint is damaged')."""
    deck = work / "stale_col.dat"
    deck.write_text((src / "tests" / "regression" / "decks" / "dem_column.dat").read_text()
                    + "[output]\ninterval = 1\n")
    other = work / "stale_other"
    folder = work / "stale_x"
    for path, end in ((other, 0.005), (folder, 0.01)):
        proc = run(exe, deck, "--output", path, "--quiet", "--end", end)
        if not check(f"stale prev: run to {end} s exits 0", proc.returncode == 0, proc.stderr.strip()):
            return
    shutil.copy(folder / "stale_col.h5", folder / "stale_col.h5.partial.prev")
    shutil.copy(other / "stale_col.h5", folder / "stale_col.h5.partial")
    first = run(exe, deck, "--output", folder, "--restart", folder / "checkpoint.h5", "--end", 0.015)
    check("stale prev: the restart of X exits 0", first.returncode == 0, first.stderr.strip())
    left = sorted(p.name for p in folder.iterdir() if not p.name.startswith("."))
    check("stale prev: only the results, the XDMF file and the checkpoint are left",
          left == ["checkpoint.h5", "stale_col.h5", "stale_col.xdmf"], f"{left}")
    second = run(exe, deck, "--output", folder, "--restart", folder / "checkpoint.h5", "--end", 0.02)
    check("stale prev: the next restart exits 0", second.returncode == 0, second.stderr.strip())
    ref = work / "stale_ref"
    proc = run(exe, deck, "--output", ref, "--quiet", "--end", 0.02)
    if second.returncode == 0 and check("stale prev: the uninterrupted run exits 0", proc.returncode == 0, ""):
        compare("stale prev", folder / "stale_col.h5", ref / "stale_col.h5")


def set_aside_partial_files(exe, src, work):
    """'<name>.h5.partial.prev': a run started afresh sets the partial file of an interrupted run
    aside under that name and puts it back if it fails; killed, it cannot. Two fresh runs killed
    after periodic checkpoints (the first one's checkpoint removed before the second starts),
    then the second continued: the run that ends deletes the
    partial file the second run set aside (it stayed, though doc/output.md says a run that ends
    deletes the .prev files). When the set-aside file holds the results of the folder's
    checkpoint (the second run killed before its first checkpoint), a restart says which file
    to rename back, and a run that writes no checkpoint (a static analysis of a deck of the same
    name) gives it its name back. A static run of a deck of the same name into the folder of a
    run stopped by SIGTERM (it sets the partial file aside itself) deleted that run's partial
    file when it ended: the command the stopped run printed was refused; it now continues it.
    A static run killed after setting that file aside and writing its own partial file: the next
    run set its partial file aside over the '.prev' file and the checkpoint's results were gone;
    now the killed run's partial file is deleted and the printed command continues the run."""
    deck = edit_deck(src / "input" / "cantilever.dat", work / "aside.dat", end=0.2, progress=EVERY_STEP,
                     extra_output=["checkpoint_interval = 100"])
    ref = reference(exe, deck, work, "aside")
    folder = work / "aside"
    for attempt in ("first", "second"):
        if attempt == "second":
            # a fresh run over a run that can be continued is refused (test_shared_folder.py):
            # the first run's checkpoint removed, as the refusal says, to start afresh
            (folder / "checkpoint.h5").unlink()
        proc = start(exe, deck, folder)
        # the progress line of step k comes after that step's checkpoint
        if not wait_for_step(proc, 200, []):
            check(f"aside: the {attempt} run reached step 200", False, proc.communicate()[1][-300:])
            return
        proc.send_signal(signal.SIGKILL)
        proc.communicate()
    check("aside: the first run's partial file set aside by the second",
          (folder / "aside.h5.partial.prev").exists(), str(files_in(folder)))
    proc = run(exe, deck, "--output", folder, "--quiet", "--restart", folder / "checkpoint.h5")
    check("aside: the second run continued: exit 0", proc.returncode == 0, proc.stderr.strip()[-300:])
    if proc.returncode == 0:
        compare("aside", folder / "aside.h5", ref)
    check("aside: the run that ended left no .prev file", files_in(folder) == ["aside.h5", "aside.xdmf",
                                                                              "checkpoint.h5"],
          str(files_in(folder)))

    # A fresh run killed after setting the partial file aside, before creating its own (the
    # state made by the rename it does): the checkpoint's results are only in the '.prev' file.
    folder = work / "aside_only"
    proc = start(exe, deck, folder)
    if not wait_for_step(proc, 200, []):
        check("aside_only: the run reached step 200", False, proc.communicate()[1][-300:])
        return
    proc.send_signal(signal.SIGKILL)
    proc.communicate()
    partial = folder / "aside.h5.partial"
    partial.rename(folder / "aside.h5.partial.prev")
    # The restart continues the checkpoint's results from the file set aside, given its name
    # back (it said to rename it back and stopped); tried on a copy of the folder, the rest
    # goes on from the state as the kill left it.
    copy = work / "aside_only_restart"
    shutil.copytree(folder, copy)
    proc = run(exe, deck, "--output", copy, "--quiet", "--restart", copy / "checkpoint.h5")
    check("aside_only: the restart continues the file set aside, under its name: exit 0",
          proc.returncode == 0 and f"were in {copy / 'aside.h5.partial'}.prev" in proc.stdout,
          (proc.stdout + proc.stderr).strip()[-300:])
    if proc.returncode == 0:
        compare("aside_only restart", copy / "aside.h5", ref)
    check("aside_only: the restart left the results, the XDMF file and the checkpoint",
          files_in(copy) == ["aside.h5", "aside.xdmf", "checkpoint.h5"], str(files_in(copy)))
    static = work / "aside_static" / "aside.dat"
    static.parent.mkdir()
    # the deck without its [time] and [output] sections, which a static analysis refuses
    text = re.sub(r"^analysis\s*=.*$", "analysis = static", deck.read_text(), count=1, flags=re.M)
    static.write_text(text[:text.index("[time]")])
    # The kill can fall while the run writes a checkpoint (every 100 steps, about 17 ms apart)
    # and leave 'checkpoint.h5.tmp', which no run reads and the next checkpoint replaces; a
    # static run writes none, and left it for good. Made here by hand, whatever the kill left:
    # the run that ends deletes it.
    (folder / "checkpoint.h5.tmp").write_bytes(b"\x89HDF\r\n\x1a\n a checkpoint cut by kill -9")
    proc = run(exe, static, "--output", folder, "--quiet")
    check("aside_only: a static run of a deck of the same name: exit 0", proc.returncode == 0,
          proc.stderr.strip()[-300:])
    check("aside_only: the static run (no checkpoint) gives the checkpoint's results their name back "
          "and deletes the stale checkpoint.h5.tmp",
          files_in(folder) == ["aside.h5", "aside.h5.partial", "aside.xdmf", "checkpoint.h5"], str(files_in(folder)))
    proc = run(exe, deck, "--output", folder, "--quiet", "--restart", folder / "checkpoint.h5")
    check("aside_only: the restart continues the run: exit 0", proc.returncode == 0,
          proc.stderr.strip()[-300:])
    if proc.returncode == 0:
        compare("aside_only", folder / "aside.h5", ref)

    # The static run sets the interrupted run's partial file aside itself (the reviewer's
    # case): it deleted it when it ended, and the checkpoint it leaves (it writes none) could no
    # longer be continued ("neither ... is the results file of the checkpoint's run").
    folder = work / "aside_static_own"
    stopped = stopped_after(exe, deck, folder, 200, "aside_static_own")
    if stopped is None:
        return
    code, out = stopped
    c = re.search(r"^to continue: (multicor .*)$", out, flags=re.M)
    check("aside_static_own: SIGTERM stops the run with the command to continue", code == 143 and c is not None,
          f"exit {code}")
    if c is None:
        return
    proc = run(exe, static, "--output", folder, "--quiet")
    check("aside_static_own: a static run of a deck of the same name: exit 0", proc.returncode == 0,
          proc.stderr.strip()[-300:])
    check("aside_static_own: the static result beside the interrupted run's partial file, nothing set aside",
          files_in(folder) == ["aside.h5", "aside.h5.partial", "aside.xdmf", "checkpoint.h5"],
          str(files_in(folder)))
    if (folder / "aside.h5").exists():
        with h5py.File(folder / "aside.h5", "r") as f:
            analysis = f.attrs["analysis"]
            analysis = analysis.decode() if isinstance(analysis, bytes) else str(analysis)
        check("aside_static_own: aside.h5 is the static run's", analysis == "static", analysis)
    proc = run(exe, *c.group(1).split()[1:], "--quiet")
    check("aside_static_own: the command the interrupted run printed continues it: exit 0", proc.returncode == 0,
          proc.stderr.strip()[-300:])
    if proc.returncode == 0:
        compare("aside_static_own", folder / "aside.h5", ref)
    check("aside_static_own: the continued run left the results, the XDMF file and the checkpoint",
          files_in(folder) == ["aside.h5", "aside.xdmf", "checkpoint.h5"], str(files_in(folder)))

    # A static run killed (kill -9) after it set the interrupted run's partial file aside and
    # wrote its own: the checkpoint's results are in '.prev' beside the killed run's partial
    # file. The next run set that partial file aside over the '.prev' file (a rename replaces
    # its target): the checkpoint's results were gone and the printed command was refused.
    folder = work / "aside_static_killed"
    stopped = stopped_after(exe, deck, folder, 200, "aside_static_killed")
    if stopped is None:
        return
    code, out = stopped
    c = re.search(r"^to continue: (multicor .*)$", out, flags=re.M)
    check("aside_static_killed: SIGTERM stops the run with the command to continue", code == 143 and c is not None,
          f"exit {code}")
    if c is None:
        return
    if shutil.which("strace") is not None:
        # killed when it opens its XDMF file: its results are written, not yet renamed
        killed_by_strace(exe, [static, "--output", folder, "--quiet"], folder / "aside.xdmf.partial",
                         ["open", "openat", "creat"], "aside_static_killed")
    else:
        # the same state by renames: the interrupted run's file set aside, a static run's
        # results (not the checkpoint's run) as the killed run's partial file
        (folder / "aside.h5.partial").rename(folder / "aside.h5.partial.prev")
        proc = run(exe, static, "--output", work / "aside_static_other", "--quiet")
        assert proc.returncode == 0, proc.stderr
        shutil.copy(work / "aside_static_other" / "aside.h5", folder / "aside.h5.partial")
    check("aside_static_killed: the checkpoint's results set aside beside the killed static run's partial file",
          {"aside.h5.partial", "aside.h5.partial.prev", "checkpoint.h5"} <= set(files_in(folder)),
          str(files_in(folder)))
    proc = run(exe, static, "--output", folder, "--quiet")
    check("aside_static_killed: the static run again: exit 0", proc.returncode == 0, proc.stderr.strip()[-300:])
    check("aside_static_killed: the checkpoint's results kept under their name, the killed run's file deleted",
          files_in(folder) == ["aside.h5", "aside.h5.partial", "aside.xdmf", "checkpoint.h5"],
          str(files_in(folder)))
    proc = run(exe, *c.group(1).split()[1:], "--quiet")
    check("aside_static_killed: the command the interrupted run printed continues it: exit 0",
          proc.returncode == 0, proc.stderr.strip()[-300:])
    if proc.returncode == 0:
        compare("aside_static_killed", folder / "aside.h5", ref)


def continuation_set_aside(exe, src, work):
    """A finished run X (to 0.1 s) continued to the deck's end, that continuation killed
    (kill -9) after a checkpoint at step 900 or later: its partial file holds X's run_id and more
    records than the finished file. A static run of a deck of the same name killed (SIGKILL, by
    strace, when it opens its XDMF file) after it set that partial file aside as '.prev' and
    wrote its own. (a) The restart (the checkpoint's command) resumed from the finished file,
    which holds fewer records than the checkpoint, and was refused ('the checkpoint is damaged
    or not of these results'); it now continues the '.prev' file, the latest state the
    checkpoint describes, and ends bitwise as the uninterrupted run. (b) A restart of the
    previous build killed after it copied the finished file to the partial file (as it did,
    then failed; the state here made by that copy): that copy holds X's run_id, so the next run
    (the static run again) set it aside over the '.prev' file, and the checkpoint's results were
    gone. Now a file of the run with fewer records than the checkpoint does not count as its
    results: it is deleted, the '.prev' file gets its name back, the restart continues it."""
    deck = edit_deck(src / "input" / "cantilever.dat", work / "cont.dat", end=0.3, progress=EVERY_STEP,
                     extra_output=["checkpoint_interval = 100"])
    ref = reference(exe, deck, work, "cont")
    static = work / "cont_static" / "cont.dat"
    static.parent.mkdir()
    text = re.sub(r"^analysis\s*=.*$", "analysis = static", deck.read_text(), count=1, flags=re.M)
    static.write_text(text[:text.index("[time]")])
    folder = work / "cont"
    proc = run(exe, deck, "--output", folder, "--quiet", "--end", 0.1)
    assert proc.returncode == 0, proc.stderr
    proc = start(exe, deck, folder, "--restart", folder / "checkpoint.h5")
    # the progress line of step k comes after that step's checkpoint
    if not wait_for_step(proc, 900, []):
        check("cont: the continuation reached step 900", False, proc.communicate()[1][-300:])
        return
    proc.send_signal(signal.SIGKILL)
    proc.communicate()
    if shutil.which("strace") is not None:
        killed_by_strace(exe, [static, "--output", folder, "--quiet"], folder / "cont.xdmf.partial",
                         ["open", "openat", "creat"], "cont")
    else:
        # the same state by renames: the continuation's file set aside, a static run's results
        # as the killed run's partial file
        (folder / "cont.h5.partial").rename(folder / "cont.h5.partial.prev")
        proc = run(exe, static, "--output", work / "cont_static_other", "--quiet")
        assert proc.returncode == 0, proc.stderr
        shutil.copy(work / "cont_static_other" / "cont.h5", folder / "cont.h5.partial")
    with h5py.File(folder / "checkpoint.h5", "r") as f:
        run_id, step = f.attrs["run_id"], int(np.ravel(f["loop"].attrs["step"])[0])

    def records(path):
        with h5py.File(path, "r") as f:
            return (f.attrs["run_id"] == run_id, f["fem/time"].shape[0] if "fem/time" in f else 0)

    # outputs every 5 steps and at step 0
    check("cont: the finished file of X (0.1 s, 101 outputs), the continuation's set aside (a checkpoint "
          "at step 900 or later: at least 181 outputs), the static run's partial file",
          step >= 900 and records(folder / "cont.h5") == (True, 101) and
          records(folder / "cont.h5.partial.prev")[0] and
          records(folder / "cont.h5.partial.prev")[1] >= step // 5 + 1 and
          not records(folder / "cont.h5.partial")[0],
          f"checkpoint at step {step}; {files_in(folder)}")
    # (a) the restart
    copy = work / "cont_restart"
    shutil.copytree(folder, copy)
    proc = run(exe, deck, "--output", copy, "--restart", copy / "checkpoint.h5")
    check("cont: the restart continues the continuation's file set aside: exit 0",
          proc.returncode == 0 and "they are continued under their name" in proc.stdout,
          (proc.stdout + proc.stderr).strip()[-300:])
    if proc.returncode == 0:
        compare("cont restart", copy / "cont.h5", ref)
    check("cont: the restart left the results, the XDMF file and the checkpoint",
          files_in(copy) == ["checkpoint.h5", "cont.h5", "cont.xdmf"], str(files_in(copy)))
    # (b) a copy of the finished file as the partial file, then the static run
    copy = work / "cont_stale"
    shutil.copytree(folder, copy)
    shutil.copy(copy / "cont.h5", copy / "cont.h5.partial")
    proc = run(exe, static, "--output", copy, "--quiet")
    check("cont stale copy: the static run again: exit 0", proc.returncode == 0, proc.stderr.strip()[-300:])
    kept = records(copy / "cont.h5.partial") if (copy / "cont.h5.partial").exists() else (False, 0)
    check("cont stale copy: the checkpoint's results kept under their name, the earlier copy deleted",
          kept[0] and kept[1] >= step // 5 + 1 and not (copy / "cont.h5.partial.prev").exists(),
          f"{kept}; {files_in(copy)}")
    proc = run(exe, deck, "--output", copy, "--quiet", "--restart", copy / "checkpoint.h5")
    check("cont stale copy: the restart continues the run: exit 0", proc.returncode == 0,
          proc.stderr.strip()[-300:])
    if proc.returncode == 0:
        compare("cont stale copy", copy / "cont.h5", ref)


def new_end_time(exe, deck, work):
    """A finished run continued to a later end time equals the run to that end time; a
    continuation that fails leaves the earlier finished result as it was."""
    folder = work / "extend"
    first = run(exe, deck, "--output", folder, "--quiet", "--end", 0.06)
    assert first.returncode == 0, first.stderr
    result = folder / f"{deck.stem}.h5"
    before = digest(result)
    ref_deck = edit_deck(deck, work / "extend_ref.dat", end=0.13)
    ref = reference(exe, ref_deck, work, "extend")
    # Fails at a write: a file size limit just above the finished file (its copy fits, the
    # continued outputs do not).
    limit = result.stat().st_size + 16384

    def limit_file_size():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    proc = subprocess.run([str(exe), str(deck), "--output", str(folder), "--quiet", "--restart",
                           str(folder / "checkpoint.h5"), "--end", "0.13"],
                          capture_output=True, text=True, preexec_fn=limit_file_size, timeout=300)
    check("failed continuation: exit 1", proc.returncode == 1, proc.stderr.strip()[-300:])
    check("failed continuation: the finished result is untouched", digest(result) == before, "")
    proc = run(exe, deck, "--output", folder, "--restart", folder / "checkpoint.h5", "--end", 0.13)
    check("continued to a new end time: exit 0", proc.returncode == 0, proc.stderr.strip()[-300:])
    if proc.returncode == 0:
        # The deck text differs from the reference's (end time): the root attribute deck_text
        # is compared apart.
        with h5py.File(result, "r") as f:
            same_deck = f.attrs["deck_text"] == deck.read_text()
        check("new end time: the file keeps the deck of the run", same_deck, "")
        a, _ = contents(result)
        b, _ = contents(ref)
        bad = [k for k in sorted(set(a) | set(b)) if a.get(k) != b.get(k)]
        check("new end time: every dataset bitwise equal to the run to that end", not bad,
              f"{len(b)} datasets" if not bad else ", ".join(bad[:5]))


def signal_with_end(exe, deck_src, work, name, end, t_stop, min_step):
    """A run given `--end t_stop` (before the deck's end), stopped by SIGTERM after min_step:
    the command printed repeats `--end` and continues to t_stop, not to the deck's end; the
    continued file equals the uninterrupted run to t_stop."""
    deck = edit_deck(deck_src, work / f"{name}.dat", end=end, progress=EVERY_STEP)
    folder = work / name
    ref_folder = work / f"ref_{name}"
    proc = run(exe, deck, "--output", ref_folder, "--quiet", "--end", t_stop)
    if proc.returncode != 0:
        raise SystemExit(f"reference run of {deck} failed: {proc.stdout}{proc.stderr}")
    proc = start(exe, deck, folder, "--end", t_stop)
    lines = []
    if not wait_for_step(proc, min_step, lines):
        check(f"{name}: run reached step {min_step}", False, proc.communicate()[1][-300:])
        return
    proc.send_signal(signal.SIGTERM)
    out, _ = proc.communicate()
    c = re.search(r"^to continue: (multicor .*)$", "".join(lines) + out, flags=re.M)
    check(f"{name}: SIGTERM stops the run with the command to continue", proc.returncode == 143 and
          c is not None, f"exit {proc.returncode}")
    if c is None:
        return
    command = c.group(1).split()
    # as the user wrote it (it printed 4.00000000000000022E-001 for 0.4; the shortest text
    # that reads back as the same double, as Python's str of a float, is the same step count)
    check(f"{name}: the command gives --end again, as written", command[-2:-1] == ["--end"] and
          float(command[-1]) == t_stop and command[-1] == str(t_stop), c.group(1))
    second = run(exe, *command[1:])
    check(f"{name}: the command continues the run", second.returncode == 0, (second.stdout + second.stderr)[-300:])
    later = re.search(r"to go on to a later end time: (multicor .*) --end T\)", second.stdout)
    check(f"{name}: the command to go on later has one --end, the T to give", later is not None and
          "--end" not in later.group(1), second.stdout.strip()[-300:])
    if second.returncode == 0:
        compare(name, folder / f"{deck.stem}.h5", ref_folder / f"{deck.stem}.h5")


def wall_time_over_runs(exe, src, work):
    """/summary@wall_seconds of a restarted run is the wall time of the analysis over its runs:
    the time recorded in the checkpoint it starts from plus its own (wall_seconds_last_run), so
    that it covers the solver's time (/dem/solver detection_seconds + solver_seconds, which
    also count every run); runs = 2. Its `done:` line gives the cost per step of its own
    steps. A checkpoint of an earlier build (without /loop@wall_seconds and runs) still
    restarts, with a note, the count then starting at the restart."""
    # 500 steps of a deposit, most of the wall time in the contact solver: the first run does
    # 480 steps (--end 0.96 s), the restart 20; the last run alone takes about 1/25 of the
    # solver's total.
    deck = edit_deck(src / "input" / "siconos_deposit_200.dat", work / "wall_runs.dat", end=1.0)
    folder = work / "wall_runs"
    first = run(exe, deck, "--output", folder, "--quiet", "--end", 0.96)
    check("wall_runs: first part exit 0", first.returncode == 0, (first.stdout + first.stderr)[-300:])
    if first.returncode != 0:
        return
    old = work / "wall_runs_old"
    shutil.copytree(folder, old)
    with h5py.File(folder / "checkpoint.h5", "r") as c:
        loop = dict(c["loop"].attrs)
    check("wall_runs: the checkpoint records the wall time and the run",
          float(loop.get("wall_seconds", -1)) > 0 and int(loop.get("runs", 0)) == 1, str(loop))
    second = run(exe, deck, "--output", folder, "--restart", folder / "checkpoint.h5")
    check("wall_runs: restart exit 0", second.returncode == 0, (second.stdout + second.stderr)[-300:])
    if second.returncode != 0:
        return
    with h5py.File(folder / "wall_runs.h5", "r") as f:
        s = dict(f["summary"].attrs)
        solver = f["dem/solver"].attrs
        in_solver = float(solver["detection_seconds"]) + float(solver["solver_seconds"])
    total, last = float(s["wall_seconds"]), float(s.get("wall_seconds_last_run", np.nan))
    check("wall_runs: /summary runs = 2", int(s.get("runs", 0)) == 2, str(s))
    # total = checkpoint's + last, one double addition: within a few ulps of the total.
    earlier = float(loop.get("wall_seconds", np.nan))
    check("wall_runs: wall_seconds = the checkpoint's wall time + wall_seconds_last_run",
          abs(total - (earlier + last)) <= 4 * np.spacing(total), f"{total} vs {earlier} + {last}")
    # Detection and solver are timed inside the steps, on the clock that times the loop, in
    # both runs; 1e-9 s for the rounding of their sums over 500 steps.
    check("wall_runs: wall_seconds covers the detection and solver time of every run",
          total + 1e-9 >= in_solver, f"wall {total} s, detection + solver {in_solver} s")
    m = re.search(r"^done: 500 steps \(20 in this run\), t = \S+ s, wall \S+ \((\S+) ms/step\); "
                  r"analysis \S+ in 2 runs$", second.stdout, flags=re.M)
    check("wall_runs: the done: line counts the run's own 20 steps and the 2 runs", m is not None,
          second.stdout.strip()[-400:])
    if m:
        # The line's time is read just before wall_seconds_last_run (the closing statistics
        # written in between take milliseconds): 20 steps at the printed cost make the run's
        # time to 0.2 s; the cost over all 500 steps would be 25 times smaller.
        check("wall_runs: ms/step = the run's wall time / its 20 steps",
              abs(float(m.group(1)) * 20 / 1000 - last) <= 0.2, f"{m.group(1)} ms/step, {last} s")
    # A checkpoint of an earlier build: neither attribute.
    with h5py.File(old / "checkpoint.h5", "r+") as c:
        for k in ("wall_seconds", "runs"):
            if k in c["loop"].attrs:
                del c["loop"].attrs[k]
    proc = run(exe, deck, "--output", old, "--restart", old / "checkpoint.h5")
    check("wall_runs_old: a checkpoint without wall time restarts, with a note",
          proc.returncode == 0 and "note: the checkpoint, written by an earlier MULTICOR build, does not "
          "record the wall time" in proc.stdout, (proc.stdout + proc.stderr)[-300:])
    if proc.returncode == 0:
        with h5py.File(old / "wall_runs.h5", "r") as f:
            s = dict(f["summary"].attrs)
        check("wall_runs_old: wall_seconds counts from the restart, runs = 2",
              s.get("wall_seconds") == s.get("wall_seconds_last_run") and int(s.get("runs", 0)) == 2,
              str(s))
        compare("wall_runs_old", old / "wall_runs.h5", folder / "wall_runs.h5")


def earlier_results(exe, src, work):
    """A coupled run whose results file lacks a series this build appends to (written by an
    earlier version: /coupling/energy/fe_reaction_work came on 2026-11-27) is not continued:
    a message that says so, exit 1, the folder as it was: the finished result, and an
    interrupted run's partial file, which the restart continues in place (the check came after
    the partial file was cut and marked running). It gave an HDF5 'no dataset' error."""
    gone = "/coupling/energy/fe_reaction_work"

    def as_earlier(results, checkpoint):
        """The results without the series, the checkpoint's list of the results' series
        (/results@datasets, one count each in /results/records) without it."""
        with h5py.File(results, "a") as f:
            del f[gone]
        with h5py.File(checkpoint, "a") as c:
            names = c["results"].attrs["datasets"].split("\n")[:-1]
            records = c["results/records"][...]
            keep = [i for i, name in enumerate(names) if name != gone]
            c["results"].attrs["datasets"] = "".join(names[i] + "\n" for i in keep)
            del c["results/records"]
            c["results/records"] = records[keep]

    deck = edit_deck(src / "input" / "coupled2d_block.dat", work / "earlier.dat", end=0.01, progress=EVERY_STEP,
                     extra_output=["checkpoint_interval = 20"])
    for kind in ("finished", "interrupted"):
        folder = work / f"earlier_{kind}"
        if kind == "finished":
            # (60 steps, as the interrupted run below)
            first = run(exe, deck, "--quiet", "--output", folder, "--end", "6e-4").returncode
            results = folder / "earlier.h5"
        else:
            stopped = stopped_after(exe, deck, folder, 60, "earlier_interrupted")
            if stopped is None:
                continue
            first = 0 if stopped[0] == 128 + signal.SIGTERM else stopped[0]
            results = folder / "earlier.h5.partial"
        as_earlier(results, folder / "checkpoint.h5")
        before = {p.name: digest(p) for p in folder.iterdir()}
        again = run(exe, deck, "--quiet", "--output", folder, "--restart", folder / "checkpoint.h5")
        after = {p.name: digest(p) for p in folder.iterdir()}
        check(f"{kind} run, results of an earlier version: restart refused, folder as it was",
              first == 0 and again.returncode == 1 and "written by an earlier version of MULTICOR"
              in again.stderr and after == before, f"exit {again.returncode}: {again.stderr.strip()[-300:]}")


def other_threads(exe, src, work):
    """A restart under another OMP_NUM_THREADS goes on with a warning naming both settings:
    its results are those of neither uninterrupted run bit for bit (doc/output.md,
    "Bitwise"); under the same setting, or another OPENBLAS_NUM_THREADS (the program runs
    OpenBLAS on one thread), no warning. /summary records the setting."""
    folder = work / "other_threads"
    deck = edit_deck(src / "input" / "cantilever.dat", work / "threads.dat", end=0.02)
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    first = run(exe, deck, "--quiet", "--output", folder, "--end", "0.01", env=env)
    same = run(exe, deck, "--output", folder, "--restart", folder / "checkpoint.h5", "--end", "0.015", env=env)
    blas = run(exe, deck, "--output", folder, "--restart", folder / "checkpoint.h5", "--end", "0.0175",
               env=dict(env, OPENBLAS_NUM_THREADS="4"))
    other = run(exe, deck, "--output", folder, "--restart", folder / "checkpoint.h5", "--end", "0.02",
                env=dict(env, OMP_NUM_THREADS="2"))
    with h5py.File(folder / "threads.h5", "r") as f:
        recorded = f["summary"].attrs["threads"]
    warned = [line for line in other.stdout.splitlines() if line.startswith("warning: the checkpoint was written with")]
    # a checkpoint of an earlier build records 'OpenMP threads N, OPENBLAS_NUM_THREADS V': only
    # the OpenMP part counts (OpenBLAS now runs on one thread)
    with h5py.File(folder / "checkpoint.h5", "r+") as f:
        f.attrs["threads"] = "OpenMP threads 2, OPENBLAS_NUM_THREADS unset"
    earlier = run(exe, deck, "--output", folder, "--restart", folder / "checkpoint.h5", "--end", "0.0225",
                  env=dict(env, OMP_NUM_THREADS="2"))
    check("restart from a checkpoint of an earlier build's format, the same OMP_NUM_THREADS: no warning",
          earlier.returncode == 0 and "warning: the checkpoint was written with" not in earlier.stdout,
          f"exit {earlier.returncode}; {earlier.stdout[-300:]}{earlier.stderr[-300:]}")
    check("restart under the same thread setting, or another OPENBLAS_NUM_THREADS (the program runs OpenBLAS "
          "on one thread): no warning; under another OMP_NUM_THREADS: one naming both",
          first.returncode == 0 and same.returncode == 0 and "warning: the checkpoint" not in same.stdout
          and blas.returncode == 0 and "warning: the checkpoint" not in blas.stdout
          and other.returncode == 0 and len(warned) == 1
          and "OpenMP threads 1, OpenBLAS 1 thread; this run has OpenMP threads 2, OpenBLAS 1 thread"
          in warned[0] and recorded == "OpenMP threads 2, OpenBLAS 1 thread",
          f"exits {first.returncode}, {same.returncode}, {blas.returncode}, {other.returncode}; {warned}; "
          f"/summary {recorded!r}")


def created_energy_counts(exe, work):
    """The warning of a converged step whose contacts created energy (once, then counted) and
    the summary's count over a restart: both from the checkpoint (/loop@creating). Before, the
    restarted run warned again at step 11 and its summary counted 1 of 20 steps."""
    warning = "J/m of energy"
    counted = "steps whose contacts created energy: 2 of 20"
    deck = work / "kane_two.dat"
    deck.write_text(KANE_TWO)
    ref_folder = work / "ref_kane_two"
    ref = run(exe, deck, "--output", ref_folder, "--quiet")
    check("kane_two: uninterrupted run, one warning (step 1), 2 of 20 steps counted",
          ref.returncode == 0 and ref.stdout.count(warning) == 1 and "warning: step 1 " in ref.stdout and
          counted in ref.stdout, ref.stdout.strip()[-400:])

    def restarted(name, folder, killed_output, the_deck=deck, reference_file=ref_folder / "kane_two.h5"):
        second = run(exe, the_deck, "--output", folder, "--restart", folder / "checkpoint.h5")
        if not check(f"{name}: restart exit 0", second.returncode == 0, (second.stdout + second.stderr)[-300:]):
            return
        check(f"{name}: one warning in all (the first part's, step 1)",
              killed_output.count(warning) == 1 and second.stdout.count(warning) == 0,
              f"{killed_output.count(warning)} before the stop, {second.stdout.count(warning)} after")
        check(f"{name}: the summary counts 2 of 20 steps", counted in second.stdout,
              [x for x in second.stdout.splitlines() if "steps whose" in x])
        compare(name, folder / f"{the_deck.stem}.h5", reference_file)

    # stopped at step 5 (--end), between the two impacts
    folder = work / "kane_two_end"
    first = run(exe, deck, "--output", folder, "--end", 5e-4)
    if check("kane_two_end: first part exit 0", first.returncode == 0, first.stderr.strip()[-300:]):
        restarted("kane_two_end", folder, first.stdout)
    # killed (SIGKILL) at the commit of the checkpoint of step 10: the restart is from step 5
    if have_strace("kane_two_kill9"):
        kdeck = edit_deck(deck, work / "kane_two_kill.dat", extra_output=["checkpoint_interval = 5"])
        folder = work / "kane_two_kill9"
        trace = "rename,renameat,renameat2"
        proc = subprocess.run(["strace", "-f", "-o", os.devnull, "-P", str(folder / "checkpoint.h5.tmp"),
                               "-e", f"trace={trace}", "-e", f"inject={trace}:signal=SIGKILL:when=2", str(exe),
                               str(kdeck), "--output", str(folder)], capture_output=True, text=True, timeout=300)
        if check("kane_two_kill9: killed at the commit of the second checkpoint", proc.returncode in (-9, 128 + 9),
                 f"exit {proc.returncode} {proc.stderr.strip()[-200:]}"):
            with h5py.File(folder / "checkpoint.h5", "r") as f:
                step = int(f["loop"].attrs["step"])
            check("kane_two_kill9: the checkpoint left is that of step 5", step == 5, f"step {step}")
            # the deck's own uninterrupted run (the same results, but for the deck's text)
            kref = run(exe, kdeck, "--output", work / "ref_kane_two_kill", "--quiet")
            assert kref.returncode == 0, kref.stderr
            restarted("kane_two_kill9", folder, proc.stdout, kdeck, work / "ref_kane_two_kill" / "kane_two_kill.h5")
    # a checkpoint of the previous build, without the count: accepted, counted from the restart
    # (the second impact alone, warned about again)
    folder = work / "kane_two_old"
    first = run(exe, deck, "--output", folder, "--end", 5e-4, "--quiet")
    assert first.returncode == 0, first.stderr
    with h5py.File(folder / "checkpoint.h5", "r+") as f:
        creating = f["loop"].attrs.get("creating")
        check("kane_two_old: the checkpoint of step 5 records one step that created energy", creating == 1,
              f"/loop@creating {creating}")
        if creating is not None:
            del f["loop"].attrs["creating"]
    second = run(exe, deck, "--output", folder, "--restart", folder / "checkpoint.h5")
    check("kane_two_old: a checkpoint without /loop@creating is accepted, the count from the restart",
          second.returncode == 0 and "steps whose contacts created energy: 1 of 20" in second.stdout,
          (second.stdout + second.stderr).strip()[-400:])

def pwrites(exe, args, counts):
    """The pwrite64 calls of a run (strace -c): the numbers of the kill points below."""
    subprocess.run(["strace", "-f", "-c", "-o", str(counts), "-e", "trace=pwrite64", str(exe)] +
                   [str(a) for a in args], capture_output=True, text=True, timeout=300)
    rows = [line.split() for line in counts.read_text().splitlines() if line.strip().endswith("pwrite64")]
    return int(rows[0][3])


def killed_in_metadata_writes(exe, src, work):
    """A SIGKILL inside HDF5's metadata writes, where the results file is changed in place: the
    restart's first flush (/summary finished and status set back to a running run) and the end
    of the run (/summary and /dem/solver closing attributes). Before, an attribute written again
    was deleted and created anew: /summary's object header got a new continuation block at the
    end of the file, written after the header that points to it, and a kill between the two
    writes (pwrite 23-28 of the restart, the last 3 of a run) left '/' unlistable and the
    checkpoint useless for good. Every kill here must leave the same command able to finish the
    run, bitwise as the uninterrupted one (doc/output.md, restart)."""
    if not have_strace("killed_in_metadata_writes"):
        return
    # the beam of input/cantilever.dat to 0.2 s (1 000 steps, of its 2 500: the writes killed
    # are those of a restart's first flush and of a run's end, whatever its length)
    (work / "meta_deck").mkdir()
    deck = edit_deck(src / "input" / "cantilever.dat", work / "meta_deck" / "cantilever.dat", end=0.2)
    env = dict(os.environ, OMP_NUM_THREADS="1")
    ref = work / "ref_meta_kill"
    proc = run(exe, deck, "--output", ref, "--quiet", env=env)
    assert proc.returncode == 0, proc.stderr

    def kill_at(args, when, sig="SIGKILL"):
        return subprocess.run(["strace", "-f", "-qq", "-o", os.devnull, "-e", "trace=pwrite64", "-e",
                               f"inject=pwrite64:signal={sig}:when={when}", str(exe)] + [str(a) for a in args],
                              capture_output=True, text=True, timeout=300, env=env)

    def finishes(name, folder, restart):
        again = run(exe, deck, "--output", folder, "--quiet",
                    *(["--restart", folder / "checkpoint.h5"] if restart else []), env=env)
        if check(f"{name}: the same command finishes the run", again.returncode == 0,
                 (again.stdout + again.stderr).strip()[-300:]):
            compare(name, folder / "cantilever.h5", ref / "cantilever.h5")

    # (a) stopped by SIGTERM in the time loop (at its 1200th pwrite: step 391 of 1000), then
    # its restart killed in its first flush (pwrite 22 is the first of the metadata, 28 the
    # superblock that ends it; the same writes as with the 2 500 steps of the deck, stopped
    # at step 991)
    seed = work / "meta_seed"
    proc = kill_at([deck, "--output", seed, "--quiet"], 1200, "SIGTERM")
    assert proc.returncode == 128 + 15, proc.stderr
    for when in (23, 25, 27):
        name = f"meta_restart_{when}"
        folder = work / name
        shutil.copytree(seed, folder)
        proc = kill_at([deck, "--output", folder, "--quiet", "--restart", folder / "checkpoint.h5"], when)
        if check(f"{name}: restart killed at its pwrite {when}", proc.returncode in (-9, 128 + 9),
                 f"exit {proc.returncode}"):
            finishes(name, folder, True)
    # (b) killed in the last writes of a run, after its final checkpoint: the results file is closed
    n = pwrites(exe, [deck, "--output", work / "meta_count", "--quiet"], work / "meta_count.txt")
    for back in (1, 2, 3):
        name = f"meta_close_{back}"
        folder = work / name
        proc = kill_at([deck, "--output", folder, "--quiet"], n - back)
        if check(f"{name}: killed at pwrite {n - back} of {n}", proc.returncode in (-9, 128 + 9),
                 f"exit {proc.returncode}"):
            finishes(name, folder, True)
    killed_before_superblock(exe, work, env)


# 100 disks dropped into a box, every contact stored: time series of several chunks each,
# new chunks at most outputs' flushes.
FLUSH_DECK = """[run]
analysis = dynamic
[particles]
material = 1 2500
deposit = 100 0 0.2 0 0.002 0.003 1 7 0.05
gravity = 0 -9.81
[walls]
wall = 0 0 0.2 0
wall = 0 0 0 0.3
wall = 0.2 0 0.2 0.3
[contacts]
law = 1 1 0.4 0.2 0
alert = 1e-3
[time]
step = 5e-4
end = 0.1
[output]
interval = 5
progress = 0
contacts = yes
checkpoint_interval = 40
"""


def killed_before_superblock(exe, work, env):
    """A SIGKILL inside an output's flush, at the write of the superblock that ends it (HDF5
    writes the superblock, which holds the file's end of allocation, last). The flush's new
    chunks and index blocks are on disk beyond the end of allocation the file then records.
    Before, the restart allocated from that stale end, over those blocks: a contact series'
    index overwritten by a heap block, so values of outputs kept from the checkpoint read
    back wrong, or the restart failed (exit 1), on every flush of this run that grew the
    file (audit of 2026-11-28; 600 disks: records of /dem/contacts/status replaced by the
    bytes of 'GCOL', exit 0). Now the restart's allocations start past the file's end."""
    deck = work / "flush_deposit.dat"
    deck.write_text(FLUSH_DECK)
    ref = work / "ref_flush"
    proc = run(exe, deck, "--output", ref, "--quiet", env=env)
    assert proc.returncode == 0, proc.stderr
    # the results file's pwrites of a run (strace -P: that file alone, as the kills below)
    trace = work / "flush_trace.txt"
    partial = work / "flush_trace" / "flush_deposit.h5.partial"
    subprocess.run(["strace", "-f", "-qq", "-o", str(trace), "-P", str(partial), "-e", "trace=pwrite64", str(exe),
                    str(deck), "--output", str(partial.parent), "--quiet"], capture_output=True, timeout=300, env=env)
    writes = [(int(m.group(2)), int(m.group(1))) for m in
              (re.search(r"pwrite64\(\d+, .*, (\d+), (\d+)\) = ", line) for line in trace.read_text().splitlines())
              if m]
    # superblock writes (offset 0) ending a flush that wrote past the file's extent at the
    # flush before: kill points in the second half of the run (checkpoints before them)
    points, end, end_before, last = [], 0, 0, 0
    for k, (offset, size) in enumerate(writes, start=1):
        if offset == 0:
            if last and any(o >= end_before for o, _ in writes[last:k - 1]):
                points.append(k)
            last, end_before = k, end
        end = max(end, offset + size)
    points = [k for k in points if 2 * k > len(writes) and k < len(writes) - 10]
    check("flush kill points: flushes that grow the file in the run's second half", len(points) >= 2,
          f"{len(writes)} pwrites, kill points {points}")
    for when in points[-2:]:
        name = f"meta_superblock_{when}"
        folder = work / name
        proc = subprocess.run(["strace", "-f", "-qq", "-o", os.devnull, "-P", str(folder / partial.name), "-e",
                               "trace=pwrite64", "-e", f"inject=pwrite64:signal=SIGKILL:when={when}", str(exe), str(deck),
                               "--output", str(folder), "--quiet"], capture_output=True, text=True, timeout=300, env=env)
        if not check(f"{name}: killed at the superblock write {when} of {len(writes)}",
                     proc.returncode in (-9, 128 + 9), f"exit {proc.returncode}"):
            continue
        again = run(exe, deck, "--output", folder, "--quiet", "--restart", folder / "checkpoint.h5", env=env)
        if check(f"{name}: the same command finishes the run", again.returncode == 0,
                 (again.stdout + again.stderr).strip()[-300:]):
            compare(name, folder / "flush_deposit.h5", ref / "flush_deposit.h5")


def part_runs(exe, src, work, decks, beam):
    """Runs stopped by a shorter end time (--end): beam, bonded rows, piston, spinning pairs,
    Siconos' rule, the coupled stack, the 2D continuum and the continuum-disk coupled runs; a
    checkpoint of another kind of run refused."""
    # Stop at step 253 (outputs every 5 steps): the extra last output of the first part
    # must be cut at the restart.
    by_end_time(exe, beam, work, "beam_end", 0.0506)
    # The row's first bond breaks at t = 0.0871 s, the second at 0.15 s: the stop at
    # t = 0.1 s (step 500) lies between them.
    ref = by_end_time(exe, src / "input" / "cohesive_row.dat", work, "bonds_end", 0.1)
    with h5py.File(ref, "r") as f, \
            h5py.File(work / "bonds_end_first_checkpoint.h5", "r") as c:
        times = f["dem/bonds/time"][...]
        in_checkpoint = int(c["dem/ruptures"].attrs["n"])
        intact = int(np.sum(c["dem/contacts/status"][...] == 3))
    check("bonds_end: one rupture before the stop, one after", len(times) == 2 and
          times[0] < 0.1 < times[1] and in_checkpoint == 1,
          f"ruptures at {times} s, {in_checkpoint} in the checkpoint")
    check("bonds_end: the checkpoint holds intact bonds (status 3)", intact == 8,
          f"{intact} intact bonds")
    # The same row with the bonds solved as a direct block ([solver] method = block): the
    # block's factor, kept from step to step, is restored from the checkpoint, with the row
    # of the bond broken before the stop deleted from it again (/dem/block/deleted; without
    # that the contacts' reactions differ from the uninterrupted run's).
    block = work / "cohesive_row_block.dat"
    block.write_text(re.sub(r"^\[solver\]\s*$", "[solver]\nmethod = block",
                            (src / "input" / "cohesive_row.dat").read_text(), count=1, flags=re.M))
    by_end_time(exe, block, work, "block_end", 0.1)
    # A driven wall and unconverged steps: the walls' end points and the count of unconverged
    # steps (/dem/solver@unconverged_steps) come back from the checkpoint. Stopped at step
    # 125, not an output step.
    piston = work / "piston.dat"
    piston.write_text(PISTON)
    ref = by_end_time(exe, piston, work, "piston_end", 0.125)
    with h5py.File(ref, "r") as f, h5py.File(work / "piston_end_first_checkpoint.h5", "r") as c:
        total = int(f["dem/solver"].attrs["unconverged_steps"])
        before = int(c["loop"].attrs["unconverged"])
        ceiling = (float(c["dem/walls/y1"][3]), float(c["dem/walls/y2"][3]))
    check("piston_end: unconverged steps before and after the stop", 0 < before < total,
          f"{before} before the stop, {total} in all")
    # 0.2 m/s for 0.125 s: both ends at 0.1 - 0.025 m (to round-off)
    check("piston_end: the piston moved down 25 mm before the stop",
          all(abs(y - 0.075) < 1e-12 for y in ceiling), f"ends at y = {ceiling} m")
    # A spinning bonded pair (bond made on the start positions): stopped at step 103.
    spin = work / "spin_pair.dat"
    spin.write_text(SPIN)
    by_end_time(exe, spin, work, "spin_end", 0.1033)
    with h5py.File(work / "spin_end_first_checkpoint.h5", "r") as c:
        status = c["dem/contacts/status"][...].tolist() if "dem/contacts/status" in c else []
    check("spin_end: the checkpoint holds the pair's intact bond", status == [3], f"statuses {status}")
    # The same pair at 50 rad/s: the rigid bond holds the velocity, so the pair drifts apart by
    # about d (omega h)^2 / 2 per step and the detection loses the bond at step 117 (logged in
    # /dem/bonds with mode 5, lost). Stopped at step 200, after the loss: a checkpoint holding
    # a lost bond was refused as damaged ('/dem/ruptures/mode is 5, outside 1..4').
    lost = work / "spin_lost.dat"
    lost.write_text(SPIN.replace("initial_rigid = all 0 0 5.0", "initial_rigid = all 0 0 50.0")
                    .replace("end = 0.2", "end = 0.4"))
    by_end_time(exe, lost, work, "lost_end", 0.2)
    with h5py.File(work / "lost_end_first_checkpoint.h5", "r") as c:
        modes = c["dem/ruptures/mode"][...].tolist() if "dem/ruptures/mode" in c else []
    check("lost_end: the checkpoint holds the lost bond (mode 5)", modes == [5], f"modes {modes}")
    # The deposit compared with Siconos, with Siconos' rule of activation ([time] contact_scheme
    # = siconos): the rule reads the outputs of the previous step's contacts, which the
    # checkpoint keeps (dem/contacts/y). Stopped at step 85, while the pile forms, and continued
    # 15 steps (the deposit's steps cost most while it forms: 65 more took 1.2 s of CPU).
    sic = edit_deck(src / "input" / "siconos_deposit_200.dat", work / "siconos_scheme.dat", end=0.2)
    check("siconos_scheme_end: the deck uses the Siconos scheme",
          re.search(r"^contact_scheme\s*=\s*siconos\s*$", sic.read_text(), flags=re.M) is not None, "")
    by_end_time(exe, sic, work, "siconos_scheme_end", 0.17)
    stack = edit_deck(src / "input" / "bending_stack.dat", work / "coupled_stack.dat", end=3.0e-4)
    by_end_time(exe, stack, work, "coupled_end", 1.3e-4)
    # 2D continuum: 300 steps (of the deck's 500), outputs every 5; the stop at step 204 is not
    # an output step.
    continuum = edit_deck(src / "input" / "continuum_cantilever_dynamic.dat", work / "continuum.dat", end=0.3)
    by_end_time(exe, continuum, work, "continuum_end", 0.2033)
    # A checkpoint whose kind of run is not the deck's (the header edited): refused.
    other_kind = work / "other_kind.h5"
    shutil.copy(work / "continuum_end" / "checkpoint.h5", other_kind)
    with h5py.File(other_kind, "r+") as f:
        f.attrs["kind"] = "coupled2d"
    proc = run(exe, continuum, "--output", work / "continuum_end", "--restart", other_kind, "--end", 0.6)
    check("a checkpoint of another kind of run refused", proc.returncode == 1 and
          "holds a coupled2d run, the deck is a continuum run" in proc.stderr, proc.stderr.strip())
    # Continuum + disks: 100 steps, outputs every 10, stop at step 45; per-disk multipliers
    # and the mediator space (multipliers on the FE nodes), whose multipliers are other rows.
    pushed = decks / "coupled2d_pushed.dat"
    by_end_time(exe, pushed, work, "coupled2d_end", 4.43e-4)
    nodes = work / "coupled2d_nodes.dat"
    nodes.write_text(re.sub(r"^\[coupling\]\s*$", "[coupling]\nmultipliers = nodes", pushed.read_text(),
                            count=1, flags=re.M))
    by_end_time(exe, nodes, work, "coupled2d_nodes_end", 6.17e-4)
    # A displacement prescribed in time inside the overlap: the continuum's audit and the
    # multipliers' work through the prescribed dofs come back from the checkpoint.
    by_end_time(exe, decks / "coupled2d_driven_edge.dat", work, "coupled2d_driven_end", 4.43e-4)


def part_signals(exe, src, work, decks, beam):
    """Runs stopped by a signal or by kill -9 after a periodic checkpoint: beam, particles,
    coupled, 2D continuum, continuum-disk coupled."""
    # each deck ends a few hundred steps after the step awaited (EVERY_STEP)
    by_signal(exe, src / "input" / "cantilever.dat", work, "beam_term", signal.SIGTERM, 0.3, 1000)
    by_signal(exe, src / "input" / "incline.dat", work, "dem_usr1", signal.SIGUSR1, 2.5, 2000)
    # Started with --end 0.4 s (the deck says 0.5 s): the printed command ends at 0.4 s too.
    signal_with_end(exe, src / "input" / "cantilever.dat", work, "beam_term_end", 0.5, 0.4, 1000)
    by_signal(exe, decks / "coupled_rigid_translation.dat", work, "coupled_term", signal.SIGTERM,
              0.015, 1000)
    by_kill_9(exe, src / "input" / "cantilever.dat", work, "beam_kill9", 0.5, 700, 2000)
    # Every 0.05 s of wall time: several checkpoints before step 3000 (about 0.2 ms per step).
    by_kill_9(exe, src / "input" / "incline.dat", work, "dem_kill9_wall", 3.5, 0, 3000,
              seconds=0.05)
    # (the continuum's steps cost 2 ms each in the Debug build: runs of 450 and 500 steps)
    by_signal(exe, src / "input" / "continuum_cantilever_dynamic.dat", work, "continuum_term",
              signal.SIGTERM, 0.45, 200)
    by_kill_9(exe, src / "input" / "continuum_cantilever_dynamic.dat", work, "continuum_kill9", 0.5, 100, 250)
    by_signal(exe, decks / "coupled2d_pushed.dat", work, "coupled2d_usr1", signal.SIGUSR1, 3.0e-3, 60)


def part_files(exe, src, work, decks, beam):
    """The results folder's files: refusals, damaged checkpoints, failed runs, kills around the
    last checkpoint, partial files set aside, counts kept in the checkpoint."""
    wall_time_over_runs(exe, src, work)
    earlier_results(exe, src, work)
    other_threads(exe, src, work)
    refusals(exe, beam, work)
    two_decks_one_folder(exe, src, work)
    damaged_bytes(exe, src, work)
    damaged_values(exe, src, work)
    damaged_contacts(exe, src, work)
    failed_runs_keep_state(exe, src, work)
    changed_mesh(exe, src, work)
    new_end_time(exe, beam, work)
    killed_after_last_checkpoint(exe, src, work)
    set_aside_partial_files(exe, src, work)
    stale_prev_of_the_same_run(exe, src, work)
    continuation_set_aside(exe, src, work)
    created_energy_counts(exe, work)
    killed_in_metadata_writes(exe, src, work)


# The three groups of checks, each independent of the others (ctest runs each as a test of
# its own, regression_test_restart_<name>, so that they run side by side and each stays well
# within the time limit: the whole script took 178 s under ctest -j2 on the loaded 2-core
# test machine, 2026-11-28, against 54 s before).
PARTS = {"runs": part_runs, "signals": part_signals, "files": part_files}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--exe", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--source", required=True)
    ap.add_argument("--part", choices=("all",) + tuple(PARTS), default="all",
                    help="the group of checks to run (ctest runs the three as three tests)")
    a = ap.parse_args()
    exe, src, work = pathlib.Path(a.exe).resolve(), pathlib.Path(a.source), pathlib.Path(a.work).resolve()
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    decks = src / "tests" / "regression" / "decks"
    beam = edit_deck(src / "input" / "cantilever.dat", work / "beam.dat", end=0.1)
    for name, part in PARTS.items():
        if a.part in ("all", name):
            part(exe, src, work, decks, beam)
    sys.exit(summary())


if __name__ == "__main__":
    main()
