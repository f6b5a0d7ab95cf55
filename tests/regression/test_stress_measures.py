#!/usr/bin/env python3
"""The out-of-plane stress sigma_zz and the von Mises stress a 2D continuum run stores next to
its in-plane stresses (doc/output.md, "/continuum"): /continuum/static/{stress_zz, von_mises}
(n_elements) and the series /continuum/{stress_zz, von_mises} (n_out, n_elements), in Pa.

- the shipped decks input/continuum_cantilever.dat (plane stress, and a copy in plane strain),
  input/continuum_cantilever_dynamic.dat in plane strain (50 steps) and input/interface_shear.dat
  (coupled to disks, two plane-strain materials of different nu on a Gmsh mesh; 20 steps):
  the stored sigma_zz is nu (sigma_xx + sigma_yy) with each element's nu in plane strain and
  exactly 0 in plane stress, the stored von Mises stress
  sqrt(((sxx - syy)^2 + (syy - szz)^2 + (szz - sxx)^2)/2 + 3 sxy^2), both computed here by
  numpy from the stored in-plane stresses and materials; the shapes and units those of the
  stress datasets;
- a dynamic run stopped and continued from its checkpoint stores the same values, bit for bit,
  as the run that was not stopped;
- the XDMF file exposes them as the cell arrays sigma_zz and von_mises: read by ParaView
  (pvpython, XDMF Reader) when installed, else by parsing the XDMF file and reading the
  datasets it references with h5py; the values are those of the HDF5 file bit for bit.
Usage (ctest does this): test_stress_measures.py --exe multicor --work DIR --source REPO
"""
import shutil
import subprocess
import sys

import h5py
import numpy as np

from checks import arguments, check, multicor, summary
from paraview_read import read_paraview
from test_xdmf_runs import read_xml

# Relative tolerance of the comparison with numpy: the same formula in the same order of IEEE
# double operations gives the same doubles (measured: equal bit for bit, Debug and Release,
# which has no FMA at -march=x86-64-v2). 4 ulps leave room for a compiler that contracts a
# product and a sum into one FMA: one rounding fewer in a few of the 5 roundings of
# sigma_zz or of the sum under von Mises' square root (which halves the relative error).
REL = 4 * np.finfo(float).eps


def deck_copy(src, work, name, replacements):
    """input/<name>.dat with its texts replaced (each must be there), written to work."""
    text = (src / "input" / f"{name}.dat").read_text()
    for old, new in replacements:
        if old not in text:
            raise SystemExit(f"input/{name}.dat has no '{old}': update this test")
        text = text.replace(old, new)
    path = work / f"{name}_{len(replacements)}.dat"
    path.write_text(text)
    return path


def expected(f, stress):
    """(sigma_zz, von Mises) by numpy from the stored stresses (..., n_elements, 3) and each
    element's material (/continuum/materials, /continuum/mesh/material)."""
    m = f["continuum/mesh/material"][...] - 1
    nu = f["continuum/materials/poisson"][...][m]
    strain = f["continuum/materials/plane_strain"][...][m] == 1
    sxx, syy, sxy = stress[..., 0], stress[..., 1], stress[..., 2]
    szz = np.where(strain, nu * (sxx + syy), 0.0)
    vm = np.sqrt(0.5 * ((sxx - syy) ** 2 + (syy - szz) ** 2 + (szz - sxx) ** 2) + 3 * sxy ** 2)
    return szz, vm, strain, nu


def check_file(name, h5, static):
    """The stored sigma_zz and von Mises of one results file against numpy; returns
    (sigma_zz, von Mises) as stored, those of the last state for a dynamic run."""
    group = "continuum/static/" if static else "continuum/"
    with h5py.File(h5, "r") as f:
        if not check(f"{name}: /{group}stress_zz and von_mises stored",
                     all(group + n in f for n in ("stress_zz", "von_mises")), str(sorted(f[group[:-1]]))):
            return None
        stress = f[group + "stress"][...]
        szz, vm = f[group + "stress_zz"][...], f[group + "von_mises"][...]
        units = [f[group + n].attrs.get("units") for n in ("stress", "stress_zz", "von_mises")]
        n_out = None if static else f["continuum/time"].shape[0]
        want_zz, want_vm, strain, nu = expected(f, stress)
    check(f"{name}: stress_zz and von_mises have the stress's layout (one value per element and state)",
          szz.shape == vm.shape == stress.shape[:-1] and (static or szz.shape[0] == n_out),
          f"{szz.shape}, {vm.shape}, stress {stress.shape}")
    check(f"{name}: units Pa, as the stress", units == ["Pa"] * 3, str(units))
    scale_zz = np.abs(nu) * (np.abs(stress[..., 0]) + np.abs(stress[..., 1]))
    err_zz = np.abs(szz - want_zz) / np.where(scale_zz > 0, scale_zz, 1.0)
    check(f"{name}: stress_zz = nu (sigma_xx + sigma_yy) in plane strain, 0 in plane stress",
          np.all(err_zz <= REL) and np.all(szz[..., ~strain] == 0.0),
          f"largest difference {err_zz.max():.2e} of nu (|sxx| + |syy|); {np.count_nonzero(strain)} elements in "
          f"plane strain of {strain.size}")
    err_vm = np.abs(vm - want_vm) / np.where(want_vm > 0, want_vm, 1.0)
    check(f"{name}: von_mises = sqrt(((sxx - syy)^2 + (syy - szz)^2 + (szz - sxx)^2)/2 + 3 sxy^2)",
          np.all(err_vm <= REL) and np.all(vm >= 0), f"largest relative difference {err_vm.max():.2e}")
    if strain.any():
        # not a vacuous comparison: sigma_zz of the plane-strain elements is of the order of
        # nu times the in-plane stresses (a bent cantilever: nu |sxx| at the fibres)
        big = np.abs(szz).max()
        check(f"{name}: plane strain: sigma_zz of the order of nu sigma_xx",
              big >= 0.1 * nu.min() * np.abs(stress[..., 0]).max(),
              f"max |sigma_zz| {big:.4e} Pa, max |sigma_xx| {np.abs(stress[..., 0]).max():.4e} Pa")
    return szz if static else szz[-1], vm if static else vm[-1]


def continued_run(exe, deck, work, stored):
    """The dynamic deck to 20 ms, continued from its checkpoint to 50 ms: the same series."""
    out = work / "continued"
    first = subprocess.run([str(exe), str(deck), "--output", str(out), "--quiet", "--end", "0.02"],
                           capture_output=True, text=True)
    again = subprocess.run([str(exe), str(deck), "--output", str(out), "--quiet", "--restart",
                            str(out / "checkpoint.h5")], capture_output=True, text=True)
    if not check("dynamic cantilever to 20 ms, continued to 50 ms", first.returncode == 0 and again.returncode == 0,
                 (first.stderr + again.stderr)[-300:]):
        return
    with h5py.File(stored, "r") as a, h5py.File(out / f"{deck.stem}.h5", "r") as b:
        same = all(n in a and n in b and a[n][...].tobytes() == b[n][...].tobytes() and a[n].shape == b[n].shape
                   for n in ("continuum/stress_zz", "continuum/von_mises"))
        shapes = [f["continuum/stress_zz"].shape if "continuum/stress_zz" in f else None for f in (b, a)]
    check("continued run: stress_zz and von_mises those of the uninterrupted run, bit for bit", same,
          f"{shapes[0]} vs {shapes[1]}")


def main():
    exe, work, src = arguments(fresh=True)
    files = {}
    files["static plane stress"] = (multicor(exe, src / "input" / "continuum_cantilever.dat", work)[0], True)
    files["static plane strain"] = (multicor(exe, deck_copy(src, work, "continuum_cantilever", [
        ("plane_stress", "plane_strain")]), work)[0], True)
    dynamic = deck_copy(src, work, "continuum_cantilever_dynamic", [("plane_stress", "plane_strain"),
                                                                    ("end = 0.5", "end = 0.05")])
    files["dynamic plane strain"] = (multicor(exe, dynamic, work)[0], False)
    files["coupled interface"] = (multicor(exe, deck_copy(src, work, "interface_shear", [
        ("mesh = file interface_shear.msh", f"mesh = file {src / 'input' / 'interface_shear.msh'}"),
        ("end = 10e-3", "end = 4e-4")]), work)[0], False)
    last = {name: check_file(name, h5, static) for name, (h5, static) in files.items()}
    continued_run(exe, dynamic, work, files["dynamic plane strain"][0])

    xdmf = {name: h5.with_suffix(".xdmf") for name, (h5, _) in files.items()}
    paths = list(xdmf.values())
    rows = read_paraview(paths, work) if shutil.which("pvpython") else read_xml(paths, work)
    if rows is None:
        return summary()
    for name, path in xdmf.items():
        blocks = rows[str(path)]["blocks"]
        block = blocks["continuum"] if "continuum" in blocks else blocks[""]
        # (read_xml gives every attribute under "data", ParaView the cell arrays under "cell_data")
        cells = block.get("cell_data", block["data"])
        if last[name] is None:
            continue
        szz, vm = last[name]
        got = [np.asarray(cells.get(n, []), float).ravel() for n in ("sigma_zz", "von_mises")]
        check(f"{name}: the XDMF file's cell arrays sigma_zz and von_mises are the stored values (last state)",
              all(g.shape == w.shape and np.array_equal(g, w) for g, w in zip(got, (szz, vm))),
              f"arrays {sorted(cells)}")
    return summary()


if __name__ == "__main__":
    sys.exit(main())
