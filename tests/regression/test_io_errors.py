#!/usr/bin/env python3
"""Errors of the files a run writes besides its HDF5 results, and of the files it finds
(doc/output.md, "Write errors", the folder lock, "Checkpoints and restart").

- The XDMF file: libgfortran did not report its write errors (exit 0 with a truncated or
  empty `.xdmf`). Its path '.partial' a link to /dev/full (every write ENOSPC), and a file
  size limit (RLIMIT_FSIZE, as `ulimit -f`) between the sizes of the HDF5 and the XDMF file
  of input/cantilever.dat: exit 1 with the system's reason, the folder's earlier result,
  XDMF file and checkpoint untouched.
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
import resource
import shutil
import subprocess
import sys

from checks import arguments, check, summary


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


def xdmf_write_errors(exe, deck, work):
    folder = work / "xdmf_full"
    first = run(exe, deck, "--output", folder, "--quiet", "--end", "0.02")
    assert first.returncode == 0, first.stderr
    before = digests(folder)
    (folder / f"{deck.stem}.xdmf.partial").symlink_to("/dev/full")
    proc = run(exe, deck, "--output", folder, "--quiet", "--end", "0.04")
    err = proc.stderr.strip()
    check("XDMF file on a full device: exit 1", proc.returncode == 1, f"exit {proc.returncode}: {err[-300:]}")
    check("XDMF file on a full device: the error names the file and the reason",
          f"cannot write the XDMF file '{folder}/{deck.stem}.xdmf.partial': No space left on device" in err,
          err[-300:])
    check("XDMF file on a full device: the earlier result, XDMF file and checkpoint untouched",
          digests(folder) == before, f"{sorted(before)} -> {sorted(digests(folder))}")

    # the whole deck: its XDMF file (one grid per output) is larger than its HDF5 file
    folder = work / "xdmf_fsize"
    ref = run(exe, deck, "--output", work / "xdmf_ref", "--quiet")
    assert ref.returncode == 0, ref.stderr
    h5 = (work / "xdmf_ref" / f"{deck.stem}.h5").stat().st_size
    xdmf = (work / "xdmf_ref" / f"{deck.stem}.xdmf").stat().st_size
    check("cantilever: the XDMF file is larger than the HDF5 file", xdmf > h5 + 65536, f"{xdmf} vs {h5} bytes")
    limit = (h5 + xdmf) // 2
    proc = run(exe, deck, "--output", folder, "--quiet", limit=limit)
    err = proc.stderr.strip()
    check(f"XDMF file beyond a file size limit of {limit} bytes: exit 1", proc.returncode == 1,
          f"exit {proc.returncode}: {err[-300:]}")
    check("XDMF file beyond the file size limit: the reason", "cannot write the XDMF file" in err and
          "File too large" in err, err[-300:])
    check("XDMF file beyond the file size limit: the folder it made removed", not folder.exists(),
          str(sorted(p.name for p in folder.iterdir())) if folder.exists() else "")


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
    xdmf_write_errors(exe, deck, work)
    zero_file_size(exe, deck, work)
    damaged_results(exe, deck, work)
    folder_errors(exe, deck, work)
    sys.exit(summary())


if __name__ == "__main__":
    main()
