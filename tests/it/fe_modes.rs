//! The FE analyst's workflow: `fricbound modes`, `[reduction.boundary]`, `fricbound reduce`
//! and DOF maps as exporters write them, against independent numbers.
//!
//! - Two identical fixed-free spring chains (x and y of the same nodes, Matrix Market with a
//!   0-based `node_id,dof,row` DOF map): the Lanczos path's frequencies against the closed
//!   form λ_j = (4k/m) sin²((2j−1)π/(2(2n+1))), every copy of each repeated pair reported,
//!   the Sturm count equal to the modes kept.
//! - The same chains, smaller: reduced-model errors shrink as fixed-interface modes are added;
//!   `reduce` output re-read gives the reduced model's frequencies; the reduced DOF map and
//!   the recovery rows; `check` prints the boundary make-up and warns about the contact node
//!   whose contact row uses only x.
//! - The cantilever plate of `tests/fe_data`: full-model frequencies (contacts open and stuck)
//!   against a dense eigen solve written here; mode shapes on the mesh as VTU.
//! - A Rayleigh-damped 2-DOF model: damping ratios α/(2ω) + βω/2 and damped frequencies.

use std::path::{Path, PathBuf};

use faer::Mat;
use fricbound::analysis::linear::LinearCase;
use fricbound::analysis::modes::{self, EigenMethod};
use fricbound::cli::modes::{modes, reduce, ContactCases, ModesOptions, ReduceOptions};
use fricbound::fe::matrix_market::{read_dof_map_with_base, read_symmetric_matrix};
use fricbound::fe::{Direction, Dof};

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// Closed-form eigenvalue j (1-based) of a fixed-free chain of n masses m and springs k.
fn chain_lambda(k: f64, m: f64, n: usize, j: usize) -> f64 {
    let s = ((2 * j - 1) as f64 * std::f64::consts::PI / (2.0 * (2 * n + 1) as f64)).sin();
    4.0 * k / m * s * s
}

const K_CHAIN: f64 = 1.0e8;
const M_CHAIN: f64 = 1.0;

/// Two identical decoupled fixed-free chains of `n` nodes (directions x and y of nodes
/// 1..=n), K and M as Matrix Market, a 0-based DOF map with the header `node_id,dof,row` and
/// numeric directions (1 = x, 2 = y); the scene (with `extra` appended) grounds node n's x
/// through one contact with a zero normal. Returns the scene path.
fn chain_scene(dir: &Path, n: usize, extra: &str) -> PathBuf {
    let row = |node: usize, d: usize| 2 * (node - 1) + d;
    let mut k = Vec::new();
    let mut m = Vec::new();
    for d in 0..2 {
        for i in 1..=n {
            let diag = if i < n { 2.0 * K_CHAIN } else { K_CHAIN };
            k.push((row(i, d), row(i, d), diag));
            if i < n {
                k.push((row(i + 1, d), row(i, d), -K_CHAIN));
            }
            m.push((row(i, d), row(i, d), M_CHAIN));
        }
    }
    let mtx = |t: &[(usize, usize, f64)]| {
        let mut s = format!(
            "%%MatrixMarket matrix coordinate real symmetric\n{} {} {}\n",
            2 * n,
            2 * n,
            t.len()
        );
        for (i, j, v) in t {
            s.push_str(&format!("{} {} {v:e}\n", i + 1, j + 1));
        }
        s
    };
    write(dir, "k.mtx", &mtx(&k));
    write(dir, "m.mtx", &mtx(&m));
    let mut map = String::from("# exported with 0-based rows\nnode_id,dof,row\n");
    for i in 1..=n {
        for d in 0..2 {
            map.push_str(&format!("{i},{},{}\n", d + 1, row(i, d)));
        }
    }
    write(dir, "dofs.csv", &map);
    let scene = format!(
        r#"title = "two fixed-free chains"
[model.matrix_market]
stiffness = "k.mtx"
mass = "m.mtx"
dof_map = "dofs.csv"
dof_map_base = 0

[[contacts]]
name = "tip"
damper = ["{n}.x"]
tangent = [1.0]
normal = [0.0]
kt = 1.0e6
kn = 1.0e6
mu = 0.3
gap = -1.0e-4

[[harmonic_loads]]
dof = "{n}.x"
harmonic = 1
cos = 1.0

[harmonics]
max = 1
samples = 32

[analysis]
freq_start_hz = 1.0
freq_end_hz = 2.0

[output]
dofs = ["1.x"]
{extra}"#
    );
    write(dir, "chains.toml", &scene)
}

#[test]
fn dof_map_header_variants_are_accepted_and_a_bad_header_lists_them() {
    let dir = tempfile::tempdir().unwrap();
    let x = |node| Dof {
        node,
        direction: Direction::X,
    };
    let y = |node| Dof {
        node,
        direction: Direction::Y,
    };
    let cases = [
        ("node,direction,row\n7,x,1\n7,y,2\n", None),
        ("node_id,direction,row\n7,x,0\n7,y,1\n", Some(0)),
        ("NID,DOF,row0\n7,1,0\n7,2,1\n", None),
        ("nodeid,dir,index\n7,x,0\n7,2,1\n", Some(0)),
        ("node,dof,row1\n7,1,1\n7,y,2\n", Some(1)),
    ];
    for (i, (text, base)) in cases.iter().enumerate() {
        let p = write(dir.path(), &format!("map{i}.csv"), text);
        let map = read_dof_map_with_base(&p, 2, *base)
            .unwrap_or_else(|e| panic!("variant {i} refused: {e}"));
        assert_eq!(map.row(7, Direction::X), Some(0), "variant {i}");
        assert_eq!(map.row(7, Direction::Y), Some(1), "variant {i}");
        assert_eq!(map.dofs(), &[x(7), y(7)]);
    }
    let bad = write(dir.path(), "bad.csv", "id,axis,row\n7,x,1\n7,y,2\n");
    let msg = read_dof_map_with_base(&bad, 2, None)
        .unwrap_err()
        .to_string();
    for accepted in [
        "bad.csv",
        "line 1",
        "node_id",
        "`dof`",
        "row0",
        "row1",
        "1-6",
        "id,axis,row",
    ] {
        assert!(msg.contains(accepted), "`{accepted}` missing from: {msg}");
    }
    let conflict = write(
        dir.path(),
        "conflict.csv",
        "node,direction,row1\n7,x,1\n7,y,2\n",
    );
    let msg = read_dof_map_with_base(&conflict, 2, Some(0))
        .unwrap_err()
        .to_string();
    assert!(msg.contains("dof_map_base = 0"), "{msg}");
    // 0-based rows read as 1-based are out of range: the base matters.
    let zero = write(
        dir.path(),
        "zero.csv",
        "node_id,direction,row\n7,x,0\n7,y,1\n",
    );
    assert!(read_dof_map_with_base(&zero, 2, None).is_err());
}

#[test]
fn lanczos_frequencies_of_two_identical_chains_match_the_closed_form_with_every_copy() {
    let dir = tempfile::tempdir().unwrap();
    let n = 1100; // 2200 DOFs: above the dense limit
    assert!(2 * n > modes::DENSE_MAX_DOFS);
    let scene = chain_scene(dir.path(), n, "");
    let report = modes(&ModesOptions {
        scene,
        count: 3,
        contacts: ContactCases::Open,
        out: Some(dir.path().join("out")),
        overrides: Vec::new(),
    })
    .unwrap();
    let full = &report.cases[0].full;
    assert!(report.cases[0].reduced.is_none());
    // 3 asked: the 2nd pair is completed to 4.
    assert_eq!(full.modes.len(), 4, "{:?}", full.modes);
    match &full.method {
        EigenMethod::Lanczos { sturm_count, .. } => assert_eq!(*sturm_count, Some(4)),
        m => panic!("expected Lanczos, got {m:?}"),
    }
    for (i, mode) in full.modes.iter().enumerate() {
        let exact = chain_lambda(K_CHAIN, M_CHAIN, n, i / 2 + 1);
        assert!(!mode.rigid);
        assert!(
            ((mode.eigenvalue - exact) / exact).abs() < 1e-8,
            "mode {}: {} vs {exact}",
            i + 1,
            mode.eigenvalue
        );
    }
    let csv = std::fs::read_to_string(report.dir.join("modes.csv")).unwrap();
    assert_eq!(csv.lines().count(), 5, "{csv}");
    assert!(report.dir.join("mode_shapes_full_open.csv").exists());
    assert!(report.dir.join("modes.json").exists());
}

#[test]
fn reduced_errors_shrink_with_modes_and_reduce_output_rereads_to_the_same_frequencies() {
    let dir = tempfile::tempdir().unwrap();
    let n = 200;
    let scene = chain_scene(dir.path(), n, "\n[reduction]\nmodes = 8\n");
    // The full model's lowest frequencies: 4 per case.
    let mut worst_previous = f64::INFINITY;
    let mut worst_errors = Vec::new();
    for kept in [2, 4, 8, 16] {
        let report = modes(&ModesOptions {
            scene: scene.clone(),
            count: 4,
            contacts: ContactCases::Both,
            out: Some(dir.path().join(format!("modes{kept}"))),
            overrides: vec![format!("reduction.modes={kept}")],
        })
        .unwrap();
        let red = report.reduction.as_ref().unwrap();
        // Node n's x (contact row) and y (completed), and the output 1.x.
        assert_eq!(
            (
                red.n_boundary,
                red.boundary_contacts,
                red.boundary_contact_nodes,
                red.boundary_outputs
            ),
            (3, 1, 1, 1)
        );
        let mut worst = 0.0_f64;
        for c in &report.cases {
            let errors = fricbound::report::modes_files::relative_errors(c);
            assert_eq!(errors.len(), 4);
            for e in errors {
                let e = e.unwrap();
                // Rayleigh-Ritz: a reduced frequency is never below the full one.
                assert!(e > -1e-9, "{e}");
                worst = worst.max(e);
            }
        }
        assert!(
            worst < worst_previous,
            "{kept} modes: worst error {worst:e}, before {worst_previous:e}"
        );
        worst_previous = worst;
        worst_errors.push(worst);
    }
    eprintln!("worst relative errors, 2/4/8/16 modes: {worst_errors:?}");
    // Converging, not merely decreasing: 16 modes at least ten times better than 2.
    assert!(worst_previous < 0.1 * worst_errors[0], "{worst_errors:?}");

    let out = dir.path().join("reduced");
    let written = reduce(&ReduceOptions {
        scene: scene.clone(),
        out: Some(out.clone()),
        overrides: Vec::new(),
    })
    .unwrap();
    let nr = written.reduction.n_reduced;
    assert_eq!(nr, 3 + 8);
    let k = read_symmetric_matrix(&out.join("K_r.mtx"), 1e-8).unwrap();
    let m = read_symmetric_matrix(&out.join("M_r.mtx"), 1e-8).unwrap();
    assert_eq!(k.nrows(), nr);
    let (values, _) = fricbound_reduction::dense_generalized_eigenvalues(
        k.to_dense().as_ref(),
        m.to_dense().as_ref(),
    )
    .unwrap();
    let again = modes(&ModesOptions {
        scene: scene.clone(),
        count: 4,
        contacts: ContactCases::Open,
        out: Some(dir.path().join("modes-again")),
        overrides: Vec::new(),
    })
    .unwrap();
    let reduced = again.cases[0].reduced.as_ref().unwrap();
    for (mode, lambda) in reduced.modes.iter().zip(&values) {
        assert!(
            ((mode.eigenvalue - lambda) / lambda).abs() < 1e-9,
            "{} vs re-read {lambda}",
            mode.eigenvalue
        );
    }
    let dofs = std::fs::read_to_string(out.join("reduced_dofs.csv")).unwrap();
    let lines: Vec<&str> = dofs.lines().collect();
    assert_eq!(lines.len(), nr + 1);
    assert_eq!(lines[0], "row,name,kind,node,direction,fixed_interface_hz");
    assert_eq!(lines[1], "1,1.x,physical,1,x,");
    assert_eq!(lines[2], format!("2,{n}.x,physical,{n},x,"));
    assert_eq!(lines[3], format!("3,{n}.y,physical,{n},y,"));
    assert!(lines[4].starts_with("4,mode1,modal,,,"), "{}", lines[4]);
    assert!(!out.join("C_r.mtx").exists(), "undamped model: no C_r");
    // Recovery row of the output 1.x: the unit row of its boundary coordinate.
    let recovery = std::fs::read_to_string(out.join("recovery_dofs.csv")).unwrap();
    assert_eq!(recovery, "row,dof\n1,1.x\n");
    let t = read_general_rows(&out.join("recovery.mtx"));
    assert_eq!(t.len(), 1);
    assert_eq!(t[0].len(), nr);
    assert!((t[0][0] - 1.0).abs() < 1e-12 && t[0][1..].iter().all(|v| v.abs() < 1e-12));

    let check = fricbound::cli::check(Some(&scene), &[]).unwrap();
    assert!(
        check.contains("boundary     3 DOFs kept physical: 1 contact, 1 other directions"),
        "{check}"
    );
    assert!(
        check.contains(&format!(
            "warning      contact tip uses direction(s) x of node {n}, which has x,y"
        )),
        "{check}"
    );
}

/// Eigenvalues of K φ = λ M φ by a dense solve written here: M = LLᵀ, the eigenvalues of
/// the symmetric L⁻¹ K L⁻ᵀ.
fn dense_eigenvalues(k: &Mat<f64>, m: &Mat<f64>) -> Vec<f64> {
    let n = k.nrows();
    let l = m.llt(faer::Side::Lower).unwrap().L().to_owned();
    let mut linv = Mat::<f64>::identity(n, n);
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(
        l.as_ref(),
        linv.as_mut(),
        faer::Par::Seq,
    );
    let a = &linv * k * linv.transpose();
    let sym = Mat::from_fn(n, n, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]));
    sym.self_adjoint_eigenvalues(faer::Side::Lower).unwrap()
}

/// Rows of a Matrix Market `coordinate real general` file, parsed here.
fn read_general_rows(path: &Path) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('%'));
    let size: Vec<usize> = lines
        .next()
        .unwrap()
        .split_whitespace()
        .map(|v| v.parse().unwrap())
        .collect();
    let mut rows = vec![vec![0.0; size[1]]; size[0]];
    for l in lines {
        let f: Vec<&str> = l.split_whitespace().collect();
        let (i, j): (usize, usize) = (f[0].parse().unwrap(), f[1].parse().unwrap());
        rows[i - 1][j - 1] = f[2].parse().unwrap();
    }
    rows
}

#[test]
fn plate_cantilever_frequencies_match_a_dense_eigen_solve() {
    let dir = tempfile::tempdir().unwrap();
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fe_data/plate-ascii.msh");
    let mesh = fricbound::fe::read_msh(&data).unwrap();
    let tip = mesh
        .nodes
        .iter()
        .find(|p| (p.coords[0] - 0.2).abs() < 1e-9 && (p.coords[1] - 0.05).abs() < 1e-9)
        .expect("tip corner node")
        .id;
    let scene_text = format!(
        r#"[model]
mesh = "{mesh}"
plane = "stress"
clamp = ["clamp"]

[[model.materials]]
group = "quads"
young = 2.1e11
poisson = 0.3
density = 7850.0
thickness = 0.01

[[model.materials]]
group = "triangles"
young = 2.1e11
poisson = 0.3
density = 7850.0
thickness = 0.01

[[contacts]]
name = "tip"
damper = ["{tip}.y"]
tangent = [1.0]
normal = [0.0]
kt = 1.0e6
kn = 1.0e6
mu = 0.3
gap = -1.0e-4

[[harmonic_loads]]
dof = "{tip}.y"
harmonic = 1
cos = 1.0

[harmonics]
max = 1
samples = 32

[analysis]
freq_start_hz = 10.0
freq_end_hz = 20.0

[output]
dofs = ["{tip}.y"]

[reduction]
modes = 6
[reduction.boundary]
groups = ["tip_edge"]
"#,
        mesh = data.display()
    );
    let scene = write(dir.path(), "plate.toml", &scene_text);
    let report = modes(&ModesOptions {
        scene: scene.clone(),
        count: 6,
        contacts: ContactCases::Both,
        out: Some(dir.path().join("out")),
        overrides: Vec::new(),
    })
    .unwrap();
    let (full, _) = fricbound::scene::load(&scene, &[])
        .unwrap()
        .validate_unreduced("plate")
        .unwrap();
    let tip_y = full.model.dof_index(&format!("{tip}.y")).unwrap();
    for c in &report.cases {
        let mut k = full.model.stiffness.to_dense();
        if c.full.case == LinearCase::Stuck {
            k[(tip_y, tip_y)] += 1.0e6;
        }
        let exact = dense_eigenvalues(&k, &full.model.mass.to_dense());
        assert_eq!(c.full.modes.len(), 6);
        assert_eq!(c.full.method, EigenMethod::Dense);
        for (i, mode) in c.full.modes.iter().enumerate() {
            assert!(
                ((mode.eigenvalue - exact[i]) / exact[i]).abs() < 1e-9,
                "{:?} mode {}: {} vs {}",
                c.full.case,
                i + 1,
                mode.eigenvalue,
                exact[i]
            );
        }
        assert!(report
            .dir
            .join(format!("modes_full_{}.vtu", modes::case_name(c.full.case)))
            .exists());
    }
    // The tip edge kept physical in both directions: its nodes but the tip corner (whose x
    // and y are kept already, as the contact node) are extra.
    let tip_nodes = mesh.group_nodes("tip_edge").unwrap().len();
    let red = report.reduction.as_ref().unwrap();
    assert_eq!(
        (
            red.boundary_contacts,
            red.boundary_contact_nodes,
            red.boundary_outputs
        ),
        (1, 1, 0)
    );
    assert_eq!(red.boundary_extra, 2 * tip_nodes - 2);
    assert!(report.dir.join("modes_reduced_stuck.vtu").exists());
    for c in &report.cases {
        for e in fricbound::report::modes_files::relative_errors(c) {
            assert!(e.unwrap() > -1e-9);
        }
    }
    // The stuck spring stiffens: every stuck frequency at or above the open one.
    for (o, s) in report.cases[0]
        .full
        .modes
        .iter()
        .zip(&report.cases[1].full.modes)
    {
        assert!(s.eigenvalue >= o.eigenvalue * (1.0 - 1e-12));
    }
}

/// `modes` of a Rayleigh-damped (α = 3 1/s, β = 2e-5 s) inline 2-DOF model with stiffness
/// `k`, contacts open and stuck (a grounded contact on `b`).
fn damped_two_dof(dir: &Path, k: [[f64; 2]; 2]) -> (fricbound::cli::modes::ModesReport, f64, f64) {
    let (alpha, beta) = (3.0, 2.0e-5);
    let m = [[2.0, 0.0], [0.0, 1.0]];
    let c: Vec<Vec<f64>> = (0..2)
        .map(|i| (0..2).map(|j| alpha * m[i][j] + beta * k[i][j]).collect())
        .collect();
    let scene = write(
        dir,
        "damped.toml",
        &format!(
            r#"[model]
dofs = ["a", "b"]
mass = [[2.0, 0.0], [0.0, 1.0]]
stiffness = [[{}, {}], [{}, {}]]
damping = [[{}, {}], [{}, {}]]

[[contacts]]
name = "g"
damper = ["b"]
tangent = [1.0]
normal = [0.0]
kt = 1.0e4
kn = 1.0e4
mu = 0.3
gap = -1.0e-4

[[harmonic_loads]]
dof = "b"
harmonic = 1
cos = 1.0

[harmonics]
max = 1
samples = 32

[analysis]
freq_start_hz = 10.0
freq_end_hz = 100.0

[output]
dofs = ["b"]
"#,
            k[0][0], k[0][1], k[1][0], k[1][1], c[0][0], c[0][1], c[1][0], c[1][1]
        ),
    );
    let report = modes(&ModesOptions {
        scene,
        count: 2,
        contacts: ContactCases::Both,
        out: Some(dir.join("out")),
        overrides: Vec::new(),
    })
    .unwrap();
    (report, alpha, beta)
}

#[test]
fn rayleigh_damped_modes_have_the_closed_form_damping_ratios() {
    let dir = tempfile::tempdir().unwrap();
    let (report, alpha, beta) = damped_two_dof(dir.path(), [[3.0e5, -1.0e5], [-1.0e5, 1.0e5]]);
    // Contacts open: C = αM + βK is proportional. (Stuck, the contact spring is in K but not
    // in C, so the closed form does not apply; the modes are still listed.)
    assert_eq!(
        report.cases[1].full_damped.as_ref().map(|d| d.modes.len()),
        Some(2)
    );
    for case in &report.cases[..1] {
        assert_eq!(case.full.case, LinearCase::Open);
        let damped = case.full_damped.as_ref().expect("damped model");
        assert_eq!((damped.modes.len(), damped.rigid), (2, 0));
        for (d, u) in damped.modes.iter().zip(&case.full.modes) {
            let omega = u.eigenvalue.sqrt();
            let zeta = alpha / (2.0 * omega) + beta * omega / 2.0;
            let fd = omega * (1.0 - zeta * zeta).sqrt() / (2.0 * std::f64::consts::PI);
            assert!(
                (d.damping_ratio - zeta).abs() < 1e-9 * zeta.max(1.0),
                "{d:?} vs ζ {zeta}"
            );
            assert!((d.damped_hz - fd).abs() < 1e-9 * fd, "{d:?} vs {fd} Hz");
            assert!((d.natural_hz - u.frequency_hz).abs() < 1e-9 * fd);
        }
    }
    let csv = std::fs::read_to_string(report.dir.join("damped_modes.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 4, "{csv}");
}

#[test]
fn a_free_body_has_rigid_modes_at_zero_and_its_damped_rigid_eigenvalues_counted_apart() {
    let dir = tempfile::tempdir().unwrap();
    // Free-free pair: held only by the contact when stuck.
    let (report, alpha, beta) = damped_two_dof(dir.path(), [[1.0e5, -1.0e5], [-1.0e5, 1.0e5]]);
    let open = &report.cases[0];
    assert_eq!(open.full.case, LinearCase::Open);
    assert!(open.full.modes[0].rigid && open.full.modes[0].frequency_hz == 0.0);
    assert!(!open.full.modes[1].rigid);
    // The elastic mode: ω² = k (1/m_a + 1/m_b).
    let omega2 = 1.0e5 * (1.0 / 2.0 + 1.0);
    assert!((open.full.modes[1].eigenvalue - omega2).abs() < 1e-9 * omega2);
    let damped = open.full_damped.as_ref().unwrap();
    // s = 0 and s = −α for the rigid motion; one elastic mode.
    assert_eq!((damped.rigid, damped.modes.len()), (2, 1));
    let omega = omega2.sqrt();
    let zeta = alpha / (2.0 * omega) + beta * omega / 2.0;
    assert!(
        (damped.modes[0].damping_ratio - zeta).abs() < 1e-9,
        "{damped:?}"
    );
    let stuck = &report.cases[1];
    assert!(stuck.full.modes.iter().all(|m| !m.rigid));
    let text = &report.text;
    assert!(text.contains("1 rigid-body mode(s) at 0 Hz"), "{text}");
    assert!(text.contains("0 (rigid body)"), "{text}");
}

#[test]
fn reduction_boundary_keeps_extra_dofs_and_groups_and_refuses_bad_ones_by_field() {
    let dir = tempfile::tempdir().unwrap();
    // Chains: one extra DOF by name.
    let scene = chain_scene(
        dir.path(),
        50,
        "\n[reduction]\nmodes = 4\n[reduction.boundary]\ndofs = [\"20.x\", \"50.y\"]\n",
    );
    let out = dir.path().join("reduced");
    let r = reduce(&ReduceOptions {
        scene: scene.clone(),
        out: Some(out.clone()),
        overrides: Vec::new(),
    })
    .unwrap();
    // 50.y is already kept (the contact node's other direction): only 20.x is extra.
    let j = &r.reduction;
    assert_eq!(
        (
            j.n_boundary,
            j.boundary_contacts,
            j.boundary_contact_nodes,
            j.boundary_outputs,
            j.boundary_extra
        ),
        (4, 1, 1, 1, 1)
    );
    let dofs = std::fs::read_to_string(out.join("reduced_dofs.csv")).unwrap();
    assert!(dofs.contains("\n2,20.x,physical,20,x,\n"), "{dofs}");
    // A name that is not a DOF, and groups without a mesh, are refused naming the field.
    let bad = fricbound::scene::load(&scene, &["reduction.boundary.dofs=[\"20.q\"]".to_string()])
        .unwrap()
        .validate_unreduced(&scene.display().to_string())
        .unwrap_err()
        .to_string();
    assert!(bad.contains("reduction.boundary.dofs[0]"), "{bad}");
    let bad = fricbound::scene::load(&scene, &["reduction.boundary.groups=[\"tip\"]".to_string()])
        .unwrap()
        .validate_unreduced(&scene.display().to_string())
        .unwrap_err()
        .to_string();
    assert!(
        bad.contains("reduction.boundary.groups[0]") && bad.contains("mesh"),
        "{bad}"
    );
}
