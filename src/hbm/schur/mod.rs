//! The `schur` formulation: Newton on all DOFs, each linear solve reduced to the relative
//! contact coordinates by eliminating everything else per harmonic.
//!
//! A contact point acts on the structure only through its relative displacements u = aₜ·x and
//! v = aₙ·x (and u₂ = aₜ₂·x for a 2D-friction point, [`crate::contact`]). Stack those rows into
//! B (n_q = 2 per 1D contact, 3 per 2D contact, ×
//! n DOFs, nonzero on the contact DOFs c only) and change coordinates on c:
//!
//! ```text
//! x_c = P q + N w,   B P = I,  B N = 0        (P = Bᵀ(BBᵀ)⁻¹, N an orthonormal basis of ker B)
//! ```
//!
//! so that y = (q, w, x_o) with x = T y and q = B x are the relative displacements themselves.
//! In these coordinates the contact forces act on the q rows only, Tᵀ J T = Ã(ω) + [N_c 0; 0 0],
//! with Ã = Tᵀ A T the linear harmonic-balance operator (block-diagonal over harmonics, real
//! 2-block form per harmonic h ≥ 1) and N_c the contact Jacobian, one (k·blocks)² block per
//! contact point (k = 2, or 3 for a 2D point). Per harmonic the z = (w, x_o) coordinates are eliminated exactly,
//!
//! ```text
//! S_h = Ã_qq − Ã_qz Ã_zz⁻¹ Ã_zq       (dynamic Schur complement on the relative coordinates)
//! ```
//!
//! and Newton's linear system becomes (blockdiag_h S_h + N_c) y_q = r_q on n_q · blocks
//! unknowns (n_q = 2 per contact point, 3 per 2D point; 1 fewer for a contact whose normal row is zero, a
//! Jenkins element to ground with a constant normal load, whose v moves with no DOF and whose
//! normal rows of N_c therefore act on nothing): with node-to-node pairs that is half the contact DOFs (4 per pair in 2D),
//! an eighth of the dense LU work of the condensed formulation. Ã_zz is the structure with
//! every contact glued (q = 0), which is regular even when a body (the damper) is held only by
//! its contacts; the 0th harmonic therefore needs no regularisation.
//!
//! Unlike [`crate::hbm::condensed`], the residual stays the full one (cheap: a dense product per
//! block), so a frequency change costs nothing until the next factorisation, and chord steps
//! of the corrector re-use the eliminated blocks. The complex dynamic stiffness is
//! complex-symmetric, not Hermitian: each Ã_zz is factored by dense LU with partial pivoting
//! in the real 2n form, as is the reduced Newton matrix (friction makes it unsymmetric).
//! faer offers dense LU but no block elimination over a coordinate change, hence this module.
//!
//! The files: [`coordinates`] (the relative contact coordinates and the change to them),
//! [`elimination`] (what the per-harmonic elimination keeps) and [`jacobian`] (the
//! elimination and the Newton matrix on the relative coordinates, its factorisation and products)
//! and [`lowrank`] (the reduced matrix factorised as a per-harmonic baseline plus a low-rank update
//! for the contacts that slip: the `schur-lowrank` formulation, for many contact points) and
//! [`modal`] (schur-lowrank's per-harmonic elimination from the modes of the glued structure,
//! computed once per harmonic-balance system, instead of an LU of Ã_zz at every frequency).

mod coordinates;
mod elimination;
mod jacobian;
pub mod lowrank;
pub mod modal;

pub use coordinates::RelativeCoordinates;
pub use jacobian::{ReducedSolver, SchurFactor, SchurJacobian};
