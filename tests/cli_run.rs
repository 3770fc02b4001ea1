//! `fricbound run` end to end: result files, headers, streaming and failure handling.

use std::path::Path;
use std::process::Command;

fn fricbound(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_fricbound"))
        .args(args)
        .output()
        .expect("fricbound runs")
}

fn scene(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("meshes/paper-wedge")
        .join(name)
        .display()
        .to_string()
}

#[test]
fn run_writes_all_results() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("zoom");
    let o = fricbound(&[
        "run",
        &scene("zoom-2nd.toml"),
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        o.status.success(),
        "stderr: {}",
        String::from_utf8_lossy(&o.stderr)
    );

    let frf = std::fs::read_to_string(out.join("frf.csv")).unwrap();
    let mut lines = frf.lines();
    assert_eq!(
        lines.next().unwrap(),
        "freq_hz,y2_amp,y2_peak,left_state,right_state,newton_iters"
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert!(rows.len() > 20);
    for r in &rows {
        assert_eq!(r.len(), 6);
        let f: f64 = r[0].parse().unwrap();
        assert!((150.0..=175.0 + 1e-9).contains(&f));
        let amp: f64 = r[1].parse().unwrap();
        let peak: f64 = r[2].parse().unwrap();
        assert!(amp > 0.0 && peak >= amp * 0.999);
        for s in &r[3..5] {
            assert!(
                ["stuck", "stick-slip", "stick-slip-liftoff", "open"].contains(s),
                "{s}"
            );
        }
        assert!(r[5].parse::<usize>().unwrap() >= 1);
    }
    let last: f64 = rows.last().unwrap()[0].parse().unwrap();
    assert!(
        (last - 175.0).abs() < 1e-9,
        "ends at the end frequency, got {last}"
    );

    for name in ["linear_open.csv", "linear_stuck.csv"] {
        let text = std::fs::read_to_string(out.join(name)).unwrap();
        assert_eq!(text.lines().next().unwrap(), "freq_hz,y2_amp");
        assert_eq!(text.lines().count(), 502);
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("solution.json")).unwrap()).unwrap();
    assert_eq!(json["status"], "complete");
    assert_eq!(json["info"]["version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(json["info"]["scene_hash"].as_str().unwrap().len(), 64);
    assert_eq!(json["info"]["blocks"], serde_json::json!(["0", "c1", "s1"]));
    let points = json["points"].as_array().unwrap();
    assert_eq!(points.len(), rows.len());
    assert_eq!(points[0]["coefficients"].as_array().unwrap().len(), 18);
    assert!(json["elapsed_s"].as_f64().unwrap() > 0.0);
    for ext in ["png", "svg"] {
        let meta = std::fs::metadata(out.join(format!("frf_y2.{ext}"))).unwrap();
        assert!(meta.len() > 1000);
    }
    // No temporary files are left behind.
    for entry in std::fs::read_dir(&out).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        assert!(!name.ends_with(".partial"), "{name}");
    }
}

#[test]
fn set_overrides_change_the_solve() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("h3");
    let o = fricbound(&[
        "run",
        &scene("zoom-2nd.toml"),
        "--quiet",
        "--out",
        out.to_str().unwrap(),
        "--set",
        "harmonics.max=3",
        "--set",
        "analysis.freq_end_hz=160",
    ]);
    assert!(
        o.status.success(),
        "stderr: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("solution.json")).unwrap()).unwrap();
    assert_eq!(
        json["info"]["blocks"],
        serde_json::json!(["0", "c1", "s1", "c2", "s2", "c3", "s3"])
    );
    let last = json["points"].as_array().unwrap().last().unwrap()["freq_hz"]
        .as_f64()
        .unwrap();
    assert!((last - 160.0).abs() < 1e-9);
}

#[test]
fn failed_continuation_keeps_finished_points_and_exits_nonzero() {
    // One Newton iteration per step and a large minimum step: the path must stall at the
    // first stick-slip transition, after some converged stuck points.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("stall");
    let o = fricbound(&[
        "run",
        &scene("zoom-2nd.toml"),
        "--quiet",
        "--out",
        out.to_str().unwrap(),
        "--set",
        "analysis.max_iterations=2",
        "--set",
        "analysis.min_step=0.05",
        "--set",
        "analysis.initial_step=0.1",
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "expected a stall");
    assert!(
        stderr.contains("stalled") && !stderr.contains("panicked"),
        "{stderr}"
    );
    let frf = std::fs::read_to_string(out.join("frf.csv")).unwrap();
    assert!(frf.lines().count() > 2, "finished points are kept");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("solution.json")).unwrap()).unwrap();
    assert!(json["status"].as_str().unwrap().starts_with("failed:"));
    assert_eq!(
        json["points"].as_array().unwrap().len(),
        frf.lines().count() - 1
    );
}
