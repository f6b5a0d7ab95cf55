"""Files of runs stopped early, and a --time outside the stored outputs: the plotting scripts
say what they did or why there is nothing to plot, in one line, never with a traceback.

The files mimic what `kill -9` leaves (doc/output.md, Interrupted runs). Killed before its
first stored output, a run's partial file holds the root attributes and /summary only
(finished = 0, status = 'running (or killed)'); killed after the output datasets were
created but before their first record, it holds time series of 0 records; killed before its
4096th step (the solver statistics are written in blocks of 4096 steps), /dem/solver holds 0
steps while the outputs are there, and so do the per-step series of /coupling.

A static or modal run flushes its file once, at its end: killed before (checked with kill -9
on a 1200 x 120 static continuum while it wrote its results and a 400 x 40 modal continuum
during its eigensolve), its partial file holds the root attributes and /summary only, the
mesh not yet visible. A mesh without a solution, or the
datasets of two groups with different numbers of records (a kill between their writes), is
what such a file shows when HDF5 has written its metadata out before the kill, which it may
do at any time. A kill inside those metadata writes can leave an object unreadable (an
object header overwritten here): the scripts say the file is damaged, in one line.
"""
import h5py
import numpy as np
import pytest
from synthetic_coupled import STEP_REALS, write_continuum_coupled, write_coupled
from synthetic_dem import H, N_OUT, STEPS_PER_OUT, write_dem
from test_continuum import write as write_continuum

import plot_beam
import plot_results
from multicor_post import continuum, coupled, particles
from multicor_post.results import ResultsError, load_results, outside_time_note

STOPPED = "partial file of a run stopped before its first stored output: nothing to plot"
STOPPED_SOLUTION = "partial file of a run stopped before its solution was written: nothing to plot"
#: The times of synthetic_dem's outputs: 0, 5 ms, 10 ms, 15 ms.
T_LAST = H * STEPS_PER_OUT * (N_OUT - 1)


def mark_killed(path, analysis="dynamic"):
    """Give a results file the root attributes and /summary of a killed run's partial file
    (as written by multicor at the file's creation; the deck's title, kept when the file has
    one, so that the figures of data another test plots are the same)."""
    with h5py.File(path, "a") as f:
        f.attrs["code_name"] = "MULTICOR"
        f.attrs["code_version"] = "0.1.0"
        f.attrs["analysis"] = analysis
        f.attrs["run_id"] = "2026-01-01T00:00:00+00:00 1"
        f.attrs["title"] = f.attrs.get("title", "")
        summary = f.require_group("summary")
        summary.attrs["finished"] = np.int32(0)
        summary.attrs["status"] = "running (or killed)"
    return path


def empty_series(path, names):
    """Cut the datasets ``names`` of a file to 0 records along their first axis (extendible,
    as multicor creates them)."""
    with h5py.File(path, "a") as f:
        for name in names:
            data = f[name][()]
            del f[name]
            f.create_dataset(name, data=data[:0], maxshape=(None,) + data.shape[1:], chunks=True)
    return path


def dem_series(path):
    """The /dem datasets with one record per stored output."""
    with h5py.File(path, "r") as f:
        names = ["dem/time", "dem/position", "dem/velocity", "dem/walls/position"]
        return names + [f"dem/energy/{n}" for n in f["dem/energy"]]


#: The concatenated contact lists of /dem/contacts (no record before the first output).
CONTACT_LISTS = ("i", "j", "normal", "rn", "rt", "status")


def assert_one_line_error(err, *parts):
    assert err.startswith(parts[0]) and err.count("\n") == 1 and "Traceback" not in err
    for part in parts[1:]:
        assert part in err


# --------------------------------------------------------------------------------------------
# Killed before the first stored output: root attributes and /summary only
# --------------------------------------------------------------------------------------------

@pytest.mark.parametrize("script", [plot_results, plot_beam])
def test_a_run_killed_before_its_first_output_has_nothing_to_plot(script, tmp_path, capsys):
    # it said "neither /fem/mesh, /continuum nor /dem: not a MULTICOR results file"
    path = mark_killed(tmp_path / "big.h5.partial")
    out = tmp_path / "png"
    assert script.main([str(path), "--out", str(out)]) == 1
    assert_one_line_error(capsys.readouterr().err, f"{script.__name__}.py: error: ", str(path),
                          STOPPED, "running (or killed)")
    assert not out.exists()


def test_a_finished_file_without_results_is_still_not_a_results_file(tmp_path, capsys):
    # only the file of an unfinished run is explained by a stop before the first output
    path = mark_killed(tmp_path / "odd.h5")
    with h5py.File(path, "a") as f:
        f["summary"].attrs["finished"] = np.int32(1)
    assert plot_results.main([str(path)]) == 1
    err = capsys.readouterr().err
    assert "not a MULTICOR results file" in err and STOPPED not in err


# --------------------------------------------------------------------------------------------
# Time series of 0 records
# --------------------------------------------------------------------------------------------

def test_particles_without_a_stored_output(tmp_path, capsys):
    # plot_configuration failed with IndexError on res.position[-1]
    path = write_dem(tmp_path / "column.h5")
    empty_series(path, dem_series(path) + [f"dem/contacts/{n}" for n in CONTACT_LISTS])
    with h5py.File(path, "a") as f:
        del f["dem/contacts/offset"]               # [0]: multicor's first entry, at creation
        f.create_dataset("dem/contacts/offset", data=[0], maxshape=(None,), dtype=np.int32)
    with pytest.raises(ResultsError, match="/dem/time holds no stored output: nothing to plot"):
        particles.load_dem(path)
    assert plot_results.main([str(path), "--out", str(tmp_path / "png")]) == 1
    assert_one_line_error(capsys.readouterr().err, "plot_results.py: error: ",
                          "/dem/time holds no stored output: nothing to plot")
    # the same file left by a killed run says so
    mark_killed(path)
    assert plot_results.main([str(path), "--out", str(tmp_path / "png")]) == 1
    assert_one_line_error(capsys.readouterr().err, "plot_results.py: error: ", STOPPED,
                          "/dem/time holds none")
    assert not (tmp_path / "png").exists()


@pytest.mark.parametrize("script", [plot_results, plot_beam])
def test_a_beam_without_a_stored_output(script, cantilever_file, tmp_path, capsys):
    # beam.plot_deflection failed with IndexError on dyn.time[-1]
    path = cantilever_file(parts=("dynamic", "energy"))
    empty_series(path, ["fem/time", "fem/displacement", "fem/velocity", "fem/acceleration",
                        "energy/time", "energy/kinetic", "energy/strain", "energy/external_work",
                        "energy/damping", "energy/balance"])
    mark_killed(path)
    with pytest.raises(ResultsError, match=STOPPED):
        load_results(path)
    assert script.main([str(path), "--out", str(tmp_path / "png")]) == 1
    assert_one_line_error(capsys.readouterr().err, f"{script.__name__}.py: error: ", STOPPED,
                          "/fem/time holds none")


def test_a_continuum_without_a_stored_output(tmp_path, capsys):
    # continuum.plot_stress failed with IndexError on res.u[-1]
    path = write_continuum(tmp_path / "plate.h5")
    with h5py.File(path, "r") as f:
        names = ["continuum/time", "continuum/displacement", "continuum/velocity",
                 "continuum/stress"] + [f"continuum/energy/{n}" for n in f["continuum/energy"]]
    empty_series(path, names)
    with pytest.raises(ResultsError, match="/continuum/time holds no stored output"):
        continuum.load_continuum(path)
    assert plot_results.main([str(path), "--out", str(tmp_path / "png")]) == 1
    assert_one_line_error(capsys.readouterr().err, "plot_results.py: error: ",
                          "/continuum/time holds no stored output: nothing to plot")


# --------------------------------------------------------------------------------------------
# A figure skipped because its series is empty
# --------------------------------------------------------------------------------------------

def test_a_solver_figure_without_steps_is_skipped_with_a_note(tmp_path, capsys, drawing_only):
    # a run killed before its 4096th step: the outputs are there, /dem/solver holds no step;
    # the solver figure was skipped without a word
    path = write_dem(tmp_path / "column.h5")
    with h5py.File(path, "r") as f:
        names = [f"dem/solver/{n}" for n in f["dem/solver"]]
    mark_killed(empty_series(path, names))
    out = tmp_path / "png"
    # the other figures: those test_particles.py's test_cli_writes_the_particle_plots draws
    # (the solver figure is drawn if saved, for the check below)
    with drawing_only("column_solver.png"):
        assert plot_results.main([str(path), "--out", str(out)]) == 0
    printed = capsys.readouterr()
    assert str(out / "column_particles.png") in printed.out.split()
    assert not (out / "column_solver.png").exists()
    assert ("plot_results.py: note: column_solver.png is not written: /dem/solver holds no step"
            in printed.err)
    # with the steps, no note (the other figures: those test_particles.py's
    # test_cli_writes_the_particle_plots draws)
    with drawing_only("full_solver.png"):
        assert plot_results.main([str(write_dem(tmp_path / "full.h5")), "--out", str(out)]) == 0
    printed = capsys.readouterr()
    assert (out / "full_solver.png").exists() and "note" not in printed.err


# --------------------------------------------------------------------------------------------
# --time outside [t0, t_last]
# --------------------------------------------------------------------------------------------

@pytest.mark.parametrize("time, used", [("99", "the last one, t = 0.015 s"),
                                        ("-5", "the first one, t = 0 s")])
def test_a_time_outside_the_outputs_gets_a_note(time, used, tmp_path, capsys, drawing_only):
    # --time 99 on a run that ends at 15 ms drew the last output without a word
    path = write_dem(tmp_path / "column.h5")
    # the configuration at the last or the first output and the series: figures that
    # test_particles.py's test_cli_writes_the_particle_plots draws
    with drawing_only():
        assert plot_results.main([str(path), "--time", time, "--out", str(tmp_path / "png")]) == 0
    err = capsys.readouterr().err
    assert err == (f"plot_results.py: note: --time {time} s is outside the stored outputs "
                   f"[0, 0.015] s: the snapshot figures show {used}\n")


@pytest.mark.parametrize("time", [0.0, 0.007, T_LAST, 0.015, T_LAST * (1 + 1e-12), -1e-14])
def test_a_time_inside_the_outputs_gets_no_note(time):
    # the ends are inside, also within round-off of them: 1e-12 relative (a few hundred ulps,
    # the size of the error of a time summed step by step) is below the 1e-9 of the span that
    # outside_time_note allows
    assert outside_time_note(time, np.array([0.0, 0.005, 0.01, T_LAST])) is None


@pytest.mark.parametrize("time", [T_LAST * (1 + 1e-6), -1e-6 * T_LAST])
def test_a_time_just_outside_the_outputs_gets_a_note(time):
    # 1e-6 of the span beyond an end: 1000 times the allowance, still a real request outside
    assert "is outside the stored outputs" in outside_time_note(time, np.array([0.0, T_LAST]))


@pytest.mark.parametrize("script", [plot_results, plot_beam])
def test_a_beam_time_outside_the_outputs_gets_a_note(script, cantilever_file, tmp_path, capsys,
                                                    drawing_only):
    path = cantilever_file(parts=("dynamic", "energy"))
    with h5py.File(path, "r") as f:
        t_last = float(f["fem/time"][-1])
    # the history and the energy do not depend on --time: test_beam.py's
    # test_cli_writes_every_plot_of_a_straight_cantilever draws them
    with drawing_only("cantilever_deflection.png"):
        assert script.main([str(path), "--time", "1e3", "--out", str(tmp_path / "png")]) == 0
    err = capsys.readouterr().err
    assert f"{script.__name__}.py: note: --time 1000 s is outside the stored outputs" in err
    assert f"the last one, t = {t_last:.6g} s" in err and err.count("\n") == 1


# --------------------------------------------------------------------------------------------
# Static and modal runs killed before their solution
# --------------------------------------------------------------------------------------------

@pytest.mark.parametrize("analysis", ["static", "modal"])
@pytest.mark.parametrize("script", [plot_results, plot_beam])
def test_a_static_run_killed_before_its_mesh_was_flushed(script, analysis, tmp_path, capsys):
    # what the real kill -9 of a static or modal run during its solve leaves: it said
    # "stopped before its first stored output", and a static run has no stored outputs
    path = mark_killed(tmp_path / "big.h5.partial", analysis)
    assert script.main([str(path), "--out", str(tmp_path / "png")]) == 1
    assert_one_line_error(capsys.readouterr().err, f"{script.__name__}.py: error: ",
                          STOPPED_SOLUTION, "running (or killed)")


@pytest.mark.parametrize("analysis", ["static", "modal"])
@pytest.mark.parametrize("script", [plot_results, plot_beam])
def test_a_beam_killed_between_its_mesh_and_its_solution(script, analysis, cantilever_file,
                                                           tmp_path, capsys):
    # it said "nothing to plot (no /fem/time, /static or /modal)", not why
    path = mark_killed(cantilever_file(parts=()), analysis)
    with pytest.raises(ResultsError, match=STOPPED_SOLUTION):
        load_results(path)
    assert script.main([str(path), "--out", str(tmp_path / "png")]) == 1
    assert_one_line_error(capsys.readouterr().err, f"{script.__name__}.py: error: ",
                          STOPPED_SOLUTION, f"no /{analysis}", "running (or killed)")
    # a finished file without its solution: said plainly, not as a stopped run
    with h5py.File(path, "a") as f:
        f["summary"].attrs["finished"] = np.int32(1)
    assert script.main([str(path), "--out", str(tmp_path / "png")]) == 1
    err = capsys.readouterr().err
    assert_one_line_error(err, f"{script.__name__}.py: error: ",
                          f"holds no /{analysis}: nothing to plot")
    assert "partial file" not in err


@pytest.mark.parametrize("analysis", ["static", "modal"])
def test_a_continuum_killed_between_its_mesh_and_its_solution(analysis, tmp_path, capsys):
    # it said "missing dataset '/continuum/time'": a static run has no time series
    path = write_continuum(tmp_path / "plate.h5.partial", analysis)
    with h5py.File(path, "a") as f:
        del f[f"continuum/{analysis}"]
    mark_killed(path, analysis)
    with pytest.raises(ResultsError, match=STOPPED_SOLUTION):
        continuum.load_continuum(path)
    assert plot_results.main([str(path), "--out", str(tmp_path / "png")]) == 1
    assert_one_line_error(capsys.readouterr().err, "plot_results.py: error: ", STOPPED_SOLUTION,
                          f"no /continuum/{analysis}", "running (or killed)")
    with h5py.File(path, "a") as f:
        f["summary"].attrs["finished"] = np.int32(1)
    assert plot_results.main([str(path), "--out", str(tmp_path / "png")]) == 1
    err = capsys.readouterr().err
    assert_one_line_error(err, "plot_results.py: error: ",
                          f"holds no /continuum/{analysis}: nothing to plot")
    assert "missing dataset" not in err and "partial file" not in err


def test_a_dynamic_continuum_killed_before_its_series_were_created(tmp_path, capsys):
    # the mesh alone in a dynamic run's partial file: said "missing dataset '/continuum/time'"
    path = write_continuum(tmp_path / "plate.h5.partial")
    with h5py.File(path, "a") as f:
        for name in ("time", "displacement", "velocity", "stress", "energy"):
            del f[f"continuum/{name}"]
    mark_killed(path)
    assert plot_results.main([str(path), "--out", str(tmp_path / "png")]) == 1
    assert_one_line_error(capsys.readouterr().err, "plot_results.py: error: ", STOPPED,
                          "no /continuum/time")


# --------------------------------------------------------------------------------------------
# --time for a static or modal run
# --------------------------------------------------------------------------------------------

@pytest.mark.parametrize("analysis", ["static", "modal"])
@pytest.mark.parametrize("script", [plot_results, plot_beam])
def test_a_time_for_a_static_beam_gets_a_note(script, analysis, cantilever_file, tmp_path,
                                              capsys, drawing_only):
    # --time 0.5 on a static run was ignored without a word
    path = cantilever_file(parts=(analysis,))
    # every figure here is one test_beam.py's test_cli_writes_every_plot_of_a_straight_cantilever
    # draws (the same cantilever, the deflection at --time 0.005)
    with drawing_only():
        assert script.main([str(path), "--time", "0.5", "--out", str(tmp_path / "png")]) == 0
        err = capsys.readouterr().err
        assert err == (f"{script.__name__}.py: note: --time 0.5 s is ignored: it applies to "
                       f"dynamic runs only, and this is a {analysis} run ("
                       + ("one solution" if analysis == "static" else "mode shapes")
                       + ", no stored outputs in time)\n")
        # without --time, or for a dynamic run, no note
        assert script.main([str(path), "--out", str(tmp_path / "png")]) == 0
        assert capsys.readouterr().err == ""
        dynamic = cantilever_file("dynamic.h5", parts=("dynamic", "energy"))
        assert script.main([str(dynamic), "--time", "0.005", "--out", str(tmp_path / "png")]) == 0
        assert capsys.readouterr().err == ""


@pytest.mark.parametrize("analysis", ["static", "modal"])
def test_a_time_for_a_static_continuum_gets_a_note(analysis, tmp_path, capsys, drawing_only):
    path = write_continuum(tmp_path / "plate.h5", analysis)
    # the figure test_continuum.py's test_cli_writes_the_figures_of_each_kind draws
    with drawing_only():
        assert plot_results.main([str(path), "--time", "2", "--out", str(tmp_path / "png")]) == 0
    err = capsys.readouterr().err
    assert err.startswith("plot_results.py: note: --time 2 s is ignored: it applies to "
                          f"dynamic runs only, and this is a {analysis} run")
    assert err.count("\n") == 1


# --------------------------------------------------------------------------------------------
# The coupling figure of a run killed before its 4096th step
# --------------------------------------------------------------------------------------------

COUPLED_KINDS = {"beam": (write_coupled, lambda path: coupled.load_coupled(path).coupling),
                 "continuum": (write_continuum_coupled, coupled.load_continuum_coupling)}


@pytest.mark.parametrize("kind", sorted(COUPLED_KINDS))
def test_the_coupling_figure_without_steps_says_so(kind, tmp_path, capsys, drawing_only):
    # the per-step panels were drawn empty (curves of no point in the legend, axes around 0)
    # with nothing saying why
    write, load = COUPLED_KINDS[kind]
    path = write(tmp_path / "glued.h5.partial")
    mark_killed(empty_series(path, [f"coupling/{n}" for n in STEP_REALS + ("sweeps",
                                                                             "corrections")]))
    diag = load(path)
    assert diag.no_step_yet
    fig = coupled.plot_coupling(diag)
    ax_r, ax_l = fig.axes[0], fig.axes[1]
    texts = [t.get_text() for ax in (ax_r, ax_l) for t in ax.texts]
    assert texts == ["residuals, sweeps and ‖λ‖ of every step: " + coupled.NO_STEP_YET]
    # no empty curve: the residual panel draws nothing, the multipliers' panel the outputs'
    assert ax_r.get_lines() == [] and ax_r.get_legend() is None
    assert all(line.get_xdata().size == N_OUT for line in ax_l.get_lines())
    # the per-step panel spans the outputs' times (in ms) as the multipliers' panel does, not
    # matplotlib's default [-0.05, 0.05]
    lo, hi = ax_r.get_xlim()
    assert (lo, hi) == ax_l.get_xlim() and lo <= 0.0 and hi >= T_LAST * 1e3
    out = tmp_path / "png"
    # the other figures of the same data: those test_coupled.py's
    # test_plot_results_handles_a_coupled_file and test_coupling_figure.py's
    # test_plot_results_writes_the_coupling_figure_of_a_continuum_run draw
    with drawing_only("glued_coupling.png"):
        assert plot_results.main([str(path), "--out", str(out)]) == 0
    printed = capsys.readouterr()
    assert str(out / "glued_coupling.png") in printed.out.split()
    assert ("plot_results.py: note: glued_coupling.png has no per-step curves: /coupling holds "
            "no step" in printed.err)


# --------------------------------------------------------------------------------------------
# A kill between the records of two groups
# --------------------------------------------------------------------------------------------

def cut_last_record(path, names):
    """Drop the last record of the datasets ``names`` (a kill after the other datasets of
    the last output were extended, before these were)."""
    with h5py.File(path, "a") as f:
        for name in names:
            f[name].resize(f[name].shape[0] - 1, axis=0)
    return path


INCOMPLETE = ("is the partial file of a stopped run (status: running (or killed)): the records "
              "of its last output are incomplete")


def test_particles_with_an_incomplete_last_output(tmp_path, capsys):
    # /dem/time holds N_OUT records, /dem/position N_OUT - 1: the shape error did not say why
    path = write_dem(tmp_path / "column.h5")
    with h5py.File(path, "a") as f:     # extendible, as multicor creates the series
        data = f["dem/position"][()]
        del f["dem/position"]
        f.create_dataset("dem/position", data=data, maxshape=(None,) + data.shape[1:])
    cut_last_record(path, ["dem/position"])
    assert plot_results.main([str(path), "--out", str(tmp_path / "png")]) == 1
    err = capsys.readouterr().err
    assert_one_line_error(err, "plot_results.py: error: ", "dataset '/dem/position' has shape")
    assert "partial file" not in err        # a finished file: not explained by a kill
    mark_killed(path)
    assert plot_results.main([str(path), "--out", str(tmp_path / "png")]) == 1
    assert_one_line_error(capsys.readouterr().err, "plot_results.py: error: ",
                          f"dataset '/dem/position' has shape ({N_OUT - 1}, ", INCOMPLETE)


def extendible(path, names):
    """Make the datasets ``names`` extendible along their first axis, as multicor creates
    its series (the synthetic writer does not)."""
    with h5py.File(path, "a") as f:
        for name in names:
            data = f[name][()]
            del f[name]
            f.create_dataset(name, data=data, maxshape=(None,) + data.shape[1:])
    return path


def test_a_killed_file_is_read_up_to_its_count_of_whole_outputs(tmp_path, capsys, drawing_only):
    # /summary@outputs counts the outputs a run flushed whole: a kill inside the flush of
    # the next one left /dem/position one record short (out of step) and the last record of
    # /dem/velocity zero (in step, but not written): both are left out, the figures drawn
    path = write_dem(tmp_path / "column.h5.partial")
    extendible(path, dem_series(path) + [f"dem/contacts/{n}" for n in CONTACT_LISTS + ("offset",)])
    with h5py.File(path, "r") as f:
        velocity = f["dem/velocity"][()]
    cut_last_record(mark_killed(path), ["dem/position"])
    with h5py.File(path, "a") as f:
        f["dem/velocity"][-1] = 0.0
    # without the count (a file of an earlier build): the out-of-step error, as before
    with pytest.raises(ResultsError, match="records of its last output are incomplete"):
        particles.load_dem(path)
    with h5py.File(path, "a") as f:
        f["summary"].attrs["outputs"] = np.int32(N_OUT - 1)
    res = particles.load_dem(path)
    assert res.time.size == N_OUT - 1 and res.position.shape[0] == N_OUT - 1
    assert np.array_equal(res.velocity, velocity[:N_OUT - 1])
    # the first output and the solver statistics, which the cut leaves as they are:
    # test_particles.py's test_cli_writes_the_particle_plots draws them
    with drawing_only(all_but=("column_particles_start.png", "column_solver.png")):
        assert plot_results.main([str(path), "--out", str(tmp_path / "png")]) == 0
    assert "error" not in capsys.readouterr().err
    # a finished file is read whole: the count does not cut it
    with h5py.File(path, "a") as f:
        f["summary"].attrs["finished"] = np.int32(1)
        f["summary"].attrs["outputs"] = np.int32(1)
    with pytest.raises(ResultsError, match="has shape"):
        particles.load_dem(path)


#: Groups of datasets written once (not one record per output): never made extendible.
_FIXED = ("continuum/mesh/", "continuum/sets/", "dem/particles/", "dem/walls/material",
          "dem/solver/", "coupling/rows/", "coupling/particles", "coupling/alpha",
          "coupling/overlap", "coupling/abscissa", "coupling/offset")


def killed_after(path, whole):
    """The file of a run killed inside the flush of its output `whole` + 1: every series of
    outputs made extendible (as multicor creates them; the synthetic writers do not), the
    per-step series of /coupling too, and /summary@outputs = `whole`, below the records the
    file holds (the audit's files cut by hand: a finished file with its count decremented)."""
    names = []
    with h5py.File(path, "r") as f:
        f.visititems(lambda name, obj: names.append(name)
                     if isinstance(obj, h5py.Dataset) and obj.ndim > 0
                     and not name.startswith(_FIXED) else None)
    extendible(path, names)
    mark_killed(path)
    with h5py.File(path, "a") as f:
        f["summary"].attrs["outputs"] = np.int32(whole)
    return path


@pytest.mark.parametrize("kind", ["continuum", "coupled continuum"])
def test_a_killed_continuum_is_read_up_to_its_count_of_whole_outputs(kind, tmp_path, capsys,
                                                                  drawing_only):
    # the continuum loader cut /continuum/time to /summary@outputs but not the series read
    # against it (displacement, stress, energy terms, /dem/position, /dem/walls/position):
    # "records of its last output are incomplete ... nothing to plot" for the partial file of
    # every continuum run killed inside a flush
    if kind == "coupled continuum":
        path = write_continuum_coupled(tmp_path / "block.h5.partial")
    else:
        path = write_continuum(tmp_path / "block.h5.partial")
    with h5py.File(path, "r") as f:
        n_out = f["continuum/time"].shape[0]
        full = {name: f[name][()] for name in ("continuum/displacement", "continuum/stress")}
    killed_after(path, n_out - 1)
    res = continuum.load_continuum(path)
    assert res.time.size == n_out - 1
    assert np.array_equal(res.u, full["continuum/displacement"][:n_out - 1])
    assert np.array_equal(res.stress, full["continuum/stress"][:n_out - 1])
    assert all(res.energy[name].size == n_out - 1 for name in continuum.ENERGY_TERMS + ("time",))
    if kind == "coupled continuum":
        # the disks drawn on the mesh, and the coupling figure's multipliers: cut likewise
        assert res.disk_time.size == n_out - 1
        assert res.disk_position.shape[0] == n_out - 1 and res.walls.shape[0] == n_out - 1
        diag = coupled.load_continuum_coupling(path)
        assert diag.time.size == n_out - 1 and diag.lam.shape[0] == n_out - 1
    out = tmp_path / "png"
    # the disks at t = 0 and the solver statistics of the coupled run, which the cut leaves as
    # they are: test_coupling_figure.py's
    # test_plot_results_writes_the_coupling_figure_of_a_continuum_run draws them
    with drawing_only(all_but=("block_particles_start.png", "block_solver.png")):
        assert plot_results.main([str(path), "--out", str(out)]) == 0
    printed = capsys.readouterr()
    assert "error" not in printed.err and str(out / "block_stress.png") in printed.out.split()
    assert str(out / "block_history.png") in printed.out.split()


def test_a_continuum_with_an_incomplete_last_output(tmp_path, capsys):
    # continuum/displacement one record short of /continuum/time: a ValueError traceback
    # from matplotlib (the history's x and y of different lengths)
    path = write_continuum(tmp_path / "plate.h5")
    with h5py.File(path, "a") as f:
        data = f["continuum/displacement"][()]
        del f["continuum/displacement"]
        f["continuum/displacement"] = data[:-1]
    mark_killed(path)
    with pytest.raises(ResultsError, match="records of its last output are incomplete"):
        continuum.load_continuum(path)
    assert plot_results.main([str(path), "--out", str(tmp_path / "png")]) == 1
    assert_one_line_error(capsys.readouterr().err, "plot_results.py: error: ",
                          "dataset '/continuum/displacement' has shape (4, 7, 2), expected "
                          "(5, 7, 2)", INCOMPLETE)


# --------------------------------------------------------------------------------------------
# Metadata damaged by a kill inside HDF5's writes: the file opens, a group does not
# --------------------------------------------------------------------------------------------

def damage_object_header(path, name):
    """Overwrite the first bytes of the object header of `name` with zeros, as a kill -9
    between HDF5's metadata writes can leave it (a header whose version byte is 0: h5py
    raises from inside h5py, e.g. KeyError 'bad object header version number' or
    RuntimeError 'bad version number for attribute message', as the audit's damaged files)."""
    with h5py.File(path, "r") as f:
        address = h5py.h5o.get_info(f[name].id).addr
    with open(path, "r+b") as raw:
        raw.seek(address)
        raw.write(bytes(16))
    return path


@pytest.mark.parametrize("script", [plot_results, plot_beam])
def test_a_file_with_a_damaged_group_is_reported_without_a_traceback(script, cantilever_file, tmp_path,
                                                                     capsys):
    # plot_results.py and plot_beam.py printed h5py's traceback (KeyError 'Unable to
    # synchronously open object (addr overflow ...)') for a partial file a kill left so
    path = tmp_path / "cantilever.h5.partial"
    path.write_bytes(cantilever_file().read_bytes())
    mark_killed(path, analysis="static")
    damage_object_header(path, "fem/mesh")
    assert script.main([str(path), "--out", str(tmp_path / "png")]) == 1
    assert_one_line_error(capsys.readouterr().err, f"{script.__name__}.py: error: ", str(path),
                          "is damaged: HDF5 cannot read part of it", "run the deck again")
    assert not (tmp_path / "png").exists()


def test_an_error_not_from_h5py_is_not_called_damage(tmp_path):
    # a bug of the scripts (an exception raised outside h5py) keeps its traceback
    from multicor_post.results import damaged_file_error
    try:
        {}["x"]
    except KeyError as exc:
        assert damaged_file_error(exc, "f.h5") is None
    # so does h5py's error for an object the file does not have (a script asking for it)
    path = tmp_path / "plain.h5"
    with h5py.File(path, "w") as f:
        f.create_group("dem")
    with h5py.File(path, "r") as f:
        with pytest.raises(KeyError) as info:
            f["dem/position"]
    assert damaged_file_error(info.value, path) is None


# --------------------------------------------------------------------------------------------
# The records of a run that failed in its time loop: '<deck>.h5.failed'
# --------------------------------------------------------------------------------------------

FAILED_STATUS = ("failed at step 41, t = 4.10000000E-002 s: step 41 (t = 4.10000E-002 s): disk 1 "
                 "is at (4.081E+291, 4.000E-002) m, beyond the box the run can represent")


def test_a_failed_runs_records_are_plotted_as_a_partial_file(tmp_path, capsys, drawing_only):
    # multicor keeps the outputs a time loop stored before a guard stopped it as
    # '<deck>.h5.failed' (finished = 0, its whole outputs counted, status naming the failure):
    # read as a partial file, up to that count, the figures named after the deck, with a note
    path = write_dem(tmp_path / "column.h5.failed")
    extendible(path, dem_series(path) + [f"dem/contacts/{n}" for n in CONTACT_LISTS + ("offset",)])
    with h5py.File(path, "r") as f:
        position = f["dem/position"][()]
    mark_killed(path)
    with h5py.File(path, "a") as f:
        f["summary"].attrs["status"] = FAILED_STATUS
        f["summary"].attrs["outputs"] = np.int32(N_OUT - 1)
    res = particles.load_dem(path)
    assert res.time.size == N_OUT - 1 and np.array_equal(res.position, position[:N_OUT - 1])
    out = tmp_path / "png"
    # the figures of the same outputs that test_particles.py's test_cli_writes_the_particle_plots
    # and test_a_killed_file_is_read_up_to_its_count_of_whole_outputs draw
    with drawing_only():
        assert plot_results.main([str(path), "--out", str(out)]) == 0
    printed = capsys.readouterr()
    names = [p.rsplit("/", 1)[-1] for p in printed.out.split()]
    assert names and all(n.startswith("column_") and n.endswith(".png") for n in names), names
    assert f"'{path}' holds the records of a run that failed" in printed.err
    assert "error" not in printed.err


def test_a_failed_file_with_nothing_stored_names_its_status(tmp_path, capsys):
    # its status is what the scripts quote when it has nothing to plot, as for a partial file
    path = mark_killed(tmp_path / "big.h5.failed")
    with h5py.File(path, "a") as f:
        f["summary"].attrs["status"] = FAILED_STATUS
    assert plot_results.main([str(path), "--out", str(tmp_path / "png")]) == 1
    assert_one_line_error(capsys.readouterr().err, "plot_results.py: error: ", str(path), STOPPED,
                          "failed at step 41")


def test_a_missing_results_file_points_to_the_failed_runs_records(tmp_path):
    (tmp_path / "run.h5.failed").write_bytes(b"")
    with pytest.raises(ResultsError, match=r"'.*run\.h5\.failed' exists: the run failed"):
        load_results(tmp_path / "run.h5")
