//! Floquet multipliers of a periodic orbit of the time integration, from its monodromy matrix:
//! an independent check of Hill's verdict ([`crate::analysis::stability`]) that linearises the
//! true non-smooth Jenkins dynamics, slider included, instead of the harmonic-balance Jacobian.
//!
//! # The period map and its state
//!
//! The state of the integrated system ([`crate::analysis::verify`], Newmark average
//! acceleration with the contact return mapping) at a period start τ = 2πp is
//! z = (q, q̇, w): displacements, velocities and the slider position of every contact point
//! (paper Eqs. 4-6: in stick the slider is frozen, in slip it follows so that T = ±μN, open it
//! follows u; a 2D point, `jenkins-2d`, has two slider coordinates along t₁, t₂ and slips by
//! radial return onto the friction circle). The accelerations are not state: the scheme starts each period from the
//! equations of motion. The period map P: z(τ = 0) ↦ z(τ = 2π) is one period of the scheme
//! ([`crate::analysis::verify`]'s stepper), so its fixed points are the periodic orbits of the
//! discretised equations of motion and the eigenvalues ρ of its Jacobian ∂P/∂z at a fixed point
//! (the monodromy matrix) are the Floquet multipliers of that orbit, with exponents
//! λ = ln ρ / T (T = 2π/ω): Re λ = ln|ρ| / T, Im λ = arg ρ / T, defined modulo ω as Hill's are.
//! For a linear system the scheme's multiplier of a damped eigenvalue s is the trapezoidal
//! rule's ((1 + s dt/2)/(1 − s dt/2))^steps, which equals e^{sT} to O((|s| dt)²) (the tests
//! check both).
//!
//! # How it is computed
//!
//! 1. The orbit: Newton shooting on P(z) − z = 0 from a starting state (the harmonic-balance
//!    point's state at τ = 0, [`crate::analysis::verify::hbm_state`]), the Jacobian of each
//!    iteration being the monodromy matrix at the iterate. Shooting converges to the periodic
//!    orbit whether it is stable or not, which a forward integration does not.
//! 2. The monodromy matrix: central differences of P, one pair of one-period integrations per
//!    state component (2·(2n + n_w) periods, n_w the slider coordinates, one per 1D point and
//!    two per 2D point: 28 for the paper's 6 DOFs and 2 contacts, 44 for its 3D version),
//!    in variables scaled by the orbit's amplitude (velocities by ω times it), with a step of
//!    [`MonodromySettings::relative_step`] and the step Newton aiming at 10⁻¹¹ of the load so
//!    that its round-off is far below the differences (its best iterate within the usual
//!    tolerance is accepted where it cycles at a kink of the law). Central differences across a stick/slip
//!    switch average the two one-sided derivatives: the non-smooth map's switching is seen
//!    through the integrated dynamics (saltation included), not through a smoothed law.
//! 3. The neutral sliders: a contact that is closed and sticks during the whole period keeps
//!    its slider fixed, so the slider's row of ∂P/∂z is exactly the unit row and one multiplier
//!    is exactly 1 (two for a 2D point, one per slider coordinate). Its eigenvector shifts the slider and, with it, the static state: it moves
//!    along the family of stuck states (the non-uniqueness the limit method is about: another
//!    initial tangential state m), it is not an instability. That row and column are removed
//!    before the eigen solve and the slider is held fixed in the shooting (where it would make
//!    P(z) − z singular); [`MonodromyStability::neutral_sliders`] names them. A slider that slips
//!    or opens during the period is reset by the slip and is forgotten: its multiplier is about 0
//!    and is kept (it never leads). A 2D slider that slips is reset along the slip direction
//!    only and its offset across it contracted by μN/|T*| < 1 per slipping step, so its
//!    multiplier lies inside the unit circle and is kept too.
//!
//! 4. The section: the period map may start at any phase τ₀ of the period (the multipliers do
//!    not depend on it), and it must start where the law is smooth in the state. A contact at
//!    a switch of its law at τ₀ makes P non-differentiable there: a limit state m = ±1 starts
//!    stuck exactly at T = ±μN, and a slipping contact sits on |T| = μN, so that a perturbation
//!    one way keeps it stuck and the other way moves its slider (central differences across
//!    such a kink mix two pieces and gave spurious exponents of ±1.5 1/s on the paper's fully
//!    stuck 210 Hz point, whose exponents are those of the linear stuck system). τ₀ is
//!    therefore the step of a first period from the start at which every contact is farthest
//!    from a switch ((μN − |T|)/(μ N_max), N/N_max closed, −kₙv/N_max open), reported as
//!    [`MonodromyStability::section_phase`] and its margin.
//!
//! 5. Grazing: a contact stuck all period that touches |T| = μN at one instant (every stuck
//!    contact of a limit state m = ±1 does, at τ_ini) makes P non-differentiable at the orbit
//!    whatever the section: a perturbation one way keeps it stuck, the other way makes it slip
//!    by an amount of the perturbation's order. Central differences then mix the two pieces;
//!    measured on the paper's fully stuck 210 Hz point (H = 5): leading exponents +1.3 and
//!    +0.39 1/s for m = −1, +1, where the stuck linear system has −0.165 (Hill) and the
//!    monodromy with μ = 1 000 (no grazing) gives −0.15. The slider of such a contact is moved
//!    inwards by [`GRAZING_NUDGE`] of μN at that instant, onto the neighbouring stuck states
//!    whose closure the limit state is, before shooting ([`MonodromyStability::grazing_nudged`]).
//!
//! The verdict uses Hill's rule: stable when the leading exponent's real part is at most
//! [`crate::analysis::stability::STABILITY_TOLERANCE`]·ω.

use std::f64::consts::PI;

use faer::{c64, Mat};
use serde::Serialize;

use crate::analysis::stability::{PointStability, VerdictSource, STABILITY_TOLERANCE};
use crate::analysis::verify::{
    hbm_state, slider_offsets, Newmark, TimeState, VerifyError, VerifySettings,
};
use crate::contact::harmonic::HarmonicSet;
use crate::model::Problem;
use crate::numerics::linalg::solve_dense;

/// Fraction of μN by which the slider of a contact that grazes the slip limit while stuck all
/// period is moved inwards (see [`monodromy_stability`]).
pub const GRAZING_NUDGE: f64 = 1e-3;

/// Settings of the monodromy computation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MonodromySettings {
    /// Central-difference step in the scaled state (relative to the orbit's amplitude).
    pub relative_step: f64,
    /// Most shooting iterations.
    pub max_shooting: usize,
    /// Shooting tolerance on max |P(z) − z| in the scaled state.
    pub shooting_tolerance: f64,
}

impl Default for MonodromySettings {
    /// Step 10⁻⁶, at most 8 shooting iterations, tolerance 10⁻⁹.
    fn default() -> Self {
        Self {
            relative_step: 1e-6,
            max_shooting: 8,
            shooting_tolerance: 1e-9,
        }
    }
}

/// The Floquet multipliers of the time integration's periodic orbit and the verdict.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MonodromyStability {
    /// Whether the leading exponent's real part is at most 10⁻⁶·ω.
    pub stable: bool,
    /// Real part of the leading Floquet exponent, ln|ρ|/T (1/s).
    pub floquet_re: f64,
    /// |arg ρ|/(2πT) of the leading multiplier (Hz, in [0, f/2]: defined modulo f).
    pub floquet_freq_hz: f64,
    /// Real parts of the kept multipliers ρ, ordered by decreasing |ρ|.
    pub multipliers_re: Vec<f64>,
    /// Imaginary parts of the kept multipliers, in the same order.
    pub multipliers_im: Vec<f64>,
    /// Contacts (indices) closed and sticking over the whole period, whose neutral slider
    /// multiplier (exactly 1) was removed.
    pub neutral_sliders: Vec<usize>,
    /// Shooting iterations made.
    pub shooting_iterations: usize,
    /// max |P(z) − z| at the orbit, relative to its amplitude (velocities over ω).
    pub periodicity_defect: f64,
    /// Whether the shooting reached [`MonodromySettings::shooting_tolerance`].
    pub orbit_converged: bool,
    /// Phase τ₀ of the period map's section (rad): where the contacts are farthest from a
    /// switch of their law.
    pub section_phase: f64,
    /// That distance, relative to the normal load (see the module docs); near 0 the period
    /// map has a kink at the orbit and the multipliers are not reliable.
    pub section_margin: f64,
    /// Contacts stuck all period that graze the slip limit, whose slider was moved inwards by
    /// [`GRAZING_NUDGE`] of μN (the limit states m = ±1 of a stuck contact).
    pub grazing_nudged: Vec<usize>,
}

/// The scaled state y = z / scale of a [`TimeState`].
fn pack(state: &TimeState, scale: &[f64]) -> Vec<f64> {
    state
        .q
        .iter()
        .chain(&state.qdot)
        .chain(&state.sliders)
        .zip(scale)
        .map(|(z, s)| z / s)
        .collect()
}

fn unpack(y: &[f64], scale: &[f64], n: usize) -> TimeState {
    let z: Vec<f64> = y.iter().zip(scale).map(|(y, s)| y * s).collect();
    TimeState {
        q: z[..n].to_vec(),
        qdot: z[n..2 * n].to_vec(),
        sliders: z[2 * n..].to_vec(),
    }
}

/// The period map linearised at a state.
struct Linearisation {
    /// ∂P/∂y in scaled variables.
    matrix: Mat<f64>,
    /// P(y), scaled.
    image: Vec<f64>,
    /// Per contact: stuck over the whole period from y.
    stuck: Vec<bool>,
}

/// The monodromy matrix (scaled) at `y` by central differences, and the period map's value at
/// `y` with the contacts stuck over its whole period.
fn monodromy_matrix(
    stepper: &Newmark<'_>,
    k0: usize,
    y: &[f64],
    scale: &[f64],
    n: usize,
    h: f64,
) -> Result<Linearisation, VerifyError> {
    let dim = y.len();
    let centre = stepper.period_map(&unpack(y, scale, n), k0)?;
    let py = pack(&centre.state, scale);
    let mut m = Mat::<f64>::zeros(dim, dim);
    let mut yp = y.to_vec();
    for j in 0..dim {
        yp[j] = y[j] + h;
        let plus = pack(
            &stepper.period_map(&unpack(&yp, scale, n), k0)?.state,
            scale,
        );
        yp[j] = y[j] - h;
        let minus = pack(
            &stepper.period_map(&unpack(&yp, scale, n), k0)?.state,
            scale,
        );
        yp[j] = y[j];
        for i in 0..dim {
            m[(i, j)] = (plus[i] - minus[i]) / (2.0 * h);
        }
    }
    Ok(Linearisation {
        matrix: m,
        image: py,
        stuck: centre.stuck_all_period,
    })
}

/// The Floquet multipliers and verdict of the periodic orbit of the time integration near
/// `start` at `freq_hz` (see the module docs), integrated with `settings.steps_per_period`
/// steps per period.
pub fn monodromy_stability(
    problem: &Problem,
    freq_hz: f64,
    start: &TimeState,
    settings: &VerifySettings,
    monodromy: &MonodromySettings,
) -> Result<MonodromyStability, VerifyError> {
    let stepper = Newmark::new(problem, freq_hz, settings)?.with_target_tolerance(1e-11);
    let n = problem.model.n_dofs();
    let nc = problem.contacts.len();
    let omega = stepper.omega;
    // Scale: the half range of the motion over one period from the start (at least a
    // millionth of the largest displacement, for a structure nearly at rest).
    // A contact stuck all period that reaches |T| = μN at one instant (a limit state m = ±1
    // does, at τ_ini) grazes the slip limit: P is not differentiable there (a perturbation one
    // way keeps it stuck, the other makes it slip by as much). Its slider is moved inwards by
    // GRAZING_NUDGE of μN at that instant, onto the stuck states next to the limit, whose
    // period map is smooth (the limit state is their closure).
    let offsets = slider_offsets(problem);
    // The slider of contact c moved by `length` (m) along its force T at the peak of its
    // friction use (inwards: towards smaller |T| there).
    let nudge = |sliders: &mut [f64], c: usize, t: [f64; 2], length: f64| {
        let magnitude = t[0].hypot(t[1]);
        if magnitude > 0.0 {
            for (a, i) in (offsets[c]..offsets[c + 1]).enumerate() {
                sliders[i] += t[a] / magnitude * length;
            }
        }
    };
    let probe = stepper.period_map(start, 0)?;
    let mut nudged_start = start.clone();
    let mut nudged = Vec::new();
    for (c, p) in problem.contacts.iter().enumerate() {
        let (use_ratio, t, nf) = probe.peak_friction_use[c];
        if probe.stuck_all_period[c] && use_ratio > 1.0 - GRAZING_NUDGE {
            let length = GRAZING_NUDGE * p.law.mu * nf / p.law.kt;
            nudge(&mut nudged_start.sliders, c, t, length);
            nudged.push(c);
        }
    }
    let start = &nudged_start;
    let first = stepper.period_map(start, 0)?;
    let q_max = start.q.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let amplitude = first.half_range.max(1e-6 * q_max).max(1e-300);
    // The section phase: the step of the period farthest from every switch of the contact
    // law, where small perturbations keep every contact on its piece of the law.
    let k0 = first
        .switch_margin
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .map_or(0, |(k, _)| k + 1)
        % stepper.steps;
    let section_margin = first
        .switch_margin
        .get((k0 + stepper.steps - 1) % stepper.steps)
        .copied()
        .unwrap_or(0.0);
    let start = &if k0 == 0 {
        start.clone()
    } else {
        stepper.advance(start, 0, k0)?.state
    };
    let slider_count = offsets[nc];
    // The contact of each slider coordinate.
    let slider_contact: Vec<usize> = (0..nc)
        .flat_map(|c| std::iter::repeat_n(c, offsets[c + 1] - offsets[c]))
        .collect();
    let scale: Vec<f64> = (0..2 * n + slider_count)
        .map(|i| {
            if (n..2 * n).contains(&i) {
                omega * amplitude
            } else {
                amplitude
            }
        })
        .collect();
    let h = monodromy.relative_step;
    let mut y = pack(start, &scale);
    let mut best: Option<(f64, Mat<f64>, Vec<bool>)> = None;
    let mut iterations = 0;
    let mut converged = false;
    // Shooting; then, if a contact of the orbit found grazes the slip limit with its slider
    // still (the time-domain limit orbit can differ from the harmonic-balance one by enough to
    // hide the grazing from the first probe), its slider is nudged inwards and the shooting
    // repeated (at most twice).
    for _round in 0..3 {
        best = None;
        converged = false;
        for it in 0..=monodromy.max_shooting {
            let Linearisation {
                matrix: m,
                image: py,
                stuck,
            } = monodromy_matrix(&stepper, k0, &y, &scale, n, h)?;
            let free: Vec<usize> = (0..y.len())
                .filter(|&i| i < 2 * n || !stuck[slider_contact[i - 2 * n]])
                .collect();
            let defect = free
                .iter()
                .map(|&i| (py[i] - y[i]).abs())
                .fold(0.0_f64, f64::max);
            if best.as_ref().is_none_or(|b| defect < b.0) {
                best = Some((defect, m.clone(), stuck.clone()));
            }
            iterations = it;
            if defect <= monodromy.shooting_tolerance {
                converged = true;
                break;
            }
            if it == monodromy.max_shooting {
                break;
            }
            // Newton: (M − I) δ = −(P(y) − y) on the free components.
            let k = free.len();
            let a = Mat::from_fn(k, k, |r, c| {
                m[(free[r], free[c])] - if r == c { 1.0 } else { 0.0 }
            });
            let rhs: Vec<f64> = free.iter().map(|&i| y[i] - py[i]).collect();
            let Ok(delta) = solve_dense(&a, &rhs) else {
                break;
            };
            for (r, &i) in free.iter().enumerate() {
                y[i] += delta[r];
            }
        }
        let orbit = stepper.period_map(&unpack(&y, &scale, n), k0)?;
        let mut moved = false;
        for (c, p) in problem.contacts.iter().enumerate() {
            let (use_ratio, t, nf) = orbit.peak_friction_use[c];
            let still = orbit.slider_range[c] <= 1e-9 * amplitude;
            if still && use_ratio > 1.0 - GRAZING_NUDGE && !nudged.contains(&c) {
                // Sliders are scaled by the amplitude, as displacements.
                let mut shift = vec![0.0; slider_count];
                nudge(&mut shift, c, t, GRAZING_NUDGE * p.law.mu * nf / p.law.kt);
                for (i, d) in shift.iter().enumerate() {
                    y[2 * n + i] += d / scale[2 * n + i];
                }
                nudged.push(c);
                moved = true;
            }
        }
        if !moved {
            break;
        }
    }
    let Some((defect, m, stuck)) = best else {
        return Err(VerifyError::Monodromy("no monodromy matrix".into()));
    };
    let kept: Vec<usize> = (0..m.nrows())
        .filter(|&i| i < 2 * n || !stuck[slider_contact[i - 2 * n]])
        .collect();
    let reduced = Mat::from_fn(kept.len(), kept.len(), |r, c| m[(kept[r], kept[c])]);
    let mut multipliers: Vec<c64> = reduced
        .eigenvalues()
        .map_err(|_| VerifyError::Monodromy("the eigen solve did not converge".into()))?;
    multipliers.sort_by(|a, b| b.norm().total_cmp(&a.norm()));
    let period = 2.0 * PI / omega;
    let lead = multipliers.first().copied().unwrap_or(c64::new(0.0, 0.0));
    let floquet_re = if lead.norm() > 0.0 {
        lead.norm().ln() / period
    } else {
        f64::NEG_INFINITY
    };
    Ok(MonodromyStability {
        stable: floquet_re <= STABILITY_TOLERANCE * omega,
        floquet_re,
        floquet_freq_hz: lead.im.atan2(lead.re).abs() / (2.0 * PI * period),
        multipliers_re: multipliers.iter().map(|r| r.re).collect(),
        multipliers_im: multipliers.iter().map(|r| r.im).collect(),
        neutral_sliders: (0..nc).filter(|&c| stuck[c]).collect(),
        shooting_iterations: iterations,
        periodicity_defect: defect,
        orbit_converged: converged,
        section_phase: k0 as f64 * 2.0 * PI / stepper.steps as f64,
        section_margin,
        grazing_nudged: nudged,
    })
}

impl MonodromyStability {
    /// The verdict as a point's [`PointStability`]: reliable where the shooting converged to
    /// the periodic orbit.
    pub fn point_stability(&self) -> PointStability {
        PointStability {
            stable: self.stable,
            floquet_re: self.floquet_re,
            floquet_freq_hz: self.floquet_freq_hz,
            method: VerdictSource::Monodromy,
            reliable: self.orbit_converged,
        }
    }
}

/// The monodromy verdict of a converged harmonic-balance point (full coefficients `x` on
/// `set` at `freq_hz`), as `fricbound verify` computes it: the time integration's state at
/// τ = 0 from the point ([`hbm_state`]), Newton shooting to the periodic orbit and the
/// multipliers of its monodromy matrix ([`monodromy_stability`], default
/// [`MonodromySettings`]), with `steps_per_period` Newmark steps per period (0: 256·H, the
/// default of `verify`). This is the per-point verdict of `analysis.stability_method =
/// "monodromy"` (and of `"hill+monodromy"` on stick-slip points).
///
/// Cost: each shooting iteration integrates 2·(2n + n_w) + 1 periods (n_w slider coordinates:
/// one per 1D point, two per 2D point; 29 on the paper system), usually 1-3 iterations.
pub fn point_monodromy(
    problem: &Problem,
    set: &HarmonicSet,
    x: &[f64],
    freq_hz: f64,
    steps_per_period: usize,
) -> Result<MonodromyStability, VerifyError> {
    let defaults = VerifySettings::for_harmonics(set.max_harmonic());
    let settings = VerifySettings {
        steps_per_period: if steps_per_period == 0 {
            defaults.steps_per_period
        } else {
            steps_per_period
        },
        ..defaults
    };
    let start = hbm_state(problem, set, x, freq_hz, settings.steps_per_period)?;
    monodromy_stability(
        problem,
        freq_hz,
        &start,
        &settings,
        &MonodromySettings::default(),
    )
}
