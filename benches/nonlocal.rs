//! Criterion bench of the nonlocal averaging against the Gauss-point pass it adds to:
//! benchmark 1's concrete block (1.2 m × 0.6 m, Q4) with NOTES.md's identified Mazars
//! concrete, `R = 0.1 m`, at element sizes 0.05, 0.025 and 0.0125 m. Timed: the local
//! Gauss-point pass of an implicit iterate (forces, trial states and tangent), the
//! nonlocal pass alone (the drivers at every point and their averages), and the whole
//! pass of the nonlocal material (both). The neighbour table is built before timing
//! (once per mesh).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use rothe::assembly::internal::{new_stores, PointPass};
use rothe::assembly::Assembler;

fn block(size: f64, nonlocal: bool) -> rothe::model::Model {
    let text = format!(
        r#"
[analysis]
t_end = 1.0e-3
dt = 1.0e-6
vtk_every = 0
[materials.concrete]
model = "mazars"
E = 33e9
nu = 0.2
rho = 2400.0
identify = {{ f_ct = 2.9e6, f_cm = 38.0e6, eps_c1 = 2.2e-3 }}
{nl}
[[bodies]]
name = "concrete"
material = "concrete"
thickness = 0.4
mesh = {{ kind = "rectangle", size = [1.2, 0.6], element_size = {size} }}
[[supports]]
set = "concrete.bottom"
fix = ["x", "y"]
"#,
        nl = if nonlocal {
            "nonlocal = { radius = 0.1 }"
        } else {
            ""
        }
    );
    rothe::config::from_str(&text, std::path::Path::new(".")).unwrap()
}

fn passes(c: &mut Criterion) {
    let mut g = c.benchmark_group("nonlocal");
    g.sample_size(10);
    for size in [0.05, 0.025, 0.0125] {
        let label = format!("{size}");
        for nonlocal in [false, true] {
            let model = block(size, nonlocal);
            let asm = Assembler::new(&model.mesh);
            let mut points = new_stores(&model.mesh, &model.materials);
            let n = model.mesh.n_dofs();
            // A field with strains around the tensile threshold (some points damage).
            let u: Vec<f64> = (0..n)
                .map(|i| {
                    let x = model.mesh.coords[i / 2];
                    1e-4 * (x[0] * x[1] * 7.0 + (i % 2) as f64 * x[1]).sin() * x[1]
                })
                .collect();
            let mut f = vec![0.0; n];
            let mut kt = vec![0.0; asm.pattern.nnz()];
            let name = if nonlocal {
                "nonlocal_gauss_point_pass"
            } else {
                "local_gauss_point_pass"
            };
            g.bench_with_input(BenchmarkId::new(name, &label), &size, |b, _| {
                b.iter(|| {
                    asm.internal_force(
                        &model.mesh,
                        &model.materials,
                        model.idealisation,
                        PointPass {
                            u: &u,
                            dt: 1e-6,
                            at_rest: false,
                            frozen: false,
                        },
                        &mut points,
                        &mut f,
                        None,
                        Some(&mut kt),
                        None,
                    )
                })
            });
            if nonlocal {
                g.bench_with_input(BenchmarkId::new("averaging_only", &label), &size, |b, _| {
                    b.iter(|| {
                        drop(asm.nonlocal_at(
                            &model.mesh,
                            &model.materials,
                            model.idealisation,
                            &u,
                            &points,
                        ));
                    })
                });
            }
        }
    }
    g.finish();
}

criterion_group!(benches, passes);
criterion_main!(benches);
