#!/usr/bin/env python3
"""Settings that another setting or the kind of run turns off: the deck is valid, the run
goes on, and a warning names the file, the line and the setting that turns it off.

- The example decks of input/ carry no such setting: `--check` prints no warning for any.
- A solver tuning value where it does nothing (`coarse_size` with the default method,
  `anderson_sweeps` with `anderson = 0`, `check_every` at relaxation 1.0) is warned about,
  one line each, in the order of the deck; the same values where they act are not.
- A static or modal analysis warns about what it does not use: [output] interval and the
  checkpoints, the mass (static), the loads (modal), and loads that are all zero at t = 0,
  where a static analysis takes their time functions.
- A rolling length beyond the radius of the largest disk of its law's materials is warned
  about at the law's line (the moment's arm would be longer than the disk).
- A [coupling] thickness other than the thickness of the continuum's material under the
  regions is warned about at its line, naming that material's line (--check and the run).
- A beam coupling's thickness more than 100 times off the width of the beam's section (the
  rectangle with its A and I; a depth typed in mm) is warned about at its line.
- Without max_offset, coupled disks off the beam's section (farther from the axis than their
  radius plus sqrt(3 I / A), the section's half-height) are warned about, naming the
  farthest; disks within it, or any distance once max_offset is set, are not.
- A static or dynamic beam or continuum run, coupled to disks or not, whose largest
  displacement exceeds 10 % of the model's extent (a modulus in MPa read as Pa) warns that linear theory does not hold, with
  exit 0; the threshold is checked on a cantilever's closed-form tip deflection. A static
  beam run's summary prints as max |displacement| that same measure, the largest nodal
  sqrt(u^2 + w^2) (a cantilever at 45 degrees: sqrt(2) times its largest component).
- Coupled disks free to turn (`[coupling] rotation = off`, the default) with a law of friction
  and no rolling resistance are warned about: they roll instead of transmitting friction.
- A `[contacts] bond` record that bonds no pair at t = 0 (a loose deposit, a row with gaps of
  1e-3 R, beyond the bond tolerance of 1e-6 R) is warned about at its line, under --check and
  at the run's start; a touching row is not, and the run's summary counts its bonds at t = 0
  (n - 1 = 4 for a row of 5 touching disks, 0 for the row with gaps).
- `[contacts] bond` records with `[solver] method = nlgs` or `coarse` (the bonds swept one
  contact at a time, whose stopping test can be met far from the solution) are warned about
  at the method's line, for particles alone and coupled to a beam; `method = block` (the
  default) and `nlgs` without bonds are not.
- In a deck with laws, walls of a material without a law with any disk material, or disks
  of a material without one with any wall material, are warned about at the first law's
  line; pairs that are one of several (input/incline.dat's inclines), laws between disks, or
  a deck without any law, are not.
- `[contacts] alert = 0` is warned about at its line (contacts seen only once disks touch).
- A time function used by a load that is zero over the whole run (a step at 1.0 s of a run
  that ends at 0.5 s) is warned about at its line, with the line of the load, under --check
  and at the run's start, once per such function; not when it acts before the end (the
  step at 1.0 s with --end 2, a table pulse inside the run).
- In a coupled run (beam or continuum: input/bending_hinged_row.dat, input/interface_shear.dat)
  `method = coarse` and `cold_start = hydrostatic` are warned about, and the warning is true:
  the run's results are those of `method = nlgs` (and of `cold_start = zero`), bit for bit.

Usage (ctest does this): test_deck_warnings.py --exe multicor --work DIR --source REPO
"""
import math
import re
import subprocess
import sys

import h5py
import numpy as np

from checks import arguments, check, summary


def multicor(exe, *args):
    return subprocess.run([str(exe), *map(str, args)], capture_output=True, text=True, timeout=300)


def warnings_of(out):
    return [line for line in out.splitlines() if line.startswith("warning:")]


def with_solver(text, lines):
    """The deck with `lines` under its [solver] header (added at the end if it has none)."""
    if re.search(r"^\[solver\]", text, flags=re.M):
        return re.sub(r"^\[solver\]\n", "[solver]\n" + lines, text, count=1, flags=re.M)
    return text + "\n[solver]\n" + lines


def line_of(text, keyword):
    """1-based line of the first `keyword =` line of `text`."""
    for i, line in enumerate(text.splitlines(), start=1):
        if re.match(rf"\s*{keyword}\s*=", line):
            return i
    raise ValueError(keyword)


def example_decks_are_quiet(exe, src):
    for deck in sorted((src / "input").glob("*.dat")):
        proc = multicor(exe, "--check", deck)
        check(f"input/{deck.name}: --check exit 0 without warning",
              proc.returncode == 0 and not warnings_of(proc.stdout + proc.stderr),
              f"exit {proc.returncode}; " + "; ".join(warnings_of(proc.stdout + proc.stderr))[:300])


def solver_values(exe, src, work):
    base = (src / "input" / "deposit.dat").read_text()
    base = re.sub(r"^\s*(anderson|method|relaxation|check_every|coarse_\w+)\s*=.*\n", "", base, flags=re.M)
    text = with_solver(base, "coarse_size = 100\nanderson = 0\nanderson_sweeps = 3\nrelaxation = 1.0\n"
                       "check_every = 5\n")
    deck = work / "ineffective.dat"
    deck.write_text(text)
    proc = multicor(exe, "--check", deck)
    said = warnings_of(proc.stdout)
    expected = [f"warning: {deck}:{line_of(text, 'coarse_size')}: [solver] coarse_size has no effect: it "
                "applies only when [solver] method = coarse; here method = block (default)",
                f"warning: {deck}:{line_of(text, 'anderson_sweeps')}: [solver] anderson_sweeps has no effect: it "
                f"applies only when [solver] anderson is not 0; here anderson = 0 (line {line_of(text, 'anderson')})",
                f"warning: {deck}:{line_of(text, 'check_every')}: [solver] check_every has no effect: it applies "
                f"only when [solver] relaxation is not 1; here relaxation = 1.0 (line {line_of(text, 'relaxation')})"]
    check("solver values without effect: valid deck", proc.returncode == 0, proc.stderr.strip()[:300])
    check("solver values without effect: one warning each, in the deck's order", said == expected,
          "\n".join(said))
    text = with_solver(base, "method = coarse\ncoarse_size = 100\nanderson = 2\nanderson_sweeps = 3\n"
                       "relaxation = 1.3\ncheck_every = 5\n")
    deck.write_text(text)
    proc = multicor(exe, "--check", deck)
    check("solver values where they act: no warning", proc.returncode == 0 and not warnings_of(proc.stdout),
          "; ".join(warnings_of(proc.stdout)))


def rolling_length(exe, src, work):
    """A rolling length beyond the radius of the largest disk of the law's materials (the
    deposit's disks: radii 2.0 to 2.5 mm) is warned about at the law's line; one below is not."""
    base = (src / "input" / "deposit.dat").read_text()
    for e_r, warned in (("10", True), ("0.002", False)):
        text = re.sub(r"^law\s*=.*$", f"law = 1 1 0.4 0.1 0 {e_r}", base, count=1, flags=re.M)
        deck = work / f"rolling_{e_r}.dat"
        deck.write_text(text)
        proc = multicor(exe, "--check", deck)
        said = warnings_of(proc.stdout)
        expected = (f"warning: {deck}:{line_of(text, 'law')}: [contacts] law: the rolling length "
                    f"e_r = {e_r} m exceeds the radius of the largest disk of materials 1 and 1")
        check(f"rolling length {e_r} m on disks of 2.5 mm: {'warned' if warned else 'no warning'}",
              proc.returncode == 0
              and (len(said) == 1 and said[0].startswith(expected) if warned else not said),
              "\n".join(said) or proc.stderr.strip()[:300])


def coupled(exe, work, name, deck_path, ends, bonds, extra=""):
    """`deck_path` (ending at `ends`, with the solver lines `extra`) with method = coarse and
    cold_start = hydrostatic: two warnings, and the results of method = nlgs, cold_start =
    zero. The sweeps are many (`extra` keeps them at about 100 per step), so that a coarse
    correction or another start of the first step would show in the results. The summary
    counts the `bonds` made at t = 0 (None: a deck without cohesion, no such line)."""
    base = re.sub(r"^\s*(method|cold_start|tolerance)\s*=.*\n", "", deck_path.read_text(), flags=re.M)
    base = re.sub(r"^end\s*=.*$", f"end = {ends}", base, count=1, flags=re.M)
    if "mesh = file " in base:
        base = base.replace("mesh = file ", f"mesh = file {deck_path.parent}/")
    results = {}
    for variant, lines in (("off", "method = coarse\ncold_start = hydrostatic\n"),
                           ("nlgs", "method = nlgs\ncold_start = zero\n")):
        text = with_solver(base, lines + extra)
        deck = work / f"{name}_{variant}.dat"
        deck.write_text(text)
        proc = multicor(exe, deck, "--output", work / f"{name}_{variant}", "--quiet")
        said = warnings_of(proc.stdout)
        if variant == "off":
            check(f"{name}: exit 0", proc.returncode == 0, proc.stderr.strip()[:300])
            check(f"{name}: method = coarse warned about at its line",
                  any(w.startswith(f"warning: {deck}:{line_of(text, 'method')}: [solver] method = coarse has no "
                                   "effect in a coupled run") for w in said), "\n".join(said))
            check(f"{name}: cold_start = hydrostatic warned about at its line",
                  any(w.startswith(f"warning: {deck}:{line_of(text, 'cold_start')}: [solver] cold_start = "
                                   "hydrostatic has no effect in a coupled run") for w in said), "\n".join(said))
        else:
            # (interface_shear's displacement starts at 1 ms: cut at 0.2 ms, its function is
            # zero over the whole run, which is warned about and is not the point here)
            said = [w for w in said if "is zero at every time of the run" not in w]
            check(f"{name}: method = nlgs is not warned about", proc.returncode == 0 and not said, "\n".join(said))
            line = f"bonds at t = 0: {bonds} (0 ruptures since" if bonds is not None else "bonds at t = 0"
            check(f"{name}: the summary {'counts' if bonds is not None else 'has no line of'} the bonds at t = 0",
                  (line in proc.stdout) == (bonds is not None), proc.stdout[-400:])
        with h5py.File(work / f"{name}_{variant}" / f"{name}_{variant}.h5", "r") as f:
            results[variant] = (f["dem/position"][...], f["dem/velocity"][...], f["dem/solver/sweeps"][...])
            named = tuple(f["dem/solver"].attrs[key] for key in ("method", "cold_start"))
        named = tuple(value.decode() if isinstance(value, bytes) else value for value in named)
        # the results name the deck's settings, as the warnings do
        expected = ("coarse", "hydrostatic") if variant == "off" else ("nlgs", "zero")
        check(f"{name}: /dem/solver names method and cold_start as the deck does ({variant})", named == expected,
              f"{named}, expected {expected}")
    same = all(np.array_equal(a, b) for a, b in zip(results["off"], results["nlgs"]))
    check(f"{name}: the results are those of method = nlgs, bit for bit", same,
          f"sweeps {results['off'][2].sum()} and {results['nlgs'][2].sum()}")
    check(f"{name}: the contacts are solved by sweeps (not a trivial step)", results["nlgs"][2].mean() > 10,
          f"sweeps per step {results['nlgs'][2].mean():.1f}")


def analysis_without_time(exe, work):
    """Settings that a static or modal analysis does not use: the output interval and the
    checkpoints (no time steps), the mass (static), the loads (modal); and a static analysis
    whose every load is zero at t = 0, where it takes its time functions (a ramp from 0): the
    solution is zero. Each warned about at its line; a dynamic run of the same deck is quiet."""
    text = """[run]
analysis = {analysis}
[beam]
mass = lumped
section = 1 2.1e11 7800 2.0e-4 1.6666666666666667e-9
line = 1 0.0 0.0 1.0 0.0 10 1
fix = 1 all
load = 11 w -10.0 1
gravity = 0 -9.81
[functions]
function = 1 ramp 0.1
[output]
interval = 5
checkpoint_interval = 100
checkpoint_seconds = 60
"""
    expected = {
        "static": [(4, "[beam] mass has no effect"), (8, "every load of this static analysis is zero at t = 0"),
                   (13, "[output] interval has no effect"), (14, "[output] checkpoint_interval has no effect"),
                   (15, "[output] checkpoint_seconds has no effect")],
        "modal": [(8, "[beam] load has no effect"), (9, "[beam] gravity has no effect"),
                  (13, "[output] interval has no effect"), (14, "[output] checkpoint_interval has no effect"),
                  (15, "[output] checkpoint_seconds has no effect")],
        "dynamic": [],
    }
    for analysis, wanted in expected.items():
        deck = work / f"no_time_{analysis}.dat"
        body = text.format(analysis=analysis)
        if analysis == "static":
            body = body.replace("gravity = 0 -9.81\n", "")
            wanted = [(line - 1 if line > 9 else line, what) for line, what in wanted]
        if analysis == "dynamic":
            body += "[time]\nstep = 1e-3\nend = 1e-2\n"
        deck.write_text(body)
        proc = multicor(exe, "--check", deck)
        said = warnings_of(proc.stdout + proc.stderr)
        found = [(int(m.group(1)), what) for line in said for what in [w for _, w in wanted]
                 if (m := re.match(rf"warning: .*{deck.name}:(\d+): ", line)) and what in line]
        check(f"{analysis} analysis: the settings it does not use are warned about at their lines",
              proc.returncode == 0 and sorted(found) == sorted(wanted) and len(said) == len(wanted),
              f"exit {proc.returncode}; " + "; ".join(said)[:600])


def continuum_static_ramp(exe, work):
    """A continuum's static analysis whose only load is a traction under a ramp from 0: zero
    at t = 0, where it takes the functions, so the solution is zero; warned about at the
    traction's line (as for the beam). The same traction constant: no warning."""
    text = """[run]
analysis = static
[continuum]
mesh = rectangle 0 -0.5 10 1 20 4 q4
material = 70e9 0.3 2700 0.1 plane_stress
fix = left x y
traction = right 0 10000 parabolic{function}
[functions]
function = 1 ramp 0.1
"""
    for function, wanted in ((" 1", 1), ("", 0)):
        deck = work / f"continuum_static{'_ramp' if function else ''}.dat"
        deck.write_text(text.format(function=function))
        proc = multicor(exe, "--check", deck)
        said = [line for line in warnings_of(proc.stdout + proc.stderr)
                if f"{deck.name}:7: every load and prescribed displacement" in line]
        check(f"continuum static, traction {'under a ramp' if function else 'constant'}: "
              f"{'warned' if wanted else 'no warning'} that the solution is zero",
              proc.returncode == 0 and len(said) == wanted and len(warnings_of(proc.stdout)) == wanted,
              f"exit {proc.returncode}; " + "; ".join(warnings_of(proc.stdout + proc.stderr))[:300])


def coupling_thickness(exe, src, work):
    """input/coupled2d_block.dat (material thickness 0.05 m) with [coupling] thickness = 0.5:
    one warning at the thickness line naming the material's line and thickness, under --check
    and at the run (exit 0 both); input/interface_shear.dat with its bottom block 0.02 m thick
    (the top block and thickness 0.01 m): the warning names the bottom block's line only."""
    text = (src / "input" / "coupled2d_block.dat").read_text()
    text = re.sub(r"^thickness\s*=.*$", "thickness = 0.5", text, count=1, flags=re.M)
    text = re.sub(r"^end\s*=.*$", "end = 2e-5", text, count=1, flags=re.M)
    deck = work / "thickness_block.dat"
    deck.write_text(text)
    expected = (f"warning: {deck}:{line_of(text, 'thickness')}: [coupling] thickness = 0.5 m differs from the "
                f"thickness 0.05 m of the continuum's material under the region ([continuum] material, line "
                f"{line_of(text, 'material')}): ")
    for mode, args in (("--check", ("--check", deck)), ("run", (deck, "--output", work / "thickness_block", "--quiet"))):
        proc = multicor(exe, *args)
        said = warnings_of(proc.stdout)
        check(f"coupling thickness 0.5 m on a 0.05 m continuum ({mode}): exit 0, one warning naming both lines",
              proc.returncode == 0 and len(said) == 1 and said[0].startswith(expected)
              and said[0].endswith("set thickness = 0.05"),
              f"exit {proc.returncode}; " + ("\n".join(said) or proc.stderr.strip()[:300]))
    source = src / "input" / "interface_shear.dat"
    text = source.read_text().replace("mesh = file ", f"mesh = file {source.parent}/")
    text = re.sub(r"^(material = 210e9 0.3 7800) 0.01 ", r"\1 0.02 ", text, count=1, flags=re.M)
    deck = work / "thickness_interface.dat"
    deck.write_text(text)
    proc = multicor(exe, "--check", deck)
    said = warnings_of(proc.stdout)
    expected = (f"warning: {deck}:{line_of(text, 'thickness')}: [coupling] thickness = 0.01 m differs from the "
                f"thickness 0.02 m of the continuum's material under the region ([continuum] material, line "
                f"{line_of(text, 'material')}): ")
    check("two blocks, the bottom one 0.02 m thick: one warning, naming its material line",
          proc.returncode == 0 and len(said) == 1 and said[0].startswith(expected),
          f"exit {proc.returncode}; " + ("\n".join(said) or proc.stderr.strip()[:300]))


def beam_coupling_thickness(exe, src, work):
    """input/bending_case1.dat (a 10 mm square beam section: A = 1e-4 m^2, I = 8.33e-10 m^4,
    the width of the rectangle with that A and I, A / sqrt(12 I / A), is 0.01 m) with its
    thickness typed in mm (10) or as 1e-5 m: warned at the thickness line, naming 0.01 m,
    exit 0 (--check and a run of 2 steps); at 0.9 m and 1.1e-4 m (inside the factor 100 that
    other section shapes need, 90 and 1/91 of the width) and at the deck's 0.01 m: quiet."""
    base = (src / "input" / "bending_case1.dat").read_text()
    for value, warned in (("10", True), ("1e-5", True), ("0.9", False), ("1.1e-4", False), ("0.01", False)):
        text = re.sub(r"^thickness\s*=.*$", f"thickness = {value}", base, count=1, flags=re.M)
        text = re.sub(r"^end\s*=.*$", "end = 2e-5", text, count=1, flags=re.M)
        deck = work / f"beam_thickness_{value}.dat"
        deck.write_text(text)
        expected = (f"warning: {deck}:{line_of(text, 'thickness')}: [coupling] thickness = {value} m is more "
                    "than 100 times off the width of the beam's section (0.01 m, the width of the rectangle "
                    "with its A and I)")
        runs = (("--check", ("--check", deck)),)
        if warned:
            runs += (("run", (deck, "--output", work / f"beam_thickness_{value}", "--quiet")),)
        for mode, args in runs:
            proc = multicor(exe, *args)
            said = warnings_of(proc.stdout)
            check(f"beam coupling thickness {value} m on a 0.01 m wide section ({mode}): exit 0, "
                  f"{'one warning' if warned else 'no warning'}",
                  proc.returncode == 0 and (len(said) == 1 and said[0].startswith(expected) if warned else not said),
                  f"exit {proc.returncode}; " + ("\n".join(said) or proc.stderr.strip()[:300]))


def coupled_disks_off_the_beam(exe, src, work):
    """The coupled example of doc/input.md (beam section A = 1e-4 m^2, I = 8.33e-10 m^4: the
    10 mm square, half-height sqrt(3 I / A) = 5 mm; disks of radius 5 mm in a row from
    x = 0.20 m, 7 of them in the overlap), its row moved off the axis by y0: warned about
    beyond 5 + 5 = 10 mm (the disk no longer touches the section), naming disk 1, its offset
    and max_offset; not below 10 mm, nor at 0.5 m once max_offset is set."""
    doc = (src / "doc" / "input.md").read_text()
    block = doc[doc.index("## Coupled runs (Arlequin)"):]
    text = block[block.index("```\n") + 4:]
    text = text[:text.index("```")]
    text = re.sub(r"^end\s*=.*$", "end = 2e-5", text, count=1, flags=re.M)
    # the distance 0.0101 and 0.0099 m are 1 % beside the threshold 0.01 m, far beyond the
    # rounding of the offset (1e-18 m)
    for y0, extra, warned in (("0.5", "", True), ("0.0101", "", True), ("0.0099", "", False),
                              ("0", "", False), ("0.5", "max_offset = 1\n", False)):
        body = re.sub(r"^row(\s*)= 17 0.20 0 ", rf"row\1= 17 0.20 {y0} ", text, count=1, flags=re.M)
        body = body.replace("[coupling]\n", "[coupling]\n" + extra)
        deck = work / f"offset_{y0}{'_limited' if extra else ''}.dat"
        deck.write_text(body)
        proc = multicor(exe, "--check", deck)
        said = warnings_of(proc.stdout)
        expected = (f"warning: {deck}:{line_of(body, 'coupled')}: [coupling] 7 of the 7 coupled disks lie off "
                    f"the beam's section; the farthest, disk 1 (line {line_of(body, 'row')}), is {y0} m from the "
                    "beam axis, beyond its radius plus the section's half-height (0.01 m; half-height sqrt(3 I / A) "
                    "= 0.005 m)")
        check(f"coupled row at y = {y0} m{' with max_offset' if extra else ''}: "
              f"{'warned' if warned else 'no warning'}, exit 0",
              proc.returncode == 0
              and (len(said) == 1 and said[0].startswith(expected) and "max_offset (e.g. 0.01 m)" in said[0]
                   if warned else not said),
              f"exit {proc.returncode}; " + ("\n".join(said) or proc.stderr.strip()[:300]))
    # the stacked layers of input/bending_stack.dat without max_offset: the outer rows at
    # 8.66 mm touch the section (below 10 mm), all 19 coupled quietly
    text = re.sub(r"^max_offset\s*=.*\n", "", (src / "input" / "bending_stack.dat").read_text(), flags=re.M)
    deck = work / "stack_all_layers.dat"
    deck.write_text(text)
    proc = multicor(exe, "--check", deck)
    check("three stacked rows, all coupled (offsets 8.66 mm < 10 mm): no warning",
          proc.returncode == 0 and "19 coupled" in proc.stdout and not warnings_of(proc.stdout),
          f"exit {proc.returncode}; " + (proc.stdout.strip()[-300:] or proc.stderr.strip()[:300]))


def large_displacements(exe, src, work):
    """Linear runs whose displacement exceeds 10 % of the model's extent warn, exit 0.
    A 1 m cantilever (E I = 350 N m^2) under an end load P: the cubic beam elements give the
    tip deflection P L^3 / (3 E I) exactly, 0.1 m (10 % of the extent, the bounding-box
    diagonal of 1 m) at P = 105 N: 110 N (0.105 m) warns, 100 N (0.095 m) does not; E in MPa
    read as Pa (2.1e5) warns, statically and in the dynamic input/cantilever.dat. The
    continuum cantilevers of input/ (static and dynamic) with E = 70e3 Pa (70 GPa written in
    kPa) warn; with 70e9 they do not."""
    beam = """[run]
analysis = static
[beam]
section = 1 {young} 7800 2.0e-4 1.6666666666666667e-9
line = 1 0.0 0.0 1.0 0.0 10 1
fix = 1 all
load = 11 w -{load}
"""
    lead = "warning: the largest displacement, "
    tail = ("linear small-strain theory does not hold at this displacement; check the units of E, the loads and "
            "the lengths ([beam] section, load, distributed, gravity, line, node)")
    for young, load, warned in (("2.1e11", "110", True), ("2.1e11", "100", False), ("2.1e5", "10", True)):
        deck = work / f"beam_{young}_{load}.dat"
        deck.write_text(beam.format(young=young, load=load))
        proc = multicor(exe, deck, "--output", work / deck.stem, "--quiet")
        said = warnings_of(proc.stdout)
        tip = float(load) / (3 * float(young) * 1.6666666666666667e-9)
        check(f"static beam, E = {young} Pa, P = {load} N (tip {tip:.4g} m on 1 m): "
              f"{'warned' if warned else 'no warning'}, exit 0",
              proc.returncode == 0 and (len(said) == 1 and said[0].startswith(lead) and said[0].endswith(tail)
                                        if warned else not said),
              f"exit {proc.returncode}; " + ("\n".join(said) or proc.stderr.strip()[:300]))
    # the summary's max |displacement| is the largest nodal norm, the measure of the warning:
    # a cantilever at 45 degrees under a vertical end load deflects across its axis by
    # (P / sqrt 2) L^3 / (3 E I) exactly (cubic elements); the axial shortening P L / (sqrt 2
    # E A), 2.5e-5 of it and at right angles, adds 3e-10 to the norm; the components are
    # 1/sqrt 2 of it. To the 6 printed digits: 1e-5
    deck = work / "beam_45_degrees.dat"
    deck.write_text(beam.format(young="2.1e11", load="10").replace("1.0 0.0 10 1", "0.7071067811865476 "
                                                                   "0.7071067811865476 10 1"))
    proc = multicor(exe, deck, "--output", work / deck.stem)
    m = re.search(r"max \|displacement\| = +(\S+) m", proc.stdout)
    printed = float(m.group(1)) if m else math.nan
    across = 10 / math.sqrt(2) / (3 * 2.1e11 * 1.6666666666666667e-9)
    check("static beam: the summary's max |displacement| is the largest nodal norm",
          abs(printed / across - 1) < 1e-5, f"{printed} vs {across:.6e} m (largest component {across / math.sqrt(2):.6e})")
    text = re.sub(r"^(section\s*=\s*1\s+)2.1e11", r"\g<1>2.1e5", (src / "input" / "cantilever.dat").read_text(),
                  count=1, flags=re.M)
    deck = work / "cantilever_mpa.dat"
    deck.write_text(text)
    proc = multicor(exe, deck, "--output", work / deck.stem, "--quiet")
    said = warnings_of(proc.stdout)
    check("dynamic beam with E = 2.1e5 Pa: warned at the end of the run, exit 0",
          proc.returncode == 0 and len(said) == 1 and said[0].startswith(lead)
          and "[beam] section, load" in said[0], f"exit {proc.returncode}; " + ("\n".join(said) or proc.stderr[:300]))
    # the dynamic continuum cantilever with E = 70e3 Pa: a largest displacement of 1.2 m
    # (mean translation removed) on an extent of 10.05 m; 70e9 Pa is quiet (input/ decks)
    text = re.sub(r"^material = 70e9 ", "material = 70e3 ", (src / "input" / "continuum_cantilever_dynamic.dat")
                  .read_text(), count=1, flags=re.M)
    deck = work / "continuum_dynamic_70e3.dat"
    deck.write_text(text)
    proc = multicor(exe, deck, "--output", work / deck.stem, "--quiet")
    said = warnings_of(proc.stdout)
    check("dynamic continuum with E = 70e3 Pa: warned at the end of the run, exit 0",
          proc.returncode == 0 and len(said) == 1 and said[0].startswith(lead)
          and "([continuum] material, load" in said[0], f"exit {proc.returncode}; " + ("\n".join(said) or proc.stderr[:300]))
    source = (src / "input" / "continuum_cantilever.dat").read_text()
    for young, warned in (("70e3", True), ("70e9", False)):
        text = re.sub(r"^material = 70e9 ", f"material = {young} ", source, count=1, flags=re.M)
        deck = work / f"continuum_{young}.dat"
        deck.write_text(text)
        proc = multicor(exe, deck, "--output", work / deck.stem, "--quiet")
        said = warnings_of(proc.stdout)
        check(f"static continuum, E = {young} Pa: {'warned' if warned else 'no warning'}, exit 0",
              proc.returncode == 0 and (len(said) == 1 and said[0].startswith(lead)
                                        and "([continuum] material, load" in said[0] if warned else not said),
              f"exit {proc.returncode}; " + ("\n".join(said) or proc.stderr.strip()[:300]))

    # coupled runs check the same: a 0.2 m cantilever clamped at x = 0 with 5 bonded disks
    # glued at its free end, under gravity, 0.1 s; E = 2.1e5 Pa (2.1e11 written in MPa): the
    # beam is so soft that it nearly falls freely, g t^2 / 2 = 4.9 cm at 0.1 s, beyond 10 % of
    # its 0.2 m extent (4.0 cm measured); E = 2.1e11 Pa moves it by 2e-7 m: quiet. (The largest
    # displacement is taken over the stored states, every 100 steps here (the end among them):
    # the displacements of both decks grow to the end. Stored at every step, they made 90 % of
    # the run's time.)
    for young, warned in (("2.1e5", True), ("2.1e11", False)):
        deck = work / f"coupled_beam_{young}.dat"
        deck.write_text(COUPLED_BEAM.format(young=young))
        proc = multicor(exe, deck, "--output", work / deck.stem, "--quiet")
        said = [w for w in warnings_of(proc.stdout) if "bonded coupled disks have turned" not in w]
        check(f"beam-coupled run, E = {young} Pa: {'warned' if warned else 'no warning'} at the end, exit 0",
              proc.returncode == 0 and (len(said) == 1 and said[0].startswith(lead)
                                        and "([beam] section, load" in said[0] if warned else not said),
              f"exit {proc.returncode}; " + ("\n".join(said) or proc.stderr.strip()[:300]))
    # an elastic block pressed (1e5 Pa) on a rigid wall through a glued row of disks: with
    # E = 1e2 Pa (1e8 in the wrong unit) it sinks by 7.4 cm within 2 ms, 6.7 times the 1.1 cm
    # of 10 % of its extent, and by metres later (an audit's deck: 3.2 m at 12 ms, through the
    # wall, exit 0 without a word); with 1e8 Pa by micrometres (stored every 50 steps, the end
    # among them)
    for young, warned in (("1e2", True), ("1e8", False)):
        deck = work / f"coupled_block_{young}.dat"
        deck.write_text(COUPLED_BLOCK.format(young=young))
        proc = multicor(exe, deck, "--output", work / deck.stem, "--quiet")
        said = warnings_of(proc.stdout)
        check(f"continuum-coupled run, E = {young} Pa: {'warned' if warned else 'no warning'} at the end, exit 0",
              proc.returncode == 0 and (len(said) == 1 and said[0].startswith(lead)
                                        and "([continuum] material, load" in said[0] if warned else not said),
              f"exit {proc.returncode}; " + ("\n".join(said) or proc.stderr.strip()[:300]))


def free_rolling(exe, work):
    """Coupled disks glued by their centres only (rotation = off, the default) in a contact
    with friction and no rolling resistance roll instead of transmitting their friction (an
    audit's block on a rigid wall through a glued row, mu = 0.3: T/N = 0.0000 with off, 0.3000
    with on): warned at the rotation line (at the thickness line when rotation is not
    written), in a continuum coupling and a beam coupling; not with rotation = on, mu = 0, or
    a rolling resistance."""
    block = COUPLED_BLOCK.format(young="1e8")
    beam = COUPLED_BEAM.format(young="2.1e11").replace("law = 1 1 0 0 1e8", "law = 1 1 0.3 0 1e8")
    cases = (("block_off", block.replace("rotation = on", "rotation = off"), "rotation", True),
             ("block_default", block.replace("rotation = on\n", ""), "thickness", True),
             ("block_on", block, None, False),
             ("block_mu0", block.replace("rotation = on", "rotation = off").replace("law = 1 1 0.3 0 0",
                                                                                     "law = 1 1 0 0 0"), None, False),
             ("block_rolling", block.replace("rotation = on", "rotation = off").replace(
                 "law = 1 1 0.3 0 0", "law = 1 1 0.3 0 0 0.001"), None, False),
             ("beam_default", beam.replace("rotation = on\n", ""), "thickness", True))
    for name, text, at, warned in cases:
        deck = work / f"rolling_{name}.dat"
        deck.write_text(text)
        proc = multicor(exe, "--check", deck)
        said = [w for w in warnings_of(proc.stdout) if "free to turn" in w]
        expected = (f"warning: {deck}:{line_of(text, at)}: [coupling] rotation = off (the default) leaves the "
                    "coupled disks free to turn: in a contact with friction and no rolling resistance (the law "
                    "of materials 1 and 1, mu = 0.3)" if warned else "")
        check(f"coupled disks free to turn ({name}): {'warned' if warned else 'no warning'}, exit 0",
              proc.returncode == 0 and (len(said) == 1 and said[0].startswith(expected) if warned else not said),
              f"exit {proc.returncode}; " + ("\n".join(said) or proc.stderr.strip()[:300]))


COUPLED_BEAM = """[run]
analysis = dynamic
[beam]
section = 1 {young} 7800 1.0e-4 8.333333333333333e-10
line = 1 0 0 0.2 0 20 1
fix = 1 all
gravity = 0 -9.81
[particles]
material = 1 7800
row = 5 0.155 0 0.005 1
gravity = 0 -9.81
[contacts]
law = 1 1 0 0 1e8
bond = 1 1 1.0
[coupling]
overlap = 0.15 0.2
thickness = 0.01
rotation = on
[time]
step = 1e-4
end = 0.1
[output]
interval = 100
"""
COUPLED_BLOCK = """[run]
analysis = dynamic
[continuum]
mesh = rectangle 0 0 0.1 0.05 20 10 q4
material = {young} 0.3 1000 0.01 plane_strain
traction = top 0 -1e5 uniform 1
rayleigh = 0 1e-4
[particles]
material = 1 1000
row = 20 0.0025 0.0025 0.0025 1
[walls]
wall = -0.05 0 0.2 0
[contacts]
law = 1 1 0.3 0 0
[coupling]
region = box 0 0.1 0 0.005 top bottom
alpha_min = 0.05
thickness = 0.01
rotation = on
[functions]
function = 1 ramp 1e-3
[time]
step = 2e-5
end = 2e-3
[output]
interval = 50
"""


BOND_DECK = """[run]
analysis = dynamic
[particles]
material = 1 2500
{disks}
gravity = 0 -9.81
{walls}
[contacts]
law = 1 1 0.3 0 1e5
bond = 1 1 0.5
[time]
step = 1e-4
end = 2e-3
"""
DEPOSIT_WALLS = "[walls]\nwall = 0 0 0.05 0\nwall = 0 0 0 0.2\nwall = 0.05 0 0.05 0.2"


def bonds_without_pairs(exe, work):
    """A bond record whose materials have no pair touching at t = 0 makes no bond: warned about
    at its line. A row of 5 touching disks (R = 10 mm) is bonded: no warning, 4 bonds."""
    cases = (("deposit", "deposit = 50 0 0.05 0.002 1e-3 2e-3 1 7", DEPOSIT_WALLS, None),
             # gap 1e-5 m = 1e-3 R, beyond the bond's 1e-6 R
             ("row_gap", "row = 5 0.01 0.1 0.01 1 1e-5", "", 0),
             ("row_touching", "row = 5 0.01 0.1 0.01 1", "", 4))
    for name, disks, walls, bonds in cases:
        text = BOND_DECK.format(disks=disks, walls=walls)
        deck = work / f"bond_{name}.dat"
        deck.write_text(text)
        warned = bonds != 4
        expected = (f"warning: {deck}:{line_of(text, 'bond')}: [contacts] bond between materials 1 and 1 makes "
                    "no bond: no two bodies of material 1 touch at t = 0")
        proc = multicor(exe, "--check", deck)
        said = warnings_of(proc.stdout)
        check(f"bond record, {name}: --check {'warns at its line' if warned else 'says nothing'}",
              proc.returncode == 0 and (len(said) == 1 and said[0].startswith(expected) if warned else not said),
              "\n".join(said) or proc.stderr.strip()[:300])
        if bonds is None:
            continue
        proc = multicor(exe, deck, "--output", work / f"bond_{name}")
        said = warnings_of(proc.stdout)
        check(f"bond record, {name}: the run {'warns' if warned else 'does not warn'} at its start and "
              f"counts {bonds} bonds at t = 0",
              proc.returncode == 0 and (len(said) == 1 and said[0].startswith(expected) if warned else not said)
              and f"bonds at t = 0: {bonds} (0 ruptures since" in proc.stdout,
              proc.stdout[-600:] + proc.stderr.strip()[:300])


def swept_bonds(exe, src, work):
    """Bonds swept one contact at a time (`method = nlgs` or `coarse` with `[contacts] bond`)
    are warned about at the method's line, naming the bond record's line, for particles alone
    (a row of 5 bonded disks) and coupled to a beam (input/bending_case1.dat), at a tolerance
    above 1e-8; `method = block` written out, or left to its default, is not; `nlgs` without
    bond records, or at 1e-8, is not."""
    row = BOND_DECK.format(disks="row = 5 0.01 0.1 0.01 1", walls="")
    case1 = (src / "input" / "bending_case1.dat").read_text()
    # (its own tolerance, 1e-8, is one at which sweeping the bonds is right: left to the default)
    case1 = re.sub(r"^\s*(method|tolerance)\s*=.*\n", "", case1, flags=re.M)
    no_bond = re.sub(r"^bond\s*=.*\n", "", row, flags=re.M)
    cases = (("row_nlgs", row, "method = nlgs\n", True), ("row_coarse", row, "method = coarse\n", True),
             ("row_block", row, "method = block\n", False), ("row_default", row, "", False),
             ("case1_nlgs", case1, "method = nlgs\n", True), ("case1_default", case1, "", False),
             ("no_bond_nlgs", no_bond, "method = nlgs\n", False),
             # at 1e-8 the audit's swept row broke where the closed form says: no warning
             ("row_nlgs_1e-6", row, "method = nlgs\ntolerance = 1e-6\n", True),
             ("row_nlgs_1e-8", row, "method = nlgs\ntolerance = 1e-8\n", False))
    for name, base, lines, warned in cases:
        text = with_solver(base, lines) if lines else base
        deck = work / f"swept_{name}.dat"
        deck.write_text(text)
        proc = multicor(exe, "--check", deck)
        said = [w for w in warnings_of(proc.stdout) if "sweeps the bonds" in w]
        if warned:
            method = re.search(r"method = (\w+)", lines).group(1)
            expected = (f"warning: {deck}:{line_of(text, 'method')}: [solver] method = {method} sweeps the bonds "
                        f"of [contacts] bond (line {line_of(text, 'bond')}) one contact at a time")
            ok = proc.returncode == 0 and len(said) == 1 and said[0].startswith(expected) \
                and said[0].endswith("method = block (the default) solves the intact bonds directly")
        else:
            ok = proc.returncode == 0 and not said
        check(f"bonds swept, {name}: {'warned at the method line' if warned else 'no warning'}", ok,
              "\n".join(said) or proc.stderr.strip()[:300])


LAWLESS = """[run]
analysis = dynamic
[particles]
material = 1 2500
material = 2 7800
material = 3 2500
material = 4 7800
{disks}
gravity = 0 -9.81
[walls]
{walls}
[contacts]
{laws}
[time]
step = 1e-4
end = 2e-3
"""


def missing_laws(exe, work):
    """In a deck with laws, walls of a material without a law with any disk material (a floor
    of material 2 under disks of material 1), or disks of a material without one with any wall
    material while other disks have one, are warned about at the first law's line, once per
    material, with the law to add. Not: pairs that are only one of several (the two inclines
    of input/incline.dat, materials 3 and 4, each with its own disk: laws 1-3 and 2-4), laws
    between disks, a deck without any law."""
    one = "disk = 0 0.05 0.05 1"
    two = "disk = 0 0.05 0.05 1\ndisk = 0.5 0.05 0.05 1"
    mixed = "disk = 0 0.05 0.05 1\ndisk = 0.5 0.05 0.05 2"
    floor = "wall = -1 0 1 0 2"
    inclines = "wall = -0.8 0.6 0.8 -0.6 3\nwall = -0.8 -0.4 0.8 -1.6 4"
    cases = (("floor", one, floor, "law = 1 1 0.3 0 0",
              ["the walls of material 2 have no law with the disks of material 1", "1 2"]),
             ("floor_and_pair", two, floor, "law = 2 2 0.3 0 0",
              ["the walls of material 2 have no law with the disks of material 1", "1 2"]),
             ("all_given", two, floor, "law = 1 2 0 0 0", []),
             ("two_materials", mixed, floor, "law = 1 2 0.3 0 0\nlaw = 2 2 0.3 0 0", []),
             ("inclines", "disk = 0.03 0.04 0.05 1\ndisk = 0.03 -0.96 0.05 2", inclines,
              "law = 1 3 0.5 0 0\nlaw = 2 4 0.1 0 0", []),
             ("disks_without", mixed, "wall = -1 0 1 0 3", "law = 1 3 0.5 0 0",
              ["the disks of material 2 have no law with the walls of material 3", "2 3"]),
             ("no_law_at_all", one, floor, "", []))
    for name, disks, walls, laws, warned in cases:
        text = LAWLESS.format(disks=disks, walls=walls, laws=laws)
        if not laws:  # (an empty section is an error)
            text = text.replace("[contacts]\n\n", "")
        deck = work / f"lawless_{name}.dat"
        deck.write_text(text)
        proc = multicor(exe, "--check", deck)
        said = [w for w in warnings_of(proc.stdout) if "have no law with the" in w]
        expected = [f"warning: {deck}:{line_of(text, 'law')}: [contacts] {warned[0]}: their contacts are "
                    "frictionless, without restitution or cohesion (the default); add law = "
                    f"{warned[1]} 0 0 0 if that is meant"] if warned else []
        check(f"materials without a law, {name}: {len(expected)} warning(s)", proc.returncode == 0 and said == expected,
              "\n".join(said) or proc.stderr.strip()[:300])

def zero_alert(exe, src, work):
    """`[contacts] alert = 0` is accepted and warned about at its line; the deposit's own
    alert (1 mm) is not."""
    base = (src / "input" / "deposit.dat").read_text()
    text = re.sub(r"^alert\s*=.*$", "alert = 0", base, count=1, flags=re.M)
    deck = work / "alert_zero.dat"
    deck.write_text(text)
    proc = multicor(exe, "--check", deck)
    said = warnings_of(proc.stdout)
    expected = (f"warning: {deck}:{line_of(text, 'alert')}: [contacts] alert = 0: a contact is seen only once "
                "its disks touch or overlap")
    check("alert = 0: warned about at its line", proc.returncode == 0 and len(said) == 1
          and said[0].startswith(expected), "\n".join(said) or proc.stderr.strip()[:300])


def idle_functions(exe, src, work):
    """input/cantilever.dat with its step moved to t0 = 1.0 s, after the end (0.5 s): the tip
    load is never applied; warned about at the function's line, naming the load's line. A
    second load under a ramp (acting) adds no warning; --end 2 (the step inside the run) and a
    table pulse inside the run give none."""
    base = (src / "input" / "cantilever.dat").read_text()
    late = base.replace("function = 1 step 0.0", "function = 1 step 1.0\nfunction = 2 ramp 0.1")
    late = re.sub(r"^(load\s*=.*)$", r"\1\nload = 11 w -1.0 2", late, count=1, flags=re.M)
    deck = work / "cantilever_late.dat"
    deck.write_text(late)
    expected = (f"warning: {deck}:{line_of(late, 'function')}: time function 1 is zero at every time of the "
                f"run, from t = 0 to its end at 5.000E-001 s: nothing it multiplies ([beam] load on line "
                f"{line_of(late, 'load')}) is applied before the end")
    proc = multicor(exe, "--check", deck)
    said = warnings_of(proc.stdout)
    check("time function zero over the run: --check warns once, at its line, naming the load",
          proc.returncode == 0 and len(said) == 1 and said[0].startswith(expected),
          "\n".join(said) or proc.stderr.strip()[:300])
    proc = multicor(exe, "--check", deck, "--end", "2")
    check("time function zero over the run: no warning when --end 2 takes the run past the step",
          proc.returncode == 0 and not warnings_of(proc.stdout), "\n".join(warnings_of(proc.stdout)))
    # the run's start (10 steps: --end 2e-3), where the interval is [0, 2 ms]
    proc = multicor(exe, deck, "--output", work / "cantilever_late", "--end", "2e-3")
    said = warnings_of(proc.stdout)
    check("time function zero over the run: the run warns at its start",
          proc.returncode == 0 and len(said) == 1
          and said[0].startswith(expected.replace("5.000E-001", "2.000E-003")),
          "\n".join(said) or proc.stderr.strip()[:300])
    pulse = base.replace("function = 1 step 0.0", "function = 1 table 0 0 0.1 1 0.2 0 1 0")
    deck = work / "cantilever_pulse.dat"
    deck.write_text(pulse)
    proc = multicor(exe, "--check", deck)
    check("time function non-zero only inside the run (a table pulse): no warning",
          proc.returncode == 0 and not warnings_of(proc.stdout), "\n".join(warnings_of(proc.stdout)))


def main():
    exe, work, src = arguments(fresh=True)
    example_decks_are_quiet(exe, src)
    analysis_without_time(exe, work)
    continuum_static_ramp(exe, work)
    solver_values(exe, src, work)
    rolling_length(exe, src, work)
    coupling_thickness(exe, src, work)
    beam_coupling_thickness(exe, src, work)
    coupled_disks_off_the_beam(exe, src, work)
    large_displacements(exe, src, work)
    free_rolling(exe, work)
    bonds_without_pairs(exe, work)
    swept_bonds(exe, src, work)
    missing_laws(exe, work)
    zero_alert(exe, src, work)
    idle_functions(exe, src, work)
    # the hinged row of the reference work (20 steps; with nlgs at 1e-4: 108 to 172 sweeps per
    # step; 17 touching cohesive disks: 16 bonds) and the interface experiment (10 steps: 19 to
    # 47 sweeps per step; no cohesion)
    coupled(exe, work, "beam", src / "input" / "bending_hinged_row.dat", "2e-4", 16, "tolerance = 1e-4\n")
    coupled(exe, work, "continuum", src / "input" / "interface_shear.dat", "2e-4", None)
    return summary()


if __name__ == "__main__":
    sys.exit(main())
