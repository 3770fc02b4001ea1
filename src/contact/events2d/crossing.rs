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
            return Some(rising_root(&value, a, b, fb, dfa));
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
            return Some(rising_root(&value, a, peak, f_peak, dfa));
        }
    }
    None
}

/// The first rise of f through zero in (a, b] where f(a) ≈ 0 (rate `dfa`) and f(b) > 0.
///
/// Where f falls at a (dfa < 0) but is already positive at the first subdivision, the dip
/// below zero is shorter than a subdivision (a trial force that barely lags the friction
/// limit at a closing, say): it is found by halving towards a, rather than taking a itself
/// as the root (which would end the phase where it starts, and the next phase there too).
fn rising_root(f: &impl Fn(f64) -> f64, a: f64, b: f64, fb: f64, dfa: f64) -> f64 {
    const SUBDIVISIONS: usize = 16;
    let mut negative: Option<(f64, f64)> = None;
    for i in 1..=SUBDIVISIONS {
        let t = if i == SUBDIVISIONS {
            b
        } else {
            a + (b - a) * i as f64 / SUBDIVISIONS as f64
        };
        let ft = if i == SUBDIVISIONS { fb } else { f(t) };
        if ft > 0.0 {
            return match negative.or_else(|| dip(f, a, t, dfa)) {
                Some((tn, fneg)) => brent(f, tn, t, fneg, ft),
                None => a,
            };
        }
        if ft < 0.0 {
            negative = Some((t, ft));
        }
    }
    b
}

/// A point of (a, t) where f < 0, found by halving t − a, when f falls at a (dfa < 0).
fn dip(f: &impl Fn(f64) -> f64, a: f64, t: f64, dfa: f64) -> Option<(f64, f64)> {
    if dfa >= 0.0 {
        return None;
    }
    let mut step = t - a;
    for _ in 0..60 {
        step *= 0.5;
        let tk = a + step;
        if tk <= a {
            break;
        }
        let fk = f(tk);
        if fk < 0.0 {
            return Some((tk, fk));
        }
    }
    None
}
