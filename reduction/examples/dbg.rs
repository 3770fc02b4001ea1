use fricbound_reduction::testmodels::*;
use fricbound_reduction::*;
fn main() {
    let (mesh, contact) = blades_and_damper(50, 10, true, 6, Some(5e8));
    let mut b = contact.clone();
    for body in 0..2 {
        let bd = &mesh.bodies[body];
        let d = bd.dof(bd.nodes[0] - 1, 0, 0, 1).unwrap();
        b.push(d);
    }
    let full = lowest_eigenpairs(mesh.k.as_ref(), mesh.m.as_ref(), 10, 0.0).unwrap();
    println!("full {:?}", full.frequencies_hz());
    for nm in [10, 30, 60, 120] {
        let r = craig_bampton(
            mesh.k.as_ref(),
            mesh.m.as_ref(),
            &b,
            &[],
            &CbOptions::with_modes(nm),
        )
        .unwrap();
        let (v, _) = dense_generalized_eigenvalues(r.stiffness.as_ref(), r.mass.as_ref()).unwrap();
        let f: Vec<f64> = v
            .iter()
            .take(10)
            .map(|l| l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI))
            .collect();
        println!(
            "nm {nm} cutoff {:.0}: {:?}",
            r.report.cutoff_hz,
            f.iter()
                .zip(full.frequencies_hz())
                .map(|(a, b)| format!("{:.2e}", a / b - 1.0))
                .collect::<Vec<_>>()
        );
    }
    let run = |ordering| {
        craig_bampton(
            mesh.k.as_ref(),
            mesh.m.as_ref(),
            &b,
            &[],
            &CbOptions {
                ordering,
                ..CbOptions::with_modes(15)
            },
        )
        .unwrap()
    };
    let x = run(Ordering::Metis);
    let y = run(Ordering::Amd);
    let nb = b.len();
    let d = &x.mass - &y.mass;
    println!(
        "nb {nb}, BB diff {:e}, coupling diff {:e}, modal diff {:e}",
        d.submatrix(0, 0, nb, nb).norm_max(),
        d.submatrix(0, nb, nb, x.n_modes).norm_max(),
        d.submatrix(nb, nb, x.n_modes, x.n_modes).norm_max()
    );
    println!(
        "K BB diff {:e}, max {:e}; lambdas {:?} vs {:?}",
        (&x.stiffness - &y.stiffness)
            .submatrix(0, 0, nb, nb)
            .norm_max(),
        x.stiffness.norm_max(),
        &x.modal_eigenvalues[..3],
        &y.modal_eigenvalues[..3]
    );
    for a in 0..x.n_modes {
        let c = d.submatrix(0, nb + a, nb, 1).norm_max();
        if c > 1e-12 {
            println!(
                "mode {a} coupling diff {c:e} vs {:e}",
                x.mass.submatrix(0, nb + a, nb, 1).norm_max()
            );
        }
    }
}
