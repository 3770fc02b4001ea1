//! The common frequency grid: a curve solved exactly at each grid frequency (Newton from its
//! path), and every grid frequency classified from the limit cases (regime, labels, band).

use crate::analysis::frf::{interpolate_on_path, FrfPoint, PointSolver};
use crate::contact::ContactState;
use crate::model::Problem;

use super::case::LimitCase;
use super::error::LimitError;
use super::side::{side_states, side_statics, LimitLabel, Regime, SideState, SideStatics};

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
