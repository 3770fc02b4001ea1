//! The `schur-krylov` formulation's linear solver: the schur formulation's unknowns and
//! residual, with each Newton system solved by a preconditioned Krylov method instead of one
//! dense LU of the whole reduced matrix blockdiag_h S_h + N_c (n_q·blocks rows, whose cost grows
//! as the cube of the contact count).
//!
//! The preconditioner uses the two structures the Newton matrix has: the linear part is
//! block-diagonal over harmonics, the contact part block-diagonal over contact points. It keeps
//! of the contact blocks only their harmonic-diagonal part (per contact and harmonic h, the mean
//! stiffness R + iI of its cos/sin 2×2 block pattern [[R, I], [−I, R]], exact for a contact stuck
//! or open over the whole period), so that the reduced matrix splits into one dense matrix
//! S_h(ω_p) + N̄_h per harmonic (n_q rows, complex), factorised by LU:
//!
//! ```text
//! P = blockdiag_h (S_h(ω_p) + N̄_h)   on the relative coordinates, with the elimination of z at ω_p
//! ```
//!
//! The Krylov method runs on the full system J x = b in problem coordinates (the products with
//! J are the schur formulation's, [`RelativeCoordinates::mul_add`]: three dense products with
//! K, M, C and the contact blocks), right-preconditioned by P⁻¹. The products need no
//! elimination at the current ω, so a step in frequency costs nothing until the preconditioner
//! is rebuilt. P is built at the first factorisation and kept over Newton iterations and
//! continuation points (its ω_p and contact blocks drift away from the current ones), and rebuilt
//! at the next factorisation once a solve needed more than [`REFRESH_ITERATIONS`] iterations,
//! or at once, for the same solve, when one does not converge in [`MAX_ITERATIONS`].
//!
//! The Krylov method is faer's BiCGSTAB (`faer::operator::bicgstab`): faer offers no GMRES, and
//! BiCGSTAB needs no restart and no basis to store. Each solve reaches a residual of
//! [`TOLERANCE`] relative to its right-hand side ([`CHORD_TOLERANCE`] for the chord steps of the
//! corrector, whose convergence is judged on the true residual), so Newton converges as with a
//! direct solve (the Jacobian is the same analytic one; only its solves are iterative).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError};

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::matrix_free::bicgstab::{bicgstab, bicgstab_scratch, BicgParams};
use faer::matrix_free::{InitialGuessStatus, LinOp, Precond};
use faer::{Mat, MatMut, MatRef, Par};

use super::coordinates::RelativeCoordinates;
use super::elimination::EliminatedHarmonic;
use super::jacobian::{solve_eliminated, ReducedFactor};
use crate::numerics::jacobian::{ImplicitFactor, ImplicitJacobian};
use crate::numerics::linalg::LinearSolveError;
use crate::numerics::work::{self, Work};

/// Relative residual ‖b − J x‖ / ‖b‖ of a Krylov solve.
pub const TOLERANCE: f64 = 1e-10;

/// Relative residual of a chord step's solve.
pub const CHORD_TOLERANCE: f64 = 1e-6;

/// Iterations after which a solve gives up (and the preconditioner is rebuilt for it).
pub const MAX_ITERATIONS: usize = 200;

/// Iterations of a solve above which the preconditioner is rebuilt at the next factorisation.
pub const REFRESH_ITERATIONS: usize = 12;

/// The preconditioner P (see the module docs): the elimination of z at ω_p and the reduced
/// matrix there factorised by [`RelativeCoordinates::reduced_factor`] without a dense LU.
pub struct HarmonicPreconditioner {
    harmonics: Arc<Vec<EliminatedHarmonic>>,
    reduced: ReducedFactor,
}

impl std::fmt::Debug for HarmonicPreconditioner {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "HarmonicPreconditioner({} harmonics)",
            self.harmonics.len()
        )
    }
}

impl RelativeCoordinates {
    /// The preconditioner at ω with the contact blocks `values`: every harmonic's elimination
    /// at ω, then the reduced matrix factorised without a dense LU.
    pub fn harmonic_preconditioner(
        &self,
        omega: f64,
        values: &[f64],
    ) -> Result<HarmonicPreconditioner, LinearSolveError> {
        if !omega.is_finite() || values.iter().any(|v| !v.is_finite()) {
            return Err(LinearSolveError::NonFinite);
        }
        let started = std::time::Instant::now();
        let harmonics = self.eliminated_at(omega)?;
        let reduced = self.reduced_factor(&harmonics, values, false)?;
        work::record(Work::Preconditioner, started);
        Ok(HarmonicPreconditioner { harmonics, reduced })
    }
}

impl HarmonicPreconditioner {
    /// P⁻¹ b (problem coordinates, harmonic-major).
    fn apply(&self, coords: &RelativeCoordinates, b: &[f64]) -> Vec<f64> {
        solve_eliminated(coords, &self.harmonics, b, |r| self.reduced.solve(r, false))
    }
}

/// The preconditioner shared by every Jacobian and factorisation of one problem, and whether
/// it is to be rebuilt.
#[derive(Debug, Default)]
struct Shared {
    current: Mutex<Option<Arc<HarmonicPreconditioner>>>,
    stale: AtomicBool,
}

impl Shared {
    fn current(&self) -> std::sync::MutexGuard<'_, Option<Arc<HarmonicPreconditioner>>> {
        self.current.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

/// The `schur-krylov` Jacobian storage for
/// [`AssembledJacobian::implicit`](crate::numerics::jacobian::AssembledJacobian::implicit):
/// the schur formulation's values (one block per contact point), solved by preconditioned
/// BiCGSTAB (see the module docs). Clones of a Jacobian share the preconditioner.
#[derive(Debug)]
pub struct KrylovSchurJacobian {
    coords: Arc<RelativeCoordinates>,
    shared: Arc<Shared>,
}

impl KrylovSchurJacobian {
    /// The storage on the relative coordinates `coords`.
    pub fn new(coords: Arc<RelativeCoordinates>) -> Self {
        Self {
            coords,
            shared: Arc::default(),
        }
    }
}

impl ImplicitJacobian for KrylovSchurJacobian {
    fn dim(&self) -> usize {
        self.coords.n_dofs() * self.coords.n_blocks()
    }
    fn values_len(&self) -> usize {
        *self
            .coords
            .value_offsets()
            .last()
            .expect("one offset per contact plus the total")
    }
    fn entry(&self, omega: f64, values: &[f64], i: usize, j: usize) -> f64 {
        self.coords.entry(omega, values, i, j)
    }
    fn mul_add(&self, omega: f64, values: &[f64], col_scale: f64, x: &[f64], y: &mut [f64]) {
        self.coords.mul_add(omega, values, col_scale, x, y)
    }
    /// Keeps the Newton matrix (ω and the contact blocks) and the current preconditioner,
    /// built here when there is none or the last solves asked for a new one.
    fn factor(
        &self,
        omega: f64,
        values: &[f64],
    ) -> Result<Box<dyn ImplicitFactor>, LinearSolveError> {
        if !omega.is_finite() || values.iter().any(|v| !v.is_finite()) {
            return Err(LinearSolveError::NonFinite);
        }
        let kept = self.shared.current().clone();
        let precond = match kept {
            Some(p) if !self.shared.stale.load(Ordering::Relaxed) => p,
            _ => {
                let p = Arc::new(self.coords.harmonic_preconditioner(omega, values)?);
                *self.shared.current() = Some(Arc::clone(&p));
                self.shared.stale.store(false, Ordering::Relaxed);
                p
            }
        };
        Ok(Box::new(KrylovFactor {
            coords: Arc::clone(&self.coords),
            omega,
            values: values.to_vec(),
            precond: Mutex::new(precond),
            shared: Arc::clone(&self.shared),
        }))
    }
}

/// A Newton matrix of the `schur-krylov` formulation ready for solves: its ω and contact
/// blocks, and the preconditioner its solves use.
struct KrylovFactor {
    coords: Arc<RelativeCoordinates>,
    omega: f64,
    values: Vec<f64>,
    precond: Mutex<Arc<HarmonicPreconditioner>>,
    shared: Arc<Shared>,
}

/// J as a faer operator.
#[derive(Debug)]
struct NewtonMatrix<'a> {
    coords: &'a RelativeCoordinates,
    omega: f64,
    values: &'a [f64],
}

/// P⁻¹ as a faer preconditioner.
#[derive(Debug)]
struct Preconditioning<'a> {
    coords: &'a RelativeCoordinates,
    precond: &'a HarmonicPreconditioner,
}

/// Applies `f` (a map of length-n vectors) to every column of `rhs`, into `out`.
fn columnwise(mut out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, f: impl Fn(&[f64]) -> Vec<f64>) {
    for c in 0..rhs.ncols() {
        let x: Vec<f64> = (0..rhs.nrows()).map(|i| rhs[(i, c)]).collect();
        let y = f(&x);
        for (i, v) in y.into_iter().enumerate() {
            out[(i, c)] = v;
        }
    }
}

impl LinOp<f64> for NewtonMatrix<'_> {
    fn apply_scratch(&self, _rhs_ncols: usize, _par: Par) -> StackReq {
        StackReq::EMPTY
    }
    fn nrows(&self) -> usize {
        self.coords.n_dofs() * self.coords.n_blocks()
    }
    fn ncols(&self) -> usize {
        self.nrows()
    }
    fn apply(&self, out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, _par: Par, _: &mut MemStack) {
        columnwise(out, rhs, |x| {
            let mut y = vec![0.0; x.len()];
            self.coords.mul_add(self.omega, self.values, 1.0, x, &mut y);
            y
        });
    }
    fn conj_apply(&self, out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, par: Par, s: &mut MemStack) {
        self.apply(out, rhs, par, s);
    }
}

impl LinOp<f64> for Preconditioning<'_> {
    fn apply_scratch(&self, _rhs_ncols: usize, _par: Par) -> StackReq {
        StackReq::EMPTY
    }
    fn nrows(&self) -> usize {
        self.coords.n_dofs() * self.coords.n_blocks()
    }
    fn ncols(&self) -> usize {
        self.nrows()
    }
    fn apply(&self, out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, _par: Par, _: &mut MemStack) {
        columnwise(out, rhs, |x| self.precond.apply(self.coords, x));
    }
    fn conj_apply(&self, out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, par: Par, s: &mut MemStack) {
        self.apply(out, rhs, par, s);
    }
}

impl Precond<f64> for Preconditioning<'_> {}

impl KrylovFactor {
    /// BiCGSTAB on J x = b, right-preconditioned by `precond`, to `tolerance`: the solution
    /// and the iterations, or None when it did not converge in [`MAX_ITERATIONS`].
    fn bicgstab(
        &self,
        precond: &HarmonicPreconditioner,
        b: &[f64],
        tolerance: f64,
    ) -> (Option<Vec<f64>>, usize) {
        let n = b.len();
        let matrix = NewtonMatrix {
            coords: &self.coords,
            omega: self.omega,
            values: &self.values,
        };
        let right = Preconditioning {
            coords: &self.coords,
            precond,
        };
        let left = faer::matrix_free::IdentityPrecond { dim: n };
        let mut params = BicgParams::<f64>::default();
        // faer 0.24.4's BiCGSTAB leaves its first residual unset with `InitialGuessStatus::Zero`:
        // the zero guess is passed as a guess (one more product with J).
        params.initial_guess = InitialGuessStatus::MaybeNonZero;
        params.rel_tolerance = tolerance;
        params.max_iters = MAX_ITERATIONS;
        let rhs = Mat::from_fn(n, 1, |i, _| b[i]);
        let mut x = Mat::<f64>::zeros(n, 1);
        let par = Par::Seq;
        let mut buffer = MemBuffer::new(bicgstab_scratch(left, &right, &matrix, 1, par));
        let outcome = bicgstab(
            x.as_mut(),
            left,
            &right,
            &matrix,
            rhs.as_ref(),
            params,
            |_| {},
            par,
            MemStack::new(&mut buffer),
        );
        match outcome {
            Ok(info) => (Some((0..n).map(|i| x[(i, 0)]).collect()), info.iter_count),
            Err(_) => (None, MAX_ITERATIONS),
        }
    }
}

impl ImplicitFactor for KrylovFactor {
    /// J⁻¹ b by preconditioned BiCGSTAB to [`TOLERANCE`] (with `single`, a chord step's solve,
    /// to [`CHORD_TOLERANCE`]). A solve that does not converge rebuilds the preconditioner at
    /// this Newton matrix and tries once more; a second failure gives non-finite values, which
    /// the callers report as a singular matrix.
    fn solve(&self, b: &[f64], single: bool) -> Vec<f64> {
        let tolerance = if single { CHORD_TOLERANCE } else { TOLERANCE };
        let precond = Arc::clone(&self.precond.lock().unwrap_or_else(PoisonError::into_inner));
        let (x, iterations) = self.bicgstab(&precond, b, tolerance);
        work::add(Work::KrylovIteration, iterations as u64);
        if iterations > REFRESH_ITERATIONS {
            self.shared.stale.store(true, Ordering::Relaxed);
        }
        if let Some(x) = x {
            return x;
        }
        let Ok(fresh) = self
            .coords
            .harmonic_preconditioner(self.omega, &self.values)
        else {
            return vec![f64::NAN; b.len()];
        };
        let fresh = Arc::new(fresh);
        *self.shared.current() = Some(Arc::clone(&fresh));
        *self.precond.lock().unwrap_or_else(PoisonError::into_inner) = Arc::clone(&fresh);
        let (x, iterations) = self.bicgstab(&fresh, b, tolerance);
        work::add(Work::KrylovIteration, iterations as u64);
        self.shared
            .stale
            .store(iterations > REFRESH_ITERATIONS, Ordering::Relaxed);
        x.unwrap_or_else(|| vec![f64::NAN; b.len()])
    }
}
