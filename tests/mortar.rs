//! Mortar (segment-to-segment) contact: the contact patch test on non-matching
//! meshes (mortar exact, node-to-segment's error reported beside it), and mortar
//! against node-to-segment on matching meshes.

use std::path::Path;

use rothe::linsolve::Backend;
use rothe::model::Model;
use rothe::output::post::cell_stress;
use rothe::time::statics::Statics;
use rothe::time::{Integrator, State};

fn model(text: &str) -> Model {
    rothe::config::from_str(text, Path::new(".")).unwrap()
}

/// Two blocks 1 x 0.5 m, one on the other, the lower with `lower` columns of
/// elements and the upper with `upper`: the lower's bottom on rollers, both left
/// sides on rollers, the upper's top pushed down by `DELTA` (one static step). The
/// exact solution is uniaxial compression `σ_yy = E (−DELTA / 1 m)` everywhere
/// (plane stress, the same material: both sides expand sideways alike, nothing
/// slips).
fn blocks(lower: usize, upper: usize, formulation: &str) -> String {
    format!(
        r#"
[analysis]
kind = "static"
t_end = 1.0
dt = 1.0
vtk_every = 0

[materials.m]
model = "elastic"
E = 30e9
nu = 0.2
rho = 2400.0

[[bodies]]
name = "lower"
material = "m"
thickness = 0.1
mesh = {{ kind = "rectangle", size = [1.0, 0.5], divisions = [{lower}, 3] }}

[[bodies]]
name = "upper"
material = "m"
thickness = 0.1
mesh = {{ kind = "rectangle", origin = [0.0, 0.5], size = [1.0, 0.5], divisions = [{upper}, 3] }}

[[supports]]
set = "lower.bottom"
fix = ["y"]

[[supports]]
set = "lower.left"
fix = ["x"]

[[supports]]
set = "upper.left"
fix = ["x"]

[[prescribed]]
set = "upper.top"
component = "y"
value = -1.0e-4

[[contact]]
name = "interface"
slave = "upper.bottom"
master = "lower.top"
formulation = "{formulation}"
"#
    )
}

const E: f64 = 30e9;
const DELTA: f64 = 1.0e-4;

/// The largest error of the element stresses against `σ_yy = −E DELTA`, `σ_xx =
/// σ_xy = 0`, and of the interface pressures against `E DELTA`, both relative to
/// `E DELTA`.
fn patch(lower: usize, upper: usize, formulation: &str) -> (f64, f64) {
    let m = model(&blocks(lower, upper, formulation));
    let mut st = Statics::new(&m, Backend::Faer).unwrap();
    let mut s: State = st.initial_state();
    st.step_accepted(&mut s).unwrap();
    let p = E * DELTA;
    let points = st.output_points(&s).unwrap_or_default();
    let stress = cell_stress(&m, &s.u, &points);
    let stress_error = stress
        .iter()
        .map(|[sxx, syy, sxy]| (sxx.abs()).max((syy + p).abs()).max(sxy.abs()) / p)
        .fold(0.0, f64::max);
    let pressed: Vec<f64> = s
        .contact
        .pressure
        .iter()
        .copied()
        .filter(|&q| q > 0.0)
        .collect();
    assert!(pressed.len() >= upper, "{pressed:?}");
    let pressure_error = pressed
        .iter()
        .map(|q| (q - p).abs() / p)
        .fold(0.0, f64::max);
    (stress_error, pressure_error)
}

#[test]
fn mortar_passes_the_contact_patch_test_on_non_matching_meshes() {
    // Mesh ratios both ways (the slave coarser and finer than the master), and a
    // matching pair. Mortar carries the uniform pressure exactly (to the solver's
    // tolerance); node-to-segment loads the master at the slave nodes only, so its
    // stresses are wrong where the meshes do not match: its error is reported and
    // must be far larger, which shows the test can fail.
    let mut worst_nts: f64 = 0.0;
    for (lower, upper) in [(4, 3), (3, 4), (7, 3), (2, 5), (5, 5)] {
        let (stress, pressure) = patch(lower, upper, "mortar");
        let (nts_stress, nts_pressure) = patch(lower, upper, "node_to_segment");
        eprintln!(
            "lower {lower} / upper {upper}: mortar stress {stress:.2e} pressure {pressure:.2e}; \
             node-to-segment stress {nts_stress:.2e} pressure {nts_pressure:.2e}"
        );
        assert!(
            stress < 1e-8,
            "mortar {lower}/{upper}: stress error {stress:e}"
        );
        // The pressure is the force over the current covered length, which the
        // sideways expansion (ν DELTA / 1 m = 2e-5) lengthens.
        assert!(
            (pressure - 2.0e-5).abs() < 1e-8,
            "mortar {lower}/{upper}: pressure error {pressure:e}"
        );
        if lower != upper {
            worst_nts = worst_nts.max(nts_stress);
        } else {
            assert!(nts_stress < 1e-8, "matching meshes: {nts_stress:e}");
        }
    }
    assert!(worst_nts > 1e-2, "node-to-segment's error {worst_nts:e}");
}

/// Benchmark 1's blocks (examples/contact/two_blocks.toml, matching 0.05 m meshes
/// at the interface) with the steel 0.1 mm above the concrete, to 0.4 ms at 4 µs.
fn impact(formulation: &str) -> (f64, f64, f64, f64) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/contact/two_blocks.toml");
    let text = std::fs::read_to_string(path)
        .unwrap()
        .replace("origin = [0.3, 0.61]", "origin = [0.3, 0.6001]")
        .replace("t_end = 6.0e-3", "t_end = 4.0e-4")
        .replace("dt = 1.0e-6", "dt = 4.0e-6")
        .replace(
            "master = \"concrete.top\"",
            &format!("master = \"concrete.top\"\nformulation = \"{formulation}\""),
        );
    let m = model(&text);
    let mut be = rothe::time::backward_euler::BackwardEuler::new(&m, Backend::Faer).unwrap();
    let mut s = be.initial_state();
    let probe = m.probes[0].node;
    let (mut peak, mut impulse, mut max_force) = (0.0f64, 0.0, 0.0f64);
    for _ in 0..m.analysis.n_steps() {
        be.step_accepted(&mut s).unwrap();
        peak = peak.max(-s.u[2 * probe + 1]);
        let f = s.contact.pairs[0].force;
        impulse += f * m.analysis.dt;
        max_force = max_force.max(f);
        assert!(s.contact.pairs[0].penetration <= m.analysis.contact_tolerance);
    }
    (
        peak,
        impulse,
        max_force,
        s.ledger.residual() / s.ledger.scale(),
    )
}

#[test]
fn mortar_and_node_to_segment_agree_on_matching_meshes() {
    let (p_m, i_m, f_m, r_m) = impact("mortar");
    let (p_n, i_n, f_n, r_n) = impact("node_to_segment");
    eprintln!(
        "mortar: peak {p_m:.6e} m, impulse {i_m:.6e} N s, max force {f_m:.6e} N, residual {r_m:.1e}; \
         node-to-segment: peak {p_n:.6e} m, impulse {i_n:.6e} N s, max force {f_n:.6e} N, residual {r_n:.1e}"
    );
    // The same interface nodes, the gaps weighed differently (mortar averages over
    // each node's shape function): the same response within the mesh's resolution.
    assert!(
        (p_m - p_n).abs() < 0.02 * p_n,
        "peak {p_m:e} against {p_n:e}"
    );
    assert!(
        (i_m - i_n).abs() < 0.01 * i_n,
        "impulse {i_m:e} against {i_n:e}"
    );
    assert!(
        (f_m - f_n).abs() < 0.05 * f_n,
        "force {f_m:e} against {f_n:e}"
    );
    assert!(r_m.abs() < 1e-9 && r_n.abs() < 1e-9);
}
