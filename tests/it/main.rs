//! The integration tests, one binary with a module per subject: each integration test file
//! would otherwise be a crate of its own that links the whole library and instantiates its
//! generic code again (52 binaries took most of a cold `cargo test`). `tests/interrupt.rs`
//! stays a binary of its own: its stop request is process-wide and would stop the runs of
//! the tests here. Helpers shared by several modules: [`support`] (running the binary,
//! reading what it wrote), [`common`] (scenes, references and comparisons) and
//! [`fe_support`] (FE test meshes). Proptest keeps the failing cases it found, which every run
//! tries first, in `tests/proptest-regressions/`, a file per source file (`<module>.txt`, or
//! `<module>/<file>.txt` for a module in a folder).

mod common;
mod fe_support;
mod support;

mod aft_jenkins;
mod aft_jenkins_2d;
mod architecture;
mod auto_formulation;
mod blade_pair_3d;
mod chord;
mod cli_run;
mod effects;
mod envelope;
mod envelope_2d;
mod envelope_fe;
mod envelope_verify;
mod error_estimate;
mod error_estimate_fe;
mod estimate_pool;
mod fe_assembly;
mod fe_blade_pair;
mod fe_matrix_market;
mod fe_modes;
mod fe_msh;
mod fe_reduced_vs_full;
mod formulations;
mod friction_2d;
mod hard_cases;
mod limits;
mod limits_unfinished;
mod monodromy;
mod nonlinear_modes;
mod outputs;
mod paper;
mod paper_case;
mod reduction_repeatable;
mod scaling;
mod scene_errors;
mod schur_lowrank;
mod stability;
mod stability_method;
mod stability_sparse;
mod statics_2d;
mod study_accuracy;
mod study_accuracy_modes;
mod study_jacobian;
mod verify;
mod verify_2d;
