//! Test fixtures shared by the unit tests of the 2D AFT's files: the law's constants, a law,
//! coefficients of a motion, and the central-difference check of the Jacobian.

use crate::contact::harmonic::HarmonicSet;
use crate::contact::ContactEffects;
use crate::contact::Jenkins2dLaw;

use super::workspace::Aft2dWorkspace;

pub(super) const KT: f64 = 1.0e5;

pub(super) const KN: f64 = 2.0e5;

pub(super) const MU: f64 = 0.3;

pub(super) fn law(m: [f64; 2]) -> Jenkins2dLaw {
    Jenkins2dLaw {
        kt: KT,
        kn: KN,
        mu: MU,
        initial_state: m,
    }
}

/// Coefficients over `set` from (block index, value) pairs.
pub(super) fn coefficients(set: &HarmonicSet, entries: &[(usize, f64)]) -> Vec<f64> {
    let mut c = vec![0.0; set.n_blocks()];
    for &(j, x) in entries {
        c[j] = x;
    }
    c
}

/// Central differences of the steady-state force coefficients in every regime.
pub(super) fn check_jacobian(effects: ContactEffects, m: [f64; 2], x: [&[f64]; 3], what: &str) {
    let worst = jacobian_mismatch(effects, m, x, what, 1e-6);
    assert!(
        worst < 1e-5,
        "{what}: largest central-difference mismatch {worst:.2e}"
    );
}

/// Largest difference between the analytic force Jacobian and central differences with
/// the step `relative_step` times the largest coefficient, relative to the largest entry
/// (128 samples; the harmonic set follows from the coefficients' length, 2H + 1).
pub(super) fn jacobian_mismatch(
    effects: ContactEffects,
    m: [f64; 2],
    x: [&[f64]; 3],
    what: &str,
    relative_step: f64,
) -> f64 {
    let set = HarmonicSet::up_to((x[0].len() - 1) / 2);
    let nb = set.n_blocks();
    let ns = 128;
    let mut aft = Aft2dWorkspace::new(&set, ns);
    let mut point = [x[0].to_vec(), x[1].to_vec(), x[2].to_vec()];
    let report = aft
        .evaluate(&law(m), effects, [&point[0], &point[1]], &point[2], true)
        .unwrap();
    let analytic = aft.dt_dx.clone();
    let analytic_n = aft.dn_dv.clone();
    let size = analytic.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
    let length = x
        .iter()
        .flat_map(|c| c.iter())
        .fold(0.0_f64, |a, v| a.max(v.abs()));
    let h = relative_step * length;
    let mut worst = 0.0_f64;
    for c in 0..3 * nb {
        let (which, i) = (c / nb, c % nb);
        let mut forces = [vec![0.0; 3 * nb], vec![0.0; 3 * nb]];
        for (s, sign) in [1.0, -1.0].into_iter().enumerate() {
            point[which][i] = x[which][i] + sign * h;
            aft.evaluate(&law(m), effects, [&point[0], &point[1]], &point[2], false)
                .unwrap();
            forces[s][..nb].copy_from_slice(&aft.t_hat[0]);
            forces[s][nb..2 * nb].copy_from_slice(&aft.t_hat[1]);
            forces[s][2 * nb..].copy_from_slice(&aft.n_hat);
        }
        point[which][i] = x[which][i];
        for r in 0..2 * nb {
            let fd = (forces[0][r] - forces[1][r]) / (2.0 * h);
            worst = worst.max((fd - analytic[r * 3 * nb + c]).abs() / size);
        }
        if which == 2 {
            for r in 0..nb {
                let fd = (forces[0][2 * nb + r] - forces[1][2 * nb + r]) / (2.0 * h);
                worst = worst.max((fd - analytic_n[r * nb + i]).abs() / size);
            }
        }
    }
    println!(
        "{what} ({:?}, {} periods): central-difference mismatch {worst:.2e} of {size:.2e} N/m",
        report.state, report.periods
    );
    worst
}

/// Coefficients (H = 1) of a barely loaded point that barely slips: gross slip along t₁
/// by 10⁻⁴ of the stick amplitude, a smaller motion along t₂, variable N. Its slip runs
/// nearly along one direction and the slider's offset across it contracts by only
/// 1 − O(10⁻⁴) per period: I − A is nearly singular at the fixed point.
pub(super) fn barely_slipping_point() -> ([Vec<f64>; 3], f64) {
    // N₀ = kₙ v₀ = 2e-5 N: μN₀/kₜ = 6e-11 m, against 50 N / kₜ = 5e-4 m for a problem.
    let v0 = 1e-10;
    let stick = MU * KN * v0 / KT;
    let a = (1.0 + 1e-4) * stick;
    (
        [
            vec![0.0, a, 0.0],
            vec![0.0, 0.0, 0.3 * a],
            vec![v0, 0.5 * v0, 0.0],
        ],
        MU * KN * v0,
    )
}
