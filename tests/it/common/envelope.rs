//! The limit states that seed the response envelope's search: the two limit curves
//! (m = ±1 on every side) solved at chosen frequencies.

use fricbound::analysis::limits::{self, group_states, EnvelopeMode};
use fricbound::model::Problem;

/// A solved limit state: m per side, full coefficients, first output's amplitude (m).
pub type LimitState = (Vec<f64>, Vec<f64>, f64);

/// The m = ±1 limit curves of `problem` solved at the frequencies `freqs` (Hz): per
/// frequency, the state of each curve that has a solution there.
pub fn limit_states(problem: &Problem, freqs: &[f64]) -> Vec<Vec<LimitState>> {
    let (_, groups) = EnvelopeMode::Sides.groups(problem);
    let cases = limits::two_point_cases(problem);
    let per_case: Vec<Vec<limits::GridSolution>> = cases
        .iter()
        .map(|c| {
            let curve = limits::solve_case(problem, c, None).unwrap_or_else(|e| panic!("{e}"));
            limits::on_grid(problem, c, &curve.points, freqs).unwrap_or_else(|e| panic!("{e}"))
        })
        .collect();
    (0..freqs.len())
        .map(|g| {
            cases
                .iter()
                .zip(&per_case)
                .filter_map(|(c, sols)| {
                    sols[g].as_ref().map(|(p, _)| {
                        (
                            group_states(c, &groups),
                            p.coefficients.clone(),
                            p.amplitudes[0],
                        )
                    })
                })
                .collect()
        })
        .collect()
}

/// [`limit_states`] without the amplitudes: per frequency, (m per side, full coefficients) of
/// each limit state, as [`fricbound::analysis::limits::EnvelopeSeeds`] takes them.
pub fn limit_seeds(problem: &Problem, freqs: &[f64]) -> Vec<Vec<(Vec<f64>, Vec<f64>)>> {
    limit_states(problem, freqs)
        .iter()
        .map(|states| as_seeds(states))
        .collect()
}

/// The (m per side, full coefficients) of limit states, as the envelope's seeds take them.
pub fn as_seeds(states: &[LimitState]) -> Vec<(Vec<f64>, Vec<f64>)> {
    states
        .iter()
        .map(|(m, x, _)| (m.clone(), x.clone()))
        .collect()
}
