"""Synthetic MULTICOR coupled results (/fem, /dem and /coupling of doc/output.md) for the
tests.

The particle part is that of synthetic_dem (5 disks of radius R, N_OUT outputs, contacts,
solver statistics), with the disks moved into a row continuing a beam along x: nodes at
x = 0, 0.04, 0.08, 0.12 m, overlap [0.08, 0.12] m, disk centres x0 = 0.08 .. 0.16 m (pitch
2 R), disks 1..3 coupled. At output k the beam deflects as w(x) = -A k (x / L)^2 (L = 0.12 m)
and the disks follow it: coupled disks on the parabola, the others on its tangent at L (a
rigid continuation); velocities are V times the displacements.

The /coupling series are told apart by their values: per-step series i of STEP_REALS is
(i + 1) 1e-18 (k + 1) at step k, /coupling/energy term i is (i + 1)^2 1e-3 k at output k (the
balance 1e-12 k), so that a figure drawing the wrong dataset draws other numbers.

`write_continuum_coupled` writes the other kind of coupled run: a 2D continuum (two Q4,
/continuum as a dynamic run writes it) glued to the same disks, with the same /coupling
group (without the beam's overlap, abscissa and offset).
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


#: Real per-step datasets of /coupling (sweeps and corrections are integers).
STEP_REALS = ("g_norm", "position_residual", "velocity_residual", "rotation_residual",
              "coordinate_residual", "lambda_norm")
#: Rows of the multipliers: x and y of each coupled disk.
N_ROWS = 2 * COUPLED.size


def step_series(name, steps):
    """The synthetic values of a per-step dataset of /coupling (module doc)."""
    if name == "sweeps":
        return np.arange(steps, dtype=np.int32) + 1
    if name == "corrections":
        return np.zeros(steps, np.int32)
    return (STEP_REALS.index(name) + 1) * 1e-18 * (np.arange(steps) + 1.0)


def energy_term(name):
    """The synthetic values of /coupling/energy/<name> at the outputs (module doc)."""
    if name == "balance":
        return 1e-12 * np.arange(N_OUT)
    return (ENERGY_NAMES.index(name) + 1) ** 2 * 1e-3 * np.arange(N_OUT)


def multipliers():
    """/coupling/lambda (N_OUT, N_ROWS): 0.1 k j at output k, row j."""
    return np.outer(np.arange(N_OUT), np.arange(N_ROWS)) * 0.1


def _coupling_group(times, steps):
    """The /coupling datasets both kinds of coupled run write."""
    data = {"coupling/time": times, "coupling/particles": COUPLED,
            "coupling/alpha": np.array([0.999, 0.5, 0.001]),
            "coupling/alpha_disks": np.array([0.999, 0.5, 0.001, 0.0, 0.0]),
            "coupling/rows/particle": np.repeat(COUPLED, 2),
            "coupling/rows/dof": np.tile(np.array([1, 2], np.int32), COUPLED.size),
            "coupling/lambda": multipliers(), "coupling/energy/time": times}
    for name in STEP_REALS + ("sweeps", "corrections"):
        data[f"coupling/{name}"] = step_series(name, steps)
    for name in ENERGY_NAMES:
        data[f"coupling/energy/{name}"] = energy_term(name)
    return data


def _write_coupling(f, data, drop):
    """Write `data` but the datasets named in `drop`, and the attributes of /coupling."""
    for name, value in data.items():
        if name not in drop:
            f.create_dataset(name, data=value)
    f["coupling"].attrs["n_rows"] = np.int32(N_ROWS)
    f["coupling"].attrs["n_points"] = np.int32(COUPLED.size)
    f["coupling"].attrs["time_step"] = H
    f["coupling"].attrs["rotation"] = np.int32(0)
    f["coupling"].attrs["weight"] = "cubic"


def write_coupled(path, title="synthetic coupled", drop=()):
    """Write a coupled results file; datasets named in `drop` are left out of /coupling."""
    write_dem(path, title=title)
    times = H * STEPS_PER_OUT * np.arange(N_OUT)
    steps = (N_OUT - 1) * STEPS_PER_OUT
    n_nodes = NODE_X.size
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
        data = _coupling_group(times, steps)
        data.update({"coupling/overlap": np.array(OVERLAP), "coupling/abscissa": DISK_X[:3],
                     "coupling/offset": np.zeros(3)})
        _write_coupling(f, data, drop)
        f.create_group("summary")
        f["summary"].attrs["steps"] = np.int32(steps)
        f["summary"].attrs["wall_seconds"] = 0.25
    return path


#: The continuum of write_continuum_coupled: two Q4 over [0, 0.16] x [-0.02, 0.02] m.
BLOCK_X = np.array([[0.0, -0.02], [0.08, -0.02], [0.16, -0.02],
                    [0.0, 0.02], [0.08, 0.02], [0.16, 0.02]])
BLOCK_CONN = np.array([[1, 2, 5, 4], [2, 3, 6, 5]], np.int32)
CONTINUUM_ENERGY = ("kinetic", "strain", "external_work", "damping", "reaction_work", "balance")


def write_continuum_coupled(path, title="synthetic continuum coupled", drop=()):
    """Write a continuum-disk coupled results file (module doc); datasets named in `drop`
    are left out of /coupling."""
    write_dem(path, title=title)
    times = H * STEPS_PER_OUT * np.arange(N_OUT)
    steps = (N_OUT - 1) * STEPS_PER_OUT
    n_nodes = BLOCK_X.shape[0]
    with h5py.File(path, "a") as f:
        f.create_dataset("continuum/mesh/coordinates", data=BLOCK_X)
        f.create_dataset("continuum/mesh/connectivity", data=BLOCK_CONN)
        f.create_dataset("continuum/mesh/kind", data=np.array([2, 2], np.int32))
        f.create_dataset("continuum/time", data=times)
        u = np.zeros((N_OUT, n_nodes, 2))
        u[:, :, 1] = np.outer(np.arange(N_OUT), beam_w(BLOCK_X[:, 0], 1))
        f.create_dataset("continuum/displacement", data=u)
        f.create_dataset("continuum/velocity", data=V * u)
        f.create_dataset("continuum/stress",
                         data=np.ones((N_OUT, 2, 3)) * np.arange(N_OUT)[:, None, None])
        f.create_dataset("continuum/energy/time", data=times)
        for name in CONTINUUM_ENERGY:
            f.create_dataset(f"continuum/energy/{name}", data=np.zeros(N_OUT))
        _write_coupling(f, _coupling_group(times, steps), drop)
    return path
