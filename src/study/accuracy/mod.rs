//! The accuracy study: what each solver setting costs in time and gives in accuracy.
//!
//! One setting at a time is changed from the scene as given: the harmonic set (H = 1 … H, and
//! the odd harmonics 1, 3, … H alone), the AFT
//! samples per period, the Newton residual tolerance, the Craig-Bampton interior modes (scenes
//! with `[reduction]`), and each effect switch (constant normal load, no lift-off, uncoupled
//! statics). Every setting's FRF is compared with a reference: the most refined setting (the
//! largest H with the most samples and the tightest tolerance, and on a reduced scene the most
//! interior modes of the study), whose convergence is checked
//! against the next refinement down (H one step lower): the difference is reported.
//!
//! Per setting: the error of each resonance peak of the first output (refined amplitude and
//! frequency, relative, against the nearest reference peak), the relative L2 error of the
//! first output's amplitude over the range both paths cover ([`curve_l2_error`]), the wall time
//! of the continuation (peak refinement excluded), Newton iterations and unknowns.
//!
//! Limit scenes are studied per limit curve ([`study_curves`]): the two-point method's m = +1
//! and m = −1 on every contact point (paper Eqs. 14-15) and each case the scene gives per damper
//! side or per contact point (`[[limits.cases]]`), each against its own reference (the same
//! case at the most refined setting). The `[limits]` and `[sweep]` tables are removed: a curve
//! is the FRF of the scene with every contact's initial state set from the case.
//!
//! The files: [`settings`](mod@settings) (the settings changed and the curves studied), [`compare`] (errors
//! against the reference and the Pareto front) and [`run`] (running the settings).

mod compare;
mod run;
mod settings;

pub use compare::{curve_l2_error, errors, pareto_front, SettingErrors, SettingResult};
pub use run::{run_setting, run_settings, CurveStudy, StudyError, StudyObserver, StudyPlan};
pub use settings::{base_overrides, load, settings, study_curves, Setting, StudyCurve};
