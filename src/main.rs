fn main() {
    let scene = fricbound::scene::parse(fricbound::scene::PAPER_DEFAULT_SCENE, "default", &[]).unwrap();
    let problem = scene.validate("default").unwrap();
    struct P;
    impl fricbound::frf::FrfObserver for P {
        fn step_cut(&mut self, f: f64, s: f64, ns: f64, r: &fricbound::continuation::NewtonFailure) { eprintln!("cut at {f:.3} {s:.3e}->{ns:.3e}: {r}"); }
        fn turning_point(&mut self, f: f64) { eprintln!("turn {f}"); }
    }
    let run = fricbound::frf::solve(&problem, &mut P).unwrap();
    for p in run.points.iter().step_by(5) {
        println!("{:9.3} {:.4e} {:?} {}", p.freq_hz, p.amplitudes[0], p.states, p.newton_iterations);
    }
    println!("points {} rejected {} time {:.3}s end {:?}", run.points.len(), run.rejected_steps, run.elapsed_s, run.end);
}
