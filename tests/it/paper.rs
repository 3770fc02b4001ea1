//! `fricbound paper`: the figure scenes of the paper's §4 study are valid at every sweep point,
//! and `fricbound paper --quick` writes every figure's data and plots and a summary whose
//! numbers are the ones in the result files.

use std::path::Path;
use std::process::Command;

use fricbound::cli::paper::FIGURES;
use fricbound::scene;
use fricbound::study::sweep;

/// Every figure scene, as shipped in `meshes/paper-wedge/` and as built into the binary, is
/// valid with the study's overrides (envelope, and `--quick`) and without `--quick`, at every one of its sweep points;
/// Figs. 13a, 15a and 15b ask for the envelope in the full study.
#[test]
fn every_figure_scene_is_valid_at_every_sweep_point() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("meshes/paper-wedge");
    for job in &FIGURES {
        let on_disk = std::fs::read_to_string(dir.join(job.scene_file)).unwrap();
        assert_eq!(
            on_disk, job.text,
            "{} differs from the built-in text",
            job.id
        );
        for overrides in [job.overrides(false), job.overrides(true)] {
            let s = scene::parse(job.text, job.scene_file, &overrides)
                .unwrap_or_else(|e| panic!("{}: {e}", job.id));
            let problem = s
                .validate(job.scene_file)
                .unwrap_or_else(|e| panic!("{}: {e}", job.id));
            assert_eq!(problem.model.n_dofs(), 6, "{}", job.id);
            if let Some(spec) = &s.sweep {
                for (series, value) in sweep::sweep_points(spec) {
                    sweep::problem_at(job.text, job.scene_file, &overrides, spec, series, value)
                        .unwrap_or_else(|e| panic!("{}: {e}", job.id));
                }
            }
        }
    }
    for id in ["fig13-3rd", "fig15a", "fig15b"] {
        let job = FIGURES.iter().find(|j| j.id == id).unwrap();
        assert!(job.computes_envelope(false), "{id}");
        let s = scene::parse(job.text, job.scene_file, &job.overrides(false)).unwrap();
        assert!(
            s.limits.as_ref().is_some_and(|l| l.envelope.is_some()),
            "{id}: no envelope"
        );
    }
    // One scene per figure of §4, Figs. 12-19.
    let ids: Vec<&str> = FIGURES.iter().map(|j| j.id).collect();
    for fig in [
        "12", "13", "15a", "15b", "16a", "16b", "16c", "17", "18a", "18b", "19a", "19b",
    ] {
        assert!(
            ids.iter()
                .any(|id| id.starts_with(&format!("fig{fig}"))
                    || (fig == "16a" && *id == "fig16a-d")),
            "no scene for Fig. {fig}"
        );
    }
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Peak amplitude of `curve` in a `peaks.csv`.
fn peak(peaks_csv: &str, curve: &str) -> f64 {
    let mut lines = peaks_csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = header.iter().position(|h| *h == "peak_amp").unwrap();
    lines
        .map(|l| l.split(',').collect::<Vec<_>>())
        .find(|f| f[0] == curve)
        .unwrap_or_else(|| panic!("no curve {curve}"))[col]
        .parse()
        .unwrap()
}

#[test]
fn paper_quick_writes_every_figure_and_a_summary_of_computed_numbers() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("paper");
    let started = std::time::Instant::now();
    let o = Command::new(env!("CARGO_BIN_EXE_fricbound"))
        .args([
            "paper",
            "--quick",
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "stderr: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    // Its time is reported, not asserted (speed is measured in benchmarks and tables).
    eprintln!("paper --quick took {:?}", started.elapsed());

    // Every figure's data and plots (PNG and SVG).
    let expect = [
        (
            "fig12",
            vec![
                "frf.csv",
                "linear_open.csv",
                "linear_stuck.csv",
                "frf_y2.png",
            ],
        ),
        (
            "fig13-3rd",
            vec![
                "limits.csv",
                "limits.json",
                "peaks.csv",
                "limits_y2.png",
                "limits_y2.svg",
            ],
        ),
        ("fig13-2nd", vec!["limits.csv", "limits_y2.png"]),
        (
            "fig15a",
            vec![
                "sweep.csv",
                "variability.csv",
                "bands_y2.png",
                "F0_130/limits_y2.png",
            ],
        ),
        ("fig15b", vec!["limits.csv", "peaks.csv", "limits_y2.png"]),
        (
            "fig16a-d",
            vec![
                "sweep.csv",
                "sweep.json",
                "optimal_y2.png",
                "resonance_y2.svg",
            ],
        ),
        ("fig16b", vec!["sweep.csv", "optimal_y2.png"]),
        (
            "fig16c",
            vec![
                "hysteresis_left.png",
                "hysteresis_right.svg",
                "hysteresis_m+1_peak.csv",
                "hysteresis_left+0.5_peak.csv",
            ],
        ),
        ("fig17", vec!["variability.csv", "F0_250/limits_y2.png"]),
        ("fig18a", vec!["bands_y2.png", "beta_90/limits.csv"]),
        ("fig18b", vec!["sweep.csv", "optimal_y2.png"]),
        ("fig19a", vec!["bands_y2.png", "beta_60/limits.csv"]),
        ("fig19b", vec!["sweep.csv", "optimal_y2.png"]),
    ];
    for (fig, files) in &expect {
        for f in files {
            let p = out.join(fig).join(f);
            assert!(
                p.metadata().map(|m| m.len() > 0).unwrap_or(false),
                "missing {}",
                p.display()
            );
        }
    }

    // The summary holds every key item, the paper's statement, and a verdict.
    let summary = read(&out.join("summary.md"));
    for item in [
        "ratio of the limit peak amplitudes",
        "resonance-frequency change",
        "pre-load where the variability",
        "optimum pre-load",
        "β ranking of the variability (β ≥ 90°)",
        "β ranking of the variability (β ≤ 90°)",
        "do the limits bound the other solutions?",
    ] {
        let line = summary
            .lines()
            .find(|l| l.starts_with(&format!("| {item}")))
            .unwrap_or_else(|| panic!("no row `{item}` in summary.md"));
        let cells: Vec<&str> = line.split(" | ").collect();
        assert_eq!(cells.len(), 4, "{line}");
        assert!(
            ["yes |", "partly |", "no |"].contains(&cells[3]),
            "no computed verdict: {line}"
        );
        assert!(!cells[2].starts_with('—'), "not computed: {line}");
    }
    for statement in ["up to 3×", "up to 3 %", "near 60 N", "45-80 N", "β = 90°"] {
        assert!(summary.contains(statement), "paper statement `{statement}`");
    }
    assert!(summary.contains("Do the limits bound"));
    // The stability section: both limit curves, without and with damper damping.
    assert!(summary.contains("## Stability of the limit curves"));
    let stability: serde_json::Value =
        serde_json::from_str(&read(&out.join("stability.json"))).unwrap();
    let curves = stability["curves"].as_array().unwrap();
    assert_eq!(curves.len(), 4, "{stability}");
    assert!(stability["failed"].as_array().unwrap().is_empty());
    for c in curves {
        let unstable = c["unstable_points"].as_u64().unwrap();
        assert!(unstable <= c["points"].as_u64().unwrap());
        assert_eq!(
            unstable == 0,
            c["unstable_hz"].as_array().unwrap().is_empty()
        );
        // Both limit curves stick-slip on one side over part of the range: the monodromy
        // gives those points' verdicts (hill+monodromy), Hill the stuck ones.
        let by_monodromy = c["monodromy_points"].as_u64().unwrap();
        assert!(
            by_monodromy > 0 && by_monodromy < c["points"].as_u64().unwrap(),
            "{c}"
        );
        assert!(c["unreliable_points"].as_u64().unwrap() <= by_monodromy);
    }

    // The numbers are the runs' own: the ratio of the limit peaks of Fig. 13 (3rd resonance)
    // in the summary is the one of its peaks.csv, and the study's largest ratio is at least it.
    let peaks = read(&out.join("fig13-3rd/peaks.csv"));
    let (a, b) = (peak(&peaks, "m+1"), peak(&peaks, "m-1"));
    let ratio = a.max(b) / a.min(b);
    assert!(ratio > 1.2, "3rd resonance limit peaks {a:e}, {b:e}");
    let section = summary
        .split("### fig13-3rd")
        .nth(1)
        .unwrap()
        .split("### ")
        .next()
        .unwrap();
    assert!(
        section.contains(&format!("| {ratio:.4} |")),
        "ratio {ratio:.4} not in:\n{section}"
    );
    let json: serde_json::Value = serde_json::from_str(&read(&out.join("summary.json"))).unwrap();
    let largest = json["max_peak_ratio"]["value"].as_f64().unwrap();
    assert!(largest >= ratio - 1e-12, "{largest} < {ratio}");
    // Every limit analysis of the study has its bound check reported.
    let analyses = json["analyses"].as_array().unwrap();
    assert!(analyses.len() >= 15, "{} analyses", analyses.len());
    let with_scan = analyses.iter().filter(|a| !a["bound"].is_null()).count();
    let rows = summary
        .split("## Do the limits bound")
        .nth(1)
        .unwrap()
        .split("## ")
        .next()
        .unwrap()
        .lines()
        .filter(|l| l.starts_with("| fig") && !l.starts_with("| figure"))
        .count();
    assert_eq!(rows, with_scan);
    assert!(with_scan >= 15, "{with_scan} bound checks");

    // The envelope over all initial states next to the two-point limits (Figs. 13a, 15b and,
    // unless --quick skips it, 15a): its columns in the figure's limits.csv, a row per analysis
    // in the envelope section whose numbers are the ones of limits.json, and its excess in the
    // key-number row on bounds.
    let with_envelope: Vec<&serde_json::Value> = analyses
        .iter()
        .filter(|a| !a["envelope"].is_null())
        .collect();
    let skipped: Vec<&str> = json["envelope_skipped"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    for id in ["fig13-3rd", "fig15b"] {
        assert!(
            with_envelope.iter().any(|a| a["figure"] == id),
            "no envelope for {id}"
        );
        assert!(!skipped.contains(&id), "{id} skipped");
        let header = read(&out.join(id).join("limits.csv"));
        let header = header.lines().next().unwrap();
        assert!(
            header.contains("y2_envelope_min_amp") && header.contains("y2_envelope_max_amp"),
            "{id}: {header}"
        );
    }
    let fig15a = with_envelope
        .iter()
        .filter(|a| a["figure"] == "fig15a")
        .count();
    assert!(
        fig15a == 3 || (fig15a == 0 && skipped == ["fig15a"]),
        "fig15a: {fig15a} envelopes, skipped {skipped:?}"
    );
    let section = summary
        .split("## The envelope over all initial states")
        .nth(1)
        .expect("no envelope section")
        .split("\n## ")
        .next()
        .unwrap();
    let rows: Vec<&str> = section
        .lines()
        .filter(|l| l.starts_with("| fig") && !l.starts_with("| figure"))
        .collect();
    assert_eq!(rows.len(), with_envelope.len(), "{section}");
    if !skipped.is_empty() {
        assert!(
            section.contains("Not computed in this run:** fig15a"),
            "{section}"
        );
    }
    // Fig. 13a's row: the largest excess above the upper limit is limits.json's, and where.
    let limits: serde_json::Value =
        serde_json::from_str(&read(&out.join("fig13-3rd/limits.json"))).unwrap();
    let check = &limits["envelope"]["check"];
    let above = 100.0 * check["max_excess_above"].as_f64().unwrap();
    let row = rows
        .iter()
        .find(|l| l.starts_with("| fig13-3rd |"))
        .unwrap();
    assert!(
        row.contains(&format!("| {above:.3} %")),
        "{above:.3} % not in {row}"
    );
    let fig13 = with_envelope
        .iter()
        .find(|a| a["figure"] == "fig13-3rd")
        .unwrap();
    assert_eq!(fig13["envelope"]["above_pct"].as_f64().unwrap(), above);
    if above > 1e-4 {
        let f = check["above_at"][0].as_f64().unwrap();
        assert!(row.contains(&format!("at {f:.3} Hz (m_left = ")), "{row}");
    }
    // Every envelope found a state at every grid frequency, over the whole grid.
    for a in &with_envelope {
        assert_eq!(a["envelope"]["unsolved"].as_u64(), Some(0), "{a}");
        assert!(a["envelope"]["compared"].as_u64().unwrap() >= 41, "{a}");
    }
    let bound_row = summary
        .lines()
        .find(|l| l.starts_with("| do the limits bound the other solutions?"))
        .unwrap();
    assert!(
        bound_row.contains("envelope over all m per side: "),
        "{bound_row}"
    );
}
