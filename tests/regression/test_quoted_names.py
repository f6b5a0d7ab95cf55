#!/usr/bin/env python3
"""Names in double quotes, end to end: a static continuum on a Gmsh mesh whose path and
physical group names hold blanks and '#' (doc/input.md, "Syntax").

The mesh, written by the real gmsh, sits in "run dir/My Meshes/bar #1.msh"; the deck in
"run dir" names it relative to its own folder (`mesh = file "My Meshes/bar #1.msh"`) and is
run from another folder. Its physical groups are "steel bar" (the surface), "left edge",
"loaded  end #2" (two blanks and a '#') and "lower left corner". Checked:
- `multicor --check` accepts the deck, and the run gives the closed form of a bar in uniaxial
  tension, plane stress: u_x(L) = F L / (E A) with F = sigma H t and A = H t, and the whole
  field u = (sigma x / E, -nu sigma y / E);
- the results keep the names: /continuum/sets/{nodes,edges,elements}/<name> with the blanks
  and the '#', the deck text with the quoted path, the title with its quotes (free text);
  the XDMF file is well-formed XML whose data items all name datasets of the results file;
- errors: `--check` and the run refuse an unterminated quote with the same message (file,
  line, keyword, column); a message echoing a name bare shows it quoted (a conflicting
  prescription on "left edge"); an unknown quoted set is named whole.

Usage (ctest does this): test_quoted_names.py --exe multicor --work DIR --source REPO
"""
import shutil
import subprocess
import xml.etree.ElementTree as ET

import h5py
import numpy as np

from checks import arguments, check, summary

L, H, NX, NY = 2.0, 0.2, 20, 2
E, NU, T, SIGMA = 2.0e11, 0.3, 0.01, 5.0e7

GEO = f"""// A bar [0, {L}] x [0, {H}] in {NX} x {NY} quadrangles, names with blanks and '#'.
Point(1) = {{0, 0, 0}};
Point(2) = {{{L}, 0, 0}};
Point(3) = {{{L}, {H}, 0}};
Point(4) = {{0, {H}, 0}};
Line(1) = {{1, 2}};
Line(2) = {{2, 3}};
Line(3) = {{3, 4}};
Line(4) = {{4, 1}};
Curve Loop(1) = {{1, 2, 3, 4}};
Plane Surface(1) = {{1}};
Transfinite Curve{{1, 3}} = {NX + 1};
Transfinite Curve{{2, 4}} = {NY + 1};
Transfinite Surface{{1}};
Recombine Surface{{1}};
Physical Surface("steel bar") = {{1}};
Physical Curve("left edge") = {{4}};
Physical Curve("loaded  end #2") = {{2}};
Physical Point("lower left corner") = {{1}};
"""

DECK = f"""[run]
title = bar "in tension" # the title is free text: its quotes stay
analysis = static
[continuum]
mesh = file "My Meshes/bar #1.msh"   # relative to this deck's folder
material = {E} {NU} 7800 {T} plane_stress "steel bar"
fix = "left edge" x
fix = "lower left corner" y
traction = "loaded  end #2" {SIGMA} 0
"""


def multicor(exe, args, cwd):
    return subprocess.run([str(exe)] + [str(a) for a in args], capture_output=True, text=True,
                          cwd=cwd, timeout=300)


def main():
    exe, work, _ = arguments(fresh=True)
    gmsh = shutil.which("gmsh")
    if gmsh is None:
        check("gmsh available", False, "gmsh not found (Debian package gmsh)")
        return summary()
    folder = work / "run dir"
    meshes = folder / "My Meshes"
    meshes.mkdir(parents=True)
    (meshes / "bar.geo").write_text(GEO)
    subprocess.run([gmsh, "-2", "-format", "msh41", str(meshes / "bar.geo"), "-o", str(meshes / "bar #1.msh")],
                   check=True, capture_output=True)
    deck = folder / "bar.dat"
    deck.write_text(DECK)
    elsewhere = work / "elsewhere"
    elsewhere.mkdir()

    # --check and the run from another folder: the mesh path is relative to the deck's folder
    proc = multicor(exe, ["--check", deck], elsewhere)
    check("--check accepts the quoted path and names", proc.returncode == 0, (proc.stdout + proc.stderr).strip())
    out = folder / "results"
    proc = multicor(exe, [deck, "--output", out, "--quiet"], elsewhere)
    if not check("the run ends (exit 0)", proc.returncode == 0, proc.stderr.strip()[:400]):
        return summary()

    with h5py.File(out / "bar.h5", "r") as f:
        x = f["continuum/mesh/coordinates"][...]
        u = f["continuum/static/displacement"][...]
        sets = {kind: sorted(f[f"continuum/sets/{kind}"].keys()) for kind in ("nodes", "edges", "elements")}
        left = f["continuum/sets/nodes/left edge"][...]
        deck_text = f.attrs["deck_text"]
        title = f.attrs["title"]
        datasets = set()
        f.visititems(lambda name, obj: datasets.add("/" + name) if isinstance(obj, h5py.Dataset) else None)
    deck_text = deck_text.decode() if isinstance(deck_text, bytes) else str(deck_text)
    title = title.decode() if isinstance(title, bytes) else str(title)
    if x.shape[0] != 2:
        x, u = x.T, u.T
    # Uniaxial tension: F L / (E A) at x = L. The uniform stress field lies in the span of the
    # Q4 element, so the FE solution is exact up to the rounding of the assembly and the
    # solve: about 1e-13 relative for this stiffness matrix (condition number ~1e4); 1e-9 of
    # the end displacement leaves room for any solver ordering and still catches a lost or
    # misplaced traction (which would be off by 1/NY of the load at least).
    force, area = SIGMA * H * T, H * T
    u_end = force * L / (E * area)
    at_end = np.isclose(x[0], L)
    check("u_x at x = L is F L / (E A)", np.max(np.abs(u[0, at_end] / u_end - 1)) < 1e-9,
          f"{u[0, at_end].min():.6e} .. {u[0, at_end].max():.6e} m, F L / (E A) = {u_end:.6e} m")
    exact = np.vstack([SIGMA / E * x[0], -NU * SIGMA / E * x[1]])
    check("displacement field (sigma x / E, -nu sigma y / E)", np.max(np.abs(u - exact)) < 1e-9 * u_end,
          f"largest error {np.max(np.abs(u - exact)):.1e} m")
    check("'left edge' holds the NY + 1 nodes at x = 0", len(left) == NY + 1 and np.allclose(x[0, left - 1], 0),
          f"{len(left)} nodes")
    check("node sets named as in the mesh, blanks and '#' kept",
          {"steel bar", "left edge", "loaded  end #2", "lower left corner"} <= set(sets["nodes"]), str(sets["nodes"]))
    check("edge and element sets", sets["edges"] == ["left edge", "loaded  end #2"]
          and "steel bar" in sets["elements"], str(sets))
    check("the stored deck keeps the quoted path", 'mesh = file "My Meshes/bar #1.msh"' in deck_text,
          deck_text.splitlines()[4] if len(deck_text.splitlines()) > 4 else deck_text)
    check("the title is free text, its quotes kept, cut at '#'", title == 'bar "in tension"', repr(title))

    xdmf = out / "bar.xdmf"
    try:
        items = [i.text.strip() for i in ET.parse(xdmf).getroot().iter("DataItem") if i.get("Format") == "HDF"]
        refs = [item.split(":", 1) for item in items]
        ok = bool(refs) and all(r[0] == "./bar.h5" and r[1] in datasets for r in refs)
        check("the XDMF file is XML and names datasets of bar.h5", ok, f"{len(refs)} data items")
    except ET.ParseError as e:
        check("the XDMF file is XML and names datasets of bar.h5", False, str(e))

    # The same refusal from --check and from a run: file, line, keyword and column.
    bad = folder / "open quote.dat"
    bad.write_text(DECK.replace('fix = "left edge" x', 'fix = "left edge x   # clamped'))
    expected = ("open quote.dat:7: keyword 'fix': unterminated quote: the double quote at column 7 has no "
                "closing one on its line")
    for args in (["--check", bad], [bad, "--output", work / "open_quote", "--quiet"]):
        proc = multicor(exe, args, elsewhere)
        check(f"{args[0] if args[0] == '--check' else 'run'}: an unterminated quote is refused",
              proc.returncode == 1 and expected in proc.stderr, proc.stderr.strip())

    # A name echoed bare in a message is shown quoted; a name unknown to the mesh whole.
    conflict = folder / "conflict.dat"
    conflict.write_text(DECK + 'displacement = "left edge" x 1e-6\n')
    proc = multicor(exe, ["--check", conflict], elsewhere)
    check("a conflicting prescription names the set quoted", proc.returncode == 1
          and 'of set "left edge", component x, is already prescribed by line 7' in proc.stderr, proc.stderr.strip())
    unknown = folder / "unknown.dat"
    unknown.write_text(DECK.replace('fix = "lower left corner" y', 'fix = "lower left" y'))
    proc = multicor(exe, ["--check", unknown], elsewhere)
    check("an unknown quoted set is named whole", proc.returncode == 1
          and "no node set named 'lower left' (known: 'lower left corner', 'loaded  end #2'" in proc.stderr,
          proc.stderr.strip())
    return summary()


if __name__ == "__main__":
    raise SystemExit(main())
