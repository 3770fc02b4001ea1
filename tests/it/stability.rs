//! Hill stability of converged points (`analysis.stability`): past the fold of a softening
//! (lift-off) resonance the saddle branch is flagged unstable with a real exponent while the
//! linear branch is stable, the
//! columns and JSON fields exist only when asked for, and the scenes Hill's method does not
//! suit are refused naming the field. The linear check (exponents = damped eigenvalues) is a
//! unit test of `analysis::stability`.

use crate::support;

use std::path::Path;

use support::{csv, json, run_scene, scene, text};

fn fold_scene() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/liftoff-fold.toml")
        .display()
        .to_string()
}

/// Column index of `name` in a CSV header.
fn column(header: &str, name: &str) -> usize {
    header
        .split(',')
        .position(|c| c == name)
        .unwrap_or_else(|| panic!("no column `{name}` in {header}"))
}

#[test]
fn the_branch_past_the_fold_is_unstable_and_the_linear_branch_stable() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_scene(&fold_scene(), dir.path(), &[]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let (header, rows) = csv(&dir.path().join("frf.csv"));
    let cell = |name: &str| -> Vec<String> {
        let c = column(&header, name);
        rows.iter().map(|r| r[c].clone()).collect()
    };
    let number =
        |name: &str| -> Vec<f64> { cell(name).iter().map(|v| v.parse().unwrap()).collect() };
    let freq = number("freq_hz");
    let floquet_re = number("floquet_re");
    let floquet_hz = number("floquet_freq_hz");
    let stable: Vec<bool> = cell("stable").iter().map(|v| v.parse().unwrap()).collect();
    let state = cell("stop_state");
    let omega_end = 2.0 * std::f64::consts::PI * 60.0;
    for i in 0..freq.len() {
        // The verdict is the sign of the leading exponent (to the documented tolerance).
        assert_eq!(stable[i], floquet_re[i] <= 1e-6 * omega_end, "point {i}");
        // With the contact closed all period the system is linear, and damped.
        if state[i] == "stuck" {
            assert!(
                stable[i] && floquet_re[i] < 0.0,
                "point {i} at {} Hz",
                freq[i]
            );
        }
    }
    // The path climbs the linear (contact closed) branch to the fold where lift-off starts …
    let fold = (1..freq.len())
        .find(|&i| freq[i] < freq[i - 1])
        .expect("the path folds back")
        - 1;
    assert!(
        fold >= 10 && (50.0..52.8).contains(&freq[fold]),
        "fold at {}",
        freq[fold]
    );
    assert!(stable[..fold - 1].iter().all(|&s| s));
    // … and comes back over the saddle branch: a real positive exponent at every point of
    // the first backward stretch (two points next to each fold left out, where it crosses 0:
    // the stretch ends at the lower fold).
    let back_end = (fold + 1..freq.len())
        .find(|&i| freq[i] > freq[i - 1])
        .unwrap_or(freq.len());
    assert!(
        back_end - fold > 10 && freq[fold] - freq[back_end - 1] > 5.0,
        "backward stretch {}..{} Hz",
        freq[back_end - 1],
        freq[fold]
    );
    for i in fold + 3..back_end - 2 {
        assert!(
            !stable[i] && floquet_re[i] > 0.0 && floquet_hz[i] == 0.0,
            "point {i} at {} Hz: Re = {}, f = {}",
            freq[i],
            floquet_re[i],
            floquet_hz[i]
        );
    }
    let solution = json(&dir.path().join("solution.json"));
    let first = &solution["points"][0];
    assert!(first["stable"].is_boolean() && first["floquet_re"].is_number());
    assert!(first["floquet_freq_hz"].is_number());
}

#[test]
fn stability_off_adds_no_columns_and_on_adds_five() {
    let dir = tempfile::tempdir().unwrap();
    // The error estimate's columns off, so that the headers compare the stability columns.
    let base = [
        "analysis.freq_start_hz=200",
        "analysis.freq_end_hz=210",
        "harmonics.max=3",
        "accuracy.estimate=false",
    ];
    let out = run_scene(&scene("full-range.toml"), dir.path(), &base);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let (header, _) = csv(&dir.path().join("frf.csv"));
    assert!(header.ends_with("newton_iters"), "{header}");
    let point = &json(&dir.path().join("solution.json"))["points"][0];
    assert!(point.get("stable").is_none());

    let on = tempfile::tempdir().unwrap();
    let mut with = base.to_vec();
    with.push("analysis.stability=true");
    let out = run_scene(&scene("full-range.toml"), on.path(), &with);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let (header, rows) = csv(&on.path().join("frf.csv"));
    assert!(
        header.ends_with(
            "newton_iters,stable,floquet_re,floquet_freq_hz,stability_method,stability_reliable"
        ),
        "{header}"
    );
    assert!(rows.iter().all(|r| r.len() == header.split(',').count()));
}

#[test]
fn scenes_hill_does_not_suit_are_refused_naming_the_field() {
    let dir = tempfile::tempdir().unwrap();
    for (overrides, field, reason) in [
        (
            vec!["analysis.stability=true", "effects.coupling=uncoupled"],
            "analysis.stability",
            "0th harmonic",
        ),
        (
            vec![
                "analysis.stability=true",
                "harmonics.max=",
                "harmonics.list=[0, 1, 3]",
            ],
            "analysis.stability",
            "without gaps",
        ),
        (
            vec![
                "analysis.stability=true",
                "analysis.hill_solver=dense",
                "harmonics.max=60",
            ],
            "analysis.hill_solver",
            "exceed the 600",
        ),
        (
            vec!["analysis.hill_solver=shift-invert"],
            "analysis.hill_solver",
            "analysis.stability is off",
        ),
    ] {
        let out = run_scene(&scene("full-range.toml"), dir.path(), &overrides);
        assert_eq!(out.status.code(), Some(1), "{overrides:?}");
        let err = text(&out.stderr);
        assert!(
            err.contains(field) && err.contains(reason),
            "{overrides:?}: {err}"
        );
    }
}

#[test]
fn a_limit_analysis_reports_where_each_limit_curve_is_unstable() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_scene(
        &scene("fig13-3rd.toml"),
        dir.path(),
        &["analysis.stability=true"],
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    let limits = json(&dir.path().join("limits.json"));
    let curves = limits["stability"]["limit_curves"].as_array().unwrap();
    assert_eq!(curves.len(), 2);
    for c in curves {
        let name = c["case"].as_str().unwrap();
        let (header, rows) = csv(&dir.path().join(format!("curve_{name}.csv")));
        assert!(
            header.ends_with(
                ",stable,floquet_re,floquet_freq_hz,stability_method,stability_reliable"
            ),
            "{header}"
        );
        let (f, s) = (column(&header, "freq_hz"), column(&header, "stable"));
        let unstable: Vec<f64> = rows
            .iter()
            .filter(|r| r[s] == "false")
            .map(|r| r[f].parse().unwrap())
            .collect();
        assert_eq!(c["points"].as_u64().unwrap() as usize, rows.len());
        assert_eq!(
            c["unstable_points"].as_u64().unwrap() as usize,
            unstable.len()
        );
        // Every unstable point lies in one of the reported stretches, and each stretch's
        // ends are unstable points.
        let stretches: Vec<(f64, f64)> = c["unstable_hz"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| (s[0].as_f64().unwrap(), s[1].as_f64().unwrap()))
            .collect();
        // (The CSV holds 11 significant digits.)
        let tol = |f: f64| 1e-9 * f;
        for &u in &unstable {
            assert!(
                stretches
                    .iter()
                    .any(|&(a, b)| a - tol(a) <= u && u <= b + tol(b)),
                "{name}: {u}"
            );
        }
        for (a, b) in &stretches {
            for end in [a, b] {
                assert!(
                    unstable.iter().any(|u| (u - end).abs() <= 1e-9 * end),
                    "{name}: {end}"
                );
            }
        }
    }
}
