//! Test problems shared by the unit tests of the continuation's files: small residuals whose
//! paths fold smoothly or at a corner, with their settings and an observer.

use crate::numerics::jacobian::AssembledJacobian;
use crate::numerics::path::{Observer, PathPoint};
use crate::numerics::residual::ParametricResidual;

use super::settings::{ContinuationSettings, OMEGA_SCALE};

/// R(x, ω) = ω/2π − f(x) for a piecewise-linear f of the single unknown x, given as
/// (f(x), f′(x)) in Hz: a path with corners, as contact transitions make them.
pub(super) struct Graph(fn(f64) -> (f64, f64));

/// g(x) (Hz) and its slope: g rises to 15 Hz at x = 1, falls steeply to 13 Hz at x = 1.2 and
/// rises on: a Z with two folds that are sharp corners (the tangent turns by about 163°), as a
/// contact sample opening or closing makes them in the sampled contact law. The path of
/// [`z_path`].
pub(super) fn g(x: f64) -> (f64, f64) {
    if x < 1.0 {
        (10.0 + 5.0 * x, 5.0)
    } else if x < 1.2 {
        (15.0 - 10.0 * (x - 1.0), -10.0)
    } else {
        (13.0 + 5.0 * (x - 1.2), 5.0)
    }
}

#[derive(Debug, Clone, thiserror::Error)]
#[error("never")]
pub(super) struct Never;

impl ParametricResidual for Graph {
    type Error = Never;
    fn dim(&self) -> usize {
        1
    }
    fn residual_scale(&self) -> f64 {
        1.0
    }
    fn residual(&mut self, x: &[f64], omega: f64, r: &mut [f64]) -> Result<(), Never> {
        r[0] = omega / OMEGA_SCALE - (self.0)(x[0]).0;
        Ok(())
    }
    fn new_jacobian(&mut self) -> AssembledJacobian {
        AssembledJacobian::dense(1)
    }
    fn residual_and_jacobian(
        &mut self,
        x: &[f64],
        omega: f64,
        r: &mut [f64],
        jac: &mut AssembledJacobian,
        dr: &mut [f64],
    ) -> Result<(), Never> {
        self.residual(x, omega, r)?;
        jac.clear();
        let slot = jac.slot(0, 0);
        jac.add_at(slot, -(self.0)(x[0]).1);
        dr[0] = 1.0 / OMEGA_SCALE;
        Ok(())
    }
}

/// b(x) (Hz) and its slope: rising by 0.2 Hz per unit of x up to x = 1 and by 3 beyond, a
/// corner where the path bends by 60° without folding (a contact's slider changing what
/// anchors it, in the event-resolved contact law). The path of [`bend`].
pub(super) fn b(x: f64) -> (f64, f64) {
    if x < 1.0 {
        (10.0 + 0.2 * x, 0.2)
    } else {
        (10.2 + 3.0 * (x - 1.0), 3.0)
    }
}

/// The Z of [`g`].
pub(super) fn z_path() -> Graph {
    Graph(g)
}

/// The bend of [`b`].
pub(super) fn bend() -> Graph {
    Graph(b)
}

pub(super) fn settings(start: f64, end: f64) -> ContinuationSettings {
    ContinuationSettings {
        freq_start_hz: start,
        freq_end_hz: end,
        initial_step: 0.05,
        min_step: 1e-4,
        max_step: 0.2,
        max_points: 2000,
        target_iterations: 4,
        max_iterations: 12,
        residual_tolerance: 1e-12,
        step_tolerance: 1e-10,
        chord_min_unknowns: usize::MAX,
    }
}

/// R(x, ω) = ω/2π − g(x) with the smooth g(x) = 14 + x³ − 3x (Hz): an S whose folds at
/// x = −1 (16 Hz) and x = 1 (12 Hz) are smooth, as the event-resolved contact law makes them.
/// With [`SmoothS::ending_at`] the residual has no zero beyond x = c (R = 1 + R₀² there):
/// a path that cannot be followed on.
pub(super) struct SmoothS {
    end: f64,
    sparse: bool,
}

impl SmoothS {
    /// The S over the whole line.
    pub(super) fn whole() -> Self {
        Self::ending_at(f64::INFINITY)
    }

    /// The S with no solution for x > `end`.
    pub(super) fn ending_at(end: f64) -> Self {
        Self { end, sparse: false }
    }

    /// The same S with its Jacobian in sparse storage, whose factorisations a corrector with
    /// chord steps carries to the next point (a dense one is not carried).
    pub(super) fn with_sparse_jacobian(self) -> Self {
        Self {
            sparse: true,
            ..self
        }
    }

    /// g(x) (Hz).
    pub(super) fn g(x: f64) -> f64 {
        14.0 + x * x * x - 3.0 * x
    }
}

impl ParametricResidual for SmoothS {
    type Error = Never;
    fn dim(&self) -> usize {
        1
    }
    fn residual_scale(&self) -> f64 {
        1.0
    }
    fn residual(&mut self, x: &[f64], omega: f64, r: &mut [f64]) -> Result<(), Never> {
        let r0 = omega / OMEGA_SCALE - Self::g(x[0]);
        r[0] = if x[0] <= self.end { r0 } else { 1.0 + r0 * r0 };
        Ok(())
    }
    fn new_jacobian(&mut self) -> AssembledJacobian {
        if self.sparse {
            AssembledJacobian::sparse(1, [(0, 0)])
        } else {
            AssembledJacobian::dense(1)
        }
    }
    fn residual_and_jacobian(
        &mut self,
        x: &[f64],
        omega: f64,
        r: &mut [f64],
        jac: &mut AssembledJacobian,
        dr: &mut [f64],
    ) -> Result<(), Never> {
        self.residual(x, omega, r)?;
        let r0 = omega / OMEGA_SCALE - Self::g(x[0]);
        let factor = if x[0] <= self.end { 1.0 } else { 2.0 * r0 };
        jac.clear();
        let slot = jac.slot(0, 0);
        jac.add_at(slot, -factor * (3.0 * x[0] * x[0] - 3.0));
        dr[0] = factor / OMEGA_SCALE;
        Ok(())
    }
}

/// Collects the accepted points of a run.
pub(super) struct Collect<'a>(pub(super) &'a mut Vec<PathPoint>);

impl<S: ParametricResidual> Observer<S> for Collect<'_> {
    fn accepted(&mut self, _: &mut S, p: &PathPoint, _: Option<&[f64]>) {
        self.0.push(p.clone());
    }
}
