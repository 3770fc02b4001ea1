//! Response limits among multiple solutions: the two-point method per damper side (paper §3).
//!
//! A fully stuck contact's static tangential force T⁰ is not unique (paper §3.1); with a wedge
//! damper, the static balance couples it to the normal load N⁰ of the other side (Eqs. 11-13),
//! so when one side is fully stuck and the other slips (§3.2, case 3) the response is not
//! unique either. The limits come from the two extreme initial tangential states of the stuck
//! side, T(τ=0) = ±μN(τ=0) (Eqs. 14-15), which put the slipping side at its maximum N⁰
//! (closest to stuck) and minimum N⁰ (closest to free).
//!
//! A [`LimitCase`] assigns one initial state m to every damper side (all points of a side start
//! the march at T = mμN). The two-point method solves the cases "m = +1 on every side" and
//! "m = −1 on every side": wherever one side is stuck, the pair holds both of its limit states.
//! The curves are then put on a common frequency grid (each grid point solved exactly by
//! Newton), every grid point is classified (unique or multiple-solution regime, which sides
//! stick or slip), and in the multiple-solution regime each limit curve is labelled by the
//! static normal load it gives the slipping side. Which label has the larger amplitude is not
//! assumed: near the optimum pre-load the two cross (paper Fig. 15b).
//!
//! Whether the limits really bound the other solutions is checked, not assumed: a scan over
//! intermediate states per side reports the largest excursion outside the band.

use rayon::prelude::*;

use crate::contact::ContactState;
use crate::frf::{self, interpolate_on_path, FrfError, FrfPoint, FrfRun, PointSolver, Silent};
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
}

/// Initial tangential state per damper side.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct LimitCase {
    /// Name used in file names and column headers (e.g. `m+1`, `m-0.5`, `left+0.5_right-0.5`).
    pub name: String,
    /// m ∈ [−1, 1] for each damper side, in the problem's side order.
    pub side_states: Vec<f64>,
}

impl LimitCase {
    /// The same m on every side.
    pub fn uniform(problem: &Problem, m: f64) -> Self {
        Self {
            name: format!("m{}", signed(m)),
            side_states: vec![m; problem.sides.len()],
        }
    }

    /// The problem with every contact's initial state set from its side.
    pub fn apply(&self, problem: &Problem) -> Problem {
        let mut p = problem.clone();
        for c in &mut p.contacts {
            c.law.initial_state = self.side_states[c.side];
        }
        p
    }
}

fn signed(m: f64) -> String {
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
        let name = problem
            .sides
            .iter()
            .zip(&side_states)
            .map(|(s, m)| format!("{}{}", s.name, signed(*m)))
            .collect::<Vec<_>>()
            .join("_");
        cases.push(LimitCase { name, side_states });
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
    /// Whether the peak was refined by extra solves (false when it lies at the range end).
    pub refined: bool,
    /// Coefficients at the peak.
    #[serde(skip)]
    pub coefficients: Vec<f64>,
    /// Contact states at the peak.
    pub states: Vec<ContactState>,
}

/// Locates the largest first-harmonic amplitude of output `output` on a path and refines it by
/// a golden-section search over frequency between the neighbours of the best sampled point,
/// each trial solved exactly at its frequency (d|q|/dω = 0 to a relative 1e-7 in frequency).
pub fn refine_peak(
    problem: &Problem,
    points: &[FrfPoint],
    output: usize,
) -> Result<Peak, FrfError> {
    let best = points
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.amplitudes[output].total_cmp(&b.1.amplitudes[output]))
        .map(|(i, _)| i)
        .expect("a run has at least one point");
    let p = &points[best];
    let unrefined = || Peak {
        freq_hz: p.freq_hz,
        amplitude: p.amplitudes[output],
        refined: false,
        coefficients: p.coefficients.clone(),
        states: p.states.clone(),
    };
    if best == 0 || best + 1 == points.len() {
        return Ok(unrefined());
    }
    let (fa, fb) = (points[best - 1].freq_hz, points[best + 1].freq_hz);
    let (mut lo, mut hi) = if fa < fb { (fa, fb) } else { (fb, fa) };
    let mut solver = PointSolver::new(problem)?;
    let mut eval = |f: f64| -> Option<FrfPoint> {
        let guess = interpolate_on_path(&points[best - 1..=best + 1], f)?;
        solver.solve(&guess, f).ok()
    };
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    let mut c = hi - ratio * (hi - lo);
    let mut d = lo + ratio * (hi - lo);
    let (mut pc, mut pd) = (eval(c), eval(d));
    let amp = |q: &Option<FrfPoint>| {
        q.as_ref()
            .map(|q| q.amplitudes[output])
            .unwrap_or(f64::NEG_INFINITY)
    };
    for _ in 0..80 {
        if (hi - lo) <= 1e-7 * p.freq_hz {
            break;
        }
        if amp(&pc) >= amp(&pd) {
            hi = d;
            d = c;
            pd = pc;
            c = hi - ratio * (hi - lo);
            pc = eval(c);
        } else {
            lo = c;
            c = d;
            pc = pd;
            d = lo + ratio * (hi - lo);
            pd = eval(d);
        }
    }
    let candidate = if amp(&pc) >= amp(&pd) { pc } else { pd };
    Ok(match candidate {
        Some(q) if q.amplitudes[output] >= p.amplitudes[output] => Peak {
            freq_hz: q.freq_hz,
            amplitude: q.amplitudes[output],
            refined: true,
            coefficients: q.coefficients,
            states: q.states,
        },
        _ => unrefined(),
    })
}

/// One solved curve.
#[derive(Debug, Clone, PartialEq)]
pub struct CaseCurve {
    /// The case.
    pub case: LimitCase,
    /// The continuation run.
    pub run: FrfRun,
    /// Refined peak of the first output DOF.
    pub peak: Peak,
}

/// Solves the FRF of one case and refines its peak (first output DOF).
pub fn solve_case(problem: &Problem, case: &LimitCase) -> Result<CaseCurve, LimitError> {
    let p = case.apply(problem);
    let err = |source| LimitError::Curve {
        case: case.name.clone(),
        source,
    };
    let run = frf::solve(&p, &mut Silent).map_err(err)?;
    let peak = refine_peak(&p, &run.points, 0).map_err(err)?;
    Ok(CaseCurve {
        case: case.clone(),
        run,
        peak,
    })
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

/// A curve solved exactly at each grid frequency (None where no path segment brackets it or
/// Newton fails).
pub fn on_grid(
    problem: &Problem,
    case: &LimitCase,
    points: &[FrfPoint],
    grid: &[f64],
) -> Result<Vec<Option<(FrfPoint, Vec<SideStatics>)>>, LimitError> {
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
pub fn classify(
    problem: &Problem,
    grid: &[f64],
    per_case: &[Vec<Option<(FrfPoint, Vec<SideStatics>)>>],
) -> Vec<GridPoint> {
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
}

/// Compares scanned curves (on the grid) and their peaks with the limits.
pub fn check_bounds(
    grid: &[GridPoint],
    limit_peaks: &[f64],
    scanned: &[(LimitCase, Vec<Option<(FrfPoint, Vec<SideStatics>)>>, Peak)],
) -> BoundCheck {
    let mut b = BoundCheck {
        max_excess_above: 0.0,
        above_at: None,
        max_excess_below: 0.0,
        below_at: None,
        peak_excess_above: 0.0,
        peak_excess_below: 0.0,
        compared: 0,
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
            if above > b.max_excess_above {
                b.max_excess_above = above;
                b.above_at = Some((g.freq_hz, case.name.clone()));
            }
            let below = (g.lower - a) / g.lower;
            if below > b.max_excess_below {
                b.max_excess_below = below;
                b.below_at = Some((g.freq_hz, case.name.clone()));
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

/// Settings of a limit analysis.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct LimitSettings {
    /// m values of the intermediate curves (the same m on every side).
    pub intermediate: Vec<f64>,
    /// Points of the common frequency grid.
    pub grid_points: usize,
    /// m values scanned per side (all combinations) to test the bounds; empty disables.
    pub bound_scan: Vec<f64>,
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
}

/// Runs the two-point limit analysis, intermediate curves and the bound scan. Curves are
/// solved in parallel (rayon); results do not depend on the thread count.
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
    let a = &problem.analysis;
    let n = settings.grid_points.max(2);
    let grid: Vec<f64> = (0..n)
        .map(|i| a.freq_start_hz + (a.freq_end_hz - a.freq_start_hz) * i as f64 / (n - 1) as f64)
        .collect();
    let limit_cases = two_point_cases(problem);
    let intermediate_cases: Vec<LimitCase> = settings
        .intermediate
        .iter()
        .map(|&m| LimitCase::uniform(problem, m))
        .collect();
    let scanned_cases = scan_cases(problem, &settings.bound_scan);

    let solve_all = |cases: &[LimitCase]| -> Result<Vec<CaseCurve>, LimitError> {
        cases
            .par_iter()
            .map(|c| {
                let curve = solve_case(problem, c)?;
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
                let curve = solve_case(problem, c)?;
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
    Ok(LimitAnalysis {
        limits,
        intermediate,
        grid: grid_points,
        bounds,
        scan_peaks,
    })
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
