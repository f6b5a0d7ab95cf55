"""The loaders read the series that grow with the outputs times the disks on demand: a plot
of a cluster-sized results file needs the memory of the outputs it draws, not of the file
(multicor_post.results.Records, doc/output.md "Plots").

A child process limits its address space (RLIMIT_AS) to what it has mapped after its imports
plus HEADROOM, then runs plot_results.py on a synthetic file whose series read whole need
several times HEADROOM; the values of the configuration figures it saves are checked against
a direct h5py read of the slices they draw."""
import json
import os
import re
import subprocess
import sys

import h5py
import numpy as np
import pytest
from synthetic_coupled import write_continuum_coupled, write_coupled
from synthetic_dem import N_OUT as DEM_OUT
from synthetic_dem import write_dem
from synthetic_large import write_large_dem

from multicor_post import continuum, coupled, particles, results
from multicor_post.particles import NOISE
from multicor_post.results import Records, ResultsError, load_results

POSTPROC = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

#: The synthetic run: disks, outputs and contacts per output. Read whole, /dem/position and
#: /dem/velocity take 2 x 5000 x 4000 x 3 x 8 B = 960 MB, the contact lists 1.5e7 x 52 B =
#: 780 MB; on disk the file is small (only OUTPUTS are written, the rest is HDF5's fill value,
#: read as values all the same).
N_DISKS, N_OUT, PER_OUTPUT = 4000, 5000, 3000
#: The outputs the figures draw (t = 0, the last; `--time` of output 1) and the one holding
#: the run's largest force.
OUTPUTS = (0, 1, N_OUT // 2, N_OUT - 1)
#: Address space the child may map beyond what its imports mapped [bytes]: 400 MiB. Reading
#: /dem/position whole (480 MB) exceeds it alone, so an eager loader fails at its first large
#: series. On demand, the figures need the outputs they draw (96 KB of positions, 156 KB of
#: contacts each), blocks of BLOCK_BYTES = 16 MiB for the run's largest force, and
#: matplotlib's own: a configuration figure of 4000 disks at 240 dpi is 1920 x 1440 RGBA
#: (11 MB) with its renderer's buffers. Measured (VmPeak beyond the imports, the child's
#: report): plot_results.py on this file 88 MB, on a file of the same disks with 4 outputs
#: 70 MB; the whole child, three configuration figures, about 140 MB (144 MB with matplotlib
#: 3.11.2, numpy 2.4.6), a third of the limit: the test does not depend on the details of a
#: matplotlib or numpy version.
HEADROOM = 400 * 2**20

CHILD = r"""
import json, os, resource, sys
sys.path.insert(0, sys.argv[1])
import numpy as np
from matplotlib.collections import EllipseCollection, LineCollection
import plot_results
from multicor_post import results


def vm(key):
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith(key + ":"):
                return int(line.split()[1]) * 1024


path, out, headroom = sys.argv[2], sys.argv[3], int(sys.argv[4])
# the values the configuration figures saved draw: at t = 0 (start), the last output (last)
# and the --time of output 1 (t1)
plotted = {}
draw = results.save_figure
CONFIGURATIONS = {"large_particles_start.png": "start", "large_particles.png": "last",
                  os.path.join("t1", "large_particles.png"): "t1"}


def save_figure(fig, name, dpi):
    key = CONFIGURATIONS.get(os.path.relpath(name, out))
    if key is None and os.path.dirname(name) == os.path.join(out, "t1"):
        return      # the series of the run with --time: drawn by the first run byte for byte
    draw(fig, name, dpi)
    if key is not None:
        ax = fig.axes[0]
        disks = next(c for c in ax.collections if isinstance(c, EllipseCollection))
        forces = next(c for c in ax.collections
                      if isinstance(c, LineCollection) and c.get_capstyle() == "round")
        plotted[f"offsets_{key}"] = disks.get_offsets()
        plotted[f"segments_{key}"] = np.array(forces.get_segments())
        plotted[f"widths_{key}"] = np.asarray(forces.get_linewidths())
        plotted[f"title_{key}"] = np.array(ax.get_title())


results.save_figure = save_figure
base = vm("VmSize")
resource.setrlimit(resource.RLIMIT_AS, (base + headroom, base + headroom))
try:
    rc = plot_results.main([path, "--out", out])
    rc_time = plot_results.main([path, "--out", os.path.join(out, "t1"), "--time", sys.argv[5]])
    np.savez(os.path.join(out, "plotted.npz"), **plotted)
except MemoryError:
    print(json.dumps({"error": "MemoryError"}))
    sys.exit(3)
print(json.dumps({"rc": rc, "rc_time": rc_time, "beyond_imports": vm("VmPeak") - base}))
"""


@pytest.mark.skipif(not os.path.exists("/proc/self/status"), reason="needs Linux's /proc")
def test_plots_of_a_large_file_stay_within_a_memory_limit(tmp_path):
    path = write_large_dem(tmp_path / "large.h5", N_DISKS, N_OUT, PER_OUTPUT, only=OUTPUTS)
    out = tmp_path / "out"
    with h5py.File(path, "r") as f:
        t1 = float(f["dem/time"][1])
    # one thread: a BLAS thread pool would map its buffers after the measured imports
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MPLBACKEND="Agg")
    proc = subprocess.run([sys.executable, "-W", "error", "-c", CHILD, POSTPROC, str(path),
                           str(out), str(HEADROOM), repr(t1)],
                          capture_output=True, text=True, env=env, timeout=600)
    assert proc.returncode == 0, f"child failed ({proc.returncode}): {proc.stdout}{proc.stderr}"
    report = json.loads(proc.stdout.strip().splitlines()[-1])
    assert report["rc"] == 0 and report["rc_time"] == 0, report
    for name in ("particles_start", "particles", "dem_energy", "solver"):
        assert (out / f"large_{name}.png").stat().st_size > 0
    assert (out / "t1" / "large_particles.png").stat().st_size > 0
    plotted = np.load(out / "plotted.npz")
    assert sorted(plotted.files) == sorted(f"{name}_{key}" for key in ("start", "t1", "last")
                                           for name in ("offsets", "segments", "widths", "title"))
    # the values drawn in the configurations saved, from the slices the figures need, read
    # directly
    with h5py.File(path, "r") as f:
        offset = f["dem/contacts/offset"][...]
        run_max = float(np.max(np.abs(f["dem/contacts/rn"][...])))
        for k, key in ((0, "start"), (1, "t1"), (N_OUT - 1, "last")):
            pos = f["dem/position"][k]
            s = slice(int(offset[k]), int(offset[k + 1]))
            i, j, rn = f["dem/contacts/i"][s], f["dem/contacts/j"][s], f["dem/contacts/rn"][s]
            assert np.array_equal(plotted[f"offsets_{key}"], pos[:, :2])
            carrying = np.abs(rn) > NOISE * run_max
            # the round-off cut depends on the force at output N_OUT // 2: some drawn, some not
            assert 0 < np.count_nonzero(carrying) < rn.size
            segments = np.stack([pos[i[carrying] - 1, :2], pos[j[carrying] - 1, :2]], axis=1)
            assert np.array_equal(plotted[f"segments_{key}"], segments)
            # widths proportional to |r_n|: ratios of stored values, to round-off (1e-12)
            widths = plotted[f"widths_{key}"]
            np.testing.assert_allclose(widths / widths.max(),
                                       np.abs(rn[carrying]) / np.abs(rn[carrying]).max(),
                                       rtol=1e-12)
            assert (f"{rn.size} contacts ({np.count_nonzero(carrying)} carrying a force)"
                    in str(plotted[f"title_{key}"]))


def _series_file(path, finished=True):
    """A results file with one series (6, 4, 3) of values 100 k + 10 n + c (output k, node n,
    column c), extendible like multicor's; a partial file (finished = 0) whose /summary
    counts 4 outputs written whole."""
    data = (100 * np.arange(6)[:, None, None] + 10 * np.arange(4)[None, :, None]
            + np.arange(3)[None, None, :]).astype(float)
    with h5py.File(path, "w") as f:
        f.create_dataset("fem/displacement", data=data, chunks=(1, 4, 3), maxshape=(None, 4, 3))
        f.create_dataset("summary/steps", data=np.zeros(1))
        f["summary"].attrs["finished"] = np.int32(1 if finished else 0)
        f["summary"].attrs["outputs"] = np.int32(4)
    return path, data


KEYS = [0, -1, 3, slice(None), slice(1, 3), slice(None, None, 2), slice(None, None, -1),
        slice(-2, None), (slice(None), 2, 1), (2, slice(None), slice(None, 2)), (Ellipsis, 0),
        (1, Ellipsis), (slice(None), np.array([0, 2])), (slice(None), [3, 1]),
        (slice(None), np.array([True, False, True, False]), -1), np.array([3, 0, 0]),
        np.array([True, False, True, True]), (-1, -1, -1), (slice(None), slice(None, None, -2)),
        # numpy moves an index array's axis to the front when a slice parts it from an integer
        # (HDF5 keeps it in place); an empty slice beside a mask (HDF5 refuses the selection)
        (1, slice(None), [0, 1]), (slice(2, 2), np.array([True, False, True, True])),
        (1, [0, 2], slice(None)), (slice(3, 1), 0)]


@pytest.mark.parametrize("finished", [True, False])
def test_records_index_like_numpy(tmp_path, finished):
    path, data = _series_file(tmp_path / "s.h5", finished)
    with h5py.File(path, "r") as f:
        rec = Records.of(f, str(path), "fem/displacement")
    kept = data if finished else data[:4]       # a partial file: the outputs written whole
    assert rec.shape == kept.shape and len(rec) == kept.shape[0] and rec.ndim == 3
    assert np.array_equal(np.asarray(rec), kept)
    for key in KEYS:
        try:
            want = kept[key]
        except IndexError:          # a mask of 4 outputs in the finished file of 6
            with pytest.raises(IndexError):
                rec[key]
            continue
        got = rec[key]
        assert np.shape(got) == want.shape and np.array_equal(got, want), key
    assert np.array_equal(rec.astype(int)[1], kept[1].astype(int)) and rec.astype(int)[1].dtype == int
    with pytest.raises(IndexError, match="out of bounds for axis 0 with size"):
        rec[kept.shape[0]]
    with pytest.raises(IndexError, match="axis 2"):
        rec[0, 0, 3]


def test_records_reductions_read_block_by_block(tmp_path, monkeypatch):
    path, data = _series_file(tmp_path / "s.h5")
    data[2, 1, 0] = -1e4
    with h5py.File(path, "r+") as f:
        f["fem/displacement"][2, 1, 0] = -1e4
        rec = results.Records.of(f, str(path), "fem/displacement")
    # blocks of one record (12 values of 8 bytes): the largest in record 2 of 6
    monkeypatch.setattr(results, "BLOCK_BYTES", 96)
    assert rec.abs_max() == results.abs_max(data) == 1e4
    norm = lambda d: np.hypot(d[..., 0], d[..., 1])  # noqa: E731
    assert np.array_equal(results.max_over_records(rec, norm), np.max(norm(data), axis=0))


def test_records_of_a_file_changed_since_loading(tmp_path):
    path, _ = _series_file(tmp_path / "s.h5")
    with h5py.File(path, "r") as f:
        rec = Records.of(f, str(path), "fem/displacement")
    with h5py.File(path, "a") as f:
        f["fem/displacement"].resize((2, 4, 3))
    with pytest.raises(ResultsError, match=r"changed since it was loaded: /fem/displacement has "
                                           r"shape \(2, 4, 3\), \(6, 4, 3\) when it was loaded"):
        rec[0]
    os.remove(path)
    with pytest.raises(ResultsError, match="cannot be read again to get /fem/displacement"):
        rec[0]


def _reshape(path, name, shape):
    """Replace dataset `name` of the file by zeros of `shape`."""
    with h5py.File(path, "a") as f:
        dtype = f[name].dtype
        del f[name]
        f.create_dataset(name, data=np.zeros(shape, dtype))
    return path


def test_series_read_on_demand_keep_their_shape_checks(tmp_path, cantilever_file):
    """A series of the wrong shape is refused when the file is loaded, from its metadata,
    with the message of a series read whole."""
    cases = [
        (particles.load_dem, write_dem(tmp_path / "d.h5"), "dem/velocity", (DEM_OUT, 5, 2),
         f"({DEM_OUT}, 5, 2), expected ({DEM_OUT}, 5, 3)"),
        (particles.load_dem, write_dem(tmp_path / "c.h5"), "dem/contacts/rn", (3,),
         "(3,), expected (12,)"),
        (load_results, cantilever_file(), "fem/acceleration", (11, 9, 2),
         "(11, 9, 2), expected (11, 9, 3)"),
        (coupled.load_coupled, write_coupled(tmp_path / "b.h5"), "fem/velocity",
         (DEM_OUT, 3, 3), f"({DEM_OUT}, 3, 3), expected ({DEM_OUT}, 4, 3)"),
        (continuum.load_continuum, write_continuum_coupled(tmp_path / "s.h5"),
         "continuum/stress", (3, 2, 3), f"(3, 2, 3), expected ({DEM_OUT}, 2, 3)"),
    ]
    for load, path, name, shape, message in cases:
        _reshape(path, name, shape)
        with pytest.raises(ResultsError, match=rf"dataset '/{name}' has shape {re.escape(message)}"):
            load(path)
