//! FRF of the reduced 2D blade pair with 2 contact pairs per side (the scaling study's
//! `2D r2 p2`, 20 modes), the case whose Newton stagnates at a contact transition between AFT
//! samples (benches/README.md, "Newton at transitions between samples"):
//! `cargo run --release --example transition_floor -- [samples] [H] [max_points] [formulation]
//! [freq_end_hz] [csv]` (defaults 128, 3, 150, auto, the study's 1000 Hz, none). Prints the
//! points, the end of the path, the Newton iterations and the wall time; with `csv`, writes
//! `freq_hz,amplitude,residual` of every point (first output DOF) there.

use fricbound::analysis::frf::{self, FrfObserver, FrfPoint};
use fricbound::model::{Formulation, JacobianStrategy};
use fricbound::study::scaling::{self, ModelSize, SolverConfig};
use std::time::Instant;

struct Collect(Vec<FrfPoint>);

impl FrfObserver for Collect {
    fn point(&mut self, point: &FrfPoint) {
        self.0.push(point.clone());
    }
}

fn main() {
    let raw: Vec<String> = std::env::args().skip(1).collect();
    let int = |i: usize, default: usize| {
        raw.get(i)
            .map(|a| a.parse().expect("integer argument"))
            .unwrap_or(default)
    };
    let formulation = match raw.get(3).map(String::as_str) {
        None | Some("auto") => Formulation::Auto,
        Some("dense") => Formulation::Dense,
        Some("sparse") => Formulation::Sparse,
        Some("condensed") => Formulation::Condensed,
        Some("schur") => Formulation::Schur,
        Some(other) => panic!("unknown formulation `{other}`"),
    };
    let size = ModelSize {
        three_d: false,
        refine: 2,
        contact_refine: 1,
        contact_pairs: Some(2),
    };
    let dir = tempfile::tempdir().expect("temporary folder");
    let reduced = scaling::reduced_problem(size, 20, dir.path()).expect("reduced model");
    let config = SolverConfig {
        harmonics: int(1, 3),
        formulation,
        jacobian: JacobianStrategy::Analytic,
        m: 1.0,
    };
    let mut p = config.apply(&reduced);
    p.samples = int(0, 128);
    p.analysis.continuation.max_points = int(2, 150);
    if let Some(end) = raw.get(4) {
        p.analysis.continuation.freq_end_hz = end.parse().expect("end frequency (Hz)");
    }
    let started = Instant::now();
    let mut points = Collect(Vec::new());
    let outcome = frf::solve(&p, &mut points);
    let wall = started.elapsed().as_secs_f64();
    let points = points.0;
    let iterations: usize = points.iter().map(|q| q.newton_iterations).sum();
    let at_floor: Vec<&FrfPoint> = points
        .iter()
        .filter(|q| q.sampling_floor.is_some())
        .collect();
    let top = points.iter().map(|q| q.freq_hz).fold(f64::NAN, f64::max);
    let end = match &outcome {
        Ok(run) => format!("{:?}", run.end),
        Err(e) => format!("error: {e}"),
    };
    println!(
        "{} samples, H = {}, {:?}: {} points, {} Newton iterations, {:.2} s; highest {:.3} Hz; end: {}",
        p.samples,
        config.harmonics,
        p.formulation(),
        points.len(),
        iterations,
        wall,
        top,
        end
    );
    for q in &at_floor {
        println!(
            "  accepted at the sampling floor: {:.4} Hz, residual {:.2e}, floor {:.2e}, {} iterations",
            q.freq_hz,
            q.residual,
            q.sampling_floor.unwrap_or(f64::NAN),
            q.newton_iterations
        );
    }
    if let Some(path) = raw.get(5) {
        let mut text = String::from("freq_hz,amplitude,residual,sampling_floor\n");
        for q in &points {
            let floor = q.sampling_floor.map(|f| f.to_string()).unwrap_or_default();
            text += &format!("{},{},{},{floor}\n", q.freq_hz, q.amplitudes[0], q.residual);
        }
        std::fs::write(path, text).expect("csv written");
    }
}
