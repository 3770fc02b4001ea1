//! Response limits among multiple solutions: the two-point method per damper side (paper §3).
//!
//! A fully stuck contact's static tangential force T⁰ is not unique (paper §3.1); with a wedge
//! damper, the static balance couples it to the normal load N⁰ of the other side (Eqs. 11-13),
//! so when one side is fully stuck and the other slips (§3.2, case 3) the response is not
//! unique either. The limits come from the two extreme initial tangential states of the stuck
//! side, T(τ=0) = ±μN(τ=0) (Eqs. 14-15), which put the slipping side at its maximum N⁰
//! (closest to stuck) and minimum N⁰ (closest to free).
//!
//! A [`LimitCase`] assigns one initial state m ∈ [−1, 1] to every contact point (the march of
//! that point starts at T = mμN). The two-point method solves the cases "m = +1 on every side"
//! and "m = −1 on every side": wherever one side is stuck, the pair holds both of its limit
//! states. Intermediate cases may be uniform (the same m everywhere) or given per damper side
//! or per contact point (e.g. m = +0.5 on the side that sticks, the scene's m elsewhere).
//! The curves are put on a common frequency grid (each grid point solved exactly by Newton),
//! every grid point is classified (unique or multiple-solution regime, which sides stick or
//! slip), and in the multiple-solution regime each limit curve is labelled by the static normal
//! load it gives the slipping side. Which label has the larger amplitude is not assumed: near
//! the optimum pre-load the two cross (paper Fig. 15b).
//!
//! Whether the limits really bound the other solutions is checked, not assumed: a scan over
//! intermediate states per side reports the largest excursion outside the band.

use rayon::prelude::*;

use crate::analysis::frf::{
    self, interpolate_on_path, FrfError, FrfPoint, FrfRun, PointSolver, Silent,
};
use crate::contact::ContactState;
use crate::hbm::{HbmError, HbmSystem};
use crate::model::Problem;

/// Errors of a limit analysis.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LimitError {
    /// A curve could not be solved.
    #[error("curve `{case}`: {source}")]
    Curve {
        /// Case name.
        case: String,
        /// Cause.
        source: FrfError,
    },
    /// Evaluating contact forces failed.
    #[error("curve `{case}`: {source}")]
    Contacts {
        /// Case name.
        case: String,
        /// Cause.
        source: HbmError,
    },
    /// No converged point of a curve lies in the peak window.
    #[error("curve `{case}`: no converged point in the peak window {lo_hz} .. {hi_hz} Hz")]
    NoPeak {
        /// Case name.
        case: String,
        /// Window start (Hz).
        lo_hz: f64,
        /// Window end (Hz).
        hi_hz: f64,
    },
}

/// An intermediate case as the scene gives it, with names resolved to indices: m per damper
/// side and per contact point. Points not named (directly or through their side) keep the
/// scene's `initial_state`; a point's own value wins over its side's.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CaseSpec {
    /// Name used in file names, column headers and legends.
    pub name: String,
    /// (side index, m) pairs.
    pub sides: Vec<(usize, f64)>,
    /// (contact index, m) pairs.
    pub contacts: Vec<(usize, f64)>,
}

/// Initial tangential state of every contact point.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct LimitCase {
    /// Name used in file names and column headers (e.g. `m+1`, `m-0.5`, `left+0.5_right-0.5`).
    pub name: String,
    /// m ∈ [−1, 1] of each contact point, in the problem's contact order.
    pub contact_states: Vec<f64>,
}

impl LimitCase {
    /// The same m on every contact point.
    pub fn uniform(problem: &Problem, m: f64) -> Self {
        Self {
            name: format!("m{}", signed(m)),
            contact_states: vec![m; problem.contacts.len()],
        }
    }

    /// One m per damper side (in the problem's side order), named after the sides.
    pub fn per_side(problem: &Problem, side_states: &[f64]) -> Self {
        let name = problem
            .sides
            .iter()
            .zip(side_states)
            .map(|(s, m)| format!("{}{}", s.name, signed(*m)))
            .collect::<Vec<_>>()
            .join("_");
        Self {
            name,
            contact_states: problem
                .contacts
                .iter()
                .map(|c| side_states[c.side])
                .collect(),
        }
    }

    /// The case a scene's `[[limits.cases]]` entry describes.
    pub fn from_spec(problem: &Problem, spec: &CaseSpec) -> Self {
        let mut states: Vec<f64> = problem
            .contacts
            .iter()
            .map(|c| c.law.initial_state)
            .collect();
        for &(side, m) in &spec.sides {
            for &c in &problem.sides[side].contacts {
                states[c] = m;
            }
        }
        for &(c, m) in &spec.contacts {
            states[c] = m;
        }
        Self {
            name: spec.name.clone(),
            contact_states: states,
        }
    }

    /// The m shared by every point of side `side`, or `None` if its points differ.
    pub fn side_state(&self, problem: &Problem, side: usize) -> Option<f64> {
        let mut ms = problem.sides[side]
            .contacts
            .iter()
            .map(|&c| self.contact_states[c]);
        let first = ms.next()?;
        ms.all(|m| m == first).then_some(first)
    }

    /// The problem with every contact's initial state set from the case.
    pub fn apply(&self, problem: &Problem) -> Problem {
        let mut p = problem.clone();
        for (c, m) in p.contacts.iter_mut().zip(&self.contact_states) {
            c.law.initial_state = *m;
        }
        p
    }
}

/// m as it appears in case names: `+0.5`, `-1`, `0`.
pub fn signed(m: f64) -> String {
    if m == 0.0 {
        "0".to_string()
    } else {
        format!("{m:+}")
    }
}

/// The two-point method's cases: m = +1 and m = −1 on every side.
pub fn two_point_cases(problem: &Problem) -> Vec<LimitCase> {
    vec![
        LimitCase::uniform(problem, 1.0),
        LimitCase::uniform(problem, -1.0),
    ]
}

/// Every combination of the given m values over the damper sides (values^sides cases).
pub fn scan_cases(problem: &Problem, values: &[f64]) -> Vec<LimitCase> {
    let sides = problem.sides.len();
    let mut cases = Vec::new();
    if values.is_empty() || sides == 0 {
        return cases;
    }
    let total = values.len().pow(sides as u32);
    for mut code in 0..total {
        let mut side_states = Vec::with_capacity(sides);
        for _ in 0..sides {
            side_states.push(values[code % values.len()]);
            code /= values.len();
        }
        cases.push(LimitCase::per_side(problem, &side_states));
    }
    cases
}

/// A refined resonance peak of a curve.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Peak {
    /// Frequency of the peak (Hz).
    pub freq_hz: f64,
    /// First-harmonic amplitude of the output DOF at the peak (m).
    pub amplitude: f64,
    /// Whether the peak is an interior local maximum of the path refined by extra solves.
    /// False when the curve has no local maximum in the peak window: the value is then the
    /// largest at an end of the window or range, not a resonance peak.
    pub refined: bool,
    /// Coefficients at the peak.
    #[serde(skip)]
    pub coefficients: Vec<f64>,
    /// Contact states at the peak.
    pub states: Vec<ContactState>,
}

impl Peak {
    fn from_point(p: &FrfPoint, output: usize, refined: bool) -> Self {
        Self {
            freq_hz: p.freq_hz,
            amplitude: p.amplitudes[output],
            refined,
            coefficients: p.coefficients.clone(),
            states: p.states.clone(),
        }
    }
}

/// Locates the resonance peak of output `output` on a path: the largest interior local maximum
/// of the first-harmonic amplitude among the points inside `window` (Hz; the whole path when
/// `None`), refined by a golden-section search along the path between its two neighbours.
///
/// Each trial is solved on the hyperplane normal to the chord through the neighbours (the
/// pseudo-arc-length corrector), not at a fixed frequency, so the search follows the branch
/// through folds and overhangs; the refined point is a stationary point of the amplitude along
/// the path to a relative 1e-7 of the chord. Where no local maximum lies in the window, the
/// largest amplitude in it is returned unrefined. `None` when no point lies in the window.
pub fn refine_peak(
    problem: &Problem,
    points: &[FrfPoint],
    output: usize,
    window: Option<(f64, f64)>,
) -> Result<Option<Peak>, FrfError> {
    let inside = |p: &FrfPoint| window.is_none_or(|(lo, hi)| p.freq_hz >= lo && p.freq_hz <= hi);
    let amp = |i: usize| points[i].amplitudes[output];
    let local_max = (1..points.len().saturating_sub(1))
        .filter(|&i| inside(&points[i]) && amp(i) >= amp(i - 1) && amp(i) >= amp(i + 1))
        .max_by(|&i, &j| amp(i).total_cmp(&amp(j)));
    let Some(best) = local_max else {
        return Ok((0..points.len())
            .filter(|&i| inside(&points[i]))
            .max_by(|&i, &j| amp(i).total_cmp(&amp(j)))
            .map(|i| Peak::from_point(&points[i], output, false)));
    };
    let (p0, p1, p2) = (&points[best - 1], &points[best], &points[best + 1]);
    let mut solver = PointSolver::new(problem)?;
    // Path parameter s ∈ [0, 2]: chord p0 → p1 for s ≤ 1, chord p1 → p2 beyond.
    let mut eval = |s: f64| -> Option<FrfPoint> {
        let solved = if s <= 1.0 {
            solver.solve_on_chord(p0, p1, s)
        } else {
            solver.solve_on_chord(p1, p2, s - 1.0)
        };
        solved.ok().filter(|q| q.amplitudes[output].is_finite())
    };
    let value = |q: &Option<FrfPoint>| {
        q.as_ref()
            .map(|q| q.amplitudes[output])
            .unwrap_or(f64::NEG_INFINITY)
    };
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    let (mut lo, mut hi) = (0.0_f64, 2.0_f64);
    let mut c = hi - ratio * (hi - lo);
    let mut d = lo + ratio * (hi - lo);
    let (mut pc, mut pd) = (eval(c), eval(d));
    let mut best_point = p1.clone();
    let keep = |q: &Option<FrfPoint>, best_point: &mut FrfPoint| {
        if let Some(q) = q {
            if q.amplitudes[output] > best_point.amplitudes[output] {
                *best_point = q.clone();
            }
        }
    };
    keep(&pc, &mut best_point);
    keep(&pd, &mut best_point);
    while hi - lo > 2e-7 {
        if value(&pc) >= value(&pd) {
            hi = d;
            d = c;
            pd = pc;
            c = hi - ratio * (hi - lo);
            pc = eval(c);
            keep(&pc, &mut best_point);
        } else {
            lo = c;
            c = d;
            pc = pd;
            d = lo + ratio * (hi - lo);
            pd = eval(d);
            keep(&pd, &mut best_point);
        }
    }
    Ok(Some(Peak::from_point(&best_point, output, true)))
}

/// The resonance of a linear reference: its largest local maximum of output `output` inside
/// `window` (Hz; anywhere when `None`), as (frequency in Hz, amplitude in m), at the reference's
/// grid resolution.
pub fn linear_resonance(
    curve: &crate::analysis::linear::LinearCurve,
    output: usize,
    window: Option<(f64, f64)>,
) -> Option<(f64, f64)> {
    let a: Vec<f64> = curve.amplitudes.iter().map(|r| r[output]).collect();
    (1..a.len().saturating_sub(1))
        .filter(|&i| a[i] > a[i - 1] && a[i] >= a[i + 1])
        .filter(|&i| window.is_none_or(|(lo, hi)| (lo..=hi).contains(&curve.freqs_hz[i])))
        .map(|i| (curve.freqs_hz[i], a[i]))
        .max_by(|x, y| x.1.total_cmp(&y.1))
}

/// One solved curve.
#[derive(Debug, Clone, PartialEq)]
pub struct CaseCurve {
    /// The case.
    pub case: LimitCase,
    /// The continuation run.
    pub run: FrfRun,
    /// Resonance peak of the first output DOF in the peak window.
    pub peak: Peak,
    /// Continuation retries with other step settings before the run succeeded (0: none).
    pub retries: usize,
}

/// Factors on the scene's continuation steps (initial and largest) tried in turn when a curve
/// fails: a continuation that stalls at a corner of the piecewise-smooth path (a contact
/// changing state) usually passes it when the corner is approached with other steps.
const STEP_RETRIES: [f64; 4] = [1.0, 0.5, 0.25, 2.0];

/// Solves the FRF of one case and locates its peak (first output DOF) in `window` (Hz).
///
/// If the continuation fails, it is repeated with the scene's initial and largest steps scaled
/// by the factors 0.5, 0.25 and 2 in turn; the number of retries is recorded, and the first
/// failure is returned when every attempt fails.
pub fn solve_case(
    problem: &Problem,
    case: &LimitCase,
    window: Option<(f64, f64)>,
) -> Result<CaseCurve, LimitError> {
    let p = case.apply(problem);
    let err = |source| LimitError::Curve {
        case: case.name.clone(),
        source,
    };
    let mut first_error = None;
    for (retries, factor) in STEP_RETRIES.iter().enumerate() {
        let mut attempt = p.clone();
        let a = &mut attempt.analysis.continuation;
        a.max_step = (a.max_step * factor).max(a.min_step);
        a.initial_step = (a.initial_step * factor).clamp(a.min_step, a.max_step);
        match frf::solve(&attempt, &mut Silent) {
            Ok(run) => {
                let peak = refine_peak(&p, &run.points, 0, window)
                    .map_err(err)?
                    .ok_or_else(|| {
                        let (lo_hz, hi_hz) = window.unwrap_or((f64::NAN, f64::NAN));
                        LimitError::NoPeak {
                            case: case.name.clone(),
                            lo_hz,
                            hi_hz,
                        }
                    })?;
                return Ok(CaseCurve {
                    case: case.clone(),
                    run,
                    peak,
                    retries,
                });
            }
            Err(e) => {
                first_error.get_or_insert(e);
            }
        }
    }
    Err(err(first_error.expect("at least one attempt")))
}

/// Static (0th-harmonic) contact forces summed over a damper side (N).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct SideStatics {
    /// Σ T⁰ over the side's points (N).
    pub tangential: f64,
    /// Σ N⁰ over the side's points (N).
    pub normal: f64,
}

/// T⁰ and N⁰ per side at coefficients x.
pub fn side_statics(system: &mut HbmSystem<'_>, x: &[f64]) -> Result<Vec<SideStatics>, HbmError> {
    let problem = system.problem();
    let mut out = vec![
        SideStatics {
            tangential: 0.0,
            normal: 0.0
        };
        problem.sides.len()
    ];
    for (c, contact) in problem.contacts.iter().enumerate() {
        system.contact_forces(c, x, false)?;
        out[contact.side].tangential += system.aft().t_hat[0];
        out[contact.side].normal += system.aft().n_hat[0];
    }
    Ok(out)
}

/// State of a damper side over one period.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum SideState {
    /// Every point fully stuck.
    Stuck,
    /// Some point slips or separates (its tangential force is unique).
    Slipping,
    /// Every point open.
    Open,
}

/// Side states from contact states.
pub fn side_states(problem: &Problem, states: &[ContactState]) -> Vec<SideState> {
    problem
        .sides
        .iter()
        .map(|side| {
            let s: Vec<ContactState> = side.contacts.iter().map(|&c| states[c]).collect();
            if s.iter().all(|x| *x == ContactState::Stuck) {
                SideState::Stuck
            } else if s.iter().all(|x| *x == ContactState::Open) {
                SideState::Open
            } else {
                SideState::Slipping
            }
        })
        .collect()
}

/// Physical label of a limit curve in the multiple-solution regime.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum LimitLabel {
    /// Maximum static normal load on the slipping side: closest to stuck.
    MaxNormalClosestToStuck,
    /// Minimum static normal load on the slipping side: closest to free.
    MinNormalClosestToFree,
}

impl LimitLabel {
    /// Text for tables.
    pub fn text(self) -> &'static str {
        match self {
            LimitLabel::MaxNormalClosestToStuck => "max N0 on slipping side: closest to stuck",
            LimitLabel::MinNormalClosestToFree => "min N0 on slipping side: closest to free",
        }
    }
}

/// Regime of a grid frequency (paper §3.2).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Regime {
    /// All sides stuck, or all slipping: one response.
    Unique,
    /// Some side fully stuck while another slips (case 3): many responses.
    Multiple {
        /// Sides fully stuck in some limit case.
        stuck_sides: Vec<usize>,
        /// Sides slipping in that case.
        slipping_sides: Vec<usize>,
    },
    /// Some limit case has no solution at this frequency.
    Unknown,
}

/// One frequency of the common grid.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct GridPoint {
    /// Frequency (Hz).
    pub freq_hz: f64,
    /// Output amplitude of each limit case (m); NaN where unsolved.
    pub amplitudes: Vec<f64>,
    /// Contact states of each limit case (empty where unsolved).
    pub states: Vec<Vec<ContactState>>,
    /// Side statics of each limit case (empty where unsolved).
    pub statics: Vec<Vec<SideStatics>>,
    /// Regime.
    pub regime: Regime,
    /// Label of each limit case (only in the multiple-solution regime).
    pub labels: Vec<Option<LimitLabel>>,
    /// Lower and upper limit amplitudes (m).
    pub lower: f64,
    /// Upper limit amplitude (m).
    pub upper: f64,
}

/// One curve solved at one grid frequency, with its side statics; `None` where unsolved.
pub type GridSolution = Option<(FrfPoint, Vec<SideStatics>)>;

/// A curve solved exactly at each grid frequency (None where no path segment brackets it or
/// Newton fails).
pub fn on_grid(
    problem: &Problem,
    case: &LimitCase,
    points: &[FrfPoint],
    grid: &[f64],
) -> Result<Vec<GridSolution>, LimitError> {
    let p = case.apply(problem);
    let mut solver = PointSolver::new(&p).map_err(|source| LimitError::Curve {
        case: case.name.clone(),
        source,
    })?;
    let mut out = Vec::with_capacity(grid.len());
    for &f in grid {
        let solved = interpolate_on_path(points, f).and_then(|g| solver.solve(&g, f).ok());
        match solved {
            Some(point) => {
                let statics =
                    side_statics(solver.system(), &point.coefficients).map_err(|source| {
                        LimitError::Contacts {
                            case: case.name.clone(),
                            source,
                        }
                    })?;
                out.push(Some((point, statics)));
            }
            None => out.push(None),
        }
    }
    Ok(out)
}

/// Classifies every grid frequency from the limit cases' grid solutions.
pub fn classify(problem: &Problem, grid: &[f64], per_case: &[Vec<GridSolution>]) -> Vec<GridPoint> {
    grid.iter()
        .enumerate()
        .map(|(g, &freq_hz)| {
            let sols: Vec<Option<&(FrfPoint, Vec<SideStatics>)>> =
                per_case.iter().map(|c| c[g].as_ref()).collect();
            let amplitudes: Vec<f64> = sols
                .iter()
                .map(|s| s.map(|s| s.0.amplitudes[0]).unwrap_or(f64::NAN))
                .collect();
            let states: Vec<Vec<ContactState>> = sols
                .iter()
                .map(|s| s.map(|s| s.0.states.clone()).unwrap_or_default())
                .collect();
            let statics: Vec<Vec<SideStatics>> = sols
                .iter()
                .map(|s| s.map(|s| s.1.clone()).unwrap_or_default())
                .collect();
            let mut labels = vec![None; per_case.len()];
            let regime =
                if sols.iter().any(|s| s.is_none()) {
                    Regime::Unknown
                } else {
                    let mut stuck_sides = Vec::new();
                    let mut slipping_sides = Vec::new();
                    for st in &states {
                        let sides = side_states(problem, st);
                        let stuck: Vec<usize> = (0..sides.len())
                            .filter(|&i| sides[i] == SideState::Stuck)
                            .collect();
                        let slipping: Vec<usize> = (0..sides.len())
                            .filter(|&i| sides[i] == SideState::Slipping)
                            .collect();
                        if !stuck.is_empty() && !slipping.is_empty() {
                            for s in stuck {
                                if !stuck_sides.contains(&s) {
                                    stuck_sides.push(s);
                                }
                            }
                            for s in slipping {
                                if !slipping_sides.contains(&s) {
                                    slipping_sides.push(s);
                                }
                            }
                        }
                    }
                    if stuck_sides.is_empty() {
                        Regime::Unique
                    } else {
                        // Label by the static normal load on the slipping side(s).
                        let n0: Vec<f64> = statics
                            .iter()
                            .map(|st| slipping_sides.iter().map(|&s| st[s].normal).sum())
                            .collect();
                        let (imax, max) = n0.iter().cloned().enumerate().fold(
                            (0, f64::NEG_INFINITY),
                            |a, (i, v)| if v > a.1 { (i, v) } else { a },
                        );
                        let (imin, min) =
                            n0.iter()
                                .cloned()
                                .enumerate()
                                .fold(
                                    (0, f64::INFINITY),
                                    |a, (i, v)| if v < a.1 { (i, v) } else { a },
                                );
                        if max - min > 1e-9 * max.abs().max(min.abs()).max(f64::MIN_POSITIVE) {
                            labels[imax] = Some(LimitLabel::MaxNormalClosestToStuck);
                            labels[imin] = Some(LimitLabel::MinNormalClosestToFree);
                        }
                        Regime::Multiple {
                            stuck_sides,
                            slipping_sides,
                        }
                    }
                };
            let finite: Vec<f64> = amplitudes
                .iter()
                .cloned()
                .filter(|a| a.is_finite())
                .collect();
            let (lower, upper) = if finite.len() == amplitudes.len() && !finite.is_empty() {
                (
                    finite.iter().cloned().fold(f64::INFINITY, f64::min),
                    finite.iter().cloned().fold(f64::NEG_INFINITY, f64::max),
                )
            } else {
                (f64::NAN, f64::NAN)
            };
            GridPoint {
                freq_hz,
                amplitudes,
                states,
                statics,
                regime,
                labels,
                lower,
                upper,
            }
        })
        .collect()
}

/// How well the limit curves bound a set of other curves.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct BoundCheck {
    /// Largest amplitude above the upper limit, relative to the upper limit there.
    pub max_excess_above: f64,
    /// Where (frequency in Hz, case name), if any excess.
    pub above_at: Option<(f64, String)>,
    /// Largest amplitude below the lower limit, relative to the lower limit there.
    pub max_excess_below: f64,
    /// Where (frequency in Hz, case name), if any excess.
    pub below_at: Option<(f64, String)>,
    /// Largest refined peak of a scanned curve above the largest limit peak (relative).
    pub peak_excess_above: f64,
    /// Smallest refined peak of a scanned curve below the smallest limit peak (relative).
    pub peak_excess_below: f64,
    /// Grid points compared.
    pub compared: usize,
    /// Contact states where the excess above the upper limit is largest.
    pub above_states: Option<ExcessStates>,
    /// Contact states where the excess below the lower limit is largest.
    pub below_states: Option<ExcessStates>,
}

/// Contact states at the point of a largest excess: they tell why the limits do not bound
/// there (e.g. a limit curve fully stuck while the scanned state slips).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ExcessStates {
    /// States of the scanned curve.
    pub scanned: Vec<ContactState>,
    /// States of each limit curve at that grid frequency.
    pub limits: Vec<Vec<ContactState>>,
}

/// Compares scanned curves (on the grid) and their peaks with the limits.
pub fn check_bounds(
    grid: &[GridPoint],
    limit_peaks: &[f64],
    scanned: &[(LimitCase, Vec<GridSolution>, Peak)],
) -> BoundCheck {
    let mut b = BoundCheck {
        max_excess_above: 0.0,
        above_at: None,
        max_excess_below: 0.0,
        below_at: None,
        peak_excess_above: 0.0,
        peak_excess_below: 0.0,
        compared: 0,
        above_states: None,
        below_states: None,
    };
    let peak_hi = limit_peaks
        .iter()
        .cloned()
        .fold(f64::NEG_INFINITY, f64::max);
    let peak_lo = limit_peaks.iter().cloned().fold(f64::INFINITY, f64::min);
    for (case, sols, peak) in scanned {
        for (g, s) in grid.iter().zip(sols) {
            let Some((p, _)) = s else { continue };
            if !(g.upper.is_finite() && g.lower.is_finite()) {
                continue;
            }
            b.compared += 1;
            let a = p.amplitudes[0];
            let above = (a - g.upper) / g.upper;
            let states = || ExcessStates {
                scanned: p.states.clone(),
                limits: g.states.clone(),
            };
            if above > b.max_excess_above {
                b.max_excess_above = above;
                b.above_at = Some((g.freq_hz, case.name.clone()));
                b.above_states = Some(states());
            }
            let below = (g.lower - a) / g.lower;
            if below > b.max_excess_below {
                b.max_excess_below = below;
                b.below_at = Some((g.freq_hz, case.name.clone()));
                b.below_states = Some(states());
            }
        }
        b.peak_excess_above = b
            .peak_excess_above
            .max((peak.amplitude - peak_hi) / peak_hi);
        b.peak_excess_below = b
            .peak_excess_below
            .max((peak_lo - peak.amplitude) / peak_lo);
    }
    b
}

/// Where hysteresis loops are wanted, on every limit and intermediate curve.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct HysteresisRequest {
    /// At each curve's resonance peak (paper Fig. 16c).
    pub at_peaks: bool,
    /// At these frequencies (Hz), on the first path segment of each curve that brackets them.
    pub freqs_hz: Vec<f64>,
}

impl Default for HysteresisRequest {
    fn default() -> Self {
        Self {
            at_peaks: true,
            freqs_hz: Vec::new(),
        }
    }
}

/// Settings of a limit analysis.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct LimitSettings {
    /// m values of uniform intermediate curves (the same m on every point).
    pub intermediate: Vec<f64>,
    /// Intermediate cases given per damper side or per contact point.
    pub cases: Vec<CaseSpec>,
    /// Points of the common frequency grid.
    pub grid_points: usize,
    /// m values scanned per side (all combinations) to test the bounds; empty disables.
    pub bound_scan: Vec<f64>,
    /// Frequency window (Hz) in which each curve's resonance peak is sought; `None`: the range.
    pub peak_window_hz: Option<(f64, f64)>,
    /// Hysteresis loops to compute.
    pub hysteresis: HysteresisRequest,
}

impl Default for LimitSettings {
    fn default() -> Self {
        Self {
            intermediate: Vec::new(),
            cases: Vec::new(),
            grid_points: 201,
            bound_scan: Vec::new(),
            peak_window_hz: None,
            hysteresis: HysteresisRequest::default(),
        }
    }
}

impl LimitSettings {
    /// The intermediate cases: uniform ones first, then those given per side or point.
    pub fn intermediate_cases(&self, problem: &Problem) -> Vec<LimitCase> {
        self.intermediate
            .iter()
            .map(|&m| LimitCase::uniform(problem, m))
            .chain(self.cases.iter().map(|c| LimitCase::from_spec(problem, c)))
            .collect()
    }
}

/// Hysteresis loops of every contact of one curve at one point.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct LoopSet {
    /// Case name of the curve.
    pub case: String,
    /// Where: `peak` or the requested frequency, e.g. `214.5 Hz`.
    pub at: String,
    /// Frequency of the point (Hz).
    pub freq_hz: f64,
    /// Output amplitude at the point (m).
    pub amplitude: f64,
    /// One loop per contact.
    pub loops: Vec<HysteresisLoop>,
}

/// Everything a limit analysis computes.
#[derive(Debug, Clone, PartialEq)]
pub struct LimitAnalysis {
    /// The two limit curves (m = +1, m = −1 on every side).
    pub limits: Vec<CaseCurve>,
    /// Intermediate curves.
    pub intermediate: Vec<CaseCurve>,
    /// Common grid with classification and band.
    pub grid: Vec<GridPoint>,
    /// Bound check of the scan (None when no scan was asked for).
    pub bounds: Option<BoundCheck>,
    /// Scanned cases with their peaks.
    pub scan_peaks: Vec<(LimitCase, Peak)>,
    /// Requested hysteresis loops.
    pub loops: Vec<LoopSet>,
    /// Requested loops that could not be computed (no solution of the curve there), as text.
    pub loops_missing: Vec<String>,
}

/// Size of the variability of one limit analysis (first output DOF).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Variability {
    /// Larger resonance-peak amplitude of the two limit curves (m).
    pub upper_peak: f64,
    /// Smaller resonance-peak amplitude of the two limit curves (m).
    pub lower_peak: f64,
    /// `upper_peak / lower_peak`.
    pub peak_ratio: f64,
    /// 100·(higher − lower)/lower resonance frequency of the two limit curves (%).
    pub peak_freq_change_pct: f64,
    /// Widest band, max over the grid of upper − lower limit (m).
    pub widest_band: f64,
    /// Frequency of the widest band (Hz).
    pub widest_band_hz: f64,
    /// Grid frequencies in the multiple-solution regime.
    pub multiple_points: usize,
    /// Grid frequencies.
    pub grid_points: usize,
}

impl LimitAnalysis {
    /// The size of the variability: limit peaks, their ratio and frequency change, widest band.
    pub fn variability(&self) -> Variability {
        let (a, b) = (&self.limits[0].peak, &self.limits[1].peak);
        let (upper_peak, lower_peak) = (a.amplitude.max(b.amplitude), a.amplitude.min(b.amplitude));
        let (f_hi, f_lo) = (a.freq_hz.max(b.freq_hz), a.freq_hz.min(b.freq_hz));
        let (widest_band, widest_band_hz) = self
            .grid
            .iter()
            .filter(|g| g.upper.is_finite() && g.lower.is_finite())
            .map(|g| (g.upper - g.lower, g.freq_hz))
            .fold((0.0, f64::NAN), |acc, x| if x.0 > acc.0 { x } else { acc });
        Variability {
            upper_peak,
            lower_peak,
            peak_ratio: upper_peak / lower_peak,
            peak_freq_change_pct: 100.0 * (f_hi - f_lo) / f_lo,
            widest_band,
            widest_band_hz,
            multiple_points: self
                .grid
                .iter()
                .filter(|g| matches!(g.regime, Regime::Multiple { .. }))
                .count(),
            grid_points: self.grid.len(),
        }
    }
}

/// Runs the two-point limit analysis, intermediate curves, the bound scan and the requested
/// hysteresis loops. Curves are solved in parallel (rayon); results do not depend on the
/// thread count.
///
/// `on_curve` is called as each limit, intermediate or scanned curve is solved (from worker
/// threads), so callers can write results as they come.
pub fn analyse<F>(
    problem: &Problem,
    settings: &LimitSettings,
    on_curve: F,
) -> Result<LimitAnalysis, LimitError>
where
    F: Fn(&CaseCurve) + Sync,
{
    let a = &problem.analysis.continuation;
    let n = settings.grid_points.max(2);
    let grid: Vec<f64> = (0..n)
        .map(|i| a.freq_start_hz + (a.freq_end_hz - a.freq_start_hz) * i as f64 / (n - 1) as f64)
        .collect();
    let window = settings.peak_window_hz;
    let limit_cases = two_point_cases(problem);
    let intermediate_cases = settings.intermediate_cases(problem);
    let scanned_cases = scan_cases(problem, &settings.bound_scan);

    let solve_all = |cases: &[LimitCase]| -> Result<Vec<CaseCurve>, LimitError> {
        cases
            .par_iter()
            .map(|c| {
                let curve = solve_case(problem, c, window)?;
                on_curve(&curve);
                Ok(curve)
            })
            .collect()
    };
    let limits = solve_all(&limit_cases)?;
    let intermediate = solve_all(&intermediate_cases)?;
    let limits_on_grid: Vec<_> = limits
        .par_iter()
        .map(|c| on_grid(problem, &c.case, &c.run.points, &grid))
        .collect::<Result<_, _>>()?;
    let grid_points = classify(problem, &grid, &limits_on_grid);

    let (bounds, scan_peaks) = if scanned_cases.is_empty() {
        (None, Vec::new())
    } else {
        let scanned: Vec<_> = scanned_cases
            .par_iter()
            .map(|c| {
                let curve = solve_case(problem, c, window)?;
                on_curve(&curve);
                let sols = on_grid(problem, c, &curve.run.points, &grid)?;
                Ok((c.clone(), sols, curve.peak))
            })
            .collect::<Result<_, LimitError>>()?;
        let limit_peaks: Vec<f64> = limits.iter().map(|c| c.peak.amplitude).collect();
        let check = check_bounds(&grid_points, &limit_peaks, &scanned);
        (
            Some(check),
            scanned.into_iter().map(|(c, _, p)| (c, p)).collect(),
        )
    };
    let per_curve: Vec<(Vec<LoopSet>, Vec<String>)> = limits
        .par_iter()
        .chain(intermediate.par_iter())
        .map(|c| curve_loops(problem, c, &settings.hysteresis))
        .collect::<Result<_, _>>()?;
    let (mut loops, mut loops_missing) = (Vec::new(), Vec::new());
    for (l, m) in per_curve {
        loops.extend(l);
        loops_missing.extend(m);
    }
    Ok(LimitAnalysis {
        limits,
        intermediate,
        grid: grid_points,
        bounds,
        scan_peaks,
        loops,
        loops_missing,
    })
}

/// The requested loops of one curve, and the requests it has no solution for.
fn curve_loops(
    problem: &Problem,
    curve: &CaseCurve,
    request: &HysteresisRequest,
) -> Result<(Vec<LoopSet>, Vec<String>), LimitError> {
    let p = curve.case.apply(problem);
    let contacts_err = |source| LimitError::Contacts {
        case: curve.case.name.clone(),
        source,
    };
    let mut sets = Vec::new();
    let mut missing = Vec::new();
    if request.at_peaks {
        sets.push(LoopSet {
            case: curve.case.name.clone(),
            at: "peak".to_string(),
            freq_hz: curve.peak.freq_hz,
            amplitude: curve.peak.amplitude,
            loops: hysteresis(&p, &curve.peak.coefficients).map_err(contacts_err)?,
        });
    }
    if !request.freqs_hz.is_empty() {
        let solved = on_grid(problem, &curve.case, &curve.run.points, &request.freqs_hz)?;
        for (&f, s) in request.freqs_hz.iter().zip(solved) {
            match s {
                Some((point, _)) => sets.push(LoopSet {
                    case: curve.case.name.clone(),
                    at: format!("{f} Hz"),
                    freq_hz: f,
                    amplitude: point.amplitudes[0],
                    loops: hysteresis(&p, &point.coefficients).map_err(contacts_err)?,
                }),
                None => missing.push(format!(
                    "curve `{}` has no solution at {f} Hz (outside its path or Newton failed)",
                    curve.case.name
                )),
            }
        }
    }
    Ok((sets, missing))
}

/// Time histories over one period of every contact at coefficients x: (u, T, v, N) samples.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct HysteresisLoop {
    /// Contact name.
    pub contact: String,
    /// Tangential relative displacement u(τ_k) (m).
    pub u: Vec<f64>,
    /// Tangential force T(τ_k) (N).
    pub t: Vec<f64>,
    /// Normal relative displacement v(τ_k) (m).
    pub v: Vec<f64>,
    /// Normal force N(τ_k) (N).
    pub n: Vec<f64>,
}

impl HysteresisLoop {
    /// Energy dissipated over the period, ∮ T du (J), by the trapezoidal rule over the samples
    /// (closed loop): zero for a fully stuck or open contact, positive when it slips.
    pub fn dissipated_energy(&self) -> f64 {
        let n = self.u.len().min(self.t.len());
        (0..n)
            .map(|k| {
                let j = (k + 1) % n;
                0.5 * (self.t[k] + self.t[j]) * (self.u[j] - self.u[k])
            })
            .sum()
    }
}

/// Hysteresis loops of all contacts of `problem` at coefficients x.
pub fn hysteresis(problem: &Problem, x: &[f64]) -> Result<Vec<HysteresisLoop>, HbmError> {
    let mut system = HbmSystem::new(problem)?;
    let mut loops = Vec::new();
    for (c, contact) in problem.contacts.iter().enumerate() {
        system.contact_forces(c, x, false)?;
        let aft = system.aft();
        loops.push(HysteresisLoop {
            contact: contact.name.clone(),
            u: aft.u.clone(),
            t: aft.t.clone(),
            v: aft.v.clone(),
            n: aft.n.clone(),
        });
    }
    Ok(loops)
}
