"""Loading results files: documented shapes, nearest-time selection, clear errors."""
import numpy as np
import pytest
from synthetic import DT, N_OUT, cantilever_layout

from multicor_post import W, ResultsError, load_results


def test_load_gives_documented_shapes_and_decoded_attributes(cantilever_file):
    res = load_results(cantilever_file())
    n = 9
    assert res.attrs["code_name"] == "MULTICOR"
    assert res.title == "synthetic cantilever"
    assert res.mesh.n_nodes == n
    assert res.dynamic.time.shape == (N_OUT,)
    assert res.dynamic.displacement.shape == (N_OUT, n, 3)
    assert res.energy.balance.shape == (N_OUT,)
    assert res.static.displacement.shape == (n, 3)
    assert res.modal.shapes.shape == (2, n, 3)
    assert res.summary == {"steps": 1000, "wall_seconds": 1.5}


def test_arrays_are_the_stored_values(cantilever_file):
    ids, xy, conn, d = cantilever_layout()
    res = load_results(cantilever_file())
    # Copies of the stored doubles: exact.
    np.testing.assert_array_equal(res.mesh.x, xy[:, 0])
    np.testing.assert_array_equal(res.static.displacement[:, W], d[:, W])
    np.testing.assert_array_equal(res.mesh.node_id, ids)


def test_connectivity_becomes_zero_based(cantilever_file):
    res = load_results(cantilever_file())
    assert res.mesh.connectivity[0].tolist() == [0, 1]
    assert res.mesh.connectivity[-1].tolist() == [7, 8]
    assert res.mesh.end_nodes().tolist() == [0, 8]


@pytest.mark.parametrize("t, expected", [
    (0.0, 0), (1.4e-3, 1), (1.6e-3, 2), (4.49e-3, 4), (-1.0, 0), (1.0, N_OUT - 1)])
def test_nearest_stored_time_is_selected(cantilever_file, t, expected):
    res = load_results(cantilever_file())
    k = res.dynamic.nearest_index(t)
    assert k == expected
    assert res.dynamic.time[k] == pytest.approx(expected * DT, rel=1e-15)


def test_parts_not_written_are_none(cantilever_file):
    res = load_results(cantilever_file(parts=("static",)))
    assert res.dynamic is None and res.energy is None and res.modal is None
    assert res.static is not None


def test_missing_file_is_a_clear_error(tmp_path):
    with pytest.raises(ResultsError, match="does not exist"):
        load_results(tmp_path / "nothing.h5")


def test_missing_file_with_partial_says_the_run_did_not_finish(tmp_path):
    (tmp_path / "run.h5.partial").write_bytes(b"")
    with pytest.raises(ResultsError, match="did not finish"):
        load_results(tmp_path / "run.h5")


def test_non_hdf5_file_is_a_clear_error(tmp_path):
    path = tmp_path / "text.h5"
    path.write_text("not HDF5\n")
    with pytest.raises(ResultsError, match="not a readable HDF5 file"):
        load_results(path)


def test_missing_dataset_is_named(cantilever_file):
    path = cantilever_file(drop=("fem/velocity",))
    with pytest.raises(ResultsError, match="missing dataset '/fem/velocity'"):
        load_results(path)


def test_missing_mesh_is_named(cantilever_file):
    path = cantilever_file(drop=("fem/mesh/coordinates",))
    with pytest.raises(ResultsError, match="/fem/mesh/coordinates"):
        load_results(path)


def test_unknown_node_id_is_a_clear_error(cantilever_file):
    res = load_results(cantilever_file())
    assert res.mesh.index_of(90) == 8
    with pytest.raises(ResultsError, match="no node with id 7"):
        res.mesh.index_of(7)


def _loaders():
    from multicor_post import continuum, coupled, particles
    return [load_results, particles.load_dem, continuum.load_continuum, coupled.load_coupled,
            coupled.load_continuum_coupling, particles.has_particles, continuum.has_continuum,
            coupled.is_coupled]


@pytest.mark.parametrize("loader", _loaders(), ids=lambda f: f.__name__)
def test_every_loader_says_what_a_checkpoint_or_a_missing_file_is(loader, tmp_path):
    # on a checkpoint the loaders said "missing dataset" (the scripts said what it is);
    # has_particles and has_continuum raised FileNotFoundError on a missing file, and
    # load_continuum said "not a readable HDF5 file ([Errno 2] ...)"
    import h5py
    with h5py.File(tmp_path / "checkpoint.h5", "w") as f:
        f.attrs["format"] = "MULTICOR checkpoint 2"
        f.create_group("fem/mesh")
        f.create_group("continuum/mesh")
    with pytest.raises(ResultsError, match=r"is a MULTICOR checkpoint \(for --restart\), not a "
                                           "results file"):
        loader(tmp_path / "checkpoint.h5")
    with pytest.raises(ResultsError, match="results file '.*none.h5' does not exist$"):
        loader(tmp_path / "none.h5")
    with pytest.raises(ResultsError, match="is a folder, not a results file"):
        loader(tmp_path)


def test_mode_labels_not_one_per_mode_are_ignored(tmp_path):
    """/modal/axial_fraction@kind with three words for two modes: no labels (the file does not
    say which word is which mode's), and axial_modes falls back to the geometry: both synthetic
    modes are the cantilever's bending shape (w only), so neither is axial."""
    import h5py
    from synthetic import write_results
    from multicor_post.beam import axial_modes
    path = write_results(tmp_path / "modes.h5", *cantilever_layout(), parts=("modal",))
    with h5py.File(path, "a") as f:
        f.create_dataset("modal/axial_fraction", data=[0.0, 0.0])
        f["modal/axial_fraction"].attrs["kind"] = "axial bending bending"
    res = load_results(path)
    assert res.modal.omega.size == 2 and res.modal.kind is None
    assert axial_modes(res).tolist() == [False, False]
