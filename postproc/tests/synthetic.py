"""Synthetic MULTICOR results files (layout of doc/output.md) for the post-processing tests.

The beam is an analytic cantilever of length L clamped at x = 0 with a tip load P: static
deflection w(x) = -P x^2 (3L - x) / (6 EI), rotation theta = dw/dx. The dynamic outputs scale
that shape by sin(omega t). Optionally the beam is rotated by an angle (inclined member).
"""
import math

import h5py
import numpy as np

L, EI, P = 2.0, 5.0e3, 100.0          # [m], [N m^2], [N]
OMEGA = 2 * math.pi * 50.0             # [rad/s]
DT, N_OUT = 1.0e-3, 11                 # output interval [s], number of outputs


def cantilever_w(x):
    """Deflection [m] of the tip-loaded cantilever."""
    return -P * x**2 * (3 * L - x) / (6 * EI)


def cantilever_theta(x):
    """Rotation dw/dx [rad] of the tip-loaded cantilever."""
    return -P * x * (2 * L - x) / (2 * EI)


def rotate(angle, ul, wl):
    """Global (u, w) of local (axial, transverse) components of a member at `angle`."""
    c, s = math.cos(angle), math.sin(angle)
    return c * ul - s * wl, s * ul + c * wl


def cantilever_layout(n_nodes=9, angle=0.0):
    """Node ids, coordinates (n, 2), 1-based connectivity (ne, 2) and static field (n, 3)."""
    s = np.linspace(0.0, L, n_nodes)
    xy = np.column_stack([s * math.cos(angle), s * math.sin(angle)])
    ids = np.arange(1, n_nodes + 1, dtype=np.int32) * 10
    conn = np.column_stack([np.arange(1, n_nodes), np.arange(2, n_nodes + 1)]).astype(np.int32)
    u, w = rotate(angle, np.zeros_like(s), cantilever_w(s))
    d = np.column_stack([u, w, cantilever_theta(s)])
    return ids, xy, conn, d


def write_results(path, ids, xy, conn, d_static, parts=("dynamic", "energy", "static", "modal"),
                  drop=(), title="synthetic cantilever"):
    """Write a results file with the given parts; datasets named in `drop` are left out."""
    n = len(ids)
    times = DT * np.arange(N_OUT)
    amp = np.sin(OMEGA * times)
    data = {
        "fem/mesh/node_id": ids,
        "fem/mesh/coordinates": xy,
        "fem/mesh/connectivity": conn,
    }
    if "dynamic" in parts:
        data["fem/time"] = times
        data["fem/displacement"] = amp[:, None, None] * d_static[None]
        data["fem/velocity"] = OMEGA * np.cos(OMEGA * times)[:, None, None] * d_static[None]
        data["fem/acceleration"] = -OMEGA**2 * amp[:, None, None] * d_static[None]
    if "energy" in parts:
        kinetic = 0.5 * np.cos(OMEGA * times) ** 2
        strain = 0.5 * amp**2
        data.update({"energy/time": times, "energy/kinetic": kinetic, "energy/strain": strain,
                     "energy/external_work": np.zeros(N_OUT), "energy/damping": np.zeros(N_OUT),
                     "energy/balance": kinetic + strain - 0.5})
    if "static" in parts:
        data["static/displacement"] = d_static
        data["static/reactions"] = np.zeros((n, 3))
    if "modal" in parts:
        omega = np.array([100.0, 600.0])
        data["modal/omega"] = omega
        data["modal/frequency"] = omega / (2 * math.pi)
        data["modal/shapes"] = np.stack([d_static, -0.5 * d_static])
    with h5py.File(path, "w") as f:
        f.attrs["code_name"] = "MULTICOR"
        f.attrs["code_version"] = "0.1.0"
        f.attrs["deck_file"] = "input/cantilever.dat"
        f.attrs["deck_text"] = "title = synthetic\n"
        f.attrs["title"] = title
        f.attrs["analysis"] = "dynamic"
        f.attrs["created"] = "2025-01-01T00:00:00+00:00"
        for name, value in data.items():
            if name in drop:
                continue
            if name.startswith(("fem/time", "fem/displacement", "fem/velocity",
                                "fem/acceleration", "energy/")):
                f.create_dataset(name, data=value, maxshape=(None,) + value.shape[1:],
                                 chunks=True)
            else:
                f.create_dataset(name, data=value)
        f.create_group("summary")
        f["summary"].attrs["steps"] = np.int32(1000)
        f["summary"].attrs["wall_seconds"] = 1.5
    return path
