//! Nonlinear modes by EPMC (`analysis::nonlinear_modes`): a linear structure gives its natural
//! frequencies and modal damping ratios, a 1-DOF Jenkins oscillator at H = 1 its
//! describing-function backbone, and the extended Jacobian equals central differences.

use fricbound::analysis::linear::LinearCase;
use fricbound::analysis::modes::damped_modes;
use fricbound::analysis::nonlinear_modes::{
    self, ModeChoice, NonlinearModeRun, NonlinearModeSettings,
};
use fricbound::contact::{jenkins_describing_function, ContactState};
use fricbound::model::Problem;

use crate::common::scenes;
use crate::support;

mod checks;
mod predict;

/// The single-DOF Jenkins oscillator of `docs/scene.md` ([`scenes::JENKINS_OSCILLATOR`]:
/// m = 1 kg, k = 1e4 N/m, c = 2 N·s/m, kₜ = 1e5 N/m, μ = 0.3, N₀ = kₙ·1e-4 m = 10 N constant)
/// at H = 1, solved to a residual of 1e-13.
fn jenkins_oscillator() -> String {
    scenes::JENKINS_OSCILLATOR.replace(
        "freq_end_hz = 40.0\n",
        "freq_end_hz = 40.0\nresidual_tolerance = 1e-13\n",
    )
}

/// (m, k, c, kₜ, μ, N₀) of [`jenkins_oscillator`].
const JENKINS: (f64, f64, f64, f64, f64, f64) = (1.0, 1.0e4, 2.0, 1.0e5, 0.3, 10.0);

fn settings(mode: ModeChoice, dof: usize, amplitude: [f64; 2]) -> NonlinearModeSettings {
    NonlinearModeSettings {
        mode,
        dof,
        amplitude,
        max_points: 400,
    }
}

fn solve(problem: &Problem, settings: &NonlinearModeSettings) -> NonlinearModeRun {
    let run = nonlinear_modes::solve(problem, settings).unwrap_or_else(|e| panic!("{e}"));
    assert!(run.is_complete(), "{:?}", run.incomplete_reason());
    run
}

/// The describing-function backbone of the oscillator at amplitude A (m): ω² = (k + k_eq)/m
/// and D = (c/m + c_eq/(m ω)) / (2ω), with the first harmonic k_eq A cos τ − c_eq A sin τ of
/// the contact force (paper Appendix, Eqs. 17-18).
fn closed_form(amplitude: f64) -> (f64, f64) {
    let (m, k, c, kt, mu, n0) = JENKINS;
    let (k_eq, c_eq) = jenkins_describing_function(kt, mu, n0, amplitude);
    let omega = ((k + k_eq) / m).sqrt();
    (omega, (c / m + c_eq / (m * omega)) / (2.0 * omega))
}

/// Backbone frequency and modal damping ratio of the Jenkins oscillator equal the closed form
/// to 1e-9 at every point from stuck (A < μN₀/kₜ = 3e-5 m) to near full slip (A = 1e-2 m,
/// μN₀/(kₜA) = 3e-3), with the event-resolved law; the sampled law at 256 samples is off by
/// its sampling error, more than 1e-7 somewhere in slip.
#[test]
fn jenkins_oscillator_backbone_equals_the_describing_function() {
    for (law, tolerance) in [("jenkins-1d", 1e-9), ("jenkins-1d-sampled", 1e-2)] {
        let overrides = [format!("contacts.0.law=\"{law}\"")];
        let overrides: Vec<&str> = overrides.iter().map(|s| s.as_str()).collect();
        let problem = scenes::problem(&jenkins_oscillator(), &overrides);
        let run = solve(&problem, &settings(ModeChoice::Number(1), 0, [1e-6, 1e-2]));
        assert!(run.points.len() > 20, "{law}: {} points", run.points.len());
        let (mut worst_f, mut worst_d) = (0.0_f64, 0.0_f64);
        let (mut stuck, mut slipping) = (0, 0);
        for p in &run.points {
            // m = 1 kg: ψ = 1, the amplitude at the DOF is the modal amplitude.
            assert!((p.dof_amplitude - p.modal_amplitude).abs() <= 1e-12 * p.modal_amplitude);
            let (omega, d) = closed_form(p.dof_amplitude);
            worst_f = worst_f.max((p.omega - omega).abs() / omega);
            worst_d = worst_d.max((p.damping_ratio - d).abs() / d);
            match p.states[0] {
                ContactState::Stuck => stuck += 1,
                _ => slipping += 1,
            }
        }
        eprintln!(
            "{law}: {} points ({stuck} stuck, {slipping} slipping), largest relative error \
             of the frequency {worst_f:.2e}, of the damping ratio {worst_d:.2e}; {:.3} s",
            run.points.len(),
            run.elapsed_s
        );
        assert!(
            stuck > 2 && slipping > 10,
            "{law}: {stuck} stuck, {slipping} slipping"
        );
        assert!(worst_f < tolerance && worst_d < tolerance, "{law}");
        if law == "jenkins-1d-sampled" {
            assert!(
                worst_d > 1e-7,
                "the sampled law's sampling error: {worst_d:.2e}"
            );
        }
        let last = run.points.last().unwrap();
        assert!((last.dof_amplitude - 1e-2).abs() < 1e-12);
        // At 1e-2 m the contact dissipates 4 μN₀ (A − μN₀/kₜ) per cycle (the hysteresis loop).
        let (_, _, _, kt, mu, n0) = JENKINS;
        let loop_area = 4.0 * mu * n0 * (1e-2 - mu * n0 / kt);
        let e = (last.friction_energy - loop_area).abs() / loop_area;
        assert!(e < tolerance.max(1e-9), "{law}: friction energy {e:.2e}");
    }
}

/// A chain of three masses with a contact that never slips (μN₀ = 1e4 N) and Rayleigh damping
/// of the stuck structure: every nonlinear mode is the linear one at all amplitudes, its
/// frequency the natural frequency |s|/2π and its damping ratio the modal damping ratio of
/// `analysis::modes::damped_modes`, to 1e-9.
#[test]
fn linear_structure_gives_its_modes_and_modal_damping() {
    let (alpha, beta) = (3.0, 2e-5);
    let k = [
        [2.0e4, -1.0e4, 0.0],
        [-1.0e4, 2.0e4, -1.0e4],
        [0.0, -1.0e4, 1.0e4],
    ];
    let m = [1.0, 2.0, 0.5];
    let kt = 5.0e3;
    let rows = |f: &dyn Fn(usize, usize) -> f64| {
        (0..3)
            .map(|i| {
                let r: Vec<String> = (0..3).map(|j| format!("{:e}", f(i, j))).collect();
                format!("[{}]", r.join(", "))
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    let k_stuck = |i: usize, j: usize| k[i][j] + if i == 2 && j == 2 { kt } else { 0.0 };
    let mass = |i: usize, j: usize| if i == j { m[i] } else { 0.0 };
    let scene = format!(
        r#"
[model]
dofs = ["a", "b", "c"]
mass = [{}]
stiffness = [{}]
damping = [{}]

[[contacts]]
name = "ground"
damper = ["c"]
tangent = [1.0]
normal = [0.0]
kt = {kt:e}
kn = 1.0e5
mu = 1.0e3
gap = -1.0e-4

[[harmonic_loads]]
dof = "a"
cos = 1.0

[harmonics]
max = 3

[effects]
normal_load = "constant"

[analysis]
freq_start_hz = 5.0
freq_end_hz = 40.0
residual_tolerance = 1e-13

[output]
dofs = ["a"]
"#,
        rows(&mass),
        rows(&|i, j| k[i][j]),
        rows(&|i, j| alpha * mass(i, j) + beta * k_stuck(i, j)),
    );
    let problem = scenes::problem(&scene, &[]);
    let reference = damped_modes(&problem, LinearCase::Stuck, 3)
        .unwrap()
        .unwrap();
    for (number, linear) in reference.modes.iter().enumerate() {
        let dof = 0;
        let run = solve(
            &problem,
            &settings(ModeChoice::Number(number + 1), dof, [1e-6, 1e-3]),
        );
        for p in &run.points {
            let f = (p.freq_hz - linear.natural_hz).abs() / linear.natural_hz;
            let d = (p.damping_ratio - linear.damping_ratio).abs() / linear.damping_ratio;
            assert!(
                f < 1e-9 && d < 1e-9,
                "mode {}: {f:.2e}, {d:.2e}",
                number + 1
            );
            assert!(p.states.iter().all(|s| *s == ContactState::Stuck));
        }
        // The same mode chosen by its nearest frequency.
        let near = solve(
            &problem,
            &settings(
                ModeChoice::NearestHz(linear.natural_hz * 1.01),
                dof,
                [1e-6, 1e-5],
            ),
        );
        assert_eq!(near.mode, number + 1);
    }
}

/// The extended Jacobian (harmonics, ω, ξ and the log-amplitude column) equals central
/// differences on the Jenkins oscillator at H = 3 in the stuck and stick-slip regimes and on
/// the paper's wedge damper (variable normal load, lift-off) at H = 3.
#[test]
fn extended_jacobian_equals_central_differences() {
    let jenkins = scenes::problem(&jenkins_oscillator(), &["harmonics.max=3"]);
    let paper = scenes::paper(&["harmonics.max=3"]);
    for (name, problem, mode, dof, amplitude) in [
        ("jenkins stuck", &jenkins, 1, 0, [1e-6, 1e-5]),
        ("jenkins slipping", &jenkins, 1, 0, [1e-6, 2e-4]),
        ("paper, 3rd mode", &paper, 3, 3, [1e-7, 1e-4]),
    ] {
        let run = solve(problem, &settings(ModeChoice::Number(mode), dof, amplitude));
        let last = run.points.last().unwrap();
        let free = nonlinear_modes::autonomous(problem);
        let start = nonlinear_modes::linear_start(&free, ModeChoice::Number(mode), dof).unwrap();
        let map = nonlinear_modes::LogAmplitude {
            a_min: run.modal_range[0],
        };
        let mut op =
            nonlinear_modes::EpmcOperator::new(&free, start.statics.clone(), dof, map, 1.0)
                .unwrap();
        let a = last.modal_amplitude;
        let mut y = op.normalised(&last.coefficients, a);
        y.push(last.omega);
        y.push(last.xi);
        let lambda = std::f64::consts::TAU * map.decade(a);
        let check = nonlinear_modes::check_jacobian(&mut op, &y, lambda, 1e-6).unwrap();
        eprintln!(
            "{name}: states {:?}, relative error {:.2e} (linear mode at {:.3} Hz)",
            last.states,
            check.relative(),
            start.omega / std::f64::consts::TAU
        );
        assert!(check.relative() < 1e-6, "{name}: {:.2e}", check.relative());
        if name == "jenkins slipping" {
            assert_eq!(last.states[0], ContactState::StickSlip);
        }
    }
}

/// The shipped nonlinear-mode scene passes `fricbound check`, which names the mode and its
/// linear frequency at rest, and `fricbound run` writes `modes_nl.csv`, `modes_nl.json`
/// (status complete, one case per sign combination per side and the intermediate one), the band
/// and the figures, and exits 0. Every case starts at the linear mode at rest and reaches the
/// highest amplitude asked.
#[test]
fn shipped_scene_checks_and_runs() {
    let scene = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/meshes/paper-wedge/modes-3rd.toml"
    );
    let o = support::fricbound(&["check", scene]);
    assert!(o.status.success(), "{}", support::text(&o.stderr));
    let described = support::text(&o.stdout);
    assert!(
        described.contains("nonlinear mode 3 by EPMC (linear at rest: 225.0791 Hz"),
        "{described}"
    );
    assert!(
        described.contains("range of the linear references, as given"),
        "{described}"
    );
    assert!(
        described.contains("error estimate on every mode point") && !described.contains("beyond"),
        "{described}"
    );
    let dir = tempfile::tempdir().unwrap();
    let o = support::run_scene(scene, dir.path(), &[]);
    assert_eq!(o.status.code(), Some(0), "{}", support::text(&o.stderr));
    let names = support::names(dir.path());
    for f in [
        "modes_nl.csv",
        "modes_nl.json",
        "modes_nl_band.csv",
        "modes_nl_frequency.png",
        "modes_nl_frequency.svg",
        "modes_nl_damping.png",
        "modes_nl_damping.svg",
    ] {
        assert!(names.contains(&f.to_string()), "{f} missing: {names:?}");
    }
    assert!(names.iter().all(|n| !n.ends_with(".vtu")), "{names:?}");
    let json = support::json(&dir.path().join("modes_nl.json"));
    assert_eq!(json["status"], "complete");
    let cases = json["cases"].as_array().unwrap();
    let case_names: Vec<&str> = cases.iter().map(|c| c["name"].as_str().unwrap()).collect();
    assert_eq!(
        case_names,
        ["m+1", "m-1", "left-1_right+1", "left+1_right-1", "m0"]
    );
    for c in cases {
        let points = c["mode"]["points"].as_array().unwrap();
        let first = &points[0];
        let last = points.last().unwrap();
        assert!((first["freq_hz"].as_f64().unwrap() - 225.0791).abs() < 1e-3);
        assert_eq!(c["status"], "complete");
        assert!(
            last["dof_amplitude"].as_f64().unwrap() > 0.9e-3,
            "{}",
            c["name"]
        );
    }
    let (header, rows) = support::csv(&dir.path().join("modes_nl.csv"));
    assert!(header.starts_with("case,modal_amplitude,y2_amp,freq_hz,damping_ratio"));
    assert!(header.ends_with(",freq_trunc_err,damping_trunc_err,y2_amp_trunc_err"));
    assert!(rows.len() > 100);
    for c in cases {
        let largest = &c["largest_trunc_err"];
        assert_eq!(largest["harmonic"], 3, "{}", c["name"]);
        assert!(largest["frequency"].as_f64().unwrap() >= 0.0);
    }
}

/// A nonlinear-mode scene without its mode, with a mode field in an FRF scene, with a reversed
/// amplitude range, an unknown DOF or a mode that does not exist is refused with the field
/// named; a phase DOF at a node of the mode is refused by `check` with the reason.
#[test]
fn bad_mode_fields_are_refused_with_the_field_named() {
    let scene = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/meshes/paper-wedge/modes-3rd.toml"
    );
    for (overrides, expected) in [
        (
            vec!["analysis.kind=\"frf\""],
            "field `analysis.mode`: belongs to a nonlinear-mode analysis",
        ),
        (
            vec!["analysis.amplitude=[1e-3, 1e-7]"],
            "field `analysis.amplitude`: the range is reversed",
        ),
        (
            vec!["analysis.dof=\"z9\""],
            "field `analysis.dof`: unknown DOF `z9`",
        ),
        (
            vec!["analysis.mode=0"],
            "field `analysis.mode`: modes are numbered from 1",
        ),
        (
            vec!["analysis.mode_freq_hz=200.0"],
            "field `analysis.mode_freq_hz`: give the mode by its number",
        ),
        (
            vec!["analysis.mode=9"],
            "mode 9 asked, the structure at rest has 6 elastic modes",
        ),
        (
            vec![
                "sweep={parameter = \"F0\", values = [60.0], output = \"limits\", \
                 targets = [{field = \"static_loads.0.value\", scale = -1.0}]}",
            ],
            "field `sweep.output`: a sweep of nonlinear modes predicts the resonance peaks",
        ),
    ] {
        let mut args = vec!["check", scene];
        for o in &overrides {
            args.extend(["--set", o]);
        }
        let o = support::fricbound(&args);
        let err = support::text(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{overrides:?}: {err}");
        assert!(err.contains(expected), "{overrides:?}: {err}");
    }
}

/// The path runs from the amplitude asked at the DOF to the one asked, not to their
/// conversions with the linear shape at rest: on the paper's 2nd mode (y2, 10⁻⁷ to 10⁻³ m) the
/// first and last points' first-harmonic amplitudes at y2 equal the ends asked to 10⁻⁹
/// relatively at H = 1 and 3, where the high end converted with the linear shape lands 0.9 %
/// and 3.5 % short of 10⁻³ m (its modal amplitude is 0.9 % and 3.7 % below the last point's),
/// and the end point lies on the path between the point before it and the modal amplitude
/// the linear shape would have stopped at. A run whose point budget runs out first says so with
/// the amplitude at the DOF it reached.
#[test]
fn the_path_runs_between_the_amplitudes_asked_at_the_dof() {
    let [low, high] = [1e-7, 1e-3];
    for h in [1, 3] {
        let problem = scenes::paper(&[&format!("harmonics.max={h}"), "accuracy.estimate=false"]);
        let dof = problem.outputs[0];
        let s = settings(ModeChoice::Number(2), dof, [low, high]);
        let run = solve(&problem, &s);
        let free = nonlinear_modes::autonomous(&problem);
        let start = nonlinear_modes::linear_start(&free, ModeChoice::Number(2), dof).unwrap();
        let converted = high / start.shape[dof].abs();
        let (first, last) = (&run.points[0], run.points.last().unwrap());
        let before = &run.points[run.points.len() - 2];
        let shortfall = 1.0 - last.modal_amplitude.recip() * converted;
        eprintln!(
            "H = {h}: {} points, first {:.12e} m, last {:.12e} m at a = {:.6e} (the linear \
             shape's {converted:.6e}, {:.2} % below), point before {:.6e} m",
            run.points.len(),
            first.dof_amplitude,
            last.dof_amplitude,
            last.modal_amplitude,
            100.0 * shortfall,
            before.dof_amplitude
        );
        assert!((first.dof_amplitude - low).abs() <= 1e-9 * low, "H = {h}");
        assert!((last.dof_amplitude - high).abs() <= 1e-9 * high, "H = {h}");
        assert!(shortfall > 5e-3, "H = {h}: {shortfall:.2e}");
        assert!(before.dof_amplitude < high && before.modal_amplitude < last.modal_amplitude);
    }
    let problem = scenes::paper(&["accuracy.estimate=false"]);
    let dof = problem.outputs[0];
    let mut s = settings(ModeChoice::Number(2), dof, [low, high]);
    s.max_points = 10;
    let run = nonlinear_modes::solve(&problem, &s).unwrap();
    assert_eq!(run.end, nonlinear_modes::NonlinearModeEnd::MaxPoints);
    let reached = run.points.last().unwrap().dof_amplitude;
    assert!(reached < high);
    let reason = run.incomplete_reason().unwrap();
    assert!(
        reason.contains(&format!(
            "at amplitude {reached:.4e} m at the DOF of 1.0000e-3 m"
        )),
        "{reason}"
    );
}

/// Two masses on springs to ground (k₁ = 4·10⁴, k₂ = 10⁴ N/m), held together by a Jenkins
/// contact (kₜ = 10⁵ N/m, μN = 3 N): stuck, the first mode moves both about alike; in full
/// slip it is the second mass's own, and the friction force, at most μN, drives the first mass
/// to (4/π) μN / (k₁ − ω²m₁), a few 10⁻⁴ m at most.
const SATURATING_PAIR: &str = r#"
[model]
dofs = ["x1", "x2"]
mass = [[1.0, 0.0], [0.0, 1.0]]
stiffness = [[4.0e4, 0.0], [0.0, 1.0e4]]
damping = [[2.0, 0.0], [0.0, 2.0]]

[[contacts]]
name = "joint"
damper = ["x1"]
body = ["x2"]
tangent = [1.0]
normal = [0.0]
kt = 1.0e5
kn = 1.0e5
mu = 0.3
gap = -1.0e-4

[[harmonic_loads]]
dof = "x2"
harmonic = 1
cos = 1.0

[harmonics]
max = 1
samples = 64

[effects]
normal_load = "constant"

[analysis]
freq_start_hz = 5.0
freq_end_hz = 40.0

[output]
dofs = ["x1"]
"#;

/// A mode whose amplitude at the DOF saturates ends at its modal amplitude limit (100 times
/// the high end's conversion with the linear shape) as `incomplete`, naming the highest
/// amplitude at the DOF it reached: asked up to 10⁻² m at the first mass, it reaches the
/// friction-driven bound (measured 2.1·10⁻⁴ m, at the modal amplitude limit 1.53).
#[test]
fn a_mode_whose_dof_amplitude_saturates_ends_at_the_modal_limit() {
    let problem = scenes::problem(SATURATING_PAIR, &["accuracy.estimate=false"]);
    let (low, high) = (1e-6, 1e-2);
    let run =
        nonlinear_modes::solve(&problem, &settings(ModeChoice::Number(1), 0, [low, high])).unwrap();
    assert_eq!(run.end, nonlinear_modes::NonlinearModeEnd::ModalLimit);
    assert!(!run.is_complete());
    let highest = run
        .points
        .iter()
        .map(|p| p.dof_amplitude)
        .fold(0.0, f64::max);
    let last = run.points.last().unwrap();
    eprintln!(
        "{} points, highest {highest:.4e} m at the DOF, last a = {:.4e} (limit {:.4e})",
        run.points.len(),
        last.modal_amplitude,
        run.modal_range[1]
    );
    assert!(highest > 5e-5 && highest < 1e-3, "{highest:.4e}");
    assert!((last.modal_amplitude - run.modal_range[1]).abs() <= 1e-9 * run.modal_range[1]);
    let reason = run.incomplete_reason().unwrap();
    assert!(
        reason.contains(&format!("reached at most {highest:.4e} m of 1.0000e-2 m")),
        "{reason}"
    );
}

/// Every point's estimate is counted once, by how it was formed: on the 1-DOF Jenkins
/// oscillator at H = 1 the stuck points already solve the extension (estimate 0, no solve), the
/// others are solved to convergence, none is left unsized.
#[test]
fn error_estimate_counts_every_point_once() {
    let problem = scenes::problem(&jenkins_oscillator(), &[]);
    let run = solve(&problem, &settings(ModeChoice::Number(1), 0, [1e-6, 1e-2]));
    let counts = run.estimate_counts.expect("the estimate is on by default");
    eprintln!("{} points: {counts:?}", run.points.len());
    assert_eq!(
        counts.converged + counts.solved + counts.not_sized,
        run.points.len()
    );
    let stuck = run
        .points
        .iter()
        .filter(|p| p.states[0] == ContactState::Stuck)
        .count();
    assert!(counts.converged >= stuck, "{counts:?}: {stuck} stuck");
    assert!(counts.solved > 100, "{counts:?}");
    assert_eq!(counts.not_sized, 0);
}

/// Points of the paper's 2nd nonlinear mode at H = 5 where a contact slips and the damping
/// ratio rises steeply with the amplitude are periodic motions of the structure with the
/// artificial damping applied: integrated from the point over 4 periods 2π/ω, the motion keeps
/// the mode's first-harmonic amplitude at y2 within 1 % and its energy within the harmonics
/// 1..5. Only a few periods: −ξ M q̇ also feeds the other modes, those damped less than ξ/2ω_k
/// grow from what the truncated start leaves in them, and over tens of periods they move the
/// motion off the orbit (at D = 3 % the first harmonic is off by 0.7 % after 4 periods, 3.3 %
/// after 8; the extended periodic motion is periodic, not stable). The state is not compared period to period: an
/// autonomous orbit keeps no phase, and the harmonic balance's period, off the true one by the
/// truncation error of H = 5, makes it drift by a few per cent per period.
#[test]
fn mode_points_are_periodic_under_the_artificial_damping() {
    let problem = scenes::paper(&["harmonics.max=5"]);
    let dof = problem.outputs[0];
    let run = solve(
        &problem,
        &settings(ModeChoice::Number(2), dof, [1e-7, 1e-3]),
    );
    let p = &run.points;
    let steep: Vec<usize> = (1..p.len() - 1)
        .filter(|&i| {
            let slope = (p[i + 1].damping_ratio / p[i - 1].damping_ratio).ln()
                / (p[i + 1].dof_amplitude / p[i - 1].dof_amplitude).ln();
            p[i].states.iter().any(|s| *s != ContactState::Stuck) && slope > 0.2
        })
        .collect();
    assert!(steep.len() > 4, "{} steep points", steep.len());
    let settings = fricbound::analysis::verify::VerifySettings {
        min_periods: 4,
        max_periods: 4,
        ..fricbound::analysis::verify::VerifySettings::for_harmonics(5)
    };
    for &i in [steep[0], steep[steep.len() / 2], steep[steep.len() - 1]].iter() {
        let v = nonlinear_modes::verify_mode_point(&problem, &p[i], &settings).unwrap();
        eprintln!(
            "{:.4e} m at {:.3} Hz, D = {:.4e}, {:?}: {} periods (settled {}, last change \
             {:.1e}), first harmonic {:.2e} from the mode's, outside 1..5 {:.1e}, dt change \
             {:.2e}",
            p[i].dof_amplitude,
            p[i].freq_hz,
            p[i].damping_ratio,
            p[i].states,
            v.fine.periods,
            v.fine.settled,
            v.fine.last_change,
            v.hbm_difference,
            v.fine.nonharmonic_energy,
            v.dt_change
        );
        assert!(
            v.hbm_difference < 1e-2,
            "point {i}: {:.2e}",
            v.hbm_difference
        );
        assert!(v.fine.nonharmonic_energy < 1e-3, "point {i}");
    }
}

/// A nonlinear-mode scene without `analysis.freq_start_hz` / `freq_end_hz` gets the range of
/// its linear references from the chosen mode: 0.5 to 1.5 times its linear frequency with the
/// contact stuck, √((k + kₜ)/m)/2π for the Jenkins oscillator; it runs. An FRF scene without
/// the range is refused with the field named.
#[test]
fn mode_scene_without_frequency_range_takes_it_from_the_mode() {
    let (m, k, _, kt, _, _) = JENKINS;
    let f = ((k + kt) / m).sqrt() / (2.0 * std::f64::consts::PI);
    let text = jenkins_oscillator()
        .replace("freq_start_hz = 5.0\nfreq_end_hz = 40.0\n", "")
        .replace(
            "[analysis]\n",
            "[analysis]\nkind = \"nonlinear-modes\"\nmode = 1\ndof = \"x\"\namplitude = [1.0e-6, 1.0e-3]\n",
        );
    assert!(!text.contains("freq_start_hz"));
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("mode.toml");
    std::fs::write(&scene, &text).unwrap();
    let scene = scene.to_str().unwrap();
    let o = support::fricbound(&["check", scene]);
    assert!(o.status.success(), "{}", support::text(&o.stderr));
    let described = support::text(&o.stdout);
    let line = described
        .lines()
        .find(|l| l.starts_with("analysis "))
        .unwrap_or_else(|| panic!("{described}"));
    let ends: Vec<f64> = line
        .split_whitespace()
        .filter_map(|w| w.trim_end_matches(',').parse().ok())
        .take(2)
        .collect();
    assert_eq!(ends.len(), 2, "{line}");
    assert!((ends[0] / (0.5 * f) - 1.0).abs() < 1e-9, "{line}: {f} Hz");
    assert!((ends[1] / (1.5 * f) - 1.0).abs() < 1e-9, "{line}: {f} Hz");
    assert!(
        line.contains(
            "range of the linear references derived: 0.5-1.5 times the mode's linear frequency"
        ),
        "{line}"
    );
    let out = dir.path().join("out");
    let o = support::run_scene(scene, &out, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", support::text(&o.stderr));
    let json = support::json(&out.join("modes_nl.json"));
    let first = &json["cases"][0]["mode"]["points"][0];
    assert!((first["freq_hz"].as_f64().unwrap() / f - 1.0).abs() < 1e-6);

    let frf = jenkins_oscillator().replace("freq_start_hz = 5.0\n", "");
    let scene = dir.path().join("frf.toml");
    std::fs::write(&scene, frf).unwrap();
    let o = support::fricbound(&["check", scene.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    let err = support::text(&o.stderr);
    assert!(
        err.contains("field `analysis.freq_start_hz`: missing"),
        "{err}"
    );
}

/// On the reduced 2D blade pair (an FE scene) a nonlinear-mode run writes the mode shape on the
/// mesh at the first and last points and at the largest damping ratio, each with the
/// first-harmonic amplitude and the contact states (a lumped scene writes none, see
/// `shipped_scene_checks_and_runs`).
#[test]
fn fe_scene_writes_the_mode_shapes_on_the_mesh() {
    let scene = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/meshes/blade-pair/blade-pair-2d.toml"
    );
    let dir = tempfile::tempdir().unwrap();
    let o = support::run_scene(
        scene,
        dir.path(),
        &[
            "analysis.kind=\"nonlinear-modes\"",
            "analysis.mode_freq_hz=900.0",
            "analysis.amplitude=[1e-9, 1e-5]",
            "accuracy.estimate=false",
        ],
    );
    assert_eq!(o.status.code(), Some(0), "{}", support::text(&o.stderr));
    for f in [
        "modes_nl_first.vtu",
        "modes_nl_last.vtu",
        "modes_nl_max_damping.vtu",
    ] {
        let text =
            std::fs::read_to_string(dir.path().join(f)).unwrap_or_else(|e| panic!("{f}: {e}"));
        for field in [
            "first_harmonic_amplitude",
            "first_harmonic_cos",
            "first_harmonic_sin",
            "contact_state",
            "static_displacement",
        ] {
            assert!(text.contains(field), "{f}: no {field}");
        }
    }
}
