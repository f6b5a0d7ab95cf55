#!/usr/bin/env python3
"""Errors of the files a run writes besides its HDF5 results, and of the files it finds
(doc/output.md, "Write errors", the folder lock, "Checkpoints and restart").

- The XDMF file: libgfortran did not report its write errors (exit 0 with a truncated or
  empty `.xdmf`). Its path '.partial' a link to /dev/full (every write ENOSPC), and a file
  size limit (RLIMIT_FSIZE, as `ulimit -f`) between the sizes of the HDF5 and the XDMF file
  of input/cantilever.dat: exit 1 with the system's reason. A static analysis (no checkpoint)
  leaves the folder as it found it. A time loop writes its XDMF file after its final
  checkpoint, with its results whole: it deleted them and its checkpoint all the same (a long
  run that hits its quota at the end lost everything). Now it leaves them as a run killed
  there does, '<name>.h5.partial' and the checkpoint of the last step (the failed XDMF file
  removed; an earlier finished result and its XDMF file untouched, an earlier partial file set
  aside deleted, as for a stopped run), and the error gives the command that finishes the run:
  run with the "disk" still full it fails again the same way, once it is freed it gives the
  uninterrupted run's results and XDMF file bit for bit (a beam with an extra output after the
  checkpoint, a bonded particle row, the beam under the file size limit). So too when the
  rename of the results file is refused (ENOSPC injected by strace; before, the partial file
  was left without its checkpoint, which the failed run deleted). A results file whose close
  fails as well (its last write refused by strace) is not trusted: the run fails as any other.
- A file size limit of 0 (`ulimit -f 0`): SIGXFSZ killed the run (exit -25) at the lock's
  first write and left an empty lock that refused every later run. Now exit 1 with the
  reason, no lock and no folder left, and the next run works. An empty lock (left so by an
  earlier version) is refused with how to remove it.
- A damaged results file continued by --restart (truncated, its first bytes overwritten, 64
  bytes of its metadata overwritten): the error says the file is damaged and names it (it said
  that file had been moved or replaced by another run, or named the temporary copy and blamed
  the deck).
- A results folder that cannot be created (its parent read-only; a regular file in its
  path): the error gives the reason.
Usage (ctest does this): test_io_errors.py --exe multicor --work DIR --source REPO
"""
import hashlib
import os
import pathlib
import resource
import shlex
import shutil
import subprocess
import sys

import h5py

from checks import arguments, check, have_strace, summary
from test_restart import compare, compare_xdmf


def run(exe, *args, limit=None, user=None):
    """multicor with `args`; under a file size limit of `limit` bytes, as user id `user`."""
    def prepare():
        if limit is not None:
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
        if user is not None:
            os.setgid(user)
            os.setuid(user)
    return subprocess.run([str(exe)] + [str(a) for a in args], capture_output=True, text=True,
                          timeout=300, preexec_fn=prepare)


def digests(folder):
    """SHA-256 of every file of `folder`, by name."""
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(folder.iterdir())
            if p.is_file() and not p.is_symlink()}


def files_in(folder):
    """The names of the files in a folder (hidden ones too: the lock); none when it is gone."""
    return sorted(p.name for p in folder.iterdir()) if folder.is_dir() else []


def finish_command(err):
    """The command the error of a run that kept its results after its final checkpoint gives
    to finish it (split as the shell would), or None."""
    head = "this command finishes the run, with no step to do: "
    if head not in err:
        return None
    return shlex.split(err.split(head, 1)[1].splitlines()[0])


def kept_after_last_checkpoint(exe, deck, folder, name, proc, reason, earlier=None):
    """The run `proc` failed writing its XDMF file after its final checkpoint: exit 1 with the
    reason; the folder holds its results '.partial' (finished = 0, this run's) and its final
    checkpoint, and of the earlier files only a finished result and its XDMF file (`earlier`:
    their digests), untouched. Returns the command the error gives to finish the run."""
    err = proc.stderr.strip()
    partial = folder / f"{deck.stem}.h5.partial"
    check(f"{name}: exit 1", proc.returncode == 1, f"exit {proc.returncode}: {err[-300:]}")
    check(f"{name}: the error names the XDMF file and the reason",
          f"cannot write the XDMF file '{folder}/{deck.stem}.xdmf.partial': {reason}" in err, err[-400:])
    check(f"{name}: the error says the results are whole, where, with which checkpoint",
          f"the results are whole, kept as '{partial}' with the checkpoint of the last step "
          f"'{folder}/checkpoint.h5'" in err, err[-400:])
    command = finish_command(err)
    check(f"{name}: the error gives the command that finishes the run",
          command is not None and command[0] == "multicor" and "--restart" in command, err[-300:])
    expected = sorted([partial.name, "checkpoint.h5"] + sorted(earlier or {}))
    check(f"{name}: the results '.partial' and the checkpoint kept, the failed XDMF file removed, "
          "nothing set aside left", files_in(folder) == expected, f"{files_in(folder)}")
    check(f"{name}: /dev/full still there (only the link was removed)", pathlib.Path("/dev/full").is_char_device(), "")
    if earlier:
        check(f"{name}: the earlier finished result and its XDMF file untouched",
              {k: v for k, v in digests(folder).items() if k in earlier} == earlier, "")
    if partial.is_file() and (folder / "checkpoint.h5").is_file():
        with h5py.File(partial, "r") as f:
            finished, run_id = int(f["summary"].attrs["finished"]), f.attrs["run_id"]
        with h5py.File(folder / "checkpoint.h5", "r") as f:
            ck_run_id = f.attrs["run_id"]
        check(f"{name}: the partial file is this run's, unfinished, and the checkpoint's results",
              finished == 0 and run_id == ck_run_id, f"finished = {finished}, run ids {run_id} / {ck_run_id}")
    return command


def finished_by_command(exe, deck, folder, name, command, reference):
    """The command the error gave, once the XDMF file can be written: the run finished with no
    step, its results and XDMF file bitwise the uninterrupted run's, nothing else left."""
    proc = run(exe, *command[1:])
    check(f"{name}: the command given finishes the run once the space is free: exit 0, no step",
          proc.returncode == 0 and "no step to do" in proc.stdout and "(0 in this run)" in proc.stdout,
          (proc.stdout + proc.stderr).strip()[-300:])
    if proc.returncode != 0:
        return
    compare(name, folder / f"{deck.stem}.h5", reference)
    compare_xdmf(name, folder / f"{deck.stem}.xdmf", reference.with_suffix(".xdmf"))
    check(f"{name}: the results, the XDMF file and the checkpoint are left",
          files_in(folder) == sorted([f"{deck.stem}.h5", f"{deck.stem}.xdmf", "checkpoint.h5"]),
          str(files_in(folder)))


def xdmf_full_after_last_checkpoint(exe, deck, work, name, end=(), earlier=None, still_full=False):
    """A dynamic run of `deck` (with `end`, options) whose XDMF file is on a full device (its
    '.partial' a link to /dev/full), in a folder that holds an `earlier` run's files: a finished
    result and its XDMF file ("finished"), or a partial file of the same deck ("interrupted", its
    checkpoint removed)."""
    ref = work / f"ref_{name}"
    proc = run(exe, deck, "--output", ref, "--quiet", *end)
    assert proc.returncode == 0, proc.stderr
    folder = work / name
    kept = None
    if earlier is not None:
        proc = run(exe, deck, "--output", folder, "--quiet", "--end", earlier[1])
        assert proc.returncode == 0, proc.stderr
        if earlier[0] == "finished":
            kept = {k: v for k, v in digests(folder).items() if k != "checkpoint.h5"}
        else:
            # what a run killed at the rename of its results leaves (but the XDMF file), its
            # checkpoint removed: a fresh run over a run that can be continued is refused
            # (test_shared_folder.py); without it, the partial file is set aside and replaced
            (folder / f"{deck.stem}.h5").rename(folder / f"{deck.stem}.h5.partial")
            (folder / f"{deck.stem}.xdmf").unlink()
            (folder / "checkpoint.h5").unlink()
    folder.mkdir(exist_ok=True)
    link = folder / f"{deck.stem}.xdmf.partial"
    link.symlink_to("/dev/full")
    proc = run(exe, deck, "--output", folder, "--quiet", *end)
    command = kept_after_last_checkpoint(exe, deck, folder, name, proc, "No space left on device", kept)
    if command is None:
        return
    if still_full:
        link.symlink_to("/dev/full")
        before = digests(folder)
        again = run(exe, *command[1:])
        check(f"{name}: the command given, the disk still full: exit 1, the same command again",
              again.returncode == 1 and finish_command(again.stderr.strip()) == command, again.stderr.strip()[-300:])
        check(f"{name}: the command given, the disk still full: the same files, the link removed",
              sorted(before) == [n for n in files_in(folder)], f"{files_in(folder)}")
    finished_by_command(exe, deck, folder, name, command, ref / f"{deck.stem}.h5")


def xdmf_write_errors(exe, src, deck, work):
    # a beam whose end (503 steps, outputs every 5) stores an extra output after the final
    # checkpoint, in the folder of a finished earlier run
    xdmf_full_after_last_checkpoint(exe, deck, work, "xdmf_full_beam", end=("--end", "0.1006"),
                                    earlier=("finished", "0.02"), still_full=True)
    # a bonded particle row (two ruptures) in the folder of an interrupted run of the deck
    xdmf_full_after_last_checkpoint(exe, src / "input" / "cohesive_row.dat", work, "xdmf_full_particles",
                                    earlier=("interrupted", "0.05"))

    # the rename of the results file refused (ENOSPC: a folder that cannot grow), by strace
    if have_strace("the rename of the results file refused"):
        folder = work / "rename_refused"
        partial = folder / f"{deck.stem}.h5.partial"
        renames = "rename,renameat,renameat2"
        proc = subprocess.run(["strace", "-f", "-qq", "-o", os.devnull, "-P", str(partial), "-e", f"trace={renames}",
                               "-e", f"inject={renames}:error=ENOSPC:when=1", str(exe), str(deck), "--output",
                               str(folder), "--quiet", "--end", "0.1006"], capture_output=True, text=True, timeout=300)
        err = proc.stderr.strip()
        command = finish_command(err)
        check("rename refused: exit 1, the error names the rename and the system's reason, says the results are "
              "whole, gives the command",
              proc.returncode == 1 and f"results: cannot rename '{partial}' to '{folder}/{deck.stem}.h5': No space left on device; the results "
              f"are whole, kept as '{partial}' with the checkpoint of the last step '{folder}/checkpoint.h5'" in err
              and command is not None, f"exit {proc.returncode}: {err[-400:]}")
        check("rename refused: the results '.partial' and the checkpoint kept, nothing else",
              files_in(folder) == sorted([partial.name, "checkpoint.h5"]), f"{files_in(folder)}")
        if command is not None:
            finished_by_command(exe, deck, folder, "rename refused", command,
                                work / "ref_xdmf_full_beam" / f"{deck.stem}.h5")

        # the XDMF file on a full device and the close of the results file refused too (its last
        # pwrite, the superblock, ENOSPC): a file whose close failed is not trusted, the run fails
        # as any other (the results and the checkpoint deleted)
        def under_strace(folder, *options):
            folder.mkdir()
            (folder / f"{deck.stem}.xdmf.partial").symlink_to("/dev/full")
            partial = folder / f"{deck.stem}.h5.partial"
            return subprocess.run(["strace", "-f", "-qq", "-P", str(partial), "-e", "trace=pwrite64", *options,
                                   str(exe), str(deck), "--output", str(folder), "--quiet", "--end", "0.1006"],
                                  capture_output=True, text=True, timeout=300)
        trace = work / "close_refused.trace"
        under_strace(work / "close_counted", "-o", str(trace))
        writes = sum("pwrite64(" in line for line in trace.read_text().splitlines())
        folder = work / "close_refused"
        proc = under_strace(folder, "-o", os.devnull, "-e", f"inject=pwrite64:error=ENOSPC:when={writes}")
        err = proc.stderr.strip()
        check(f"XDMF file and the close of the results file refused (pwrite {writes}): exit 1, both errors, no command",
              proc.returncode == 1 and "cannot write the XDMF file" in err and "cannot close file" in err and
              finish_command(err) is None, f"exit {proc.returncode}: {err[-300:]}")
        check("XDMF file and the close of the results file refused: nothing left", files_in(folder) == [],
              str(files_in(folder)))

    # a static analysis writes no checkpoint: the folder as it found it
    static = src / "tests" / "regression" / "decks" / "cantilever_static.dat"
    folder = work / "xdmf_full_static"
    first = run(exe, static, "--output", folder, "--quiet")
    assert first.returncode == 0, first.stderr
    before = digests(folder)
    (folder / f"{static.stem}.xdmf.partial").symlink_to("/dev/full")
    proc = run(exe, static, "--output", folder, "--quiet")
    err = proc.stderr.strip()
    check("static, XDMF file on a full device: exit 1 with the reason", proc.returncode == 1 and
          f"cannot write the XDMF file '{folder}/{static.stem}.xdmf.partial': No space left on device" in err
          and finish_command(err) is None, f"exit {proc.returncode}: {err[-300:]}")
    check("static, XDMF file on a full device: the earlier result and XDMF file untouched, nothing else",
          digests(folder) == before and files_in(folder) == sorted(before), f"{files_in(folder)}")

    # the whole deck: its XDMF file (one grid per output) is larger than its HDF5 file
    folder = work / "xdmf_fsize"
    ref = run(exe, deck, "--output", work / "xdmf_ref", "--quiet")
    assert ref.returncode == 0, ref.stderr
    h5 = (work / "xdmf_ref" / f"{deck.stem}.h5").stat().st_size
    xdmf = (work / "xdmf_ref" / f"{deck.stem}.xdmf").stat().st_size
    check("cantilever: the XDMF file is larger than the HDF5 file", xdmf > h5 + 65536, f"{xdmf} vs {h5} bytes")
    limit = (h5 + xdmf) // 2
    proc = run(exe, deck, "--output", folder, "--quiet", limit=limit)
    command = kept_after_last_checkpoint(exe, deck, folder, f"XDMF file beyond a file size limit of {limit} bytes",
                                         proc, "File too large")
    if command is not None:
        finished_by_command(exe, deck, folder, "XDMF file beyond the file size limit, then without it", command,
                            work / "xdmf_ref" / f"{deck.stem}.h5")


def zero_file_size(exe, deck, work):
    folder = work / "fsize0"
    proc = run(exe, deck, "--output", folder, "--quiet", "--end", "0.01", limit=0)
    err = proc.stderr.strip()
    check("file size limit 0: exit 1 (not killed by SIGXFSZ)", proc.returncode == 1,
          f"exit {proc.returncode}: {err[-300:]}")
    check("file size limit 0: the lock file cannot be written, with the reason",
          f"cannot create the lock file '{folder}/.multicor.lock': File too large" in err, err[-300:])
    check("file size limit 0: no lock, no folder left", not folder.exists(),
          str(sorted(p.name for p in folder.iterdir())) if folder.exists() else "")
    proc = run(exe, deck, "--output", folder, "--quiet", "--end", "0.01")
    check("file size limit 0: the next run works", proc.returncode == 0, proc.stderr.strip()[-300:])
    lock = folder / ".multicor.lock"
    lock.write_bytes(b"")
    proc = run(exe, deck, "--output", folder, "--quiet", "--end", "0.01")
    err = proc.stderr.strip()
    check("empty lock: exit 1", proc.returncode == 1, f"exit {proc.returncode}")
    check("empty lock: says it is empty and how to remove it",
          f"locked by an empty lock file '{lock}'" in err and f"rm {lock})" in err, err[-300:])
    lock.unlink()
    left = sorted(p.name for p in folder.iterdir() if p.name.startswith(".multicor"))
    check("the lock's own temporary files are gone", left == [], str(left))


def damaged_results(exe, deck, work):
    base = work / "damaged_base"
    first = run(exe, deck, "--output", base, "--quiet", "--end", "0.3")
    assert first.returncode == 0, first.stderr
    size = (base / f"{deck.stem}.h5").stat().st_size
    random_bytes = bytes((37 * k + 11) % 256 for k in range(64))

    def truncate(f):
        os.truncate(f, 400000)

    def overwrite(offset):
        def damage(f):
            with open(f, "r+b") as h:
                h.seek(offset)
                h.write(random_bytes)
        return damage

    cases = [("truncated", truncate), ("first bytes overwritten", overwrite(0)),
             ("metadata at byte 8000 overwritten", overwrite(8000))]
    check("damaged results: the file is longer than its truncation", size > 400000, f"{size} bytes")
    for name, damage in cases:
        folder = work / ("damaged_" + name.split()[0])
        shutil.rmtree(folder, ignore_errors=True)
        shutil.copytree(base, folder)
        result = folder / f"{deck.stem}.h5"
        damage(result)
        before = digests(folder)
        proc = run(exe, deck, "--output", folder, "--quiet", "--restart", folder / "checkpoint.h5")
        err = proc.stderr.strip()
        check(f"damaged results ({name}): exit 1", proc.returncode == 1, f"exit {proc.returncode}")
        check(f"damaged results ({name}): says the file is damaged, names it, and what to do",
              f"the results file '{result}' of the checkpoint's run is damaged" in err and
              ".partial" not in err and f"{deck.name}:" not in err and "without --restart" in err, err[-400:])
        check(f"damaged results ({name}): the folder as it was", digests(folder) == before, "")


def folder_errors(exe, deck, work):
    # as user nobody when root (root may write a read-only folder)
    user = 65534 if os.geteuid() == 0 else None
    if user is not None and run(exe, "--version", user=user).returncode != 0:
        print("skip   folder in a read-only folder: user nobody cannot run the program here")
        user = -1
    parent = work / "read_only"
    parent.mkdir()
    parent.chmod(0o555)
    if user is not None:
        work.chmod(0o755)
    if user != -1:
        proc = run(exe, deck, "--output", parent / "sub", "--quiet", "--end", "0.01", user=user)
        err = proc.stderr.strip()
        check("folder in a read-only folder: exit 1 with the reason", proc.returncode == 1 and
              f"cannot create folder '{parent}/sub': Permission denied" in err,
              f"exit {proc.returncode}: {err[-300:]}")
    parent.chmod(0o755)
    # a folder that user nobody may not enter (mode 0744): its sub-folder is refused for that
    # reason (before: "'nx' is a file, not a folder", from a failed access to 'nx/.')
    if user is not None and user != -1:
        locked = work / "no_entry"
        locked.mkdir()
        locked.chmod(0o744)
        proc = run(exe, deck, "--output", locked / "sub", "--quiet", "--end", "0.01", user=user)
        err = proc.stderr.strip()
        check("folder in a folder one may not enter: exit 1, Permission denied", proc.returncode == 1 and
              f"cannot create folder '{locked}/sub': Permission denied" in err and "is a file" not in err,
              f"exit {proc.returncode}: {err[-300:]}")
        locked.chmod(0o755)
    a_file = work / "a_file"
    a_file.write_text("x\n")
    proc = run(exe, deck, "--output", a_file / "sub" / "deeper", "--quiet", "--end", "0.01")
    err = proc.stderr.strip()
    check("folder under a regular file: exit 1 naming the file", proc.returncode == 1 and
          f"cannot create folder '{a_file}/sub': '{a_file}' is a file, not a folder" in err,
          f"exit {proc.returncode}: {err[-300:]}")


def main():
    exe, work, src = arguments(fresh=True)
    deck = work / "cantilever.dat"
    shutil.copy(src / "input" / "cantilever.dat", deck)
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    xdmf_write_errors(exe, src, deck, work)
    zero_file_size(exe, deck, work)
    damaged_results(exe, deck, work)
    folder_errors(exe, deck, work)
    stale_lock_race(exe, deck, work)
    sys.exit(summary())


def stale_lock_race(exe, deck, work):
    """Two runs take over one stale lock at once: one runs, the other is refused. Run B is held
    (strace, 1.5 s) as it takes the stale lock out of the way: now at its second unlink, that
    of its `.break` lock line's file, holding `.break` (run A, started meanwhile, is refused:
    B takes the stale lock over, and then runs); in the versions before at its first rename
    (setting the stale lock aside) or its second unlink (of the stale lock, by name), and run A
    took the stale lock over meanwhile and held the folder (its first write held 5 s). In the
    first version B then removed A's new lock by name and linked its own: both ran in the
    folder (a review's finding). A third run defeated the renaming version:
    test_lock_takeover.py."""
    if not have_strace("stale_lock_race"):
        return
    import socket
    import time
    folder = work / "stale_race"
    folder.mkdir()
    (folder / ".multicor.lock").write_text(f"{socket.gethostname()} 999999 2026-11-28T00:00:00\n")
    args = [str(exe), str(deck), "--output", str(folder), "--quiet", "--end", "0.01"]
    b = subprocess.Popen(["strace", "-f", "-qq", "-o", os.devnull, "-e", "trace=rename,renameat,renameat2,unlink,unlinkat",
                          "-e", "inject=rename,renameat,renameat2:delay_enter=1500000:when=1",
                          "-e", "inject=unlink,unlinkat:delay_enter=1500000:when=2"] + args,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(0.5)
    a = subprocess.Popen(["strace", "-f", "-qq", "-o", os.devnull, "-e", "trace=pwrite64",
                          "-e", "inject=pwrite64:delay_enter=5000000:when=1"] + args,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    out_b, err_b = b.communicate(timeout=120)
    out_a, err_a = a.communicate(timeout=120)
    codes = sorted([a.returncode, b.returncode])
    refused = [e for e in (err_a, err_b) if f"results folder '{folder}' is in use by another run" in e]
    check("two runs taking over one stale lock: one runs (exit 0), the other is refused (exit 1)",
          codes == [0, 1] and len(refused) == 1, f"exits A {a.returncode}, B {b.returncode}: "
          f"{err_a.strip()[-200:]} | {err_b.strip()[-200:]}")


if __name__ == "__main__":
    main()
