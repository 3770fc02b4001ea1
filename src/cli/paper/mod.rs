//! `fricbound paper`: regenerates the data and figures of the paper's §4 study (Figs. 12-19)
//! into one output folder, one sub-folder per figure, and writes `summary.md` (and
//! `summary.json`) with the key numbers computed from the runs next to the paper's statements.
//!
//! The figure scenes are the files `meshes/paper-wedge/fig*.toml`, built into the binary so
//! that the command runs from any folder. `--quick` applies coarser settings (fewer sweep
//! values, a coarser grid and continuation steps, a smaller bound scan) so that the whole study
//! runs in seconds, e.g. in a test; its numbers are coarser, not different in kind.
//!
//! Results are written as each figure finishes, and `summary.md` is rewritten after every
//! figure, so an interrupted run keeps everything finished so far. A figure that fails is
//! reported in the summary and the others still run; the command then ends with an error.
//!
//! The files, lowest first:
//! - `figures`: the study's jobs ([`FigureJob`], [`FIGURES`]), which of them compute the
//!   response envelope over all initial states ([`EnvelopeUse`]: Figs. 13a, 15a, 15b, with
//!   [`ENVELOPE_OVERRIDE`]) and the result of one ([`FigureResult`]);
//! - `numbers`: what the summary reports ([`KeyNumbers`] and its rows), written as
//!   `summary.json`;
//! - `from_runs`: the key numbers computed from the runs ([`key_numbers`]);
//! - `comparison`: the paper's statements, the criteria of agreement ([`Agreement`]) and where
//!   fricbound and the paper differ;
//! - `markdown`: `summary.md` ([`markdown()`]);
//! - `stability`: Hill stability of the 3rd-resonance limit curves without and with damper
//!   damping ([`stability_study`]), a section of `summary.md` and `stability.json`;
//! - `runner`: the command itself ([`paper`], [`PaperOptions`], [`PaperReport`]).

mod comparison;
mod figures;
mod from_runs;
mod markdown;
mod numbers;
mod runner;
mod stability;

pub use comparison::Agreement;
pub use figures::{EnvelopeUse, FigureJob, FigureResult, ENVELOPE_OVERRIDE, FIGURES};
pub use from_runs::{key_numbers, PEAK_TOLERANCE};
pub use markdown::markdown;
pub use numbers::{
    AnalysisRow, BetaRow, BoundRow, EnvelopeRow, KeyNumbers, Located, LoopRow, ResonanceEnds,
    SweepRow,
};
pub use runner::{paper, paper_summary_line, PaperOptions, PaperReport};
pub use stability::{stability_markdown, stability_study, CurveStability, StabilityStudy};
