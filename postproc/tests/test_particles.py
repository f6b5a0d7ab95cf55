"""Particle results: loading of the /dem group, the force network drawn from the contacts
(segments between centres, or to the contact point on a wall; widths proportional to r_n),
and plot_results.py dispatching to the beam and particle plots."""
import numpy as np
import pytest
from synthetic import cantilever_layout, write_results
from synthetic_dem import G, MASS, N_DISKS, N_OUT, R, column_state, write_dem
from synthetic_large import write_large_dem

import plot_results
from matplotlib.collections import QuadMesh
from matplotlib.colors import to_rgba
from multicor_post.particles import (MAX_FORCE_WIDTH, force_segments, force_widths, load_dem,
                                     plot_configuration, plot_solver, plot_velocities)
from multicor_post.results import ResultsError

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def test_loader_reads_the_documented_layout(tmp_path):
    res = load_dem(write_dem(tmp_path / "col.h5"))
    assert res.n == N_DISKS + 2
    assert res.position.shape == (N_OUT, N_DISKS + 2, 3)
    assert res.walls.shape == (N_OUT, 1, 4)
    assert list(res.material) == [1, 1, 1, 2, 2]
    # compressed rows: no contact at output 0, then N_DISKS + 1 per output
    c = res.contacts
    assert c.at(0) == slice(0, 0)
    assert c.at(2) == slice(N_DISKS + 1, 2 * (N_DISKS + 1))
    assert res.solver.time[0] == pytest.approx(1e-3, rel=1e-12)   # step 1 ends at h
    assert int(np.count_nonzero(~res.solver.converged)) == 1
    assert res.nearest_index(0.0126) == 3                           # outputs every 5 ms
    assert res.nearest_index(0.0112) == 2                           # 10 ms nearer than 15 ms
    assert res.title == "synthetic column"


def test_force_segments_join_centres_and_reach_the_wall(tmp_path):
    res = load_dem(write_dem(tmp_path / "col.h5"))
    k = 2
    seg, rn, status = force_segments(res, k)
    pos = column_state(k)
    # floor contact of disk 1: from its centre down by R along -n to the floor (y = 0 + shift)
    np.testing.assert_allclose(seg[0], [pos[0, :2], pos[0, :2] - [0.0, R]], rtol=0, atol=1e-15)
    # pair (1, 2): from disk 2 to disk 1
    np.testing.assert_allclose(seg[1], [pos[1, :2], pos[0, :2]], rtol=0, atol=1e-15)
    # the bond of the hanging disk: from disk 5 to disk 4, in tension
    np.testing.assert_allclose(seg[-1], [pos[4, :2], pos[3, :2]], rtol=0, atol=1e-15)
    # column at rest: r_n = disks above x m g (the synthetic data state it; checks the slice)
    np.testing.assert_allclose(rn[:N_DISKS], MASS * G * np.arange(N_DISKS, 0, -1), rtol=1e-14)
    assert rn[-1] < 0 and list(status) == [1] * N_DISKS + [3]


def test_line_width_grows_in_proportion_to_the_normal_force():
    rn = np.array([4.0, 2.0, -1.0, 0.0])
    widths = force_widths(rn)
    np.testing.assert_allclose(widths, MAX_FORCE_WIDTH * np.array([1.0, 0.5, 0.25, 0.0]),
                               rtol=1e-15)
    assert np.all(force_widths(np.zeros(3)) == 0.0)


def test_force_scale_is_the_largest_tension_when_it_exceeds_the_compressions(tmp_path):
    """A cohesive contact pulled at twice the largest compression: the scale of the run is
    that |r_n|, the widths at that scale stay within MAX_FORCE_WIDTH, the widest being the
    bond; a compression between NOISE times the largest compression and NOISE times the
    scale is round-off, not drawn."""
    import h5py
    from multicor_post.particles import NOISE, force_scale
    path = write_dem(tmp_path / "col.h5")
    with h5py.File(path, "r+") as f:
        rn = f["dem/contacts/rn"][...]
        pull = -2.0 * rn.max()                       # the bond: 2 x (3 m g), in tension
        rn[N_DISKS::N_DISKS + 1] = pull
        rn[N_DISKS - 1::N_DISKS + 1] = 0.75 * NOISE * -pull    # the top pair of the column
        f["dem/contacts/rn"][...] = rn
    res = load_dem(path)
    assert force_scale(res) == -pull                 # |r_n| of a stored double: exact
    widths = force_widths(res.contacts.rn, force_scale(res))
    assert widths.max() <= MAX_FORCE_WIDTH and widths[N_DISKS] == MAX_FORCE_WIDTH
    assert int(np.argmax(widths)) == N_DISKS
    assert "4 contacts (3 carrying a force)" in plot_configuration(res, 2).axes[0].get_title()


def test_configuration_draws_disks_forces_and_walls(tmp_path):
    res = load_dem(write_dem(tmp_path / "col.h5"))
    fig = plot_configuration(res, 2)
    ax = fig.axes[0]
    disks, marks, walls, bonds, forces = ax.collections
    assert len(disks.get_offsets()) == N_DISKS + 2
    assert len(walls.get_segments()) == 1
    # the one intact bond (status 3) is drawn under the force network
    assert len(bonds.get_segments()) == 1
    widths = np.asarray(forces.get_linewidths())
    # widths follow |r_n| (floor 3 m g, then 2, 1, and the bond 1 m g)
    np.testing.assert_allclose(widths / widths[0], [1.0, 2 / 3, 1 / 3, 1 / 3], rtol=1e-12)
    colors = forces.get_colors()
    assert tuple(colors[-1][:3]) != tuple(colors[0][:3])          # tension drawn red
    assert "4 contacts (4 carrying a force)" in ax.get_title()
    # output 0 has no contact: only disks, rotation marks and walls
    assert len(plot_configuration(res, 0).axes[0].collections) == 3
    assert "0 contacts (0 carrying a force)" in plot_configuration(res, 0).axes[0].get_title()


def test_configuration_of_a_run_without_stored_contacts_says_so(tmp_path):
    # [output] contacts = no (no /dem/contacts): the title said "2 disks, 0 contacts (0
    # carrying a force)", as if the disks touched nothing
    res = load_dem(write_dem(tmp_path / "bare.h5", with_contacts=False))
    title = plot_configuration(res, 2).axes[0].get_title()
    assert title.endswith(f": {N_DISKS + 2} disks, contacts not stored")
    assert "0 contacts" not in title


def test_solver_plot_marks_the_unconverged_step(tmp_path):
    res = load_dem(write_dem(tmp_path / "col.h5"))
    ax = plot_solver(res).axes[0]
    marked = [line for line in ax.get_lines() if line.get_marker() == "o"]
    assert len(marked) == 1 and len(marked[0].get_xdata()) == 1
    # step 8 (index 7) ends at t = 8 ms
    assert marked[0].get_xdata()[0] == pytest.approx(8.0)
    # the error and residual relative to their scales: '[-]', as every axis gives its unit
    assert plot_solver(res).axes[1].get_ylabel() == "relative error [-]"


def test_solver_plot_of_exact_steps_draws_without_warning(tmp_path):
    # a direct block solve stores error and residual 0 at every step (input/bending_case1.dat):
    # the log axis of the errors must not be left to autoscale on no data (matplotlib then
    # warns "identical low and high ylims" at savefig)
    import warnings

    import h5py
    path = write_dem(tmp_path / "col.h5")
    with h5py.File(path, "r+") as f:
        for name in ("dem/solver/error", "dem/solver/residual"):
            f[name][...] = 0.0
        f["dem/solver"].attrs["tolerance"] = 1e-8     # that deck's (the warning depends on it)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fig = plot_solver(load_dem(path))
        fig.savefig(tmp_path / "solver.png")
    # the cap of 1000 sweeps is far above the 1 to 15 of the steps: written, not drawn
    assert [t.get_text() for t in fig.axes[0].texts] == ["max_sweeps = 1000 (off the scale)"]
    assert not [line for line in fig.axes[0].get_lines() if line.get_linestyle() == "--"]
    texts = [t.get_text() for t in fig.axes[1].texts]
    assert texts == ["error and residual 0 at every step"]
    # the plot of a run with nonzero errors has no such note
    assert not plot_solver(load_dem(write_dem(tmp_path / "b.h5"))).axes[1].texts


def test_cli_says_what_a_checkpoint_or_an_fclib_file_is(tmp_path, capsys):
    # the other HDF5 files multicor writes next to the results (attributes as multicor writes
    # them: doc/output.md, checkpoint and FCLIB export)
    import h5py
    with h5py.File(tmp_path / "checkpoint.h5", "w") as f:
        f.attrs["format"] = "MULTICOR checkpoint 1"
        f.create_group("dem")
    with h5py.File(tmp_path / "run_fclib_3.h5", "w") as f:
        f.create_group("fclib_local")
    assert plot_results.main([str(tmp_path / "checkpoint.h5")]) == 1
    assert "is a MULTICOR checkpoint (for --restart)" in capsys.readouterr().err
    assert plot_results.main([str(tmp_path / "run_fclib_3.h5")]) == 1
    assert "exported in FCLIB's format ([solver] fclib_step)" in capsys.readouterr().err


def test_solver_plot_names_the_method(tmp_path):
    # /dem/solver@method as multicor writes it (doc/output.md); a file without the attribute
    # names no method
    import h5py
    title = plot_solver(load_dem(write_dem(tmp_path / "a.h5"))).axes[0].get_title()
    assert "contact solver, every step" in title
    for method in ("block", "nlgs", "coarse"):
        path = write_dem(tmp_path / f"{method}.h5")
        with h5py.File(path, "r+") as f:
            f["dem/solver"].attrs["method"] = method
        title = plot_solver(load_dem(path)).axes[0].get_title()
        assert f"contact solver (method = {method}), every step" in title


def test_solver_plot_draws_the_cap_when_a_step_comes_near_it(tmp_path):
    import h5py
    path = write_dem(tmp_path / "col.h5")
    with h5py.File(path, "r+") as f:
        f["dem/solver/sweeps"][7] = 1000          # the unconverged step stopped at the cap
    ax = plot_solver(load_dem(path)).axes[0]
    caps = [line for line in ax.get_lines() if line.get_linestyle() == "--"]
    assert len(caps) == 1 and caps[0].get_ydata()[0] == 1000 and not ax.texts


def check_pngs(paths):
    assert paths
    for path in paths:
        with open(path, "rb") as f:
            assert f.read(8) == PNG_SIGNATURE


def test_cli_writes_the_particle_plots(tmp_path, capsys):
    path = write_dem(tmp_path / "col.h5")
    out = tmp_path / "png"
    assert plot_results.main([str(path), "--out", str(out)]) == 0
    names = sorted(p.name for p in out.iterdir())
    assert names == ["col_dem_energy.png", "col_particles.png", "col_particles_start.png",
                     "col_solver.png", "col_velocities.png"]
    assert sorted(capsys.readouterr().out.split()) == sorted(str(out / n) for n in names)
    check_pngs(list(out.iterdir()))


def test_cli_snapshot_at_a_time_and_without_contacts_or_walls(tmp_path, drawing_only):
    path = write_dem(tmp_path / "bare.h5", with_contacts=False, with_walls=False)
    out = tmp_path / "png"
    # the series (energy, solver, velocities) do not depend on the contacts, walls or --time:
    # test_cli_writes_the_particle_plots draws them
    with drawing_only("bare_particles.png", "bare_particles_start.png"):
        assert plot_results.main([str(path), "--time", "0.01", "--out", str(out)]) == 0
    names = sorted(p.name for p in out.iterdir())
    assert "bare_particles.png" in names and "bare_particles_start.png" not in names
    res = load_dem(path)
    assert res.contacts is None and res.walls is None
    assert "t = 10 ms" in plot_configuration(res, res.nearest_index(0.01)).axes[0].get_title()


def test_cli_dispatches_to_beam_and_particles(tmp_path, drawing_only):
    beam_only = tmp_path / "beam.h5"
    ids, xy, conn, d = cantilever_layout()
    write_results(beam_only, ids, xy, conn, d, parts=("static",))
    both = write_dem(tmp_path / "both.h5", with_beam=True)
    out = tmp_path / "png"
    assert plot_results.main([str(beam_only), "--out", str(out)]) == 0
    assert sorted(p.name for p in out.iterdir()) == ["beam_static.png"]
    # the particle figures not checked here: those test_cli_writes_the_particle_plots draws
    with drawing_only("both_static.png", "both_particles.png", "both_solver.png"):
        assert plot_results.main([str(both), "--out", str(out)]) == 0
    names = {p.name for p in out.iterdir()}
    assert {"both_static.png", "both_particles.png", "both_solver.png"} <= names


def test_cli_reports_missing_files_and_datasets(tmp_path, capsys):
    assert plot_results.main([str(tmp_path / "none.h5")]) == 1
    assert "does not exist" in capsys.readouterr().err
    path = write_dem(tmp_path / "broken.h5", drop=("dem/contacts/rn",))
    assert plot_results.main([str(path)]) == 1
    assert "missing dataset '/dem/contacts/rn'" in capsys.readouterr().err
    with pytest.raises(ResultsError, match="no /dem group"):
        load_dem(write_results(tmp_path / "b.h5", *cantilever_layout(), parts=("static",)))


@pytest.mark.parametrize("n_disks", [17, 50])
def test_velocities_of_many_disks_are_told_apart_by_a_numbered_colour_bar(tmp_path, n_disks):
    # 17 disks (the row of input/bending_case1.dat) had no legend and the default cycle's
    # 10 colours, 7 of them drawn twice: now one colour per disk along the colour map, and a
    # colour bar from disk 1 to disk n giving each its colour
    res = load_dem(write_large_dem(tmp_path / "many.h5", n_disks, n_out=4, per_output=2))
    fig = plot_velocities(res)
    velocity_axes = fig.axes[:3]
    for ax in velocity_axes:
        colours = [tuple(to_rgba(line.get_color())) for line in ax.get_lines()]
        assert len(colours) == n_disks
        assert len(set(colours)) == n_disks
    bar, = [ax for ax in fig.axes if ax not in velocity_axes]
    assert bar.get_ylabel() == "disk"
    assert bar.get_ylim() == (0.5, n_disks + 0.5)   # one band per disk, centred on its number
    fig.canvas.draw()                                # the bar's colours are set when drawn
    mesh, = [c for c in bar.collections if isinstance(c, QuadMesh)]
    bands = mesh.get_facecolors()
    assert len(bands) == n_disks
    for band, line in zip(bands, velocity_axes[0].get_lines()):
        # the band of disk i on the bar has the colour of its curve (the same rgba numbers)
        assert tuple(band) == to_rgba(line.get_color())
    assert velocity_axes[0].get_legend() is None


def test_velocities_of_a_few_disks_keep_their_legend(tmp_path):
    res = load_dem(write_dem(tmp_path / "col.h5"))
    fig = plot_velocities(res)
    assert len(fig.axes) == 3                       # no colour bar
    legend = fig.axes[0].get_legend()
    assert [t.get_text() for t in legend.get_texts()] == [f"disk {i}" for i in range(1, 6)]
