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
//! In the uncoupled mode the 0th harmonic is fixed by a static pre-solve ([`crate::hbm::statics::static_solve`]) and
//! only h ≥ 1 are unknowns.
//!
//! The Jacobian ∂R/∂x is dense here (lumped and reduced models); contact blocks come from the
//! analytic AFT Jacobian or, as a checked alternative, from finite differences.

use crate::contact::aft::AftWorkspace;
use crate::contact::aft2d::Aft2dWorkspace;
use crate::contact::harmonic::{Block, HarmonicSet};
use crate::contact::{ContactState, Jenkins2dLaw, JenkinsLaw, TimeResolution};
use crate::hbm::error::HbmError;
use crate::hbm::pattern::{ContactSlots, JacobianLayout};
use crate::hbm::schur::RelativeCoordinates;
use crate::hbm::statics::static_solve;
use crate::model::{Coupling, Formulation, JacobianStrategy, Problem};
use crate::numerics::derivatives::{check_operator_jacobian, JacobianCheck};
use crate::numerics::jacobian::{AssembledJacobian, Storage};
use crate::numerics::ParametricResidual;
use std::sync::Arc;

mod differences;

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
    /// The march of the 2D-friction points; None when the problem has none (costs nothing).
    aft2d: Option<Aft2dWorkspace>,
    u_coef: Vec<f64>,
    /// Coefficients of the second tangential displacement u₂ (2D points only).
    u2_coef: Vec<f64>,
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
    /// Initial tangential state (m₁, m₂) of every contact set by
    /// [`HbmSystem::set_initial_states`] or [`HbmSystem::set_initial_states_2d`], in place of
    /// the problem's; `None`: the problem's. m₂ is used by 2D points only.
    initial_states: Option<Vec<[f64; 2]>>,
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
        let aft2d = problem
            .contacts
            .iter()
            .any(|c| c.law_2d().is_some())
            .then(|| {
                let mut w = Aft2dWorkspace::new(&force_set, problem.samples);
                // The 2D march settles geometrically (slowly near grazing, see
                // `aft2d::DEFAULT_MAX_PERIODS`): it keeps its own period budget unless the scene
                // asks for more.
                w.settings = crate::contact::aft::MarchSettings {
                    max_periods: problem.march.max_periods.max(w.settings.max_periods),
                    ..problem.march
                };
                w
            });
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
        // The periodicity tolerance of both marches is never finer than round-off against the
        // loads on the structure (`MarchSettings::force_scale`): the total force applied, the
        // static loads' and the harmonic amplitudes' magnitudes summed (N). A sum, not a norm:
        // a load shared over many nodes (a pre-load distributed by mass) counts in full.
        let force_scale = problem.static_load.iter().map(|x| x.abs()).sum::<f64>()
            + problem
                .harmonic_loads
                .iter()
                .map(|l| l.cos.hypot(l.sin))
                .sum::<f64>();
        aft.settings.force_scale = force_scale;
        let aft2d = aft2d.map(|mut w| {
            w.settings.force_scale = force_scale;
            w
        });
        let static_offset = match problem.effects.coupling {
            Coupling::Coupled => vec![0.0; n],
            Coupling::Uncoupled => static_solve(problem)?,
        };
        let storage = match problem.formulation() {
            Formulation::Sparse => Storage::Sparse,
            Formulation::Schur | Formulation::SchurLowRank => Storage::Schur,
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
            aft2d,
            u_coef: vec![0.0; nbf],
            u2_coef: vec![0.0; nbf],
            v_coef: vec![0.0; nbf],
            states: vec![ContactState::Open; problem.contacts.len()],
            strategy: problem.analysis.jacobian,
            storage,
            layout: None,
            relative,
            unknowns,
            initial_states: None,
        })
    }

    /// Sets the initial tangential state m ∈ [−1, 1] of every contact (one per contact, in the
    /// problem's order), in place of the problem's `law.initial_state`, without rebuilding the
    /// system (its Jacobian pattern, symbolic factorisation and AFT plans do not depend on m).
    /// The response envelope solves many states of one problem that differ only in m. The
    /// residual and Jacobian are then those of the problem with these initial states.
    ///
    /// # Panics
    /// If `m` does not have one entry per contact.
    ///
    /// The m given is along the first tangent; a 2D point keeps the problem's m₂ when its m₁ is
    /// the problem's, and starts at (m, 0) otherwise, as a limit case does
    /// ([`crate::analysis::limits::LimitCase::apply`]).
    #[track_caller]
    pub fn set_initial_states(&mut self, m: &[f64]) {
        assert_eq!(
            m.len(),
            self.problem.contacts.len(),
            "one initial state per contact"
        );
        let states = self
            .problem
            .contacts
            .iter()
            .zip(m)
            .map(|(c, &m1)| {
                let m2 = c.second_tangent.as_ref().map_or(0.0, |s| s.initial_state);
                [m1, if m1 == c.law.initial_state { m2 } else { 0.0 }]
            })
            .collect();
        self.initial_states = Some(states);
    }

    /// [`Self::set_initial_states`] with both components (m₁, m₂) of every contact (m₂ is
    /// ignored on 1D points; |m| ≤ 1 is the caller's to keep).
    ///
    /// # Panics
    /// If `m` does not have one entry per contact.
    #[track_caller]
    pub fn set_initial_states_2d(&mut self, m: &[[f64; 2]]) {
        assert_eq!(
            m.len(),
            self.problem.contacts.len(),
            "one initial state per contact"
        );
        self.initial_states = Some(m.to_vec());
    }

    /// The Jenkins law contact `c` is evaluated with: the problem's, with the initial state set
    /// by [`HbmSystem::set_initial_states`] if any.
    pub fn law(&self, c: usize) -> JenkinsLaw {
        let mut law = self.problem.contacts[c].law;
        if let Some(m) = &self.initial_states {
            law.initial_state = m[c][0];
        }
        law
    }

    /// The 2D law contact `c` is evaluated with (None for a 1D point): the problem's, with the
    /// initial state set by [`HbmSystem::set_initial_states`] if any.
    pub fn law_2d(&self, c: usize) -> Option<Jenkins2dLaw> {
        let mut law = self.problem.contacts[c].law_2d()?;
        if let Some(m) = &self.initial_states {
            law.initial_state = m[c];
        }
        Some(law)
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

    /// The 2D AFT workspace (None when the problem has no 2D-friction point); after
    /// [`Self::contact_forces`] of a 2D point it holds that point's time histories.
    pub fn aft2d(&mut self) -> Option<&mut Aft2dWorkspace> {
        self.aft2d.as_mut()
    }

    /// Constant (0th-harmonic) forces (T̂₁⁰, N̂⁰) (N) of the last [`Self::contact_forces`] of
    /// contact `c`, from whichever march (1D or 2D) its law uses; T̂₁⁰ is along the first tangent.
    pub fn last_constant_forces(&self, c: usize) -> (f64, f64) {
        match (
            &self.aft2d,
            self.problem.contacts[c].second_tangent.is_some(),
        ) {
            (Some(w), true) => (w.t_hat[0][0], w.n_hat[0]),
            _ => (self.aft.t_hat[0], self.aft.n_hat[0]),
        }
    }

    /// Fills û, v̂ (and û₂ for a 2D point) of contact `c` on the AFT blocks from the unknowns x.
    fn contact_coefficients(&mut self, c: usize, x: &[f64]) {
        let n = self.problem.model.n_dofs();
        let contact = &self.problem.contacts[c];
        self.u_coef.iter_mut().for_each(|v| *v = 0.0);
        self.u2_coef.iter_mut().for_each(|v| *v = 0.0);
        self.v_coef.iter_mut().for_each(|v| *v = 0.0);
        for (j, &jf) in self.block_map.iter().enumerate() {
            let q = &x[j * n..(j + 1) * n];
            self.u_coef[jf] = contact.tangential_of(q);
            self.u2_coef[jf] = contact.second_tangential_of(q);
            self.v_coef[jf] = contact.normal_of(q);
        }
        // The AFT set always has the constant block first (harmonic 0 sorts first).
        if !self.unknowns.has_constant() {
            self.u_coef[0] = contact.tangential_of(&self.static_offset);
            self.u2_coef[0] = contact.second_tangential_of(&self.static_offset);
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
        let state = self.march_contact(c, jacobian)?;
        self.states[c] = state;
        Ok(state)
    }

    /// Marches contact `c` from the coefficients û, û₂, v̂ in the system's buffers (filled by
    /// [`Self::contact_coefficients`], v̂ including the gap) with the march its law needs: the
    /// 2D workspace for a 2D point, the 1D one otherwise; event-resolved for `jenkins-1d` and
    /// `jenkins-2d`, sampled for `jenkins-1d-sampled` and `jenkins-2d-sampled`. The forces (and, with
    /// `jacobian`, their derivatives) stay in that workspace. The one place that chooses
    /// between the two marches.
    fn march_contact(&mut self, c: usize, jacobian: bool) -> Result<ContactState, HbmError> {
        let law = self.law(c);
        let contact = &self.problem.contacts[c];
        let effects = self.problem.effects.contact;
        let report = match (self.law_2d(c), self.aft2d.as_mut()) {
            (Some(law), Some(aft2d)) => {
                let u = [self.u_coef.as_slice(), self.u2_coef.as_slice()];
                match contact.resolution {
                    TimeResolution::Events => {
                        aft2d.evaluate_events(&law, effects, u, &self.v_coef, jacobian)
                    }
                    TimeResolution::Samples => {
                        aft2d.evaluate(&law, effects, u, &self.v_coef, jacobian)
                    }
                }
            }
            _ => match contact.resolution {
                TimeResolution::Events => {
                    self.aft
                        .evaluate_events(&law, effects, &self.u_coef, &self.v_coef, jacobian)
                }
                TimeResolution::Samples => {
                    self.aft
                        .evaluate(&law, effects, &self.u_coef, &self.v_coef, jacobian)
                }
            },
        }
        .map_err(|source| HbmError::Aft {
            contact: contact.name.clone(),
            source,
        })?;
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

    /// Round-off level of the residual at (x, ω) (N): ε ‖ |K||q_j| + (hω)²|M||q_j| +
    /// hω|C||q_partner| + |F_j| ‖ over the coefficient blocks j (entries and coefficients taken
    /// by absolute value), the size of the rounding errors of the linear part's sums. The
    /// contact forces add terms of the size of the forces themselves, which the loads they
    /// balance already count. Costs one pass over the nonzeros of K, M and C per block.
    pub fn round_off(&self, x: &[f64], omega: f64) -> f64 {
        let n = self.problem.model.n_dofs();
        let m = &self.problem.model;
        let blocks = self.unknowns.blocks();
        let mut sum: Vec<f64> = self.excitation.iter().map(|f| f.abs()).collect();
        for (j, b) in blocks.iter().enumerate() {
            let hw = b.harmonic() as f64 * omega;
            let (q, y) = (&x[j * n..(j + 1) * n], j * n);
            m.stiffness
                .for_each_nonzero(|p, c, v| sum[y + p] += (v * q[c]).abs());
            if hw != 0.0 {
                m.mass
                    .for_each_nonzero(|p, c, v| sum[y + p] += (hw * hw * v * q[c]).abs());
            }
            if let Some((pj, _)) = self.partner(*b) {
                let qp = &x[pj * n..(pj + 1) * n];
                m.damping
                    .for_each_nonzero(|p, c, v| sum[y + p] += (hw * v * qp[c]).abs());
            }
        }
        f64::EPSILON * sum.iter().map(|v| v * v).sum::<f64>().sqrt()
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
            if contact.second_tangent.is_some() {
                let slots = jac.as_mut().map(|(jac, slots)| (&mut **jac, &slots[c]));
                self.add_contact_terms_2d(c, r, slots);
                continue;
            }
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

    /// The forces of 2D-friction contact `c` (just evaluated) into r, and their analytic
    /// Jacobian at `slots`: forces (T̂₁, T̂₂, N̂) act along the rows (aₜ₁, aₜ₂, aₙ), and
    /// ∂(T̂₁, T̂₂)/∂(û₁, û₂, v̂), ∂N̂/∂v̂ come from [`Aft2dWorkspace::evaluate`].
    fn add_contact_terms_2d(
        &mut self,
        c: usize,
        r: &mut [f64],
        jac: Option<(&mut AssembledJacobian, &ContactSlots)>,
    ) {
        let n = self.problem.model.n_dofs();
        let nb = self.block_map.len();
        let contact = &self.problem.contacts[c];
        let aft = self.aft2d.as_ref().expect("2D points have a 2D workspace");
        let nbf = aft.harmonic_set().n_blocks();
        let second = &contact
            .second_tangent
            .as_ref()
            .expect("called for 2D points")
            .row;
        for (j, &jf) in self.block_map.iter().enumerate() {
            let forces = [aft.t_hat[0][jf], aft.t_hat[1][jf], aft.n_hat[jf]];
            for (row, force) in [&contact.tangential, second, &contact.normal]
                .into_iter()
                .zip(forces)
            {
                for &(p, a) in row {
                    r[j * n + p] += a * force;
                }
            }
        }
        let Some((jac, lc)) = jac else {
            return;
        };
        let d = lc.dofs;
        let local_rows = [&lc.tangential, &lc.tangential2, &lc.normal];
        let width = 3 * nbf;
        for (j, &jf) in self.block_map.iter().enumerate() {
            for (i, &if_) in self.block_map.iter().enumerate() {
                let slots = &lc.slots[(j * nb + i) * d * d..(j * nb + i + 1) * d * d];
                for force in 0..3 {
                    for coordinate in 0..3 {
                        let value = match (force, coordinate) {
                            (2, 2) => aft.dn_dv[jf * nbf + if_],
                            (2, _) => 0.0,
                            (f, b) => aft.dt_dx[(f * nbf + jf) * width + b * nbf + if_],
                        };
                        if value == 0.0 {
                            continue;
                        }
                        for &(a, ap) in local_rows[force] {
                            for &(b, aq) in local_rows[coordinate] {
                                jac.add_at(slots[a * d + b], ap * value * aq);
                            }
                        }
                    }
                }
            }
        }
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
}

impl ParametricResidual for HbmSystem<'_> {
    type Error = HbmError;
    fn dim(&self) -> usize {
        HbmSystem::dim(self)
    }
    fn residual_scale(&self) -> f64 {
        self.load_norm()
    }
    fn round_off(&mut self, x: &[f64], lambda: f64) -> f64 {
        HbmSystem::round_off(self, x, lambda)
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
