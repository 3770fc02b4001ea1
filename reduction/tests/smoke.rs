use fricbound_reduction::testmodels::*;
use fricbound_reduction::*;

#[test]
fn smoke() {
    let (mesh, contact) = blades_and_damper(40, 8, true, 5, Some(1e8));
    let n = mesh.n();
    eprintln!("n = {n}, contact {}", contact.len());
    let full = lowest_eigenpairs(mesh.k.as_ref(), mesh.m.as_ref(), 12, 0.0).unwrap();
    eprintln!(
        "full: {:?} res {:e} restarts {}",
        full.frequencies_hz(),
        full.max_residual,
        full.restarts
    );
    let opts = CbOptions::with_modes(20);
    let r = craig_bampton(mesh.k.as_ref(), mesh.m.as_ref(), &contact, &[0, 5], &opts).unwrap();
    eprintln!("{}", r.report);
    let (vals, _) = dense_generalized_eigenvalues(r.stiffness.as_ref(), r.mass.as_ref()).unwrap();
    let f: Vec<f64> = vals
        .iter()
        .take(12)
        .map(|l| l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI))
        .collect();
    eprintln!("red : {:?}", f);
}
