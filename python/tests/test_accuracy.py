"""The accuracy study from Python against the CLI's study.csv."""

import csv
import math
import subprocess

import numpy as np

import fricbound
from fricbound import Scene

from conftest import PAPER


def test_accuracy_study_equals_the_cli_study_csv(cli_binary, tmp_path):
    """`fricbound.accuracy_study` of a limit scene gives the CLI's rows (per limit curve, same
    settings, Newton counts and errors), and its errors fall as H grows."""
    scene_path = PAPER / "fig13-3rd.toml"
    events = []
    study = fricbound.accuracy_study(Scene.from_toml(str(scene_path)), quick=True, progress=events.append)
    assert study.complete
    curves = list(dict.fromkeys(study.curve))
    assert curves == ["m+1", "m-1"]
    assert set(study.references) == set(curves)
    settings = study.rows()
    assert len(events) == len(settings)
    assert all(e["kind"] == "setting" for e in events)

    out = tmp_path / "study"
    done = subprocess.run(
        [str(cli_binary), "study", "accuracy", str(scene_path), "--quick", "--quiet", "--out", str(out)],
        capture_output=True,
        text=True,
    )
    assert done.returncode in (0, 3), done.stderr
    with open(out / "study.csv", newline="") as f:
        cli = {(r["curve"], r["setting"]): r for r in csv.DictReader(f)}
    # Every check and setting row of Python is a CLI row (the CLI writes no reference rows).
    ours = [i for i, role in enumerate(study.role) if role != "reference"]
    assert len(ours) == len(cli)
    for i in ours:
        row = cli[(study.curve[i], study.setting[i].replace(",", ";"))]
        assert row["group"] == study.group[i]
        assert row["status"] == study.setting_status[i].replace(",", ";")
        assert int(row["unknowns"]) == study.unknowns[i]
        assert int(row["newton_iterations"]) == study.newton_iterations[i]
        assert int(row["points"]) == study.points[i]
        for col, ours_col in (("curve_l2_err", study.curve_l2), ("peak_amp_err", study.peak_amp_err)):
            if row[col] in ("", "NaN", "nan"):
                assert math.isnan(ours_col[i])
            else:
                assert math.isclose(float(row[col]), ours_col[i], rel_tol=1e-3, abs_tol=1e-300)

    for curve in curves:
        by_label = {study.setting[i]: i for i in study.rows(curve)}
        assert study.peak_amp_err[by_label["H = 5"]] < study.peak_amp_err[by_label["H = 1"]]
        front = study.pareto_front(curve)
        assert front and all(label in by_label for label in front)
    frame = study.to_pandas()
    assert len(frame) == len(study.curve)
    assert np.all(frame["curve_l2"].to_numpy()[study.rows(role="reference")] == 0.0)
