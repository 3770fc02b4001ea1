//! Studies over many scenes: each varies scene inputs, builds a problem per variant through
//! `crate::scene`, and runs analyses on them.
//!
//! May use `crate::scene`, `crate::analysis` and every layer below. (A study sits above the
//! scene layer because it edits scene fields; an analysis works on one checked problem and
//! never sees a scene.)
//!
//! | module | main types | job |
//! |---|---|---|
//! | [`sweep`] | `SweepPoint`, `run`, `problem_at` | sweeps of any numeric scene field: optimal curves, resonance-frequency limits, limit analyses per value (paper Figs. 15-19) |
//! | [`accuracy`] | `Setting`, `StudyCurve`, `study_curves`, `SettingResult`, `run_settings`, `pareto_front` | what each solver setting (harmonics, samples, tolerance, interior modes, effect switches) costs in time and gives in accuracy against a converged reference, on the FRF or on each limit curve |
//! | [`jacobian`] | `Case`, `measure_case`, `ladder`, `CaseResult` | the analytic Jacobian against finite differences and the formulations side by side (time per residual, Jacobian, Newton iteration and FRF point), with `auto`'s choice marked |
//! | [`contacts`] | `ContactCase`, `measure_case`, `fitted_exponent` | one limit curve of the reduced blade pair against the contact count: time, work, memory (`fricbound bench contacts`) |
//! | [`scaling`] | `ModelSize`, `SolverConfig`, `NewtonIteration` | what FE size, contact count, harmonics and solver strategy cost |

pub mod accuracy;
pub mod contacts;
pub mod jacobian;
pub mod scaling;
pub mod sweep;
