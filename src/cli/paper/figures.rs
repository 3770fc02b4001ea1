//! The jobs of the paper's §4 study and their results: one [`FigureJob`] per figure (its
//! scene, built into the binary, its coarser `--quick` settings and whether it computes the
//! response envelope), the list [`FIGURES`] in the paper's order, and the [`FigureResult`] of
//! running one.

use crate::cli::context::RunReport;

/// One figure of the study: the scene that computes it and its coarser `--quick` settings.
#[derive(Debug)]
pub struct FigureJob {
    /// Identifier, also the sub-folder name (e.g. `fig16a-d`).
    pub id: &'static str,
    /// Scene file name in `meshes/paper-wedge/`.
    pub scene_file: &'static str,
    /// Scene text (the file, built in).
    pub text: &'static str,
    /// What the figure shows, one line.
    pub caption: &'static str,
    /// `--set` overrides applied with `--quick`.
    pub quick: &'static [&'static str],
    /// Whether the figure's limit analyses also compute the response envelope over all
    /// initial states (one m per damper side), and in which mode of the study.
    pub envelope: EnvelopeUse,
}

/// When a figure computes the response envelope (`[limits] envelope = "sides"`, set by the
/// override [`ENVELOPE_OVERRIDE`]) next to its two-point limits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EnvelopeUse {
    /// Never.
    Off,
    /// In the full study and with `--quick`.
    Always,
    /// In the full study only: with `--quick` it would cost more than a few seconds.
    FullOnly,
}

/// The override that asks a figure's limit analyses for the envelope, one m per damper side.
pub const ENVELOPE_OVERRIDE: &str = "limits.envelope=\"sides\"";

impl FigureJob {
    /// Whether the figure computes the envelope in this mode of the study.
    pub fn computes_envelope(&self, quick: bool) -> bool {
        match self.envelope {
            EnvelopeUse::Off => false,
            EnvelopeUse::Always => true,
            EnvelopeUse::FullOnly => !quick,
        }
    }

    /// The `--set` overrides the study applies to the figure's scene: the envelope when the
    /// figure computes it, then the `--quick` settings.
    pub fn overrides(&self, quick: bool) -> Vec<String> {
        let envelope = self
            .computes_envelope(quick)
            .then(|| ENVELOPE_OVERRIDE.to_string());
        let coarse = self.quick.iter().filter(|_| quick).map(|s| s.to_string());
        envelope.into_iter().chain(coarse).collect()
    }
}

/// Coarser limit-analysis settings for `--quick`.
macro_rules! quick_limits {
    ($($extra:expr),*) => {
        &[
            "limits.grid_points=41",
            "limits.bound_scan=[-0.5, 0.5]",
            "analysis.max_step=0.25",
            $($extra),*
        ]
    };
}

/// The [`FigureJob`] `id` of the scene file `meshes/paper-wedge/<file>`, whose text is built
/// in from that file (so the name and the text cannot disagree).
macro_rules! figure {
    ($id:literal, $file:literal, $caption:literal, $quick:expr) => {
        figure!($id, $file, $caption, $quick, EnvelopeUse::Off)
    };
    ($id:literal, $file:literal, $caption:literal, $quick:expr, $envelope:expr) => {
        FigureJob {
            id: $id,
            scene_file: $file,
            text: include_str!(concat!("../../../meshes/paper-wedge/", $file)),
            caption: $caption,
            quick: $quick,
            envelope: $envelope,
        }
    };
}

/// The figures of the paper's §4, in the paper's order.
pub static FIGURES: [FigureJob; 13] = [
    figure!(
        "fig12",
        "fig12-linear.toml",
        "linear references (contacts open and stuck) over 50-350 Hz, with one nonlinear FRF",
        &["analysis.linear_points=301"]
    ),
    figure!(
        "fig13-2nd",
        "fig13-2nd.toml",
        "limits and contact states around the 2nd resonance, F0 = 120 N (Figs. 13b, 14b)",
        quick_limits!("limits.intermediate=[0.0]")
    ),
    figure!(
        "fig13-3rd",
        "fig13-3rd.toml",
        "limits and contact states around the 3rd resonance, F0 = 120 N (Figs. 13a, 14a)",
        quick_limits!("limits.intermediate=[0.0]"),
        EnvelopeUse::Always
    ),
    figure!(
        "fig15a",
        "fig15a.toml",
        "limits at F0 = 60, 130 and 400 N (Fig. 15a)",
        quick_limits!(),
        EnvelopeUse::Always
    ),
    figure!(
        "fig15b",
        "fig15b.toml",
        "limits and intermediate curves near the optimum, F0 = 60 N (Fig. 15b)",
        quick_limits!(),
        EnvelopeUse::Always
    ),
    figure!(
        "fig16a-d",
        "fig16a-d.toml",
        "optimal-curve and resonance-frequency limits over F0 = 10-500 N (Figs. 16a, 16d)",
        &[
            "sweep.values=[10.0, 20.0, 40.0, 60.0, 130.0, 250.0, 500.0]",
            "analysis.max_step=0.25",
        ]
    ),
    figure!(
        "fig16b",
        "fig16b.toml",
        "limit and intermediate optimal curves near the optimum, F0 = 30-90 N (Fig. 16b)",
        &[
            "sweep.values=[36.0, 44.0, 52.0, 60.0, 68.0]",
            "analysis.max_step=0.25",
        ]
    ),
    figure!(
        "fig16c",
        "fig16c.toml",
        "hysteresis loops at resonance, F0 = 80 N (Fig. 16c)",
        quick_limits!()
    ),
    figure!(
        "fig17",
        "fig17.toml",
        "flat damper (beta = 180 deg): limits and contact states (Fig. 17)",
        quick_limits!("sweep.values=[250.0]")
    ),
    figure!(
        "fig18a",
        "fig18a.toml",
        "variability bands for beta = 90-180 deg (Fig. 18a)",
        quick_limits!()
    ),
    figure!(
        "fig18b",
        "fig18b.toml",
        "optimal-curve limits for beta = 90-180 deg (Fig. 18b)",
        &["sweep.values=[120.0, 400.0]", "analysis.max_step=0.25"]
    ),
    figure!(
        "fig19a",
        "fig19a.toml",
        "variability bands for beta = 30-90 deg with blade pre-loads (Fig. 19a)",
        quick_limits!()
    ),
    figure!(
        "fig19b",
        "fig19b.toml",
        "pseudo-optimal curves over the blade pre-load, beta = 30-90 deg (Fig. 19b)",
        &[
            "sweep.values=[0.0, 500.0, 1000.0]",
            "analysis.max_step=0.25",
        ]
    ),
];

/// The run of one figure.
#[derive(Debug)]
pub struct FigureResult {
    /// The figure.
    pub job: &'static FigureJob,
    /// Its results, or why it failed.
    pub outcome: Result<RunReport, String>,
    /// Wall time (s).
    pub elapsed_s: f64,
}

impl FigureResult {
    /// The results when the figure ran.
    pub fn report(&self) -> Option<&RunReport> {
        self.outcome.as_ref().ok()
    }
}
