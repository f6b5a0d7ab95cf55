"""Plots: element interpolation against the analytic cantilever, tip detection, PNG output."""
import math

import numpy as np
import pytest
from synthetic import L, cantilever_layout, cantilever_theta, cantilever_w, rotate

import plot_beam
from multicor_post import load_results
from multicor_post.beam import auto_scale, default_node, element_fields, plot_deflection

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def mesh_of(path):
    return load_results(path).mesh


def test_hermite_interpolation_reproduces_the_cubic_cantilever(cantilever_file):
    res = load_results(cantilever_file(parts=("static",)))
    curves = element_fields(res.mesh, res.static.displacement, points=7)
    w_max = abs(cantilever_w(L))
    for x, y, ux, uy in curves:
        # The deflection is cubic: Hermite elements hold it exactly, up to round-off
        # (~1e-16 relative per operation, a few dozen operations).
        assert np.max(np.abs(uy - cantilever_w(x))) < 1e-13 * w_max
        assert np.max(np.abs(ux)) < 1e-13 * w_max
        np.testing.assert_array_equal(y, 0.0)


def test_hermite_interpolation_in_an_inclined_member(cantilever_file):
    angle = math.radians(30.0)
    res = load_results(cantilever_file(angle=angle, parts=("static",)))
    w_max = abs(cantilever_w(L))
    for x, y, ux, uy in element_fields(res.mesh, res.static.displacement, points=5):
        s = np.hypot(x, y)
        u_ref, w_ref = rotate(angle, np.zeros_like(s), cantilever_w(s))
        # Same cubic in the member's frame; rotation adds a few roundings.
        assert np.max(np.abs(ux - u_ref)) < 1e-13 * w_max
        assert np.max(np.abs(uy - w_ref)) < 1e-13 * w_max


def test_rotation_is_the_slope_of_the_deflection():
    # Guards the sign convention of the synthetic data the other tests rely on.
    x, h = 1.3, 1e-6
    slope = (cantilever_w(x + h) - cantilever_w(x - h)) / (2 * h)
    # Central difference of a cubic: error h^2 * w'''/6 ~ 1e-14, far below 1e-9.
    assert slope == pytest.approx(cantilever_theta(x), rel=1e-9)


def test_default_node_is_the_free_end(cantilever_file):
    res = load_results(cantilever_file())
    assert default_node(res) == 90


def test_default_node_of_a_frame_clamped_at_both_ends_is_the_one_that_moves_most(tmp_path):
    # A portal frame (nodes 1-3 up, 3-5 across, 5-7 down) clamped at nodes 1 and 7, its ends:
    # they do not move, so the history would be a flat line at zero; the top swings most at
    # node 4 (the sway u = 1e-3 y plus a sag of the beam, largest at mid-span).
    from synthetic import write_results
    ids = np.arange(1, 8, dtype=np.int32)
    xy = np.array([[0, 0], [0, 1], [0, 2], [1, 2], [2, 2], [2, 1], [2, 0]], dtype=float)
    conn = np.column_stack([np.arange(1, 7), np.arange(2, 8)]).astype(np.int32)
    d = np.zeros((7, 3))
    d[:, 0] = 1e-3 * xy[:, 1]
    d[3, 1] = -1e-3
    res = load_results(write_results(tmp_path / "portal.h5", ids, xy, conn, d, parts=("static",)))
    assert default_node(res) == 4


def test_auto_scale_is_round_and_makes_the_largest_displacement_visible():
    ids, xy, conn, d = cantilever_layout()
    from multicor_post.results import Mesh
    mesh = Mesh(node_id=ids, x=xy[:, 0], y=xy[:, 1], connectivity=conn - 1)
    scale = auto_scale(mesh, d)
    mantissa = scale / 10 ** math.floor(math.log10(scale))
    assert mantissa == pytest.approx(1.0) or mantissa == pytest.approx(2.0) \
        or mantissa == pytest.approx(5.0)
    # Target 10 % of the size; rounding down to 1-2-5 keeps it within a factor 2.5.
    shown = scale * np.max(np.abs(d[:, 1])) / L
    assert 0.04 <= shown <= 0.1 + 1e-12
    # displacements already a tenth of the beam or more are drawn at true scale: a factor
    # rounded down from below 2 would shrink them (0.5 for a deflection of a fifth) or be
    # too close to 1 to tell from it
    assert auto_scale(mesh, d * (0.2 * L / np.max(np.abs(d[:, 1])))) == 1.0
    assert auto_scale(mesh, d * (0.1 / 1.5 * L / np.max(np.abs(d[:, 1])))) == 1.0


def test_deflection_title_states_the_nearest_stored_time(cantilever_file):
    res = load_results(cantilever_file())
    fig, k = plot_deflection(res, time=4.4e-3)
    assert k == 4
    title = fig.axes[0].get_title()
    assert "t = 4 ms" in title and "nearest" in title


def check_pngs(paths):
    assert paths
    for path in paths:
        with open(path, "rb") as f:
            head = f.read(8)
        assert head == PNG_SIGNATURE
        assert path.stat().st_size > 5000


def test_cli_writes_every_plot_of_a_straight_cantilever(cantilever_file, tmp_path, capsys):
    path = cantilever_file()
    out = tmp_path / "png"
    assert plot_beam.main([str(path), "--time", "0.005", "--out", str(out)]) == 0
    printed = capsys.readouterr().out.split()
    names = sorted(p.name for p in out.iterdir())
    assert names == ["cantilever_deflection.png", "cantilever_energy.png",
                     "cantilever_history_node90.png", "cantilever_modes.png",
                     "cantilever_static.png"]
    assert sorted(printed) == sorted(str(out / n) for n in names)
    check_pngs(list(out.iterdir()))


def test_cli_plots_the_deformed_shape_of_an_l_frame(tmp_path, capsys):
    from synthetic import write_results
    # Column up the y axis (nodes 1-5), then a beam along x (nodes 5-9).
    ids = np.arange(1, 10, dtype=np.int32)
    xy = np.array([[0, 0], [0, .5], [0, 1], [0, 1.5], [0, 2],
                   [.5, 2], [1, 2], [1.5, 2], [2, 2]], dtype=float)
    conn = np.column_stack([np.arange(1, 9), np.arange(2, 10)]).astype(np.int32)
    d = np.zeros((9, 3))
    d[:, 0] = 1e-3 * xy[:, 1]
    d[:, 1] = -2e-3 * xy[:, 0]
    path = write_results(tmp_path / "lframe.h5", ids, xy, conn, d, parts=("dynamic",))
    out = tmp_path / "png"
    assert plot_beam.main([str(path), "--node", "5", "--out", str(out), "--scale", "100"]) == 0
    names = sorted(p.name for p in out.iterdir())
    assert names == ["lframe_deflection.png", "lframe_history_node5.png"]
    check_pngs(list(out.iterdir()))


def test_cli_reports_a_missing_file_and_exits_1(tmp_path, capsys):
    assert plot_beam.main([str(tmp_path / "none.h5")]) == 1
    assert "does not exist" in capsys.readouterr().err


def test_cli_reports_a_missing_dataset_and_exits_1(cantilever_file, capsys):
    path = cantilever_file(drop=("energy/balance",))
    assert plot_beam.main([str(path)]) == 1
    assert "missing dataset '/energy/balance'" in capsys.readouterr().err


@pytest.mark.parametrize("labelled", [True, False])
def test_an_axial_mode_of_a_straight_beam_draws_its_axial_displacement(labelled, tmp_path):
    # an axial mode (w = 0, u = sin(pi x / 2L): the first mode of a clamped-free bar) was
    # drawn as a flat line at zero: the figure plotted w only. Now its u, dashed, '(axial)'
    # in the legend; with /modal/axial_fraction@kind or, in a file without it, because u
    # dominates
    import h5py
    from synthetic import write_results
    from multicor_post.beam import plot_modes
    ids, xy, conn, d = cantilever_layout()
    path = write_results(tmp_path / "bar.h5", ids, xy, conn, d, parts=("modal",))
    x = xy[:, 0]
    bar = np.zeros_like(d)
    bar[:, 0] = 3.0 * np.sin(np.pi * x / (2 * L))       # arbitrary scale, as the solver's
    with h5py.File(path, "a") as f:
        f["modal/shapes"][1] = bar
        if labelled:
            f.create_dataset("modal/axial_fraction", data=[0.0, 1.0])
            f["modal/axial_fraction"].attrs["kind"] = "bending axial "
    fig = plot_modes(load_results(path))
    ax = fig.axes[0]
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert legend[0].endswith("Hz") and legend[1].endswith("Hz (axial)")
    # the curves of mode 2 (colour C1): u / max|u| element by element, linear between the
    # nodes, so at each element's ends the nodal values (to round-off of the interpolation:
    # a few ulps of 1)
    lines = [line for line in ax.get_lines() if line.get_color() == "C1"]
    assert len(lines) == conn.shape[0] and all(line.get_linestyle() == "--" for line in lines)
    for line, (a, b) in zip(lines, conn - 1):
        y = line.get_ydata()
        assert abs(y[0] - np.sin(np.pi * x[a] / (2 * L))) < 1e-14
        assert abs(y[-1] - np.sin(np.pi * x[b] / (2 * L))) < 1e-14
    # the bending mode keeps its w, solid
    w_lines = [line for line in ax.get_lines() if line.get_color() == "C0"]
    assert w_lines[-1].get_linestyle() == "-"
    assert w_lines[-1].get_ydata()[-1] == pytest.approx(-1.0, abs=1e-14)  # tip w / max|d|
    assert "axial mode" in ax.get_ylabel()
