//! Where an exit function of a phase turns positive inside a bracket: a sign change, or a
//! graze inside the cell, refined by Brent's method (the rules of the 1D march,
//! [`crate::contact::events::march`], on functions of the 2D element).

use crate::contact::events::roots::brent;

/// The first root in (a, b] at which an exit function turns positive, if any: a sign change
/// across the cell, or a graze (f′ falls from positive to negative inside it at a positive
/// maximum of f). At a phase's first cell f(a) is zero by construction and f falls first (as
/// in the 1D march, [`crate::contact::events::march`]).
pub(super) fn crossing(
    f: &impl Fn(f64) -> (f64, f64),
    (a, (fa, dfa)): (f64, (f64, f64)),
    (b, (fb, dfb)): (f64, (f64, f64)),
    zero: f64,
    first: bool,
) -> Option<f64> {
    let value = |t: f64| f(t).0;
    if fb > zero {
        if fa < -zero {
            return Some(brent(value, a, b, fa, fb));
        }
        if first || fa <= zero {
            return Some(rising_root(&value, (a, b), fb, zero));
        }
        return Some(a);
    }
    if dfa > 0.0 && dfb < 0.0 {
        let peak = brent(|t| f(t).1, a, b, dfa, dfb);
        let f_peak = value(peak);
        if f_peak > zero && peak > a {
            if fa < -zero {
                return Some(brent(value, a, peak, fa, f_peak));
            }
            return Some(rising_root(&value, (a, peak), f_peak, zero));
        }
    }
    None
}

/// The first rise of f through zero in (a, b] where f(a) ≈ 0 and f(b) > 0: a point where
/// f is below −`zero` (its round-off) is sought on a subdivision that is geometric toward a
/// (the stretch where f dips below zero may be far shorter than the cell: a contact that
/// closes and opens again, a slider that stops for an instant and slips on) and uniform
/// beyond, then the root is refined from it; where f rises above `zero` first, it rises from
/// a itself. The same rule as the 1D march's ([`crate::contact::events::march`]).
fn rising_root(f: &impl Fn(f64) -> f64, (a, b): (f64, f64), fb: f64, zero: f64) -> f64 {
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
