//! A limit analysis goes on past a case that fails or stops early: every case is attempted and
//! says how it ended, an unfinished curve keeps its finished points, the band exists where both
//! limit curves were solved (NaN elsewhere), and `fricbound run` writes and draws what there is,
//! lists every curve's status in `limits.json` and ends `incomplete: …` with exit code 3.

use crate::support;

use fricbound::analysis::limits::{self, CurveStatus, LimitAnalysis, LimitSettings, Regime};
use fricbound::cli::EXIT_INCOMPLETE;
use fricbound::model::Problem;
use fricbound::scene;
use support::{csv, fricbound, json, scene as scene_path, text};

/// Continuation step (scaled arc length) used as initial, smallest and largest step, so that
/// a case's path takes fixed steps and its point count is fixed.
const STEP: &str = "0.25";

/// The Figs. 13-14 scene (3rd resonance, 200-235 Hz) with fixed steps, a small grid, one
/// intermediate curve and no bound scan, plus `extra`.
fn overrides(extra: &[String]) -> Vec<String> {
    let mut o: Vec<String> = [
        format!("analysis.initial_step={STEP}"),
        format!("analysis.min_step={STEP}"),
        format!("analysis.max_step={STEP}"),
        "limits.grid_points=41".to_string(),
        "limits.bound_scan=[]".to_string(),
        "limits.intermediate=[0.0]".to_string(),
    ]
    .to_vec();
    o.extend(extra.iter().cloned());
    o
}

fn problem(extra: &[String]) -> (Problem, LimitSettings) {
    let file = scene_path("fig13-3rd.toml");
    let text = std::fs::read_to_string(&file).unwrap();
    let (p, l) = scene::parse(&text, &file, &overrides(extra))
        .unwrap()
        .validate_with_limits(&file)
        .unwrap();
    (p, l.unwrap())
}

fn analyse(extra: &[String]) -> LimitAnalysis {
    let (p, l) = problem(extra);
    limits::analyse(&p, &l, |_| {}).unwrap()
}

/// The smallest `analysis.max_points` with which `case` covers the range (bisection;
/// completion is checked again where it is used).
fn min_budget(problem: &Problem, case: &limits::LimitCase) -> usize {
    let complete = |b: usize| {
        let mut p = problem.clone();
        p.analysis.continuation.max_points = b;
        limits::attempt_case(&p, case, None).status.is_complete()
    };
    let (mut lo, mut hi) = (1, 1000);
    assert!(complete(hi), "{} does not complete", case.name);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if complete(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

/// The point budget that the shorter limit path fits in and the longer one does not, with the
/// index of the limit curve that then stops early. Calibrated on the limit cases themselves,
/// so the test follows changes of the step control.
fn budget() -> (usize, usize) {
    let (p, _) = problem(&[]);
    let n: Vec<usize> = limits::two_point_cases(&p)
        .iter()
        .map(|c| min_budget(&p, c))
        .collect();
    assert_ne!(
        n[0], n[1],
        "the limit paths need the same budget: the test needs another step"
    );
    let long = if n[0] > n[1] { 0 } else { 1 };
    (n[0].min(n[1]), long)
}

/// What a user should see: the limit curve that used up `analysis.max_points` is
/// `incomplete: …` with its finished points, the other one and the intermediate curve are
/// still solved, the band exists on the stretch both limit curves cover and is NaN (regime
/// `unknown`) above it.
#[test]
fn a_limit_curve_that_stops_early_keeps_its_points_and_the_others_are_still_solved() {
    let (max_points, long) = budget();
    let a = analyse(&[format!("analysis.max_points={max_points}")]);
    let (stopped, finished) = (&a.limits[long], &a.limits[1 - long]);

    assert!(finished.status.is_complete(), "{:?}", finished.status);
    assert!(finished.peak.as_ref().is_some_and(|p| p.refined));
    match &stopped.status {
        CurveStatus::Incomplete { reason } => {
            assert!(reason.contains("max_points"), "{reason}")
        }
        other => panic!("{} should be incomplete: {other:?}", stopped.case.name),
    }
    assert_eq!(stopped.points.len(), max_points);
    let reached = stopped.points.iter().map(|p| p.freq_hz).fold(0.0, f64::max);
    assert!(reached > 200.0 && reached < 235.0, "{reached}");
    // The intermediate curve was attempted too (whatever its own budget allowed).
    assert_eq!(a.intermediate.len(), 1);
    assert!(!a.intermediate[0].points.is_empty());

    // The band where both limit curves exist, NaN and `unknown` elsewhere.
    let band = a.band_points();
    assert!(
        band > 0 && band < a.grid.len(),
        "{band} of {}",
        a.grid.len()
    );
    for g in &a.grid {
        if g.lower.is_finite() {
            assert!(g.freq_hz <= reached + 1e-9, "band at {} Hz", g.freq_hz);
            assert!(g.upper >= g.lower);
        } else {
            assert!(g.upper.is_nan() && g.regime == Regime::Unknown);
        }
        if g.freq_hz > reached {
            assert!(
                g.lower.is_nan(),
                "band above the stopped curve at {}",
                g.freq_hz
            );
        }
    }
    // The analysis says which curve did not cover the range.
    assert!(!a.is_complete());
    let unfinished = a.unfinished();
    assert!(
        unfinished
            .iter()
            .any(|r| r.starts_with(&format!("curve `{}` incomplete: ", stopped.case.name))),
        "{unfinished:?}"
    );
    assert!(!unfinished.iter().any(|r| r.contains(&finished.case.name)));
}

/// What a user should see: when no case can be solved (one Newton iteration, three at fixed
/// frequency, on a thousand times the paper's excitation: the start leaves a residual of about
/// 0.3), every case is still attempted and each is `failed: …` with its reason; nothing stops
/// at the first one.
#[test]
fn every_case_is_attempted_when_cases_fail() {
    let a = analyse(&[
        "analysis.max_iterations=1".into(),
        "harmonic_loads.0.sin=-2e4".into(),
        "harmonic_loads.1.sin=5e3".into(),
        "limits.bound_scan=[-1.0, 1.0]".into(),
    ]);
    assert_eq!(a.limits.len(), 2);
    assert_eq!(a.intermediate.len(), 1);
    assert_eq!(a.scanned.len(), 4);
    for c in a.limits.iter().chain(&a.intermediate) {
        assert!(
            c.status
                .text()
                .starts_with("failed: no solution at the start"),
            "{}: {}",
            c.case.name,
            c.status.text()
        );
        assert!(c.points.is_empty() && c.peak.is_none());
    }
    assert!(a
        .scanned
        .iter()
        .all(|c| matches!(c.status, CurveStatus::Failed { .. })));
    assert_eq!(a.unfinished().len(), 7);
    assert_eq!(a.band_points(), 0);
    assert!(a.variability().peak_ratio.is_nan());
}

/// The same stopped analysis through `fricbound run`: exit code 3 naming the curve, every
/// curve's status in `limits.json`, the stopped curve's points in its `curve_*.csv`, NaN band
/// cells above it in `limits.csv`, the statuses in `peaks.csv`, and the figure.
#[test]
fn the_run_writes_every_curve_status_and_exits_3() {
    let (max_points, long) = budget();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("limits");
    let mut args: Vec<String> = vec![
        "run".into(),
        scene_path("fig13-3rd.toml"),
        "--quiet".into(),
        "--out".into(),
        out.display().to_string(),
    ];
    for o in overrides(&[format!("analysis.max_points={max_points}")]) {
        args.push("--set".into());
        args.push(o);
    }
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = fricbound(&args);
    let stderr = text(&o.stderr);
    assert_eq!(
        o.status.code(),
        Some(i32::from(EXIT_INCOMPLETE)),
        "{stderr}"
    );
    let names = ["m+1", "m-1"];
    let (stopped, finished) = (names[long], names[1 - long]);
    assert!(
        stderr.starts_with("incomplete: ")
            && stderr.contains(&format!("curve `{stopped}` incomplete: "))
            && stderr.contains("the band exists at "),
        "{stderr}"
    );

    let j = json(&out.join("limits.json"));
    assert!(j["status"].as_str().unwrap().starts_with("incomplete: "));
    let curves = j["curves"].as_array().unwrap();
    let status_of = |name: &str| {
        curves
            .iter()
            .find(|c| c["case"] == name)
            .unwrap_or_else(|| panic!("{name} not in {curves:?}"))["status"]
            .as_str()
            .unwrap()
            .to_string()
    };
    assert_eq!(status_of(finished), "complete");
    assert!(status_of(stopped).starts_with("incomplete: "));
    assert!(curves.iter().any(|c| c["case"] == "m0"));
    let stopped_json = j["limits"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["case"]["name"] == stopped)
        .unwrap();
    assert_eq!(stopped_json["points"].as_array().unwrap().len(), max_points);
    let defined = j["band"]["defined_points"].as_u64().unwrap();
    assert!(defined > 0 && defined < 41, "{defined}");

    let (_, rows) = csv(&out.join(format!("curve_{stopped}.csv")));
    assert_eq!(rows.len(), max_points);
    let (header, rows) = csv(&out.join("limits.csv"));
    let lower = header.split(',').position(|h| h == "lower_amp").unwrap();
    let nan = rows.iter().filter(|r| r[lower] == "NaN").count();
    assert!(nan > 0 && nan < rows.len(), "{nan} NaN band cells");
    let peaks = std::fs::read_to_string(out.join("peaks.csv")).unwrap();
    assert!(peaks.lines().next().unwrap().ends_with(",status"));
    assert!(peaks.contains("\"incomplete: "), "{peaks}");
    for f in ["limits_y2.png", "limits_y2.svg"] {
        assert!(out.join(f).is_file(), "{f}");
    }
}
