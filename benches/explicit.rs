//! Criterion bench of the explicit path on benchmark 1's two blocks (NOTES.md) at
//! 0.05 m and at a mesh 4x finer (0.0125 m):
//! - element updates per second (throughput in elements): the internal force of
//!   every element at new displacements, for elastic concrete (`K u` on the shared
//!   pattern) and for Mazars concrete (the Gauss-point loop with the damage update);
//! - one central-difference step in persistent contact, and the same step of the
//!   same state without the contact pair (the kinematic method's share).
//!
//! Single-threaded figures: run with `RAYON_NUM_THREADS=1`.

use criterion::{criterion_group, criterion_main, BatchSize, BenchmarkId, Criterion, Throughput};
use rothe::assembly::internal::{new_stores, PointPass};
use rothe::assembly::Assembler;
use rothe::model::Model;
use rothe::time::central_difference::CentralDifference;
use rothe::time::Integrator;

const MAZARS: &str =
    "model = \"mazars\"\neps_t0 = 1.0e-4\nA_t = 1.0\nB_t = 1.0e4\nA_c = 1.2\nB_c = 1.5e3";

fn scenario(size: f64, concrete: &str, contact: bool) -> Model {
    let base = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("examples/explicit/two_blocks_central_difference.toml"),
    )
    .unwrap();
    let (nx, ny, ns) = (
        (1.2 / size) as usize,
        (0.6 / size) as usize,
        (0.6 / size) as usize,
    );
    let mut text = base
        .replace("divisions = [24, 12]", &format!("divisions = [{nx}, {ny}]"))
        .replace("divisions = [12, 12]", &format!("divisions = [{ns}, {ns}]"))
        .replace("origin = [0.3, 0.61]", "origin = [0.3, 0.6001]")
        .replace("t_end = 4.0e-3", "t_end = 1.0")
        .replace("vtk_every = 100", "vtk_every = 0")
        .replace(
            "[materials.concrete]\nmodel = \"elastic\"",
            &format!("[materials.concrete]\n{concrete}"),
        );
    if !contact {
        let at = text
            .find("\n[[contact]]")
            .expect("the example has a contact pair")
            + 1;
        let end = text[at..].find("\n\n").map_or(text.len(), |e| at + e);
        text.replace_range(at..end, "");
    }
    rothe::config::from_str(&text, std::path::Path::new("."))
        .unwrap_or_else(|e| panic!("{e}\n{text}"))
}

const SIZES: [(f64, &str); 2] = [(0.05, "0.05m"), (0.0125, "0.0125m")];

fn element_updates(c: &mut Criterion) {
    let mut g = c.benchmark_group("explicit_element_updates");
    g.sample_size(10);
    for (size, label) in SIZES {
        for (name, concrete) in [("elastic", "model = \"elastic\""), ("mazars", MAZARS)] {
            let m = scenario(size, concrete, false);
            let asm = Assembler::new(&m.mesh);
            let n = m.mesh.n_dofs();
            let u: Vec<f64> = (0..n).map(|d| 1e-6 * ((d * 7919) % 13) as f64).collect();
            let mut f = vec![0.0; n];
            g.throughput(Throughput::Elements(m.mesh.n_elements() as u64));
            if name == "elastic" {
                let k = asm.stiffness(&m.mesh, &m.materials, m.idealisation);
                g.bench_with_input(BenchmarkId::new(name, label), &size, |b, _| {
                    b.iter(|| asm.pattern.matvec(&k, &u, &mut f))
                });
            } else {
                let mut stores = new_stores(&m.mesh, &m.materials);
                g.bench_with_input(BenchmarkId::new(name, label), &size, |b, _| {
                    b.iter(|| {
                        asm.internal_force(
                            &m.mesh,
                            &m.materials,
                            m.idealisation,
                            PointPass {
                                u: &u,
                                dt: m.analysis.time.dt,
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
        }
    }
    g.finish();
}

fn steps(c: &mut Criterion) {
    let mut g = c.benchmark_group("explicit_step");
    g.sample_size(10);
    for (size, label) in SIZES {
        let with = scenario(size, "model = \"elastic\"", true);
        let without = scenario(size, "model = \"elastic\"", false);
        // Into persistent contact: the steel meets the concrete after 26 µs.
        let mut cd = CentralDifference::new(&with).unwrap();
        let mut s = cd.initial_state().unwrap();
        while s.t < 1e-4 {
            cd.step_accepted(&mut s).unwrap();
        }
        assert!(s.contact.pairs[0].force > 0.0, "in contact");
        for (name, model) in [("with_contact", &with), ("without_contact", &without)] {
            let mut cd = CentralDifference::new(model).unwrap();
            g.throughput(Throughput::Elements(1));
            g.bench_with_input(BenchmarkId::new(name, label), &size, |b, _| {
                b.iter_batched(
                    || s.clone(),
                    |mut st| {
                        cd.step_accepted(&mut st).unwrap();
                        st
                    },
                    BatchSize::LargeInput,
                )
            });
        }
    }
    g.finish();
}

criterion_group!(benches, element_updates, steps);
criterion_main!(benches);
