//! Two-point limit method on the paper case (§4.2-4.3), labels, bounds and sweeps.

use fricbound::contact::ContactState;
use fricbound::limits::{self, LimitCase, LimitLabel, LimitSettings, Regime};
use fricbound::model::Problem;
use fricbound::reference::paper_wedge_scene;
use fricbound::scene::{self, SweepOutput, SweepSpec, SweepTarget};
use fricbound::sweep;

fn overrides(lo: f64, hi: f64, extra: &[String]) -> Vec<String> {
    let mut o = vec![
        format!("analysis.freq_start_hz={lo}"),
        format!("analysis.freq_end_hz={hi}"),
        "analysis.max_step=0.1".to_string(),
    ];
    o.extend(extra.iter().cloned());
    o
}

fn paper(lo: f64, hi: f64, extra: &[String]) -> Problem {
    scene::parse(paper_wedge_scene(), "paper", &overrides(lo, hi, extra))
        .unwrap()
        .validate("paper")
        .unwrap()
}

/// Contact angles for apical angle β (damper-face frames, normal from damper into blade).
fn beta(b: f64) -> Vec<String> {
    vec![
        format!("contacts.0.angle_deg={}", 90.0 + b / 2.0),
        format!("contacts.1.angle_deg={}", 270.0 - b / 2.0),
    ]
}

fn preload(f0: f64) -> String {
    format!("static_loads.0.value={}", -f0)
}

fn settings(intermediate: &[f64]) -> LimitSettings {
    LimitSettings {
        intermediate: intermediate.to_vec(),
        grid_points: 61,
        bound_scan: vec![],
        ..LimitSettings::default()
    }
}

#[test]
fn limit_peaks_agree_at_the_2nd_resonance_and_differ_at_the_3rd() {
    let second = paper(150.0, 175.0, &[]);
    let peaks: Vec<_> = limits::two_point_cases(&second)
        .iter()
        .map(|c| limits::solve_case(&second, c, None).unwrap().peak)
        .collect();
    let rel = (peaks[0].amplitude - peaks[1].amplitude).abs() / peaks[0].amplitude;
    assert!(peaks[0].refined && peaks[1].refined);
    assert!(rel < 1e-5, "2nd resonance: limit peaks differ by {rel:.2e}");

    let third = paper(200.0, 235.0, &[]);
    let peaks: Vec<_> = limits::two_point_cases(&third)
        .iter()
        .map(|c| limits::solve_case(&third, c, None).unwrap().peak)
        .collect();
    let (hi, lo) = (
        peaks[0].amplitude.max(peaks[1].amplitude),
        peaks[0].amplitude.min(peaks[1].amplitude),
    );
    assert!(
        hi > 1.2 * lo,
        "3rd resonance: limit peaks {hi:.4e} and {lo:.4e} are not 20 % apart"
    );
    for p in &peaks {
        assert!(
            p.states.contains(&ContactState::Stuck) && p.states.contains(&ContactState::StickSlip)
        );
    }
}

#[test]
fn intermediate_peaks_lie_between_the_limit_peaks_at_high_preloads() {
    for f0 in [130.0, 400.0] {
        let problem = paper(195.0, 240.0, &[preload(f0)]);
        let limit_peaks: Vec<f64> = limits::two_point_cases(&problem)
            .iter()
            .map(|c| {
                limits::solve_case(&problem, c, None)
                    .unwrap()
                    .peak
                    .amplitude
            })
            .collect();
        let (hi, lo) = (
            limit_peaks[0].max(limit_peaks[1]),
            limit_peaks[0].min(limit_peaks[1]),
        );
        for m in [-0.5, 0.0, 0.5] {
            let peak = limits::solve_case(&problem, &LimitCase::uniform(&problem, m), None)
                .unwrap()
                .peak;
            let slack = 1e-6 * hi;
            assert!(
                peak.amplitude <= hi + slack && peak.amplitude >= lo - slack,
                "F0 = {f0} N, m = {m}: peak {:.6e} outside [{lo:.6e}, {hi:.6e}]",
                peak.amplitude
            );
        }
    }
}

#[test]
fn labels_agree_with_the_static_balance_of_the_damper() {
    let problem = paper(200.0, 235.0, &[]);
    let analysis = limits::analyse(&problem, &settings(&[]), |_| {}).unwrap();
    let (kd, f0) = (3.0e5, 120.0);
    let frames: Vec<((f64, f64), (f64, f64))> = [150.0f64, 210.0]
        .iter()
        .map(|a| {
            let r = a.to_radians();
            ((r.cos(), r.sin()), (-r.sin(), r.cos()))
        })
        .collect();
    let mut checked = 0;
    for g in &analysis.grid {
        let Regime::Multiple {
            stuck_sides,
            slipping_sides,
        } = &g.regime
        else {
            continue;
        };
        assert_eq!((stuck_sides.len(), slipping_sides.len()), (1, 1));
        let (k, s) = (stuck_sides[0], slipping_sides[0]);
        // Slipping side's N⁰ from the damper's static balance (Eq. 11 with K_D): the slipping
        // side carries F0 − K_D q_D − (stuck side's force), projected on its normal.
        let mut n0 = Vec::new();
        for (c, curve) in analysis.limits.iter().enumerate() {
            let p = curve.case.apply(&problem);
            let x = fricbound::frf::interpolate_on_path(&curve.run.points, g.freq_hz).unwrap();
            let mut solver = fricbound::frf::PointSolver::new(&p).unwrap();
            let point = solver.solve(&x, g.freq_hz).unwrap();
            let q0 = &point.coefficients[0..6];
            let (xd, yd) = (q0[4], q0[5]);
            let st = &g.statics[c];
            let ((tx, ty), (nx, ny)) = frames[k];
            let fx = -kd * (xd - yd) - (tx * st[k].tangential + nx * st[k].normal);
            let fy = -kd * (yd - xd) - f0 - (ty * st[k].tangential + ny * st[k].normal);
            // The contact pushes the damper along −(t T + n N): N_s = −n_s · (remaining force).
            let (_, (sx, sy)) = frames[s];
            let from_balance = fx * sx + fy * sy;
            let from_aft = st[s].normal;
            assert!(
                (from_balance - from_aft).abs() < 1e-6 * f0,
                "{} Hz, case {c}: N0 from balance {from_balance} vs AFT {from_aft}",
                g.freq_hz
            );
            n0.push(from_aft);
        }
        let max_case = if n0[0] > n0[1] { 0 } else { 1 };
        assert_eq!(
            g.labels[max_case],
            Some(LimitLabel::MaxNormalClosestToStuck),
            "{} Hz",
            g.freq_hz
        );
        assert_eq!(
            g.labels[1 - max_case],
            Some(LimitLabel::MinNormalClosestToFree),
            "{} Hz",
            g.freq_hz
        );
        checked += 1;
    }
    assert!(checked > 10, "only {checked} multiple-solution points");
}

fn widest_band(b: f64) -> f64 {
    let problem = paper(195.0, 250.0, &beta(b));
    let analysis = limits::analyse(&problem, &settings(&[]), |_| {}).unwrap();
    analysis
        .grid
        .iter()
        .filter(|g| g.upper.is_finite())
        .map(|g| g.upper - g.lower)
        .fold(0.0, f64::max)
}

#[test]
fn flat_damper_band_is_far_narrower_and_beta_90_is_widest() {
    let widths: Vec<(f64, f64)> = [90.0, 120.0, 150.0, 180.0]
        .iter()
        .map(|&b| (b, widest_band(b)))
        .collect();
    let w = |b: f64| widths.iter().find(|x| x.0 == b).unwrap().1;
    assert!(
        w(180.0) < 0.1 * w(120.0),
        "flat {:.3e} vs 120° {:.3e}",
        w(180.0),
        w(120.0)
    );
    for &(b, width) in &widths {
        if b != 90.0 {
            assert!(
                w(90.0) > width,
                "β = 90° band {:.3e} not wider than β = {b}° {width:.3e}",
                w(90.0)
            );
        }
    }
}

#[test]
fn sweeps_are_identical_with_one_and_two_threads() {
    let spec = SweepSpec {
        parameter: "F0".into(),
        unit: "N".into(),
        values: vec![60.0, 120.0, 250.0],
        targets: vec![SweepTarget {
            field: "static_loads.0.value".into(),
            scale: -1.0,
            offset: 0.0,
        }],
        output: SweepOutput::Peaks,
        series: None,
    };
    let mut text = paper_wedge_scene().to_string();
    text.push_str("\n[limits]\nintermediate = [0.0]\n");
    let o = overrides(200.0, 235.0, &[]);
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| sweep::run(&text, "paper", &o, &spec, |_| {}).unwrap())
    };
    let one = run(1);
    let two = run(2);
    assert_eq!(one, two);
    assert_eq!(one.len(), 3);
    assert_eq!(one[0].cases, vec!["m+1", "m-1", "m0"]);
}
