"""Synthetic MULTICOR particle results (the /dem layout of doc/output.md) for the tests.

A column of N_DISKS disks of radius R resting on a floor (wall 1), with a cohesive disk
hanging from a fixed one beside it: at rest each contact of the column carries the weight of
the disks above it (r_n = k m g), the bond holds the hanging disk in tension (r_n = -m g).
The outputs repeat that state, shifted up by a small offset per output so that the output
index can be recognised; the solver statistics have one unconverged step.
"""
import math

import h5py
import numpy as np

R, RHO, G = 0.01, 2500.0, 9.81
MASS = RHO * math.pi * R**2
N_DISKS = 3                      # column; disks 4 (fixed) and 5 (hanging) beside it
N_OUT, H, STEPS_PER_OUT = 4, 1e-3, 5
SHIFT = 1e-4                     # upward offset per output [m]


def column_state(k):
    """Positions (5, 3) at output k."""
    pos = np.zeros((N_DISKS + 2, 3))
    pos[:N_DISKS, 1] = R + 2 * R * np.arange(N_DISKS) + SHIFT * k
    pos[N_DISKS] = [0.1, 0.2, 0.0]
    pos[N_DISKS + 1] = [0.1, 0.2 - 2 * R, 0.0]
    return pos


def contacts():
    """One output's contacts: floor-disk 1, pairs (i-1, i) of the column, the bond."""
    i = list(range(1, N_DISKS + 1)) + [N_DISKS + 2]
    j = [-1] + list(range(1, N_DISKS)) + [N_DISKS + 1]
    normal = [[0.0, 1.0]] * N_DISKS + [[0.0, -1.0]]
    rn = [(N_DISKS - k) * MASS * G for k in range(N_DISKS)] + [-MASS * G]
    status = [1] * N_DISKS + [3]
    return (np.array(i, np.int32), np.array(j, np.int32), np.array(normal), np.array(rn),
            np.zeros(len(i)), np.array(status, np.int32))


def write_dem(path, drop=(), with_contacts=True, with_walls=True, title="synthetic column",
              with_beam=False):
    """Write a results file; datasets named in `drop` are left out."""
    n = N_DISKS + 2
    steps = (N_OUT - 1) * STEPS_PER_OUT
    times = H * STEPS_PER_OUT * np.arange(N_OUT)
    i, j, normal, rn, rt, status = contacts()
    m = i.size
    data = {
        "dem/particles/radius": np.full(n, R),
        "dem/particles/mass": np.full(n, MASS),
        "dem/particles/inertia": np.full(n, 0.5 * MASS * R**2),
        "dem/particles/material": np.array([1] * N_DISKS + [2, 2], np.int32),
        "dem/time": times,
        "dem/position": np.stack([column_state(k) for k in range(N_OUT)]),
        "dem/velocity": np.zeros((N_OUT, n, 3)),
        "dem/energy/time": times,
        "dem/energy/kinetic": np.zeros(N_OUT),
        "dem/energy/potential": MASS * G * SHIFT * np.arange(N_OUT),
        "dem/energy/external_work": np.zeros(N_OUT),
        "dem/energy/drive_work": MASS * G * SHIFT * np.arange(N_OUT),
        "dem/energy/dissipated": np.zeros(N_OUT),
        "dem/energy/numerical": np.zeros(N_OUT),
        "dem/energy/balance": np.zeros(N_OUT),
        "dem/solver/sweeps": np.arange(1, steps + 1, dtype=np.int32),
        "dem/solver/contacts": np.full(steps, m, np.int32),
        "dem/solver/active": np.full(steps, m, np.int32),
        "dem/solver/converged": np.array([0 if s == 7 else 1 for s in range(steps)], np.int32),
        "dem/solver/error": np.full(steps, 1e-5),
        "dem/solver/residual": np.full(steps, 1e-6),
    }
    if with_walls:
        data["dem/walls/material"] = np.array([1], np.int32)
        data["dem/walls/position"] = np.tile([[-0.05, 0.0, 0.2, 0.0]], (N_OUT, 1, 1))
    if with_contacts:
        data["dem/contacts/offset"] = (m * np.arange(N_OUT + 1)).astype(np.int32)
        data["dem/contacts/offset"][1:] -= m          # no contacts at output 0
        data["dem/contacts/i"] = np.tile(i, N_OUT - 1)
        data["dem/contacts/j"] = np.tile(j, N_OUT - 1)
        data["dem/contacts/normal"] = np.tile(normal, (N_OUT - 1, 1))
        data["dem/contacts/rn"] = np.tile(rn, N_OUT - 1)
        data["dem/contacts/rt"] = np.tile(rt, N_OUT - 1)
        data["dem/contacts/status"] = np.tile(status, N_OUT - 1)
    with h5py.File(path, "w") as f:
        f.attrs["code_name"] = "MULTICOR"
        f.attrs["title"] = title
        f.attrs["analysis"] = "dynamic"
        for name, value in data.items():
            if name not in drop:
                f.create_dataset(name, data=value)
        f["dem"].attrs["time_step"] = H
        f["dem"].attrs["n_particles"] = np.int32(n)
        f["dem/solver"].attrs["tolerance"] = 1.666e-4
        f["dem/solver"].attrs["max_sweeps"] = np.int32(1000)
        if with_beam:
            f.create_dataset("fem/mesh/node_id", data=np.array([1, 2], np.int32))
            f.create_dataset("fem/mesh/coordinates", data=np.array([[0.0, -0.1], [0.2, -0.1]]))
            f.create_dataset("fem/mesh/connectivity", data=np.array([[1, 2]], np.int32))
            f.create_dataset("static/displacement", data=np.zeros((2, 3)))
            f.create_dataset("static/reactions", data=np.zeros((2, 3)))
    return path
