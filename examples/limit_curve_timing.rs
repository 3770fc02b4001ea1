//! Times one limit curve (m = +1 on every contact point) of the reduced blade pair with many
//! contact pairs per side: `cargo run --release --example limit_curve_timing -- [contact_refine]
//! [H] [max_points] [chord_min_unknowns] [fd] [formulation]` (defaults 8, 3, 150, the library
//! default, 0, auto; `fd` = 1 for forward differences; formulation `auto`, `dense`, `sparse`,
//! `condensed`, `schur` or `schur-lowrank`). The scaling study (`fricbound bench scaling`) measures the same
//! case among others.

use fricbound::model::{Formulation, JacobianStrategy};
use fricbound::study::scaling::{self, ModelSize, SolverConfig};

fn main() {
    let raw: Vec<String> = std::env::args().skip(1).collect();
    let formulation = match raw.get(5).map(String::as_str) {
        None | Some("auto") => Formulation::Auto,
        Some("dense") => Formulation::Dense,
        Some("sparse") => Formulation::Sparse,
        Some("condensed") => Formulation::Condensed,
        Some("schur") => Formulation::Schur,
        Some("schur-lowrank") => Formulation::SchurLowRank,
        Some(other) => panic!("unknown formulation `{other}`"),
    };
    let args: Vec<usize> = raw
        .iter()
        .take(5)
        .map(|a| a.parse().expect("integer arguments"))
        .collect();
    let arg = |i: usize, default: usize| args.get(i).copied().unwrap_or(default);
    let size = ModelSize {
        three_d: false,
        refine: 2,
        contact_refine: arg(0, 8),
        contact_pairs: None,
    };
    let dir = tempfile::tempdir().expect("temporary folder");
    let reduced = scaling::reduced_problem(size, 20, dir.path()).expect("reduced model");
    let config = SolverConfig {
        harmonics: arg(1, 3),
        formulation,
        jacobian: if arg(4, 0) == 1 {
            JacobianStrategy::ForwardDifference
        } else {
            JacobianStrategy::Analytic
        },
        m: 1.0,
    };
    let mut p = config.apply(&reduced);
    p.analysis.continuation.chord_min_unknowns = arg(3, fricbound::model::CHORD_MIN_UNKNOWNS);
    p.analysis.continuation.max_points = arg(2, 150);
    let m = scaling::measure_solve(&size.label(), &p, &config, true).expect("measured");
    println!(
        "{}: {} pairs/side, H = {}, {} unknowns ({}, {}): one iteration {:.1} ms; {} points in {:.2} s, {:.1} ms per point, {} iterations",
        m.case,
        m.pairs_per_side,
        m.harmonics,
        m.unknowns,
        m.formulation,
        m.jacobian,
        m.iteration_ms,
        m.points,
        m.frf_s,
        m.per_point_ms,
        m.iterations
    );
}
