"""A sparse FE model through scipy.sparse and `reduce`, the sweeps, and Dask."""

import math

import numpy as np
import pytest

import fricbound
from fricbound import Scene

from conftest import PAPER

sp = pytest.importorskip("scipy.sparse")
spla = pytest.importorskip("scipy.sparse.linalg")


def _chain(n_nodes, k=1.0e7, m=0.05):
    """A clamped 2D spring chain (bar): nodes 1..n along x, each with x and y DOFs, axial
    springs between x DOFs and shear springs between y DOFs of neighbours, node 0 clamped.
    DOF 2i is x of node i+1, 2i+1 its y."""
    n = 2 * n_nodes
    rows, cols, vals = [], [], []

    def spring(i, j, kk):
        for a, b, v in ((i, i, kk), (j, j, kk), (i, j, -kk), (j, i, -kk)):
            rows.append(a), cols.append(b), vals.append(v)

    for node in range(n_nodes):
        for d, kk in ((0, k), (1, 0.3 * k)):
            dof = 2 * node + d
            if node == 0:
                rows.append(dof), cols.append(dof), vals.append(kk)  # to the clamp
            else:
                spring(dof - 2, dof, kk)
    K = sp.csc_matrix((vals, (rows, cols)), shape=(n, n))
    M = sp.identity(n, format="csc") * m
    return K, M


def test_reduce_a_sparse_fe_model_and_solve_it():
    """Craig-Bampton of a 400-DOF sparse chain from scipy.sparse: the reduced model's lowest
    frequencies equal the full model's (scipy eigsh), and a scene built from the reduced
    matrices, with a contact that stays open, gives the full model's linear response
    (scipy spsolve of K - ω²M + iωC) at the tip."""
    n_nodes = 200
    K, M = _chain(n_nodes)
    n = K.shape[0]
    tip_x, tip_y = n - 2, n - 1
    red = fricbound.reduce(K, M, boundary=[tip_x, tip_y], modes=12, recover=[n // 2])
    assert red.stiffness.shape == (14, 14) and red.n_modes == 12
    assert red.recovery.shape == (1, 14)

    lam_full = spla.eigsh(K, k=4, M=M, sigma=0.0, which="LM", return_eigenvectors=False)
    f_full = np.sort(np.sqrt(lam_full)) / (2 * math.pi)
    f_red = _frequencies(red)[:4]
    # Rayleigh-Ritz: upper bounds, close with 12 modes (measured: 3e-5 on the first, 7e-4 on
    # the fourth).
    assert np.all(f_red >= f_full * (1 - 1e-12))
    np.testing.assert_allclose(f_red, f_full, rtol=2e-3)
    assert abs(f_red[0] / f_full[0] - 1) < 1e-4

    # Rayleigh damping on the reduced matrices: C = beta K (beta in s) is the same on both.
    beta = 1e-5
    dofs = ["tx", "ty"] + [f"q{i}" for i in range(red.n_modes)]
    f_range = (0.5 * f_full[0], 0.9 * f_full[0])
    scene = Scene.from_matrices(
        red.mass, beta * red.stiffness, red.stiffness,
        dofs=dofs,
        contacts=[{
            "name": "stop", "damper": ["tx", "ty"], "body": [], "angle_deg": 0.0,
            "kt": 1e5, "kn": 1e5, "mu": 0.3, "gap": 1e-2,
        }],
        loads=[{"dof": "tx", "harmonic": 1, "cos": 1.0}],
        freq_range_hz=f_range,
        outputs=["tx"],
    )
    info = scene.check()
    assert info["dofs"] == dofs
    r = fricbound.run(scene)
    assert r.complete and np.all(r.states == "open")

    # The harmonic balance of the reduced model with its contact open is the reduced model's
    # linear response (exact), and that is the full sparse model's within the reduction error.
    F = np.zeros(n, dtype=complex)
    F[tip_x] = 1.0
    Fr = np.zeros(len(dofs), dtype=complex)
    Fr[0] = 1.0
    C = beta * K
    for f, amp in zip(r.freq_hz[::10], r.amplitude("tx")[::10]):
        w = 2 * math.pi * f
        ur = np.linalg.solve(red.stiffness * (1 + 1j * w * beta) - w * w * red.mass, Fr)
        assert abs(amp - abs(ur[0])) <= 1e-8 * abs(ur[0]), (f, amp, abs(ur[0]))
        u = spla.spsolve((K - w * w * M + 1j * w * C).tocsc(), F)
        assert abs(amp - abs(u[tip_x])) <= 1e-3 * abs(u[tip_x]), (f, amp, abs(u[tip_x]))


def _frequencies(red):
    lam = np.linalg.eigvals(np.linalg.solve(red.mass, red.stiffness)).real
    return np.sort(np.sqrt(np.clip(lam, 0.0, None))) / (2 * math.pi)


def test_reduce_with_every_mode_is_exact():
    """Keeping every fixed-interface mode, the reduced model has the full model's
    frequencies to round-off (dense scipy eigen solve of the 40-DOF chain)."""
    scipy_linalg = pytest.importorskip("scipy.linalg")
    K, M = _chain(20)
    n = K.shape[0]
    red = fricbound.reduce(K, M, boundary=[n - 2, n - 1], modes=n - 2)
    assert red.n_modes == n - 2
    lam = scipy_linalg.eigh(K.toarray(), M.toarray(), eigvals_only=True)
    np.testing.assert_allclose(_frequencies(red), np.sqrt(lam) / (2 * math.pi), rtol=1e-8)


def test_reduce_rejects_bad_input():
    K, M = _chain(5)
    with pytest.raises(ValueError, match=r"boundary\[1\] = 99"):
        fricbound.reduce(K, M, boundary=[0, 99], modes=2)
    with pytest.raises(ValueError, match="shape"):
        fricbound.reduce(K, M[:4, :4], boundary=[0], modes=2)


def test_sweep_equals_the_scene_sweep_and_the_dask_sweep():
    """The pre-load sweep of Fig. 16a at three values: `fricbound.sweep` with a field and
    values equals the scene's own [sweep] table cut to those values, and the Dask
    `limits_sweep` over a LocalCluster of 2 workers equals the same tasks run serially."""
    distributed = pytest.importorskip("dask.distributed")
    f0 = [40.0, 120.0, 300.0]
    scene = Scene.from_toml(PAPER / "fig16a-d.toml")
    own = fricbound.sweep(scene.copy().set("sweep.values", f0))
    given = fricbound.sweep(scene, "static_loads.0.value", f0, scale=-1.0, parameter="F0", unit="N")
    assert own.complete and given.complete
    np.testing.assert_array_equal(own.peak_amplitude, given.peak_amplitude)
    np.testing.assert_array_equal(own.peak_freq_hz, given.peak_freq_hz)
    upper, lower = given.limit_peaks()
    assert np.all(upper >= lower) and upper[1] > 1.2 * lower[1]  # multiple solutions at 120 N

    values = [-v for v in f0]
    serial = fricbound.dask.limits_sweep(scene, "static_loads.0.value", values, client="serial")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        distributed_df = fricbound.dask.limits_sweep(scene, "static_loads.0.value", values, client=client)
        frf_df = fricbound.dask.sweep(
            Scene.from_toml(PAPER / "zoom-2nd.toml"), "contacts.0.mu", [0.3, 0.5], client=client
        )
    assert list(distributed_df["value"]) == values
    assert distributed_df.equals(serial)
    np.testing.assert_array_equal(distributed_df["m+1_amp"], given.peak_amplitude[:, 0])
    frf_serial = fricbound.dask.sweep(
        Scene.from_toml(PAPER / "zoom-2nd.toml"), "contacts.0.mu", [0.3, 0.5], client="serial"
    )
    cols = [c for c in frf_serial.columns if c != "elapsed_s"]
    assert frf_df[cols].equals(frf_serial[cols])
    assert list(frf_df["status"]) == ["complete", "complete"]


def test_limit_analysis_from_python():
    """The 3rd-resonance limit analysis: two limit curves whose band holds multiple solutions,
    the upper limit above the lower, and a grid DataFrame."""
    scene = Scene.from_toml(PAPER / "fig13-3rd.toml")
    events = []
    r = fricbound.limits(scene, progress=events.append)
    assert [c.name for c in r.limits] == ["m+1", "m-1"]
    # One event per limit, intermediate and scanned curve (3 intermediate, 3 x 3 scanned).
    assert len(events) == 2 + 3 + 9 and {"m+1", "m-1"} <= {e["name"] for e in events}
    assert all(e["kind"] == "curve" and e["status"] == "complete" for e in events)
    assert r.complete, r.status
    assert np.all(r.grid_upper >= r.grid_lower - 1e-15)
    assert "multiple" in set(r.grid_regime)
    df = r.to_pandas()
    assert {"freq_hz", "lower", "upper", "regime"} <= set(df.columns)
    v = r.variability
    assert v["peak_ratio"] > 1.0


def test_limits_sweep_of_whole_analyses_matches_limits():
    """`limits_sweep(output="limits")` summarises the whole limit analysis at each value: at
    the scene's own value it gives the numbers of `fricbound.limits` on the scene."""
    scene = Scene.from_toml(PAPER / "fig13-3rd.toml")
    df = fricbound.dask.limits_sweep(scene, "contacts.0.mu", [0.5], client="serial", output="limits")
    r = fricbound.limits(scene)
    row = df.iloc[0]
    assert row["status"] == r.status
    for key in ("upper_peak", "lower_peak", "peak_ratio", "widest_band", "multiple_points"):
        assert row[key] == r.variability[key], key
    assert row["m+1_amp"] == r.limits[0].peak["amplitude"]
    with pytest.raises(ValueError, match="output"):
        fricbound.dask.limits_sweep(scene, "contacts.0.mu", [0.5], client="serial", output="bands")
    with pytest.raises(ValueError, match="contacts.0.friction"):
        fricbound.dask.sweep(scene, "contacts.0.friction", [0.5], client="serial")


@pytest.mark.parametrize("values", [[0.3, 0.5], [0.3, -1.0]])
def test_dask_sweep_on_its_own_cluster_shuts_down_without_output(capfd, values):
    """`fricbound.dask.sweep` without a client starts a LocalCluster for the call and closes
    it: nothing is written to stderr (the workers' included), also when a task fails (μ < 0)
    while another still solves; the failure is raised with its own type and message once
    every task has ended."""
    pytest.importorskip("dask.distributed")
    scene = Scene.from_toml(PAPER / "zoom-2nd.toml")
    capfd.readouterr()
    if values[1] < 0:
        with pytest.raises(ValueError, match=r"contacts\[0\]\.mu"):
            fricbound.dask.sweep(scene, "contacts.0.mu", values)
    else:
        df = fricbound.dask.sweep(scene, "contacts.0.mu", values)
        assert list(df["status"]) == ["complete", "complete"]
    captured = capfd.readouterr()
    assert captured.err == ""


def test_solve_error_pickles_as_itself():
    """A SolveError raised on a Dask worker comes back as a SolveError."""
    import pickle

    e = pickle.loads(pickle.dumps(fricbound.SolveError("scene: no solution")))
    assert type(e) is fricbound.SolveError and str(e) == "scene: no solution"
