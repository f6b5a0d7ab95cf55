"""Coupled (Arlequin beam + particles) results: loading of the /fem, /dem and /coupling groups
of a MULTICOR results file (layout in doc/output.md) and the figures of the reference
experiments (doc/experiments.md): profiles of displacement and velocity along x with the FE
nodes and the disks on the same axes, the deformed configuration with the overlap shaded,
the history of a tracked disk in several runs, the profiles of several runs against each
other, and the coupling diagnostics (constraint residuals, multipliers, energy audit).

The coupling diagnostics are those of either kind of coupled run: the /coupling group is
written by the same code for a beam (/fem) and for a 2D continuum (/continuum) glued to disks.
One figure (`plot_coupling`) draws a `CouplingDiagnostics`, which a small loader per kind
gives: `CoupledResults.coupling` (beam, read by `load_coupled`) and
`load_continuum_coupling` (continuum).
Figures use matplotlib's object API and the Agg renderer.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Optional, Sequence

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import EllipseCollection
from matplotlib.figure import Figure

from .beam import _time_unit, magnification
from .results import (FigureFiles, Records, ResultsError, _decode_attrs, _Getter, _open_results,
                      no_output_error)

#: Columns of the nodal and per-disk arrays: x (u), y (w), rotation.
X, Y, ROT = 0, 1, 2
#: Colours: beam (FE) and disks (DEM), coupled disks, overlap shading.
FE_COLOUR, DEM_COLOUR, COUPLED_COLOUR, OVERLAP_COLOUR = "C0", "C3", "C2", "0.85"
#: Per-step datasets of /coupling (entry k: the step ending at t = (k + 1) h).
STEP_SERIES = ("g_norm", "position_residual", "velocity_residual", "rotation_residual",
               "coordinate_residual", "lambda_norm", "sweeps", "corrections")


@dataclass
class CouplingDiagnostics:
    """The /coupling group of a coupled run, beam or 2D continuum (module doc). The per-step
    series and the energy terms are those the file holds: a figure says which it lacks. With
    the mediator space (multipliers = nodes, a /coupling/mediator_nodes dataset), lambda_norm
    is the norm of the multipliers on the FE nodes, and lam still the forces of the rows."""

    path: str
    title: str
    body: str                    # the FE side, in the figure's legends: "beam", "continuum"
    time: np.ndarray             # (n_out,) [s] of the stored outputs
    lam: np.ndarray              # (n_out, n_rows) [N, N.m]
    steps: dict                  # STEP_SERIES present, each (n_steps,)
    energy: dict                 # /coupling/energy/<name> (n_out,) [J] present, with "time"
    attrs: dict                  # attributes of /coupling (time_step, rotation, ...)
    mediator: bool = False       # multipliers = nodes

    @property
    def no_step_yet(self) -> bool:
        """True when the file holds the per-step series but no step in them: a run stopped
        before its 4096th step (they are written in blocks of 4096 steps and at the end)."""
        return bool(self.steps) and all(v.size == 0 for v in self.steps.values())

    def step_time(self) -> np.ndarray:
        """End time of each recorded step [s] (NaN without the time_step attribute)."""
        n = next((v.size for v in self.steps.values()), 0)
        return (np.arange(n) + 1) * float(self.attrs.get("time_step", np.nan))


def _read_coupling(f, get, path: str, time: np.ndarray, body: str) -> CouplingDiagnostics:
    """The /coupling group of an open results file whose outputs are at ``time``: the
    multipliers are required; the per-step series and energy terms are read when present
    (shapes checked)."""
    n_rows = int(f["coupling"].attrs.get("n_rows", 0))
    present = [name for name in STEP_SERIES if f"coupling/{name}" in f]
    n_steps = f[f"coupling/{present[0]}"].shape[0] if present else 0
    energy = {}
    if "coupling/energy" in f:
        energy = {name: get(f"coupling/energy/{name}", (time.size,))
                  for name in f["coupling/energy"].keys()}
    attrs = _decode_attrs(f.attrs)
    return CouplingDiagnostics(
        path=path, title=attrs.get("title", "") or os.path.basename(path), body=body, time=time,
        lam=get("coupling/lambda", (time.size, n_rows)),
        steps={name: get(f"coupling/{name}", (n_steps,)) for name in present}, energy=energy,
        attrs=_decode_attrs(f["coupling"].attrs), mediator="coupling/mediator_nodes" in f)


def _same_times(path: str, a: np.ndarray, b: np.ndarray, names: str) -> None:
    """ResultsError unless two time axes of one file agree (to 1e-12 of the largest time)."""
    if not np.allclose(a, b, rtol=0, atol=1e-12 * max(1.0, float(np.abs(a).max(initial=0.0)))):
        raise ResultsError(f"{path}: {names} differ")


def load_continuum_coupling(path) -> CouplingDiagnostics:
    """The coupling diagnostics of a 2D continuum coupled to disks (/continuum, /dem and
    /coupling; the outputs at /coupling/time, which /continuum/time repeats). ResultsError
    when the file is missing, unreadable, not such a run, or a dataset does not follow the
    layout."""
    path = os.fspath(path)
    f = _open_results(path)
    with f:
        if "coupling" not in f or "continuum" not in f:
            raise ResultsError(f"{path}: a /coupling and a /continuum group are needed (not a "
                               "continuum coupled to disks)")
        get = _Getter(f, path, kind="coupled continuum results file")
        time = get("coupling/time", (None,))
        if time.size == 0:
            raise no_output_error(f, path, "coupling/time")
        _same_times(path, time, get("continuum/time", (time.size,)),
                    "/coupling/time and /continuum/time")
        return _read_coupling(f, get, path, time, body="continuum")


def region_forces(path) -> tuple[np.ndarray, np.ndarray]:
    """(time [s], forces [N]) of a 2D continuum coupled to disks: forces[k, r, c] is the sum
    of the multipliers of region r + 1 (the deck's region lines in order) in direction c (0 =
    x, 1 = y) at output k, i.e. the force the continuum exerts on the glued disks of that
    region through the glue (the sign of /coupling/lambda, doc/output.md; the continuum
    receives its opposite). From /coupling/rows/region; the
    multipliers alternate from step to step around their mean in impacts and sliding, so
    average two successive outputs for a resultant (multicor_post.interface.pair_mean).
    ResultsError when the file has no /coupling/rows/region (a beam coupling, or a file of an
    earlier build)."""
    path = os.fspath(path)
    f = _open_results(path)
    with f:
        if "coupling/rows/region" not in f:
            raise ResultsError(f"{path}: no /coupling/rows/region (not a continuum coupled to "
                               "disks, or a results file of an earlier build)")
        get = _Getter(f, path, kind="coupled continuum results file")
        time = get("coupling/time", (None,))
        region = get("coupling/rows/region", (None,)).astype(int)
        dof = get("coupling/rows/dof", (region.size,)).astype(int)
        lam = get("coupling/lambda", (time.size, region.size))
    forces = np.zeros((time.size, max(region.max(initial=0), 0), 2))
    for r in range(forces.shape[1]):
        for c in range(2):
            forces[:, r, c] = lam[:, (region == r + 1) & (dof == c + 1)].sum(axis=1)
    return time, forces


@dataclass
class CoupledResults:
    """The three parts of a coupled results file, at the stored outputs. The fields of the
    beam and of the disks are `Records`, read on demand (``res.position[k]`` reads output k);
    the rest are arrays."""

    path: str
    attrs: dict                  # root attributes (title, ...)
    node_x: np.ndarray           # (n_nodes,) [m]
    node_y: np.ndarray           # (n_nodes,) [m]
    connectivity: np.ndarray     # (n_elements, 2), 0-based
    time: np.ndarray             # (n_out,) [s] (the same outputs for /fem, /dem, /coupling)
    fe_displacement: Records     # (n_out, n_nodes, 3): u, w, theta
    fe_velocity: Records         # (n_out, n_nodes, 3)
    radius: np.ndarray           # (n,) [m]
    position: Records            # (n_out, n, 3): x, y, rot
    velocity: Records            # (n_out, n, 3)
    overlap: np.ndarray          # (2,): s_fe, s_particle [m]
    coupled: np.ndarray          # (n_points,) 0-based disk indices
    alpha: np.ndarray            # (n_points,) weight at the coupled disks
    coupling: CouplingDiagnostics   # multipliers, per-step series, energy audit
    summary: dict                # /summary attributes (steps, wall_seconds, ...) or {}

    @property
    def title(self) -> str:
        return self.attrs.get("title", "") or os.path.basename(self.path)

    @property
    def n_disks(self) -> int:
        return int(self.radius.size)

    @property
    def size(self) -> float:
        """Larger side of the model's box at t = 0 (beam nodes and disks) [m]."""
        xy, r = self.position[0][:, :2], self.radius[:, None]
        nodes = np.column_stack([self.node_x, self.node_y])
        lo = np.vstack([nodes, xy - r]).min(axis=0)
        hi = np.vstack([nodes, xy + r]).max(axis=0)
        return float(np.max(hi - lo))

    @property
    def length(self) -> float:
        """Extent of the model along x [m] (beam and disks at t = 0)."""
        lo = min(self.node_x.min(), (self.position[0, :, X] - self.radius).min())
        hi = max(self.node_x.max(), (self.position[0, :, X] + self.radius).max())
        return float(hi - lo)

    def nearest_index(self, t: Optional[float]) -> int:
        """Index of the stored output nearest to ``t`` (the last one when ``t`` is None)."""
        if t is None:
            return self.time.size - 1
        return int(np.argmin(np.abs(self.time - t)))

    def node_abscissa(self) -> np.ndarray:
        """Curvilinear abscissa of each node along the elements, from node 0 [m]."""
        s = np.zeros(self.node_x.size)
        for a, b in self.connectivity:
            s[b] = s[a] + np.hypot(self.node_x[b] - self.node_x[a], self.node_y[b] - self.node_y[a])
        return s

    def overlap_x(self) -> tuple[float, float]:
        """x coordinates of the overlap's ends (beam along x: interpolation of the nodes)."""
        s = self.node_abscissa()
        order = np.argsort(s)
        return tuple(float(np.interp(v, s[order], self.node_x[order])) for v in self.overlap)


def is_coupled(path) -> bool:
    """Whether a results file holds a coupled run (a /coupling group); ResultsError when it is
    missing, not a results file or unreadable (`_open_results`)."""
    with _open_results(os.fspath(path)) as f:
        return "coupling" in f


def load_coupled(path) -> CoupledResults:
    """Read a coupled results file. Raises ResultsError with a clear message when the file is
    missing, unreadable, not a coupled run, or a dataset does not follow the layout."""
    path = os.fspath(path)
    f = _open_results(path)
    with f:
        if "coupling" not in f:
            raise ResultsError(f"{path}: no /coupling group (not a coupled run)")
        get = _Getter(f, path, kind="coupled results file")
        xy = get("fem/mesh/coordinates", (None, 2))
        n_nodes = xy.shape[0]
        time = get("fem/time", (None,))
        if time.size == 0:
            raise no_output_error(f, path, "fem/time")
        n_out = time.size
        radius = get("dem/particles/radius", (None,))
        n = radius.size
        _same_times(path, time, get("dem/time", (n_out,)), "/fem/time and /dem/time")
        return CoupledResults(
            path=path, attrs=_decode_attrs(f.attrs), node_x=xy[:, 0], node_y=xy[:, 1],
            connectivity=get("fem/mesh/connectivity", (None, 2)).astype(int) - 1, time=time,
            fe_displacement=get.records("fem/displacement", (n_out, n_nodes, 3)),
            fe_velocity=get.records("fem/velocity", (n_out, n_nodes, 3)), radius=radius,
            position=get.records("dem/position", (n_out, n, 3)),
            velocity=get.records("dem/velocity", (n_out, n, 3)),
            overlap=get("coupling/overlap", (2,)),
            coupled=get("coupling/particles", (None,)).astype(int) - 1,
            alpha=get("coupling/alpha", (None,)),
            coupling=_read_coupling(f, get, path, time, body="beam"),
            summary=_decode_attrs(f["summary"].attrs) if "summary" in f else {})


# --------------------------------------------------------------------------------------------
# Profiles
# --------------------------------------------------------------------------------------------

@dataclass
class Profile:
    """Fields along x at one output: FE nodes (sorted by x) and disks (by initial x)."""

    time: float
    node_x: np.ndarray      # (n_nodes,) initial x [m]
    node_d: np.ndarray      # (n_nodes, 2) displacement u, w [m]
    node_v: np.ndarray      # (n_nodes, 2) velocity [m/s]
    disk_x: np.ndarray      # (n,) initial x [m]
    disk_y: np.ndarray      # (n,) initial y [m]
    disk_d: np.ndarray      # (n, 2) displacement of the centre [m]
    disk_v: np.ndarray      # (n, 2) velocity [m/s]


def profile(res: CoupledResults, k: int) -> Profile:
    """Displacements and velocities of the FE nodes and the disks at output ``k``."""
    order = np.argsort(res.node_x)
    p0 = res.position[0]
    return Profile(time=float(res.time[k]), node_x=res.node_x[order],
                   node_d=res.fe_displacement[k][order, :2],
                   node_v=res.fe_velocity[k][order, :2],
                   disk_x=p0[:, X].copy(), disk_y=p0[:, Y].copy(),
                   disk_d=res.position[k, :, :2] - p0[:, :2],
                   disk_v=res.velocity[k, :, :2])


def history(res: CoupledResults, disk: int) -> tuple[np.ndarray, np.ndarray]:
    """Time and displacement (n_out, 2) of one disk (0-based index)."""
    if not 0 <= disk < res.n_disks:
        raise ResultsError(f"{res.path}: no disk {disk + 1} (the run has {res.n_disks})")
    return res.time, res.position[:, disk, :2] - res.position[0, disk, :2]


def rigid_fit(x: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, float]:
    """Least-squares straight line through (x, d): coefficients (slope, intercept) and the
    largest deviation from it, the measure of a rigid-body (linear) profile."""
    if x.size < 2:
        return np.array([0.0, float(d[0]) if d.size else 0.0]), 0.0
    fit = np.polyfit(x, d, 1)
    return fit, float(np.max(np.abs(np.polyval(fit, x) - d)))


# --------------------------------------------------------------------------------------------
# Figures
# --------------------------------------------------------------------------------------------

def _new_figure(width=8.0, height=6.0, rows=1):
    """A figure of ``rows`` axes one above the other, sharing their x axis (the same abscissa
    or time in every figure of several rows): its numbers, and its label with the unit, are
    those of the bottom axes alone."""
    fig = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(fig)
    axes = [fig.add_subplot(rows, 1, 1)]
    axes += [fig.add_subplot(rows, 1, i + 1, sharex=axes[0]) for i in range(1, rows)]
    for ax in axes[:-1]:
        ax.tick_params(labelbottom=False)
    return fig, axes


def _unit(values, base: str) -> tuple[float, str]:
    vmax = float(np.max(np.abs(values))) if np.size(values) else 0.0
    for factor, prefix in ((1.0, ""), (1e3, "m"), (1e6, "µ"), (1e9, "n")):
        if vmax * factor >= 1.0 or vmax == 0.0:
            return factor, prefix + base
    return 1e9, "n" + base


def _time_text(t: float, times: np.ndarray) -> str:
    """A stored time in the unit of the run's times (s, ms or µs: beam._time_unit), as the
    other figures' titles give it."""
    factor, unit = _time_unit(times)
    return f"{t * factor:.6g} {unit}"


def _shade_overlap(ax, res: CoupledResults, label: bool = True):
    a, b = res.overlap_x()
    ax.axvspan(min(a, b), max(a, b), color=OVERLAP_COLOUR, zorder=0,
               label="overlap" if label else None)


def plot_profiles(res: CoupledResults, time: Optional[float] = None,
                  component: int = Y) -> Figure:
    """Displacement (top) and velocity (bottom) along x of the FE nodes (line) and the disks
    (markers; coupled disks filled) at the stored output nearest to ``time``: vertical
    components by default, horizontal with ``component = X``."""
    k = res.nearest_index(time)
    p = profile(res, k)
    name = "vertical" if component == Y else "horizontal"
    fig, (ax_d, ax_v) = _new_figure(8.0, 7.0, rows=2)
    coupled = np.zeros(res.n_disks, bool)
    coupled[res.coupled] = True
    for ax, fe, dem, base, what in ((ax_d, p.node_d, p.disk_d, "m", "displacement"),
                                    (ax_v, p.node_v, p.disk_v, "m/s", "velocity")):
        scale, unit = _unit(np.concatenate([fe[:, component], dem[:, component]]), base)
        _shade_overlap(ax, res)
        ax.plot(p.node_x, scale * fe[:, component], "-o", color=FE_COLOUR, ms=3,
                label="beam (FE nodes)")
        ax.plot(p.disk_x[~coupled], scale * dem[~coupled, component], "s", color=DEM_COLOUR,
                mfc="none", ms=5, label="disks")
        if coupled.any():
            ax.plot(p.disk_x[coupled], scale * dem[coupled, component], "s",
                    color=COUPLED_COLOUR, ms=5, label="coupled disks")
        ax.set_ylabel(f"{name} {what} [{unit}]")
        ax.grid(True, alpha=0.3)
    ax_v.set_xlabel("x at t = 0 [m]")
    ax_d.legend(loc="best", fontsize="small")
    ax_d.set_title(f"{res.title}\nt = {_time_text(p.time, res.time)}")
    return fig


#: Largest displacement of a configuration plot magnified automatically, as a fraction of the
#: model's size (the larger side of its box at t = 0): the deformation scale of Abaqus' and
#: of the beam plots (beam.auto_scale).
SCALE_FRACTION = 0.1
#: Largest change of the distance between the centres of two neighbouring disks that an
#: automatic magnification may draw, as a fraction of the smaller radius: magnified further,
#: the drawing would show disks overlapping or parted that are not (a quarter of a radius is
#: a visible part of a disk). Neighbours: disks whose gap is at most that much at t = 0 or at
#: the output drawn.
GAP_CHANGE = 0.25


def near_pairs(xy: np.ndarray, radius: np.ndarray, gap: float) -> tuple[np.ndarray, np.ndarray]:
    """(i, j), i < j: the pairs of disks (centres ``xy`` (n, 2), radii ``radius``) whose gap
    (distance of the centres minus the radii) is at most ``gap`` times the smaller radius;
    found in a grid of cells the size of the largest such distance, each disk against the
    disks of its cell and of the 8 around it (O(n) for disks of similar sizes)."""
    n = radius.size
    if n < 2:
        return np.zeros(0, int), np.zeros(0, int)
    reach = (2.0 + gap) * float(radius.max())
    cell = np.floor((xy - xy.min(axis=0)) / reach).astype(np.int64)
    # cell (cx, cy) -> cx rows + cy: the rows leave room for cy - 1 and cy + 1 of every cell
    rows = int(cell[:, 1].max()) + 3
    key = cell[:, 0] * rows + cell[:, 1]
    order = np.argsort(key, kind="stable")
    ordered = key[order]
    first, second = [], []
    # half of the 9 neighbouring cells: each pair of cells is looked at once
    for dx, dy in ((0, 0), (1, -1), (1, 0), (1, 1), (0, 1)):
        lo = np.searchsorted(ordered, key + dx * rows + dy, side="left")
        hi = np.searchsorted(ordered, key + dx * rows + dy, side="right")
        count = hi - lo
        within = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
        first.append(np.repeat(np.arange(n), count))
        second.append(order[np.repeat(lo, count) + within])
    i, j = np.concatenate(first), np.concatenate(second)
    i, j = np.minimum(i, j)[i != j], np.maximum(i, j)[i != j]
    pair = np.unique(i * n + j)
    i, j = pair // n, pair % n
    distance = np.hypot(*(xy[j] - xy[i]).T)
    keep = distance <= radius[i] + radius[j] + gap * np.minimum(radius[i], radius[j])
    return i[keep], j[keep]


def scale_limits(res: CoupledResults, k: int,
                 fraction: float = SCALE_FRACTION) -> tuple[float, float]:
    """(wanted, allowed) magnifications of the displacements at output ``k``: ``wanted``
    draws the largest displacement (beam nodes and disks) as ``fraction`` of the model's size
    (inf when nothing moves); ``allowed`` is the largest that draws no change of the distance
    between the centres of two neighbouring disks (`GAP_CHANGE`) above GAP_CHANGE times the
    smaller radius (inf when no neighbours' distance changes). A row or a stack of disks that
    bends as a body keeps its distances: it is magnified like the beam; disks that move
    against each other by a visible part of a radius are drawn at true scale."""
    p = profile(res, k)
    dmax = max(float(np.hypot(*p.node_d.T).max(initial=0.0)),
               float(np.hypot(*p.disk_d.T).max(initial=0.0)))
    wanted = fraction * res.size / dmax if dmax > 0.0 else np.inf
    start, now = res.position[0][:, :2], res.position[k][:, :2]
    pairs = [near_pairs(xy, res.radius, GAP_CHANGE) for xy in (start, now)]
    i, j = (np.concatenate(side) for side in zip(*pairs))
    change = np.abs(np.hypot(*(now[j] - now[i]).T) - np.hypot(*(start[j] - start[i]).T))
    moved = change > 0.0
    allowed = float(np.min(GAP_CHANGE * np.minimum(res.radius[i], res.radius[j])[moved]
                           / change[moved])) if moved.any() else np.inf
    return wanted, allowed


def auto_scale(res: CoupledResults, k: int, fraction: float = SCALE_FRACTION) -> float:
    """Displacement scale factor of a configuration plot (`scale_limits`): the wanted
    magnification, at most the allowed one, rounded down to 1, 2 or 5 times a power of ten;
    1 (true scale) when either is below 2 or nothing moves."""
    return _chosen_scale(*scale_limits(res, k, fraction))


def _chosen_scale(wanted: float, allowed: float) -> float:
    """The factor `auto_scale` chooses from the magnifications `scale_limits` gives."""
    raw = min(wanted, allowed)
    return magnification(raw)


def plot_configuration(res: CoupledResults, time: Optional[float] = None,
                       scale: Optional[float] = None) -> Figure:
    """The deformed configuration at the stored output nearest to ``time``: the beam through
    its displaced nodes, the disks as circles at their displaced centres (coupled disks in
    green), the initial beam dashed, the overlap shaded; displacements times ``scale``
    (default: auto_scale), the factor in the title and the legend (and, when the disks'
    relative motion keeps it below the wanted one, why: `scale_limits`)."""
    k = res.nearest_index(time)
    limited = False
    if scale is None:
        wanted, allowed = scale_limits(res, k)
        scale = _chosen_scale(wanted, allowed)
        limited = scale != _chosen_scale(wanted, np.inf)
    d = res.fe_displacement[k]
    p0 = res.position[0]
    centres = p0[:, :2] + scale * (res.position[k, :, :2] - p0[:, :2])
    # Figure height from the drawing's aspect ratio (equal axes).
    xs = np.concatenate([res.node_x + scale * d[:, X], centres[:, 0] - res.radius,
                         centres[:, 0] + res.radius])
    ys = np.concatenate([res.node_y + scale * d[:, Y], centres[:, 1] - res.radius,
                         centres[:, 1] + res.radius, res.node_y])
    pad = 0.04 * (xs.max() - xs.min())
    width = 9.0
    height = min(9.0, max(3.0, 1.6 + 7.8 * (ys.max() - ys.min() + 2 * pad) / (xs.max() - xs.min()
                                                                              + 2 * pad)))
    fig, (ax,) = _new_figure(width, height)
    _shade_overlap(ax, res)
    for a, b in res.connectivity:
        ax.plot(res.node_x[[a, b]], res.node_y[[a, b]], "--", color="0.6", lw=1)
        ax.plot(res.node_x[[a, b]] + scale * d[[a, b], X], res.node_y[[a, b]] + scale * d[[a, b], Y],
                "-", color=FE_COLOUR, lw=2.5, zorder=3)
    colours = np.array([DEM_COLOUR] * res.n_disks, dtype=object)
    colours[res.coupled] = COUPLED_COLOUR
    ax.add_collection(EllipseCollection(2 * res.radius, 2 * res.radius, 0.0, units="xy",
                                        offsets=centres, offset_transform=ax.transData,
                                        facecolors=(0, 0, 0, 0), edgecolors=list(colours),
                                        lw=1.2, zorder=2))
    ax.set_xlim(xs.min() - pad, xs.max() + pad)
    ax.set_ylim(ys.min() - pad, ys.max() + pad)
    magnified = "true scale" if scale == 1.0 else f"displacements × {scale:g}"
    ax.plot([], [], "--", color="0.6", lw=1, label="beam at t = 0")
    ax.plot([], [], "-", color=FE_COLOUR, lw=2.5, label=f"beam (deformed, {magnified})")
    ax.plot([], [], "o", mfc="none", color=DEM_COLOUR, label="disks")
    ax.plot([], [], "o", mfc="none", color=COUPLED_COLOUR, label="coupled disks")
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    fig.legend(loc="outside lower center", ncol=5, fontsize="small", frameon=False)
    more = "magnifying" if scale == 1.0 else "magnifying more"
    why = (f" ({more} would draw gaps between disks changed by over {GAP_CHANGE:g} R)"
           if limited else "")
    ax.set_title(f"{res.title}\nt = {_time_text(res.time[k], res.time)}, {magnified}{why}")
    return fig


def plot_histories(runs: Sequence[CoupledResults], disk: int, labels: Sequence[str],
                   component: int = Y) -> Figure:
    """Displacement (top) and velocity (bottom) history of one disk (0-based index; the same
    disk at the same abscissa) in several runs. ResultsError when a run has no such disk (a
    negative index would silently draw a disk counted from the end under the wrong number)."""
    for r in runs:
        n = r.velocity.shape[1]
        if not 0 <= disk < n:
            raise ResultsError(f"{r.path}: no disk {disk + 1} (the run has disks 1..{n})")
    fig, (ax_d, ax_v) = _new_figure(8.0, 6.5, rows=2)
    d_all = np.concatenate([history(r, disk)[1][:, component] for r in runs])
    v_all = np.concatenate([r.velocity[:, disk, component] for r in runs])
    sd, ud = _unit(d_all, "m")
    sv, uv = _unit(v_all, "m/s")
    for r, label in zip(runs, labels):
        t, d = history(r, disk)
        ax_d.plot(t * 1e3, sd * d[:, component], label=label)
        ax_v.plot(t * 1e3, sv * r.velocity[:, disk, component], label=label)
    name = "vertical" if component == Y else "horizontal"
    x0 = runs[0].position[0, disk, X]
    ax_d.set_ylabel(f"{name} displacement [{ud}]")
    ax_v.set_ylabel(f"{name} velocity [{uv}]")
    ax_v.set_xlabel("t [ms]")
    for ax in (ax_d, ax_v):
        ax.grid(True, alpha=0.3)
    ax_d.legend(loc="best", fontsize="small")
    ax_d.set_title(f"disk {disk + 1} (x = {x0:.3g} m)")
    return fig


def plot_compare_profiles(runs: Sequence[CoupledResults], labels: Sequence[str],
                          time: Optional[float] = None, component: int = Y,
                          zoom_run: Optional[int] = None) -> Figure:
    """Displacement (top) and velocity (bottom) along x of several runs at the stored output
    nearest to ``time``: beam as lines, disks as markers (all disks of every layer). With
    ``zoom_run``, the vertical axes span that run's values (with a margin) and the points of
    the other runs beyond them are drawn at the edge and labelled with their value."""
    fig, (ax_d, ax_v) = _new_figure(8.0, 7.0, rows=2)
    profiles = [profile(r, r.nearest_index(time)) for r in runs]

    def values(p, field):
        return np.concatenate([getattr(p, f"node_{field}")[:, component],
                               getattr(p, f"disk_{field}")[:, component]])

    _shade_overlap(ax_d, runs[0])
    _shade_overlap(ax_v, runs[0], label=False)
    markers = "soD^v"
    name = "vertical" if component == Y else "horizontal"
    for ax, field, base, what in ((ax_d, "d", "m", "displacement"), (ax_v, "v", "m/s", "velocity")):
        ref = values(profiles[zoom_run], field) if zoom_run is not None else \
            np.concatenate([values(p, field) for p in profiles])
        scale, unit = _unit(ref, base)
        lo, hi = float(ref.min()), float(ref.max())
        pad = 0.15 * max(hi - lo, 1e-300)
        lo, hi = lo - pad, hi + pad
        for i, (p, label) in enumerate(zip(profiles, labels)):
            colour = f"C{i}"
            node = getattr(p, f"node_{field}")[:, component]
            disk = getattr(p, f"disk_{field}")[:, component]
            shown = np.clip(disk, lo, hi) if zoom_run is not None else disk
            ax.plot(p.node_x, scale * (np.clip(node, lo, hi) if zoom_run is not None else node), "-",
                    color=colour, label=f"{label}: beam")
            ax.plot(p.disk_x, scale * shown, markers[i % 5], color=colour, mfc="none", ms=4,
                    label=f"{label}: disks")
            off = [(x, v, c) for x, v, c in zip(p.disk_x, disk, shown) if v != c]
            for x, v, c in off:
                ax.plot(x, scale * c, "v" if c <= lo else "^", color=colour, ms=7)
            if off:
                ax.text(0.5, 0.04 + 0.5 * i, "off scale, " + label + ":\n" + "\n".join(
                    f"disk at x = {x:.3g} m: {scale * v:.3g} {unit}" for x, v, _ in off),
                    transform=ax.transAxes, ha="center", va="bottom", fontsize="small",
                    color=colour, bbox=dict(facecolor="white", edgecolor=colour, alpha=0.9))
        if zoom_run is not None:
            ax.set_ylim(scale * lo, scale * hi)
        ax.set_ylabel(f"{name} {what} [{unit}]")
        ax.grid(True, alpha=0.3)
    ax_v.set_xlabel("x at t = 0 [m]")
    ax_d.legend(loc="best", fontsize="small")
    ax_d.set_title(f"t = {_time_text(profiles[0].time, runs[0].time)}")
    return fig


#: Per-step residual curves of the coupling figure: dataset, label.
RESIDUALS = (("position_residual", "|q - C u| [m]"),
             ("coordinate_residual", "|x - x0 - C(u - u0)| [m]"),
             ("velocity_residual", "velocity residual [m/s]"),
             ("g_norm", "‖g‖ before the multipliers [m/s]"))
#: Curves of the energy panel: the /coupling/energy terms summed, label (the FE side's name
#: replaces {body}).
ENERGY_CURVES = ((("fe_kinetic", "fe_strain"), "{body}: kinetic + strain"),
                 (("dem_kinetic", "dem_potential"), "disks: kinetic + potential"),
                 (("external_work",), "external work"),
                 (("contact_dissipation",), "dissipated in contacts"),
                 (("fe_damping", "numerical_dissipation"), "damping + numerical dissipation"),
                 (("balance",), "balance (0 = exact)"))


#: What the per-step panels of the coupling figure say when the file holds no step yet.
NO_STEP_YET = "no per-step record yet (written every 4096 steps and at the end)"


def _note_no_step_yet(ax, what: str) -> None:
    """Say on the axes that the per-step series ``what`` hold no step yet (`NO_STEP_YET`)."""
    ax.text(0.5, 0.5, f"{what}: {NO_STEP_YET}", transform=ax.transAxes, ha="center",
            va="center", fontsize="small", color="C3")


def _note_absent(ax, names) -> None:
    """Say on the axes which datasets the file lacks (nothing is drawn for them)."""
    if names:
        ax.text(0.01, 0.02, "not in the file: " + ", ".join(names), transform=ax.transAxes,
                fontsize="small", color="C3", va="bottom")


def _legend(ax) -> None:
    if ax.get_legend_handles_labels()[0]:
        ax.legend(loc="best", fontsize="small")


def plot_coupling(diag: CouplingDiagnostics) -> Figure:
    """Coupling diagnostics of a coupled run, beam or continuum: constraint residuals and
    sweeps of every step, multipliers at the outputs and their norm at every step, energy
    audit at the outputs. A dataset the file lacks is named on its panel, not drawn; so is
    the absence of any step in the per-step series (`NO_STEP_YET`: a run stopped before its
    4096th step), the panels then spanning the outputs' times."""
    fig, (ax_r, ax_l, ax_e) = _new_figure(8.0, 9.0, rows=3)
    e = diag.energy
    # no step yet: nothing to draw per step (empty curves would only fill the legends)
    steps = {} if diag.no_step_yet else diag.steps
    ft, ut = _time_unit(np.concatenate([diag.time, diag.energy.get("time", [])]))
    t = diag.step_time() * ft
    residuals = list(RESIDUALS)
    if diag.attrs.get("rotation", 0) == 1:
        residuals.append(("rotation_residual", "rotation residual [rad]"))
    for name, label in residuals:
        if name in steps:
            # a residual of exactly 0 (the first step of a run at rest) has no logarithm: a gap
            ax_r.semilogy(t, np.where(steps[name] > 0, steps[name], np.nan), label=label)
    if diag.no_step_yet:
        _note_no_step_yet(ax_r, "residuals, sweeps and ‖λ‖ of every step")
        ax_r.set_yticks([])
    else:
        _note_absent(ax_r, [name for name, _ in residuals + [("sweeps", "")]
                            if name not in steps])
    # the units of the residuals drawn (each in its legend label): m, m/s, rad
    units = [label.rsplit("[", 1)[1].rstrip("]") for name, label in residuals if name in steps]
    ax_r.set_ylabel(f"residual [{', '.join(dict.fromkeys(units))}]" if units else "residual")
    _legend(ax_r)
    if "sweeps" in steps:
        ax_s = ax_r.twinx()
        ax_s.plot(t, steps["sweeps"], color="0.5", lw=0.6)
        ax_s.set_ylabel("sweeps per step", color="0.4")
    n_rows = diag.lam.shape[1]
    for j in range(n_rows):
        ax_l.plot(diag.time * ft, diag.lam[:, j], lw=0.8,
                  label=f"λ: {n_rows} rows on the coupled disks, at the outputs" if j == 0
                  else None)
    if "lambda_norm" in steps:
        # with the mediator space, lambda_norm is the norm of the multipliers on the FE nodes,
        # not of the rows' forces on the disks
        ax_l.plot(t, steps["lambda_norm"], "k", lw=1.2,
                  label="‖λ_m‖ of every step (mediator multipliers on the FE nodes)"
                  if diag.mediator else "‖λ‖ of every step")
    # without a step, the empty per-step panel spans the outputs' times (the shared x axis)
    if not diag.no_step_yet:
        _note_absent(ax_l, [] if "lambda_norm" in steps else ["lambda_norm"])
    ax_l.set_ylabel("multipliers λ [N, N·m]" if diag.attrs.get("rotation", 0) == 1
                    else "multipliers λ [N]")
    _legend(ax_l)
    absent = []
    for names, label in ENERGY_CURVES:
        missing = [n for n in names if n not in e]
        if missing or "time" not in e:
            absent += missing
            continue
        style, what = {}, label.format(body=diag.body)
        if names == ("balance",):
            style = {"color": "k", "lw": 1.5}
            what += f"; largest |balance| {np.abs(e['balance']).max(initial=0.0):.2g} J"
        ax_e.plot(e["time"] * ft, sum(e[n] for n in names), label=what, **style)
    _note_absent(ax_e, absent + ([] if "time" in e else ["energy/time"]))
    ax_e.set_ylabel("energy [J]")
    ax_e.set_xlabel(f"t [{ut}]")
    _legend(ax_e)
    for ax in (ax_r, ax_l, ax_e):
        ax.grid(True, alpha=0.3)
    ax_r.set_title(f"{diag.title}\ncoupling of the {diag.body} and the disks")
    return fig


def _save_coupling(files: FigureFiles, diag: CouplingDiagnostics,
                   notes: Optional[list]) -> None:
    """Save <name>_coupling.png; a sentence in ``notes`` (when given) when its per-step
    panels are empty (`CouplingDiagnostics.no_step_yet`)."""
    files.save(plot_coupling(diag), "coupling")
    if diag.no_step_yet and notes is not None:
        notes.append(f"{files.stem}_coupling.png has no per-step curves: /coupling holds no "
                     "step (its per-step series are written every 4096 steps and at the end "
                     "of a run: a run stopped before its 4096th step has none); the "
                     "multipliers and the energy at the outputs are drawn")


def write_coupling(diag: CouplingDiagnostics, out_dir, dpi: int = 120,
                   notes: Optional[list] = None) -> list[str]:
    """Write <name>_coupling.png (`plot_coupling`) in ``out_dir``; return its path in a list.
    Per-step panels without a step get a sentence in ``notes``, when given."""
    files = FigureFiles(diag.path, out_dir, dpi)
    _save_coupling(files, diag, notes)
    return files.written


def write_all(res: CoupledResults, out_dir, time: Optional[float] = None,
              scale: Optional[float] = None, dpi: int = 120,
              notes: Optional[list] = None) -> list[str]:
    """Write the plots of one coupled run as PNG files in ``out_dir``; return their paths:
    <name>_profiles.png, <name>_configuration.png (at the output nearest to ``time``, default
    the last) and <name>_coupling.png (per-step panels without a step: a sentence in
    ``notes``, when given)."""
    files = FigureFiles(res.path, out_dir, dpi)
    files.save(plot_profiles(res, time), "profiles")
    files.save(plot_configuration(res, time, scale), "configuration")
    _save_coupling(files, res.coupling, notes)
    return files.written
