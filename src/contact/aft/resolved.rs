//! The event-resolved evaluation of the 1D Jenkins law into the AFT workspace's outputs
//! ([`crate::contact::events`] does the work): the same force coefficients, Jacobian, time
//! samples and contact state as the sampled march, so every caller reads either alike.

use super::{AftError, AftWorkspace, MarchReport, SampleKind, Signal};
use crate::contact::events::bounds::BoundLaw;
use crate::contact::events::march::{
    closed_intervals, periodic_orbit, Anchor, Grid, LawParams, Phase, Piece, Signals,
};
use crate::contact::events::{ForceOutputs, MarchFailure};
use crate::contact::{ContactEffects, ContactState, JenkinsLaw};
use std::f64::consts::PI;

impl AftWorkspace {
    /// The phases (stick, slip, open) of the last [`Self::evaluate_events`] over one period,
    /// in time order: where the law is differentiable and where it has a seam (a slip that
    /// appears inside a stick, [`crate::contact::events`]) is read from them.
    pub fn event_phases(&self) -> &[Piece] {
        &self.events.pieces
    }

    /// Evaluates the contact forces (and, if asked, their Jacobian) for coefficients û, v̂ with
    /// the transitions located in continuous time ([`crate::contact::events`]); the samples
    /// (N of them) only bracket the events and carry the time histories for outputs.
    ///
    /// `v_coefficients` already include the gap in the constant block. Results are left where
    /// [`Self::evaluate`] leaves them.
    pub fn evaluate_events(
        &mut self,
        law: &JenkinsLaw,
        effects: ContactEffects,
        u_coefficients: &[f64],
        v_coefficients: &[f64],
        jacobian: bool,
    ) -> Result<MarchReport, AftError> {
        if u_coefficients
            .iter()
            .chain(v_coefficients)
            .any(|x| !x.is_finite())
        {
            return Err(AftError::NonFinite);
        }
        self.synthesize(u_coefficients, Signal::U);
        self.synthesize(v_coefficients, Signal::V);
        self.events
            .differentiate(&self.set, u_coefficients, v_coefficients);
        // u′ and v′ on the grid; u″ and v″ only where the march asks for them.
        for (coefficients, samples) in [0, 2].iter().zip(&mut self.events.derivative_samples) {
            super::synthesize_into(
                &self.set,
                self.inverse.as_ref(),
                (&mut self.spectrum, &mut self.scratch_inv),
                &self.events.derivative_coefficients[*coefficients],
                samples,
            );
        }
        let constant_v = self
            .set
            .constant_block()
            .map(|j| v_coefficients[j])
            .unwrap_or(0.0);
        self.normal_forces(law, effects, constant_v);
        let params = LawParams::new(law, effects, constant_v);
        let signals = Signals {
            blocks: self.set.blocks(),
            u: u_coefficients,
            v: v_coefficients,
        };
        // Plain comparisons (the samples are finite): these loops vectorise.
        let (mut umin, mut umax, mut nmax) = (f64::INFINITY, f64::NEG_INFINITY, 0.0_f64);
        for &x in &self.u {
            umin = if x < umin { x } else { umin };
            umax = if x > umax { x } else { umax };
        }
        for &x in &self.n {
            nmax = if x.abs() > nmax { x.abs() } else { nmax };
        }
        let scale = (umax - umin) + law.mu * nmax / law.kt + f64::MIN_POSITIVE;
        let tolerance =
            self.settings.periodicity_tolerance * self.settings.length_scale(scale, law.kt);
        let mut pieces = std::mem::take(&mut self.events.pieces);
        let mut intervals = std::mem::take(&mut self.events.closed_intervals);
        let mut bounds = std::mem::take(&mut self.events.bounds);
        let orbit = {
            let [du, dv] = &self.events.derivative_samples;
            let [_, ddu, _, ddv] = &self.events.derivative_coefficients;
            let law = BoundLaw {
                kt: params.kt,
                mu_kn: params.mu_kn,
                constant_limit: params.constant_limit,
            };
            let coefficients = (signals.blocks, signals.u, signals.v);
            bounds.fill(law, coefficients, [&self.u, du], [&self.v, dv]);
            let grid = Grid {
                u: [&self.u, du],
                v: [&self.v, dv],
                second: [ddu, ddv],
                basis: &self.basis,
                bounds: &bounds,
            };
            if params.constant_limit.is_none() && effects.liftoff {
                closed_intervals(&signals, &grid, &mut intervals);
            }
            periodic_orbit(
                &params,
                &signals,
                &grid,
                self.settings.max_periods,
                tolerance,
                (&mut pieces, &mut self.events.previous_pieces),
            )
        };
        self.events.pieces = pieces;
        self.events.closed_intervals = intervals;
        self.events.bounds = bounds;
        let periods = orbit.map_err(|failure| match failure {
            MarchFailure::NotSettled { periods, drift } => AftError::NotSettled { periods, drift },
            MarchFailure::TooManyEvents => AftError::TooManyEvents,
        })?;
        let jacobian = jacobian.then_some([
            self.dt_du.as_mut_slice(),
            self.dt_dv.as_mut_slice(),
            self.dn_dv.as_mut_slice(),
        ]);
        self.events.integrate(
            &self.set,
            &params,
            effects,
            &signals,
            ForceOutputs {
                t_hat: &mut self.t_hat,
                n_hat: &mut self.n_hat,
                jacobian,
            },
        );
        self.sample_orbit(&params);
        let pieces = &self.events.pieces;
        self.initial_anchor = pieces.iter().any(|p| {
            matches!(
                p.phase,
                Phase::Stick {
                    anchor: Anchor::Initial,
                    ..
                }
            )
        });
        let open = pieces.iter().filter(|p| p.phase == Phase::Open).count();
        let state = if open == pieces.len() {
            ContactState::Open
        } else if open > 0 {
            ContactState::StickSlipLiftoff
        } else if pieces.iter().any(|p| matches!(p.phase, Phase::Slip { .. })) {
            ContactState::StickSlip
        } else {
            ContactState::Stuck
        };
        Ok(MarchReport { state, periods })
    }

    /// The tangential force samples T(τₖ) and sample kinds of the orbit in the event buffers
    /// (the normal force samples are set by `normal_forces`): sample k lies in the first
    /// piece that ends after τₖ (the last piece takes the rest).
    fn sample_orbit(&mut self, params: &LawParams) {
        let ns = self.n_samples;
        let pieces = &self.events.pieces;
        let step = 2.0 * PI / ns as f64;
        let mut k = 0;
        for (p, piece) in pieces.iter().enumerate() {
            // Samples k..end: τₖ = k·step < piece.end.
            let end = if p + 1 == pieces.len() {
                ns
            } else {
                ((piece.end / step).ceil().max(0.0) as usize).clamp(k, ns)
            };
            let range = k..end;
            let (t, kinds) = (&mut self.t[range.clone()], &mut self.kinds[range.clone()]);
            match piece.phase {
                // The anchor fields serve the sampled law's Jacobian only; the event law's
                // anchors live in its pieces, so these samples record the kind alone.
                Phase::Stick { w, .. } => {
                    for (t, u) in t.iter_mut().zip(&self.u[range]) {
                        *t = params.kt * (u - w);
                    }
                    kinds.fill(SampleKind::Stick {
                        anchor: 0,
                        sign: 0.0,
                    });
                }
                Phase::Slip { sign } => {
                    for (t, v) in t.iter_mut().zip(&self.v[range]) {
                        *t = sign
                            * match params.constant_limit {
                                Some(l) => l,
                                None => params.mu_kn * v.max(0.0),
                            };
                    }
                    kinds.fill(SampleKind::Slip { sign });
                }
                Phase::Open => {
                    t.fill(0.0);
                    kinds.fill(SampleKind::Open);
                }
            }
            k = end;
        }
        // No pieces (never after a march): no force.
        self.t[k..].fill(0.0);
        self.kinds[k..].fill(SampleKind::Open);
    }
}
