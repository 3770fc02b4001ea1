//! Minimisation of a smooth (or piecewise smooth) function of a few variables over a box
//! l ≤ x ≤ u, where an evaluation may fail: a projected quasi-Newton method (BFGS on the free
//! variables, Armijo backtracking along the projected path).
//!
//! Why hand-written: the well-kept Rust optimisation crate (`argmin`) has L-BFGS without bounds
//! (its L-BFGS-B was proposed but not merged), and none lets an evaluation fail, which ours do
//! (each is a Newton solve that may not converge). The problems here have a handful of
//! variables (one per damper side or contact point), so a dense inverse-Hessian estimate is
//! cheap and the method stays short.
//!
//! # Method
//!
//! At x with gradient g, a variable is *active* when it sits on a bound and g pushes it
//! outward (x_i = l_i, g_i > 0 or x_i = u_i, g_i < 0). The projected gradient is g with the
//! active entries zeroed; its ∞-norm below `gradient_tolerance` ends the search (first-order
//! optimality in the box). The step direction on the free variables is −H g (H the BFGS
//! estimate of the inverse Hessian, restricted to the free variables), 0 on the active ones;
//! when it is not a descent direction H is reset and the projected steepest descent is used.
//! The step x(α) = P(x + α d) (P the projection onto the box) is accepted when
//! f(x(α)) ≤ f(x) + c₁ gᵀ(x(α) − x) (Armijo); α is halved otherwise, or when the evaluation
//! fails. H is updated with the step and gradient change when their product is positive.
//! An evaluation may also say that f at x equals f at another point (f is flat beyond a range
//! of a variable that is not known in advance, as the response is in the initial state of a
//! friction contact beyond the range where the contact stays stuck); the search then moves to
//! that point and takes the range's edge as the variable's bound from then on.

/// Limits of [`minimise_in_box`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoxSettings {
    /// Most iterations (accepted steps).
    pub max_iterations: usize,
    /// Most function evaluations, including failed ones.
    pub max_evaluations: usize,
    /// ∞-norm of the projected gradient at which the search ends.
    pub gradient_tolerance: f64,
    /// ∞-norm of a step below which the search ends.
    pub step_tolerance: f64,
    /// Largest ∞-norm of a trial step (α = 1 is shortened to it).
    pub max_step: f64,
}

impl Default for BoxSettings {
    fn default() -> Self {
        Self {
            max_iterations: 40,
            max_evaluations: 120,
            gradient_tolerance: 1e-8,
            step_tolerance: 1e-7,
            max_step: 1.0,
        }
    }
}

/// Why a search ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum BoxStop {
    /// Projected gradient below its tolerance.
    Gradient,
    /// No step longer than the step tolerance decreases f (a kink, or a failed line search).
    Step,
    /// Iteration or evaluation budget used up.
    Budget,
    /// The starting point could not be evaluated.
    StartFailed,
}

/// The outcome of [`minimise_in_box`].
#[derive(Debug, Clone, PartialEq)]
pub struct BoxMinimum {
    /// Best point found (inside the box).
    pub x: Vec<f64>,
    /// f there (NaN when the start failed).
    pub value: f64,
    /// Projected gradient there.
    pub projected_gradient: Vec<f64>,
    /// Accepted steps.
    pub iterations: usize,
    /// Function evaluations, failed ones included.
    pub evaluations: usize,
    /// Why the search ended.
    pub stop: BoxStop,
}

/// The projection of `x` onto the box [lower, upper].
pub fn project(x: &[f64], lower: &[f64], upper: &[f64]) -> Vec<f64> {
    x.iter()
        .zip(lower.iter().zip(upper))
        .map(|(&v, (&l, &u))| v.clamp(l, u))
        .collect()
}

/// g with the entries of variables held on a bound (x on a bound, g pointing outward) zeroed.
pub fn projected_gradient(x: &[f64], g: &[f64], lower: &[f64], upper: &[f64]) -> Vec<f64> {
    (0..x.len())
        .map(|i| {
            let at_lower = x[i] <= lower[i] && g[i] > 0.0;
            let at_upper = x[i] >= upper[i] && g[i] < 0.0;
            if at_lower || at_upper {
                0.0
            } else {
                g[i]
            }
        })
        .collect()
}

/// Minimises f over the box [lower, upper] from `start` (projected into the box first).
/// `f(x)` returns the value, the gradient and the point it stands for, or `None` where it
/// cannot be evaluated. The point is `x` itself, or another point of the box where f is known
/// to take the same value with the gradient given (f constant along the move): the search then
/// continues from there. This serves functions that depend on x only through a clamp to a
/// range not known in advance (the initial state of a friction contact acts only within the
/// range where the contact stays stuck): the evaluation moves x onto that range, where the
/// gradient is the one-sided derivative into it. Never fails: the best point evaluated and why
/// the search stopped are returned.
///
/// # Panics
/// If `start`, `lower` and `upper` differ in length or some lower bound exceeds its upper.
#[track_caller]
pub fn minimise_in_box(
    start: &[f64],
    lower: &[f64],
    upper: &[f64],
    settings: &BoxSettings,
    mut f: impl FnMut(&[f64]) -> Option<(f64, Vec<f64>, Vec<f64>)>,
) -> BoxMinimum {
    let k = start.len();
    assert!(
        lower.len() == k && upper.len() == k,
        "box and start differ in length"
    );
    assert!(
        lower.iter().zip(upper).all(|(l, u)| l <= u),
        "lower bound above upper bound"
    );
    let mut evaluations = 1usize;
    // The box, narrowed where an evaluation moved a variable back from beyond a range.
    let (mut lower, mut upper) = (lower.to_vec(), upper.to_vec());
    let narrow = |asked: &[f64], moved: &[f64], lower: &mut [f64], upper: &mut [f64]| {
        for i in 0..asked.len() {
            if moved[i] < asked[i] - 1e-12 {
                upper[i] = upper[i].min(moved[i]).max(lower[i]);
            } else if moved[i] > asked[i] + 1e-12 {
                lower[i] = lower[i].max(moved[i]).min(upper[i]);
            }
        }
    };
    let mut x = project(start, &lower, &upper);
    let Some((mut fx, mut g, moved)) = f(&x) else {
        return BoxMinimum {
            projected_gradient: vec![f64::NAN; k],
            x,
            value: f64::NAN,
            iterations: 0,
            evaluations,
            stop: BoxStop::StartFailed,
        };
    };
    narrow(&x, &moved, &mut lower, &mut upper);
    x = project(&moved, &lower, &upper);
    let identity = |k: usize| -> Vec<f64> {
        (0..k * k)
            .map(|i| if i % (k + 1) == 0 { 1.0 } else { 0.0 })
            .collect()
    };
    let mut h = identity(k);
    let mut iterations = 0usize;
    let stop = loop {
        let pg = projected_gradient(&x, &g, &lower, &upper);
        if pg.iter().all(|v| v.abs() <= settings.gradient_tolerance) {
            break BoxStop::Gradient;
        }
        if iterations >= settings.max_iterations || evaluations >= settings.max_evaluations {
            break BoxStop::Budget;
        }
        let free: Vec<bool> = pg.iter().map(|v| *v != 0.0).collect();
        let mut accepted = None;
        // Quasi-Newton direction first, the projected steepest descent if it fails.
        for attempt in 0..2 {
            if attempt == 1 {
                h = identity(k);
            }
            let mut d: Vec<f64> = (0..k)
                .map(|i| {
                    if !free[i] {
                        return 0.0;
                    }
                    -(0..k)
                        .filter(|&j| free[j])
                        .map(|j| h[i * k + j] * g[j])
                        .sum::<f64>()
                })
                .collect();
            let slope: f64 = d.iter().zip(&g).map(|(a, b)| a * b).sum();
            if slope.is_nan() || slope >= 0.0 {
                if attempt == 0 {
                    continue;
                }
                d = pg.iter().map(|v| -v).collect();
            }
            let longest = d.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
            let mut alpha = if longest > settings.max_step {
                settings.max_step / longest
            } else {
                1.0
            };
            while evaluations < settings.max_evaluations {
                let asked: Vec<f64> = project(
                    &x.iter()
                        .zip(&d)
                        .map(|(a, b)| a + alpha * b)
                        .collect::<Vec<_>>(),
                    &lower,
                    &upper,
                );
                let asked_norm = asked
                    .iter()
                    .zip(&x)
                    .fold(0.0_f64, |a, (p, q)| a.max((p - q).abs()));
                if asked_norm < settings.step_tolerance {
                    break;
                }
                evaluations += 1;
                if let Some((ft, gt, moved)) = f(&asked) {
                    narrow(&asked, &moved, &mut lower, &mut upper);
                    let trial = project(&moved, &lower, &upper);
                    let step: Vec<f64> = trial.iter().zip(&x).map(|(a, b)| a - b).collect();
                    let decrease: f64 = step.iter().zip(&g).map(|(a, b)| a * b).sum();
                    if ft <= fx + 1e-4 * decrease && ft < fx {
                        accepted = Some((trial, ft, gt, step));
                        break;
                    }
                }
                alpha *= 0.5;
            }
            if accepted.is_some() {
                break;
            }
        }
        let Some((trial, ft, gt, s)) = accepted else {
            break if evaluations >= settings.max_evaluations {
                BoxStop::Budget
            } else {
                BoxStop::Step
            };
        };
        // BFGS update of the inverse Hessian with the step s and gradient change y.
        let y: Vec<f64> = gt.iter().zip(&g).map(|(a, b)| a - b).collect();
        let sy: f64 = s.iter().zip(&y).map(|(a, b)| a * b).sum();
        let (ns, ny) = (
            s.iter().map(|v| v * v).sum::<f64>().sqrt(),
            y.iter().map(|v| v * v).sum::<f64>().sqrt(),
        );
        if sy > 1e-10 * ns * ny {
            if iterations == 0 {
                // Scale the first estimate to the curvature seen (Nocedal & Wright, Eq. 6.20).
                let scale = sy / (ny * ny);
                h.iter_mut().for_each(|v| *v *= scale);
            }
            let rho = 1.0 / sy;
            let hy: Vec<f64> = (0..k)
                .map(|i| (0..k).map(|j| h[i * k + j] * y[j]).sum())
                .collect();
            let yhy: f64 = y.iter().zip(&hy).map(|(a, b)| a * b).sum();
            for i in 0..k {
                for j in 0..k {
                    h[i * k + j] += -rho * (hy[i] * s[j] + s[i] * hy[j])
                        + (rho * rho * yhy + rho) * s[i] * s[j];
                }
            }
        }
        x = trial;
        fx = ft;
        g = gt;
        iterations += 1;
    };
    BoxMinimum {
        projected_gradient: projected_gradient(&x, &g, &lower, &upper),
        x,
        value: fx,
        iterations,
        evaluations,
        stop,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rosenbrock(x: &[f64]) -> Option<(f64, Vec<f64>, Vec<f64>)> {
        let (a, b) = (x[0], x[1]);
        Some((
            (1.0 - a).powi(2) + 100.0 * (b - a * a).powi(2),
            vec![
                -2.0 * (1.0 - a) - 400.0 * a * (b - a * a),
                200.0 * (b - a * a),
            ],
            x.to_vec(),
        ))
    }

    #[test]
    fn finds_the_interior_minimum_of_rosenbrock() {
        let settings = BoxSettings {
            max_iterations: 200,
            max_evaluations: 2000,
            ..BoxSettings::default()
        };
        let m = minimise_in_box(
            &[-1.0, 1.0],
            &[-2.0, -2.0],
            &[2.0, 2.0],
            &settings,
            rosenbrock,
        );
        assert!(
            (m.x[0] - 1.0).abs() < 1e-5 && (m.x[1] - 1.0).abs() < 1e-5,
            "{m:?}"
        );
    }

    #[test]
    fn stops_on_the_bound_where_the_minimum_lies_outside() {
        // Minimum of the unconstrained problem at (1, 1); with b ≤ 0.5 the constrained minimum
        // lies on b = 0.5 at the minimiser of (1 − a)² + 100 (0.5 − a²)².
        let m = minimise_in_box(
            &[0.0, 0.0],
            &[-2.0, -2.0],
            &[2.0, 0.5],
            &BoxSettings {
                max_iterations: 200,
                max_evaluations: 2000,
                ..BoxSettings::default()
            },
            rosenbrock,
        );
        assert_eq!(m.x[1], 0.5);
        // a* where d/da [(1 − a)² + 100 (0.5 − a²)²] = 0, by bisection on [0.5, 1].
        let d = |a: f64| -2.0 * (1.0 - a) - 400.0 * a * (0.5 - a * a);
        let (mut lo, mut hi) = (0.5, 1.0);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if d(mid) < 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        assert!(
            (m.x[0] - lo).abs() < 1e-6,
            "a = {} vs a* = {lo} ({:?})",
            m.x[0],
            m.stop
        );
    }

    #[test]
    fn a_failing_region_is_avoided_and_a_failing_start_reported() {
        // f = −x on [0, 1], undefined beyond 0.7: the search stops just below 0.7.
        let f = |x: &[f64]| (x[0] <= 0.7).then(|| (-x[0], vec![-1.0], x.to_vec()));
        let settings = BoxSettings {
            max_iterations: 200,
            max_evaluations: 2000,
            ..BoxSettings::default()
        };
        let m = minimise_in_box(&[0.0], &[0.0], &[1.0], &settings, f);
        assert!(m.x[0] <= 0.7 && m.x[0] > 0.7 - 1e-6, "{m:?}");
        let m = minimise_in_box(&[0.9], &[0.0], &[1.0], &BoxSettings::default(), f);
        assert_eq!(m.stop, BoxStop::StartFailed);
    }

    #[test]
    fn a_flat_range_beyond_an_unknown_edge_becomes_a_bound() {
        // f = −x₀ − (x₁ − 0.2)² depends on x₀ only through min(x₀, 0.6): an evaluation beyond
        // 0.6 stands for 0.6 with the one-sided gradient there.
        let f = |x: &[f64]| {
            let a = x[0].min(0.6);
            Some((
                -a + (x[1] - 0.2).powi(2),
                vec![-1.0, 2.0 * (x[1] - 0.2)],
                vec![a, x[1]],
            ))
        };
        let m = minimise_in_box(
            &[-1.0, -1.0],
            &[-1.0; 2],
            &[1.0; 2],
            &BoxSettings::default(),
            f,
        );
        assert_eq!(m.x[0], 0.6, "{m:?}");
        assert!((m.x[1] - 0.2).abs() < 1e-6, "{m:?}");
        assert!(m.evaluations < 40, "{m:?}");
    }
}
