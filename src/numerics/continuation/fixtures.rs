//! Test problems shared by the unit tests of the continuation's files: small residuals whose
//! paths fold, turn sharp corners, dead-end or hairpin, with their settings and an observer.

use crate::numerics::jacobian::AssembledJacobian;
use crate::numerics::path::{Observer, PathPoint};
use crate::numerics::residual::ParametricResidual;

use super::settings::{ContinuationSettings, OMEGA_SCALE};

/// R(x, ω) = ω/2π − g(x): a path whose frequency is the piecewise-linear g of the single
/// unknown x. g rises to 15 Hz at x = 1, falls steeply to 13 Hz at x = 1.2 and rises on:
/// a Z with two folds that are sharp corners (the tangent turns by about 163°), as a
/// contact sample opening or closing makes them in the sampled contact law.
pub(super) struct ZPath;

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

impl ParametricResidual for ZPath {
    type Error = Never;
    fn dim(&self) -> usize {
        1
    }
    fn residual_scale(&self) -> f64 {
        1.0
    }
    fn residual(&mut self, x: &[f64], omega: f64, r: &mut [f64]) -> Result<(), Never> {
        r[0] = omega / OMEGA_SCALE - g(x[0]).0;
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
        jac.add_at(slot, -g(x[0]).1);
        dr[0] = 1.0 / OMEGA_SCALE;
        Ok(())
    }
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

/// A path that ends at a contact transition it cannot pass (a dead end of the sampled
/// contact law's piecewise-smooth residual): two unknowns, R₁ = ω/2π − 10 − 5x₁ and, up to
/// x₁ = 1 (15 Hz), R₂ = x₂ − 5(x₁ − 1)² (the incoming branch, curved in x₂), beyond it
/// R₂ = 1 + |x₂|, which has no zero. Past the end the Jacobian's null direction is the
/// incoming tangent, so the corner search's points behind the corner lie on the incoming
/// branch, where its curvature turns the tangent by more than the same-piece test allows
/// at the largest corner step.
pub(super) struct DeadEnd;

impl DeadEnd {
    fn second(x: &[f64]) -> (f64, f64, f64) {
        if x[0] <= 1.0 {
            let d = x[0] - 1.0;
            (x[1] - 5.0 * d * d, -10.0 * d, 1.0)
        } else {
            (1.0 + x[1].abs(), 0.0, if x[1] < 0.0 { -1.0 } else { 1.0 })
        }
    }
}

impl ParametricResidual for DeadEnd {
    type Error = Never;
    fn dim(&self) -> usize {
        2
    }
    fn residual_scale(&self) -> f64 {
        1.0
    }
    fn residual(&mut self, x: &[f64], omega: f64, r: &mut [f64]) -> Result<(), Never> {
        r[0] = omega / OMEGA_SCALE - 10.0 - 5.0 * x[0];
        r[1] = Self::second(x).0;
        Ok(())
    }
    fn new_jacobian(&mut self) -> AssembledJacobian {
        AssembledJacobian::dense(2)
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
        let (_, d1, d2) = Self::second(x);
        jac.clear();
        let slot = jac.slot(0, 0);
        jac.add_at(slot, -5.0);
        let slot = jac.slot(1, 0);
        jac.add_at(slot, d1);
        let slot = jac.slot(1, 1);
        jac.add_at(slot, d2);
        dr[0] = 1.0 / OMEGA_SCALE;
        dr[1] = 0.0;
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

/// The dead end of [`DeadEnd`] met behind a fold, as the 1D paths of the sampled contact
/// law meet theirs (`tests/hard_cases.rs` at F₀ = 1 N, 18.78 Hz, and
/// `tests/data/liftoff-fold.toml`, 32.52 Hz, both below a fold they turned back at): the
/// frequency 15 − 5(x₁ − 1)² rises to a smooth fold at 15 Hz (x₁ = 1) and falls to 10 Hz at
/// x₁ = 2, where the path ends (R₂ = x₂ − 5(x₁ − 2)² up to x₁ = 2, 1 + |x₂| beyond, which
/// has no zero).
pub(super) struct FoldThenDeadEnd;

impl FoldThenDeadEnd {
    fn second(x: &[f64]) -> (f64, f64, f64) {
        if x[0] <= 2.0 {
            let d = x[0] - 2.0;
            (x[1] - 5.0 * d * d, -10.0 * d, 1.0)
        } else {
            (1.0 + x[1].abs(), 0.0, if x[1] < 0.0 { -1.0 } else { 1.0 })
        }
    }

    fn freq_hz(x: &[f64]) -> f64 {
        15.0 - 5.0 * (x[0] - 1.0) * (x[0] - 1.0)
    }
}

impl ParametricResidual for FoldThenDeadEnd {
    type Error = Never;
    fn dim(&self) -> usize {
        2
    }
    fn residual_scale(&self) -> f64 {
        1.0
    }
    fn residual(&mut self, x: &[f64], omega: f64, r: &mut [f64]) -> Result<(), Never> {
        r[0] = omega / OMEGA_SCALE - Self::freq_hz(x);
        r[1] = Self::second(x).0;
        Ok(())
    }
    fn new_jacobian(&mut self) -> AssembledJacobian {
        AssembledJacobian::dense(2)
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
        let (_, d1, d2) = Self::second(x);
        jac.clear();
        let slot = jac.slot(0, 0);
        jac.add_at(slot, 10.0 * (x[0] - 1.0));
        let slot = jac.slot(1, 0);
        jac.add_at(slot, d1);
        let slot = jac.slot(1, 1);
        jac.add_at(slot, d2);
        dr[0] = 1.0 / OMEGA_SCALE;
        dr[1] = 0.0;
        Ok(())
    }
}

/// A corner in the response coefficients whose outgoing piece leaves behind the incoming
/// direction while the frequency keeps rising (as at the 3D blade pair's contact transitions
/// at 882-885 Hz): y = (x₁, x₂, ω/2π) runs along piece A, c + s·(1, 0, 0.1) for s ≤ 0, then
/// along piece B, c + s·(−0.5, 1, 0.1) for s > 0, with c = (1, 0, 10.1) (their chords make a
/// cosine of −0.35). R = L±·(y − c), piecewise linear and continuous across the plane
/// x₁ + x₂ = 1: L⁻ has null vector A's direction, L⁺ = L⁻ + a·(1, 1, 0)ᵀ that of B.
pub(super) struct CoefficientCorner;

impl CoefficientCorner {
    const CORNER: [f64; 3] = [1.0, 0.0, 10.1];

    fn operator(x: &[f64]) -> [[f64; 3]; 2] {
        if x[0] + x[1] <= 1.0 {
            [[-0.1, 0.0, 1.0], [0.0, 1.0, 0.0]]
        } else {
            [[-0.4, -0.3, 1.0], [-2.0, -1.0, 0.0]]
        }
    }
}

impl ParametricResidual for CoefficientCorner {
    type Error = Never;
    fn dim(&self) -> usize {
        2
    }
    fn residual_scale(&self) -> f64 {
        1.0
    }
    fn residual(&mut self, x: &[f64], omega: f64, r: &mut [f64]) -> Result<(), Never> {
        let y = [x[0], x[1], omega / OMEGA_SCALE];
        for (ri, row) in r.iter_mut().zip(Self::operator(x)) {
            *ri = (0..3).map(|j| row[j] * (y[j] - Self::CORNER[j])).sum();
        }
        Ok(())
    }
    fn new_jacobian(&mut self) -> AssembledJacobian {
        AssembledJacobian::dense(2)
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
        for (i, row) in Self::operator(x).iter().enumerate() {
            for (j, value) in row[..2].iter().enumerate() {
                let slot = jac.slot(i, j);
                jac.add_at(slot, *value);
            }
            dr[i] = row[2] / OMEGA_SCALE;
        }
        Ok(())
    }
}

/// A sharp fold at a corner whose outgoing side runs back within 1.6° of the incoming one
/// (as the 3D blade pair's fold at 874.57 Hz, whose sides lie 2.3 % apart 0.02 Hz from
/// it): y = (x₁, x₂, ω/2π) comes up along A, c + σ·a with a = (−1, −ε, −1) and σ ≥ 0, and
/// leaves along B, c + σ·b with b = (−1, ε, −1), c = (1, 0, 10.5), ε = 0.02. R = L±·(y − c)
/// is piecewise linear and continuous across the plane x₂ = 0 (L⁻ has null vector a, L⁺ =
/// L⁻ − 2·e₂·(0, 1, 0)ᵀ has b), so below 10.5 Hz both sides are solutions, 2εσ apart in x₂,
/// and above it none.
pub(super) struct Hairpin;

impl Hairpin {
    const CORNER: [f64; 3] = [1.0, 0.0, 10.5];
    pub(super) const EPS: f64 = 0.02;

    fn operator(x: &[f64]) -> [[f64; 3]; 2] {
        if x[1] <= 0.0 {
            [[1.0, 0.0, -1.0], [0.0, 1.0, -Self::EPS]]
        } else {
            [[1.0, 0.0, -1.0], [0.0, -1.0, -Self::EPS]]
        }
    }
}

impl ParametricResidual for Hairpin {
    type Error = Never;
    fn dim(&self) -> usize {
        2
    }
    fn residual_scale(&self) -> f64 {
        1.0
    }
    fn residual(&mut self, x: &[f64], omega: f64, r: &mut [f64]) -> Result<(), Never> {
        let y = [x[0], x[1], omega / OMEGA_SCALE];
        for (ri, row) in r.iter_mut().zip(Self::operator(x)) {
            *ri = (0..3).map(|j| row[j] * (y[j] - Self::CORNER[j])).sum();
        }
        Ok(())
    }
    fn new_jacobian(&mut self) -> AssembledJacobian {
        AssembledJacobian::dense(2)
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
        for (i, row) in Self::operator(x).iter().enumerate() {
            for (j, value) in row[..2].iter().enumerate() {
                let slot = jac.slot(i, j);
                jac.add_at(slot, *value);
            }
            dr[i] = row[2] / OMEGA_SCALE;
        }
        Ok(())
    }
}
