//! Prints the limit analysis of the paper case for a few settings (exploration aid).
//! Usage: cargo run --release --example limits_probe -- LO HI [FIELD=VALUE ...]

fn main() {
    let mut args = std::env::args().skip(1);
    let lo: f64 = args.next().and_then(|a| a.parse().ok()).unwrap_or(200.0);
    let hi: f64 = args.next().and_then(|a| a.parse().ok()).unwrap_or(235.0);
    let mut overrides: Vec<String> = vec![
        format!("analysis.freq_start_hz={lo}"),
        format!("analysis.freq_end_hz={hi}"),
        "analysis.max_step=0.1".into(),
    ];
    overrides.extend(args);
    let problem =
        fricbound::scene::parse(fricbound::scene::paper_wedge_scene(), "paper", &overrides)
            .and_then(|s| s.validate("paper"))
            .unwrap_or_else(|e| panic!("{e}"));
    let settings = fricbound::analysis::limits::LimitSettings {
        intermediate: vec![-0.5, 0.0, 0.5],
        grid_points: 71,
        bound_scan: vec![-0.5, 0.0, 0.5],
        ..Default::default()
    };
    let t = std::time::Instant::now();
    let a = fricbound::analysis::limits::analyse(&problem, &settings, |_| {})
        .unwrap_or_else(|e| panic!("{e}"));
    println!("time {:.3}s", t.elapsed().as_secs_f64());
    for c in a.limits.iter().chain(&a.intermediate) {
        match &c.peak {
            Some(p) => println!(
                "{:>6} peak {:.4} Hz {:.5e} refined {} {:?} ({})",
                c.case.name,
                p.freq_hz,
                p.amplitude,
                p.refined,
                p.states,
                c.status.text()
            ),
            None => println!("{:>6} no peak ({})", c.case.name, c.status.text()),
        }
    }
    let widest = a
        .grid
        .iter()
        .filter(|g| g.upper.is_finite())
        .map(|g| g.upper - g.lower)
        .fold(0.0, f64::max);
    println!("widest band {widest:.4e}");
    for g in a.grid.iter().step_by(7) {
        println!(
            "{:.2} {:?} lo {:.3e} hi {:.3e} {:?}",
            g.freq_hz, g.regime, g.lower, g.upper, g.labels
        );
    }
    println!("{:?}", a.bounds);
}
