//! Criterion bench of the implicit step of damage and plasticity against the elastic
//! step on the paper's two benchmarks (`examples/benchmarks/`): benchmark 1 at the
//! mesh size 0.05 m and benchmark 2 as written, each with the concrete elastic,
//! Mazars (the identified, nonlocal law of the files) and Rankine-Hill, the last two
//! with the factor kept while the iterations converge on it (the default) and
//! refactorised at every changed tangent (`keep_factor = false`, full Newton).
//!
//! Each model is marched to 2.55 ms, just before the impactor touches (2.6 ms in
//! both files), once; a timed sample is the 200 steps (0.2 ms) through the impact
//! from that state, each with a new integrator whose factor is the one at rest (the
//! march's up to the impact, every point being elastic until then). The ratios to
//! the elastic step on the same file, mesh and step are what the notes quote.

use std::path::Path;

use criterion::{criterion_group, criterion_main, BatchSize, BenchmarkId, Criterion};
use rothe::config::{LoadOptions, Overrides};
use rothe::linsolve::Backend;
use rothe::time::backward_euler::BackwardEuler;
use rothe::time::{Integrator, State};

/// Time marched before the timed steps (s).
const BEFORE_IMPACT: f64 = 2.55e-3;
/// Steps in a timed sample.
const TIMED_STEPS: usize = 200;

/// The benchmark `file` with the concrete `variant`; `full` refactorises at every
/// changed tangent.
fn model(file: &str, size: Option<&str>, variant: &str, full: bool) -> rothe::model::Model {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/benchmarks")
        .join(format!("{file}.toml"));
    let mut ov = Overrides::none()
        .variant(&format!("concrete={variant}"))
        .unwrap();
    if let Some(size) = size {
        ov = ov.set(&format!("meshing.element_size={size}")).unwrap();
    }
    if full {
        ov = ov.set("analysis.keep_factor=false").unwrap();
    }
    rothe::config::load_with_overrides(&path, &LoadOptions::unlimited(), &ov).unwrap()
}

fn steps(c: &mut Criterion) {
    let mut g = c.benchmark_group("nonlinear_step");
    g.sample_size(10);
    let cases = [
        ("elastic", "elastic", false),
        ("mazars", "mazars", false),
        ("mazars_full_newton", "mazars", true),
        ("rankine_hill", "rankine_hill", false),
        ("rankine_hill_full_newton", "rankine_hill", true),
    ];
    for (file, size) in [("two_blocks", Some("0.05")), ("rc_beam_punch", None)] {
        for (name, variant, full) in cases {
            let m = model(file, size, variant, full);
            let mut be = BackwardEuler::new(&m, Backend::Faer).unwrap();
            let mut s0: State = be.initial_state();
            while s0.t < BEFORE_IMPACT - 0.5 * m.analysis.time.dt {
                be.step_accepted(&mut s0).unwrap();
            }
            g.bench_with_input(BenchmarkId::new(file, name), &(), |b, _| {
                b.iter_batched(
                    // A new integrator (its factor at rest, as the march had it
                    // before the impact: every point still elastic) and the state.
                    || (BackwardEuler::new(&m, Backend::Faer).unwrap(), s0.clone()),
                    |(mut be, mut s)| {
                        for _ in 0..TIMED_STEPS {
                            be.step_accepted(&mut s).unwrap();
                        }
                        s.t
                    },
                    BatchSize::PerIteration,
                )
            });
        }
    }
    g.finish();
}

criterion_group!(benches, steps);
criterion_main!(benches);
