//! The event-resolved Jenkins law: stick, slip, opening and closing located in continuous
//! time, and the force's Fourier coefficients integrated exactly between them.
//!
//! # Why
//!
//! The Jenkins force is continuous in time. When its transitions are located in continuous
//! time, its Fourier coefficients are continuously differentiable in the harmonic unknowns: the
//! terms in d(transition time) cancel because the force is continuous across each transition.
//! Sampling the law (the paper's AFT, [`crate::contact::aft`]) snaps each transition to the
//! grid and puts a kink in the residual each time a transition crosses a sample; Newton then
//! stagnates just above its tolerance there. This law has no such kinks.
//!
//! One seam is the element's own, and stays: where a stick's slider changes the slip that
//! anchors it. Where the trial force kₜ(u − w) of a stick touches ±μN without crossing it, a
//! slip of vanishing length appears inside the stick (for a contact stuck all period, slip
//! begins) and the slider after it moves by max(e, 0)/kₜ, e the excess of the trial force over
//! μN at its peak; where a stuck orbit touches the cone at two peaks of nearly equal height,
//! the slider is anchored at the higher one. Either way the forces stay continuous but their
//! derivatives jump, as a play operator's do. The sampled law tends to the same one-sided
//! slopes as N grows (`tests/it/aft_jenkins/seam.rs`), and the continuation turns such corners
//! ([`crate::numerics::continuation`]).
//!
//! # The law (paper Eqs. 4-6)
//!
//! u(τ) and v(τ) are trigonometric polynomials of the unknowns; with a variable normal load
//! N = kₙ v while closed (v > 0), L = μN is the friction limit. Phases and their ends:
//!
//! | phase | force | ends when | next |
//! |---|---|---|---|
//! | stick, slider w | T = kₜ (u − w) | s T − L rises through 0 | slip s |
//! | slip s | T = s L | kₜ s u′ − L′ falls through 0 (the slider stops) | stick, w = u − s L/kₜ |
//! | slip s | T = s L | v falls through 0 | open |
//! | open | T = 0 | v rises through 0 | stick, w = u (or slip at once when kₜ|u′| > L′) |
//!
//! With a constant normal load, L = μ max(kₙ v̂₀, 0) is constant and the contact never opens
//! or closes. The march starts at τ = 0 with T(0) = m μN(0) (paper Eqs. 14-15), so a contact
//! stuck all period keeps its initial state m and the limit method works unchanged; the
//! periodic state is found as [`march::periodic_orbit`] explains.
//!
//! # Integrals and Jacobian
//!
//! Each phase's force is a trigonometric polynomial (kₜ u − kₜ w, s μkₙ v, or 0), so the
//! Fourier coefficients are closed-form integrals of products of cosines and sines over the
//! phases: with the moments c(m) = ∫ cos mτ, s(m) = ∫ sin mτ over the stuck, slipping and
//! closed stretches (m ≤ 2H), every product integral follows from
//! [`crate::contact::harmonic::product_integral`]. The Jacobian differentiates each phase's
//! force with the phases held fixed (the boundary terms cancel); the one dependence left is
//! the slider w on its anchor:
//!
//! * initial: w = u(0) − m L(0)/kₜ, dw = du(0) − m dL(0)/kₜ;
//! * end of a slip at τₐ: w = u(τₐ) − s L(τₐ)/kₜ, dw = du(τₐ) − s dL(τₐ)/kₜ (the τₐ term
//!   vanishes: at τₐ, kₜ u′ = s L′);
//! * closing at τ_c: w = u(τ_c) with v(τ_c) = 0, dw = du(τ_c) − (u′/v′)(τ_c) dv(τ_c).

pub mod bounds;
pub mod march;
pub(crate) mod roots;

use crate::contact::harmonic::{product_integral, Block, HarmonicSet};
use crate::contact::{ContactEffects, JenkinsLaw, NormalLoad};
use march::{Anchor, LawParams, Phase, Piece, Signals};
use std::f64::consts::PI;

pub use march::MarchFailure;

/// Moments ∫ cos mτ and ∫ sin mτ (m = 0..=2H) of a weight over one period.
#[derive(Debug, Clone, Default)]
pub(crate) struct Moments {
    c: Vec<f64>,
    s: Vec<f64>,
}

impl Moments {
    pub(crate) fn reset(&mut self, len: usize) {
        self.c.clear();
        self.c.resize(len, 0.0);
        self.s.clear();
        self.s.resize(len, 0.0);
    }

    pub(crate) fn add(&mut self, weight: f64, piece: &Moments) {
        for (a, b) in self.c.iter_mut().zip(&piece.c) {
            *a += weight * b;
        }
        for (a, b) in self.s.iter_mut().zip(&piece.s) {
            *a += weight * b;
        }
    }

    /// ∫ weight · b_j b_i over the period.
    pub(crate) fn gram(&self, bj: Block, bi: Block) -> f64 {
        let c = |m: i64| self.c[m.unsigned_abs() as usize];
        let s = |m: i64| m.signum() as f64 * self.s[m.unsigned_abs() as usize];
        product_integral(c, s, bj, bi)
    }

    /// ∫ weight · b_j over the period.
    pub(crate) fn single(&self, b: Block) -> f64 {
        match b {
            Block::Constant => self.c[0],
            Block::Cos(h) => self.c[h],
            Block::Sin(h) => self.s[h],
        }
    }

    /// The moments of the unit weight over [t0, t1]; sin mt, cos mt by the angle-addition
    /// recurrence from sin t, cos t.
    pub(crate) fn interval(&mut self, t0: f64, t1: f64) {
        self.c[0] = t1 - t0;
        self.s[0] = 0.0;
        let ((a0, b0), (a1, b1)) = (t0.sin_cos(), t1.sin_cos());
        let (mut s0, mut c0, mut s1, mut c1) = (0.0, 1.0, 0.0, 1.0);
        for m in 1..self.c.len() {
            (s0, c0) = (s0 * b0 + c0 * a0, c0 * b0 - s0 * a0);
            (s1, c1) = (s1 * b1 + c1 * a1, c1 * b1 - s1 * a1);
            let mf = m as f64;
            self.c[m] = (s1 - s0) / mf;
            self.s[m] = (c0 - c1) / mf;
        }
    }
}

/// Forces and derivatives written by [`EventSolver::integrate`], one coefficient per force
/// block, Jacobians row-major n_blocks × n_blocks.
pub struct ForceOutputs<'a> {
    /// T̂ (N).
    pub t_hat: &'a mut [f64],
    /// N̂ (N).
    pub n_hat: &'a mut [f64],
    /// ∂T̂/∂û, ∂T̂/∂v̂, ∂N̂/∂v̂ (N/m), filled when given.
    pub jacobian: Option<[&'a mut [f64]; 3]>,
}

/// Buffers of the event-resolved law for one harmonic set.
#[derive(Debug, Clone, Default)]
pub struct EventSolver {
    /// Coefficients of u′, u″, v′, v″ on the force blocks.
    pub derivative_coefficients: [Vec<f64>; 4],
    /// Grid samples of u′ and v′.
    pub derivative_samples: [Vec<f64>; 2],
    /// Phases of the last periodic orbit over [0, 2π].
    pub pieces: Vec<Piece>,
    /// Scratch for the march: the phases of the period before.
    pub previous_pieces: Vec<Piece>,
    /// Stretches of [0, 2π] where v > 0 (variable normal load with lift-off).
    pub closed_intervals: Vec<(f64, f64)>,
    /// Bounds of the exit functions over blocks of grid cells (for the march to skip them).
    pub bounds: bounds::CellBounds,
    stick: Moments,
    slip: Moments,
    closed: Moments,
    piece: Moments,
    anchor_row: Vec<f64>,
}

impl EventSolver {
    /// Buffers for `set` with `n_samples` bracketing samples per period.
    pub fn new(set: &HarmonicSet, n_samples: usize) -> Self {
        let nb = set.n_blocks();
        Self {
            derivative_coefficients: std::array::from_fn(|_| vec![0.0; nb]),
            derivative_samples: std::array::from_fn(|_| vec![0.0; n_samples]),
            anchor_row: vec![0.0; nb],
            ..Self::default()
        }
    }

    /// Fills [`Self::derivative_coefficients`] from û and v̂: d/dτ (a cos hτ + b sin hτ) =
    /// h b cos hτ − h a sin hτ, and the second derivative is −h² times the signal's part.
    pub fn differentiate(&mut self, set: &HarmonicSet, u: &[f64], v: &[f64]) {
        let [du, ddu, dv, ddv] = &mut self.derivative_coefficients;
        for (signal, first, second) in [(u, du, ddu), (v, dv, ddv)] {
            for (j, block) in set.blocks().iter().enumerate() {
                let h = block.harmonic() as f64;
                second[j] = -h * h * signal[j];
                first[j] = match *block {
                    Block::Constant => 0.0,
                    Block::Cos(n) => set.sin_block(n).map_or(0.0, |s| h * signal[s]),
                    Block::Sin(n) => set.cos_block(n).map_or(0.0, |c| -h * signal[c]),
                };
            }
        }
    }

    /// Integrates the forces of the orbit in [`Self::pieces`] and of the normal spring over
    /// [`Self::closed_intervals`] into `out` (see the module doc): T̂, N̂ and, when asked,
    /// their Jacobian.
    pub fn integrate(
        &mut self,
        set: &HarmonicSet,
        law: &LawParams,
        effects: ContactEffects,
        signals: &Signals<'_>,
        out: ForceOutputs<'_>,
    ) {
        let blocks = set.blocks();
        let nb = blocks.len();
        let len = 2 * set.max_harmonic() + 1;
        for m in [
            &mut self.stick,
            &mut self.slip,
            &mut self.closed,
            &mut self.piece,
        ] {
            m.reset(len);
        }
        let ForceOutputs {
            t_hat,
            n_hat,
            mut jacobian,
        } = out;
        t_hat.iter_mut().for_each(|x| *x = 0.0);
        n_hat.iter_mut().for_each(|x| *x = 0.0);
        if let Some(jac) = jacobian.as_mut() {
            jac.iter_mut()
                .for_each(|m| m.iter_mut().for_each(|x| *x = 0.0));
        }
        let variable = law.constant_limit.is_none();
        let normal_gram = variable && effects.liftoff;
        let constant_block = set.constant_block();
        for p in &self.pieces {
            self.piece.interval(p.start, p.end);
            match p.phase {
                Phase::Open => continue,
                Phase::Slip { sign } => self.slip.add(sign, &self.piece),
                Phase::Stick { anchor, w } => {
                    self.stick.add(1.0, &self.piece);
                    // −kₜ w ∫ b_j, and the slider's own derivatives −kₜ ∫b_j ⊗ dw.
                    for (j, b) in blocks.iter().enumerate() {
                        t_hat[j] -= law.kt * w * self.piece.single(*b);
                    }
                    if let Some(jac) = jacobian.as_mut() {
                        let (tau, du_scale, dv_scale) = anchor_sensitivity(law, anchor, signals);
                        for (r, b) in self.anchor_row.iter_mut().zip(blocks) {
                            *r = HarmonicSet::basis(*b, tau);
                        }
                        let [dt_du, dt_dv, _] = jac;
                        for (j, b) in blocks.iter().enumerate() {
                            let pj = -law.kt * self.piece.single(*b);
                            if pj == 0.0 {
                                continue;
                            }
                            for i in 0..nb {
                                dt_du[j * nb + i] += pj * du_scale * self.anchor_row[i];
                            }
                            if dv_scale != 0.0 {
                                if variable {
                                    for i in 0..nb {
                                        dt_dv[j * nb + i] += pj * dv_scale * self.anchor_row[i];
                                    }
                                } else if let Some(c) = constant_block {
                                    dt_dv[j * nb + c] += pj * dv_scale;
                                }
                            }
                        }
                    }
                }
            }
        }
        if normal_gram {
            for &(t0, t1) in &self.closed_intervals {
                self.piece.interval(t0, t1);
                self.closed.add(1.0, &self.piece);
            }
        }

        // Phase integrals of kₜ u (stick), s μkₙ v (slip) and kₙ v (closed).
        let constant_v = constant_block.map_or(0.0, |c| signals.v[c]);
        for j in 0..nb {
            for i in 0..nb {
                let stick = self.stick.gram(blocks[j], blocks[i]);
                t_hat[j] += law.kt * stick * signals.u[i];
                if variable {
                    let slip = self.slip.gram(blocks[j], blocks[i]);
                    t_hat[j] += law.mu_kn * slip * signals.v[i];
                    if let Some([dt_du, dt_dv, _]) = jacobian.as_mut() {
                        dt_du[j * nb + i] += law.kt * stick;
                        dt_dv[j * nb + i] += law.mu_kn * slip;
                    }
                }
                if normal_gram {
                    let closed = self.closed.gram(blocks[j], blocks[i]);
                    n_hat[j] += law.kn * closed * signals.v[i];
                    if let Some([_, _, dn_dv]) = jacobian.as_mut() {
                        dn_dv[j * nb + i] += law.kn * closed;
                    }
                } else if variable {
                    // Without lift-off N = kₙ v all period: N̂ = kₙ v̂ (∫ b_j b_i = δ/c_j).
                    let full = if i == j {
                        1.0 / normalisation(blocks[j])
                    } else {
                        0.0
                    };
                    n_hat[j] += law.kn * full * signals.v[i];
                    if let Some([_, _, dn_dv]) = jacobian.as_mut() {
                        dn_dv[j * nb + i] += law.kn * full;
                    }
                } else if let Some([dt_du, _, _]) = jacobian.as_mut() {
                    dt_du[j * nb + i] += law.kt * stick;
                }
            }
        }
        if let (false, Some(c)) = (variable, constant_block) {
            // Constant load: T = s L₀ in slip, N = kₙ v̂₀ (clamped at 0 with lift-off).
            let limit = law.constant_limit.unwrap_or(0.0);
            let active = !effects.liftoff || law.kn * constant_v > 0.0;
            let n0 = if active { law.kn * constant_v } else { 0.0 };
            for j in 0..nb {
                let slip = self.slip.single(blocks[j]);
                t_hat[j] += limit * slip;
                if blocks[j] == Block::Constant {
                    n_hat[j] += n0 * 2.0 * PI;
                }
                if let Some([_, dt_dv, dn_dv]) = jacobian.as_mut() {
                    if limit > 0.0 {
                        dt_dv[j * nb + c] += law.mu_kn * slip;
                    }
                    if active && blocks[j] == Block::Constant {
                        dn_dv[j * nb + c] += law.kn * 2.0 * PI;
                    }
                }
            }
        }
        // Fourier normalisation: coefficient_j = c_j ∫ f b_j.
        for (j, b) in blocks.iter().enumerate() {
            let cj = normalisation(*b);
            t_hat[j] *= cj;
            n_hat[j] *= cj;
            if let Some(jac) = jacobian.as_mut() {
                for m in jac.iter_mut() {
                    m[j * nb..(j + 1) * nb].iter_mut().for_each(|x| *x *= cj);
                }
            }
        }
    }
}

/// c_j in coefficient_j = c_j ∫₀^{2π} f b_j dτ: 1/(2π) for the constant, 1/π otherwise.
pub(crate) fn normalisation(b: Block) -> f64 {
    match b {
        Block::Constant => 0.5 / PI,
        _ => 1.0 / PI,
    }
}

/// The slider's anchor as (τ, scale of du(τ), scale of dv(τ)): dw = du(τ)·a + dv(τ)·b, where
/// dv(τ) stands for dv̂₀ under a constant normal load (see the module doc).
fn anchor_sensitivity(law: &LawParams, anchor: Anchor, signals: &Signals<'_>) -> (f64, f64, f64) {
    let limit_scale = |sign: f64, tau: f64| {
        // dL = μkₙ dv while closed (or μkₙ dv̂₀ with a positive constant load), else 0.
        let closed = match law.constant_limit {
            Some(l) => l > 0.0,
            None => signals.at(tau).v[0] > 0.0,
        };
        if closed {
            -sign * law.mu_kn / law.kt
        } else {
            0.0
        }
    };
    match anchor {
        Anchor::Initial => (0.0, 1.0, limit_scale(law.m, 0.0)),
        Anchor::SlipEnd { tau, sign } => (tau, 1.0, limit_scale(sign, tau)),
        Anchor::Closing { tau } => {
            let k = signals.at(tau);
            (tau, 1.0, -k.u[1] / k.v[1])
        }
    }
}

impl LawParams {
    /// The march's parameters for a Jenkins law under `effects`, given v̂₀ (m, gap included).
    pub fn new(law: &JenkinsLaw, effects: ContactEffects, constant_v: f64) -> Self {
        Self {
            kt: law.kt,
            mu_kn: law.mu * law.kn,
            m: law.initial_state,
            constant_limit: match effects.normal_load {
                NormalLoad::Variable => None,
                NormalLoad::Constant => Some(law.mu * (law.kn * constant_v).max(0.0)),
            },
            kn: law.kn,
        }
    }
}
