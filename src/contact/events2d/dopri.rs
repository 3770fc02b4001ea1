//! Dormand–Prince 8(5,3) steps (Hairer's DOP853) with their dense output of order 7, for the
//! slip angle θ and its forward sensitivities.
//!
//! Written here rather than taken from a crate: the system is one scalar ODE plus its linear
//! sensitivity equations, integrated over a few hundred steps per period inside every
//! residual evaluation; the march needs the dense output between steps (to locate the end of
//! a slip and to integrate the force harmonics) and a step it controls (capped by the
//! bracketing grid, cut at events), with buffers kept from one call to the next. The ODE
//! crates on crates.io either allocate per call, hide the interpolant, or bring a linear
//! algebra stack the contact layer does not use.
//!
//! Why 8th order: the march integrates θ to a tolerance far below the harmonic-balance
//! Newton's ([`super::ODE_TOLERANCE`]), where the step count of a method of order p falls like
//! tol^(−1/(p+1)): at 10⁻¹¹ an 8th-order step is several times longer than a 5th-order one,
//! and the force quadrature (one Gauss–Legendre rule per step) shrinks with the step count.
//! The dense output's three extra stages are computed only for the steps that need it.
//!
//! The coefficients are those of Hairer, Nørsett & Wanner, *Solving Ordinary Differential
//! Equations I* (2nd ed., 1993, §II.10) as published with their code DOP853; the error
//! estimate is theirs (a 5th-order estimate corrected by a 3rd-order one).

/// Nodes c_i of the 16 stages: 12 of the step, the 13th (first same as last) at its end, and
/// 3 more for the dense output.
#[rustfmt::skip]
const C: [f64; 16] = [
    0.0, 0.05260015195876773, 0.0789002279381516, 0.1183503419072274,
    0.2816496580927726, 0.3333333333333333, 0.25, 0.3076923076923077,
    0.6512820512820513, 0.6, 0.8571428571428571, 1.0,
    1.0, 0.1, 0.2, 0.7777777777777778,
];

/// The coupling coefficients a_ij, j < i, of stage i (row 12: the weights b of the 8th-order
/// solution; rows 13-15: the dense output's extra stages).
#[rustfmt::skip]
const A: [&[f64]; 16] = [
    &[],
    &[
        0.05260015195876773,
    ],
    &[
        0.0197250569845379, 0.0591751709536137,
    ],
    &[
        0.02958758547680685, 0.0, 0.08876275643042054,
    ],
    &[
        0.2413651341592667, 0.0, -0.8845494793282861, 0.924834003261792,
    ],
    &[
        0.037037037037037035, 0.0, 0.0, 0.17082860872947386,
        0.12546768756682242,
    ],
    &[
        0.037109375, 0.0, 0.0, 0.17025221101954405,
        0.06021653898045596, -0.017578125,
    ],
    &[
        0.03709200011850479, 0.0, 0.0, 0.17038392571223998,
        0.10726203044637328, -0.015319437748624402, 0.008273789163814023,
    ],
    &[
        0.6241109587160757, 0.0, 0.0, -3.3608926294469414,
        -0.868219346841726, 27.59209969944671, 20.154067550477894, -43.48988418106996,
    ],
    &[
        0.47766253643826434, 0.0, 0.0, -2.4881146199716677,
        -0.590290826836843, 21.230051448181193, 15.279233632882423, -33.28821096898486,
        -0.020331201708508627,
    ],
    &[
        -0.9371424300859873, 0.0, 0.0, 5.186372428844064,
        1.0914373489967295, -8.149787010746927, -18.52006565999696, 22.739487099350505,
        2.4936055526796523, -3.0467644718982196,
    ],
    &[
        2.273310147516538, 0.0, 0.0, -10.53449546673725,
        -2.0008720582248625, -17.9589318631188, 27.94888452941996, -2.8589982771350235,
        -8.87285693353063, 12.360567175794303, 0.6433927460157636,
    ],
    &[
        0.054293734116568765, 0.0, 0.0, 0.0,
        0.0, 4.450312892752409, 1.8915178993145003, -5.801203960010585,
        0.3111643669578199, -0.1521609496625161, 0.20136540080403034, 0.04471061572777259,
    ],
    &[
        0.056167502283047954, 0.0, 0.0, 0.0,
        0.0, 0.0, 0.25350021021662483, -0.2462390374708025,
        -0.12419142326381637, 0.15329179827876568, 0.00820105229563469, 0.007567897660545699,
        -0.008298,
    ],
    &[
        0.03183464816350214, 0.0, 0.0, 0.0,
        0.0, 0.028300909672366776, 0.053541988307438566, -0.05492374857139099,
        0.0, 0.0, -0.00010834732869724932, 0.0003825710908356584,
        -0.00034046500868740456, 0.1413124436746325,
    ],
    &[
        -0.42889630158379194, 0.0, 0.0, 0.0,
        0.0, -4.697621415361164, 7.683421196062599, 4.06898981839711,
        0.3567271874552811, 0.0, 0.0, 0.0,
        -0.0013990241651590145, 2.9475147891527724, -9.15095847217987,
    ],
];

/// Weights of the 3rd-order error estimate over stages 1-13.
#[rustfmt::skip]
const E3: [f64; 13] = [
    -0.18980075407240762, 0.0, 0.0, 0.0,
    0.0, 4.450312892752409, 1.8915178993145003, -5.801203960010585,
    -0.4226823213237919, -0.1521609496625161, 0.20136540080403034, 0.02265179219836082,
    0.0,
];

/// Weights of the 5th-order error estimate over stages 1-13.
#[rustfmt::skip]
const E5: [f64; 13] = [
    0.01312004499419488, 0.0, 0.0, 0.0,
    0.0, -1.2251564463762044, -0.4957589496572502, 1.6643771824549864,
    -0.35032884874997366, 0.3341791187130175, 0.08192320648511571, -0.022355307863886294,
    0.0,
];

/// Weights of the dense output's coefficients 4-7 over the 16 stages.
#[rustfmt::skip]
const D: [[f64; 16]; 4] = [
    [
        -8.428938276109013, 0.0, 0.0, 0.0,
        0.0, 0.5667149535193777, -3.0689499459498917, 2.38466765651207,
        2.117034582445028, -0.871391583777973, 2.2404374302607883, 0.6315787787694688,
        -0.08899033645133331, 18.148505520854727, -9.194632392478356, -4.436036387594894,
    ],
    [
        10.427508642579134, 0.0, 0.0, 0.0,
        0.0, 242.28349177525817, 165.20045171727028, -374.5467547226902,
        -22.113666853125306, 7.733432668472264, -30.674084731089398, -9.332130526430229,
        15.697238121770845, -31.139403219565178, -9.35292435884448, 35.81684148639408,
    ],
    [
        19.985053242002433, 0.0, 0.0, 0.0,
        0.0, -387.0373087493518, -189.17813819516758, 527.8081592054236,
        -11.57390253995963, 6.8812326946963, -1.0006050966910838, 0.7777137798053443,
        -2.778205752353508, -60.19669523126412, 84.32040550667716, 11.99229113618279,
    ],
    [
        -25.69393346270375, 0.0, 0.0, 0.0,
        0.0, -154.18974869023643, -231.5293791760455, 357.6391179106141,
        93.40532418362432, -37.45832313645163, 104.0996495089623, 29.8402934266605,
        -43.53345659001114, 96.32455395918828, -39.17726167561544, -149.72683625798564,
    ],
];

/// Stage buffers, the step's result and its dense output, for states of one length.
#[derive(Debug, Clone, Default)]
pub struct Dopri {
    /// Stage derivatives k₁..k₁₆ (k₁₃ is the derivative at the step's end).
    k: [Vec<f64>; 16],
    stage: Vec<f64>,
    /// State at the end of the last step tried.
    pub y_new: Vec<f64>,
    /// The state at the start of the last accepted step.
    base: Vec<f64>,
    /// Dense output coefficients F₁..F₇ of the last accepted step.
    cont: [Vec<f64>; 7],
    /// Start and length of the last accepted step.
    t0: f64,
    h: f64,
    /// Whether the dense output of the last accepted step was built.
    dense_ready: bool,
}

impl Dopri {
    /// Sizes the buffers for states of length `n`.
    pub fn resize(&mut self, n: usize) {
        for v in self.k.iter_mut().chain(self.cont.iter_mut()).chain([
            &mut self.stage,
            &mut self.y_new,
            &mut self.base,
        ]) {
            v.clear();
            v.resize(n, 0.0);
        }
        self.dense_ready = false;
    }

    /// Sets the derivative at the start of the next step (call after a jump of the state).
    pub fn start(&mut self, f: &mut impl FnMut(f64, &[f64], &mut [f64]), t: f64, y: &[f64]) {
        let mut k1 = std::mem::take(&mut self.k[0]);
        f(t, y, &mut k1);
        self.k[0] = k1;
    }

    /// Evaluates stage `s` at (t + c_s h, y + h Σ_{j<s} a_sj k_j).
    fn stage(
        &mut self,
        f: &mut impl FnMut(f64, &[f64], &mut [f64]),
        s: usize,
        t: f64,
        y: &[f64],
        h: f64,
    ) {
        combine(&mut self.stage, y, h, A[s], &self.k);
        let mut k = std::mem::take(&mut self.k[s]);
        f(t + C[s] * h, &self.stage, &mut k);
        self.k[s] = k;
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
        for s in 1..12 {
            self.stage(f, s, t, y, h);
        }
        combine(&mut self.y_new, y, h, A[12], &self.k);
        let mut k13 = std::mem::take(&mut self.k[12]);
        f(t + h, &self.y_new, &mut k13);
        self.k[12] = k13;
        let (mut err5, mut err3) = (0.0, 0.0);
        for (j, k) in self.k[..13].iter().enumerate() {
            err5 += E5[j] * k[0];
            err3 += E3[j] * k[0];
        }
        // Scaled by the larger of the two, so that tiny estimates do not underflow to 0/0.
        let scale = err5.abs().max(err3.abs());
        if scale == 0.0 || !scale.is_finite() {
            return if scale == 0.0 { 0.0 } else { f64::NAN };
        }
        let (e5, e3) = ((err5 / scale).powi(2), (err3 / scale).powi(2));
        (h * scale * e5 / (e5 + 0.01 * e3).sqrt()).abs()
    }

    /// Accepts the last step tried from (t, y): builds its dense output when `dense` (three
    /// more evaluations of f), and its end rate becomes the next step's start rate. The
    /// caller then copies [`Self::y_new`] into y.
    pub fn accept(
        &mut self,
        f: &mut impl FnMut(f64, &[f64], &mut [f64]),
        t: f64,
        y: &[f64],
        h: f64,
        dense: bool,
    ) {
        self.t0 = t;
        self.h = h;
        self.dense_ready = dense;
        if dense {
            for s in 13..16 {
                self.stage(f, s, t, y, h);
            }
            self.base.copy_from_slice(y);
            for i in 0..y.len() {
                let delta = self.y_new[i] - y[i];
                self.cont[0][i] = delta;
                self.cont[1][i] = h * self.k[0][i] - delta;
                self.cont[2][i] = 2.0 * delta - h * (self.k[12][i] + self.k[0][i]);
            }
            for (r, d) in D.iter().enumerate() {
                let out = &mut self.cont[3 + r];
                out.iter_mut().for_each(|x| *x = 0.0);
                for (dj, k) in d.iter().zip(&self.k) {
                    if *dj != 0.0 {
                        let scale = h * dj;
                        out.iter_mut().zip(k).for_each(|(o, kj)| *o += scale * kj);
                    }
                }
            }
        }
        self.k.swap(0, 12);
    }

    /// Component i of the dense output of the last accepted step at τ (built by
    /// [`Self::accept`] with `dense`).
    pub fn dense(&self, i: usize, tau: f64) -> f64 {
        debug_assert!(
            self.dense_ready,
            "dense output of a step accepted without it"
        );
        let x = (tau - self.t0) / self.h;
        let x1 = 1.0 - x;
        let c = &self.cont;
        let inner = c[4][i] + x1 * (c[5][i] + x * c[6][i]);
        self.base[i] + x * (c[0][i] + x1 * (c[1][i] + x * (c[2][i] + x1 * (c[3][i] + x * inner))))
    }

    /// The whole dense output of the last accepted step at τ into `out`.
    pub fn dense_all(&self, tau: f64, out: &mut [f64]) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.dense(i, tau);
        }
    }
}

/// out = y + h Σ_j a_j k_j over the nonzero a_j (one pass per stage, so the loops run along
/// the state).
fn combine(out: &mut [f64], y: &[f64], h: f64, a: &[f64], k: &[Vec<f64>; 16]) {
    out.copy_from_slice(y);
    for (aj, kj) in a.iter().zip(k) {
        if *aj != 0.0 {
            let scale = h * aj;
            out.iter_mut().zip(kj).for_each(|(o, x)| *o += scale * x);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y′ = −y·cos t + sin 3t over [0, 4] against a fine reference: eighth order in the step,
    /// the dense output agrees with the steps, and the error estimate is of the step's error.
    #[test]
    fn steps_and_dense_output_are_accurate() {
        let f = |t: f64, y: &[f64], dy: &mut [f64]| dy[0] = -y[0] * t.cos() + (3.0 * t).sin();
        // The end value, the dense output at τ = 2.025 (inside a step) and the largest error
        // estimate with n steps.
        let run = |n: usize| {
            let mut d = Dopri::default();
            d.resize(1);
            let mut g = f;
            let mut y = vec![1.0];
            let h = 4.0 / n as f64;
            let query = 2.025;
            d.start(&mut g, 0.0, &y);
            let mut at_query = f64::NAN;
            let mut largest_estimate: f64 = 0.0;
            for s in 0..n {
                let t = s as f64 * h;
                largest_estimate = largest_estimate.max(d.try_step(&mut g, t, &y, h));
                let inside = t <= query && query < t + h;
                d.accept(&mut g, t, &y, h, inside);
                if inside {
                    at_query = d.dense(0, query);
                }
                y.copy_from_slice(&d.y_new);
            }
            (y[0], at_query, largest_estimate)
        };
        let (reference, query_reference, _) = run(4000);
        let (coarse, _, coarse_estimate) = run(20);
        let (fine, query_fine, _) = run(40);
        let ratio = (coarse - reference).abs() / (fine - reference).abs();
        assert!(ratio > 120.0, "order: error ratio {ratio}");
        assert!(
            (query_fine - query_reference).abs() < 1e-9,
            "{query_fine} vs {query_reference}"
        );
        // The estimate is of the size of a step's error (20 steps make the end's error).
        let end_error = (coarse - reference).abs();
        assert!(
            coarse_estimate > 0.01 * end_error / 20.0 && coarse_estimate < 100.0 * end_error,
            "estimate {coarse_estimate:e} against the end's error {end_error:e}"
        );
    }
}
