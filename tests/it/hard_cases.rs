//! Hard cases of the paper's wedge-damper system (β = 120°, F0 = 120 N, 50-350 Hz unless
//! changed): each is a full continuation that must reach the end of the range with every point
//! converged and finite, and is checked against an independent expectation.
//!
//! The check shared by every case: wherever every contact is fully stuck over the period, the
//! contact forces' dynamic parts are kₜu and kₙv exactly, so the response there must equal the
//! linear response with all contacts stuck (closed form, `analysis::linear`), whatever the
//! frame angles, gap, harmonics or pre-load.

use fricbound::analysis::frf::{self, FrfPoint, FrfRun, Silent};
use fricbound::analysis::limits;
use fricbound::analysis::linear::{self, LinearCase};
use fricbound::analysis::peaks;
use fricbound::contact::ContactState;
use fricbound::model::Problem;
use fricbound::scene::{self, paper_wedge_scene};

fn problem(overrides: &[&str]) -> Problem {
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    scene::parse(paper_wedge_scene(), "paper", &overrides)
        .and_then(|s| s.validate("paper"))
        .unwrap_or_else(|e| panic!("{overrides:?}: {e}"))
}

/// Solves the FRF and checks what every hard case must show: the run covers the range, its
/// last point is at the end frequency exactly, every point converged with finite outputs, and
/// fully stuck points equal the stuck linear response.
fn solve_complete(p: &Problem, label: &str) -> FrfRun {
    let run = frf::solve(p, &mut Silent).unwrap_or_else(|e| panic!("{label}: {e}"));
    assert!(run.is_complete(), "{label}: {:?}", run.incomplete_reason());
    check_points(p, &run.points, label);
    run
}

/// The checks of [`solve_complete`] on the points of a path that reached the end frequency.
fn check_points(p: &Problem, points: &[FrfPoint], label: &str) {
    let range = &p.analysis.continuation;
    assert_eq!(
        points.last().map(|q| q.freq_hz),
        Some(range.freq_end_hz),
        "{label}: the last point is not at the end frequency"
    );
    for q in points {
        assert!(
            q.residual <= range.residual_tolerance,
            "{label}: point at {} Hz not converged ({:e})",
            q.freq_hz,
            q.residual
        );
        assert!(
            q.amplitudes.iter().chain(&q.peaks).all(|v| v.is_finite()),
            "{label}: non-finite output at {} Hz",
            q.freq_hz
        );
        // The time-domain peak is at least the first-harmonic amplitude.
        for (a, pk) in q.amplitudes.iter().zip(&q.peaks) {
            assert!(
                *pk >= a * (1.0 - 1e-12),
                "{label}: peak {pk} < amplitude {a}"
            );
        }
    }
    let stuck: Vec<_> = points
        .iter()
        .filter(|q| q.states.iter().all(|s| *s == ContactState::Stuck))
        .collect();
    let freqs: Vec<f64> = stuck.iter().map(|q| q.freq_hz).collect();
    let linear = linear::frf(p, LinearCase::Stuck, &freqs).expect("stuck linear response");
    let d = p.outputs[0];
    for (q, lin) in stuck.iter().zip(&linear) {
        let rel = (q.amplitudes[0] - lin[d]).abs() / lin[d];
        assert!(
            rel < 1e-6,
            "{label}: fully stuck at {} Hz but {} ≠ stuck linear {} (rel {rel:e})",
            q.freq_hz,
            q.amplitudes[0],
            lin[d]
        );
    }
}

/// The resonance peaks of the stuck linear reference of output 0 over the range: local maxima
/// of a 0.5 Hz grid, each refined by golden-section search on the closed-form response.
fn stuck_linear_peaks(p: &Problem) -> Vec<(f64, f64)> {
    let d = p.outputs[0];
    let amp = |f: f64| linear::frf(p, LinearCase::Stuck, &[f]).expect("linear")[0][d];
    let range = &p.analysis.continuation;
    let grid: Vec<f64> = (0..=((range.freq_end_hz - range.freq_start_hz) / 0.5) as usize)
        .map(|i| range.freq_start_hz + 0.5 * i as f64)
        .collect();
    let a: Vec<f64> = grid.iter().map(|&f| amp(f)).collect();
    (1..a.len() - 1)
        .filter(|&i| a[i] > a[i - 1] && a[i] >= a[i + 1])
        .map(|i| {
            let ratio = (5f64.sqrt() - 1.0) / 2.0;
            let (mut lo, mut hi) = (grid[i - 1], grid[i + 1]);
            while hi - lo > 1e-9 {
                let c = hi - ratio * (hi - lo);
                let d = lo + ratio * (hi - lo);
                if amp(c) >= amp(d) {
                    hi = d;
                } else {
                    lo = c;
                }
            }
            let f = 0.5 * (lo + hi);
            (f, amp(f))
        })
        .collect()
}

/// Every refined peak of the FRF equals a peak of the stuck linear reference within 0.1 %, and
/// every linear peak is found.
fn peaks_match_stuck_linear(p: &Problem, run: &FrfRun, label: &str) {
    let found = &peaks::path_peaks(p, &run.points).expect("peaks")[0];
    let expected = stuck_linear_peaks(p);
    assert_eq!(
        found.len(),
        expected.len(),
        "{label}: peaks {:?} vs stuck linear {expected:?}",
        found
            .iter()
            .map(|k| (k.freq_hz, k.amplitude))
            .collect::<Vec<_>>()
    );
    for (k, (f, a)) in found.iter().zip(&expected) {
        let rel = (k.amplitude - a).abs() / a;
        assert!(
            rel < 1e-3,
            "{label}: peak {:.4e} at {:.3} Hz vs stuck linear {a:.4e} at {f:.3} Hz (rel {rel:.2e})",
            k.amplitude,
            k.freq_hz
        );
    }
}

/// F0 = 100 kN: every contact stays stuck, so the FRF is the stuck linear one, and continuation
/// must not step over its four resonance peaks (a user sees all four at their linear height).
#[test]
fn very_high_preload_gives_the_stuck_linear_peaks() {
    let p = problem(&["static_loads.0.value=-1e5"]);
    let run = solve_complete(&p, "F0 = 1e5 N");
    peaks_match_stuck_linear(&p, &run, "F0 = 1e5 N");
}

/// Contact stiffnesses a thousand times lower: the slip threshold μN/kₜ is a thousand times
/// larger, the contacts stay stuck, and the FRF is the (softer) stuck linear one, peaks and all.
#[test]
fn soft_contacts_stay_stuck_and_give_the_stuck_linear_peaks() {
    let p = problem(&[
        "contacts.0.kt=300",
        "contacts.0.kn=300",
        "contacts.1.kt=300",
        "contacts.1.kn=300",
    ]);
    let run = solve_complete(&p, "k × 1e-3");
    peaks_match_stuck_linear(&p, &run, "k × 1e-3");
}

/// β = 60°, 90° and 180° (frames at 180° ∓ α, α = (180° − β)/2): the range is covered and the
/// stuck stretches are linear; the flat damper (β = 180°) has no damper-induced coupling.
#[test]
fn other_apical_angles_cover_the_range() {
    for (beta, left, right) in [(60, 120.0, 240.0), (90, 135.0, 225.0), (180, 180.0, 180.0)] {
        let p = problem(&[
            &format!("contacts.0.angle_deg={left}"),
            &format!("contacts.1.angle_deg={right}"),
        ]);
        solve_complete(&p, &format!("β = {beta}°"));
    }
}

/// μ = 0: no tangential force at all; wherever the contacts stay closed the system is linear
/// with the normal springs only, so the FRF equals the stuck linear response of the same
/// structure with kₜ → 0 there (most of the range; contacts lift off near resonances).
#[test]
fn frictionless_contacts_give_the_normal_spring_linear_system() {
    let p = problem(&["contacts.0.mu=0", "contacts.1.mu=0"]);
    let run = solve_complete(&p, "μ = 0");
    let normal_only = problem(&["contacts.0.kt=1e-9", "contacts.1.kt=1e-9"]);
    // Where a contact lifts off (near the 2nd resonance the blade-2 side does), the normal
    // spring acts for part of the period only and the system is not linear there.
    let closed: Vec<_> = run
        .points
        .iter()
        .filter(|q| {
            q.states
                .iter()
                .all(|s| !matches!(s, ContactState::StickSlipLiftoff | ContactState::Open))
        })
        .collect();
    assert!(
        closed.len() * 2 > run.points.len(),
        "μ = 0: contacts closed at only {} of {} points",
        closed.len(),
        run.points.len()
    );
    let freqs: Vec<f64> = closed.iter().map(|q| q.freq_hz).collect();
    let linear = linear::frf(&normal_only, LinearCase::Stuck, &freqs).expect("linear");
    let d = p.outputs[0];
    for (q, lin) in closed.iter().zip(&linear) {
        let rel = (q.amplitudes[0] - lin[d]).abs() / lin[d];
        assert!(rel < 1e-6, "μ = 0 at {} Hz: rel {rel:e}", q.freq_hz);
    }
}

/// 25 harmonics with 4096 samples per period: a big harmonic balance (6 DOFs × 51 blocks) must
/// still follow the whole path, every branch included (near 254.8 Hz the path turns back up at
/// a fold onto a branch above those followed there).
#[test]
fn many_harmonics_follow_every_branch_to_the_end() {
    let p = problem(&["harmonics.max=25", "harmonics.samples=4096"]);
    solve_complete(&p, "H = 25");
}

/// A small initial gap on both contacts (1 µm): the pre-load closes it, and contacts graze
/// (touch and part) in parts of the range; the path must still reach the end.
#[test]
fn grazing_contacts_cover_the_range() {
    let p = problem(&["contacts.0.gap=1e-6", "contacts.1.gap=1e-6"]);
    solve_complete(&p, "gap = 1 µm");
}

/// The resonance frequencies of the linear reference `case` of output 0 (local maxima of a
/// 0.25 Hz grid over the range).
fn linear_resonances(p: &Problem, case: LinearCase) -> Vec<f64> {
    let d = p.outputs[0];
    let range = &p.analysis.continuation;
    let grid: Vec<f64> = (0..=((range.freq_end_hz - range.freq_start_hz) / 0.25) as usize)
        .map(|i| range.freq_start_hz + 0.25 * i as f64)
        .collect();
    let a: Vec<f64> = linear::frf(p, case, &grid)
        .expect("linear response")
        .iter()
        .map(|row| row[d])
        .collect();
    (1..a.len() - 1)
        .filter(|&i| a[i] > a[i - 1] && a[i] >= a[i + 1])
        .map(|i| grid[i])
        .collect()
}

/// F0 = 1 N and 5 N against a 20 N excitation: the damper is barely held, bounces and slips,
/// and the path folds back (at about 66 and 80 Hz) through corners of the sampled contact law.
/// A user sees the whole range covered (the run follows the folds and, where the path does
/// not come back, goes on from the branch past the fold, filling it back toward the fold).
/// At 1 N the damper hardly holds the blades: every resonance of the open-contact linear
/// system has an FRF peak within 1 % of its frequency.
#[test]
fn low_preloads_cover_the_range() {
    for f0 in [1.0, 5.0] {
        let label = format!("F0 = {f0} N");
        let p = problem(&[&format!("static_loads.0.value={}", -f0)]);
        let run = solve_complete(&p, &label);
        if f0 > 1.0 {
            continue;
        }
        let found = &peaks::path_peaks(&p, &run.points).expect("peaks")[0];
        let open = linear_resonances(&p, LinearCase::Open);
        assert!(!open.is_empty());
        for fo in open {
            let off = found
                .iter()
                .map(|k| (k.freq_hz - fo).abs() / fo)
                .fold(f64::INFINITY, f64::min);
            assert!(
                off < 0.01,
                "{label}: no FRF peak within 1 % of the open-contact resonance at {fo} Hz \
                 (peaks {:?})",
                found.iter().map(|k| k.freq_hz).collect::<Vec<_>>()
            );
        }
    }
}

/// μ = 5: the friction limit is ten times the paper's, the contacts hardly slip; a user sees
/// the whole range, with the response on the stuck linear one wherever the contacts stay stuck.
#[test]
fn high_friction_covers_the_range() {
    let p = problem(&["contacts.0.mu=5", "contacts.1.mu=5"]);
    solve_complete(&p, "μ = 5");
}

/// No blade damping (C = 0; the damper has none either): only friction dissipates, so the
/// resonances are held by slip alone. A user sees the whole range, every point converged.
#[test]
fn no_structural_damping_covers_the_range() {
    let p = problem(&[
        "model.damping.0.0=0",
        "model.damping.1.1=0",
        "model.damping.2.2=0",
        "model.damping.3.3=0",
    ]);
    solve_complete(&p, "C = 0");
}

/// A start exactly on resonances of the stuck structure (224.94, 399.93 Hz and the nearly
/// undamped damper mode at 555.07 Hz, where the stuck linear guess is near-singular), and a
/// range across that damper mode (50-600 Hz): each run starts and covers its range.
#[test]
fn starts_on_resonances_and_ranges_across_the_damper_mode_cover_the_range() {
    for (start, end) in [
        (224.94, 350.0),
        (399.93, 450.0),
        (555.07, 600.0),
        (50.0, 600.0),
    ] {
        let p = problem(&[
            &format!("analysis.freq_start_hz={start}"),
            &format!("analysis.freq_end_hz={end}"),
        ]);
        solve_complete(&p, &format!("{start}-{end} Hz"));
    }
}

/// A limit scene solved as `fricbound run` would: every curve (m = ±1 per side and the
/// intermediate ones) must cover the range with the checks of [`check_points`], and the band
/// they form must exist over the whole grid with its upper edge above its lower one.
fn limits_complete(path: &str, overrides: &[&str], label: &str) {
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let file = format!("{}/{path}", env!("CARGO_MANIFEST_DIR"));
    let (p, settings) = scene::load(std::path::Path::new(&file), &overrides)
        .and_then(|s| s.validate_with_limits(&file))
        .unwrap_or_else(|e| panic!("{label}: {e}"));
    let settings = settings.expect("a limit scene");
    let analysis = limits::analyse(&p, &settings, |_| {}).unwrap_or_else(|e| panic!("{e}"));
    assert!(
        analysis.is_complete(),
        "{label}: not every curve is complete: {:?}",
        analysis.unfinished()
    );
    for curve in analysis.limits.iter().chain(&analysis.intermediate) {
        let q = curve.case.apply(&p);
        check_points(&q, &curve.points, &format!("{label}, {}", curve.case.name));
    }
    for g in &analysis.grid {
        assert!(
            g.upper.is_finite() && g.lower.is_finite() && g.upper >= g.lower,
            "{label}: band at {} Hz: {} .. {}",
            g.freq_hz,
            g.lower,
            g.upper
        );
    }
}

/// The paper's Fig. 13 limit scene (3rd resonance, β = 120°) at F0 = 5 N instead of 120 N: the
/// damper is barely held and slips or lifts off over most of the range. A user sees both limit
/// curves and the intermediate ones cover 200-235 Hz and a band over the whole grid.
#[test]
fn limit_scene_at_a_low_preload_covers_the_range() {
    limits_complete(
        "meshes/paper-wedge/fig13-3rd.toml",
        &["static_loads.0.value=-5"],
        "Fig. 13, F0 = 5 N",
    );
}

/// The 2D FE blade pair (Craig-Bampton, a patch of contact pairs per damper side) with a
/// tenth of its pre-load (5 N instead of 50 N): pairs open and close along the patches, and a
/// user sees both limit curves and the intermediate one reach 1100 Hz from 700 Hz, complete.
#[test]
fn fe_blade_pair_limits_at_a_low_preload_reach_the_end() {
    limits_complete(
        "meshes/blade-pair/blade-pair-2d-limits.toml",
        &["static_loads.0.value=5"],
        "FE blade pair, 5 N",
    );
}

/// Open gaps of 1 mm on both faces: at rest the damper hangs free above its contacts and the
/// pre-load must slide it 1 mm down into the wedge. The linear guesses leave it hanging (a
/// singular Jacobian); the run starts from the static state with the contacts. A user sees
/// the whole range, with the damper seated (no point has both contacts open all period).
#[test]
fn open_gaps_that_the_preload_closes_cover_the_range() {
    let p = problem(&["contacts.0.gap=1e-3", "contacts.1.gap=1e-3"]);
    let run = solve_complete(&p, "gap = 1 mm");
    assert!(run
        .points
        .iter()
        .all(|q| q.states.iter().any(|s| *s != ContactState::Open)));
}

/// The unreduced 2D FE blade pair (5 002 DOFs, no damping at all) with 0.1 mm open gaps on
/// both contact patches: at rest the damper hangs free and the pre-load must slide it across
/// the gaps as a whole. Each row of K q then sums terms of about 10⁷ N that cancel, so the
/// residual cannot fall below about 10⁻¹⁰ of the 50 N pre-load spread over the damper's nodes:
/// Newton accepts it at that round-off level (before, every start guess failed after 108
/// iterations). A user sees the first point solved with the damper seated on its patches;
/// the run is asked for its first points only (the whole range takes minutes).
#[test]
fn undamped_fe_model_with_open_gaps_solves_its_first_point() {
    let file = format!(
        "{}/meshes/blade-pair/blade-pair-2d.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let overrides: Vec<String> = [
        "reduction=",
        "contact_patches.0.gap=1e-4",
        "contact_patches.1.gap=1e-4",
        "analysis.max_points=3",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let p = scene::load(std::path::Path::new(&file), &overrides)
        .and_then(|s| s.validate(&file))
        .unwrap_or_else(|e| panic!("{e}"));
    let run = frf::solve(&p, &mut Silent).unwrap_or_else(|e| panic!("first point: {e}"));
    let first = run.points.first().expect("a first point");
    assert_eq!(first.freq_hz, p.analysis.continuation.freq_start_hz);
    assert!(
        first.residual < 1e-9,
        "residual {:e} beyond the round-off level",
        first.residual
    );
    assert!(first.amplitudes.iter().all(|a| a.is_finite() && *a > 0.0));
    assert!(
        first.states.iter().any(|s| *s != ContactState::Open),
        "the damper is not seated"
    );
    // Three points asked for, three solved: the budget, not a failure, ends the run.
    assert_eq!(run.points.len(), 3);
    assert!(!run.is_complete());
}
