//! Newton at fixed frequencies from one point of a run's `solution.json` (exploration aid).
//! Usage: cargo run --release --example point_probe -- SCENE SOLUTION INDEX F1 [F2 ...] [-- FIELD=VALUE ...]
//!
//! Each `F` (Hz) is solved from point INDEX of SOLUTION (its coefficients); `mirrorJ` replaces
//! the start by the point reflected through INDEX, 2 x_INDEX − x_J, and `chain` starts each
//! later solve from the previous solution; `xchordJ@T` solves with the frequency free on the
//! hyperplane normal to the chord from J to INDEX in the unknowns alone, T chord lengths from
//! J (the way round a fold at INDEX). The overrides are the run's `--set` fields.

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let split = args.iter().position(|a| a == "--").unwrap_or(args.len());
    let (head, overrides) = (
        &args[..split],
        args.get(split + 1..).unwrap_or(&[]).to_vec(),
    );
    let (_, problem) =
        fricbound::scene::load_problem(std::path::Path::new(&head[0]), &overrides).unwrap();
    let text = std::fs::read_to_string(&head[1]).unwrap();
    let sol: serde_json::Value = serde_json::from_str(&text).unwrap();
    let index: usize = head[2].parse().unwrap();
    let point = &sol["points"][index];
    let x0 = coefficients(point);
    println!(
        "point {index}: {} Hz, {:?}",
        point["freq_hz"], point["amplitudes"]
    );
    let mut solver = fricbound::analysis::frf::PointSolver::new(&problem).unwrap();
    let mut x0 = x0;
    let mut chain = false;
    for f in &head[3..] {
        if let Some(j) = f.strip_prefix("mirror") {
            // Reflect the point through `index`: 2 x_index − x_j.
            let j: usize = j.parse().unwrap();
            let xj = coefficients(&sol["points"][j]);
            x0 = x0.iter().zip(&xj).map(|(a, b)| 2.0 * a - b).collect();
            println!("mirror of {j} ({} Hz)", sol["points"][j]["freq_hz"]);
            continue;
        }
        if let Some(spec) = f.strip_prefix("xchord") {
            // `xchordJ@T`: the point on the hyperplane normal to the chord from J to INDEX in
            // the unknowns alone (the frequency left free), at T chord lengths from J (T > 1
            // goes on past INDEX): the way on past a fold of the frequency.
            let (j, t) = spec.split_once('@').unwrap();
            let (j, t): (usize, f64) = (j.parse().unwrap(), t.parse().unwrap());
            let mut a = point_of(&sol["points"][j]);
            let b = point_of(point);
            a.freq_hz = b.freq_hz;
            match solver.solve_on_chord(&a, &b, t) {
                Ok(q) => println!(
                    "xchord {j}@{t}: {} Hz {:?} its {} distance from INDEX {:.3e}",
                    q.freq_hz,
                    q.amplitudes,
                    q.newton_iterations,
                    distance(&q.coefficients, &b.coefficients)
                ),
                Err(e) => println!("xchord {j}@{t}: {e}"),
            }
            continue;
        }
        if f == "chain" {
            chain = true;
            continue;
        }
        let f: f64 = f.parse().unwrap();
        match solver.solve(&x0, f) {
            Ok(q) => {
                let d: f64 = q
                    .coefficients
                    .iter()
                    .zip(&x0)
                    .map(|(a, b)| (a - b) * (a - b))
                    .sum::<f64>()
                    .sqrt()
                    / x0.iter().map(|a| a * a).sum::<f64>().sqrt();
                println!(
                    "{f} Hz: {:?} its {} distance {d:.3e}",
                    q.amplitudes, q.newton_iterations
                );
                if chain {
                    x0 = q.coefficients.clone();
                }
            }
            Err(e) => println!("{f} Hz: {e}"),
        }
    }
}

/// The Fourier coefficients of a point of `solution.json`.
fn coefficients(point: &serde_json::Value) -> Vec<f64> {
    point["coefficients"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect()
}

/// A point of `solution.json` as an FRF point (frequency, amplitudes and coefficients).
fn point_of(point: &serde_json::Value) -> fricbound::analysis::frf::FrfPoint {
    fricbound::analysis::frf::FrfPoint {
        freq_hz: point["freq_hz"].as_f64().unwrap(),
        amplitudes: vec![],
        peaks: vec![],
        states: vec![],
        newton_iterations: 0,
        residual: 0.0,
        coefficients: coefficients(point),
        accuracy: None,
        pending_estimate: None,
        stability: None,
    }
}

/// ‖a − b‖ / ‖b‖.
fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(p, q)| (p - q) * (p - q))
        .sum::<f64>()
        .sqrt()
        / b.iter().map(|q| q * q).sum::<f64>().sqrt()
}
