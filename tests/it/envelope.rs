//! The response envelope over the initial tangential states (`[limits] envelope`): the
//! sensitivity dA/dm of the implicit-function theorem against central differences of solved
//! amplitudes in every contact regime, and the optimised envelope against a dense scan of
//! m per side on the paper case (`meshes/paper-wedge/fig13-3rd.toml`).

use crate::common;
use crate::support;

use common::envelope::limit_seeds;
use common::scenes::load;

use fricbound::analysis::frf::PointSolver;
use fricbound::analysis::limits::{
    self, amplitude_sensitivity, envelope_at, EnvelopeMode, EnvelopeSeeds, LimitCase,
};
use fricbound::contact::aft::AftWorkspace;
use fricbound::contact::harmonic::HarmonicSet;
use fricbound::contact::{ContactEffects, ContactState, JenkinsLaw, NormalLoad};
use fricbound::model::Problem;
use std::f64::consts::PI;
use std::path::Path;

/// The scene of Figs. 13-14 (β = 120°, F0 = 120 N, 200-235 Hz), with overrides.
fn fig13(extra: &[&str]) -> Problem {
    load("meshes/paper-wedge/fig13-3rd.toml", extra)
}

/// The case with m per side.
fn per_side(problem: &Problem, m: &[f64]) -> LimitCase {
    LimitCase::per_side(problem, m)
}

/// Newton at m per side from x0, walked from m0 in steps of m when the direct solve fails:
/// (first output's amplitude, full coefficients, contact states).
fn solve_at(
    problem: &Problem,
    m0: &[f64],
    x0: &[f64],
    m: &[f64],
    freq_hz: f64,
) -> Option<(f64, Vec<f64>, Vec<ContactState>)> {
    for steps in [1usize, 4, 16] {
        let mut x = x0.to_vec();
        let mut last = None;
        for s in 1..=steps {
            let t = s as f64 / steps as f64;
            let mi: Vec<f64> = m0.iter().zip(m).map(|(a, b)| a + t * (b - a)).collect();
            let p = per_side(problem, &mi).apply(problem);
            let mut solver = PointSolver::new(&p).ok()?;
            match solver.solve(&x, freq_hz) {
                Ok(point) => {
                    x = point.coefficients.clone();
                    last = Some((point.amplitudes[0], point.coefficients, point.states));
                }
                Err(_) => {
                    last = None;
                    break;
                }
            }
        }
        if last.is_some() {
            return last;
        }
    }
    None
}

/// dA/dm per side at m from the implicit-function theorem, with the amplitude and states.
fn analytic(problem: &Problem, m: &[f64], x: &[f64], freq_hz: f64) -> (Vec<f64>, Vec<bool>) {
    let (_, groups) = EnvelopeMode::Sides.groups(problem);
    let p = per_side(problem, m).apply(problem);
    let mut solver = PointSolver::new(&p).unwrap();
    let s = amplitude_sensitivity(solver.system(), x, 2.0 * PI * freq_hz, &groups).unwrap();
    (s.gradient[0].clone(), s.active)
}

/// Checks dA/dm against central differences (step h in m) at m per side, from the limit
/// state `(m0, x0)`; returns the states at m and the analytic gradient.
fn check_regime(
    problem: &Problem,
    seed: &(Vec<f64>, Vec<f64>),
    m: &[f64],
    freq_hz: f64,
) -> (Vec<ContactState>, Vec<f64>) {
    let (a, x, states) = solve_at(problem, &seed.0, &seed.1, m, freq_hz)
        .unwrap_or_else(|| panic!("no solution at m = {m:?}, {freq_hz} Hz"));
    let (gradient, active) = analytic(problem, m, &x, freq_hz);
    let h = 1e-4;
    for g in 0..m.len() {
        let shifted = |d: f64| {
            let mut mm = m.to_vec();
            mm[g] += d;
            solve_at(problem, m, &x, &mm, freq_hz).unwrap().0
        };
        let cd = (shifted(h) - shifted(-h)) / (2.0 * h);
        let err = (gradient[g] - cd).abs();
        assert!(
            err <= 1e-3 * cd.abs() + 1e-7 * a,
            "{freq_hz} Hz, m = {m:?}, side {g}: dA/dm {:.6e} (IFT) vs {cd:.6e} (central \
             differences), states {states:?}",
            gradient[g]
        );
        // A side whose m does not act has an exactly zero gradient.
        if !active[g] {
            assert_eq!(gradient[g], 0.0);
        }
    }
    (states, gradient)
}

#[test]
fn sensitivity_matches_central_differences_in_every_regime() {
    let problem = fig13(&[]);
    let freqs = [205.0, 215.0, 222.0];
    let seeds = limit_seeds(&problem, &freqs);
    // Stuck: both sides stuck at 205 Hz; m moves the static forces only, and the response of
    // the stuck (linear) system does not move.
    let (states, g) = check_regime(&problem, &seeds[0][1], &[-0.3, 0.4], 205.0);
    assert_eq!(states, vec![ContactState::Stuck; 2]);
    assert!(g.iter().all(|v| v.abs() < 1e-9), "{g:?}");
    // Multiple-solution regime: left stuck, right slips; dA/dm_left is large, dA/dm_right = 0.
    let (states, g) = check_regime(&problem, &seeds[1][1], &[-0.6, 0.3], 215.0);
    assert_eq!(states, vec![ContactState::Stuck, ContactState::StickSlip]);
    assert!(g[0].abs() > 1e-7 && g[1] == 0.0, "{g:?}");
    // Slip and lift-off: a light pre-load (F0 = 15 N). At 204 Hz the left side slips and
    // lifts off, the right side slips; at 212 Hz the right side is open all period.
    let light = fig13(&["static_loads.0.value=-15"]);
    let seeds = limit_seeds(&light, &[204.0, 212.0]);
    for (i, f) in [204.0, 212.0].into_iter().enumerate() {
        let (states, g) = check_regime(&light, &seeds[i][0], &[0.5, -0.5], f);
        assert!(!states.contains(&ContactState::Stuck), "{f} Hz: {states:?}");
        let expected = if i == 0 {
            [ContactState::StickSlipLiftoff, ContactState::StickSlip]
        } else {
            [ContactState::StickSlipLiftoff, ContactState::Open]
        };
        assert_eq!(states, expected, "{f} Hz");
        assert_eq!(g, vec![0.0, 0.0], "{f} Hz: no stuck side, m has no effect");
    }
}

/// Largest and smallest first-output amplitude over a dense scan of `values` m per side (all
/// combinations) on the square of half-width `half` around `centre` (cut to [−1, 1]), solved in
/// a raster from the m = −1 limit state, and the m attaining them.
fn dense_scan(
    problem: &Problem,
    seeds: &[(Vec<f64>, Vec<f64>)],
    freq_hz: f64,
    values: usize,
    centre: [f64; 2],
    half: f64,
) -> ((f64, Vec<f64>), (f64, Vec<f64>)) {
    let axis = |c: f64| -> Vec<f64> {
        (0..values)
            .map(|i| (c - half + 2.0 * half * i as f64 / (values - 1) as f64).clamp(-1.0, 1.0))
            .collect()
    };
    let (ms, ms_right) = (axis(centre[0]), axis(centre[1]));
    let start = seeds
        .iter()
        .find(|s| s.0 == vec![-1.0, -1.0])
        .expect("the m = -1 limit state");
    let (mut max, mut min) = ((f64::NEG_INFINITY, vec![]), (f64::INFINITY, vec![]));
    let mut row_start = (start.0.clone(), start.1.clone());
    for &left in &ms {
        let mut prev = row_start.clone();
        for (j, &right) in ms_right.iter().enumerate() {
            let m = vec![left, right];
            let (a, x, _) = solve_at(problem, &prev.0, &prev.1, &m, freq_hz)
                .or_else(|| {
                    seeds
                        .iter()
                        .find_map(|s| solve_at(problem, &s.0, &s.1, &m, freq_hz))
                })
                .unwrap_or_else(|| panic!("scan: no solution at m = {m:?}, {freq_hz} Hz"));
            if a > max.0 {
                max = (a, m.clone());
            }
            if a < min.0 {
                min = (a, m.clone());
            }
            prev = (m, x);
            if j == 0 {
                row_start = prev.clone();
            }
        }
    }
    (max, min)
}

#[test]
fn optimised_envelope_equals_a_dense_scan_on_the_paper_case() {
    let problem = fig13(&[]);
    let (_, groups) = EnvelopeMode::Sides.groups(&problem);
    let freqs = [205.0, 213.0, 215.0, 220.0];
    let seeds = limit_seeds(&problem, &freqs);
    for (f, s) in freqs.iter().zip(&seeds) {
        let point = envelope_at(
            &problem,
            &groups,
            *f,
            &EnvelopeSeeds {
                states: s.clone(),
                starts: Vec::new(),
            },
            &limits::envelope::search_settings(),
        );
        let (hi, lo) = (
            point.max[0].as_ref().unwrap(),
            point.min[0].as_ref().unwrap(),
        );
        // 41 × 41 over the box, then 41 × 41 over the cell around each extreme (spacing
        // 0.0025): the envelope's maximum can sit at the edge of a stuck range (beyond it the
        // side slips and the response drops), which one pass at spacing 0.05 cannot resolve.
        let (coarse_hi, coarse_lo) = dense_scan(&problem, s, *f, 41, [0.0, 0.0], 1.0);
        let zoom = |m: &[f64]| [m[0], m[1]];
        let (scan_hi, _) = dense_scan(&problem, s, *f, 41, zoom(&coarse_hi.1), 0.05);
        let (_, scan_lo) = dense_scan(&problem, s, *f, 41, zoom(&coarse_lo.1), 0.05);
        let scan_hi = if coarse_hi.0 > scan_hi.0 {
            coarse_hi
        } else {
            scan_hi
        };
        let scan_lo = if coarse_lo.0 < scan_lo.0 {
            coarse_lo
        } else {
            scan_lo
        };
        let limit_hi = s
            .iter()
            .map(|(_, x)| limits_amplitude(&problem, x))
            .fold(f64::NEG_INFINITY, f64::max);
        println!(
            "{f} Hz: envelope max {:.6e} at m {:?}, min {:.6e} at m {:?} ({} solves); 41x41 scan \
             max {:.6e} at {:?}, min {:.6e} at {:?}; upper limit {:.6e} (envelope {:+.3} %)",
            hi.amplitude,
            hi.m,
            lo.amplitude,
            lo.m,
            point.solves,
            scan_hi.0,
            scan_hi.1,
            scan_lo.0,
            scan_lo.1,
            limit_hi,
            100.0 * (hi.amplitude / limit_hi - 1.0)
        );
        for (what, e, s) in [
            ("max", hi.amplitude, scan_hi.0),
            ("min", lo.amplitude, scan_lo.0),
        ] {
            assert!(
                ((e - s) / s).abs() <= 1e-3,
                "{f} Hz: envelope {what} {e:.6e} vs dense scan {s:.6e}"
            );
        }
        // The optimiser is not beaten by the scan by more than rounding.
        assert!(hi.amplitude >= scan_hi.0 * (1.0 - 1e-6));
        assert!(lo.amplitude <= scan_lo.0 * (1.0 + 1e-6));
    }
}

/// The envelope reuses one point solver for every m and frequency of a stretch
/// (`HbmSystem::set_initial_states`): each solve and sensitivity must equal, bit for bit, those of
/// a solver built afresh for the problem with that m, whatever was solved before with the
/// reused one (m in both regimes, both directions, two frequencies).
#[test]
fn reused_solver_equals_a_fresh_solver_for_every_m() {
    let problem = fig13(&[]);
    let (_, groups) = EnvelopeMode::Sides.groups(&problem);
    let freqs = [213.0, 215.0];
    let seeds = limit_seeds(&problem, &freqs);
    let mut reused = PointSolver::new(&problem).unwrap();
    let ms: [[f64; 2]; 5] = [
        [1.0, 1.0],
        [-0.6, 0.3],
        [-1.0, -1.0],
        [0.2, -0.8],
        [-0.6, 0.3],
    ];
    let mut compared = 0;
    for (f, s) in freqs.iter().zip(&seeds) {
        let omega = 2.0 * PI * f;
        for m in &ms {
            let x0 = &s[0].1;
            let case = per_side(&problem, m);
            let p = case.apply(&problem);
            let mut fresh = PointSolver::new(&p).unwrap();
            let expected = fresh.solve(x0, *f);
            reused.system().set_initial_states(&case.contact_states);
            let got = reused.solve(x0, *f);
            match (expected, got) {
                (Ok(e), Ok(g)) => {
                    assert_eq!(e, g, "{f} Hz, m = {m:?}: reused solver differs");
                    let se = amplitude_sensitivity(fresh.system(), &e.coefficients, omega, &groups)
                        .unwrap();
                    let sg =
                        amplitude_sensitivity(reused.system(), &g.coefficients, omega, &groups)
                            .unwrap();
                    assert_eq!(se, sg, "{f} Hz, m = {m:?}: sensitivity differs");
                    compared += 1;
                }
                (Err(_), Err(_)) => {}
                (e, g) => panic!("{f} Hz, m = {m:?}: fresh {e:?} vs reused {g:?}"),
            }
        }
    }
    assert!(compared >= 8, "only {compared} states solved");
}

/// First output's first-harmonic amplitude of full coefficients (y2, H = 1 blocks 0, c1, s1).
fn limits_amplitude(problem: &Problem, x: &[f64]) -> f64 {
    let n = problem.model.n_dofs();
    let d = problem.outputs[0];
    x[n + d].hypot(x[2 * n + d])
}

/// A contact regime of the AFT check: name, u amplitude over the stick limit, v amplitude over
/// the mean v, m values, expected state, whether m acts.
type Regime<'a> = (&'a str, f64, f64, &'a [f64], ContactState, bool);

/// ∂T̂/∂m of the AFT (analytic: μN(0) on the mean, zero elsewhere, in the stuck state only)
/// against central differences of the march in m, in every regime of a single contact with
/// variable normal load and lift-off.
#[test]
fn aft_initial_state_derivative_matches_central_differences() {
    let set = HarmonicSet::up_to(2);
    let mut aft = AftWorkspace::new(&set, 256);
    let effects = ContactEffects {
        normal_load: NormalLoad::Variable,
        liftoff: true,
    };
    let (kt, kn, mu) = (3.0e5, 3.0e5, 0.5);
    let n0 = 100.0 / kn;
    // u amplitude relative to the stick limit μN/kₜ, v amplitude relative to the mean v.
    // (name, u amplitude / stick limit, v amplitude / mean v, m values, state, whether m acts).
    let regimes: [Regime; 4] = [
        (
            "stuck",
            0.2,
            0.1,
            &[-0.4, 0.1, 0.35],
            ContactState::Stuck,
            true,
        ),
        // Slips in the first period, then sticks touching μN once a period: m is forgotten.
        (
            "stuck after a transient slip",
            0.2,
            0.3,
            &[-0.4],
            ContactState::Stuck,
            false,
        ),
        (
            "stick-slip",
            3.0,
            0.3,
            &[-0.4, 0.1, 0.35],
            ContactState::StickSlip,
            false,
        ),
        (
            "lift-off",
            3.0,
            1.5,
            &[-0.4, 0.1, 0.35],
            ContactState::StickSlipLiftoff,
            false,
        ),
    ];
    for (name, du, dv, ms, expected, acts) in regimes {
        let q = du * mu * 100.0 / kt;
        // Blocks: constant, cos 1, sin 1, cos 2, sin 2.
        let u = [1e-5, q, 0.3 * q, 0.1 * q, 0.0];
        let v = [n0, 0.5 * dv * n0, dv * n0 * 0.6, 0.0, 0.05 * n0];
        let eval = |aft: &mut AftWorkspace, m: f64| {
            let law = JenkinsLaw {
                kt,
                kn,
                mu,
                initial_state: m,
            };
            let report = aft.evaluate(&law, effects, &u, &v, false).unwrap();
            (aft.t_hat.clone(), report.state, law)
        };
        for &m in ms {
            let (_, state, law) = eval(&mut aft, m);
            assert_eq!(state, expected, "{name}, m = {m}");
            let analytic = aft.initial_state_derivative(&law);
            let h = 1e-6;
            let (tp, _, _) = eval(&mut aft, m + h);
            let (tm, _, _) = eval(&mut aft, m - h);
            for b in 0..tp.len() {
                let cd = (tp[b] - tm[b]) / (2.0 * h);
                let a = if b == 0 { analytic } else { 0.0 };
                assert!(
                    (cd - a).abs() <= 1e-6 * (mu * 100.0),
                    "{name}, m = {m}, block {b}: {a} (analytic) vs {cd} (central differences)"
                );
            }
            assert_eq!(analytic != 0.0, acts, "{name}, m = {m}: {analytic}");
        }
    }
}

#[test]
fn scene_field_is_checked_and_the_run_writes_the_envelope() {
    let path = Path::new("meshes/paper-wedge/fig13-3rd.toml");
    let err = fricbound::scene::load(path, &["limits.envelope=corners".to_string()])
        .and_then(|s| s.validate("fig13-3rd"))
        .map(|_| ())
        .unwrap_err()
        .to_string();
    assert!(err.contains("envelope"), "{err}");

    let out = std::env::temp_dir().join(format!("fricbound-envelope-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let out_text = out.display().to_string();
    let scene_path = support::scene("fig13-3rd.toml");
    let mut args = vec!["run", scene_path.as_str(), "--out", out_text.as_str()];
    for o in [
        "limits.envelope=sides",
        "limits.grid_points=15",
        "limits.bound_scan=[]",
        "limits.intermediate=[]",
        "analysis.freq_start_hz=210",
        "analysis.freq_end_hz=220",
    ] {
        args.extend(["--set", o]);
    }
    let o = support::fricbound(&args);
    assert!(
        o.status.success(),
        "{}\n{}",
        support::text(&o.stdout),
        support::text(&o.stderr)
    );
    let stdout = support::text(&o.stdout);
    assert!(stdout.contains("envelope (2 m per side)"), "{stdout}");
    let (header, rows) = support::csv(&out.join("limits.csv"));
    let cols: Vec<&str> = header.split(',').collect();
    let (lo, hi, upper, lower) = (
        cols.iter()
            .position(|c| *c == "y2_envelope_min_amp")
            .unwrap(),
        cols.iter()
            .position(|c| *c == "y2_envelope_max_amp")
            .unwrap(),
        cols.iter().position(|c| *c == "upper_amp").unwrap(),
        cols.iter().position(|c| *c == "lower_amp").unwrap(),
    );
    assert_eq!(rows.len(), 15);
    for r in &rows {
        let v = |i: usize| r[i].parse::<f64>().unwrap();
        // The limit states are among the states searched: the envelope holds the band.
        assert!(v(hi) >= v(upper) * (1.0 - 1e-9) && v(lo) <= v(lower) * (1.0 + 1e-9));
    }
    let j = support::json(&out.join("limits.json"));
    let e = &j["envelope"];
    assert_eq!(e["mode"], "sides");
    assert_eq!(e["groups"], serde_json::json!(["left", "right"]));
    assert_eq!(e["points"].as_array().unwrap().len(), 15);
    assert_eq!(e["peaks"].as_array().unwrap().len(), 2);
    assert!(e["check"]["max_excess_above"].as_f64().unwrap() > 0.01);
    assert_eq!(j["status"], "complete");
    assert!(out.join("limits_y2.png").exists());
    let _ = std::fs::remove_dir_all(&out);
}
