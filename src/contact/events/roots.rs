//! Brent's root finder on a bracket, for locating contact events in continuous time.
//!
//! Written here rather than taken from a crate: the contact layer uses no other layer of the
//! crate, the routine is thirty lines, and the event march needs a bracketing method that
//! never leaves its bracket and stops at round-off of τ (no crate offers that contract with
//! a closure that may be called a few hundred thousand times per Newton iteration without
//! allocation).

/// A root of `f` in [a, b] where f(a) and f(b) have opposite signs (or one is zero), located
/// by Brent's method (inverse quadratic interpolation, secant and bisection steps) to an
/// absolute tolerance of a few ulps of τ. `fa`, `fb` are f(a), f(b). The root found is the one
/// the bracket converges to; with several roots in [a, b] any of them may be returned.
pub fn brent(mut f: impl FnMut(f64) -> f64, a: f64, b: f64, fa: f64, fb: f64) -> f64 {
    let (mut a, mut b, mut fa, mut fb) = (a, b, fa, fb);
    if fa == 0.0 {
        return a;
    }
    if fb == 0.0 {
        return b;
    }
    debug_assert!(fa.signum() != fb.signum(), "brent needs a sign change");
    let (mut c, mut fc) = (a, fa);
    let mut d = b - a;
    let mut e = d;
    for _ in 0..200 {
        if fb.signum() == fc.signum() {
            c = a;
            fc = fa;
            d = b - a;
            e = d;
        }
        if fc.abs() < fb.abs() {
            a = b;
            b = c;
            c = a;
            fa = fb;
            fb = fc;
            fc = fa;
        }
        let tol = 2.0 * f64::EPSILON * b.abs().max(1.0);
        let m = 0.5 * (c - b);
        if m.abs() <= tol || fb == 0.0 {
            return b;
        }
        if e.abs() >= tol && fa.abs() > fb.abs() {
            let s = fb / fa;
            let (mut p, mut q) = if a == c {
                (2.0 * m * s, 1.0 - s)
            } else {
                let q = fa / fc;
                let r = fb / fc;
                (
                    s * (2.0 * m * q * (q - r) - (b - a) * (r - 1.0)),
                    (q - 1.0) * (r - 1.0) * (s - 1.0),
                )
            };
            if p > 0.0 {
                q = -q;
            } else {
                p = -p;
            }
            if 2.0 * p < (3.0 * m * q - (tol * q).abs()).min((e * q).abs()) {
                e = d;
                d = p / q;
            } else {
                d = m;
                e = m;
            }
        } else {
            d = m;
            e = m;
        }
        a = b;
        fa = fb;
        b += if d.abs() > tol { d } else { tol.copysign(m) };
        fb = f(b);
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_roots_to_round_off() {
        let f = |x: f64| x.cos() - x;
        let r = brent(f, 0.0, 1.0, f(0.0), f(1.0));
        assert!((r - 0.739_085_133_215_160_6).abs() < 1e-15, "{r}");
        // A root at a double-precision-sized bracket end, and a steep function.
        let g = |x: f64| (x - 3.0).powi(3);
        let r = brent(g, 0.0, 3.0 + 1e-9, g(0.0), g(3.0 + 1e-9));
        assert!((r - 3.0).abs() < 1e-5, "{r}");
        let h = |x: f64| (1e6 * (x - 0.3)).tanh();
        let r = brent(h, 0.0, 1.0, h(0.0), h(1.0));
        assert!((r - 0.3).abs() < 1e-14, "{r}");
    }
}
