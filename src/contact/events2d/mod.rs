//! The event-resolved 2D Jenkins law: the isotropic Jenkins element in the tangent plane with
//! its stick, slip, opening and closing located in continuous time.
//!
//! # The law
//!
//! u(τ) ∈ ℝ² (the tangential relative displacement along t₁, t₂) and v(τ) are trigonometric
//! polynomials of the unknowns; L = μN is the friction limit (N = kₙ v while closed, or the
//! constant kₙ v̂₀). The slider w ∈ ℝ² carries the spring force T = kₜ (u − w), |T| ≤ L.
//!
//! | phase | force | ends when | next |
//! |---|---|---|---|
//! | stick, slider w | T = kₜ (u − w) | \|kₜ(u − w)\| − L rises through 0 | slip, θ = angle of T |
//! | slip, angle θ | T = L e(θ), e = (cos θ, sin θ) | L′ − kₜ u′·e rises through 0 (the slip rate λ = (kₜ u′·e − L′)/kₜ reaches 0) | stick, w = u − L e/kₜ |
//! | stick or slip | | v falls through 0 | open |
//! | open | T = 0 | v rises through 0 | stick, w = u (or slip at once when kₜ\|u′\| > L′) |
//!
//! In slip the e⊥ component of T′ = kₜ(u′ − λ e) gives the angle's ODE
//! θ′ = kₜ (u′·e⊥)/L, e⊥ = (−sin θ, cos θ), integrated by Dormand–Prince 8(5,3) ([`dopri`]) to
//! [`ODE_TOLERANCE`] with steps no longer than a cell of the bracketing grid (the samples);
//! its dense output locates the slip's end (Brent on the exit function) and carries the
//! Gauss–Legendre quadrature of the force harmonics over each step. Stick pieces are
//! integrated in closed form (T is kₜ u minus a constant), as by the 1D law
//! ([`crate::contact::events`]).
//!
//! # Sensitivities
//!
//! With respect to the parameters p = (w_start, û₁, û₂, v̂) the slip angle's sensitivity
//! S = ∂θ/∂p obeys S′ = −kₜ (u′·e)/L · S + ∂θ′/∂p, integrated with θ in the same steps. The
//! transition-time terms cancel, as in 1D, since T is continuous at every transition:
//!
//! * at a slip onset τₛ: S(τₛ) = kₜ e⊥·(du − dw)/L (the onset time's terms, kₜ(u′·e⊥)/L from
//!   the stick and from the ODE, cancel);
//! * at a slip end τₐ: dw = du − (dL e + L e⊥ S)/kₜ (the τₐ term is e times the slip rate,
//!   zero there);
//! * at closing τ_c: dw = du(τ_c) − u′(τ_c) dv(τ_c)/v′(τ_c) (T = 0 there, as in 1D).
//!
//! The period map's derivative A = ∂w_end/∂w_start and B = ∂w_end/∂(û, v̂) are the slider's
//! sensitivities at the period's end; the periodic state and its derivative
//! dw_start = (I − A)⁻¹ B dx are in [`crate::contact::aft2d`]'s `resolved` file.

mod crossing;
pub mod dopri;
pub mod march;

use crate::contact::harmonic::Block;

/// Absolute tolerance (rad) of one step of the slip angle's integration: far below what a
/// harmonic-balance Newton resolves (forces to ~10⁻¹¹ of μN).
pub const ODE_TOLERANCE: f64 = 1e-11;

/// u₁, u₂, v and their first two τ-derivatives at one instant (m, m/rad, m/rad²).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Kinematics2 {
    /// [u, u′, u″] along t₁ and t₂.
    pub u: [[f64; 3]; 2],
    /// [v, v′, v″] (gap included).
    pub v: [f64; 3],
}

/// Coefficients of u₁, u₂ and v on the force blocks, evaluated at any τ by direct summation.
#[derive(Clone, Copy)]
pub struct Path2<'a> {
    /// Blocks of the coefficients.
    pub blocks: &'a [Block],
    /// û₁, û₂ (m).
    pub u: [&'a [f64]; 2],
    /// v̂ including the gap (m).
    pub v: &'a [f64],
}

impl Path2<'_> {
    /// u₁, u₂, v and their derivatives at τ.
    pub fn at(&self, tau: f64) -> Kinematics2 {
        self.kinematics(tau, None)
    }

    /// u₁, u₂, v and their derivatives at τ, with the basis b_i(τ) and its rate b_i′(τ)
    /// (as [`Self::basis`]) from the same table of harmonics.
    pub fn at_with_basis(&self, tau: f64, b: &mut [f64], db: &mut [f64]) -> Kinematics2 {
        self.kinematics(tau, Some((b, db)))
    }

    fn kinematics(&self, tau: f64, mut basis: Option<(&mut [f64], &mut [f64])>) -> Kinematics2 {
        let mut table = Harmonics::at(tau);
        let (mut u0, mut u1, mut v) = ([0.0; 3], [0.0; 3], [0.0; 3]);
        let coefficients = self.u[0].iter().zip(self.u[1]).zip(self.v);
        for (j, (block, ((&c0, &c1), &cv))) in self.blocks.iter().zip(coefficients).enumerate() {
            let (b0, b1, b2) = table.derivatives(*block);
            if let Some((b, db)) = basis.as_mut() {
                b[j] = b0;
                db[j] = b1;
            }
            u0 = [u0[0] + c0 * b0, u0[1] + c0 * b1, u0[2] + c0 * b2];
            u1 = [u1[0] + c1 * b0, u1[1] + c1 * b1, u1[2] + c1 * b2];
            v = [v[0] + cv * b0, v[1] + cv * b1, v[2] + cv * b2];
        }
        Kinematics2 { u: [u0, u1], v }
    }

    /// u₁′, u₂′ and v at τ alone (what the slip angle's rate needs), with the basis and its
    /// rate when `basis` is given.
    pub fn slip_inputs(
        &self,
        tau: f64,
        mut basis: Option<(&mut [f64], &mut [f64])>,
    ) -> ([f64; 2], f64) {
        let mut table = Harmonics::at(tau);
        let (mut du, mut v) = ([0.0; 2], 0.0);
        let coefficients = self.u[0].iter().zip(self.u[1]).zip(self.v);
        for (j, (block, ((&c0, &c1), &cv))) in self.blocks.iter().zip(coefficients).enumerate() {
            let (b0, b1, _) = table.derivatives(*block);
            if let Some((b, db)) = basis.as_mut() {
                b[j] = b0;
                db[j] = b1;
            }
            du = [du[0] + c0 * b1, du[1] + c1 * b1];
            v += cv * b0;
        }
        (du, v)
    }

    /// The basis b_i(τ) and its rate b_i′(τ) over the blocks.
    pub fn basis(&self, tau: f64, b: &mut [f64], db: &mut [f64]) {
        let mut table = Harmonics::at(tau);
        for ((block, x), dx) in self.blocks.iter().zip(b).zip(db) {
            let (b0, b1, _) = table.derivatives(*block);
            *x = b0;
            *dx = b1;
        }
    }
}

/// Longest run of the angle-addition recurrence between two harmonics of a block list;
/// a larger gap (or a harmonic below the last) takes its sine and cosine directly.
const RECURRENCE_GAP: usize = 32;

/// cos hτ and sin hτ for the harmonics of the blocks in turn, from one `sin_cos` of τ and the
/// angle-addition recurrence (rounding grows like h·ε): the blocks come in increasing
/// harmonic order, so each step of the recurrence serves the next block.
struct Harmonics {
    tau: f64,
    s1: f64,
    c1: f64,
    h: usize,
    c: f64,
    s: f64,
}

impl Harmonics {
    fn at(tau: f64) -> Self {
        let (s1, c1) = tau.sin_cos();
        Self {
            tau,
            s1,
            c1,
            h: 0,
            c: 1.0,
            s: 0.0,
        }
    }

    /// b(τ), b′(τ), b″(τ) of one basis function.
    fn derivatives(&mut self, block: Block) -> (f64, f64, f64) {
        let h = block.harmonic();
        if h == 0 {
            return (1.0, 0.0, 0.0);
        }
        if h < self.h || h > self.h + RECURRENCE_GAP {
            let (s, c) = (h as f64 * self.tau).sin_cos();
            (self.h, self.c, self.s) = (h, c, s);
        }
        while self.h < h {
            let c = self.c * self.c1 - self.s * self.s1;
            self.s = self.s * self.c1 + self.c * self.s1;
            self.c = c;
            self.h += 1;
        }
        let hf = h as f64;
        let (s, c) = (self.s, self.c);
        match block {
            Block::Constant => (1.0, 0.0, 0.0),
            Block::Cos(_) => (c, -hf * s, -hf * hf * c),
            Block::Sin(_) => (s, hf * c, -hf * hf * s),
        }
    }
}

/// The 2D law's parameters as the march needs them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Law2 {
    /// Tangential stiffness kₜ (N/m).
    pub kt: f64,
    /// μ kₙ (N/m).
    pub mu_kn: f64,
    /// The constant friction limit μ max(kₙ v̂₀, 0) (N) with a constant normal load; `None`
    /// with a variable one (L = μ kₙ v while closed).
    pub constant_limit: Option<f64>,
}

impl Law2 {
    /// Friction limit L and its first two τ-derivatives, unclamped (smooth through v = 0).
    pub fn limit(&self, k: &Kinematics2) -> [f64; 3] {
        match self.constant_limit {
            Some(l) => [l, 0.0, 0.0],
            None => [
                self.mu_kn * k.v[0],
                self.mu_kn * k.v[1],
                self.mu_kn * k.v[2],
            ],
        }
    }
}

/// The parameter columns of the sensitivities: w_start (2), then û₁, û₂, v̂ (n_blocks each)
/// when `count` > 2 (a march that only needs the period map's derivative A carries 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Columns {
    /// Columns carried: 2 or 2 + 3 n_blocks.
    pub count: usize,
    /// Blocks per signal.
    pub nb: usize,
    /// The constant block of v̂ (the constant normal load's column), if any.
    pub constant: Option<usize>,
}

impl Columns {
    /// Whether the coefficient columns are carried.
    pub fn full(&self) -> bool {
        self.count > 2
    }

    /// Adds `scale`·du_a(τ) (the basis `b` in the û_a columns).
    pub fn add_du(&self, a: usize, scale: f64, b: &[f64], out: &mut [f64]) {
        if self.full() {
            let o = 2 + a * self.nb;
            for (x, bi) in out[o..o + self.nb].iter_mut().zip(b) {
                *x += scale * bi;
            }
        }
    }

    /// Adds `scale`·dv(τ) (the basis `b` in the v̂ columns, or the constant column alone
    /// under a constant normal load when `constant_load`).
    pub fn add_dv(&self, scale: f64, b: &[f64], constant_load: bool, out: &mut [f64]) {
        if !self.full() {
            return;
        }
        let o = 2 + 2 * self.nb;
        if constant_load {
            if let Some(c) = self.constant {
                out[o + c] += scale;
            }
        } else {
            for (x, bi) in out[o..o + self.nb].iter_mut().zip(b) {
                *x += scale * bi;
            }
        }
    }
}
