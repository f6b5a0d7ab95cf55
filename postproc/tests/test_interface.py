"""Tests of the interface-experiment reader (multicor_post.interface) on a synthetic file:
two one-element blocks, one glued disk per band, multipliers that alternate from output to
output about a known mean, and a known slip; and the sliding-over-disks curve."""
import h5py
import numpy as np
import pytest

from multicor_post import interface

N_OUT = 6
SLIP = np.linspace(0.0, 1.0e-3, N_OUT)
T_MEAN, N_MEAN, ALT = 300.0, -1000.0, 50.0


@pytest.fixture
def interface_file(tmp_path):
    path = tmp_path / "interface.h5"
    x = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0, 2], [1, 2], [1, 3], [0, 3]], float)
    u = np.zeros((N_OUT, 8, 2))
    u[:, 4:, 0] = SLIP[:, None]                       # the top block moves in x as a whole
    sign = (-1.0) ** np.arange(N_OUT)                 # the step-to-step alternation
    lam = np.zeros((N_OUT, 4))
    lam[:, 0] = -T_MEAN + ALT * sign                  # bottom disk, x
    lam[:, 1] = -N_MEAN - ALT * sign                  # bottom disk, y
    lam[:, 2] = T_MEAN - ALT * sign                   # top disk, x
    lam[:, 3] = N_MEAN + ALT * sign                   # top disk, y
    lam[0] = 0.0
    with h5py.File(path, "w") as f:
        f["coupling/time"] = np.arange(N_OUT) * 1e-4
        f["coupling/lambda"] = lam
        f["coupling/rows/dof"] = np.array([1, 2, 1, 2], np.int32)
        f["coupling/rows/particle"] = np.array([1, 1, 2, 2], np.int32)
        f["dem/position"] = np.tile(np.array([[0.5, 0.9, 0.0], [0.5, 2.1, 0.0]]), (N_OUT, 1, 1))
        f["dem/particles/radius"] = np.array([0.1, 0.1])
        f["continuum/mesh/coordinates"] = x
        f["continuum/mesh/connectivity"] = np.array([[1, 2, 3, 4], [5, 6, 7, 8]], np.int32)
        f["continuum/mesh/kind"] = np.array([2, 2], np.int32)
        f["continuum/displacement"] = u
        f["continuum/stress"] = np.zeros((N_OUT, 2, 3))
        f["continuum/sets/nodes/bottom_block"] = np.array([1, 2, 3, 4], np.int32)
        f["continuum/sets/nodes/top_block"] = np.array([5, 6, 7, 8], np.int32)
        for name in ("coupling/energy/balance", "continuum/energy/balance", "continuum/energy/reaction_work"):
            f[name] = np.zeros(N_OUT)
    return path


def test_pair_mean_removes_the_alternation_and_bands_are_split(interface_file):
    run = interface.InterfaceRun(interface_file)
    t_top, n_top, t_bot, n_bot = run.band_resultants()
    # From output 2 on, each pair holds both phases: the mean is exact (sums of a few values
    # of O(1e3) written as float64: a few ulps).
    tol = 8 * np.spacing(1e3)
    assert np.allclose(t_top[2:], T_MEAN, rtol=0, atol=tol)
    assert np.allclose(n_top[2:], N_MEAN, rtol=0, atol=tol)
    assert np.allclose(t_bot[2:], -T_MEAN, rtol=0, atol=tol)
    assert np.allclose(n_bot[2:], -N_MEAN, rtol=0, atol=tol)


def test_slip_and_apparent_friction(interface_file):
    run = interface.InterfaceRun(interface_file)
    assert np.array_equal(run.slip(), SLIP)
    s, mu = run.apparent_friction()
    # Output 0 carries no load and is left out (below 0.2 of the largest normal load); output
    # 1 (about half the load: its pair holds output 0) is kept. From output 2 on T / N is
    # the ratio of the means, to rounding.
    assert s[0] == SLIP[1]
    assert np.allclose(mu[s > SLIP[1]], T_MEAN / -N_MEAN, rtol=1e-14)
    # Blocks sheared through their height (u_x linear in y): the slip is taken where the
    # blocks face each other, the top block's lower edge (y = 2, u_x = SLIP) and the bottom
    # block's upper edge (y = 1, u_x = 0), not on their other edges (y = 3: SLIP + gamma,
    # y = 0: -gamma). Exact: gamma * 0 = 0, and the mean of two equal doubles is that double.
    gamma = 2.0e-4
    with h5py.File(interface_file, "r+") as f:
        x = f["continuum/mesh/coordinates"][...]
        u = f["continuum/displacement"][...]
        u[:, 4:, 0] = SLIP[:, None] + gamma * (x[4:, 1] - 2.0)
        u[:, :4, 0] = gamma * (x[:4, 1] - 1.0)
        f["continuum/displacement"][...] = u
    assert np.array_equal(interface.InterfaceRun(interface_file).slip(), SLIP)


def test_sliding_over_disks_starts_at_mu_and_vanishes_at_the_crest():
    mu, r = 0.3, 0.0125
    assert interface.sliding_over_disks(mu, 0.0, r) == pytest.approx(mu, rel=1e-15)
    s0 = 2 * r * np.sin(np.arctan(mu))
    assert interface.sliding_over_disks(mu, s0, r) == pytest.approx(0.0, abs=1e-15)


def test_figures_are_drawn(interface_file):
    run = interface.InterfaceRun(interface_file)
    fig = interface.plot_friction([("synthetic", run)], "t", (0.3,), 0.1)
    assert len(fig.axes[0].lines) == 3                # the run, the theory and its legend entry
    # a ratio: '[-]', as every axis gives its unit
    assert fig.axes[0].get_ylabel() == "apparent friction T / N (top band) [-]"
    assert interface.plot_configuration(run, N_OUT - 1) is not None
    assert interface.plot_stress(run, N_OUT - 1, "vm") is not None


def test_a_killed_run_is_read_up_to_its_count_of_whole_outputs(interface_file):
    # the reader took every record of a killed run's partial file, those of the output the
    # kill cut too (its multipliers, displacements, contacts partly written), where the other
    # loaders stop at /summary@outputs
    with h5py.File(interface_file, "a") as f:
        for name in ("coupling/time", "coupling/lambda", "dem/position", "continuum/displacement",
                     "continuum/stress", "coupling/energy/balance", "continuum/energy/balance",
                     "continuum/energy/reaction_work"):
            data = f[name][()]
            del f[name]      # extendible, as multicor creates its series
            f.create_dataset(name, data=data, maxshape=(None,) + data.shape[1:])
        f.create_group("summary")
        f["summary"].attrs["finished"] = np.int32(0)
        f["summary"].attrs["outputs"] = np.int32(N_OUT - 2)
    run = interface.InterfaceRun(interface_file)
    assert run.time.size == N_OUT - 2 and run.lam.shape[0] == N_OUT - 2
    assert run.position.shape[0] == N_OUT - 2 and run.u.shape[0] == N_OUT - 2
    assert run.stress.shape[0] == N_OUT - 2 and run.balance.size == N_OUT - 2
    assert np.array_equal(run.slip(), SLIP[:N_OUT - 2])


def test_von_mises_of_the_stress_plot_takes_sigma_zz_in_plane_strain(interface_file):
    """An element in plane strain has sigma_zz = nu (sigma_xx + sigma_yy): with sigma_xx =
    sigma_yy = 1 MPa and nu = 0.3, sigma_zz = 0.6 MPa and von Mises sqrt(((0)^2 + 0.4^2 +
    0.4^2) / 2) = 0.4 MPa, where the plane-stress formula gives 1 MPa (the interface
    experiment's blocks are in plane strain). The second element is in plane stress: 1 MPa.
    A file without /continuum/materials keeps sigma_zz = 0 and says so."""
    with h5py.File(interface_file, "r+") as f:
        stress = np.zeros((N_OUT, 2, 3))
        stress[:, :, 0] = stress[:, :, 1] = 1e6
        f["continuum/stress"][...] = stress
    run = interface.InterfaceRun(interface_file)
    fig = interface.plot_stress(run, N_OUT - 1, "vm")
    assert fig.axes[1].get_ylabel() == "von Mises (sigma_zz taken as 0) [MPa]"
    with h5py.File(interface_file, "r+") as f:
        f["continuum/mesh/material"] = np.array([1, 2], np.int32)
        f["continuum/materials/poisson"] = np.array([0.3, 0.3])
        f["continuum/materials/plane_strain"] = np.array([1, 0], np.int32)
    run = interface.InterfaceRun(interface_file)
    fig = interface.plot_stress(run, N_OUT - 1, "vm")
    values = fig.axes[0].collections[0].get_array()
    # the formula's arithmetic in double precision: 1e-12 relative
    np.testing.assert_allclose(values, [0.4, 1.0], rtol=1e-12)
    assert fig.axes[1].get_ylabel() == "von Mises [MPa]"


def test_stress_plot_takes_the_stored_von_mises(interface_file):
    """A file that stores /continuum/von_mises (the builds since it, doc/output.md): the plot
    shows those values, not the ones it would compute from the stresses (here 1 MPa with
    sigma_zz taken as 0: the file has no materials); a partial file's complete outputs alone."""
    stored = np.array([[2.5e6, 4.0e6]] * N_OUT) * np.arange(1, N_OUT + 1)[:, None]
    with h5py.File(interface_file, "r+") as f:
        stress = np.zeros((N_OUT, 2, 3))
        stress[:, :, 0] = 1e6
        f["continuum/stress"][...] = stress
        # extendible, as multicor creates its series
        f.create_dataset("continuum/von_mises", data=stored, maxshape=(None, 2))
    run = interface.InterfaceRun(interface_file)
    assert np.array_equal(run.stored_von_mises, stored)
    fig = interface.plot_stress(run, N_OUT - 1, "vm")
    # the stored doubles divided by 1e6 for MPa, as the plot does: equal
    assert np.array_equal(fig.axes[0].collections[0].get_array(), stored[-1] / 1e6)
    assert fig.axes[1].get_ylabel() == "von Mises [MPa]"
    with h5py.File(interface_file, "r+") as f:
        f.create_group("summary")
        f["summary"].attrs["finished"] = np.int32(0)
        f["summary"].attrs["outputs"] = np.int32(N_OUT - 2)
    assert interface.InterfaceRun(interface_file).stored_von_mises.shape == (N_OUT - 2, 2)


def test_von_mises_counts_the_shear_three_times():
    """Von Mises of a pure shear tau is sqrt(3) tau; with normal stresses and shear in plane
    strain, the same value as from the deviator of the full 3-D stress tensor, sqrt(3/2 s:s),
    with sigma_zz = nu (sigma_xx + sigma_yy): (1, 1, 0.5) MPa, nu = 0.3 gives sigma_zz = 0.6
    MPa and sqrt(0.4^2 + 3 x 0.5^2) = sqrt(0.91) = 0.954 MPa (2 sxy^2 would give 0.812)."""
    tau = 2.5e6
    # a square root and a few products of doubles: a few ulps, 1e-14 relative
    assert interface.von_mises(np.array([0.0, 0.0, tau])) == pytest.approx(np.sqrt(3) * tau, rel=1e-14)
    sxx, syy, sxy, nu = 1.0e6, 1.0e6, 0.5e6, 0.3
    szz = nu * (sxx + syy)
    sigma = np.array([[sxx, sxy, 0.0], [sxy, syy, 0.0], [0.0, 0.0, szz]])
    dev = sigma - np.trace(sigma) / 3 * np.eye(3)
    expected = np.sqrt(1.5 * np.sum(dev * dev))
    assert expected == pytest.approx(np.sqrt(0.91e12), rel=1e-14)
    assert interface.von_mises(np.array([sxx, syy, sxy]), nu) == pytest.approx(expected, rel=1e-14)
