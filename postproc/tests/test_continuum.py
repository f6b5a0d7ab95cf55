"""2D continuum results (/continuum of doc/output.md): the loader, the stress plot on the
deformed mesh (magnification, values per element, the disks of a coupled run), the history,
the energy audit and the mode shapes, and plot_results.py dispatching to them.

The synthetic mesh: two Q4 and one T3, nodes 1..7; a displacement field u = A k (y, x^2)
at state k (dynamic), k = 1 for the static solution; stress of element e at state k equal to
k (e + 1) (1, 2, 3) kPa, so that every value drawn can be traced to its element and state."""
import h5py
import numpy as np
import pytest

import plot_results
from multicor_post import continuum
from multicor_post.results import ResultsError

X = np.array([[0, 0], [1, 0], [2, 0], [0, 1], [1, 1], [2, 1], [3, 0.5]], float)
CONN = np.array([[1, 2, 5, 4], [2, 3, 6, 5], [3, 7, 6, 0]], np.int32)
KIND = np.array([2, 2, 1], np.int32)
A = 1e-4
N_OUT = 5


def field(k):
    return A * k * np.stack([X[:, 1], X[:, 0] ** 2], axis=1)


def stress(k):
    return 1e3 * k * np.outer(np.arange(1, 4), [1.0, 2.0, 3.0])


def write(path, analysis="dynamic", disks=False):
    with h5py.File(path, "w") as f:
        f.attrs["title"] = f"synthetic {analysis}"
        f.attrs["analysis"] = analysis
        f["continuum/mesh/coordinates"] = X
        f["continuum/mesh/connectivity"] = CONN
        f["continuum/mesh/kind"] = KIND
        if analysis == "static":
            f["continuum/static/displacement"] = field(1)
            f["continuum/static/stress"] = stress(1)
        elif analysis == "modal":
            f["continuum/modal/frequency"] = np.array([10.0, 25.0])
            f["continuum/modal/omega"] = 2 * np.pi * np.array([10.0, 25.0])
            f["continuum/modal/shapes"] = np.stack([field(1), field(-2)])
        else:
            t = 1e-3 * np.arange(N_OUT)
            f["continuum/time"] = t
            f["continuum/displacement"] = np.stack([field(k) for k in range(N_OUT)])
            f["continuum/velocity"] = np.zeros((N_OUT, len(X), 2))
            f["continuum/stress"] = np.stack([stress(k) for k in range(N_OUT)])
            f["continuum/energy/time"] = t
            for i, name in enumerate(continuum.ENERGY_TERMS):
                f[f"continuum/energy/{name}"] = (i + 1) * t
            if disks:
                # two disks moving with the mesh's node 3 and 6 (a coupled run's glue)
                start = np.array([[2.0, 0.0, 0.0], [2.0, 1.0, 0.0]])
                move = np.stack([np.concatenate([field(k)[[2, 5]], np.zeros((2, 1))], axis=1)
                                 for k in range(N_OUT)])
                f["dem/position"] = start + move
                # a floor, and a wall driven along x at 1 m/s
                f["dem/walls/position"] = np.stack([[[-1.0, -0.5, 4.0, -0.5], [3.5, 0.0 + t[k], 3.5, 1.0 + t[k]]]
                                                    for k in range(N_OUT)])
                f["dem/particles/radius"] = np.array([0.1, 0.2])
                f["dem/time"] = t
    return path


def test_loader_reads_each_kind_of_run(tmp_path):
    s = continuum.load_continuum(write(tmp_path / "s.h5", "static"))
    assert (s.analysis, s.time, s.u.shape, s.stress.shape) == ("static", None, (1, 7, 2), (1, 3, 3))
    d = continuum.load_continuum(write(tmp_path / "d.h5"))
    assert d.analysis == "dynamic" and d.u.shape == (N_OUT, 7, 2) and d.stress.shape == (N_OUT, 3, 3)
    assert d.nearest_index(2.4e-3) == 2 and d.nearest_index(None) == N_OUT - 1
    m = continuum.load_continuum(write(tmp_path / "m.h5", "modal"))
    assert m.analysis == "modal" and list(m.frequency) == [10.0, 25.0] and m.stress is None


def test_missing_dataset_names_it(tmp_path):
    path = write(tmp_path / "d.h5")
    with h5py.File(path, "r+") as f:
        del f["continuum/stress"]
    with pytest.raises(ResultsError, match="/continuum/stress"):
        continuum.load_continuum(path)
    assert plot_results.main([str(path), "--out", str(tmp_path / "png")]) == 1


def test_small_displacements_are_magnified_to_a_tenth_of_the_mesh(tmp_path):
    res = continuum.load_continuum(write(tmp_path / "s.h5", "static"))
    u = res.u[0]
    s = continuum.auto_scale(res, u)
    # the mesh's larger side is 3 m: the largest displacement is drawn as 0.3 m, the factor
    # rounded down to 1, 2 or 5 times a power of ten (the title says "× 200", not "× 212"):
    # the drawn displacement is within a factor 2.5 below 0.3 m (the widest step, 2 -> 5)
    mantissa = s / 10 ** np.floor(np.log10(s))
    assert min(abs(mantissa - m) for m in (1.0, 2.0, 5.0)) < 1e-12
    shown = s * np.max(np.hypot(u[:, 0], u[:, 1]))
    assert 0.3 / 2.5 <= shown <= 0.3
    # displacements already larger than that are drawn at true scale, and so are those that
    # a factor below 2 would magnify (never a factor that shrinks them)
    assert continuum.auto_scale(res, 1e4 * u) == 1.0
    assert continuum.auto_scale(res, 0.3 / 1.5 / np.max(np.hypot(u[:, 0], u[:, 1])) * u) == 1.0


def test_mode_shapes_are_drawn_as_a_tenth_of_the_mesh_whatever_their_norm(tmp_path):
    path = write(tmp_path / "m.h5", "modal")
    with h5py.File(path, "r+") as f:
        # mass-normalised shapes of a light body are large: the second one 1.8e2 m here
        f["continuum/modal/shapes"][1] = 1e5 * f["continuum/modal/shapes"][1]
    fig = continuum.plot_modes(continuum.load_continuum(path))
    for ax in fig.axes[:2]:
        outline = np.concatenate([p.vertices for p in ax.collections[0].get_paths()])
        drawn = np.concatenate([p.vertices for p in ax.collections[1].get_paths()])
        # a mode shape has no true scale: its largest nodal displacement is drawn as a tenth
        # of the mesh's larger side (3 m), above or below its stored norm; exact but for the
        # rounding of the coordinates (1e-12 m on 3 m)
        assert np.max(np.hypot(*(drawn - outline).T)) == pytest.approx(0.3, abs=1e-12)


def test_stress_plot_colours_each_element_on_the_deformed_mesh(tmp_path):
    res = continuum.load_continuum(write(tmp_path / "d.h5"))
    k = 3
    fig = continuum.plot_stress(res, time=3e-3, scale=50.0)
    assert len(fig.axes) == 6                       # three panels and their colour bars
    for c in range(3):
        ax = fig.axes[c]
        outline, deformed = ax.collections[0], ax.collections[1]
        # values in kPa (largest 3 (3) 3 = 27 kPa at k = 3), element by element
        np.testing.assert_allclose(deformed.get_array(), stress(k)[:, c] / 1e3, rtol=1e-12)
        # vertices: x + scale u at state k; the T3 has 3 of them, the outline the reference x
        for e, path in enumerate(deformed.get_paths()):
            n = 3 if KIND[e] == 1 else 4
            expected = X[CONN[e, :n] - 1] + 50.0 * field(k)[CONN[e, :n] - 1]
            np.testing.assert_allclose(path.vertices[:n], expected, rtol=0, atol=1e-12)
        np.testing.assert_allclose(outline.get_paths()[1].vertices[:4], X[CONN[1] - 1], atol=0)
    assert "t = 3 ms" in fig.get_suptitle() and "× 50" in fig.get_suptitle()


def test_the_stress_title_of_a_tall_body_fits_in_the_figure(tmp_path):
    # the title was that of the top panel, centred over it: over the narrow panels of a tall
    # body (the interface experiment's blocks, 0.5 x 0.45 m) a long title ran out of the
    # figure on both sides and was clipped
    res = continuum.load_continuum(write(tmp_path / "d.h5"))
    res.x = res.x * [0.1, 3.0]                       # 0.3 m wide, 3 m high
    res.title = ("contact interface: disk layer between two blocks, normal then tangential "
                 "loading, and a title longer than the figure is wide")
    fig = continuum.plot_stress(res)
    fig.canvas.draw()
    box = fig.bbox
    for text in [fig._suptitle] + [ax.title for ax in fig.axes]:
        if text is not None and text.get_text():
            extent = text.get_window_extent()
            # whole pixels: the renderer rounds the text's box
            assert box.x0 - 1 <= extent.x0 and extent.x1 <= box.x1 + 1, text.get_text()
    assert "stress per element on the deformed mesh" in fig.get_suptitle()


def test_disks_of_a_coupled_run_move_with_the_same_magnification(tmp_path):
    res = continuum.load_continuum(write(tmp_path / "c.h5", disks=True))
    k, s = N_OUT - 1, 20.0
    disks = continuum.plot_stress(res, scale=s).axes[0].collections[2]
    # the paths of a PatchCollection are in data coordinates: a circle's centre is the middle
    # of its extent
    drawn = np.array([(p.vertices.min(axis=0) + p.vertices.max(axis=0)) / 2 for p in disks.get_paths()])
    radii = np.array([np.ptp(p.vertices[:, 0]) / 2 for p in disks.get_paths()])
    # the node each disk follows, drawn magnified like the mesh
    expected = X[[2, 5]] + s * field(k)[[2, 5]]
    np.testing.assert_allclose(drawn, expected, rtol=0, atol=1e-12)
    np.testing.assert_allclose(radii, [0.1, 0.2], rtol=1e-12)
    # the walls, their displacements magnified the same way (the driven one moved 4 mm in y)
    walls = continuum.plot_stress(res, scale=s).axes[0].collections[3].get_segments()
    np.testing.assert_allclose(walls[1], [[3.5, s * 4e-3], [3.5, 1.0 + s * 4e-3]], rtol=0, atol=1e-12)
    np.testing.assert_allclose(walls[0], [[-1.0, -0.5], [4.0, -0.5]], rtol=0, atol=0)


def test_history_of_the_node_that_moves_most(tmp_path):
    res = continuum.load_continuum(write(tmp_path / "d.h5"))
    fig, node = continuum.plot_history(res)
    assert node == 7                                 # x = 3: u_y = A k 9, the largest
    ux, uy = fig.axes[0].get_lines()
    # in mm, as the beam plots give a largest value of 3.6 mm (it said [m] whatever the size)
    assert fig.axes[0].get_ylabel() == "displacement [mm]"
    np.testing.assert_allclose(uy.get_ydata(), [1e3 * field(k)[6, 1] for k in range(N_OUT)],
                               rtol=1e-12)
    np.testing.assert_allclose(ux.get_ydata(), [1e3 * field(k)[6, 0] for k in range(N_OUT)],
                               rtol=1e-12)
    assert continuum.plot_history(res, node=2)[1] == 2
    # the default is the largest displacement over the run, not at the last state (the
    # states read into memory to change them: a loaded series is read from the file)
    res.u = np.array(res.u)
    res.u[-1] = 0.0
    res.u[-1, 1] = [1e-9, 0.0]
    assert continuum.plot_history(res)[1] == 7
    with pytest.raises(ResultsError, match="no node 8"):
        continuum.plot_history(res, node=8)


def test_energy_plot_draws_the_audit(tmp_path):
    res = continuum.load_continuum(write(tmp_path / "d.h5"))
    ax, ax_b = continuum.plot_energy(res).axes
    t = 1e-3 * np.arange(N_OUT)
    drawn = {line.get_label(): line.get_ydata() for line in ax.get_lines()}
    np.testing.assert_allclose(drawn["strain"], 2 * t, rtol=1e-12)          # term 2 of the file
    np.testing.assert_allclose(ax_b.get_lines()[0].get_ydata(), 6 * t, rtol=1e-12)   # balance


def test_cli_writes_the_figures_of_each_kind(tmp_path, capsys):
    for analysis, names in (("static", ["stress"]),
                            ("dynamic", ["stress", "continuum_energy", "history"]),
                            ("modal", ["modes"])):
        path = write(tmp_path / f"{analysis}.h5", analysis)
        out = tmp_path / analysis
        assert plot_results.main([str(path), "--out", str(out)]) == 0
        printed = capsys.readouterr().out.split()
        assert printed == [str(out / f"{analysis}_{n}.png") for n in names]
        for p in printed:
            with open(p, "rb") as f:
                assert f.read(8) == b"\x89PNG\r\n\x1a\n"


def test_partial_file_of_an_unfinished_run(tmp_path, capsys, drawing_only):
    # deck.h5.partial (a run stopped by a signal): the figures are named after the deck and
    # the script says what the file is
    path = write(tmp_path / "run.h5.partial", "static")
    # the figure test_cli_writes_the_figures_of_each_kind draws of the same static run
    with drawing_only():
        assert plot_results.main([str(path), "--out", str(tmp_path / "png")]) == 0
    out = capsys.readouterr()
    assert out.out.split() == [str(tmp_path / "png" / "run_stress.png")]
    assert "partial file of a run that did not finish" in out.err


def test_round_off_components_are_drawn_white(tmp_path):
    # a bar in uniaxial tension: sigma_yy and sigma_xy are round-off of sigma_xx (1e-16 of
    # it); their panels take the limits of 1e-9 of sigma_xx, not their own noise's
    path = write(tmp_path / "s.h5", "static")
    with h5py.File(path, "r+") as f:
        f["continuum/static/stress"][...] = np.array([[1e6, 1e-10, -2e-10], [1e6, -1e-10, 3e-10],
                                                      [1e6, 2e-10, 1e-10]])
    fig = continuum.plot_stress(continuum.load_continuum(path))
    for c in (1, 2):
        lo, hi = fig.axes[c].collections[1].get_clim()
        assert hi == pytest.approx(1e-9, rel=1e-12) and lo == -hi      # MPa: 1e-9 of 1 MPa
        assert "round-off" in fig.axes[3 + c].get_ylabel()
    # the real component keeps its own limits
    assert fig.axes[0].collections[1].get_clim()[1] == pytest.approx(1.0, rel=1e-12)
    assert "round-off" not in fig.axes[3].get_ylabel()


def with_materials(path, young=210e9):
    """The results file with /continuum/materials/young and /continuum/mesh/material (every
    element of material 1), as a build since /continuum/materials writes them."""
    with h5py.File(path, "r+") as f:
        f["continuum/materials/young"] = np.array([young])
        f["continuum/mesh/material"] = np.ones(len(CONN), np.int32)
    return path


def test_the_stress_of_a_rigid_motion_is_drawn_as_zero_to_round_off(tmp_path):
    # input/coupled2d_block.dat: a steel block in a rigid motion, |u| 0.94 mm, elements of
    # 0.25 m; its stresses of 1e-7 Pa are D B u of displacements equal to their rounding,
    # which every component drew in a full colour range, as a pattern of stress. Here: a
    # translation of 1 mm (|u| = sqrt(5) mm) with stresses of +-5e-7 Pa
    path = with_materials(write(tmp_path / "s.h5", "static"))
    noise = 5e-7 * np.array([[1.0, -0.4, 0.2], [-0.6, 0.9, -1.0], [0.3, 0.7, -0.5]])
    with h5py.File(path, "r+") as f:
        f["continuum/static/displacement"][...] = np.tile([1e-3, -2e-3], (len(X), 1))
        f["continuum/static/stress"][...] = noise
    res = continuum.load_continuum(path)
    # shortest side 1 m (the Q4s'; the T3's are 1.12 m and 1 m): 1e3 eps E |u| / h
    level = 1e3 * np.finfo(float).eps * 210e9 * np.sqrt(5) * 1e-3 / 1.0
    assert continuum.roundoff_stress(res, res.u[0]) == pytest.approx(level, rel=1e-12)
    fig = continuum.plot_stress(res)
    for c in range(3):
        # the colour range is +-that level (about 1e-4 Pa): the noise is drawn near white
        lo, hi = fig.axes[c].collections[1].get_clim()
        assert hi == pytest.approx(level, rel=1e-12) and lo == -hi
        assert "zero to round-off" in fig.axes[3 + c].get_ylabel()
    assert fig.get_suptitle().endswith(
        "\nevery component zero to round-off (|σ| at most 5e-07 Pa)")


def test_a_small_real_stress_keeps_its_colour_range(tmp_path):
    # the synthetic kPa stresses of displacements of 0.9 mm in steel: 1e11 times the rounding
    # of a stress computed from them, drawn in their own range
    res = continuum.load_continuum(with_materials(write(tmp_path / "s.h5", "static")))
    assert continuum.roundoff_stress(res, res.u[0]) < 1e-4
    fig = continuum.plot_stress(res)
    for c in range(3):
        assert "round-off" not in fig.axes[3 + c].get_ylabel()
        # kPa, the 99th percentile of the element values 1, 2, 3 (times c + 1)
        top = np.percentile(stress(1)[:, c], 99) / 1e3
        assert fig.axes[c].collections[1].get_clim()[1] == pytest.approx(top, rel=1e-12)
    assert "zero to round-off" not in fig.get_suptitle()
