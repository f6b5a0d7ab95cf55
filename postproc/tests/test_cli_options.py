"""Command-line options and output folders of the plotting scripts: a value that cannot give a
meaningful figure, a folder that cannot be written and a file of the wrong kind end with a
one-line message (usage errors exit 2, file errors exit 1), never a traceback and never a
figure saved with exit 0."""
import os

import h5py
import pytest
from synthetic_coupled import write_coupled
from synthetic_dem import write_dem

import plot_beam
import plot_experiments
import plot_results
import run_interface_experiment


@pytest.mark.parametrize("script", [plot_results, plot_beam])
def test_an_output_folder_that_is_a_file_is_an_error(script, cantilever_file, tmp_path, capsys):
    path = cantilever_file()
    blocker = tmp_path / "blocker"
    blocker.write_text("")
    # --out names the file itself, or a folder under it (makedirs: NotADirectoryError)
    for out in (blocker, blocker / "png"):
        assert script.main([str(path), "--out", str(out)]) == 1
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and str(blocker) in err and "Traceback" not in err
    assert blocker.read_text() == ""


@pytest.mark.parametrize("script", [plot_results, plot_beam])
@pytest.mark.parametrize("option, value, message", [
    ("--scale", "nan", "expected a finite real number, got 'nan'"),
    ("--scale", "inf", "expected a finite real number, got 'inf'"),
    ("--scale", "-inf", "expected a finite real number, got '-inf'"),
    ("--scale", "0", "expected a scale factor > 0, got '0'"),
    ("--scale", "-10", "expected a scale factor > 0, got '-10'"),
    ("--time", "nan", "expected a finite real number, got 'nan'"),
    ("--time", "inf", "expected a finite real number, got 'inf'"),
    ("--time", "5 ms", "expected a real number, got '5 ms'"),
])
def test_a_time_or_scale_without_a_meaning_is_a_usage_error(script, option, value, message,
                                                             cantilever_file, tmp_path, capsys):
    # nan or inf scales failed inside matplotlib with a traceback or drew an empty deformed
    # shape with exit 0; --time nan silently drew the first output
    out = tmp_path / "png"
    with pytest.raises(SystemExit) as stop:
        script.main([str(cantilever_file()), f"{option}={value}", "--out", str(out)])
    assert stop.value.code == 2
    assert f"argument {option}: {message}" in capsys.readouterr().err
    assert not out.exists()


def test_a_finite_scale_and_time_are_accepted(cantilever_file, tmp_path, drawing_only):
    out = tmp_path / "png"
    # of a straight beam, the deflection at the first output (--time -1) is the figure these
    # values shape; the others are those test_beam.py's
    # test_cli_writes_every_plot_of_a_straight_cantilever draws
    with drawing_only("cantilever_deflection.png"):
        assert plot_results.main([str(cantilever_file()), "--scale", "1e-3", "--time", "-1",
                                  "--out", str(out)]) == 0
    assert any(out.iterdir())


def test_plot_beam_sends_particle_and_continuum_files_to_plot_results(tmp_path, capsys):
    # it said "missing dataset '/fem/mesh/node_id' (not a MULTICOR results file, or one
    # from another version)" of a valid results file without a beam
    dem = write_dem(tmp_path / "column.h5")
    continuum = tmp_path / "plate.h5"
    with h5py.File(continuum, "w") as f:
        f.create_group("continuum/mesh")
    for path, what in ((dem, "particles (/dem)"), (continuum, "a 2D continuum (/continuum)")):
        assert plot_beam.main([str(path), "--out", str(tmp_path / "png")]) == 1
        err = capsys.readouterr().err
        assert f"holds no beam (/fem/mesh) but {what}: plot it with plot_results.py" in err
    assert not (tmp_path / "png").exists()


def test_plot_beam_says_what_a_checkpoint_is(tmp_path, capsys):
    with h5py.File(tmp_path / "checkpoint.h5", "w") as f:
        f.attrs["format"] = "MULTICOR checkpoint 1"
        f.create_group("fem/mesh")
    assert plot_beam.main([str(tmp_path / "checkpoint.h5")]) == 1
    assert "is a MULTICOR checkpoint (for --restart)" in capsys.readouterr().err


@pytest.mark.parametrize("disk", ["0", "-2", "10000"])
def test_plot_experiments_refuses_a_tracked_disk_the_runs_do_not_have(disk, tmp_path, capsys):
    # --track 0 drew the last disk (index -1) under the title 'disk 0', with exit 0; then the
    # refusal came after the profiles and configurations of the folder had been replaced
    for case in plot_experiments.CASES:
        (tmp_path / case).mkdir()
        write_coupled(tmp_path / case / f"{case}.h5", title=case)
    earlier = tmp_path / "bending_case1_profiles.png"
    earlier.write_bytes(b"figure of an earlier run")
    before = sorted(tmp_path.rglob("*"))
    assert plot_experiments.main(["--results", str(tmp_path), "--track", disk]) == 1
    err = capsys.readouterr().err
    assert f"no disk {disk} (the run has disks 1.." in err
    # refused before any figure: nothing written, the earlier figure as it was
    assert sorted(tmp_path.rglob("*")) == before
    assert earlier.read_bytes() == b"figure of an earlier run"


def test_plot_experiments_creates_no_folder_for_results_it_cannot_load(tmp_path, capsys):
    # a mistyped --results (the default --out) was created as an empty folder
    missing = tmp_path / "typo"
    assert plot_experiments.main(["--results", str(missing)]) == 1
    assert "does not exist" in capsys.readouterr().err
    assert not missing.exists()


def test_plot_experiments_output_folder_that_is_a_file(tmp_path, capsys):
    blocker = tmp_path / "blocker"
    blocker.write_text("")
    for case in plot_experiments.CASES:
        (tmp_path / case).mkdir()
        write_coupled(tmp_path / case / f"{case}.h5", title=case)
    # disks the synthetic runs have (5; the default 7 11 17 is refused before the folder)
    assert plot_experiments.main(["--results", str(tmp_path), "--out", str(blocker), "--track", "2", "5"]) == 1
    assert f"the folder of the figures '{blocker}' is a file" in capsys.readouterr().err


@pytest.fixture
def fake_exe(tmp_path):
    exe = tmp_path / "multicor"
    exe.write_text("#!/bin/sh\nexit 0\n")
    exe.chmod(0o755)
    return exe


def test_run_interface_experiment_keeps_a_folder_it_did_not_write(fake_exe, tmp_path, capsys):
    # --out is emptied first: a folder of other results (a typo such as --out results) was
    # deleted whole before anything ran
    out = tmp_path / "results"
    out.mkdir()
    (out / "precious.h5").write_bytes(b"x")
    assert run_interface_experiment.main(["--exe", str(fake_exe), "--out", str(out)]) == 1
    assert "holds precious.h5, which this script did not write" in capsys.readouterr().err
    assert (out / "precious.h5").read_bytes() == b"x"


@pytest.mark.parametrize("case, message", [
    ("exe", "not an executable file"), ("deck", "no such deck"), ("out", "a file, not a folder")])
def test_run_interface_experiment_checks_its_arguments_first(case, message, fake_exe, tmp_path,
                                                             capsys):
    # each was a traceback (PermissionError in a thread, FileNotFoundError, NotADirectoryError)
    blocker = tmp_path / "blocker"
    blocker.write_text("keep")
    args = {"exe": str(fake_exe), "deck": run_interface_experiment.ROOT / "input" /
            "interface_shear.dat", "out": str(tmp_path / "new")}
    args[case] = {"exe": str(blocker), "deck": str(tmp_path / "none.dat"),
                  "out": str(blocker)}[case]
    argv = [f"--{k}={v}" for k, v in args.items()]
    assert run_interface_experiment.main(argv) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err
    assert blocker.read_text() == "keep" and not (tmp_path / "new").exists()


def test_run_interface_experiment_empties_an_earlier_experiment(fake_exe, tmp_path):
    # the folder of an earlier experiment is still emptied (the fake executable prints no
    # deck reference, so multicor-sweep refuses to create the sweeps: exit 1 after the folder
    # was emptied and the base deck written)
    out = tmp_path / "interface"
    for name in ("mu", "cohesion", "width"):
        (out / name / "runs").mkdir(parents=True)
    (out / "mu" / "old.txt").write_text("old")
    (out / "interface_shear.dat").write_text("old")
    assert run_interface_experiment.main(["--exe", str(fake_exe), "--out", str(out),
                                          "-j", "1"]) == 1
    assert not (out / "mu" / "old.txt").exists()
    assert "mesh = file " in (out / "interface_shear.dat").read_text()


def test_a_node_without_a_history_to_plot_is_said_to_be_unused(cantilever_file, tmp_path, capsys,
                                                               drawing_only):
    # --node was silently ignored where no node history is drawn (static, modal, particles)
    static = cantilever_file("static.h5", parts=("static",))
    # figures drawn by test_beam.py's test_cli_writes_every_plot_of_a_straight_cantilever and
    # test_particles.py's test_cli_writes_the_particle_plots (--node changes none of them)
    with drawing_only():
        assert plot_results.main([str(static), "--node", "3", "--out", str(tmp_path / "a")]) == 0
        err = capsys.readouterr().err
        assert "--node 3 is not used" in err and "static.h5" in err
        dem = write_dem(tmp_path / "dem.h5")
        assert plot_results.main([str(dem), "--node", "3", "--out", str(tmp_path / "b")]) == 0
        assert "--node 3 is not used" in capsys.readouterr().err
    # where the history is drawn, no note (the energy, static and modal figures: those of
    # test_cli_writes_every_plot_of_a_straight_cantilever)
    dynamic = cantilever_file("dynamic.h5")
    with drawing_only("dynamic_deflection.png", "dynamic_history_node50.png"):
        assert plot_results.main([str(dynamic), "--node", "50", "--out", str(tmp_path / "c")]) == 0
    assert "not used" not in capsys.readouterr().err


def test_a_scale_without_a_deformed_shape_to_magnify_is_said_to_be_unused(cantilever_file,
                                                                          tmp_path, capsys,
                                                                          drawing_only):
    # --scale was silently ignored where no figure magnifies displacements: a straight beam
    # (its deflection drawn in length units), its mode shapes, particles only
    from test_continuum import write as write_continuum
    straight = cantilever_file("straight.h5")
    # --scale changes none of these figures: the straight beam's are drawn by
    # test_a_node_without_a_history_to_plot_is_said_to_be_unused (the deflection at the last
    # output) and test_beam.py's test_cli_writes_every_plot_of_a_straight_cantilever, the
    # particles' by test_particles.py's test_cli_writes_the_particle_plots
    with drawing_only():
        for script in (plot_results, plot_beam):
            assert script.main([str(straight), "--scale", "100", "--out", str(tmp_path / "a")]) == 0
            err = capsys.readouterr().err
            assert err == (f"{script.__name__}.py: note: --scale 100 is not used: '{straight}' "
                           "has no deformed shape to magnify (frames, 2D continua and "
                           "beam-coupled runs have one; a straight beam's deflection is drawn "
                           "in length units)\n")
        dem = write_dem(tmp_path / "dem.h5")
        assert plot_results.main([str(dem), "--scale", "5", "--out", str(tmp_path / "b")]) == 0
        assert "--scale 5 is not used" in capsys.readouterr().err
    # where a deformed shape is drawn (a frame, a continuum, a beam-coupled run), no note; the
    # figures --scale shapes are drawn, the others are those of the tests named above and of
    # test_continuum.py's test_cli_writes_the_figures_of_each_kind and test_coupled.py's
    # test_plot_results_handles_a_coupled_file
    frame = cantilever_file("frame.h5", angle=0.5)
    plate = write_continuum(tmp_path / "plate.h5")
    glued = write_coupled(tmp_path / "glued.h5")
    for path, drawn in ((frame, ("deflection", "history_node90", "static", "modes")),
                        (plate, ("stress",)), (glued, ("configuration",))):
        with drawing_only(*(f"{path.stem}_{name}.png" for name in drawn)):
            assert plot_results.main([str(path), "--scale", "100", "--out",
                                      str(tmp_path / "c")]) == 0
        assert "not used" not in capsys.readouterr().err
    # the figures plot_results.py has just drawn of the frame
    with drawing_only():
        assert plot_beam.main([str(frame), "--scale", "100", "--out", str(tmp_path / "c")]) == 0
    assert "not used" not in capsys.readouterr().err


@pytest.mark.parametrize("script", [plot_results, plot_beam])
def test_a_folder_given_as_the_results_file_is_a_one_line_error(script, tmp_path, capsys):
    # h5py's message ('Is a directory', with HDF5's 'time = ...' field ending in a newline)
    # made it two lines
    assert script.main([str(tmp_path)]) == 1
    err = capsys.readouterr().err
    assert err == (f"{script.__name__}.py: error: '{tmp_path}' is a folder, not a results file: "
                   "give the <deck name>.h5 in it\n")
