//! Newton at contact transitions between AFT samples: the reduced 2D blade pair with 2 contact
//! pairs per side (the scaling study's `2D r2 p2`, 20 modes) at H = 3 and 128 samples per
//! period. Near 911.86 Hz a stick-slip transition falls between two samples; the corrector
//! stagnates at a relative residual of about 10⁻⁸, far below the AFT's own sampling error there
//! (a floor of about 10⁻⁴). The point is accepted at that floor and marked; its amplitude is
//! that of the 512-sample run within the sampling error measured between the two runs
//! (benches/README.md, "Newton at transitions between samples").

use fricbound::analysis::frf::{self, FrfRun, Silent};
use fricbound::model::{Formulation, JacobianStrategy, Problem};
use fricbound::numerics::continuation::SAMPLING_FLOOR_FRACTION;
use fricbound::numerics::PathEnd;
use fricbound::study::scaling::{self, ModelSize, SolverConfig};

/// Relative difference of the amplitude between the 128- and 512-sample runs allowed at a point
/// accepted at the floor: the difference measured there is 1.0·10⁻⁴ (dense) ; ordinary points
/// of the same runs differ by a median of 2·10⁻⁴ and 4·10⁻⁴ between 910 and 914 Hz.
const SAMPLING_AGREEMENT: f64 = 1e-3;

fn blade_pair(samples: usize) -> Problem {
    let dir = tempfile::tempdir().unwrap();
    let size = ModelSize {
        three_d: false,
        refine: 2,
        contact_refine: 1,
        contact_pairs: Some(2),
    };
    let reduced = scaling::reduced_problem(size, 20, dir.path()).unwrap();
    let config = SolverConfig {
        harmonics: 3,
        formulation: Formulation::Auto,
        jacobian: JacobianStrategy::Analytic,
        m: 1.0,
    };
    let mut p = config.apply(&reduced);
    p.samples = samples;
    p.analysis.continuation.max_points = 1500;
    p
}

fn run(samples: usize) -> FrfRun {
    frf::solve(&blade_pair(samples), &mut Silent).unwrap()
}

/// The 128-sample FRF crosses the whole 700-1000 Hz window, through the transition near
/// 911.86 Hz; the points accepted at the floor are marked with it, their residual is above the
/// tolerance and at most the stated fraction of the floor, and their amplitude is the
/// 512-sample run's at the same frequency.
#[test]
fn the_blade_pair_passes_the_transition_between_samples_at_128_samples() {
    let coarse = run(128);
    assert_eq!(coarse.end, PathEnd::EndFrequency);
    let at_floor: Vec<_> = coarse
        .points
        .iter()
        .filter(|p| p.sampling_floor.is_some())
        .collect();
    assert!(!at_floor.is_empty(), "no point was accepted at the floor");
    let fine = run(512);
    assert_eq!(fine.end, PathEnd::EndFrequency);
    for p in at_floor {
        let floor = p.sampling_floor.unwrap();
        assert!(
            p.residual > 1e-10 && p.residual <= SAMPLING_FLOOR_FRACTION * floor,
            "{} Hz: residual {:e}, floor {floor:e}",
            p.freq_hz,
            p.residual
        );
        let difference = fine
            .crossings(p.freq_hz, 0)
            .iter()
            .map(|c| (c.amplitude - p.amplitudes[0]).abs() / p.amplitudes[0])
            .fold(f64::INFINITY, f64::min);
        assert!(
            difference <= SAMPLING_AGREEMENT,
            "{} Hz: amplitude {:e} differs from the 512-sample run's by {difference:e}",
            p.freq_hz,
            p.amplitudes[0]
        );
    }
}
