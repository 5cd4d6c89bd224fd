//! Criterion bench of single Gauss-point updates (updates per second) for every
//! material model, along a fixed pseudo-random strain path of 1000 increments.

#[path = "common/workload.rs"]
mod workload;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use rothe::config::MaterialSpec;
use rothe::material::StrainStep;

const MODELS: [(&str, &str); 6] = [
    ("elastic", "model = \"elastic\""),
    ("kelvin_voigt", "model = \"kelvin_voigt\"\nbeta = 1e6"),
    ("sls", "model = \"sls\"\nalpha = 0.5\nbeta = 1e-3"),
    ("mazars", "model = \"mazars\"\neps_t0 = 1.0e-4\nA_t = 1.0\nB_t = 1.0e4\nA_c = 1.2\nB_c = 1.5e3"),
    ("mazars_classic", "model = \"mazars\"\nvariant = \"classic\"\neps_t0 = 1.0e-4\nA_t = 1.0\nB_t = 1.0e4\nA_c = 1.2\nB_c = 1.5e3"),
    ("rankine_hill", "model = \"rankine_hill\"\ntension = { law = \"bilinear\", strength = 2.9e6, post_yield_modulus = 1.65e9 }\ncompression = { law = \"bilinear\", strength = 30.0e6, post_yield_modulus = 1.65e9 }"),
];

fn updates(c: &mut Criterion) {
    let mut g = c.benchmark_group("gauss_point_update");
    let n = 1000;
    // A cyclic biaxial path with shear reaching about 3x the cracking strain.
    let path: Vec<[f64; 3]> = (0..n)
        .map(|k| {
            let t = k as f64 / n as f64 * 6.0 * std::f64::consts::PI;
            [
                3e-4 * t.sin(),
                -1e-4 * (1.3 * t).cos(),
                2e-4 * (0.7 * t).sin(),
            ]
        })
        .collect();
    g.throughput(Throughput::Elements(n as u64));
    for (name, text) in MODELS {
        let spec: MaterialSpec =
            toml::from_str(&format!("{text}\nE = 33e9\nnu = 0.2\nrho = 2400.0")).unwrap();
        let m = rothe::config::material(name, "material", &spec).unwrap();
        let ns = m.n_state(3);
        g.bench_with_input(BenchmarkId::new(name, n), &n, |b, _| {
            b.iter(|| {
                let (mut st_n, mut st) = (vec![0.0; ns], vec![0.0; ns]);
                let mut eps_n = [0.0; 3];
                let mut acc = 0.0;
                for eps in &path {
                    let r = m.update::<3, rothe::fe::PlaneStress>(
                        &StrainStep {
                            eps_n,
                            eps: *eps,
                            dt: 1e-5,
                            length: 0.1,
                            tangent: true,
                        },
                        &st_n,
                        &mut st,
                    );
                    acc += r.sigma[0];
                    eps_n = *eps;
                    std::mem::swap(&mut st_n, &mut st);
                }
                acc
            })
        });
    }
    g.finish();
}

/// The Gauss-point pass of a solid (W3 at `n = 16`: 16 384 hexahedra, 8 points each,
/// about as many as W3's runs hold per core; smaller meshes measure the thread
/// pool's wake-ups more than the points)
/// for the elastic and Mazars models: internal force, trial states and energies at a
/// bending field that cracks the clamped end (Mazars). Throughput in elements; the
/// pass runs on every core, so per core is the figure over the core count.
fn solid_pass(c: &mut Criterion) {
    use rothe::assembly::internal::{new_stores, PointPass};
    let mut g = c.benchmark_group("solid_gauss_point_pass");
    for (name, text) in [MODELS[0], MODELS[3]] {
        let scenario = workload::w3_scenario(16).replace("model = \"elastic\"", text);
        let model = rothe::config::from_str(&scenario, std::path::Path::new(".")).unwrap();
        let asm = rothe::assembly::Assembler::new(&model.mesh);
        let mut stores = new_stores(&model.mesh, &model.materials);
        // u_y = -c x²: curvature 2c, strain 2c·|y - 0.25| at most 0.25 * 2c = 4e-4.
        let u: Vec<f64> = model
            .mesh
            .coords
            .iter()
            .flat_map(|x| [-8e-4 * x[0] * (x[1] - 0.25), -4e-4 * x[0] * x[0], 0.0])
            .collect();
        let mut f = vec![0.0; u.len()];
        g.throughput(Throughput::Elements(model.mesh.n_elements() as u64));
        g.bench_function(name, |b| {
            b.iter(|| {
                asm.internal_force(
                    &model.mesh,
                    &model.materials,
                    model.idealisation,
                    PointPass {
                        u: &u,
                        dt: 1e-5,
                        at_rest: false,
                        frozen: false,
                    },
                    &mut stores,
                    &mut f,
                    None,
                    None,
                    None,
                )
            })
        });
    }
    g.finish();
}

criterion_group!(benches, updates, solid_pass);
criterion_main!(benches);
