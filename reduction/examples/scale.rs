//! Scale check: build a synthetic clamped 2D plane-stress strip (or a 3D hex
//! bar with `--hex`) of about `--dofs` DOFs in memory, reduce it and print
//! a table of sizes, times per phase and peak memory.
//!
//! ```text
//! cargo run --release -p fricbound-reduction --example scale -- \
//!     --dofs 1000000 --modes 50 --boundary 400 [--hex] [--aspect 2] \
//!     [--ordering metis|amd|both] [--threads 1] [--block-size 64]
//! ```
//!
//! The boundary DOFs are the nodes of the top edge (face) nearest the free
//! end, all components, as a contact patch would be (then the bottom edge
//! if the top one is too short). The peak memory of the
//! reduction alone is measured by resetting the kernel's high-water mark
//! (`/proc/self/clear_refs`) after the mesh is built; the mesh itself (K and
//! M) stays resident and is included.

use fricbound_reduction::testmodels::{cantilever_2d, cantilever_3d, Mesh};
use fricbound_reduction::{craig_bampton, peak_memory_bytes, CbOptions, Ordering};
use std::time::Instant;

struct Args {
    dofs: usize,
    modes: usize,
    boundary: usize,
    hex: bool,
    aspect: f64,
    orderings: Vec<Ordering>,
    threads: usize,
    block_size: usize,
    lanczos_block: usize,
    basis_factor: f64,
}

fn parse() -> Result<Args, String> {
    let mut a = Args {
        dofs: 10_000,
        modes: 50,
        boundary: 400,
        hex: false,
        aspect: 2.0,
        orderings: vec![Ordering::Metis],
        threads: 1,
        block_size: 64,
        lanczos_block: 8,
        basis_factor: 2.0,
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        let mut value = || it.next().ok_or(format!("{flag} needs a value"));
        match flag.as_str() {
            "--dofs" => a.dofs = value()?.parse().map_err(|e| format!("--dofs: {e}"))?,
            "--modes" => a.modes = value()?.parse().map_err(|e| format!("--modes: {e}"))?,
            "--boundary" => {
                a.boundary = value()?.parse().map_err(|e| format!("--boundary: {e}"))?
            }
            "--aspect" => a.aspect = value()?.parse().map_err(|e| format!("--aspect: {e}"))?,
            "--threads" => a.threads = value()?.parse().map_err(|e| format!("--threads: {e}"))?,
            "--block-size" => {
                a.block_size = value()?
                    .parse()
                    .map_err(|e| format!("--block-size: {e}"))?
            }
            "--lanczos-block" => {
                a.lanczos_block = value()?
                    .parse()
                    .map_err(|e| format!("--lanczos-block: {e}"))?
            }
            "--basis-factor" => {
                a.basis_factor = value()?
                    .parse()
                    .map_err(|e| format!("--basis-factor: {e}"))?
            }
            "--hex" => a.hex = true,
            "--ordering" => {
                a.orderings = match value()?.as_str() {
                    "metis" => vec![Ordering::Metis],
                    "amd" => vec![Ordering::Amd],
                    "both" => vec![Ordering::Metis, Ordering::Amd],
                    o => return Err(format!("unknown ordering {o}")),
                }
            }
            "-h" | "--help" => {
                return Err("usage: scale --dofs N --modes M --boundary B [--hex] [--aspect A] [--ordering metis|amd|both] [--threads T] [--block-size S] [--lanczos-block P] [--basis-factor F]".into())
            }
            f => return Err(format!("unknown argument {f}")),
        }
    }
    Ok(a)
}

/// Contact patch: nodes of the top edge/face, from the free end inwards
/// (then of the bottom edge/face).
fn boundary_dofs(mesh: &Mesh, want: usize) -> Vec<usize> {
    let bd = &mesh.bodies[0];
    let [nx, ny, nz] = bd.nodes;
    let mut out = Vec::new();
    // top edge/face first, then the bottom one if more DOFs are asked
    'outer: for iy in [ny - 1, 0] {
        for ix in (1..nx).rev() {
            for iz in 0..nz {
                for d in bd.node_dofs(ix, iy, iz) {
                    if out.len() == want {
                        break 'outer;
                    }
                    out.push(d);
                }
            }
        }
    }
    out
}

fn gib(b: Option<u64>) -> String {
    b.map(|b| format!("{:.2}", b as f64 / (1u64 << 30) as f64))
        .unwrap_or_else(|| "n/a".into())
}

fn main() {
    let args = match parse() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    let t0 = Instant::now();
    let mesh = if args.hex {
        cantilever_3d(args.dofs, args.aspect)
    } else {
        cantilever_2d(args.dofs, args.aspect)
    };
    let t_mesh = t0.elapsed().as_secs_f64();
    let [nx, ny, nz] = mesh.bodies[0].nodes;
    println!(
        "mesh: {} {} nodes × {} × {} -> {} DOFs, K nnz {}, built in {:.1} s, peak so far {} GiB",
        if args.hex { "3D hex" } else { "2D quad" },
        nx,
        ny,
        nz,
        mesh.n(),
        mesh.k.compute_nnz(),
        t_mesh,
        gib(peak_memory_bytes())
    );
    let boundary = boundary_dofs(&mesh, args.boundary);
    // recovery: a few DOFs along the mid line
    let bd = &mesh.bodies[0];
    let recover: Vec<usize> = (1..=10)
        .filter_map(|k| bd.dof(k * (nx - 1) / 10, ny / 2, nz / 2, 0))
        .collect();
    println!(
        "{:>9} {:>5} {:>5} {:>6} {:>11} | {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} | {:>7} | {:>8} {:>8} {:>9}",
        "DOFs",
        "nb",
        "modes",
        "order",
        "factor nnz",
        "valid",
        "factor",
        "eigen",
        "constr",
        "sturm",
        "cpu",
        "wall",
        "peak GiB",
        "maxres",
        "cutoff Hz"
    );
    println!("{:>42} | {:^55} |", "", "CPU seconds (one thread)");
    for &ordering in &args.orderings {
        // reset the high-water mark so that the peak is that of this reduction
        let _ = std::fs::write("/proc/self/clear_refs", "5");
        let opts = CbOptions {
            n_modes: args.modes,
            ordering,
            threads: args.threads,
            block_size: args.block_size,
            lanczos: fricbound_reduction::LanczosOptions {
                block: args.lanczos_block,
                basis_factor: args.basis_factor,
                ..Default::default()
            },
            ..Default::default()
        };
        match craig_bampton(mesh.k.as_ref(), mesh.m.as_ref(), &boundary, &recover, &opts) {
            Ok(r) => {
                let p = &r.report;
                let c = p.cpu_phases.unwrap_or_default();
                println!(
                    "{:>9} {:>5} {:>5} {:>6} {:>11} | {:>7.2} {:>7.2} {:>7.2} {:>7.2} {:>7.2} {:>7.1} | {:>7.1} | {:>8} {:>8.1e} {:>9.1}",
                    p.n_full,
                    p.n_boundary,
                    p.n_modes,
                    p.ordering.to_string(),
                    p.factor_nnz,
                    c.validate,
                    c.factor,
                    c.eigen,
                    c.constraint,
                    c.sturm,
                    p.cpu_seconds.unwrap_or(f64::NAN),
                    p.t_total,
                    gib(p.peak_memory_bytes),
                    p.eigen_max_residual,
                    p.cutoff_hz
                );
                eprintln!("{p}");
            }
            Err(e) => {
                eprintln!("reduction failed: {e}");
                std::process::exit(1);
            }
        }
    }
    println!(
        "threads: {} (constraint-mode blocks), faer sequential",
        args.threads
    );
}
