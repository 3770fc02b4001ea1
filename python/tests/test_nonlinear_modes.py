"""fricbound.nonlinear_modes against the CLI's modes_nl.csv and the scene checks."""

import subprocess

import numpy as np
import pytest

import fricbound
from fricbound import Scene

from conftest import PAPER


def test_mode_equals_the_cli_and_has_a_pandas_table(cli_binary, tmp_path):
    """The shipped nonlinear-mode scene solved from Python gives the CLI's modes_nl.csv numbers
    case by case, and the tables hold every point."""
    scene = PAPER / "modes-3rd.toml"
    out = tmp_path / "cli"
    subprocess.run([str(cli_binary), "run", str(scene), "--quiet", "--out", str(out)], check=True)
    rows = np.genfromtxt(out / "modes_nl.csv", delimiter=",", names=True, dtype=None, encoding="utf-8")

    result = fricbound.nonlinear_modes(str(scene))
    assert result.complete, result.status
    assert result.case_names == ["m+1", "m-1", "left-1_right+1", "left+1_right-1", "m0"]
    for name in result.case_names:
        mode = result.cases[name]
        mine = rows[rows["case"] == name]
        np.testing.assert_allclose(mode.freq_hz, mine["freq_hz"], rtol=1e-9)
        np.testing.assert_allclose(mode.damping_ratio, mine["damping_ratio"], rtol=1e-9)
        np.testing.assert_allclose(mode.amplitude, mine["y2_amp"], rtol=1e-9)
        sized = ~np.isnan(mine["freq_trunc_err"])
        np.testing.assert_allclose(
            mode.freq_trunc_err[sized], mine["freq_trunc_err"][sized], rtol=1e-3, atol=1e-15
        )
        assert np.isnan(mode.freq_trunc_err[~sized]).all()
        assert mode.mode == 3
        assert abs(mode.linear_freq_hz - 225.0791) < 1e-3
    assert result.band is not None and len(result.band["amplitude"]) > 10
    table = result.to_pandas()
    assert len(table) == len(rows)
    assert list(table.columns[:4]) == ["case", "modal_amplitude", "amplitude", "freq_hz"]
    assert "right_state" in table.columns


def test_keywords_set_the_mode_and_bad_input_names_the_field():
    """Without [limits] one case, the scene's; the 2nd mode of the paper scene chosen by its
    nearest frequency falls from 162 Hz as the damper slips, with a predicted peak for the
    paper's excitation; a reversed range raises ValueError naming analysis.amplitude."""
    scene = Scene.paper()
    result = fricbound.nonlinear_modes(scene, mode_freq_hz=150.0, dof="y2", amplitude=[1e-7, 1e-3])
    assert result.complete, result.status
    assert result.case_names == ["scene"]
    assert result.cases["scene"].mode == 2
    assert abs(result.freq_hz[0] - 161.981) < 1e-2
    assert result.freq_hz[-1] < result.freq_hz[0] - 1.0
    assert np.all(np.diff(result.amplitude) != 0)
    peak = result.predicted_peak
    assert peak is not None and 1e-4 < peak["amplitude"] < 1e-3
    with pytest.raises(ValueError, match="analysis.amplitude"):
        fricbound.nonlinear_modes(scene, mode=2, dof="y2", amplitude=[1e-3, 1e-7])


def test_a_sweep_of_a_mode_scene_predicts_each_case_peak():
    """fricbound.sweep on a nonlinear-mode scene with [limits]: per pre-load the peak each
    case's mode predicts (the four sign combinations per side bound the response), equal to
    the prediction of fricbound.nonlinear_modes at that pre-load."""
    scene = (
        Scene.paper()
        .set("analysis.kind", "nonlinear-modes")
        .set("analysis.mode", 2)
        .set("analysis.dof", "y2")
        .set("analysis.amplitude", [1e-8, 3e-3])
        .set("analysis.freq_start_hz", 140.0)
        .set("analysis.freq_end_hz", 185.0)
        .set("accuracy.estimate", False)
        .set("limits.peak_window_hz", [140.0, 185.0])
    )
    result = fricbound.sweep(scene, "static_loads.0.value", [60.0, 240.0], scale=-1.0, parameter="F0", unit="N")
    assert result.peaks_from == "predicted from the nonlinear mode of each case"
    assert result.limit_cases == 4
    assert result.cases[:2] == ["m+1", "m-1"]
    upper, lower = result.limit_peaks()
    assert np.all(upper >= lower) and np.all(lower > 0)
    modes = fricbound.nonlinear_modes(scene.copy().set("static_loads.0.value", -240.0))
    for k, name in enumerate(result.cases):
        np.testing.assert_allclose(
            result.peak_amplitude[1, k], modes.cases[name].predicted_peak["amplitude"], rtol=1e-9
        )
