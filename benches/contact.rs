//! Criterion bench of implicit contact on benchmark 1's two blocks (NOTES.md; both
//! elastic, `h = 1e-7` s, the paper's step) at the mesh sizes 0.05 m and 0.0125 m:
//! one backward-Euler step in persistent contact with the condensed QP, with the
//! full QP, and the same step of the same state without contact. The steel block
//! starts a micrometre above the concrete and is marched into contact (1000 steps)
//! before the timed steps, each of which starts from that state.
//!
//! After the benches it prints, per mesh, the split of a condensed step: the time to
//! form `W`, the QP, detection, and the solves.

use criterion::{criterion_group, criterion_main, BatchSize, BenchmarkId, Criterion};
use rothe::linsolve::Backend;
use rothe::model::Model;
use rothe::time::backward_euler::BackwardEuler;
use rothe::time::{Integrator, State};

/// Steps marched before the timed ones: 0.1 ms, well into the contact.
const WARM_UP: usize = 1000;

fn scenario(size: f64, contact: Option<&str>) -> Model {
    let (nx, ny, ns) = (
        (1.2 / size) as usize,
        (0.6 / size) as usize,
        (0.6 / size) as usize,
    );
    let pair = if contact.is_some() {
        "[[contact]]\nname = \"impact\"\nslave = \"steel.bottom\"\nmaster = \"concrete.top\"\n"
    } else {
        ""
    };
    let qp = contact.unwrap_or("condensed");
    let text = format!(
        r#"
[analysis]
t_end = 1.0
dt = 1.0e-7
gravity = [0.0, -9.81]
vtk_every = 0
contact_qp = "{qp}"
[materials.steel]
model = "elastic"
E = 210e9
nu = 0.3
rho = 7850.0
[materials.concrete]
model = "elastic"
E = 33e9
nu = 0.2
rho = 2400.0
[[bodies]]
name = "concrete"
material = "concrete"
thickness = 0.4
mesh = {{ kind = "rectangle", size = [1.2, 0.6], divisions = [{nx}, {ny}] }}
[[bodies]]
name = "steel"
material = "steel"
thickness = 0.2
velocity = [0.0, -3.836]
mesh = {{ kind = "rectangle", origin = [0.3, 0.600001], size = [0.6, 0.6], divisions = [{ns}, {ns}] }}
[[supports]]
set = "concrete.bottom"
fix = ["x", "y"]
[[supports]]
set = "steel.bottom_left"
fix = ["x"]
[[supports]]
set = "steel.bottom_right"
fix = ["x"]
[[supports]]
set = "steel.top_left"
fix = ["x"]
[[supports]]
set = "steel.top_right"
fix = ["x"]
{pair}
"#
    );
    rothe::config::from_str(&text, std::path::Path::new(".")).expect("valid scenario")
}

/// The state after the warm-up, in persistent contact.
fn in_contact(model: &Model) -> State {
    let mut be = BackwardEuler::new(model, Backend::Faer).unwrap();
    let mut s = be.initial_state();
    for _ in 0..WARM_UP {
        be.step_accepted(&mut s).unwrap();
    }
    assert!(
        s.contact.pairs[0].force > 0.0,
        "in contact after the warm-up"
    );
    s
}

const SIZES: [(f64, &str); 2] = [(0.05, "0.05m"), (0.0125, "0.0125m")];

fn steps(c: &mut Criterion) {
    let mut g = c.benchmark_group("contact_step");
    g.sample_size(10);
    for (size, label) in SIZES {
        let condensed = scenario(size, Some("condensed"));
        let state = in_contact(&condensed);
        let cases = [
            ("without_contact", scenario(size, None)),
            ("condensed", condensed),
            ("full", scenario(size, Some("full"))),
        ];
        for (name, model) in &cases {
            let mut be = BackwardEuler::new(model, Backend::Faer).unwrap();
            g.bench_with_input(BenchmarkId::new(*name, label), &size, |b, _| {
                b.iter_batched(
                    || state.clone(),
                    |mut s| {
                        be.step_accepted(&mut s).unwrap();
                        s
                    },
                    BatchSize::LargeInput,
                )
            });
        }
    }
    g.finish();
    split();
}

/// Where a condensed step's time goes, from the integrator's own counters.
fn split() {
    eprintln!("\ncondensed step, per step (ms): W | QP | detection | solves | solves/step | QPs/step | rows/QP");
    for (size, label) in SIZES {
        let model = scenario(size, Some("condensed"));
        let mut be = BackwardEuler::new(&model, Backend::Faer).unwrap();
        let mut s = in_contact(&model);
        // The state's contact state is the warm-up's: march a few steps so the
        // integrator's own caches are warm too.
        for _ in 0..10 {
            be.step_accepted(&mut s).unwrap();
        }
        let (c0, t0) = (be.contact_stats().unwrap(), be.system().timing());
        let n = 100;
        for _ in 0..n {
            be.step_accepted(&mut s).unwrap();
        }
        let (c1, t1) = (be.contact_stats().unwrap(), be.system().timing());
        let per = |x: f64| 1e3 * x / n as f64;
        eprintln!(
            "{label}: {:.3} | {:.3} | {:.3} | {:.3} | {:.2} | {:.2} | {:.1}",
            per(c1.w_s - c0.w_s),
            per(c1.qp_s - c0.qp_s),
            per(c1.detect_s - c0.detect_s),
            per(t1.solve_s - t0.solve_s),
            (t1.solves - t0.solves) as f64 / n as f64,
            (c1.qps - c0.qps) as f64 / n as f64,
            (c1.rows - c0.rows) as f64 / (c1.qps - c0.qps).max(1) as f64,
        );
    }
}

criterion_group!(benches, steps);
criterion_main!(benches);
