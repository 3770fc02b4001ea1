//! The scaling study's building blocks on the few-contact end of its ladder (the reduced 2D
//! blade pair with 2 contact pairs per side): configuration grid, unknown counts, the timed
//! Newton iteration and a measured FRF.

use fricbound::model::{Formulation, JacobianStrategy};
use fricbound::study::scaling::{self, ModelSize, NewtonIteration, SolverConfig};

fn two_pairs() -> fricbound::model::Problem {
    let dir = tempfile::tempdir().unwrap();
    let size = ModelSize {
        three_d: false,
        refine: 2,
        contact_refine: 1,
        contact_pairs: Some(2),
    };
    assert_eq!(size.label(), "2D r2 p2");
    scaling::reduced_problem(size, 20, dir.path()).unwrap()
}

#[test]
fn grid_covers_every_formulation_and_jacobian_per_harmonic_count() {
    let grid = SolverConfig::grid(&[1, 3]);
    assert_eq!(grid.len(), 2 * 5 * 2);
    for h in [1, 3] {
        for f in scaling::FORMULATIONS {
            for j in scaling::JACOBIANS {
                assert_eq!(
                    grid.iter()
                        .filter(|c| c.harmonics == h && c.formulation == f && c.jacobian == j)
                        .count(),
                    1
                );
            }
        }
    }
    assert!(grid.iter().all(|c| c.m == 0.0));
}

/// Counted unknowns are those of the operator; the Newton step of one iteration is the same
/// in the dense, sparse and schur formulations (same unknowns), and the condensed one works
/// on the contact DOFs alone.
#[test]
fn newton_iteration_sizes_and_steps_agree_across_formulations() {
    let base = two_pairs();
    assert_eq!(base.contacts.len(), 4, "2 pairs on each of 2 sides");
    let mut reference: Option<Vec<f64>> = None;
    for config in SolverConfig::grid(&[3]) {
        if config.jacobian != JacobianStrategy::Analytic {
            continue;
        }
        let p = config.apply(&base);
        assert_eq!(p.harmonics, vec![1, 2, 3]);
        let mut iteration = NewtonIteration::new(&p, 850.0).unwrap();
        assert_eq!(iteration.unknowns(), scaling::unknowns(&p));
        let blocks = 7;
        let expected_factored = match config.formulation {
            Formulation::Schur | Formulation::SchurLowRank => 2 * 4 * blocks,
            Formulation::Condensed => p.contact_dofs().len() * blocks,
            _ => p.model.n_dofs() * blocks,
        };
        assert_eq!(scaling::factored_size(&p), expected_factored);
        let step = iteration.run().unwrap();
        assert!(step.iter().all(|v| v.is_finite()));
        if config.formulation == Formulation::Condensed {
            assert_eq!(step.len(), p.contact_dofs().len() * blocks);
            continue;
        }
        match &reference {
            None => reference = Some(step),
            Some(r) => {
                let scale = r.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
                let diff = r
                    .iter()
                    .zip(&step)
                    .fold(0.0_f64, |a, (x, y)| a.max((x - y).abs()));
                assert!(
                    diff < 1e-8 * scale,
                    "{}: step differs by {diff:e} (scale {scale:e})",
                    config.label()
                );
            }
        }
    }
}

#[test]
fn measured_frf_reaches_the_window_end() {
    let base = two_pairs();
    let config = SolverConfig {
        harmonics: 1,
        formulation: Formulation::Auto,
        jacobian: JacobianStrategy::Analytic,
        m: 1.0,
    };
    let mut p = config.apply(&base);
    p.analysis.continuation.max_points = 2000;
    let m = scaling::measure_solve("2D r2 p2, reduced", &p, &config, true).unwrap();
    assert_eq!(m.pairs_per_side, 2);
    // `auto` takes the formulation estimated fastest: schur on the reduced blade pair (on the
    // 7-pair scene it was measured 2.3 times faster than dense, the choice of the size rule it
    // replaced).
    assert_eq!(m.formulation, "schur");
    // The path reaches the window's end with every stretch on a branch.
    assert!(m.frf && m.complete, "{m:?}");
    assert!(m.points > 10 && m.points < 2000);
    assert!(m.iterations >= m.points);
    assert!(m.iteration_ms > 0.0 && m.frf_s > 0.0);
}
