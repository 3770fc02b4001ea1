//! `fricbound study accuracy --quick` end to end on the paper case around its 2nd resonance
//! (a narrowed range, so that the whole study takes seconds): files, rows and the ordering of
//! the errors along the harmonic ladder.

mod support;

use support::{csv, fricbound, scene, text};

#[test]
fn quick_accuracy_study_runs_end_to_end() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("acc");
    let o = fricbound(&[
        "study",
        "accuracy",
        &scene("zoom-2nd.toml"),
        "--quick",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
        "--set",
        "analysis.freq_start_hz=157.0",
        "--set",
        "analysis.freq_end_hz=166.0",
    ]);
    assert!(o.status.success(), "stderr: {}", text(&o.stderr));
    let (header, rows) = csv(&out.join("study.csv"));
    assert!(
        header.starts_with(
            "group,setting,status,unknowns,points,newton_iterations,time_s,curve_l2_err,\
             peak_amp_err,peak_freq_err,peak1_amp_err,peak1_freq_err"
        ),
        "{header}"
    );
    // The reference check, 3 harmonic sets and one odd-only set, 3 sample counts, 2
    // tolerances, 3 effect switches (labels and statuses hold no commas: one cell each).
    assert_eq!(rows.len(), 13, "{rows:?}");
    let row = |label: &str| {
        rows.iter()
            .find(|r| r[1].trim_matches('"') == label)
            .unwrap_or_else(|| panic!("no row {label}: {rows:?}"))
    };
    let l2 = |label: &str| row(label)[7].parse::<f64>().unwrap();
    let peak = |label: &str| row(label)[8].parse::<f64>().unwrap();
    // The reference (H = 7) is converged: H = 5 agrees to 1e-3; H = 1 is off by percents,
    // and the errors fall along the ladder.
    let check = rows.iter().find(|r| r[0] == "reference").unwrap();
    assert!(check[8].parse::<f64>().unwrap() < 1e-3, "{check:?}");
    assert!(peak("H = 1") > 0.02, "{}", peak("H = 1"));
    assert!(l2("H = 1") > l2("H = 3") && l2("H = 3") > l2("H = 5"));
    for r in &rows {
        assert_eq!(r[2].trim_matches('"'), "complete", "{r:?}");
        assert!(r[6].parse::<f64>().unwrap() > 0.0);
    }
    let md = std::fs::read_to_string(out.join("study.md")).unwrap();
    assert!(md.contains("| harmonics | H = 1 |"), "{md}");
    assert!(md.contains("Pareto"));
    for f in ["accuracy_pareto.png", "accuracy_pareto.svg"] {
        assert!(std::fs::metadata(out.join(f)).unwrap().len() > 1000, "{f}");
    }
    assert!(text(&o.stdout).contains("Pareto front:"));
}
