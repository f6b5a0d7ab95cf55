"""Load a MULTICOR results file (HDF5, layout in doc/output.md).

Every array is in h5py (C) order: nodal fields are ``(n_nodes, 3)`` with the columns
``u`` (x displacement), ``w`` (y displacement), ``theta`` (rotation about z); time series add
a first axis, one entry per stored output.

The loaders read the mesh, the times, the energy audits and the per-step series into numpy
arrays. The series whose size grows with the outputs times the nodes, disks or contacts
(the fields of a mesh, the disks' positions and velocities, the contact lists) are `Records`:
they read the part asked for when indexed (``res.position[k]`` reads output k only), so that
a plot of a few outputs of a cluster-sized run needs the memory of those outputs, not of the
file. A `Records` opens the file for each read and closes it after; the loaders leave no file
open.
"""
from __future__ import annotations

import argparse
import contextlib
import math
import os
import sys
from dataclasses import dataclass, field
from typing import Optional

import h5py
import numpy as np

#: Column of each DOF in nodal arrays.
U, W, THETA = 0, 1, 2


class ResultsError(Exception):
    """A results file is missing, unreadable or does not follow the documented layout."""


class FigureFiles:
    """Writes the PNG figures of one results file into ``out_dir`` as <stem>_<name>.png
    (`figure_stem`) and keeps their paths, in order, in ``written``."""

    def __init__(self, results_path, out_dir, dpi: int = 120):
        self.out_dir = os.fspath(out_dir)
        make_out_dir(self.out_dir)
        self.stem = figure_stem(results_path)
        self.dpi = dpi
        self.written: list[str] = []

    def save(self, fig, name: str, dpi: Optional[int] = None) -> None:
        path = os.path.join(self.out_dir, f"{self.stem}_{name}.png")
        save_figure(fig, path, self.dpi if dpi is None else dpi)
        self.written.append(path)


def make_out_dir(out_dir) -> None:
    """Create the folder of the figures (and its parents); ResultsError naming it when that
    fails (a file of that name, no permission, a read-only file system)."""
    if os.path.exists(out_dir) and not os.path.isdir(out_dir):
        raise ResultsError(f"the folder of the figures '{os.fspath(out_dir)}' is a file")
    try:
        os.makedirs(out_dir, exist_ok=True)
    except OSError as exc:
        raise ResultsError(f"cannot create the folder of the figures '{os.fspath(out_dir)}' "
                           f"({exc.strerror or exc})") from None


def save_figure(fig, path, dpi: int) -> None:
    """fig.savefig(path); ResultsError naming the file when it cannot be written."""
    try:
        fig.savefig(path, dpi=dpi)
    except OSError as exc:
        raise ResultsError(f"cannot write the figure '{os.fspath(path)}' "
                           f"({exc.strerror or exc})") from None


def finite_float(text: str) -> float:
    """argparse type of a time or scale option: a finite real number (nan and inf are
    refused as a usage error: no stored output is 'nearest' to nan, and a nan or infinite
    scale draws nothing or fails inside matplotlib)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a real number, got '{text}'") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"expected a finite real number, got '{text}'")
    return value


def scale_factor(text: str) -> float:
    """argparse type of --scale: a finite real number > 0 (0 would draw the undeformed shape
    labelled as deformed, a negative factor the displacements the wrong way round)."""
    value = finite_float(text)
    if value <= 0.0:
        raise argparse.ArgumentTypeError(f"expected a scale factor > 0, got '{text}'")
    return value


def file_contents(path) -> tuple[bool, bool, bool, bool]:
    """(has beam results, has particle results, is a coupled run, has a 2D continuum) of a
    results file; ResultsError saying what the file is when it is missing, not HDF5, a
    checkpoint or an FCLIB export."""
    path = os.fspath(path)
    # the other HDF5 files multicor writes (a checkpoint, an FCLIB export): _open_results says
    # what they are and where the results are
    with _open_results(path) as f:
        contents = ("fem/mesh" in f, "dem" in f, "coupling" in f, "continuum/mesh" in f)
        # a run killed before its first stored output leaves the root attributes and /summary
        status = unfinished_status(f)
        if (not any(contents) and status is not None
                and _decode_attrs(f.attrs).get("code_name") == "MULTICOR"):
            raise ResultsError(f"'{path}' is the {stopped_early(f)} (status: {status})")
        return contents


#: What the scripts say of the file of a run that stopped before its first stored output.
STOPPED_BEFORE_OUTPUT = "partial file of a run stopped before its first stored output: nothing to plot"
#: What they say of the file of a static or modal run that stopped before its solution.
STOPPED_BEFORE_SOLUTION = ("partial file of a run stopped before its solution was written: "
                           "nothing to plot")


def stopped_early(f) -> str:
    """What the scripts say of an open partial file without results: STOPPED_BEFORE_SOLUTION
    for a static or modal run (root attribute analysis), else STOPPED_BEFORE_OUTPUT."""
    if _decode_attrs(f.attrs).get("analysis") in ("static", "modal"):
        return STOPPED_BEFORE_SOLUTION
    return STOPPED_BEFORE_OUTPUT


def unfinished_status(f) -> Optional[str]:
    """The /summary status of an open results file whose run did not finish (finished = 0:
    a partial file); None for a finished run's file or one without /summary."""
    if "summary" not in f:
        return None
    attrs = _decode_attrs(f["summary"].attrs)
    if int(attrs.get("finished", 1)) != 0:
        return None
    return str(attrs.get("status", "")) or "unknown"


def no_output_error(f, path: str, dataset: str) -> ResultsError:
    """The error for an open results file whose time series ``dataset`` (e.g. 'dem/time')
    holds no record: saying so, and for a partial file that its run stopped before its first
    stored output."""
    status = unfinished_status(f)
    if status is not None:
        return ResultsError(f"'{path}' is the {STOPPED_BEFORE_OUTPUT} (/{dataset} holds none; "
                            f"status: {status})")
    return ResultsError(f"{path}: /{dataset} holds no stored output: nothing to plot")


def no_results_error(f, path: str, what: str) -> ResultsError:
    """The error for an open results file with a mesh but none of the results ``what`` names
    (e.g. '/continuum/static'): for a partial file, that its run stopped before writing them
    (a static or modal run is killed between its mesh and its solution), else that there is
    nothing to plot."""
    status = unfinished_status(f)
    if status is not None:
        return ResultsError(f"'{path}' is the {stopped_early(f)} (no {what}; status: {status})")
    return ResultsError(f"{path}: holds no {what}: nothing to plot")


def shape_error(f, path: str, name: str, got: tuple, want: tuple) -> ResultsError:
    """The error for a dataset ``name`` of shape ``got`` where ``want`` was expected (None: any
    extent). In a partial file whose datasets differ in their number of records only (the
    first axis), the run was killed between writing two of them: the message says so."""
    wanted = tuple("n" if s is None else s for s in want)
    message = f"{path}: dataset '/{name}' has shape {tuple(got)}, expected {wanted}"
    status = unfinished_status(f)
    if (status is not None and len(got) == len(want) and len(got) > 0
            and all(w is None or g == w for g, w in zip(got[1:], want[1:]))):
        message += (f"; '{path}' is the partial file of a stopped run (status: {status}): "
                    "the records of its last output are incomplete (the run was killed while "
                    "writing them): nothing to plot")
    return ResultsError(message)


def unused_time_note(requested: Optional[float], analysis: str) -> Optional[str]:
    """The note for a --time given for a static or modal run (one solution, no stored
    outputs in time): ignored; None otherwise."""
    if requested is None or analysis not in ("static", "modal"):
        return None
    holds = "one solution" if analysis == "static" else "mode shapes"
    return (f"--time {requested:g} s is ignored: it applies to dynamic runs only, and this is "
            f"a {analysis} run ({holds}, no stored outputs in time)")


def unused_scale_note(scale: Optional[float], path, drawn: bool) -> Optional[str]:
    """The note for a --scale given for a file none of whose figures magnifies displacements
    (``drawn`` False: particles only, a straight beam, whose deflection is drawn in length
    units, or a beam's mode shapes); None otherwise."""
    if scale is None or drawn:
        return None
    return (f"--scale {scale:g} is not used: '{os.fspath(path)}' has no deformed shape to "
            "magnify (frames, 2D continua and beam-coupled runs have one; a straight beam's "
            "deflection is drawn in length units)")


def outside_time_note(requested: Optional[float], times: Optional[np.ndarray]) -> Optional[str]:
    """The note for a requested snapshot time outside the stored outputs [t0, t_last] (the
    snapshot figures then show the first or the last one, the nearest); None when the time is
    inside, not given, or the run has no time series (static, modal)."""
    if requested is None or times is None or np.size(times) == 0:
        return None
    t0, t1 = float(np.min(times)), float(np.max(times))
    # the stored times are multiples of the step computed in binary: a requested time that
    # matches an end to 1e-9 of the run's span (far above that round-off, far below any
    # step) is that end, not outside
    tol = 1e-9 * max(abs(t0), abs(t1), t1 - t0)
    if t0 - tol <= requested <= t1 + tol:
        return None
    used = "the last one, t = %.6g s" % t1 if requested > t1 else "the first one, t = %.6g s" % t0
    return (f"--time {requested:g} s is outside the stored outputs [{t0:.6g}, {t1:.6g}] s: the "
            f"snapshot figures show {used}")


def figure_stem(path) -> str:
    """The name the figures of a results file start with: the deck name, also for the
    partial file of an unfinished run (``deck.h5.partial`` gives ``deck``) and the records of
    a failed run (``deck.h5.failed``)."""
    name = os.path.basename(os.fspath(path))
    for suffix in UNFINISHED_SUFFIXES:
        if name.endswith(suffix):
            name = name[:-len(suffix)]
    return os.path.splitext(name)[0]


#: What multicor appends to `<deck>.h5` for the file of a run that did not finish: a partial
#: file (running, stopped, killed) and the records of a run that failed in its time loop
#: (doc/output.md, Interrupted runs).
UNFINISHED_SUFFIXES = (".partial", ".failed")


def unfinished_note(path) -> Optional[str]:
    """What the plotting scripts print with the figures of a run that did not finish, from
    its file's name: a partial file or a failed run's records; None for a results file."""
    path = os.fspath(path)
    if path.endswith(".partial"):
        return (f"'{path}' is the partial file of a run that did not finish: the figures show "
                "the outputs stored so far")
    if path.endswith(".failed"):
        return (f"'{path}' holds the records of a run that failed (its /summary status says "
                "why): the figures show the outputs stored before the failure")
    return None


@dataclass
class Mesh:
    """FE mesh: deck node ids, coordinates [m] and element connectivity (0-based indices)."""

    node_id: np.ndarray        # (n_nodes,) int
    x: np.ndarray              # (n_nodes,) [m]
    y: np.ndarray              # (n_nodes,) [m]
    connectivity: np.ndarray   # (n_elements, 2) int, 0-based node indices

    @property
    def n_nodes(self) -> int:
        return int(self.node_id.size)

    def index_of(self, node_id: int) -> int:
        """Position of the node with deck id ``node_id``."""
        hits = np.flatnonzero(self.node_id == node_id)
        if hits.size == 0:
            raise ResultsError(f"no node with id {node_id} (ids: {_id_range(self.node_id)})")
        return int(hits[0])

    def is_straight_along_x(self, rtol: float = 1e-9) -> bool:
        """True when every node lies on one horizontal line (a straight beam along x)."""
        size = max(np.ptp(self.x), np.ptp(self.y), 1e-300)
        return bool(np.ptp(self.y) <= rtol * size)

    def end_nodes(self) -> np.ndarray:
        """Indices of the nodes that belong to exactly one element (free or supported ends)."""
        counts = np.bincount(self.connectivity.ravel(), minlength=self.n_nodes)
        return np.flatnonzero(counts == 1)


@dataclass
class Dynamic:
    """Stored outputs of a dynamic run."""

    time: np.ndarray           # (n_out,) [s]
    # the fields: Records, read on demand (module doc), or arrays of the same shape
    displacement: Records      # (n_out, n_nodes, 3) [m, m, rad]
    velocity: Records          # (n_out, n_nodes, 3) [m/s, m/s, rad/s]
    acceleration: Records      # (n_out, n_nodes, 3) [m/s^2, m/s^2, rad/s^2]

    def nearest_index(self, t: float) -> int:
        """Index of the stored output whose time is nearest to ``t`` (first one on a tie)."""
        if self.time.size == 0:
            raise ResultsError("the results hold no stored output")
        return int(np.argmin(np.abs(self.time - t)))


@dataclass
class Energy:
    """Energy audit of a dynamic run [J]; balance = K + S + D - W - (same at the start)."""

    time: np.ndarray
    kinetic: np.ndarray
    strain: np.ndarray
    external_work: np.ndarray
    damping: np.ndarray
    balance: np.ndarray


@dataclass
class Static:
    """Static solution."""

    displacement: np.ndarray   # (n_nodes, 3) [m, m, rad]
    reactions: np.ndarray      # (n_nodes, 3) [N, N, N.m]


@dataclass
class Modal:
    """Eigenmodes, lowest first."""

    omega: np.ndarray          # (n_modes,) [rad/s]
    frequency: np.ndarray      # (n_modes,) [Hz]
    shapes: np.ndarray         # (n_modes, n_nodes, 3), arbitrary scale
    #: one label per mode ('axial', 'bending', 'mixed', 'rigid': /modal/axial_fraction@kind);
    #: None for a file without them (an earlier build)
    kind: Optional[list] = None


@dataclass
class Results:
    """Everything in one results file; parts the run did not write are ``None``."""

    path: str
    attrs: dict                # root attributes as str (code_name, title, analysis, ...)
    mesh: Mesh
    dynamic: Optional[Dynamic] = None
    energy: Optional[Energy] = None
    static: Optional[Static] = None
    modal: Optional[Modal] = None
    summary: dict = field(default_factory=dict)

    @property
    def title(self) -> str:
        return self.attrs.get("title", "") or os.path.basename(self.path)

    @property
    def analysis(self) -> str:
        """'dynamic' when the file holds time series, else 'static' or 'modal' by what it
        holds ('' for none)."""
        if self.dynamic is not None:
            return "dynamic"
        return "static" if self.static is not None else "modal" if self.modal is not None else ""


def load_results(path) -> Results:
    """Read a results file. Raises ResultsError with a clear message when it is missing,
    not an HDF5 file, or lacks a dataset of the documented layout."""
    path = os.fspath(path)
    f = _open_results(path)
    with f:
        reader = _Reader(f, path)
        mesh = Mesh(node_id=reader.array("fem/mesh/node_id", ndim=1).astype(int),
                    x=reader.array("fem/mesh/coordinates", ndim=2, shape=(None, 2))[:, 0],
                    y=reader.array("fem/mesh/coordinates", ndim=2, shape=(None, 2))[:, 1],
                    connectivity=reader.array("fem/mesh/connectivity", ndim=2,
                                              shape=(None, 2)).astype(int) - 1)
        n = mesh.n_nodes
        if mesh.x.size != n:
            raise ResultsError(f"{path}: /fem/mesh/coordinates has {mesh.x.size} nodes, "
                               f"/fem/mesh/node_id {n}")
        if mesh.connectivity.size and (mesh.connectivity.min() < 0
                                       or mesh.connectivity.max() >= n):
            raise ResultsError(f"{path}: /fem/mesh/connectivity refers to nodes outside 1..{n}")
        res = Results(path=path, attrs=_decode_attrs(f.attrs), mesh=mesh)
        if "fem/time" in f:
            time = reader.array("fem/time", ndim=1)
            if time.size == 0:
                raise no_output_error(f, path, "fem/time")
            shape = (time.size, n, 3)
            res.dynamic = Dynamic(time=time,
                                  displacement=reader.records("fem/displacement", shape),
                                  velocity=reader.records("fem/velocity", shape),
                                  acceleration=reader.records("fem/acceleration", shape))
        if "energy" in f:
            time = reader.array("energy/time", ndim=1)
            parts = {name: reader.array(f"energy/{name}", shape=time.shape)
                     for name in ("kinetic", "strain", "external_work", "damping", "balance")}
            res.energy = Energy(time=time, **parts)
        if "static" in f:
            res.static = Static(displacement=reader.array("static/displacement", shape=(n, 3)),
                                reactions=reader.array("static/reactions", shape=(n, 3)))
        if "modal" in f:
            omega = reader.array("modal/omega", ndim=1)
            res.modal = Modal(omega=omega,
                              frequency=reader.array("modal/frequency", shape=omega.shape),
                              shapes=reader.array("modal/shapes", shape=(omega.size, n, 3)),
                              kind=_mode_kinds(f, omega.size))
        if "summary" in f:
            res.summary = _decode_attrs(f["summary"].attrs)
        if res.dynamic is None and res.static is None and res.modal is None:
            # the mesh is written first: a run killed before its solution or first output
            missing = {"static": "/static", "modal": "/modal", "dynamic": "/fem/time"}
            raise no_results_error(f, path, missing.get(res.attrs.get("analysis"),
                                                         "/fem/time, /static or /modal"))
    return res


def _mode_kinds(f, n_modes: int) -> Optional[list]:
    """The labels of /modal/axial_fraction@kind (one word per mode), or None when the file
    has none or not one per mode."""
    if "modal/axial_fraction" not in f:
        return None
    kind = f["modal/axial_fraction"].attrs.get("kind")
    if isinstance(kind, (bytes, np.bytes_)):
        kind = kind.decode("utf-8", errors="replace")
    words = str(kind).split() if kind is not None else []
    return words if len(words) == n_modes else None


def _open_results(path: str) -> h5py.File:
    """Open a results file for reading. Raises ResultsError, in one line, when it is missing
    (saying so when the run left a '.partial' or '.failed' file), a folder, not a readable HDF5 file, or one
    of the other HDF5 files multicor writes: a checkpoint or an FCLIB export (saying what it
    is and where the results are)."""
    path = os.fspath(path)
    if not os.path.exists(path):
        hint = ""
        if os.path.exists(path + ".partial"):
            hint = f" ('{path}.partial' exists: the run did not finish)"
        elif os.path.exists(path + ".failed"):
            hint = f" ('{path}.failed' exists: the run failed, and those are its records)"
        raise ResultsError(f"results file '{path}' does not exist{hint}")
    if os.path.isdir(path):
        raise ResultsError(f"'{path}' is a folder, not a results file: give the <deck name>.h5 "
                           "in it")
    try:
        f = h5py.File(path, "r")
    except OSError as exc:
        # HDF5's message spans lines (its 'time = ...' field ends with one): joined
        raise ResultsError(f"'{path}' is not a readable HDF5 file ({' '.join(str(exc).split())})"
                           ) from None
    try:
        if str(f.attrs.get("format", "")).startswith("MULTICOR checkpoint"):
            raise ResultsError(f"'{path}' is a MULTICOR checkpoint (for --restart), not a "
                               "results file: plot the <deck name>.h5 next to it")
        if "fclib_local" in f:
            raise ResultsError(f"'{path}' is a contact problem exported in FCLIB's format "
                               "([solver] fclib_step), not a results file")
    except BaseException:
        f.close()
        raise
    return f


def damaged_file_error(exc: BaseException, path) -> Optional[ResultsError]:
    """The ResultsError to report for an exception raised by h5py while reading `path`
    (an HDF5 error inside a file that opened: metadata of a run killed while HDF5 wrote
    them), or None when the exception did not come from h5py (a bug, raised as it is)."""
    tb = exc.__traceback__
    while tb is not None:
        module = tb.tb_frame.f_globals.get("__name__", "")
        if module == "h5py" or module.startswith("h5py."):
            break
        tb = tb.tb_next
    if tb is None and not type(exc).__module__.startswith("h5py"):
        return None
    if "doesn't exist" in str(exc):
        return None     # a missing object (a script asking for what the file lacks), not damage
    return ResultsError(f"'{os.fspath(path)}' is damaged: HDF5 cannot read part of it "
                        f"({str(exc).strip(chr(39))}). A run killed while HDF5 wrote the file "
                        "leaves it so; run the deck again (its checkpoint, if any, says "
                        "whether --restart can continue it)")


#: What a plotting script catches around reading a results file (report_read_error).
READ_ERRORS = (ResultsError, KeyError, RuntimeError, OSError, ValueError)


def report_read_error(prog: str, exc: BaseException, path) -> int:
    """Exit code 1 of script `prog` after printing its one-line message for `exc`, raised while
    reading the results file `path`: a ResultsError as it is, an h5py error as the file's
    damage (damaged_file_error); any other exception (a bug) is raised again."""
    error = exc if isinstance(exc, ResultsError) else damaged_file_error(exc, path)
    if error is None:
        raise exc
    print(f"{prog}: error: {error}", file=sys.stderr)
    return 1


#: Series that grow by step, not by output (their own count), or by event: never cut.
_NOT_OUTPUT_SERIES = ("dem/solver/", "dem/bonds/", "coupling/g_norm", "coupling/position_residual",
                      "coupling/velocity_residual", "coupling/rotation_residual",
                      "coupling/coordinate_residual", "coupling/lambda_norm", "coupling/sweeps",
                      "coupling/corrections")


def complete_records(f, name: str, data: np.ndarray) -> np.ndarray:
    """The records of dataset `name` (read as `data`) that belong to the outputs a killed
    run wrote whole. A run counts each output in /summary@outputs after flushing it (and
    flushes again); a kill inside an output's flush can leave that output's records partly
    written (doc/output.md, "Every output is flushed"). In the partial file of a run that did
    not finish, the series of stored outputs (extendible datasets, but the per-step and event
    series) are cut to that many records, and the contact lists of /dem/contacts to that
    output's offset. Other datasets, finished files and files without the count are returned
    as they are (`complete_cut`)."""
    if data.ndim == 0:
        return data
    cut = complete_cut(f, name)
    return data if cut is None else data[:cut]


def complete_cut(f, name: str) -> Optional[int]:
    """The end ``e`` such that ``data[:e]`` are the records of dataset `name` of the open file
    `f` that `complete_records` keeps, from the file's metadata (and one entry of
    /dem/contacts/offset); None when it keeps them all."""
    summary = f.get("summary")
    if summary is None or "outputs" not in summary.attrs or f[name].ndim == 0:
        return None
    if int(summary.attrs.get("finished", 1)) != 0:
        return None
    if f[name].maxshape[0] is not None or name.startswith(_NOT_OUTPUT_SERIES):
        return None
    n = int(summary.attrs["outputs"])
    if name == "dem/contacts/offset":
        return n + 1
    if name.startswith("dem/contacts/"):
        offset = f["dem/contacts/offset"]
        return int(offset[min(n, len(offset) - 1)]) if len(offset) else None
    return n


def complete_shape(f, name: str) -> tuple:
    """The shape of the records of dataset `name` that `complete_records` keeps, from the
    file's metadata: nothing is read but one entry of /dem/contacts/offset."""
    shape = tuple(f[name].shape)
    cut = complete_cut(f, name)
    if cut is None or not shape:
        return shape
    return (len(range(shape[0])[:cut]),) + shape[1:]


#: Largest block of a `Records` read at once by a reduction over all its records
#: (`abs_max`, `max_over_records`) [bytes]: 16 MiB, small beside a plot's own memory (a
#: configuration figure of 10^4 disks at 240 dpi takes about 100 MB) and large enough that a
#: series is read in few calls (a contact list of 10^8 entries in 50 blocks).
BLOCK_BYTES = 1 << 24


class Records:
    """A series of a results file read on demand: one of the datasets that grow with the
    outputs times the nodes, disks or contacts (module doc). Indexing reads the records it
    selects, as a numpy array of `dtype` (the values of numpy indexing): an integer or a slice
    on the first axis, then integers, slices or one increasing index array go to HDF5 as a
    selection; other index arrays and masks read the records the first index selects, then
    index them in memory. ``np.asarray(records)`` reads them all. The file is opened for
    each read and closed after it. `shape` is that of the records the loader kept (in a
    killed run's partial file, those of the outputs written whole: `complete_records`)."""

    def __init__(self, path: str, name: str, shape: tuple, dtype, source_dtype=None):
        #: results file
        self.path = path
        #: dataset, without the leading '/'
        self.name = name
        #: shape of the records kept
        self.shape = tuple(int(s) for s in shape)
        #: type of the values returned
        self.dtype = np.dtype(dtype)
        self._source_dtype = np.dtype(dtype if source_dtype is None else source_dtype)
        self._abs_max: Optional[float] = None

    @classmethod
    def of(cls, f, path: str, name: str, dtype=None) -> "Records":
        """The records of dataset `name` of the open results file `f` (at `path`) that
        `complete_records` keeps; values of the dataset's type unless `dtype` is given."""
        source = f[name].dtype
        return cls(path, name, complete_shape(f, name), source if dtype is None else dtype,
                   source)

    @property
    def ndim(self) -> int:
        return len(self.shape)

    @property
    def size(self) -> int:
        return int(np.prod(self.shape, dtype=np.int64))

    def __len__(self) -> int:
        if not self.shape:
            raise TypeError("len() of a 0-d series")
        return self.shape[0]

    def __repr__(self) -> str:
        return f"Records('{self.path}', '/{self.name}', shape={self.shape}, dtype={self.dtype})"

    def astype(self, dtype) -> "Records":
        """The same records, read as values of `dtype` (nothing is read now)."""
        return Records(self.path, self.name, self.shape, dtype, self._source_dtype)

    def __array__(self, dtype=None, copy=None):
        data = self[...]
        return data if dtype is None else data.astype(dtype, copy=False)

    def __iter__(self):
        for k in range(len(self)):
            yield self[k]

    def __getitem__(self, key):
        key = self._expand(key)
        if not key:
            key = (slice(None),)
        first = _normalized_index(key[0], self.shape[0])
        rest = tuple(_normalized_index(k, n, axis)
                     for axis, (k, n) in enumerate(zip(key[1:], self.shape[1:]), start=1))
        with self._dataset() as ds:
            if _selection(first, rest, self.shape):
                data = ds[(first,) + rest]
            else:
                lo, hi, local = _covering(first, self.shape[0])
                data = ds[lo:hi][(local,) + tuple(key[1:])]
        return self._convert(data)

    def abs_max(self) -> float:
        """Largest |value| of all the records (0 for none), read block by block
        (`BLOCK_BYTES`); kept for the next call."""
        if self._abs_max is None:
            top = 0.0
            for block in self._blocks():
                if block.size:
                    top = max(top, float(np.max(np.abs(block))))
            self._abs_max = top
        return self._abs_max

    def max_over_records(self, per_record) -> np.ndarray:
        """``np.max(per_record(values), axis=0)`` over all the records, read block by block
        (`BLOCK_BYTES`); `per_record` maps a block of records (first axis) to one value per
        record and entry, e.g. the displacement's length at each node."""
        top = None
        for block in self._blocks():
            if block.shape[0]:
                part = np.max(per_record(block), axis=0)
                top = part if top is None else np.maximum(top, part)
        if top is None:
            raise ValueError(f"/{self.name} holds no record")
        return top

    def _blocks(self):
        """The records in consecutive blocks of at most BLOCK_BYTES (one record at least),
        the file open while they are read."""
        record = max(self.dtype.itemsize, self._source_dtype.itemsize) * int(
            np.prod(self.shape[1:], dtype=np.int64))
        step = max(1, BLOCK_BYTES // max(record, 1))
        with self._dataset() as ds:
            for lo in range(0, self.shape[0], step):
                yield self._convert(ds[lo:min(lo + step, self.shape[0])])

    def _expand(self, key) -> tuple:
        """The key as a tuple of one index per axis at most (Ellipsis expanded)."""
        key = key if isinstance(key, tuple) else (key,)
        if any(k is None for k in key):
            raise IndexError(f"/{self.name}: np.newaxis is not supported on a series read on "
                             "demand (index np.asarray(...) or the records read)")
        dots = [i for i, k in enumerate(key) if k is Ellipsis]
        if len(dots) > 1:
            raise IndexError("an index can only have a single ellipsis ('...')")
        if dots:
            i = dots[0]
            key = key[:i] + (slice(None),) * (self.ndim - len(key) + 1) + key[i + 1:]
        if len(key) > self.ndim:
            raise IndexError(f"too many indices for /{self.name}: it has {self.ndim} "
                             f"dimensions but {len(key)} were indexed")
        return key

    def _convert(self, data):
        data = np.asarray(data)
        if data.dtype != self.dtype:
            data = data.astype(self.dtype)
        return data[()] if data.ndim == 0 else data

    @contextlib.contextmanager
    def _dataset(self):
        """The dataset, in the results file opened for one read: ResultsError when the file
        cannot be opened again or no longer holds the records the loader found."""
        try:
            f = h5py.File(self.path, "r")
        except OSError as exc:
            raise ResultsError(f"'{self.path}' cannot be read again to get /{self.name} "
                               f"({' '.join(str(exc).split())}): it was moved, removed or is "
                               "being rewritten since it was loaded") from None
        with f:
            ds = f.get(self.name)
            if (not isinstance(ds, h5py.Dataset) or tuple(ds.shape[1:]) != self.shape[1:]
                    or (self.shape and ds.shape[0] < self.shape[0])):
                got = "none" if not isinstance(ds, h5py.Dataset) else f"shape {tuple(ds.shape)}"
                raise ResultsError(f"'{self.path}' changed since it was loaded: /{self.name} "
                                   f"has {got}, {self.shape} when it was loaded (load it "
                                   "again)")
            yield ds


def _normalized_index(key, n: int, axis: int = 0):
    """The index of axis `axis` of a series, of length `n` (the first axis: the records
    kept): an integer made non-negative and checked, a slice of positive step bounded to the
    axis, an index array or a mask as a checked integer array."""
    if isinstance(key, (int, np.integer)):
        k = int(key)
        if not -n <= k < n:
            raise IndexError(f"index {k} is out of bounds for axis {axis} with size {n}")
        return k + n if k < 0 else k
    if isinstance(key, slice):
        start, stop, step = key.indices(n)
        if step > 0:
            return slice(start, max(start, stop), step)
        return key
    return _index_array(key, n, axis)


def _index_array(key, n: int, axis: int) -> np.ndarray:
    """An index array or a boolean mask along an axis of length `n`, as checked
    non-negative integers."""
    a = np.asarray(key)
    if a.dtype == bool:
        if a.shape != (n,):
            raise IndexError(f"boolean index of shape {a.shape} does not match axis {axis} "
                             f"of size {n}")
        return np.flatnonzero(a)
    if a.dtype.kind not in "iu":
        raise IndexError("only integers, slices, ellipsis and integer or boolean arrays are "
                         "valid indices")
    if a.size and (a.min() < -n or a.max() >= n):
        raise IndexError(f"index out of bounds for axis {axis} with size {n}")
    return np.where(a < 0, a + n, a)


def _selection(first, rest, shape) -> bool:
    """Whether HDF5 selects (first, *rest) as numpy would index: integers, slices of
    positive step, and at most one 1-D strictly increasing index array; none of them empty
    (HDF5 refuses an empty selection beside an index array), and the integers next to the
    array (numpy moves the array's axis to the front when a slice parts them; HDF5 keeps
    it in place)."""
    arrays, advanced = 0, []
    for axis, (k, n) in enumerate(zip((first,) + rest, shape)):
        if isinstance(k, int):
            advanced.append(axis)
            continue
        if isinstance(k, slice) and (k.step or 1) > 0:
            if len(range(n)[k]) == 0:
                return False
            continue
        if isinstance(k, np.ndarray) and k.ndim == 1 and k.size and np.all(np.diff(k) > 0):
            arrays += 1
            advanced.append(axis)
            continue
        return False
    if arrays == 1 and advanced[-1] - advanced[0] + 1 != len(advanced):
        return False
    return arrays <= 1


def _covering(first, n: int) -> tuple[int, int, object]:
    """(lo, hi, local): the range of records lo:hi that holds those the first index selects,
    and that index within the range."""
    if isinstance(first, int):
        return first, first + 1, 0
    if isinstance(first, slice):
        picked = range(n)[first]
        if len(picked) == 0:
            return 0, 0, slice(None)
        lo, hi = min(picked[0], picked[-1]), max(picked[0], picked[-1]) + 1
        stop = picked[-1] - lo - 1 if picked.step < 0 else picked[-1] - lo + 1
        return lo, hi, slice(picked[0] - lo, None if stop < 0 else stop, picked.step)
    if first.size == 0:
        return 0, 0, first
    lo, hi = int(first.min()), int(first.max()) + 1
    return lo, hi, first - lo


def abs_max(values) -> float:
    """Largest |value| of an array or a `Records` (block by block), 0 for none."""
    if isinstance(values, Records):
        return values.abs_max()
    values = np.asarray(values)
    return float(np.max(np.abs(values))) if values.size else 0.0


def max_over_records(values, per_record) -> np.ndarray:
    """``np.max(per_record(values), axis=0)`` of an array or a `Records` (block by block:
    `Records.max_over_records`)."""
    if isinstance(values, Records):
        return values.max_over_records(per_record)
    return np.max(per_record(np.asarray(values)), axis=0)


class _Reader:
    """Reads datasets with shape checks and messages that name the file and the dataset."""

    def __init__(self, f, path):
        self.f = f
        self.path = path

    def array(self, name, ndim=None, shape=None):
        self._check(name, ndim, shape)
        data = np.asarray(self.f[name][()], dtype=float if self.f[name].dtype.kind == "f"
                          else None)
        return complete_records(self.f, name, data)

    def records(self, name, shape):
        """The dataset as `Records` (read on demand), its shape checked from the metadata."""
        self._check(name, None, shape)
        return Records.of(self.f, self.path, name,
                          dtype=float if self.f[name].dtype.kind == "f" else None)

    def _check(self, name, ndim, shape):
        """ResultsError unless the records of dataset `name` that `complete_records` keeps
        have `ndim` dimensions and the `shape` (None = any extent), from the metadata."""
        if name not in self.f or not isinstance(self.f[name], h5py.Dataset):
            raise ResultsError(f"{self.path}: missing dataset '/{name}' (not a MULTICOR "
                               "results file, or one from another version)")
        got = complete_shape(self.f, name)
        if shape is not None:
            ndim = len(shape)
        if ndim is not None and len(got) != ndim:
            raise ResultsError(f"{self.path}: dataset '/{name}' has {len(got)} dimensions, "
                               f"expected {ndim}")
        if shape is not None and any(want is not None and g != want
                                     for g, want in zip(got, shape)):
            raise shape_error(self.f, self.path, name, got, shape)


class _Getter:
    """Reads a dataset and checks its shape (None = any extent); `kind` names the file in the
    message for a missing dataset. `records` gives a series read on demand instead."""

    def __init__(self, f, path, kind="results file"):
        self.f = f
        self.path = path
        self.kind = kind

    def __call__(self, name, shape):
        self._check(name, shape)
        return complete_records(self.f, name, np.asarray(self.f[name][()]))

    def records(self, name, shape) -> Records:
        """The dataset as `Records` (read on demand), its shape checked from the metadata."""
        self._check(name, shape)
        return Records.of(self.f, self.path, name)

    def _check(self, name, shape):
        """ResultsError unless dataset `name` exists and the records `complete_records` keeps
        have the `shape`, from the metadata."""
        if name not in self.f or not isinstance(self.f[name], h5py.Dataset):
            raise ResultsError(f"{self.path}: missing dataset '/{name}' (not a MULTICOR "
                               f"{self.kind}, or one from another version)")
        got = complete_shape(self.f, name)
        if len(got) != len(shape) or any(w is not None and g != w for g, w in zip(got, shape)):
            raise shape_error(self.f, self.path, name, got, shape)


def _decode_attrs(attrs) -> dict:
    out = {}
    for key, value in attrs.items():
        if isinstance(value, (bytes, np.bytes_)):
            value = value.decode("utf-8", errors="replace")
        elif isinstance(value, np.generic):
            value = value.item()
        out[key] = value
    return out


def _id_range(ids) -> str:
    ids = np.asarray(ids)
    if ids.size == 0:
        return "none"
    return f"{ids.min()}..{ids.max()}"
