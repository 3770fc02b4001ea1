//! Whether the points of a run with the largest truncation estimates have a counterpart at a
//! higher harmonic count: each is padded with zero coefficients and solved by Newton on the
//! refined harmonic set, at its own frequency and across the path (on the hyperplane normal to
//! the chord to its neighbour), and the true error of its amplitude printed next to its
//! estimate (docs/accuracy.md, "The larger blade pair at H = 1, on its small folds").
//!
//! Run: `cargo run --release --example refine_flagged_points -- SCENE FROM_HZ TO_HZ H COUNT
//! H_REF...` (e.g. `meshes/blade-pair/blade-pair-2d.toml 855 895 1 8 3 5 7`): solves SCENE at
//! harmonic count H over FROM_HZ-TO_HZ, takes the COUNT points with the largest estimate of the
//! first output, and refines each at every H_REF.

use fricbound::analysis::frf::{self, FrfPoint, Silent};
use fricbound::model::Problem;
use fricbound::scene;

fn load(path: &str, overrides: &[String]) -> Problem {
    scene::load(std::path::Path::new(path), overrides)
        .expect("scene loads")
        .validate(path)
        .expect("scene is valid")
}

fn states(p: &FrfPoint) -> String {
    let mut counts = std::collections::BTreeMap::new();
    for s in &p.states {
        *counts.entry(s.label()).or_insert(0) += 1;
    }
    counts
        .iter()
        .map(|(k, v)| format!("{v} {k}"))
        .collect::<Vec<_>>()
        .join(", ")
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 6 {
        eprintln!("usage: SCENE FROM_HZ TO_HZ H COUNT H_REF...");
        std::process::exit(2);
    }
    let scene_path = &args[0];
    let base = [
        format!("analysis.freq_start_hz={}", args[1]),
        format!("analysis.freq_end_hz={}", args[2]),
    ];
    let h: usize = args[3].parse().expect("H");
    let count: usize = args[4].parse().expect("COUNT");
    let refs: Vec<usize> = args[5..]
        .iter()
        .map(|a| a.parse().expect("H_REF"))
        .collect();
    let mut overrides = base.to_vec();
    overrides.push(format!("harmonics.max={h}"));
    let problem = load(scene_path, &overrides);
    let started = std::time::Instant::now();
    let run = frf::solve(&problem, &mut Silent).expect("run solves");
    println!(
        "H = {h}: {} points in {:.1} s, {} turning points, {:?}",
        run.points.len(),
        started.elapsed().as_secs_f64(),
        run.turning_points.len(),
        run.incomplete_reason()
    );
    let mut ranked: Vec<usize> = (0..run.points.len())
        .filter(|&i| run.points[i].accuracy.is_some())
        .collect();
    let estimate = |i: usize| {
        run.points[i]
            .accuracy
            .as_ref()
            .map_or(0.0, |a| a.truncation[0])
    };
    ranked.sort_by(|&a, &b| estimate(b).total_cmp(&estimate(a)));
    ranked.truncate(count);
    let starts = run.branch_starts();
    for &h_ref in &refs {
        let mut o = base.to_vec();
        o.push(format!("harmonics.max={h_ref}"));
        o.push("accuracy.estimate=false".to_string());
        let refined = load(scene_path, &o);
        let n = refined.model.n_dofs();
        let blocks = refined.unknown_harmonics().n_blocks();
        let mut solver = frf::PointSolver::new(&refined).expect("point solver");
        // Zero padding onto 0..H_REF (the blocks of 0..H are a prefix of those of 0..H_REF).
        let pad = |p: &FrfPoint| -> FrfPoint {
            let mut q = p.clone();
            q.coefficients.resize(n * blocks, 0.0);
            q
        };
        for &i in &ranked {
            let p = &run.points[i];
            let acc = p.accuracy.as_ref().expect("ranked points have an estimate");
            let (fixed, across) = acc
                .both_truncation
                .as_ref()
                .map_or((f64::NAN, f64::NAN), |(f, a)| (f[0], a[0]));
            let (slide, step) = acc.slide_and_step;
            println!(
                "H {h} pt {i} {:.4} Hz amp {:.5e} [{}]: estimate {:.3e} (fixed {fixed:.3e}, across {across:.3e}, slide {:.1} steps, reports across {})",
                p.freq_hz,
                p.amplitudes[0],
                states(p),
                acc.truncation[0],
                slide / step,
                acc.across_path
            );
            match solver.solve(&pad(p).coefficients, p.freq_hz) {
                Ok(q) => println!(
                    "   H {h_ref} fixed frequency: amp {:.5e} [{}], true error {:.3e}",
                    q.amplitudes[0],
                    states(&q),
                    (p.amplitudes[0] - q.amplitudes[0]).abs() / q.amplitudes[0]
                ),
                Err(e) => println!("   H {h_ref} fixed frequency: no convergence ({e:?})"),
            }
            // The neighbour on the same branch (the one before, else the one after).
            let neighbour = if i > 0 && !starts.contains(&i) {
                Some(i - 1)
            } else if i + 1 < run.points.len() && !starts.contains(&(i + 1)) {
                Some(i + 1)
            } else {
                None
            };
            if let Some(j) = neighbour {
                let (a, b) = (pad(&run.points[j]), pad(p));
                match solver.solve_on_chord(&a, &b, 1.0) {
                    Ok(q) => println!(
                        "   H {h_ref} across the path: {:.4} Hz amp {:.5e} [{}], true error {:.3e}",
                        q.freq_hz,
                        q.amplitudes[0],
                        states(&q),
                        (p.amplitudes[0] - q.amplitudes[0]).abs() / q.amplitudes[0]
                    ),
                    Err(e) => println!("   H {h_ref} across the path: no convergence ({e:?})"),
                }
            }
        }
    }
}
