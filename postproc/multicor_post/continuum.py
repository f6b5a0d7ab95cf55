"""2D continuum results (the /continuum group of doc/output.md): static, modal and dynamic
runs, alone or coupled to disks.

Figures (``write_all``):
- <name>_stress.png: sigma_xx, sigma_yy and sigma_xy per element (centre values, as stored) on
  the deformed mesh at one state (static: the solution; dynamic: the stored state nearest to
  the time asked, default the last), the undeformed outline in grey and, in a coupled run, the
  disks (their displacements from the first output magnified like the mesh's). Small
  displacements are magnified (the factor is in the title). A component zero to round-off
  (below ROUNDOFF of the largest, or `roundoff_stress`: a rigid motion's) is drawn white.
- <name>_continuum_energy.png (dynamic): the energy audit of /continuum/energy.
- <name>_history.png (dynamic): the displacement of one node against time (default: the node
  with the largest displacement over the stored states).
- <name>_modes.png (modal): the first mode shapes with their frequencies.
"""
from dataclasses import dataclass
import os
import textwrap
from typing import Optional

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import LineCollection, PatchCollection, PolyCollection
from matplotlib.figure import Figure
from matplotlib.patches import Circle

from .beam import _length_unit, _time_unit, magnification
from .results import (FigureFiles, Records, ResultsError, _open_results, complete_records,
                      complete_shape, max_over_records, no_output_error, no_results_error,
                      shape_error, unfinished_status)


@dataclass
class ContinuumResults:
    """The /continuum group of one results file. ``u`` has one row per state: the static
    solution (time None), or the stored states of a dynamic run; ``stress`` likewise (None
    for a modal run). Those of a dynamic run, and the disks' positions of a coupled one, are
    `Records`, read on demand (``res.u[k]`` reads state k); the rest are arrays."""
    path: str
    title: str
    analysis: str
    x: np.ndarray              # (n_nodes, 2) reference coordinates [m]
    connectivity: np.ndarray   # (n_elements, 4), 1-based, 0 after a triangle's third node
    kind: np.ndarray           # (n_elements,) 1 = T3, 2 = Q4
    time: Optional[np.ndarray]
    u: np.ndarray              # (n_states, n_nodes, 2) [m] (dynamic: Records)
    stress: Optional[np.ndarray]   # (n_states, n_elements, 3) [Pa] (dynamic: Records)
    energy: Optional[dict]
    frequency: Optional[np.ndarray] = None   # modal [Hz]
    disk_position: Optional[Records] = None   # coupled: (n_out, n_disks, 3)
    disk_radius: Optional[np.ndarray] = None
    disk_time: Optional[np.ndarray] = None
    walls: Optional[np.ndarray] = None   # coupled: (n_out, n_walls, 4) x1, y1, x2, y2
    young: Optional[np.ndarray] = None   # (n_elements,) [Pa]; None: a file without materials

    def nearest_index(self, t: Optional[float]) -> int:
        """The stored state nearest to time t (the last one for None or a static run)."""
        if t is None or self.time is None:
            return self.u.shape[0] - 1
        return int(np.argmin(np.abs(self.time - t)))


#: Characters of a title line that fit across a figure 8 inches wide (at matplotlib's 'large'
#: font about 6.6 points a character, 576 points): a longer line is wrapped.
TITLE_CHARACTERS = 80

#: Relative level below which a stress component is round-off of the largest one.
ROUNDOFF = 1e-9
#: Multiple of eps E |u|max / h (`roundoff_stress`) below which a state's stresses are zero to
#: round-off. The stresses of a rigid motion are D B u of nodal displacements that agree to
#: their rounding: 1 to 3.3 times eps E |u|max / h measured in input/coupled2d_block.dat over
#: its 100 steps (the displacements' rounding adds up step after step); 1e3 leaves room for
#: 10^5 times as many steps adding up at random, and stays at a strain of 2e-13 |u|max / h,
#: below what a solve in double precision resolves.
ROUNDOFF_STRAIN = 1e3

ENERGY_TERMS = ("kinetic", "strain", "external_work", "damping", "reaction_work", "balance")


def has_continuum(path) -> bool:
    """Whether the results file holds a 2D continuum; ResultsError when it is missing, not a
    results file or unreadable (`_open_results`)."""
    with _open_results(os.fspath(path)) as f:
        return "continuum/mesh/coordinates" in f


def load_continuum(path) -> ContinuumResults:
    """Read the /continuum group (and the disks of a coupled run); ResultsError when the file
    is missing, not a results file (`_open_results`) or lacks a dataset its kind of run must
    hold."""
    path = os.fspath(path)
    f = _open_results(path)
    with f:
        def need(name):
            if name not in f:
                raise ResultsError(f"{path}: missing dataset '/{name}' (not a MULTICOR continuum "
                                   "results file, or one from another version)")
            return complete_records(f, name, f[name][...])

        x = need("continuum/mesh/coordinates")
        connectivity = need("continuum/mesh/connectivity")
        kind = need("continuum/mesh/kind")
        title = str(f.attrs.get("title", os.path.basename(path)))
        analysis = str(f.attrs.get("analysis", ""))
        time = stress = energy = frequency = None
        if "continuum/static" in f:
            analysis = "static"
            u = need("continuum/static/displacement")[None]
            stress = need("continuum/static/stress")[None]
        elif "continuum/modal" in f:
            analysis = "modal"
            u = need("continuum/modal/shapes")
            frequency = need("continuum/modal/frequency")
        elif analysis in ("static", "modal"):
            # the mesh is written before the solution: a run killed in between
            raise no_results_error(f, path, f"/continuum/{analysis}")
        else:
            analysis = "dynamic"
            if "continuum/time" not in f and unfinished_status(f) is not None:
                raise no_results_error(f, path, "/continuum/time")
            time = need("continuum/time")
            if time.size == 0:
                raise no_output_error(f, path, "continuum/time")
            u = records(f, path, "continuum/displacement", time.size)
            stress = records(f, path, "continuum/stress", time.size)
            energy = {"time": need("continuum/energy/time")}
            energy.update({name: records(f, path, f"continuum/energy/{name}",
                                         energy["time"].size, lazy=False)
                           for name in ENERGY_TERMS})
        res = ContinuumResults(path, title, analysis, x, connectivity, kind, time, u, stress,
                               energy, frequency)
        if "continuum/materials/young" in f and "continuum/mesh/material" in f:
            material = need("continuum/mesh/material")
            young = need("continuum/materials/young")
            if material.shape == (connectivity.shape[0],) and material.size and \
                    1 <= material.min() and material.max() <= young.size:
                res.young = young[material - 1]
        if "dem/position" in f:
            res.disk_radius = need("dem/particles/radius")
            res.disk_time = need("dem/time")
            if res.disk_time.size == 0:
                raise no_output_error(f, path, "dem/time")
            res.disk_position = records(f, path, "dem/position", res.disk_time.size)
            if "dem/walls/position" in f:
                res.walls = records(f, path, "dem/walls/position", res.disk_time.size, lazy=False)
    return res


def records(f, path: str, name: str, n_out: int, lazy: bool = True):
    """The dataset ``name`` of the open results file ``path``, one record per stored output
    (in a killed run's partial file, those of the outputs it wrote whole: `complete_records`),
    as `Records` read on demand (``lazy``: the fields), else as an array (the energy terms):
    ResultsError (`shape_error`) unless it holds ``n_out`` of them, from the metadata, or when
    it is missing."""
    if name not in f:
        raise ResultsError(f"{path}: missing dataset '/{name}' (not a MULTICOR continuum "
                           "results file, or one from another version)")
    shape = complete_shape(f, name)
    if len(shape) == 0 or shape[0] != n_out:
        raise shape_error(f, path, name, shape, (n_out,) + shape[1:])
    return Records.of(f, path, name) if lazy else complete_records(f, name, f[name][...])


def element_polygons(x, connectivity, kind, u=None, scale=1.0):
    """Outlines of the elements (list of (3 or 4, 2) arrays) at x + scale u."""
    xy = x if u is None else x + scale * u
    return [xy[connectivity[e, :3 if kind[e] == 1 else 4] - 1] for e in range(connectivity.shape[0])]


def auto_scale(res: ContinuumResults, u: np.ndarray, fraction: float = 0.1) -> float:
    """Magnification of the displacements u (`beam.magnification`): the largest drawn as about
    `fraction` of the mesh's larger side, the factor rounded down to 1, 2 or 5 times a power
    of ten; 1 (true scale) when nothing moves or the displacements are already that large."""
    raw = mode_scale(res, u, fraction)
    return magnification(raw) if raw > 0.0 else 1.0


def mode_scale(res: ContinuumResults, u: np.ndarray, fraction: float = 0.1) -> float:
    """Factor drawing the largest of the displacements u as `fraction` of the mesh's larger
    side, larger or smaller than 1 (a mode shape has no true scale); 0 when nothing moves."""
    size = float(np.max(np.ptp(res.x, axis=0)))
    umax = float(np.max(np.hypot(u[:, 0], u[:, 1]))) if u.size else 0.0
    return fraction * size / umax if umax > 0.0 else 0.0


def shortest_side(res: ContinuumResults) -> float:
    """Length of the shortest side of the elements in the reference mesh [m]."""
    shortest = np.inf
    for corners in element_polygons(res.x, res.connectivity, res.kind):
        sides = np.hypot(*(np.roll(corners, -1, axis=0) - corners).T)
        shortest = min(shortest, float(sides.min()))
    return shortest


def roundoff_stress(res: ContinuumResults, u: np.ndarray) -> float:
    """Stress [Pa] below which a component of the state of displacements ``u`` is zero to
    round-off: ROUNDOFF_STRAIN eps E |u|max / h (E the largest Young modulus, h the shortest
    element side), D B u of nodal displacements known to their rounding eps |u|. 0 for a
    file without the materials (of a build before /continuum/materials) or a state at rest."""
    if res.young is None or not res.young.size or not u.size:
        return 0.0
    umax = float(np.max(np.hypot(u[:, 0], u[:, 1])))
    h = shortest_side(res)
    if umax == 0.0 or not 0.0 < h < np.inf:
        return 0.0
    return ROUNDOFF_STRAIN * np.finfo(float).eps * float(np.max(res.young)) * umax / h


def _figure(width=8.0, height=6.0):
    fig = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _stress_unit(values) -> tuple[float, str]:
    vmax = float(np.max(np.abs(values))) if np.size(values) else 0.0
    for factor, unit in ((1e-9, "GPa"), (1e-6, "MPa"), (1e-3, "kPa")):
        if vmax * factor >= 1.0:
            return factor, unit
    return 1.0, "Pa"


def _draw_disks(ax, res: ContinuumResults, k: int, scale: float):
    """The disks of a coupled run at the DEM output nearest to the continuum's state k, their
    displacements from the first output magnified by the mesh's `scale`, and its walls."""
    if res.disk_position is None:
        return
    j = res.disk_position.shape[0] - 1
    if res.time is not None and res.disk_time is not None:
        j = int(np.argmin(np.abs(res.disk_time - res.time[k])))
    start = res.disk_position[0]
    pos = start + scale * (res.disk_position[j] - start)
    ax.add_collection(PatchCollection([Circle((p[0], p[1]), r) for p, r in zip(pos, res.disk_radius)],
                                      facecolor="none", edgecolor="0.25", lw=0.4))
    if res.walls is not None and res.walls.shape[1] > 0:
        # the walls' displacements (driven walls) magnified like everything else
        walls = res.walls[0] + scale * (res.walls[j] - res.walls[0])
        ax.add_collection(LineCollection(walls.reshape(-1, 2, 2), colors="0.2", linewidths=2.0))


def plot_stress(res: ContinuumResults, time: Optional[float] = None,
                scale: Optional[float] = None) -> Figure:
    """sigma_xx, sigma_yy, sigma_xy per element on the deformed mesh (module doc)."""
    if res.stress is None:
        raise ResultsError(f"{res.path}: a {res.analysis} run stores no stress")
    k = res.nearest_index(time)
    u = res.u[k]
    stress = res.stress[k]      # the state's, read once
    s = scale if scale is not None else auto_scale(res, u)
    deformed = element_polygons(res.x, res.connectivity, res.kind, u, s)
    outline = element_polygons(res.x, res.connectivity, res.kind)
    fs, us = _stress_unit(stress)
    # one panel per component, as high as the body's shape asks (a slender one gets thin ones)
    corners = np.concatenate([res.x, res.x + s * u])
    extent = np.ptp(corners, axis=0)
    panel = float(np.clip(6.5 * extent[1] / max(extent[0], 1e-300) + 0.9, 1.6, 3.5))
    fig = _figure(height=1.0 + 3 * panel)
    axes = fig.subplots(3, 1, sharex=True)
    # a component below ROUNDOFF times the largest one (sigma_yy of a bar in uniaxial
    # tension), or below the rounding of a stress computed from these displacements (every
    # component of a rigid motion: `roundoff_stress`), is zero to round-off: drawn white over
    # a colour range of that level, not as a saturated pattern of noise
    overall = float(np.max(np.abs(stress))) * fs if stress.size else 0.0
    floor = max(ROUNDOFF * overall, roundoff_stress(res, u) * fs)
    zero = []
    for c, (ax, name) in enumerate(zip(axes, ("σ_xx", "σ_yy", "σ_xy"))):
        values = stress[:, c] * fs
        # colour limits at the 99th percentile of |value|, so that a few elements at a corner
        # singularity (a clamped edge) do not wash out the field; the colour bar says so
        top = float(np.max(np.abs(values)))
        lim = float(np.percentile(np.abs(values), 99)) if values.size else 0.0
        lim = lim if lim > 0 else (top or 1.0)
        noise = top <= floor and floor > 0.0
        if noise:
            lim = floor
            zero.append(top)
        ax.add_collection(PolyCollection(outline, facecolor="none", edgecolor="0.8", lw=0.3))
        pc = PolyCollection(deformed, array=values, cmap="RdBu_r", edgecolor="face", lw=0.2)
        pc.set_clim(-lim, lim)
        ax.add_collection(pc)
        _draw_disks(ax, res, k, s)
        ax.autoscale_view()
        ax.set_aspect("equal")
        ax.set_ylabel("y [m]")
        label = f"{name} [{us}]" + (f" (largest {top:.3g})" if top > lim * (1 + 1e-12) else "")
        if noise:
            label = (f"{name} [{us}] (zero to round-off: at most {top:.1g})" if top > 0.0
                     else f"{name} [{us}] (zero)")
        fig.colorbar(pc, ax=ax, label=label, extend="both" if top > lim * (1 + 1e-12) else "neither")
    axes[-1].set_xlabel("x [m]")
    when = ""
    if res.time is not None:
        ft, ut = _time_unit(res.time)
        when = f", t = {res.time[k] * ft:.6g} {ut}"
    magnified = "true scale" if s == 1.0 else f"displacements × {s:.3g}"
    # over the figure, not over the panels: those of a tall body are narrower than its title
    # (which the figure clipped); a title line longer than the figure is wide is wrapped
    title = f"{res.title}\nstress per element on the deformed mesh{when} ({magnified})"
    if len(zero) == 3:
        title += f"\nevery component zero to round-off (|σ| at most {max(zero) / fs:.1g} Pa)"
    fig.suptitle("\n".join(textwrap.fill(line, TITLE_CHARACTERS) for line in title.split("\n")))
    return fig


def default_node(res: ContinuumResults) -> int:
    """0-based index of the node with the largest displacement over the stored states (read
    block by block: `max_over_records`)."""
    return int(np.argmax(max_over_records(res.u, lambda u: np.hypot(u[..., 0], u[..., 1]))))


def plot_history(res: ContinuumResults, node: Optional[int] = None) -> tuple[Figure, int]:
    """u_x and u_y of a node against time (dynamic runs); node is the 1-based mesh index
    (default: `default_node`). Returns the figure and the 1-based node plotted."""
    if res.time is None:
        raise ResultsError(f"{res.path}: a {res.analysis} run has no time history")
    n = default_node(res) if node is None else node - 1
    if not 0 <= n < res.x.shape[0]:
        raise ResultsError(f"{res.path}: no node {node} (the mesh has {res.x.shape[0]} nodes)")
    ft, ut = _time_unit(res.time)
    # the unit of the beam plots (m, mm or µm by the largest value)
    u = res.u[:, n]     # the node's history, read once
    fl, ul = _length_unit(u)
    fig = _figure(height=4.5)
    ax = fig.subplots()
    ax.plot(res.time * ft, u[:, 0] * fl, label="u_x")
    ax.plot(res.time * ft, u[:, 1] * fl, label="u_y")
    ax.set_xlabel(f"time [{ut}]")
    ax.set_ylabel(f"displacement [{ul}]")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    ax.set_title(f"{res.title}\nnode {n + 1} at ({res.x[n, 0]:.4g}, {res.x[n, 1]:.4g}) m")
    return fig, n + 1


def plot_energy(res: ContinuumResults) -> Figure:
    """The energy audit of a dynamic run: kinetic, strain, works, damping and the balance
    residual (doc/output.md)."""
    if res.energy is None:
        raise ResultsError(f"{res.path}: a {res.analysis} run has no energy audit")
    e = res.energy
    ft, ut = _time_unit(e["time"])
    t = e["time"] * ft
    fig = _figure(height=6.5)
    ax, ax_b = fig.subplots(2, 1, sharex=True)
    labels = {"kinetic": "kinetic", "strain": "strain", "external_work": "work of the loads",
              "damping": "damping (dissipated)", "reaction_work": "work of the reactions"}
    for name, label in labels.items():
        ax.plot(t, e[name], lw=1.0, label=label)
    ax.set_ylabel("energy [J]")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    ax_b.plot(t, e["balance"], lw=1.0, color="k")
    ax_b.set_ylabel("balance residual [J]")
    ax_b.set_xlabel(f"time [{ut}]")
    ax_b.grid(True, alpha=0.3)
    ax.set_title(f"{res.title}\ncontinuum energy audit")
    return fig


def plot_modes(res: ContinuumResults, max_modes: int = 6,
               scale: Optional[float] = None) -> Figure:
    """The first mode shapes (mass-normalised, each magnified to a tenth of the mesh) with
    their frequencies."""
    if res.frequency is None:
        raise ResultsError(f"{res.path}: not a modal run")
    n = min(max_modes, res.u.shape[0])
    fig = _figure(height=2.0 + 1.6 * n)
    axes = np.atleast_1d(fig.subplots(n, 1, sharex=True))
    outline = element_polygons(res.x, res.connectivity, res.kind)
    for m, ax in enumerate(axes):
        s = scale if scale is not None else (mode_scale(res, res.u[m]) or 1.0)
        ax.add_collection(PolyCollection(outline, facecolor="none", edgecolor="0.8", lw=0.3))
        ax.add_collection(PolyCollection(element_polygons(res.x, res.connectivity, res.kind, res.u[m], s),
                                         facecolor="#c6dbef", edgecolor="0.2", lw=0.3))
        ax.autoscale_view()
        ax.set_aspect("equal")
        ax.set_ylabel("y [m]")
        ax.set_title(f"mode {m + 1}: {res.frequency[m]:.6g} Hz", fontsize="small")
    axes[-1].set_xlabel("x [m]")
    fig.suptitle(res.title)
    return fig


def write_all(res: ContinuumResults, out_dir, time: Optional[float] = None,
              scale: Optional[float] = None, node: Optional[int] = None) -> list[str]:
    """Write the figures of the module doc as PNG files in ``out_dir``; return their paths."""
    files = FigureFiles(res.path, out_dir)
    if res.analysis == "modal":
        files.save(plot_modes(res, scale=scale), "modes")
        return files.written
    files.save(plot_stress(res, time=time, scale=scale), "stress")
    if res.analysis == "dynamic":
        files.save(plot_energy(res), "continuum_energy")
        files.save(plot_history(res, node)[0], "history")
    return files.written
