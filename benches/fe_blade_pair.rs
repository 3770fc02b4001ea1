//! FE input at about 100 k DOFs: generating the blade-pair mesh, assembling K and M, clamping
//! and pairing the contact patches, for the 2D model (refine 10, 114 k DOFs) and the 3D model
//! (refine 2, 83 k DOFs); and writing/reading the 2D mesh as binary .msh.

use criterion::{criterion_group, criterion_main, Criterion};
use fricbound::fe::assembly::{assemble, GroupMaterial};
use fricbound::fe::blade_pair::{generate, BladePairParams};
use fricbound::fe::contact_patch::pair_patch;
use fricbound::fe::material::{Material, PlaneAssumption};
use fricbound::fe::msh_read::read_msh_bytes;
use fricbound::fe::msh_write::{msh_bytes, MshFormat};

fn materials() -> Vec<GroupMaterial> {
    ["blade1", "blade2", "damper"]
        .iter()
        .map(|g| GroupMaterial::new(g, Material::steel(0.01)))
        .collect()
}

fn blade_pair(c: &mut Criterion) {
    let mut group = c.benchmark_group("fe_blade_pair");
    group.sample_size(10);
    for (name, refine, three_d) in [("2d_114k", 10, false), ("3d_83k", 2, true)] {
        let params = BladePairParams {
            refine,
            three_d,
            ..BladePairParams::default()
        };
        group.bench_function(format!("generate_{name}"), |b| {
            b.iter(|| generate(&params).expect("mesh"))
        });
        let mesh = generate(&params).expect("mesh");
        group.bench_function(format!("assemble_{name}"), |b| {
            b.iter(|| assemble(&mesh, &materials(), PlaneAssumption::Stress).expect("assembly"))
        });
        let model = assemble(&mesh, &materials(), PlaneAssumption::Stress).expect("assembly");
        group.bench_function(format!("clamp_and_pair_{name}"), |b| {
            b.iter(|| {
                let clamped = model.clamp_group(&mesh, "clamp").expect("clamp");
                for spec in params.patch_specs().expect("specs") {
                    pair_patch(&mesh, &clamped.dofs, &spec).expect("pairs");
                }
            })
        });
        if !three_d {
            let bytes = msh_bytes(&mesh, MshFormat::Binary).expect("bytes");
            group.bench_function(format!("msh_binary_write_read_{name}"), |b| {
                b.iter(|| {
                    let bytes = msh_bytes(&mesh, MshFormat::Binary).expect("bytes");
                    read_msh_bytes(&bytes, "bench").expect("read")
                })
            });
            drop(bytes);
        }
    }
    group.finish();
}

criterion_group!(benches, blade_pair);
criterion_main!(benches);
