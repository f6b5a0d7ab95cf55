"""results.png of `scripts/multicor-sweep collect` (its plot function on rows as collect builds
them from results.csv): a word-valued swept key and a sweep without any value yet, the units
on its axes (of the keys from the deck reference, of the scalars from the results'
datasets); the grid file of `create --grid`."""
import importlib.machinery
import importlib.util
import math
import pathlib
import subprocess

import matplotlib.figure
import numpy as np
import pytest

SCRIPT = pathlib.Path(__file__).resolve().parents[2] / "scripts" / "multicor-sweep"


@pytest.fixture(scope="module")
def sweep_tool():
    loader = importlib.machinery.SourceFileLoader("multicor_sweep", str(SCRIPT))
    spec = importlib.util.spec_from_loader("multicor_sweep", loader)
    module = importlib.util.module_from_spec(spec)
    loader.exec_module(module)
    return module


@pytest.fixture
def saved(monkeypatch):
    """The figures plot() saves, with the path they were saved to (written as well)."""
    figures = []
    original = matplotlib.figure.Figure.savefig

    def keep(fig, path, *args, **kwargs):
        figures.append((fig, pathlib.Path(path)))
        return original(fig, path, *args, **kwargs)

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", keep)
    return figures


def manifest_of(key, values):
    return {"keys": [key],
            "points": [{"name": f"p{i + 1:03d}", "params": {key: v}}
                       for i, v in enumerate(values)]}


def test_a_word_valued_key_is_drawn_at_its_positions(sweep_tool, saved, tmp_path):
    # solver.method = block,nlgs,coarse: as numbers every x was nan and the figure was empty
    methods = ["block", "nlgs", "coarse"]
    manifest = manifest_of("solver.method", methods)
    rows = [{"point": p["name"], **p["params"], "sweeps": repr(s)}
            for p, s in zip(manifest["points"], [21.0, 21.0, 22.0])]
    sweep_tool.plot(tmp_path, manifest, rows, ["sweeps"], None)
    assert (tmp_path / "results.png").stat().st_size > 0
    (fig, path), = saved
    ax = fig.axes[0]
    line, = ax.get_lines()
    # positions 0, 1, 2 in the sweep's order and the values of results.csv: exact
    assert list(line.get_xdata()) == [0.0, 1.0, 2.0]
    assert list(line.get_ydata()) == [21.0, 21.0, 22.0]
    assert [t.get_text() for t in ax.get_xticklabels()] == methods


def test_numbers_stay_on_a_numeric_axis(sweep_tool, saved, tmp_path):
    manifest = manifest_of("time.step", ["2e-4", "1e-4"])
    rows = [{"point": p["name"], **p["params"], "vy": repr(v)}
            for p, v in zip(manifest["points"], [-2.0, -1.0])]
    sweep_tool.plot(tmp_path, manifest, rows, ["vy"], None)
    (fig, _), = saved
    line, = fig.axes[0].get_lines()
    assert list(line.get_xdata()) == [1e-4, 2e-4]     # sorted by the value, exact
    assert list(line.get_ydata()) == [-1.0, -2.0]


def test_no_figure_when_no_point_has_a_value(sweep_tool, saved, tmp_path, capsys):
    # nothing finished yet: the figure was an empty frame saved with exit 0; an earlier
    # results.png would describe another results.csv
    (tmp_path / "results.png").write_bytes(b"stale")
    manifest = manifest_of("time.step", ["1e-4", "2e-4"])
    rows = [{"point": p["name"], **p["params"], "vy": ""} for p in manifest["points"]]
    sweep_tool.plot(tmp_path, manifest, rows, ["vy"], None)
    assert saved == []
    assert not (tmp_path / "results.png").exists()
    assert "no plot: no point has a value of vy yet" in capsys.readouterr().err


def test_a_scalar_without_values_says_so_on_its_axis(sweep_tool, saved, tmp_path):
    manifest = manifest_of("time.step", ["1e-4", "2e-4"])
    rows = [{"point": p["name"], **p["params"], "vy": "1.0", "missing": ""}
            for p in manifest["points"]]
    sweep_tool.plot(tmp_path, manifest, rows, ["vy", "missing"], None)
    (fig, _), = saved
    texts = [t.get_text() for t in fig.axes[1].texts]
    assert texts == ["no point has a value of missing"]
    assert not fig.axes[0].texts
    assert all(math.isfinite(y) for y in fig.axes[0].get_lines()[0].get_ydata())


@pytest.mark.parametrize("case, reason", [("missing", "No such file or directory"),
                                          ("folder", "Is a directory"),
                                          ("binary", "can't decode byte 0xff")])
def test_a_grid_file_that_cannot_be_read_is_a_sweep_error(case, reason, sweep_tool, tmp_path):
    # create --grid FILE: each was a traceback (FileNotFoundError, IsADirectoryError,
    # UnicodeDecodeError)
    path = tmp_path / case
    if case == "folder":
        path.mkdir()
    elif case == "binary":
        path.write_bytes(b"\xff\xfe time.step = 1")
    with pytest.raises(sweep_tool.SweepError) as err:
        sweep_tool.read_grid_file(path)
    assert str(err.value).startswith(f"--grid {path}: cannot read it (")
    assert reason in str(err.value)


def test_a_grid_file_gives_its_keys_and_values(sweep_tool, tmp_path):
    path = tmp_path / "grid.txt"
    path.write_text("# comment\ntime.step = 1e-4, 2e-4\n\nsolver.method = block  # end\n")
    assert sweep_tool.read_grid_file(path) == [("time.step", ["1e-4", "2e-4"]),
                                               ("solver.method", ["block"])]


def test_the_axes_give_the_units_of_the_key_and_of_the_scalar(sweep_tool, saved, tmp_path):
    # 'vx' against 'time.step', without units: now those of the deck reference (the
    # manifest's) and of the results' dataset (collect's)
    manifest = manifest_of("time.step", ["1e-4", "2e-4"])
    manifest["units"] = {"time.step": "s"}
    rows = [{"point": p["name"], **p["params"], "vx": "1.0", "n": "2"}
            for p in manifest["points"]]
    sweep_tool.plot(tmp_path, manifest, rows, ["vx", "n"], None, {"vx": "m/s", "n": ""})
    (fig, _), = saved
    assert [ax.get_xlabel() for ax in fig.axes] == ["time.step [s]"] * 2
    # a count or a ratio has no unit: its name alone
    assert [ax.get_ylabel() for ax in fig.axes] == ["vx [m/s]", "n"]


def test_a_manifest_without_units_keeps_the_names(sweep_tool, saved, tmp_path):
    # a sweep created before the units were recorded
    manifest = manifest_of("time.step", ["1e-4", "2e-4"])
    rows = [{"point": p["name"], **p["params"], "vx": "1.0"} for p in manifest["points"]]
    sweep_tool.plot(tmp_path, manifest, rows, ["vx"], None)
    (fig, _), = saved
    assert (fig.axes[0].get_xlabel(), fig.axes[0].get_ylabel()) == ("time.step", "vx")


def test_a_scalar_has_the_unit_of_the_columns_it_selects(sweep_tool, tmp_path):
    h5py = pytest.importorskip("h5py")
    with h5py.File(tmp_path / "r.h5", "w") as f:
        f["dem/velocity"] = np.zeros((4, 2, 3))
        f["dem/velocity"].attrs["units"] = "m/s, m/s, rad/s"
        f["dem/energy/balance"] = np.zeros(4)
        f["dem/energy/balance"].attrs["units"] = "J/m"
        f["coupling/lambda"] = np.zeros((4, 14))
        f["coupling/lambda"].attrs["units"] = "N, N.m"
        f["dem/solver/sweeps"] = np.ones(4, np.int32)
    with h5py.File(tmp_path / "r.h5", "r") as f:
        units = {spec: sweep_tool.scalar_unit(f, "s=" + spec) for spec in (
            "dem/velocity[-1,1,0]", "dem/velocity[-1,1,2]", "max(dem/velocity[:,1,0:2])",
            "absmax(dem/velocity)", "dem/energy/balance[-1]", "coupling/lambda[-1,3]",
            "dem/solver/sweeps[0]", "dem/missing[0]")}
    assert units == {"dem/velocity[-1,1,0]": "m/s", "dem/velocity[-1,1,2]": "rad/s",
                     "max(dem/velocity[:,1,0:2])": "m/s",
                     "absmax(dem/velocity)": "m/s, rad/s",       # columns of both units
                     "dem/energy/balance[-1]": "J/m",
                     "coupling/lambda[-1,3]": "N, N.m",          # rows, not one per column
                     "dem/solver/sweeps[0]": "", "dem/missing[0]": ""}


def test_the_deck_reference_gives_the_units_of_the_values(sweep_tool, monkeypatch):
    reference = "\n".join([
        "### [time]", "",
        "| keyword | values | unit | default | allowed | description |",
        "|---|---|---|---|---|---|",
        "| `step` | `step` (real) | s | required | > 0 | Time step h. |",
        "| `scheme` | `scheme` (word) | | `newmark` | newmark, central | Scheme. |",
        "### [particles]", "",
        "| `gravity` | `gx` (real) | m/s^2 | 0 0 | | Gravity. |",
        "| | `gy` (real) | m/s^2 | | | |", ""])
    monkeypatch.setattr(sweep_tool.subprocess, "run", lambda *a, **k: subprocess.CompletedProcess(
        a, 0, stdout=reference, stderr=""))
    schema = sweep_tool.read_schema("multicor")
    assert schema["time"]["step"]["units"] == {"step": "s"}
    assert schema["time"]["scheme"]["units"] == {"scheme": ""}
    assert schema["particles"]["gravity"]["units"] == {"gx": "m/s^2", "gy": "m/s^2"}
    assert [f[0] for f in schema["particles"]["gravity"]["fields"]] == ["gx", "gy"]


def test_the_legend_gives_the_units_of_the_other_keys(sweep_tool, saved, tmp_path):
    manifest = {"keys": ["contacts.law[2].mu", "particles.gravity.gy"],
                "units": {"contacts.law[2].mu": "", "particles.gravity.gy": "m/s^2"},
                "points": [{"name": f"p{i}", "params": {"contacts.law[2].mu": mu,
                                                         "particles.gravity.gy": g}}
                           for i, (mu, g) in enumerate([("0.1", "-9.81"), ("0.2", "-9.81")])]}
    rows = [{"point": p["name"], **p["params"], "vx": "1.0"} for p in manifest["points"]]
    sweep_tool.plot(tmp_path, manifest, rows, ["vx"], None, {"vx": "m/s"})
    (fig, _), = saved
    assert fig.axes[0].get_xlabel() == "contacts.law[2].mu"      # a ratio: no unit
    assert [t.get_text() for t in fig.axes[0].get_legend().get_texts()] == [
        "particles.gravity.gy=-9.81 m/s^2"]
