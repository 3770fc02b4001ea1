//! What `fricbound run` leaves on disk and how it exits: honest completion (status and exit
//! code 3 when the range or a case was not covered), result files of an earlier run removed
//! before a run starts, a default folder per set of overrides, figure titles naming the
//! overrides, and the size check that refuses a problem too large for the machine before
//! anything is written; `fricbound check` prints that estimate without listing thousands of
//! harmonics.

use crate::support;

use std::path::{Path, PathBuf};
use std::process::Command;

use fricbound::cli::{EXIT_COMPLETE, EXIT_ERROR, EXIT_INCOMPLETE};
use fricbound::report::owned::is_owned;
use support::{fricbound, fricbound_in, json, names, run_scene, scene, text};

/// Files of the user's that the tests put into output folders.
const USER_FILES: &[&str] = &["notes.txt"];

/// Every file a run wrote into `dir` (and its sub-folders) is one the next run will remove
/// (the user's [`USER_FILES`] aside).
fn assert_all_owned(dir: &Path) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let entry = entry.unwrap();
        let name = entry.file_name().to_string_lossy().into_owned();
        if entry.file_type().unwrap().is_dir() {
            assert!(entry.path().join("limits.json").is_file(), "{name}/");
            assert_all_owned(&entry.path());
        } else if !USER_FILES.contains(&name.as_str()) {
            assert!(is_owned(&name), "{} is not in the owned list", name);
        }
    }
}

/// The case: the point budget of the default paper scene used up after two points.
/// The run writes and draws the two points, says `incomplete: …` in solution.json and on
/// stderr, and exits with 3.
#[test]
fn a_run_that_does_not_cover_the_range_is_incomplete_and_exits_3() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("budget");
    let o = fricbound(&[
        "run",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
        "--set",
        "analysis.max_points=2",
    ]);
    let stderr = text(&o.stderr);
    assert_eq!(
        o.status.code(),
        Some(i32::from(EXIT_INCOMPLETE)),
        "{stderr}"
    );
    assert!(
        stderr.starts_with("incomplete: ") && stderr.contains("analysis.max_points = 2"),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    let sol = json(&out.join("solution.json"));
    let status = sol["status"].as_str().unwrap();
    assert!(status.starts_with("incomplete: "), "{status}");
    assert_eq!(
        status,
        format!("incomplete: {}", stderr["incomplete: ".len()..].trim_end())
    );
    let frf = std::fs::read_to_string(out.join("frf.csv")).unwrap();
    assert_eq!(
        frf.lines().count(),
        3,
        "header and the two finished points:\n{frf}"
    );
    assert_eq!(sol["points"].as_array().unwrap().len(), 2);
    for ext in ["png", "svg"] {
        assert!(
            out.join(format!("frf_y2.{ext}")).is_file(),
            "the points are drawn"
        );
    }

    // The same scene with its budget covers the range: complete, exit code 0.
    let full = dir.path().join("full");
    let o = fricbound(&["run", "--quiet", "--out", full.to_str().unwrap()]);
    assert_eq!(
        o.status.code(),
        Some(i32::from(EXIT_COMPLETE)),
        "{}",
        text(&o.stderr)
    );
    assert!(o.stderr.is_empty(), "{}", text(&o.stderr));
    assert_eq!(json(&full.join("solution.json"))["status"], "complete");
}

/// A limit analysis whose curves cannot cover the range (point budget too small) is incomplete:
/// status `incomplete: …` in limits.json naming the curve, exit code 3, and what finished is
/// still written and drawn.
#[test]
fn an_incomplete_limit_analysis_exits_3_with_its_finished_results() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("limits");
    let o = run_scene(
        &scene("fig13-3rd.toml"),
        &out,
        &[
            "limits.grid_points=41",
            "limits.bound_scan=[]",
            "limits.intermediate=[0.0]",
            "analysis.max_step=0.25",
            "analysis.max_points=30",
        ],
    );
    let stderr = text(&o.stderr);
    assert_eq!(
        o.status.code(),
        Some(i32::from(EXIT_INCOMPLETE)),
        "{stderr}"
    );
    assert!(
        stderr.starts_with("incomplete: ") && stderr.contains("curve `m"),
        "{stderr}"
    );
    let status = json(&out.join("limits.json"))["status"]
        .as_str()
        .unwrap()
        .to_string();
    assert!(
        status.starts_with("incomplete: ") && status.contains("max_points = 30"),
        "{status}"
    );
    for f in ["limits.json", "peaks.csv", "limits_y2.png", "limits_y2.svg"] {
        assert!(out.join(f).is_file(), "{f}: {:?}", names(&out));
    }
    assert_all_owned(&out);
}

/// A sweep with failed cases is incomplete: sweep.json's status names the points, exit code 3,
/// the tables and figures are written.
#[test]
fn a_sweep_with_failed_cases_exits_3() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sweep");
    let o = run_scene(
        &scene("fig16a-d.toml"),
        &out,
        &[
            "sweep.values=[60.0, 130.0]",
            "analysis.max_step=0.25",
            "analysis.max_points=20",
        ],
    );
    let stderr = text(&o.stderr);
    assert_eq!(
        o.status.code(),
        Some(i32::from(EXIT_INCOMPLETE)),
        "{stderr}"
    );
    let status = json(&out.join("sweep.json"))["status"]
        .as_str()
        .unwrap()
        .to_string();
    assert!(
        status.starts_with("incomplete: 2 of 2 sweep points") && status.contains("F0 = 60 N"),
        "{status}"
    );
    for f in ["sweep.csv", "optimal_y2.png", "resonance_y2.svg"] {
        assert!(out.join(f).is_file(), "{f}: {:?}", names(&out));
    }
    assert_all_owned(&out);

    // With the default budget the same sweep is complete.
    let ok = dir.path().join("sweep-ok");
    let o = run_scene(
        &scene("fig16a-d.toml"),
        &ok,
        &["sweep.values=[60.0, 130.0]", "analysis.max_step=0.25"],
    );
    assert_eq!(
        o.status.code(),
        Some(i32::from(EXIT_COMPLETE)),
        "{}",
        text(&o.stderr)
    );
    assert_eq!(json(&ok.join("sweep.json"))["status"], "complete");
}

/// A failed run into a folder that holds an earlier run's results: none of them remain (no
/// figure, no frf.csv of the first run), files that are not results stay.
#[test]
fn a_failed_run_leaves_no_results_of_an_earlier_run() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("same");
    let o = run_scene(&scene("zoom-2nd.toml"), &out, &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let first = std::fs::read_to_string(out.join("frf.csv")).unwrap();
    assert!(out.join("frf_y2.png").is_file());
    assert_all_owned(&out);
    std::fs::write(out.join("notes.txt"), "mine").unwrap();

    // The stall of tests/it/cli_run.rs: fails after some converged points.
    let o = run_scene(
        &scene("zoom-2nd.toml"),
        &out,
        &[
            "analysis.max_iterations=1",
            "analysis.min_step=0.05",
            "analysis.initial_step=0.1",
        ],
    );
    assert_eq!(
        o.status.code(),
        Some(i32::from(EXIT_ERROR)),
        "{}",
        text(&o.stderr)
    );
    let files = names(&out);
    for gone in ["frf_y2.png", "frf_y2.svg"] {
        assert!(
            !files.contains(&gone.to_string()),
            "{gone} of the first run: {files:?}"
        );
    }
    let second = std::fs::read_to_string(out.join("frf.csv")).unwrap();
    assert_ne!(second, first);
    // The first run reached the end frequency (175 Hz); the stalled one did not.
    let last_freq = |csv: &str| -> f64 {
        let row = csv.lines().last().unwrap();
        row.split(',').next().unwrap().parse().unwrap()
    };
    assert!((last_freq(&first) - 175.0).abs() < 1e-9);
    assert!(last_freq(&second) < 175.0 - 1e-6, "{}", last_freq(&second));
    let sol = json(&out.join("solution.json"));
    assert!(sol["status"].as_str().unwrap().starts_with("failed:"));
    assert_eq!(
        sol["points"].as_array().unwrap().len(),
        second.lines().count() - 1
    );
    assert_eq!(
        std::fs::read_to_string(out.join("notes.txt")).unwrap(),
        "mine"
    );

    // A limit analysis, then an FRF into the same folder: no limit-analysis file remains.
    let o = run_scene(
        &scene("fig13-3rd.toml"),
        &out,
        &[
            "limits.grid_points=41",
            "limits.bound_scan=[]",
            "analysis.max_step=0.25",
        ],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(out.join("limits.json").is_file() && out.join("curve_m+1.csv").is_file());
    assert!(!out.join("frf.csv").exists() && !out.join("solution.json").exists());
    assert_all_owned(&out);
    let o = run_scene(&scene("zoom-2nd.toml"), &out, &["analysis.freq_end_hz=152"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let files = names(&out);
    assert!(
        !files.iter().any(|f| f.starts_with("limits")
            || f.starts_with("curve_")
            || f.starts_with("hysteresis")),
        "{files:?}"
    );
    // peaks.csv is the FRF run's now (one row per resonance or anti-resonance), not the limit
    // analysis' (one row per curve).
    let peaks = std::fs::read_to_string(out.join("peaks.csv")).unwrap();
    assert!(peaks.starts_with("dof,kind,freq_hz,"), "{peaks}");
    assert!(files.contains(&"notes.txt".to_string()));
}

/// `--set` variants get their own default folder `out/<stem>-<8 hex digits of the SHA-256 of
/// the overrides>`, printed at the end of the run; the scene's own folder is left alone.
#[test]
fn overrides_get_their_own_default_folder() {
    use sha2::{Digest, Sha256};
    let dir = tempfile::tempdir().unwrap();
    let overrides = ["analysis.freq_end_hz=152", "harmonics.max=2"];
    let o = fricbound_in(
        dir.path(),
        &[
            "run",
            &scene("zoom-2nd.toml"),
            "--set",
            overrides[0],
            "--set",
            overrides[1],
        ],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let hash: String = Sha256::digest(overrides.join("\n").as_bytes())
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    let expected = PathBuf::from("out").join(format!("zoom-2nd-{}", &hash[..8]));
    let stdout = text(&o.stdout);
    assert!(
        stdout.contains(&format!("results in {}", expected.display())),
        "{stdout}"
    );
    assert!(dir.path().join(&expected).join("frf.csv").is_file());
    assert!(!dir.path().join("out/zoom-2nd").exists());

    // With --quiet, stdout is the output folder alone, one line, for scripts to find it.
    let mut quiet = vec!["run", "--quiet"];
    let scene_arg = scene("zoom-2nd.toml");
    quiet.push(&scene_arg);
    for o in &overrides {
        quiet.extend(["--set", o]);
    }
    let o = fricbound_in(dir.path(), &quiet);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert_eq!(text(&o.stdout), format!("{}\n", expected.display()));

    // The library function agrees, and tells other override sets and no overrides apart.
    let scene_path = PathBuf::from("meshes/zoom-2nd.toml");
    let owned: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    assert_eq!(
        fricbound::cli::default_out_dir(Some(&scene_path), &owned),
        expected
    );
    assert_eq!(
        fricbound::cli::default_out_dir(Some(&scene_path), &[]),
        PathBuf::from("out/zoom-2nd")
    );
    assert_ne!(
        fricbound::cli::default_out_dir(Some(&scene_path), &owned[..1]),
        expected
    );
    assert_eq!(
        fricbound::cli::default_out_dir(None, &[]),
        PathBuf::from("out/paper-wedge")
    );
}

/// A figure's title names the overrides it was solved with next to the scene's title.
#[test]
fn figure_titles_name_the_overrides() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("titled");
    let o = run_scene(
        &scene("zoom-2nd.toml"),
        &out,
        &["static_loads.0.value=-100", "analysis.freq_end_hz=152"],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let svg = std::fs::read_to_string(out.join("frf_y2.svg")).unwrap();
    assert!(
        svg.contains("[static_loads.0.value=-100, analysis.freq_end_hz=152]"),
        "the title names the overrides"
    );
    // The title states the pre-load solved with, never the scene file's.
    assert!(svg.contains("F0 = 100 N"), "the title shows the actual F0");
    assert!(!svg.contains("F0 = 120 N"), "no stale F0 in the title");
    // Without overrides, the scene's title alone.
    let plain = dir.path().join("plain");
    let o = run_scene(&scene("zoom-2nd.toml"), &plain, &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let svg = std::fs::read_to_string(plain.join("frf_y2.svg")).unwrap();
    assert!(!svg.contains("static_loads.0.value"));
    assert!(svg.contains("F0 = 120 N"), "the scene's own F0");
}

/// The case: H = 10 000 with 32 768 samples aborted on a 5 GB allocation. It is now
/// refused from the size estimate, before the output folder is created, with exit code 1 and a
/// message naming the fields to lower. The run is made under a 4 GB address-space limit, so a
/// run that allocated the AFT matrices (5 GB each) would abort instead of exiting with 1.
#[test]
fn a_problem_too_large_for_the_machine_is_refused_before_anything_is_written() {
    let overrides = [
        "harmonics.max=10000".to_string(),
        "harmonics.samples=32768".to_string(),
    ];
    let (_, _, problem, _) = fricbound::cli::load_scene(None, &overrides).unwrap();
    let cost = fricbound::hbm::cost::estimate(&problem);
    assert_eq!(cost.force_blocks, 20_001);
    // At least the two AFT matrices of 32 768 × 20 001 values.
    assert!(cost.aft_bytes >= 2.0 * 32768.0 * 20001.0 * 8.0);
    let Some(available) = fricbound::hbm::cost::available_memory() else {
        eprintln!("no /proc/meminfo: the refusal is skipped by design, nothing to test");
        return;
    };
    assert!(
        cost.bytes() > available as f64,
        "this machine has {available} bytes available, more than the estimate {}",
        cost.bytes()
    );

    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("big");
    let command = format!(
        "ulimit -v 4000000 && exec '{}' run --quiet --out '{}' --set {} --set {}",
        env!("CARGO_BIN_EXE_fricbound"),
        out.display(),
        overrides[0],
        overrides[1]
    );
    let o = Command::new("sh").arg("-c").arg(&command).output().unwrap();
    let stderr = text(&o.stderr);
    assert_eq!(o.status.code(), Some(i32::from(EXIT_ERROR)), "{stderr}");
    assert!(stderr.starts_with("error: "), "{stderr}");
    for field in [
        "refused",
        "harmonics.max",
        "harmonics.samples",
        "model size",
        "available",
    ] {
        assert!(stderr.contains(field), "{field}: {stderr}");
    }
    assert!(!out.exists(), "nothing is created before the refusal");

    // `check` says so too, with the estimate, and does not print 10 001 harmonics.
    let o = fricbound(&["check", "--set", &overrides[0], "--set", &overrides[1]]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let stdout = text(&o.stdout);
    let line = stdout
        .lines()
        .find(|l| l.starts_with("harmonics "))
        .unwrap();
    assert!(line.len() < 200, "{line}");
    assert!(
        line.contains("[0, 1, 2, 3, 4, …, 9996, 9997, 9998, 9999, 10000]")
            && line.contains("10001 harmonics, 20001 blocks"),
        "{line}"
    );
    assert!(stdout.contains("memory per Newton iteration ≈"), "{stdout}");
    assert!(stdout.contains("time per point ≈"), "{stdout}");
    assert!(stdout.contains("`run` refuses this scene"), "{stdout}");
    assert!(stdout.lines().all(|l| l.len() < 400), "{stdout}");
}

/// `check` on the default scene: the cost lines, and a scene that fits.
#[test]
fn check_prints_the_cost_of_a_small_scene() {
    let o = fricbound(&["check"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let stdout = text(&o.stdout);
    assert!(
        stdout.contains("formulation  dense (auto): 18 Newton unknowns"),
        "{stdout}"
    );
    let cost = stdout.lines().find(|l| l.starts_with("cost ")).unwrap();
    assert!(
        cost.contains("MiB") && cost.contains("(estimate: 3.5 factorisations of "),
        "{cost}"
    );
    if fricbound::hbm::cost::available_memory().is_some() {
        assert!(stdout.contains("): fits"), "{stdout}");
    }
}

/// `check` says on which extended sets the error estimate solves the points beyond its step's
/// linear range: under `"auto"` the reduced blade pair at H = 11 flags on H = 23 (a solve of 12
/// iterations at 17.9 run points each is beyond the budget) and does not step on H = 47 (its
/// points flagged); at H = 3 it solves on H = 7 and does not step on H = 15 (a widened point's
/// two steps 1.6 + 12.2 run points); `"solve"` solves on both, and at H = 1 `"auto"` solves on
/// both.
#[test]
fn check_names_the_sets_the_estimate_solves_on() {
    let scene = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("meshes/blade-pair/blade-pair-2d.toml")
        .display()
        .to_string();
    let line = |overrides: &[&str]| {
        let mut args = vec!["check", scene.as_str()];
        for o in overrides {
            args.extend(["--set", o]);
        }
        let o = fricbound(&args);
        assert!(o.status.success(), "{}", text(&o.stderr));
        let stdout = text(&o.stdout);
        stdout
            .lines()
            .find(|l| l.starts_with("  beyond "))
            .unwrap_or_default()
            .to_string()
    };
    let auto = line(&["harmonics.max=11"]);
    assert!(
        auto.contains("flagged on H = 23")
            && auto.contains("not stepped, its points flagged, on H = 47")
            && auto.contains("[auto: "),
        "{auto}"
    );
    // The extended systems' formulation and factorised size are named under it.
    let o = fricbound(&["check", scene.as_str(), "--set", "harmonics.max=3"]);
    let stdout = text(&o.stdout);
    for (set, rows) in [("2H + 1", 420), ("4H + 3", 868)] {
        let named = stdout
            .lines()
            .find(|l| l.starts_with(&format!("  {set}")))
            .unwrap_or_default();
        assert!(
            named.contains(&format!("factorised matrix of {rows} rows")),
            "{stdout}"
        );
    }
    let h3 = line(&["harmonics.max=3"]);
    assert!(
        h3.contains("solved on H = 7") && h3.contains("not stepped, its points flagged, on H = 15"),
        "{h3}"
    );
    let solve = line(&["harmonics.max=11", "accuracy.beyond_linear_range=solve"]);
    assert!(
        solve.contains("solved on H = 23") && solve.contains("solved on H = 47"),
        "{solve}"
    );
    let low = line(&[]);
    assert!(
        low.contains("solved on H = 3") && low.contains("solved on H = 7"),
        "{low}"
    );
}
