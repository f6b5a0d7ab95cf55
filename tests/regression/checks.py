"""The checks of the regression scripts: each prints one line, 'ok' or 'FAILED', with its
name and the figures behind it; `summary` prints the closing line 'N passed, M failed' and
gives the exit code (0 only when every check passed and at least one ran). Also the command
line of the scripts and a run of multicor."""
import argparse
import pathlib
import shutil
import subprocess

FAILED = []
PASSED = []


def check(name, ok, detail=""):
    """Record check `name` (ok is its outcome) and print it with `detail`; returns ok."""
    ok = bool(ok)
    print(f"{'ok    ' if ok else 'FAILED'} {name}: {detail}")
    (PASSED if ok else FAILED).append(name)
    return ok


def have_strace(what):
    """Whether strace is here for the fault-injection checks of `what`. strace is a required
    package (./test.sh installs it, scripts/bootstrap.sh): without it those checks would not
    run, so its absence is a failed check, not a skip."""
    found = shutil.which("strace") is not None
    if not found:
        check(f"strace for {what}", False, "strace not found (Debian package strace; ./test.sh installs it)")
    return found


def summary():
    """Print the failed checks and the closing line; the script's exit code."""
    if FAILED:
        print("failed:", ", ".join(FAILED))
    print(f"{len(PASSED)} passed, {len(FAILED)} failed")
    return 1 if FAILED or not PASSED else 0


def arguments(fresh=False):
    """The command line of the scripts (ctest gives it): --exe multicor --work DIR --source
    REPO; returns the three as absolute paths, the work folder created (emptied first when
    `fresh`)."""
    ap = argparse.ArgumentParser()
    ap.add_argument("--exe", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--source", required=True)
    args = ap.parse_args()
    work = pathlib.Path(args.work).resolve()
    if fresh:
        shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True, exist_ok=True)
    return pathlib.Path(args.exe).resolve(), work, pathlib.Path(args.source).resolve()


def multicor(exe, deck, work, quiet=True):
    """Run multicor on `deck` with the results in work/<deck stem>; on a non-zero exit print
    its output and stop the script. Returns (path of the results file, completed process)."""
    out = work / deck.stem
    proc = subprocess.run([str(exe), str(deck), "--output", str(out)] + (["--quiet"] if quiet else []),
                          capture_output=True, text=True)
    if proc.returncode != 0:
        print(proc.stdout, proc.stderr)
        raise SystemExit(f"multicor failed on {deck} (exit {proc.returncode})")
    return out / f"{deck.stem}.h5", proc


def check_summary_without_steps(name, h5, seconds):
    """/summary of a static or modal analysis (doc/output.md): finished, steps = 0, its wall
    time (building the model, solving, writing: at most the `seconds` the process took, which
    the caller measured around it), that of its only run, and the date-time it ended."""
    import re
    import h5py
    import math
    with h5py.File(h5, "r") as f:
        s = dict(f["summary"].attrs)
    wall = float(s.get("wall_seconds", math.nan))
    ok = (int(s.get("finished", 0)) == 1 and s.get("status") == "finished" and int(s.get("steps", -1)) == 0
          and int(s.get("runs", 0)) == 1 and 0 <= wall <= seconds
          and s.get("wall_seconds_last_run") == wall
          and re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d[+-]\d\d:\d\d", str(s.get("ended", ""))) is not None)
    return check(f"{name}: /summary steps = 0, wall_seconds (<= the process's {seconds:.3f} s), ended", ok, str(s))


def plots(src, h5, out, names):
    """plot_results.py on a results file, as ./run.sh calls it after a run (with Python's
    warnings turned into errors): check that it exits 0, prints nothing on stderr and writes
    exactly the PNG files <stem>_<name>.png of `names`, in that order."""
    import sys
    out = pathlib.Path(out)
    proc = subprocess.run([sys.executable, "-W", "error", str(src / "postproc" / "plot_results.py"), str(h5),
                           "--out", str(out)], capture_output=True, text=True)
    stem = pathlib.Path(h5).stem
    expected = [str(out / f"{stem}_{n}.png") for n in names]
    printed = proc.stdout.split()
    check(f"plot_results.py on {pathlib.Path(h5).name}",
          proc.returncode == 0 and not proc.stderr and printed == expected
          and all(pathlib.Path(p).stat().st_size > 0 for p in printed),
          f"exit {proc.returncode}, stderr {proc.stderr.strip()[-300:]!r}, printed {printed}")


# One Python process running postproc/plot_results.py's command line (its __main__) on several
# files in turn: argv[1] the script, argv[2] a JSON list of argument lists; prints a JSON list
# of [exit code, stdout, stderr] per file (an exception: code 1, its traceback on stderr).
_PLOTS_DRIVER = """import contextlib, io, json, runpy, sys, traceback
script, runs, results = sys.argv[1], json.loads(sys.argv[2]), []
for args in runs:
    out, err, code = io.StringIO(), io.StringIO(), 0
    sys.argv = [script] + args
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            runpy.run_path(script, run_name="__main__")
        except SystemExit as e:
            code = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
        except Exception:
            code = 1
            traceback.print_exc()
    results.append([code, out.getvalue(), err.getvalue()])
print(json.dumps(results))
"""


def plots_together(src, runs):
    """`plots` on several results files, `runs` a list of (h5, out, names), in ONE Python process
    (with warnings as errors), which runs plot_results.py's command line on each in turn: the
    interpreter and matplotlib start once (about 1 s of CPU each time). Each file's check is
    that of `plots` (exit code 0, nothing on its stderr, the PNG files printed in order), and
    the process itself must exit 0 with nothing on its stderr (what the libraries write
    there). Use `plots` for at least one file: the true command line, a process of its own."""
    import json
    import sys
    script = src / "postproc" / "plot_results.py"
    args = [[str(h5), "--out", str(out)] for h5, out, _ in runs]
    proc = subprocess.run([sys.executable, "-W", "error", "-c", _PLOTS_DRIVER, str(script), json.dumps(args)],
                          capture_output=True, text=True)
    try:
        results = json.loads(proc.stdout)
    except ValueError:
        results = []
    if len(results) != len(runs):
        results = [[None, "", ""]] * len(runs)
    for (h5, out, names), (code, stdout, stderr) in zip(runs, results):
        out = pathlib.Path(out)
        stem = pathlib.Path(h5).stem
        expected = [str(out / f"{stem}_{n}.png") for n in names]
        printed = stdout.split()
        check(f"plot_results.py on {pathlib.Path(h5).name} (one process with others)",
              proc.returncode == 0 and not proc.stderr and code == 0 and not stderr and printed == expected
              and all(pathlib.Path(p).stat().st_size > 0 for p in printed),
              f"exit {code}, stderr {stderr.strip()[-300:]!r}, printed {printed}; the process: exit "
              f"{proc.returncode}, stderr {proc.stderr.strip()[-300:]!r}")


def with_solver_lines(deck, dst, lines):
    """Write to `dst` the deck `deck` with `lines` added at the top of its [solver] section
    (which it must have); returns `dst`."""
    text = deck.read_text()
    assert "[solver]\n" in text, deck
    dst.write_text(text.replace("[solver]\n", "[solver]\n" + "".join(f"{ln}\n" for ln in lines), 1))
    return dst


def datasets(path, group="/"):
    """Every dataset below `group` of the HDF5 file `path`, by its name relative to the group:
    name -> array."""
    import h5py
    found = {}
    with h5py.File(path, "r") as f:
        f[group].visititems(lambda name, obj: found.update({name: obj[()]}) if isinstance(obj, h5py.Dataset)
                            else None)
    return found
