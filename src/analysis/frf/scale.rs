//! The arc length's scales and step groups, from the stuck-linear response over the range: so
//! that a large static part does not dominate the path's steps.

use std::f64::consts::PI;

use crate::analysis::linear;
use crate::contact::harmonic::{Block, HarmonicSet};
use crate::hbm::operator::HbmOperator;
use crate::model::Problem;
use crate::numerics::continuation::AdaptiveScale;
use crate::numerics::linalg::LinearSolveError;

/// Scale of each unknown in the arc length (m), in the operator's layout: per coefficient
/// block, the largest stuck-linear response norm of that kind of block over the range (the
/// static block's norm for the 0th harmonic, the dynamic blocks' for the others), divided so
/// that climbing to it costs a quarter of the range in arc length.
///
/// One scale for all unknowns would let a large static part (a high pre-load) dominate the
/// arc length: the dynamic response would then hardly count, steps would grow to the largest
/// one and cross resonance peaks. Each kind of block gets its own scale, with a floor of 10⁻³
/// of the other so that a block without load (no static load) does not get a zero scale.
pub(super) fn arc_length_x_scale(
    problem: &Problem,
    set: &HarmonicSet,
    system: &HbmOperator<'_>,
) -> Result<Vec<f64>, LinearSolveError> {
    let a = &problem.analysis.continuation;
    // The 0th harmonic of the guess does not depend on ω: solved once, the dynamic harmonics
    // on the grid.
    let dynamic = HarmonicSet::new(
        set.harmonics()
            .iter()
            .copied()
            .filter(|&h| h != 0)
            .collect(),
    );
    let static_norm = if set.has_constant() {
        crate::numerics::linalg::norm(&linear::stuck_guess(
            problem,
            &HarmonicSet::new(vec![0]),
            0.0,
        )?)
    } else {
        0.0
    };
    let mut dynamic_norm = 0.0_f64;
    for i in 0..=40 {
        let f = a.freq_start_hz + (a.freq_end_hz - a.freq_start_hz) * i as f64 / 40.0;
        let x = linear::stuck_guess(problem, &dynamic, 2.0 * PI * f)?;
        dynamic_norm = dynamic_norm.max(crate::numerics::linalg::norm(&x));
    }
    let x_ref = static_norm.hypot(dynamic_norm);
    let range = a.freq_end_hz - a.freq_start_hz;
    let to_scale =
        |block_norm: f64| (block_norm.max(1e-3 * x_ref) / (0.25 * range)).max(f64::MIN_POSITIVE);
    let (static_scale, dynamic_scale) = (to_scale(static_norm), to_scale(dynamic_norm));
    let n = problem.model.n_dofs();
    let full: Vec<f64> = set
        .blocks()
        .iter()
        .flat_map(|b| {
            let s = match b {
                Block::Constant => static_scale,
                _ => dynamic_scale,
            };
            std::iter::repeat_n(s, n)
        })
        .collect();
    Ok(system.restrict(&full))
}

/// The groups of [`arc_length_x_scale`] (static block, dynamic blocks) as an adaptive scale:
/// each grows with its block's norm along the path, at the same climb (a quarter of the range).
pub(super) fn adaptive_scale(
    problem: &Problem,
    set: &HarmonicSet,
    system: &HbmOperator<'_>,
) -> AdaptiveScale {
    let a = &problem.analysis.continuation;
    let n = problem.model.n_dofs();
    let full: Vec<f64> = set
        .blocks()
        .iter()
        .flat_map(|b| {
            let g = if *b == Block::Constant { 0.0 } else { 1.0 };
            std::iter::repeat_n(g, n)
        })
        .collect();
    AdaptiveScale {
        group_of: system.restrict(&full).iter().map(|&g| g as usize).collect(),
        climb: 0.25 * (a.freq_end_hz - a.freq_start_hz),
    }
}

/// For each output DOF, the indices of its first-harmonic cosine and sine among the operator's
/// unknowns (outputs the operator does not carry are left out), for the step length to follow
/// the output amplitudes ([`Continuation::with_amplitude_steps`](crate::numerics::continuation::Continuation::with_amplitude_steps)).
pub(super) fn output_amplitude_groups(
    problem: &Problem,
    set: &HarmonicSet,
    system: &HbmOperator<'_>,
) -> Vec<Vec<usize>> {
    let n = problem.model.n_dofs();
    let blocks: Vec<usize> = [set.cos_block(1), set.sin_block(1)]
        .into_iter()
        .flatten()
        .collect();
    problem
        .outputs
        .iter()
        .filter_map(|&d| {
            let mut marker = vec![0.0; n * set.n_blocks()];
            for &j in &blocks {
                marker[j * n + d] = 1.0;
            }
            let group: Vec<usize> = system
                .restrict(&marker)
                .iter()
                .enumerate()
                .filter(|(_, &v)| v == 1.0)
                .map(|(i, _)| i)
                .collect();
            (!group.is_empty()).then_some(group)
        })
        .collect()
}
