//! The key numbers of the paper's §4 study: what the summary reports, one type per kind of row,
//! all gathered in [`KeyNumbers`], which is written as `summary.json` as it is.

use serde::Serialize;

/// A number and where it was found.
#[derive(Debug, Clone, Serialize)]
pub struct Located {
    /// The value.
    pub value: f64,
    /// Figure identifier.
    pub figure: String,
    /// Parameter values, e.g. `beta = 90 deg, F0 = 500 N`.
    pub at: String,
}

/// Bound check of one limit analysis (in % of the limit there).
#[derive(Debug, Clone, Serialize)]
pub struct BoundRow {
    /// Largest excess of a scanned curve above the upper limit, pointwise (%).
    pub above_pct: f64,
    /// Where: frequency (Hz) and scanned case.
    pub above_at: Option<(f64, String)>,
    /// Largest excess below the lower limit, pointwise (%).
    pub below_pct: f64,
    /// Where: frequency (Hz) and scanned case.
    pub below_at: Option<(f64, String)>,
    /// Largest scanned resonance peak above the larger limit peak (%).
    pub peak_above_pct: f64,
    /// Smallest scanned resonance peak below the smaller limit peak (%).
    pub peak_below_pct: f64,
    /// At the largest excess above: every limit curve fully stuck while the scanned state
    /// slips (the mechanism described in the summary).
    pub above_stuck_limit_vs_slipping: bool,
}

/// The response envelope of one limit analysis over all initial states (one m per damper
/// side, `[limits] envelope = "sides"`) against the two limit curves, first output DOF (y2).
/// Excesses are relative to the limit curve there, in %.
#[derive(Debug, Clone, Serialize)]
pub struct EnvelopeRow {
    /// Name of each side, the order of every `m` vector.
    pub sides: Vec<String>,
    /// Grid frequencies compared (band and envelope both exist).
    pub compared: usize,
    /// Grid frequencies where the envelope's max exceeds the upper limit (by more than 10⁻⁶).
    pub points_above: usize,
    /// Grid frequencies where the envelope's min lies below the lower limit.
    pub points_below: usize,
    /// Largest excess of the envelope's max above the upper limit, pointwise (%).
    pub above_pct: f64,
    /// Where: frequency (Hz) and the m per side attaining it.
    pub above_at: Option<(f64, Vec<f64>)>,
    /// Largest excess of the envelope's min below the lower limit, pointwise (%).
    pub below_pct: f64,
    /// Where: frequency (Hz) and the m per side attaining it.
    pub below_at: Option<(f64, Vec<f64>)>,
    /// Largest envelope max at the limit peaks over the larger limit peak (%).
    pub peak_above_pct: f64,
    /// Grid frequencies where no state could be solved.
    pub unsolved: usize,
    /// Newton solves of the search.
    pub solves: usize,
    /// Wall time of the envelope (s).
    pub elapsed_s: f64,
}

impl EnvelopeRow {
    /// `m_left = −0.622, m_right = +0.000`: the m of each side.
    pub fn m_text(&self, m: &[f64]) -> String {
        self.sides
            .iter()
            .zip(m)
            .map(|(side, m)| format!("m_{side} = {m:+.3}"))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// One limit analysis of the study.
#[derive(Debug, Clone, Serialize)]
pub struct AnalysisRow {
    /// Figure identifier.
    pub figure: String,
    /// Sweep point (empty for a single analysis).
    pub at: String,
    /// Swept parameter value, if any.
    pub value: Option<f64>,
    /// Limit case with the larger resonance peak, its peak (m) and frequency (Hz).
    pub upper: (String, f64, f64),
    /// Limit case with the smaller resonance peak, its peak (m) and frequency (Hz).
    pub lower: (String, f64, f64),
    /// Ratio of the limit peaks.
    pub ratio: f64,
    /// Resonance-frequency change between the limit peaks (%).
    pub freq_change_pct: f64,
    /// Whether both limit peaks are interior maxima.
    pub refined: bool,
    /// Widest band (m) and its frequency (Hz).
    pub widest_band: (f64, f64),
    /// Share of grid frequencies with multiple solutions.
    pub multiple_share: f64,
    /// Contact states at each limit peak, `case: contact state, ...`.
    pub peak_states: Vec<String>,
    /// Whether every grid point has the same side stuck in both limit curves, and which.
    pub always_stuck_side: Option<String>,
    /// Intermediate curves whose resonance peak lies outside the two limit peaks.
    pub intermediates_outside: Vec<String>,
    /// Bound check, when the scene asked for a scan.
    pub bound: Option<BoundRow>,
    /// The response envelope against the limits, when the figure computes it.
    pub envelope: Option<EnvelopeRow>,
}

/// One value of a peak sweep.
#[derive(Debug, Clone, Serialize)]
pub struct SweepRow {
    /// Series value, if any.
    pub series: Option<f64>,
    /// Parameter value.
    pub value: f64,
    /// Resonance peak per case (m); NaN where it failed.
    pub peaks: Vec<f64>,
    /// Ratio of the limit peaks (NaN if missing).
    pub ratio: f64,
    /// Frequency change between the limit peaks (%).
    pub freq_change_pct: f64,
    /// Both limit peaks are interior maxima.
    pub refined: bool,
}

/// Variability of one apical angle.
#[derive(Debug, Clone, Serialize)]
pub struct BetaRow {
    /// Apical angle (deg).
    pub beta: f64,
    /// Ratio of the limit peaks (for sweeps: the largest over the sweep).
    pub ratio: f64,
    /// Where the largest ratio is (sweeps), e.g. `F0 = 500 N`.
    pub at: String,
    /// Widest FRF band (m), for limit analyses.
    pub widest_band: Option<f64>,
}

/// Energy dissipated per cycle at one curve's resonance (Fig. 16c).
#[derive(Debug, Clone, Serialize)]
pub struct LoopRow {
    /// Curve.
    pub case: String,
    /// Frequency of the loop (Hz).
    pub freq_hz: f64,
    /// Output amplitude there (m).
    pub amplitude: f64,
    /// (contact, ∮T du in J) per contact.
    pub energy: Vec<(String, f64)>,
}

/// Resonance frequencies (Hz) of the two limit curves (higher, lower) at the smallest and the
/// largest swept pre-load, and the stuck-linear resonance (Fig. 16d).
#[derive(Debug, Clone, Copy, Serialize)]
pub struct ResonanceEnds {
    /// At the smallest F0.
    pub smallest_f0: (f64, f64),
    /// At the largest F0.
    pub largest_f0: (f64, f64),
    /// Stuck-linear 3rd resonance.
    pub stuck: f64,
}

/// Every key number of the study.
#[derive(Debug, Clone, Default, Serialize)]
pub struct KeyNumbers {
    /// Resonance frequencies (Hz) of the linear references: contacts open, stuck (Fig. 12).
    pub linear_resonances_hz: Option<(Vec<f64>, Vec<f64>)>,
    /// Every limit analysis.
    pub analyses: Vec<AnalysisRow>,
    /// Optimal-curve sweep over F0 (Figs. 16a, 16d).
    pub f0_sweep: Vec<SweepRow>,
    /// Fine sweep near the optimum with intermediate cases (Fig. 16b), and its case names.
    pub f0_fine: Vec<SweepRow>,
    /// Case names of the fine sweep.
    pub f0_fine_cases: Vec<String>,
    /// Largest ratio of the limit peaks over the study.
    pub max_peak_ratio: Option<Located>,
    /// Largest resonance-frequency change between the limit peaks over the study (%).
    pub max_freq_change_pct: Option<Located>,
    /// F0 (N) where the two limit peaks cross (the closed band collapses).
    pub limit_peaks_cross_f0: Vec<f64>,
    /// Largest F0 (N) up to which the limit peaks agree within 1 %, and the next swept F0.
    pub unique_up_to_f0: Option<(f64, Option<f64>)>,
    /// Pre-load of the minimum resonance peak (the optimum) per case (N); flag: at a sweep end.
    pub optimum_f0: Vec<(String, f64, bool)>,
    /// F0 values (N) of the fine sweep at which an intermediate peak lies outside the limits.
    pub intermediates_outside_f0: Vec<f64>,
    /// Upper and lower limit peak at the largest F0 of the sweep over the stuck-linear peak.
    pub high_f0_over_stuck: Option<(f64, f64, f64)>,
    /// Resonance frequencies of the two limit curves at the ends of the F0 sweep.
    pub f0_sweep_frequencies: Option<ResonanceEnds>,
    /// β ≥ 90°: FRF variability at a fixed pre-load (Fig. 18a).
    pub beta_high_frf: Vec<BetaRow>,
    /// β ≥ 90°: largest variability over the F0 sweep (Fig. 18b).
    pub beta_high_optimal: Vec<BetaRow>,
    /// β ≤ 90°: FRF variability with blade pre-loads (Fig. 19a).
    pub beta_low_frf: Vec<BetaRow>,
    /// β ≤ 90°: largest variability over the blade pre-load sweep (Fig. 19b).
    pub beta_low_pseudo: Vec<BetaRow>,
    /// Smallest and largest ratio over the blade pre-load per β (Fig. 19b).
    pub beta_low_pseudo_spread: Vec<(f64, f64, f64)>,
    /// Largest ratio of the limit peaks in the F0 sweep at β = 120° (Fig. 16a), and F0 (N).
    pub f0_sweep_max_ratio: Option<(f64, f64)>,
    /// Largest resonance-frequency change in the F0 sweep at β = 120° (Fig. 16d), and F0 (N).
    pub f0_sweep_max_freq_change_pct: Option<(f64, f64)>,
    /// Loops at resonance (Fig. 16c).
    pub loops: Vec<LoopRow>,
    /// Sweep points or figures that failed, one line each.
    pub failures: Vec<String>,
    /// Figures that compute the envelope in the full study but skipped it in this (`--quick`)
    /// run.
    pub envelope_skipped: Vec<String>,
}
