//! The corner of the stuck set that a creeping march of the event-resolved 2D law converges
//! to, found directly.
//!
//! The stuck set S is the set of slider positions w for which the spring force stays within
//! the friction circle all period: the intersection of the discs D(τ) of centre u(τ) and
//! radius r(τ) = L(τ)/kₜ. A period started outside S slips where g(τ) = |u(τ) − w| − r(τ)
//! rises through 0, and each slip pulls the slider back onto the disc of its end (the slip
//! ends where g has a local maximum 0). Where two discs D(τ₁), D(τ₂) are active, the march
//! alternates between them like alternating projections onto two convex sets: when their
//! boundaries meet at an acute corner c of S (the normals n₁, n₂ of the two circles at c more
//! than 90° apart, as at the onset of slip of a nearly straight path), a slider in the corner's
//! normal cone {c + α n₁ + β n₂ : α, β > 0} stays in it and converges to c, but only
//! geometrically with the ratio cos²φ (φ the corner's angle), and like n^(−1/2) where the two
//! circles are tangent (the seam where the stuck set shrinks to a point). A march into such a
//! corner never meets a per-period drift tolerance: c is found here instead from its grazing
//! conditions
//!
//! g(τᵢ, c) = 0,  ∂g/∂τ(τᵢ, c) = 0  (i = 1, 2),
//!
//! by alternating the two circles' intersection (given τ₁, τ₂) with the refinement of the
//! maxima of g (given c) until c no longer moves; the maxima are stationary in τ, so c is
//! first-order insensitive to the times and the alternation converges quadratically. The
//! corner is accepted when the rest of the period stays inside the friction circle there and
//! the march's slider lies in its normal cone (then the plain march from it converges to c).
//!
//! Its derivative follows from the implicit function theorem on the grazing conditions; the
//! times' terms drop out (∂g/∂τ = 0 at both), leaving eᵢ·dc = eᵢ·du(τᵢ) − dr(τᵢ) with
//! eᵢ = (u(τᵢ) − c)/rᵢ: a 2 × 2 system whose determinant e₁ × e₂ = sin φ vanishes at the seam
//! (where the state itself has a square-root kink).

use crate::contact::events::roots::brent;
use crate::contact::events2d::march::PeriodMarch;
use std::f64::consts::PI;

/// Most alternations of the circles' intersection and the maxima's refinement.
const CORNER_ITERATIONS: usize = 16;

/// A corner of the stuck set with its two grazing times.
#[derive(Debug, Clone, Copy)]
pub(super) struct Corner {
    /// The slider position c (m).
    pub w: [f64; 2],
    /// The grazing times τ₁, τ₂ (rad).
    pub times: [f64; 2],
    /// The unit vectors eᵢ = (u(τᵢ) − c)/rᵢ (the spring's direction at each grazing).
    pub directions: [[f64; 2]; 2],
}

/// g(τ) = |u(τ) − w| − r(τ) and its first two τ-derivatives (m, m/rad, m/rad²).
fn exceedance(march: &PeriodMarch<'_>, tau: f64, w: [f64; 2]) -> [f64; 3] {
    let k = march.path.at(tau);
    let l = march.law.limit(&k);
    let kt = march.law.kt;
    let d = [k.u[0][0] - w[0], k.u[1][0] - w[1]];
    let rho = d[0].hypot(d[1]);
    let du = [k.u[0][1], k.u[1][1]];
    let ddu = [k.u[0][2], k.u[1][2]];
    if rho == 0.0 {
        return [-l[0] / kt, -l[1] / kt, -l[2] / kt];
    }
    let e = [d[0] / rho, d[1] / rho];
    let along = e[0] * du[0] + e[1] * du[1];
    let speed2 = du[0] * du[0] + du[1] * du[1];
    [
        rho - l[0] / kt,
        along - l[1] / kt,
        (speed2 - along * along) / rho + e[0] * ddu[0] + e[1] * ddu[1] - l[2] / kt,
    ]
}

/// The local maximum of g(·, w) bracketed by [a, b] (where ∂g/∂τ falls through 0), or the
/// better end when the rate does not change sign.
fn maximum(march: &PeriodMarch<'_>, w: [f64; 2], a: f64, b: f64) -> f64 {
    let ga = exceedance(march, a, w);
    let gb = exceedance(march, b, w);
    if ga[1] > 0.0 && gb[1] < 0.0 {
        brent(|t| exceedance(march, t, w)[1], a, b, ga[1], gb[1])
    } else if ga[0] >= gb[0] {
        a
    } else {
        b
    }
}

/// The intersection of the circles |c − pᵢ| = rᵢ nearer to `near`, if they meet.
fn intersection(p: [[f64; 2]; 2], r: [f64; 2], near: [f64; 2]) -> Option<[f64; 2]> {
    let d = [p[1][0] - p[0][0], p[1][1] - p[0][1]];
    let dist = d[0].hypot(d[1]);
    if !(dist.is_finite() && dist > 0.0) {
        return None;
    }
    let a = (r[0] * r[0] - r[1] * r[1] + dist * dist) / (2.0 * dist);
    let h2 = r[0] * r[0] - a * a;
    if h2 < 0.0 {
        return None;
    }
    let h = h2.sqrt();
    let (ex, ey) = (d[0] / dist, d[1] / dist);
    let base = [p[0][0] + a * ex, p[0][1] + a * ey];
    let candidates = [
        [base[0] - h * ey, base[1] + h * ex],
        [base[0] + h * ey, base[1] - h * ex],
    ];
    let distance = |c: [f64; 2]| (c[0] - near[0]).hypot(c[1] - near[1]);
    Some(if distance(candidates[0]) <= distance(candidates[1]) {
        candidates[0]
    } else {
        candidates[1]
    })
}

/// The corner of the stuck set that the march's slider `w` (at the start of a period that
/// slipped, without lift-off) converges to, when it creeps into one (module doc); `scale`
/// is the point's motion scale (m).
pub(super) fn creeping_corner(march: &PeriodMarch<'_>, w: [f64; 2], scale: f64) -> Option<Corner> {
    let n = march.n_samples;
    let cell = 2.0 * PI / n as f64;
    // Closed all period (no lift-off, whose resets have no corner).
    if (0..n).any(|k| march.law.limit(&march.path.at(k as f64 * cell))[0] <= 0.0) {
        return None;
    }
    let g: Vec<f64> = (0..n)
        .map(|k| exceedance(march, k as f64 * cell, w)[0])
        .collect();
    // The active times: the local maxima of g, bracketed on the grid and refined (a grazing
    // peak lies between samples: at 128 samples a period of the first harmonic puts the
    // samples next to it up to g″ cell²/8 below it, far more than the excess of a creeping
    // slip), above −`inside` (one may have just been met, to rounding): exactly two, one of
    // them above 0.
    let inside = 1e-9 * scale;
    let mut times = [0.0; 2];
    let mut count = 0;
    let mut exceeds = false;
    for k in 0..n {
        let (before, after) = (g[(k + n - 1) % n], g[(k + 1) % n]);
        if g[k] >= before && g[k] > after {
            let t = maximum(march, w, (k as f64 - 1.0) * cell, (k as f64 + 1.0) * cell);
            let peak = exceedance(march, t, w)[0];
            if peak > -inside {
                if count == 2 {
                    return None;
                }
                times[count] = t;
                count += 1;
                exceeds |= peak > 0.0;
            }
        }
    }
    if count != 2 || !exceeds {
        return None;
    }
    let mut c = w;
    let round_off = 16.0 * f64::EPSILON * (scale + w[0].hypot(w[1]));
    let mut moved = f64::INFINITY;
    let mut sine = 1.0_f64;
    for _ in 0..CORNER_ITERATIONS {
        for t in &mut times {
            *t = maximum(march, c, *t - cell, *t + cell);
        }
        let kin = times.map(|t| march.path.at(t));
        let centres = kin.map(|k| [k.u[0][0], k.u[1][0]]);
        let radii = kin.map(|k| march.law.limit(&k)[0] / march.law.kt);
        let next = intersection(centres, radii, c)?;
        moved = (next[0] - c[0]).hypot(next[1] - c[1]);
        c = next;
        // Rounding of the radii moves c by up to 1/sin φ times itself (φ the angle between
        // the circles at c).
        let e = [0, 1].map(|i| [centres[i][0] - c[0], centres[i][1] - c[1]]);
        sine = ((e[0][0] * e[1][1] - e[0][1] * e[1][0]) / (radii[0] * radii[1])).abs();
        if moved <= round_off / sine.max(1e-8) {
            break;
        }
    }
    if moved.is_nan() || moved > round_off / sine.max(1e-8) {
        return None;
    }
    // Inside the friction circle the rest of the period (to rounding of the motion scale).
    let near = |k: usize| {
        times.iter().any(|&t| {
            let d = (k as f64 * cell - t).rem_euclid(2.0 * PI);
            d.min(2.0 * PI - d) <= 1.5 * cell
        })
    };
    if (0..n).any(|k| !near(k) && exceedance(march, k as f64 * cell, c)[0] > inside) {
        return None;
    }
    let directions = times.map(|t| {
        let k = march.path.at(t);
        let d = [k.u[0][0] - c[0], k.u[1][0] - c[1]];
        let r = d[0].hypot(d[1]);
        [d[0] / r, d[1] / r]
    });
    // The slider in the normal cone: w − c = α n₁ + β n₂ with nᵢ = −eᵢ, α, β > 0.
    let n1 = directions[0].map(|x| -x);
    let n2 = directions[1].map(|x| -x);
    let det = n1[0] * n2[1] - n1[1] * n2[0];
    let o = [w[0] - c[0], w[1] - c[1]];
    let alpha = (o[0] * n2[1] - o[1] * n2[0]) / det;
    let beta = (n1[0] * o[1] - n1[1] * o[0]) / det;
    if !(alpha > 0.0 && beta > 0.0) {
        return None;
    }
    Some(Corner {
        w: c,
        times,
        directions,
    })
}

/// The corner's derivative with respect to the coefficients (û₁, û₂, v̂), 2 × 3 n_blocks
/// row-major, from eᵢ·dc = eᵢ·du(τᵢ) − dr(τᵢ) (module doc); `None` at the seam (e₁ ∥ e₂).
pub(super) fn corner_derivative(march: &PeriodMarch<'_>, corner: &Corner) -> Option<Vec<f64>> {
    let columns = march.columns;
    let c = columns.count;
    let nb = columns.nb;
    let (mut b, mut db) = (vec![0.0; nb], vec![0.0; nb]);
    let constant = march.law.constant_limit.is_some();
    let mut rows = vec![0.0; 2 * c];
    for (i, (&t, e)) in corner.times.iter().zip(&corner.directions).enumerate() {
        march.path.basis(t, &mut b, &mut db);
        let row = &mut rows[i * c..(i + 1) * c];
        columns.add_du(0, e[0], &b, row);
        columns.add_du(1, e[1], &b, row);
        columns.add_dv(-march.law.mu_kn / march.law.kt, &b, constant, row);
    }
    let e = corner.directions;
    let det = e[0][0] * e[1][1] - e[0][1] * e[1][0];
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = [e[1][1] / det, -e[0][1] / det, -e[1][0] / det, e[0][0] / det];
    let x = c - 2;
    let mut out = vec![0.0; 2 * x];
    for i in 0..x {
        let (r0, r1) = (rows[2 + i], rows[c + 2 + i]);
        out[i] = inv[0] * r0 + inv[1] * r1;
        out[x + i] = inv[2] * r0 + inv[3] * r1;
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::super::fixtures::{law, KN, KT, MU};
    use super::super::workspace::Aft2dWorkspace;
    use crate::contact::events2d::march::{Buffers, PeriodMarch};
    use crate::contact::events2d::{Columns, Law2, Path2};
    use crate::contact::harmonic::HarmonicSet;
    use crate::contact::{ContactEffects, ContactState, NormalLoad};

    /// The mean normal displacement (m).
    const V0: f64 = 1e-4;

    /// The friction limit's radius r = μkₙv₀/kₜ (m).
    fn radius() -> f64 {
        MU * KN * V0 / KT
    }

    fn effects(load: NormalLoad) -> ContactEffects {
        ContactEffects {
            normal_load: load,
            liftoff: false,
        }
    }

    /// A straight path a cos τ along (cos ψ, sin ψ) with a = (1 − δ) r, over harmonics 0 and 1,
    /// and its stuck set's corners ±h e⊥, h = √(r² − a²) (the lens between the discs at ±a).
    struct Lens {
        u: [Vec<f64>; 2],
        v: Vec<f64>,
        along: [f64; 2],
        across: [f64; 2],
        a: f64,
        h: f64,
    }

    fn lens(delta: f64, psi: f64) -> Lens {
        let r = radius();
        let a = (1.0 - delta) * r;
        let (s, c) = psi.sin_cos();
        Lens {
            u: [vec![0.0, c * a, 0.0], vec![0.0, s * a, 0.0]],
            v: vec![V0, 0.0, 0.0],
            along: [c, s],
            across: [-s, c],
            a,
            h: (r * r - a * a).sqrt(),
        }
    }

    /// The initial state m = cos β e + sin β e⊥ in the lens's frame, as a vector.
    fn state(l: &Lens, beta: f64) -> [f64; 2] {
        let (s, c) = beta.sin_cos();
        [
            c * l.along[0] + s * l.across[0],
            c * l.along[1] + s * l.across[1],
        ]
    }

    /// The slider after `periods` plain periods of the event march from T(0) = μN(0) m.
    fn plain_march(l: &Lens, m: [f64; 2], periods: usize) -> [f64; 2] {
        let set = HarmonicSet::up_to(1);
        let blocks = set.blocks().to_vec();
        let march = PeriodMarch {
            path: Path2 {
                blocks: &blocks,
                u: [&l.u[0], &l.u[1]],
                v: &l.v,
            },
            law: Law2 {
                kt: KT,
                mu_kn: MU * KN,
                constant_limit: None,
            },
            columns: Columns {
                count: 2,
                nb: blocks.len(),
                constant: Some(0),
            },
            n_samples: 128,
            limit_scale: MU * KN * V0,
        };
        let mut buffers = Buffers::default();
        buffers.resize(&march.columns);
        let r = radius();
        let mut w = [l.a * l.along[0] - r * m[0], l.a * l.along[1] - r * m[1]];
        for _ in 0..periods {
            buffers.dw.copy_from_slice(&[1.0, 0.0, 0.0, 1.0]);
            w = march.run(&mut buffers, w, None).unwrap().w;
        }
        w
    }

    /// Evaluates the event law, checks its forces against the stuck period from the slider
    /// `expected` (T = kₜ(u − w)) and returns the largest central-difference mismatch of the
    /// Jacobian relative to its largest entry (steps of 10⁻⁶ of the stick range, or 10⁻³ of
    /// the distance δr to the seam where the lens closes when smaller). Measured 1e-9 to
    /// 1.3e-6 (δ = 10⁻⁵, where an evaluation next to the corner may still end on a fixed
    /// point within the periodicity tolerance of it); checked, as the fixtures' other
    /// Jacobian checks are, to 1e-5.
    fn check(
        l: &Lens,
        m: [f64; 2],
        load: NormalLoad,
        expected: [f64; 2],
        delta: f64,
        what: &str,
    ) -> f64 {
        let set = HarmonicSet::up_to(1);
        let nb = set.n_blocks();
        let mut aft = Aft2dWorkspace::new(&set, 128);
        let x = [l.u[0].clone(), l.u[1].clone(), l.v.clone()];
        let report = aft
            .evaluate_events(&law(m), effects(load), [&x[0], &x[1]], &x[2], true)
            .unwrap();
        let friction = MU * KN * V0;
        let mut error = 0.0_f64;
        for a in 0..2 {
            error = error.max((aft.t_hat[a][0] + KT * expected[a]).abs());
            error = error.max((aft.t_hat[a][1] - KT * l.a * l.along[a]).abs());
            error = error.max(aft.t_hat[a][2].abs());
        }
        println!(
            "{what}: {:?} in {} periods, slider {:?} (expected {:?}), force error {:.2e} of μN",
            report.state,
            report.periods,
            aft.slider_start,
            expected,
            error / friction
        );
        assert!(
            matches!(report.state, ContactState::Stuck | ContactState::StickSlip),
            "{what}: {report:?}"
        );
        assert!(error < 1e-11 * friction, "{what}: {:.2e}", error / friction);
        let analytic = aft.dt_dx.clone();
        let step = (1e-6 * radius()).min(1e-3 * delta * radius());
        let (mut worst, mut largest) = (0.0_f64, 0.0_f64);
        for col in 0..3 * nb {
            let (which, j) = (col / nb, col % nb);
            let mut ends = [
                [vec![0.0; nb], vec![0.0; nb]],
                [vec![0.0; nb], vec![0.0; nb]],
            ];
            for (side, sign) in [1.0, -1.0].into_iter().enumerate() {
                let mut p = x.clone();
                p[which][j] += sign * step;
                aft.evaluate_events(&law(m), effects(load), [&p[0], &p[1]], &p[2], false)
                    .unwrap();
                ends[side] = aft.t_hat.clone();
            }
            for row in 0..2 * nb {
                let (a, i) = (row / nb, row % nb);
                let difference = (ends[0][a][i] - ends[1][a][i]) / (2.0 * step);
                let entry = analytic[row * 3 * nb + col];
                worst = worst.max((entry - difference).abs());
                largest = largest.max(entry.abs());
            }
        }
        worst / largest
    }

    /// A slider started far across a nearly straight path creeps into the corner of the thin
    /// stuck set (the plain march by cos²φ per period, φ the corner's angle, 1 − 8·10⁻⁵ at
    /// δ = 10⁻⁵): the corner is found directly, its forces are the stuck period's from it, a
    /// long plain march lands there, and the Jacobian matches central differences.
    #[test]
    fn a_march_creeping_into_a_corner_of_the_stuck_set_rests_there() {
        for load in [NormalLoad::Variable, NormalLoad::Constant] {
            for (delta, psi) in [(1e-2, 0.3), (1e-4, -1.1), (1e-5, 2.0)] {
                let l = lens(delta, psi);
                let m = state(&l, -1.2);
                let corner = [l.h * l.across[0], l.h * l.across[1]];
                let what = format!("{load:?} δ = {delta:e}");
                let mismatch = check(&l, m, load, corner, delta, &what);
                println!("{what}: Jacobian mismatch {mismatch:.2e}");
                assert!(mismatch < 1e-5, "{what}: {mismatch:.2e}");
            }
        }
        // The plain march's own limit (cos²φ = 0.92 per period at δ = 10⁻²), to its own
        // rounding amplified by 1/(1 − cos²φ) (measured 7.5e-12 of the stick range).
        let l = lens(1e-2, 0.3);
        let w = plain_march(&l, state(&l, -1.2), 600);
        let corner = [l.h * l.across[0], l.h * l.across[1]];
        let gap = (w[0] - corner[0]).hypot(w[1] - corner[1]);
        println!("plain march after 600 periods: {gap:.2e} m from the corner");
        assert!(gap < 1e-10 * radius(), "{gap:.2e}");
    }

    /// A contact stuck all period with the initial state m at the angle β from the path
    /// (T(0) = μN(0) m) starts to slip at β* = acos(a/r), where its initial slider is the
    /// stuck set's corner; past it the march creeps back into that corner. On either side of
    /// the seam the state and the Jacobian are right.
    #[test]
    fn a_contact_stuck_with_its_initial_state_that_just_starts_to_slip() {
        for load in [NormalLoad::Variable, NormalLoad::Constant] {
            for delta in [1e-3, 1e-5] {
                let l = lens(delta, 0.4);
                let seam = (l.a / radius()).acos();
                for side in [-1.0, 1.0] {
                    let beta = seam * (1.0 + side * 0.1);
                    let m = state(&l, beta);
                    let expected = if side > 0.0 {
                        [-l.h * l.across[0], -l.h * l.across[1]]
                    } else {
                        let r = radius();
                        [l.a * l.along[0] - r * m[0], l.a * l.along[1] - r * m[1]]
                    };
                    let what = format!("{load:?} δ = {delta:e}, β = {:.4} β*", beta / seam);
                    let mismatch = check(&l, m, load, expected, delta, &what);
                    println!("{what}: Jacobian mismatch {mismatch:.2e}");
                    assert!(mismatch < 1e-5, "{what}: {mismatch:.2e}");
                }
            }
        }
    }
}
