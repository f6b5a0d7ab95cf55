"""Tests of the coupling figure (multicor_post.coupled.plot_coupling) of both kinds of coupled
run, a beam (synthetic_coupled.write_coupled) and a 2D continuum
(write_continuum_coupled) glued to disks: every value drawn is the dataset of the file its
label names (each synthetic series has values of its own, and a mutation of one dataset
must move its curve and no other), a dataset the file lacks is named on the figure and not
drawn, and plot_results.py writes <name>_coupling.png for both kinds."""
import os
import shutil

import h5py
import numpy as np
import pytest

import plot_results
from multicor_post import coupled
from multicor_post.results import ResultsError
from synthetic_coupled import write_continuum_coupled, write_coupled
from synthetic_dem import H, N_OUT, STEPS_PER_OUT

#: The synthetic run lasts 15 ms: the figure's times are in ms.
MS = 1e3
#: Values read back from float64 datasets, or sums of two of them: exact; the figure's times
#: are the file's times times 1e3 (a rounding of that product, a few ulps of 15).
EXACT = 0.0
TIME_ULPS = 4 * np.spacing(15.0)

#: The curves of each panel: label (its start, the balance's label goes on with the largest
#: value) -> the /coupling datasets summed into it.
RESIDUAL_CURVES = {"|q - C u|": ("position_residual",),
                   "|x - x0 - C(u - u0)|": ("coordinate_residual",),
                   "velocity residual": ("velocity_residual",),
                   "‖g‖ before the multipliers": ("g_norm",)}
ENERGY_CURVES = {"{body}: kinetic + strain": ("energy/fe_kinetic", "energy/fe_strain"),
                 "disks: kinetic + potential": ("energy/dem_kinetic", "energy/dem_potential"),
                 "external work": ("energy/external_work",),
                 "dissipated in contacts": ("energy/contact_dissipation",),
                 "damping + numerical dissipation": ("energy/fe_damping",
                                                     "energy/numerical_dissipation"),
                 "balance (0 = exact)": ("energy/balance",)}

KINDS = {"beam": (write_coupled, lambda path: coupled.load_coupled(path).coupling),
         "continuum": (write_continuum_coupled, coupled.load_continuum_coupling)}


def figure(path, kind):
    """plot_coupling of the file, loaded by the loader of its kind."""
    return coupled.plot_coupling(KINDS[kind][1](path))


def curves(ax, body):
    """{key of the curve tables: line} of one panel (a label is matched by its start)."""
    out = {}
    for line in ax.get_lines():
        label = line.get_label()
        for key in list(RESIDUAL_CURVES) + list(ENERGY_CURVES):
            if label.startswith(key.format(body=body)):
                out[key] = line
    return out


def expected(f, names):
    """Sum of the /coupling datasets `names` as the file holds them."""
    return sum(f[f"coupling/{n}"][()] for n in names)


def drawn_values(path, kind):
    """{curve key: (x, y)} of the residual and energy panels, the multiplier rows, the
    ‖λ‖ curve and the sweeps."""
    fig = figure(path, kind)
    ax_r, ax_l, ax_e, ax_s = fig.axes
    out = {key: (line.get_xdata(), line.get_ydata())
           for ax in (ax_r, ax_e) for key, line in curves(ax, kind).items()}
    lam = [line for line in ax_l.get_lines()]
    out["lambda rows"] = (lam[0].get_xdata(), np.stack([line.get_ydata() for line in lam[:-1]],
                                                       axis=1))
    out["lambda_norm"] = (lam[-1].get_xdata(), lam[-1].get_ydata())
    out["sweeps"] = (ax_s.get_lines()[0].get_xdata(), ax_s.get_lines()[0].get_ydata())
    return out


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_every_curve_is_the_dataset_its_label_names(tmp_path, kind):
    path = KINDS[kind][0](tmp_path / f"{kind}.h5")
    drawn = drawn_values(path, kind)
    steps = (N_OUT - 1) * STEPS_PER_OUT
    step_t = (np.arange(steps) + 1) * H * MS     # entry k: the step ending at (k + 1) h
    out_t = H * STEPS_PER_OUT * np.arange(N_OUT) * MS
    with h5py.File(path, "r") as f:
        for key, names in RESIDUAL_CURVES.items():
            x, y = drawn[key]
            np.testing.assert_allclose(x, step_t, rtol=0, atol=TIME_ULPS)
            np.testing.assert_allclose(y, expected(f, names), rtol=0, atol=EXACT)
        for key, names in ENERGY_CURVES.items():
            x, y = drawn[key]
            np.testing.assert_allclose(x, out_t, rtol=0, atol=TIME_ULPS)
            np.testing.assert_allclose(y, expected(f, names), rtol=0, atol=EXACT)
        x, y = drawn["lambda rows"]
        np.testing.assert_allclose(x, out_t, rtol=0, atol=TIME_ULPS)
        np.testing.assert_array_equal(y, f["coupling/lambda"][()])
        np.testing.assert_array_equal(drawn["lambda_norm"][1], f["coupling/lambda_norm"][()])
        np.testing.assert_array_equal(drawn["sweeps"][1], f["coupling/sweeps"][()])
    # the kind's name in the legend, the largest |balance| (1e-12 k at output k) in its label
    labels = [line.get_label() for line in figure(path, kind).axes[2].get_lines()]
    assert f"{kind}: kinetic + strain" in labels
    assert f"balance (0 = exact); largest |balance| {3e-12:.2g} J" in labels


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_a_mutated_dataset_moves_its_curve_and_no_other(tmp_path, kind):
    # the synthetic series differ from each other, but a figure that drew, e.g., the
    # velocity residual under the label of the position residual could still pass a test
    # written from the same table: change one dataset at a time in a copy of the file and
    # check that exactly the curve of that dataset moves, to the new values
    path = KINDS[kind][0](tmp_path / f"{kind}.h5")
    before = drawn_values(path, kind)
    # the premise: no two curves draw the same numbers
    assert len({v[1].tobytes() for v in before.values()}) == len(before)
    mutations = {key: names[0] for key, names in {**RESIDUAL_CURVES, **ENERGY_CURVES}.items()}
    mutations.update({"lambda rows": "lambda", "lambda_norm": "lambda_norm", "sweeps": "sweeps"})
    for key, name in mutations.items():
        copy = tmp_path / f"{kind}_{name.replace('/', '_')}.h5"
        shutil.copy(path, copy)
        with h5py.File(copy, "r+") as f:
            f[f"coupling/{name}"][...] = 3 * f[f"coupling/{name}"][()] + 7
        after = drawn_values(copy, kind)
        for other in before:
            moved = not np.array_equal(before[other][1], after[other][1])
            assert moved == (other == key), f"mutating /coupling/{name} moved '{other}'"
        with h5py.File(path, "r") as f:
            # the curve of a sum moves by the change of its first term, 2 x + 7; rounding of
            # 3 x + 7 and of the difference: a few ulps of the values (|x| <= 0.06, 7)
            np.testing.assert_allclose(after[key][1] - before[key][1],
                                       2 * f[f"coupling/{name}"][()] + 7, rtol=1e-12)


def test_a_dataset_the_file_lacks_is_named_and_not_drawn(tmp_path):
    path = write_continuum_coupled(tmp_path / "c.h5",
                                   drop=("coupling/coordinate_residual", "coupling/lambda_norm",
                                         "coupling/energy/fe_damping"))
    fig = figure(path, "continuum")
    ax_r, ax_l, ax_e = fig.axes[:3]
    notes = {ax: " ".join(t.get_text() for t in ax.texts) for ax in (ax_r, ax_l, ax_e)}
    assert "not in the file: coordinate_residual" in notes[ax_r]
    assert "not in the file: lambda_norm" in notes[ax_l]
    assert "not in the file: fe_damping" in notes[ax_e]
    assert "|x - x0 - C(u - u0)|" not in curves(ax_r, "continuum")
    assert "damping + numerical dissipation" not in curves(ax_e, "continuum")
    # what the file holds is still drawn
    assert len(curves(ax_r, "continuum")) == 3 and len(curves(ax_e, "continuum")) == 5
    # a complete file has no such note
    complete = figure(write_continuum_coupled(tmp_path / "full.h5"), "continuum")
    assert not any(ax.texts for ax in complete.axes)


def test_continuum_loader_checks_the_time_axes_and_the_kind(tmp_path):
    path = write_continuum_coupled(tmp_path / "c.h5")
    with h5py.File(path, "r+") as f:
        f["continuum/time"][1] += 1e-6
    with pytest.raises(ResultsError, match="/coupling/time and /continuum/time differ"):
        coupled.load_continuum_coupling(path)
    with pytest.raises(ResultsError, match="not a continuum coupled to disks"):
        coupled.load_continuum_coupling(write_coupled(tmp_path / "beam.h5"))
    broken = write_continuum_coupled(tmp_path / "b.h5", drop=("coupling/lambda",))
    with pytest.raises(ResultsError, match="missing dataset '/coupling/lambda'"):
        coupled.load_continuum_coupling(broken)


def test_plot_results_writes_the_coupling_figure_of_a_continuum_run(tmp_path, capsys):
    path = write_continuum_coupled(tmp_path / "block.h5")
    out = tmp_path / "png"
    assert plot_results.main([str(path), "--out", str(out)]) == 0
    printed = capsys.readouterr().out.split()
    # the continuum's figures, then the coupling figure, then the disks'
    assert printed[:4] == [str(out / f"block_{n}.png")
                           for n in ("stress", "continuum_energy", "history", "coupling")]
    assert printed[4] == str(out / "block_particles_start.png")
    with open(printed[3], "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n"
    assert os.path.getsize(printed[3]) > 10000
    assert "profiles" not in " ".join(printed)    # no beam to draw a profile of



def test_rotation_rows_add_the_rotation_residual(tmp_path):
    # without rotation rows the file's rotation_residual is 0 by definition: not drawn; with
    # them (attribute rotation = 1) it is, and the multipliers are forces and moments
    path = write_continuum_coupled(tmp_path / "c.h5")
    labels = [line.get_label() for line in figure(path, "continuum").axes[0].get_lines()]
    assert not any(label.startswith("rotation residual") for label in labels)
    with h5py.File(path, "r+") as f:
        f["coupling"].attrs["rotation"] = np.int32(1)
        rotation = f["coupling/rotation_residual"][()]
    fig = figure(path, "continuum")
    line = [ln for ln in fig.axes[0].get_lines() if ln.get_label().startswith("rotation residual")]
    np.testing.assert_array_equal(line[0].get_ydata(), rotation)
    assert fig.axes[1].get_ylabel() == "multipliers λ [N, N·m]"


def test_the_norm_of_the_mediator_multipliers_says_so(tmp_path):
    # multipliers = nodes: /coupling/lambda holds the forces of the disk rows, lambda_norm the
    # norm of the multipliers on the FE nodes (/coupling/mediator_nodes): the label says which
    path = write_continuum_coupled(tmp_path / "c.h5")
    assert figure(path, "continuum").axes[1].get_lines()[-1].get_label() == "‖λ‖ of every step"
    with h5py.File(path, "r+") as f:
        f["coupling/mediator_nodes"] = np.array([2, 3, 5, 6], np.int32)
    label = figure(path, "continuum").axes[1].get_lines()[-1].get_label()
    assert label == "‖λ_m‖ of every step (mediator multipliers on the FE nodes)"


def test_region_forces_sum_the_rows_of_each_region(tmp_path):
    # the synthetic multipliers are 0.1 k j at output k, row j (rows x, y of 3 disks); rows
    # 0-1 in region 2, rows 2-5 in region 1: region 1's x sums rows 2 and 4, its y rows 3 and 5
    path = write_continuum_coupled(tmp_path / "block.h5")
    with pytest.raises(ResultsError, match="no /coupling/rows/region"):
        coupled.region_forces(path)
    with h5py.File(path, "a") as f:
        f.create_dataset("coupling/rows/region", data=np.array([2, 2, 1, 1, 1, 1], np.int32))
    time, forces = coupled.region_forces(path)
    k = np.arange(N_OUT)
    assert forces.shape == (N_OUT, 2, 2) and time.size == N_OUT
    # sums of at most two values 0.1 k j: exact up to one rounding (1e-15 relative)
    np.testing.assert_allclose(forces[:, 0, 0], 0.1 * k * (2 + 4), rtol=1e-15)
    np.testing.assert_allclose(forces[:, 0, 1], 0.1 * k * (3 + 5), rtol=1e-15)
    np.testing.assert_allclose(forces[:, 1, 0], 0.1 * k * 0, rtol=1e-15)
    np.testing.assert_allclose(forces[:, 1, 1], 0.1 * k * 1, rtol=1e-15)


def test_every_axis_of_the_figure_gives_its_unit(tmp_path):
    # the residual axis said 'residual' over curves in m and m/s, and the two upper panels
    # had time axes of their own, numbered but without a label (nor its unit): the panels
    # now share the bottom one's, 't [ms]'
    path = write_coupled(tmp_path / "b.h5")
    fig = figure(path, "beam")
    ax_r, ax_l, ax_e, ax_s = fig.axes
    assert ax_r.get_ylabel() == "residual [m, m/s]"
    assert ax_e.get_xlabel() == "t [ms]"
    fig.canvas.draw()                                   # tick labels are set when drawn
    assert any(t.get_visible() and t.get_text() for t in ax_e.get_xticklabels())
    for ax in (ax_r, ax_l):
        assert ax.get_shared_x_axes().joined(ax, ax_e)
        assert ax.get_xlabel() == ""
        assert not any(t.get_visible() and t.get_text() for t in ax.get_xticklabels())
    with h5py.File(path, "r+") as f:
        f["coupling"].attrs["rotation"] = np.int32(1)
    assert figure(path, "beam").axes[0].get_ylabel() == "residual [m, m/s, rad]"
