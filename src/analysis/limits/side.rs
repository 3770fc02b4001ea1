//! Damper sides: their static (0th-harmonic) contact forces T⁰ and N⁰, their state over a
//! period (stuck, slipping, open), and the regime and limit labels these give a grid frequency
//! (paper §3.2).

use crate::contact::ContactState;
use crate::hbm::{HbmError, HbmSystem};
use crate::model::Problem;

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
        let (tangential, normal) = system.last_constant_forces(c);
        out[contact.side].tangential += tangential;
        out[contact.side].normal += normal;
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
