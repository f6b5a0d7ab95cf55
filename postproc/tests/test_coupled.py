"""Tests of the coupled-results loader and figures (multicor_post.coupled), of
plot_results.py on a coupled file and of plot_experiments.py, on synthetic files whose
fields are known in closed form (synthetic_coupled)."""
import os

import numpy as np
import pytest

import plot_experiments
import plot_results
from multicor_post import coupled
from multicor_post.results import ResultsError
from synthetic import cantilever_layout, write_results
from synthetic_coupled import (COUPLED, DISK_X, NODE_X, OVERLAP, V, beam_w, disk_dy,
                               write_coupled)
from synthetic_dem import H, N_OUT, R, STEPS_PER_OUT

# Values written as float64 and read back: exact; derived ones (differences of positions
# of O(0.1 m)): a few ulps of 0.2.
EXACT = 0.0
ULPS = 8 * np.spacing(0.2)


@pytest.fixture
def coupled_file(tmp_path):
    return write_coupled(tmp_path / "coupled.h5")


def test_loader_reads_the_three_parts_with_zero_based_coupled_disks(coupled_file):
    res = coupled.load_coupled(coupled_file)
    assert res.n_disks == DISK_X.size
    assert res.time.shape == (N_OUT,)
    assert res.fe_displacement.shape == (N_OUT, NODE_X.size, 3)
    assert res.coupling.lam.shape == (N_OUT, 2 * COUPLED.size)
    np.testing.assert_array_equal(res.coupled, COUPLED - 1)
    np.testing.assert_allclose(res.overlap, OVERLAP, rtol=0, atol=EXACT)
    assert res.coupling.steps["g_norm"].size == (N_OUT - 1) * STEPS_PER_OUT
    assert res.summary["wall_seconds"] == 0.25
    assert res.title == "synthetic coupled"


def test_profile_gives_displacements_from_the_initial_positions(coupled_file):
    res = coupled.load_coupled(coupled_file)
    k = 2
    p = coupled.profile(res, k)
    np.testing.assert_allclose(p.node_d[:, 1], beam_w(NODE_X, k), rtol=0, atol=EXACT)
    np.testing.assert_allclose(p.disk_d[:, 1], disk_dy(DISK_X, k), rtol=0, atol=ULPS)
    np.testing.assert_allclose(p.disk_v[:, 1], V * disk_dy(DISK_X, k), rtol=1e-12, atol=ULPS)
    np.testing.assert_allclose(p.disk_x, DISK_X, rtol=0, atol=EXACT)


def test_nearest_output_and_default_last(coupled_file):
    res = coupled.load_coupled(coupled_file)
    dt = H * STEPS_PER_OUT
    assert res.nearest_index(1.1 * dt) == 1
    assert res.nearest_index(None) == N_OUT - 1
    assert res.nearest_index(100.0) == N_OUT - 1


def test_rigid_fit_is_exact_on_a_line_and_measures_curvature():
    x = np.array([0.1, 0.2, 0.3, 0.5])
    fit, dev = coupled.rigid_fit(x, 2.0 - 3.0 * x)
    # A least-squares line through collinear points: round-off only.
    assert abs(fit[0] + 3.0) < 1e-12
    assert dev < 1e-14
    _, dev = coupled.rigid_fit(x, x**2)
    # x^2 deviates from its best line by a visible amount on [0.1, 0.5].
    assert dev > 1e-3


def test_history_of_the_tracked_disk_and_unknown_disk(coupled_file):
    res = coupled.load_coupled(coupled_file)
    t, d = coupled.history(res, 4)
    np.testing.assert_allclose(d[:, 1], [disk_dy(DISK_X[4], k) for k in range(N_OUT)],
                               rtol=0, atol=ULPS)
    with pytest.raises(ResultsError, match="no disk 9"):
        coupled.history(res, 8)


def test_overlap_ends_in_x_on_a_beam_along_x(coupled_file):
    res = coupled.load_coupled(coupled_file)
    a, b = res.overlap_x()
    assert (a, b) == pytest.approx(OVERLAP, abs=1e-15)


def test_loader_refuses_an_uncoupled_file_and_a_missing_dataset(tmp_path, coupled_file):
    ids, xy, conn, d = cantilever_layout()
    beam_only = write_results(tmp_path / "beam.h5", ids, xy, conn, d)
    with pytest.raises(ResultsError, match="no /coupling group"):
        coupled.load_coupled(beam_only)
    broken = write_coupled(tmp_path / "broken.h5", drop=("coupling/lambda",))
    with pytest.raises(ResultsError, match="missing dataset '/coupling/lambda'"):
        coupled.load_coupled(broken)
    with pytest.raises(ResultsError, match="does not exist"):
        coupled.load_coupled(tmp_path / "none.h5")


def test_write_all_writes_the_coupled_plots(tmp_path, coupled_file):
    paths = coupled.write_all(coupled.load_coupled(coupled_file), tmp_path / "out", time=5e-3)
    names = sorted(os.path.basename(p) for p in paths)
    assert names == ["coupled_configuration.png", "coupled_coupling.png", "coupled_profiles.png"]
    assert all(os.path.getsize(p) > 10000 for p in paths)


def test_auto_scale_magnifies_a_row_that_bends_as_a_body(coupled_file):
    # The disks follow the beam (a parabola, then its tangent): their displacement at the
    # last output, 5 mm, exceeds R/4 = 2.5 mm, which drew them at true scale (x 1): a
    # deflection invisible beside the model. It is now drawn as 10 % of the model's size,
    # the factor rounded down to 1, 2 or 5 times a power of ten (exact).
    res = coupled.load_coupled(coupled_file)
    size = DISK_X[-1] + R                     # box 0 .. 0.17 m along x, 0.02 m high
    assert res.size == pytest.approx(size, rel=1e-15)
    dmax = abs(disk_dy(DISK_X[-1], N_OUT - 1))
    assert dmax > R / 4
    assert coupled.scale_limits(res, N_OUT - 1)[0] == pytest.approx(0.1 * size / dmax, rel=1e-12)
    assert coupled.auto_scale(res, N_OUT - 1) == 2.0            # 3.4 rounded down
    assert coupled.auto_scale(res, 1) == 10.0                   # 10.2 rounded down
    # output 0: nothing moves
    assert coupled.auto_scale(res, 0) == 1.0
    fig = coupled.plot_configuration(res)
    assert fig.axes[0].get_title().endswith(", displacements × 2")
    assert "beam (deformed, displacements × 2)" in [t.get_text() for t in fig.legends[0].texts]


def with_disk_moved(res, disk, dx):
    """The results with disk `disk` (0-based) moved by dx along x at every output after the
    first (towards its neighbour at dx > 0): the positions as an array in memory."""
    position = np.asarray(res.position).copy()
    position[1:, disk, 0] += dx
    res.position = position
    return res


def test_auto_scale_keeps_the_gaps_between_disks_as_they_are(coupled_file):
    # Disk 4 moves 1 mm towards disk 5 (pitch 2 R): x 10 would draw the gap closed by 1 cm,
    # the disks overlapping; the magnification stops where a gap drawn changes by R/4:
    # 0.25 R / (the largest change of a neighbours' distance, 1 mm and the bending's 3e-6 m)
    # = 2.49, rounded down to 2.
    res = with_disk_moved(coupled.load_coupled(coupled_file), 3, 1e-3)
    wanted, allowed = coupled.scale_limits(res, 1)
    row = [np.hypot(*np.diff(res.position[k][:, :2], axis=0).T) for k in (0, 1)]
    # the same differences of positions as scale_limits takes: round-off of 0.02 m, 1e-12
    assert allowed == pytest.approx(0.25 * R / np.abs(row[1] - row[0]).max(), rel=1e-12)
    assert allowed == pytest.approx(2.5, rel=1e-2)     # the bending's share, 0.3 %
    assert wanted > 10.0
    assert coupled.auto_scale(res, 1) == 2.0
    title = coupled.plot_configuration(res, time=float(res.time[1])).axes[0].get_title()
    assert title.endswith(", displacements × 2 (magnifying more would draw gaps between "
                          "disks changed by over 0.25 R)")
    # 2 mm, over R/8: magnifying at all would change the gap by over R/4: true scale
    res = with_disk_moved(coupled.load_coupled(coupled_file), 3, 2e-3)
    assert coupled.auto_scale(res, 1) == 1.0
    assert "true scale (magnifying would" in coupled.plot_configuration(
        res, time=float(res.time[1])).axes[0].get_title()


def test_near_pairs_are_those_a_search_of_every_pair_finds():
    rng = np.random.default_rng(7)
    radius = rng.uniform(0.5, 1.0, 400)
    xy = rng.uniform(0.0, 30.0, (400, 2))
    i, j = coupled.near_pairs(xy, radius, 0.25)
    a, b = np.triu_indices(400, 1)
    gap = np.hypot(*(xy[b] - xy[a]).T) - radius[a] - radius[b]
    near = gap <= 0.25 * np.minimum(radius[a], radius[b])
    assert near.sum() > 100                    # the test has pairs to find
    assert sorted(zip(i.tolist(), j.tolist())) == sorted(zip(a[near].tolist(), b[near].tolist()))


def test_plot_results_handles_a_coupled_file(tmp_path, coupled_file, capsys):
    assert plot_results.main([str(coupled_file), "--out", str(tmp_path / "p")]) == 0
    printed = capsys.readouterr().out.split()
    names = {os.path.basename(p) for p in printed}
    # Coupled plots, beam plots and particle plots of the same file.
    assert {"coupled_profiles.png", "coupled_configuration.png", "coupled_coupling.png",
            "coupled_deflection.png", "coupled_particles.png"} <= names


def test_plot_experiments_writes_png_pdf_and_summary(tmp_path, capsys):
    for case in plot_experiments.CASES:
        (tmp_path / case).mkdir()
        write_coupled(tmp_path / case / f"{case}.h5", title=case)
    assert plot_experiments.main(["--results", str(tmp_path), "--time", "5e-3",
                                  "--track", "5"]) == 0
    out = capsys.readouterr().out
    for name in ("bending_case1_profiles", "bending_stack_configuration",
                 "history_case1_case2_disk5", "stack_vs_row"):
        for ext in ("png", "pdf"):
            assert (tmp_path / f"{name}.{ext}").stat().st_size > 5000
    summary = (tmp_path / "experiments_summary.txt").read_text()
    assert "bending_stack" in summary and "max|q-Cu|" in summary
    # Beyond the overlap the synthetic disks lie on a straight line: rigid fit exact.
    line = [s for s in summary.splitlines() if s.strip().startswith("bending_case1 at t = ")][0]
    assert float(line.split("max deviation")[1].split()[0]) < 1e-15
    assert "experiments_summary.txt" in out


def test_plot_experiments_reports_a_missing_case(tmp_path, capsys):
    assert plot_experiments.main(["--results", str(tmp_path)]) == 1
    assert "does not exist" in capsys.readouterr().err


def test_experiments_summary_names_the_stored_time_it_reads(coupled_file):
    """The profile lines give the time of the output they read: at a stored time only that,
    elsewhere a line saying the requested time has no output and which one is read instead
    (they were labelled with the requested time, 0.02 s, while they read the last output)."""
    res = coupled.load_coupled(coupled_file)
    dt = H * STEPS_PER_OUT
    at = plot_experiments.summary_lines({"case": res}, float(res.time[2]))
    assert not any("no output" in line for line in at)
    assert any(line.startswith(f"  case at t = {float(res.time[2]):g} s: beam end w") for line in at)
    late = plot_experiments.summary_lines({"case": res}, 100.0)
    assert f"  case: no output at t = 100 s; the nearest, t = {float(res.time[-1]):g} s:" in late
    assert any(line.startswith(f"  case at t = {float(res.time[-1]):g} s: beam end w") for line in late)
    assert float(res.time[-1]) == pytest.approx((N_OUT - 1) * dt, rel=1e-12)


def test_titles_give_the_time_in_the_unit_of_the_run(coupled_file):
    # '{t * 1e3:.3g} ms' gave 't = 1.23e+03 ms' for a run over 1 s: now the unit of the other
    # figures (s from 1 s on, ms, µs) and their 6 significant digits
    res = coupled.load_coupled(coupled_file)
    res.time = res.time * 1e2 + 0.1234567             # 0.1234567 .. 1.6234567 s
    title = coupled.plot_profiles(res).axes[0].get_title()
    assert title.endswith("\nt = 1.62346 s")
    config = coupled.plot_configuration(res, time=0.0).axes[0].get_title()
    assert config.endswith("\nt = 0.123457 s, true scale")     # nothing moves at t = 0
    compare = coupled.plot_compare_profiles([res], ["a"]).axes[0].get_title()
    assert compare == "t = 1.62346 s"
    # a run of a few ms keeps its ms (the synthetic outputs: 0 .. 15 ms)
    short = coupled.load_coupled(coupled_file)
    assert coupled.plot_profiles(short).axes[0].get_title().endswith("\nt = 15 ms")


@pytest.mark.parametrize("draw", [
    lambda res: coupled.plot_profiles(res),
    lambda res: coupled.plot_histories([res], 4, ["a"]),
    lambda res: coupled.plot_compare_profiles([res], ["a"])])
def test_panels_one_above_the_other_share_the_labelled_x_axis(coupled_file, draw):
    # the upper panel (the displacements) had an x axis of its own, numbered without a label
    fig = draw(coupled.load_coupled(coupled_file))
    top, bottom = fig.axes
    assert top.get_shared_x_axes().joined(top, bottom)
    assert bottom.get_xlabel() in ("x at t = 0 [m]", "t [ms]")
    fig.canvas.draw()                                   # tick labels are set when drawn
    assert any(t.get_visible() and t.get_text() for t in bottom.get_xticklabels())
    assert not any(t.get_visible() and t.get_text() for t in top.get_xticklabels())
