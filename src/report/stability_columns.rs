//! The stability columns of `frf.csv` and every `curve_*.csv` (`stable`, `floquet_re`,
//! `floquet_freq_hz`, `stability_method`, `stability_reliable`), appended after the other
//! columns when the scene sets `analysis.stability` (see [`crate::analysis::stability`] and
//! `analysis.stability_method`). Kept in one place so that other column additions merge
//! without touching these.

use std::fmt::Write as _;

use crate::analysis::stability::PointStability;
use crate::model::Problem;

/// The header cells (each with its leading comma), empty when stability is off.
pub fn header(problem: &Problem) -> &'static str {
    if problem.analysis.stability {
        ",stable,floquet_re,floquet_freq_hz,stability_method,stability_reliable"
    } else {
        ""
    }
}

/// A row's cells (each with its leading comma): `true`/`false`, the leading Floquet
/// exponent's real part (1/s), its frequency (Hz), the method that gave the verdict (`hill`,
/// `monodromy`, or `failed` with the first three cells empty) and whether the verdict is
/// reliable (`true`/`false`); nothing when the point has no stability (stability off).
pub fn cells(stability: Option<&PointStability>) -> String {
    let mut s = String::new();
    if let Some(p) = stability {
        if p.has_verdict() {
            let _ = write!(
                s,
                ",{},{:.6e},{:.6e}",
                p.stable, p.floquet_re, p.floquet_freq_hz
            );
        } else {
            s.push_str(",,,");
        }
        let _ = write!(s, ",{},{}", p.method.label(), p.reliable);
    }
    s
}
