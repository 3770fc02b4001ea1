//! One period of the event-resolved 2D march: phases, their exits located in continuous
//! time, the slip angle's integration, and (for the final period) the force integrals.

use super::crossing::crossing;
use super::dopri::Dopri;
use super::{Columns, Kinematics2, Law2, Path2, ODE_TOLERANCE};
use crate::contact::events::{MarchFailure, Moments};
use std::f64::consts::PI;

/// Gauss–Legendre nodes and weights on [−1, 1] (8 points: exact for degree 15; a step of
/// the slip's integration spans at most one cell of the bracketing grid).
const GL_X: [f64; 4] = [
    0.183_434_642_495_649_8,
    0.525_532_409_916_329,
    0.796_666_477_413_626_7,
    0.960_289_856_497_536_3,
];
const GL_W: [f64; 4] = [
    0.362_683_783_378_362,
    0.313_706_645_877_887_3,
    0.222_381_034_453_374_5,
    0.101_228_536_290_376_3,
];

/// Below this fraction of the point's largest friction limit a slip that is about to open
/// ends: the angle's ODE stiffens like 1/L there, and the force left to integrate is of the
/// order of this fraction squared.
const OPENING_LIMIT_FRACTION: f64 = 1e-9;

/// Most integration steps (tried) of one period before the march gives up.
const MAX_STEPS: usize = 400_000;

/// The state of the element over a stretch of time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Phase2 {
    /// Stuck: T = kₜ (u − w) with the slider w (m); its derivative is in the buffers.
    Stick {
        /// Slider position (m).
        w: [f64; 2],
    },
    /// Slipping: T = L e(θ), θ and its sensitivities in the buffers.
    Slip,
    /// No friction force (separated, or a non-positive friction limit).
    Open,
}

/// What ends a phase.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Exit {
    /// |kₜ(u − w)| reaches L: stick → slip.
    SlipOnset,
    /// The slip rate falls to zero: slip → stick.
    StickOnset,
    /// v falls through 0: → open.
    Opening,
    /// v rises through 0: open → stick (or slip at once).
    Closing,
}

/// Scratch of the march, kept between calls.
#[derive(Debug, Clone, Default)]
pub struct Buffers {
    /// The slip angle's integrator.
    pub dopri: Dopri,
    /// θ and its sensitivities (1 + columns) during a slip.
    pub y: Vec<f64>,
    /// The slider's derivative, 2 × columns row-major: dw_start on entry, dw_end on return.
    pub dw: Vec<f64>,
    b: Vec<f64>,
    db: Vec<f64>,
    rhs_b: Vec<f64>,
    rhs_db: Vec<f64>,
    dense: Vec<f64>,
    dt: Vec<f64>,
    h_guess: f64,
}

impl Buffers {
    /// Sizes the buffers for `columns`.
    pub fn resize(&mut self, columns: &Columns) {
        let c = columns.count;
        self.dopri.resize(1 + c);
        for (v, n) in [
            (&mut self.y, 1 + c),
            (&mut self.dense, 1 + c),
            (&mut self.dt, 2 * c),
            (&mut self.b, columns.nb),
            (&mut self.db, columns.nb),
            (&mut self.rhs_b, columns.nb),
            (&mut self.rhs_db, columns.nb),
        ] {
            v.clear();
            v.resize(n, 0.0);
        }
        self.dw.resize(2 * c, 0.0);
    }
}

/// What the final period leaves for the force integrals and the outputs.
#[derive(Debug, Clone, Default)]
pub struct Record {
    /// ∫ b_j T_a over the slips (unnormalised), per tangent a.
    pub slip_integrals: [Vec<f64>; 2],
    /// ∫ b_j dT_a over the slips, rows a·n_blocks + j, columns as the march's.
    pub slip_derivative: Vec<f64>,
    /// Stick pieces (start, end, slider).
    pub sticks: Vec<(f64, f64, [f64; 2])>,
    /// The sliders' derivatives of the stick pieces, 2 × columns each, in order.
    pub stick_derivatives: Vec<f64>,
    /// T₁, T₂ at the grid samples.
    pub samples: [Vec<f64>; 2],
    /// Whether the element slips at each grid sample.
    pub slipping: Vec<bool>,
    /// Whether the element is open at each grid sample.
    pub open: Vec<bool>,
}

impl Record {
    /// Clears the record for `n_samples` samples and `columns`.
    pub fn reset(&mut self, columns: &Columns, n_samples: usize) {
        for v in &mut self.slip_integrals {
            v.clear();
            v.resize(columns.nb, 0.0);
        }
        self.slip_derivative.clear();
        self.slip_derivative
            .resize(2 * columns.nb * columns.count, 0.0);
        self.sticks.clear();
        self.stick_derivatives.clear();
        for v in &mut self.samples {
            v.clear();
            v.resize(n_samples, 0.0);
        }
        self.slipping.clear();
        self.slipping.resize(n_samples, false);
        self.open.clear();
        self.open.resize(n_samples, false);
    }
}

/// The end of one period.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PeriodEnd {
    /// Slider position at τ = 2π (m); its derivative is left in [`Buffers::dw`].
    pub w: [f64; 2],
    /// Whether some slip lasted a positive time.
    pub slipped: bool,
    /// Whether the contact was open for a positive time.
    pub opened: bool,
    /// Whether it was open all period.
    pub all_open: bool,
}

/// One period's march of a point: its path, law, sensitivity columns and grid.
pub struct PeriodMarch<'a> {
    /// The point's relative motion.
    pub path: Path2<'a>,
    /// The law.
    pub law: Law2,
    /// The sensitivity columns carried.
    pub columns: Columns,
    /// Bracketing grid: samples per period.
    pub n_samples: usize,
    /// The point's largest friction limit over the period (N).
    pub limit_scale: f64,
}

impl PeriodMarch<'_> {
    fn cell(&self) -> f64 {
        2.0 * PI / self.n_samples as f64
    }

    fn variable(&self) -> bool {
        self.law.constant_limit.is_none()
    }

    /// Marches one period from the slider `w_start` (its derivative in `buf.dw`), recording
    /// the final period's integrals and samples in `record` when given.
    pub fn run(
        &self,
        buf: &mut Buffers,
        w_start: [f64; 2],
        mut record: Option<&mut Record>,
    ) -> Result<PeriodEnd, MarchFailure> {
        let end = 2.0 * PI;
        // Each period's steps depend on its own start only (not on an earlier evaluation).
        buf.h_guess = 0.0;
        let mut phase = self.start_phase(buf, w_start);
        let mut t = 0.0;
        let mut events = 0;
        let mut steps = 0;
        let mut strict = false;
        let (mut slipped, mut opened, mut all_open) = (false, false, true);
        loop {
            let (tau, exit) = match phase {
                Phase2::Stick { w } => {
                    let exits: &[Exit] = if self.variable() {
                        &[Exit::SlipOnset, Exit::Opening]
                    } else {
                        &[Exit::SlipOnset]
                    };
                    let next = self.next_explicit(exits, w, (t, end), strict);
                    let tau = next.map_or(end, |n| n.0);
                    if let Some(r) = record.as_deref_mut() {
                        r.sticks.push((t, tau, w));
                        r.stick_derivatives.extend_from_slice(&buf.dw);
                        self.fill_samples(r, t, tau, |k: &Kinematics2, _| {
                            [
                                self.law.kt * (k.u[0][0] - w[0]),
                                self.law.kt * (k.u[1][0] - w[1]),
                            ]
                        });
                    }
                    (tau, next.map(|n| n.1))
                }
                Phase2::Open => {
                    let exits: &[Exit] = if self.variable() {
                        &[Exit::Closing]
                    } else {
                        &[]
                    };
                    let next = self.next_explicit(exits, [0.0; 2], (t, end), strict);
                    let tau = next.map_or(end, |n| n.0);
                    if let Some(r) = record.as_deref_mut() {
                        self.fill_samples(r, t, tau, |_, _| [0.0; 2]);
                        mark(&mut r.open, self.cell(), t, tau);
                    }
                    (tau, next.map(|n| n.1))
                }
                Phase2::Slip => {
                    self.slip(buf, record.as_deref_mut(), (t, end), &mut steps, strict)?
                }
            };
            if tau > t {
                match phase {
                    Phase2::Slip => slipped = true,
                    Phase2::Open => opened = true,
                    Phase2::Stick { .. } => {}
                }
                all_open &= phase == Phase2::Open;
            }
            let Some(exit) = exit else { break };
            // A phase that ended where it began (its exit function within its round-off band
            // at once) hands over at an instant where the next phase's exit function is within
            // its own band too: where both rise from it, the two phases alternated there for
            // ever (a contact closing as its trial force grows exactly as fast as the friction
            // limit, kₜ|u′| ≈ L′). The next phase's first cell then reads signs against the
            // round-off alone, which find the stretch it holds for, however short.
            strict = tau <= t;
            phase = self.after(buf, phase, exit, tau);
            t = tau;
            events += 1;
            if events > 4 * self.n_samples + 16 {
                return Err(MarchFailure::TooManyEvents);
            }
        }
        let w = match phase {
            Phase2::Stick { w } => w,
            Phase2::Open => self.open_slider(buf, end),
            Phase2::Slip => self.slip_slider(buf, end),
        };
        Ok(PeriodEnd {
            w,
            slipped,
            opened,
            all_open,
        })
    }

    /// The phase at τ = 0 from the slider w: open without a friction limit, stuck inside the
    /// friction circle, slipping at once on (or beyond: radial return) the circle when the
    /// trial force leaves it, else stuck on it.
    fn start_phase(&self, buf: &mut Buffers, w: [f64; 2]) -> Phase2 {
        let k = self.path.at(0.0);
        let l = self.law.limit(&k);
        if l[0] <= 0.0 {
            self.open_slider(buf, 0.0);
            return Phase2::Open;
        }
        let kt = self.law.kt;
        let t = [kt * (k.u[0][0] - w[0]), kt * (k.u[1][0] - w[1])];
        let magnitude = t[0].hypot(t[1]);
        if magnitude < l[0] * (1.0 - 1e-12) {
            return Phase2::Stick { w };
        }
        let e = [t[0] / magnitude, t[1] / magnitude];
        let rate = kt * (k.u[0][1] * e[0] + k.u[1][1] * e[1]) - l[1];
        let speed = k.u[0][1].hypot(k.u[1][1]) + k.u[0][2].hypot(k.u[1][2]);
        let size = kt * speed + l[1].abs() + l[2].abs();
        self.start_slip(buf, 0.0, w);
        if rate > 1e-12 * size {
            return Phase2::Slip;
        }
        if magnitude > l[0] {
            return Phase2::Stick {
                w: self.slip_slider(buf, 0.0),
            };
        }
        // Back to the slider's own derivative (start_slip left it in place).
        Phase2::Stick { w }
    }

    /// The phase that starts at an exit at τ.
    fn after(&self, buf: &mut Buffers, phase: Phase2, exit: Exit, tau: f64) -> Phase2 {
        match (exit, phase) {
            (Exit::SlipOnset, Phase2::Stick { w }) => {
                self.start_slip(buf, tau, w);
                Phase2::Slip
            }
            (Exit::StickOnset, _) => Phase2::Stick {
                w: self.slip_slider(buf, tau),
            },
            (Exit::Closing, _) => self.close(buf, tau),
            _ => Phase2::Open,
        }
    }

    /// θ = angle of T = kₜ(u − w) at τ and S = kₜ e⊥·(du − dw)/|T| into `buf.y`.
    fn start_slip(&self, buf: &mut Buffers, tau: f64, w: [f64; 2]) {
        let k = self.path.at_with_basis(tau, &mut buf.b, &mut buf.db);
        let kt = self.law.kt;
        let t = [kt * (k.u[0][0] - w[0]), kt * (k.u[1][0] - w[1])];
        let magnitude = t[0].hypot(t[1]).max(f64::MIN_POSITIVE);
        let theta = t[1].atan2(t[0]);
        let ep = [-theta.sin(), theta.cos()];
        let c = self.columns.count;
        buf.y[0] = theta;
        let s = &mut buf.y[1..];
        for (i, x) in s.iter_mut().enumerate() {
            *x = -kt * (ep[0] * buf.dw[i] + ep[1] * buf.dw[c + i]) / magnitude;
        }
        for (a, ea) in ep.iter().enumerate() {
            self.columns.add_du(a, kt * ea / magnitude, &buf.b, s);
        }
    }

    /// The slider w = u − L e(θ)/kₜ at the end of a slip at τ (θ, S in `buf.y`), with its
    /// derivative dw = du − (dL e + L e⊥ S)/kₜ into `buf.dw`.
    fn slip_slider(&self, buf: &mut Buffers, tau: f64) -> [f64; 2] {
        let k = self.path.at_with_basis(tau, &mut buf.b, &mut buf.db);
        let l = self.law.limit(&k)[0].max(0.0);
        let kt = self.law.kt;
        let (s, co) = buf.y[0].sin_cos();
        let e = [co, s];
        let ep = [-s, co];
        let c = self.columns.count;
        let constant = self.law.constant_limit.is_some();
        for a in 0..2 {
            let row = &mut buf.dw[a * c..(a + 1) * c];
            for (x, sc) in row.iter_mut().zip(&buf.y[1..]) {
                *x = -l * ep[a] * sc / kt;
            }
            self.columns.add_du(a, 1.0, &buf.b, row);
            if l > 0.0 {
                self.columns
                    .add_dv(-e[a] * self.law.mu_kn / kt, &buf.b, constant, row);
            }
        }
        [k.u[0][0] - l * e[0] / kt, k.u[1][0] - l * e[1] / kt]
    }

    /// The slider of an open contact, w = u(τ), with dw = du(τ) into `buf.dw`.
    fn open_slider(&self, buf: &mut Buffers, tau: f64) -> [f64; 2] {
        let k = self.path.at_with_basis(tau, &mut buf.b, &mut buf.db);
        let c = self.columns.count;
        buf.dw.iter_mut().for_each(|x| *x = 0.0);
        for a in 0..2 {
            self.columns
                .add_du(a, 1.0, &buf.b, &mut buf.dw[a * c..(a + 1) * c]);
        }
        [k.u[0][0], k.u[1][0]]
    }

    /// Closing at τ (v = 0): the slider at u (T = 0), dw = du − u′ dv/v′; the contact slips
    /// at once along u′ where the trial force grows faster than L (kₜ|u′| > L′).
    fn close(&self, buf: &mut Buffers, tau: f64) -> Phase2 {
        let k = self.path.at(tau);
        let w = self.open_slider(buf, tau);
        let c = self.columns.count;
        if k.v[1] != 0.0 {
            for a in 0..2 {
                let scale = -k.u[a][1] / k.v[1];
                self.columns
                    .add_dv(scale, &buf.b, false, &mut buf.dw[a * c..(a + 1) * c]);
            }
        }
        let l = self.law.limit(&k);
        let speed = k.u[0][1].hypot(k.u[1][1]);
        let size = self.law.kt * (speed + k.u[0][2].hypot(k.u[1][2])) + l[1].abs() + l[2].abs();
        if self.law.kt * speed - l[1] > 1e-12 * size && speed > 0.0 {
            let theta = k.u[1][1].atan2(k.u[0][1]);
            let ep = [-theta.sin(), theta.cos()];
            buf.y.iter_mut().for_each(|x| *x = 0.0);
            buf.y[0] = theta;
            for (a, ea) in ep.iter().enumerate() {
                self.columns.add_du(a, ea / speed, &buf.db, &mut buf.y[1..]);
            }
            return Phase2::Slip;
        }
        Phase2::Stick { w }
    }

    /// Exit function f and its rate of `exit` at kinematics k (slider w for a stick, angle θ
    /// for a slip).
    fn exit(&self, exit: Exit, w: [f64; 2], theta: f64, k: &Kinematics2) -> (f64, f64) {
        let kt = self.law.kt;
        let l = self.law.limit(k);
        match exit {
            Exit::SlipOnset => {
                let t = [kt * (k.u[0][0] - w[0]), kt * (k.u[1][0] - w[1])];
                let m = t[0].hypot(t[1]);
                let rate = if m > 0.0 {
                    kt * (t[0] * k.u[0][1] + t[1] * k.u[1][1]) / m
                } else {
                    0.0
                };
                (m - l[0], rate - l[1])
            }
            Exit::StickOnset => {
                let (s, c) = theta.sin_cos();
                let along = k.u[0][1] * c + k.u[1][1] * s;
                let across = -k.u[0][1] * s + k.u[1][1] * c;
                let along2 = k.u[0][2] * c + k.u[1][2] * s;
                let rate = if l[0] > 0.0 { kt * across / l[0] } else { 0.0 };
                (l[1] - kt * along, l[2] - kt * (along2 + across * rate))
            }
            Exit::Opening => (-k.v[0], -k.v[1]),
            Exit::Closing => (k.v[0], k.v[1]),
        }
    }

    /// The size of f below which it counts as zero: a margin over the round-off of its terms
    /// (10⁻¹² of them), or the slip angle's tolerance for the end of a slip. `strict`: the
    /// round-off itself (16 ε of the terms), for the first cell of a phase that follows one
    /// that ended at once ([`Self::run`]), where the margin hides which way f goes.
    fn zero_level(&self, exit: Exit, w: [f64; 2], k: &Kinematics2, strict: bool) -> f64 {
        let kt = self.law.kt;
        let l = self.law.limit(k);
        let relative = if strict { 16.0 * f64::EPSILON } else { 1e-12 };
        match exit {
            Exit::SlipOnset => {
                let u = k.u[0][0].hypot(k.u[1][0]);
                relative * (kt * (u + w[0].hypot(w[1])) + l[0].abs())
            }
            Exit::StickOnset => {
                let speed = k.u[0][1].hypot(k.u[1][1]);
                let relative = if strict {
                    relative
                } else {
                    10.0 * ODE_TOLERANCE
                };
                relative * (l[1].abs() + kt * speed)
            }
            // v is zero where the contact has just closed or opened: its rates set the size.
            Exit::Opening | Exit::Closing => {
                relative * (k.v[0].abs() + k.v[1].abs() + k.v[2].abs())
            }
        }
    }

    /// The first exit of an explicit phase (stick with slider w, or open) in (t0, t_end],
    /// bracketed on the grid cells and refined by Brent's method; `strict`: the first cell
    /// reads signs against round-off alone (after a phase that ended at once, [`Self::run`]).
    fn next_explicit(
        &self,
        exits: &[Exit],
        w: [f64; 2],
        (t0, t_end): (f64, f64),
        strict: bool,
    ) -> Option<(f64, Exit)> {
        if exits.is_empty() {
            return None;
        }
        let cell = self.cell();
        let mut a = t0;
        let mut ka = self.path.at(t0);
        let mut first = true;
        let mut k = (t0 / cell).floor() as usize + 1;
        loop {
            let b = (k as f64 * cell).min(t_end);
            let kb = self.path.at(b);
            if b > a {
                let mut best: Option<(f64, Exit)> = None;
                for &exit in exits {
                    let f = |t: f64| self.exit(exit, w, 0.0, &self.path.at(t));
                    let zero = self.zero_level(exit, w, &ka, strict && first);
                    let fa = self.exit(exit, w, 0.0, &ka);
                    let fb = self.exit(exit, w, 0.0, &kb);
                    if let Some(tau) = crossing(&f, (a, fa), (b, fb), zero, first) {
                        if best.is_none_or(|(t, _)| tau < t) {
                            best = Some((tau, exit));
                        }
                    }
                }
                if best.is_some() {
                    return best;
                }
                first = false;
            }
            if b >= t_end {
                return None;
            }
            a = b;
            ka = kb;
            k += 1;
        }
    }

    /// Integrates a slip from t0 (θ, S in `buf.y`) until it ends (the slip rate reaches
    /// zero, or the contact opens) or until t_end; returns the end and its exit. Records the
    /// force integrals and samples on the way; `strict`: its first step reads signs against
    /// round-off alone (after a phase that ended at once, [`Self::run`]).
    fn slip(
        &self,
        buf: &mut Buffers,
        mut record: Option<&mut Record>,
        (t0, t_end): (f64, f64),
        steps: &mut usize,
        strict: bool,
    ) -> Result<(f64, Option<Exit>), MarchFailure> {
        let (t_stop, stop_exit) = if self.variable() {
            match self.next_explicit(&[Exit::Opening], [0.0; 2], (t0, t_end), false) {
                Some((tau, e)) => (tau, Some(e)),
                None => (t_end, None),
            }
        } else {
            (t_end, None)
        };
        let cell = self.cell();
        let h_min = 1e-13 * 2.0 * PI;
        let Buffers {
            dopri,
            y,
            rhs_b,
            rhs_db,
            ..
        } = buf;
        let mut rhs = |tau: f64, y: &[f64], dy: &mut [f64]| {
            self.slip_rate(tau, y, dy, rhs_b, rhs_db);
        };
        dopri.start(&mut rhs, t0, y);
        let mut t = t0;
        let mut first = true;
        if buf.h_guess <= 0.0 {
            buf.h_guess = 0.1 * cell;
        }
        let mut k = self.path.at(t);
        loop {
            let remaining = t_stop - t;
            if remaining <= h_min {
                return Ok((t_stop, stop_exit));
            }
            let limit = self.law.limit(&k);
            let closing_in = limit[1] < 0.0;
            if stop_exit.is_some()
                && closing_in
                && limit[0] < OPENING_LIMIT_FRACTION * self.limit_scale
            {
                // About to open: the rest of the force, of order L², with θ frozen.
                if let Some(r) = record.as_deref_mut() {
                    buf.dense.copy_from_slice(&buf.y);
                    self.quadrature_frozen(buf, r, t, t_stop);
                }
                return Ok((t_stop, stop_exit));
            }
            let mut h = buf.h_guess.min(cell).min(remaining);
            if remaining - h < 0.01 * h {
                h = remaining;
            }
            let Buffers {
                dopri,
                y,
                rhs_b,
                rhs_db,
                ..
            } = buf;
            let mut rhs = |tau: f64, y: &[f64], dy: &mut [f64]| {
                self.slip_rate(tau, y, dy, rhs_b, rhs_db);
            };
            let error = dopri.try_step(&mut rhs, t, y, h);
            *steps += 1;
            if *steps > MAX_STEPS || !error.is_finite() && h <= h_min {
                return Err(MarchFailure::TooManyEvents);
            }
            let factor = if error > 0.0 {
                0.9 * (ODE_TOLERANCE / error).powf(0.125)
            } else {
                5.0
            };
            if (error > ODE_TOLERANCE || !error.is_finite()) && h > h_min {
                buf.h_guess = h * factor.clamp(0.1, 0.9);
                continue;
            }
            let fa = self.exit(Exit::StickOnset, [0.0; 2], y[0], &k);
            let zero = self.zero_level(Exit::StickOnset, [0.0; 2], &k, strict && first);
            let t1 = t + h;
            let kb = self.path.at(t1);
            let fb = self.exit(Exit::StickOnset, [0.0; 2], dopri.y_new[0], &kb);
            // The dense output serves the force quadrature and a possible end of the slip in
            // the step (a sign change or a graze of the exit function, as `crossing` tests).
            let dense = record.is_some() || fb.0 > zero || (fa.1 > 0.0 && fb.1 < 0.0);
            dopri.accept(&mut rhs, t, y, h, dense);
            let g = |tau: f64| {
                self.exit(
                    Exit::StickOnset,
                    [0.0; 2],
                    dopri.dense(0, tau),
                    &self.path.at(tau),
                )
            };
            let root = crossing(&g, (t, fa), (t1, fb), zero, first);
            first = false;
            let end = root.unwrap_or(t1);
            if let Some(r) = record.as_deref_mut() {
                self.quadrature(buf, r, t, end);
            }
            buf.h_guess = h * factor.clamp(0.2, 5.0);
            if let Some(tau) = root {
                let Buffers { dopri, y, .. } = buf;
                dopri.dense_all(tau, y);
                return Ok((tau, Some(Exit::StickOnset)));
            }
            buf.y.copy_from_slice(&buf.dopri.y_new);
            t = t1;
            k = kb;
            if t >= t_stop {
                return Ok((t_stop, stop_exit));
            }
        }
    }

    /// The slip angle's rate θ′ = kₜ (u′·e⊥)/L and its sensitivities' rates (module doc).
    fn slip_rate(&self, tau: f64, y: &[f64], dy: &mut [f64], b: &mut [f64], db: &mut [f64]) {
        let (up, v) = if self.columns.full() {
            self.path.slip_inputs(tau, Some((&mut *b, &mut *db)))
        } else {
            self.path.slip_inputs(tau, None)
        };
        let l = self.law.constant_limit.unwrap_or(self.law.mu_kn * v);
        let kt = self.law.kt;
        let (s, c) = y[0].sin_cos();
        if l <= OPENING_LIMIT_FRACTION * self.limit_scale {
            // At a closing that slips at once: θ follows the direction of u′.
            let k = self.path.at(tau);
            let speed2 = up[0] * up[0] + up[1] * up[1];
            dy.iter_mut().for_each(|x| *x = 0.0);
            if speed2 > 0.0 {
                dy[0] = (up[0] * k.u[1][2] - up[1] * k.u[0][2]) / speed2;
            }
            return;
        }
        let rate = kt * (-up[0] * s + up[1] * c) / l;
        let damping = -kt * (up[0] * c + up[1] * s) / l;
        dy[0] = rate;
        for (d, x) in dy[1..].iter_mut().zip(&y[1..]) {
            *d = damping * x;
        }
        if self.columns.full() {
            let out = &mut dy[1..];
            self.columns.add_du(0, -kt * s / l, db, out);
            self.columns.add_du(1, kt * c / l, db, out);
            let constant = self.law.constant_limit.is_some();
            self.columns
                .add_dv(-rate * self.law.mu_kn / l, b, constant, out);
        }
    }

    /// Gauss–Legendre quadrature of the slip force T = L e(θ) and its derivative over [a, b]
    /// inside the last accepted step, and the samples there.
    fn quadrature(&self, buf: &mut Buffers, r: &mut Record, a: f64, b: f64) {
        if b > a {
            let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
            for (x, wq) in GL_X.iter().zip(GL_W) {
                for tau in [mid - half * x, mid + half * x] {
                    let Buffers { dopri, dense, .. } = buf;
                    dopri.dense_all(tau, dense);
                    self.slip_node(buf, r, tau, half * wq);
                }
            }
        }
        let dopri = &buf.dopri;
        self.fill_samples(r, a, b, |k, tau| {
            let l = self.law.limit(k)[0].max(0.0);
            let (s, c) = dopri.dense(0, tau).sin_cos();
            [l * c, l * s]
        });
        mark(&mut r.slipping, self.cell(), a, b);
    }

    /// The same with θ and S frozen at `buf.dense` (the last instants before an opening).
    fn quadrature_frozen(&self, buf: &mut Buffers, r: &mut Record, a: f64, b: f64) {
        if b > a {
            let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
            for (x, wq) in GL_X.iter().zip(GL_W) {
                for tau in [mid - half * x, mid + half * x] {
                    self.slip_node(buf, r, tau, half * wq);
                }
            }
        }
        let (s, c) = buf.dense[0].sin_cos();
        self.fill_samples(r, a, b, |k, _| {
            let l = self.law.limit(k)[0].max(0.0);
            [l * c, l * s]
        });
        mark(&mut r.slipping, self.cell(), a, b);
    }

    /// One quadrature node at τ with weight `weight`, θ and S in `buf.dense`.
    fn slip_node(&self, buf: &mut Buffers, r: &mut Record, tau: f64, weight: f64) {
        let k = self.path.at_with_basis(tau, &mut buf.b, &mut buf.db);
        let l = self.law.limit(&k)[0].max(0.0);
        let (s, c) = buf.dense[0].sin_cos();
        let e = [c, s];
        let ep = [-s, c];
        let nb = self.columns.nb;
        for a in 0..2 {
            for (o, bj) in r.slip_integrals[a].iter_mut().zip(&buf.b) {
                *o += weight * bj * l * e[a];
            }
        }
        let cols = self.columns.count;
        let constant = self.law.constant_limit.is_some();
        for a in 0..2 {
            let dt = &mut buf.dt[a * cols..(a + 1) * cols];
            for (d, sc) in dt.iter_mut().zip(&buf.dense[1..]) {
                *d = l * ep[a] * sc;
            }
            if l > 0.0 {
                self.columns
                    .add_dv(e[a] * self.law.mu_kn, &buf.b, constant, dt);
            }
            for (j, bj) in buf.b.iter().enumerate() {
                let scale = weight * bj;
                if scale == 0.0 {
                    continue;
                }
                let row = &mut r.slip_derivative[(a * nb + j) * cols..(a * nb + j + 1) * cols];
                for (o, d) in row.iter_mut().zip(dt.iter()) {
                    *o += scale * d;
                }
            }
        }
    }

    /// Fills the force samples at the grid instants in [a, b) with `force(k, τ)`.
    fn fill_samples(
        &self,
        r: &mut Record,
        a: f64,
        b: f64,
        force: impl Fn(&Kinematics2, f64) -> [f64; 2],
    ) {
        let cell = self.cell();
        let (lo, hi) = sample_range(cell, a, b, self.n_samples);
        for k in lo..hi {
            let tau = k as f64 * cell;
            let t = force(&self.path.at(tau), tau);
            r.samples[0][k] = t[0];
            r.samples[1][k] = t[1];
        }
    }
}

/// The grid samples k with τ_k in [a, b).
fn sample_range(cell: f64, a: f64, b: f64, n: usize) -> (usize, usize) {
    let lo = ((a / cell).ceil().max(0.0) as usize).min(n);
    let hi = ((b / cell).ceil().max(0.0) as usize).min(n);
    (lo, hi.max(lo))
}

/// Marks the grid samples in [a, b).
fn mark(flags: &mut [bool], cell: f64, a: f64, b: f64) {
    let (lo, hi) = sample_range(cell, a, b, flags.len());
    flags[lo..hi].iter_mut().for_each(|x| *x = true);
}

/// Buffers of the event-resolved 2D law kept between evaluations (in the 2D workspace).
#[derive(Debug, Clone, Default)]
pub struct EventScratch {
    pub(crate) buffers: Buffers,
    pub(crate) record: Record,
    pub(crate) start_derivative: Vec<f64>,
    pub(crate) gram: Moments,
    pub(crate) piece: Moments,
    pub(crate) closed: Vec<(f64, f64)>,
}
