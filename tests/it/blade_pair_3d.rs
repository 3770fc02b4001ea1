//! The 3D blade pair with 2D tangential friction (`meshes/blade-pair/blade-pair-3d.toml`):
//! the scene validates into a Craig-Bampton-reduced model whose 56 patch contact points all
//! carry the `jenkins-2d` law; fixed-frequency solves near the first bending pair, where
//! contacts stick, slip and lift off, give the same solutions in the schur (the scene's),
//! schur-lowrank and dense formulations; `fricbound run` of a narrow window completes with its result files and
//! VTU output; the FRF over 840-900 Hz is complete through both folds on the event-resolved
//! `jenkins-2d`; and the m = +1 limit curve crosses its former stall at
//! 852.78 Hz. The tests of the path at single contact transitions were measured on the sampled
//! laws and run on them (`SAMPLED`).

use crate::support;

use std::path::Path;

use fricbound::analysis::frf::PointSolver;
use fricbound::analysis::linear::stuck_guess;
use fricbound::contact::{ContactState, FrictionLaw};
use fricbound::model::{Formulation, Problem};
use fricbound::scene;

const SCENE: &str = "meshes/blade-pair/blade-pair-3d.toml";

/// Overrides that put the 3D scenes on the sampled laws (`jenkins-2d-sampled` patches, the
/// axial springs on `jenkins-1d-sampled`), as they were when the tests of the sampled law's
/// corners, leaps and stalls below were measured.
const SAMPLED: [&str; 4] = [
    "contact_patches.0.law=\"jenkins-2d-sampled\"",
    "contact_patches.1.law=\"jenkins-2d-sampled\"",
    "contacts.0.law=\"jenkins-1d-sampled\"",
    "contacts.1.law=\"jenkins-1d-sampled\"",
];

/// `overrides` after [`SAMPLED`].
fn sampled(overrides: &[&'static str]) -> Vec<&'static str> {
    SAMPLED.iter().chain(overrides).copied().collect()
}

/// Fixed frequencies below the first bending pair (Hz), each solved by Newton from the stuck
/// linear response; at these the patch points are stuck, open or in stick-slip with lift-off.
const FREQUENCIES: [f64; 2] = [720.0, 840.0];

fn problem(overrides: &[&str]) -> Problem {
    let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    scene::load_problem(Path::new(SCENE), &o).unwrap().1
}

#[test]
fn the_reduced_3d_scene_has_2d_friction_and_schur_and_dense_solve_it_alike() {
    // One reduction serves every check (it is most of the test's time).
    let scene = problem(&[]);
    let friction_2d = scene
        .contacts
        .iter()
        .filter(|c| c.friction_law() == FrictionLaw::Jenkins2d)
        .count();
    // 28 pairs per side on two sides, plus the two frictionless axial retention springs.
    assert_eq!(friction_2d, 56);
    assert_eq!(scene.contacts.len(), 58);
    // Craig-Bampton: 336 contact DOFs, 1 output DOF and 21 interior coordinates.
    assert!(
        scene.model.n_dofs() < 400,
        "{} reduced DOFs",
        scene.model.n_dofs()
    );
    // The scene sets schur (the scene file says why).
    assert_eq!(scene.formulation(), Formulation::Schur);
    let with = |formulation: Formulation| {
        let mut p = scene.clone();
        p.analysis.formulation = formulation;
        assert_eq!(p.formulation(), formulation);
        p
    };
    let dense = with(Formulation::Dense);
    let mut reference = PointSolver::new(&dense).unwrap();
    for formulation in [Formulation::Schur, Formulation::SchurLowRank] {
        let schur = with(formulation);
        let mut a = PointSolver::new(&schur).unwrap();
        let mut slipping = 0;
        for f in FREQUENCIES {
            let guess = stuck_guess(
                &schur,
                &schur.unknown_harmonics(),
                2.0 * std::f64::consts::PI * f,
            )
            .unwrap();
            let x = a.solve(&guess, f).unwrap();
            let y = reference.solve(&guess, f).unwrap();
            let scale = x.coefficients.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            let largest = x
                .coefficients
                .iter()
                .zip(&y.coefficients)
                .fold(0.0_f64, |m, (p, q)| m.max((p - q).abs()));
            println!(
                "{formulation:?}, {f} Hz: amplitude {:.6e} m, {} / dense {} Newton iterations, \
                 largest difference {:.2e} of the largest coefficient",
                x.amplitudes[0],
                x.newton_iterations,
                y.newton_iterations,
                largest / scale
            );
            assert!(
                largest <= 1e-6 * scale,
                "{formulation:?}, {f} Hz: {largest:.3e} vs {scale:.3e}"
            );
            assert_eq!(x.states, y.states, "{formulation:?}, {f} Hz");
            // The first two contacts are the frictionless axial retention springs.
            slipping += x.states[2..]
                .iter()
                .filter(|s| matches!(s, ContactState::StickSlip | ContactState::StickSlipLiftoff))
                .count();
        }
        // The 2D friction law is exercised: some patch points slip.
        assert!(slipping > 0);
    }
}

#[test]
fn a_short_frf_of_the_3d_scene_completes_with_vtu_output() {
    let out = std::env::temp_dir().join(format!("fricbound-blade-3d-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let run = support::run_scene(
        SCENE,
        &out,
        &[
            "analysis.freq_start_hz=700",
            "analysis.freq_end_hz=720",
            "accuracy.estimate=false",
        ],
    );
    assert!(run.status.success(), "{}", support::text(&run.stderr));
    let (header, rows) = support::csv(&out.join("frf.csv"));
    assert!(header.contains("left-1_state") && header.contains("right-28_state"));
    assert!(rows.len() >= 3, "{} points", rows.len());
    let last: f64 = rows.last().unwrap()[0].parse().unwrap();
    assert!((last - 720.0).abs() < 1e-6, "ends at {last} Hz");
    let files = support::names(&out);
    for f in ["modes_stuck.vtu", "response_peak.vtu", "solution.json"] {
        assert!(files.iter().any(|n| n == f), "{f} missing: {files:?}");
    }
    let _ = std::fs::remove_dir_all(&out);
}

/// A narrow FRF of the 3D scene run by the CLI with the `--set` overrides: its frequencies
/// (Hz) in path order, the state of `contact` at the first and at the last point, and the
/// text of `solution.json`.
struct NarrowFrf {
    freqs: Vec<f64>,
    first_state: String,
    last_state: String,
    solution: String,
}

fn narrow_frf(tag: &str, contact: &str, overrides: &[&str]) -> NarrowFrf {
    let out = std::env::temp_dir().join(format!("fricbound-blade-3d-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let run = support::run_scene(SCENE, &out, overrides);
    assert!(run.status.success(), "{}", support::text(&run.stderr));
    let (header, rows) = support::csv(&out.join("frf.csv"));
    let state = header
        .split(',')
        .position(|c| c == format!("{contact}_state"))
        .unwrap();
    let frf = NarrowFrf {
        freqs: rows.iter().map(|r| r[0].parse().unwrap()).collect(),
        first_state: rows[0][state].clone(),
        last_state: rows.last().unwrap()[state].clone(),
        solution: std::fs::read_to_string(out.join("solution.json")).unwrap(),
    };
    let _ = std::fs::remove_dir_all(&out);
    frf
}

/// On the rising flank of the first bending pair, 885.4-885.7 Hz, contact points change state
/// (`right-7` closes into stick-slip with lift-off); a 840-900 Hz run
/// turned back at a corner there (measured: benches/README.md, "3D blade pair with 2D
/// friction"). Followed on its own with the window's step sizes, the path crosses it without a
/// step cut, monotonically in frequency, and the run ends `complete` at 885.7 Hz.
#[test]
fn the_3d_frf_crosses_contact_transitions_on_the_bending_flank() {
    let frf = narrow_frf(
        "flank",
        "right-7",
        &sampled(&[
            "analysis.freq_start_hz=885.4",
            "analysis.freq_end_hz=885.7",
            "analysis.linear_points=3",
            "accuracy.estimate=false",
        ]),
    );
    let freqs = &frf.freqs;
    assert!(
        freqs.windows(2).all(|w| w[1] > w[0]),
        "not monotone: {freqs:?}"
    );
    assert!((freqs.last().unwrap() - 885.7).abs() < 1e-6);
    assert_eq!(frf.first_state, "open");
    assert_eq!(frf.last_state, "stick-slip-liftoff");
    assert!(frf.solution.contains("\"status\": \"complete\""), "status");
    assert!(frf.solution.contains("\"step_cuts\": []"), "step cuts");
}

/// At 886.685 Hz, on the rising flank of the first bending pair, `left-25` closes into
/// stick-slip with lift-off; a 840-900 Hz run failed there at every step and its corner search
/// resumed the path on the incoming branch, which it then retraced downwards (benches/README.md,
/// "FRF across the bending pair"). Started below it, the path crosses it: every point at a
/// higher frequency than the one before (no point repeats the way up going down), the run
/// `complete` at the end frequency, and `left-25` open at the start and touching at the end.
#[test]
fn the_3d_frf_crosses_the_transition_at_886_685_hz_without_turning_back() {
    let frf = narrow_frf(
        "886",
        "left-25",
        &sampled(&[
            "analysis.freq_start_hz=886.6",
            "analysis.freq_end_hz=886.75",
            "analysis.max_step=0.02",
            "analysis.linear_points=3",
            "accuracy.estimate=false",
        ]),
    );
    let freqs = &frf.freqs;
    println!("{} points: {freqs:?}", freqs.len());
    assert!(
        freqs.windows(2).all(|w| w[1] > w[0]),
        "not monotone: {freqs:?}"
    );
    assert!(freqs[0] < 886.685 && (freqs.last().unwrap() - 886.75).abs() < 1e-6);
    assert_ne!(frf.first_state, frf.last_state);
    assert!(frf.solution.contains("\"status\": \"complete\""), "status");
}

/// The FRF across the first bending pair, 840-900 Hz (the scene's window): up the lower
/// branch past the contact transitions at 886.685 Hz, round the fold at 886.85 Hz, down the
/// middle branch, round the sharp fold at 874.57 Hz and up the upper branch over the resonance
/// peak and down its flank to 900 Hz, on the scene's event-resolved `jenkins-2d`: one path,
/// `complete` (exit 0), no jump, with both folds among the turning points (measured: 886.84
/// and 873.52 Hz) and the resonance (5.58e-5 m at 873.54 Hz) far above the lower branch. (On
/// the sampled 2D law at 128 samples the sharp fold sat at 874.57 Hz and the peak at 874.73
/// Hz; with the simplified continuation that path leaves the fold region at its corners and
/// jumps past it onto the lower branch's continuation, missing the resonance.)
#[test]
fn the_3d_frf_over_the_bending_pair_is_complete_through_both_folds() {
    let out = std::env::temp_dir().join(format!("fricbound-blade-3d-frf-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let run = support::run_scene(
        SCENE,
        &out,
        &[
            "analysis.freq_start_hz=840",
            "analysis.freq_end_hz=900",
            "analysis.linear_points=3",
            "accuracy.estimate=false",
        ],
    );
    assert!(run.status.success(), "{}", support::text(&run.stderr));
    let solution = support::json(&out.join("solution.json"));
    assert_eq!(solution["status"].as_str().unwrap(), "complete");
    assert_eq!(solution["jumps"].as_array().unwrap().len(), 0, "jumps");
    let folds: Vec<f64> = solution["turning_points_hz"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    println!("turning points {folds:?}, jumps {}", solution["jumps"]);
    assert!(
        folds.iter().any(|&f| (886.8..886.9).contains(&f)),
        "{folds:?}"
    );
    assert!(
        folds.iter().any(|&f| (873.4..873.7).contains(&f)),
        "{folds:?}"
    );
    let (_, rows) = support::csv(&out.join("frf.csv"));
    let points: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| (r[0].parse().unwrap(), r[1].parse().unwrap()))
        .collect();
    let (peak_hz, peak) = points
        .iter()
        .copied()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap();
    let lower = points
        .iter()
        .filter(|p| p.0 < 870.0)
        .map(|p| p.1)
        .fold(0.0, f64::max);
    println!(
        "{} points; peak {peak:.4e} m at {peak_hz:.4} Hz",
        points.len()
    );
    assert!(peak > 5.0 * lower && (873.4..874.0).contains(&peak_hz));
    assert!((points.last().unwrap().0 - 900.0).abs() < 1e-9);
    let _ = std::fs::remove_dir_all(&out);
}

/// The m = +1 limit curve of `blade-pair-3d-limits.toml` used to stall at 852.78 Hz: point
/// `left-17` slips essentially along one direction there, and its 2D march crept towards a
/// degenerate fixed point without settling in 2000 periods (benches/README.md, "3D blade pair
/// with 2D friction"). With the 2D march's safeguarded Newton restarts the curve crosses that
/// frequency on a narrow window and ends `complete`.
#[test]
fn the_m_plus_1_limit_curve_passes_its_former_stall_at_852_78_hz() {
    use fricbound::analysis::limits::curve::attempt_case;
    let (start, end) = (LIMIT_WINDOW_HZ[0], LIMIT_WINDOW_HZ[1]);
    let (problem, case) = m_plus_1_case(start, end, &[]);
    let curve = attempt_case(&problem, &case, None);
    let reached = curve
        .points
        .iter()
        .map(|p| p.freq_hz)
        .fold(f64::NEG_INFINITY, f64::max);
    let iterations: usize = curve.points.iter().map(|p| p.newton_iterations).sum();
    println!(
        "m = +1 over {start}-{end} Hz: {} ({} points, {iterations} Newton iterations, reached \
         {reached:.4} Hz)",
        curve.status.text(),
        curve.points.len()
    );
    assert!(curve.status.is_complete(), "{}", curve.status.text());
    assert!(
        reached > 852.78 && (reached - end).abs() < 1e-6,
        "{reached}"
    );
}

const LIMITS_SCENE: &str = "meshes/blade-pair/blade-pair-3d-limits.toml";

/// The limit scene over `start`-`end` Hz (the estimate off, `extra` overrides added) and its
/// limit case m = +1 (both patches stuck at T = +μN at the start of the march).
fn m_plus_1_case(
    start: f64,
    end: f64,
    extra: &[&str],
) -> (Problem, fricbound::analysis::limits::case::LimitCase) {
    let mut o = vec![
        format!("analysis.freq_start_hz={start}"),
        format!("analysis.freq_end_hz={end}"),
        "accuracy.estimate=false".to_string(),
    ];
    o.extend(SAMPLED.iter().chain(extra).map(|s| s.to_string()));
    let problem = scene::load_problem(Path::new(LIMITS_SCENE), &o).unwrap().1;
    let case = fricbound::analysis::limits::case::two_point_cases(&problem)
        .into_iter()
        .find(|c| c.name == "m+1")
        .unwrap();
    (problem, case)
}

/// A window across the former stall of the m = +1 limit curve (Hz).
const LIMIT_WINDOW_HZ: [f64; 2] = [852.5, 853.2];
