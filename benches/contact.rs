//! Criterion bench of implicit contact on benchmark 1's two blocks (NOTES.md; both
//! elastic, `h = 1e-7` s, the paper's step) at the mesh sizes 0.05 m and 0.0125 m:
//! one backward-Euler step in persistent contact, node to segment and mortar with
//! the condensed QP, mortar with Coulomb friction (μ = 0.4, the steel's corners
//! free as in the benchmark's friction variant), mortar with the full QP, and the
//! same step of the same state without contact. The steel block starts a micrometre
//! above the concrete and is marched into contact (1000 steps) before the timed
//! steps, each of which starts from that state (each formulation from its own).
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

/// How the pair is enforced: QP, formulation and `μ` (`None`: no contact).
type Enforced<'a> = Option<(&'a str, &'a str, f64)>;

fn scenario(size: f64, contact: Enforced) -> Model {
    let (nx, ny, ns) = (
        (1.2 / size) as usize,
        (0.6 / size) as usize,
        (0.6 / size) as usize,
    );
    let pair = match contact {
        Some((_, formulation, mu)) => format!(
            "[[contact]]\nname = \"impact\"\nslave = \"steel.bottom\"\nmaster = \"concrete.top\"\n\
             formulation = \"{formulation}\"\nmu = {mu:e}\n"
        ),
        None => String::new(),
    };
    let qp = contact.map_or("condensed", |c| c.0);
    // Friction holds the steel sideways: its corners are free then.
    let corners = if contact.is_some_and(|c| c.2 > 0.0) {
        ""
    } else {
        CORNERS
    };
    let text = format!(
        r#"
[analysis]
t_end = 1.0
dt = 1.0e-7
gravity = [0.0, -9.81]
vtk_every = 0
contact_qp = "condensed"
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
{corners}
{pair}
"#
    );
    let mut m = rothe::config::from_str(&text, std::path::Path::new(".")).expect("valid scenario");
    // Scenarios refuse the full QP; the library runs it as the reference.
    if qp == "full" {
        m.analysis.contact.qp = rothe::model::ContactQp::Full;
    }
    m
}

/// The supports holding the steel's corners horizontally.
const CORNERS: &str = r#"
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
"#;

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
        let cases = [
            (
                "node_to_segment",
                Some(("condensed", "node_to_segment", 0.0)),
            ),
            ("without_contact", None),
            ("mortar_friction", Some(("condensed", "mortar", 0.4))),
            ("mortar", Some(("condensed", "mortar", 0.0))),
            ("mortar_full_qp", Some(("full", "mortar", 0.0))),
        ];
        let mut state = None;
        for (name, enforced) in cases {
            let model = scenario(size, enforced);
            // The state without contact is node to segment's (its contact part
            // unread), the full QP's is mortar's (its rows the same).
            if enforced.is_some_and(|e| e.0 == "condensed") {
                state = Some(in_contact(&model));
            }
            let state = state.clone().expect("node to segment first");
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

/// Where a condensed step's time goes, from the integrator's own counters.
fn split() {
    eprintln!("\ncondensed step, per step (ms): W | QP | detection | solves | solves/step | QPs/step | rows/QP");
    for ((size, label), (formulation, mu)) in SIZES.iter().flat_map(|s| {
        [
            (*s, ("node_to_segment", 0.0)),
            (*s, ("mortar", 0.0)),
            (*s, ("mortar", 0.4)),
        ]
    }) {
        let label = format!("{label} {formulation} mu = {mu}");
        let model = scenario(size, Some(("condensed", formulation, mu)));
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
