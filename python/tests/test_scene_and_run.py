"""The Python API against the CLI, the TOML scenes and bad input."""

import csv
import io
import json
import math
import os
import pickle
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import fricbound
from fricbound import Scene

from conftest import PAPER

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib


def test_paper_case_equals_the_cli_frf_csv(cli_binary, tmp_path):
    """The built-in paper scene solved from Python gives the CLI's frf.csv, byte for byte, and
    the arrays hold the same numbers."""
    out = tmp_path / "cli"
    subprocess.run([str(cli_binary), "run", "--quiet", "--out", str(out)], check=True)
    cli_csv = (out / "frf.csv").read_text()

    result = fricbound.run(Scene.paper())
    assert result.complete, result.status
    assert result.csv == cli_csv

    rows = np.genfromtxt(io.StringIO(cli_csv), delimiter=",", names=True, dtype=None, encoding="utf-8")
    assert len(rows) == len(result) > 100
    np.testing.assert_allclose(result.freq_hz, rows["freq_hz"], rtol=1e-9)
    np.testing.assert_allclose(result.amplitude("y2"), rows["y2_amp"], rtol=1e-9)
    np.testing.assert_array_equal(result.states[:, 0], rows["left_state"])
    df = result.to_pandas()
    assert list(df.columns) == cli_csv.splitlines()[0].split(",")
    # The amplitude is the first harmonic of the coefficients (harmonic-major layout).
    c1, s1 = result.coefficient("y2", "c1"), result.coefficient("y2", "s1")
    np.testing.assert_allclose(np.hypot(c1, s1), result.amplitude("y2"), rtol=1e-12)
    # The error estimate is on by default: one column pair per output, finite and small.
    assert result.trunc_err.shape == (len(result), 1)
    assert np.all(np.isfinite(result.sampling_err))
    # The largest displacement over the period is frf.csv's <dof>_peak column.
    np.testing.assert_allclose(result.max_displacement[:, 0], rows["y2_peak"], rtol=1e-9)


def test_refined_peaks_equal_the_cli_peaks_csv(cli_binary, tmp_path):
    """`FrfResult.peaks` holds the refined resonances and anti-resonances the CLI writes to
    peaks.csv: the same text byte for byte, and columns of the same names and values."""
    out = tmp_path / "cli"
    subprocess.run([str(cli_binary), "run", "--quiet", "--out", str(out)], check=True)
    cli_peaks = (out / "peaks.csv").read_text()
    result = fricbound.run(Scene.paper())
    assert result.peaks_csv == cli_peaks
    rows = list(csv.DictReader(io.StringIO(cli_peaks)))
    assert list(result.peaks) == cli_peaks.splitlines()[0].split(",")
    assert len(rows) == len(result.peaks["freq_hz"]) >= 3
    assert list(result.peaks["kind"]) == [r["kind"] for r in rows]
    assert list(result.peaks["dof"]) == [r["dof"] for r in rows]
    np.testing.assert_allclose(result.peaks["freq_hz"], [float(r["freq_hz"]) for r in rows], rtol=1e-9)
    np.testing.assert_allclose(result.peaks["amplitude"], [float(r["amplitude"]) for r in rows], rtol=1e-9)
    assert list(result.peaks["refined"]) == [r["refined"] == "true" for r in rows]
    assert list(result.peaks["path_index"]) == [int(r["path_index"]) for r in rows]
    assert list(result.peaks["left_state"]) == [r["left_state"] for r in rows]
    # A refined resonance is at least as high as the path point it was refined from, and it
    # is not the per-point largest displacement (the renamed array).
    res = result.resonances("y2")
    assert len(res["freq_hz"]) >= 1 and res["refined"].all()
    assert np.all(res["amplitude"] >= res["path_amplitude"] * (1 - 1e-12))
    assert isinstance(result.peaks, dict) and result.max_displacement.shape == (len(result), 1)
    assert list(result.peaks_to_pandas().columns) == list(result.peaks)
    again = pickle.loads(pickle.dumps(result))
    assert again.peaks_csv == result.peaks_csv


def _paper_matrices_scene(path):
    """`Scene.from_matrices` built from a paper scene file's tables."""
    t = tomllib.loads(path.read_text())
    m = t["model"]
    return Scene.from_matrices(
        np.array(m["mass"]),
        np.array(m["damping"]),
        np.array(m["stiffness"]),
        dofs=m["dofs"],
        contacts=t["contacts"],
        loads=t["static_loads"] + t["harmonic_loads"],
        freq_range_hz=(t["analysis"]["freq_start_hz"], t["analysis"]["freq_end_hz"]),
        outputs=t["output"]["dofs"],
        harmonics=t["harmonics"]["max"],
        samples=t["harmonics"]["samples"],
        title=t["title"],
        analysis={"max_step": t["analysis"]["max_step"]},
        effects=t["effects"],
    )


def test_scene_from_numpy_matrices_equals_the_toml_scene():
    path = PAPER / "zoom-2nd.toml"
    from_toml = Scene.from_toml(path)
    from_numpy = _paper_matrices_scene(path)
    assert from_numpy.to_toml() == from_toml.to_toml()
    assert from_numpy == from_toml
    a, b = fricbound.run(from_toml), fricbound.run(from_numpy)
    assert a.csv == b.csv
    np.testing.assert_array_equal(a.coefficients, b.coefficients)
    # scipy.sparse matrices give the same scene.
    sp = pytest.importorskip("scipy.sparse")
    t = tomllib.loads(path.read_text())
    m = t["model"]
    sparse = Scene.from_matrices(
        sp.csr_matrix(np.array(m["mass"])),
        sp.csr_matrix(np.array(m["damping"])),
        sp.csr_matrix(np.array(m["stiffness"])),
        dofs=m["dofs"],
        contacts=t["contacts"],
        loads=t["static_loads"] + t["harmonic_loads"],
        freq_range_hz=(150.0, 175.0),
        outputs=["y2"],
        title=t["title"],
        analysis={"max_step": 0.1},
        effects=t["effects"],
    )
    assert sparse == from_toml


def test_set_uses_the_cli_paths_and_overrides_match_the_cli(cli_binary, tmp_path):
    scene = Scene.from_toml(PAPER / "zoom-2nd.toml").set("contacts.0.mu", 0.3).set("harmonics.max", 3)
    assert scene.overrides == ["contacts.0.mu=0.3", "harmonics.max=3"]
    info = scene.check()
    assert info["harmonics"] == [0, 1, 2, 3] and info["outputs"] == ["y2"]
    out = tmp_path / "cli"
    subprocess.run(
        [str(cli_binary), "run", str(PAPER / "zoom-2nd.toml"), "--quiet", "--out", str(out),
         "--set", "contacts.0.mu=0.3", "--set", "harmonics.max=3"],
        check=True,
    )
    assert fricbound.run(scene).csv == (out / "frf.csv").read_text()


@pytest.mark.parametrize(
    "field, value, named",
    [
        ("contacts.0.mu", -0.3, "contacts[0].mu"),
        ("contacts.1.initial_state", 2.0, "contacts[1].initial_state"),
        ("analysis.freq_end_hz", 10.0, "analysis"),
        ("model.dofs.2", "nowhere", "contacts"),
    ],
)
def test_bad_values_raise_value_error_naming_the_field(field, value, named):
    scene = Scene.paper().set(field, value)
    with pytest.raises(ValueError) as e:
        scene.check()
    assert named in str(e.value)
    assert "paper-wedge" in str(e.value)  # the file
    with pytest.raises(ValueError):
        fricbound.run(scene)


def test_bad_fields_and_text_raise_value_error():
    scene = Scene.paper()
    with pytest.raises(ValueError, match="contacts.0.friction"):
        scene.set("contacts.0.friction", 0.3)
    assert scene.overrides == []  # unchanged
    with pytest.raises(ValueError, match="line 2, column 1: unknown field `bogus`"):
        Scene.from_toml("title = 'x'\nbogus = 1\n")
    with pytest.raises(ValueError, match=r"model.stiffness\[1\]\[0\] is nan"):
        Scene.from_matrices(
            np.eye(2), None, np.array([[1.0, 0.0], [np.nan, 1.0]]),
            dofs=["a", "b"], freq_range_hz=(1.0, 2.0),
        )
    with pytest.raises(ValueError, match="unknown field"):
        Scene.from_matrices(
            np.eye(2), None, np.eye(2), dofs=["a", "b"], freq_range_hz=(1.0, 2.0),
            contacts=[{"name": "c", "damper": ["a"], "kt": 1.0, "kn": 1.0, "mu": 0.1, "bogus": 1}],
        )
    with pytest.raises(ValueError, match="modes: case"):
        fricbound.modes(scene, 3, case="loose")


def test_progress_callback_and_its_exception_stop_the_solve():
    seen = []
    fricbound.run(Scene.from_toml(PAPER / "zoom-2nd.toml"), progress=seen.append)
    assert len(seen) > 10 and seen[0]["kind"] == "point"
    assert [e["points"] for e in seen] == list(range(1, len(seen) + 1))

    class Stop(Exception):
        pass

    def stop_after_five(event):
        if event["points"] >= 5:
            raise Stop()

    with pytest.raises(Stop):
        fricbound.run(Scene.paper(), progress=stop_after_five)
    # The stop request was withdrawn: the next solve runs to the end.
    assert fricbound.run(Scene.from_toml(PAPER / "zoom-2nd.toml")).complete


def test_ctrl_c_interrupts_a_long_solve():
    """SIGINT during a solve raises KeyboardInterrupt within a second, not at the end."""
    scene = Scene.paper().set("harmonics.max", 15).set("analysis.max_step", 0.05)
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    started = time.perf_counter()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        fricbound.run(scene)
    elapsed = time.perf_counter() - started
    timer.cancel()
    assert elapsed < 3.0, elapsed


def test_scenes_and_results_pickle():
    scene = Scene.from_toml(PAPER / "zoom-2nd.toml").set("contacts.0.mu", 0.4)
    back = pickle.loads(pickle.dumps(scene))
    assert back == scene and back.overrides == scene.overrides
    result = fricbound.run(scene)
    again = pickle.loads(pickle.dumps(result))
    np.testing.assert_array_equal(again.amplitudes, result.amplitudes)
    assert again.csv == result.csv and again.status == result.status


def test_stability_columns_when_asked():
    scene = Scene.from_toml(PAPER / "zoom-2nd.toml").set("analysis.stability", True)
    r = fricbound.run(scene)
    assert r.stable.dtype == bool and r.stable.shape == (len(r),)
    assert np.all(np.isfinite(r.floquet_re))
    # A stable point has no growing exponent.
    assert np.all(r.floquet_re[r.stable] <= 1e-6 * 2 * math.pi * r.freq_hz[r.stable])
    assert "stable" in r.to_pandas().columns
    # Which method decided, and whether it can be trusted, as the CLI's frf.csv columns.
    assert list(r.stability_method) == ["hill"] * len(r)
    rows = list(csv.DictReader(io.StringIO(r.csv)))
    assert [row["stability_method"] for row in rows] == list(r.stability_method)
    assert [row["stability_reliable"] == "true" for row in rows] == list(r.stability_reliable)
    # Hill is trusted only where every contact is stuck or open all period.
    for k in range(len(r)):
        trusted = all(state in ("stuck", "open") for state in r.states[k])
        assert bool(r.stability_reliable[k]) == trusted


def test_modes_of_the_paper_structure():
    """The paper structure with contacts open: blades and a free damper (two rigid-body
    modes of the damper among the lowest). Checked against scipy's dense eigen solve."""
    scipy_linalg = pytest.importorskip("scipy.linalg")
    t = tomllib.loads((PAPER / "full-range.toml").read_text())
    m = fricbound.modes(Scene.from_toml(PAPER / "full-range.toml"), 6, case="open")
    lam = scipy_linalg.eigh(np.array(t["model"]["stiffness"]), np.array(t["model"]["mass"]), eigvals_only=True)
    expected = np.sqrt(np.clip(lam, 0.0, None)) / (2 * math.pi)
    # The damper's rigid-body mode is reported as 0 Hz (scipy: round-off of a few µHz).
    assert m.rigid[0] and m.frequency_hz[0] == 0.0 and expected[0] < 1e-4
    np.testing.assert_allclose(np.sort(m.frequency_hz)[1:], np.sort(expected)[1:], rtol=1e-8)
    assert m.to_pandas().shape == (6, 4)


def test_verify_by_time_integration():
    """At 120 Hz the paper case's HBM point is stable (Hill) and the time integration started
    from it stays at its amplitude (an independent method: Newmark on the same equations)."""
    v = fricbound.verify(Scene.paper(), [120.0])
    c = v.cases[0]
    assert c["hill_stable"] is True and c["stays"], c
    assert c["hbm_difference"] < 1e-3 and c["dt_change"] < 1e-3
    assert c["last_period"].shape == (1, c["steps_per_period"])
    assert list(v.to_pandas().columns[:3]) == ["freq_hz", "y2_hbm_amp", "y2_time_amp"]
    assert v.status == "complete" and v.complete
    with pytest.raises(ValueError, match="freqs_hz"):
        fricbound.verify(Scene.paper(), [-5.0])


def test_verify_status_is_the_cli_status(cli_binary, tmp_path):
    """A time integration that does not settle within its period budget makes the verify
    incomplete, with the reason `fricbound verify` gives (its exit code 3); one that settles
    is complete (exit code 0)."""
    for freqs, periods, code in (([120.0, 140.0], 2, 3), ([120.0], None, 0)):
        cli = [str(cli_binary), "verify", "--quiet", "--freqs", ",".join(str(f) for f in freqs),
               "--out", str(tmp_path / f"v{code}")]
        if periods is not None:
            cli += ["--max-periods", str(periods)]
        done = subprocess.run(cli, capture_output=True, text=True)
        assert done.returncode == code, done.stderr
        v = fricbound.verify(Scene.paper(), freqs, max_periods=periods)
        if code == 0:
            assert v.status == "complete" and v.complete
        else:
            cli_status = [line for line in done.stderr.splitlines() if line.startswith("incomplete: ")]
            assert [v.status] == cli_status
            assert v.status == "incomplete: 120 Hz did not settle, 140 Hz did not settle"
            assert not v.complete
            assert not any(c["settled"] for c in v.cases)


def test_linear_references_equal_the_cli_files(cli_binary, tmp_path):
    """The open and stuck linear references equal the CLI's linear_open.csv and
    linear_stuck.csv."""
    scene = Scene.from_toml(PAPER / "zoom-2nd.toml")
    out = tmp_path / "cli"
    subprocess.run([str(cli_binary), "run", str(PAPER / "zoom-2nd.toml"), "--quiet", "--out", str(out)], check=True)
    for case in ("open", "stuck"):
        lin = fricbound.linear(scene, case)
        rows = np.genfromtxt(out / f"linear_{case}.csv", delimiter=",", names=True)
        np.testing.assert_allclose(lin.freq_hz, rows["freq_hz"], rtol=1e-9)
        np.testing.assert_allclose(lin.amplitude("y2"), rows["y2_amp"], rtol=1e-9)
    assert len(fricbound.linear(scene, "stuck", points=11).freq_hz) == 11


def test_run_summary_as_solution_json(cli_binary, tmp_path):
    """At a pre-load of 1 N the damper bounces and the path folds back several times: the
    status, turning points, step cuts and jumps are the same in Python as in the CLI's
    solution.json of the same scene."""
    overrides = {"static_loads.0.value": -1.0, "accuracy.estimate": False}
    scene = Scene.paper()
    for field, value in overrides.items():
        scene.set(field, value)
    out = tmp_path / "cli"
    cli = [str(cli_binary), "run", "--quiet", "--out", str(out)]
    for field, value in overrides.items():
        cli += ["--set", f"{field}={str(value).lower()}"]
    assert subprocess.run(cli).returncode == 0
    with open(out / "solution.json") as f:
        solution = json.load(f)
    result = fricbound.run(scene)
    assert result.status == solution["status"] == "complete"
    assert result.turning_points_hz == solution["turning_points_hz"]
    assert len(result.turning_points_hz) > 0
    assert result.rejected_steps == len(solution["step_cuts"])
    assert result.jumps == solution["jumps"]
    assert len(result.freq_hz) == len(solution["points"])


def test_incomplete_and_too_large_runs_say_so():
    """A run that uses up its point budget is returned as incomplete (the CLI's exit code 3);
    a scene estimated not to fit in memory is refused before anything is solved."""
    r = fricbound.run(Scene.paper().set("analysis.max_points", 20))
    assert not r.complete and r.status.startswith("incomplete: the point budget")
    assert len(r) == 20
    with pytest.raises(MemoryError, match="harmonics.max"):
        fricbound.run(Scene.paper().set("harmonics.max", 10000).set("harmonics.samples", 32768))


def test_limits_with_envelope_returns_it_as_arrays():
    """`[limits] envelope = "sides"` through `set`: the envelope comes back on the common grid,
    every bound between the smallest and largest limit-curve amplitude it must contain, and its
    check names where the limits fail to bound it."""
    scene = Scene.from_toml(PAPER / "fig13-3rd.toml")
    scene.set("limits.envelope", "sides").set("limits.grid_points", 9)
    r = fricbound.limits(scene)
    env = r.envelope
    assert env is not None and env["mode"] == "sides"
    assert env["groups"] == ["left", "right"]
    n = len(r.grid_freq_hz)
    assert env["min"].shape == (n, 1) and env["max"].shape == (n, 1)
    assert env["max_m"].shape == (n, 1, 2)
    solved = ~np.isnan(env["max"][:, 0])
    assert solved.all()
    # The limit curves are states of the search box: the envelope contains them.
    assert (env["max"][:, 0] >= r.grid_upper * (1 - 1e-6)).all()
    assert (env["min"][:, 0] <= r.grid_lower * (1 + 1e-6)).all()
    assert (np.abs(env["max_m"]) <= 1 + 1e-12).all()
    assert env["check"]["compared"] == n
    df = r.to_pandas()
    assert "envelope_max" in df.columns
    scene_off = Scene.from_toml(PAPER / "fig13-3rd.toml").set("limits.grid_points", 9)
    assert fricbound.limits(scene_off).envelope is None
