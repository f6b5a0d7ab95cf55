"""A large synthetic particle results file (the /dem layout of doc/output.md), to test and
measure the memory the loaders need: its series grow with the outputs times the disks and
the contacts, as those of a cluster-sized run (doc/cluster.md).

A square grid of `n_disks` disks of radius R (spacing 2R); output k moves every disk up by
SHIFT * k and holds `per_output` contacts between horizontal neighbours, whose normal force
is rn_of(k, c): 1 to 8 N/m, but PEAK_FACTOR times that at output n_out // 2, so that the
forces the configuration figure leaves out as round-off (below 1e-6 of the run's largest,
particles.NOISE) are those below about 3.75 N/m: which they are depends on every output.
The datasets are chunked as multicor chunks its series (about 64 KiB, at least one record).

With ``only`` given, only those outputs are written: the others are left to HDF5's fill
value (0; the file stays small on disk), but read as whole records all the same, so that
reading a series whole takes its full size in memory.
"""
import math

import h5py
import numpy as np

R = 0.01
SHIFT = 1e-5                     # upward offset per output [m]
H = 1e-4                         # time step [s]; one output per step
PEAK_FACTOR = 5e5                # the run's largest |rn| / that of the other outputs (module doc)
CHUNK_BYTES = 65536              # multicor's target chunk size (src/io/hdf5_file.fypp)


def grid(n_disks):
    """(x, y) (n_disks, 2) of the disks at output 0, and the side of the square grid."""
    side = math.ceil(math.sqrt(n_disks))
    k = np.arange(n_disks)
    return np.column_stack([R + 2 * R * (k % side), R + 2 * R * (k // side)]), side


def state(k, n_disks):
    """Positions (n_disks, 3) at output k: the grid moved up by SHIFT * k, rotation k / 100."""
    xy, _ = grid(n_disks)
    pos = np.empty((n_disks, 3))
    pos[:, :2] = xy
    pos[:, 1] += SHIFT * k
    pos[:, 2] = k / 100.0
    return pos


def contact_lists(k, n_disks, per_output, n_out):
    """(i, j, normal, rn, rt, status, m) of output k: disk c and its right neighbour, c =
    0, 1, ... skipping the ends of the grid's rows, 1-based; the normal from j to i is -x."""
    _, side = grid(n_disks)
    first = np.arange(n_disks - 1)
    first = first[(first % side) != side - 1][:per_output]
    m = first.size
    i, j = (first + 2).astype(np.int32), (first + 1).astype(np.int32)
    normal = np.tile([-1.0, 0.0], (m, 1))
    rn = rn_of(k, np.arange(m), n_out)
    return (i, j, normal, rn, 0.1 * rn, np.ones(m, np.int32), 1e-3 * rn)


def rn_of(k, c, n_out):
    """Normal force of contact c at output k [N/m]: 1 + c mod 7 + k / n_out, times
    PEAK_FACTOR at output n_out // 2."""
    rn = 1.0 + (np.asarray(c) % 7) + k / n_out
    return rn * (PEAK_FACTOR if k == n_out // 2 else 1.0)


def _series(f, name, shape, dtype):
    """An extendible series of records of shape shape[1:], chunked like multicor's."""
    record = int(np.prod(shape[1:], dtype=np.int64)) * np.dtype(dtype).itemsize
    rows = max(1, min(1024, CHUNK_BYTES // max(record, 1)))
    return f.create_dataset(name, shape=shape, dtype=dtype, chunks=(rows,) + tuple(shape[1:]),
                            maxshape=(None,) + tuple(shape[1:]), fillvalue=0)


def write_large_dem(path, n_disks, n_out, per_output, only=None, block=50):
    """Write the file (module doc); ``only``: the outputs written (None: all), the others
    left to the fill value. Returns the path."""
    outputs = range(n_out) if only is None else sorted(set(int(k) % n_out for k in only))
    m = contact_lists(0, n_disks, per_output, n_out)[0].size
    times = H * np.arange(n_out)
    with h5py.File(path, "w") as f:
        f.attrs["code_name"] = "MULTICOR"
        f.attrs["title"] = f"large synthetic grid ({n_disks} disks, {n_out} outputs)"
        f.attrs["analysis"] = "dynamic"
        f["dem/particles/radius"] = np.full(n_disks, R)
        f["dem/particles/mass"] = np.full(n_disks, 2500.0 * math.pi * R**2)
        f["dem/particles/material"] = np.ones(n_disks, np.int32)
        f["dem/time"] = times
        f["dem/energy/time"] = times
        for name in ("kinetic", "potential", "external_work", "drive_work", "dissipated",
                     "numerical", "balance"):
            f[f"dem/energy/{name}"] = np.sin(times * (1 + len(name)))
        steps = n_out
        f["dem/solver/sweeps"] = (1 + np.arange(steps) % 13).astype(np.int32)
        f["dem/solver/contacts"] = np.full(steps, m, np.int32)
        f["dem/solver/active"] = np.full(steps, m, np.int32)
        f["dem/solver/converged"] = np.ones(steps, np.int32)
        f["dem/solver/error"] = 1e-6 * (1 + np.arange(steps) % 5)
        f["dem/solver/residual"] = 1e-7 * (1 + np.arange(steps) % 3)
        f["dem"].attrs["time_step"] = H
        f["dem"].attrs["n_particles"] = np.int32(n_disks)
        f["dem/solver"].attrs["tolerance"] = 1e-5
        f["dem/solver"].attrs["max_sweeps"] = np.int32(100)
        f["dem/solver"].attrs["method"] = "nlgs"
        position = _series(f, "dem/position", (n_out, n_disks, 3), np.float64)
        velocity = _series(f, "dem/velocity", (n_out, n_disks, 3), np.float64)
        f["dem/contacts/offset"] = (m * np.arange(n_out + 1)).astype(np.int64)
        lists = {name: _series(f, f"dem/contacts/{name}", (n_out * m,) + extra, dtype)
                 for name, extra, dtype in (("i", (), np.int32), ("j", (), np.int32),
                                            ("normal", (2,), np.float64), ("rn", (), np.float64),
                                            ("rt", (), np.float64), ("status", (), np.int32),
                                            ("m", (), np.float64))}
        outputs = list(outputs)
        # consecutive outputs in blocks (a few MB each: the parent process stays small too)
        for start in range(0, len(outputs), block):
            ks = outputs[start:start + block]
            lo, hi = ks[0], ks[-1] + 1
            if hi - lo != len(ks):          # not consecutive: one by one
                for k in ks:
                    _write_outputs(position, velocity, lists, [k], n_disks, per_output, n_out, m)
                continue
            _write_outputs(position, velocity, lists, ks, n_disks, per_output, n_out, m)
    return path


def _write_outputs(position, velocity, lists, ks, n_disks, per_output, n_out, m):
    """Write the consecutive outputs ks."""
    lo, hi = ks[0], ks[-1] + 1
    position[lo:hi] = np.stack([state(k, n_disks) for k in ks])
    vel = np.zeros((hi - lo, n_disks, 3))
    vel[:, :, 1] = SHIFT / H
    velocity[lo:hi] = vel
    parts = [contact_lists(k, n_disks, per_output, n_out) for k in ks]
    for c, name in enumerate(("i", "j", "normal", "rn", "rt", "status", "m")):
        lists[name][lo * m:hi * m] = np.concatenate([p[c] for p in parts])
