//! Branches past a run's jumps: the branch found past a fold, fills back down toward it and
//! bridges over stretches no branch reached, with their leaps placed in the run's report.

use std::collections::VecDeque;
use std::f64::consts::PI;

use super::cuts::fill_cut;
use super::observer::{Adapter, Silent};
use super::status::{BranchEnd, FrfError, FrfPoint, GivenUp, Jump, JumpKind};
use crate::analysis::estimate_pool::EstimatePool;
use crate::analysis::linear;
use crate::contact::harmonic::HarmonicSet;
use crate::hbm::operator::HbmOperator;
use crate::model::Problem;
use crate::numerics::continuation::AdaptiveScale;
use crate::numerics::{Continuation, ContinuationSettings, PathSummary};

/// How far past the highest frequency a path reached a jump lands, as fractions of the range,
/// tried in turn until a point converges there.
const JUMP_FRACTIONS: &[f64] = &[0.0005, 0.002, 0.005, 0.01, 0.02, 0.03, 0.05, 0.1, 0.2];

/// Point budget of each direction of a bridge branch (see [`Branching::bridge`]).
const BRIDGE_POINTS: usize = 300;

/// Most branches solved inside the stretches left uncovered by one jump.
const MAX_BRIDGES: usize = 8;

/// Where in an uncovered stretch a bridge branch is sought, as fractions of the stretch, in
/// the order tried.
const BRIDGE_FRACTIONS: &[f64] = &[0.5, 0.25, 0.75, 0.1, 0.9];

/// Weights w of the blends (1 − w)·lower end + w·upper end of the stretch's end points'
/// coefficients tried as Newton guesses, in the order tried.
const BRIDGE_BLENDS: &[f64] = &[0.5, 0.25, 0.75, 0.0, 1.0];

/// What the branches of one run share: the settings, the arc-length scale, how it grows and
/// which amplitudes the steps follow.
pub(super) struct Branching<'a> {
    pub(super) settings: ContinuationSettings,
    pub(super) x_scale: &'a [f64],
    pub(super) adaptive: &'a AdaptiveScale,
    pub(super) amplitude_groups: &'a [Vec<usize>],
}

impl Branching<'_> {
    /// Follows the path silently from `x` (the operator's unknowns, converged at `from_hz`)
    /// toward `to_hz` (below or above) with at most `max_points` points. Returns the points in
    /// path order (the first is the start point) and the summary, None when the continuation
    /// failed (its points up to the failure are kept). With `estimates`, each point gets
    /// its error estimate across the path as it is accepted (or, formed on a worker, pending
    /// until the run reports the point).
    pub(super) fn follow(
        &self,
        system: &mut HbmOperator<'_>,
        x: &[f64],
        from_hz: f64,
        to_hz: f64,
        max_points: usize,
        estimates: Option<&EstimatePool<'_>>,
    ) -> (Vec<FrfPoint>, Option<PathSummary>) {
        let settings = ContinuationSettings {
            freq_start_hz: from_hz,
            freq_end_hz: to_hz,
            max_points,
            ..self.settings
        };
        let mut collect = Adapter {
            observer: &mut Silent,
            points: Vec::new(),
            failure: None,
            estimates,
            in_order: false,
            held: VecDeque::new(),
        };
        let mut continuation = Continuation::new(settings, self.x_scale.to_vec())
            .with_adaptive_scale(self.adaptive.clone())
            .with_amplitude_steps(self.amplitude_groups.to_vec());
        let summary = continuation.run(system, x, &mut collect).ok();
        (std::mem::take(&mut collect.points), summary)
    }

    /// Branches inside the stretch between `below` (the highest point of the branch before a
    /// jump) and `above` (the lowest point of the branch after it), which neither reached.
    ///
    /// At a fold of the sampled contact law's solution curve, two branches can fold away from
    /// each other with solutions between them on neither (a damper bouncing at a low
    /// pre-load). Newton from blends of the two ends' coefficients ([`BRIDGE_BLENDS`]) at
    /// points inside the stretch ([`BRIDGE_FRACTIONS`]) finds such solutions; each is followed
    /// down toward `below` and up toward `above`, and what is still uncovered on either side
    /// is bridged in turn, up to [`MAX_BRIDGES`] branches and `budget` points. Returns the
    /// branches found, each in path order from its lowest point up, sorted by their lowest
    /// frequency, with the cuts of its way down and of its way up (see [`fill_cut`]).
    pub(super) fn bridge(
        &self,
        system: &mut HbmOperator<'_>,
        below: &FrfPoint,
        above: &FrfPoint,
        budget: usize,
        estimates: Option<&EstimatePool<'_>>,
        (followed, branch_starts): (&[FrfPoint], &[usize]),
    ) -> Vec<BridgeBranch> {
        let mut branches: Vec<BridgeBranch> = Vec::new();
        let mut gaps = vec![(below.clone(), above.clone())];
        let mut used = 0;
        let solver = Continuation::new(self.settings, self.x_scale.to_vec());
        while let Some((lo, hi)) = gaps.pop() {
            if branches.len() >= MAX_BRIDGES || used + 2 > budget {
                break;
            }
            let Some((freq_hz, x)) = solve_between(system, &solver, &lo, &hi) else {
                continue;
            };
            let per_side = BRIDGE_POINTS.min((budget - used) / 2);
            let (mut down, down_end) =
                self.follow(system, &x, freq_hz, lo.freq_hz, per_side, estimates);
            let (up, up_end) = self.follow(system, &x, freq_hz, hi.freq_hz, per_side, estimates);
            // Either way turned back at a fold of its own before its edge, or was given up or
            // ran out of points before it: cut there (both ways may be).
            let cut_of = |side: &[FrfPoint], travel_down: bool, end: &Option<PathSummary>| {
                end.as_ref().and_then(|summary| {
                    fill_cut(
                        followed,
                        branch_starts,
                        side,
                        travel_down,
                        summary.end,
                        summary.turning_points.last().copied(),
                    )
                })
            };
            let cuts = [cut_of(&down, true, &down_end), cut_of(&up, false, &up_end)];
            // The leaps of both ways as placed in the branch: the way down reversed, then the
            // way up without its first point (the way down's first).
            let down_len = down.len();
            let mut leap_points = down_end
                .as_ref()
                .map_or(Vec::new(), |s| reversed_leaps(&s.leap_landings, down_len));
            leap_points.extend(
                up_end
                    .as_ref()
                    .map_or(Vec::new(), |s| forward_leaps(&s.leap_landings, 1, down_len)),
            );
            down.reverse();
            // Both directions start with the point at `freq_hz`: keep one.
            let branch: Vec<FrfPoint> = down.into_iter().chain(up.into_iter().skip(1)).collect();
            used += branch.len();
            let by_freq = |a: &&FrfPoint, b: &&FrfPoint| a.freq_hz.total_cmp(&b.freq_hz);
            let (Some(low), Some(high)) =
                (branch.iter().min_by(by_freq), branch.iter().max_by(by_freq))
            else {
                continue;
            };
            let gap_below = Jump {
                from_hz: lo.freq_hz,
                to_hz: low.freq_hz,
                first_point: 0,
                kind: JumpKind::Bridge,
                before: BranchEnd::Bridge,
                fill_cut: None,
                cut_check: None,
                second_cut: None,
                second_cut_check: None,
                end_check: None,
            };
            if gap_below.uncovered_hz() > 0.0 {
                gaps.push((lo.clone(), low.clone()));
            }
            let gap_above = Jump {
                from_hz: high.freq_hz,
                to_hz: hi.freq_hz,
                ..gap_below
            };
            if gap_above.uncovered_hz() > 0.0 {
                gaps.push((high.clone(), hi.clone()));
            }
            let ways = [&down_end, &up_end];
            let summaries = || ways.iter().filter_map(|w| w.as_ref());
            branches.push(BridgeBranch {
                points: branch,
                cuts,
                turning_points: summaries()
                    .flat_map(|s| s.turning_points.iter().copied())
                    .collect(),
                rejected_steps: summaries().map(|s| s.rejected_steps).sum(),
                leaps: summaries().flat_map(|s| s.leaps.iter().copied()).collect(),
                leap_points,
            });
        }
        branches.sort_by(|a, b| a.points[0].freq_hz.total_cmp(&b.points[0].freq_hz));
        branches
    }
}

/// One branch solved inside a stretch no branch reached ([`Branching::bridge`]): its points
/// from its lowest up, the cuts of its way down and of its way up ([`fill_cut`]), and what the
/// continuation met on the two ways: turning points (Hz), rejected steps and leaps (each as
/// (last point before, first point after) in the way's own direction of travel, Hz).
pub(super) struct BridgeBranch {
    pub(super) points: Vec<FrfPoint>,
    pub(super) cuts: [Option<GivenUp>; 2],
    pub(super) turning_points: Vec<f64>,
    pub(super) rejected_steps: usize,
    pub(super) leaps: Vec<(f64, f64)>,
    /// The indices in `points` of each leap's point before and landing, in the order of
    /// `leaps`.
    pub(super) leap_points: Vec<Option<(usize, usize)>>,
}

/// The (point before, landing) indices of the leaps of a path of `len` points, whose landings
/// are the path's points `landings` ([`PathSummary::leap_landings`]), in a report that lists
/// the path in reverse: path point k at `len − 1 − k` (the path's first point last; where the
/// report leaves that point out, the index `len − 1` is the point reported right after).
pub(super) fn reversed_leaps(landings: &[usize], len: usize) -> Vec<Option<(usize, usize)>> {
    landings
        .iter()
        .map(|&l| Some((len.checked_sub(l)?, len.checked_sub(l + 1)?)))
        .collect()
}

/// The (point before, landing) indices of the leaps of a path whose landings are its points
/// `landings`, in a report that lists the path in order from its point `first` at index
/// `offset` (the points before `first` left out).
pub(super) fn forward_leaps(
    landings: &[usize],
    first: usize,
    offset: usize,
) -> Vec<Option<(usize, usize)>> {
    landings
        .iter()
        .map(|&l| {
            Some((
                (l.checked_sub(1)? + offset).checked_sub(first)?,
                (l + offset).checked_sub(first)?,
            ))
        })
        .collect()
}

/// A converged point strictly between `lo` and `hi` (Hz and operator unknowns), by Newton at
/// fixed frequency from blends of their coefficients (see [`Branching::bridge`]).
fn solve_between(
    system: &mut HbmOperator<'_>,
    solver: &Continuation,
    lo: &FrfPoint,
    hi: &FrfPoint,
) -> Option<(f64, Vec<f64>)> {
    for fraction in BRIDGE_FRACTIONS {
        let freq_hz = lo.freq_hz + fraction * (hi.freq_hz - lo.freq_hz);
        let omega = 2.0 * PI * freq_hz;
        for w in BRIDGE_BLENDS {
            let blend: Vec<f64> = lo
                .coefficients
                .iter()
                .zip(&hi.coefficients)
                .map(|(a, b)| (1.0 - w) * a + w * b)
                .collect();
            let guess = system.restrict(&blend);
            if let Ok(p) = solver.solve_fixed(system, &guess, omega) {
                return Some((freq_hz, p.x));
            }
        }
    }
    None
}

/// A converged point just past `highest` (Hz) on whatever branch Newton finds there, for the
/// path to go on from after a fold it did not come back from: at each of [`JUMP_FRACTIONS`] of
/// the range past `highest` (capped at the end frequency), from the stuck linear guess there,
/// the open-contact one (harmonics of the open structure on the stuck static state), then from
/// the highest point solved so far. Returns the frequency and the operator's
/// unknowns, or None when no guess converges.
pub(super) fn jump_target(
    problem: &Problem,
    set: &HarmonicSet,
    system: &mut HbmOperator<'_>,
    continuation: &Continuation,
    points: &[FrfPoint],
    highest: f64,
) -> Result<Option<(f64, Vec<f64>)>, FrfError> {
    let settings = &problem.analysis.continuation;
    let range = settings.freq_end_hz - settings.freq_start_hz;
    let top = points.iter().find(|p| p.freq_hz == highest);
    for fraction in JUMP_FRACTIONS {
        let freq_hz = (highest + fraction * range).min(settings.freq_end_hz);
        if freq_hz <= highest {
            return Ok(None);
        }
        let omega = 2.0 * PI * freq_hz;
        let mut guesses = vec![
            system.restrict(&linear::stuck_guess(problem, set, omega)?),
            system.restrict(&linear::open_guess(problem, set, omega)?),
        ];
        if let Some(p) = top {
            guesses.push(system.restrict(&p.coefficients));
        }
        for g in guesses {
            if let Ok(p) = continuation.solve_fixed(system, &g, omega) {
                return Ok(Some((freq_hz, p.x)));
            }
        }
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A leap's recorded landing placed in the report: a path reported in order from its
    /// point `first` at `offset`, or in reverse (its first point last, or left out with the
    /// point reported after the path in its place); a point before that the report does not
    /// hold gives none.
    #[test]
    fn leap_landings_are_placed_where_the_report_puts_the_path() {
        // The main path at offset 10: landing 1 and 3 (before 0 and 2).
        assert_eq!(
            forward_leaps(&[1, 3], 0, 10),
            vec![Some((10, 11)), Some((12, 13))]
        );
        // A bridge's way up after its way down of 4 points, its first point (the way down's
        // first) not repeated: path point k at 4 − 1 + k.
        assert_eq!(
            forward_leaps(&[1, 3], 1, 4),
            vec![Some((3, 4)), Some((5, 6))]
        );
        // A way up with no way down before it: the point before its first leap is not there.
        assert_eq!(forward_leaps(&[1, 2], 1, 0), vec![None, Some((0, 1))]);
        // A path of 5 points in reverse: path point k at 4 − k.
        assert_eq!(reversed_leaps(&[1, 3], 5), vec![Some((4, 3)), Some((2, 1))]);
    }
}
