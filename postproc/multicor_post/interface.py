"""The interface experiment (input/interface_shear.dat): two elastic blocks, a layer of disks
glued to each block in an Arlequin band, a normal pressure, then a tangential displacement of
the top block (doc/experiments.md, "The interface experiment").

Apparent friction. The tangential and normal resultants of a band are the sums of its
multipliers in x and y: the forces the block applies on the disks it glues. They, not the
reactions on the top edge, measure what crosses the disk layer: the reactions also carry the
inertia and the Rayleigh damping of the whole top block. With the schemes of the coupled step
(average acceleration, theta = 1/2) the multipliers alternate from step to step about their
mean; the deck stores every 5th step (odd), so that two successive outputs see the two phases:
their mean (`pair_mean`) removes the alternation. The apparent friction is that of the top
band, T / (-N) (T > 0 drags the disks along +x, N < 0 presses them); the bottom band carries
-T and -N (the disks' momentum changes little).

Slip: the top block's mean x displacement along its lower edge minus the bottom block's along
its upper edge (the mesh nodes of each block at that height).

Disks that slide without rolling over disks of the row below (square lattice, contact normal
vertical at the start): at a relative shift s the normal turns by phi = asin(s / 2R) and the
apparent friction is tan(atan(mu) - phi) (`sliding_over_disks`): mu at the start, then lower
as the upper row passes over the crest of the row below.
"""
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import LineCollection, PatchCollection, PolyCollection
from matplotlib.figure import Figure
from matplotlib.patches import Circle

from .continuum import element_polygons
from .results import ResultsError, _open_results, complete_records


class InterfaceRun:
    """The quantities of one run of the interface experiment, read from its HDF5 file."""

    def __init__(self, path):
        self.path = str(path)
        f = _open_results(self.path)
        with f:
            for name in ("coupling/lambda", "continuum/displacement", "dem/position"):
                if name not in f:
                    raise ResultsError(f"{self.path}: no {name} (not a coupled continuum run)")
            def read(name):
                # a killed run's partial file: the records of the outputs it wrote whole
                return complete_records(f, name, f[name][...])

            self.time = read("coupling/time")
            self.lam = read("coupling/lambda")
            self.row_dof = read("coupling/rows/dof")
            self.row_disk = read("coupling/rows/particle") - 1
            self.position = read("dem/position")
            self.radius = read("dem/particles/radius")
            self.x = read("continuum/mesh/coordinates")
            self.connectivity = read("continuum/mesh/connectivity")
            self.kind = read("continuum/mesh/kind")
            self.u = read("continuum/displacement")
            self.stress = read("continuum/stress")
            # the von Mises stress the run stored with the stresses (doc/output.md); None for a
            # file of a build before it, whose von Mises `plot_stress` computes (`von_mises`)
            self.stored_von_mises = read("continuum/von_mises") if "continuum/von_mises" in f else None
            self.sets = {k: f["continuum/sets/nodes"][k][...] - 1 for k in f["continuum/sets/nodes"]}
            self.balance = read("coupling/energy/balance")
            self.fe_balance = read("continuum/energy/balance")
            self.reaction_work = read("continuum/energy/reaction_work")
            # sigma_zz = nu (sigma_xx + sigma_yy) of a plane-strain element, 0 in plane stress:
            # the element's nu where it is in plane strain, else 0 (None: a file of a build
            # before /continuum/materials, which does not say the hypothesis)
            self.plane_strain_nu = None
            if "continuum/materials/poisson" in f and "continuum/mesh/material" in f:
                m = f["continuum/mesh/material"][...] - 1
                nu = f["continuum/materials/poisson"][...] * (f["continuum/materials/plane_strain"][...] == 1)
                self.plane_strain_nu = nu[m]
            self.contacts = None
            if "dem/contacts/offset" in f:
                self.contacts = {k: read(f"dem/contacts/{k}") for k in ("i", "j", "rn", "offset")}
        y0 = self.position[0, self.row_disk, 1]
        self.top_rows = y0 > 0.5 * (y0.min() + y0.max())

    def band_resultants(self):
        """(T_top, N_top, T_bottom, N_bottom) per output [N], pair-averaged."""
        out = []
        for band in (self.top_rows, ~self.top_rows):
            for dof in (1, 2):
                out.append(pair_mean(self.lam[:, band & (self.row_dof == dof)].sum(axis=1)))
        return tuple(out)

    def slip(self):
        """Top block's mean x displacement on its lower edge minus the bottom block's on its
        upper edge, per output [m]."""
        top, bottom = self.sets["top_block"], self.sets["bottom_block"]
        lower = top[np.isclose(self.x[top, 1], self.x[top, 1].min())]
        upper = bottom[np.isclose(self.x[bottom, 1], self.x[bottom, 1].max())]
        return self.u[:, lower, 0].mean(axis=1) - self.u[:, upper, 0].mean(axis=1)

    def apparent_friction(self, min_load=0.2):
        """(slip, mu_app) of the top band where its normal load exceeds min_load times its
        largest value (the ratio means nothing while the layer is unloaded)."""
        t_top, n_top, _, _ = self.band_resultants()
        s = self.slip()
        load = -n_top
        keep = load > min_load * load.max()
        return s[keep], t_top[keep] / load[keep]


def pair_mean(a):
    """Mean of each output with the one before (the first kept as it is)."""
    a = np.asarray(a, dtype=float)
    return np.concatenate([a[:1], 0.5 * (a[1:] + a[:-1])])


def sliding_over_disks(mu, s, radius):
    """tan(atan(mu) - asin(s / 2R)): rows of disks sliding without rolling (module doc)."""
    return np.tan(np.arctan(mu) - np.arcsin(np.clip(s / (2 * radius), -1, 1)))


def peak_and_residual(s, mu_app, last=1.0e-3):
    """Largest apparent friction once the top block moves (s > 1 um), and its mean over the
    last `last` metres of slip."""
    moving = s > 1.0e-6
    if not moving.any():
        return np.nan, np.nan
    peak = mu_app[moving].max()
    tail = s >= s.max() - last
    return peak, mu_app[tail].mean()


def von_mises(stress, plane_strain_nu=None):
    """Von Mises stress of (xx, yy, xy) [Pa]: sigma_zz = nu (xx + yy) in plane strain, with nu
    given per element (0 for an element in plane stress), or 0 when nu is None. For the files
    of builds before /continuum/von_mises, which store the stresses alone."""
    sxx, syy, sxy = stress[..., 0], stress[..., 1], stress[..., 2]
    szz = 0 if plane_strain_nu is None else plane_strain_nu * (sxx + syy)
    return np.sqrt(0.5 * ((sxx - syy) ** 2 + (syy - szz) ** 2 + (szz - sxx) ** 2) + 3 * sxy ** 2)


# --------------------------------------------------------------------------- figures


def plot_friction(curves, title, mu_theory=(), radius=None):
    """Apparent friction against slip, one curve per (label, InterfaceRun); dashed: the
    sliding-over-disks curve of each mu in mu_theory."""
    fig, ax = _figure((6.4, 4.2))
    for label, run in curves:
        s, mu = run.apparent_friction()
        ax.plot(s * 1e3, mu, label=label)
    for mu in mu_theory:
        s = np.linspace(0, max(run.slip().max() for _, run in curves), 200)
        ax.plot(s * 1e3, sliding_over_disks(mu, s, radius), "k--", lw=0.8)
    if mu_theory:
        ax.plot([], [], "k--", lw=0.8, label="tan(atan mu - asin(s/2R))")
    ax.set_xlabel("slip [mm]")
    ax.set_ylabel("apparent friction T / N (top band) [-]")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small")
    fig.tight_layout()
    return fig


def _figure(size):
    """A figure with one axes on the Agg canvas (no pyplot state)."""
    fig = Figure(figsize=size)
    FigureCanvasAgg(fig)
    return fig, fig.subplots()


def _element_polygons(run, k, scale=1.0):
    """Deformed element outlines at output k (list of (n, 2) arrays)."""
    return element_polygons(run.x, run.connectivity, run.kind, run.u[k], scale)


def plot_configuration(run, k, window=None):
    """Deformed mesh (true scale), disks as circles and the contact network (line width
    proportional to the normal force) at output k, around the interface."""
    fig, ax = _figure((8, 4.2))
    ax.add_collection(PolyCollection(_element_polygons(run, k), facecolor="none", edgecolor="0.6", lw=0.5))
    pos = run.position[k]
    glued = np.zeros(len(pos), bool)
    glued[run.row_disk] = True
    circles = [Circle((p[0], p[1]), r) for p, r in zip(pos, run.radius)]
    ax.add_collection(PatchCollection(circles, facecolor=np.where(glued, "#9ecae1", "#fdd0a2"),
                                      edgecolor="k", lw=0.4))
    if run.contacts is not None and k + 1 < len(run.contacts["offset"]):
        a, b = run.contacts["offset"][k], run.contacts["offset"][k + 1]
        i, j, rn = (run.contacts[n][a:b] for n in ("i", "j", "rn"))
        real = (i > 0) & (j > 0) & (rn > 0)
        if real.any():
            seg = np.stack([pos[i[real] - 1, :2], pos[j[real] - 1, :2]], axis=1)
            lw = 3.0 * rn[real] / rn[real].max()
            ax.add_collection(LineCollection(seg, colors="r", linewidths=lw))
    ax.set_aspect("equal")
    if window is None:
        y = pos[:, 1]
        pad = 4 * run.radius.max()
        window = (run.x[:, 0].min(), run.x[:, 0].max(), y.min() - pad, y.max() + pad)
    ax.set_xlim(window[0], window[1])
    ax.set_ylim(window[2], window[3])
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(f"t = {run.time[k] * 1e3:.2f} ms, slip {run.slip()[k] * 1e3:.2f} mm "
                 "(blue: glued disks; red: contact forces)")
    fig.tight_layout()
    return fig


def plot_stress(run, k, component="xy"):
    """Stress field in the blocks at output k: sigma_xy, or von Mises ('vm'), per element
    (centre values) on the deformed mesh [MPa]. The von Mises stress is the stored one
    (/continuum/von_mises), computed from the stresses and the materials for a file of an
    earlier build that lacks it."""
    s = run.stress[k]
    if component == "xy":
        values = s[:, 2]
    elif run.stored_von_mises is not None:
        values = run.stored_von_mises[k]
    else:
        values = von_mises(s, run.plane_strain_nu)
    fig, ax = _figure((7, 5))
    pc = PolyCollection(_element_polygons(run, k), array=values / 1e6, cmap="RdBu_r" if component == "xy"
                        else "viridis", edgecolor="none")
    if component == "xy":
        lim = np.abs(values).max() / 1e6
        pc.set_clim(-lim, lim)
    ax.add_collection(pc)
    ax.autoscale_view()
    ax.set_aspect("equal")
    label = "sigma_xy" if component == "xy" else \
        "von Mises" if run.stored_von_mises is not None or run.plane_strain_nu is not None else \
        "von Mises (sigma_zz taken as 0)"
    fig.colorbar(pc, ax=ax, label=label + " [MPa]")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(f"t = {run.time[k] * 1e3:.2f} ms, slip {run.slip()[k] * 1e3:.2f} mm")
    fig.tight_layout()
    return fig
