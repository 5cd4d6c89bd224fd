//! The explicit path: central differences with lumped mass and the kinematic contact
//! method. Stability limit against the mesh's highest mode, energy conservation at
//! second order, the two bars against 1D wave theory, momentum through impacts,
//! friction and the position weight, ledgers with every material model, and the
//! same scenario through both paths.

use std::path::Path;

use rothe::config::LoadOptions;
use rothe::linsolve::Backend;
use rothe::model::Model;
use rothe::time::backward_euler::BackwardEuler;
use rothe::time::central_difference::CentralDifference;
use rothe::time::{Integrator, State};

fn load(text: &str, allow_unstable: bool) -> rothe::Result<Model> {
    let opts = LoadOptions {
        memory_limit: None,
        allow_unstable,
        distributed_factor: false,
    };
    rothe::config::from_str_with(text, Path::new("."), &opts)
}

fn example(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A steel plate 0.4 x 0.2 m fixed at its left edge, set moving at (1, 0.5) m/s: the
/// support sends waves of every wavelength through it.
fn plate(dt: Option<f64>, t_end: f64) -> String {
    format!(
        r#"
[analysis]
scheme = "central_difference"
t_end = {t_end:e}
{}
vtk_every = 0
[materials.steel]
model = "elastic"
E = 210e9
nu = 0.3
rho = 7850.0
[[bodies]]
name = "plate"
material = "steel"
thickness = 0.1
velocity = [1.0, 0.5]
mesh = {{ kind = "rectangle", size = [0.4, 0.2], divisions = [8, 4] }}
[[supports]]
set = "plate.left"
fix = ["x", "y"]
"#,
        dt.map(|h| format!("dt = {h:e}")).unwrap_or_default()
    )
}

/// Largest `|E_kin + E_el − E_0| / E_0` over a run, and whether it stayed finite.
fn energy_drift(m: &Model) -> (f64, bool) {
    let mut cd = CentralDifference::new(m).unwrap();
    let mut s = cd.initial_state().unwrap();
    let e0 = s.ledger.kinetic() + s.ledger.elastic();
    let mut worst: f64 = 0.0;
    for _ in 0..m.analysis.n_steps() {
        match cd.step_accepted(&mut s) {
            Ok(_) => {}
            Err(_) => return (f64::INFINITY, false),
        }
        let e = s.ledger.kinetic() + s.ledger.elastic();
        if !e.is_finite() {
            return (f64::INFINITY, false);
        }
        worst = worst.max((e - e0).abs() / e0);
        if worst > 1e6 {
            // Blown up: the ledger still closes relative to its (huge) scale.
            return (worst, true);
        }
        assert!(
            s.ledger.residual().abs() <= 1e-11 * s.ledger.scale(),
            "ledger residual {} of {}",
            s.ledger.residual(),
            s.ledger.scale()
        );
    }
    (worst, true)
}

#[test]
fn a_step_just_above_the_mesh_limit_blows_up_and_just_below_does_not() {
    // The mesh's own limit 2/ω_max (power iteration on M⁻¹K) against the two
    // estimates: the element bound min_e 2/ω_e (Irons' theorem: never above the
    // mesh's) and the paper's L_e/c.
    let m = load(&plate(None, 2e-3), false).unwrap();
    let exact = rothe::time::cfl::mesh_stable_step(&m, 20_000);
    let bound = rothe::time::cfl::stable_step(&m).unwrap().dt;
    let paper = rothe::time::cfl::critical_step(&m).unwrap().dt;
    eprintln!("paper {paper:.4e} s, element bound {bound:.4e} s, mesh {exact:.4e} s");
    assert!(paper <= bound && bound <= exact * (1.0 + 1e-9));
    // The default step is ω times the paper's estimate.
    assert!((m.analysis.time.dt - 0.9 * paper).abs() < 1e-15);
    // 2 % below the mesh's limit: bounded for 4000 steps; 2 % above: it blows up.
    let below = load(&plate(Some(0.98 * exact), 4000.0 * 0.98 * exact), true).unwrap();
    let (drift, finite) = energy_drift(&below);
    assert!(finite && drift < 0.05, "below the limit: drift {drift}");
    let above = load(&plate(Some(1.02 * exact), 4000.0 * 1.02 * exact), true).unwrap();
    let (drift, _) = energy_drift(&above);
    assert!(drift > 1e6, "above the limit: drift {drift}");
}

/// The steel plate of [`plate`] with `material` lines for its model and `analysis`
/// lines added.
fn damped_plate(dt: f64, steps: f64, material: &str, analysis: &str) -> String {
    plate(Some(dt), steps * dt)
        .replace("vtk_every = 0", &format!("vtk_every = 0\n{analysis}"))
        .replace("model = \"elastic\"", material)
}

#[test]
fn damped_steps_hold_just_below_their_limit_and_grow_just_above() {
    // Damping the scheme takes at the half-step velocity (Kelvin-Voigt dashpots,
    // Rayleigh a_k K) lowers the limit of a mode of frequency ω and damping rate
    // c = 2ξω to 2/(√(ω² + c²/4) + c/2); with stiffness-proportional damping
    // (c = α ω², a_k ω²) the lowest limit is the highest mode's. Mass damping (zeta,
    // a_m), taken at v_{n+1}, leaves the limit where it is. The mesh's limit from
    // its own ω_max (power iteration): 2 % below it the energy never grows over 4000
    // steps, 2 % above it grows by more than 10⁶. The element bound the scheme
    // refuses larger steps by (cfl::stable_step) is below the mesh's limit.
    let undamped = load(&plate(None, 2e-3), false).unwrap();
    let omega = 2.0 / rothe::time::cfl::mesh_stable_step(&undamped, 20_000);
    let alpha = 1.0 / omega; // ξ = αω/2 = 0.5 in the highest mode
    let cases = [
        (
            "Kelvin-Voigt, eta = alpha C",
            format!("model = \"kelvin_voigt\"\nalpha = {alpha:e}"),
            String::new(),
            alpha,
        ),
        (
            "Rayleigh a_k K with mass damping a_m M and zeta",
            "model = \"elastic\"".to_string(),
            format!("rayleigh = [2.0e5, {alpha:e}]\nzeta = 1.0e5"),
            alpha,
        ),
    ];
    for (what, material, analysis, a_k) in &cases {
        let limit = rothe::time::cfl::damped_limit(omega, a_k * omega * omega);
        let bound = {
            let m = load(&damped_plate(limit, 1.0, material, analysis), true).unwrap();
            rothe::time::cfl::stable_step(&m).unwrap().dt
        };
        eprintln!(
            "{what}: mesh limit {limit:.4e} s (undamped {:.4e}), element bound {bound:.4e} s",
            2.0 / omega
        );
        assert!(
            bound <= limit * (1.0 + 1e-9),
            "{what}: bound {bound} above the limit {limit}"
        );
        assert!(
            bound >= 0.8 * limit,
            "{what}: bound {bound} far below the limit {limit}"
        );
        let below = load(
            &damped_plate(0.98 * limit, 4000.0, material, analysis),
            true,
        )
        .unwrap();
        let (drift, finite) = energy_drift(&below);
        assert!(
            finite && drift <= 1.0 + 1e-9,
            "{what}: below the limit the energy grew: drift {drift}"
        );
        let above = load(
            &damped_plate(1.02 * limit, 4000.0, material, analysis),
            true,
        )
        .unwrap();
        let (drift, _) = energy_drift(&above);
        assert!(drift > 1e6, "{what}: above the limit: drift {drift}");
    }
    // The paper's identity viscosity (eta = beta I) is not proportional to K: its
    // modes are not the elastic ones, and the element bound, which takes the largest
    // frequency and the largest damping rate together, is a safe step.
    let material = "model = \"kelvin_voigt\"\nbeta = 3.0e5";
    let probe = load(&damped_plate(1e-7, 1.0, material, ""), true).unwrap();
    let bound = rothe::time::cfl::stable_step(&probe).unwrap().dt;
    assert!(
        bound < 0.9 * 2.0 / omega,
        "the viscosity lowers the bound: {bound}"
    );
    let at = load(&damped_plate(0.98 * bound, 4000.0, material, ""), true).unwrap();
    let (drift, finite) = energy_drift(&at);
    assert!(
        finite && drift <= 1.0 + 1e-9,
        "identity viscosity at its bound: drift {drift}"
    );
}

#[test]
fn a_step_above_the_stable_step_is_refused_naming_the_limit_and_the_element() {
    let m = load(&plate(None, 2e-3), false).unwrap();
    let bound = rothe::time::cfl::stable_step(&m).unwrap();
    let e = load(&plate(Some(1.01 * bound.dt), 2e-3), false)
        .unwrap_err()
        .to_string();
    for word in [
        "analysis.dt",
        "stable step",
        "block 0 element",
        "--allow-unstable",
        "L_e/c",
    ] {
        assert!(e.contains(word), "`{word}` not in: {e}");
    }
    assert!(load(&plate(Some(1.01 * bound.dt), 2e-3), true).is_ok());
    // A consistent mass or a step-less backward Euler are refused too.
    let consistent =
        plate(None, 2e-3).replace("vtk_every = 0", "vtk_every = 0\nmass = \"consistent\"");
    assert!(load(&consistent, false)
        .unwrap_err()
        .to_string()
        .contains("analysis.mass"));
    let implicit = plate(None, 2e-3).replace("scheme = \"central_difference\"\n", "");
    assert!(load(&implicit, false)
        .unwrap_err()
        .to_string()
        .contains("analysis.dt"));
}

#[test]
fn elastic_waves_conserve_energy_to_second_order() {
    // Velocity Verlet conserves E_kin − (h²/8) aᵀMa exactly, so E_kin + E_el drifts
    // by O(h²): the observed order of the largest drift over 1 ms.
    let m = load(&plate(None, 1e-3), false).unwrap();
    let h0 = rothe::time::cfl::stable_step(&m).unwrap().dt * 0.5;
    let drifts: Vec<f64> = [h0, h0 / 2.0, h0 / 4.0]
        .iter()
        .map(|&h| {
            let m = load(&plate(Some(h), 1e-3), false).unwrap();
            energy_drift(&m).0
        })
        .collect();
    let orders: Vec<f64> = drifts.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
    eprintln!("energy drifts {drifts:?}, observed orders {orders:?}");
    for p in &orders {
        assert!((1.8..2.2).contains(p), "orders {orders:?}");
    }
}

/// The bars example through the explicit path, with step `omega` x the estimate.
fn explicit_bars(omega: f64) -> Model {
    let text = example("contact/bars_impact.toml")
        .replace(
            "dt = 1.0e-6",
            &format!("scheme = \"central_difference\"\nomega = {omega}"),
        )
        .replace("vtk_every = 20", "vtk_every = 0")
        .replace("contact_qp = \"condensed\"\n", "");
    load(&text, false).unwrap()
}

fn momentum(m: &Model, s: &State, mass: &[f64], body: usize) -> (f64, f64) {
    let (mut p, mut mm) = (0.0, 0.0);
    for (n, &b) in m.mesh.node_body.iter().enumerate() {
        if b == body {
            p += mass[2 * n] * s.v[2 * n];
            mm += mass[2 * n];
        }
    }
    (p, mm)
}

#[test]
fn two_bars_collide_as_1d_wave_theory_says_and_conserve_momentum() {
    // 1D waves: contact for 2L/c = 0.4 ms at ρcAv/2 = 1e5 N, then the striker stands
    // and the target leaves at v. The kinematic method: momentum conserved to 1e-12
    // at every step, no node behind the master after any step.
    for omega in [0.9, 0.45] {
        let m = explicit_bars(omega);
        let mut cd = CentralDifference::new(&m).unwrap();
        let mass = cd.lumped_mass().to_vec();
        let mut s = cd.initial_state().unwrap();
        let p0 = momentum(&m, &s, &mass, 0).0 + momentum(&m, &s, &mass, 1).0;
        let mut p_prev = p0;
        let (mut t_on, mut t_off, mut plateau, mut count) = (None, None, 0.0, 0);
        for _ in 0..m.analysis.n_steps() {
            cd.step_accepted(&mut s).unwrap();
            // Through every step, impacts included, the momentum changes by round-off
            // only (1e-13); over the run that round-off adds up (the stiffness's
            // column sums are zero to ε|K|, times the growing displacements).
            let p = momentum(&m, &s, &mass, 0).0 + momentum(&m, &s, &mass, 1).0;
            assert!(
                (p - p_prev).abs() <= 1e-13 * p0.abs(),
                "momentum step {p} vs {p_prev}"
            );
            assert!((p - p0).abs() <= 1e-11 * p0.abs(), "momentum {p} vs {p0}");
            p_prev = p;
            assert!(
                s.contact.pairs[0].penetration <= 1e-12,
                "{}",
                s.contact.pairs[0].penetration
            );
            assert!(s.ledger.residual().abs() <= 1e-11 * s.ledger.scale());
            let f = s.contact.pairs[0].force;
            if f > 0.0 {
                t_on.get_or_insert(s.t - m.analysis.time.dt);
                t_off = Some(s.t);
                if s.t > 1e-4 && s.t < 3e-4 {
                    plateau += f;
                    count += 1;
                }
            }
        }
        let duration = t_off.unwrap() - t_on.unwrap();
        let plateau = plateau / count as f64;
        let (ps, ms) = momentum(&m, &s, &mass, 0);
        let (pt, mt) = momentum(&m, &s, &mass, 1);
        eprintln!(
            "omega {omega}: h = {:.3e} s, duration {duration:.4e} s, plateau {plateau:.5e} N, striker {:.4} m/s, target {:.4} m/s, D_contact {:.4e} J",
            m.analysis.time.dt,
            ps / ms,
            pt / mt,
            s.ledger.dissipated().contact
        );
        assert!((duration - 4e-4).abs() < 0.02 * 4e-4, "duration {duration}");
        assert!((plateau - 1e5).abs() < 0.02 * 1e5, "plateau {plateau}");
        assert!((ps / ms).abs() < 0.03 && (pt / mt - 1.0).abs() < 0.03);
    }
}

/// A steel block 0.2 x 0.1 m thrown at (1, −1) m/s onto a rigid floor, with the
/// friction `beta` and position weight `w` of the pair.
fn thrown(beta: f64, w: f64, dt: f64, t_end: f64, gap: f64) -> Model {
    load(&thrown_text(beta, w, dt, t_end, gap), false).unwrap()
}

/// The text of [`thrown`].
fn thrown_text(beta: f64, w: f64, dt: f64, t_end: f64, gap: f64) -> String {
    format!(
        r#"
[analysis]
scheme = "central_difference"
t_end = {t_end:e}
dt = {dt:e}
vtk_every = 0
[materials.steel]
model = "elastic"
E = 210e9
nu = 0.3
rho = 7850.0
[[bodies]]
name = "block"
material = "steel"
thickness = 0.1
velocity = [1.0, -1.0]
mesh = {{ kind = "rectangle", origin = [0.0, {gap:e}], size = [0.2, 0.1], divisions = [4, 2] }}
[[contact]]
name = "floor"
slave = "block.bottom"
rigid_line = [[-1.0, 0.0], [2.0, 0.0]]
friction = {beta}
position_weight = {w}
"#
    )
}

#[test]
fn coulomb_friction_bounds_the_impact_impulse_by_mu_times_the_normal_one() {
    // The thrown block of the next test with Coulomb's μ instead of β: the impact
    // stops the bottom nodes (lumped mass m_b) vertically, a normal impulse m_b v_y =
    // m_b; stopping them sideways too would take m_b v_x = m_b, which the cone allows
    // for μ ≥ 1 (they stick) and caps at μ m_b below (they slide on). The floor is
    // external: the block's horizontal momentum drops by min(μ, 1) m_b.
    let m_b = 0.2 * 0.1 * 0.1 * 7850.0 / 4.0;
    for mu in [0.0f64, 0.3, 0.7, 2.0] {
        let text = thrown_text(0.0, 0.5, 1e-6, 3e-4, 0.5e-6)
            .replace("friction = 0", &format!("mu = {mu:e}"));
        let m = load(&text, false).unwrap();
        let mut cd = CentralDifference::new(&m).unwrap();
        let mass = cd.lumped_mass().to_vec();
        let mut s = cd.initial_state().unwrap();
        let px0 = momentum(&m, &s, &mass, 0).0;
        cd.step_accepted(&mut s).unwrap();
        let px1 = momentum(&m, &s, &mass, 0).0;
        let rec = s.contact.pairs[0];
        eprintln!(
            "μ = {mu}: momentum {px0:.6} → {px1:.6}; forces normal {:.6e} tangential {:.6e} N",
            rec.force, rec.tangential_force
        );
        let expect = px0 - mu.min(1.0) * m_b;
        assert!(
            (px1 - expect).abs() <= 1e-8 * px0,
            "μ = {mu}: {px1} against {expect}"
        );
        assert!(rec.tangential_force.abs() <= mu * rec.force * (1.0 + 1e-8));
        for _ in 1..m.analysis.n_steps() {
            cd.step_accepted(&mut s).unwrap();
            let rec = s.contact.pairs[0];
            assert!(rec.tangential_force.abs() <= mu * rec.force * (1.0 + 1e-8) + 1e-9);
            assert!(s.ledger.residual().abs() <= 1e-11 * s.ledger.scale());
        }
    }
}

#[test]
fn friction_interpolates_between_sliding_and_sticking() {
    // The bottom nodes (lumped mass m_b = 3.925 kg of the block's 15.7 kg) hit the
    // rigid floor within the first step. The impact stops them vertically; friction β
    // takes the fraction β of their horizontal velocity: the block's horizontal
    // momentum drops by β m_b v_x (the floor is external), and the impact removes
    // ½ m_b (v_y² + (1 − (1 − β)²) v_x²) of kinetic energy, up to the work of the
    // position update (1e-3 of it here). A frictionless floor keeps the horizontal
    // momentum for the whole run.
    let m_b = 0.2 * 0.1 * 0.1 * 7850.0 / 4.0;
    for beta in [0.0, 0.5, 1.0] {
        let m = thrown(beta, 0.5, 1e-6, 3e-4, 0.5e-6);
        let mut cd = CentralDifference::new(&m).unwrap();
        let mass = cd.lumped_mass().to_vec();
        let mut s = cd.initial_state().unwrap();
        let px0 = momentum(&m, &s, &mass, 0).0;
        cd.step_accepted(&mut s).unwrap();
        let px1 = momentum(&m, &s, &mass, 0).0;
        let d1 = s.ledger.dissipated().contact;
        let loss = 0.5 * m_b * (1.0 + (1.0 - (1.0 - beta) * (1.0 - beta)));
        eprintln!("β = {beta}: momentum {px0:.6} → {px1:.6}, D_contact {d1:.6} J (impact loss {loss:.6} J)");
        assert!((px1 - (px0 - beta * m_b)).abs() <= 1e-12 * px0, "{px1}");
        assert!((d1 - loss).abs() <= 1e-2 * loss, "{d1} vs {loss}");
        for _ in 1..m.analysis.n_steps() {
            cd.step_accepted(&mut s).unwrap();
            assert!(s.ledger.residual().abs() <= 1e-11 * s.ledger.scale());
            assert!(s.contact.pairs[0].penetration <= 1e-12);
        }
        if beta == 0.0 {
            let px = momentum(&m, &s, &mass, 0).0;
            assert!((px - px0).abs() <= 1e-12 * px0, "{px} vs {px0}");
        }
    }
}

#[test]
fn the_position_weight_sets_where_an_impacting_node_stops() {
    // The bottom nodes start g0 = 0.3 h v above the floor: they hit it at
    // t_c = 0.3 h, and the paper's update x = x⁰ + t_c (w v + (1 − w) v×) + (h − t_c) v×
    // with v× normal 0 leaves them at the gap (1 − w) g0.
    let (h, v) = (1e-6, 1.0);
    let g0 = 0.3 * h * v;
    for w in [0.0, 0.5, 1.0] {
        let m = thrown(0.0, w, h, h, g0);
        let mut cd = CentralDifference::new(&m).unwrap();
        let mut s = cd.initial_state().unwrap();
        cd.step_accepted(&mut s).unwrap();
        let bottom = &m.contacts[0].sides[0].slaves;
        for &n in bottom {
            let gap = s.contact.gap[n];
            assert!(
                (gap - (1.0 - w) * g0).abs() <= 1e-9 * g0,
                "w = {w}: node {n} at gap {gap} instead of {}",
                (1.0 - w) * g0
            );
        }
        assert_eq!(s.contact.pairs[0].active, bottom.len());
    }
}

/// Probe peak deflection and total dissipation (D_contact + D_num) of a run.
fn peak_and_loss<I: Integrator>(i: &mut I) -> (f64, f64) {
    let m = i.model();
    let probe = m.probes[0].node;
    let n = m.analysis.n_steps();
    let mut s = i.initial_state().unwrap();
    let mut peak: f64 = 0.0;
    for _ in 0..n {
        i.step_accepted(&mut s).unwrap();
        peak = peak.max(s.u[2 * probe + 1].abs());
    }
    let d = s.ledger.dissipated();
    (peak, d.contact + d.numerical)
}

#[test]
fn both_paths_agree_as_both_steps_shrink() {
    // Benchmark 1's blocks (elastic, lumped mass in both) from the example pair:
    // the probe's peak deflection and the total dissipation of the two paths come
    // closer as both steps shrink 4x. The dissipation converges slowly: backward
    // Euler's damping of the impact's waves shrinks like h^½ (theory/contact.md),
    // towards the loss both share, the inelastic impact of the contact nodes.
    let implicit = example("explicit/two_blocks_backward_euler.toml");
    let explicit = example("explicit/two_blocks_central_difference.toml");
    let mut diffs = Vec::new();
    for (h, omega) in [(1e-6, 0.9), (2.5e-7, 0.225)] {
        let mi = load(
            &implicit.replace("dt = 2.5e-7", &format!("dt = {h:e}")),
            false,
        )
        .unwrap();
        let me = load(
            &explicit.replace(
                "scheme = \"central_difference\"",
                &format!("scheme = \"central_difference\"\nomega = {omega}"),
            ),
            false,
        )
        .unwrap();
        let (pi, di) = peak_and_loss(&mut BackwardEuler::new(&mi, Backend::Faer).unwrap());
        let (pe, de) = peak_and_loss(&mut CentralDifference::new(&me).unwrap());
        eprintln!(
            "implicit h = {h:e}: peak {pi:.5e} m, loss {di:.3} J; explicit h = {:.3e}: peak {pe:.5e} m, loss {de:.3} J",
            me.analysis.time.dt
        );
        diffs.push(((pi - pe).abs() / pe, (di - de).abs() / de));
    }
    eprintln!("relative differences (peak, loss): {diffs:?}");
    assert!(
        diffs[1].0 < 0.5 * diffs[0].0 && diffs[1].0 < 0.005,
        "{diffs:?}"
    );
    assert!(diffs[1].1 < 0.6 * diffs[0].1, "{diffs:?}");
}

#[test]
fn explicit_ledgers_close_with_every_material_model() {
    // The drop of the implicit contact test through central differences: the ledger
    // closes to round-off at every step (every term is formed on its own), the
    // material lines never fall, no node ends behind the master, and the contact line
    // takes the inelastic impact of the contact nodes.
    let base = example("explicit/two_blocks_central_difference.toml")
        .replace("divisions = [24, 12]", "divisions = [12, 6]")
        .replace("divisions = [12, 12]", "divisions = [6, 6]")
        .replace("origin = [0.3, 0.61]", "origin = [0.3, 0.601]")
        .replace("t_end = 4.0e-3", "t_end = 1.0e-3")
        .replace("vtk_every = 100", "vtk_every = 0");
    let elastic = "[materials.concrete]\nmodel = \"elastic\"\nE = 33e9\nnu = 0.2\nrho = 2400.0";
    assert!(base.contains(elastic));
    for (name, lines) in [
        ("elastic", "model = \"elastic\""),
        ("kelvin_voigt", "model = \"kelvin_voigt\"\nbeta = 1.0e6"),
        ("sls", "model = \"sls\"\nalpha = 0.5\nbeta = 1.0e-4"),
        (
            "mazars",
            "model = \"mazars\"\neps_t0 = 1.0e-4\nA_t = 1.0\nB_t = 1.0e4\nA_c = 1.2\nB_c = 1.5e3",
        ),
        (
            "rankine_hill",
            "model = \"rankine_hill\"\ntension = { law = \"bilinear\", strength = 2.9e6, post_yield_modulus = 1.65e9 }\ncompression = { law = \"bilinear\", strength = 30.0e6, post_yield_modulus = 1.65e9 }",
        ),
    ] {
        let text = base.replace(
            elastic,
            &format!("[materials.concrete]\n{lines}\nE = 33e9\nnu = 0.2\nrho = 2400.0"),
        );
        let m = load(&text, false).unwrap();
        let mut cd = CentralDifference::new(&m).unwrap();
        let mut s = cd.initial_state().unwrap();
        let mut prev = *s.ledger.dissipated();
        let mut max_force: f64 = 0.0;
        for _ in 0..m.analysis.n_steps() {
            cd.step_accepted(&mut s).unwrap();
            let l = &s.ledger;
            assert!(
                l.residual().abs() <= 1e-10 * l.scale(),
                "{name} at t = {}: residual {} of {}",
                s.t,
                l.residual(),
                l.scale()
            );
            let d = l.dissipated();
            for ((line, now), (_, before)) in d.lines().iter().zip(prev.lines()).take(3) {
                assert!(*now >= before - 1e-12 * l.scale(), "{name}: {line} fell from {before} to {now}");
            }
            prev = *d;
            assert!(s.contact.pairs[0].penetration <= 1e-12);
            max_force = max_force.max(s.contact.pairs[0].force);
        }
        let d = s.ledger.dissipated();
        eprintln!(
            "{name}: h = {:.3e} s, D_contact {:.3} J, D_num {:.3} J, material {:.3} J of E_kin0 {:.1} J, max force {max_force:.3e} N",
            m.analysis.time.dt,
            d.contact,
            d.numerical,
            d.material(),
            s.ledger.kinetic_0()
        );
        assert!(max_force > 0.0 && d.contact > 0.0, "{name}: the blocks met");
        if name != "elastic" {
            assert!(d.material() > 0.0, "{name}: the concrete dissipated nothing");
        }
    }
}

#[test]
fn the_exact_critical_step_is_the_measured_stability_limit() {
    // analysis.critical_step = "eigen": the mesh's own limit from Lanczos on M_L⁻¹K
    // (and M_L⁻¹C for the dashpots), against the limit measured by bisection on the
    // step: below it the energy stays bounded over 4000 steps, above it grows past
    // 10⁶. Undamped, and with Kelvin-Voigt's η = αC (ξ = 0.5 in the highest mode),
    // where the damped limit 2/(√(ω² + c²/4) + c/2) is exact too. The element bound
    // lies below both.
    let undamped = load(&plate(None, 2e-3), false).unwrap();
    let omega = rothe::modal::highest_frequency(&undamped).unwrap();
    let alpha = 1.0 / omega;
    let cases = [
        ("undamped", "model = \"elastic\"".to_string()),
        (
            "Kelvin-Voigt, eta = alpha C",
            format!("model = \"kelvin_voigt\"\nalpha = {alpha:e}"),
        ),
    ];
    for (what, material) in &cases {
        let eigen = "critical_step = \"eigen\"";
        let probe = load(&damped_plate(1e-7, 1.0, material, eigen), true).unwrap();
        let exact = rothe::modal::exact_stable_step(&probe).unwrap();
        let bound = rothe::time::cfl::stable_step(&probe).unwrap().dt;
        let holds = |h: f64| {
            let m = load(&damped_plate(h, 4000.0, material, ""), true).unwrap();
            let (drift, finite) = energy_drift(&m);
            finite && drift < 2.0
        };
        let (mut lo, mut hi) = (0.95 * exact.dt, 1.05 * exact.dt);
        assert!(
            holds(lo) && !holds(hi),
            "{what}: the limit is not bracketed"
        );
        for _ in 0..8 {
            let mid = 0.5 * (lo + hi);
            if holds(mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let measured = 0.5 * (lo + hi);
        eprintln!(
            "{what}: exact {:.6e} s, measured {measured:.6e} s ({:+.3} %), element bound {bound:.6e} s",
            exact.dt,
            100.0 * (exact.dt / measured - 1.0)
        );
        assert!(
            (exact.dt / measured - 1.0).abs() < 0.005,
            "{what}: exact {} against measured {measured}",
            exact.dt
        );
        assert!(bound <= exact.dt * (1.0 + 1e-9), "{what}: bound {bound}");
        // The scenario's default step is omega (0.9) times the exact one; a given
        // step above it is refused, naming the rule.
        let chosen = load(
            &damped_plate(1e-7, 1.0, material, eigen).replace("dt = 1e-7\n", ""),
            false,
        )
        .unwrap();
        assert!(
            (chosen.analysis.time.dt / (0.9 * exact.dt) - 1.0).abs() < 1e-12,
            "{what}: default step {}",
            chosen.analysis.time.dt
        );
        let e = load(&damped_plate(1.01 * exact.dt, 10.0, material, eigen), false)
            .unwrap_err()
            .to_string();
        assert!(e.contains("analysis.dt") && e.contains("eigen"), "{e}");
    }
}
