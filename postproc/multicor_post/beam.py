"""Plots of beam results: deflection along the beam, deformed shape of a frame, node history,
energy audit and mode shapes. Figures are built with matplotlib's object API and the Agg
renderer (no display needed); ``write_all`` saves PNG files.

Between nodes the fields are drawn with the element's own interpolation (Euler-Bernoulli:
axial displacement linear, transverse displacement cubic Hermite in u, w, theta), so a coarse
mesh still gives the true element curve.
"""
from __future__ import annotations

from typing import Optional

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from .results import THETA, U, W, FigureFiles, Mesh, Results, ResultsError, max_over_records

POINTS_PER_ELEMENT = 16


# --------------------------------------------------------------------------------------------
# Interpolation
# --------------------------------------------------------------------------------------------

def element_fields(mesh: Mesh, d: np.ndarray, points: int = POINTS_PER_ELEMENT):
    """Undeformed positions and global displacements along every element.

    ``d`` is (n_nodes, 3) = (u, w, theta). Returns a list with one tuple per element:
    ``(x, y, ux, uy)``, arrays of ``points`` values from its first to its second node.
    """
    xi = np.linspace(0.0, 1.0, points)
    n1 = 1 - 3 * xi**2 + 2 * xi**3
    n2 = xi - 2 * xi**2 + xi**3
    n3 = 3 * xi**2 - 2 * xi**3
    n4 = -xi**2 + xi**3
    out = []
    for a, b in mesh.connectivity:
        ex, ey = mesh.x[b] - mesh.x[a], mesh.y[b] - mesh.y[a]
        length = float(np.hypot(ex, ey))
        if length == 0.0:
            raise ResultsError(f"element {a + 1}-{b + 1} has zero length")
        c, s = ex / length, ey / length
        # Local (axial, transverse) components at both ends; rotations are frame invariant.
        ua, wa = c * d[a, U] + s * d[a, W], -s * d[a, U] + c * d[a, W]
        ub, wb = c * d[b, U] + s * d[b, W], -s * d[b, U] + c * d[b, W]
        ul = (1 - xi) * ua + xi * ub
        wl = n1 * wa + length * n2 * d[a, THETA] + n3 * wb + length * n4 * d[b, THETA]
        out.append((mesh.x[a] + xi * ex, mesh.y[a] + xi * ey, c * ul - s * wl, s * ul + c * wl))
    return out


def auto_scale(mesh: Mesh, d: np.ndarray, fraction: float = 0.1) -> float:
    """Magnification (`magnification`) making the largest displacement about ``fraction`` of
    the structure's size; 1 (true scale) when nothing moves or the displacements are already
    that large."""
    size = max(np.ptp(mesh.x), np.ptp(mesh.y))
    dmax = float(np.max(np.hypot(d[:, U], d[:, W]))) if d.size else 0.0
    if dmax == 0.0 or size == 0.0:
        return 1.0
    return magnification(fraction * size / dmax)


def magnification(raw: float) -> float:
    """Displacement factor of a drawing for the wanted magnification ``raw``: rounded down to
    1, 2 or 5 times a power of ten (`round_scale`), so that the title gives a round factor;
    1 (true scale) when ``raw`` is below 2 (never a factor that shrinks the displacements, nor
    one too close to 1 to tell from the true scale) or not finite."""
    return round_scale(raw) if 2.0 <= raw < np.inf else 1.0


def round_scale(raw: float) -> float:
    """The largest round factor (1, 2 or 5 times a power of ten) not above ``raw`` > 0."""
    exponent = np.floor(np.log10(raw))
    mantissa = raw / 10**exponent
    step = 1.0 if mantissa < 2 else 2.0 if mantissa < 5 else 5.0
    return float(step * 10**exponent)


def default_node(res: Results) -> int:
    """Deck id of the 'tip': the end node (in one element only) that moves most; when no end
    node moves (a frame supported at both ends, a mesh without ends), the node that moves
    most; the last end node (else the last node) when nothing moves."""
    mesh = res.mesh
    if res.dynamic is not None:
        motion = max_over_records(res.dynamic.displacement,
                                  lambda d: np.hypot(d[..., U], d[..., W]))
    elif res.static is not None:
        motion = np.hypot(res.static.displacement[:, U], res.static.displacement[:, W])
    else:
        motion = np.zeros(mesh.n_nodes)
    ends = mesh.end_nodes()
    candidates = ends if ends.size and motion[ends].any() else np.arange(mesh.n_nodes)
    if not motion.any():
        candidates = ends if ends.size else candidates
    best = candidates[np.argmax(motion[candidates])] if motion.any() else candidates[-1]
    return int(mesh.node_id[best])


# --------------------------------------------------------------------------------------------
# Units for readable axes
# --------------------------------------------------------------------------------------------

def _length_unit(values) -> tuple[float, str]:
    vmax = float(np.max(np.abs(values))) if np.size(values) else 0.0
    if vmax >= 0.1 or vmax == 0.0:
        return 1.0, "m"
    if vmax >= 1e-4:
        return 1e3, "mm"
    return 1e6, "µm"


def _time_unit(values) -> tuple[float, str]:
    vmax = float(np.max(np.abs(values))) if np.size(values) else 0.0
    if vmax >= 1.0 or vmax == 0.0:
        return 1.0, "s"
    if vmax >= 1e-3:
        return 1e3, "ms"
    return 1e6, "µs"


def _new_figure(rows: int = 1, height: float = 4.2):
    fig = Figure(figsize=(8.0, height * rows if rows > 1 else height), layout="constrained")
    FigureCanvasAgg(fig)
    return fig


# --------------------------------------------------------------------------------------------
# Figures
# --------------------------------------------------------------------------------------------

def plot_field(res: Results, d: np.ndarray, what: str, scale: Optional[float] = None) -> Figure:
    """Deflection w along a straight beam, or the deformed shape of any other frame.
    ``what`` is the title's description (e.g. 'static solution' or 't = 5 ms')."""
    mesh = res.mesh
    if mesh.is_straight_along_x():
        fig = _new_figure(rows=2, height=3.0)
        ax_w, ax_u = fig.subplots(2, 1, sharex=True)
        curves = element_fields(mesh, d)
        fx, ux = _length_unit(mesh.x)
        fw, uw = _length_unit([c[3] for c in curves])
        fu, uu = _length_unit([c[2] for c in curves])
        for i, (x, _, dx, dy) in enumerate(curves):
            ax_w.plot(x * fx, dy * fw, color="C0", label="w (element interpolation)" if i == 0 else None)
            ax_u.plot(x * fx, dx * fu, color="C1")
        ax_w.plot(mesh.x * fx, d[:, W] * fw, "o", color="C0", ms=3.5, label="nodes")
        ax_u.plot(mesh.x * fx, d[:, U] * fu, "o", color="C1", ms=3.5)
        ax_w.set_ylabel(f"deflection w [{uw}]")
        ax_u.set_ylabel(f"axial displacement u [{uu}]")
        ax_u.set_xlabel(f"x [{ux}]")
        ax_w.set_title(f"{res.title}\ndeflection along the beam, {what}")
        ax_w.legend(loc="best", fontsize="small")
        for ax in (ax_w, ax_u):
            ax.grid(True, alpha=0.3)
            ax.axhline(0.0, color="0.5", lw=0.8)
        return fig
    if scale is None:
        scale = auto_scale(mesh, d)
    fig = _new_figure(height=6.0)
    ax = fig.subplots()
    curves = element_fields(mesh, d)
    fx, ux = _length_unit(np.concatenate([mesh.x, mesh.y]))
    for i, (x, y, dx, dy) in enumerate(curves):
        ax.plot(x * fx, y * fx, "--", color="0.6", lw=1.0, label="undeformed" if i == 0 else None)
        ax.plot((x + scale * dx) * fx, (y + scale * dy) * fx, color="C0", lw=2.0,
                label=f"deformed (displacements × {scale:g})" if i == 0 else None)
    ax.plot((mesh.x + scale * d[:, U]) * fx, (mesh.y + scale * d[:, W]) * fx, "o", color="C0",
            ms=3.5)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(f"x [{ux}]")
    ax.set_ylabel(f"y [{ux}]")
    ax.set_title(f"{res.title}\ndeformed shape, {what}")
    ax.legend(loc="best", fontsize="small")
    ax.grid(True, alpha=0.3)
    return fig


def uses_scale(res: Results) -> bool:
    """Whether `write_all` draws a deformed shape magnified by its ``scale``: that of a frame
    (not a straight beam along x, drawn as its deflection) at an output or its static
    solution."""
    return (not res.mesh.is_straight_along_x()
            and (res.dynamic is not None or res.static is not None))


def plot_deflection(res: Results, time: Optional[float] = None,
                    scale: Optional[float] = None) -> tuple[Figure, int]:
    """Deflection (or deformed shape) at the stored output nearest to ``time`` (default: the
    last one). Returns the figure and the index of the output shown."""
    if res.dynamic is None:
        raise ResultsError(f"{res.path}: no time history (/fem/time) in these results")
    dyn = res.dynamic
    k = dyn.nearest_index(dyn.time[-1] if time is None else time)
    ft, ut = _time_unit(dyn.time)
    what = f"t = {dyn.time[k] * ft:.6g} {ut}"
    span = float(np.max(np.abs(dyn.time))) if dyn.time.size else 0.0
    if time is not None and not np.isclose(dyn.time[k], time, rtol=1e-9, atol=1e-12 * span):
        what += f" (stored output nearest to the requested {time * ft:.6g} {ut})"
    return plot_field(res, dyn.displacement[k], what, scale), k


def plot_history(res: Results, node_id: Optional[int] = None) -> tuple[Figure, int]:
    """Displacements w(t) and u(t) of one node (default: the tip). Returns the figure and
    the node id."""
    if res.dynamic is None:
        raise ResultsError(f"{res.path}: no time history (/fem/time) in these results")
    if node_id is None:
        node_id = default_node(res)
    i = res.mesh.index_of(node_id)
    dyn = res.dynamic
    ft, ut = _time_unit(dyn.time)
    fig = _new_figure(rows=2, height=3.0)
    ax_w, ax_u = fig.subplots(2, 1, sharex=True)
    d = dyn.displacement[:, i]      # the node's history, read once
    fw, uw = _length_unit(d[:, W])
    fu, uu = _length_unit(d[:, U])
    ax_w.plot(dyn.time * ft, d[:, W] * fw, color="C0")
    ax_u.plot(dyn.time * ft, d[:, U] * fu, color="C1")
    ax_w.set_ylabel(f"w [{uw}]")
    ax_u.set_ylabel(f"u [{uu}]")
    ax_u.set_xlabel(f"time [{ut}]")
    where = f"x = {res.mesh.x[i]:.4g} m, y = {res.mesh.y[i]:.4g} m"
    ax_w.set_title(f"{res.title}\ndisplacement history of node {node_id} ({where})")
    for ax in (ax_w, ax_u):
        ax.grid(True, alpha=0.3)
        ax.axhline(0.0, color="0.5", lw=0.8)
    return fig, node_id


def plot_energy(res: Results) -> Figure:
    """Energies and the balance residual against time."""
    if res.energy is None:
        raise ResultsError(f"{res.path}: no /energy group in these results")
    e = res.energy
    ft, ut = _time_unit(e.time)
    fig = _new_figure(rows=2, height=3.0)
    ax, ax_b = fig.subplots(2, 1, sharex=True, height_ratios=[2, 1])
    t = e.time * ft
    ax.plot(t, e.kinetic, label="kinetic")
    ax.plot(t, e.strain, label="strain")
    ax.plot(t, e.kinetic + e.strain, "--", label="kinetic + strain")
    ax.plot(t, e.external_work, label="external work")
    if np.any(e.damping != 0.0):
        ax.plot(t, e.damping, label="damping dissipation")
    ax.set_ylabel("energy [J]")
    ax.set_title(f"{res.title}\nenergy audit")
    ax.legend(loc="best", fontsize="small")
    ax_b.plot(t, e.balance, color="C3")
    ax_b.set_ylabel("balance [J]")
    ax_b.set_xlabel(f"time [{ut}]")
    for a in (ax, ax_b):
        a.grid(True, alpha=0.3)
    return fig


def axial_modes(res: Results) -> np.ndarray:
    """Whether each mode of a modal run is axial: labelled 'axial' in /modal/axial_fraction@kind,
    or, without that label ('mixed', 'rigid', or a file of an earlier build), when its largest
    nodal axial displacement exceeds its largest transverse one (in each element's axes)."""
    modal = res.modal
    flags = np.zeros(modal.omega.size, bool)
    for k in range(modal.omega.size):
        label = modal.kind[k] if modal.kind is not None else ""
        if label in ("axial", "bending"):
            flags[k] = label == "axial"
            continue
        axial = transverse = 0.0
        for a, b in res.mesh.connectivity:
            ex, ey = res.mesh.x[b] - res.mesh.x[a], res.mesh.y[b] - res.mesh.y[a]
            length = float(np.hypot(ex, ey))
            c, s = ex / length, ey / length
            for n in (a, b):
                d = modal.shapes[k, n]
                axial = max(axial, abs(c * d[U] + s * d[W]))
                transverse = max(transverse, abs(-s * d[U] + c * d[W]))
        flags[k] = axial > transverse
    return flags


def plot_modes(res: Results, max_modes: int = 6) -> Figure:
    """Mode shapes (each scaled to a unit largest displacement) with their frequencies. Along
    a straight beam the deflection w of each mode is drawn against x, and the axial
    displacement u of an axial mode (`axial_modes`; its w is zero), dashed, marked '(axial)'
    in the legend; a frame's modes are drawn as deformed shapes."""
    if res.modal is None:
        raise ResultsError(f"{res.path}: no /modal group in these results")
    mesh, modal = res.mesh, res.modal
    n = min(max_modes, modal.omega.size)
    fig = _new_figure(height=4.8)
    ax = fig.subplots()
    straight = mesh.is_straight_along_x()
    axial = axial_modes(res) if straight else np.zeros(modal.omega.size, bool)
    fx, ux = _length_unit(np.concatenate([mesh.x, mesh.y]))
    size = max(np.ptp(mesh.x), np.ptp(mesh.y))
    for k in range(n):
        shape = modal.shapes[k]
        peak = float(np.max(np.hypot(shape[:, U], shape[:, W])))
        shape = shape / peak if peak > 0 else shape
        label = f"mode {k + 1}: f = {modal.frequency[k]:.5g} Hz" + (" (axial)" if axial[k] else "")
        curves = element_fields(mesh, shape)
        for j, (x, y, dx, dy) in enumerate(curves):
            if straight:
                ax.plot(x * fx, dx if axial[k] else dy, "--" if axial[k] else "-",
                        color=f"C{k}", label=label if j == 0 else None)
            else:
                s = 0.15 * size
                ax.plot((x + s * dx) * fx, (y + s * dy) * fx, color=f"C{k}",
                        label=label if j == 0 else None)
    if straight:
        ax.axhline(0.0, color="0.5", lw=0.8)
        if axial[:n].any():
            ax.set_ylabel("w, or u of an axial mode (dashed) / max |displacement| [-]")
        else:
            ax.set_ylabel("w / max |displacement| [-]")
    else:
        for x, y, _, _ in element_fields(mesh, np.zeros((mesh.n_nodes, 3))):
            ax.plot(x * fx, y * fx, "--", color="0.6", lw=1.0)
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_ylabel(f"y [{ux}]")
    ax.set_xlabel(f"x [{ux}]")
    ax.set_title(f"{res.title}\nmode shapes (lowest {n} of {modal.omega.size})")
    ax.legend(loc="best", fontsize="small")
    ax.grid(True, alpha=0.3)
    return fig


# --------------------------------------------------------------------------------------------
# All plots of one file
# --------------------------------------------------------------------------------------------

def write_all(res: Results, out_dir, time: Optional[float] = None,
              node_id: Optional[int] = None, scale: Optional[float] = None,
              dpi: int = 120) -> list[str]:
    """Write every plot the results allow as PNG files in ``out_dir``; return their paths."""
    files = FigureFiles(res.path, out_dir, dpi)
    save, written = files.save, files.written
    if res.dynamic is not None:
        fig, _ = plot_deflection(res, time, scale)
        save(fig, "deflection")
        fig, node = plot_history(res, node_id)
        save(fig, f"history_node{node}")
    if res.energy is not None:
        save(plot_energy(res), "energy")
    if res.static is not None:
        save(plot_field(res, res.static.displacement, "static solution", scale), "static")
    if res.modal is not None:
        save(plot_modes(res), "modes")
    if not written:
        raise ResultsError(f"{res.path}: nothing to plot (no /fem/time, /static or /modal)")
    return written
