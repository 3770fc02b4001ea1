//! `fricbound study accuracy --quick` end to end on the paper case around its 2nd resonance
//! (a narrowed range, so that the whole study takes seconds): files, rows and the ordering of
//! the errors along the harmonic ladder.

use crate::support;

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
            "curve,group,setting,status,unknowns,points,newton_iterations,time_s,curve_l2_err,\
             peak_amp_err,peak_freq_err,peak1_amp_err,peak1_freq_err"
        ),
        "{header}"
    );
    // The reference check, 3 harmonic sets and one odd-only set, 3 sample counts, 2
    // tolerances, 3 effect switches (labels and statuses hold no commas: one cell each).
    assert_eq!(rows.len(), 13, "{rows:?}");
    let row = |label: &str| {
        rows.iter()
            .find(|r| r[2].trim_matches('"') == label)
            .unwrap_or_else(|| panic!("no row {label}: {rows:?}"))
    };
    let l2 = |label: &str| row(label)[8].parse::<f64>().unwrap();
    let peak = |label: &str| row(label)[9].parse::<f64>().unwrap();
    // The reference (H = 7) is converged: H = 5 agrees to 1e-3; H = 1 is off by percents,
    // and the errors fall along the ladder.
    let check = rows.iter().find(|r| r[1] == "reference").unwrap();
    assert!(check[9].parse::<f64>().unwrap() < 1e-3, "{check:?}");
    assert!(peak("H = 1") > 0.02, "{}", peak("H = 1"));
    assert!(l2("H = 1") > l2("H = 3") && l2("H = 3") > l2("H = 5"));
    for r in &rows {
        // A scene without `[limits]` is studied on its FRF alone.
        assert_eq!(r[0], "frf", "{r:?}");
        assert_eq!(r[3].trim_matches('"'), "complete", "{r:?}");
        assert!(r[7].parse::<f64>().unwrap() > 0.0);
    }
    let md = std::fs::read_to_string(out.join("study.md")).unwrap();
    assert!(md.contains("| harmonics | H = 1 |"), "{md}");
    assert!(md.contains("Pareto"));
    for f in ["accuracy_pareto.png", "accuracy_pareto.svg"] {
        assert!(std::fs::metadata(out.join(f)).unwrap().len() > 1000, "{f}");
    }
    assert!(text(&o.stdout).contains("Pareto front:"));
}

/// A limit scene is studied per limit curve: the paper's 3rd resonance (`fig13-3rd.toml`,
/// narrowed around the peaks) on m = +1 and m = −1, each against its own reference.
#[test]
fn quick_accuracy_study_of_a_limit_scene_covers_each_limit_curve() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("acc");
    let o = fricbound(&[
        "study",
        "accuracy",
        &scene("fig13-3rd.toml"),
        "--quick",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
        "--set",
        "analysis.freq_start_hz=212",
        "--set",
        "analysis.freq_end_hz=228",
    ]);
    assert!(o.status.success(), "stderr: {}", text(&o.stderr));
    let (header, rows) = csv(&out.join("study.csv"));
    assert!(
        header.starts_with("curve,group,setting,status,"),
        "{header}"
    );
    // Per curve: the reference check and the 12 settings of a quick study.
    let curves = ["m+1", "m-1"];
    for c in curves {
        let of_curve: Vec<&Vec<String>> = rows.iter().filter(|r| r[0] == c).collect();
        assert_eq!(of_curve.len(), 13, "{c}: {rows:?}");
        let row = |label: &str| {
            of_curve
                .iter()
                .find(|r| r[2] == label)
                .unwrap_or_else(|| panic!("{c}: no row {label}"))
        };
        let l2 = |label: &str| row(label)[8].parse::<f64>().unwrap();
        // The curve's own reference is converged (H = 5 against H = 7), and the harmonic
        // ladder converges towards it.
        let check = of_curve.iter().find(|r| r[1] == "reference").unwrap();
        assert!(check[9].parse::<f64>().unwrap() < 1e-2, "{c}: {check:?}");
        assert!(
            l2("H = 1") > l2("H = 5"),
            "{c}: {} {}",
            l2("H = 1"),
            l2("H = 5")
        );
        for r in &of_curve {
            assert_eq!(r[3], "complete", "{c}: {r:?}");
        }
    }
    assert_eq!(rows.len(), 26, "{rows:?}");
    let md = std::fs::read_to_string(out.join("study.md")).unwrap();
    // The two curves differ (that is why each needs its own reference): their references'
    // peaks are not the same.
    let peaks: Vec<&str> = md
        .lines()
        .filter(|l| l.starts_with("Reference peaks"))
        .collect();
    assert_eq!(peaks.len(), 2, "{md}");
    assert_ne!(peaks[0], peaks[1]);
    for c in curves {
        assert!(md.contains(&format!("## Curve `{c}`")), "{md}");
        assert!(md.contains(&format!("accuracy_pareto_{c}.png")), "{md}");
        for ext in ["png", "svg"] {
            let f = out.join(format!("accuracy_pareto_{c}.{ext}"));
            assert!(std::fs::metadata(&f).unwrap().len() > 1000, "{f:?}");
        }
    }
    assert!(
        std::fs::metadata(out.join("accuracy_pareto.png"))
            .unwrap()
            .len()
            > 1000
    );
    let stdout = text(&o.stdout);
    assert!(
        stdout.contains("curve m+1: reference") && stdout.contains("curve m-1: reference"),
        "{stdout}"
    );
}

/// The curves of a study: the FRF of a scene without `[limits]`; the two limit curves and
/// each per-side case of a limit scene.
#[test]
fn study_curves_of_plain_and_limit_scenes() {
    use fricbound::study::accuracy::{study_curves, StudyPlan};
    let parsed = |text: &str, label: &str| fricbound::scene::parse(text, label, &[]).unwrap();
    let plain = std::fs::read_to_string(scene("zoom-2nd.toml")).unwrap();
    let curves = study_curves(&parsed(&plain, "zoom-2nd.toml"), "zoom-2nd.toml").unwrap();
    assert_eq!(curves.len(), 1);
    assert_eq!(curves[0].name, "frf");
    assert!(curves[0].case.is_none());
    let limits = std::fs::read_to_string(scene("fig13-3rd.toml")).unwrap()
        + "\n[[limits.cases]]\nname = \"stuck-left\"\nsides = { left = 1.0, right = -1.0 }\n";
    let curves = study_curves(&parsed(&limits, "fig13-3rd.toml"), "fig13-3rd.toml").unwrap();
    let names: Vec<&str> = curves.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["m+1", "m-1", "stuck-left"]);
    let states: Vec<Vec<f64>> = curves
        .iter()
        .map(|c| c.case.as_ref().unwrap().contact_states.clone())
        .collect();
    assert_eq!(states, [vec![1.0, 1.0], vec![-1.0, -1.0], vec![1.0, -1.0]]);
    // A bad override is an error naming the field, not a panic.
    let err = StudyPlan::new(
        &limits,
        "fig13-3rd.toml",
        &["harmonics.max=zero".to_string()],
        true,
    )
    .expect_err("a bad override is refused")
    .to_string();
    assert!(err.contains("harmonics.max"), "{err}");
}
