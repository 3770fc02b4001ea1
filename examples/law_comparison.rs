//! The FRF runs of benches/README.md's "Event-resolved against sampled contact law" table: each
//! scene on the event-resolved law and on the sampled law, with the present continuation, and
//! per run its status, points, Newton iterations, step cuts, turning points, jumps and wall time
//! (the error estimate off, so that the times are the path's alone).
//!
//! Usage: `cargo run --release --example law_comparison -- [all] [FILTER]`. Without `all` the
//! runs that take minutes (the unreduced FE model, the 3D blade pair) are left out; FILTER keeps
//! the cases whose name contains it.

mod common;

use std::path::Path;

use fricbound::analysis::frf::{self, Silent};
use fricbound::model::Problem;
use fricbound::report::files::status_text;
use fricbound::scene;

/// Where a case's scene comes from.
enum Source {
    /// The built-in paper scene.
    Paper,
    /// The generated 2D blade pair with 2 contact pairs per side (`examples/common`).
    SmallBladePair,
    /// A scene file of the repository.
    File(&'static str),
}

/// One row pair of the table.
struct Case {
    name: &'static str,
    source: Source,
    overrides: &'static [&'static str],
    /// The fields that set the contact law, given `=LAW` per law.
    law_fields: &'static [&'static str],
    /// The event-resolved and the sampled law's names.
    laws: [&'static str; 2],
    /// Whether the case takes minutes (run only with `all`).
    long: bool,
}

const PAPER_CONTACTS: &[&str] = &["contacts.0.law", "contacts.1.law"];
const PATCHES: &[&str] = &["contact_patches.0.law", "contact_patches.1.law"];
const LAWS_1D: [&str; 2] = ["jenkins-1d", "jenkins-1d-sampled"];
const LAWS_2D: [&str; 2] = ["jenkins-2d", "jenkins-2d-sampled"];

const CASES: &[Case] = &[
    Case {
        name: "paper, full range, F0 = 1 N",
        source: Source::Paper,
        overrides: &["static_loads.0.value=-1"],
        law_fields: PAPER_CONTACTS,
        laws: LAWS_1D,
        long: false,
    },
    Case {
        name: "paper, F0 = 5 N",
        source: Source::Paper,
        overrides: &["static_loads.0.value=-5"],
        law_fields: PAPER_CONTACTS,
        laws: LAWS_1D,
        long: false,
    },
    Case {
        name: "paper, F0 = 10 N",
        source: Source::Paper,
        overrides: &["static_loads.0.value=-10"],
        law_fields: PAPER_CONTACTS,
        laws: LAWS_1D,
        long: false,
    },
    Case {
        name: "paper, F0 = 120 N",
        source: Source::Paper,
        overrides: &[],
        law_fields: PAPER_CONTACTS,
        laws: LAWS_1D,
        long: false,
    },
    Case {
        name: "2-pair 2D blade pair, 700-1000 Hz",
        source: Source::SmallBladePair,
        overrides: &[],
        law_fields: PATCHES,
        laws: LAWS_1D,
        long: false,
    },
    Case {
        name: "7-pair 2D blade pair, 700-1100 Hz",
        source: Source::File("meshes/blade-pair/blade-pair-2d.toml"),
        overrides: &[],
        law_fields: PATCHES,
        laws: LAWS_1D,
        long: false,
    },
    Case {
        name: "undamped unreduced 2D FE model (5 002 DOFs, 0.1 mm gaps)",
        source: Source::File("meshes/blade-pair/blade-pair-2d.toml"),
        overrides: &[
            "reduction=",
            "contact_patches.0.gap=1e-4",
            "contact_patches.1.gap=1e-4",
        ],
        law_fields: PATCHES,
        laws: LAWS_1D,
        long: true,
    },
    Case {
        name: "3D blade pair, 840-900 Hz",
        source: Source::File("meshes/blade-pair/blade-pair-3d.toml"),
        overrides: &["analysis.freq_start_hz=840", "analysis.freq_end_hz=900"],
        law_fields: PATCHES,
        laws: LAWS_2D,
        long: true,
    },
];

/// The case's problem on `law`, the estimate off.
fn problem(case: &Case, law: &str) -> Problem {
    let mut overrides: Vec<String> = case.overrides.iter().map(|s| s.to_string()).collect();
    overrides.push("accuracy.estimate=false".to_string());
    overrides.extend(case.law_fields.iter().map(|f| format!("{f}=\"{law}\"")));
    match &case.source {
        Source::Paper => scene::parse(scene::paper_wedge_scene(), "paper", &overrides)
            .and_then(|s| s.validate("paper"))
            .unwrap_or_else(|e| panic!("{e}")),
        Source::SmallBladePair => common::SmallBladePair::new().problem(&overrides),
        Source::File(file) => {
            let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(file);
            scene::load_problem(&path, &overrides)
                .unwrap_or_else(|e| panic!("{e}"))
                .1
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let all = args.iter().any(|a| a == "all");
    let filter = args
        .iter()
        .find(|a| *a != "all")
        .cloned()
        .unwrap_or_default();
    println!(
        "| scene | law | status | points | Newton iterations | step cuts | turning points | \
         jumps | wall s |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for case in CASES {
        if (case.long && !all) || !case.name.contains(&filter) {
            continue;
        }
        for (i, law) in case.laws.iter().enumerate() {
            let problem = problem(case, law);
            let name = if i == 0 { case.name } else { "" };
            match frf::solve(&problem, &mut Silent) {
                Ok(run) => println!(
                    "| {name} | {law} | {} | {} | {} | {} | {} | {} | {:.2} |",
                    status_text(run.incomplete_reason().as_deref()),
                    run.points.len(),
                    run.points
                        .iter()
                        .map(|p| p.newton_iterations)
                        .sum::<usize>(),
                    run.rejected_steps,
                    run.turning_points.len(),
                    run.jumps.len(),
                    run.elapsed_s
                ),
                Err(e) => println!("| {name} | {law} | failed: {e} | | | | | | |"),
            }
        }
    }
}
