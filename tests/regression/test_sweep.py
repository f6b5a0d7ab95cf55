#!/usr/bin/env python3
"""scripts/multicor-sweep without Slurm: keys, generated decks, local runs, the table.

- The deck parser reads a name in double quotes as one value, blanks and '#' inside it.
- Keys that the deck does not contain are refused with exit code 1, naming the key, and
  leave no sweep folder; a value that fails `multicor --check` is reported with multicor's
  message naming the generated deck and line.
- A grid file selecting a record by its values (`contacts.law[material1=2 material2=3].mu`)
  and a positional field: the generated decks differ from the deck only in the swept tokens
  (comments and layout kept).
- Two values of one record swept together, the first written longer than the deck's
  (mu 0.1 -> 0.25, and cohesion), the record chosen by numbers written otherwise (2.0, 2d0):
  both values in their own fields.
- Functions called directly: Slurm time limits in minutes (days, seconds rounded up), sbatch
  short options with attached values (-pdebug), a point with Python's -15 and a checkpoint.
- A sequential local run of input/incline.dat over mu of the slipping disk in {0.1, 0.2}:
  the table gives the closed-form final velocity g (sin phi - mu cos phi) cos phi t of
  disk 2, and reductions (absmax of the energy balance, absmax of a negative velocity = -min
  read with h5py) next to indexed values; `starts` counts the starts of job.log but those
  refused by the folder lock.
- A point that fails at run time (gravity 1e300: the run stops with exit code 1) is
  reported as failed; the next `run` runs only that point again.
- Decks whose Gmsh mesh path is relative to their folder, quoted ("My Meshes/bar #1.msh")
  or bare, swept into a folder elsewhere: each point's deck names the mesh by its absolute
  path (quoted when needed), nothing else changes, and a static bar in tension runs
  (max |u| = tx L / E); the mesh path swept itself; an absolute path left as written.
- Records selected by a quoted name (`[edge_set="right #end"]`, in --set and in a grid
  file), matched exactly (a trailing blank is another name); a bare value with '#' or a
  blank, or a quote left open: refused, the message showing the quotes.
- A restart that fails (exit 1) keeps its checkpoint: status calls the point failed.
- create refuses a --time that is no Slurm time limit or not longer than --signal-seconds,
  --max-running 0, a --dir that is a file; `submit` and `status` with stand-ins for sbatch
  and squeue (no Slurm daemon): the cap of --max-running kept by a resubmission, points
  still pending or running in an earlier job not submitted again, squeue out of reach
  (submit refuses unless --force); the collect job with the array's partition, account and
  qos and a time limit within the array's; a collect job refused: the array recorded,
  not submitted again; an array on another cluster (--clusters) asked of it (squeue -M).
Usage (ctest does this): test_sweep.py --exe multicor --work DIR --source REPO
"""
import csv
import importlib.machinery
import json
import math
import re
import subprocess
import sys
import types

from checks import arguments, check, summary

SIN_PHI, COS_PHI, T_END, G = 0.6, 0.8, 0.5, 9.81      # input/incline.dat


def sweep_tool(src, args, expect=0):
    cmd = [sys.executable, str(src / "scripts" / "multicor-sweep")] + [str(a) for a in args]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if expect is not None and proc.returncode != expect:
        print(proc.stdout, proc.stderr)
        raise SystemExit(f"{' '.join(cmd)}: exit {proc.returncode}, expected {expect}")
    return proc


def read_table(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def refused_keys(src, exe, work):
    """Keys the deck does not contain: exit 1, the key named, no sweep folder left."""
    deck = src / "input" / "incline.dat"
    cases = [("contacts.law[3].mu=0.2", "has 2 'law' record(s) in [contacts]"),
             ("contacts.law.mu=0.2", "has 2 'law' records in [contacts] (lines 36, 37)"),
             ("contacts.law[material1=2 material2=9].mu=0.2", "it matches 0"),
             ("solver.tolerance=1e-5", "does not give 'tolerance' in [solver]"),
             ("contacts.law[1].friction=0.2", "'law' has no value 'friction'"),
             ("contacts.law[1].rolling=1e-3", "does not give 'rolling'"),
             ("time.stepp=1e-4", "section [time] has no keyword 'stepp'"),
             ("contact.law[1].mu=0.2", "there is no section [contact]"),
             ("particles.gravity=1", "'gravity' has several values (gx gy)"),
             ("run.title=x", "'title' is text")]
    for key, expected in cases:
        folder = work / "refused"
        proc = sweep_tool(src, ["create", deck, "--exe", exe, "--set", key, "--dir", folder],
                          expect=None)
        k = key.rsplit("=", 1)[0]
        check(f"refuses {k}", proc.returncode == 1 and f"'{k}'" in proc.stderr
              and expected in proc.stderr and not folder.exists(), proc.stderr.strip())
    proc = sweep_tool(src, ["create", deck, "--exe", exe, "--set", "time.end=1",
                            "--set", "time.end=2", "--dir", work / "refused"], expect=None)
    check("refuses a key given twice", proc.returncode == 1
          and "key given twice: time.end" in proc.stderr, proc.stderr.strip())
    proc = sweep_tool(src, ["create", deck, "--exe", exe, "--set", "contacts.law[2].mu=0.1",
                            "--set", "contacts.law[material1=2].3=0.2", "--dir",
                            work / "refused"], expect=None)
    check("refuses two keys naming the same value", proc.returncode == 1
          and "name the same value" in proc.stderr, proc.stderr.strip())
    # a value listed twice, as the same text or as the same number written otherwise
    for values, said in (("1e-4,2e-4,1e-4", "('1e-4' would"),
                         ("1e-4,1E-4", "'1e-4' and '1E-4', the same number")):
        proc = sweep_tool(src, ["create", deck, "--exe", exe, "--set", f"time.step={values}",
                                "--dir", work / "refused"], expect=None)
        check(f"refuses a value listed twice ({values})", proc.returncode == 1
              and "key 'time.step': a value is listed twice" in proc.stderr and said in proc.stderr
              and not (work / "refused").exists(), proc.stderr.strip())
    # a value that the deck check refuses (mu < 0): the message of multicor, naming the line
    proc = sweep_tool(src, ["create", deck, "--exe", exe, "--set", "contacts.law[2].mu=0.1,-1",
                            "--dir", work / "bad_value"], expect=None)
    check("refuses a point that fails multicor --check", proc.returncode == 1
          and "p002 (contacts.law[2].mu=-1)" in proc.stderr
          and "bad_value/decks/p002.dat:" in proc.stderr and "mu" in proc.stderr,
          proc.stderr.strip())


def generated_decks(src, exe, work):
    deck = src / "input" / "incline.dat"
    grid = work / "grid.txt"
    grid.write_text("# friction of the lower disk on its incline, chosen by materials\n"
                    "contacts.law[material1=2 material2=3].mu = 0.1, 0.2\n"
                    "particles.disk[2].3 = 0.05   # the radius, by position\n")
    folder = work / "seq"
    sweep_tool(src, ["create", deck, "--exe", exe, "--grid", grid, "--dir", folder,
                     "--scalar", "v2x=dem/velocity[-1,1,0]",
                     "--scalar", "balance=absmax(dem/energy/balance)",
                     "--scalar", "vmax=max(dem/velocity[:,1,0])",
                     "--scalar", "vy=absmax(dem/velocity[:,1,1])"])
    original = deck.read_text().splitlines()
    for name, mu in (("p001", "0.1"), ("p002", "0.2")):
        lines = (folder / "decks" / f"{name}.dat").read_text().splitlines()
        # the header: '# multicor-sweep point ...' and one line per key
        check(f"{name}: header names the point", lines[0].startswith(
            f"# multicor-sweep point {name} of 2") and lines[1].startswith("#   contacts.law"),
            lines[0])
        body = lines[3:]
        changed = [(a, b) for a, b in zip(original, body) if a != b]
        expected_line = "law      = 2          3          " + mu.ljust(3) \
            + "  0            0"
        check(f"{name}: only the swept token changed", len(body) == len(original)
              and len(changed) == (0 if mu == "0.1" else 1)
              and all(b == expected_line for _, b in changed), str(changed))
    # the keys' units, from the deck reference, for the axes of results.png: mu has none
    units = json.loads((folder / "sweep.json").read_text()).get("units")
    check("sweep.json: the units of the swept values", units == {
        "contacts.law[material1=2 material2=3].mu": "", "particles.disk[2].3": "m"}, str(units))
    return folder


def sweep_module(src):
    """scripts/multicor-sweep loaded as a module, to call its functions."""
    loader = importlib.machinery.SourceFileLoader("multicor_sweep", str(src / "scripts" / "multicor-sweep"))
    sweep = types.ModuleType(loader.name)
    loader.exec_module(sweep)
    return sweep


def quoted_names(src):
    """The deck parser of multicor-sweep reads names in double quotes as multicor does: one
    value each, blanks and '#' inside; the value after such a name is the one a key names."""
    sweep = sweep_module(src)
    lines = ["[run]", 'title = a "quoted # title', "analysis = static", "[continuum]",
             'mesh = file "My Meshes/bar #1.msh"  # "an open quote in a comment',
             'load = "loaded  end #2" x 1e3   # the load',
             "fix = left x y"]
    records = {r.keyword: r for r in sweep.parse_deck(lines)}
    tokens = {k: [lines[r.lineno - 1][a:b] for a, b in r.spans] for k, r in records.items()}
    check("multicor-sweep: quoted names are one value each",
          tokens["mesh"] == ["file", '"My Meshes/bar #1.msh"'] and tokens["load"] == ['"loaded  end #2"', "x", "1e3"]
          and tokens["fix"] == ["left", "x", "y"] and tokens["title"] == ["a", '"quoted'], str(tokens))
    check("multicor-sweep: a quoted name matches a selector's value", sweep.same_value('"left"', "left"), "")


def script_functions(src, work):
    """Functions of multicor-sweep called directly: Slurm's time limits in minutes, sbatch's
    short options with their value attached, the state of a point killed by a signal."""
    sweep = sweep_module(src)
    # Slurm (parse_time.c, time_str2mins): D days of 24 h, the total seconds rounded up to
    # the minute as (s + 59) / 60: 2-03:04:05 = 183845 s -> 3065 min, 2-03:04:00 -> 3064 min;
    # 10:75 = 675 s -> 12 min, 1:30:90 = 5490 s -> 92 min (the script gave 11 and 91)
    expected = {"1-00": 1440, "2-03": 3060, "2-03:04": 3064, "2-03:04:00": 3064,
                "2-03:04:05": 3065, "10:75": 12, "1:30:90": 92, "10:00": 10, "10:01": 11}
    got = {t: sweep.time_minutes(t) for t in expected}
    check("time_minutes: a day is 24 h, seconds rounded up to the minute", got == expected, str(got))
    got = sweep.sbatch_values(["-pdebug", "-Aacct", "--time=5"])
    check("sbatch_values: short options with their value attached (-pdebug, -Aacct)",
          got == {"--partition": "debug", "--account": "acct", "--time": "5"}, str(got))
    # a folder written by a local run before it recorded the shell's code: Python's -15 for
    # SIGTERM, and the checkpoint of the stop
    folder = work / "killed_before"
    out = folder / "runs" / "p001"
    out.mkdir(parents=True)
    (out / "exit_status").write_text("-15\n")
    (out / sweep.CHECKPOINT_NAME).write_text("")
    state = sweep.point_state(folder, {"name": "p001"})
    check("point_state: exit_status -15 (Python's code of SIGTERM) with a checkpoint: 'checkpoint'",
          state == "checkpoint", state)
    # scalar_value reads only the selected records through h5py; the selections h5py does not
    # take (a negative step) are read whole and selected as numpy does: both give numpy's values
    import h5py
    import numpy as np
    data = np.arange(60.0).reshape(5, 4, 3) - 17.0
    with h5py.File(work / "scalars.h5", "w") as f:
        f["s"] = data
    with h5py.File(work / "scalars.h5", "r") as f:
        cases = {"s[-1,1,0]": data[-1, 1, 0], "max(s[:,1,0])": data[:, 1, 0].max(),
                 "sum(s[::-1,0,2])": data[::-1, 0, 2].sum(), "absmax(s[1:3,-1])": np.abs(data[1:3, -1]).max(),
                 "mean(s)": data.mean()}
        got = {spec: sweep.scalar_value(f, f"x={spec}") for spec in cases}
        try:
            sweep.scalar_value(f, "x=s[7,0,0]")
            out_of_range = "no error"
        except IndexError as e:
            out_of_range = f"IndexError {e}"
    check("scalar_value: selections read through h5py or whole give numpy's values; an index out "
          "of range is numpy's IndexError", got == {k: float(v) for k, v in cases.items()}
          and out_of_range.startswith("IndexError"), f"{got}, {out_of_range}")


def same_record(src, exe, work):
    """Two values of one record swept together, the first longer than the text it replaces
    (mu 0.1 -> 0.25), the record chosen by a selector whose numbers are written otherwise
    than in the deck (material1 = 2.0, 2d0 for the deck's 2): both values land in their own
    fields of the incline's second law (before: edits applied from the left, the shift of the
    first moved the second: '0.25  0 20'; or the selector matched nothing)."""
    deck = src / "input" / "incline.dat"
    folder = work / "same_record"
    proc = sweep_tool(src, ["create", deck, "--exe", exe,
                            "--set", "contacts.law[material1=2.0 material2=3].mu=0.25,0.125",
                            "--set", "contacts.law[material1=2d0 material2=3].cohesion=2",
                            "--dir", folder], expect=None)
    decks = sorted((folder / "decks").glob("*.dat")) if proc.returncode == 0 else []
    check("selectors 2.0 and 2d0 match the law of materials 2 and 3: 2 decks",
          [d.name for d in decks] == ["p001.dat", "p002.dat"], proc.stderr.strip()[-300:])
    for path, mu in zip(decks, ("0.25", "0.125")):
        laws = [line.split("#")[0].split("=", 1)[1].split()
                for line in path.read_text().splitlines() if line.startswith("law")]
        check(f"{path.stem}: mu = {mu} and cohesion = 2 in the second law, the first unchanged",
              laws == [["1", "3", "0.5", "0", "0"], ["2", "3", mu, "0", "2"]], str(laws))


def sequential_run(src, folder):
    proc = sweep_tool(src, ["run", folder])
    print(proc.stdout.strip())
    rows = read_table(folder / "results.csv")
    check("table: two rows", len(rows) == 2, str(len(rows)))
    for r in rows:
        mu = float(r["contacts.law[material1=2 material2=3].mu"])
        ref = COS_PHI * G * (SIN_PHI - mu * COS_PHI) * T_END
        # constant acceleration from the first step: exact to round-off (1e-12 relative)
        check(f"{r['point']} mu={mu}: closed-form velocity", r["summary.finished"] == "1"
              and math.isclose(float(r["v2x"]), ref, rel_tol=1e-12)
              and float(r["vmax"]) == float(r["v2x"]),
              f"v2x={r['v2x']} (max over outputs {r['vmax']}) closed form {ref!r}")
        # the energy audit closes to round-off: |balance| <= 1e-9 J/m on ~20 J/m moved
        check(f"{r['point']}: energy balance collected", 0 <= float(r["balance"]) < 1e-9,
              r["balance"])
        # vy of disk 2 is <= 0 at every output (it slides down from rest): absmax is -min,
        # read with h5py; the table's repr of a double reads back exactly
        import h5py
        with h5py.File(folder / r["file"], "r") as f:
            vy = f["dem/velocity"][:, 1, 1]
        check(f"{r['point']}: absmax of a negative series is -min", float(r["vy"]) == -vy.min()
              and vy.max() <= 0 < -vy.min(), f"vy={r['vy']} -min={float(-vy.min())!r}")
    check("results.png drawn", (folder / "results.png").exists(), "")
    # the scalars' units for its axes: from the datasets' units attributes (a column of
    # /dem/velocity's 'm/s, m/s, rad/s', /dem/energy's J/m)
    import h5py
    tool = sweep_module(src)
    with h5py.File(folder / rows[0]["file"], "r") as f:
        units = {spec.split("=")[0]: tool.scalar_unit(f, spec) for spec in
                 ("v2x=dem/velocity[-1,1,0]", "balance=absmax(dem/energy/balance)",
                  "w=dem/velocity[-1,1,2]", "v=absmax(dem/velocity)")}
    check("units of the scalars", units == {"v2x": "m/s", "balance": "J/m", "w": "rad/s",
                                             "v": "m/s, rad/s"}, str(units))
    killed_point(src, folder)
    failed_records(src, folder)


def failed_records(src, folder):
    """A point whose time loop failed after storing outputs keeps them as pNNN.h5.failed
    (doc/output.md): collect reads its /summary, so that the table says what failed, and
    leaves its scalars empty, for its last values are no results (before: an empty row)."""
    import shutil
    import h5py
    import numpy as np
    copy = folder.parent / (folder.name + "_failed")
    shutil.rmtree(copy, ignore_errors=True)
    shutil.copytree(folder, copy)
    out = copy / "runs" / "p001"
    status = "failed at step 41, t = 4.10000000E-002 s: step 41: disk 2 is at 4e291 m"
    with h5py.File(out / "p001.h5", "a") as f:
        f["summary"].attrs["finished"] = np.int32(0)
        f["summary"].attrs["status"] = status
    (out / "p001.h5").rename(out / "p001.h5.failed")
    (out / "exit_status").write_text("1\n")
    sweep_tool(src, ["collect", "--no-plot", copy], expect=None)
    rows = {r["point"]: r for r in read_table(copy / "results.csv")}
    check("collect: a failed point's /summary read from its .failed file, its scalars empty",
          rows["p001"]["summary.status"] == status and rows["p001"]["file"].endswith("p001.h5.failed")
          and all(rows["p001"][k] == "" for k in ("v2x", "vmax", "balance", "vy"))
          and rows["p002"]["v2x"] != "",
          str({k: v for k, v in rows["p001"].items() if k.startswith("summary") or k in ("v2x", "file")}))


def killed_point(src, folder):
    """A point whose run was killed after a restart: its partial file holds the closing
    /summary attributes of the stop it continued (here those of the finished run), which are
    not the killed run's: collect leaves their cells empty, keeps the status."""
    import shutil
    import h5py
    import numpy as np
    copy = folder.parent / (folder.name + "_killed")
    shutil.rmtree(copy, ignore_errors=True)
    shutil.copytree(folder, copy)
    out = copy / "runs" / "p001"
    finished = out / "p001.h5"
    with h5py.File(finished, "a") as f:
        f["summary"].attrs["finished"] = np.int32(0)
        f["summary"].attrs["status"] = "running (or killed)"
    finished.rename(out / "p001.h5.partial")
    # p002 started twice more by Slurm jobs, the second refused by the first's folder lock
    # (the job script's lines): 3 starts, 1 refused, so 2 starts counted
    with open(copy / "runs" / "p002" / "job.log", "a") as log:
        log.write("2026-01-01T00:00:00+00:00 p002 start 71 restart_count=0: --quiet p002.dat\n"
                  "2026-01-01T00:00:01+00:00 p002 start 72 restart_count=0: --quiet p002.dat\n"
                  "2026-01-01T00:00:02+00:00 p002 refused 72: another run holds the folder "
                  "(71); exit_status left to it\n")
    sweep_tool(src, ["collect", "--no-plot", copy])
    rows = {r["point"]: r for r in read_table(copy / "results.csv")}
    closing = ("summary.steps", "summary.wall_seconds", "summary.wall_seconds_last_run", "summary.runs",
               "summary.ended", "summary.threads")
    check("collect: a killed point's closing /summary cells empty, its status kept",
          rows["p001"]["summary.status"] == "running (or killed)" and rows["p001"]["summary.finished"] == "0"
          and all(rows["p001"][c] == "" for c in closing)
          and all(rows["p002"][c] != "" for c in closing),
          str({k: v for k, v in rows["p001"].items() if k.startswith("summary")}))
    check("collect: starts counted from job.log, a start refused by the lock not counted",
          rows["p001"].get("starts") == "1" and rows["p002"].get("starts") == "2",
          str([rows[p].get("starts") for p in ("p001", "p002")]))


def failing_point(src, exe, work):
    folder = work / "fail"
    sweep_tool(src, ["create", src / "input" / "incline.dat", "--exe", exe,
                     "--set", "particles.gravity.gy=-9.81,-1e300", "--dir", folder])
    proc = sweep_tool(src, ["run", folder, "-j", "2"], expect=1)
    print(proc.stdout.strip())
    rows = {r["point"]: r for r in read_table(folder / "results.csv")}
    check("a failing point: exit 1 in the table, the other finished",
          rows["p002"]["exit_status"] == "1" and rows["p002"].get("summary.finished") != "1"
          and rows["p001"]["summary.finished"] == "1", str(rows["p002"]))
    status = sweep_tool(src, ["status", folder]).stdout
    check("status: 1 finished, 1 failed", "p002 failed" in status
          and "1 finished, 1 failed" in status, status.strip())
    again = sweep_tool(src, ["run", folder, "--no-collect"], expect=1)
    check("the next run retries the failed point only",
          "1 points finished before, 1 to run" in again.stdout, again.stdout.strip())
    # A restart that fails keeps its checkpoint: p001 as if stopped by SIGUSR1 (exit 138, the
    # checkpoint of its end), its deck changed since (a comment): the restart is refused, exit
    # 1. status must call it failed, as doc/cluster.md defines it (before: 'checkpoint').
    out = folder / "runs" / "p001"
    (out / "exit_status").write_text("138\n")
    check("p001 as if stopped: a checkpoint, status says so", (out / "checkpoint.h5").exists()
          and "p001 checkpoint" in sweep_tool(src, ["status", folder]).stdout, "")
    with open(folder / "decks" / "p001.dat", "a") as fh:
        fh.write("# changed after the checkpoint\n")
    sweep_tool(src, ["run", folder, "--no-collect"], expect=1)
    status = sweep_tool(src, ["status", folder]).stdout
    check("a failed restart (exit 1, its checkpoint kept): status says failed",
          (out / "exit_status").read_text().strip() == "1" and (out / "checkpoint.h5").exists()
          and "p001 failed" in status and "2 failed" in status, status.strip())


def killed_local_point(src, exe, work):
    """A point of a local run killed by a signal (kill -9) after its first checkpoint: the
    runner records the shell's code, 128 + 9, and status calls it 'checkpoint' (before:
    Python's -9, and 'failed'). The executable is a stand-in that leaves a checkpoint in its
    --output folder and kills itself."""
    folder = work / "killed_local"
    sweep_tool(src, ["create", src / "input" / "incline.dat", "--exe", exe,
                     "--set", "particles.gravity.gy=-9.81", "--dir", folder])
    fake = work / "killed_multicor.sh"
    fake.write_text('#!/bin/sh\nwhile [ $# -gt 0 ]; do [ "$1" = --output ] && out=$2; shift; done\n'
                    ': > "$out/checkpoint.h5"\nkill -9 $$\n')
    fake.chmod(0o755)
    manifest = json.loads((folder / "sweep.json").read_text())
    manifest["exe"] = str(fake)
    (folder / "sweep.json").write_text(json.dumps(manifest))
    sweep_tool(src, ["run", folder, "--no-collect"], expect=1)
    out = folder / "runs" / "p001"
    status = sweep_tool(src, ["status", folder]).stdout
    check("a local point killed by kill -9: exit_status 137, status 'checkpoint'",
          (out / "exit_status").read_text().strip() == "137" and "p001 checkpoint" in status,
          (out / "exit_status").read_text().strip() + " / " + status.strip())


def wrong_scalar(src, exe, work):
    """A --scalar whose dataset the results do not have (a typo in its path): the points run,
    and collecting says which scalar and exits 1 (before, exit 0 with an empty column and
    h5py's own words)."""
    folder = work / "wrong_scalar"
    sweep_tool(src, ["create", src / "input" / "incline.dat", "--exe", exe, "--set", "time.end=0.1",
                     "--scalar", "v=nonexist/x[0]", "--scalar", "vx=dem/velocity[-1,1,0]", "--dir", folder])
    proc = sweep_tool(src, ["run", folder], expect=1)
    rows = read_table(folder / "results.csv")
    check("a wrong scalar: the point finished, its column empty, the good one filled",
          rows[0]["summary.finished"] == "1" and rows[0]["v"] == "" and rows[0]["vx"] != "", str(rows[0]))
    check("a wrong scalar: named with the dataset it lacks, exit 1",
          "no dataset 'nonexist/x'" in proc.stderr and "error: scalar v=nonexist/x[0]" in proc.stderr,
          proc.stderr.strip()[-300:])


def refused_options(src, exe, work):
    """Options that sbatch would refuse only at submit, or no folder to write: refused by
    create with a message (before: accepted, or a Python traceback)."""
    deck = src / "input" / "incline.dat"
    (work / "a_file").write_text("")
    for options, said in ((["--time", "1 hour"], "--time '1 hour': not a Slurm time limit"),
                          (["--max-running", "0"], "--max-running 0: at least 1"),
                          # SIGUSR1 at the first time-limit check of every start (before: accepted)
                          (["--time", "1"], "--time 1 (60 s) is not longer than --signal-seconds 120"),
                          (["--time", "00:30", "--signal-seconds", "60"],
                           "--time 00:30 (60 s) is not longer than --signal-seconds 60"),
                          (["--dir", work / "a_file"], "exists and is not a folder"),
                          (["--dir", work / "a_file" / "x"], "cannot create the sweep folder")):
        args = ["create", deck, "--exe", exe, "--set", "time.end=0.1,0.2"] + options
        if "--dir" not in options:
            args += ["--dir", work / "refused_option"]
        proc = sweep_tool(src, args, expect=None)
        check(f"create refuses {' '.join(map(str, options))}", proc.returncode == 1
              and f"multicor-sweep: error: " in proc.stderr and said in proc.stderr
              and "Traceback" not in proc.stderr and not (work / "refused_option").exists(),
              proc.stderr.strip()[-300:])
    for time in ("90", "05:00", "01:30:00", "2-00", "2-00:30", "2-00:30:00", "UNLIMITED"):
        folder = work / f"time_{time.replace(':', '_')}"
        proc = sweep_tool(src, ["create", deck, "--exe", exe, "--set", "time.end=0.1",
                                "--time", time, "--dir", folder], expect=None)
        check(f"create accepts --time {time}", proc.returncode == 0
              and f"#SBATCH --time={time}\n" in (folder / "sweep.slurm").read_text(),
              proc.stderr.strip())


BAR_GEO = """// A bar [0, 2] x [0, 0.2] m in 10 quadrangles; set names with blanks and '#'.
Point(1) = {0, 0, 0};
Point(2) = {2, 0, 0};
Point(3) = {2, 0.2, 0};
Point(4) = {0, 0.2, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve{1, 3} = 11;
Transfinite Curve{2, 4} = 2;
Transfinite Surface{1};
Recombine Surface{1};
Physical Surface("bar") = {1};
Physical Curve("left edge") = {4};
Physical Curve("right #end") = {2};
Physical Curve("top") = {3};
Physical Point("lower left corner") = {1};
"""
BAR_L, BAR_E = 2.0, 2e11


def bar_deck(mesh):
    return f"""[run]
analysis = static
[continuum]
mesh     = file {mesh}   # relative to this deck's folder
material = {BAR_E} 0.3 7800 0.01 plane_stress bar
fix      = "left edge" x
fix      = "lower left corner" y
traction = "right #end" 5e7 0
traction = top 0 0
"""


def name_in_deck(path):
    """A path as a deck names it: between double quotes when it holds blanks or '#'."""
    return f'"{path}"' if re.search(r"[\s#]", str(path)) else str(path)


def relative_meshes(src, exe, work):
    """Decks whose Gmsh mesh path is relative to their folder (the default): written into
    SWEEP/decks/, each point's deck names the same mesh by its absolute path (quoted when it
    holds blanks or '#'); every other line unchanged. A static bar in tension, tx swept by a
    quoted selector: max |u| = tx L / E. The mesh path swept itself: its values are relative to
    the deck's folder too. Returns the deck with the quoted path (or None without gmsh)."""
    import shutil
    gmsh = shutil.which("gmsh")
    if not check("gmsh available", gmsh is not None, "gmsh not found (Debian package gmsh)"):
        return None
    # the deck with the quoted path in "deck dir"; the other (unquoted path) in "plain"
    folder, plain = work / "deck dir", work / "plain"
    (folder / "My Meshes").mkdir(parents=True)
    (plain / "meshes").mkdir(parents=True)
    (work / "bar.geo").write_text(BAR_GEO)
    quoted_mesh = folder / "My Meshes" / "bar #1.msh"
    subprocess.run([gmsh, "-2", "-format", "msh41", str(work / "bar.geo"), "-o", str(quoted_mesh)],
                   check=True, capture_output=True)
    plain_mesh = plain / "meshes" / "bar.msh"
    shutil.copy(quoted_mesh, plain_mesh)
    decks = {"quoted": folder / "bar.dat", "plain": plain / "plain.dat"}
    decks["quoted"].write_text(bar_deck('"My Meshes/bar #1.msh"'))
    decks["plain"].write_text(bar_deck("meshes/bar.msh"))
    scalar = ["--scalar", "umax=absmax(continuum/static/displacement)"]
    # the sweep folders lie elsewhere (not next to the deck): a path relative to the deck's
    # folder would name no file from SWEEP/decks/
    cases = (("quoted", ['continuum.traction[edge_set="right #end"].tx=5e7,1e8'],
              f'"{quoted_mesh}"'),
             ("plain", ["continuum.traction[1].tx=5e7,1e8"], name_in_deck(plain_mesh)))
    for name, sets, mesh in cases:
        sweep = work / "sweeps" / f"{name} mesh"
        args = ["create", decks[name], "--exe", exe, "--dir", sweep] + scalar
        for s in sets:
            args += ["--set", s]
        proc = sweep_tool(src, args, expect=None)
        if not check(f"{name} relative mesh path: create passes multicor --check",
                     proc.returncode == 0, proc.stderr.strip()[-600:]):
            continue
        original = decks[name].read_text().splitlines()
        for p, tx in (("p001", "5e7"), ("p002", "1e8")):
            body = (sweep / "decks" / f"{p}.dat").read_text().splitlines()[2:]   # header: 2 lines
            changed = [(a, b) for a, b in zip(original, body) if a != b]
            expected = [(original[3], f"mesh     = file {mesh}   # relative to this deck's folder")]
            if tx != "5e7":
                expected.append((original[7], f'traction = "right #end" {tx} 0'))
            check(f"{name} {p}: the mesh path made absolute, the swept value, nothing else",
                  len(body) == len(original) and changed == expected, str(changed))
        proc = sweep_tool(src, ["run", sweep, "--no-collect"], expect=None)
        sweep_tool(src, ["collect", sweep, "--no-plot"], expect=None)
        rows = read_table(sweep / "results.csv") if (sweep / "results.csv").exists() else []
        key = sets[0].rsplit("=", 1)[0]
        for r in rows:
            ref = float(r[key]) * BAR_L / BAR_E
            check(f"{name} {r['point']}: the run finds the mesh, max |u| = tx L / E",
                  r.get("summary.finished") == "1" and r.get("umax")
                  and math.isclose(float(r["umax"]), ref, rel_tol=1e-9),
                  f"umax={r.get('umax')} tx L / E={ref!r}")
        check(f"{name}: both points ran", len(rows) == 2 and proc.returncode == 0,
              proc.stdout.strip()[-300:] + proc.stderr.strip()[-300:])
    # the mesh path swept: each value relative to the deck's folder, quoted or not
    sweep = work / "sweeps" / "mesh path"
    proc = sweep_tool(src, ["create", decks["plain"], "--exe", exe, "--dir", sweep, "--set",
                            'continuum.mesh.path=meshes/bar.msh,"../deck dir/My Meshes/bar #1.msh"'],
                      expect=None)
    if check("the mesh path swept: create passes multicor --check", proc.returncode == 0,
             proc.stderr.strip()[-600:]):
        lines = [(sweep / "decks" / f"{p}.dat").read_text().splitlines()[5] for p in ("p001", "p002")]
        check("the mesh path swept: each value made absolute",
              lines == [f"mesh     = file {name_in_deck(plain_mesh)}   # relative to this deck's folder",
                        f'mesh     = file "{plain}/../deck dir/My Meshes/bar #1.msh"   # relative to '
                        "this deck's folder"],
              str(lines))
        proc = sweep_tool(src, ["run", sweep, "--no-collect"], expect=None)
        check("the mesh path swept: both points run", proc.returncode == 0 and all(
            (sweep / "runs" / p / "exit_status").read_text().strip() == "0" for p in ("p001", "p002")),
            proc.stdout.strip()[-300:] + proc.stderr.strip()[-300:])
    # an absolute mesh path stays as written
    absolute = folder / "absolute.dat"
    absolute.write_text(bar_deck(f'"{quoted_mesh}"'))
    sweep = work / "sweeps" / "absolute"
    proc = sweep_tool(src, ["create", absolute, "--exe", exe, "--dir", sweep,
                            "--set", "continuum.traction[1].tx=5e7"], expect=None)
    check("an absolute mesh path: the deck unchanged but its header",
          proc.returncode == 0 and (sweep / "decks" / "p001.dat").read_text().splitlines()[2:]
          == absolute.read_text().splitlines(), proc.stderr.strip()[-600:])
    return decks["quoted"]


def quoted_selectors(src, exe, work, deck):
    """A record selected by a quoted name: blanks and '#' inside, matched exactly (a trailing
    blank is another name); a bare value with '#' or a blank: the message says to quote it."""
    cases = (('continuum.traction[edge_set="right #end"].tx=1e6', 0, None),
             ('continuum.traction[edge_set="top"].ty=1e3', 0, None),
             ("continuum.traction[edge_set=top tx=0].ty=1e3", 0, None),
             ('continuum.traction[edge_set="right #end" tx=5e7].tx=1e6', 0, None),
             ('continuum.traction[edge_set="right #end "].tx=1e6', 1, "it matches 0 (none)"),
             ('continuum.traction[edge_set="right"].tx=1e6', 1, "it matches 0 (none)"),
             ("continuum.traction[edge_set=right #end].tx=1e6", 1, "between double quotes"),
             ('continuum.traction[edge_set="right #end].tx=1e6', 1, "between double quotes"))
    for n, (key, code, said) in enumerate(cases):
        folder = work / "selectors" / str(n)
        proc = sweep_tool(src, ["create", deck, "--exe", exe, "--set", key, "--dir", folder],
                          expect=None)
        check(f"selector {key.rsplit('=', 1)[0]}: " + ("accepted" if code == 0 else "refused"),
              proc.returncode == code and (said is None or said in proc.stderr)
              and "Traceback" not in proc.stderr, proc.stderr.strip()[-400:])
    # a grid file: the '#' of a quoted name is no comment
    grid = work / "selectors" / "grid.txt"
    grid.write_text('continuum.traction[edge_set="right #end"].tx = 1e6, 2e6   # the loaded end\n')
    proc = sweep_tool(src, ["create", deck, "--exe", exe, "--grid", grid, "--dir",
                            work / "selectors" / "grid"], expect=None)
    check("a grid file: a quoted selector with '#'", proc.returncode == 0, proc.stderr.strip()[-400:])
    if (work / "selectors" / "0" / "decks" / "p001.dat").exists():
        line = (work / "selectors" / "0" / "decks" / "p001.dat").read_text().splitlines()[9]
        check("the quoted selector names the record of its name", line == 'traction = "right #end" 1e6 0',
              line)


SBATCH = """#!/bin/bash
# stand-in for sbatch: logs its arguments, answers job ${FAKE_JOB:-42}; FAKE_COLLECT_FAIL:
# refuses the collect job (--wrap)
echo "$*" >> "$FAKE_LOG"
if [ -n "${FAKE_COLLECT_FAIL:-}" ] && [[ " $* " == *" --wrap "* ]]; then
    echo "sbatch: error: Batch job submission failed: Required partition not available" >&2
    exit 1
fi
echo "${FAKE_JOB:-42}"
"""
SQUEUE = """#!/bin/bash
# stand-in for squeue [-M CLUSTER] -h -r -o '%F|%K|%T' -j JOBS: prints $FAKE_SQUEUE;
# FAKE_SQUEUE_FAIL: fails; FAKE_CLUSTER: the jobs are on that cluster, which only -M asks
# (as Slurm: the local cluster does not know them; -M prints a 'CLUSTER: name' line first)
if [ -n "${FAKE_SQUEUE_FAIL:-}" ]; then
    echo "slurm_load_jobs error: Unable to contact slurm controller (connect failure)" >&2
    exit 1
fi
if [ -n "${FAKE_CLUSTER:-}" ]; then
    if [ "$1" != -M ] || [ "$2" != "$FAKE_CLUSTER" ]; then
        echo "slurm_load_jobs error: Invalid job id specified" >&2
        exit 1
    fi
    echo "CLUSTER: $FAKE_CLUSTER"
fi
printf "%b" "${FAKE_SQUEUE:-}"
"""


def submission(src, exe, work):
    """`submit` and `status` with stand-ins for sbatch and squeue: a folder with a space, the
    cap of --max-running kept by a resubmission, points that an earlier job still holds
    pending or running neither resubmitted nor advised to be, squeue out of reach."""
    import os
    import shlex
    bin_dir = work / "bin"
    bin_dir.mkdir()
    for name, text in (("sbatch", SBATCH), ("squeue", SQUEUE)):
        (bin_dir / name).write_text(text)
        (bin_dir / name).chmod(0o755)
    folder = work / "stand in"
    proc = sweep_tool(src, ["create", src / "input" / "incline.dat", "--exe", exe,
                            "--set", "time.end=0.1,0.2,0.3", "--max-running", "1",
                            "--time", "5", "--dir", folder])
    check("create: the next command with the folder shell-quoted",
          f"next: multicor-sweep submit {shlex.quote(str(folder))} " in proc.stdout, proc.stdout)
    script = (folder / "sweep.slurm").read_text()
    check("job script: the log folder between double quotes (it has a space)",
          f'#SBATCH --output="{folder}/logs/%A_%a.out"\n' in script, "")
    (folder / "runs" / "p001").mkdir(parents=True)
    (folder / "runs" / "p001" / "exit_status").write_text("0\n")
    log = work / "sbatch.log"

    def tool(args, expect=0, **env):
        e = dict(os.environ, PATH=f"{bin_dir}:{os.environ['PATH']}", FAKE_LOG=str(log), **env)
        cmd = [sys.executable, str(src / "scripts" / "multicor-sweep")] + [str(a) for a in args]
        proc = subprocess.run(cmd, capture_output=True, text=True, env=e)
        if expect is not None and proc.returncode != expect:
            print(proc.stdout, proc.stderr)
        return proc

    def calls():
        return log.read_text().splitlines() if log.exists() else []

    proc = tool(["submit", "--no-collect", folder])
    check("resubmission of p002, p003 keeps the cap: --array=2-3%1",
          proc.returncode == 0 and calls() and "--array=2-3%1 " in calls()[-1],
          f"{proc.stderr.strip()} {calls()}")
    queued = "42|2|RUNNING\n42|3|PENDING\n"
    proc = tool(["submit", "--no-collect", folder], FAKE_SQUEUE=queued)
    check("submit while the points are running or pending: nothing submitted",
          proc.returncode == 0 and len(calls()) == 1 and "nothing to submit" in proc.stdout
          and "p002 (running, job 42)" in proc.stdout, proc.stdout + proc.stderr)
    proc = tool(["status", folder], FAKE_SQUEUE=queued)
    check("status: p002 running, p003 pending, wait; no advice to submit",
          "p002 running" in proc.stdout and "p003 pending" in proc.stdout
          and "wait for them" in proc.stdout and "submit" not in proc.stdout, proc.stdout)
    proc = tool(["submit", "--no-collect", folder], FAKE_SQUEUE="42|2|RUNNING\n")
    check("submit while p002 runs: only p003, with the cap (--array=3%1)",
          proc.returncode == 0 and len(calls()) == 2 and "--array=3%1 " in calls()[-1],
          proc.stdout + proc.stderr)
    proc = tool(["submit", "--no-collect", folder], expect=1, FAKE_SQUEUE_FAIL="1")
    check("squeue out of reach: submit refuses, says so, names --force",
          proc.returncode == 1 and "cannot ask Slurm" in proc.stderr
          and "Unable to contact" in proc.stderr and "--force" in proc.stderr
          and len(calls()) == 2, proc.stderr)
    proc = tool(["status", folder], FAKE_SQUEUE_FAIL="1")
    check("squeue out of reach: status says so, advises submit --force once they ended",
          "cannot ask Slurm" in proc.stdout and "once those jobs have ended" in proc.stdout,
          proc.stdout)
    proc = tool(["submit", "--force", "--no-collect", folder], FAKE_SQUEUE_FAIL="1")
    check("submit --force: submitted without squeue", proc.returncode == 0
          and len(calls()) == 3 and "--array=2-3%1 " in calls()[-1], proc.stdout + proc.stderr)
    proc = tool(["status", folder])
    check("status once the jobs ended: advises submit", "continue the others: multicor-sweep "
          f"submit {shlex.quote(str(folder))}" in proc.stdout, proc.stdout)
    collect_job(src, exe, work, tool, calls)


def collect_job(src, exe, work, tool, calls):
    """The collect job gets the array's partition, account, qos (create --sbatch, overridden
    by submit's options), not its --cpus-per-task, and a time limit of 10 minutes or the
    array's when shorter (before: none of them, --time=10 always). A collect job that sbatch
    refuses: the array stays recorded in sweep.json (before: "jobs": [], and the next submit
    started the running points again), the message gives the commands to collect later."""
    import json
    import shlex
    folder = work / "collect job"
    sweep_tool(src, ["create", src / "input" / "incline.dat", "--exe", exe, "--set",
                     "time.end=0.1,0.2", "--time", "3", "--sbatch=--partition=short",
                     "--sbatch", "-A me", "--sbatch=--cpus-per-task=4", "--sbatch=--qos=low",
                     "--dir", folder])
    proc = tool(["submit", folder, "--qos=high", "-c", "2"], FAKE_JOB="51")
    array, collect = calls()[-2:] if len(calls()) >= 2 else ("", "")
    options = collect.split(" --wrap ")[0].split()
    check("collect job: the array's partition, account, qos (submit's over create's), the "
          "array's time (3 min, under 10), no --cpus-per-task",
          proc.returncode == 0 and "--qos=high -c 2 " in array and "--dependency=afterany:51" in options
          and {"--partition=short", "--account=me", "--qos=high", "--time=3"} <= set(options)
          and "--time=10" not in options and not any(o.startswith(("-c", "--cpus")) for o in options),
          f"{proc.stdout}{proc.stderr}\n{collect}")
    proc = tool(["submit", "--force", folder, "--time", "01:00:00", "-p", "long"], FAKE_JOB="52")
    options = calls()[-1].split(" --wrap ")[0].split()
    check("collect job: --time=10 under a longer array's limit, submit's -p",
          {"--partition=long", "--time=10"} <= set(options), calls()[-1])
    # the collect job refused: the array recorded at once, the way to collect later given
    folder = work / "collect refused"
    sweep_tool(src, ["create", src / "input" / "incline.dat", "--exe", exe, "--set",
                     "time.end=0.1,0.2", "--time", "5", "--dir", folder])
    proc = tool(["submit", folder, "--partition=other"], expect=1, FAKE_JOB="61",
                FAKE_COLLECT_FAIL="1")
    jobs = json.loads((folder / "sweep.json").read_text())["jobs"]
    q = shlex.quote(str(folder))
    check("collect job refused: exit 1, said, the array 61 recorded, the commands given",
          proc.returncode == 1 and jobs == ["61"] and "job array 61: 2 points" in proc.stdout
          and "the collect job was not submitted: sbatch: error: Batch job submission failed: "
          "Required partition not available" in proc.stderr
          and "job array 61 is submitted and recorded in" in proc.stderr
          and "--dependency=afterany:61" in proc.stderr and f"collect {q}" in proc.stderr
          and "Traceback" not in proc.stderr, f"{jobs}\n{proc.stdout}{proc.stderr}")
    queued = "61|1|RUNNING\n61|2|RUNNING\n"
    proc = tool(["status", folder], FAKE_SQUEUE=queued)
    check("collect job refused: status shows the points running, advises to wait",
          "p001 running" in proc.stdout and "wait for them" in proc.stdout
          and "submit" not in proc.stdout, proc.stdout)
    n = len(calls())
    proc = tool(["submit", folder], FAKE_SQUEUE=queued)
    check("collect job refused: a second submit starts nothing again",
          proc.returncode == 0 and "nothing to submit" in proc.stdout and len(calls()) == n,
          proc.stdout + proc.stderr)
    other_cluster(src, exe, work, tool, calls)


def other_cluster(src, exe, work, tool, calls):
    """An array sent to another cluster (sbatch answers 'JOB;CLUSTER'): its cluster recorded
    with the job, and squeue asked with -M (before, squeue asked the local cluster, which
    does not know the job: status called the running points not started, and a second
    submit started them again)."""
    import json
    folder = work / "other cluster"
    sweep_tool(src, ["create", src / "input" / "incline.dat", "--exe", exe, "--set",
                     "time.end=0.1,0.2", "--time", "5", "--dir", folder])
    proc = tool(["submit", folder, "--clusters=far"], FAKE_JOB="71;far")
    manifest = json.loads((folder / "sweep.json").read_text())
    check("other cluster: the array and the collect job recorded with their cluster",
          proc.returncode == 0 and manifest["jobs"] == ["71", "71"]
          and manifest.get("clusters") == {"71": "far"}
          and "--clusters=far" in calls()[-1], f"{manifest}\n{proc.stdout}{proc.stderr}")
    queued = "71|1|RUNNING\n71|2|PENDING\n"
    proc = tool(["status", folder], FAKE_SQUEUE=queued, FAKE_CLUSTER="far")
    check("other cluster: status asks it (-M far): p001 running, p002 pending",
          "p001 running" in proc.stdout and "p002 pending" in proc.stdout
          and "wait for them" in proc.stdout, proc.stdout + proc.stderr)
    n = len(calls())
    proc = tool(["submit", folder], FAKE_SQUEUE=queued, FAKE_CLUSTER="far")
    check("other cluster: a second submit starts nothing again",
          proc.returncode == 0 and "nothing to submit" in proc.stdout and len(calls()) == n,
          proc.stdout + proc.stderr)


def main():
    exe, work, src = arguments(fresh=True)
    quoted_names(src)
    script_functions(src, work)
    refused_keys(src, exe, work)
    same_record(src, exe, work)
    refused_options(src, exe, work)
    submission(src, exe, work)
    folder = generated_decks(src, exe, work)
    sequential_run(src, folder)
    failing_point(src, exe, work)
    killed_local_point(src, exe, work)
    wrong_scalar(src, exe, work)
    deck = relative_meshes(src, exe, work)
    if deck is not None:
        quoted_selectors(src, exe, work, deck)
    return summary()


if __name__ == "__main__":
    sys.exit(main())
