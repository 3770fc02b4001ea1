//! Golden-section search for the maximum of a function of one variable on a bracket, where an
//! evaluation may fail. Shared by the time-domain peak of a Fourier series (evaluations never
//! fail) and the refinement of resonance peaks along a solved path (each evaluation is a
//! Newton solve, which may fail).

/// (√5 − 1)/2: each step keeps this fraction of the bracket.
const RATIO: f64 = 0.618_033_988_749_894_9;

/// The outcome of [`maximise`].
#[derive(Debug, Clone, PartialEq)]
pub struct GoldenSearch<T> {
    /// The best evaluation seen: (argument, value, payload); None when none succeeded.
    pub best: Option<(f64, f64, T)>,
    /// Whether the search narrowed the bracket down to its tolerance with every evaluation
    /// succeeding (false: it stopped at the first failed evaluation).
    pub complete: bool,
}

/// Golden-section search for a maximum of `f` on [lo, hi], until the bracket is narrower than
/// `tolerance`. `f(x)` returns the value and a payload (e.g. the solved point), or None where it
/// cannot be evaluated; the search then stops, since it can no longer tell which side to keep.
/// Returns the best evaluation seen. On a unimodal function this converges to the maximum.
pub fn maximise<T>(
    lo: f64,
    hi: f64,
    tolerance: f64,
    mut f: impl FnMut(f64) -> Option<(f64, T)>,
) -> GoldenSearch<T> {
    let mut best: Option<(f64, f64, T)> = None;
    let mut eval = |x: f64, best: &mut Option<(f64, f64, T)>| -> Option<f64> {
        let (v, payload) = f(x)?;
        if best.as_ref().is_none_or(|b| v > b.1) {
            *best = Some((x, v, payload));
        }
        Some(v)
    };
    let (mut lo, mut hi) = (lo, hi);
    let mut c = hi - RATIO * (hi - lo);
    let mut d = lo + RATIO * (hi - lo);
    let (vc, vd) = (eval(c, &mut best), eval(d, &mut best));
    let (Some(mut vc), Some(mut vd)) = (vc, vd) else {
        return GoldenSearch {
            best,
            complete: false,
        };
    };
    while hi - lo > tolerance {
        if vc >= vd {
            hi = d;
            d = c;
            vd = vc;
            c = hi - RATIO * (hi - lo);
            match eval(c, &mut best) {
                Some(v) => vc = v,
                None => {
                    return GoldenSearch {
                        best,
                        complete: false,
                    }
                }
            }
        } else {
            lo = c;
            c = d;
            vc = vd;
            d = lo + RATIO * (hi - lo);
            match eval(d, &mut best) {
                Some(v) => vd = v,
                None => {
                    return GoldenSearch {
                        best,
                        complete: false,
                    }
                }
            }
        }
    }
    GoldenSearch {
        best,
        complete: true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A parabola's maximum is found to the tolerance; the payload is the evaluated argument's.
    #[test]
    fn finds_the_maximum_of_a_parabola() {
        let s = maximise(0.0, 3.0, 1e-10, |x| Some((-(x - 1.234).powi(2), x * 2.0)));
        assert!(s.complete);
        let (x, v, payload) = s.best.unwrap();
        assert!((x - 1.234).abs() < 1e-9, "{x}");
        assert!(v <= 0.0 && v > -1e-17);
        assert_eq!(payload, x * 2.0);
    }

    /// A failed evaluation stops the search and says so, keeping what it had seen.
    #[test]
    fn a_failed_evaluation_stops_the_search() {
        let mut calls = 0;
        let s = maximise(0.0, 1.0, 1e-12, |x| {
            calls += 1;
            (calls < 5).then_some((x, ()))
        });
        assert!(!s.complete);
        assert!(s.best.is_some());
        assert_eq!(calls, 5);
    }
}
