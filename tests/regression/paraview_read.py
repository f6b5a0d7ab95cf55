"""What ParaView reads from XDMF files: pvpython's 'XDMF Reader' at the last stored time,
every point and cell array selected, returned as plain Python values (floats go through JSON
as their shortest repr, so they compare bit for bit with the HDF5 datasets).

    rows = read_paraview(paths, work)   # {str(path): {"times": n, "blocks": {name: block},
                                        #               "warped": points (when a displacement)}}

A block is {"points": [[x, y, z], ...], "cells": n, "data": {point array: values},
"cell_data": {cell array: values}, "cell_points": [[0-based point ids of each cell], ...]}; a file with one part gives one block named "". Used by
the regression scripts that check the XDMF files (test_xdmf_runs.py, test_continuum_runs.py,
test_coupled2d_runs.py); the caller checks pvpython is installed (`shutil.which("pvpython")`).
"""
import json
import subprocess

from checks import check

READER = """import json, sys
from paraview.simple import XDMFReader, WarpByVector
from paraview import servermanager as sm
from vtk.numpy_interface import dataset_adapter as dsa
for path in sys.argv[1:]:
    r = XDMFReader(FileNames=[path])
    r.UpdatePipelineInformation()
    r.PointArrayStatus = r.GetProperty("PointArrayInfo")[::2]
    r.CellArrayStatus = r.GetProperty("CellArrayInfo")[::2]
    times = list(r.TimestepValues) if r.TimestepValues else [0.0]
    r.UpdatePipeline(times[-1])
    d = sm.Fetch(r)
    if d.IsA("vtkMultiBlockDataSet"):
        blocks = [(d.GetMetaData(b).Get(d.NAME()), d.GetBlock(b)) for b in range(d.GetNumberOfBlocks())]
    else:
        blocks = [("", d)]
    out = {"times": len(times), "blocks": {}}
    for name, g in blocks:
        w = dsa.WrapDataObject(g)
        out["blocks"][name] = {"points": w.Points.tolist(), "cells": g.GetNumberOfCells(),
                               "data": {k: w.PointData[k].tolist() for k in w.PointData.keys()},
                               "cell_data": {k: w.CellData[k].tolist() for k in w.CellData.keys()},
                               "cell_points": [[g.GetCell(c).GetPointId(k) for k in range(g.GetCell(c).GetNumberOfPoints())]
                                               for c in range(g.GetNumberOfCells())]}
    if "displacement" in out["blocks"].get("", {}).get("data", {}):
        warp = WarpByVector(Input=r, Vectors=["POINTS", "displacement"])
        warp.UpdatePipeline(times[-1])
        out["warped"] = dsa.WrapDataObject(sm.Fetch(warp)).Points.tolist()
    print("RESULT", json.dumps([path, out]))  # a path may hold blanks
"""


def read_paraview(paths, work, name="ParaView (pvpython, XDMF Reader) opens every XDMF file"):
    """{str(path): what ParaView reads at the last time} (module doc), or None after a failed
    check `name` when pvpython fails or misses a file."""
    script = work / "read_xdmf.py"
    script.write_text(READER)
    proc = subprocess.run(["pvpython", "--force-offscreen-rendering", str(script)] + [str(p) for p in paths],
                          capture_output=True, text=True, timeout=300)
    rows = {}
    for line in proc.stdout.splitlines():
        if line.startswith("RESULT "):
            path, row = json.loads(line.split(" ", 1)[1])
            rows[path] = row
    ok = proc.returncode == 0 and len(rows) == len(paths)
    check(name, ok, proc.stderr[-400:] if not ok else f"{len(rows)} files")
    return rows if ok else None
