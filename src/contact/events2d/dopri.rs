//! Dormand–Prince 5(4) steps with Shampine's dense output of order 4, for the slip angle θ
//! and its forward sensitivities.
//!
//! Written here rather than taken from a crate: the system is one scalar ODE plus its linear
//! sensitivity equations, integrated over a few hundred steps per period inside every
//! residual evaluation; the march needs the dense output between steps (to locate the end of
//! a slip and to integrate the force harmonics) and a step it controls (capped by the
//! bracketing grid, cut at events), with buffers kept from one call to the next. The ODE
//! crates on crates.io either allocate per call, hide the interpolant, or bring a linear
//! algebra stack the contact layer does not use. The coefficients are those of Dormand &
//! Prince (1980) and of the dense output of Hairer, Nørsett & Wanner's DOPRI5.

const C: [f64; 7] = [0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0];
const A2: [f64; 1] = [0.2];
const A3: [f64; 2] = [3.0 / 40.0, 9.0 / 40.0];
const A4: [f64; 3] = [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0];
const A5: [f64; 4] = [
    19372.0 / 6561.0,
    -25360.0 / 2187.0,
    64448.0 / 6561.0,
    -212.0 / 729.0,
];
const A6: [f64; 5] = [
    9017.0 / 3168.0,
    -355.0 / 33.0,
    46732.0 / 5247.0,
    49.0 / 176.0,
    -5103.0 / 18656.0,
];
/// The 5th-order weights (row 7 of the tableau: first same as last).
const B: [f64; 6] = [
    35.0 / 384.0,
    0.0,
    500.0 / 1113.0,
    125.0 / 192.0,
    -2187.0 / 6784.0,
    11.0 / 84.0,
];
/// Error weights b − b̂ over stages 1..7.
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];
/// Dense output weights over stages 1..7.
const D: [f64; 7] = [
    -12715105075.0 / 11282082432.0,
    0.0,
    87487479700.0 / 32700410799.0,
    -10690763975.0 / 1880347072.0,
    701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0,
    69997945.0 / 29380423.0,
];

/// Stage buffers, the step's result and its dense output, for states of one length.
#[derive(Debug, Clone, Default)]
pub struct Dopri {
    k: [Vec<f64>; 7],
    stage: Vec<f64>,
    /// State at the end of the last step tried.
    pub y_new: Vec<f64>,
    /// Dense output coefficients of the last accepted step (Hairer's rcont1..5).
    cont: [Vec<f64>; 5],
    /// Start and length of the last accepted step.
    t0: f64,
    h: f64,
}

impl Dopri {
    /// Sizes the buffers for states of length `n`.
    pub fn resize(&mut self, n: usize) {
        for v in self
            .k
            .iter_mut()
            .chain(self.cont.iter_mut())
            .chain([&mut self.stage, &mut self.y_new])
        {
            v.clear();
            v.resize(n, 0.0);
        }
    }

    /// Sets the derivative at the start of the next step (call after a jump of the state).
    pub fn start(&mut self, f: &mut impl FnMut(f64, &[f64], &mut [f64]), t: f64, y: &[f64]) {
        let mut k1 = std::mem::take(&mut self.k[0]);
        f(t, y, &mut k1);
        self.k[0] = k1;
    }

    /// The derivative at the start of the next step (θ′ in component 0).
    pub fn rate(&self) -> &[f64] {
        &self.k[0]
    }

    /// The derivative at the end of the last step tried (stage 7, first same as last).
    pub fn end_rate(&self) -> &[f64] {
        &self.k[6]
    }

    /// Tries one step of length h from (t, y); returns the error estimate of component 0
    /// (absolute) and leaves the new state in [`Self::y_new`].
    pub fn try_step(
        &mut self,
        f: &mut impl FnMut(f64, &[f64], &mut [f64]),
        t: f64,
        y: &[f64],
        h: f64,
    ) -> f64 {
        let rows: [&[f64]; 5] = [&A2, &A3, &A4, &A5, &A6];
        for (s, a) in rows.iter().enumerate() {
            let stage = s + 1;
            for (i, out) in self.stage.iter_mut().enumerate() {
                let mut acc = 0.0;
                for (j, aj) in a.iter().enumerate() {
                    acc += aj * self.k[j][i];
                }
                *out = y[i] + h * acc;
            }
            let mut k = std::mem::take(&mut self.k[stage]);
            f(t + C[stage] * h, &self.stage, &mut k);
            self.k[stage] = k;
        }
        for (i, out) in self.y_new.iter_mut().enumerate() {
            let mut acc = 0.0;
            for (j, bj) in B.iter().enumerate() {
                acc += bj * self.k[j][i];
            }
            *out = y[i] + h * acc;
        }
        let mut k7 = std::mem::take(&mut self.k[6]);
        f(t + h, &self.y_new, &mut k7);
        self.k[6] = k7;
        let error: f64 = E.iter().zip(&self.k).map(|(e, k)| e * k[0]).sum();
        (h * error).abs()
    }

    /// Accepts the last step tried from (t, y): builds its dense output, and its end rate
    /// becomes the next step's start rate. The caller then copies [`Self::y_new`] into y.
    pub fn accept(&mut self, t: f64, y: &[f64], h: f64) {
        for i in 0..y.len() {
            let diff = self.y_new[i] - y[i];
            let bspl = h * self.k[0][i] - diff;
            self.cont[0][i] = y[i];
            self.cont[1][i] = diff;
            self.cont[2][i] = bspl;
            self.cont[3][i] = diff - h * self.k[6][i] - bspl;
            let mut acc = 0.0;
            for (j, dj) in D.iter().enumerate() {
                acc += dj * self.k[j][i];
            }
            self.cont[4][i] = h * acc;
        }
        self.t0 = t;
        self.h = h;
        self.k.swap(0, 6);
    }

    /// Component i of the dense output of the last accepted step at τ.
    pub fn dense(&self, i: usize, tau: f64) -> f64 {
        let s = (tau - self.t0) / self.h;
        let s1 = 1.0 - s;
        let c = &self.cont;
        c[0][i] + s * (c[1][i] + s1 * (c[2][i] + s * (c[3][i] + s1 * c[4][i])))
    }

    /// The whole dense output of the last accepted step at τ into `out`.
    pub fn dense_all(&self, tau: f64, out: &mut [f64]) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.dense(i, tau);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y′ = −y·cos t + sin 3t over [0, 4] against a fine reference: fifth order in the step,
    /// and the dense output agrees with the steps.
    #[test]
    fn steps_and_dense_output_are_accurate() {
        let f = |t: f64, y: &[f64], dy: &mut [f64]| dy[0] = -y[0] * t.cos() + (3.0 * t).sin();
        // The end value and the dense output at τ = 2.025 (inside a step) with n steps.
        let run = |n: usize| {
            let mut d = Dopri::default();
            d.resize(1);
            let mut g = f;
            let mut y = vec![1.0];
            let h = 4.0 / n as f64;
            let query = 2.025;
            d.start(&mut g, 0.0, &y);
            let mut at_query = f64::NAN;
            for s in 0..n {
                let t = s as f64 * h;
                d.try_step(&mut g, t, &y, h);
                d.accept(t, &y, h);
                if t <= query && query < t + h {
                    at_query = d.dense(0, query);
                }
                y.copy_from_slice(&d.y_new);
            }
            (y[0], at_query)
        };
        let (reference, query_reference) = run(4000);
        let (coarse, _) = run(40);
        let (fine, query_fine) = run(80);
        let ratio = (coarse - reference).abs() / (fine - reference).abs();
        assert!(ratio > 20.0, "order: error ratio {ratio}");
        assert!(
            (query_fine - query_reference).abs() < 1e-6,
            "{query_fine} vs {query_reference}"
        );
    }
}
