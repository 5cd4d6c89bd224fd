//! Criterion benches of workload W1 (see `benches/common/workload.rs`): element assembly of K and
//! M, numeric factorisation of the effective matrix, and one backward-Euler step and
//! one trapezoidal step, each
//! at several sizes (`ny`), with setup outside the timed loop. Larger sizes and the
//! CHOLMOD backend: `cargo run --release --example w1 -- NY [faer|cholmod]`.

#[path = "common/workload.rs"]
mod workload;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use rothe::assembly::internal::{new_stores, PointPass};
use rothe::assembly::Assembler;
use rothe::linsolve::Backend;
use rothe::model::ViscoelasticState;
use rothe::time::backward_euler::BackwardEuler;
use rothe::time::march::march_steps;
use rothe::time::Integrator;

fn assembly(c: &mut Criterion) {
    let mut g = c.benchmark_group("w1_assembly");
    g.sample_size(10);
    for ny in [25usize, 100] {
        let model = workload::w1(ny).unwrap();
        let asm = Assembler::new(&model.mesh);
        g.bench_with_input(BenchmarkId::new("stiffness", ny), &ny, |b, _| {
            b.iter(|| asm.stiffness(&model.mesh, &model.materials, model.idealisation))
        });
        g.bench_with_input(BenchmarkId::new("consistent_mass", ny), &ny, |b, _| {
            b.iter(|| asm.mass(&model.mesh, &model.materials, false))
        });
        g.bench_with_input(BenchmarkId::new("pattern_and_colours", ny), &ny, |b, _| {
            b.iter(|| Assembler::new(&model.mesh))
        });
    }
    g.finish();
}

fn factorisation_and_step(c: &mut Criterion) {
    let mut g = c.benchmark_group("w1_solver");
    g.sample_size(10);
    for ny in [25usize, 100] {
        let model = workload::w1(ny).unwrap();
        let mut be = BackwardEuler::new(&model, Backend::Faer).unwrap();
        g.bench_with_input(BenchmarkId::new("refactorize", ny), &ny, |b, _| {
            b.iter(|| be.set_step(model.analysis.time.dt).unwrap())
        });
        let mut s = be.initial_state();
        g.bench_with_input(BenchmarkId::new("step", ny), &ny, |b, _| {
            b.iter(|| be.step_accepted(&mut s).unwrap())
        });
        // The trapezoidal rule's step beside it (theory/trapezoidal.md).
        let mut trap = model.clone();
        trap.analysis.time.scheme = rothe::model::TimeScheme::Trapezoidal;
        let mut tr = BackwardEuler::new(&trap, Backend::Faer).unwrap();
        let mut s = tr.initial_state();
        g.bench_with_input(BenchmarkId::new("step_trapezoidal", ny), &ny, |b, _| {
            b.iter(|| tr.step_accepted(&mut s).unwrap())
        });
    }
    g.finish();
}

fn sls(c: &mut Criterion) {
    // The standard linear solid on nodal fields (the default) and at the Gauss
    // points, and the Gauss-point pass the nodal fields save.
    let mut g = c.benchmark_group("w1_sls");
    g.sample_size(10);
    for ny in [25usize, 100] {
        for state in [ViscoelasticState::Nodal, ViscoelasticState::Points] {
            let mut model = workload::w1_with(ny, workload::W1_SLS).unwrap();
            model.analysis.time.viscoelastic_state = state;
            let mut be = BackwardEuler::new(&model, Backend::Faer).unwrap();
            let mut s = be.initial_state();
            let name = format!("step_{state:?}").to_lowercase();
            g.bench_with_input(BenchmarkId::new(name, ny), &ny, |b, _| {
                b.iter(|| be.step_accepted(&mut s).unwrap())
            });
        }
        let model = workload::w1_with(ny, workload::W1_SLS).unwrap();
        let asm = Assembler::new(&model.mesh);
        let mut points = new_stores(&model.mesh, &model.materials);
        let n = model.mesh.n_dofs();
        let u: Vec<f64> = (0..n).map(|i| 1e-6 * (i % 7) as f64).collect();
        let (mut f, mut fp) = (vec![0.0; n], vec![0.0; n]);
        g.bench_with_input(BenchmarkId::new("gauss_point_loop", ny), &ny, |b, _| {
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
                    &mut points,
                    &mut f,
                    Some(&mut fp),
                    None,
                    None,
                )
            })
        });
    }
    g.finish();
}

fn nonlinear(c: &mut Criterion) {
    // Cost per step of the damage and plasticity variants (10 steps from the state
    // after the first cracking, each bench iteration from a copy of that state).
    let mut g = c.benchmark_group("w1_nonlinear");
    g.sample_size(10);
    let ny = 25;
    for variant in ["elastic", "mazars", "mazars-fixed", "rankine-hill"] {
        let model = workload::w1_variant(ny, variant).unwrap();
        let mut be = BackwardEuler::new(&model, Backend::Faer).unwrap();
        let mut s0 = be.initial_state();
        for _ in 0..10 {
            be.step_accepted(&mut s0).unwrap();
        }
        g.bench_with_input(BenchmarkId::new(variant, ny), &ny, |b, _| {
            b.iter(|| {
                let mut s = s0.clone();
                march_steps(&mut be, &mut s, 10).unwrap()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, assembly, factorisation_and_step, sls, nonlinear);
criterion_main!(benches);
