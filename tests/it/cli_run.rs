//! `fricbound run` end to end: result files, headers, streaming and failure handling, and the
//! refined resonances and anti-resonances of an FRF run (`peaks.csv`, `peaks` in
//! `solution.json`) against a linear FRF computed here from the scene's matrices.

use crate::support;

use support::{csv, json, run_scene, scene, text};

#[test]
fn run_writes_all_results() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("zoom");
    let o = run_scene(&scene("zoom-2nd.toml"), &out, &[]);
    assert!(
        o.status.success(),
        "stderr: {}",
        String::from_utf8_lossy(&o.stderr)
    );

    let frf = std::fs::read_to_string(out.join("frf.csv")).unwrap();
    let mut lines = frf.lines();
    assert_eq!(
        lines.next().unwrap(),
        "freq_hz,y2_amp,y2_peak,left_state,right_state,newton_iters,y2_trunc_err,y2_sampling_err,\
         estimate_harmonic,estimate_method"
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert!(rows.len() > 20);
    let mut extensions = std::collections::BTreeSet::new();
    let mut methods = std::collections::BTreeMap::new();
    for r in &rows {
        assert_eq!(r.len(), 10);
        // The error estimate: relative, finite, non-negative.
        for e in &r[6..8] {
            let e: f64 = e.parse().unwrap();
            assert!(e.is_finite() && e >= 0.0, "{e}");
        }
        // The extension it comes from at H = 1: 2H + 1 = 3, or 4H + 3 = 7 where widened.
        let top: usize = r[8].parse().unwrap();
        assert!(top == 3 || top == 7, "{top}");
        extensions.insert(top);
        assert!(
            ["step", "solved", "unsized", "converged"].contains(&r[9]),
            "{}",
            r[9]
        );
        // `unsolved` only with `accuracy.beyond_linear_range = "flag"` (below).
        *methods.entry(r[9]).or_insert(0_usize) += 1;
    }
    println!("estimate_harmonic values: {extensions:?}, estimate_method counts: {methods:?}");
    for r in &rows {
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
    let json = json(&out.join("solution.json"));
    assert_eq!(json["status"], "complete");
    // H = 1 is about 10 % off near this resonance (tests/it/error_estimate.rs): solution.json
    // has it, and a run that is not quiet says so on stderr (a quiet one writes nothing there).
    let largest = json["accuracy"]["max_trunc_err"][0].as_f64().unwrap();
    assert!(largest > 0.05, "{largest}");
    // The largest extension any point used is the largest of the CSV column.
    assert_eq!(
        json["accuracy"]["max_estimate_harmonic"].as_u64(),
        extensions.last().map(|&h| h as u64)
    );
    // ... and the counts of solved and unsized rows are the CSV's.
    for (key, label) in [("solved_points", "solved"), ("unsized_points", "unsized")] {
        assert_eq!(
            json["accuracy"][key].as_u64(),
            Some(methods.get(label).copied().unwrap_or(0) as u64),
            "{key}"
        );
    }
    assert!(o.stderr.is_empty(), "{}", text(&o.stderr));
    let loud = support::fricbound(&[
        "run",
        &scene("zoom-2nd.toml"),
        "--out",
        dir.path().join("loud").to_str().unwrap(),
    ]);
    assert!(loud.status.success());
    let stderr = text(&loud.stderr);
    assert!(
        stderr.contains("warning: accuracy: the harmonic truncation error of y2")
            && stderr.contains("harmonics.max > 1 needed"),
        "{stderr}"
    );
    assert_eq!(json["info"]["version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(json["info"]["scene_hash"].as_str().unwrap().len(), 64);
    assert_eq!(json["info"]["blocks"], serde_json::json!(["0", "c1", "s1"]));
    let points = json["points"].as_array().unwrap();
    assert_eq!(points.len(), rows.len());
    assert_eq!(points[0]["coefficients"].as_array().unwrap().len(), 18);
    assert!(json["elapsed_s"].as_f64().unwrap() > 0.0);
    // The refined resonances and anti-resonances of y2, in peaks.csv and solution.json alike.
    let (header, peaks) = csv(&out.join("peaks.csv"));
    assert_eq!(
        header,
        "dof,kind,freq_hz,amplitude,refined,at_branch_end,path_index,path_freq_hz,\
         path_amplitude,left_state,right_state"
    );
    assert!(
        peaks.iter().any(|r| r[1] == "resonance"),
        "the 2nd resonance is in 150-175 Hz: {peaks:?}"
    );
    assert_eq!(json["peaks"].as_array().unwrap().len(), peaks.len());
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
    let o = run_scene(
        &scene("zoom-2nd.toml"),
        &out,
        &["harmonics.max=3", "analysis.freq_end_hz=160"],
    );
    assert!(
        o.status.success(),
        "stderr: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let json = json(&out.join("solution.json"));
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
    // Two Newton iterations per step and a large minimum step: stuck points (a linear
    // problem) converge in two (one step, and the residual after it checked), so the path
    // over the full range, stuck at its start, must stall at the first stick-slip transition
    // (159.8 Hz), after some converged stuck points.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("stall");
    let o = run_scene(
        &scene("full-range.toml"),
        &out,
        &[
            "analysis.max_iterations=2",
            "analysis.min_step=0.05",
            "analysis.initial_step=0.1",
        ],
    );
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "expected a stall");
    assert!(
        stderr.contains("stalled") && !stderr.contains("panicked"),
        "{stderr}"
    );
    let frf = std::fs::read_to_string(out.join("frf.csv")).unwrap();
    assert!(frf.lines().count() > 2, "finished points are kept");
    let json = json(&out.join("solution.json"));
    assert!(json["status"].as_str().unwrap().starts_with("failed:"));
    assert_eq!(
        json["points"].as_array().unwrap().len(),
        frf.lines().count() - 1
    );
}

/// Two masses: x1 (1 kg) on a 10⁴ N/m spring to the ground, x2 (0.1 kg) hung from it by
/// 10³ N/m, driven by 1 N cos ωt on x1. One grounded contact on x1 with a zero normal
/// direction: its normal load is the constant kn·1e-4 = 10 N. With μ = 0 it transmits nothing
/// (the structure alone); with μ = 100 (slip force 1000 N, far above kt times any amplitude
/// reached) it stays stuck and adds kt = 10⁵ N/m to x1. Either way the response is linear.
const TWO_DOF: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/two-dof-grounded.toml"
));

/// First-harmonic amplitudes |X1|, |X2| of (K − ω²M + iωC) X = (1, 0) for the two-DOF scene
/// with `k11` on x1's diagonal, at `f` Hz (Cramer's rule on the 2 × 2 complex system).
fn linear_amplitudes(k11: f64, f: f64) -> [f64; 2] {
    let w = 2.0 * std::f64::consts::PI * f;
    let (a, b, d) = (
        (k11 - w * w, 2.0 * w),
        (-1.0e3, 0.0),
        (1.0e3 - 0.1 * w * w, 0.5 * w),
    );
    let det = (
        a.0 * d.0 - a.1 * d.1 - (b.0 * b.0 - b.1 * b.1),
        a.0 * d.1 + a.1 * d.0 - 2.0 * b.0 * b.1,
    );
    let det = det.0.hypot(det.1);
    [d.0.hypot(d.1) / det, b.0.hypot(b.1) / det]
}

/// The extremum of `sign` × |X_output| of the linear FRF between `lo` and `hi` (Hz), by
/// golden-section search: (Hz, m).
fn linear_extremum(k11: f64, output: usize, sign: f64, mut lo: f64, mut hi: f64) -> (f64, f64) {
    let g = |f: f64| sign * linear_amplitudes(k11, f)[output];
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    while hi - lo > 1e-10 {
        let c = hi - ratio * (hi - lo);
        let d = lo + ratio * (hi - lo);
        if g(c) >= g(d) {
            hi = d;
        } else {
            lo = c;
        }
    }
    let f = 0.5 * (lo + hi);
    (f, linear_amplitudes(k11, f)[output])
}

/// Runs the two-DOF scene with `overrides` into `out`; returns the exit code.
fn run_two_dof(out: &std::path::Path, overrides: &[&str]) -> Option<i32> {
    let scene_file = out.with_extension("toml");
    std::fs::write(&scene_file, TWO_DOF).unwrap();
    let o = run_scene(scene_file.to_str().unwrap(), out, overrides);
    assert!(!text(&o.stderr).contains("panicked"), "{}", text(&o.stderr));
    o.status.code()
}

/// Checks `peaks.csv` and `solution.json`'s `peaks` of a complete two-DOF run against the
/// linear FRF with `k11` on x1's diagonal: the kinds per output in path order, each refined
/// extremum equal to the linear one found between its path neighbours (amplitude within
/// 10⁻⁶, frequency within 10⁻³ Hz), the raw path value on the right side of it, and the JSON
/// holding the CSV's values. Returns the CSV rows.
fn check_two_dof_peaks(
    out: &std::path::Path,
    k11: f64,
    expected: &[(&str, &str)],
) -> Vec<Vec<String>> {
    let (header, rows) = csv(&out.join("peaks.csv"));
    assert_eq!(
        header,
        "dof,kind,freq_hz,amplitude,refined,at_branch_end,path_index,path_freq_hz,\
         path_amplitude,ground_state"
    );
    let kinds: Vec<(&str, &str)> = rows
        .iter()
        .map(|r| (r[0].as_str(), r[1].as_str()))
        .collect();
    assert_eq!(kinds, expected, "{rows:?}");
    let (_, frf) = csv(&out.join("frf.csv"));
    let sol = json(&out.join("solution.json"));
    let records = sol["peaks"].as_array().unwrap();
    assert_eq!(records.len(), rows.len());
    for (r, j) in rows.iter().zip(records) {
        let num = |k: usize| -> f64 { r[k].parse().unwrap() };
        let (output, sign) = (
            if r[0] == "x1" { 0 } else { 1 },
            if r[1] == "resonance" { 1.0 } else { -1.0 },
        );
        let (freq, amp, path_freq, path_amp) = (num(2), num(3), num(7), num(8));
        assert_eq!(r[4], "true", "refined: {r:?}");
        assert_eq!(r[5], "false", "at_branch_end: {r:?}");
        let i: usize = r[6].parse().unwrap();
        let row_freq = |k: usize| -> f64 { frf[k][0].parse().unwrap() };
        assert_eq!(
            row_freq(i),
            path_freq,
            "path_index points at the path point"
        );
        let (f, a) = linear_extremum(k11, output, sign, row_freq(i - 1), row_freq(i + 1));
        let rel = (amp - a).abs() / a;
        assert!(
            rel < 1e-6 && (freq - f).abs() < 1e-3,
            "{r:?}: linear {a:.9e} m at {f:.6} Hz (rel {rel:.1e})"
        );
        assert!(sign * (amp - path_amp) >= 0.0, "{r:?}");
        // The same values in solution.json (the CSV prints ten significant digits).
        assert_eq!(j["dof"], r[0].as_str());
        assert_eq!(j["kind"], r[1].as_str());
        assert_eq!(j["refined"], true);
        assert_eq!(j["at_branch_end"], false);
        assert_eq!(j["path_index"], i);
        assert_eq!(j["states"], serde_json::json!([r[9]]));
        for (key, v) in [
            ("freq_hz", freq),
            ("amplitude", amp),
            ("path_amplitude", path_amp),
        ] {
            let x = j[key].as_f64().unwrap();
            assert!((x - v).abs() <= 1e-9 * v.abs(), "{key}: {x} vs {v}");
        }
    }
    rows
}

/// The refined resonances and anti-resonances of an FRF run are those of the linear FRF when
/// the contact makes the system linear: free (μ = 0, the structure's own K) and stuck (μ = 100,
/// K + kt on x1). A user sees in `peaks.csv` every resonance of each output, x1's
/// anti-resonance at √(k₂/m₂)/2π ≈ 15.9 Hz and the minimum of x2 between its resonances, to
/// 10⁻⁶ of the exact values, however coarse the plotted path. A run stopped by its point budget still writes the extrema it passed.
#[test]
fn frf_peaks_are_the_linear_frf_extrema() {
    let dir = tempfile::tempdir().unwrap();
    let free = dir.path().join("free");
    assert_eq!(run_two_dof(&free, &[]), Some(0));
    let all = [
        ("x1", "resonance"),
        ("x1", "anti-resonance"),
        ("x1", "resonance"),
        ("x2", "resonance"),
        ("x2", "anti-resonance"),
        ("x2", "resonance"),
    ];
    let rows = check_two_dof_peaks(&free, 1.1e4, &all);
    assert_eq!(json(&free.join("solution.json"))["status"], "complete");

    // Stuck: x1's mode moves up to about 53 Hz, beyond the range solved here, and x1 barely
    // moves at x2's mode. (The point budget is raised: the continuation crawls through this
    // small-amplitude stretch.)
    let stuck = dir.path().join("stuck");
    let stuck_run = [
        "contacts.0.mu=100",
        "analysis.freq_end_hz=30",
        "analysis.max_points=20000",
    ];
    assert_eq!(run_two_dof(&stuck, &stuck_run), Some(0));
    let stuck_rows = check_two_dof_peaks(
        &stuck,
        1.1e4 + 1.0e5,
        &[
            ("x1", "resonance"),
            ("x1", "anti-resonance"),
            ("x2", "resonance"),
        ],
    );
    assert!(stuck_rows.iter().all(|r| r[9] == "stuck"), "{stuck_rows:?}");

    // The free run stopped two points after x1's anti-resonance: incomplete (exit 3), and its
    // peaks.csv holds the extrema passed, with the values of the complete run (the same path).
    let budget = rows[1][6].parse::<usize>().unwrap() + 2;
    let part = dir.path().join("part");
    let max_points = format!("analysis.max_points={budget}");
    assert_eq!(run_two_dof(&part, &[&max_points]), Some(3));
    let sol = json(&part.join("solution.json"));
    assert!(sol["status"].as_str().unwrap().starts_with("incomplete: "));
    let (_, part_rows) = csv(&part.join("peaks.csv"));
    // Those interior to the points computed (indices 0 .. budget − 1): x1's first resonance
    // and anti-resonance, and x2's first resonance.
    let passed: Vec<Vec<String>> = rows
        .iter()
        .filter(|r| r[6].parse::<usize>().unwrap() + 1 < budget)
        .cloned()
        .collect();
    assert_eq!(passed.len(), 3, "{rows:?}");
    assert_eq!(part_rows, passed);
    assert_eq!(sol["peaks"].as_array().unwrap().len(), 3);
}

/// The rows of a CSV file, each split into its cells.
type CsvRows = Vec<Vec<String>>;

/// The rows of the `frf.csv` of two runs of one scene (written into `a` and `b`), whose headers
/// and row counts agree, with the index of a column by its name.
fn paired_frf_rows(
    a: &std::path::Path,
    b: &std::path::Path,
) -> (impl Fn(&str) -> usize, CsvRows, CsvRows) {
    let (header, rows_a) = csv(&a.join("frf.csv"));
    let (header_b, rows_b) = csv(&b.join("frf.csv"));
    assert_eq!(header, header_b);
    assert_eq!(rows_a.len(), rows_b.len());
    let column = move |name: &str| header.split(',').position(|c| c == name).unwrap();
    (column, rows_a, rows_b)
}

/// `accuracy.beyond_linear_range = "flag"`: the points whose estimate's step leaves its linear
/// range are flagged `unsolved` instead of solved on the extended set, and every other cell is
/// the default run's: the same path, the same steps and sampling estimates. `solution.json`
/// counts them, and a run that is not quiet names their band and the field to change.
#[test]
fn flagging_beyond_the_linear_range_skips_only_the_solves() {
    let dir = tempfile::tempdir().unwrap();
    let solve = dir.path().join("solve");
    let flag = dir.path().join("flag");
    let zoom = scene("zoom-2nd.toml");
    let h3 = "harmonics.max=3";
    assert!(run_scene(&zoom, &solve, &[h3]).status.success());
    let flagged = support::fricbound(&[
        "run",
        &zoom,
        "--set",
        h3,
        "--set",
        "accuracy.beyond_linear_range=flag",
        "--out",
        flag.to_str().unwrap(),
    ]);
    assert!(flagged.status.success(), "{}", text(&flagged.stderr));
    let (column, by_solve, by_flag) = paired_frf_rows(&solve, &flag);
    let (trunc, sampling, method) = (
        column("y2_trunc_err"),
        column("y2_sampling_err"),
        column("estimate_method"),
    );
    let mut unsolved = 0_u64;
    for (s, f) in by_solve.iter().zip(&by_flag) {
        // The path and the points are the same.
        assert_eq!(s[..trunc], f[..trunc]);
        assert_eq!(s[sampling], f[sampling]);
        match s[method].as_str() {
            "step" | "converged" => assert_eq!(s, f),
            "solved" | "unsized" => {
                assert_eq!(f[method], "unsolved", "{f:?}");
                unsolved += 1;
            }
            other => panic!("unexpected estimate_method {other}"),
        }
    }
    // Around the resonance, where the contacts slip, the steps leave their linear range at
    // H = 3 (the contact law's transitions move between samples with the extra harmonics).
    assert!(unsolved >= 10, "{unsolved} of {}", by_flag.len());
    let json = json(&flag.join("solution.json"));
    assert_eq!(json["accuracy"]["unsolved_points"].as_u64(), Some(unsolved));
    assert_eq!(json["accuracy"]["solved_points"].as_u64(), Some(0));
    let stderr = text(&flagged.stderr);
    assert!(
        stderr.contains("was not sized between")
            && stderr.contains("accuracy.beyond_linear_range = \"flag\""),
        "{stderr}"
    );
}

/// Under `"auto"` the wider set (4H + 3) is not stepped on where a widened point's two steps
/// cost more than `SolveBudget::STEP_RUN_POINTS` run points: on the paper case at H = 15 the
/// wider set is H = 63 (1.9 + 14.5 run points), and the points sent there (a contact stuck
/// all period) are flagged `unsolved` with their estimate on H = 31, where `"solve"` steps on
/// H = 63; every other cell is the same in both runs. `check` says so.
#[test]
fn a_wider_set_beyond_the_step_budget_is_not_stepped_on() {
    let dir = tempfile::tempdir().unwrap();
    let auto = dir.path().join("auto");
    let solve = dir.path().join("solve");
    let zoom = scene("zoom-2nd.toml");
    let h15 = "harmonics.max=15";
    let checked = support::fricbound(&["check", &zoom, "--set", h15]);
    assert!(checked.status.success(), "{}", text(&checked.stderr));
    let summary = text(&checked.stdout);
    assert!(
        summary.contains("solved on H = 31")
            && summary.contains("not stepped, its points flagged, on H = 63"),
        "{summary}"
    );
    assert!(run_scene(&zoom, &auto, &[h15]).status.success());
    let solved = run_scene(&zoom, &solve, &[h15, "accuracy.beyond_linear_range=solve"]);
    assert!(solved.status.success(), "{}", text(&solved.stderr));
    let (column, by_auto, by_solve) = paired_frf_rows(&auto, &solve);
    let (trunc, harmonic, method) = (
        column("y2_trunc_err"),
        column("estimate_harmonic"),
        column("estimate_method"),
    );
    let mut flagged = 0_u64;
    for (a, s) in by_auto.iter().zip(&by_solve) {
        assert_eq!(a[..trunc], s[..trunc], "the same path");
        if s[harmonic] == "63" {
            assert_eq!(a[harmonic], "31", "{a:?}");
            assert_eq!(a[method], "unsolved", "{a:?}");
            flagged += 1;
        } else {
            assert_eq!(a, s);
            assert_ne!(a[method], "unsolved", "{a:?}");
        }
    }
    assert!(flagged >= 1, "no point of {} widened", by_auto.len());
    let json = json(&auto.join("solution.json"));
    assert_eq!(json["accuracy"]["unsolved_points"].as_u64(), Some(flagged));
}

/// The pages written for users: README.md and the guide's chapters (`docs/src/*.md`; not the
/// contributors' pages in `docs/src/dev/`), of the pages the link check reads.
fn user_pages() -> Vec<std::path::PathBuf> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    support::doc_links::documentation_files(root)
        .into_iter()
        .filter(|p| *p == root.join("README.md") || p.parent() == Some(&root.join("docs/src")))
        .collect()
}

/// The scene files a user meets: every `.toml` scene shipped under `meshes/` and `tests/data/`,
/// and every complete scene (one with a `[model]` or `[mesh]` table) in a `toml` block of
/// README.md or the guide (`docs/src`), written to a temporary file.
fn shipped_and_shown_scenes(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut scenes = Vec::new();
    let mut folders = vec![root.join("meshes"), root.join("tests/data")];
    while let Some(folder) = folders.pop() {
        for entry in std::fs::read_dir(&folder).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                folders.push(path);
            } else if path.extension().is_some_and(|e| e == "toml") {
                scenes.push(path);
            }
        }
    }
    for page in user_pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        for (i, block) in text.split("```toml\n").skip(1).enumerate() {
            let block = block.split("```").next().unwrap();
            if block.contains("[model]") || block.contains("[mesh]") {
                let stem = page.file_stem().unwrap().to_string_lossy();
                let file = dir.join(format!("{stem}-{i}.toml"));
                std::fs::write(&file, block).unwrap();
                scenes.push(file);
            }
        }
    }
    scenes.sort();
    scenes
}

/// Every scene a user meets passes `fricbound check` (exit 0): the shipped scenes and the
/// complete scenes shown in README.md and the guide.
#[test]
fn every_shipped_or_shown_scene_passes_check() {
    let dir = tempfile::tempdir().unwrap();
    let scenes = shipped_and_shown_scenes(dir.path());
    assert!(
        scenes.iter().any(|s| s.starts_with(dir.path())),
        "no complete scene found in the guide"
    );
    assert!(scenes.len() > 20, "{scenes:?}");
    let failed: Vec<String> = scenes
        .iter()
        .filter_map(|scene| {
            let o = support::fricbound(&["check", &scene.display().to_string()]);
            (!o.status.success()).then(|| format!("{}: {}", scene.display(), text(&o.stderr)))
        })
        .collect();
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

/// Commands of README.md and the guide that this test does not run, with the reason.
const COMMANDS_NOT_RUN: &[(&str, &str)] = &[
    (
        "paper --quick",
        "tests/it/paper.rs runs it and checks what it writes",
    ),
    (
        "paper",
        "the full study takes minutes; tests/it/paper.rs runs `paper --quick`",
    ),
    ("bench scaling", "the scaling study takes minutes"),
    (
        "bench contacts",
        "its curves take up to minutes each; tests/it/schur_lowrank.rs runs it on one contact refinement",
    ),
];

/// A shell command line split into words ('…' and "…" quote, no other shell syntax).
fn shell_words(line: &str) -> Vec<String> {
    let (mut words, mut word, mut quote, mut started) = (Vec::new(), String::new(), None, false);
    for c in line.chars() {
        match (quote, c) {
            (Some(q), c) if c == q => quote = None,
            (Some(_), c) => word.push(c),
            (None, '\'' | '"') => {
                quote = Some(c);
                started = true;
            }
            (None, c) if c.is_whitespace() => {
                if started || !word.is_empty() {
                    words.push(std::mem::take(&mut word));
                }
                started = false;
            }
            (None, c) => word.push(c),
        }
    }
    if started || !word.is_empty() {
        words.push(word);
    }
    words
}

/// The fricbound commands in the `sh` blocks of README.md and the guide (other commands, such
/// as `cargo test`, are not fricbound's): the arguments after
/// `fricbound` or `cargo run --release --`, and the exit code the text gives (3 where its
/// comment says "exits 3", else 0). Lines with placeholders (`scene.toml`, `SCENE`, `DIR`,
/// `[--…]`, `F=V`) are templates, not commands.
fn documented_commands() -> Vec<(String, Vec<String>, i32)> {
    let mut commands = Vec::new();
    for page in user_pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        for block in text.split("```sh\n").skip(1) {
            for line in block.split("```").next().unwrap().lines() {
                let (command, comment) = line.split_once(" #").unwrap_or((line, ""));
                let Some(args) = ["fricbound ", "cargo run --release -- "]
                    .iter()
                    .find_map(|prefix| command.trim().strip_prefix(prefix))
                else {
                    continue;
                };
                let template = ["scene.toml", "SCENE", "DIR", "[--", "F=V"];
                if template.iter().any(|t| args.contains(t)) {
                    continue;
                }
                let code = if comment.contains("exits 3") { 3 } else { 0 };
                commands.push((args.to_string(), shell_words(args), code));
            }
        }
    }
    commands
}

/// Every command of README.md and the guide's `sh` blocks exits as the text says (0, or 3
/// where it says why), run from a fresh folder that sees the repository's `meshes/`; the few
/// left out are named in [`COMMANDS_NOT_RUN`] with the reason.
#[test]
fn every_documented_command_exits_as_documented() {
    let dir = tempfile::tempdir().unwrap();
    let meshes = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("meshes");
    std::os::unix::fs::symlink(meshes, dir.path().join("meshes")).unwrap();
    let commands = documented_commands();
    assert!(commands.len() > 15, "{commands:?}");
    let mut failed = Vec::new();
    let mut ran = std::collections::BTreeSet::new();
    for (line, args, code) in commands {
        let skipped = COMMANDS_NOT_RUN
            .iter()
            .any(|(prefix, _)| line == *prefix || line.starts_with(&format!("{prefix} ")));
        if skipped || !ran.insert(line.clone()) {
            continue;
        }
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = support::fricbound_in(dir.path(), &args);
        if o.status.code() != Some(code) {
            failed.push(format!(
                "`{line}` exited {:?}, the text says {code}: {}",
                o.status.code(),
                text(&o.stderr).lines().last().unwrap_or("")
            ));
        }
    }
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}
