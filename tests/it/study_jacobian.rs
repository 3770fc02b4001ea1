//! `fricbound study jacobian --quick` end to end: the paper case around its 2nd resonance as
//! the scene, plus the quick ladder (paper case at H = 1 and 5, a chain with Jenkins elements
//! to ground, the reduced blade pair with 2 pairs per side): files, one row per case and
//! formulation, Jacobians that match differences, and `auto`'s choice marked.

use crate::support;

use support::{csv, fricbound, scene, text};

#[test]
fn quick_jacobian_study_runs_end_to_end() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("jac");
    let o = fricbound(&[
        "study",
        "jacobian",
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
    let (header, rows) = csv(&out.join("jacobian.csv"));
    assert!(
        header.starts_with("case,dofs,contacts,harmonics,formulation,auto,fastest,status,"),
        "{header}"
    );
    let column = |name: &str| {
        header
            .split(',')
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("no column {name} in {header}"))
    };
    let (case, formulation, auto, fastest, status) = (
        column("case"),
        column("formulation"),
        column("auto"),
        column("fastest"),
        column("status"),
    );
    let (forward, central, point_ms) = (
        column("jacobian_vs_forward"),
        column("jacobian_vs_central"),
        column("point_ms"),
    );
    // The scene, the paper case at H = 1 and 5, one chain, one blade pair: 5 cases × 5.
    assert_eq!(rows.len(), 25, "{rows:?}");
    let mut cases: Vec<&str> = rows.iter().map(|r| r[case].as_str()).collect();
    cases.dedup();
    assert_eq!(cases.len(), 5, "{cases:?}");
    for c in &cases {
        let of_case: Vec<&Vec<String>> = rows.iter().filter(|r| r[case] == *c).collect();
        let names: Vec<&str> = of_case.iter().map(|r| r[formulation].as_str()).collect();
        assert_eq!(
            names,
            ["dense", "sparse", "condensed", "schur", "schur-lowrank"],
            "{c}"
        );
        // Exactly one formulation is auto's, and one the fastest.
        assert_eq!(
            of_case.iter().filter(|r| r[auto] == "true").count(),
            1,
            "{c}"
        );
        assert_eq!(
            of_case.iter().filter(|r| r[fastest] == "true").count(),
            1,
            "{c}"
        );
        for r in &of_case {
            let s = r[status].as_str();
            assert!(
                s == "measured" || s.starts_with("refused:") || s.starts_with("skipped:"),
                "{c} {}: {s}",
                r[formulation]
            );
            if s == "measured" {
                // The analytic Jacobian of every formulation matches central differences
                // closely and forward differences to their truncation error.
                let (f, ce) = (
                    r[forward].parse::<f64>().unwrap(),
                    r[central].parse::<f64>().unwrap(),
                );
                assert!(ce < 1e-5, "{c} {}: central {ce}", r[formulation]);
                assert!(f < 1e-3, "{c} {}: forward {f}", r[formulation]);
                assert!(r[point_ms].parse::<f64>().unwrap() > 0.0);
            }
        }
    }
    // The chain's contacts have a zero normal direction: schur takes them.
    let chain_schur = rows
        .iter()
        .find(|r| r[case].starts_with("chain") && r[formulation] == "schur")
        .unwrap();
    assert_eq!(chain_schur[status], "measured", "{chain_schur:?}");
    let md = std::fs::read_to_string(out.join("jacobian.md")).unwrap();
    assert!(md.contains("`auto` picks"), "{md}");
    assert!(md.contains("| **auto**") || md.contains("**auto**"), "{md}");
    assert!(text(&o.stdout).contains("`auto` picks the fastest formulation per FRF point in"));
    assert!(!out.join("ladder-meshes").exists());
}
