#!/usr/bin/env python3
"""The XDMF file next to the results file of every kind of run, read as ParaView reads it.

Short decks written here (a column of disks falling on a floor; a 4-element cantilever in
static, dynamic and modal analysis; a 4 x 2 Q4 plate, static, whose cells' point ids must be
its 1-based connectivity less 1) and the reference experiment input/bending_case1.dat cut
to 2 ms (beam-particle coupled). For each, ParaView's pvpython (the 'XDMF Reader') opens
`<deck>.xdmf` and the values it reads must equal the HDF5 datasets, bit for bit (the XDMF
file only points into the HDF5 file: no value is copied or converted): the number of stored
states (modes), the number of points, and the positions / displacements of the last state.
For the dynamic beam, ParaView's Warp By Vector on "displacement" must give the deformed
nodes. A restart that continues the dynamic beam to a later end rewrites the XDMF file with
every state of the continued file; a later run in that folder stopped by SIGTERM leaves the
XDMF file and the finished HDF5 file as they were (no XDMF file for the partial file, none
claiming the stopped run's states). Without pvpython the XDMF file is read by a small
interpreter of its hyperslab references here (meshio does not read XDMF hyperslabs).
Usage (ctest does this): test_xdmf_runs.py --exe multicor --work DIR --source REPO
"""
import hashlib
import re
import shutil
import signal
import subprocess
import sys
import xml.etree.ElementTree as ET

import h5py
import numpy as np

from checks import arguments, check, multicor, summary
from paraview_read import read_paraview

DISKS = """# A column of 5 disks dropped onto a floor between two side walls.
[run]
title = XDMF test: falling column
analysis = dynamic
[particles]
material = 1 1000
row = 5 0 0.3 0.125 1 0 90
gravity = 0 -9.81
[walls]
wall = -1 0 1 0
wall = -0.2 0 -0.2 2
wall = 0.2 2 0.2 0
[contacts]
law = 1 1 0.3 0 0
alert = 0.01
[time]
step = 1e-3
end = 0.03
[output]
interval = 10
"""

BEAM = """# A 1 m steel cantilever in 4 elements, tip load -10 N.
[run]
title = XDMF test: cantilever
analysis = {analysis}
[beam]
section  = 1   2.1e11   7800   2.0e-4   1.6666666666666667e-9
line     = 1   0.0 0.0  1.0 0.0  4  1
fix      = 1 all
load     = 5   w  -10.0  {function}
{extra}"""

DYNAMIC = """[functions]
function = 1 step 0.0
[time]
step = 1e-3
end = {end}
[output]
interval = 2
"""

CONTINUUM = """# A 2 m x 1 m plate of 4 x 2 Q4, clamped on the left, pulled on the right.
[run]
title = XDMF test: continuum plate
analysis = static
[continuum]
mesh = rectangle 0 0 2 1 4 2 q4
material = 70e9 0.3 2700 0.1 plane_stress
fix = left x y
traction = right 1e5 0
"""


def item_values(item, folder):
    """The values of an XDMF DataItem (an HDF5 dataset or a hyperslab of one), by h5py."""
    if item.get("ItemType") == "HyperSlab":
        sel, ref = list(item)
        rank = len(ref.get("Dimensions").split())
        start, stride, count = np.array(sel.text.split(), int).reshape(3, rank)
        data = item_values(ref, folder)
        index = tuple(slice(a, a + s * c, s) for a, s, c in zip(start, stride, count))
        return data[index].reshape([int(n) for n in item.get("Dimensions").split()])
    name, dataset = item.text.strip().split(":", 1)
    with h5py.File(folder / name, "r") as f:
        return f[dataset][...].reshape([int(n) for n in item.get("Dimensions").split()])


def read_xml(paths, work):
    """What an XDMF 2 reader gets at the last time, without ParaView: each part's last grid
    (the grid itself for a static file), its points (z = 0 added) and point data."""
    rows = {}
    for path in paths:
        domain = ET.parse(path).getroot().find("Domain")
        out = {"blocks": {}}
        for part in domain.findall("Grid"):
            grids = part.findall("Grid") if part.get("GridType") == "Collection" else [part]
            out["times"] = len(grids)
            g = grids[-1]
            xy = item_values(g.find("Geometry/DataItem"), path.parent).reshape(-1, 2)
            points = np.column_stack([xy, np.zeros(len(xy))])
            data = {}
            for a in g.findall("Attribute"):
                v = item_values(a.find("DataItem"), path.parent)
                if a.get("AttributeType") == "Vector" and v.shape[-1] == 2:
                    v = np.column_stack([v.reshape(-1, 2), np.zeros(v.size // 2)])
                data[a.get("Name")] = v.tolist()
            name = part.get("Name") if len(domain.findall("Grid")) > 1 else ""
            topo = g.find("Topology")
            cells = int(topo.get("NumberOfElements"))
            # The 0-based point ids of each cell, as an XDMF reader takes them from the
            # Topology's DataItem and BaseOffset (one kind of cell: n_elements rows).
            item = topo.find("DataItem")
            cell_points = None
            if item is not None:
                ids = item_values(item, path.parent).reshape(cells, -1) - int(topo.get("BaseOffset", "0"))
                cell_points = ids.tolist()
            out["blocks"][name] = {"points": points.tolist(), "cells": cells, "data": data, "cell_points": cell_points}
        if "displacement" in out["blocks"].get("", {}).get("data", {}):
            b = out["blocks"][""]
            out["warped"] = (np.array(b["points"]) + np.array(b["data"]["displacement"])).tolist()
        rows[str(path)] = out
    print("skip   ParaView: no pvpython; the XDMF files are read by the interpreter of this script")
    return rows


def xyz(a):
    """(n, 2) or (n, 3) columns x, y as points with z = 0."""
    a = np.asarray(a)
    return np.column_stack([a[:, 0], a[:, 1], np.zeros(len(a))])


def same(name, got, want):
    """Exact equality: ParaView reads the very doubles of the HDF5 file."""
    got, want = np.asarray(got, float), np.asarray(want, float)
    ok = got.shape == want.shape and np.array_equal(got, want)
    err = np.abs(got - want).max() if got.shape == want.shape else f"shape {got.shape} vs {want.shape}"
    return check(name, ok, f"{want.shape}, largest difference {err}")


def interrupted(exe, work, folder):
    """A run of the same deck to a far end, stopped by SIGTERM in `folder`: the finished
    result and its XDMF file stay as they were."""
    h5, xdmf = folder / "xdmf_beam_dynamic.h5", folder / "xdmf_beam_dynamic.xdmf"
    before = {p: hashlib.sha256(p.read_bytes()).hexdigest() for p in (h5, xdmf) if p.exists()}
    long_deck = work / "long" / "xdmf_beam_dynamic.dat"
    long_deck.parent.mkdir(exist_ok=True)
    long_deck.write_text(BEAM.format(analysis="dynamic", function="1",
                                     extra=DYNAMIC.format(end="1000.0") + "progress = 0.02\n"))
    proc = subprocess.Popen([str(exe), str(long_deck), "--output", str(folder)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    started = False
    for line in proc.stdout:
        m = re.match(r"step (\d+)/", line)
        if m and int(m.group(1)) >= 100:
            started = True
            break
    proc.send_signal(signal.SIGTERM)
    try:
        proc.communicate(timeout=120)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.communicate()
    check("stopped run: exit 143 after a few outputs", started and proc.returncode == 128 + signal.SIGTERM,
          f"exit {proc.returncode}")
    after = {p: hashlib.sha256(p.read_bytes()).hexdigest() for p in (h5, xdmf) if p.exists()}
    check("stopped run: the finished result and its XDMF file are left as they were", len(before) == 2
          and after == before, ", ".join(p.name for p in before if after.get(p) != before[p]))
    check("stopped run: no XDMF file for the partial file", not list(folder.glob("*.xdmf.partial")) and
          (folder / "xdmf_beam_dynamic.h5.partial").exists(), sorted(p.name for p in folder.iterdir()))


def main():
    exe, work, src = arguments(fresh=True)
    decks = {
        "xdmf_disks": DISKS,
        "xdmf_beam_static": BEAM.format(analysis="static", function="", extra=""),
        "xdmf_beam_dynamic": BEAM.format(analysis="dynamic", function="1", extra=DYNAMIC.format(end="0.01")),
        "xdmf_beam_modal": BEAM.format(analysis="modal", function="", extra="[modal]\nmodes = 3\n"),
        "xdmf_continuum": CONTINUUM,
        # XML's markup characters in the deck's name, hence in the HDF5 file's name that the
        # XDMF file quotes: they must be written as entities (else the XML ends there)
        "xdmf_a&b<c>": BEAM.format(analysis="static", function="", extra=""),
        # A name that starts with a non-ASCII letter or a blank: ParaView's XDMF 2 reader strips
        # the leading bytes <= ' ' (signed char) of a reference, the UTF-8 bytes of 'ñ' with them,
        # unless the reference starts with './'
        "ñxdmf": BEAM.format(analysis="static", function="", extra=""),
        " xdmf_lead": BEAM.format(analysis="static", function="", extra=""),
    }
    h5 = {}
    for name, text in decks.items():
        deck = work / f"{name}.dat"
        deck.write_text(text)
        h5[name] = multicor(exe, deck, work)[0]
    # A colon in the name: ParaView's XDMF 2 reader splits 'file.h5:/dataset' at the first one
    # and crashes; the run warns (and still writes both files).
    deck = work / "xdmf_t:1.dat"
    deck.write_text(BEAM.format(analysis="static", function="", extra=""))
    h5_colon, proc = multicor(exe, deck, work)
    check("a colon in the deck name: warned", "contains a colon, which ParaView's XDMF reader cannot open"
          in proc.stdout + proc.stderr and h5_colon.with_suffix(".xdmf").exists(), (proc.stdout + proc.stderr)[-300:])
    # Beam-particle coupled: the reference experiment, 2 ms of it.
    out = work / "bending_case1"
    proc = subprocess.run([str(exe), str(src / "input" / "bending_case1.dat"), "--output", str(out), "--quiet",
                           "--end", "0.002"], capture_output=True, text=True)
    check("bending_case1 to 2 ms runs", proc.returncode == 0, proc.stderr[-300:])
    h5["coupled"] = out / "bending_case1.h5"
    # A restart that continues the dynamic beam: its XDMF file holds the continued states.
    cont = work / "xdmf_beam_continued"
    deck = work / "xdmf_beam_dynamic.dat"
    first = subprocess.run([str(exe), str(deck), "--output", str(cont), "--quiet", "--end", "0.006"],
                           capture_output=True, text=True)
    again = subprocess.run([str(exe), str(deck), "--output", str(cont), "--quiet", "--restart",
                            str(cont / "checkpoint.h5")], capture_output=True, text=True)
    check("dynamic beam to 6 ms, continued to 10 ms", first.returncode == 0 and again.returncode == 0,
          (first.stderr + again.stderr)[-300:])
    h5["continued"] = cont / "xdmf_beam_dynamic.h5"
    interrupted(exe, work, cont)
    xdmf = {k: v.with_suffix(".xdmf") for k, v in h5.items()}
    check("an XDMF file next to every results file", all(p.exists() for p in xdmf.values()),
          ", ".join(p.name for p in xdmf.values() if not p.exists()) or "all")
    check("no temporary XDMF file left", not list(work.rglob("*.xdmf.partial")), "")
    paths = list(xdmf.values())
    rows = read_paraview(paths, work) if shutil.which("pvpython") else read_xml(paths, work)
    if rows is None:
        return summary()
    r = {k: rows[str(p)] for k, p in xdmf.items()}

    with h5py.File(h5["xdmf_disks"], "r") as f:
        t, pos, vel, rad = f["dem/time"][...], f["dem/position"][-1], f["dem/velocity"][-1], f["dem/particles/radius"][...]
        walls = f["dem/walls/position"][-1]
    d = r["xdmf_disks"]
    check("disks: every stored state, disks and walls", d["times"] == len(t) and set(d["blocks"]) == {"disks", "walls"},
          f"{d['times']} states vs {len(t)}, blocks {sorted(d['blocks'])}")
    # The disks moved: the last state is not the first (else the check below could not fail).
    check("disks: they fell", pos[0, 1] < 0.3 - 1e-3, f"y of disk 1: {pos[0, 1]:.6f} m")
    b = d["blocks"]["disks"]
    same("disks: centres at the last state", b["points"], xyz(pos))
    same("disks: radius", b["data"]["radius"], rad)
    same("disks: velocity at the last state", b["data"]["velocity"], xyz(vel))
    same("disks: rotation at the last state", b["data"]["rotation"], pos[:, 2])
    same("walls: end points at the last state", d["blocks"]["walls"]["points"], xyz(walls.reshape(-1, 2)))
    check("walls: one segment per wall", d["blocks"]["walls"]["cells"] == len(walls), d["blocks"]["walls"]["cells"])

    with h5py.File(h5["xdmf_beam_static"], "r") as f:
        x, u = f["fem/mesh/coordinates"][...], f["static/displacement"][...]
    s = r["xdmf_beam_static"]
    b = s["blocks"][""]
    check("beam static: one state, 5 nodes, 4 segments", s["times"] == 1 and len(b["points"]) == 5 and b["cells"] == 4,
          f"{s['times']} states, {len(b['points'])} points, {b['cells']} cells")
    same("beam static: reference coordinates", b["points"], xyz(x))
    same("beam static: displacement (u, w, 0)", b["data"]["displacement"], xyz(u))
    same("beam static: rotation", b["data"]["rotation"], u[:, 2])

    with h5py.File(h5["xdmf_a&b<c>"], "r") as f:
        u = f["static/displacement"][...]
    s = r["xdmf_a&b<c>"]
    check("a deck named with '&', '<' and '>': one state, 5 nodes", s["times"] == 1 and
          len(s["blocks"][""]["points"]) == 5, f"{s['times']} states")
    same("a deck named with '&', '<' and '>': displacement", s["blocks"][""]["data"]["displacement"], xyz(u))
    for name in ("ñxdmf", " xdmf_lead"):
        with h5py.File(h5[name], "r") as f:
            u = f["static/displacement"][...]
        s = r[name]
        check(f"a deck named '{name}.dat': one state, 5 nodes", s["times"] == 1 and
              len(s["blocks"].get("", {}).get("points", [])) == 5, f"{s['times']} states, blocks {sorted(s['blocks'])}")
        same(f"a deck named '{name}.dat': displacement", s["blocks"].get("", {}).get("data", {}).get("displacement"),
             xyz(u))

    with h5py.File(h5["xdmf_beam_dynamic"], "r") as f:
        t, x, u = f["fem/time"][...], f["fem/mesh/coordinates"][...], f["fem/displacement"][-1]
    s = r["xdmf_beam_dynamic"]
    b = s["blocks"][""]
    check("beam dynamic: every stored state", s["times"] == len(t), f"{s['times']} vs {len(t)}")
    check("beam dynamic: the tip moved", u[-1, 1] < 0, f"w(tip) = {u[-1, 1]:.3e} m")
    same("beam dynamic: displacement at the last state", b["data"]["displacement"], xyz(u))
    # Warp By Vector: x + u, computed by ParaView (one rounding, as numpy's).
    same("beam dynamic: Warp By Vector gives the deformed nodes", s["warped"], xyz(x + u[:, :2]))

    with h5py.File(h5["continued"], "r") as f:
        t, u = f["fem/time"][...], f["fem/displacement"][-1]
    s = r["continued"]
    check("restarted beam: the states of the continued file", s["times"] == len(t) == r["xdmf_beam_dynamic"]["times"],
          f"{s['times']} vs {len(t)}")
    same("restarted beam: displacement at the last state", s["blocks"][""]["data"]["displacement"], xyz(u))

    with h5py.File(h5["xdmf_beam_modal"], "r") as f:
        shapes = f["modal/shapes"][...]
    s = r["xdmf_beam_modal"]
    check("beam modal: one time step per mode", s["times"] == len(shapes), f"{s['times']} vs {len(shapes)}")
    same("beam modal: last mode shape", s["blocks"][""]["data"]["mode_shape"], xyz(shapes[-1]))

    # The cells' node ids: XDMF counts points from 0, the 1-based connectivity less 1
    # (integers, compared exactly).
    with h5py.File(h5["xdmf_continuum"], "r") as f:
        conn, topo = f["continuum/mesh/connectivity"][...], f["continuum/mesh/topology"][...]
        n_nodes = len(f["continuum/mesh/coordinates"])
    b = r["xdmf_continuum"]["blocks"][""]
    check("continuum: topology is the connectivity less 1, ids 0 to n_nodes - 1",
          topo.shape == conn.shape == (8, 4) and np.array_equal(topo, conn - 1) and topo.min() == 0
          and topo.max() == n_nodes - 1, f"topology {topo.min()}..{topo.max()}, {n_nodes} nodes")
    check("continuum: each cell's point ids as the reader reads them", b["cells"] == 8 and
          np.array_equal(np.asarray(b["cell_points"]), conn - 1), f"{b['cell_points']} vs {(conn - 1).tolist()}")

    with h5py.File(h5["coupled"], "r") as f:
        t, x = f["coupling/time"][...], f["fem/mesh/coordinates"][...]
        u, pos = f["fem/displacement"][-1], f["dem/position"][-1]
    s = r["coupled"]
    check("coupled: beam and disks, every stored state", s["times"] == len(t) and set(s["blocks"]) == {"beam", "disks"},
          f"{s['times']} states vs {len(t)}, blocks {sorted(s['blocks'])}")
    same("coupled: beam nodes", s["blocks"]["beam"]["points"], xyz(x))
    same("coupled: beam displacement at the last state", s["blocks"]["beam"]["data"]["displacement"], xyz(u))
    same("coupled: disk centres at the last state", s["blocks"]["disks"]["points"], xyz(pos))
    return summary()


if __name__ == "__main__":
    sys.exit(main())
