//! How a branch of a run ended (left the range, given up, retraced) and where a fill or bridge
//! was left off the stretches followed before it: the cuts the judgements then look past.

use super::checks::RETRACE_TOLERANCE;
use super::status::{BranchEnd, FrfPoint, GiveUpCause, GivenUp};
use crate::numerics::PathEnd;

/// The cuts of a bridge's way down and way up ([`fill_cut`]) as its jump's
/// ([`Jump::fill_cut`](super::Jump::fill_cut), [`Jump::second_cut`](super::Jump::second_cut)): the
/// way down's first, and a single cut, either way's, as `fill_cut`.
pub(super) fn bridge_cuts([down, up]: [Option<GivenUp>; 2]) -> (Option<GivenUp>, Option<GivenUp>) {
    match down {
        Some(down) => (Some(down), up),
        None => (up, None),
    }
}

/// How the branch of `points[segment_start..]` ended, for the jump past it: [`PathEnd`] `end`
/// of its continuation (a turned-back end: left the range, dead end or no progress), and
/// `fold_hz`, the last turning point of that continuation. A branch given up (dead end, no
/// progress) is [`BranchEnd::OutsideRange`] when its last point lies below `freq_start_hz`,
/// [`BranchEnd::Retrace`] when it lies on a stretch already followed
/// or on one of the branches solved past it (`later`, each a path without jumps; see
/// [`on_followed_stretch`]), else [`BranchEnd::Abandoned`].
pub(super) fn branch_end(
    points: &[FrfPoint],
    branch_starts: &[usize],
    segment_start: usize,
    fold_hz: Option<f64>,
    end: PathEnd,
    later: &[&[FrfPoint]],
    freq_start_hz: f64,
) -> BranchEnd {
    let cause = match end {
        PathEnd::DeadEnd => GiveUpCause::DeadEnd,
        PathEnd::NoProgress => GiveUpCause::NoProgress,
        _ => return BranchEnd::LeftRange,
    };
    let Some(last) = points.len().checked_sub(1) else {
        return BranchEnd::LeftRange;
    };
    let amplitude = points[last].amplitudes.first().copied().unwrap_or(f64::NAN);
    let amplitude_rising = last > segment_start
        && points[last - 1]
            .amplitudes
            .first()
            .is_some_and(|&a| amplitude > a);
    let given_up = GivenUp {
        freq_hz: points[last].freq_hz,
        amplitude,
        amplitude_rising,
        fold_hz,
        cause,
    };
    if given_up.freq_hz < freq_start_hz {
        BranchEnd::OutsideRange(given_up)
    } else if on_followed_stretch(points, branch_starts, last, later) {
        BranchEnd::Retrace(given_up)
    } else {
        BranchEnd::Abandoned(given_up)
    }
}

/// Whether point `last` of `points` (the last point of a branch given up) lies on a stretch of
/// path followed elsewhere: some segment between consecutive points, within a branch (not
/// across a jump at `branch_starts`) and before the last monotone stretch that leads into
/// `last` (which crosses its frequency trivially), or within one of the paths `later`,
/// brackets its frequency with every output's linearly interpolated amplitude within
/// [`RETRACE_TOLERANCE`] of the point's.
fn on_followed_stretch(
    points: &[FrfPoint],
    branch_starts: &[usize],
    last: usize,
    later: &[&[FrfPoint]],
) -> bool {
    // The monotone stretch into `last`: back while the frequency keeps moving the same way.
    let mut stretch_start = last;
    if last > 0 {
        let direction = (points[last].freq_hz - points[last - 1].freq_hz).signum();
        stretch_start = last - 1;
        while stretch_start > 0
            && !branch_starts.contains(&stretch_start)
            && (points[stretch_start].freq_hz - points[stretch_start - 1].freq_hz).signum()
                == direction
        {
            stretch_start -= 1;
        }
    }
    // The run's points up to the start of that stretch, cut at the branch starts.
    let mut cuts: Vec<usize> = branch_starts
        .iter()
        .copied()
        .filter(|&b| b > 0 && b <= stretch_start)
        .collect();
    cuts.sort_unstable();
    cuts.dedup();
    let mut paths: Vec<&[FrfPoint]> = Vec::new();
    let mut from = 0;
    for cut in cuts {
        paths.push(&points[from..cut]);
        from = cut;
    }
    paths.push(&points[from..=stretch_start]);
    paths.extend_from_slice(later);
    passes_through(&paths, &points[last])
}

/// Whether some segment between consecutive points of one of `paths` brackets `target`'s
/// frequency with every output's linearly interpolated amplitude within
/// [`RETRACE_TOLERANCE`] of `target`'s.
fn passes_through(paths: &[&[FrfPoint]], target: &FrfPoint) -> bool {
    paths.iter().any(|path| {
        path.windows(2).any(|w| {
            let (p, q) = (&w[0], &w[1]);
            if (p.freq_hz - target.freq_hz) * (q.freq_hz - target.freq_hz) > 0.0
                || p.freq_hz == q.freq_hz
            {
                return false;
            }
            let t = (target.freq_hz - p.freq_hz) / (q.freq_hz - p.freq_hz);
            target.amplitudes.iter().enumerate().all(|(o, &a)| {
                let on_segment = p.amplitudes[o] + t * (q.amplitudes[o] - p.amplitudes[o]);
                (on_segment - a).abs() <= RETRACE_TOLERANCE * a.abs()
            })
        })
    })
}

/// Where the fill of a branch past a jump (`fill`, in path order from the jump target down toward
/// the highest frequency of the branch before) was left on a branch that may go on: when its last
/// step heads up (it turned back at a fold of its own, the last at `fold_hz`, and stopped on
/// reaching its end frequency: `end`), the branch goes on above its last point, which no
/// continuation follows; when it was given up before its edge (`end` a dead end or no progress,
/// heading either way) or stopped there for its point budget (`end` [`PathEnd::MaxPoints`]), the
/// branch goes on beyond its last point. None when it reached its end frequency heading down, or
/// left its range, or when its last point lies on the run's `points` before the jump (within a
/// branch at `branch_starts`, see [`passes_through`]). Whether a cut leaves response missing is
/// judged once the run is over ([`judge_cuts`](super::judge::judge_cuts)): the branch followed on
/// from the jump target may pass it.
///
/// A bridge branch is followed the same way from inside a stretch toward each of its edges
/// (`travel_down` false for the way up: then a last step heading down is the cut).
pub(super) fn fill_cut(
    points: &[FrfPoint],
    branch_starts: &[usize],
    fill: &[FrfPoint],
    travel_down: bool,
    end: PathEnd,
    fold_hz: Option<f64>,
) -> Option<GivenUp> {
    let [.., before, last] = fill else {
        return None;
    };
    let heading_up = last.freq_hz > before.freq_hz;
    let turned_back = last.freq_hz != before.freq_hz && heading_up == travel_down;
    let cause = match end {
        PathEnd::EndFrequency if turned_back => GiveUpCause::FillEnd,
        PathEnd::DeadEnd => GiveUpCause::DeadEnd,
        PathEnd::NoProgress => GiveUpCause::NoProgress,
        PathEnd::MaxPoints => GiveUpCause::PointBudget,
        PathEnd::EndFrequency | PathEnd::LeftRangeBelow => return None,
    };
    let mut cuts: Vec<usize> = branch_starts
        .iter()
        .copied()
        .filter(|&b| b > 0 && b < points.len())
        .collect();
    cuts.sort_unstable();
    cuts.dedup();
    let mut paths: Vec<&[FrfPoint]> = Vec::new();
    let mut from = 0;
    for cut in cuts {
        paths.push(&points[from..cut]);
        from = cut;
    }
    paths.push(&points[from..]);
    if passes_through(&paths, last) {
        return None;
    }
    let amplitude = last.amplitudes.first().copied().unwrap_or(f64::NAN);
    Some(GivenUp {
        freq_hz: last.freq_hz,
        amplitude,
        amplitude_rising: before.amplitudes.first().is_some_and(|&a| amplitude > a),
        fold_hz,
        cause,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::frf::checks::{CutCheck, CutVerdict, Landing};
    use crate::analysis::frf::fixtures::{covered_check, folded_path, line_point, run_with_jumps};
    use crate::analysis::frf::status::{Jump, JumpKind};

    /// A branch given up by a dead end on the middle branch past a fold, its amplitude rising
    /// away from the upper branch it turned back from, is abandoned: the jump records where
    /// (last point, first output's amplitude, the fold) and why, and the run that went on to the
    /// end frequency past it is incomplete, saying so; its JSON record says `abandoned`.
    #[test]
    fn a_branch_abandoned_past_a_fold_makes_the_run_incomplete() {
        let points = folded_path(&[(109.5, 2.5), (109.0, 3.0)]);
        let end = branch_end(&points, &[], 0, Some(110.0), PathEnd::DeadEnd, &[], 0.0);
        let BranchEnd::Abandoned(given_up) = end else {
            panic!("{end:?}");
        };
        assert_eq!(given_up.freq_hz, 109.0);
        assert_eq!(given_up.amplitude, 3.0);
        assert!(given_up.amplitude_rising);
        assert_eq!(given_up.fold_hz, Some(110.0));
        assert_eq!(given_up.cause, GiveUpCause::DeadEnd);
        let mut run = run_with_jumps(vec![Jump {
            from_hz: 110.0,
            to_hz: 110.0,
            first_point: points.len(),
            kind: JumpKind::PastDeadEnd,
            before: end,
            fill_cut: None,
            cut_check: None,
            second_cut: None,
            second_cut_check: None,
            end_check: None,
        }]);
        run.points = points;
        assert!(!run.is_complete());
        let reason = run.incomplete_reason().unwrap();
        for words in [
            "abandoned at 109.0000 Hz",
            "amplitude 3.000e0 m, rising",
            "below the fold at 110.0000 Hz",
            "dead end",
            "possibly the resonance peak",
            "past 110.0000 Hz",
        ] {
            assert!(reason.contains(words), "{words:?} not in {reason}");
        }
        let json = serde_json::to_value(run.jumps[0]).unwrap();
        assert_eq!(json["abandoned"], true);
        assert_eq!(json["before"]["how"], "abandoned");
        assert_eq!(json["before"]["freq_hz"], 109.0);
        assert_eq!(json["before"]["cause"], "dead-end");
        // An uncovered stretch is reported with it.
        run.jumps[0].to_hz = 111.0;
        let reason = run.incomplete_reason().unwrap();
        assert!(reason.contains("110.0000-111.0000 Hz") && reason.contains("abandoned at"));
        run.jumps[0].to_hz = 110.0;
        // Judged once the run is over (`end_check`): Newton past the point landing on a
        // stretch of the run covers it, the run is complete; landing off the run, or nowhere,
        // it stays abandoned and the reason says where Newton landed.
        let covered = covered_check(108.9, 3.1, 1e-4, 1e-12, 2);
        run.jumps[0].end_check = Some(covered);
        assert!(!run.jumps[0].abandons_branch());
        assert!(run.is_complete(), "{:?}", run.incomplete_reason());
        let json = serde_json::to_value(run.jumps[0]).unwrap();
        assert_eq!(json["abandoned"], false);
        assert_eq!(json["end_check"]["verdict"], "covered");
        for verdict in [CutVerdict::Abandoned, CutVerdict::Unjudged] {
            run.jumps[0].end_check = Some(CutCheck {
                landing: Landing {
                    distance: Some(3e-2),
                    resolved_distance: None,
                    ..covered.landing
                },
                verdict,
                ..covered
            });
            assert!(run.jumps[0].abandons_branch());
            let reason = run.incomplete_reason().unwrap();
            assert!(
                reason.contains("abandoned at 109.0000 Hz")
                    && reason.contains("Newton just past the point given up"),
                "{reason}"
            );
        }
    }

    /// A branch given up where it was retracing the stretch already followed (the points
    /// after the fold lie back on the rising branch, within 1 % of its amplitude) abandoned
    /// nothing: the run stays complete. Just outside the tolerance it is abandoned.
    #[test]
    fn a_branch_given_up_on_a_stretch_already_followed_is_a_retrace() {
        for cause in [PathEnd::DeadEnd, PathEnd::NoProgress] {
            let on_line = |f: f64| 1.0 + 0.1 * (f - 100.0);
            let points = folded_path(&[(109.5, on_line(109.5)), (108.5, on_line(108.5) * 1.009)]);
            let end = branch_end(&points, &[], 0, Some(110.0), cause, &[], 0.0);
            assert!(matches!(end, BranchEnd::Retrace(_)), "{end:?}");
            let mut run = run_with_jumps(vec![Jump {
                from_hz: 110.0,
                to_hz: 110.0,
                first_point: points.len(),
                kind: JumpKind::PastFold,
                before: end,
                fill_cut: None,
                cut_check: None,
                second_cut: None,
                second_cut_check: None,
                end_check: None,
            }]);
            run.points = points;
            assert!(run.is_complete(), "{:?}", run.incomplete_reason());
            assert!(!run.jumps[0].abandons_branch());

            let off = folded_path(&[(109.5, on_line(109.5)), (108.5, on_line(108.5) * 1.011)]);
            let end = branch_end(&off, &[], 0, Some(110.0), cause, &[], 0.0);
            assert!(matches!(end, BranchEnd::Abandoned(_)), "{end:?}");
        }
    }

    /// The stretch followed on another branch counts too, but not a segment across a jump; a
    /// branch given up while still rising (no fold) is abandoned with no fold named, one that
    /// left the range below the start abandoned nothing.
    #[test]
    fn retraces_are_sought_within_branches_and_a_left_range_abandons_nothing() {
        // Branch 1: 100..110 Hz on the line; branch 2 (from index 11): 112 Hz down to
        // 105 Hz on a line with amplitude 5, then up again to 106 Hz at the first line's
        // amplitude: the segment across the jump (110 Hz, 2) to (112 Hz, 5) does not count.
        // How branch 2, given up at its last point after the fold at 105 Hz, ended.
        let end_of_branch_2 = |points: &[FrfPoint]| {
            branch_end(
                points,
                &[11],
                11,
                Some(105.0),
                PathEnd::NoProgress,
                &[],
                0.0,
            )
        };
        let mut points = folded_path(&[]);
        points.push(line_point(112.0, 5.0, 0.0));
        points.push(line_point(105.0, 5.0, 0.0));
        points.push(line_point(106.0, 1.6, 0.0));
        let end = end_of_branch_2(&points);
        let BranchEnd::Retrace(g) = end else {
            panic!("{end:?}")
        };
        assert_eq!(g.cause, GiveUpCause::NoProgress);
        assert!(g.describe().contains("above the fold at 105.0000 Hz"));
        // At 111 Hz only the segment across the jump, (110 Hz, 2) to (112 Hz, 5), passes
        // through the point's amplitude 3.5: not a stretch followed.
        points.pop();
        points.push(line_point(111.0, 3.5, 0.0));
        let end = end_of_branch_2(&points);
        assert!(matches!(end, BranchEnd::Abandoned(_)), "{end:?}");

        let rising = folded_path(&[]);
        let end = branch_end(&rising, &[], 0, None, PathEnd::DeadEnd, &[], 0.0);
        let BranchEnd::Abandoned(g) = end else {
            panic!("{end:?}")
        };
        assert_eq!((g.freq_hz, g.fold_hz), (110.0, None));
        assert!(!g.describe().contains("fold"));
        // A branch solved past it (here a fill from 109 to 111 Hz) passing through the point
        // within the tolerance: the branch goes on there, nothing was abandoned.
        let fill = [line_point(109.0, 1.9, 0.0), line_point(111.0, 2.1, 0.0)];
        let end = branch_end(&rising, &[], 0, None, PathEnd::DeadEnd, &[&fill], 0.0);
        assert!(matches!(end, BranchEnd::Retrace(_)), "{end:?}");
        let fill = [line_point(109.0, 1.9, 0.0), line_point(111.0, 2.2, 0.0)];
        let end = branch_end(&rising, &[], 0, None, PathEnd::DeadEnd, &[&fill], 0.0);
        assert!(matches!(end, BranchEnd::Abandoned(_)), "{end:?}");
        // Given up below the start frequency: outside the range, nothing in it abandoned.
        let end = branch_end(&rising, &[], 0, None, PathEnd::DeadEnd, &[], 110.5);
        assert!(matches!(end, BranchEnd::OutsideRange(_)), "{end:?}");
        let mut run = run_with_jumps(vec![Jump {
            from_hz: 110.0,
            to_hz: 110.0,
            first_point: rising.len(),
            kind: JumpKind::PastDeadEnd,
            before: end,
            fill_cut: None,
            cut_check: None,
            second_cut: None,
            second_cut_check: None,
            end_check: None,
        }]);
        run.points = rising.clone();
        assert!(run.is_complete(), "{:?}", run.incomplete_reason());
        assert_eq!(
            branch_end(
                &rising,
                &[],
                0,
                Some(110.0),
                PathEnd::LeftRangeBelow,
                &[],
                0.0
            ),
            BranchEnd::LeftRange
        );
    }

    /// The fill of the branch past a jump, followed from 115 Hz down toward 110 Hz (the highest
    /// frequency of the branch before, on A = 1 + 0.1 (f − 100)), turns back up at a fold of its
    /// own at 109.5 Hz and stops on reaching 110 Hz at amplitude 3.5, off the branch before: cut
    /// (recorded in the jump, not in the status). Heading down at its end, or ending on the
    /// branch before, it is not.
    #[test]
    fn a_fill_that_turned_back_up_off_the_path_followed_is_cut() {
        let points = folded_path(&[]);
        let fill = [
            line_point(115.0, 3.0, 0.0),
            line_point(112.0, 3.3, 0.0),
            line_point(109.5, 3.6, 0.0),
            line_point(110.0, 3.5, 0.0),
        ];
        let cut = fill_cut(
            &points,
            &[],
            &fill,
            true,
            PathEnd::EndFrequency,
            Some(109.5),
        )
        .unwrap();
        assert_eq!((cut.freq_hz, cut.amplitude), (110.0, 3.5));
        assert!(!cut.amplitude_rising);
        assert_eq!(cut.cause, GiveUpCause::FillEnd);
        assert!(cut.describe().contains("above the fold at 109.5000 Hz"));
        let mut run = run_with_jumps(vec![Jump {
            from_hz: 110.0,
            to_hz: 109.5,
            first_point: points.len(),
            kind: JumpKind::PastFold,
            before: BranchEnd::LeftRange,
            fill_cut: Some(cut),
            cut_check: None,
            second_cut: None,
            second_cut_check: None,
            end_check: None,
        }]);
        run.points = points.clone();
        // Not judged yet (a jump as reported during the run): not counted in the status.
        assert!(run.is_complete(), "{:?}", run.incomplete_reason());
        let json = serde_json::to_value(run.jumps[0]).unwrap();
        assert_eq!(json["abandoned"], false);
        assert_eq!(json["fill_cut"]["freq_hz"], 110.0);
        assert_eq!(json["fill_cut"]["cause"], "fill-end");
        assert!(json["cut_check"].is_null());
        // Judged covered: still complete; judged abandoned or unjudged: incomplete, and the
        // status says where and what Newton found.
        let check = covered_check(110.01, 3.6, 2e-3, 1e-9, 3);
        run.jumps[0].cut_check = Some(check);
        assert!(run.is_complete(), "{:?}", run.incomplete_reason());
        assert!(!run.jumps[0].abandons_branch());
        run.jumps[0].cut_check = Some(CutCheck {
            landing: Landing {
                distance: Some(0.4),
                resolved_distance: None,
                ..check.landing
            },
            verdict: CutVerdict::Abandoned,
            ..check
        });
        let reason = run.incomplete_reason().unwrap();
        assert!(
            reason.contains("was left at 110.0000 Hz")
                && reason.contains("at 110.0100 Hz, lands at 3.600e0 m")
                && reason.contains("40.00 %")
                && reason.contains("was not computed"),
            "{reason}"
        );
        let json = serde_json::to_value(run.jumps[0]).unwrap();
        assert_eq!(json["abandoned"], false);
        assert_eq!(json["cut_check"]["verdict"], "abandoned");
        assert_eq!(json["cut_check"]["freq_hz"], 110.01);
        run.jumps[0].cut_check = Some(CutCheck {
            landing: Landing {
                amplitude: None,
                distance: None,
                ..check.landing
            },
            newton_iterations: 0,
            verdict: CutVerdict::Unjudged,
            ..check
        });
        let reason = run.incomplete_reason().unwrap();
        assert!(
            reason.contains("converged at none") && reason.contains("may be missing"),
            "{reason}"
        );
        // Heading down at its end: the fill reached the fold's frequency from above.
        assert_eq!(
            fill_cut(&points, &[], &fill[..3], true, PathEnd::EndFrequency, None),
            None
        );
        // Back on the branch before (A = 2 at 110 Hz): nothing cut.
        let mut onto = fill.clone();
        onto[3] = line_point(110.0, 2.0, 0.0);
        assert_eq!(
            fill_cut(
                &points,
                &[],
                &onto,
                true,
                PathEnd::EndFrequency,
                Some(109.5)
            ),
            None
        );
        // A bridge's way up that turned back down at a fold of its own before its edge.
        let up = [
            line_point(104.0, 3.0, 0.0),
            line_point(106.0, 3.2, 0.0),
            line_point(105.5, 3.3, 0.0),
        ];
        let cut = fill_cut(&points, &[], &up, false, PathEnd::EndFrequency, Some(106.0));
        assert!(cut.is_some_and(|g| g.freq_hz == 105.5 && g.amplitude_rising));
        assert_eq!(
            fill_cut(&points, &[], &up[..2], false, PathEnd::EndFrequency, None),
            None
        );
        // Left the range: not a cut.
        assert_eq!(
            fill_cut(
                &points,
                &[],
                &fill,
                true,
                PathEnd::LeftRangeBelow,
                Some(109.5)
            ),
            None
        );
        // Given up before its edge (a dead end, no progress), heading either way and off the
        // path followed: a cut, with its cause.
        for (end, cause) in [
            (PathEnd::DeadEnd, GiveUpCause::DeadEnd),
            (PathEnd::NoProgress, GiveUpCause::NoProgress),
        ] {
            for side in [&fill[..3], &fill[..]] {
                let cut = fill_cut(&points, &[], side, true, end, None).unwrap();
                assert_eq!(cut.cause, cause);
                assert_eq!(cut.freq_hz, side[side.len() - 1].freq_hz);
            }
            assert_eq!(fill_cut(&points, &[], &onto, true, end, None), None);
        }
    }

    /// A fill or bridge that used up its point budget before the edge of its stretch, heading
    /// either way and off the path followed, leaves its branch unfollowed beyond its last
    /// point: a cut (`point-budget`), judged like the others; the status names the cause. On
    /// the path followed, nothing is cut.
    #[test]
    fn a_fill_or_bridge_out_of_points_is_cut() {
        let points = folded_path(&[]);
        // A fill from 115 Hz heading down toward 110 Hz, stopped at 112 Hz; a bridge's way up
        // stopped at 106 Hz.
        let down = [line_point(115.0, 3.0, 0.0), line_point(112.0, 3.3, 0.0)];
        let up = [line_point(104.0, 3.0, 0.0), line_point(106.0, 3.2, 0.0)];
        for (side, travel_down) in [(&down[..], true), (&up[..], false)] {
            let cut = fill_cut(&points, &[], side, travel_down, PathEnd::MaxPoints, None)
                .expect("a stretch out of points off the path is cut");
            assert_eq!(cut.cause, GiveUpCause::PointBudget);
            assert_eq!(cut.freq_hz, side[1].freq_hz);
            assert!(
                cut.describe().contains("point budget"),
                "{}",
                cut.describe()
            );
            let json = serde_json::to_value(cut).unwrap();
            assert_eq!(json["cause"], "point-budget");
        }
        // Stopped on the branch before (A = 1.6 at 106 Hz): nothing left unfollowed.
        let on = [line_point(104.0, 3.0, 0.0), line_point(106.0, 1.6, 0.0)];
        assert_eq!(
            fill_cut(&points, &[], &on, false, PathEnd::MaxPoints, None),
            None
        );
    }

    /// A bridge followed toward both edges of its stretch and left at both (its way down
    /// turned back up at a fold of its own, its way up was given up by a dead end) keeps both
    /// cuts: `fill_cut` the way down's, `second_cut` the way up's; both are judged, and the
    /// second alone not covered makes the run incomplete, naming it. Its JSON record has both.
    #[test]
    fn a_bridge_cut_on_both_sides_keeps_and_counts_both_cuts() {
        let points = folded_path(&[]);
        let way_down = [
            line_point(107.0, 3.0, 0.0),
            line_point(104.5, 3.3, 0.0),
            line_point(104.8, 3.4, 0.0),
        ];
        let way_up = [line_point(107.0, 3.0, 0.0), line_point(108.5, 3.1, 0.0)];
        let cuts = [
            fill_cut(
                &points,
                &[],
                &way_down,
                true,
                PathEnd::EndFrequency,
                Some(104.5),
            ),
            fill_cut(&points, &[], &way_up, false, PathEnd::DeadEnd, None),
        ];
        let (cut, second_cut) = bridge_cuts(cuts);
        let (cut, second_cut) = (cut.unwrap(), second_cut.unwrap());
        assert_eq!((cut.freq_hz, cut.cause), (104.8, GiveUpCause::FillEnd));
        assert_eq!(
            (second_cut.freq_hz, second_cut.cause),
            (108.5, GiveUpCause::DeadEnd)
        );
        // One way cut: it is the jump's `fill_cut`, whichever way.
        assert_eq!(bridge_cuts([None, cuts[1]]), (cuts[1], None));
        assert_eq!(bridge_cuts([cuts[0], None]), (cuts[0], None));
        let covered = covered_check(104.9, 3.41, 1e-4, 1e-12, 2);
        let abandoned = CutCheck {
            landing: Landing {
                amplitude: Some(3.11),
                ..Landing::nowhere(108.6)
            },
            verdict: CutVerdict::Abandoned,
            ..covered
        };
        let mut run = run_with_jumps(vec![Jump {
            from_hz: 104.0,
            to_hz: 104.0,
            first_point: points.len(),
            kind: JumpKind::Bridge,
            before: BranchEnd::Bridge,
            fill_cut: Some(cut),
            cut_check: Some(covered),
            second_cut: Some(second_cut),
            second_cut_check: Some(covered),
            end_check: None,
        }]);
        run.points = points;
        assert!(run.is_complete(), "{:?}", run.incomplete_reason());
        assert_eq!(run.jumps[0].cuts().count(), 2);
        run.jumps[0].second_cut_check = Some(abandoned);
        let reason = run
            .incomplete_reason()
            .expect("the way up's cut is not covered");
        assert!(
            reason.contains("was left at 108.5000 Hz") && !reason.contains("left at 104.8000"),
            "{reason}"
        );
        assert_eq!(
            run.jumps[0].cut_uncovered().map(|(g, _)| g.freq_hz),
            Some(108.5)
        );
        let json = serde_json::to_value(run.jumps[0]).unwrap();
        assert_eq!(json["fill_cut"]["freq_hz"], 104.8);
        assert_eq!(json["cut_check"]["verdict"], "covered");
        assert_eq!(json["cut_check"]["resolved_distance"], 1e-12);
        assert_eq!(json["second_cut"]["freq_hz"], 108.5);
        assert_eq!(json["second_cut_check"]["verdict"], "abandoned");
    }
}
