//! Dense, sparse, condensed and schur formulations of the harmonic balance solve the same problem:
//! same solutions to solver tolerance, Jacobians that match central differences, and sparse
//! or dense storage of the structural matrices giving the same answers.

use faer::Mat;
use fricbound::analysis::frf::{self, PointSolver, Silent};
use fricbound::hbm::operator::HbmOperator;
use fricbound::hbm::{check_jacobian, HbmSystem};
use fricbound::model::matrix::StructuralMatrix;
use fricbound::model::{Formulation, HarmonicLoad, JacobianStrategy, Problem};
use fricbound::numerics::derivatives::check_operator_jacobian;
use fricbound::numerics::jacobian::Storage;

use crate::common;
use common::points::assert_same_point;
use common::scenes::{paper, problem};

/// The paper system with a flexible tip on each blade DOF: tip masses (0.3 kg) tied to the
/// blade DOFs by springs (4e5 N/m), damped (5 N s/m), excited and observed at the tips. The
/// tips carry no contact, so the condensed formulation eliminates them.
fn with_blade_tips(mut p: Problem) -> Problem {
    let n0 = p.model.n_dofs();
    let n = n0 + 4;
    let (m0, c0, k0) = (
        p.model.mass.to_dense(),
        p.model.damping.to_dense(),
        p.model.stiffness.to_dense(),
    );
    let grow =
        |a: &Mat<f64>| Mat::from_fn(n, n, |i, j| if i < n0 && j < n0 { a[(i, j)] } else { 0.0 });
    let (mut m, mut c, mut k) = (grow(&m0), grow(&c0), grow(&k0));
    for t in 0..4 {
        let (tip, root) = (n0 + t, t);
        m[(tip, tip)] = 0.3;
        c[(tip, tip)] = 5.0;
        let s = 4.0e5;
        k[(tip, tip)] += s;
        k[(root, root)] += s;
        k[(tip, root)] -= s;
        k[(root, tip)] -= s;
    }
    p.model.mass = StructuralMatrix::Dense(m);
    p.model.damping = StructuralMatrix::Dense(c);
    p.model.stiffness = StructuralMatrix::Dense(k);
    for name in ["x1t", "y1t", "x2t", "y2t"] {
        p.model.dof_names.push(name.to_string());
    }
    p.static_load.resize(n, 0.0);
    p.harmonic_loads = p
        .harmonic_loads
        .iter()
        .map(|l| HarmonicLoad {
            dof: n0 + l.dof,
            ..*l
        })
        .collect();
    p.outputs = vec![n0 + 3, 3];
    p
}

fn to_sparse(a: &StructuralMatrix) -> StructuralMatrix {
    StructuralMatrix::sparse_from_triplets(a.n(), &a.triplets())
}

fn sparse_storage(mut p: Problem) -> Problem {
    p.model.mass = to_sparse(&p.model.mass);
    p.model.damping = to_sparse(&p.model.damping);
    p.model.stiffness = to_sparse(&p.model.stiffness);
    p
}

fn with_formulation(mut p: Problem, f: Formulation) -> Problem {
    p.analysis.formulation = f;
    p
}

/// Solves every variant at frequencies along the dense path and compares the coefficients.
fn assert_variants_agree(base: &Problem, variants: &[(&str, Problem)]) {
    let run = frf::solve(base, &mut Silent).unwrap();
    let lo = run.points.first().unwrap().freq_hz;
    let hi = run.points.last().unwrap().freq_hz;
    let mut reference = PointSolver::new(base).unwrap();
    for (name, variant) in variants {
        let mut solver = PointSolver::new(variant).unwrap();
        let mut compared = 0;
        for i in 1..40 {
            let f = lo + (hi - lo) * i as f64 / 40.0;
            let guess = frf::interpolate_on_path(&run.points, f).unwrap();
            let (Ok(a), Ok(b)) = (reference.solve(&guess, f), solver.solve(&guess, f)) else {
                continue;
            };
            assert_same_point(&a, &b, &format!("{name} at {f:.3} Hz"));
            compared += 1;
        }
        assert!(compared >= 30, "{name}: only {compared} points compared");
    }
}

#[test]
fn all_formulations_agree_on_the_paper_case_around_the_3rd_resonance() {
    let base = paper(&[
        "analysis.freq_start_hz=195",
        "analysis.freq_end_hz=245",
        "analysis.formulation=dense",
        "contacts.0.initial_state=0.5",
    ]);
    let variants = [
        (
            "sparse",
            with_formulation(base.clone(), Formulation::Sparse),
        ),
        (
            "condensed",
            with_formulation(base.clone(), Formulation::Condensed),
        ),
        (
            "sparse storage, auto",
            with_formulation(sparse_storage(base.clone()), Formulation::Auto),
        ),
        ("schur", with_formulation(base.clone(), Formulation::Schur)),
    ];
    assert_eq!(variants[2].1.formulation(), Formulation::Sparse);
    assert_variants_agree(&base, &variants);
}

#[test]
fn all_formulations_agree_with_eliminated_linear_dofs_and_three_harmonics() {
    let base = with_blade_tips(paper(&[
        "analysis.freq_start_hz=150",
        "analysis.freq_end_hz=260",
        "harmonics.max=3",
        "analysis.formulation=dense",
    ]));
    let variants = [
        (
            "sparse",
            with_formulation(base.clone(), Formulation::Sparse),
        ),
        (
            "condensed",
            with_formulation(base.clone(), Formulation::Condensed),
        ),
        (
            "condensed, sparse storage",
            with_formulation(sparse_storage(base.clone()), Formulation::Condensed),
        ),
        ("sparse, central differences", {
            let mut p = with_formulation(base.clone(), Formulation::Sparse);
            p.analysis.jacobian = JacobianStrategy::CentralDifference;
            p
        }),
        ("condensed, forward differences", {
            let mut p = with_formulation(base.clone(), Formulation::Condensed);
            p.analysis.jacobian = JacobianStrategy::ForwardDifference;
            p
        }),
        ("schur", with_formulation(base.clone(), Formulation::Schur)),
        (
            "schur, sparse storage",
            with_formulation(sparse_storage(base.clone()), Formulation::Schur),
        ),
        ("schur, forward differences", {
            let mut p = with_formulation(base.clone(), Formulation::Schur);
            p.analysis.jacobian = JacobianStrategy::ForwardDifference;
            p
        }),
        ("schur, central differences", {
            let mut p = with_formulation(base.clone(), Formulation::Schur);
            p.analysis.jacobian = JacobianStrategy::CentralDifference;
            p
        }),
    ];
    assert_variants_agree(&base, &variants);
}

#[test]
fn uncoupled_statics_agree_between_formulations() {
    let base = with_blade_tips(paper(&[
        "analysis.freq_start_hz=195",
        "analysis.freq_end_hz=245",
        "effects.coupling=uncoupled",
        "analysis.formulation=dense",
    ]));
    let variants = [
        ("sparse", sparse_storage(base.clone())),
        (
            "condensed",
            with_formulation(base.clone(), Formulation::Condensed),
        ),
        ("schur", with_formulation(base.clone(), Formulation::Schur)),
    ];
    assert_variants_agree(&base, &variants);
}

#[test]
fn sparse_and_condensed_jacobians_match_central_differences() {
    let base = with_blade_tips(paper(&[
        "analysis.freq_start_hz=150",
        "analysis.freq_end_hz=260",
        "harmonics.max=3",
    ]));
    let run = frf::solve(&base, &mut Silent).unwrap();
    let sparse = with_formulation(sparse_storage(base.clone()), Formulation::Sparse);
    let condensed = with_formulation(base.clone(), Formulation::Condensed);
    let schur = with_formulation(base.clone(), Formulation::Schur);
    let mut checked_slipping = 0;
    let mut sign_ratios = Vec::new();
    for p in run.points.iter().step_by(7) {
        let omega = 2.0 * std::f64::consts::PI * p.freq_hz;
        let mut s = HbmSystem::new(&sparse).unwrap();
        assert_eq!(s.storage(), Storage::Sparse);
        let check = check_jacobian(&mut s, &p.coefficients, omega, 1e-7).unwrap();
        assert!(
            check.relative() < 1e-6,
            "sparse at {:.3} Hz: {:.3e}",
            p.freq_hz,
            check.relative()
        );
        let mut c = HbmOperator::new(&condensed).unwrap();
        let xc = c.restrict(&p.coefficients);
        let check = check_operator_jacobian(&mut c, &xc, omega, 1e-7).unwrap();
        assert!(
            check.relative() < 1e-6,
            "condensed at {:.3} Hz: {:.3e}",
            p.freq_hz,
            check.relative()
        );
        let mut s = HbmSystem::new(&schur).unwrap();
        assert_eq!(s.storage(), Storage::Schur);
        let check = check_jacobian(&mut s, &p.coefficients, omega, 1e-7).unwrap();
        assert!(
            check.relative() < 1e-6,
            "schur at {:.3} Hz: {:.3e}",
            p.freq_hz,
            check.relative()
        );
        sign_ratios.push(schur_solves_match_dense(
            &base,
            &schur,
            &p.coefficients,
            omega,
        ));
        if p.states.iter().any(|s| s.is_unique()) {
            checked_slipping += 1;
        }
    }
    assert!(
        checked_slipping >= 3,
        "only {checked_slipping} slipping states checked"
    );
    // The schur factorisation's determinant sign is the dense one's up to a factor fixed by
    // the change to relative coordinates, at every point (the continuation orients its
    // tangents by it).
    assert!(
        sign_ratios.iter().all(|r| *r == sign_ratios[0]),
        "{sign_ratios:?}"
    );
}

#[test]
fn full_continuation_runs_agree_between_formulations() {
    let base = with_blade_tips(paper(&[
        "analysis.freq_start_hz=195",
        "analysis.freq_end_hz=245",
        "analysis.formulation=dense",
    ]));
    // Paths differ in their steps (the arc length is measured on each formulation's own
    // unknowns), so compare the refined peaks, which do not depend on the sampling.
    let peak = |p: &Problem| {
        let run = frf::solve(p, &mut Silent).unwrap();
        fricbound::analysis::limits::refine_peak(p, &run.points, 0, None)
            .unwrap()
            .expect("a peak inside the range")
            .amplitude
    };
    let dense = peak(&base);
    for f in [
        Formulation::Sparse,
        Formulation::Condensed,
        Formulation::Schur,
    ] {
        let other = peak(&with_formulation(base.clone(), f));
        assert!(
            (other - dense).abs() <= 1e-6 * dense,
            "{f:?}: refined peak {other:.8e} vs dense {dense:.8e}"
        );
    }
}

/// The schur Jacobian at (x, ω) has the dense Jacobian's entries, and its solves (plain and
/// bordered) give the dense solutions. Returns the ratio of the bordered matrices'
/// determinant signs (dense over schur).
fn schur_solves_match_dense(dense: &Problem, schur: &Problem, x: &[f64], omega: f64) -> f64 {
    let mut d = HbmSystem::new(dense).unwrap();
    let mut s = HbmSystem::new(schur).unwrap();
    let n = d.dim();
    let (mut r, mut dw) = (vec![0.0; n], vec![0.0; n]);
    let mut jd = d.new_jacobian();
    let mut js = s.new_jacobian();
    d.residual_and_jacobian(x, omega, &mut r, &mut jd, &mut dw)
        .unwrap();
    s.residual_and_jacobian(x, omega, &mut r, &mut js, &mut dw)
        .unwrap();
    let (a, b) = (jd.to_dense(), js.to_dense());
    let scale = (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .fold(0.0_f64, |m, (i, j)| m.max(a[(i, j)].abs()));
    for i in 0..n {
        for j in 0..n {
            assert!(
                (a[(i, j)] - b[(i, j)]).abs() <= 1e-12 * scale,
                "entry ({i}, {j}): dense {} vs schur {}",
                a[(i, j)],
                b[(i, j)]
            );
        }
    }
    let rhs: Vec<f64> = (0..n).map(|i| ((i * 37 % 11) as f64 - 5.0) * 0.1).collect();
    let xd = jd.solve(&rhs).unwrap();
    let xs = js.solve(&rhs).unwrap();
    let xn = xd.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    for i in 0..n {
        assert!(
            (xd[i] - xs[i]).abs() <= 1e-9 * xn,
            "solve {i}: {} vs {}",
            xd[i],
            xs[i]
        );
    }
    let row: Vec<f64> = (0..=n).map(|i| ((i * 13 % 7) as f64 - 3.0) * 0.2).collect();
    let mut brhs = rhs.clone();
    brhs.push(0.7);
    let col_scale = vec![3.0; n];
    let (yd, sign_d) = jd.solve_bordered(&col_scale, &dw, &row, &brhs).unwrap();
    let (ys, sign_s) = js.solve_bordered(&col_scale, &dw, &row, &brhs).unwrap();
    let yn = yd.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    for i in 0..=n {
        assert!(
            (yd[i] - ys[i]).abs() <= 1e-9 * yn,
            "bordered {i}: {} vs {}",
            yd[i],
            ys[i]
        );
    }
    sign_d.expect("the dense LU's sign") * sign_s.expect("the schur LU's sign")
}

#[test]
fn schur_formulation_refuses_dependent_contact_rows() {
    let mut p = with_blade_tips(paper(&[]));
    let twin = p.contacts[0].clone();
    p.contacts.push(fricbound::contact::ContactPoint {
        name: "twin".into(),
        ..twin
    });
    p.analysis.formulation = Formulation::Schur;
    let err = HbmSystem::new(&p)
        .err()
        .expect("dependent rows are refused");
    assert!(err.to_string().contains("linearly dependent"), "{err}");
    // `auto` does not pick the schur formulation for such a problem.
    p.analysis.formulation = Formulation::Auto;
    p.harmonics = (1..=40).collect();
    assert_ne!(p.formulation(), Formulation::Schur);
}

/// The chain of unit masses with Jenkins elements to ground of the Jacobian study, at H = 5.
fn chain_scene(n: usize, jenkins: usize) -> String {
    fricbound::study::jacobian::chain_scene(n, jenkins, 5)
}

/// `auto` takes, on a dense model, the formulation the cost estimate finds fastest (dense
/// unless another is estimated 1.5 times faster), and says why. A chain of 40 masses with 10
/// Jenkins elements to ground at H = 5 (440 unknowns) was solved dense, and took 62 s where the
/// sparse formulation takes 5.5 s; the paper's system stays dense.
#[test]
fn auto_picks_the_formulation_estimated_fastest() {
    let text = chain_scene(40, 10);
    let chain = problem(&text, &[]);
    assert_eq!(chain.formulation(), Formulation::Sparse);
    let (_, why) = chain.auto_formulation();
    for f in ["dense", "sparse", "condensed"] {
        assert!(why.contains(f), "{why}");
    }
    assert_eq!(paper(&[]).formulation(), Formulation::Dense);
}

/// A Jenkins element to ground with a zero normal direction (constant normal load from its
/// interference) has one relative coordinate: the schur formulation gives it the tangential
/// one alone, and then matches the dense formulation: the same Jacobian entries and solves at
/// converged points, and the same solutions along the path.
#[test]
fn schur_handles_contacts_with_a_zero_normal_direction() {
    let text = chain_scene(12, 3);
    let chain = problem(&text, &[]);
    let dense = with_formulation(chain.clone(), Formulation::Dense);
    let schur = with_formulation(chain, Formulation::Schur);
    // One coordinate per contact and coefficient block (H = 5: 11 blocks).
    assert_eq!(fricbound::hbm::cost::factored_size(&schur), 3 * 11);
    let run = frf::solve(&dense, &mut Silent).unwrap();
    for k in [run.points.len() / 3, 2 * run.points.len() / 3] {
        let point = &run.points[k];
        let omega = 2.0 * std::f64::consts::PI * point.freq_hz;
        schur_solves_match_dense(&dense, &schur, &point.coefficients, omega);
    }
    assert_variants_agree(&dense, &[("schur", schur)]);
}

/// The schur factorisation keeps the per-harmonic elimination of the last ω and reuses it at
/// the same ω: solves on one system at ω₁ (twice, with the contact blocks of two different
/// states), then ω₂, then ω₁ again, equal bit for bit those of a fresh system for each
/// (state, ω), and the reused ones equal the dense solves to round-off.
#[test]
fn schur_reuses_the_elimination_at_a_repeated_frequency_exactly() {
    let base = with_blade_tips(paper(&[
        "analysis.freq_start_hz=195",
        "analysis.freq_end_hz=245",
        "harmonics.max=3",
    ]));
    let run = frf::solve(&base, &mut Silent).unwrap();
    let schur = with_formulation(base.clone(), Formulation::Schur);
    // A point where a contact slips, and one in other contact states.
    let a = run
        .points
        .iter()
        .find(|p| p.states.iter().any(|s| s.is_unique()))
        .expect("a slipping point");
    let b = run
        .points
        .iter()
        .find(|p| p.states != a.states)
        .expect("a point in other states");
    let omega = |f: f64| 2.0 * std::f64::consts::PI * f;
    let n = a.coefficients.len();
    let rhs: Vec<f64> = (0..n).map(|i| ((i * 37 % 11) as f64 - 5.0) * 0.1).collect();
    let solve = |s: &mut HbmSystem, x: &[f64], w: f64| {
        let (mut r, mut dw) = (vec![0.0; n], vec![0.0; n]);
        let mut j = s.new_jacobian();
        s.residual_and_jacobian(x, w, &mut r, &mut j, &mut dw)
            .unwrap();
        j.solve(&rhs).unwrap()
    };
    let mut reused = HbmSystem::new(&schur).unwrap();
    assert_eq!(reused.storage(), Storage::Schur);
    let w1 = omega(a.freq_hz);
    let w2 = omega(b.freq_hz);
    for (x, w) in [
        (&a.coefficients, w1),
        (&b.coefficients, w1),
        (&b.coefficients, w2),
        (&a.coefficients, w1),
    ] {
        let got = solve(&mut reused, x, w);
        let fresh = solve(&mut HbmSystem::new(&schur).unwrap(), x, w);
        assert_eq!(got, fresh, "ω = {w}");
        let dense = solve(&mut HbmSystem::new(&base).unwrap(), x, w);
        let scale = dense.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        for (g, d) in got.iter().zip(&dense) {
            assert!((g - d).abs() <= 1e-9 * scale, "ω = {w}: {g} vs dense {d}");
        }
    }
}
