//! The reduced model of an FE scene does not depend on what runs beside its reduction: the
//! 2D blade pair reduced on its own and reduced while another reduction runs on a second
//! thread of the same rayon pool (as a limit analysis's curves or an accuracy study's settings
//! are) gives the same matrices, bit for bit. METIS' random numbers come from one static state
//! of the process; two orderings drawing from it at the same time used to make the reduced
//! mass matrix differ by 10⁻¹¹ from run to run (`fricbound_reduction::ordering`).

use fricbound::scene;

const SCENE: &str = "meshes/blade-pair/blade-pair-2d.toml";

/// The reduced linear model of the 2D blade pair with `modes` interior modes, as text (`{:?}`
/// of an f64 is its shortest round-trip form, so equal texts are equal bits).
fn reduced_model(modes: usize) -> String {
    let text = std::fs::read_to_string(SCENE).expect("the blade pair scene is committed");
    let overrides = vec![format!("reduction.modes={modes}")];
    let problem = scene::parse(&text, SCENE, &overrides)
        .and_then(|s| s.validate(SCENE))
        .unwrap_or_else(|e| panic!("{e}"));
    format!("{:?}", problem.model)
}

#[test]
fn a_reduction_beside_another_gives_the_same_matrices_as_one_alone() {
    let alone = reduced_model(40);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .expect("a pool of two threads");
    for round in 0..3 {
        let (beside, other) =
            pool.install(|| rayon::join(|| reduced_model(40), || reduced_model(20)));
        assert!(beside == alone, "round {round}: the reduced model changed");
        assert!(other != alone);
    }
}
