//! Harmonic-balance residual R(x, ω) = D(ω) x + F̂_c(x) − F̂_ex (paper Eq. 7) and its Jacobian.
//!
//! The unknown x holds the Fourier coefficients of all DOFs, harmonic-major (see
//! [`crate::contact::harmonic`]). For harmonic h the linear part acting on (q_ch, q_sh) is
//!
//! ```text
//! ⎡ K − (hω)²M     hωC      ⎤ ⎡q_ch⎤
//! ⎣   −hωC       K − (hω)²M ⎦ ⎣q_sh⎦
//! ```
//!
//! and the 0th harmonic (when coupled) is K q₀ + F̂_c,0 − F_static = 0, which carries the pre-load
//! into the contacts (paper Eq. 3: statics and dynamics coupled through the contact forces).
//! In the uncoupled mode the 0th harmonic is fixed by a static pre-solve ([`static_solve`]) and
//! only h ≥ 1 are unknowns.
//!
//! The Jacobian ∂R/∂x is dense here (lumped and reduced models); contact blocks come from the
//! analytic AFT Jacobian or, as a checked alternative, from finite differences.

use crate::contact::aft::{AftError, AftWorkspace};
use crate::contact::harmonic::{Block, HarmonicSet};
use crate::contact::ContactState;
use crate::hbm::formulation::RelativeCoordinatesError;
use crate::hbm::pattern::{ContactSlots, JacobianLayout};
use crate::hbm::schur::RelativeCoordinates;
use crate::model::{Coupling, Formulation, JacobianStrategy, Problem};
use crate::numerics::jacobian::{AssembledJacobian, Storage};
use crate::numerics::linalg::LinearSolveError;
use crate::numerics::ParametricResidual;
use std::sync::Arc;

/// Errors while evaluating or solving the harmonic balance.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HbmError {
    /// The AFT of a contact failed.
    #[error("contact `{contact}`: {source}")]
    Aft {
        /// Contact name.
        contact: String,
        /// Cause.
        source: AftError,
    },
    /// A linear solve failed.
    #[error("linear solve: {0}")]
    Linear(#[from] LinearSolveError),
    /// The problem does not admit the formulation asked for.
    #[error("formulation: {0}")]
    Formulation(#[from] RelativeCoordinatesError),
    /// The static pre-solve of the uncoupled mode did not converge.
    #[error("static pre-solve did not converge in {iterations} iterations (relative residual {residual:.3e})")]
    StaticNotConverged {
        /// Iterations made.
        iterations: usize,
        /// Final residual norm relative to the static load.
        residual: f64,
    },
}

/// The harmonic-balance operator of a problem.
pub struct HbmSystem<'p> {
    problem: &'p Problem,
    unknowns: HarmonicSet,
    /// For each unknown block, its index in the AFT block list.
    block_map: Vec<usize>,
    /// Fixed 0th harmonic of the DOFs in the uncoupled mode (zeros when coupled).
    static_offset: Vec<f64>,
    excitation: Vec<f64>,
    aft: AftWorkspace,
    u_coef: Vec<f64>,
    v_coef: Vec<f64>,
    /// Contact states of the last evaluation, one per contact.
    pub states: Vec<ContactState>,
    /// Jacobian strategy (from the problem, may be changed for checks and benchmarks).
    pub strategy: JacobianStrategy,
    /// Storage of the full Jacobian.
    storage: Storage,
    /// Pattern and slot tables, built on the first Jacobian request.
    layout: Option<JacobianLayout>,
    /// Relative contact coordinates of the schur formulation.
    relative: Option<Arc<RelativeCoordinates>>,
}

impl<'p> HbmSystem<'p> {
    /// Builds the operator; in the uncoupled mode this runs the static pre-solve.
    pub fn new(problem: &'p Problem) -> Result<Self, HbmError> {
        let unknowns = problem.unknown_harmonics();
        let force_set = problem.force_harmonics();
        let block_map = unknowns
            .blocks()
            .iter()
            .map(|b| {
                force_set
                    .blocks()
                    .iter()
                    .position(|c| c == b)
                    .expect("unknown harmonics are a subset of the force harmonics")
            })
            .collect();
        let n = problem.model.n_dofs();
        let nbf = force_set.n_blocks();
        let mut aft = AftWorkspace::new(&force_set, problem.samples);
        aft.settings = problem.march;
        let mut excitation = vec![0.0; n * unknowns.n_blocks()];
        if let Some(j) = unknowns.constant_block() {
            excitation[j * n..(j + 1) * n].copy_from_slice(&problem.static_load);
        }
        for load in &problem.harmonic_loads {
            if let Some(j) = unknowns.cos_block(load.harmonic) {
                excitation[j * n + load.dof] += load.cos;
            }
            if let Some(j) = unknowns.sin_block(load.harmonic) {
                excitation[j * n + load.dof] += load.sin;
            }
        }
        let static_offset = match problem.effects.coupling {
            Coupling::Coupled => vec![0.0; n],
            Coupling::Uncoupled => static_solve(problem)?,
        };
        let storage = match problem.formulation() {
            Formulation::Sparse => Storage::Sparse,
            Formulation::Schur => Storage::Schur,
            _ => Storage::Dense,
        };
        let relative = match storage {
            Storage::Schur => Some(Arc::new(RelativeCoordinates::new(problem, &unknowns)?)),
            _ => None,
        };
        Ok(Self {
            problem,
            block_map,
            static_offset,
            excitation,
            aft,
            u_coef: vec![0.0; nbf],
            v_coef: vec![0.0; nbf],
            states: vec![ContactState::Open; problem.contacts.len()],
            strategy: problem.analysis.jacobian,
            storage,
            layout: None,
            relative,
            unknowns,
        })
    }

    /// Storage of the full Jacobian (dense or sparse, from the problem's formulation).
    pub fn storage(&self) -> Storage {
        self.storage
    }

    /// Uses `storage` for the Jacobian from now on (for comparisons and benchmarks); the
    /// schur storage fails when the problem has no independent relative contact coordinates.
    pub fn set_storage(&mut self, storage: Storage) -> Result<(), HbmError> {
        if storage == Storage::Schur && self.relative.is_none() {
            self.relative = Some(Arc::new(RelativeCoordinates::new(
                self.problem,
                &self.unknowns,
            )?));
        }
        if storage != self.storage {
            self.storage = storage;
            self.layout = None;
        }
        Ok(())
    }

    fn layout(&mut self) -> &JacobianLayout {
        if self.layout.is_none() {
            self.layout = Some(match (&self.relative, self.storage) {
                (Some(r), Storage::Schur) => {
                    JacobianLayout::relative(self.problem, &self.unknowns, Arc::clone(r))
                }
                _ => JacobianLayout::new(self.problem, &self.unknowns, self.storage),
            });
        }
        self.layout.as_ref().expect("built above")
    }

    /// The problem.
    pub fn problem(&self) -> &'p Problem {
        self.problem
    }

    /// Harmonic set of the unknowns.
    pub fn unknowns(&self) -> &HarmonicSet {
        &self.unknowns
    }

    /// Number of unknowns (DOFs × coefficient blocks).
    pub fn dim(&self) -> usize {
        self.problem.model.n_dofs() * self.unknowns.n_blocks()
    }

    /// The fixed 0th harmonic in the uncoupled mode (zeros when coupled).
    pub fn static_offset(&self) -> &[f64] {
        &self.static_offset
    }

    /// Excitation vector F̂_ex in the unknown layout (N).
    pub fn excitation(&self) -> &[f64] {
        &self.excitation
    }

    /// Norm used to make residuals relative: ‖F̂_ex‖ including static loads, and the static
    /// load in the uncoupled mode (N).
    pub fn load_norm(&self) -> f64 {
        let e: f64 = self.excitation.iter().map(|x| x * x).sum();
        let s: f64 = self.problem.static_load.iter().map(|x| x * x).sum();
        e.max(s).sqrt().max(f64::MIN_POSITIVE)
    }

    /// Mutable access to the AFT workspace (for time histories after an evaluation).
    pub fn aft(&mut self) -> &mut AftWorkspace {
        &mut self.aft
    }

    /// Fills û, v̂ of contact `c` on the AFT blocks from the unknowns x.
    fn contact_coefficients(&mut self, c: usize, x: &[f64]) {
        let n = self.problem.model.n_dofs();
        let contact = &self.problem.contacts[c];
        self.u_coef.iter_mut().for_each(|v| *v = 0.0);
        self.v_coef.iter_mut().for_each(|v| *v = 0.0);
        for (j, &jf) in self.block_map.iter().enumerate() {
            let q = &x[j * n..(j + 1) * n];
            self.u_coef[jf] = contact.tangential_of(q);
            self.v_coef[jf] = contact.normal_of(q);
        }
        // The AFT set always has the constant block first (harmonic 0 sorts first).
        if !self.unknowns.has_constant() {
            self.u_coef[0] = contact.tangential_of(&self.static_offset);
            self.v_coef[0] = contact.normal_of(&self.static_offset);
        }
        self.v_coef[0] -= contact.gap;
    }

    /// Runs the AFT of contact `c` at x; results stay in the workspace.
    pub fn contact_forces(
        &mut self,
        c: usize,
        x: &[f64],
        jacobian: bool,
    ) -> Result<ContactState, HbmError> {
        self.contact_coefficients(c, x);
        let contact = &self.problem.contacts[c];
        let report = self
            .aft
            .evaluate(
                &contact.law,
                self.problem.effects.contact,
                &self.u_coef,
                &self.v_coef,
                jacobian,
            )
            .map_err(|source| HbmError::Aft {
                contact: contact.name.clone(),
                source,
            })?;
        self.states[c] = report.state;
        Ok(report.state)
    }

    /// Linear part D(ω)x − F̂_ex into r, and ∂(D x)/∂ω into `dr_domega` if given. K, M and C
    /// are applied to all coefficient blocks at once ([`StructuralMatrix::mul_blocks`]).
    ///
    /// [`StructuralMatrix::mul_blocks`]: crate::model::matrix::StructuralMatrix::mul_blocks
    fn linear_residual(&self, x: &[f64], omega: f64, r: &mut [f64], dr_domega: Option<&mut [f64]>) {
        let n = self.problem.model.n_dofs();
        let m = &self.problem.model;
        let blocks = self.unknowns.blocks();
        let nb = blocks.len();
        let kx = m.stiffness.mul_blocks(x, nb);
        let mx = m.mass.mul_blocks(x, nb);
        let cx = m.damping.mul_blocks(x, nb);
        for (j, b) in blocks.iter().enumerate() {
            let hw = b.harmonic() as f64 * omega;
            let partner = self.partner(*b);
            let rj = &mut r[j * n..(j + 1) * n];
            for (p, v) in rj.iter_mut().enumerate() {
                *v = kx[(p, j)] - hw * hw * mx[(p, j)] - self.excitation[j * n + p];
            }
            if let Some((pj, c_sign)) = partner {
                for (p, v) in rj.iter_mut().enumerate() {
                    *v += c_sign * hw * cx[(p, pj)];
                }
            }
        }
        if let Some(dr) = dr_domega {
            for (j, b) in blocks.iter().enumerate() {
                let h = b.harmonic() as f64;
                let partner = self.partner(*b);
                let drj = &mut dr[j * n..(j + 1) * n];
                for (p, v) in drj.iter_mut().enumerate() {
                    *v = -2.0 * h * h * omega * mx[(p, j)];
                }
                if let Some((pj, c_sign)) = partner {
                    for (p, v) in drj.iter_mut().enumerate() {
                        *v += c_sign * h * cx[(p, pj)];
                    }
                }
            }
        }
    }

    /// The block coupled to `b` through damping and the sign of that coupling: the cosine
    /// block of harmonic h gets +hωC q_sh, the sine block −hωC q_ch.
    fn partner(&self, b: Block) -> Option<(usize, f64)> {
        match b {
            Block::Cos(h) => self.unknowns.sin_block(h).map(|j| (j, 1.0)),
            Block::Sin(h) => self.unknowns.cos_block(h).map(|j| (j, -1.0)),
            Block::Constant => None,
        }
    }

    /// A Jacobian in the storage of this system, with its pattern (and, when sparse, its
    /// symbolic factorisation, shared with every other Jacobian of this system).
    pub fn new_jacobian(&mut self) -> AssembledJacobian {
        self.layout().new_jacobian()
    }

    /// Linear part of ∂R/∂x into `jac` (overwrites).
    fn linear_jacobian(&mut self, omega: f64, jac: &mut AssembledJacobian) {
        jac.clear();
        jac.set_frequency(omega);
        let blocks = self.unknowns.blocks().to_vec();
        let partners: Vec<Option<(usize, f64)>> = blocks.iter().map(|b| self.partner(*b)).collect();
        let layout = self.layout();
        for (j, b) in blocks.iter().enumerate() {
            let hw = b.harmonic() as f64 * omega;
            for &(slot, k, m) in &layout.stiffness[j] {
                jac.add_at(slot, k - hw * hw * m);
            }
            if let Some((_, c_sign)) = partners[j] {
                for &(slot, c) in &layout.damping[j] {
                    jac.add_at(slot, c_sign * hw * c);
                }
            }
        }
    }

    /// Adds the contact forces to r (and, with `jac`, the analytic contact Jacobian).
    fn add_contacts(
        &mut self,
        x: &[f64],
        r: &mut [f64],
        jac: Option<&mut AssembledJacobian>,
    ) -> Result<(), HbmError> {
        match jac {
            None => self.add_contact_terms(x, r, None),
            Some(jac) => {
                let layout = self
                    .layout
                    .take()
                    .expect("the linear Jacobian built the layout");
                let result = self.add_contact_terms(x, r, Some((jac, &layout.contacts)));
                self.layout = Some(layout);
                result
            }
        }
    }

    /// Adds the contact forces at full coefficients x to r (full layout), and their analytic
    /// Jacobian into `jac` at the given slots (one [`ContactSlots`] per contact).
    pub fn add_contact_terms(
        &mut self,
        x: &[f64],
        r: &mut [f64],
        mut jac: Option<(&mut AssembledJacobian, &[ContactSlots])>,
    ) -> Result<(), HbmError> {
        let n = self.problem.model.n_dofs();
        let nbf = self.aft.harmonic_set().n_blocks();
        let nb = self.block_map.len();
        let problem = self.problem;
        for c in 0..problem.contacts.len() {
            self.contact_forces(c, x, jac.is_some())?;
            let contact = &problem.contacts[c];
            for (j, &jf) in self.block_map.iter().enumerate() {
                let t = self.aft.t_hat[jf];
                let nn = self.aft.n_hat[jf];
                for &(p, a) in &contact.tangential {
                    r[j * n + p] += a * t;
                }
                for &(p, a) in &contact.normal {
                    r[j * n + p] += a * nn;
                }
            }
            if let Some((jac, slots)) = jac.as_mut() {
                let lc = &slots[c];
                let d = lc.dofs;
                for (j, &jf) in self.block_map.iter().enumerate() {
                    for (i, &if_) in self.block_map.iter().enumerate() {
                        let tu = self.aft.dt_du[jf * nbf + if_];
                        let tv = self.aft.dt_dv[jf * nbf + if_];
                        let nv = self.aft.dn_dv[jf * nbf + if_];
                        if tu == 0.0 && tv == 0.0 && nv == 0.0 {
                            continue;
                        }
                        let slots = &lc.slots[(j * nb + i) * d * d..(j * nb + i + 1) * d * d];
                        for &(a, ap) in &lc.tangential {
                            for &(b, aq) in &lc.tangential {
                                jac.add_at(slots[a * d + b], ap * tu * aq);
                            }
                            for &(b, aq) in &lc.normal {
                                jac.add_at(slots[a * d + b], ap * tv * aq);
                            }
                        }
                        for &(a, ap) in &lc.normal {
                            for &(b, aq) in &lc.normal {
                                jac.add_at(slots[a * d + b], ap * nv * aq);
                            }
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// Residual R(x, ω) into r (length [`Self::dim`]); ω in rad/s.
    pub fn residual(&mut self, x: &[f64], omega: f64, r: &mut [f64]) -> Result<(), HbmError> {
        self.linear_residual(x, omega, r, None);
        self.add_contacts(x, r, None)
    }

    /// Residual, ∂R/∂x (by the current strategy) and ∂R/∂ω at (x, ω).
    pub fn residual_and_jacobian(
        &mut self,
        x: &[f64],
        omega: f64,
        r: &mut [f64],
        jac: &mut AssembledJacobian,
        dr_domega: &mut [f64],
    ) -> Result<(), HbmError> {
        match self.strategy {
            JacobianStrategy::Analytic => {
                self.linear_residual(x, omega, r, Some(dr_domega));
                self.linear_jacobian(omega, jac);
                self.add_contacts(x, r, Some(jac))
            }
            JacobianStrategy::ForwardDifference | JacobianStrategy::CentralDifference
                if self.storage == Storage::Schur =>
            {
                self.linear_residual(x, omega, r, Some(dr_domega));
                self.linear_jacobian(omega, jac);
                self.add_contacts(x, r, None)?;
                let states = self.states.clone();
                let central = self.strategy == JacobianStrategy::CentralDifference;
                self.contact_difference_blocks(x, central, jac)?;
                self.states = states;
                Ok(())
            }
            JacobianStrategy::ForwardDifference | JacobianStrategy::CentralDifference => {
                self.layout();
                self.linear_residual(x, omega, r, Some(dr_domega));
                self.add_contacts(x, r, None)?;
                let states = self.states.clone();
                self.finite_difference_jacobian(x, omega, r, jac)?;
                self.states = states;
                Ok(())
            }
        }
    }

    /// The contact blocks of the schur storage by forward or central differences of each
    /// contact's AFT with respect to its own relative-coordinate coefficients (û, v̂ on every
    /// unknown block): 2·blocks (forward) or 4·blocks (central) contact evaluations per
    /// contact, the linear part being exact. Steps as in [`finite_difference_jacobian`],
    /// relative to |coefficient| or, when smaller, the RMS of x.
    fn contact_difference_blocks(
        &mut self,
        x: &[f64],
        central: bool,
        jac: &mut AssembledJacobian,
    ) -> Result<(), HbmError> {
        let nb = self.block_map.len();
        let dim = x.len().max(1);
        let typical = (x.iter().map(|v| v * v).sum::<f64>() / dim as f64).sqrt();
        let eps = if central { 6e-6 } else { 1.5e-8 };
        let problem = self.problem;
        let slots = self
            .layout()
            .contacts
            .iter()
            .map(|c| c.slots.clone())
            .collect::<Vec<_>>();
        for c in 0..problem.contacts.len() {
            self.contact_coefficients(c, x);
            let (u0, v0) = (self.u_coef.clone(), self.v_coef.clone());
            let base = self.contact_force_coefficients(c, &u0, &v0)?;
            for (i, &if_) in self.block_map.clone().iter().enumerate() {
                for b in 0..2 {
                    let value = if b == 0 { u0[if_] } else { v0[if_] };
                    let step = eps * value.abs().max(typical).max(1e-12);
                    let perturbed = |sign: f64| {
                        let (mut u, mut v) = (u0.clone(), v0.clone());
                        if b == 0 {
                            u[if_] += sign * step;
                        } else {
                            v[if_] += sign * step;
                        }
                        (u, v)
                    };
                    let (up, vp) = perturbed(1.0);
                    let plus = self.contact_force_coefficients(c, &up, &vp)?;
                    let minus = if central {
                        let (um, vm) = perturbed(-1.0);
                        Some(self.contact_force_coefficients(c, &um, &vm)?)
                    } else {
                        None
                    };
                    for (j, &jf) in self.block_map.iter().enumerate() {
                        for a in 0..2 {
                            let d = match &minus {
                                Some(m) => (plus[a][jf] - m[a][jf]) / (2.0 * step),
                                None => (plus[a][jf] - base[a][jf]) / step,
                            };
                            jac.add_at(slots[c][((j * nb + i) * 2 + a) * 2 + b], d);
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// T̂ and N̂ (AFT blocks) of contact `c` at given û, v̂ (v̂ including the gap).
    fn contact_force_coefficients(
        &mut self,
        c: usize,
        u: &[f64],
        v: &[f64],
    ) -> Result<[Vec<f64>; 2], HbmError> {
        let contact = &self.problem.contacts[c];
        self.aft
            .evaluate(&contact.law, self.problem.effects.contact, u, v, false)
            .map_err(|source| HbmError::Aft {
                contact: contact.name.clone(),
                source,
            })?;
        Ok([self.aft.t_hat.clone(), self.aft.n_hat.clone()])
    }

    /// ∂R/∂x by forward or central differences (the strategy decides), given R at x.
    fn finite_difference_jacobian(
        &mut self,
        x: &[f64],
        omega: f64,
        r0: &[f64],
        jac: &mut AssembledJacobian,
    ) -> Result<(), HbmError> {
        let central = self.strategy == JacobianStrategy::CentralDifference;
        finite_difference_jacobian(|x, r| self.residual(x, omega, r), x, r0, central, jac)
    }
}

impl ParametricResidual for HbmSystem<'_> {
    type Error = HbmError;
    fn dim(&self) -> usize {
        HbmSystem::dim(self)
    }
    fn residual_scale(&self) -> f64 {
        self.load_norm()
    }
    fn residual(&mut self, x: &[f64], lambda: f64, r: &mut [f64]) -> Result<(), Self::Error> {
        HbmSystem::residual(self, x, lambda, r)
    }
    fn new_jacobian(&mut self) -> AssembledJacobian {
        HbmSystem::new_jacobian(self)
    }
    fn residual_and_jacobian(
        &mut self,
        x: &[f64],
        lambda: f64,
        r: &mut [f64],
        jac: &mut AssembledJacobian,
        dr_dlambda: &mut [f64],
    ) -> Result<(), Self::Error> {
        HbmSystem::residual_and_jacobian(self, x, lambda, r, jac, dr_dlambda)
    }
}

/// ∂R/∂x of any residual by forward (one evaluation per unknown) or central (two) differences,
/// given R at x. Steps are relative to |xᵢ| or, when smaller, to the RMS of x.
pub fn finite_difference_jacobian<E>(
    mut residual: impl FnMut(&[f64], &mut [f64]) -> Result<(), E>,
    x: &[f64],
    r0: &[f64],
    central: bool,
    jac: &mut AssembledJacobian,
) -> Result<(), E> {
    let dim = x.len();
    let mut xp = x.to_vec();
    let mut rp = vec![0.0; dim];
    let mut rm = vec![0.0; if central { dim } else { 0 }];
    let mut column = vec![0.0; dim];
    let typical = (x.iter().map(|v| v * v).sum::<f64>() / dim.max(1) as f64).sqrt();
    let eps = if central { 6e-6 } else { 1.5e-8 };
    jac.clear();
    for i in 0..dim {
        let step = eps * x[i].abs().max(typical).max(1e-12);
        xp[i] = x[i] + step;
        residual(&xp, &mut rp)?;
        if central {
            xp[i] = x[i] - step;
            residual(&xp, &mut rm)?;
            for k in 0..dim {
                column[k] = (rp[k] - rm[k]) / (2.0 * step);
            }
        } else {
            for k in 0..dim {
                column[k] = (rp[k] - r0[k]) / step;
            }
        }
        jac.set_column(i, &column);
        xp[i] = x[i];
    }
    Ok(())
}

/// Static pre-solve of the uncoupled mode: K q + F_c,static(q) = F_static, with each contact
/// loaded from rest (slider at zero): N = kₙ max(v, 0), T = clamp(kₜ u, −μN, μN). Newton with
/// backtracking, on the Jacobian storage of the problem's formulation.
pub fn static_solve(problem: &Problem) -> Result<Vec<f64>, HbmError> {
    let n = problem.model.n_dofs();
    let k = &problem.model.stiffness;
    let f = &problem.static_load;
    let fnorm = f
        .iter()
        .map(|x| x * x)
        .sum::<f64>()
        .sqrt()
        .max(f64::MIN_POSITIVE);
    // The static system has one block: dense unless the model is held sparse (the schur
    // formulation's elimination would not pay off on one block).
    let storage = if problem.formulation() == Formulation::Sparse {
        Storage::Sparse
    } else {
        Storage::Dense
    };
    let layout = JacobianLayout::new(problem, &HarmonicSet::new(vec![0]), storage);
    let residual_of = |q: &[f64], r: &mut [f64], jac: Option<&mut AssembledJacobian>| {
        for (p, v) in r.iter_mut().enumerate() {
            *v = -f[p];
        }
        k.mul_add(1.0, q, r);
        let mut jac = jac;
        if let Some(j) = jac.as_deref_mut() {
            j.clear();
            for &(slot, kv, _) in &layout.stiffness[0] {
                j.add_at(slot, kv);
            }
        }
        for (c, lc) in problem.contacts.iter().zip(&layout.contacts) {
            let law = &c.law;
            let u = c.tangential_of(q);
            let v = c.normal_of(q) - c.gap;
            let nf = (law.kn * v).max(0.0);
            let limit = law.mu * nf;
            let tp = law.kt * u;
            let t = tp.clamp(-limit, limit);
            for &(p, a) in &c.tangential {
                r[p] += a * t;
            }
            for &(p, a) in &c.normal {
                r[p] += a * nf;
            }
            if let Some(j) = jac.as_deref_mut() {
                if v >= 0.0 {
                    let d = lc.dofs;
                    for &(a, ap) in &lc.normal {
                        for &(b, aq) in &lc.normal {
                            j.add_at(lc.slots[a * d + b], ap * law.kn * aq);
                        }
                    }
                    for &(a, ap) in &lc.tangential {
                        if tp.abs() <= limit || limit == 0.0 {
                            for &(b, aq) in &lc.tangential {
                                j.add_at(lc.slots[a * d + b], ap * law.kt * aq);
                            }
                        } else {
                            for &(b, aq) in &lc.normal {
                                j.add_at(
                                    lc.slots[a * d + b],
                                    ap * tp.signum() * law.mu * law.kn * aq,
                                );
                            }
                        }
                    }
                }
            }
        }
    };
    let mut q = vec![0.0; n];
    let mut r = vec![0.0; n];
    let mut jac = layout.new_jacobian();
    let max_iterations = 100;
    let mut rel = f64::INFINITY;
    let mut trial = vec![0.0; n];
    let mut rt = vec![0.0; n];
    for _ in 0..max_iterations {
        residual_of(&q, &mut r, Some(&mut jac));
        rel = r.iter().map(|x| x * x).sum::<f64>().sqrt() / fnorm;
        if rel <= 1e-12 {
            return Ok(q);
        }
        let neg: Vec<f64> = r.iter().map(|x| -x).collect();
        let dq = jac.solve(&neg)?;
        // Backtracking on the residual norm keeps the non-smooth contact law from cycling.
        let mut alpha = 1.0;
        loop {
            for p in 0..n {
                trial[p] = q[p] + alpha * dq[p];
            }
            residual_of(&trial, &mut rt, None);
            let rel_t = rt.iter().map(|x| x * x).sum::<f64>().sqrt() / fnorm;
            if rel_t < rel || alpha < 1e-4 {
                break;
            }
            alpha *= 0.5;
        }
        q.copy_from_slice(&trial);
    }
    Err(HbmError::StaticNotConverged {
        iterations: max_iterations,
        residual: rel,
    })
}

/// Comparison of the analytic Jacobian with central differences at one state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JacobianCheck {
    /// Largest |analytic − central difference| over ∂R/∂x and ∂R/∂ω (scaled per column).
    pub max_error: f64,
    /// Largest |entry| of the analytic Jacobian (same scaling).
    pub max_entry: f64,
}

impl JacobianCheck {
    /// max_error / max_entry.
    pub fn relative(&self) -> f64 {
        self.max_error / self.max_entry.max(f64::MIN_POSITIVE)
    }
}

/// Checks the analytic Jacobian of `system` at (x, ω) against central differences with
/// relative step `rel_step` (on each unknown, scaled by the state's RMS value). Columns are
/// compared after multiplying by their step scale, so x- and ω-columns weigh alike.
pub fn check_jacobian(
    system: &mut HbmSystem<'_>,
    x: &[f64],
    omega: f64,
    rel_step: f64,
) -> Result<JacobianCheck, HbmError> {
    let saved = system.strategy;
    system.strategy = JacobianStrategy::Analytic;
    let result = check_operator_jacobian(system, x, omega, rel_step);
    system.strategy = saved;
    result
}

/// [`check_jacobian`] for any operator: compares the Jacobian the operator forms (whatever its
/// strategy and storage, entries outside a sparse pattern count as zero) with central
/// differences of its residual.
pub fn check_operator_jacobian<S: ParametricResidual>(
    system: &mut S,
    x: &[f64],
    omega: f64,
    rel_step: f64,
) -> Result<JacobianCheck, S::Error> {
    let dim = system.dim();
    let mut r = vec![0.0; dim];
    let mut jac = system.new_jacobian();
    let mut dw = vec![0.0; dim];
    let result = (|| {
        system.residual_and_jacobian(x, omega, &mut r, &mut jac, &mut dw)?;
        let typical = (x.iter().map(|v| v * v).sum::<f64>() / dim as f64)
            .sqrt()
            .max(1e-12);
        let mut xp = x.to_vec();
        let (mut rp, mut rm) = (vec![0.0; dim], vec![0.0; dim]);
        let mut max_error = 0.0_f64;
        let mut max_entry = 0.0_f64;
        for i in 0..=dim {
            let (scale, step) = if i < dim {
                (typical, rel_step * typical)
            } else {
                (omega, rel_step * omega)
            };
            if i < dim {
                xp[i] = x[i] + step;
                system.residual(&xp, omega, &mut rp)?;
                xp[i] = x[i] - step;
                system.residual(&xp, omega, &mut rm)?;
                xp[i] = x[i];
            } else {
                system.residual(x, omega + step, &mut rp)?;
                system.residual(x, omega - step, &mut rm)?;
            }
            for k in 0..dim {
                let fd = (rp[k] - rm[k]) / (2.0 * step);
                let an = if i < dim { jac.get(k, i) } else { dw[k] };
                max_error = max_error.max((fd - an).abs() * scale);
                max_entry = max_entry.max(an.abs() * scale);
            }
        }
        Ok(JacobianCheck {
            max_error,
            max_entry,
        })
    })();
    result
}
