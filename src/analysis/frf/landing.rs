//! Newton landings past a point of a run (a cut, a dead end, a fold) and their comparison with
//! the run's crossings of the landing's frequency: the evidence every judgement rests on.

use std::f64::consts::PI;

use super::checks::{CutCheck, CutVerdict, FoldCheck, Landing, RETRACE_TOLERANCE};
use super::point::{full_point, land_round_fold, newton_at, relative_distance, ROUND_FOLD_CHORD};
use super::status::FrfPoint;
use crate::hbm::operator::HbmOperator;
use crate::numerics::continuation::SAME_SOLUTION_TOLERANCE;
use crate::numerics::Continuation;

/// Offsets past a cut at which [`judge_cuts`](super::judge::judge_cuts) tries Newton, in units of
/// the cut's last frequency step (clamped to [10⁻⁷, 5·10⁻⁴] of the cut's frequency), in the order
/// tried: the first that converges is the landing. Then [`CUT_CHECK_FALLBACKS`].
pub const CUT_CHECK_OFFSETS: &[f64] = &[1.0, 0.25, 0.0625];

/// Offsets past a cut, relative to its frequency, tried when none of [`CUT_CHECK_OFFSETS`]
/// converges: at a dead end Newton at a fixed frequency can fail close past the point (at
/// F0 = 1 N on the paper's system a bridge given up at 152.2176 Hz: no convergence from 10⁻⁷
/// to 5·10⁻⁴ past it, a landing on the run at 10⁻³).
pub const CUT_CHECK_FALLBACKS: &[f64] = &[1e-4, 1e-3];

/// The judgement of a dead end past which Newton at a fixed frequency converges nowhere (`past_hz`
/// the last frequency tried): the stretch may have met a fold of the sampled contact law, a corner
/// where the branch turns back, whose other side the path could not turn onto. That side is sought
/// by Newton with the frequency free on the hyperplane normal to the stretch's chord in the
/// unknowns alone ([`ROUND_FOLD_CHORD`] back, stepped [`ROUND_FOLD_STEPS`](super::ROUND_FOLD_STEPS)
/// past the dead end): where the unknowns go on past the dead-end point, a branch that turned back
/// at a fold lies at a lower frequency (higher on a stretch running down). A landing behind the
/// dead end is judged as the landing past a cut stretch's fold ([`judge_beyond_fold`]: on the run,
/// or below the run's largest amplitude there, is covered). Recorded as a [`CutCheck`] whose own
/// landing is nowhere and whose [`CutCheck::beyond_fold`] is that judgement, the fold at the dead
/// end. None where no such landing converges.
pub(super) fn judge_round_dead_end(
    system: &mut HbmOperator<'_>,
    newton: &Continuation,
    (points, starts): (&[FrfPoint], &[usize]),
    branch: std::ops::Range<usize>,
    i: usize,
    past_hz: f64,
) -> Option<CutCheck> {
    let f = points[i].freq_hz;
    let into: Vec<usize> = if i == branch.start {
        (i + 1..branch.end).collect()
    } else {
        (branch.start..i).rev().collect()
    };
    let a = into
        .iter()
        .copied()
        .find(|&k| (points[k].freq_hz - f).abs() >= ROUND_FOLD_CHORD * f)
        .or_else(|| into.last().copied())?;
    let landing = land_round_fold(system, newton.settings, &points[a], &points[i])?;
    let own = a.min(i)..=a.max(i);
    let compared = compare_with_run(system, newton, points, starts, &own, &landing);
    // A landing on the stretch into the dead end itself (the chord's hyperplane crossing it
    // again behind the point) is no other side: no fold was found.
    if compared.covered && compared.own_side {
        return None;
    }
    let fold = fold_check(f, &compared);
    Some(CutCheck {
        landing: Landing::nowhere(past_hz),
        own_side: false,
        newton_iterations: 0,
        beyond_fold: Some(fold),
        verdict: fold.verdict,
    })
}

/// Newton at fixed frequencies past `f` (Hz) in `direction` (±1) from the coefficients
/// `start`, at the offsets [`CUT_CHECK_OFFSETS`] of `step` (Hz, the last frequency step into
/// `f`, clamped to [10⁻⁷, 5·10⁻⁴] of `f`), then [`CUT_CHECK_FALLBACKS`]: the frequency of the
/// last solve tried (Hz) and the first point that converged, if any.
pub(super) fn land_past(
    system: &mut HbmOperator<'_>,
    newton: &Continuation,
    start: &[f64],
    f: f64,
    direction: f64,
    step: f64,
) -> (f64, Option<FrfPoint>) {
    let guess = system.restrict(start);
    let step = step.clamp(1e-7 * f, 5e-4 * f);
    let mut freq_hz = f;
    let offsets = CUT_CHECK_OFFSETS
        .iter()
        .map(|m| m * step)
        .chain(CUT_CHECK_FALLBACKS.iter().map(|r| r * f));
    for offset in offsets {
        freq_hz = f + direction * offset;
        let Ok(p) = newton.solve_fixed(system, &guess, 2.0 * PI * freq_hz) else {
            continue;
        };
        if let Ok(mut point) = full_point(system, &p) {
            point.freq_hz = freq_hz;
            return (freq_hz, Some(point));
        }
    }
    (freq_hz, None)
}

/// The judgement past the fold at `fold_hz` (Hz) of a cut stretch that came back along its
/// own other side ([`CutCheck::beyond_fold`]): `landing`, solved at `freq_hz` (Hz) past the
/// fold, compared with the run ([`compare_with_run`]).
#[allow(clippy::too_many_arguments)]
pub(super) fn judge_beyond_fold(
    system: &mut HbmOperator<'_>,
    newton: &Continuation,
    points: &[FrfPoint],
    starts: &[usize],
    own: &std::ops::RangeInclusive<usize>,
    fold_hz: f64,
    freq_hz: f64,
    landing: Option<FrfPoint>,
) -> FoldCheck {
    let Some(landing) = landing else {
        return FoldCheck {
            fold_hz,
            landing: Landing::nowhere(freq_hz),
            run_amplitude: None,
            verdict: CutVerdict::Unjudged,
        };
    };
    let compared = compare_with_run(system, newton, points, starts, own, &landing);
    fold_check(fold_hz, &compared)
}

/// The judgement past the fold at `fold_hz` (Hz) of a landing `compared` with the run: on a
/// stretch, or below the run's largest amplitude there, covered; else abandoned.
fn fold_check(fold_hz: f64, compared: &Comparison) -> FoldCheck {
    let below_run = |run: f64| compared.landing.amplitude.is_some_and(|a| a <= run);
    let verdict = match compared.run_amplitude {
        _ if compared.covered => CutVerdict::Covered,
        Some(run) if below_run(run) => CutVerdict::Covered,
        _ => CutVerdict::Abandoned,
    };
    FoldCheck {
        fold_hz,
        landing: compared.landing,
        run_amplitude: compared.run_amplitude,
        verdict,
    }
}

/// How a landing compares with the run ([`compare_with_run`]).
pub(super) struct Comparison {
    /// The landing, at its frequency, with [`Landing::distance`] and
    /// [`Landing::resolved_distance`] from this comparison.
    pub(super) landing: Landing,
    /// [`CutCheck::own_side`].
    pub(super) own_side: bool,
    /// Whether Newton from a crossing within [`RETRACE_TOLERANCE`] found the landing.
    pub(super) covered: bool,
    /// The largest first-output amplitude of the run's crossings of the landing's frequency
    /// (m); None without a crossing.
    pub(super) run_amplitude: Option<f64>,
}

/// Compares `landing` with every crossing of its frequency by the run's `points` within a
/// branch (not across a jump at `starts`), those inside `own` marked as the cut's own side:
/// each crossing within [`RETRACE_TOLERANCE`] on the coefficients, nearest first, is solved
/// again by Newton at the landing's frequency ([`resolve_crossing`]), and the first whose
/// solution is the landing (within [`SAME_SOLUTION_TOLERANCE`]) covers it.
pub(super) fn compare_with_run(
    system: &mut HbmOperator<'_>,
    newton: &Continuation,
    points: &[FrfPoint],
    starts: &[usize],
    own: &std::ops::RangeInclusive<usize>,
    landing: &FrfPoint,
) -> Comparison {
    let freq_hz = landing.freq_hz;
    let norm = crate::numerics::linalg::norm(&landing.coefficients);
    let mut run_amplitude: Option<f64> = None;
    // Every crossing of the landing's frequency within a branch, nearest first.
    let mut crossings: Vec<Crossing> = (0..points.len().saturating_sub(1))
        .filter(|&k| !starts.contains(&(k + 1)))
        .filter_map(|k| {
            let (p, q) = (&points[k], &points[k + 1]);
            if (p.freq_hz - freq_hz) * (q.freq_hz - freq_hz) > 0.0 || p.freq_hz == q.freq_hz {
                return None;
            }
            let t = (freq_hz - p.freq_hz) / (q.freq_hz - p.freq_hz);
            if let (Some(a), Some(b)) = (p.amplitudes.first(), q.amplitudes.first()) {
                let on = a + t * (b - a);
                run_amplitude = Some(run_amplitude.map_or(on, |r| r.max(on)));
            }
            let squared: f64 = landing
                .coefficients
                .iter()
                .zip(p.coefficients.iter().zip(&q.coefficients))
                .map(|(c, (a, b))| (c - (a + t * (b - a))).powi(2))
                .sum();
            Some(Crossing {
                segment: k,
                t,
                distance: squared.sqrt() / norm,
                own_side: own.contains(&k) && own.contains(&(k + 1)),
            })
        })
        .collect();
    crossings.sort_by(|a, b| a.distance.total_cmp(&b.distance));
    let omega = 2.0 * PI * freq_hz;
    let mut covered = false;
    let mut resolved: Option<(&Crossing, Option<f64>)> = None;
    for crossing in crossings
        .iter()
        .take_while(|c| c.distance <= RETRACE_TOLERANCE)
    {
        let apart = resolve_crossing(system, newton, points, crossing, omega, landing);
        let covers = apart.is_some_and(|d| d <= SAME_SOLUTION_TOLERANCE);
        if resolved.is_none() || covers {
            resolved = Some((crossing, apart));
        }
        if covers {
            covered = true;
            break;
        }
    }
    let shown = resolved.map(|(c, _)| c).or(crossings.first());
    Comparison {
        landing: Landing {
            freq_hz,
            amplitude: Some(landing.amplitudes.first().copied().unwrap_or(f64::NAN)),
            distance: shown.map(|c| c.distance),
            resolved_distance: resolved.and_then(|(_, d)| d),
        },
        own_side: shown.is_some_and(|c| c.own_side),
        covered,
        run_amplitude,
    }
}

/// A crossing of a frequency by a segment of the run's points (see
/// [`judge_cut`](super::judge::judge_cut)).
struct Crossing {
    /// Index of the segment's first point.
    pub(super) segment: usize,
    /// Where along the segment, from its first point (0) to its second (1).
    pub(super) t: f64,
    /// ‖c − c_run‖ / ‖c‖ between the landing and the linear interpolation along the segment.
    pub(super) distance: f64,
    /// Whether the segment lies on the cut's own side of its fold ([`CutCheck::own_side`]).
    pub(super) own_side: bool,
}

/// ‖c − c_N‖ / ‖c‖ between `landing` (converged at ω = `omega`, rad/s) and Newton's solution
/// c_N at the same ω from `crossing`: from its coefficients interpolated along the segment,
/// and, unless that solution is the landing, from those of the segment's nearer point; the
/// smaller of the two. The same solution to solver precision when at most
/// [`SAME_SOLUTION_TOLERANCE`]: where neighbouring pieces of the sampled contact law lie a few
/// 10⁻³ apart, the two starts can reach different ones (on the paper's system at F0 = 2 N, at
/// 153.2274 Hz, the interpolated start a solution 3.2·10⁻³ from the landing, the nearer point
/// the landing itself). None when Newton converges from neither.
fn resolve_crossing(
    system: &mut HbmOperator<'_>,
    newton: &Continuation,
    points: &[FrfPoint],
    crossing: &Crossing,
    omega: f64,
    landing: &FrfPoint,
) -> Option<f64> {
    let (p, q) = (&points[crossing.segment], &points[crossing.segment + 1]);
    let t = crossing.t;
    let interpolated: Vec<f64> = p
        .coefficients
        .iter()
        .zip(&q.coefficients)
        .map(|(a, b)| a + t * (b - a))
        .collect();
    let nearer = if t < 0.5 { p } else { q };
    let mut apart: Option<f64> = None;
    for start in [interpolated.as_slice(), nearer.coefficients.as_slice()] {
        if let Some(c) = newton_at(system, newton, start, omega) {
            let d = relative_distance(&c, &landing.coefficients);
            apart = Some(apart.map_or(d, |a| a.min(d)));
            if d <= SAME_SOLUTION_TOLERANCE {
                break;
            }
        }
    }
    apart
}
