//! Branches the FRF's continuation gave up (a dead end or no progress) before jumping past the
//! highest frequency reached: how each jump records the branch before it, checked against an
//! independent fixed-frequency Newton solve from the point given up, and the run's status.
//!
//! - `tests/data/liftoff-fold.toml` (1 DOF with a one-sided contact): the path bounces between
//!   two corners of the sampled law at 32.07 and 32.52 Hz and is given up at 32.52 Hz on the
//!   stretch it had followed already: a retrace, the run stays complete.
//! - The paper's system at F0 = 1 N (50-350 Hz): every branch given up is classified, and each
//!   classification is checked by Newton at a frequency just past the point given up (in the
//!   direction the path was going), seeded from that point.
//! - The paper's system at −5 N and H = 3: a dead end past which Newton converges nowhere,
//!   judged on the other side of the fold it turns back at; at F0 = 10 N and H = 3 with a
//!   coarse smallest step, a leap onto another branch whose branch before goes on on the run.

//!
//! Dead ends, leaps and jumps arise where the path meets the corners of the sampled contact
//! law; the event-resolved law (`jenkins-1d`) has none on these cases (its paths through them
//! are complete without a jump), so every case here runs `jenkins-1d-sampled`.

mod common;
mod support;

use std::path::Path;

use fricbound::analysis::frf::{self, BranchEnd, CutVerdict, FrfRun, GivenUp, PointSolver, Silent};
use fricbound::model::Problem;
use fricbound::scene::{self, paper_wedge_scene};

use support::{json, run_scene, text};

fn liftoff_fold() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/liftoff-fold.toml")
        .display()
        .to_string()
}

/// The paper scene's two contacts on the sampled law.
const SAMPLED: [&str; 2] = common::scenes::SAMPLED_PAPER;

/// The FE scenes' two contact patches on the sampled law.
const SAMPLED_PATCHES: [&str; 2] = [
    "contact_patches.0.law=\"jenkins-1d-sampled\"",
    "contact_patches.1.law=\"jenkins-1d-sampled\"",
];

/// The lift-off oscillator's contact on the sampled law.
const SAMPLED_STOP: &str = "contacts.0.law=\"jenkins-1d-sampled\"";

fn paper(overrides: &[&str]) -> Problem {
    let overrides: Vec<String> = SAMPLED
        .iter()
        .chain(overrides)
        .map(|s| s.to_string())
        .collect();
    scene::parse(paper_wedge_scene(), "paper", &overrides)
        .and_then(|s| s.validate("paper"))
        .unwrap_or_else(|e| panic!("{overrides:?}: {e}"))
}

/// ‖x − reference‖ / ‖reference‖ over all Fourier coefficients.
fn coefficients_apart(x: &[f64], reference: &[f64]) -> f64 {
    let norm = reference.iter().map(|v| v * v).sum::<f64>().sqrt();
    x.iter()
        .zip(reference)
        .map(|(a, b)| (a - b).powi(2))
        .sum::<f64>()
        .sqrt()
        / norm
}

/// The points given up of a run, with the index of each one's point in the run.
fn given_up(run: &FrfRun) -> Vec<(BranchEnd, GivenUp, usize)> {
    run.jumps
        .iter()
        .filter_map(|j| match j.before {
            BranchEnd::Abandoned(g) | BranchEnd::Retrace(g) | BranchEnd::OutsideRange(g) => {
                Some((j.before, g, j.first_point - 1))
            }
            _ => None,
        })
        .collect()
}

/// Newton at fixed frequencies just past the point given up (0.05 %, 0.2 %, 1 % of its
/// frequency, in the direction the path was going: down when it had turned back down at its
/// fold), from that point's coefficients: the first converged amplitude of the first output
/// and its frequency, and whether some branch of the run crosses that frequency within 1 % of
/// that amplitude. None when Newton converges at none of them.
fn newton_past(p: &Problem, run: &FrfRun, g: &GivenUp, index: usize) -> Option<(f64, f64, bool)> {
    let down = g.fold_hz.is_some_and(|fold| fold >= g.freq_hz);
    let mut solver = PointSolver::new(p).expect("point solver");
    for offset in [5e-4, 2e-3, 1e-2] {
        let f = g.freq_hz * if down { 1.0 - offset } else { 1.0 + offset };
        if let Ok(q) = solver.solve(&run.points[index].coefficients, f) {
            let a = q.amplitudes[0];
            let on_run = run
                .crossings(f, 0)
                .iter()
                .any(|c| (c.amplitude - a).abs() <= 1e-2 * a);
            return Some((f, a, on_run));
        }
    }
    None
}

/// The lift-off oscillator's path is given up at a dead end at 32.52 Hz, on the stretch
/// between two corners that it had followed twice already: a retrace, so the run, which jumped
/// past the fold at 51.46 Hz and reached 60 Hz, is complete, and the CLI says so (exit 0,
/// `before.how` = `retrace`, `abandoned` false).
#[test]
fn a_dead_end_on_a_stretch_already_followed_abandons_nothing() {
    let (_, p) = scene::load_problem(
        Path::new(&liftoff_fold()),
        &[
            "analysis.stability=false".to_string(),
            SAMPLED_STOP.to_string(),
        ],
    )
    .unwrap();
    let run = frf::solve(&p, &mut Silent).unwrap();
    assert!(run.is_complete(), "{:?}", run.incomplete_reason());
    let given = given_up(&run);
    assert_eq!(given.len(), 1, "{:?}", run.jumps);
    let (end, g, _) = given[0];
    assert!(matches!(end, BranchEnd::Retrace(_)), "{end:?}");
    assert!((g.freq_hz - 32.52).abs() < 0.01, "{g:?}");

    let dir = tempfile::tempdir().unwrap();
    let out = run_scene(
        &liftoff_fold(),
        dir.path(),
        &["analysis.stability=false", SAMPLED_STOP],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let sol = json(&dir.path().join("solution.json"));
    assert_eq!(sol["status"], "complete");
    let jump = &sol["jumps"][0];
    assert_eq!(jump["kind"], "past-dead-end");
    assert_eq!(jump["abandoned"], false);
    assert_eq!(jump["before"]["how"], "retrace");
    assert!(
        text(&out.stderr).contains("a retrace"),
        "{}",
        text(&out.stderr)
    );
}

/// At F0 = 1 N every branch given up is classified, and the classification agrees with Newton
/// from the point given up at a frequency just past it: a branch abandoned inside the range
/// leads to a solution no branch of the run holds; a retrace to one the run holds. One given
/// up below the start frequency (50 Hz) is outside the range. The CLI's exit code and
/// `solution.json` say the same.
#[test]
fn branches_given_up_at_a_low_preload_are_classified_as_newton_finds_them() {
    let p = paper(&["static_loads.0.value=-1"]);
    let run = frf::solve(&p, &mut Silent).unwrap();
    let given = given_up(&run);
    assert!(!given.is_empty(), "{:?}", run.jumps);
    for (end, g, index) in &given {
        let newton = newton_past(&p, &run, g, *index);
        eprintln!("{end:?}: Newton past it {newton:?}");
        match end {
            BranchEnd::OutsideRange(_) => assert!(g.freq_hz < 50.0),
            BranchEnd::Abandoned(_) => {
                let (f, a, on_run) = newton.expect("Newton converges past the point");
                assert!(!on_run, "{a} m at {f} Hz lies on the run");
            }
            BranchEnd::Retrace(_) => {
                if let Some((f, a, on_run)) = newton {
                    assert!(on_run, "{a} m at {f} Hz is on no branch of the run");
                }
            }
            _ => unreachable!(),
        }
    }
    let abandoned = run.jumps.iter().filter(|j| j.abandons_branch()).count();
    assert_eq!(run.is_complete(), abandoned == 0);

    let dir = tempfile::tempdir().unwrap();
    let scene_file = dir.path().join("paper.toml");
    std::fs::write(&scene_file, paper_wedge_scene()).unwrap();
    let out_dir = dir.path().join("out");
    let out = run_scene(
        scene_file.to_str().unwrap(),
        &out_dir,
        &["static_loads.0.value=-1", SAMPLED[0], SAMPLED[1]],
    );
    let sol = json(&out_dir.join("solution.json"));
    let status = sol["status"].as_str().unwrap().to_string();
    // Each leap of the run is judged in solution.json as in the library.
    let checks = sol["leap_checks"].as_array().unwrap();
    assert_eq!(checks.len(), run.leap_checks.len());
    assert_eq!(checks.len(), sol["leaps_hz"].as_array().unwrap().len());
    for (c, l) in checks.iter().zip(&run.leap_checks) {
        assert_eq!(c["verdict"], "covered");
        assert_eq!(c["from_hz"].as_f64().unwrap(), l.from_hz);
    }
    let flagged = sol["jumps"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|j| j["abandoned"] == true)
        .count();
    assert_eq!(flagged, abandoned, "{}", sol["jumps"]);
    if abandoned > 0 {
        assert_eq!(out.status.code(), Some(3), "{}", text(&out.stderr));
        assert!(
            status.starts_with("incomplete: ") && status.contains("a branch was abandoned at"),
            "{status}"
        );
        assert!(text(&out.stderr).contains("ABANDONED"));
    } else {
        assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    }
}

/// The 2D FE blade pair's m = +1 limit curve at a tenth of its pre-load (5 N), run as an FRF
/// (700-1100 Hz, H = 1): running down from a fold at 875.87 Hz with the amplitude rising, the
/// path meets a dead end at 875.50 Hz and jumps past it; Newton past the point given up
/// converges at none of the frequencies tried, nor with the frequency free round a fold
/// there, so whether the branch goes on is not known
/// (`unjudged`) and the run is incomplete (checked again by `PointSolver`). The CLI says so:
/// exit 3, ABANDONED on stderr with the judgement, and `solution.json` holds the library's
/// status, marks the same jumps abandoned and records each judgement (`end_check`).
#[test]
fn the_cli_says_which_branch_a_run_abandoned() {
    let scene_file = format!(
        "{}/meshes/blade-pair/blade-pair-2d-limits.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let overrides = [
        "limits=",
        "static_loads.0.value=5",
        "contact_patches.0.initial_state=1",
        "contact_patches.1.initial_state=1",
        "accuracy.estimate=false",
        SAMPLED_PATCHES[0],
        SAMPLED_PATCHES[1],
    ];
    let owned: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let (_, p) = scene::load_problem(Path::new(&scene_file), &owned).unwrap();
    let run = frf::solve(&p, &mut Silent).unwrap();
    let reason = run.incomplete_reason().expect("an abandoned branch");
    assert!(reason.contains("a branch was abandoned at"), "{reason}");
    let label = "blade pair, m = +1 at 5 N";
    let abandoned = common::abandoned::abandoned_branches_are_off_the_run(&p, &run, label);
    assert!(!abandoned.is_empty(), "{:?}", run.jumps);

    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("out");
    let out = run_scene(&scene_file, &out_dir, &overrides);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    assert!(
        stderr.contains("ABANDONED: the branch given up at"),
        "{stderr}"
    );
    let sol = json(&out_dir.join("solution.json"));
    assert_eq!(sol["status"], format!("incomplete: {reason}"));
    let flagged: Vec<&serde_json::Value> = sol["jumps"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|j| j["abandoned"] == true)
        .collect();
    assert_eq!(flagged.len(), abandoned.len(), "{}", sol["jumps"]);
    for (file, jump) in flagged.iter().zip(&abandoned) {
        assert_eq!(file["before"]["how"], "abandoned");
        let check = jump.end_check.expect("judged");
        assert_eq!(
            file["end_check"]["verdict"],
            serde_json::to_value(check.verdict).unwrap()
        );
        assert_eq!(
            file["end_check"]["freq_hz"].as_f64(),
            Some(check.landing.freq_hz)
        );
    }
}

/// The cuts of the fills and bridges (`fill_cut`: a branch solved past a jump and left off
/// every stretch followed before) are judged once the run is over (`cut_check`), and each
/// judgement agrees with an independent check: Newton by `PointSolver` at the judgement's
/// frequency from the cut point's coefficients lands where the judgement says, and a landing
/// judged covered has some crossing of the run within 1 % of its first output's amplitude,
/// one judged abandoned none within 1 % on every output at once; a landing on the cut's own
/// side is judged past its fold, where Newton lands where the judgement says, above every
/// crossing of the run when not covered. At F0 = 5 N the cut at 80.4161 Hz lands on the fill's
/// own side, and past its fold below the run: the run stays complete; the run's status counts
/// exactly the cuts judged not covered.
#[test]
fn cuts_of_fills_and_bridges_are_judged_by_newton_past_them() {
    let mut judged_at_5n = Vec::new();
    for f0 in [1.0, 5.0] {
        let p = paper(&[&format!("static_loads.0.value={}", -f0)]);
        let run = frf::solve(&p, &mut Silent).unwrap();
        let mut solver = PointSolver::new(&p).expect("point solver");
        let starts = run.branch_starts();
        for (k, jump) in run.jumps.iter().enumerate() {
            let Some(cut) = jump.fill_cut else {
                assert!(jump.cut_check.is_none(), "{jump:?}");
                continue;
            };
            let check = jump.cut_check.expect("every cut is judged");
            eprintln!("F0 = {f0} N: cut {cut:?}\n  judged {check:?}");
            let end = starts.get(k + 1).copied().unwrap_or(run.points.len());
            let point = run.points[jump.first_point..end]
                .iter()
                .find(|q| q.freq_hz == cut.freq_hz && q.amplitudes[0] == cut.amplitude)
                .expect("the cut point is on its branch");
            // Just past the cut: within 10⁻³ of its frequency.
            assert!(
                (check.landing.freq_hz - cut.freq_hz).abs() <= 1e-3 * cut.freq_hz * (1.0 + 1e-12)
                    && check.landing.freq_hz != cut.freq_hz,
                "{check:?}"
            );
            match (
                check.verdict,
                solver.solve(&point.coefficients, check.landing.freq_hz),
            ) {
                (CutVerdict::Unjudged, landing) => assert!(landing.is_err(), "{landing:?}"),
                (verdict, Ok(q)) => {
                    let a = q.amplitudes[0];
                    let judged = check.landing.amplitude.expect("a landing");
                    assert!((a - judged).abs() <= 1e-6 * judged, "{a} vs {judged}");
                    let crossings = run.crossings(check.landing.freq_hz, 0);
                    let near_first = crossings
                        .iter()
                        .any(|c| (c.amplitude - a).abs() <= 1e-2 * a);
                    let near_all = crossings.iter().any(|c| {
                        (0..q.amplitudes.len()).all(|o| {
                            let s = &run.points[c.segment..=c.segment + 1];
                            let t = (check.landing.freq_hz - s[0].freq_hz)
                                / (s[1].freq_hz - s[0].freq_hz);
                            let on =
                                s[0].amplitudes[o] + t * (s[1].amplitudes[o] - s[0].amplitudes[o]);
                            (on - q.amplitudes[o]).abs() <= 1e-2 * q.amplitudes[o]
                        })
                    });
                    match (verdict, check.beyond_fold) {
                        (_, None) if verdict == CutVerdict::Covered => {
                            assert!(near_first, "{crossings:?}")
                        }
                        (_, None) => assert!(!near_all, "{crossings:?}"),
                        // The landing is the cut's own side: judged past its fold.
                        (_, Some(fold)) => {
                            assert!(near_first, "{crossings:?}");
                            let judged = fold.landing.amplitude.expect("a landing past the fold");
                            let at_fold = run.points[jump.first_point..end]
                                .iter()
                                .find(|q| q.freq_hz == fold.fold_hz)
                                .expect("the fold is on the cut's branch");
                            let q = solver
                                .solve(&at_fold.coefficients, fold.landing.freq_hz)
                                .expect("Newton past the fold");
                            let b = q.amplitudes[0];
                            assert!((b - judged).abs() <= 1e-6 * judged, "{b} vs {judged}");
                            let largest = run
                                .crossings(fold.landing.freq_hz, 0)
                                .iter()
                                .map(|c| c.amplitude)
                                .fold(f64::NEG_INFINITY, f64::max);
                            if verdict != CutVerdict::Covered {
                                assert!(b > largest, "{b} under the run's {largest}");
                            }
                        }
                    }
                }
                (verdict, Err(e)) => panic!("{verdict:?} but Newton fails: {e}"),
            }
            if f0 == 5.0 {
                judged_at_5n.push((cut, check));
            }
        }
        let uncovered = run
            .jumps
            .iter()
            .filter(|j| j.cut_uncovered().is_some())
            .count();
        let abandoned = run.abandoned().count();
        assert_eq!(run.is_complete(), uncovered + abandoned == 0);
        if f0 == 5.0 {
            assert!(run.is_complete(), "{:?}", run.incomplete_reason());
        }
    }
    // The fill at 80.4161 Hz came back along its own side (Newton from it finds the landing)
    // from its fold at 80.4043 Hz; past that fold Newton lands on the lower branch, below the
    // resonance branch the run followed there: covered.
    assert!(
        judged_at_5n.iter().any(|(cut, check)| {
            (cut.freq_hz - 80.4161).abs() < 1e-3
                && check.verdict == CutVerdict::Covered
                && check.own_side
                && check.beyond_fold.is_some_and(|fold| {
                    fold.verdict == CutVerdict::Covered
                        && fold
                            .landing
                            .amplitude
                            .zip(fold.run_amplitude)
                            .is_some_and(|(a, r)| a < r)
                })
        }),
        "{judged_at_5n:?}"
    );
}

/// At F0 = 1 N the path leaps once, from 19.0467 to 19.2388 Hz, over a corner of the sampled
/// contact law. Followed back from the landing, the path reaches 19.0467 Hz on the piece of
/// the solution curve next to the one the leap left, within the run's 1 % of the point before
/// the leap: the leap is covered. Independently, Newton at 19.0467 Hz from the landing
/// converges to a solution within 1 % of that point too (on all Fourier coefficients).
#[test]
fn a_leap_over_a_corner_at_a_low_preload_is_covered_as_newton_finds() {
    let p = paper(&["static_loads.0.value=-1"]);
    let run = frf::solve(&p, &mut Silent).unwrap();
    assert!(!run.leaps.is_empty(), "no leap at F0 = 1 N");
    assert_eq!(run.leap_checks.len(), run.leaps.len());
    let mut solver = PointSolver::new(&p).unwrap();
    for check in &run.leap_checks {
        eprintln!("{check:?}");
        assert_eq!(check.verdict, CutVerdict::Covered, "{check:?}");
        let d = check.distance.unwrap();
        assert!(d <= frf::RETRACE_TOLERANCE, "{check:?}");
        assert!(check.points >= 2);
        let i = run
            .points
            .iter()
            .position(|q| q.freq_hz == check.to_hz)
            .expect("the landing is a point of the run");
        let before = &run.points[i - 1];
        assert_eq!(before.freq_hz, check.from_hz);
        let there = solver
            .solve(&run.points[i].coefficients, check.from_hz)
            .unwrap();
        let apart = coefficients_apart(&there.coefficients, &before.coefficients);
        eprintln!(
            "Newton at {:.4} Hz from the landing: {apart:.3e} from the point before",
            check.from_hz
        );
        assert!(apart <= frf::RETRACE_TOLERANCE, "{apart}");
    }
    assert!(run.is_complete(), "{:?}", run.incomplete_reason());
}

/// Leaps inside the fills after a jump and inside the bridges are listed and judged as the
/// main path's are. At F0 = 15 N and H = 3 with a smallest step of 1 Hz (so that a corrector
/// failing twice leaps instead of cutting the step further) the path leaps over 14 spots, ten
/// of them on the fill after the bridge at 210.60 Hz, which is reported in reverse (falling
/// from the jump target, listed rising): each leap's two points are consecutive in the report,
/// in either order, where the run recorded them (`FrfRun::leap_points`), and followed back
/// from its landing the path reaches the point before it
/// (checked here again by Newton at the frequency before the leap from the landing).
#[test]
fn leaps_inside_fills_are_listed_and_judged() {
    let p = paper(&[
        "static_loads.0.value=-15",
        "harmonics.max=3",
        "analysis.min_step=1",
        "accuracy.estimate=false",
    ]);
    let run = frf::solve(&p, &mut Silent).unwrap();
    assert_eq!(run.leap_checks.len(), run.leaps.len());
    let first_jump = run.jumps.first().expect("the path jumps").first_point;
    let mut solver = PointSolver::new(&p).unwrap();
    let mut in_reverse = 0;
    assert_eq!(run.leap_points.len(), run.leaps.len());
    for ((&(from_hz, to_hz), check), &recorded) in
        run.leaps.iter().zip(&run.leap_checks).zip(&run.leap_points)
    {
        eprintln!("{check:?}");
        assert_eq!((check.from_hz, check.to_hz), (from_hz, to_hz));
        let at = |a: f64, b: f64| {
            (1..run.points.len())
                .find(|&i| run.points[i - 1].freq_hz == a && run.points[i].freq_hz == b)
        };
        let (before, landing) = match (at(from_hz, to_hz), at(to_hz, from_hz)) {
            (Some(i), _) => (i - 1, i),
            (None, Some(i)) => {
                in_reverse += 1;
                assert!(
                    i > first_jump,
                    "a main-path leap reported in reverse at {i}"
                );
                (i, i - 1)
            }
            (None, None) => panic!("leap {from_hz} -> {to_hz}: its points are not consecutive"),
        };
        // The indices the run recorded are the two points found by frequency.
        assert_eq!(recorded, Some((before, landing)), "{from_hz} -> {to_hz}");
        assert_eq!(check.verdict, CutVerdict::Covered, "{check:?}");
        let there = solver
            .solve(&run.points[landing].coefficients, from_hz)
            .unwrap();
        let apart = coefficients_apart(&there.coefficients, &run.points[before].coefficients);
        assert!(
            apart <= frf::RETRACE_TOLERANCE,
            "{from_hz} -> {to_hz}: {apart}"
        );
    }
    assert!(in_reverse >= 1, "no leap on a fill: {:?}", run.leaps);
}

/// At a pre-load of −5 N and H = 3 (50-350 Hz) the fill solved past the jump at 78.50 Hz
/// comes up to a dead end at 92.0992 Hz in halving steps (the corrector failing past it at
/// every step), and Newton at fixed frequencies past it converges nowhere: the branch turns
/// back there, at a corner of the sampled contact law. The judgement seeks the other side of
/// that fold with the frequency free, on the stretch's chord in the unknowns
/// (`judge_round_dead_end`), lands just behind the dead end, below the run's largest
/// amplitude there, and covers the cut. Checked again: fixed-frequency Newton from the cut
/// point fails at the frequency the judgement tried past it and converges at the landing's
/// frequency behind it to the stretch's own side there, not the landing (which Newton from
/// the stretch does not reach: `resolved_distance`); `PointSolver` finds the landing again
/// from the same two points, and Newton at the landing's fixed frequency from it stays there
/// (a solution of the harmonic balance, another than the stretch's own); the run's crossings
/// there reach above the landing. The rest of the run stays `incomplete` for the stretch
/// 78.50-90.15 Hz that no branch reached.
#[test]
fn a_dead_end_that_turns_back_at_a_fold_is_judged_on_its_other_side() {
    let p = paper(&[
        "static_loads.0.value=-5",
        "harmonics.max=3",
        "accuracy.estimate=false",
    ]);
    let run = frf::solve(&p, &mut Silent).unwrap();
    let (k, jump) = run
        .jumps
        .iter()
        .enumerate()
        .find(|(_, j)| {
            j.fill_cut
                .is_some_and(|c| (c.freq_hz - 92.0992).abs() < 1e-3)
        })
        .unwrap_or_else(|| panic!("no cut at 92.0992 Hz: {:?}", run.jumps));
    let cut = jump.fill_cut.unwrap();
    assert_eq!(cut.cause, frf::GiveUpCause::DeadEnd);
    let check = jump.cut_check.expect("judged");
    eprintln!("{check:?}");
    assert_eq!(check.verdict, CutVerdict::Covered, "{check:?}");
    assert!(check.landing.amplitude.is_none(), "{check:?}");
    let fold = check.beyond_fold.expect("judged round the fold");
    assert_eq!(fold.fold_hz, cut.freq_hz);
    assert_eq!(fold.verdict, CutVerdict::Covered);
    let landing_hz = fold.landing.freq_hz;
    let amplitude = fold.landing.amplitude.expect("a landing");
    // Behind the dead end (the stretch came up to it), next to it.
    assert!(landing_hz < cut.freq_hz && landing_hz > cut.freq_hz * (1.0 - 1e-3));
    // Another solution than the stretch's own there.
    assert!(
        fold.landing.resolved_distance.is_some_and(|d| d > 1e-8),
        "{fold:?}"
    );
    let starts = run.branch_starts();
    let end = starts.get(k + 1).copied().unwrap_or(run.points.len());
    let i = (jump.first_point..end)
        .find(|&i| run.points[i].freq_hz == cut.freq_hz)
        .expect("the cut point is on its branch");
    let mut solver = PointSolver::new(&p).unwrap();
    let cut_point = &run.points[i];
    assert!(solver
        .solve(&cut_point.coefficients, check.landing.freq_hz)
        .is_err());
    let own = solver
        .solve(&cut_point.coefficients, landing_hz)
        .expect("the stretch's own side behind the dead end");
    assert!(
        (own.amplitudes[0] - amplitude).abs() > 1e-6 * amplitude,
        "{} m is the landing's {amplitude} m",
        own.amplitudes[0]
    );
    // The same construction through the public solver (the chord from the first point of the
    // stretch at least 5·10⁻⁵ of the frequency back), and the landing confirmed by Newton at
    // its fixed frequency: a solution there, not the stretch's own.
    // The stretch into the cut, nearest point first.
    let into: Vec<usize> = if i == jump.first_point {
        (i + 1..end).collect()
    } else {
        (jump.first_point..i).rev().collect()
    };
    let back = into
        .into_iter()
        .find(|&j| {
            (run.points[j].freq_hz - cut.freq_hz).abs() >= frf::ROUND_FOLD_CHORD * cut.freq_hz
        })
        .expect("a point that far back");
    let again = solver
        .solve_round_fold(&run.points[back], cut_point)
        .expect("the landing again");
    assert_eq!(again.freq_hz, landing_hz);
    assert_eq!(again.amplitudes[0], amplitude);
    let fixed = solver
        .solve(&again.coefficients, landing_hz)
        .expect("Newton at the landing's frequency");
    assert!(
        coefficients_apart(&fixed.coefficients, &again.coefficients) < 1e-8,
        "the landing is not a fixed-frequency solution"
    );
    assert!(coefficients_apart(&fixed.coefficients, &own.coefficients) > 1e-6);
    let largest = run
        .crossings(landing_hz, 0)
        .iter()
        .map(|c| c.amplitude)
        .fold(f64::NEG_INFINITY, f64::max);
    assert!(amplitude < largest, "{amplitude} not below {largest}");
    assert_eq!(fold.run_amplitude, Some(largest));
    let reason = run
        .incomplete_reason()
        .expect("the stretch no branch reached");
    assert!(
        reason.contains("no solution was found at 78.5010-90.1522 Hz"),
        "{reason}"
    );
    assert!(!reason.contains("92.0992"), "{reason}");
}

/// A leap onto another branch whose branch before goes on onto the run. At F0 = 10 N and
/// H = 3 with a smallest step of 1 Hz the path leaps from 207.5087 to 207.5248 Hz, and
/// followed back from the landing it reaches 207.5087 Hz 2.4 % from the point before the leap:
/// another branch. The branch through that point is then judged as a branch given up at a dead
/// end (`LeapCheck::past`): Newton past it, the way the path was going, lands on a stretch of
/// the run (Newton from that stretch converges to the landing), so nothing is missing and the
/// leap is covered. Checked again by `PointSolver`: from the point before the leap at the
/// judgement's frequency it lands at the judgement's amplitude, and from the nearest crossing
/// of the run there on the same solution.
#[test]
fn a_leap_onto_another_branch_is_covered_where_the_branch_it_left_goes_on_on_the_run() {
    let p = paper(&[
        "static_loads.0.value=-10",
        "harmonics.max=3",
        "analysis.min_step=1",
        "accuracy.estimate=false",
    ]);
    let run = frf::solve(&p, &mut Silent).unwrap();
    let check = run
        .leap_checks
        .iter()
        .find(|c| (c.from_hz - 207.5087).abs() < 1e-3)
        .unwrap_or_else(|| panic!("no leap from 207.5087 Hz: {:?}", run.leap_checks));
    eprintln!("{check:?}");
    assert!(
        check.distance.is_some_and(|d| d > frf::RETRACE_TOLERANCE),
        "{check:?}"
    );
    assert_eq!(check.verdict, CutVerdict::Covered);
    let past = check.past.expect("the branch before the leap judged");
    assert_eq!(past.verdict, CutVerdict::Covered);
    let amplitude = past.landing.amplitude.expect("Newton lands past the point");
    let f = past.landing.freq_hz;
    assert!(f > check.from_hz && f < check.from_hz * (1.0 + 1e-3), "{f}");
    let before = run
        .points
        .iter()
        .find(|q| q.freq_hz == check.from_hz)
        .expect("the point before the leap");
    let mut solver = PointSolver::new(&p).unwrap();
    let landing = solver
        .solve(&before.coefficients, f)
        .expect("Newton past it");
    assert!((landing.amplitudes[0] - amplitude).abs() <= 1e-6 * amplitude);
    let on_run = run.crossings(f, 0).iter().any(|c| {
        (c.amplitude - amplitude).abs() <= 1e-2 * amplitude
            && solver
                .solve(&run.points[c.nearest_point].coefficients, f)
                .is_ok_and(|q| coefficients_apart(&q.coefficients, &landing.coefficients) < 1e-8)
    });
    assert!(on_run, "no crossing of the run at {f} Hz holds the landing");
}
