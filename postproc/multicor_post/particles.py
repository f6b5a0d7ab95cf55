"""Discrete-element (particle) results: loading of the /dem group of a MULTICOR results file
(layout in doc/output.md) and its plots: configuration (disks as circles, contact forces as
lines whose width grows with the normal force, walls), energy audit, solver statistics, and
the velocity history of small systems. Figures use matplotlib's object API and the Agg
renderer; ``write_all`` saves PNG files.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Optional

import numpy as np
from matplotlib import colormaps
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.cm import ScalarMappable
from matplotlib.collections import EllipseCollection, LineCollection
from matplotlib.colors import BoundaryNorm
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import MaxNLocator

from .beam import _time_unit
from .results import (FigureFiles, Records, ResultsError, _decode_attrs, _Getter, _open_results,
                      abs_max, no_output_error)

#: Columns of the per-disk arrays: x [m], y [m], rotation [rad].
X, Y, ROT = 0, 1, 2
#: Contact status codes (/dem/contacts/status).
OPEN, STICK, SLIP, COHESIVE, BROKEN = 0, 1, 2, 3, 4
STATUS_NAMES = {OPEN: "open", STICK: "stick", SLIP: "slip", COHESIVE: "cohesive", BROKEN: "broken"}
#: Largest line width of the force network [points].
MAX_FORCE_WIDTH = 4.0
#: Systems up to this many disks get a rotation mark in each disk and a velocity history.
SMALL_SYSTEM = 50
#: Contact forces below this fraction of the largest of the run are not drawn.
NOISE = 1e-6
#: Velocity histories of up to this many disks get a legend, one colour of matplotlib's
#: default cycle (10 colours) each; more are coloured by number (VELOCITY_MAP).
LEGEND_DISKS = 10
#: Colour map of the disks' numbers in the velocity histories of more than LEGEND_DISKS:
#: sequential and perceptually uniform, its ends (dark blue, yellow) both visible on white.
VELOCITY_MAP = colormaps["viridis"]


@dataclass
class Contacts:
    """Contact network at the stored outputs, compressed rows: the contacts of output k are
    entries ``offset[k]:offset[k + 1]`` of the other arrays. The lists are `Records`, read on
    demand (``c.rn[c.at(k)]`` reads output k's); the offsets are an array."""

    offset: np.ndarray    # (n_out + 1,) int
    i: Records            # (n_c,) int, 1-based disk
    j: Records            # (n_c,) int, 1-based disk (> 0) or wall (-j, < 0)
    normal: Records       # (n_c, 2), unit, from j to i
    rn: Records           # (n_c,) [N/m], > 0 compression, < 0 cohesive tension
    rt: Records           # (n_c,) [N/m]
    status: Records       # (n_c,) int, STATUS_NAMES
    m: Optional[Records] = None  # (n_c,) [N.m/m] contact moment on i (files before it: None)

    def at(self, k: int) -> slice:
        """Entries of output ``k``."""
        return slice(int(self.offset[k]), int(self.offset[k + 1]))


@dataclass
class DemEnergy:
    """Energy audit per unit thickness [J/m] at the stored outputs."""

    time: np.ndarray
    kinetic: np.ndarray
    potential: np.ndarray
    external_work: np.ndarray
    drive_work: np.ndarray
    dissipated: np.ndarray
    numerical: np.ndarray
    balance: np.ndarray


@dataclass
class Solver:
    """Contact solver statistics of every time step (step k ends at t = (k + 1) h)."""

    sweeps: np.ndarray      # (n_steps,) int
    contacts: np.ndarray    # (n_steps,) int, contacts in the list
    active: np.ndarray      # (n_steps,) int, contacts in the solve
    converged: np.ndarray   # (n_steps,) bool
    error: np.ndarray       # (n_steps,) convergence norm
    residual: np.ndarray    # (n_steps,) Signorini-Coulomb residual
    tolerance: float
    max_sweeps: int
    time_step: float
    method: str = ""        # [solver] method (nlgs, block, coarse); "" in files without it

    @property
    def time(self) -> np.ndarray:
        return self.time_step * np.arange(1, self.sweeps.size + 1)


@dataclass
class DemResults:
    """The /dem group of a results file. The positions and velocities are `Records`, read on
    demand (``res.position[k]`` reads output k); the other fields are arrays."""

    path: str
    attrs: dict                    # root attributes (title, analysis, ...)
    radius: np.ndarray             # (n,) [m]
    mass: np.ndarray               # (n,) [kg/m]
    material: np.ndarray           # (n,) deck material ids
    time: np.ndarray               # (n_out,) [s]
    position: Records              # (n_out, n, 3): x, y, rot
    velocity: Records              # (n_out, n, 3)
    walls: Optional[np.ndarray]    # (n_out, n_walls, 4): x1, y1, x2, y2, or None
    energy: DemEnergy
    solver: Solver
    contacts: Optional[Contacts] = None

    @property
    def title(self) -> str:
        return self.attrs.get("title", "") or os.path.basename(self.path)

    @property
    def n(self) -> int:
        return int(self.radius.size)

    def nearest_index(self, t: float) -> int:
        """Index of the stored output nearest to ``t`` (first one on a tie)."""
        return int(np.argmin(np.abs(self.time - t)))


def has_particles(path) -> bool:
    """Whether a results file holds discrete-element results (a /dem group); ResultsError when
    it is missing, not a results file or unreadable (`_open_results`)."""
    with _open_results(os.fspath(path)) as f:
        return "dem" in f


def load_dem(path) -> DemResults:
    """Read the /dem group of a results file. Raises ResultsError with a clear message when
    the file is missing, unreadable, or a dataset does not follow the documented layout."""
    path = os.fspath(path)
    f = _open_results(path)
    with f:
        if "dem" not in f:
            raise ResultsError(f"{path}: no /dem group (no particles in this run)")
        get = _Getter(f, path)
        radius = get("dem/particles/radius", (None,))
        n = radius.size
        time = get("dem/time", (None,))
        if time.size == 0:
            raise no_output_error(f, path, "dem/time")
        n_out = time.size
        walls = None
        if "dem/walls/position" in f:
            walls = get("dem/walls/position", (n_out, None, 4))
        energy = DemEnergy(**{name: get(f"dem/energy/{name}", (n_out,)) for name in (
            "time", "kinetic", "potential", "external_work", "drive_work", "dissipated",
            "numerical", "balance")})
        sweeps = get("dem/solver/sweeps", (None,)).astype(int)
        steps = (sweeps.size,)
        solver_attrs = _decode_attrs(f["dem/solver"].attrs)
        solver = Solver(sweeps=sweeps, contacts=get("dem/solver/contacts", steps).astype(int),
                        active=get("dem/solver/active", steps).astype(int),
                        converged=get("dem/solver/converged", steps).astype(bool),
                        error=get("dem/solver/error", steps),
                        residual=get("dem/solver/residual", steps),
                        tolerance=float(solver_attrs.get("tolerance", np.nan)),
                        max_sweeps=int(solver_attrs.get("max_sweeps", 0)),
                        time_step=float(_decode_attrs(f["dem"].attrs).get("time_step", np.nan)),
                        method=str(solver_attrs.get("method", "")))
        res = DemResults(path=path, attrs=_decode_attrs(f.attrs), radius=radius,
                         mass=get("dem/particles/mass", (n,)),
                         material=get("dem/particles/material", (n,)).astype(int),
                         time=time, position=get.records("dem/position", (n_out, n, 3)),
                         velocity=get.records("dem/velocity", (n_out, n, 3)), walls=walls,
                         energy=energy, solver=solver)
        if "dem/contacts" in f:
            offset = get("dem/contacts/offset", (n_out + 1,)).astype(int)
            m = int(offset[-1]) if offset.size else 0
            if offset.size and (offset[0] != 0 or np.any(np.diff(offset) < 0)):
                raise ResultsError(f"{path}: /dem/contacts/offset must start at 0 and not "
                                   "decrease")
            lists = get.records
            res.contacts = Contacts(offset=offset, i=lists("dem/contacts/i", (m,)).astype(int),
                                    j=lists("dem/contacts/j", (m,)).astype(int),
                                    normal=lists("dem/contacts/normal", (m, 2)),
                                    rn=lists("dem/contacts/rn", (m,)),
                                    rt=lists("dem/contacts/rt", (m,)),
                                    status=lists("dem/contacts/status", (m,)).astype(int),
                                    m=lists("dem/contacts/m", (m,)) if "dem/contacts/m" in f else None)
    return res


# --------------------------------------------------------------------------------------------
# Figures
# --------------------------------------------------------------------------------------------

def _new_figure(width=8.0, height=6.0):
    fig = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def force_segments(res: DemResults, k: int):
    """Segments of the force network of output ``k``: for each contact of the stored list,
    the line from the centre of disk i to the centre of disk j (or to the contact point on
    the wall). Returns ``(segments (m, 2, 2), rn (m,), status (m,))``."""
    if res.contacts is None:
        return np.zeros((0, 2, 2)), np.zeros(0), np.zeros(0, dtype=int)
    c = res.contacts
    s = c.at(k)
    i, j = c.i[s] - 1, c.j[s]
    pos = res.position[k]
    start = pos[i, :2]
    end = np.empty_like(start)
    disk = j > 0
    end[disk] = pos[j[disk] - 1, :2]
    # Wall contact: the contact point is the disk centre minus R along the normal (the
    # normal goes from the wall into the disk).
    end[~disk] = start[~disk] - res.radius[i[~disk], None] * c.normal[s][~disk]
    return np.stack([start, end], axis=1), c.rn[s], c.status[s]


def force_scale(res: DemResults) -> float:
    """Largest |r_n| of the run [N/m] (0 without contacts), the contact lists read block by
    block (`abs_max`)."""
    if res.contacts is None or res.contacts.rn.size == 0:
        return 0.0
    return abs_max(res.contacts.rn)


def force_widths(rn: np.ndarray, scale: Optional[float] = None) -> np.ndarray:
    """Line widths [points] proportional to |r_n|: MAX_FORCE_WIDTH for the largest
    (or for ``scale``)."""
    if scale is None:
        scale = float(np.max(np.abs(rn))) if rn.size else 0.0
    if scale <= 0.0:
        return np.zeros_like(rn)
    return MAX_FORCE_WIDTH * np.abs(rn) / scale


def plot_configuration(res: DemResults, k: Optional[int] = None) -> Figure:
    """Disks at output ``k`` (default: the last), coloured by material, the walls, and the
    contact forces: black lines for compression, red for cohesive tension, width
    proportional to |r_n| (MAX_FORCE_WIDTH for the largest force of the snapshot; forces
    below NOISE times the largest of the run are left out); intact bonds as thin blue lines,
    broken bonds as grey crosses at the contact point, and contact moments as orange rings
    at the contact point, their area proportional to |m|. The title counts the contacts, or
    says 'contacts not stored' for a run without /dem/contacts ([output] contacts = no)."""
    if k is None:
        k = res.time.size - 1
    pos = res.position[k]
    fig = _new_figure()
    ax = fig.subplots()
    materials = np.unique(res.material)
    palette = ["#9ecae1", "#fdd0a2", "#c7e9c0", "#dadaeb", "#fcbba1", "#d9d9d9"]
    colors = [palette[int(np.searchsorted(materials, m)) % len(palette)] for m in res.material]
    disks = EllipseCollection(2 * res.radius, 2 * res.radius, np.zeros(res.n), units="xy",
                              offsets=pos[:, :2], offset_transform=ax.transData,
                              facecolors=colors, edgecolors="0.35" if res.n <= 500 else "0.6",
                              linewidths=0.4 if res.n <= 500 else 0.15)
    ax.add_collection(disks)
    handles = []
    lo = (pos[:, :2] - res.radius[:, None]).min(axis=0)
    hi = (pos[:, :2] + res.radius[:, None]).max(axis=0)
    if res.n <= SMALL_SYSTEM:
        marks = np.stack([pos[:, :2], pos[:, :2] + res.radius[:, None]
                          * np.column_stack([np.cos(pos[:, ROT]), np.sin(pos[:, ROT])])], axis=1)
        ax.add_collection(LineCollection(marks, colors="0.35", linewidths=0.8))
    if res.walls is not None and res.walls.shape[1] > 0:
        w = res.walls[k]
        ax.add_collection(LineCollection(w.reshape(-1, 2, 2), colors="0.2", linewidths=2.5))
        lo = np.minimum(lo, np.minimum(w[:, :2], w[:, 2:]).min(axis=0))
        hi = np.maximum(hi, np.maximum(w[:, :2], w[:, 2:]).max(axis=0))
    segments, rn, status = force_segments(res, k)
    bonded = status == COHESIVE
    if np.any(bonded):
        ax.add_collection(LineCollection(segments[bonded], colors="tab:blue", linewidths=0.6, zorder=1))
        handles.append(Line2D([], [], color="tab:blue", lw=0.6, label="intact bonds"))
    broken = status == BROKEN
    if np.any(broken):
        mid = segments[broken].mean(axis=1)
        ax.plot(mid[:, 0], mid[:, 1], "x", color="0.4", ms=5, zorder=3)
        handles.append(Line2D([], [], color="0.4", marker="x", ls="", label="broken bonds"))
    if res.contacts is not None and res.contacts.m is not None:
        mom = np.abs(res.contacts.m[res.contacts.at(k)])
        big = mom > NOISE * abs_max(res.contacts.m) if mom.size else mom > 0
        if np.any(big):
            mid = segments[big].mean(axis=1)
            ax.scatter(mid[:, 0], mid[:, 1], s=80.0 * mom[big] / mom[big].max(), facecolors="none",
                       edgecolors="tab:orange", linewidths=1.0, zorder=4)
            handles.append(Line2D([], [], color="tab:orange", marker="o", mfc="none", ls="",
                                  label=f"moment, area ∝ |m|; largest {mom[big].max():.3g} N.m/m"))
    # Forces below NOISE times the largest of the run are round-off of the solver: not drawn.
    carrying = np.abs(rn) > NOISE * force_scale(res)
    scale = float(np.max(np.abs(rn[carrying]))) if np.any(carrying) else 0.0
    # The thickest line is at most 70 % of a mean disk diameter as drawn (the axes span
    # about 4.8 inches = 345 points along the longer side of the data).
    span = float(max(hi - lo)) if np.all(hi > lo) else 1.0
    width = float(np.clip(0.7 * 345.0 * 2.0 * np.mean(res.radius) / span, 0.5, MAX_FORCE_WIDTH))
    if np.any(carrying):
        widths = force_widths(rn[carrying], scale) * width / MAX_FORCE_WIDTH
        tension = rn[carrying] < 0
        color = np.where(tension, "tab:red", "black")
        ax.add_collection(LineCollection(segments[carrying], colors=list(color),
                                         linewidths=widths, capstyle="round"))
        if np.any(~tension):
            handles.append(Line2D([], [], color="black", lw=2.0, label="compression"))
        if np.any(tension):
            handles.append(Line2D([], [], color="tab:red", lw=2.0, label="cohesive tension"))
        handles.append(Line2D([], [], color="0.5", lw=width,
                              label=f"width ∝ |r_n|; this width: {scale:.3g} N/m"))
    if res.walls is not None and res.walls.shape[1] > 0:
        handles.append(Line2D([], [], color="0.2", lw=2.5, label="walls"))
    if res.n <= 20:
        for i in range(res.n):
            ax.annotate(str(i + 1), pos[i, :2], xytext=(0, 0), textcoords="offset points",
                        ha="center", va="center", fontsize="x-small", color="0.15")
    # Keep the plotted box between 1:2 and 2:1, so that a row or a column stays readable.
    size = hi - lo
    grow = np.maximum(0.5 * size[::-1] - size, 0.0)
    lo, hi = lo - grow / 2, hi + grow / 2
    margin = 0.03 * max(hi - lo)
    ax.set_xlim(lo[0] - margin, hi[0] + margin)
    ax.set_ylim(lo[1] - margin, hi[1] + margin)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ft, ut = _time_unit(res.time)
    if res.contacts is None:
        # [output] contacts = no: no /dem/contacts, not a snapshot without contacts
        network = "contacts not stored"
    else:
        network = (f"{int(np.size(rn))} contacts ({int(np.count_nonzero(carrying))} carrying a "
                   "force)")
    ax.set_title(f"{res.title}\nt = {res.time[k] * ft:.6g} {ut}: {res.n} disks, {network}")
    if handles:
        ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.1),
                  ncol=2, fontsize="small", frameon=False)
    return fig


def plot_energy(res: DemResults) -> Figure:
    """Energy audit against time: kinetic, change of the gravity potential, works and
    dissipations, and the balance residual."""
    e = res.energy
    ft, ut = _time_unit(e.time)
    t = e.time * ft
    fig = _new_figure(height=6.0)
    ax, ax_b = fig.subplots(2, 1, sharex=True, height_ratios=[2, 1])
    ax.plot(t, e.kinetic, label="kinetic")
    ax.plot(t, e.potential - e.potential[0], label="potential (change since t = 0)")
    if np.any(e.external_work != 0.0):
        ax.plot(t, e.external_work, label="work of the loads")
    if np.any(e.drive_work != 0.0):
        ax.plot(t, e.drive_work, label="work of imposed velocities and walls")
    ax.plot(t, e.dissipated, label="dissipated by the contacts")
    if np.any(e.numerical != 0.0):
        ax.plot(t, e.numerical, label="dissipated by the scheme (theta > 1/2)")
    ax.set_ylabel("energy [J/m]")
    ax.set_title(f"{res.title}\nenergy audit of the particles (per unit thickness)")
    ax.legend(loc="best", fontsize="small")
    ax_b.plot(t, e.balance, color="C3")
    ax_b.set_ylabel("balance [J/m]")
    ax_b.set_xlabel(f"time [{ut}]")
    for a in (ax, ax_b):
        a.grid(True, alpha=0.3)
    return fig


def plot_solver(res: DemResults) -> Figure:
    """Solver statistics of every step: sweeps, convergence error and residual, contacts;
    steps that did not converge are marked in red."""
    s = res.solver
    ft, ut = _time_unit(s.time)
    t = s.time * ft
    bad = ~s.converged
    fig = _new_figure(height=7.5)
    ax_s, ax_e, ax_c = fig.subplots(3, 1, sharex=True)
    ax_s.plot(t, s.sweeps, lw=0.8, color="C0")
    if s.max_sweeps and np.max(s.sweeps, initial=0) >= 0.1 * s.max_sweeps:
        ax_s.axhline(s.max_sweeps, color="0.5", ls="--", lw=0.8,
                     label=f"max_sweeps = {s.max_sweeps}")
    elif s.max_sweeps:
        # a cap far above every step would squash the sweeps to the bottom of the axis
        ax_s.text(0.99, 0.95, f"max_sweeps = {s.max_sweeps} (off the scale)", transform=ax_s.transAxes,
                  ha="right", va="top", fontsize="small", color="0.3")
    if np.any(bad):
        ax_s.plot(t[bad], s.sweeps[bad], "o", color="tab:red", ms=3,
                  label=f"not converged ({int(np.count_nonzero(bad))} steps)")
    ax_s.set_ylabel("sweeps")
    if ax_s.get_legend_handles_labels()[0]:
        ax_s.legend(loc="best", fontsize="small")
    positive = lambda v: np.where(v > 0, v, np.nan)  # noqa: E731 (log axes skip zeros)
    if not np.any(s.error > 0) and not np.any(s.residual > 0):
        # Every step solved exactly (a direct block solve): the log axis would have nothing
        # to scale to but the tolerance line (matplotlib warns of identical limits), so it is
        # given its limits before anything is drawn, and the fact is written out.
        ref = s.tolerance if np.isfinite(s.tolerance) and s.tolerance > 0 else 1.0
        ax_e.set_yscale("log")
        ax_e.set_ylim(ref / 10.0, ref * 10.0)
        ax_e.text(0.5, 0.3, "error and residual 0 at every step", transform=ax_e.transAxes,
                  ha="center", va="center", fontsize="small", color="0.3")
    ax_e.semilogy(t, positive(s.error), lw=0.8, label="convergence error (sweep change)")
    ax_e.semilogy(t, positive(s.residual), lw=0.8, label="Signorini-Coulomb residual")
    if np.isfinite(s.tolerance):
        ax_e.axhline(s.tolerance, color="0.5", ls="--", lw=0.8,
                     label=f"tolerance {s.tolerance:.4g}")
    ax_e.set_ylabel("relative error [-]")
    ax_e.legend(loc="best", fontsize="small")
    ax_c.plot(t, s.contacts, lw=0.8, label="contacts in the list")
    ax_c.plot(t, s.active, lw=0.8, label="active contacts")
    ax_c.set_ylabel("contacts")
    ax_c.set_xlabel(f"time [{ut}]")
    ax_c.legend(loc="best", fontsize="small")
    method = f" (method = {s.method})" if s.method else ""
    ax_s.set_title(f"{res.title}\ncontact solver{method}, every step (h = {s.time_step:.4g} s)")
    for a in (ax_s, ax_e, ax_c):
        a.grid(True, alpha=0.3)
    return fig


def plot_velocities(res: DemResults) -> Figure:
    """Velocity history (vx, vy, omega) of every disk of a small system. Up to
    LEGEND_DISKS disks, each has a colour of matplotlib's default cycle and a legend entry;
    more (the cycle would repeat its 10 colours: 17 disks drew 7 pairs of one colour) are
    coloured by their number along a sequential colour map, numbered by a colour bar."""
    ft, ut = _time_unit(res.time)
    t = res.time * ft
    fig = _new_figure(height=7.0)
    axes = fig.subplots(3, 1, sharex=True)
    labels = ["v_x [m/s]", "v_y [m/s]", "ω [rad/s]"]
    numbered = res.n > LEGEND_DISKS
    if numbered:
        # one colour per disk number, 1 .. n, in bands of a discrete colour bar
        norm = BoundaryNorm(np.arange(res.n + 1) + 0.5, VELOCITY_MAP.N)
        colour = [VELOCITY_MAP(norm(i + 1)) for i in range(res.n)]
    else:
        colour = [f"C{i}" for i in range(res.n)]
    for i in range(res.n):
        v = res.velocity[:, i]      # the disk's history, read once
        for d, ax in enumerate(axes):
            ax.plot(t, v[:, d], lw=1.0, color=colour[i], label=f"disk {i + 1}" if d == 0 else None)
    for d, ax in enumerate(axes):
        ax.set_ylabel(labels[d])
        ax.grid(True, alpha=0.3)
    axes[-1].set_xlabel(f"time [{ut}]")
    if numbered:
        bar = fig.colorbar(ScalarMappable(norm=norm, cmap=VELOCITY_MAP), ax=axes, aspect=40,
                           label="disk")
        bar.locator = MaxNLocator(nbins=min(res.n, 20), integer=True)
        bar.update_ticks()
    elif res.n > 0:
        axes[0].legend(loc="best", fontsize="small", ncol=2)
    axes[0].set_title(f"{res.title}\nvelocities of the disks")
    return fig


# --------------------------------------------------------------------------------------------
# All plots of one file
# --------------------------------------------------------------------------------------------

def write_all(res: DemResults, out_dir, time: Optional[float] = None,
              dpi: int = 120, notes: Optional[list] = None) -> list[str]:
    """Write every particle plot as PNG files in ``out_dir``; return their paths:
    <name>_particles.png (configuration at the output nearest to ``time``, default the last),
    <name>_particles_start.png (at t = 0, when ``time`` is not given), <name>_dem_energy.png,
    <name>_solver.png, and <name>_velocities.png for small systems. A figure left out because
    its series is empty (the solver statistics of a run stopped before its 4096th step) gets a
    sentence in ``notes``, when given, for the caller to print."""
    files = FigureFiles(res.path, out_dir, dpi)
    save = files.save
    # Thousands of disks need more pixels to be seen one by one.
    dpi_config = dpi if res.n <= 500 else 2 * dpi
    if time is None:
        save(plot_configuration(res, 0), "particles_start", dpi_config)
        save(plot_configuration(res), "particles", dpi_config)
    else:
        save(plot_configuration(res, res.nearest_index(time)), "particles", dpi_config)
    save(plot_energy(res), "dem_energy")
    if res.solver.sweeps.size:
        save(plot_solver(res), "solver")
    elif notes is not None:
        notes.append(f"{files.stem}_solver.png is not written: /dem/solver holds no step (its "
                     "series are written every 4096 steps and at the end of a run: a run "
                     "stopped before its 4096th step has none)")
    if res.n <= SMALL_SYSTEM:
        save(plot_velocities(res), "velocities")
    return files.written
