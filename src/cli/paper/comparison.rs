//! The paper's statements and whether the key numbers agree with them: the criteria of
//! agreement, the table of key numbers set against the paper's statements ([`key_table`]), and
//! the section on where fricbound and the paper differ, and why ([`differences`]).
//!
//! Nothing here is typed in but the paper's statements and the criteria of agreement: the
//! numbers are those of [`KeyNumbers`].

use std::fmt::Write as _;

use serde::Serialize;

use super::numbers::{AnalysisRow, BetaRow, KeyNumbers};

/// Agreement of a fricbound number with the paper's statement.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Agreement {
    /// Within the stated criterion.
    Agrees,
    /// Same trend or overlapping ranges, but not within the criterion.
    Partly,
    /// Outside.
    Disagrees,
    /// The figures it needs did not run.
    NotComputed,
}

impl Agreement {
    /// The word in the table's "agrees?" column.
    fn text(self) -> &'static str {
        match self {
            Agreement::Agrees => "yes",
            Agreement::Partly => "partly",
            Agreement::Disagrees => "no",
            Agreement::NotComputed => "not computed",
        }
    }
}

/// β values by decreasing limit-peak ratio: `90° (1.234) > 120° (1.100)`.
pub(super) fn ranking(rows: &[BetaRow]) -> String {
    let mut sorted: Vec<&BetaRow> = rows.iter().collect();
    sorted.sort_by(|a, b| b.ratio.total_cmp(&a.ratio));
    sorted
        .iter()
        .map(|r| format!("{}° ({:.3})", r.beta, r.ratio))
        .collect::<Vec<_>>()
        .join(" > ")
}

/// The limit-peak ratio at apical angle `beta`, if it was computed.
fn ratio_at(rows: &[BetaRow], beta: f64) -> Option<f64> {
    rows.iter().find(|r| r.beta == beta).map(|r| r.ratio)
}

/// The paper's three claims on β ≥ 90°: largest variability at 90°, nearly none at 180°,
/// and 160° above 150° (not monotonic).
fn high_beta_checks(rows: &[BetaRow]) -> Option<(bool, bool, bool)> {
    let top = rows.iter().max_by(|a, b| a.ratio.total_cmp(&b.ratio))?;
    let flat = ratio_at(rows, 180.0)?;
    let (r150, r160) = (ratio_at(rows, 150.0)?, ratio_at(rows, 160.0)?);
    Some((top.beta == 90.0, flat < 1.01, r160 > r150))
}

/// The paper's claim on β ≤ 90°: the variability shrinks steadily as β decreases from 90°.
fn low_beta_monotonic(rows: &[BetaRow]) -> Option<bool> {
    if rows.len() < 2 {
        return None;
    }
    let mut sorted: Vec<&BetaRow> = rows.iter().collect();
    sorted.sort_by(|a, b| a.beta.total_cmp(&b.beta));
    Some(sorted.windows(2).all(|w| w[1].ratio > w[0].ratio))
}

/// The `## Key numbers` section: one row per statement of the paper (quantity, the paper,
/// fricbound, agrees?) and the criteria.
pub(super) fn key_table(s: &mut String, k: &KeyNumbers) {
    let _ = writeln!(s, "## Key numbers\n");
    let _ = writeln!(
        s,
        "| quantity | the paper | fricbound | agrees? |\n| --- | --- | --- | --- |"
    );
    // 1. Ratio of the limit peaks.
    let (text, agree) = match &k.max_peak_ratio {
        Some(m) => {
            let a = if (m.value - 3.0).abs() <= 0.2 * 3.0 {
                Agreement::Agrees
            } else if m.value >= 1.5 {
                Agreement::Partly
            } else {
                Agreement::Disagrees
            };
            (
                format!("largest {:.2}× ({}, {})", m.value, m.figure, m.at),
                a,
            )
        }
        None => ("—".to_string(), Agreement::NotComputed),
    };
    let mut text = text;
    if let Some((r, f0)) = k.f0_sweep_max_ratio {
        let _ = write!(
            text,
            "; in the F0 sweep at β = 120° (Fig. 16a) {r:.2}× at F0 = {f0} N"
        );
    }
    if let Some(b) = k.beta_high_optimal.iter().find(|b| b.beta == 90.0) {
        let _ = write!(text, "; at β = 90° (Fig. 18b) {:.2}× at {}", b.ratio, b.at);
    }
    let _ = writeln!(
        s,
        "| ratio of the limit peak amplitudes (upper/lower) | up to 3× | {text} | {} |",
        agree.text()
    );
    // 2. Resonance-frequency change: over the whole study, and in the paper's Fig. 16d sweep.
    let near3 = |v: f64| (v - 3.0).abs() <= 1.0;
    let (text, agree) = match (&k.max_freq_change_pct, k.f0_sweep_max_freq_change_pct) {
        (Some(m), sweep) => {
            let mut t = format!("largest {:.2} % ({}, {})", m.value, m.figure, m.at);
            if let Some((v, f0)) = sweep {
                let _ = write!(
                    t,
                    "; in the F0 sweep at β = 120° (Fig. 16d) {v:.2} % at F0 = {f0} N"
                );
            }
            let a = if near3(m.value) {
                Agreement::Agrees
            } else if sweep.is_some_and(|(v, _)| near3(v)) || m.value > 0.5 {
                Agreement::Partly
            } else {
                Agreement::Disagrees
            };
            (t, a)
        }
        (None, _) => ("—".to_string(), Agreement::NotComputed),
    };
    let _ = writeln!(
        s,
        "| resonance-frequency change between the limits | up to 3 % | {text} | {} |",
        agree.text()
    );
    // 3. Pre-load where the variability disappears.
    let (text, agree) = if k.limit_peaks_cross_f0.is_empty() && k.unique_up_to_f0.is_none() {
        ("—".to_string(), Agreement::NotComputed)
    } else {
        let mut t = String::new();
        if !k.limit_peaks_cross_f0.is_empty() {
            let _ = write!(
                t,
                "the limit peaks cross (closed band collapses) at F0 ≈ {} N",
                k.limit_peaks_cross_f0
                    .iter()
                    .map(|f| format!("{f:.0}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
        if let Some((f, next)) = k.unique_up_to_f0 {
            let _ = write!(
                t,
                "{}limit peaks within 1 % for F0 ≤ {f} N{}",
                if t.is_empty() { "" } else { "; " },
                next.map(|n| format!(", apart from the next swept value ({n} N) on"))
                    .unwrap_or_default()
            );
        }
        let a = match k.limit_peaks_cross_f0.first() {
            Some(f) if (f - 60.0).abs() <= 15.0 => Agreement::Agrees,
            Some(f) if (30.0..=90.0).contains(f) => Agreement::Partly,
            Some(_) => Agreement::Disagrees,
            None => Agreement::Partly,
        };
        (t, a)
    };
    let _ = writeln!(
        s,
        "| pre-load where the variability (closed band) disappears | near 60 N (Fig. 15a) | {text} | {} |",
        agree.text()
    );
    // 4. Optimum pre-load range.
    let limits_opt: Vec<&(String, f64, bool)> = k
        .optimum_f0
        .iter()
        .filter(|(c, _, _)| c == "m+1" || c == "m-1")
        .collect();
    let (text, agree) = if limits_opt.len() == 2 {
        let lo = limits_opt.iter().map(|o| o.1).fold(f64::INFINITY, f64::min);
        let hi = limits_opt
            .iter()
            .map(|o| o.1)
            .fold(f64::NEG_INFINITY, f64::max);
        let inside = |v: f64| (45.0..=80.0).contains(&v);
        let a = if inside(lo) && inside(hi) {
            Agreement::Agrees
        } else if hi >= 45.0 && lo <= 80.0 {
            Agreement::Partly
        } else {
            Agreement::Disagrees
        };
        (
            format!(
                "{lo:.0}-{hi:.0} N ({}){}",
                limits_opt
                    .iter()
                    .map(|(c, f, _)| format!("{c}: {f:.1} N"))
                    .collect::<Vec<_>>()
                    .join(", "),
                if limits_opt.iter().any(|o| o.2) {
                    " — a minimum lies at an end of the sweep"
                } else {
                    ""
                }
            ),
            a,
        )
    } else {
        ("—".to_string(), Agreement::NotComputed)
    };
    let _ = writeln!(
        s,
        "| optimum pre-load (minimum of the limit optimal curves) | around 45-80 N | {text} | {} |",
        agree.text()
    );
    // 5. β ranking.
    let rows = if k.beta_high_frf.is_empty() {
        &k.beta_high_optimal
    } else {
        &k.beta_high_frf
    };
    let (text, agree) = match high_beta_checks(rows) {
        Some((top90, flat, non_mono)) => {
            let n = [top90, flat, non_mono].iter().filter(|x| **x).count();
            (
                format!(
                    "FRF limit-peak ratio at F0 = 120 N: {}; largest at 90°: {}, flat ≈ unique: {}, 160° > 150°: {}",
                    ranking(rows),
                    yes(top90),
                    yes(flat),
                    yes(non_mono)
                ),
                match n {
                    3 => Agreement::Agrees,
                    0 => Agreement::Disagrees,
                    _ => Agreement::Partly,
                },
            )
        }
        None => ("—".to_string(), Agreement::NotComputed),
    };
    let _ = writeln!(
        s,
        "| β ranking of the variability (β ≥ 90°) | largest at β = 90°, almost none at 180°, not monotonic between 150° and 160° (160° wider in Fig. 18a) | {text} | {} |",
        agree.text()
    );
    // The limits bound at high pre-loads and need not near the optimum (Fig. 15).
    let row = |f0: f64| {
        k.analyses
            .iter()
            .find(|r| r.figure == "fig15a" && r.value == Some(f0))
    };
    // Bounded: neither the scanned states nor the envelope over all m (when computed) leave
    // the band by more than 0.1 %, and no intermediate peak lies outside the limit peaks.
    let envelope_excess = |r: &AnalysisRow| {
        r.envelope
            .as_ref()
            .map_or(0.0, |e| e.above_pct.max(e.below_pct))
    };
    let bounded = |r: &AnalysisRow| {
        r.bound.as_ref().map(|b| {
            b.above_pct.max(b.below_pct).max(envelope_excess(r)) < 0.1
                && r.intermediates_outside.is_empty()
        })
    };
    let (text, agree) = match (row(130.0), row(400.0), row(60.0)) {
        (Some(a), Some(b), Some(c)) => match (bounded(a), bounded(b), bounded(c)) {
            (Some(x), Some(y), Some(z)) => {
                let excess = |r: &AnalysisRow| {
                    r.bound
                        .as_ref()
                        .map_or(0.0, |b| b.above_pct.max(b.below_pct))
                };
                // The envelope over all m per side, where it was computed (at 60 N, Fig. 15b
                // is the same case when Fig. 15a ran without it).
                let fig15b = k.analyses.iter().find(|r| r.figure == "fig15b");
                let at_60 = c
                    .envelope
                    .as_ref()
                    .or(fig15b.and_then(|r| r.envelope.as_ref()));
                let envelopes = [
                    ("130 N", a.envelope.as_ref()),
                    ("400 N", b.envelope.as_ref()),
                    ("60 N", at_60),
                ];
                let excesses = envelopes
                    .iter()
                    .filter_map(|(at, e)| Some((*at, (*e)?)))
                    .map(|(at, e)| {
                        let side = |what: &str, pct: f64, p: &Option<(f64, Vec<f64>)>| {
                            p.as_ref().filter(|_| pct > 1e-4).map(|(f, m)| {
                                format!("{pct:.3} % {what} ({f:.2} Hz, {})", e.m_text(m))
                            })
                        };
                        let parts: Vec<String> = side("above", e.above_pct, &e.above_at)
                            .into_iter()
                            .chain(side("below", e.below_pct, &e.below_at))
                            .collect();
                        if parts.is_empty() {
                            format!("inside the band at {at}")
                        } else {
                            format!("{} at {at}", parts.join(" and "))
                        }
                    })
                    .collect::<Vec<_>>();
                let envelope = if excesses.is_empty() {
                    String::new()
                } else {
                    format!("; envelope over all m per side: {}", excesses.join("; "))
                };
                (
                    format!(
                        "largest pointwise excess of the scanned states: {:.3} % at 130 N, {:.3} % at 400 N, {:.3} % at 60 N{envelope}; bounded at 130 N: {}, at 400 N: {}, at 60 N: {}",
                        excess(a),
                        excess(b),
                        excess(c),
                        yes(x),
                        yes(y),
                        yes(z)
                    ),
                    match (x && y, z) {
                        (true, false) => Agreement::Agrees,
                        (true, true) | (false, false) => Agreement::Partly,
                        (false, true) => Agreement::Disagrees,
                    },
                )
            }
            _ => ("— (no bound scan)".to_string(), Agreement::NotComputed),
        },
        _ => ("—".to_string(), Agreement::NotComputed),
    };
    let _ = writeln!(
        s,
        "| do the limits bound the other solutions? | yes at 130 and 400 N (closed band), not necessarily near the optimum, 60 N (Fig. 15) | {text} | {} |",
        agree.text()
    );
    let (text, agree) = match low_beta_monotonic(&k.beta_low_frf) {
        Some(m) => (
            format!("{} (F0 = 500 N, P = 500 N)", ranking(&k.beta_low_frf)),
            if m {
                Agreement::Agrees
            } else {
                Agreement::Disagrees
            },
        ),
        None => ("—".to_string(), Agreement::NotComputed),
    };
    let _ = writeln!(
        s,
        "| β ranking of the variability (β ≤ 90°) | shrinks steadily as β decreases from 90° (Fig. 19a) | {text} | {} |",
        agree.text()
    );
    let _ = writeln!(
        s,
        "\nCriteria: ratio within 20 % of 3; frequency change within 1 percentage point of 3 %; \
         crossing within 15 N of 60 N; both optima inside 45-80 N (partly: the ranges overlap); \
         all three β claims (partly: some); bounded means no scanned state more than 0.1 % \
         outside the band at any grid frequency and no intermediate peak outside the limit \
         peaks. \"partly\" means the same kind of behaviour with different numbers.\n"
    );
}

/// "yes" or "no".
pub(super) fn yes(b: bool) -> &'static str {
    if b {
        "yes"
    } else {
        "no"
    }
}

/// The `## Where fricbound and the paper differ, and why` section: a note on each key number
/// outside its criterion, then the model as solved and the inputs the paper does not give.
pub(super) fn differences(s: &mut String, k: &KeyNumbers) {
    let _ = writeln!(s, "## Where fricbound and the paper differ, and why\n");
    if let Some(m) = &k.max_peak_ratio {
        if (m.value - 3.0).abs() > 0.6 {
            let _ = writeln!(
                s,
                "- **Ratio of the limit peaks** ({:.2}× at most here, 3× in the paper). The \
                 ratio grows with the pre-load and with the damper-induced cross coupling (it \
                 is largest at β = 90° and high F0 here too), so the largest value depends on \
                 the pre-loads and angles swept, which the paper gives only for some figures \
                 (its Fig. 18 pre-loads and Fig. 19 blade pre-loads are not stated; this study \
                 assumes them, see below). It also depends on which blade each contact frame \
                 belongs to and on the direction of the pre-load: with the paper's Table 1 \
                 stiffness k_xy couples x and y with a fixed sign, so mirroring the geometry \
                 (damper above vs below the blades) is not a symmetry of the model and changes \
                 how the excitation loads each contact.",
                m.value
            );
        }
    }
    if let Some(m) = &k.max_freq_change_pct {
        if (m.value - 3.0).abs() > 1.0 {
            let _ = writeln!(
                s,
                "- **Resonance-frequency change** ({:.2} % at most here, up to 3 % in the \
                 paper).{} The larger changes come from configurations where the two limit \
                 peaks lie far apart in frequency ({}, {}); the paper states its maximum over \
                 its own sweeps, whose points it does not list.",
                m.value,
                k.f0_sweep_max_freq_change_pct
                    .map(|(v, f0)| format!(
                        " In the paper's Fig. 16d configuration (β = 120°, F0 sweep) it is \
                         {v:.2} % at most (F0 = {f0} N)."
                    ))
                    .unwrap_or_default(),
                m.figure,
                m.at
            );
        }
    }
    let unbounded: Vec<&AnalysisRow> = k
        .analyses
        .iter()
        .filter(|r| r.bound.as_ref().is_some_and(|b| b.above_pct > 0.1))
        .collect();
    if !unbounded.is_empty() {
        let softening = unbounded
            .iter()
            .filter(|r| {
                r.bound
                    .as_ref()
                    .is_some_and(|b| b.above_stuck_limit_vs_slipping)
            })
            .count();
        let _ = writeln!(
            s,
            "- **Pointwise bounds.** In {} of the limit analyses with a scan, some intermediate \
             state rises above the upper limit at some frequency, although no scanned resonance \
             peak exceeds the limit peaks. In {softening} of them the upper limit curve is fully \
             stuck on every contact there while the scanned state slips: a slightly slipping \
             contact is softer, which moves its resonance down towards that frequency, above the \
             stuck response. The paper draws its closed bands by eye at 130 and 400 N; here they \
             hold for the resonance peaks, and pointwise only where no limit curve is fully \
             stuck next to a slipping intermediate one.",
            unbounded.len()
        );
    }
    if let Some(f) = k.limit_peaks_cross_f0.first() {
        if (f - 60.0).abs() > 15.0 {
            let _ = writeln!(
                s,
                "- **Pre-load of the collapse** (≈ {f:.0} N here, near 60 N in the paper). The \
                 band collapses where the two limit curves straddle the optimum pre-load, so it \
                 moves with the optimum (next item)."
            );
        }
    }
    let opt: Vec<f64> = k
        .optimum_f0
        .iter()
        .filter(|(c, _, _)| c == "m+1" || c == "m-1")
        .map(|o| o.1)
        .collect();
    if opt.iter().any(|v| !(45.0..=80.0).contains(v)) {
        let _ = writeln!(
            s,
            "- **Optimum pre-load** ({}, 45-80 N in the paper). The optimum lies where the \
             slipping side's static normal load N⁰, set by F0 through the damper's static balance \
             (Eq. 11 with K_D), lets it slip over a useful part of the cycle, so it depends on \
             how the excitation moves each face relative to its blade. That depends on the \
             contact-frame and sign conventions (described below), which the paper gives only \
             as Eq. (16), without saying which blade each frame belongs to or which way the \
             normal points; these scenes follow the free-body diagram of Eq. (11) and reproduce \
             the contact numbering of Fig. 14. The paper's range is read off a plot whose sweep \
             points it does not give; the data here cannot single out one cause.",
            opt.iter()
                .map(|v| format!("{v:.0} N"))
                .collect::<Vec<_>>()
                .join(" and ")
        );
    }
    if low_beta_monotonic(&k.beta_low_frf) == Some(false) {
        let _ = writeln!(
            s,
            "- **β < 90°** (not a steady decrease here). The paper explains its β < 90° results \
             by the damper losing contact under the pre-load unless the blades are pressed \
             onto it. In this model the wedge keeps contact without blade pre-loads too (it \
             spreads the elastically held blades), so the extra pre-loads P only add normal \
             load, and the variability need not shrink with β. The blade pre-load of Fig. 19a \
             is not given in the paper (P = 500 N assumed)."
        );
    }
    let _ = writeln!(
        s,
        "\n**The model, as solved here** (the same for every figure): the paper's Table 1 \
         lumped system with the damper spring K_D; one Jenkins element per damper face with \
         kt = kn = 3·10⁵ N/m, μ = 0.5, variable normal load and lift-off; harmonic balance with \
         the 1st harmonic and the 0th coupled (statics and dynamics solved together), 256 AFT \
         samples per period; contact frames of Eq. (16) as rotations by ∓α of the damper faces, \
         normal from the damper into the blade, contact 1 (`left`) on blade 1; the pre-load F0 \
         along −y on the damper (Eq. 11 read with the contact forces holding the damper up); for \
         β < 90° the blade pre-loads +P on x1 and −P on x2. The limit cases are m = ±1 on every \
         point (Eqs. 14-15); which one is closest to stuck is decided at each frequency from the \
         slipping side's static normal load, not assumed.\n"
    );
    let _ = writeln!(
        s,
        "**Inputs the paper does not give, assumed here:** F0 = 120 N for the β sweep of Fig. \
         18a; F0 = 500 N with P = 500 N and β = 30, 45, 60, 75, 90° for Fig. 19a; the pre-loads \
         of Fig. 17a (100, 250, 400 N); the sweep ranges (F0 = 10-500 N, P = 0-1000 N). Nothing \
         was fitted to the paper's numbers.\n"
    );
}
