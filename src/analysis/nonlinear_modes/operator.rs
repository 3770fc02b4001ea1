//! The EPMC operator: the harmonic balance of the autonomous structure with the artificial
//! damping −ξ M q̇, in normalised harmonics, with the normalisation and phase equations
//! appended, as a [`ParametricResidual`] in the log of the modal amplitude.
//!
//! Unknowns y = (ψ, ω, ξ): ψ the harmonic coefficients in the harmonic-balance layout (all DOFs,
//! harmonic-major), ω (rad/s), ξ (1/s). The motion is x = x_s + a ψ: a the modal amplitude
//! (kg^½·m), x_s the static state at rest (m, in the 0th harmonic only; the pre-loaded
//! equilibrium with the contacts stuck, see [`super::start::rest_statics`]). The 0th harmonic
//! of ψ is the static state's change with the vibration, relative to a (Krack 2015, §3, keeps
//! the static part unscaled; relative to a, every unknown of the linear mode stays constant
//! along the path, and a static shift that grows with a, such as the offset an initial
//! tangential state gives a stuck contact, does not take over the arc length). The equations
//! are, all divided by a so that they keep their size as a falls over decades (the residual's
//! tolerance is relative to a fixed scale),
//!
//! ```text
//! R̃  = (1/a) [D(ω) x + ξ·E(ω) x + F̂c(x) − F̂_static]          (harmonic balance)
//! g₁ = s · (ψ_c1ᵀ M ψ_c1 + ψ_s1ᵀ M ψ_s1 − 1)                    (normalisation)
//! g₂ = s · √m̄ · ψ_s1[d]                                        (phase: sine of DOF d is zero)
//! ```
//!
//! with E the artificial damping's block: for the cosine rows of harmonic h −hω M q_sh, for the
//! sine rows +hω M q_ch (the linear part's damping with C replaced by C − ξ M). The equation of
//! motion is that of Krack (2015, Eq. 5), M q̈ + (C − ξ M) q̇ + K q + f_c(q) = F_static: ξ > 0
//! feeds in the energy the structure dissipates, and the modal damping ratio is D = ξ / (2ω).
//! s = ω₀² ‖M φ‖ (the size of K ψ at the start) weighs the two extra rows like the others, and
//! m̄ = tr M / n makes ψ's entries dimensionless in g₂. Since ∂x/∂ψ = a I, the Jacobian's ψ block
//! is the harmonic balance's ∂R/∂x (plus ξE), unscaled.
//!
//! The continuation parameter λ is the decade of a: λ / 2π = 1 + log₁₀(a / a_min), so that
//! continuation, which measures λ in "Hz" (λ / 2π), counts one unit per decade from 1 at
//! a_min (see [`LogAmplitude`]).

use crate::contact::harmonic::HarmonicSet;
use crate::hbm::{HbmError, HbmSystem};
use crate::model::Problem;
use crate::numerics::jacobian::{AssembledJacobian, Storage};
use crate::numerics::ParametricResidual;

/// The map between the continuation parameter λ and the modal amplitude a:
/// a = a_min · 10^(λ/2π − 1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LogAmplitude {
    /// Modal amplitude at λ/2π = 1 (kg^½·m).
    pub a_min: f64,
}

impl LogAmplitude {
    /// The modal amplitude a (kg^½·m) at λ.
    pub fn amplitude(&self, lambda: f64) -> f64 {
        self.a_min * 10f64.powf(lambda / std::f64::consts::TAU - 1.0)
    }

    /// λ/2π ("Hz" of the continuation) of the modal amplitude a.
    pub fn decade(&self, a: f64) -> f64 {
        1.0 + (a / self.a_min).log10()
    }

    /// da/dλ divided by a: ln 10 / 2π.
    pub fn log_derivative() -> f64 {
        std::f64::consts::LN_10 / std::f64::consts::TAU
    }
}

/// The EPMC operator of a problem (module docs). The problem must have no harmonic loads
/// (the autonomous structure); its static loads stay.
pub struct EpmcOperator<'p> {
    system: HbmSystem<'p>,
    n: usize,
    nb: usize,
    cos1: usize,
    sin1: usize,
    constant: Option<usize>,
    /// Static state at rest x_s (m), added to the 0th harmonic.
    statics: Vec<f64>,
    phase_dof: usize,
    /// Weight s of the extra rows (N/kg^½, the size of K ψ).
    pub(super) row_scale: f64,
    /// √(tr M / n) (kg^½).
    mass_root: f64,
    residual_scale: f64,
    map: LogAmplitude,
    jac_h: AssembledJacobian,
    r_h: Vec<f64>,
    dr_h: Vec<f64>,
}

impl<'p> EpmcOperator<'p> {
    /// The operator on the autonomous `problem` about the static state `statics` (m, one per
    /// DOF; ignored when the statics are uncoupled), with the phase fixed at DOF `phase_dof`,
    /// the amplitude map `map` and the extra rows weighted by `row_scale` (N/kg^½), which is
    /// also the residual's scale.
    ///
    /// The harmonic balance is held in dense storage (the extended Jacobian is dense).
    pub fn new(
        problem: &'p Problem,
        statics: Vec<f64>,
        phase_dof: usize,
        map: LogAmplitude,
        row_scale: f64,
    ) -> Result<Self, HbmError> {
        let mut system = HbmSystem::new(problem)?;
        system.set_storage(Storage::Dense)?;
        let set = system.unknowns().clone();
        let n = problem.model.n_dofs();
        let (cos1, sin1) = first_harmonic_blocks(&set);
        let mut trace = 0.0;
        problem.model.mass.for_each_nonzero(|i, j, v| {
            if i == j {
                trace += v;
            }
        });
        let jac_h = system.new_jacobian();
        let dim_h = system.dim();
        Ok(Self {
            n,
            nb: set.n_blocks(),
            cos1,
            sin1,
            constant: set.constant_block(),
            statics,
            phase_dof,
            row_scale,
            mass_root: (trace / n as f64).sqrt(),
            residual_scale: row_scale.max(f64::MIN_POSITIVE),
            map,
            jac_h,
            r_h: vec![0.0; dim_h],
            dr_h: vec![0.0; dim_h],
            system,
        })
    }

    /// The harmonic-balance system (contact states and time histories of the last evaluation).
    pub fn system(&mut self) -> &mut HbmSystem<'p> {
        &mut self.system
    }

    /// The (autonomous) problem.
    pub fn problem(&self) -> &'p Problem {
        self.system.problem()
    }

    /// The harmonic set of ψ.
    pub fn unknowns(&self) -> &HarmonicSet {
        self.system.unknowns()
    }

    /// The amplitude map.
    pub fn map(&self) -> LogAmplitude {
        self.map
    }

    /// Unknowns of ψ (DOFs × blocks).
    pub fn harmonic_dim(&self) -> usize {
        self.n * self.nb
    }

    /// Block index of the cosine and sine of the first harmonic.
    pub fn first_harmonic(&self) -> (usize, usize) {
        (self.cos1, self.sin1)
    }

    /// The motion's coefficients x = x_s + a ψ (m).
    pub fn physical(&self, psi: &[f64], a: f64) -> Vec<f64> {
        let n = self.n;
        let mut x: Vec<f64> = psi[..n * self.nb].iter().map(|v| a * v).collect();
        if let Some(j) = self.constant {
            for (v, s) in x[j * n..(j + 1) * n].iter_mut().zip(&self.statics) {
                *v += s;
            }
        }
        x
    }

    /// ψ of the motion x at modal amplitude a: (x − x_s) / a.
    pub fn normalised(&self, x: &[f64], a: f64) -> Vec<f64> {
        let n = self.n;
        let mut psi = x.to_vec();
        if let Some(j) = self.constant {
            for (v, s) in psi[j * n..(j + 1) * n].iter_mut().zip(&self.statics) {
                *v -= s;
            }
        }
        psi.iter_mut().for_each(|v| *v /= a);
        psi
    }

    /// The artificial damping's term ξ E(ω) x into `out` (added), on the harmonic layout, and
    /// E x alone (its ∂/∂ξ) into `d_xi`, E'(ω) x (its ∂/∂ω without ξ) into `d_omega`.
    fn artificial_damping(
        &self,
        x: &[f64],
        (omega, xi): (f64, f64),
        out: &mut [f64],
        d_xi: &mut [f64],
        d_omega: &mut [f64],
    ) {
        let n = self.n;
        let set = self.system.unknowns();
        let mx = self.system.problem().model.mass.mul_blocks(x, self.nb);
        for (j, b) in set.blocks().iter().enumerate() {
            let Some((pj, sign)) = set.quadrature_partner(*b) else {
                continue;
            };
            let h = b.harmonic() as f64;
            for p in 0..n {
                let e = sign * h * mx[(p, pj)];
                d_omega[j * n + p] = e;
                d_xi[j * n + p] = omega * e;
                out[j * n + p] += xi * omega * e;
            }
        }
    }

    /// The two extra rows (normalisation, phase) of ψ.
    fn constraints(&self, psi: &[f64]) -> [f64; 2] {
        let n = self.n;
        let mass = &self.system.problem().model.mass;
        let mut norm = -1.0;
        for j in [self.cos1, self.sin1] {
            let block = &psi[j * n..(j + 1) * n];
            let mut m_block = vec![0.0; n];
            mass.mul_add(1.0, block, &mut m_block);
            norm += block.iter().zip(&m_block).map(|(a, b)| a * b).sum::<f64>();
        }
        [
            self.row_scale * norm,
            self.row_scale * self.mass_root * psi[self.sin1 * n + self.phase_dof],
        ]
    }

    /// Residual and, with `jacobian`, its Jacobian (dense, n_h + 2 square) and ∂/∂λ.
    fn evaluate(
        &mut self,
        y: &[f64],
        lambda: f64,
        r: &mut [f64],
        jacobian: Option<(&mut AssembledJacobian, &mut [f64])>,
    ) -> Result<(), HbmError> {
        let dim_h = self.harmonic_dim();
        let (omega, xi) = (y[dim_h], y[dim_h + 1]);
        let a = self.map.amplitude(lambda);
        let x = self.physical(y, a);
        let mut r_h = std::mem::take(&mut self.r_h);
        let mut dr_h = std::mem::take(&mut self.dr_h);
        let mut jac_h = match jacobian {
            Some(_) => Some(std::mem::replace(
                &mut self.jac_h,
                AssembledJacobian::dense(0),
            )),
            None => None,
        };
        let result = match jac_h.as_mut() {
            Some(j) => self
                .system
                .residual_and_jacobian(&x, omega, &mut r_h, j, &mut dr_h),
            None => self.system.residual(&x, omega, &mut r_h),
        };
        if let Err(e) = result {
            self.r_h = r_h;
            self.dr_h = dr_h;
            if let Some(j) = jac_h {
                self.jac_h = j;
            }
            return Err(e);
        }
        let (mut d_xi, mut d_omega) = (vec![0.0; dim_h], vec![0.0; dim_h]);
        self.artificial_damping(&x, (omega, xi), &mut r_h, &mut d_xi, &mut d_omega);
        for i in 0..dim_h {
            r[i] = r_h[i] / a;
        }
        let [g1, g2] = self.constraints(y);
        r[dim_h] = g1;
        r[dim_h + 1] = g2;
        if let (Some((jac, dr_dlambda)), Some(jh)) = (jacobian, jac_h.as_ref()) {
            self.fill_jacobian(y, (a, omega, xi), jh, (&dr_h, &d_xi, &d_omega), jac);
            self.parameter_column(y, r, jac, dr_dlambda);
        }
        self.r_h = r_h;
        self.dr_h = dr_h;
        if let Some(j) = jac_h {
            self.jac_h = j;
        }
        Ok(())
    }

    /// The extended Jacobian from the harmonic balance's ∂R/∂x (`jh`), ∂R/∂ω of its linear
    /// part and the artificial damping's derivatives (module docs).
    fn fill_jacobian(
        &self,
        y: &[f64],
        (a, omega, xi): (f64, f64, f64),
        jh: &AssembledJacobian,
        (dr_h, d_xi, d_omega): (&[f64], &[f64], &[f64]),
        jac: &mut AssembledJacobian,
    ) {
        let n = self.n;
        let dim_h = self.harmonic_dim();
        jac.clear();
        for (i, j, v) in jh.triplets() {
            let slot = jac.slot(i, j);
            jac.add_at(slot, v);
        }
        // ξ E: cosine rows of harmonic h against its sine block, and back; E's entries ±hω M.
        let set = self.system.unknowns();
        let mass = self.system.problem().model.mass.triplets();
        for (j, b) in set.blocks().iter().enumerate() {
            let Some((pj, sign)) = set.quadrature_partner(*b) else {
                continue;
            };
            let e = sign * b.harmonic() as f64 * omega * xi;
            for &(p, q, m) in &mass {
                let slot = jac.slot(j * n + p, pj * n + q);
                jac.add_at(slot, e * m);
            }
        }
        for i in 0..dim_h {
            let row = 1.0 / a;
            let s_omega = jac.slot(i, dim_h);
            jac.add_at(s_omega, row * (dr_h[i] + xi * d_omega[i]));
            let s_xi = jac.slot(i, dim_h + 1);
            jac.add_at(s_xi, row * d_xi[i]);
        }
        let mass = &self.system.problem().model.mass;
        for j in [self.cos1, self.sin1] {
            let mut m_block = vec![0.0; n];
            mass.mul_add(1.0, &y[j * n..(j + 1) * n], &mut m_block);
            for (p, v) in m_block.iter().enumerate() {
                let slot = jac.slot(dim_h, j * n + p);
                jac.add_at(slot, 2.0 * self.row_scale * v);
            }
        }
        let slot = jac.slot(dim_h + 1, self.sin1 * n + self.phase_dof);
        jac.add_at(slot, self.row_scale * self.mass_root);
    }

    /// ∂R̃/∂λ from the filled Jacobian: (dR̃/da)·a·ln10/2π with a·dR̃/da = −R̃ + J̃ ψ (J̃ the
    /// Jacobian's ψ block, since ∂x/∂a = ψ); zero on the extra rows.
    fn parameter_column(
        &self,
        y: &[f64],
        r: &[f64],
        jac: &AssembledJacobian,
        dr_dlambda: &mut [f64],
    ) {
        let dim_h = self.harmonic_dim();
        let k = LogAmplitude::log_derivative();
        dr_dlambda.iter_mut().for_each(|v| *v = 0.0);
        for (i, j, v) in jac.triplets() {
            if i < dim_h && j < dim_h {
                dr_dlambda[i] += k * v * y[j];
            }
        }
        for i in 0..dim_h {
            dr_dlambda[i] -= k * r[i];
        }
    }
}

/// The cosine and sine blocks of the first harmonic.
///
/// # Panics
/// If the set has no first harmonic (the scene check requires it for this analysis).
#[track_caller]
pub(super) fn first_harmonic_blocks(set: &HarmonicSet) -> (usize, usize) {
    match (set.cos_block(1), set.sin_block(1)) {
        (Some(c), Some(s)) => (c, s),
        _ => panic!("nonlinear modes need the first harmonic in the harmonic set"),
    }
}

impl ParametricResidual for EpmcOperator<'_> {
    type Error = HbmError;

    fn dim(&self) -> usize {
        self.harmonic_dim() + 2
    }

    fn residual_scale(&self) -> f64 {
        self.residual_scale
    }

    /// The harmonic balance's round-off level at the motion (its sums of K x, M x, C x and the
    /// loads, [`HbmSystem::round_off`]) divided by a, as the rows are: at small amplitudes the
    /// static rows' round-off (K x_s against the pre-load, large on an FE model) is amplified
    /// by 1/a, and Newton cannot go below it.
    fn round_off(&mut self, y: &[f64], lambda: f64) -> f64 {
        let a = self.map.amplitude(lambda);
        let x = self.physical(y, a);
        self.system.round_off(&x, y[self.harmonic_dim()]) / a
    }

    fn residual(&mut self, y: &[f64], lambda: f64, r: &mut [f64]) -> Result<(), HbmError> {
        self.evaluate(y, lambda, r, None)
    }

    fn new_jacobian(&mut self) -> AssembledJacobian {
        AssembledJacobian::dense(self.dim())
    }

    fn residual_and_jacobian(
        &mut self,
        y: &[f64],
        lambda: f64,
        r: &mut [f64],
        jac: &mut AssembledJacobian,
        dr_dlambda: &mut [f64],
    ) -> Result<(), HbmError> {
        self.evaluate(y, lambda, r, Some((jac, dr_dlambda)))
    }
}
