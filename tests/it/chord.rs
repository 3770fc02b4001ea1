//! Chord iterations in the continuation corrector and in fixed-frequency Newton (a factorised
//! Jacobian reused, with Broyden updates, while the residual falls fast enough; on by default
//! only for large problems) trace the same solutions as full Newton: forced on for the paper
//! case around the 3rd resonance, the refined limit peaks (amplitude and frequency, independent
//! of the path's sampling) agree with full Newton to 1e-6 relative, with dense and sparse
//! storage of the Jacobian and with the schur formulation (whose factorisations are also
//! carried from one continuation point to the next and whose chord solves run in single
//! precision), for less effort (a chord step counts a third of a Newton iteration).

use fricbound::analysis::limits;
use fricbound::model::Problem;
use fricbound::scene;
use fricbound::scene::paper_wedge_scene;

fn paper(formulation: &str, chord: bool) -> Problem {
    let overrides = vec![
        "analysis.freq_start_hz=200".to_string(),
        "analysis.freq_end_hz=235".to_string(),
        "analysis.max_step=0.1".to_string(),
        format!("analysis.formulation={formulation}"),
    ];
    let mut p = scene::parse(paper_wedge_scene(), "paper", &overrides)
        .unwrap()
        .validate("paper")
        .unwrap();
    if chord {
        p.analysis.continuation.chord_min_unknowns = 0;
    }
    assert!(p.model.n_dofs() * 3 < fricbound::model::CHORD_MIN_UNKNOWNS);
    p
}

#[test]
fn chord_iterations_give_the_newton_limit_peaks() {
    for formulation in ["dense", "sparse", "schur"] {
        let (newton, chord) = (paper(formulation, false), paper(formulation, true));
        for case in limits::two_point_cases(&newton) {
            let a = limits::solve_case(&newton, &case, None).unwrap();
            let b = limits::solve_case(&chord, &case, None).unwrap();
            let (pa, pb) = (a.peak.as_ref().unwrap(), b.peak.as_ref().unwrap());
            assert!(pa.refined && pb.refined, "{formulation} {}", case.name);
            let da = (pa.amplitude - pb.amplitude).abs() / pa.amplitude;
            let df = (pa.freq_hz - pb.freq_hz).abs() / pa.freq_hz;
            assert!(
                da < 1e-6 && df < 1e-6,
                "{formulation} {}: Newton {:.8e} m at {:.6} Hz, chord {:.8e} m at {:.6} Hz",
                case.name,
                pa.amplitude,
                pa.freq_hz,
                pb.amplitude,
                pb.freq_hz
            );
            let iterations = |c: &limits::CaseCurve| -> usize {
                c.points.iter().map(|p| p.newton_iterations).sum()
            };
            // Chord steps count a third of an iteration: the chord path was taken.
            assert!(
                iterations(&b) < iterations(&a),
                "{formulation} {}: chord {} vs Newton {} iterations",
                case.name,
                iterations(&b),
                iterations(&a)
            );
        }
    }
}
