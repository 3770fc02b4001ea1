//! Where one Newton iteration of a scene's frequency response spends its time:
//! `cargo run --release --example newton_phases -- SCENE [FIELD=VALUE ...]` (each argument after
//! the scene is a `--set` override; give a short window, e.g. `analysis.freq_start_hz=851.9
//! analysis.freq_end_hz=852`).
//!
//! Solves the scene's FRF over its window, takes the last converged point (x, ω) and, at it,
//! times each phase of a Newton iteration, repeated until it has run for a second: the residual
//! (linear part and every contact's AFT march), the residual with the analytic Jacobian (the
//! marches with their derivatives, and their scatter into the Jacobian's storage), the
//! factorisation of the bordered Jacobian (for the schur formulation: the per-harmonic
//! elimination of the non-contact coordinates, reused at a repeated ω as here, and the LU of
//! the reduced matrix; the schur rows also time it at a new ω every call), one solve
//! with it; then each contact point's march alone, with and without its Jacobian, and how many
//! periods it marched. Wall and process CPU time (all threads) per call, in ms; the CPU time
//! comes from `/proc/self/stat` (Linux). The numbers are the machine's of the moment: run it
//! on a quiet machine for absolute times, the shares hold under load.

use std::path::Path;
use std::time::Instant;

use fricbound::analysis::frf::{self, PointSolver, Silent};
use fricbound::contact::aft::AftWorkspace;
use fricbound::contact::aft2d::Aft2dWorkspace;
use fricbound::hbm::schur::RelativeCoordinates;
use fricbound::numerics::linalg::{packed_complex_lu, packed_lu};
use fricbound::scene;

use faer::{c64, Mat};

/// CPU time of the whole process (user + system, all threads) in seconds.
fn process_cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // Fields after the command name (which is in parentheses and may hold spaces).
    let after = stat.rsplit_once(')').map_or("", |(_, rest)| rest);
    let fields: Vec<&str> = after.split_whitespace().collect();
    let ticks = |i: usize| {
        fields
            .get(i)
            .and_then(|v| v.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    // utime and stime are fields 14 and 15 of the line, 12 and 13 after the name.
    (ticks(11) + ticks(12)) / 100.0
}

/// Runs `f` until a second has passed (at least `min_calls` times): (wall ms, CPU ms) per call.
fn time_per_call(min_calls: usize, f: impl FnMut()) -> (f64, f64, usize) {
    time_for(1.0, min_calls, f)
}

/// Runs `f` until `seconds` have passed (at least `min_calls` times): (wall ms, CPU ms) per
/// call, and the calls.
fn time_for(seconds: f64, min_calls: usize, mut f: impl FnMut()) -> (f64, f64, usize) {
    let (wall, cpu) = (Instant::now(), process_cpu_seconds());
    let mut calls = 0;
    while calls < min_calls || wall.elapsed().as_secs_f64() < seconds {
        f();
        calls += 1;
    }
    let per = |s: f64| 1e3 * s / calls as f64;
    (
        per(wall.elapsed().as_secs_f64()),
        per(process_cpu_seconds() - cpu),
        calls,
    )
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some((scene_path, overrides)) = args.split_first() else {
        eprintln!("usage: newton_phases SCENE [FIELD=VALUE ...]");
        std::process::exit(2);
    };
    let (_, mut problem) =
        scene::load_problem(Path::new(scene_path), overrides).unwrap_or_else(|e| {
            eprintln!("{e}");
            std::process::exit(1);
        });
    // `CHORD_MIN_UNKNOWNS=0` carries factorisations over Newton iterations and points from
    // that many unknowns (the library's default is `CHORD_MIN_UNKNOWNS`, 1500).
    if let Some(min) = std::env::var("CHORD_MIN_UNKNOWNS")
        .ok()
        .and_then(|v| v.parse().ok())
    {
        problem.analysis.continuation.chord_min_unknowns = min;
    }
    let (started, cpu) = (Instant::now(), process_cpu_seconds());
    let run = frf::solve(&problem, &mut Silent).expect("the FRF starts");
    let point = run.points.last().expect("a converged point");
    let iterations: usize = run.points.iter().map(|p| p.newton_iterations).sum();
    let cpu = process_cpu_seconds() - cpu;
    println!(
        "FRF (chord from {} unknowns): {} points, {iterations} Newton iterations, {} step cuts, \
         {:.2} s wall, {cpu:.2} s CPU ({:.1} ms per iteration); timing at {:.4} Hz (first output \
         {:.9e} m), states {}",
        problem.analysis.continuation.chord_min_unknowns,
        run.points.len(),
        run.rejected_steps,
        started.elapsed().as_secs_f64(),
        1e3 * cpu / iterations.max(1) as f64,
        point.freq_hz,
        point.amplitudes[0],
        summary(&point.states)
    );
    let omega = 2.0 * std::f64::consts::PI * point.freq_hz;
    let x = point.coefficients.clone();
    let mut solver = PointSolver::new(&problem).expect("a point solver");
    let system = solver.system();
    let dim = system.dim();
    println!(
        "unknowns {dim}, storage {:?}, contacts {}",
        system.storage(),
        problem.contacts.len()
    );

    let mut rows: Vec<(String, (f64, f64, usize))> = Vec::new();
    let mut r = vec![0.0; dim];
    rows.push((
        "residual (linear part + every march)".to_string(),
        time_per_call(3, || system.residual(&x, omega, &mut r).unwrap()),
    ));
    let mut jac = system.new_jacobian();
    let mut dr = vec![0.0; dim];
    rows.push((
        "residual and analytic Jacobian".to_string(),
        time_per_call(3, || {
            system
                .residual_and_jacobian(&x, omega, &mut r, &mut jac, &mut dr)
                .unwrap()
        }),
    ));
    let ones = vec![1.0; dim];
    // A border row like the continuation's tangent: unit weight on ω, small on x.
    let mut row: Vec<f64> = (0..dim).map(|i| 1e-3 * ((i % 7) as f64 - 3.0)).collect();
    row.push(1.0);
    let factor = jac.factor_bordered(&ones, &dr, &row).unwrap();
    rows.push((
        "factorisation of the bordered Jacobian".to_string(),
        time_per_call(3, || {
            jac.factor_bordered(&ones, &dr, &row).unwrap();
        }),
    ));
    let mut rhs = r.clone();
    rhs.push(0.0);
    rows.push((
        "one solve with the factorisation".to_string(),
        time_per_call(3, || {
            factor.solve(&rhs).unwrap();
        }),
    ));
    rows.push((
        "one chord solve (single-precision factors)".to_string(),
        time_per_call(3, || {
            factor.solve_chord(&rhs).unwrap();
        }),
    ));

    // Per contact: its march alone, in the system (as Newton runs it) and in a workspace of
    // our own that reports the periods (checked to give the system's forces).
    let n = problem.model.n_dofs();
    let unknowns = problem.unknown_harmonics();
    let force_set = problem.force_harmonics();
    let nbf = force_set.n_blocks();
    let settings_2d = system.aft2d().map(|w| w.settings);
    let settings_1d = system.aft().settings;
    let static_offset = system.static_offset().to_vec();
    let mut own_2d = Aft2dWorkspace::new(&force_set, problem.samples);
    if let Some(s) = settings_2d {
        own_2d.settings = s;
    }
    let mut own_1d = AftWorkspace::new(&force_set, problem.samples);
    own_1d.settings = settings_1d;
    let (mut march_wall, mut march_cpu, mut jac_wall, mut jac_cpu) = (0.0, 0.0, 0.0, 0.0);
    let mut periods: Vec<(usize, String)> = Vec::new();
    for (c, contact) in problem.contacts.iter().enumerate() {
        // A quarter of a second each: the sums over contacts carry the CPU clock's 10 ms
        // resolution over 58 · 0.25 s.
        let (w, u, _) = time_for(0.25, 2, || {
            system.contact_forces(c, &x, false).unwrap();
        });
        march_wall += w;
        march_cpu += u;
        let (w, u, _) = time_for(0.25, 2, || {
            system.contact_forces(c, &x, true).unwrap();
        });
        jac_wall += w;
        jac_cpu += u;
        let mut coef = [vec![0.0; nbf], vec![0.0; nbf], vec![0.0; nbf]];
        for (j, b) in unknowns.blocks().iter().enumerate() {
            let jf = force_set.blocks().iter().position(|f| f == b).unwrap();
            let q = &x[j * n..(j + 1) * n];
            coef[0][jf] = contact.tangential_of(q);
            coef[1][jf] = contact.second_tangential_of(q);
            coef[2][jf] = contact.normal_of(q);
        }
        if !unknowns.has_constant() {
            coef[0][0] = contact.tangential_of(&static_offset);
            coef[1][0] = contact.second_tangential_of(&static_offset);
            coef[2][0] = contact.normal_of(&static_offset);
        }
        coef[2][0] -= contact.gap;
        let effects = problem.effects.contact;
        system.contact_forces(c, &x, false).unwrap();
        let report = match system.law_2d(c) {
            Some(law) => {
                let report = own_2d
                    .evaluate(&law, effects, [&coef[0], &coef[1]], &coef[2], false)
                    .unwrap();
                let theirs = system.aft2d().unwrap();
                assert_eq!(own_2d.t_hat, theirs.t_hat, "{}", contact.name);
                report
            }
            None => {
                let report = own_1d
                    .evaluate(&system.law(c), effects, &coef[0], &coef[2], false)
                    .unwrap();
                assert_eq!(own_1d.t_hat, system.aft().t_hat, "{}", contact.name);
                report
            }
        };
        periods.push((report.periods, format!("{} {}", contact.name, report.state)));
    }
    rows.push((
        "  of which: every contact's march (no Jacobian)".to_string(),
        (march_wall, march_cpu, 0),
    ));
    rows.push((
        "  of which: every contact's march with its Jacobian".to_string(),
        (jac_wall, jac_cpu, 0),
    ));

    // The schur factorisation's parts, at the sizes of this problem: per harmonic h ≥ 1 a
    // complex LU of A_zz (the non-contact coordinates), its solve with the n_q columns of
    // A_zq and the product A_qz W; the same in real arithmetic for h = 0; then the LU of the
    // reduced matrix on the n_q · blocks relative coordinates. Generic well-conditioned
    // matrices of those sizes (dense LU and products cost the same whatever the entries).
    if let Ok(coords) = RelativeCoordinates::new(&problem, &unknowns) {
        let (n, n_q, nb) = (coords.n_dofs(), coords.n_relative(), coords.n_blocks());
        let nz = n - n_q;
        // Contact blocks of stuck springs (1e7 N/m on each coordinate), so that the reduced
        // matrix is regular (a damper held only by its contacts is a free body without them).
        let offsets = coords.value_offsets().to_vec();
        let mut values = vec![0.0; *offsets.last().unwrap()];
        for p in 0..offsets.len() - 1 {
            let k = (((offsets[p + 1] - offsets[p]) as f64).sqrt() as usize) / nb;
            for j in 0..nb {
                for a in 0..k {
                    values[offsets[p] + ((j * nb + j) * k + a) * k + a] = 1e7;
                }
            }
        }
        let coords = std::sync::Arc::new(coords);
        // At the same ω every call (a fixed-frequency Newton: the per-harmonic elimination is
        // reused), and at a new ω every call (a continuation step: it is not).
        rows.push((
            "schur factorisation alone, same ω every call (RelativeCoordinates::factor)"
                .to_string(),
            time_per_call(3, || {
                coords
                    .factor(omega, &values, fricbound::hbm::schur::ReducedSolver::Dense)
                    .unwrap();
            }),
        ));
        let mut step = 0.0;
        rows.push((
            "schur factorisation alone, a new ω every call".to_string(),
            time_per_call(3, || {
                step += 1.0;
                coords
                    .factor(
                        omega * (1.0 + 1e-9 * step),
                        &values,
                        fricbound::hbm::schur::ReducedSolver::Dense,
                    )
                    .unwrap();
            }),
        ));
        let entry = |i: usize, j: usize| {
            if i == j {
                4.0
            } else {
                1.0 / (1.0 + (i + 2 * j) as f64)
            }
        };
        let zz = Mat::from_fn(nz, nz, |i, j| c64::new(entry(i, j), 0.1 * entry(j, i)));
        let zq = Mat::from_fn(nz, n_q, |i, j| c64::new(entry(i, j), 0.0));
        let qz = Mat::from_fn(n_q, nz, |i, j| c64::new(entry(i, j), 0.0));
        let lu = packed_complex_lu(zz.clone()).unwrap();
        let mut w = zq.clone();
        lu.solve_in_place(&mut w);
        let harmonics = (nb - 1) / 2;
        let label = |what: &str| format!("  {what} (×{harmonics} harmonics ≥ 1)");
        let complex_lu = time_per_call(3, || {
            packed_complex_lu(zz.clone()).unwrap();
        });
        let complex_solve = time_per_call(3, || {
            let mut w = zq.clone();
            lu.solve_in_place(&mut w);
        });
        let complex_product = time_per_call(3, || {
            let _ = &qz * &w;
        });
        let real_zz = Mat::from_fn(nz, nz, entry);
        let real_zq = Mat::from_fn(nz, n_q, entry);
        let real_qz = Mat::from_fn(n_q, nz, entry);
        let real_elimination = time_per_call(3, || {
            let lu = packed_lu(real_zz.clone()).unwrap();
            let mut w = real_zq.clone();
            lu.solve_in_place(&mut w);
            let _ = &real_qz * &w;
        });
        let reduced = Mat::from_fn(n_q * nb, n_q * nb, entry);
        let reduced_lu = time_per_call(3, || {
            packed_lu(reduced.clone()).unwrap().to_single();
        });
        rows.push((label(&format!("complex LU of A_zz, {nz}²")), complex_lu));
        rows.push((
            label(&format!("A_zz⁻¹ A_zq, {n_q} right-hand sides")),
            complex_solve,
        ));
        rows.push((
            label(&format!("A_qz W, {n_q}×{nz}×{n_q} complex")),
            complex_product,
        ));
        rows.push((
            "  h = 0: real LU, solve and product".to_string(),
            real_elimination,
        ));
        rows.push((
            format!(
                "  LU of the reduced matrix, {0}×{0}, and its single copy",
                n_q * nb
            ),
            reduced_lu,
        ));
    }

    println!("\n| phase | wall ms per call | CPU ms per call | calls timed |");
    println!("| --- | ---: | ---: | ---: |");
    for (name, (wall, cpu, calls)) in &rows {
        let calls = if *calls == 0 {
            "(sum over contacts)".to_string()
        } else {
            calls.to_string()
        };
        println!("| {name} | {wall:.2} | {cpu:.2} | {calls} |");
    }
    periods.sort_by_key(|p| std::cmp::Reverse(p.0));
    let total: usize = periods.iter().map(|p| p.0).sum();
    println!(
        "\nmarch periods: {total} over {} contacts (mean {:.1}); most: {}",
        periods.len(),
        total as f64 / periods.len().max(1) as f64,
        periods
            .iter()
            .take(6)
            .map(|(p, what)| format!("{what}: {p}"))
            .collect::<Vec<_>>()
            .join(", ")
    );
}

/// Contact states counted by kind.
fn summary(states: &[fricbound::contact::ContactState]) -> String {
    let mut counts: Vec<(String, usize)> = Vec::new();
    for s in states {
        match counts.iter_mut().find(|(l, _)| l == s.label()) {
            Some((_, k)) => *k += 1,
            None => counts.push((s.label().to_string(), 1)),
        }
    }
    counts
        .iter()
        .map(|(l, k)| format!("{k} {l}"))
        .collect::<Vec<_>>()
        .join(", ")
}
