//! A-posteriori error estimate of a converged harmonic-balance point: how much each output's
//! first-harmonic amplitude would change if the harmonic set were larger (truncation) or the
//! AFT sampled the period more finely (sampling).
//!
//! # Truncation
//!
//! A converged point x (harmonics 0..H, or the scene's set) is padded with zero coefficients
//! for the harmonics H+1 … 2H+1 ([`extended_harmonic`]) and put into the harmonic balance on the
//! extended set (paper Eq. 7 with more harmonics), at the same frequency and the same number of
//! samples per period (doubled only where the scene's count does not resolve 2H+1). With the
//! same samples the displacement samples, the march and the kept force harmonics are those of
//! the converged point, so the residual is zero on the kept harmonics and holds on the new ones
//! exactly what the truncation threw away: the contact forces' harmonics H+1 … 2H+1. One Newton step of the extended system, δ = −J⁻¹R, pushes these forces
//! through the dynamic stiffness of the new harmonics (with the contacts' linearisation) and
//! carries their effect back onto the kept harmonics through the contact Jacobian. The
//! estimate of an output is |A(x + δ) − A(x)| / A(x), A the first-harmonic amplitude
//! √(c₁² + s₁²).
//!
//! Where the harmonics beyond 2H + 1 may matter ([`TailTest`]: a contact stuck all period,
//! whose mean force holds every harmonic of u(τ = 0), or an extension whose upper half of
//! harmonics still changes the estimate as much as its lower half) the point is estimated
//! again in the same way on the wider set H+1 … 4H+3 ([`wider_harmonic`]) and reports that
//! estimate ([`PointAccuracy::estimate_harmonic`] says which), unless its step on 2H + 1 is
//! within its linear range and its estimate below a gate ([`WidenGate`], 8 × 10⁻⁶ at the
//! default 1 % threshold, derived from the largest measured ratio of the widened estimate to
//! the 2H + 1 one).
//!
//! # Where the step leaves its linear range
//!
//! The extended residual is evaluated once more at the stepped point. Where it is more than
//! [`LinearRange::MAX_CONTRACTION`] of the residual before the step, the step is outside the
//! range where its linearisation holds (a contact whose regime differs between the point and
//! the extended solution: docs/accuracy.md, "Why the estimate missed on the small blade
//! pair"), and the point is solved on the extended set to convergence, which it then reports
//! ([`EstimateMethod::Solved`]): at its frequency where it reports the fixed-frequency step,
//! across the path where it reports the across-path step (Newton on the extended system
//! bordered with the path's hyperplane through the point, normal · (x − x₀, ω − ω₀) = 0, the
//! normal the step was bordered with; the amplitude change across the path). Where that
//! solve does not converge the point is not sizeable ([`EstimateMethod::Unsized`], warned in
//! a band of its own). Against the true error across the path the converged across-path
//! estimate is within 0.91-1.05 of it on the paper case (H = 1, 3; 208 points above 10⁻³) and
//! 0.78-1.82 on the small blade pair (H = 1, 3; 129 points), formed at every point by the
//! tests (`tests/it/error_estimate.rs`, `tests/it/error_estimate_fe.rs`).
//!
//! # Points that already solve the extension
//!
//! Where the padded point already solves the extended system, and the point the harmonic
//! balance at twice the samples, within the run's Newton tolerance (`solves_padded`: e.g.
//! every contact stuck or open all period, where the contact forces are linear in the motion
//! and hold no harmonic the point lacks), the point is a converged solution of both by the
//! run's own criterion: both estimates are 0, formed from those two residuals without a
//! Jacobian ([`EstimateMethod::Converged`]). A step from such a point moves within round-off,
//! and its contraction says nothing of linearity; it was taken for a step beyond its linear
//! range before, and solved again at a cost: on the blade pair at H = 11 every point over
//! 700-720 Hz (step estimates below 10⁻¹¹, their converged solves 1.5 × 10⁻¹² at most), at
//! 5.1 s of CPU for a run of 0.38 s (now 0.42 s with the estimate). Where the sampling residual
//! is above the tolerance the point takes the full estimate, and its truncation step counts
//! as within its linear range ([`LinearRange::holds`]).
//!
//! # Sampling
//!
//! The same point put into the harmonic balance of the same harmonic set at twice the samples
//! per period: the residual is what the coarser sampling of the march misses (stick-slip and
//! lift-off transitions located to a sample). It is pushed through the Jacobian already
//! factorised for the truncation step (the extended system's; the residual on the kept
//! harmonics, zero on the new ones): one Newton step as above, at the cost of one residual
//! at twice the samples and one more solve with the same factors.
//!
//! # Across the path or at a fixed frequency
//!
//! On a continuation path (every point of an FRF run, limit and intermediate curves) the
//! extended system is factorised bordered with the path's arc-length row, normal · (δx, δω)
//! = 0, the normal being the path's tangent at the point in the continuation's scaled metric
//! (paper Eq. 9; see [`crate::numerics::Observer::accepted`]). Its solutions give two steps
//! from one factorisation: the step *across the path* (it may change the frequency and stays
//! in the hyperplane orthogonal to the path: it moves the point onto the refined path at the
//! same place along it), and, with one more solve for the path's direction z, the step *at the
//! fixed frequency* (the across-path step slid along z back onto the point's frequency). The
//! fixed-frequency Jacobian is singular at a fold of the path (a turning point), where the
//! slide, hence the fixed-frequency estimate, grows without bound (806 % at H = 1, 395 at
//! H = 3 on the reduced blade pair next to its fold); the bordered matrix is regular there.
//! The point reports the fixed-frequency estimate unless the slide exceeds
//! [`PathSwitch::SLIDE_STEPS`] continuation steps ([`PointAccuracy::across_path`] says
//! which one it reports; both truncation estimates are kept in
//! [`PointAccuracy::both_truncation`]). Away from folds the two differ where the path is
//! steep: the across-path step measures the error across the path, the fixed-frequency one
//! the (larger) error at a fixed frequency, which is what an FRF is read at. Points solved at
//! a fixed frequency (the end frequency of a path, the bridge points between branches,
//! refined peaks) take the plain fixed-frequency step. An estimate that cannot be formed (an
//! AFT march that does not settle, a singular matrix) is NaN.
//!
//! Cost per point: one residual, Jacobian and factorisation of the system on 2H+1 harmonics
//! (in the formulation the cost model picks for that system, see `extended_formulation`),
//! one residual at twice the samples, and two solves with the same factors (three with the
//! path's direction on a path point; before the sampling step reused the factors, it took a
//! Jacobian and a factorisation of its own), and one residual at the stepped point for the
//! contraction of the step the point reports (a path point evaluated it for both of its step
//! sets before, on 2H + 1 and on 4H + 3). The bordered factorisation adds one row and
//! column (dense storage) or one solve for the border column (storages that eliminate the
//! border by blocks). A point whose step leaves its linear range ([`LinearRange`]) adds a
//! Newton solve of the extended system: a Jacobian, a factorisation and the line search's
//! residuals per iteration; at its frequency up to three times the continuation's iteration
//! limit, across the path up to that limit (the corrector's own, one row and column more)
//! where it does not converge. It starts from the stepped point where the step lowers the
//! residual (the iterate Newton from the padded point reaches first), so it repeats no work of
//! the step. A point sent to the wider set but kept on 2H + 1 by [`WidenGate`] saves the
//! wider set's residual, Jacobian and factorisation. On the larger blade pair at H = 1
//! (855-895 Hz, 1076 points) these solves take most of the estimate's time (the failing ones
//! 46 %, the converging ones 40 %, the steps 14 %): 23-26 s of user CPU with the estimate
//! against 3.2-3.4 s without (6.8-8.2×; 15 s, about 5×, before the solve across the path,
//! which sizes 285 of its 607 points next to the small folds); the gate keeps none of its
//! points on 2H + 1, since 417 of its 450 widened points have 2H + 1 estimates above the 1 %
//! threshold itself (docs/accuracy.md, "What the estimate costs, and where the time goes").
//!
//! Which extended sets a point beyond its step's linear range is solved on, and whether the
//! wider set is stepped on at all, is the scene's choice (`accuracy.beyond_linear_range`): by
//! default ([`SolveBudget`]) a set is solved on only where the cost model puts a solve at the
//! iteration limit at most 100 run points, and the wider set stepped on only where a point's
//! two steps cost at most 10; beyond that the point is flagged ([`EstimateMethod::Unsolved`];
//! a point sent to a wider set that is not stepped on is flagged with its 2H + 1 estimate). On
//! the 3D blade pair at H = 1 the steps and solves on H = 7 at every point (38-45 of its 56
//! contact points stay stuck all period, so every point is widened) had a 2.5-minute run past
//! 33 minutes at 217 of its 1174 points; with the budget the run takes 1.03× its wall time
//! without the estimate, every point flagged.
//!
//! Every estimate runs on a pool of one thread of the estimator's own
//! (`ErrorEstimator::on_one_thread`): faer then factorises the extended systems (2-5× the
//! run's) on that one thread instead of splitting each factorisation over rayon's threads,
//! which on a loaded machine mostly wait for each other (on the blade pair above 28-43 s of
//! user and 2-18 s of system CPU before, with the same results).
//!
//! An FRF run hands its points to estimators on worker threads of their own
//! ([`crate::analysis::estimate_pool`]), one per thread of rayon's global pool, and goes on
//! with the continuation meanwhile: the CPU is the same, the wall time shared over the cores
//! (on the blade pair above 9.7-10.9 s of wall time against 20.7-22.2 s inline on two cores).
//! Runs inside a rayon job (the limit curves, the accuracy study's settings) estimate inline.
//!
//! # Files
//!
//! [`report`] (what an estimate says of a point), [`problems`] (the refined problems and
//! operators), [`rules`] (how far an estimate goes: budget, tail test, widen gate, linear
//! range), [`estimator`] (the estimate of a point), [`converged`] (the extension solved to
//! convergence) and [`warnings`](mod@warnings) (the run's accuracy warnings).

mod converged;
mod estimator;
mod problems;
mod report;
mod rules;
mod warnings;

pub use estimator::ErrorEstimator;
pub use problems::{extended_harmonic, wider_harmonic, EstimateProblems};
pub use report::{EstimateMethod, PathPlace, PathSwitch, PointAccuracy};
pub use rules::{LinearRange, SetBudget, SolveBudget, TailTest, WidenGate};
pub use warnings::{
    largest, run_warnings, warning_text, warnings, AccuracyWarning, EstimateKind, BEYOND_LINEAR,
    MERGE_FRACTION,
};
