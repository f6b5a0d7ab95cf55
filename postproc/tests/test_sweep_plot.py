"""results.png of `scripts/multicor-sweep collect` (its plot function on rows as collect builds
them from results.csv): a word-valued swept key and a sweep without any value yet; the grid
file of `create --grid`."""
import importlib.machinery
import importlib.util
import math
import pathlib

import matplotlib.figure
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
