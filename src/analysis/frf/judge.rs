//! The judgements of a finished run: each cut, abandoned branch end and leap, by Newton past it
//! compared with the run, so that the run's status says what response may be missing.

use std::f64::consts::PI;

use super::branches::Branching;
use super::checks::{CutCheck, CutVerdict, Landing, LeapCheck, RETRACE_TOLERANCE};
use super::landing::{compare_with_run, judge_beyond_fold, judge_round_dead_end, land_past};
use super::observer::FrfObserver;
use super::point::{newton_at, relative_distance};
use super::status::{BranchEnd, FrfPoint, FrfRun, GiveUpCause, GivenUp};
use crate::hbm::operator::HbmOperator;
use crate::numerics::{Continuation, PathEnd};

/// The step, relative to the frequency, of which [`CUT_CHECK_OFFSETS`](super::CUT_CHECK_OFFSETS)
/// are taken past a point given up at a dead end ([`GiveUpCause::DeadEnd`]; see [`judge_cut`]): the
/// largest a cut's last step is clamped to. On the paper's system at F0 = 2 N Newton from the dead
/// end at 153.0743 Hz converges 6·10⁻⁹ of the frequency past it (the branch's own next bit, 2
/// Newton iterations), at none of 10⁻⁷ to 5·10⁻⁴, and on the run 10⁻³ past it.
pub const DEAD_END_CHECK_STEP: f64 = 5e-4;

/// Judges the cuts of every jump of `run` ([`Jump::fill_cut`](super::Jump::fill_cut),
/// [`Jump::second_cut`](super::Jump::second_cut)), and the last point of every branch abandoned
/// before a jump ([`BranchEnd::Abandoned`]), now that every branch of the run is known, sets their
/// [`Jump::cut_check`](super::Jump::cut_check),
/// [`Jump::second_cut_check`](super::Jump::second_cut_check) and
/// [`Jump::end_check`](super::Jump::end_check) and tells `observer` ([`FrfObserver::cut_judged`]).
/// A branch given up at a dead end or for want of progress off every stretch followed is judged as
/// a cut is: the point given up, like a cut, is where the run stopped following a branch, and only
/// Newton past it tells whether that branch goes on off the run (on the paper's system at F0 = 2 N
/// the dead end at 153.0743 Hz: Newton 10⁻³ of the frequency past it lands 0.24 % from the nearest
/// stretch of the run, and Newton from that stretch's nearer point converges to the landing:
/// covered). Past a dead end the offsets are taken of [`DEAD_END_CHECK_STEP`]; where Newton
/// converges at none of them, the other side of a fold at the dead end is sought with the frequency
/// free ([`judge_round_dead_end`]: on the 3D blade pair's m = −1 limit curve the dead end at
/// 869.0841 Hz turns back there, its other side at 869.0661 Hz below the run: covered; on the 2D
/// blade pair's m = +1 limit curve at 5 N neither converges past the dead end at 875.5021 Hz:
/// unjudged).
///
/// Newton at a fixed frequency just past the cut, in the direction its stretch was going at its
/// last step (away from the point before it on the branch; by its fold when the branch holds the
/// cut point alone), from the cut point's coefficients, at the offsets
/// [`CUT_CHECK_OFFSETS`](super::CUT_CHECK_OFFSETS) then
/// [`CUT_CHECK_FALLBACKS`](super::CUT_CHECK_FALLBACKS) until one converges: at most five
/// fixed-frequency solves per cut, one where Newton converges just past it. The landing is
/// compared, over all its Fourier coefficients, with every crossing of its frequency by the run's
/// points (linear along a segment within a branch, not across a jump), the cut's own branch
/// included (a crossing on the other side of the cut's fold is recorded as [`CutCheck::own_side`]).
/// Each crossing within [`RETRACE_TOLERANCE`], nearest first, is then solved again by Newton at the
/// landing's frequency, from its interpolated coefficients (else from the segment's nearer point):
/// the first whose solution is the landing (within [`SAME_SOLUTION_TOLERANCE`]) covers the cut.
/// When none does the branch goes on beyond the cut unfollowed ([`CutVerdict::Abandoned`]): next to
/// a fold of the cut's own stretch its two sides lie within the tolerance of each other, so a
/// landing on the branch beyond the cut is that close to the side already followed, and only Newton
/// from that side tells them apart. When no solve past the cut converges the cut is
/// [`CutVerdict::Unjudged`]; the status counts both as not covered.
pub(super) fn judge_cuts<O: FrfObserver>(
    system: &mut HbmOperator<'_>,
    newton: &Continuation,
    run: &mut FrfRun,
    observer: &mut O,
) {
    let starts = run.branch_starts();
    for k in 0..run.jumps.len() {
        let jump = run.jumps[k];
        // The branch before the jump, given up off every stretch followed: its last point is
        // the last of the branch that ends at the jump.
        let end_check = match &jump.before {
            BranchEnd::Abandoned(given_up) => {
                let branch = k.checked_sub(1).map_or(0, |j| starts[j])..jump.first_point;
                Some(judge_cut(
                    system,
                    newton,
                    &run.points,
                    &starts,
                    branch,
                    given_up,
                ))
            }
            _ => None,
        };
        run.jumps[k].end_check = end_check;
        if jump.fill_cut.is_none() && jump.second_cut.is_none() {
            if end_check.is_some() {
                observer.cut_judged(k, &run.jumps[k]);
            }
            continue;
        }
        let first = jump.first_point;
        let end = starts
            .get(k + 1)
            .copied()
            .unwrap_or(run.points.len())
            .max(first);
        let mut judge =
            |cut: &GivenUp| judge_cut(system, newton, &run.points, &starts, first..end, cut);
        let checks = (
            jump.fill_cut.as_ref().map(&mut judge),
            jump.second_cut.as_ref().map(&mut judge),
        );
        run.jumps[k].cut_check = checks.0;
        run.jumps[k].second_cut_check = checks.1;
        observer.cut_judged(k, &run.jumps[k]);
    }
}

/// Most points of the path followed back from a leap's landing ([`judge_leaps`]).
pub const LEAP_CHECK_POINTS: usize = 300;

/// Judges every leap of the run ([`LeapCheck`]): from the leap's landing (the first point
/// after it) the path is followed back to the frequency of the point before it, with the
/// run's continuation settings and scales and at most [`LEAP_CHECK_POINTS`] points, and the
/// solution it reaches there is compared with Newton's solution at that frequency started
/// from the point before the leap. On one solution curve the path followed back comes round
/// to that point (through whatever the leap passed over); where the leap crossed a fold onto
/// another curve, the path back reaches the frequency on that other curve first.
pub(super) fn judge_leaps<O: FrfObserver>(
    system: &mut HbmOperator<'_>,
    newton: &Continuation,
    branching: &Branching<'_>,
    run: &mut FrfRun,
    observer: &mut O,
) {
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1.0);
    let starts = run.branch_starts();
    for k in 0..run.leaps.len() {
        let (from_hz, to_hz) = run.leaps[k];
        // (before, landing) as recorded, checked against the leap's frequencies.
        let at = run.leap_points.get(k).copied().flatten().filter(|&(b, l)| {
            match (run.points.get(b), run.points.get(l)) {
                (Some(b), Some(l)) => close(b.freq_hz, from_hz) && close(l.freq_hz, to_hz),
                _ => false,
            }
        });
        let mut check = LeapCheck {
            from_hz,
            to_hz,
            before_amplitude: None,
            back_amplitude: None,
            distance: None,
            points: 0,
            verdict: CutVerdict::Unjudged,
            past: None,
        };
        if let Some((b, l)) = at {
            let (before, landing) = (&run.points[b], &run.points[l]);
            check.before_amplitude = before.amplitudes.first().copied();
            let x = system.restrict(&landing.coefficients);
            let (back, summary) =
                branching.follow(system, &x, to_hz, from_hz, LEAP_CHECK_POINTS, None);
            check.points = back.len();
            let reached = summary.is_some_and(|s| s.end == PathEnd::EndFrequency);
            if let (true, Some(end)) = (reached, back.last()) {
                check.back_amplitude = end.amplitudes.first().copied();
                let omega = 2.0 * PI * end.freq_hz;
                if let Some(own) = newton_at(system, newton, &before.coefficients, omega) {
                    let d = relative_distance(&end.coefficients, &own);
                    check.distance = Some(d);
                    check.verdict = if d <= RETRACE_TOLERANCE {
                        CutVerdict::Covered
                    } else {
                        CutVerdict::Abandoned
                    };
                }
            }
            if check.verdict == CutVerdict::Abandoned {
                let past = judge_past_leap(system, newton, &run.points, &starts, (b, l));
                if let Some(past) = past {
                    check.verdict = past.verdict;
                    check.past = Some(past);
                }
            }
        }
        observer.leap_judged(&check);
        run.leap_checks.push(check);
    }
}

/// The branch through the point before a leap onto another branch (`before`, `landing`:
/// indices of the point before the leap and of the landing in `points`), judged as a branch
/// given up at a dead end ([`judge_cut`]): the corrector failed at every step past that point,
/// as at a dead end. None when the point is the first of its stretch (no direction to go on
/// in).
fn judge_past_leap(
    system: &mut HbmOperator<'_>,
    newton: &Continuation,
    points: &[FrfPoint],
    starts: &[usize],
    (before, landing): (usize, usize),
) -> Option<CutCheck> {
    // The stretch into the point before the leap, within its branch: the point before it
    // along the path is on the side away from the landing.
    let branch_start = starts
        .iter()
        .copied()
        .filter(|&s| s <= before)
        .max()
        .unwrap_or(0);
    let branch_end = starts
        .iter()
        .copied()
        .filter(|&s| s > before)
        .min()
        .unwrap_or(points.len());
    let stretch = if landing > before {
        branch_start..before + 1
    } else {
        before..branch_end
    };
    if stretch.len() < 2 {
        return None;
    }
    let given_up = GivenUp {
        freq_hz: points[before].freq_hz,
        amplitude: points[before]
            .amplitudes
            .first()
            .copied()
            .unwrap_or(f64::NAN),
        amplitude_rising: false,
        fold_hz: None,
        cause: GiveUpCause::DeadEnd,
    };
    Some(judge_cut(
        system, newton, points, starts, stretch, &given_up,
    ))
}

/// The judgement of one cut `cut` of the branch `points[branch]` (see [`judge_cuts`]).
fn judge_cut(
    system: &mut HbmOperator<'_>,
    newton: &Continuation,
    points: &[FrfPoint],
    starts: &[usize],
    branch: std::ops::Range<usize>,
    cut: &GivenUp,
) -> CutCheck {
    let unjudged = |freq_hz: f64, newton_iterations: usize| CutCheck {
        landing: Landing::nowhere(freq_hz),
        own_side: false,
        newton_iterations,
        beyond_fold: None,
        verdict: CutVerdict::Unjudged,
    };
    let is_cut = |p: &FrfPoint| {
        p.freq_hz == cut.freq_hz
            && p.amplitudes
                .first()
                .map_or(cut.amplitude.is_nan(), |&a| a == cut.amplitude)
    };
    // The cut point is the first or the last of its branch (the fill is reported from the
    // cut up; a bridge from its lower end, cut or not, to its upper end).
    let Some(i) = [branch.start, branch.end.saturating_sub(1)]
        .into_iter()
        .find(|&i| branch.contains(&i) && is_cut(&points[i]))
    else {
        return unjudged(cut.freq_hz, 0);
    };
    let f = cut.freq_hz;
    // The point before the cut along the stretch, skipping points at the same frequency.
    let before = if i == branch.start {
        points[i + 1..branch.end]
            .iter()
            .find(|p| p.freq_hz != f)
            .map(|p| p.freq_hz)
    } else {
        points[branch.start..i]
            .iter()
            .rev()
            .find(|p| p.freq_hz != f)
            .map(|p| p.freq_hz)
    };
    let (direction, step) = match before {
        Some(b) => ((f - b).signum(), (f - b).abs()),
        None => {
            let down = cut.fold_hz.is_some_and(|fold| fold >= f);
            (if down { -1.0 } else { 1.0 }, 1e-4 * f)
        }
    };
    // At a dead end the corrector failed at every step down to the minimum, so the last
    // step is tiny, and a landing that close past the point is the branch's own next bit,
    // which no stretch holds by construction: there the judgement steps as far as a cut's
    // largest step.
    let step = if cut.cause == GiveUpCause::DeadEnd {
        DEAD_END_CHECK_STEP * f
    } else {
        step
    };
    let (freq_hz, landing) = land_past(system, newton, &points[i].coefficients, f, direction, step);
    let Some(landing) = landing else {
        // Nothing past a dead end: the branch may turn back there, at a fold whose other side
        // runs back beside the stretch into it.
        if cut.cause == GiveUpCause::DeadEnd {
            if let Some(check) =
                judge_round_dead_end(system, newton, (points, starts), branch, i, freq_hz)
            {
                return check;
            }
        }
        return unjudged(freq_hz, 0);
    };
    // The cut's own stretch and the one before it on its branch (the other side of the fold
    // it turned back at): next to a fold its two sides lie within the tolerance of each
    // other, so the comparison by interpolation does not tell the branch beyond the cut from
    // the side already followed; nor can that side be left out (at F0 = 5 N on the paper's
    // system the landings 10⁻⁷ to 2·10⁻³ past the cut at 80.4161 Hz follow that side within
    // 0.002-0.18 %, as close as its linear interpolation over a 0.75 Hz segment allows, and
    // no other stretch crosses there). Newton from the crossing tells them apart.
    let away: Vec<usize> = if i == branch.start {
        (i..branch.end).collect()
    } else {
        (branch.start..=i).rev().collect()
    };
    let mut turns = 0;
    let mut heading = 0.0;
    let mut reach = 0;
    // The fold the cut's stretch turned back at: the point where the way back from the cut
    // first turns.
    let mut fold = None;
    for w in 1..away.len() {
        let d = (points[away[w]].freq_hz - points[away[w - 1]].freq_hz).signum();
        if d != 0.0 && heading != 0.0 && d != heading {
            turns += 1;
            fold.get_or_insert(w - 1);
            if turns == 2 {
                break;
            }
        }
        if d != 0.0 {
            heading = d;
        }
        reach = w;
    }
    let own = away.get(reach).map_or(i..=i, |&j| i.min(j)..=i.max(j));
    let compared = compare_with_run(system, newton, points, starts, &own, &landing);
    // Landed on the cut's own other side, the same solution: the stretch came back along
    // the side it had followed into its fold, so that fold is where the path reversed on one
    // solution curve, and the branch goes on beyond it, the way that side was heading.
    let beyond_fold = match (compared.covered, compared.own_side, fold) {
        (true, true, Some(w)) => {
            let j = away[w];
            let fold_hz = points[j].freq_hz;
            let into = away[w + 1..]
                .iter()
                .map(|&k| points[k].freq_hz)
                .find(|&g| g != fold_hz);
            into.map(|g| {
                let (freq_hz, landing) = land_past(
                    system,
                    newton,
                    &points[j].coefficients,
                    fold_hz,
                    (fold_hz - g).signum(),
                    (fold_hz - g).abs(),
                );
                judge_beyond_fold(
                    system, newton, points, starts, &own, fold_hz, freq_hz, landing,
                )
            })
        }
        _ => None,
    };
    let verdict = match (&beyond_fold, compared.covered) {
        (Some(b), _) => b.verdict,
        (None, true) => CutVerdict::Covered,
        (None, false) => CutVerdict::Abandoned,
    };
    CutCheck {
        landing: compared.landing,
        own_side: compared.own_side,
        newton_iterations: landing.newton_iterations,
        beyond_fold,
        verdict,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::frf::observer::Silent;
    use crate::analysis::frf::run::solve;
    use crate::analysis::frf::scale::arc_length_x_scale;
    use crate::model::Problem;
    use crate::numerics::continuation::SAME_SOLUTION_TOLERANCE;

    /// The paper's system at F0 = 1 N, for [`judge_cut`] at its real folds.
    fn paper_at_1n() -> Problem {
        crate::scene::parse(
            crate::scene::PAPER_DEFAULT_SCENE,
            "paper",
            &["static_loads.0.value=-1".to_string()],
        )
        .and_then(|s| s.validate("paper"))
        .expect("the built-in scene is valid")
    }

    /// At the real folds of the paper's system at F0 = 1 N: a stretch followed into a fold
    /// and one point back out of it, cut there (as a fill or bridge stopping at its edge).
    /// Newton one step past the cut lands on the branch beyond it. Where the other side of the
    /// fold (the cut stretch's own side) crosses that frequency within 1 % of the landing,
    /// linear interpolation cannot tell them apart, but Newton at that frequency from the
    /// other side converges to another solution: the cut is not covered. With the branch
    /// beyond the cut in the run (the points the FRF followed there, as another branch), the
    /// same landing is covered, Newton from that branch converging to it.
    #[test]
    fn a_landing_beyond_a_fold_of_its_own_stretch_is_told_from_the_other_side_by_newton() {
        let problem = paper_at_1n();
        let run = solve(&problem, &mut Silent).unwrap();
        let starts = run.branch_starts();
        let mut system = HbmOperator::new(&problem).unwrap();
        let set = system.unknowns().clone();
        let x_scale = arc_length_x_scale(&problem, &set, &system).unwrap();
        let newton = Continuation::new(problem.analysis.continuation, x_scale);
        let p = &run.points;
        let direction = |k: usize| (p[k + 1].freq_hz - p[k].freq_hz).signum();
        let same_branch = |a: usize, b: usize| !starts.iter().any(|&s| s > a && s <= b);
        let mut told = 0;
        for k in 1..p.len().saturating_sub(2) {
            // A fold at point k: the stretch into it and the one out of it in one branch.
            if !same_branch(k - 1, k + 2) || direction(k - 1) * direction(k) >= 0.0 {
                continue;
            }
            let mut a = k - 1;
            while a > 0 && same_branch(a - 1, k) && direction(a - 1) == direction(k - 1) {
                a -= 1;
            }
            let mut b = k + 1;
            while b + 1 < p.len()
                && same_branch(k, b + 1)
                && direction(b) == direction(k)
                && b < k + 20
            {
                b += 1;
            }
            // The stretch into the fold and one point out: cut at point k + 1.
            let stretch: Vec<FrfPoint> = p[a..=k + 1].to_vec();
            let cut = GivenUp {
                freq_hz: p[k + 1].freq_hz,
                amplitude: p[k + 1].amplitudes[0],
                amplitude_rising: p[k + 1].amplitudes[0] > p[k].amplitudes[0],
                fold_hz: Some(p[k].freq_hz),
                cause: GiveUpCause::FillEnd,
            };
            let alone = judge_cut(&mut system, &newton, &stretch, &[], 0..stretch.len(), &cut);
            let (Some(d), true) = (alone.landing.distance, alone.own_side) else {
                continue;
            };
            if d > RETRACE_TOLERANCE || alone.verdict == CutVerdict::Unjudged {
                continue;
            }
            // The branch beyond the cut, as the run followed it, as another branch.
            let mut with_beyond = stretch.clone();
            with_beyond.extend_from_slice(&p[k + 1..=b]);
            let beyond = judge_cut(
                &mut system,
                &newton,
                &with_beyond,
                &[stretch.len()],
                0..stretch.len(),
                &cut,
            );
            eprintln!(
                "fold at {:.4} Hz, cut at {:.4} Hz: alone {alone:?}; with the branch beyond \
                 {beyond:?}",
                p[k].freq_hz, cut.freq_hz
            );
            assert_eq!(beyond.landing.freq_hz, alone.landing.freq_hz);
            if beyond.verdict != CutVerdict::Covered || beyond.own_side {
                // The run's branch beyond the cut does not cross the landing's frequency.
                continue;
            }
            assert!(beyond.landing.resolved_distance.unwrap() <= SAME_SOLUTION_TOLERANCE);
            // Where Newton from the other side finds the landing itself, the stretch came
            // back along that side (a reversal on one solution curve, a corner of the sampled
            // law): judged beyond the fold instead. Elsewhere the two sides are two solutions.
            if alone.beyond_fold.is_some() {
                assert!(alone.landing.resolved_distance.unwrap() <= SAME_SOLUTION_TOLERANCE);
                continue;
            }
            assert_eq!(alone.verdict, CutVerdict::Abandoned, "{alone:?}");
            let apart = alone
                .landing
                .resolved_distance
                .expect("Newton from the other side");
            assert!(apart > SAME_SOLUTION_TOLERANCE, "{alone:?}");
            let words = alone.describe();
            assert!(words.contains("beyond the fold"), "{words}");
            told += 1;
        }
        assert!(told > 0, "no fold within 1 % told apart by Newton");
    }

    /// A stretch that came back along the side it had followed into its fold (the paper's
    /// system at F0 = 1 N: a monotone stretch of the run above 100 Hz, then its last points
    /// again in reverse, as a fill or bridge reversing on one solution curve), cut there. Newton
    /// past the cut lands on that side, the same solution (covered by interpolation before
    /// Newton was asked); the branch goes on beyond the fold, where the run, without the
    /// points it followed there, has nothing: not covered, the status naming a branch beyond
    /// the fold not followed. With those points in the run (as another branch) it is covered.
    #[test]
    fn a_stretch_back_along_its_own_side_is_judged_beyond_its_fold() {
        let problem = paper_at_1n();
        let run = solve(&problem, &mut Silent).unwrap();
        let starts = run.branch_starts();
        let mut system = HbmOperator::new(&problem).unwrap();
        let set = system.unknowns().clone();
        let x_scale = arc_length_x_scale(&problem, &set, &system).unwrap();
        let newton = Continuation::new(problem.analysis.continuation, x_scale);
        let p = &run.points;
        let direction = |k: usize| (p[k + 1].freq_hz - p[k].freq_hz).signum();
        // Ten points of one branch above 100 Hz, the frequency moving one way throughout.
        let a = (0..p.len().saturating_sub(10))
            .find(|&a| {
                p[a].freq_hz > 100.0
                    && !starts.iter().any(|&s| s > a && s <= a + 9)
                    && (a..a + 9).all(|k| direction(k) == direction(a) && direction(k) != 0.0)
            })
            .expect("a monotone stretch");
        let mut back: Vec<FrfPoint> = p[a..=a + 5].to_vec();
        back.push(p[a + 4].clone());
        back.push(p[a + 3].clone());
        let last = &p[a + 3];
        let cut = GivenUp {
            freq_hz: last.freq_hz,
            amplitude: last.amplitudes[0],
            amplitude_rising: last.amplitudes[0] > p[a + 4].amplitudes[0],
            fold_hz: Some(p[a + 5].freq_hz),
            cause: GiveUpCause::FillEnd,
        };
        let alone = judge_cut(&mut system, &newton, &back, &[], 0..back.len(), &cut);
        eprintln!("stretch from {:.4} Hz: {alone:?}", p[a].freq_hz);
        assert!(alone.own_side, "{alone:?}");
        assert!(
            alone.landing.distance.unwrap() <= RETRACE_TOLERANCE,
            "{alone:?}"
        );
        assert!(
            alone.landing.resolved_distance.unwrap() <= SAME_SOLUTION_TOLERANCE,
            "{alone:?}"
        );
        let fold = alone.beyond_fold.expect("judged beyond the fold");
        assert_eq!(fold.fold_hz, p[a + 5].freq_hz);
        assert_eq!(fold.run_amplitude, None, "{fold:?}");
        assert_eq!(alone.verdict, CutVerdict::Abandoned, "{alone:?}");
        let words = alone.describe();
        assert!(
            words.contains("came back along the side") && words.contains("not followed"),
            "{words}"
        );
        let mut with_beyond = back.clone();
        with_beyond.extend_from_slice(&p[a + 5..=a + 9]);
        let beyond = judge_cut(
            &mut system,
            &newton,
            &with_beyond,
            &[back.len()],
            0..back.len(),
            &cut,
        );
        eprintln!("with the points beyond: {beyond:?}");
        let fold = beyond.beyond_fold.expect("judged beyond the fold");
        assert!(
            fold.landing.resolved_distance.unwrap() <= SAME_SOLUTION_TOLERANCE,
            "{fold:?}"
        );
        assert_eq!(beyond.verdict, CutVerdict::Covered, "{beyond:?}");
    }
}
