//! The event march: the Jenkins element driven by trigonometric polynomials u(τ), v(τ), its
//! stick, slip and open phases and the instants where one gives way to the next.
//!
//! Each phase has *exit functions* f(τ) that are negative while the phase holds; an event is
//! the first instant where one of them turns positive. They are bracketed on the sample grid
//! (values and rates from the grid signals), grazes inside a cell are caught by the sign
//! change of f′ across it, and every root is refined by Brent's method on direct evaluations
//! of the trigonometric polynomials, to round-off of τ. Blocks of cells where bounds of the
//! exit functions ([`super::bounds`]) rule out any root or graze are passed over whole.

use super::bounds::{Bounded, CellBounds};
use super::roots::brent;
use crate::contact::harmonic::{Block, SampleBasis};
use std::f64::consts::PI;

/// u, v and their first two τ-derivatives at one instant (m, m/rad, m/rad²).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Kinematics {
    /// [u, u′, u″] of the tangential relative displacement.
    pub u: [f64; 3],
    /// [v, v′, v″] of the normal relative displacement (gap included).
    pub v: [f64; 3],
}

/// Coefficients of u and v on the force blocks, evaluated at any τ by direct summation.
pub struct Signals<'a> {
    /// Blocks of the coefficients.
    pub blocks: &'a [Block],
    /// û (m).
    pub u: &'a [f64],
    /// v̂ including the gap (m).
    pub v: &'a [f64],
}

impl Signals<'_> {
    /// u, v and their derivatives at τ.
    pub fn at(&self, tau: f64) -> Kinematics {
        let mut k = Kinematics::default();
        // sin hτ, cos hτ by the angle-addition recurrence from sin τ, cos τ (the blocks are
        // in increasing harmonic order): one sin_cos per evaluation.
        let (s1, c1) = tau.sin_cos();
        let (mut harmonic, mut s, mut c) = (0usize, 0.0, 1.0);
        for (j, block) in self.blocks.iter().enumerate() {
            let (cu, cv) = (self.u[j], self.v[j]);
            match *block {
                Block::Constant => {
                    k.u[0] += cu;
                    k.v[0] += cv;
                }
                Block::Cos(n) | Block::Sin(n) => {
                    while harmonic < n {
                        (s, c) = (s * c1 + c * s1, c * c1 - s * s1);
                        harmonic += 1;
                    }
                    let h = n as f64;
                    // d/dτ cos hτ = −h sin hτ, d/dτ sin hτ = h cos hτ.
                    let (b0, b1, b2) = match *block {
                        Block::Cos(_) => (c, -h * s, -h * h * c),
                        _ => (s, h * c, -h * h * s),
                    };
                    for (out, coef) in [(&mut k.u, cu), (&mut k.v, cv)] {
                        out[0] += coef * b0;
                        out[1] += coef * b1;
                        out[2] += coef * b2;
                    }
                }
            }
        }
        k
    }
}

/// The grid values of [`Kinematics`] over one period, N samples at τₖ = 2πk/N: u, u′, v, v′
/// as samples, u″ and v″ from their coefficients at the few samples that need them (the end
/// of a slip is the one exit whose rate uses them).
pub struct Grid<'a> {
    /// [u, u′] samples.
    pub u: [&'a [f64]; 2],
    /// [v, v′] samples.
    pub v: [&'a [f64]; 2],
    /// Coefficients of u″ and v″ on the force blocks.
    pub second: [&'a [f64]; 2],
    /// The synthesis matrix of the grid (basis values at the samples).
    pub basis: &'a SampleBasis,
    /// Bounds of the exit functions over blocks of cells, filled from these samples.
    pub bounds: &'a CellBounds,
}

impl Grid<'_> {
    fn len(&self) -> usize {
        self.u[0].len()
    }

    /// The kinematics at sample k (0 ≤ k < N); u″ and v″ only with `second` (zero otherwise).
    fn at(&self, k: usize, second: bool) -> Kinematics {
        let (ddu, ddv) = if second {
            let row = self.basis.row(k);
            let dot = |c: &[f64]| row.iter().zip(c).map(|(e, c)| e * c).sum::<f64>();
            (dot(self.second[0]), dot(self.second[1]))
        } else {
            (0.0, 0.0)
        };
        Kinematics {
            u: [self.u[0][k], self.u[1][k], ddu],
            v: [self.v[0][k], self.v[1][k], ddv],
        }
    }
}

/// The Jenkins law's parameters as the march needs them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LawParams {
    /// Tangential stiffness kₜ (N/m).
    pub kt: f64,
    /// Normal stiffness kₙ (N/m).
    pub kn: f64,
    /// μ kₙ (N/m): the friction limit per unit compression.
    pub mu_kn: f64,
    /// Initial tangential state m ∈ [−1, 1].
    pub m: f64,
    /// The constant friction limit μ max(kₙ v̂₀, 0) (N) with a constant normal load; `None`
    /// with a variable one, whose limit is μ kₙ v(τ) while closed.
    pub constant_limit: Option<f64>,
}

impl LawParams {
    /// Friction limit L = μN and its first two τ-derivatives (N, N/rad, N/rad²) while closed
    /// (unclamped: the exit functions stay smooth through v = 0).
    fn limit(&self, k: &Kinematics) -> [f64; 3] {
        match self.constant_limit {
            Some(l) => [l, 0.0, 0.0],
            None => [
                self.mu_kn * k.v[0],
                self.mu_kn * k.v[1],
                self.mu_kn * k.v[2],
            ],
        }
    }

    /// Whether the contact carries friction at this instant (L > 0).
    pub fn closed(&self, k: &Kinematics) -> bool {
        self.limit(k)[0] > 0.0
    }

    /// Slider position w (m) of a stick phase anchored at `anchor` (`at` gives the kinematics
    /// at any τ): T = kₜ (u − w) during that phase.
    pub fn slider(&self, anchor: Anchor, at: impl Fn(f64) -> Kinematics) -> f64 {
        match anchor {
            Anchor::Initial => {
                let k = at(0.0);
                k.u[0] - self.m * self.limit(&k)[0] / self.kt
            }
            Anchor::SlipEnd { tau, sign } => {
                let k = at(tau);
                k.u[0] - sign * self.limit(&k)[0] / self.kt
            }
            Anchor::Closing { tau } => at(tau).u[0],
        }
    }
}

/// What fixed the slider of a stick phase.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Anchor {
    /// The initial condition T(0) = m μ N(0) (paper Eqs. 14-15).
    Initial,
    /// The end of a slip of sign `sign` at `tau`: w = u − sign μN / kₜ there.
    SlipEnd {
        /// τ of the event (rad, on the march's time line).
        tau: f64,
        /// Sign of the slip that ended.
        sign: f64,
    },
    /// The closing of the contact at `tau`: w = u there (T = 0).
    Closing {
        /// τ of the event (rad).
        tau: f64,
    },
}

/// The state of the element over a stretch of time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Phase {
    /// Stuck: T = kₜ (u − w) with the slider w (m) set by `anchor`.
    Stick {
        /// What set the slider.
        anchor: Anchor,
        /// Slider position (m).
        w: f64,
    },
    /// Slipping: T = sign · μN.
    Slip {
        /// ±1.
        sign: f64,
    },
    /// No friction force (separated, or a non-positive normal load).
    Open,
}

/// One phase over [start, end] (rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Piece {
    /// Start τ (rad).
    pub start: f64,
    /// End τ (rad).
    pub end: f64,
    /// The phase.
    pub phase: Phase,
}

/// What ends a phase.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Event {
    /// |kₜ(u − w)| reaches μN with T of this sign: stick → slip.
    SlipOnset(f64),
    /// The slip of this sign stops (kₜ s u′ falls below the rate of μN): slip → stick.
    StickOnset(f64),
    /// v falls through 0: → open.
    Opening,
    /// v rises through 0: open → stick (or straight into slip).
    Closing,
}

/// Errors of the event march.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MarchFailure {
    /// The state did not repeat within the allowed periods; the last slider change (m).
    NotSettled {
        /// Periods marched.
        periods: usize,
        /// Last change of the slider over one period (m).
        drift: f64,
    },
    /// More events in one period than the grid can resolve (a chattering state).
    TooManyEvents,
}

/// The periodic orbit of one contact.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Orbit {
    /// Phases over one period, shifted to start at τ = 0 and end at 2π, in order.
    pub pieces: Vec<Piece>,
    /// Periods marched, the periodic one included.
    pub periods: usize,
}

/// Marches the element from τ = 0 until one period's end state equals its start state, and
/// returns the pieces of that period.
///
/// The element forgets its past at every slip or opening (the slider is then set by u and μN
/// alone), so once one period's last reset repeats, every later period repeats it exactly:
/// the one-period map of the slider is piecewise constant wherever it resets. The march thus
/// stops after two or three periods with an exactly periodic event sequence, or after the
/// first with a contact stuck all period from its initial state.
///
/// A period need not be marched to its end: as soon as one of its events repeats an event of
/// the period before, one period later to round-off of τ and into the same phase, the rest of
/// it is the rest of that period shifted by 2π (the phase after an event is set by the event
/// alone), and so is its end state, which the end-of-period test would then accept. That
/// rest is copied instead of marched. `previous` is scratch for the period before.
pub fn periodic_orbit(
    law: &LawParams,
    signals: &Signals<'_>,
    grid: &Grid<'_>,
    max_periods: usize,
    tolerance: f64,
    (pieces, previous): (&mut Vec<Piece>, &mut Vec<Piece>),
) -> Result<usize, MarchFailure> {
    let marcher = Marcher {
        law,
        signals,
        grid,
        cell: 2.0 * PI / grid.len() as f64,
    };
    let mut state = marcher.initial_phase();
    let mut drift = f64::INFINITY;
    let max_events = 4 * grid.len() + 16;
    previous.clear();
    for period in 1..=max_periods.max(2) {
        pieces.clear();
        let start = state;
        let (mut t, end) = (2.0 * PI * (period - 1) as f64, 2.0 * PI * period as f64);
        let mut matched = false;
        loop {
            match marcher.next_event(state, t, end) {
                None => {
                    pieces.push(Piece {
                        start: t,
                        end,
                        phase: state,
                    });
                    break;
                }
                Some((tau, event)) => {
                    pieces.push(Piece {
                        start: t,
                        end: tau,
                        phase: state,
                    });
                    state = marcher.after(event, tau);
                    t = tau;
                    if let Some(q) = repeated_piece(previous, tau - 2.0 * PI, state, tolerance) {
                        pieces.push(Piece {
                            start: tau,
                            end: previous[q].end + 2.0 * PI,
                            phase: state,
                        });
                        pieces.extend(previous[q + 1..].iter().map(|p| shifted(*p, 2.0 * PI)));
                        matched = true;
                        break;
                    }
                }
            }
            if pieces.len() > max_events {
                return Err(MarchFailure::TooManyEvents);
            }
        }
        let repeats = matched
            || match (start, state) {
                (Phase::Slip { sign: a }, Phase::Slip { sign: b }) => a == b,
                (Phase::Open, Phase::Open) => true,
                (Phase::Stick { w: a, .. }, Phase::Stick { w: b, .. }) => {
                    drift = (a - b).abs();
                    drift <= tolerance
                }
                _ => false,
            };
        if repeats {
            let shift = 2.0 * PI * (period - 1) as f64;
            pieces.retain(|p| p.end > p.start);
            for p in pieces.iter_mut() {
                *p = shifted(*p, -shift);
            }
            return Ok(period);
        }
        std::mem::swap(pieces, previous);
    }
    Err(MarchFailure::NotSettled {
        periods: max_periods.max(2),
        drift,
    })
}

/// `piece` moved by `by` (rad) along the time line, its anchor with it.
fn shifted(mut piece: Piece, by: f64) -> Piece {
    piece.start += by;
    piece.end += by;
    if let Phase::Stick { anchor, .. } = &mut piece.phase {
        match anchor {
            Anchor::SlipEnd { tau, .. } | Anchor::Closing { tau } => *tau += by,
            Anchor::Initial => {}
        }
    }
    piece
}

/// The index of the piece of the previous period (`previous`, in order) that an event starts
/// at `tau` (rad, on that period's time line) to round-off, in `phase` (a stick's slider
/// within `tolerance`, m); the first piece, which no event of that period starts, never.
fn repeated_piece(previous: &[Piece], tau: f64, phase: Phase, tolerance: f64) -> Option<usize> {
    let eps = 1e-12 * tau.abs().max(1.0);
    let first = previous.partition_point(|p| p.start < tau - eps).max(1);
    previous
        .iter()
        .enumerate()
        .skip(first)
        .take_while(|(_, p)| p.start <= tau + eps)
        .find(|(_, p)| match (p.phase, phase) {
            (Phase::Slip { sign: a }, Phase::Slip { sign: b }) => a == b,
            (Phase::Open, Phase::Open) => true,
            (Phase::Stick { w: a, .. }, Phase::Stick { w: b, .. }) => (a - b).abs() <= tolerance,
            _ => false,
        })
        .map(|(i, _)| i)
}

struct Marcher<'a> {
    law: &'a LawParams,
    signals: &'a Signals<'a>,
    grid: &'a Grid<'a>,
    /// Grid spacing (rad).
    cell: f64,
}

/// One cell (a, b] of the march for one exit function: τ (rad), f and f′ at both ends, the
/// level below which f counts as zero at a, and whether the cell is the phase's first.
#[derive(Clone, Copy)]
struct Cell {
    a: (f64, f64, f64),
    b: (f64, f64, f64),
    zero: f64,
    first: bool,
}

impl Marcher<'_> {
    /// The phase at τ = 0: open without a friction limit there, else stuck with the slider
    /// at T(0) = m μN(0), or slipping at once when |m| = 1 and the trial force leaves the
    /// friction cone immediately.
    fn initial_phase(&self) -> Phase {
        let k = self.signals.at(0.0);
        if !self.law.closed(&k) {
            return Phase::Open;
        }
        let w = self.law.slider(Anchor::Initial, |t| self.signals.at(t));
        let sign = self.law.m.signum();
        if self.law.m.abs() >= 1.0 - 1e-12 && self.leaves_at_once(Event::SlipOnset(sign), w, &k) {
            return Phase::Slip { sign };
        }
        Phase::Stick {
            anchor: Anchor::Initial,
            w,
        }
    }

    /// The phase that starts at an event at τ.
    fn after(&self, event: Event, tau: f64) -> Phase {
        match event {
            Event::SlipOnset(sign) => Phase::Slip { sign },
            Event::Opening => Phase::Open,
            Event::StickOnset(sign) => {
                let anchor = Anchor::SlipEnd { tau, sign };
                Phase::Stick {
                    anchor,
                    w: self.law.slider(anchor, |t| self.signals.at(t)),
                }
            }
            Event::Closing => {
                // T = 0 at closing; the contact slips at once where the trial force grows
                // faster than μN (|kₜ u′| > μ kₙ v′).
                let k = self.signals.at(tau);
                let w = k.u[0];
                let sign = k.u[1].signum();
                if self.leaves_at_once(Event::SlipOnset(sign), w, &k) {
                    Phase::Slip { sign }
                } else {
                    Phase::Stick {
                        anchor: Anchor::Closing { tau },
                        w,
                    }
                }
            }
        }
    }

    /// The events that can end `phase`, and how many of the three slots are used. A stick
    /// ends at a slip onset, and (with a variable load) at an opening: where T is zero as N
    /// falls to 0 (no friction, μ = 0, or no tangential motion) no slip onset precedes it.
    fn exits(&self, phase: Phase) -> ([Event; 3], usize) {
        let variable = self.law.constant_limit.is_none();
        let stick = [
            Event::SlipOnset(1.0),
            Event::SlipOnset(-1.0),
            Event::Opening,
        ];
        match phase {
            Phase::Stick { .. } => (stick, if variable { 3 } else { 2 }),
            Phase::Slip { sign } => (
                [Event::StickOnset(sign), Event::Opening, Event::Opening],
                if variable { 2 } else { 1 },
            ),
            Phase::Open => ([Event::Closing; 3], usize::from(variable)),
        }
    }

    /// Exit function f and its rate f′ of `event` at kinematics k (slider w for a stick).
    fn exit(&self, event: Event, w: f64, k: &Kinematics) -> (f64, f64) {
        let kt = self.law.kt;
        let l = self.law.limit(k);
        match event {
            Event::SlipOnset(s) => (s * kt * (k.u[0] - w) - l[0], s * kt * k.u[1] - l[1]),
            Event::StickOnset(s) => (l[1] - s * kt * k.u[1], l[2] - s * kt * k.u[2]),
            Event::Opening => (-k.v[0], -k.v[1]),
            Event::Closing => (k.v[0], k.v[1]),
        }
    }

    /// Whether a phase that starts with `event`'s exit function at zero leaves at once: f′ is
    /// positive beyond round-off of its terms (a rate of zero to round-off, as where u and N
    /// move in phase and T touches ±μN at a maximum, keeps the phase).
    fn leaves_at_once(&self, event: Event, w: f64, k: &Kinematics) -> bool {
        let rate = self.exit(event, w, k).1;
        let l = self.law.limit(k);
        let size = self.law.kt * (k.u[1].abs() + k.u[2].abs()) + l[1].abs() + l[2].abs();
        rate > 1e-12 * size
    }

    /// The size of f for `event` below which it counts as zero (round-off of its terms): a
    /// crossing is an event only where f rises above it, so that a phase touching its limit
    /// (the limit cases' stuck orbits touch ±μN where they start and end) does not leave it
    /// by rounding.
    fn zero_level(&self, event: Event, w: f64, k: &Kinematics) -> f64 {
        let kt = self.law.kt;
        let l = self.law.limit(k);
        let size = match event {
            Event::SlipOnset(_) => kt * (k.u[0].abs() + w.abs()) + l[0].abs(),
            Event::StickOnset(_) => l[1].abs() + kt * k.u[1].abs(),
            // v is zero where the contact has just closed or opened: its rates set the size.
            Event::Opening | Event::Closing => k.v[0].abs() + k.v[1].abs() + k.v[2].abs(),
        };
        1e-12 * size
    }

    /// The first event of `phase` in (t0, t_end], with its time.
    ///
    /// The exit functions and their rates at a cell's end are carried over as the next cell's
    /// start values, and a cell is examined further only where an exit function ends above
    /// zero or its rate falls from positive to negative (the two cases
    /// [`Self::crossing`] looks at): most cells cost one evaluation of each exit function.
    fn next_event(&self, phase: Phase, t0: f64, t_end: f64) -> Option<(f64, Event)> {
        let (events, count) = self.exits(phase);
        let events = &events[..count];
        if events.is_empty() {
            return None;
        }
        let w = match phase {
            Phase::Stick { w, .. } => w,
            _ => 0.0,
        };
        let n = self.grid.len();
        // Only the end of a slip has a rate that needs u″ and v″.
        let second = matches!(phase, Phase::Slip { .. });
        let mut a = t0;
        let mut ka = self.signals.at(t0);
        let mut exits_a = [(0.0, 0.0); 3];
        for (x, &event) in exits_a.iter_mut().zip(events) {
            *x = self.exit(event, w, &ka);
        }
        let mut first = true;
        let mut k = (t0 / self.cell).floor() as usize + 1;
        let mut index = k % n;
        loop {
            if !first {
                // a is the grid point k − 1: pass over the rest of its block at once where
                // no exit function can turn positive in it, as long as the block ends
                // before t_end.
                let i = if index == 0 { n - 1 } else { index - 1 };
                let cells = self.grid.bounds.cells;
                let block = i / cells;
                let block_end = ((block + 1) * cells).min(n);
                let a_next = k - 1 + (block_end - i);
                if (a_next as f64) * self.cell < t_end && self.block_quiet(phase, block) {
                    let ia = block_end % n;
                    a = a_next as f64 * self.cell;
                    ka = self.grid.at(ia, second);
                    for (x, &event) in exits_a.iter_mut().zip(events) {
                        *x = self.exit(event, w, &ka);
                    }
                    k = a_next + 1;
                    index = if ia + 1 == n { 0 } else { ia + 1 };
                    continue;
                }
            }
            let grid_b = k as f64 * self.cell;
            let (b, kb) = if grid_b < t_end {
                (grid_b, self.grid.at(index, second))
            } else {
                (t_end, self.signals.at(t_end))
            };
            let mut exits_b = [(0.0, 0.0); 3];
            for (x, &event) in exits_b.iter_mut().zip(events) {
                *x = self.exit(event, w, &kb);
            }
            if b > a {
                let mut best: Option<(f64, Event)> = None;
                for (i, &event) in events.iter().enumerate() {
                    let ((fa, dfa), (fb, dfb)) = (exits_a[i], exits_b[i]);
                    // The zero level is never negative: below both tests, no root (see
                    // `crossing`).
                    if fb <= 0.0 && !(dfa > 0.0 && dfb < 0.0) {
                        continue;
                    }
                    let zero = self.zero_level(event, w, &ka);
                    let cell = Cell {
                        a: (a, fa, dfa),
                        b: (b, fb, dfb),
                        zero,
                        first,
                    };
                    if let Some(tau) = self.crossing(event, w, cell) {
                        if best.is_none_or(|(t, _)| tau < t) {
                            best = Some((tau, event));
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
            exits_a = exits_b;
            k += 1;
            index = if index + 1 == n { 0 } else { index + 1 };
        }
    }

    /// Whether no exit function of `phase` can turn positive anywhere in block `block` of
    /// the grid ([`CellBounds`]).
    fn block_quiet(&self, phase: Phase, block: usize) -> bool {
        let bound = |which| self.grid.bounds.of(block, which);
        let stays_closed = self.law.constant_limit.is_some() || bound(Bounded::Opening) < 0.0;
        match phase {
            Phase::Stick { w, .. } => {
                let ktw = self.law.kt * w;
                bound(Bounded::SlipPositive) - ktw < 0.0
                    && bound(Bounded::SlipNegative) + ktw < 0.0
                    && stays_closed
            }
            Phase::Slip { sign } => {
                let end = if sign > 0.0 {
                    Bounded::StickPositive
                } else {
                    Bounded::StickNegative
                };
                bound(end) < 0.0 && stays_closed
            }
            Phase::Open => self.law.constant_limit.is_some() || bound(Bounded::Closing) < 0.0,
        }
    }

    /// The first root in (a, b] at which `event`'s exit function turns positive, if any: a
    /// sign change across the cell, or a graze (f′ falls from positive to negative inside the
    /// cell at a positive maximum of f). At a phase's first cell f(a) is zero by construction
    /// (the event that started it), and f is known to fall first.
    fn crossing(&self, event: Event, w: f64, cell: Cell) -> Option<f64> {
        let Cell {
            a: (a, fa, dfa),
            b: (b, fb, dfb),
            zero,
            first,
        } = cell;
        let f = |t: f64| self.exit(event, w, &self.signals.at(t)).0;
        if fb > zero {
            if fa < -zero {
                return Some(brent(f, a, b, fa, fb));
            }
            if first || fa <= zero {
                return Some(self.rising_root(&f, (a, b), fb, zero));
            }
            // Above zero at a cell start past the first: a root missed before; stop here.
            return Some(a);
        }
        if dfa > 0.0 && dfb < 0.0 {
            let df = |t: f64| self.exit(event, w, &self.signals.at(t)).1;
            let peak = brent(df, a, b, dfa, dfb);
            let f_peak = f(peak);
            if f_peak > zero && peak > a {
                if fa < -zero {
                    return Some(brent(f, a, peak, fa, f_peak));
                }
                return Some(self.rising_root(&f, (a, peak), f_peak, zero));
            }
        }
        None
    }

    /// The first rise of f through zero in (a, b] where f(a) ≈ 0 and f(b) > 0: a point where
    /// f is below −`zero` (its round-off) is sought on a subdivision that is geometric toward a
    /// (the stretch where f dips below zero may be far shorter than the cell: a contact that
    /// closes and opens again, a slider that stops for an instant and slips on) and uniform
    /// beyond, then the root is refined from it; where f rises above `zero` first, it rises
    /// from a itself.
    fn rising_root(&self, f: &impl Fn(f64) -> f64, (a, b): (f64, f64), fb: f64, zero: f64) -> f64 {
        const GEOMETRIC: i32 = 40;
        const UNIFORM: usize = 16;
        let geometric = (5..=GEOMETRIC).rev().map(|k| a + (b - a) * 0.5_f64.powi(k));
        let uniform = (1..=UNIFORM).map(|i| a + (b - a) * i as f64 / UNIFORM as f64);
        let mut negative: Option<(f64, f64)> = None;
        for t in geometric.chain(uniform) {
            let ft = if t >= b { fb } else { f(t) };
            if ft > zero {
                return match negative {
                    Some((tn, fneg)) => brent(f, tn, t, fneg, ft),
                    None => a,
                };
            }
            if ft < -zero {
                negative = Some((t, ft));
            }
        }
        b
    }
}

/// The stretches of one period [0, 2π] where v > 0 (the normal spring is compressed), in order:
/// the roots of v bracketed on the grid (a double crossing inside a cell is caught by the sign
/// change of v′ across it) and refined by Brent's method. The normal force's own phases, apart
/// from the tangential ones (which coincide with them only where μ > 0).
pub fn closed_intervals(signals: &Signals<'_>, grid: &Grid<'_>, out: &mut Vec<(f64, f64)>) {
    out.clear();
    let n = grid.len();
    let cell = 2.0 * PI / n as f64;
    let v = |t: f64| signals.at(t).v[0];
    let dv = |t: f64| signals.at(t).v[1];
    let at = |k: usize| {
        if k == n {
            (2.0 * PI, grid.v[0][0], grid.v[1][0])
        } else {
            (k as f64 * cell, grid.v[0][k], grid.v[1][k])
        }
    };
    let mut closed = grid.v[0][0] > 0.0;
    let mut start = 0.0;
    let switch = |tau: f64, now_closed: bool, start: &mut f64, out: &mut Vec<(f64, f64)>| {
        if now_closed {
            *start = tau;
        } else {
            out.push((*start, tau));
        }
    };
    let mut k = 0;
    while k < n {
        let bounds = grid.bounds;
        if k % bounds.cells == 0 {
            // v keeps its sign over the whole block: no root, no short closing or opening.
            let block = k / bounds.cells;
            if bounds.of(block, Bounded::Opening) < 0.0 || bounds.of(block, Bounded::Closing) < 0.0
            {
                k = (k + bounds.cells).min(n);
                continue;
            }
        }
        let ((a, va, da), (b, vb, db)) = (at(k), at(k + 1));
        k += 1;
        if (va > 0.0) != (vb > 0.0) {
            let tau = brent(v, a, b, va, vb);
            closed = vb > 0.0;
            switch(tau, closed, &mut start, out);
        } else if da.signum() != db.signum() && da != 0.0 && db != 0.0 {
            // An extremum inside the cell: a short closing (peak above 0 between two points
            // at or below it) or a short opening (trough at or below 0 between two above it).
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
