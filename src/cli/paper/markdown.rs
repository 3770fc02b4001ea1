//! `summary.md`: the document around the comparison with the paper ([`markdown`]): the header,
//! the key-number table and the differences (from the comparison), the bound checks, the
//! envelope over all initial states against the limits, one section per figure with its images and numbers, and the failures.

use std::fmt::Write as _;

use super::comparison::{differences, key_table, ranking, yes};
use super::figures::FigureResult;
use super::numbers::{AnalysisRow, BetaRow, KeyNumbers, ResonanceEnds};

/// `summary.md`: the key numbers next to the paper's statements.
pub fn markdown(figures: &[FigureResult], k: &KeyNumbers, quick: bool, elapsed_s: f64) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# fricbound: the paper's §4 study, key numbers\n");
    let _ = writeln!(
        s,
        "Ferhatoglu & Zucca, JSV 494 (2021), §4 (Figs. 12-19), recomputed by `fricbound paper{}` \
         (fricbound {}) in {elapsed_s:.1} s. Every number below is computed from the runs in \
         this folder; only the paper's statements are quoted. Amplitudes are the first-harmonic \
         amplitude of y2 (m); peaks are the refined resonance peaks of each curve in the 3rd \
         resonance region (190-235 Hz) unless said otherwise.\n",
        if quick { " --quick" } else { "" },
        env!("CARGO_PKG_VERSION")
    );
    if quick {
        let _ = writeln!(
            s,
            "**Quick mode:** coarser sweeps, grid, continuation steps and bound scan; the \
             numbers are indicative only (run without `--quick` for the study).\n"
        );
    }
    let ran: Vec<&str> = figures.iter().map(|f| f.job.id).collect();
    let _ = writeln!(s, "Figures run: {}.\n", ran.join(", "));

    key_table(&mut s, k);
    bounds_table(&mut s, k);
    envelope_table(&mut s, k);
    figure_sections(&mut s, figures, k);
    differences(&mut s, k);
    if !k.failures.is_empty() {
        let _ = writeln!(s, "## Failures\n");
        for f in &k.failures {
            let _ = writeln!(s, "- {f}");
        }
        s.push('\n');
    }
    s
}

/// The `## Do the limits bound the other solutions?` section: the bound check of every limit
/// analysis with a scan.
fn bounds_table(s: &mut String, k: &KeyNumbers) {
    let _ = writeln!(s, "## Do the limits bound the other solutions?\n");
    let _ = writeln!(
        s,
        "For every limit analysis with a bound scan, every combination of intermediate initial \
         states m per damper side is solved and compared with the band: pointwise at each grid \
         frequency, and at the resonance peaks. The paper: the limits enclose a closed band at \
         high pre-loads (130 and 400 N, Fig. 15a) and need not near the optimum (60 N, Fig. \
         15b).\n"
    );
    let _ = writeln!(
        s,
        "| figure | at | largest excess above the upper limit (pointwise) | below the lower limit (pointwise) | scanned peaks above / below the limit peaks | intermediate peaks outside the limit peaks |\n| --- | --- | --- | --- | --- | --- |"
    );
    for r in &k.analyses {
        let Some(b) = &r.bound else { continue };
        // Where, for excesses above the round-off of the comparison.
        let place = |p: &Option<(f64, String)>, pct: f64| {
            p.as_ref()
                .filter(|_| pct > 1e-4)
                .map(|(f, c)| format!(" ({c} at {f:.2} Hz)"))
                .unwrap_or_default()
        };
        let _ = writeln!(
            s,
            "| {} | {} | {:.3} %{} | {:.3} %{} | {:.3} % / {:.3} % | {} |",
            r.figure,
            if r.at.is_empty() { "—" } else { &r.at },
            b.above_pct,
            place(&b.above_at, b.above_pct),
            b.below_pct,
            place(&b.below_at, b.below_pct),
            b.peak_above_pct,
            b.peak_below_pct,
            if r.intermediates_outside.is_empty() {
                "none".to_string()
            } else {
                r.intermediates_outside.join(", ")
            }
        );
    }
    s.push('\n');
}

/// The `## The envelope over all initial states` section: per limit analysis that computed the
/// response envelope (one m per side), where and by how much it leaves the band of the two
/// limit curves.
fn envelope_table(s: &mut String, k: &KeyNumbers) {
    let rows: Vec<&AnalysisRow> = k.analyses.iter().filter(|r| r.envelope.is_some()).collect();
    if rows.is_empty() && k.envelope_skipped.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        "## The envelope over all initial states
"
    );
    let _ = writeln!(
        s,
        "For Figs. 13a, 15a and 15b the limit analysis also computes the response envelope \
         (`[limits] envelope = \"sides\"`): at every grid frequency the largest and smallest \
         amplitude of y2 over all initial states m ∈ [−1, 1] per damper side, by bounded \
         optimisation with the implicit-function sensitivity dA/dm, and at the limit curves' \
         peaks. Where the envelope leaves the band of the two limit curves, the two-point limits \
         fail to bound the response; the excesses are relative to the limit curve at that \
         frequency, with the m per side that attains them. The envelope's columns \
         (`y2_envelope_min_amp`, `y2_envelope_max_amp`) are in the figure's `limits.csv`, its \
         details in `limits.json` → `envelope`, and it is drawn (black) in `limits_y2.png`.\n"
    );
    if !k.envelope_skipped.is_empty() {
        let _ = writeln!(
            s,
            "**Not computed in this run:** {} (`--quick` skips the envelope there: it costs more \
             than a few seconds; run without `--quick`).\n",
            k.envelope_skipped.join(", ")
        );
    }
    if rows.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        "| figure | at | envelope above the upper limit (largest, where, m per side) | envelope below the lower limit | grid frequencies above / below / compared | envelope at the limit peaks above the larger limit peak | solves, time |\n| --- | --- | --- | --- | --- | --- | --- |"
    );
    for r in rows {
        let Some(e) = &r.envelope else { continue };
        let place = |p: &Option<(f64, Vec<f64>)>, pct: f64| {
            p.as_ref()
                .filter(|_| pct > 1e-4)
                .map(|(f, m)| format!(" at {f:.3} Hz ({})", e.m_text(m)))
                .unwrap_or_default()
        };
        let _ = writeln!(
            s,
            "| {} | {} | {:.3} %{} | {:.3} %{} | {} / {} / {}{} | {:.3} % | {}, {:.1} s |",
            r.figure,
            if r.at.is_empty() { "—" } else { &r.at },
            e.above_pct,
            place(&e.above_at, e.above_pct),
            e.below_pct,
            place(&e.below_at, e.below_pct),
            e.points_above,
            e.points_below,
            e.compared,
            if e.unsolved > 0 {
                format!(" ({} unsolved)", e.unsolved)
            } else {
                String::new()
            },
            e.peak_above_pct,
            e.solves,
            e.elapsed_s
        );
    }
    s.push('\n');
}

/// The `## Figure by figure` section: per figure its caption, scene, time, images and the
/// numbers it gives.
fn figure_sections(s: &mut String, figures: &[FigureResult], k: &KeyNumbers) {
    let _ = writeln!(s, "## Figure by figure\n");
    for f in figures {
        let _ = writeln!(
            s,
            "### {}: {}\n\nScene `meshes/paper-wedge/{}`, results in `{}/` ({:.1} s).\n",
            f.job.id, f.job.caption, f.job.scene_file, f.job.id, f.elapsed_s
        );
        let report = match &f.outcome {
            Ok(r) => r,
            Err(e) => {
                let _ = writeln!(s, "**Failed:** {e}\n");
                continue;
            }
        };
        figure_links(s, f.job.id, &report.dir);
        match f.job.id {
            "fig12" => {
                if let Some((open, stuck)) = &k.linear_resonances_hz {
                    let list = |v: &[f64]| {
                        v.iter()
                            .map(|f| format!("{f:.1}"))
                            .collect::<Vec<_>>()
                            .join(", ")
                    };
                    let _ = writeln!(
                        s,
                        "Linear resonances of y2 (grid of the linear references): contacts open \
                         (blades alone) {} Hz; contacts stuck (damper attached through kt, kn) {} \
                         Hz. The paper: the damper does not affect the 1st mode but its mass \
                         lowers it slightly, and it stiffens modes 2-4.\n",
                        list(open),
                        list(stuck)
                    );
                }
            }
            "fig16a-d" => f0_section(s, k),
            "fig16b" => fine_section(s, k),
            "fig16c" => loops_section(s, k),
            "fig18b" => beta_sweep_section(s, &k.beta_high_optimal, "F0"),
            "fig19b" => {
                beta_sweep_section(s, &k.beta_low_pseudo, "P");
                if !k.beta_low_pseudo_spread.is_empty() {
                    let _ = writeln!(
                        s,
                        "Smallest and largest limit-peak ratio over P per β: {}. The paper: the \
                         limits stay parallel (constant band) as P grows, until the stuck \
                         resonance is reached.\n",
                        k.beta_low_pseudo_spread
                            .iter()
                            .map(|(b, lo, hi)| format!("{b}°: {lo:.3}-{hi:.3}"))
                            .collect::<Vec<_>>()
                            .join("; ")
                    );
                }
            }
            _ => {}
        }
        analysis_rows(s, k, f.job.id);
        if f.job.id == "fig13-2nd" || f.job.id == "fig13-3rd" {
            states_note(s, k, f.job.id);
        }
    }
}

/// Embeds the figure's main image and links its other top-level images (PNG; each has an
/// SVG twin).
fn figure_links(s: &mut String, id: &str, dir: &std::path::Path) {
    let mut pngs: Vec<String> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .flatten()
        .filter_map(|e| e.file_name().into_string().ok())
        .filter(|n| n.ends_with(".png"))
        .collect();
    pngs.sort();
    let main = ["bands_", "limits_", "optimal_", "frf_"]
        .iter()
        .find_map(|p| pngs.iter().find(|n| n.starts_with(p)));
    if let Some(m) = main {
        let _ = writeln!(s, "![{id}]({id}/{m})\n");
    }
    let others: Vec<String> = pngs
        .iter()
        .filter(|n| Some(*n) != main)
        .map(|n| format!("[{n}]({id}/{n})"))
        .collect();
    if !others.is_empty() {
        let _ = writeln!(s, "Other figures: {}.\n", others.join(", "));
    }
}

/// The table of figure `id`'s limit analyses: limit peaks, ratio, frequency change, band.
fn analysis_rows(s: &mut String, k: &KeyNumbers, id: &str) {
    let rows: Vec<&AnalysisRow> = k.analyses.iter().filter(|r| r.figure == id).collect();
    if rows.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        "| at | upper limit peak | lower limit peak | ratio | frequency change | widest band | multiple-solution share | peaks refined |\n| --- | --- | --- | --- | --- | --- | --- | --- |"
    );
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} {} m at {:.2} Hz | {} {} m at {:.2} Hz | {:.4} | {:.3} % | {} m at {:.2} Hz | {:.0} % | {} |",
            if r.at.is_empty() { "—" } else { &r.at },
            r.upper.0,
            e(r.upper.1),
            r.upper.2,
            r.lower.0,
            e(r.lower.1),
            r.lower.2,
            r.ratio,
            r.freq_change_pct,
            e(r.widest_band.0),
            r.widest_band.1,
            100.0 * r.multiple_share,
            yes(r.refined)
        );
    }
    s.push('\n');
}

/// The contact states at the limit peaks of figure `id` (Figs. 13-14), next to the paper's.
fn states_note(s: &mut String, k: &KeyNumbers, id: &str) {
    let Some(r) = k.analyses.iter().find(|r| r.figure == id) else {
        return;
    };
    let paper = if id == "fig13-2nd" {
        "both contacts slip at the 2nd resonance (contact 1 stick-slip, contact 2 \
         stick-slip-lift-off, Fig. 14b), so the limit curves coincide"
    } else {
        "contact 1 stays fully stuck over the whole interval while contact 2 stick-slips \
         (Fig. 14a), so the curves differ"
    };
    let _ = writeln!(
        s,
        "Contact states (contact 1 = `left`, blade 1; contact 2 = `right`, blade 2) at the limit \
         peaks: {}. Side stuck at every grid frequency in both limit curves: {}. Limit peaks \
         differ by {:.2e} (relative). The paper: {paper}.\n",
        r.peak_states.join("; "),
        r.always_stuck_side.as_deref().unwrap_or("none"),
        r.ratio - 1.0
    );
}

/// The F0 sweep (Figs. 16a, 16d): peaks per F0, saturation at the stuck peak, frequencies.
fn f0_section(s: &mut String, k: &KeyNumbers) {
    if k.f0_sweep.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        "| F0 (N) | m+1 peak (m) | m-1 peak (m) | ratio | frequency change |\n| --- | --- | --- | --- | --- |"
    );
    for r in &k.f0_sweep {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.4} | {:.3} %{} |",
            r.value,
            e(r.peaks[0]),
            e(r.peaks[1]),
            r.ratio,
            r.freq_change_pct,
            if r.refined { "" } else { " (no interior peak)" }
        );
    }
    s.push('\n');
    if let Some((f0, hi, lo)) = k.high_f0_over_stuck {
        let _ = writeln!(
            s,
            "At F0 = {f0} N the limit peaks are {:.0} % and {:.0} % of the stuck-linear 3rd \
             resonance peak (the paper: the optimal-curve limits saturate at the fully stuck \
             linear case).",
            100.0 * hi,
            100.0 * lo
        );
    }
    if let Some(ResonanceEnds {
        smallest_f0: (lo_hi, lo_lo),
        largest_f0: (hi_hi, hi_lo),
        stuck,
    }) = k.f0_sweep_frequencies
    {
        let _ = writeln!(
            s,
            "Resonance-frequency limits (Fig. 16d): {lo_lo:.2}-{lo_hi:.2} Hz at the smallest F0, \
             {hi_lo:.2}-{hi_hi:.2} Hz at the largest; stuck-linear resonance {stuck:.2} Hz (the \
             paper: the limits start together and end together at the stuck resonance)."
        );
    }
    s.push('\n');
}

/// The fine F0 sweep (Fig. 16b): the optimum pre-loads and where intermediate peaks lie
/// outside the limit peaks.
fn fine_section(s: &mut String, k: &KeyNumbers) {
    if k.f0_fine.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        "Optimum pre-load (minimum of each optimal curve, parabolic through the three lowest \
         swept values): {}.\n",
        k.optimum_f0
            .iter()
            .map(|(c, f, end)| format!(
                "{c} {f:.1} N{}",
                if *end { " (at a sweep end)" } else { "" }
            ))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let _ = writeln!(
        s,
        "Pre-loads at which an intermediate curve's resonance peak lies outside the two limit \
         peaks (the transition region of Fig. 15b): {}.\n",
        if k.intermediates_outside_f0.is_empty() {
            "none".to_string()
        } else {
            let lo = k
                .intermediates_outside_f0
                .iter()
                .cloned()
                .fold(f64::INFINITY, f64::min);
            let hi = k
                .intermediates_outside_f0
                .iter()
                .cloned()
                .fold(f64::NEG_INFINITY, f64::max);
            format!(
                "{lo}-{hi} N ({} of {} swept values)",
                k.intermediates_outside_f0.len(),
                k.f0_fine.len()
            )
        }
    );
}

/// The loops at resonance (Fig. 16c): energy dissipated per cycle per contact and curve.
fn loops_section(s: &mut String, k: &KeyNumbers) {
    if k.loops.is_empty() {
        return;
    }
    let contacts: Vec<&String> = k.loops[0].energy.iter().map(|(c, _)| c).collect();
    let _ = write!(s, "| curve | resonance | amplitude |");
    for c in &contacts {
        let _ = write!(s, " energy dissipated per cycle, `{c}` (J) |");
    }
    let _ = write!(s, "\n| --- | --- | --- |");
    for _ in &contacts {
        s.push_str(" --- |");
    }
    s.push('\n');
    for l in &k.loops {
        let _ = write!(
            s,
            "| {} | {:.2} Hz | {} m |",
            l.case,
            l.freq_hz,
            e(l.amplitude)
        );
        for (_, w) in &l.energy {
            // Round-off of a stuck contact's closed loop is ~1e-19 J: print it as zero.
            if w.abs() < 1e-12 {
                s.push_str(" 0 |");
            } else {
                let _ = write!(s, " {} |", e(*w));
            }
        }
        s.push('\n');
    }
    let _ = writeln!(
        s,
        "\nThe paper: the slipping contact has quite different loops for the limit and \
         intermediate states, so the damping differs; the stuck contact dissipates nothing. \
         Loops: `hysteresis_<contact>.png` and `hysteresis_<curve>_peak.csv`.\n"
    );
}

/// The largest limit-peak ratio of a sweep over `parameter` per apical angle, and their
/// ranking (Figs. 18b, 19b).
fn beta_sweep_section(s: &mut String, rows: &[BetaRow], parameter: &str) {
    if rows.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        "Largest limit-peak ratio over the {parameter} sweep per apical angle: {}.\n",
        rows.iter()
            .map(|r| format!("β = {}°: {:.3} ({})", r.beta, r.ratio, r.at))
            .collect::<Vec<_>>()
            .join("; ")
    );
    let _ = writeln!(s, "Ranking: {}.\n", ranking(rows));
}

/// An amplitude or energy in the summary's format, `1.2345e-5`.
fn e(v: f64) -> String {
    format!("{v:.4e}")
}
