//! The envelope over the range: the bounds at each frequency from the seeds of the limit curves
//! and the previous frequency, in chunks, and its comparison with the limits.

use rayon::prelude::*;

use crate::analysis::frf::PointSolver;
use crate::model::Problem;
use crate::numerics::box_minimize::{minimise_in_box, BoxSettings};

use super::report::{
    Envelope, EnvelopeAtPeak, EnvelopeBound, EnvelopeCheck, EnvelopeMode, EnvelopePoint,
};
use super::search::{corners, side_corners, Evaluator, SearchLayout};
use crate::analysis::limits::case::LimitCase;
use crate::analysis::limits::grid::{GridPoint, GridSolution};
use crate::analysis::limits::peak::Peak;

/// Stretches of the grid solved in parallel (each warm-started along itself).
pub const CHUNKS: usize = 8;

/// What the envelope search starts from at one frequency.
#[derive(Debug, Clone, Default)]
pub struct EnvelopeSeeds {
    /// (m per group or per search variable, full coefficients): states solved at this
    /// frequency, or guesses from a neighbouring frequency, each corrected by Newton first.
    pub states: Vec<(Vec<f64>, Vec<f64>)>,
    /// Further starting m vectors.
    pub starts: Vec<Vec<f64>>,
}

/// The envelope at one frequency: for every output DOF, the largest and smallest amplitude over
/// m ∈ [−1, 1]^k (k = groups; the unit disc for the m = (m₁, m₂) of a group with 2D points),
/// sought from the seeds' states and starts and the box corners. Seeds and starts give m per
/// group (along t₁: m₂ = 0 for 2D groups) or per search variable ([`SearchLayout`]).
/// Builds one point solver for `problem` and sets its initial states per evaluation (see
/// [`envelope_at_with`]); a problem whose solver cannot be built has no bound.
pub fn envelope_at(
    problem: &Problem,
    groups: &[Vec<usize>],
    freq_hz: f64,
    seeds: &EnvelopeSeeds,
    search: &BoxSettings,
) -> EnvelopePoint {
    match PointSolver::new(problem) {
        Ok(mut solver) => envelope_at_with(&mut solver, groups, freq_hz, seeds, search),
        Err(_) => EnvelopePoint::unsolved(
            freq_hz,
            SearchLayout::new(problem, groups).len(),
            problem.outputs.len(),
        ),
    }
}

/// [`envelope_at`] with a point solver already built for the problem (`solver`), reused for
/// every evaluation: only the initial states of its contacts change between Newton solves
/// ([`HbmSystem::set_initial_states`]), so its Jacobian pattern, symbolic factorisation,
/// arc-length scaling and AFT plans are built once. The results are those of a solver built
/// afresh for the problem with each m (tested). The solver's initial states are left at the
/// last evaluation's.
///
/// [`HbmSystem::set_initial_states`]: crate::hbm::HbmSystem::set_initial_states
pub fn envelope_at_with(
    solver: &mut PointSolver<'_>,
    groups: &[Vec<usize>],
    freq_hz: f64,
    seeds: &EnvelopeSeeds,
    search: &BoxSettings,
) -> EnvelopePoint {
    let problem = solver.system().problem();
    let layout = SearchLayout::new(problem, groups);
    let k = layout.len();
    let outputs = problem.outputs.len();
    // Seeds and starts: m per group (along t₁) or per variable, into search coordinates.
    let to_y = |m: &[f64]| layout.expand(m).map(|m| layout.search_coordinates(&m));
    let mut ev = Evaluator::new(solver, &layout, freq_hz);
    for (m, x) in &seeds.states {
        if let Some(y) = to_y(m) {
            ev.solve_from(&y, x);
        }
    }
    let mut starts: Vec<Vec<f64>> = seeds.states.iter().map(|(m, _)| m.clone()).collect();
    starts.extend(seeds.starts.iter().cloned());
    starts.extend(side_corners(problem, groups));
    starts.extend(corners(groups.len()));
    starts.push(vec![0.0; groups.len()]);
    let mut unique: Vec<Vec<f64>> = Vec::new();
    for y in starts
        .iter()
        .filter_map(|m| to_y(m))
        .chain(layout.second_tangent_starts())
    {
        if !unique.contains(&y) {
            unique.push(y);
        }
    }
    let (lower, upper) = (vec![-1.0; k], vec![1.0; k]);
    if !ev.solved.is_empty() {
        for o in 0..outputs {
            for sense in [1.0, -1.0] {
                let reference = ev
                    .extreme(o, sense)
                    .map_or(1.0, |s| s.sensitivity.amplitudes[o])
                    .max(f64::MIN_POSITIVE);
                for start in &unique {
                    // f = −sense·A/A_ref: minimising it maximises (sense = 1) or minimises A.
                    minimise_in_box(start, &lower, &upper, search, |y| {
                        let i = ev.at(y)?;
                        let solved = &ev.solved[i];
                        let s = &solved.sensitivity;
                        let gradient = ev.layout.chain(&solved.y, &s.gradient[o]);
                        Some((
                            -sense * s.amplitudes[o] / reference,
                            gradient.iter().map(|g| -sense * g / reference).collect(),
                            solved.y.clone(),
                        ))
                    });
                }
            }
        }
    }
    let bound = |o: usize, sense: f64| {
        ev.extreme(o, sense).map(|s| EnvelopeBound {
            amplitude: s.sensitivity.amplitudes[o],
            m: s.m.clone(),
            states: s.point.states.clone(),
            coefficients: s.point.coefficients.clone(),
        })
    };
    let acting = (0..k)
        .map(|g| ev.solved.iter().any(|s| s.sensitivity.active[g]))
        .collect();
    EnvelopePoint {
        freq_hz,
        min: (0..outputs).map(|o| bound(o, -1.0)).collect(),
        max: (0..outputs).map(|o| bound(o, 1.0)).collect(),
        acting,
        solves: ev.solves,
    }
}

/// The m of each group in a case (the first contact's m where a group's points differ).
pub fn group_states(case: &LimitCase, groups: &[Vec<usize>]) -> Vec<f64> {
    groups
        .iter()
        .map(|g| g.first().map_or(0.0, |&c| case.contact_states[c]))
        .collect()
}

/// A solved state as a seed: m per group, full coefficients, first output's amplitude (m).
type Seed = (Vec<f64>, Vec<f64>, f64);

/// The states of solved curves at one grid frequency as seeds.
fn solved_seeds(
    cases: &[(&LimitCase, &[GridSolution])],
    g: usize,
    groups: &[Vec<usize>],
) -> Vec<Seed> {
    cases
        .iter()
        .filter_map(|(case, sols)| {
            sols.get(g).and_then(|s| s.as_ref()).map(|(p, _)| {
                (
                    group_states(case, groups),
                    p.coefficients.clone(),
                    p.amplitudes.first().copied().unwrap_or(f64::NAN),
                )
            })
        })
        .collect()
}

/// The solved curves an envelope starts from: the limit curves (and scanned cases) with their
/// grid solutions, and the limit curves' peaks.
pub struct EnvelopeInputs<'a> {
    /// The limit curves on the grid (their states are seeds at every grid frequency).
    pub limits: Vec<(&'a LimitCase, &'a [GridSolution])>,
    /// The scanned cases on the grid (the largest and smallest at each frequency are seeds).
    pub scanned: Vec<(&'a LimitCase, &'a [GridSolution])>,
    /// The limit curves' resonance peaks.
    pub peaks: Vec<(&'a LimitCase, &'a Peak)>,
}

/// The envelope over the grid and at the limit curves' peaks, and how the band of the limit
/// curves (`band`, first output DOF) compares with it.
pub fn envelope(
    problem: &Problem,
    mode: EnvelopeMode,
    band: &[GridPoint],
    inputs: &EnvelopeInputs<'_>,
    search: &BoxSettings,
) -> Envelope {
    let started = std::time::Instant::now();
    let (group_names, groups) = mode.groups(problem);
    let layout = SearchLayout::new(problem, &groups);
    let names = layout.names(&group_names);
    let n = band.len();
    let chunk = n.div_ceil(CHUNKS).max(1);
    let starts: Vec<usize> = (0..n).step_by(chunk).collect();
    let points: Vec<EnvelopePoint> = starts
        .par_iter()
        .flat_map_iter(|&first| {
            let mut out: Vec<EnvelopePoint> = Vec::new();
            // One solver per stretch, reused at every frequency of it.
            let mut solver = PointSolver::new(problem).ok();
            for g in first..(first + chunk).min(n) {
                let mut seeds = EnvelopeSeeds {
                    states: solved_seeds(&inputs.limits, g, &groups)
                        .into_iter()
                        .map(|(m, x, _)| (m, x))
                        .collect(),
                    starts: Vec::new(),
                };
                // The largest and smallest scanned states at this frequency.
                let scanned = solved_seeds(&inputs.scanned, g, &groups);
                let by_amp = |a: &&Seed, b: &&Seed| a.2.total_cmp(&b.2);
                for s in [scanned.iter().max_by(by_amp), scanned.iter().min_by(by_amp)]
                    .into_iter()
                    .flatten()
                {
                    seeds.states.push((s.0.clone(), s.1.clone()));
                }
                // Warm start: the states attaining the previous frequency's bounds.
                if let Some(previous) = out.last() {
                    for b in previous.max.iter().chain(&previous.min).flatten() {
                        seeds.states.push((b.m.clone(), b.coefficients.clone()));
                    }
                }
                let freq_hz = band[g].freq_hz;
                out.push(match solver.as_mut() {
                    Some(solver) => envelope_at_with(solver, &groups, freq_hz, &seeds, search),
                    None => EnvelopePoint::unsolved(freq_hz, layout.len(), problem.outputs.len()),
                });
            }
            out
        })
        .collect();
    let peaks: Vec<EnvelopeAtPeak> = inputs
        .peaks
        .par_iter()
        .map(|(case, peak)| {
            let seeds = EnvelopeSeeds {
                states: vec![(group_states(case, &groups), peak.coefficients.clone())],
                starts: Vec::new(),
            };
            EnvelopeAtPeak {
                case: case.name.clone(),
                limit_amplitude: peak.amplitude,
                point: envelope_at(problem, &groups, peak.freq_hz, &seeds, search),
            }
        })
        .collect();
    let check = compare(band, &points, &peaks);
    let solves = points.iter().map(|p| p.solves).sum::<usize>()
        + peaks.iter().map(|p| p.point.solves).sum::<usize>();
    let unsolved = points
        .iter()
        .filter(|p| p.max.iter().any(|b| b.is_none()))
        .count();
    Envelope {
        mode,
        groups: names,
        points,
        peaks,
        check,
        solves,
        unsolved,
        elapsed_s: started.elapsed().as_secs_f64(),
    }
}

/// How the band compares with the envelope (first output DOF).
fn compare(
    band: &[GridPoint],
    points: &[EnvelopePoint],
    peaks: &[EnvelopeAtPeak],
) -> EnvelopeCheck {
    let mut c = EnvelopeCheck {
        compared: 0,
        max_excess_above: 0.0,
        above_at: None,
        max_excess_below: 0.0,
        below_at: None,
        points_above: 0,
        points_below: 0,
        peak_excess_above: 0.0,
    };
    for (g, p) in band.iter().zip(points) {
        let (Some(Some(hi)), Some(Some(lo))) = (p.max.first(), p.min.first()) else {
            continue;
        };
        if !(g.upper.is_finite() && g.lower.is_finite()) {
            continue;
        }
        c.compared += 1;
        let above = (hi.amplitude - g.upper) / g.upper;
        let below = (g.lower - lo.amplitude) / g.lower;
        if above > 1e-6 {
            c.points_above += 1;
        }
        if below > 1e-6 {
            c.points_below += 1;
        }
        if above > c.max_excess_above {
            c.max_excess_above = above;
            c.above_at = Some((g.freq_hz, hi.m.clone()));
        }
        if below > c.max_excess_below {
            c.max_excess_below = below;
            c.below_at = Some((g.freq_hz, lo.m.clone()));
        }
    }
    let limit_peak = peaks
        .iter()
        .map(|p| p.limit_amplitude)
        .fold(f64::NEG_INFINITY, f64::max);
    for p in peaks {
        if let Some(Some(hi)) = p.point.max.first() {
            c.peak_excess_above = c.peak_excess_above.max(hi.amplitude / limit_peak - 1.0);
        }
    }
    c
}
