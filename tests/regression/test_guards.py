#!/usr/bin/env python3
"""Scenarios that used to run to NaN with exit 0, crash, or misbehave, and must now stop
cleanly: guards on the initial state and after every step (non-finite state, disks beyond
the representable box, a driven wall with one end beyond it, tunnelling), the warning of a
disk moving farther than the alert distance in one step, one writer per results folder (lock file), --output '',
--end 1e999, abc, 5s or ' 5' and the usage line of a bad command line, no empty folder left by a failed run, three-digit
exponents in messages, decks with a UTF-8 byte-order mark or CR-only line endings, a deck with Latin-1 comments.

Each failed run must exit 1 with a message naming the deck, the step and the body, and leave
an earlier finished result in the folder byte for byte.
Usage (ctest does this): test_guards.py --exe multicor --work DIR --source REPO
"""
import hashlib
import os
import pathlib
import re
import shutil
import socket
import subprocess
import sys

import h5py
import numpy as np

from checks import arguments, check, summary


def multicor(exe, *args):
    return subprocess.run([str(exe), *map(str, args)], capture_output=True, text=True, timeout=300)


def digest(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


def failing_run(exe, work, name, text, expect, earlier_deck):
    """Run `text` into a folder holding an earlier finished result of the same name (from
    `earlier_deck`); it must exit 1 with `expect` in the message and keep that result."""
    folder = work / name
    folder.mkdir(parents=True, exist_ok=True)
    deck = work / f"{name}.dat"
    deck.write_text(earlier_deck)
    first = multicor(exe, deck, "--output", folder, "--quiet")
    earlier = folder / f"{name}.h5"
    if first.returncode != 0 or not earlier.exists():
        check(f"{name}: earlier run", False, first.stderr)
        return ""
    before = digest(earlier)
    deck.write_text(text)
    proc = multicor(exe, deck, "--output", folder, "--quiet")
    check(f"{name}: exit 1", proc.returncode == 1, f"exit {proc.returncode}")
    found = re.search(expect, proc.stderr) is not None
    check(f"{name}: message", found and f"{name}.dat" in proc.stderr, proc.stderr.strip()[:400])
    check(f"{name}: earlier result intact", digest(earlier) == before, "")
    check(f"{name}: lock released", not (folder / ".multicor.lock").exists(), "")
    return proc.stderr


def beam_deck(load="-10.0", extra=""):
    return f"""[run]
analysis = dynamic
[beam]
section = 1 2.1e11 7800 2.0e-4 1.6666666666666667e-9
line = 1 0 0 1 0 20 1
fix = 1 all
load = 21 w {load}
{extra}
[time]
step = 2e-4
end = 2e-3
[output]
progress = 0
"""


def dem_deck(step="1e-3", gravity="0 -9.81", n=200, end="0.01", solver=""):
    return f"""[run]
analysis = dynamic
[particles]
material = 1 2500
deposit = {n} 0 0.2 0 0.004 0.005 1 7
gravity = {gravity}
[walls]
wall = 0 0 0.2 0
wall = 0 0 0 0.4
wall = 0.2 0 0.2 0.4
[contacts]
law = 1 1 0.4 0.1 0
{solver}
[time]
step = {step}
end = {end}
[output]
progress = 0
"""


def non_finite(exe, work):
    """Loads and gravity of 1e300 ran to the end writing NaN/Inf with exit 0."""
    failing_run(exe, work, "beam_load_1e300", beam_deck(load="-1e300"),
                r"step 1 \(t = 2\.00000E-004 s\): beam", beam_deck())
    gravity = failing_run(exe, work, "dem_gravity_1e300", dem_deck(gravity="0 -1e300"),
                          r"step 1 \(t = 1\.00000E-003 s\): disk \d+ is at .* beyond the box", dem_deck())
    check("dem_gravity_1e300: no initial velocity among the causes (the disks start at rest)",
          "initial velocity" not in gravity, gravity.strip()[:400])
    # An initial velocity of 1e150 m/s: the causes named forces and gravity only.
    fast_start = dem_deck().replace("gravity = 0 -9.81\n", "gravity = 0 -9.81\ninitial_velocity = 1 x 1e150\n", 1)
    failing_run(exe, work, "dem_initial_velocity_1e150", fast_start,
                r"step 1 \(t = 1\.00000E-003 s\): disk 1 is at .* beyond the box .*likely cause: a disk escaping "
                r"with no wall to stop it, or an initial velocity \(the disks start at up to 1\.000E\+150 m/s: "
                r"\[particles\] initial_velocity, initial_rigid\), a force or gravity far too large", dem_deck())
    # a floor sliding along itself at 1e300 m/s: finite, but 1e297 m away after a step (the
    # run ended with exit 0, its walls beyond the box; at 9e307 m/s and a longer run they
    # were written as Inf)
    fast_wall = dem_deck().replace("wall = 0 0 0.2 0\n", "wall = 0 0 0.2 0 1 1e300 0\n", 1)
    failing_run(exe, work, "dem_wall_velocity_1e300", fast_wall,
                r"step 1 \(t = 1\.00000E-003 s\): wall 1 has moved to .* beyond the box", dem_deck())


def coupled_non_finite(exe, work, decks):
    """A coupled run with a beam load of 1e300 stops at the first step. Node 11 lies on the
    overlap's end (alpha = alpha_min = 1e-3): the load is applied in full on a thousandth of
    the node's mass, so the initial acceleration (step 0) already overflows (when the load was
    weighted by alpha the run stopped at step 1)."""
    text = (decks / "coupled_rigid_translation.dat").read_text()
    bad = text.replace("line     = 1   0.0  0.0  0.10  0.0  10  1",
                       "line     = 1   0.0  0.0  0.10  0.0  10  1\nload = 11 w -1e300", 1)
    failing_run(exe, work, "coupled_load_1e300", bad, r"step 0 \(t = 0\.00000E\+000 s\): beam .*a load", text)


def coupled2d_initial_state(exe, work, src):
    """A coupled continuum + disk deck with a disk or continuum velocity of 1e200 m/s: the
    speed is finite, but its kinetic energy (~1e400 J) is not. The deck is refused before the
    run (as `--check` does), at the record that gives the velocity (the run used to stop at
    step 0, blaming loads or moduli for the continuum)."""
    text = (src / "input" / "coupled2d_block.dat").read_text()
    disks = "initial_rigid = 1:last 0.3 -0.2 0.4 1.5 0.5"
    block = "initial_velocity = 0.3 -0.2 0.4 1.5 0.5"
    if disks not in text or block not in text:
        check("coupled2d initial state: deck lines found", False, "input/coupled2d_block.dat changed")
        return
    fast_disks = text.replace(disks, disks.replace("0.3", "1e200", 1))
    failing_run(exe, work, "coupled2d_disk_velocity_1e200", fast_disks,
                r"\.dat:\d+: keyword 'initial_rigid': the kinetic energy of the initial velocities is "
                r"beyond the range of double precision: disk 1 ", text)
    fast_block = text.replace(block, block.replace("0.3", "1e200", 1))
    failing_run(exe, work, "coupled2d_block_velocity_1e200", fast_block,
                r"\.dat:\d+: keyword 'initial_velocity': the kinetic energy 1/2 v\.M v of this initial "
                r"velocity is beyond the range of double precision", text)


def continuum_blow_up_cause(exe, work, src):
    """A dynamic continuum with a density of 1e-300 blew up at the first step. Average
    acceleration is unconditionally stable, so the message must not blame the time step (it
    did): its highest frequency is beyond double precision, which no time step resolves, and it
    is refused before the run at the material line (fem_newmark's round-off check). With Newmark
    beta = 0.1, gamma = 0.5 (2 beta < gamma, conditionally stable) the time step is refused
    before the run, at its keyword (the critical step of that model is 0)."""
    text = (src / "input" / "continuum_cantilever_dynamic.dat").read_text()
    material = "material = 70e9 0.3 2700 0.1 plane_stress"
    if material not in text or "end = 0.5" not in text:
        check("continuum blow-up: deck lines found", False, "input/continuum_cantilever_dynamic.dat changed")
        return
    # the earlier result in the folder: the deck as it is, to the same end as the runs refused
    # (10 steps; its 500 add nothing to what is checked here)
    short = text.replace("end = 0.5", "end = 0.01")
    light = short.replace(material, material.replace("2700", "1e-300"))
    message = failing_run(exe, work, "continuum_density_1e-300", light,
                          r":\d+: keyword 'material': the stiffness and density of the model give a highest "
                          r"natural frequency that no time step resolves .*a stiffness or density is far out of "
                          r"range", short)
    check("continuum blow-up: the time step is not blamed", "lower [time] step" not in message, message[:300])
    conditional = light.replace("[time]", "[time]\nscheme = newmark\nbeta = 0.1\ngamma = 0.5", 1)
    failing_run(exe, work, "continuum_density_1e-300_beta", conditional,
                r":\d+: keyword 'step': time step .* exceeds the critical time step .* only conditionally stable",
                short)


def aliased_harmonic(exe, work):
    """A harmonic load faster than 1/(2h) ran without a word (the run sees an alias of it):
    warned once, naming the deck line and both frequencies; below 1/(2h) nothing is said."""
    for freq, warned in (("3000", True), ("2000", False)):   # h = 2e-4 s: 1/(2h) = 2500 Hz
        text = beam_deck(load="-10.0 1", extra=f"[functions]\nfunction = 1 harmonic {freq}")
        deck = work / f"harmonic_{freq}.dat"
        deck.write_text(text)
        proc = multicor(exe, deck, "--output", work / f"harmonic_{freq}", "--quiet")
        out = proc.stdout + proc.stderr
        if warned:
            said = re.search(r"harmonic_%s\.dat:\d+: harmonic function 1 at %s Hz is above 1/\(2 h\) = 2500 Hz"
                             % (freq, freq), out) is not None
        else:
            said = "warning" in out
        check(f"harmonic at {freq} Hz runs", proc.returncode == 0, proc.stderr.strip())
        check(f"harmonic at {freq} Hz: aliasing warning {'given' if warned else 'absent'}", said == warned,
              out.strip()[:300])


SQUEEZE = """[run]
analysis = dynamic
[particles]
material = 1 2500
disk = 0 0.01 0.01 1
[walls]
wall = -0.1 0 0.1 0
wall = 0.1 0.02 -0.1 0.02 1 0 -{v}
[contacts]
law = 1 1 0.4 0 0
[time]
step = 1e-3
end = {end}
[output]
progress = 0
"""


def squeezed(exe, work):
    """A disk squeezed between the floor and a ceiling driven down at 1 cm/s (no escape) is
    pushed through a wall over many steps, 10 um per step: the error said 'within one step'
    and advised a time step 2.5e-3 m / 1e-5 m = 250 times larger. It now says the step is
    not the cause; a run stopped before the crossing (the ceiling 5 mm down) is fine."""
    failing_run(exe, work, "dem_squeezed_disk", SQUEEZE.format(v="0.01", end="3"),
                r"disk 1 passed through wall \d \(its centre moved 1\.000E-005 m .*the time step is not the "
                r"cause: the contacts did not hold the disk back", SQUEEZE.format(v="0.01", end="0.5"))


def tunnelling(exe, work):
    """A step so large that disks pass through the floor ran to the end with one warning."""
    failing_run(exe, work, "dem_tunnelling_floor", dem_deck(step="0.05", end="1"),
                r"disk \d+ passed through wall 1 within one step .* lower \[time\] step to", dem_deck())
    pair = """[run]
analysis = dynamic
[particles]
material = 1 2500
disk = 0 0 0.01 1
disk = 0.025 0 0.01 1
initial_velocity = 2 x -6
[contacts]
law = 1 1 0.4 0 0
[time]
step = {h}
end = {end}
[output]
progress = 0
"""
    # Relative motion 6 m/s x 0.01 s = 0.06 m: the centres cross before mid-step (start gap
    # 0.025 m), the contact of the step then pushes them further through. The earlier result
    # (each case here) is the same pair with a step of 1e-4 s, run through the collision: no
    # tunnelling is found in it (here the disks touch at 0.9 ms, of 5 ms).
    failing_run(exe, work, "dem_tunnelling_pair", pair.format(h="0.01", end="0.05"),
                r"disks 1 and 2 passed through each other within one step", pair.format(h="1e-4", end="0.005"))
    # Two disks 0.1 m apart closing at 20 m/s with h = 0.05 s: 1 m per step, so they are never
    # near each other at a detection (the mid configuration already has them 0.4 m apart on
    # the other side) and are no contact candidates; the swept-box check finds them.
    far = """[run]
analysis = dynamic
[particles]
material = 1 2500
disk = 0.05 0.011 0.01 1
disk = 0.15 0.011 0.01 1
initial_velocity = 1 x 10
initial_velocity = 2 x -10
[contacts]
law = 1 1 0.3 0 0
[time]
step = {h}
end = {end}
[output]
progress = 0
"""
    # the earlier result: they meet at 4 ms (and stay in contact), of 10 ms
    failing_run(exe, work, "dem_tunnelling_unseen_pair", far.format(h="0.05", end="0.5"),
                r"disks 1 and 2 passed through each other within one step", far.format(h="1e-4", end="0.01"))
    # A fast disk falling through a resting one: its swept box starts to the right of the
    # resting disk's, so the search looks behind it in the sorted order too.
    through = """[run]
analysis = dynamic
[particles]
material = 1 2500
disk = 0.100 0.0 0.01 1
disk = 0.102 0.5 0.01 1
initial_velocity = 2 y -20
[contacts]
law = 1 1 0.3 0 0
[time]
step = {h}
end = {end}
[output]
progress = 0
"""
    # the earlier result: they meet at 24 ms (0.48 m at 20 m/s), of 30 ms
    failing_run(exe, work, "dem_tunnelling_falling_through", through.format(h="0.05", end="0.5"),
                r"disks 1 and 2 passed through each other within one step", through.format(h="1e-4", end="0.03"))
    # The same with a lateral offset of 0.4 of the radius sum (0.008 m): the relative path
    # comes closer than (r_i + r_j)/2 = 0.01 m, so the disks passed through each other (a
    # threshold of a quarter of the sum, 0.005 m, would miss it).
    offset = through.replace("disk = 0.102 0.5 0.01 1", "disk = 0.108 0.5 0.01 1")
    failing_run(exe, work, "dem_tunnelling_falling_offset", offset.format(h="0.05", end="0.5"),
                r"disks 1 and 2 passed through each other within one step", offset.format(h="1e-4", end="0.03"))


def lock(exe, work):
    """One writer per results folder."""
    deck = work / "locked.dat"
    deck.write_text(beam_deck())
    folder = work / "locked"
    folder.mkdir(parents=True, exist_ok=True)
    lockfile = folder / ".multicor.lock"
    (folder / "locked.h5").unlink(missing_ok=True)
    host = socket.gethostname()
    # A live owner on this host: this very process.
    lockfile.write_text(f"{host} {os.getpid()} 2026-01-01T00:00:00\n")
    proc = multicor(exe, deck, "--output", folder, "--quiet")
    check("lock: second writer refused (exit 1)", proc.returncode == 1, f"exit {proc.returncode}")
    check("lock: message names the owner",
          "in use by another run" in proc.stderr and f"{host} {os.getpid()}" in proc.stderr,
          proc.stderr.strip())
    check("lock: owner's lock kept, nothing written",
          lockfile.exists() and not (folder / "locked.h5").exists(), "")
    # A stale lock: a process that has ended.
    dead = subprocess.Popen(["true"])
    dead.wait()
    lockfile.write_text(f"{host} {dead.pid} 2026-01-01T00:00:00\n")
    proc = multicor(exe, deck, "--output", folder, "--quiet")
    check("lock: stale lock taken over", proc.returncode == 0
          and "taking over the stale lock" in proc.stdout, proc.stdout.strip()[:300] + proc.stderr)
    check("lock: removed at the end", not lockfile.exists() and (folder / "locked.h5").exists(), "")
    # A lock from another host cannot be checked: respected.
    lockfile.write_text(f"another-host-{host} 1 2026-01-01T00:00:00\n")
    proc = multicor(exe, deck, "--output", folder, "--quiet")
    check("lock: another host's lock respected", proc.returncode == 1, proc.stderr.strip()[:200])
    lockfile.unlink()


def output_empty(exe, work):
    deck = work / "empty_output.dat"
    deck.write_text(beam_deck())
    proc = multicor(exe, deck, "--output", "", "--quiet")
    check("--output '': bad command line (exit 2)", proc.returncode == 2
          and "--output needs a folder name" in proc.stderr, f"exit {proc.returncode} {proc.stderr}")
    check("--output '': nothing at the root", not pathlib.Path("/empty_output.h5").exists()
          and not pathlib.Path("/empty_output.h5.partial").exists(), "")


def end_option(exe, work):
    """--end 1e999 died of SIGFPE while reading the number (Debug build: overflow trap in
    strtod); 'inf', 'nan' and overflowing values are bad command lines (exit 2)."""
    deck = work / "end_option.dat"
    deck.write_text(beam_deck())
    folder = work / "end_option"
    for value in ("1e999", "-1e999", "1e400", "inf", "nan", "1e-400", "0", "-1"):
        proc = multicor(exe, deck, "--output", folder, "--quiet", "--end", value)
        check(f"--end {value}: bad command line (exit 2)", proc.returncode == 2
              and "--end needs a" in proc.stderr and value in proc.stderr,
              f"exit {proc.returncode} {proc.stderr.strip()[:300]}")
    check("--end: nothing written", not folder.exists(), "")
    # a repeated option is a bad command line, as a repeated keyword in a deck is an error
    for args, name in ((["--output", folder, "--output", work / "other"], "--output"),
                       (["--output", folder, "--end", "1e-3", "--end", "2e-3"], "--end"),
                       (["--output", folder, "--restart", work / "a.h5", "--restart", work / "b.h5"], "--restart")):
        proc = multicor(exe, deck, *args, "--quiet")
        check(f"{name} twice: bad command line (exit 2)", proc.returncode == 2 and f"{name} given twice" in proc.stderr,
              f"exit {proc.returncode} {proc.stderr.strip()[:200]}")
    check("repeated options: nothing written", not folder.exists() and not (work / "other").exists(), "")
    # A word is not a number (it said "needs a finite time"); an infinity is not finite.
    for value, expect in (("abc", "--end needs a time in seconds, got 'abc', which is not a number"),
                          ("1x", "got '1x', which is not a number"),
                          ("-Infinity", "--end needs a finite time in seconds, got '-Infinity'"),
                          # a time with its unit: the deck's hint on units
                          ("5s", "got '5s', which is not a number; '5s' looks like a number with its unit: "
                                 "a value is a plain number in SI units")):
        proc = multicor(exe, deck, "--output", folder, "--end", value)
        check(f"--end {value}: '{expect}'", proc.returncode == 2 and expect in proc.stderr,
              f"exit {proc.returncode} {proc.stderr.strip()[:300]}")
    # Blanks around the number (a quoted shell variable) are no part of it: it said 'not a number'.
    blanks = work / "end_option_blanks"
    proc = multicor(exe, deck, "--output", blanks, "--quiet", "--end", " 1e-3 ")
    check("--end ' 1e-3 ': runs to 1e-3 s", proc.returncode == 0 and (blanks / "end_option.h5").exists(),
          f"exit {proc.returncode} {proc.stderr.strip()[:300]}")
    if proc.returncode == 0:
        with h5py.File(blanks / "end_option.h5", "r") as f:
            # steps of 2e-4 s: 5 to the end time read, 10 to the deck's
            check("--end ' 1e-3 ': 5 steps", int(f["summary"].attrs["steps"]) == 5, str(dict(f["summary"].attrs)))
    # The usage line of a bad command line names every option of --help (it left out --end,
    # --restart and -q).
    usage = multicor(exe, "--bogus").stderr
    helped = multicor(exe, "--help").stdout
    options = re.findall(r"^  (?:(-\w), )?\s*(--[\w-]+)", helped, flags=re.M)
    check("--help lists the options", len(options) >= 8, helped[:300])
    missing = [long for short, long in options if long not in usage and not (short and short in usage)]
    check("usage line: every option of --help", not missing, f"missing {missing}: {usage}")


def no_empty_folder(exe, work):
    """A failed run given a new --output folder left it behind, empty; a folder that existed
    before the run stays."""
    deck = work / "new_folder.dat"
    deck.write_text(beam_deck(load="-1e300"))
    new = work / "new_folder_parent" / "a" / "b"
    proc = multicor(exe, deck, "--output", new, "--quiet")
    check("failed run into a new folder: exit 1", proc.returncode == 1, proc.stderr.strip()[:300])
    check("failed run into a new folder: no folder left", not (work / "new_folder_parent").exists(),
          "")
    old = work / "old_folder"
    old.mkdir(parents=True, exist_ok=True)
    proc = multicor(exe, deck, "--output", old / "sub", "--quiet")
    check("failed run into a new subfolder: exit 1", proc.returncode == 1, "")
    check("failed run into a new subfolder: the existing parent kept, the subfolder removed",
          old.is_dir() and not (old / "sub").exists(), "")


def exponents(exe, work):
    """tolerance = 1e-300 printed as '1.00-300' (no exponent letter) in the warnings."""
    deck = work / "tiny_tolerance.dat"
    deck.write_text(dem_deck(n=30, end="0.05", solver="[solver]\ntolerance = 1e-300\nmax_sweeps = 2"))
    proc = multicor(exe, deck, "--output", work / "tiny_tolerance", "--quiet")
    check("exponents: run", proc.returncode == 0, proc.stderr)
    check("exponents: 'tolerance  1.00E-300' in the warning", "tolerance  1.00E-300" in proc.stdout
          and not re.search(r"\d-300", proc.stdout.replace("E-300", "")), proc.stdout[:300])


def line_endings(exe, work):
    """A UTF-8 byte-order mark was refused; CR-only line endings read as an empty deck. Both
    must give the same results as the plain deck."""
    plain = beam_deck()
    variants = {"plain": plain.encode(), "bom": b"\xef\xbb\xbf" + plain.encode(),
                "cr": plain.replace("\n", "\r").encode(), "crlf": plain.replace("\n", "\r\n").encode()}
    results = {}
    for name, data in variants.items():
        deck = work / f"endings_{name}.dat"
        deck.write_bytes(data)
        proc = multicor(exe, deck, "--output", work / "endings", "--quiet")
        check(f"line endings: {name} runs", proc.returncode == 0, proc.stderr.strip())
        if proc.returncode == 0:
            with h5py.File(work / "endings" / f"endings_{name}.h5", "r") as f:
                results[name] = f["fem/displacement"][...]
    for name in ("bom", "cr", "crlf"):
        if name in results and "plain" in results:
            # Same deck, same arithmetic: bit-identical results.
            check(f"line endings: {name} gives the plain deck's results",
                  np.array_equal(results[name], results["plain"]), "")


def deck_hash(text):
    """The deck hash of a checkpoint (driver_checkpoint_file deck_hash), computed here from
    the file's bytes: two polynomial hashes modulo primes below 2**31, seeded with the length."""
    p1, p2 = 2147483647, 2147483629
    h1, h2 = len(text), 7
    for b in text:
        h1 = (h1 * 257 + b) % p1
        h2 = (h2 * 263 + b + 1) % p2
    return f"{h1:08X}{h2:08X}"


def latin1_comment(exe, work):
    """A deck saved as Latin-1 with accents in comments only ran before bytes that are not
    UTF-8 were refused, and its checkpoint could be continued; saving it again as UTF-8 makes
    it another deck for --restart. Such comments are a warning: the run goes on, the results
    store the deck as UTF-8 (U+FFFD in place of each such byte: the plotting scripts decode it),
    the checkpoint's deck hash is that of the file's bytes (as before the check), and the
    results equal those of the deck without the accents. Outside a comment (the title) such a
    byte is still an error."""
    plain = beam_deck().replace("[run]", "# poutre de test\n[run]").replace("[time]", "[time] # pas de temps")
    latin = plain.replace("poutre de test", "poutre d\xe9pos\xe9e").replace("pas de temps", "\xe0 voir").encode("latin-1")
    folder = work / "latin1"
    for name, data in (("plain", plain.encode()), ("latin", latin)):
        (work / f"latin1_{name}.dat").write_bytes(data)
    proc = multicor(exe, work / "latin1_latin.dat", "--output", folder)
    check("latin-1 comment: runs", proc.returncode == 0, proc.stderr.strip()[:300])
    expect = ("warning: " + str(work / "latin1_latin.dat") + ":1: byte 0xE9 at column 11, in a comment, is not "
              "UTF-8 text (1 more line has such bytes in its comment): the results store the deck with U+FFFD")
    check("latin-1 comment: warned at its line and column", expect in proc.stdout + proc.stderr,
          (proc.stdout + proc.stderr)[:600])
    if proc.returncode == 0:
        with h5py.File(folder / "latin1_latin.h5", "r") as f:
            try:
                text = f.attrs["deck_text"]
                text = text if isinstance(text, str) else text.decode("utf-8")
            except UnicodeDecodeError as e:
                text = f"not UTF-8: {e}"
            displacement = f["fem/displacement"][...]
        check("latin-1 comment: the stored deck is UTF-8, U+FFFD for each byte",
              text == latin.decode("utf-8", errors="replace") and text.count("\ufffd") == 3, text[:200])
        with h5py.File(folder / "checkpoint.h5", "r") as f:
            hashed = f.attrs["deck_hash"]
            hashed = hashed if isinstance(hashed, str) else hashed.decode()
        check("latin-1 comment: the checkpoint hashes the file's bytes", hashed == deck_hash(latin),
              f"checkpoint {hashed}, bytes {deck_hash(latin)}")
        proc = multicor(exe, work / "latin1_latin.dat", "--output", folder, "--quiet",
                        "--restart", folder / "checkpoint.h5", "--end", "4e-3")
        check("latin-1 comment: its checkpoint is continued", proc.returncode == 0, proc.stderr.strip()[:300])
        proc = multicor(exe, work / "latin1_plain.dat", "--output", work / "latin1_plain", "--quiet")
        if check("latin-1 comment: the deck without accents runs", proc.returncode == 0, proc.stderr.strip()[:300]):
            with h5py.File(work / "latin1_plain" / "latin1_plain.h5", "r") as f:
                # a comment changes nothing computed: the same results bit for bit
                check("latin-1 comment: same results as without the accents",
                      np.array_equal(f["fem/displacement"][...], displacement), "")
    title = beam_deck().replace("[run]", "[run]\ntitle = poutre d\xe9pos\xe9e # ok").encode("latin-1")
    (work / "latin1_title.dat").write_bytes(title)
    proc = multicor(exe, work / "latin1_title.dat", "--output", work / "latin1_title", "--quiet")
    check("latin-1 title: refused", proc.returncode == 1 and
          "latin1_title.dat:2: byte 0xE9 at column 17 is not UTF-8 text: save the deck as UTF-8" in proc.stderr,
          f"exit {proc.returncode} {proc.stderr.strip()[:300]}")


def end_off_the_steps(exe, work):
    """An end time that is not a whole number of steps: the run goes to the next step, and says
    so once; a whole number (2e-3 s of 2e-4 s steps, a quotient rounded in floating point) is
    silent."""
    for name, end, steps, warned in (("end_on_steps", "2e-3", 10, False), ("end_off_steps", "2.0000001e-3", 11, True)):
        deck = work / f"{name}.dat"
        deck.write_text(beam_deck().replace("end = 2e-3", f"end = {end}"))
        proc = multicor(exe, deck, "--output", work / name, "--quiet")
        said = [ln for ln in (proc.stdout + proc.stderr).splitlines() if "is not a whole number of time steps" in ln]
        check(f"{name}: exit 0", proc.returncode == 0, f"exit {proc.returncode}")
        check(f"{name}: {'warned once' if warned else 'no warning'}", len(said) == (1 if warned else 0),
              "; ".join(said) or "none")
        with h5py.File(work / name / f"{name}.h5", "r") as f:
            done = int(f["summary"].attrs["steps"])
        check(f"{name}: {steps} steps done", done == steps, f"{done}")


def speed_warning(exe, work):
    """A disk that moves farther than the alert distance in one step (its contacts may be
    found late) is reported once, with the distance |v| h of the fastest disk, |v| from both
    components of its velocity."""
    deck_text = """[run]
analysis = dynamic
[particles]
material = 1 2500
disk = 0 0 0.01 1
disk = 1 0 0.01 1
initial_velocity = 1 x {vx}
initial_velocity = 1 y {vy}
[contacts]
law = 1 1 0.4 0 0
alert = 1e-3
[time]
step = 1e-3
end = 5e-3
[output]
progress = 0
"""
    # |v| h against the alert distance 1 mm: 3 mm straight down, 5 mm along (3, 4) m/s,
    # 0.5 mm along (0.3, 0.4) m/s (below it: no warning). No force acts: |v| stays.
    for name, vx, vy, moved, speed in (("speed_down", "0", "-3", "3.00E-003", "3.00E+000"),
                                       ("speed_oblique", "3", "4", "5.00E-003", "5.00E+000"),
                                       ("speed_slow", "0.3", "0.4", None, None)):
        deck = work / f"{name}.dat"
        deck.write_text(deck_text.format(vx=vx, vy=vy))
        proc = multicor(exe, deck, "--output", work / name, "--quiet")
        check(f"{name}: exit 0", proc.returncode == 0, proc.stderr.strip()[:300])
        said = [ln for ln in proc.stdout.splitlines() if "more than the alert distance" in ln]
        if moved is None:
            check(f"{name}: no speed warning", not said, "; ".join(said))
        else:
            expect = rf"a disk moves\s+{re.escape(moved)} m in one step \(speed\s+{re.escape(speed)} m/s\)"
            check(f"{name}: one speed warning, {moved} m in one step", len(said) == 1
                  and re.search(expect, said[0]) is not None, "; ".join(said) or "none")


def wall_end_beyond_box(exe, work):
    """A driven wall whose second end point leaves the box the run can represent, while its
    first one is still inside, stops the run like a wall that leaves it whole."""
    # The box: |x|, |y| <= 1e-6 r_min / eps (dem_detection::coordinate_limit), r_min = 0.01 m.
    limit = 1.0e-6 * (0.01 / float(np.finfo(float).eps))
    # A floor ending 5 cm inside the box, driven along itself at 100 m/s: 10 cm per step of
    # 1 ms, so its second end is beyond the box after step 1 and its first at x = 0.1 m.
    text = f"""[run]
analysis = dynamic
[particles]
material = 1 2500
disk = 1 0.011 0.01 1
[walls]
wall = 0 0 {limit - 0.05!r} 0 1 {{v}} 0
[contacts]
law = 1 1 0.4 0 0
[time]
step = 1e-3
end = 5e-3
[output]
progress = 0
"""
    failing_run(exe, work, "dem_wall_end_beyond_box", text.format(v="100"),
                r"step 1 \(t = 1\.00000E-003 s\): wall 1 has moved to \(1\.0+E-0*1, 0\.0+E\+0+\) - .* beyond the box",
                text.format(v="1"))


#: A disk driven by a force of 1e300 N switched on at t = 0.041 s (the audit's late.dat): it
#: runs 40 steps, storing an output every 2 (21 with the initial state) and a checkpoint
#: every 10, then step 41 puts it beyond the box.
LATE_DECK = """[run]
analysis = dynamic
[particles]
material = 1   7800
disk     = 0.03  0.04   0.05    1
force = 1 x 1e300 1
[functions]
function = 1 table 0 0 0.04 0 0.041 1
[time]
step     = 1.0e-3
end      = 0.05
[output]
interval = 2
checkpoint_interval = 10
progress = 0
"""
LATE_STATUS = r"failed at step 41, t = 4\.10000000E-002 s: step 41 \(t = 4\.10000E-002 s\): disk 1 is at "


def failed_records(exe, work):
    """A time loop that failed after some outputs deleted them all, its checkpoints and the
    folder it created: nothing was left to see what led to the blow-up (a kill -9 kept more).
    Its records are now kept as '<name>.h5.failed' (/summary status naming the failure, the
    outputs whole), beside the folder's earlier files left byte for byte; its checkpoints are
    dropped. A later fresh run and a restart of the earlier checkpoint go on as if it were
    not there, and a restart that fails replaces it, its own results file left to the next
    restart."""
    for old in ("failed_new", "failed_kept"):
        shutil.rmtree(work / old, ignore_errors=True)
    new = work / "failed_new" / "sub"
    deck = work / "late.dat"
    deck.write_text(LATE_DECK)
    proc = multicor(exe, deck, "--output", new, "--quiet")
    failed = new / "late.h5.failed"
    check("failed run: exit 1", proc.returncode == 1, f"exit {proc.returncode}")
    check("failed run: the message ends with where the records are",
          proc.stderr.strip().endswith(f"the records up to the failure (21 outputs) are kept in '{failed}' "
                                       "(/summary status: what failed)"), proc.stderr.strip()[-300:])
    check("failed run into a new folder: the folder kept with the records alone",
          new.is_dir() and sorted(p.name for p in new.iterdir()) == ["late.h5.failed"],
          str(sorted(new.iterdir())) if new.is_dir() else "no folder")
    if failed.exists():
        failed_file(failed)
    failed_beside_results(exe, work, deck)


def failed_file(failed):
    """The checks of the records of the late deck's failed run."""
    with h5py.File(failed, "r") as f:
        attrs = dict(f["summary"].attrs)
        time = f["dem/time"][()]
        position = f["dem/position"][()]
    check("failed records: /summary finished = 0, outputs 21, steps 40",
          (attrs["finished"], attrs["outputs"], attrs["steps"]) == (0, 21, 40), str(attrs))
    check("failed records: status names the step and the failure",
          re.match(LATE_STATUS, attrs["status"]) is not None, attrs["status"][:200])
    # the stored times are k * 1e-3 computed in binary: 1e-12 is far above their round-off
    check("failed records: the 21 outputs up to t = 0.04 s, finite",
          time.shape == (21,) and np.allclose(time, 2e-3 * np.arange(21), rtol=0, atol=1e-12)
          and position.shape[0] == 21 and np.isfinite(position).all(), f"{time.shape} {position.shape}")


def failed_beside_results(exe, work, deck):
    """The late deck failing in a folder holding a finished run to 0.03 s (the same deck,
    --end) and its checkpoint, then restarted."""
    folder = work / "failed_kept"
    first = multicor(exe, deck, "--output", folder, "--quiet", "--end", "0.03")
    check("failed run beside a result: the earlier run", first.returncode == 0, first.stderr[-300:])
    earlier = {p.name: digest(p) for p in folder.iterdir()}
    proc = multicor(exe, deck, "--output", folder, "--quiet")
    check("failed run beside a result: exit 1", proc.returncode == 1, proc.stderr.strip()[:300])
    after = {p.name: digest(p) for p in folder.iterdir() if p.name != "late.h5.failed"}
    check("failed run beside a result: its records kept, the earlier files byte for byte",
          (folder / "late.h5.failed").exists() and after == earlier, f"{sorted(after)} {sorted(earlier)}")
    if not (folder / "late.h5.failed").exists():
        return
    kept = digest(folder / "late.h5.failed")
    # a restart of the earlier checkpoint (step 30) to 0.036 s, then a fresh run to 0.03 s
    proc = multicor(exe, deck, "--restart", folder / "checkpoint.h5", "--quiet", "--end", "0.036")
    with h5py.File(folder / "late.h5", "r") as f:
        outputs = f["dem/time"].shape[0]
    check("restart beside the records of a failed run: extends the earlier result",
          proc.returncode == 0 and outputs == 19, f"exit {proc.returncode}, {outputs} outputs; {proc.stderr[-300:]}")
    check("restart beside the records of a failed run: they are left as they were",
          digest(folder / "late.h5.failed") == kept, "")
    # a restart that fails (from step 36, at step 41): the copy of the finished file it
    # continued becomes the records, replacing the earlier ones; the finished file stays
    finished = digest(folder / "late.h5")
    checkpoint = digest(folder / "checkpoint.h5")
    proc = multicor(exe, deck, "--restart", folder / "checkpoint.h5", "--quiet")
    with h5py.File(folder / "late.h5.failed", "r") as f:
        attrs = dict(f["summary"].attrs)
        outputs = f["dem/time"].shape[0]
    check("failed restart: exit 1, the records replaced by its own (21 outputs)",
          proc.returncode == 1 and digest(folder / "late.h5.failed") != kept and outputs == 21
          and attrs["outputs"] == 21 and re.match(LATE_STATUS, attrs["status"]) is not None,
          f"exit {proc.returncode}, {outputs} outputs, {attrs['status'][:100]}")
    check("failed restart: the finished result and its checkpoint as they were, nothing else",
          digest(folder / "late.h5") == finished and digest(folder / "checkpoint.h5") == checkpoint
          and sorted(p.name for p in folder.iterdir()) == ["checkpoint.h5", "late.h5", "late.h5.failed", "late.xdmf"],
          str(sorted(p.name for p in folder.iterdir())))
    # a restart that continues a partial file in place (the checkpoint's results, as a
    # stopped run leaves them) keeps it for the next restart and copies it as the records
    (folder / "late.h5").rename(folder / "late.h5.partial")
    proc = multicor(exe, deck, "--restart", folder / "checkpoint.h5", "--quiet")
    check("failed restart of a partial file: exit 1, the partial file kept, its copy the records",
          proc.returncode == 1 and (folder / "late.h5.partial").exists()
          and digest(folder / "late.h5.partial") == digest(folder / "late.h5.failed"), proc.stderr.strip()[-200:])
    proc = multicor(exe, deck, "--restart", folder / "checkpoint.h5", "--quiet", "--end", "0.04")
    check("failed restart of a partial file: the next restart continues it",
          proc.returncode == 0 and (folder / "late.h5").exists() and not (folder / "late.h5.partial").exists(),
          proc.stderr.strip()[-300:])
    proc = multicor(exe, deck, "--output", folder, "--quiet", "--end", "0.03")
    check("fresh run beside the records of a failed run: exit 0, the records left",
          proc.returncode == 0 and (folder / "late.h5.failed").exists(), proc.stderr.strip()[-300:])


def main():
    exe, work, src = arguments()
    non_finite(exe, work)
    coupled_non_finite(exe, work, src / "tests" / "regression" / "decks")
    coupled2d_initial_state(exe, work, src)
    continuum_blow_up_cause(exe, work, src)
    aliased_harmonic(exe, work)
    tunnelling(exe, work)
    squeezed(exe, work)
    lock(exe, work)
    output_empty(exe, work)
    end_option(exe, work)
    no_empty_folder(exe, work)
    failed_records(exe, work)
    exponents(exe, work)
    speed_warning(exe, work)
    wall_end_beyond_box(exe, work)
    line_endings(exe, work)
    latin1_comment(exe, work)
    end_off_the_steps(exe, work)
    return summary()


if __name__ == "__main__":
    sys.exit(main())
