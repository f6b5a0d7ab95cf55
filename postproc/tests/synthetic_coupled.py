"""Synthetic MULTICOR coupled results (/fem, /dem and /coupling of doc/output.md) for the
tests.

The particle part is that of synthetic_dem (5 disks of radius R, N_OUT outputs, contacts,
solver statistics), with the disks moved into a row continuing a beam along x: nodes at
x = 0, 0.04, 0.08, 0.12 m, overlap [0.08, 0.12] m, disk centres x0 = 0.08 .. 0.16 m (pitch
2 R), disks 1..3 coupled. At output k the beam deflects as w(x) = -A k (x / L)^2 (L = 0.12 m)
and the disks follow it: coupled disks on the parabola, the others on its tangent at L (a
rigid continuation); velocities are V times the displacements.
"""
import h5py
import numpy as np

from synthetic_dem import H, N_OUT, STEPS_PER_OUT, write_dem

NODE_X = np.array([0.0, 0.04, 0.08, 0.12])
DISK_X = np.array([0.08, 0.10, 0.12, 0.14, 0.16])
L, A, V = 0.12, 1e-3, 10.0
OVERLAP = (0.08, 0.12)
COUPLED = np.array([1, 2, 3], np.int32)
ENERGY_NAMES = ("fe_kinetic", "fe_strain", "fe_external_work", "fe_damping", "fe_coupling_work",
                "dem_kinetic", "dem_potential", "dem_external_work", "dem_drive_work",
                "contact_dissipation", "numerical_dissipation", "dem_coupling_work",
                "external_work", "coupling_work", "balance")


def beam_w(x, k):
    """Deflection of the beam at output k."""
    return -A * k * (np.asarray(x) / L) ** 2


def disk_dy(x, k):
    """Vertical displacement of the disks at output k: parabola up to L, tangent beyond."""
    x = np.asarray(x)
    return np.where(x <= L + 1e-12, beam_w(x, k), -A * k * (1 + 2 * (x - L) / L))


def write_coupled(path, title="synthetic coupled", drop=()):
    """Write a coupled results file; datasets named in `drop` are left out of /coupling."""
    write_dem(path, title=title)
    times = H * STEPS_PER_OUT * np.arange(N_OUT)
    steps = (N_OUT - 1) * STEPS_PER_OUT
    n_nodes, n_rows = NODE_X.size, 2 * COUPLED.size
    d = np.zeros((N_OUT, n_nodes, 3))
    pos = np.zeros((N_OUT, DISK_X.size, 3))
    for k in range(N_OUT):
        d[k, :, 1] = beam_w(NODE_X, k)
        pos[k, :, 0] = DISK_X
        pos[k, :, 1] = disk_dy(DISK_X, k)
    with h5py.File(path, "a") as f:
        del f["dem/position"], f["dem/velocity"]
        f.create_dataset("dem/position", data=pos)
        vel = V * (pos - pos[0])
        f.create_dataset("dem/velocity", data=vel)
        f.create_dataset("fem/mesh/node_id", data=np.arange(1, n_nodes + 1, dtype=np.int32))
        f.create_dataset("fem/mesh/coordinates", data=np.stack([NODE_X, 0 * NODE_X], axis=1))
        f.create_dataset("fem/mesh/connectivity",
                         data=np.array([[i, i + 1] for i in range(1, n_nodes)], np.int32))
        f.create_dataset("fem/time", data=times)
        f.create_dataset("fem/displacement", data=d)
        f.create_dataset("fem/velocity", data=V * d)
        f.create_dataset("fem/acceleration", data=np.zeros_like(d))
        data = {"coupling/time": times, "coupling/overlap": np.array(OVERLAP),
                "coupling/particles": COUPLED, "coupling/alpha": np.array([0.999, 0.5, 0.001]),
                "coupling/abscissa": DISK_X[:3], "coupling/offset": np.zeros(3),
                "coupling/alpha_disks": np.array([0.999, 0.5, 0.001, 0.0, 0.0]),
                "coupling/rows/particle": np.repeat(COUPLED, 2),
                "coupling/rows/dof": np.tile(np.array([1, 2], np.int32), COUPLED.size),
                "coupling/lambda": np.outer(np.arange(N_OUT), np.arange(n_rows)) * 0.1,
                "coupling/energy/time": times}
        for name in ("g_norm", "position_residual", "velocity_residual", "rotation_residual",
                     "coordinate_residual", "lambda_norm"):
            data[f"coupling/{name}"] = np.full(steps, 1e-18)
        data["coupling/sweeps"] = np.arange(steps, dtype=np.int32) + 1
        data["coupling/corrections"] = np.zeros(steps, np.int32)
        for name in ENERGY_NAMES:
            data[f"coupling/energy/{name}"] = np.linspace(0.0, 1.0, N_OUT) * (name != "balance")
        for name, value in data.items():
            if name not in drop:
                f.create_dataset(name, data=value)
        f["coupling"].attrs["n_rows"] = np.int32(n_rows)
        f["coupling"].attrs["n_points"] = np.int32(COUPLED.size)
        f["coupling"].attrs["time_step"] = H
        f["coupling"].attrs["weight"] = "cubic"
        f.create_group("summary")
        f["summary"].attrs["steps"] = np.int32(steps)
        f["summary"].attrs["wall_seconds"] = 0.25
    return path
