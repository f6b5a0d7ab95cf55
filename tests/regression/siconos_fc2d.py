"""Siconos' side of tests/regression/test_fclib_siconos.py, run by the system Python that has
Debian's python3-siconos (4.4) and python3-h5py: the virtual environment of the tests does not
see them, as it does not see ParaView's pvpython.

    python3 siconos_fc2d.py FCLIB_FILE OUT_JSON --tolerance TOL --max-iter N

1. Reads the local problem as FCLIB's own reader does (fclib.c: fclib_read_local and
   fclib_read_solution), and lists every way the file departs from what that reader needs
   (missing datasets, sizes other than those it allocates, strings it cannot read).
2. Builds a siconos.numerics FrictionContactProblem of dimension 2 from W, q and mu.
3. Siconos' error of the stored solution r: fc2d_compute_error of libsiconos_numerics (not
   wrapped in the Python module, called through ctypes on the problem's C pointer), with the
   norm fc2d_nsgs passes it, |q|; Siconos 4.4 divides by max(norm, |r|, |W r + q|).
4. Solves the problem with fc2d NSGS (SICONOS_FRICTION_2D_NSGS) from r = 0 and writes
   Siconos' solution, its error and the counts to OUT_JSON.
"""
import argparse
import ctypes
import ctypes.util
import json
import sys

import h5py
import numpy as np
import siconos
import siconos.numerics as sn


def read_fclib_local(path):
    """(problem dict, list of departures from FCLIB's layout). The sizes are those that
    fclib.c allocates before H5LTread_dataset_int/double read a whole dataset into them."""
    bad = []
    f = h5py.File(path, "r")

    def data(name, kind, size=None):
        if name not in f or not isinstance(f[name], h5py.Dataset):
            bad.append(f"{name}: missing")
            return None
        d = f[name]
        if d.dtype.kind not in kind:
            bad.append(f"{name}: type {d.dtype}, FCLIB reads {'int' if kind == 'iu' else 'double'}")
        if size is not None and d.size != size:
            bad.append(f"{name}: {d.size} values, FCLIB's reader allocates {size}")
        return d[...].ravel()

    def scalar(name):
        v = data(name, "iu", 1)
        return int(v[0]) if v is not None and v.size == 1 else None

    dim = scalar("/fclib_local/spacedim")
    if dim not in (2, 3):
        bad.append(f"/fclib_local/spacedim = {dim}: FCLIB asserts 2 or 3")
    nzmax, m, n, nz = (scalar(f"/fclib_local/W/{k}") for k in ("nzmax", "m", "n", "nz"))
    out = {"spacedim": dim, "W": None}
    if None in (dim, nzmax, m, n, nz):
        return out, bad
    if nz == -1:        # compressed columns: p has n + 1 column pointers
        p = data("/fclib_local/W/p", "iu", n + 1)
        i = data("/fclib_local/W/i", "iu", nzmax)
    elif nz == -2:      # compressed rows
        p = data("/fclib_local/W/p", "iu", m + 1)
        i = data("/fclib_local/W/i", "iu", nzmax)
    elif nz >= 0:       # triplet: p row indices, i column indices
        p = data("/fclib_local/W/p", "iu", nz)
        i = data("/fclib_local/W/i", "iu", nz)
    else:
        bad.append(f"/fclib_local/W/nz = {nz}: FCLIB knows -1 (CSC), -2 (CSR), >= 0 (triplet)")
        return out, bad
    x = data("/fclib_local/W/x", "f", nzmax)
    if m != n or m % dim:
        bad.append(f"W is {m} x {n}: FCLIB needs a square W with rows a multiple of spacedim {dim}")
    q = data("/fclib_local/vectors/q", "f", m)
    mu = data("/fclib_local/vectors/mu", "f", m // dim)
    if any(v is None for v in (p, i, x, q, mu)) or bad:
        return out, bad
    W = np.zeros((m, n))
    if nz < 0:
        outer = n if nz == -1 else m
        if p[0] != 0 or np.any(np.diff(p) < 0) or p[-1] > nzmax:
            bad.append("W/p: pointers must start at 0, not decrease and end at most at nzmax")
            return out, bad
        if np.any(i < 0) or np.any(i >= (m if nz == -1 else n)):
            bad.append("W/i: index out of range (FCLIB, like CSparse, counts from 0)")
            return out, bad
        for c in range(outer):
            k = slice(p[c], p[c + 1])
            if np.any(np.diff(i[k]) <= 0):
                bad.append(f"W: indices of line {c} not strictly increasing (CSparse canonical form)")
            if nz == -1:
                W[i[k], c] += x[k]
            else:
                W[c, i[k]] += x[k]
    else:
        np.add.at(W, (p, i), x[:nz])
    # Optional problem information: H5LTread_dataset_string reads fixed-length strings only.
    info = {}
    if "/fclib_local/info" in f:
        for k in ("title", "description", "math_info"):
            name = f"/fclib_local/info/{k}"
            if name in f:
                d = f[name]
                if d.dtype.kind != "S" or h5py.check_string_dtype(d.dtype).length is None or d.shape != ():
                    bad.append(f"{name}: not a scalar fixed-length string (H5LTread_dataset_string)")
                else:
                    info[k] = d[()].decode("ascii", "replace").rstrip("\0")
    # The solution as fclib_read_solution reads it for a local problem: u and r, W/n values.
    sol = {}
    if "/solution" in f:
        for k in ("u", "r"):
            v = data(f"/solution/{k}", "f", n)
            if v is not None:
                sol[k] = v
    if "/guesses" in f:
        g = scalar("/guesses/number_of_guesses")
        for j in range(1, (g or 0) + 1):
            for k in ("u", "r"):
                data(f"/guesses/{j}/{k}", "f", n)
    out.update(W=W, q=q, mu=mu, info=info, solution=sol)
    return out, bad


def compute_error(lib, problem, r, norm):
    """Siconos' fc2d_compute_error(problem, r, w, tol, norm, &error); returns (error, w = W r + q)."""
    dp = ctypes.POINTER(ctypes.c_double)
    r = np.ascontiguousarray(r, dtype=np.float64).copy()
    w = np.zeros_like(r)
    err = ctypes.c_double(-1.0)
    lib.fc2d_compute_error(ctypes.c_void_p(int(problem.this)), r.ctypes.data_as(dp),
                           w.ctypes.data_as(dp), ctypes.c_double(1.0), ctypes.c_double(norm),
                           ctypes.byref(err))
    return err.value, w


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("fclib")
    ap.add_argument("out")
    ap.add_argument("--tolerance", type=float, required=True)
    ap.add_argument("--max-iter", type=int, required=True)
    args = ap.parse_args()
    prob, bad = read_fclib_local(args.fclib)
    result = {"siconos": siconos.version, "layout": bad, "info": prob.get("info", {})}
    if not bad and prob["spacedim"] != 2:
        bad.append(f"spacedim {prob['spacedim']}: not a problem for Siconos' fc2d")
    if not bad and "r" not in prob["solution"]:
        bad.append("no /solution with u and r (fclib_write_solution's group)")
    if bad:
        json.dump(result, open(args.out, "w"))
        return 0
    W, q, mu, sol = prob["W"], prob["q"], prob["mu"], prob["solution"]
    m = len(q)
    name = ctypes.util.find_library("siconos_numerics")
    if name is None:
        raise SystemExit("libsiconos_numerics not found by ctypes.util.find_library")
    lib = ctypes.CDLL(name)
    lib.fc2d_compute_error.restype = ctypes.c_int
    problem = sn.FrictionContactProblem(2, W, q, mu)
    norm_q = float(np.linalg.norm(q))
    result["stored_error_by_siconos"], w = compute_error(lib, problem, sol["r"], norm_q)
    result["stored_u_by_siconos"] = w.tolist()
    # The same error with a norm far above every vector: Siconos' scaling is then that norm
    # (tells max(norm, |r|, |u|) from a division by the norm passed alone).
    result["stored_error_norm_1e30"] = compute_error(lib, problem, sol["r"], 1e30)[0]
    options = sn.SolverOptions(sn.SICONOS_FRICTION_2D_NSGS)
    options.dparam[sn.SICONOS_DPARAM_TOL] = args.tolerance
    options.iparam[sn.SICONOS_IPARAM_MAX_ITER] = args.max_iter
    r, u = np.zeros(m), np.zeros(m)
    info = sn.fc2d_driver(problem, r, u, options)
    err, w = compute_error(lib, problem, r, norm_q)
    result.update(nsgs_info=int(info), nsgs_iterations=int(options.iparam[sn.SICONOS_IPARAM_ITER_DONE]),
                  nsgs_residual=float(options.dparam[sn.SICONOS_DPARAM_RESIDU]), r=r.tolist(),
                  u=u.tolist(), error=err, u_from_r=w.tolist())
    json.dump(result, open(args.out, "w"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
