//! Criterion bench of contact between solids: benchmark 1's two blocks as boxes
//! (`examples/benchmarks/two_blocks_solid.toml`, both elastic, `h = 1e-7` s, the
//! plane bench's step, `benches/contact.rs`) at
//! the mesh sizes 0.1 m and 0.05 m: one backward-Euler step in persistent contact
//! (node to face and mortar, condensed QP), node to face with Coulomb friction
//! (μ = 0.4, the steel's corner edges free), and the same step of the same state
//! without contact.
//! The steel starts a micrometre above the concrete and is marched into contact
//! (1000 steps) before the timed steps, each of which starts from that state.

use criterion::{criterion_group, criterion_main, BatchSize, BenchmarkId, Criterion};
use rothe::linsolve::Backend;
use rothe::model::Model;
use rothe::time::backward_euler::BackwardEuler;
use rothe::time::{Integrator, State};

/// Steps marched before the timed ones: 0.1 ms, well into the contact.
const WARM_UP: usize = 1000;

/// `Some((μ, formulation))`: contact with Coulomb's `μ`; `None`: no contact.
fn scenario(size: f64, contact: Option<(f64, &str)>) -> Model {
    let pair = match contact {
        Some((mu, formulation)) => format!(
            "[[contact]]\nname = \"impact\"\nslave = \"steel.bottom\"\nmaster = \"concrete.top\"\nmu = {mu:e}\nformulation = \"{formulation}\"\n"
        ),
        None => String::new(),
    };
    let corners = if contact.is_some_and(|(mu, _)| mu > 0.0) {
        ""
    } else {
        r#"
[[supports]]
set = "steel.bottom_left"
fix = ["x"]
[[supports]]
set = "steel.bottom_right"
fix = ["x"]
"#
    };
    let text = format!(
        r#"
[analysis]
t_end = 1.0
dt = 1.0e-7
gravity = [0.0, -9.81, 0.0]
vtk_every = 0
[meshing]
element_size = {size:e}
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
mesh = {{ kind = "box", size = [1.2, 0.6, 0.4], x_lines = [0.3, 0.9], z_lines = [0.1, 0.3] }}
[[bodies]]
name = "steel"
material = "steel"
velocity = [0.0, -3.836, 0.0]
mesh = {{ kind = "box", origin = [0.3, 0.600001, 0.1], size = [0.6, 0.6, 0.2] }}
[[supports]]
set = "concrete.bottom"
fix = ["x", "y", "z"]
{corners}
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

fn steps(c: &mut Criterion) {
    let mut g = c.benchmark_group("solid_contact_step");
    g.sample_size(10);
    for (size, label) in [(0.1, "0.1m"), (0.05, "0.05m")] {
        let mut state = None;
        for (name, enforced) in [
            ("node_to_face", Some((0.0, "node_to_face"))),
            ("without_contact", None),
            ("mortar", Some((0.0, "mortar"))),
            ("node_to_face_friction", Some((0.4, "node_to_face"))),
        ] {
            let model = scenario(size, enforced);
            // The step without contact starts from node to face's frictionless state.
            if enforced.is_some() {
                state = Some(in_contact(&model));
            }
            let state = state.clone().expect("frictionless first");
            let mut be = BackwardEuler::new(&model, Backend::Faer).unwrap();
            g.bench_with_input(BenchmarkId::new(name, label), &size, |b, _| {
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

/// Where a contact step's time goes, from the integrator's own counters (per step,
/// ms): forming `W`, the QP, detection, the solves, and the counts.
fn split() {
    eprintln!("\nsolid contact step, per step (ms): W | QP | detection | solves | solves/step | QPs/step | rows/QP | cone programs/QP");
    for (size, mu, formulation) in [
        (0.1, 0.0, "node_to_face"),
        (0.1, 0.0, "mortar"),
        (0.1, 0.4, "node_to_face"),
        (0.05, 0.0, "node_to_face"),
        (0.05, 0.0, "mortar"),
        (0.05, 0.4, "node_to_face"),
    ] {
        let model = scenario(size, Some((mu, formulation)));
        let mut be = BackwardEuler::new(&model, Backend::Faer).unwrap();
        let mut s = in_contact(&model);
        for _ in 0..5 {
            be.step_accepted(&mut s).unwrap();
        }
        let (c0, t0) = (be.contact_stats().unwrap(), be.system().timing());
        let n = 50;
        for _ in 0..n {
            be.step_accepted(&mut s).unwrap();
        }
        let (c1, t1) = (be.contact_stats().unwrap(), be.system().timing());
        let per = |x: f64| 1e3 * x / n as f64;
        let qps = (c1.qps - c0.qps).max(1) as f64;
        eprintln!(
            "{size} m, {formulation}, mu = {mu}: {:.3} | {:.3} | {:.3} | {:.3} | {:.2} | {:.2} | {:.1} | {:.2}",
            per(c1.w_s - c0.w_s),
            per(c1.qp_s - c0.qp_s),
            per(c1.detect_s - c0.detect_s),
            per(t1.solve_s - t0.solve_s),
            (t1.solves - t0.solves) as f64 / n as f64,
            qps / n as f64,
            (c1.rows - c0.rows) as f64 / qps,
            (c1.cone_programs - c0.cone_programs) as f64 / qps,
        );
    }
}

criterion_group!(benches, steps);
criterion_main!(benches);
