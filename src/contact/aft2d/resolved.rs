//! The event-resolved evaluation of the 2D Jenkins law into the 2D workspace's outputs
//! ([`crate::contact::events2d`] marches one period): the periodic state by Newton on the
//! one-period map of the slider, the force harmonics integrated between the transitions, and
//! their analytic Jacobian through the periodic state.
//!
//! # The periodic state
//!
//! The march starts at τ = 0 from the initial condition T(0) = μN(0)·m. A contact stuck all
//! of that period keeps it (the limit cases' states, as in 1D). Otherwise the start w of a
//! periodic period solves Φ(w) = w, Φ the one-period map of the slider, and is found by
//! Newton on it: w ← w + (I − A)⁻¹ (Φ(w) − w) with A = ∂Φ/∂w from the march's sensitivities,
//! the step halved until the mismatch falls (down to 1/32, then a plain period). A period
//! that slips depends on its start only through the angle at its first slip onset, so A has
//! rank one and Newton converges in a few periods even where the plain map creeps (a slip
//! nearly along one direction). Once the mismatch is within the periodicity tolerance,
//! Newton polishes it to round-off while it still falls.
//!
//! A period stuck throughout after a transient slip rests on one of a continuum of periodic
//! states, the one the history chose: its start's derivative is the history's, carried along
//! the plain periods that led there. A Newton step that lands in the stuck set is therefore
//! not kept: the march then repeats with plain periods from the initial condition.
//!
//! # Degenerate states at the onset of slip
//!
//! Where the stuck set (the slider positions stuck all period) is a thin lens, as where a
//! nearly straight path is about to slip, a slider outside it slips a little at each of the
//! lens's two ends every period and creeps into its corner, geometrically with a ratio close to
//! 1 and like n^(−1/2) where the lens closes: the limit is a stuck period that just grazes the
//! friction limit twice, never reached in a finite number of periods. Newton on Φ then lands
//! in the lens (its fixed point is the corner, on the edge of the stuck set) and the plain
//! periods creep. Each plain period, and the Newton fixed point, are therefore tested for such
//! a corner ([`grazing`](super::grazing)): the two grazings' conditions are solved for it
//! directly, it is accepted when the rest of the period stays inside the friction circle and
//! the slider lies in its normal cone (from where the march converges to it), and its
//! derivative follows from the implicit function theorem on the grazing conditions (the
//! history's limit). The plain periods otherwise end when the Newton step (I − A)⁻¹(Φ(w) − w),
//! the estimated distance to the fixed point, is within the tolerance, not the last period's
//! drift, which a slowly converging sequence meets far from its limit.
//!
//! # The Jacobian
//!
//! The final period is marched with the sensitivities of every parameter (w_start, û₁, û₂,
//! v̂) and integrated into G = ∂T̂/∂(w_start, x). The start's derivative is the fixed
//! point's, dw_start = (I − A)⁻¹ B (B = ∂Φ/∂x; where |det(I − A)| is below
//! [`FIXED_POINT_CONDITION`] the singular direction is left out, as in the sampled march), or
//! the history's, and dT̂/dx = G_x + G_w dw_start.

use super::grazing::{corner_derivative, creeping_corner};
use super::settle::{newton_step, pseudo_inverse, FIXED_POINT_CONDITION};
use super::workspace::{Aft2dWorkspace, SampleKind};
use crate::contact::aft::{AftError, MarchReport};
use crate::contact::events::roots::brent;
use crate::contact::events::{normalisation, MarchFailure};
use crate::contact::events2d::march::{EventScratch, PeriodEnd, PeriodMarch};
use crate::contact::events2d::{Columns, Law2, Path2};
use crate::contact::point::Jenkins2dLaw;
use crate::contact::{ContactEffects, ContactState, NormalLoad};
use std::f64::consts::PI;

/// Where the final period's start comes from.
enum Start {
    /// Stuck all period from the initial condition, or stuck after plain periods: the
    /// start's derivative (2 × 3 n_blocks) is the history's.
    History(Vec<f64>),
    /// The fixed point of the period map, reached with slip or lift-off.
    FixedPoint,
}

/// A period marched from a start, with its mismatch.
#[derive(Clone, Copy)]
struct Trial {
    start: [f64; 2],
    end: PeriodEnd,
    a: [f64; 4],
    drift: f64,
}

impl Trial {
    fn moves(&self) -> bool {
        self.end.slipped || self.end.opened
    }
}

/// Smallest fraction of a Newton step tried before a plain period.
const MIN_STEP_FRACTION: f64 = 1.0 / 32.0;

/// Newton steps at most spent polishing the fixed point to round-off.
const POLISH_STEPS: usize = 6;

impl Aft2dWorkspace {
    /// Evaluates the contact forces (and, if asked, their Jacobian) with the transitions
    /// located in continuous time ([`crate::contact::events2d`]); the samples only bracket the
    /// events and carry the time histories. Results are left where [`Self::evaluate`] leaves
    /// them.
    pub fn evaluate_events(
        &mut self,
        law: &Jenkins2dLaw,
        effects: ContactEffects,
        u_coefficients: [&[f64]; 2],
        v_coefficients: &[f64],
        jacobian: bool,
    ) -> Result<MarchReport, AftError> {
        self.sample_motion(law, effects, u_coefficients, v_coefficients)?;
        let nb = self.set.n_blocks();
        let constant_v = self.set.constant_block().map_or(0.0, |j| v_coefficients[j]);
        let law2 = Law2 {
            kt: law.kt,
            mu_kn: law.mu * law.kn,
            constant_limit: match effects.normal_load {
                NormalLoad::Variable => None,
                NormalLoad::Constant => Some(law.mu * (law.kn * constant_v).max(0.0)),
            },
        };
        let nmax = self.n.iter().fold(0.0_f64, |a, &x| a.max(x.abs()));
        let range = |x: &[f64]| {
            let (lo, hi) = x
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &y| {
                    (a.min(y), b.max(y))
                });
            hi - lo
        };
        self.march_scale =
            range(&self.u[0]).hypot(range(&self.u[1])) + law.mu * nmax / law.kt + f64::MIN_POSITIVE;
        self.tolerance_scale = self.settings.length_scale(self.march_scale, law.kt);
        let blocks = self.set.blocks().to_vec();
        let march = PeriodMarch {
            path: Path2 {
                blocks: &blocks,
                u: u_coefficients,
                v: v_coefficients,
            },
            law: law2,
            columns: Columns {
                count: if jacobian { 2 + 3 * nb } else { 2 },
                nb,
                constant: self.set.constant_block(),
            },
            n_samples: self.n_samples,
            limit_scale: law.mu * nmax,
        };
        let mut scratch = std::mem::take(&mut self.events);
        let result =
            self.periodic_state(law, &march, &mut scratch)
                .and_then(|(start, w, periods)| {
                    self.finish(law.kn, effects, &march, &mut scratch, start, w, periods)
                });
        self.events = scratch;
        result.map_err(|failure| match failure {
            MarchFailure::NotSettled { periods, drift } => AftError::NotSettled { periods, drift },
            MarchFailure::TooManyEvents => AftError::TooManyEvents,
        })
    }

    /// The start of the periodic period, where its derivative comes from, and the periods
    /// marched (module doc).
    fn periodic_state(
        &mut self,
        law: &Jenkins2dLaw,
        march: &PeriodMarch<'_>,
        s: &mut EventScratch,
    ) -> Result<(Start, [f64; 2], usize), MarchFailure> {
        let limit0 = law.mu * self.n[0].max(0.0);
        let u0 = [self.u[0][0], self.u[1][0]];
        self.initial_slider = if limit0 > 0.0 {
            [
                u0[0] - law.initial_state[0] * limit0 / law.kt,
                u0[1] - law.initial_state[1] * limit0 / law.kt,
            ]
        } else {
            u0
        };
        initial_derivative(law, march, limit0 > 0.0, &mut s.start_derivative);
        // The periods before the final one carry only the two columns of A = ∂Φ/∂w: the
        // first period's coefficient columns are needed only when the march then rests stuck
        // (the history's derivative), and are marched again for that case alone.
        let small = PeriodMarch {
            columns: Columns {
                count: 2,
                ..march.columns
            },
            ..*march
        };
        s.buffers.resize(&small.columns);
        s.buffers.dw.iter_mut().for_each(|x| *x = 0.0);
        let first = small.run(&mut s.buffers, self.initial_slider, None)?;
        if !(first.slipped || first.opened) {
            s.buffers.resize(&march.columns);
            let start = Start::History(x_part(&s.start_derivative, march));
            return Ok((start, self.initial_slider, 1));
        }
        let settled = self.newton(&small, s, first.w)?;
        s.buffers.resize(&march.columns);
        match settled {
            Settled::FixedPoint { w, periods } => {
                // A fixed point within the tolerance of a corner of the stuck set, slipping by
                // no more than the tolerance allows, is the corner (the plain march's limit).
                if !first.opened {
                    if let Some(found) = self.corner(march, w) {
                        return Ok((found.0, found.1, periods));
                    }
                }
                Ok((Start::FixedPoint, w, periods))
            }
            Settled::Stuck {
                w,
                periods,
                used_newton: false,
            } => {
                s.buffers.dw.copy_from_slice(&s.start_derivative);
                march.run(&mut s.buffers, self.initial_slider, None)?;
                Ok((Start::History(x_part(&s.buffers.dw, march)), w, periods))
            }
            Settled::Stuck { .. } => self.plain(march, s),
        }
    }

    /// Newton on the period map from the slider `w` (module doc).
    fn newton(
        &self,
        march: &PeriodMarch<'_>,
        s: &mut EventScratch,
        w: [f64; 2],
    ) -> Result<Settled, MarchFailure> {
        let tol = self.settings.periodicity_tolerance * self.tolerance_scale;
        let budget = self.settings.max_periods.max(2);
        let mut periods = 2;
        let mut used_newton = false;
        let mut current = trial(march, s, w)?;
        loop {
            if !current.moves() {
                return Ok(Settled::Stuck {
                    w: current.start,
                    periods,
                    used_newton,
                });
            }
            if current.drift <= tol {
                let w = self.polish(march, s, current)?;
                return Ok(Settled::FixedPoint { w, periods });
            }
            if periods >= budget {
                return Err(MarchFailure::NotSettled {
                    periods,
                    drift: current.drift,
                });
            }
            let mut next = None;
            if let Some(step) = newton_step(current.mismatch(), current.a, self.march_scale) {
                let mut fraction = 1.0;
                while fraction >= MIN_STEP_FRACTION && periods < budget {
                    let start = [
                        current.start[0] + fraction * step[0],
                        current.start[1] + fraction * step[1],
                    ];
                    let t = trial(march, s, start)?;
                    periods += 1;
                    if t.drift < (1.0 - 1e-4 * fraction) * current.drift {
                        next = Some(t);
                        break;
                    }
                    fraction *= 0.5;
                }
            }
            current = match next {
                Some(t) => {
                    used_newton = true;
                    t
                }
                None => {
                    periods += 1;
                    trial(march, s, current.end.w)?
                }
            };
        }
    }

    /// Newton steps on a fixed point within the tolerance, while they cut its mismatch and
    /// keep the period slipping (or lifting off), down to round-off. (Continuing while they
    /// shorten the Newton step instead, as the plain periods stop on it, turned the 3D blade
    /// pair's 840-900 Hz path back and forth between its two folds.)
    fn polish(
        &self,
        march: &PeriodMarch<'_>,
        s: &mut EventScratch,
        mut current: Trial,
    ) -> Result<[f64; 2], MarchFailure> {
        for _ in 0..POLISH_STEPS {
            let round_off =
                64.0 * f64::EPSILON * (current.start[0].hypot(current.start[1]) + self.march_scale);
            if current.drift <= round_off {
                break;
            }
            let Some(step) = newton_step(current.mismatch(), current.a, self.march_scale) else {
                break;
            };
            let start = [current.start[0] + step[0], current.start[1] + step[1]];
            let t = trial(march, s, start)?;
            if !(t.moves() && t.drift < current.drift) {
                break;
            }
            current = t;
        }
        Ok(current.start)
    }

    /// Plain periods from the initial condition with the start's derivative carried along,
    /// until a period is stuck throughout (the history's state), the Newton step of the period
    /// map (the estimated distance to its fixed point) is within the tolerance, or the slider
    /// is found creeping into a corner of the stuck set ([`grazing`](super::grazing)).
    fn plain(
        &self,
        march: &PeriodMarch<'_>,
        s: &mut EventScratch,
    ) -> Result<(Start, [f64; 2], usize), MarchFailure> {
        let tol = self.settings.periodicity_tolerance * self.tolerance_scale;
        let budget = self.settings.max_periods.max(2);
        let c = march.columns.count;
        let mut derivative = s.start_derivative.clone();
        let mut w = self.initial_slider;
        let mut drift = f64::INFINITY;
        for period in 1..=budget {
            // The w_start columns restart from the identity each period (A of this period);
            // the coefficient columns carry the history.
            derivative[..2].copy_from_slice(&[1.0, 0.0]);
            derivative[c..c + 2].copy_from_slice(&[0.0, 1.0]);
            s.buffers.dw.copy_from_slice(&derivative);
            let end = march.run(&mut s.buffers, w, None)?;
            if !(end.slipped || end.opened) {
                return Ok((Start::History(x_part(&derivative, march)), w, period));
            }
            let mismatch = [end.w[0] - w[0], end.w[1] - w[1]];
            drift = mismatch[0].hypot(mismatch[1]);
            let d = &s.buffers.dw;
            let a = [d[0], d[1], d[c], d[c + 1]];
            let distance = newton_step(mismatch, a, self.march_scale)
                .map_or(f64::INFINITY, |step| step[0].hypot(step[1]));
            if !end.opened {
                if let Some((start, corner)) = self.corner(march, w) {
                    return Ok((start, corner, period));
                }
            }
            let round_off = 64.0 * f64::EPSILON * (w[0].hypot(w[1]) + self.march_scale);
            if distance <= tol || drift <= round_off {
                return Ok((Start::FixedPoint, w, period));
            }
            derivative.copy_from_slice(&s.buffers.dw);
            w = end.w;
        }
        Err(MarchFailure::NotSettled {
            periods: budget,
            drift,
        })
    }

    /// The corner of the stuck set that the slider `w`, at the start of a period that slips
    /// without lift-off, creeps into, with its derivative ([`grazing`](super::grazing)).
    fn corner(&self, march: &PeriodMarch<'_>, w: [f64; 2]) -> Option<(Start, [f64; 2])> {
        let corner = creeping_corner(march, w, self.march_scale)?;
        let derivative = if march.columns.full() {
            corner_derivative(march, &corner)?
        } else {
            Vec::new()
        };
        Some((Start::History(derivative), corner.w))
    }

    /// Marches the periodic period from `w` with every sensitivity and fills the outputs.
    #[allow(clippy::too_many_arguments)]
    fn finish(
        &mut self,
        kn: f64,
        effects: ContactEffects,
        march: &PeriodMarch<'_>,
        s: &mut EventScratch,
        start: Start,
        w: [f64; 2],
        periods: usize,
    ) -> Result<MarchReport, MarchFailure> {
        let c = march.columns.count;
        s.buffers.dw.iter_mut().for_each(|x| *x = 0.0);
        s.buffers.dw[0] = 1.0;
        s.buffers.dw[c + 1] = 1.0;
        s.record.reset(&march.columns, self.n_samples);
        let end = march.run(&mut s.buffers, w, Some(&mut s.record))?;
        self.integrate_forces(march, s);
        if march.columns.full() {
            let start_derivative = match start {
                Start::History(d) => d,
                Start::FixedPoint => fixed_point_derivative(&s.buffers.dw, march),
            };
            self.fold(march, &s.record.slip_derivative, &start_derivative);
        }
        self.normal_harmonics(kn, effects, march, s);
        for k in 0..self.n_samples {
            let t = [s.record.samples[0][k], s.record.samples[1][k]];
            self.t[0][k] = t[0];
            self.t[1][k] = t[1];
            let magnitude = t[0].hypot(t[1]);
            self.kinds[k] = if s.record.open[k] {
                SampleKind::Open
            } else if s.record.slipping[k] && magnitude > 0.0 {
                SampleKind::Slip {
                    direction: [t[0] / magnitude, t[1] / magnitude],
                    ratio: 1.0,
                }
            } else {
                SampleKind::Stick
            };
        }
        self.slider_start = w;
        let state = if end.all_open {
            ContactState::Open
        } else if end.opened {
            ContactState::StickSlipLiftoff
        } else if end.slipped {
            ContactState::StickSlip
        } else {
            ContactState::Stuck
        };
        Ok(MarchReport { state, periods })
    }

    /// T̂ and G = ∂T̂/∂(w_start, x) (left in the record's slip derivative) from the slip
    /// integrals and the stick pieces' closed forms.
    fn integrate_forces(&mut self, march: &PeriodMarch<'_>, s: &mut EventScratch) {
        let blocks = self.set.blocks();
        let nb = blocks.len();
        let c = march.columns.count;
        let kt = march.law.kt;
        let len = 2 * self.set.max_harmonic() + 1;
        s.gram.reset(len);
        s.piece.reset(len);
        let record = &mut s.record;
        let g = &mut record.slip_derivative;
        for a in 0..2 {
            self.t_hat[a].copy_from_slice(&record.slip_integrals[a]);
        }
        for (p, &(t0, t1, w)) in record.sticks.iter().enumerate() {
            if t1 <= t0 {
                continue;
            }
            s.piece.interval(t0, t1);
            s.gram.add(1.0, &s.piece);
            let dw = &record.stick_derivatives[p * 2 * c..(p + 1) * 2 * c];
            for a in 0..2 {
                for (j, b) in blocks.iter().enumerate() {
                    let single = s.piece.single(*b);
                    self.t_hat[a][j] -= kt * w[a] * single;
                    let row = &mut g[(a * nb + j) * c..(a * nb + j + 1) * c];
                    for (o, d) in row.iter_mut().zip(&dw[a * c..(a + 1) * c]) {
                        *o -= kt * single * d;
                    }
                }
            }
        }
        for a in 0..2 {
            for j in 0..nb {
                for i in 0..nb {
                    let gram = s.gram.gram(blocks[j], blocks[i]);
                    self.t_hat[a][j] += kt * gram * march.path.u[a][i];
                    if march.columns.full() {
                        g[(a * nb + j) * c + 2 + a * nb + i] += kt * gram;
                    }
                }
            }
        }
        for a in 0..2 {
            for (j, b) in blocks.iter().enumerate() {
                let cj = normalisation(*b);
                self.t_hat[a][j] *= cj;
                g[(a * nb + j) * c..(a * nb + j + 1) * c]
                    .iter_mut()
                    .for_each(|x| *x *= cj);
            }
        }
    }

    /// dT̂/dx = G_x + G_w · dw_start into `dt_dx`.
    fn fold(&mut self, march: &PeriodMarch<'_>, g: &[f64], start: &[f64]) {
        let c = march.columns.count;
        let x = c - 2;
        for r in 0..2 * march.columns.nb {
            let row = &g[r * c..(r + 1) * c];
            let out = &mut self.dt_dx[r * x..(r + 1) * x];
            for (i, o) in out.iter_mut().enumerate() {
                *o = row[2 + i] + row[0] * start[i] + row[1] * start[x + i];
            }
        }
    }

    /// N̂ and ∂N̂/∂v̂: closed forms over the closed stretches (variable load with lift-off),
    /// kₙ v̂ (without lift-off), or the constant kₙ v̂₀.
    fn normal_harmonics(
        &mut self,
        kn: f64,
        effects: ContactEffects,
        march: &PeriodMarch<'_>,
        s: &mut EventScratch,
    ) {
        let blocks = self.set.blocks();
        let nb = blocks.len();
        self.n_hat.iter_mut().for_each(|x| *x = 0.0);
        self.dn_dv.iter_mut().for_each(|x| *x = 0.0);
        let v = march.path.v;
        match (effects.normal_load, effects.liftoff) {
            (NormalLoad::Variable, true) => {
                closed_intervals(&march.path, self.n_samples, &mut s.closed);
                let len = 2 * self.set.max_harmonic() + 1;
                s.gram.reset(len);
                s.piece.reset(len);
                for &(t0, t1) in &s.closed {
                    s.piece.interval(t0, t1);
                    s.gram.add(1.0, &s.piece);
                }
                for j in 0..nb {
                    let cj = normalisation(blocks[j]);
                    for i in 0..nb {
                        let gram = cj * kn * s.gram.gram(blocks[j], blocks[i]);
                        self.n_hat[j] += gram * v[i];
                        self.dn_dv[j * nb + i] = gram;
                    }
                }
            }
            (NormalLoad::Variable, false) => {
                for j in 0..nb {
                    self.n_hat[j] = kn * v[j];
                    self.dn_dv[j * nb + j] = kn;
                }
            }
            (NormalLoad::Constant, liftoff) => {
                if let Some(c) = self.set.constant_block() {
                    let n0 = kn * v[c];
                    if !liftoff || n0 > 0.0 {
                        self.n_hat[c] = n0;
                        self.dn_dv[c * nb + c] = kn;
                    }
                }
            }
        }
    }
}

/// How the Newton iteration on the period map ended.
enum Settled {
    /// At the fixed point, with slip or lift-off.
    FixedPoint { w: [f64; 2], periods: usize },
    /// At a period stuck throughout.
    Stuck {
        w: [f64; 2],
        periods: usize,
        used_newton: bool,
    },
}

impl Trial {
    fn mismatch(&self) -> [f64; 2] {
        [self.end.w[0] - self.start[0], self.end.w[1] - self.start[1]]
    }
}

/// One period from `start` with the period map's derivative (2 columns).
fn trial(
    march: &PeriodMarch<'_>,
    s: &mut EventScratch,
    start: [f64; 2],
) -> Result<Trial, MarchFailure> {
    s.buffers.dw.copy_from_slice(&[1.0, 0.0, 0.0, 1.0]);
    let end = march.run(&mut s.buffers, start, None)?;
    let d = &s.buffers.dw;
    Ok(Trial {
        start,
        end,
        a: [d[0], d[1], d[2], d[3]],
        drift: (end.w[0] - start[0]).hypot(end.w[1] - start[1]),
    })
}

/// The derivative (2 × columns) of the initial slider w = u(0) − m L(0)/kₜ.
fn initial_derivative(
    law: &Jenkins2dLaw,
    march: &PeriodMarch<'_>,
    closed: bool,
    out: &mut Vec<f64>,
) {
    let columns = march.columns;
    let c = columns.count;
    out.clear();
    out.resize(2 * c, 0.0);
    if !columns.full() {
        return;
    }
    let nb = columns.nb;
    let (mut b, mut db) = (vec![0.0; nb], vec![0.0; nb]);
    march.path.basis(0.0, &mut b, &mut db);
    let constant = march.law.constant_limit.is_some();
    for a in 0..2 {
        let row = &mut out[a * c..(a + 1) * c];
        columns.add_du(a, 1.0, &b, row);
        if closed {
            let scale = -law.initial_state[a] * march.law.mu_kn / law.kt;
            columns.add_dv(scale, &b, constant, row);
        }
    }
}

/// The coefficient columns (2 × 3 n_blocks) of a slider derivative over all columns.
fn x_part(d: &[f64], march: &PeriodMarch<'_>) -> Vec<f64> {
    let c = march.columns.count;
    let x = c - 2;
    let mut out = vec![0.0; 2 * x];
    for a in 0..2 {
        out[a * x..(a + 1) * x].copy_from_slice(&d[a * c + 2..(a + 1) * c]);
    }
    out
}

/// dw_start = (I − A)⁻¹ B from the final period's slider derivative [A | B]; the singular
/// direction is left out where |det(I − A)| is below [`FIXED_POINT_CONDITION`].
fn fixed_point_derivative(d: &[f64], march: &PeriodMarch<'_>) -> Vec<f64> {
    let c = march.columns.count;
    let a = [d[0], d[1], d[c], d[c + 1]];
    let m = [1.0 - a[0], -a[1], -a[2], 1.0 - a[3]];
    let det = m[0] * m[3] - m[1] * m[2];
    let inv = if det.abs() > FIXED_POINT_CONDITION {
        [m[3] / det, -m[1] / det, -m[2] / det, m[0] / det]
    } else {
        pseudo_inverse(m, FIXED_POINT_CONDITION)
    };
    let b = x_part(d, march);
    let x = c - 2;
    let mut out = vec![0.0; 2 * x];
    for i in 0..x {
        out[i] = inv[0] * b[i] + inv[1] * b[x + i];
        out[x + i] = inv[2] * b[i] + inv[3] * b[x + i];
    }
    out
}

/// The stretches of [0, 2π] where v > 0, bracketed on `n` cells (a double crossing inside a
/// cell caught by the sign change of v′) and refined by Brent's method.
fn closed_intervals(path: &Path2<'_>, n: usize, out: &mut Vec<(f64, f64)>) {
    out.clear();
    let cell = 2.0 * PI / n as f64;
    let v = |t: f64| path.at(t).v[0];
    let dv = |t: f64| path.at(t).v[1];
    let at = |k: usize| {
        let tau = if k == n { 2.0 * PI } else { k as f64 * cell };
        let kin = path.at(tau);
        (tau, kin.v[0], kin.v[1])
    };
    let mut closed = at(0).1 > 0.0;
    let mut start = 0.0;
    let switch = |tau: f64, now_closed: bool, start: &mut f64, out: &mut Vec<(f64, f64)>| {
        if now_closed {
            *start = tau;
        } else {
            out.push((*start, tau));
        }
    };
    for k in 0..n {
        let ((a, va, da), (b, vb, db)) = (at(k), at(k + 1));
        if (va > 0.0) != (vb > 0.0) {
            let tau = brent(v, a, b, va, vb);
            closed = vb > 0.0;
            switch(tau, closed, &mut start, out);
        } else if da.signum() != db.signum() && da != 0.0 && db != 0.0 {
            let extremum = brent(dv, a, b, da, db);
            let ve = v(extremum);
            if (va > 0.0) != (ve > 0.0) {
                let first = brent(v, a, extremum, va, ve);
                let second = brent(v, extremum, b, ve, vb);
                switch(first, !closed, &mut start, out);
                switch(second, closed, &mut start, out);
            }
        }
    }
    if closed {
        out.push((start, 2.0 * PI));
    }
}
