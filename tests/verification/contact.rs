//! Implicit contact: a block resting on a block, two bars colliding head on against
//! 1D wave theory, momentum in a free collision, condensed against full QP with the
//! KKT conditions, a beam dropped on unilateral supports, the energy split of an impact
//! against its closed form, ledgers with every material model, and the validation of
//! contact pairs.

use std::path::Path;

use rothe::linsolve::Backend;
use rothe::model::{ContactQp, Model};
use rothe::time::backward_euler::BackwardEuler;
use rothe::time::{Integrator, State};

/// The text of `examples/contact/NAME`.
fn example(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/contact")
        .join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

use crate::common::model;

/// Momentum `Σ M v` of the nodes of `body` in direction `dir`, and the body's mass.
fn momentum(m: &Model, s: &State, body: usize, mass: &[f64], dir: usize) -> (f64, f64) {
    let (mut p, mut mm) = (0.0, 0.0);
    for (n, &b) in m.mesh.node_body.iter().enumerate() {
        if b == body {
            p += s.mv[2 * n + dir];
            mm += mass[2 * n + dir];
        }
    }
    (p, mm)
}

#[test]
fn a_block_resting_on_a_block_carries_its_weight() {
    // Reference: statics. A steel block 0.5 x 0.2 x 0.1 m on a fixed steel base,
    // touching at t = 0, under gravity; mass damping (ζ = 2000 1/s) settles it. The
    // total contact force equals the weight ρ V g = 770.085 N to the solver's
    // tolerance, and no node penetrates beyond the contact tolerance.
    let text = example("block_resting.toml");
    let m = model(&text);
    let mut be = BackwardEuler::new(&m, Backend::Faer).unwrap();
    let mut s = be.initial_state();
    let tol = m.analysis.contact.tolerance;
    for _ in 0..m.analysis.n_steps() {
        be.step_accepted(&mut s).unwrap();
        assert!(
            s.contact.pairs[0].penetration <= tol,
            "penetration {}",
            s.contact.pairs[0].penetration
        );
        assert!(s.ledger.relative_residual() < 1e-8);
    }
    let weight = 0.5 * 0.2 * 0.1 * 7850.0 * 9.81;
    let f = s.contact.pairs[0].force;
    assert!(
        (f - weight).abs() < 1e-6 * weight,
        "contact force {f} vs weight {weight}"
    );
    assert_eq!(
        s.contact.pairs[0].active, 5,
        "every bottom node of the block bears"
    );
}

/// The bar impact example at step `h` with the QP form `qp`.
fn bars(h: f64, qp: &str) -> String {
    let text = example("bars_impact.toml");
    let with = text
        .replace("dt = 1.0e-6", &format!("dt = {h:e}"))
        .replace(
            "contact_qp = \"condensed\"",
            &format!("contact_qp = \"{qp}\""),
        )
        .replace("vtk_every = 20", "vtk_every = 0");
    assert_eq!(
        with.matches(&format!("dt = {h:e}")).count(),
        1,
        "the example's step changed"
    );
    with
}

/// Contact duration, plateau force, final striker and target velocities, and the
/// largest change of the total momentum over the run.
fn bar_impact(h: f64, qp: &str) -> (f64, f64, f64, f64, f64) {
    let m = model(&bars(h, qp));
    let mut be = BackwardEuler::new(&m, Backend::Faer).unwrap();
    let mass = be.mass().row_sums(&be.assembler().pattern);
    let mut s = be.initial_state();
    let p0 = momentum(&m, &s, 0, &mass, 0).0 + momentum(&m, &s, 1, &mass, 0).0;
    let (mut t_on, mut t_off, mut plateau, mut count) = (None, None, 0.0, 0);
    let mut dp: f64 = 0.0;
    let tol = m.analysis.contact.tolerance;
    for _ in 0..m.analysis.n_steps() {
        be.step_accepted(&mut s).unwrap();
        let f = s.contact.pairs[0].force;
        let p = momentum(&m, &s, 0, &mass, 0).0 + momentum(&m, &s, 1, &mass, 0).0;
        dp = dp.max((p - p0).abs());
        assert!(s.contact.pairs[0].penetration <= tol);
        if f > 0.0 {
            t_on.get_or_insert(s.t - h);
            t_off = Some(s.t);
            if s.t > 1e-4 && s.t < 3e-4 {
                plateau += f;
                count += 1;
            }
        }
    }
    let (ps, ms) = momentum(&m, &s, 0, &mass, 0);
    let (pt, mt) = momentum(&m, &s, 1, &mass, 0);
    (
        t_off.unwrap() - t_on.unwrap(),
        plateau / count as f64,
        ps / ms,
        pt / mt,
        dp / p0.abs(),
    )
}

#[test]
fn two_bars_collide_as_1d_wave_theory_says() {
    // Reference: 1D elastic waves (e.g. Graff, Wave Motion in Elastic Solids, §1.6).
    // Two equal bars, L = 1 m, c = √(E/ρ) = 5000 m/s (ν = 0), area 0.05 x 0.1 m², the
    // striker at v = 1 m/s: contact lasts 2L/c = 0.4 ms at the force ρcAv/2 = 1e5 N,
    // then the striker stands still and the target leaves at v. Backward Euler with
    // the QP contact converges to it as h → 0; linear momentum is conserved at every
    // step to solver tolerance.
    let (c, force, v) = (5000.0, 8000.0 * 5000.0 * 0.005 * 1.0 / 2.0, 1.0);
    let mut errors = Vec::new();
    for h in [4e-6, 2e-6, 1e-6] {
        let (duration, plateau, vs, vt, dp) = bar_impact(h, "condensed");
        eprintln!(
            "h = {h:e}: duration {duration:.4e} s (2L/c = {:.4e}), plateau {plateau:.6e} N, striker {vs:.4e} m/s, target {vt:.4e} m/s, momentum drift {dp:.1e}",
            2.0 / c
        );
        assert!(dp < 1e-9, "momentum drift {dp}");
        assert!((duration - 2.0 / c).abs() <= 2.0 * h, "duration {duration}");
        assert!((plateau - force).abs() < 1e-3 * force, "plateau {plateau}");
        errors.push((vs.abs(), (vt - v).abs()));
    }
    // The post-impact velocities converge with h at order one half, not one: the
    // impact sends a discontinuous wave, and backward Euler's numerical damping
    // (amplitude factor 1/√(1 + ω²h²)) acts on it as a diffusion of strength c²h/2,
    // which spreads the front over a width c√(h t) (theory/contact.md). The
    // duration is exact to the step at every h.
    let orders: Vec<(f64, f64)> = errors
        .windows(2)
        .map(|w| ((w[0].0 / w[1].0).log2(), (w[0].1 / w[1].1).log2()))
        .collect();
    eprintln!("velocity errors {errors:?}, observed orders (striker, target) {orders:?}");
    for (a, b) in &orders {
        assert!(
            (0.35..0.75).contains(a) && (0.35..0.75).contains(b),
            "orders {orders:?}"
        );
    }
    assert!(errors[2].0 < 0.1 && errors[2].1 < 0.1, "{errors:?}");
}

#[test]
fn the_condensed_and_the_full_qp_give_the_same_forces() {
    // The dual (condensed) and the primal (full) QP are the same problem: the same
    // multipliers at every step to solver tolerance, and the multipliers satisfy the
    // KKT conditions (λ ≥ 0, no penetration, no force across an open gap).
    // Scenarios refuse the full QP (it stalls where contact opens); the library
    // still runs it as the reference.
    let run = |qp: &str| {
        let mut m = model(&bars(2e-6, "condensed"));
        assert_eq!(m.analysis.contact.qp, ContactQp::Condensed);
        if qp == "full" {
            m.analysis.contact.qp = ContactQp::Full;
        }
        let mut be = BackwardEuler::new(&m, Backend::Faer).unwrap();
        let mut s = be.initial_state();
        let mut forces = Vec::new();
        for _ in 0..100 {
            be.step_accepted(&mut s).unwrap();
            for (_, l) in &s.contact.active {
                assert!(*l >= 0.0);
            }
            assert!(s.contact.pairs[0].penetration <= m.analysis.contact.tolerance);
            forces.push(s.contact.active.clone());
        }
        forces
    };
    let (a, b) = (run("condensed"), run("full"));
    let scale = 1e5;
    for (step, (x, y)) in a.iter().zip(&b).enumerate() {
        assert_eq!(x.len(), y.len(), "step {step}: active sets {x:?} vs {y:?}");
        for ((kx, lx), (ky, ly)) in x.iter().zip(y) {
            assert_eq!(kx, ky);
            assert!((lx - ly).abs() < 1e-6 * scale, "step {step}: {lx} vs {ly}");
        }
    }
}

#[test]
fn a_beam_dropped_on_unilateral_supports_bounces_off_them() {
    // A steel beam 1.7 x 0.25 x 0.2 m falling at 1 m/s onto two rigid supports
    // 0.23 m long at its ends (benchmark 2's supports): the supports push while the
    // beam presses on them (never pull: the force is never negative), then the beam
    // lifts off, moving up, and the force is zero again.
    let text = example("beam_on_supports.toml");
    let m = model(&text);
    let mut be = BackwardEuler::new(&m, Backend::Faer).unwrap();
    let mass = be.mass().row_sums(&be.assembler().pattern);
    let mut s = be.initial_state();
    let (mut pushed, mut lifted) = (false, false);
    for _ in 0..m.analysis.n_steps() {
        be.step_accepted(&mut s).unwrap();
        let f = s.contact.pairs[0].force + s.contact.pairs[1].force;
        assert!(
            s.contact.pairs.iter().all(|p| p.force >= 0.0),
            "a support pulls"
        );
        for p in &s.contact.pairs {
            assert!(p.penetration <= m.analysis.contact.tolerance);
        }
        let (p, mm) = momentum(&m, &s, 0, &mass, 1);
        if f > 0.0 {
            pushed = true;
        } else if pushed && p / mm > 0.0 {
            lifted = true;
        }
    }
    assert!(
        pushed && lifted,
        "the beam bounces off: pushed {pushed}, lifted {lifted}"
    );
}

fn drop_on(material: &str) -> String {
    format!(
        r#"
[analysis]
t_end = 1.0e-3
dt = 2.0e-6
vtk_every = 0
[materials.steel]
model = "elastic"
E = 210e9
nu = 0.3
rho = 7850.0
[materials.concrete]
E = 33e9
nu = 0.2
rho = 2400.0
{material}
[[bodies]]
name = "base"
material = "concrete"
thickness = 0.4
mesh = {{ kind = "rectangle", size = [1.2, 0.6], divisions = [12, 6] }}
[[bodies]]
name = "block"
material = "steel"
thickness = 0.2
velocity = [0.0, -3.836]
mesh = {{ kind = "rectangle", origin = [0.3, 0.601], size = [0.6, 0.6], divisions = [6, 6] }}
[[supports]]
set = "base.bottom"
fix = ["x", "y"]
[[supports]]
set = "block.bottom_left"
fix = ["x"]
[[contact]]
name = "impact"
slave = "block.bottom"
master = "base.top"
"#
    )
}

#[test]
fn contact_ledgers_close_with_every_material_model() {
    // Benchmark 1's two blocks (coarse, 0.1 m) with the concrete as each model, by
    // backward Euler, the trapezoidal rule (with and without the contact predictor)
    // and generalized-α: the ledger closes to the iteration tolerance at every step, the physical lines
    // never fall, and the contact line takes the energy of the impact.
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
      for (scheme, predictor) in [
          ("backward_euler", "none"),
          ("trapezoidal", "none"),
          ("generalized_alpha", "none"),
          ("trapezoidal", "stabilised"),
      ] {
        let name = format!("{name} ({scheme}, predictor {predictor})");
        let text = drop_on(lines).replace(
            "[analysis]",
            &format!("[analysis]\nscheme = \"{scheme}\"\ncontact_predictor = \"{predictor}\""),
        );
        let m = model(&text);
        let mut be = BackwardEuler::new(&m, Backend::Faer).unwrap();
        let mut s = be.initial_state();
        let mut prev = *s.ledger.dissipated();
        let mut max_force: f64 = 0.0;
        let mut worst_fall: f64 = 0.0;
        let mut u_prev = s.u.clone();
        rothe::time::march::march(
            &mut be,
            &mut s,
            rothe::time::march::StepControl::of(&m),
            |_, s, marched| {
                // The slave nodes sit above master nodes (both meshes 0.1 m): a node in
                // a notch of the deformed surface must not keep the loop from settling.
                if let rothe::time::march::Marched::Cut { reason, .. } = marched {
                    panic!("{name}: a step was cut at t = {}: {reason}", s.t);
                }
                let l = &s.ledger;
                assert!(
                    l.residual().abs() <= 1e-6 * l.scale(),
                    "{name} at t = {}: residual {} of {}",
                    s.t,
                    l.residual(),
                    l.scale()
                );
                let d = l.dissipated();
                // The contact line's increments are λ·(g⁰ − g¹) up to the linearisation
                // of the gaps over the step (theory/contact.md): it may fall by at most
                // the remainder Σλ·|Δu|²/L, with |Δu| the largest nodal increment and
                // L = 0.1 m the segments.
                let du2 = s
                    .u
                    .chunks(2)
                    .zip(u_prev.chunks(2))
                    .map(|(a, b)| (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2))
                    .fold(0.0f64, f64::max);
                let remainder = s.contact.pairs[0].force * du2 / 0.1;
                // The physical lines, contact, friction and the predictor's.
                for ((line, now), (_, before)) in d.lines().iter().zip(prev.lines()).take(6) {
                    let slack = 1e-9 * l.scale() + if *line == "contact" { remainder } else { 0.0 };
                    if *line == "contact" {
                        worst_fall = worst_fall.max((before - now) / remainder.max(1e-300));
                    }
                    assert!(
                        *now >= before - slack,
                        "{name}: {line} fell from {before} to {now} (scale {})",
                        l.scale()
                    );
                }
                prev = *d;
                u_prev.clone_from(&s.u);
                max_force = max_force.max(s.contact.pairs[0].force);
                assert!(s.contact.pairs[0].penetration <= m.analysis.contact.tolerance);
                Ok(())
            },
        )
        .unwrap();
        assert!(max_force > 0.0, "{name}: the blocks met");
        eprintln!(
            "{name}: E_kin0 {:.3} J, D_contact {:.3e} J, D_num {:.3} J, material {:.3} J, max force {max_force:.3e} N, worst fall of D_contact {worst_fall:.2} of the remainder bound",
            s.ledger.kinetic_0(),
            s.ledger.dissipated().contact,
            s.ledger.dissipated().numerical,
            s.ledger.dissipated().material()
        );
      }
    }
}

#[test]
fn contact_pairs_are_validated() {
    let base = drop_on("model = \"elastic\"");
    let cases: [(&str, &str, &str); 6] = [
        (
            "master = \"base.top\"",
            "master = \"block.bottom\"",
            "is the slave set too",
        ),
        (
            "master = \"base.top\"",
            "master = \"base.roof\"",
            "unknown edge set `base.roof`",
        ),
        (
            "master = \"base.top\"",
            "master = \"base.all\"",
            "is a node set",
        ),
        (
            "slave = \"block.bottom\"",
            "slave = \"block.nothing\"",
            "unknown set `block.nothing`",
        ),
        (
            "master = \"base.top\"",
            "rigid_line = [[0.0, 0.0], [0.0, 0.0]]",
            "zero length",
        ),
        (
            "master = \"base.top\"",
            "master = \"base.top\"\nrigid_line = [[0.0, 0.0], [1.0, 0.0]]",
            "give exactly one of",
        ),
    ];
    for (from, to, words) in cases {
        let e = rothe::config::from_str(&base.replace(from, to), Path::new("."))
            .unwrap_err()
            .to_string();
        assert!(e.contains("contact[0]") && e.contains(words), "{e}");
    }
    let e = rothe::config::from_str(
        &(base.clone()
            + "[[contact]]\nname = \"impact\"\nslave = \"base.top\"\nmaster = \"block.bottom\"\n"),
        Path::new("."),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("contact[1].name") && e.contains("duplicate"),
        "{e}"
    );
    let e = rothe::config::from_str(
        &base.replace("master = \"base.top\"", "master = \"block.top\""),
        Path::new("."),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("self-contact"), "{e}");
}

#[test]
fn friction_and_formulation_keys_are_validated() {
    let base = drop_on("model = \"elastic\"");
    let pair = "master = \"base.top\"";
    let explicit = |t: &str| {
        t.replace(
            "vtk_every = 0",
            "vtk_every = 0\nscheme = \"central_difference\"",
        )
    };
    let cases: Vec<(String, &str, &str)> = vec![
        (
            base.replace(pair, &format!("{pair}\nmu = -0.1")),
            "contact[0].mu",
            "friction coefficient",
        ),
        (
            base.replace(pair, &format!("{pair}\nformulation = \"mortar\""))
                .replace("slave = \"block.bottom\"", "slave = \"block.bottom_left\""),
            "contact[0].formulation",
            "mortar needs the slave",
        ),
        (
            base.replace(pair, &format!("{pair}\nboth_ways = true")),
            "contact[0].both_ways",
            "one pass",
        ),
        (
            base.replace(
                pair,
                &format!("{pair}\nformulation = \"node_to_segment\"\nmortar_basis = \"dual\""),
            ),
            "contact[0].mortar_basis",
            "mortar pairs only",
        ),
        (
            explicit(&base.replace(pair, &format!("{pair}\nmortar_basis = \"standard\""))),
            "contact[0].mortar_basis",
            "mortar pairs only",
        ),
        (
            base.replace(
                pair,
                "rigid_line = [[0.0, 0.0], [1.2, 0.0]]\nformulation = \"mortar\"",
            ),
            "contact[0].formulation",
            "a rigid line is straight",
        ),
        (
            explicit(&base.replace(pair, &format!("{pair}\nmu = 0.3\nfriction = 0.5"))),
            "contact[0].mu",
            "not both",
        ),
        (
            explicit(&base.replace(pair, &format!("{pair}\nformulation = \"mortar\""))),
            "contact[0].formulation",
            "node to segment",
        ),
        (
            base.replace(pair, &format!("{pair}\nmu = 0.3"))
                .replace("vtk_every = 0", "vtk_every = 0\ncontact_qp = \"full\""),
            "analysis.contact_qp",
            "not a solver for runs",
        ),
        (
            base.replace("divisions = [12, 6]", "divisions = [480, 6]"),
            "contact[0].formulation",
            "too fine for mortar",
        ),
    ];
    for (text, field, words) in cases {
        let e = rothe::config::from_str(&text, Path::new("."))
            .unwrap_err()
            .to_string();
        assert!(e.contains(field) && e.contains(words), "{e}");
    }
    // Node to segment takes any mesh ratio; rigid lines and the explicit path take μ.
    for text in [
        base.replace("divisions = [12, 6]", "divisions = [240, 6]")
            .replace(pair, &format!("{pair}\nformulation = \"node_to_segment\"")),
        base.replace(pair, "rigid_line = [[0.0, 0.0], [1.2, 0.0]]\nmu = 0.5"),
        explicit(&base.replace(pair, &format!("{pair}\nmu = 0.3"))),
    ] {
        let m = model(&text);
        assert_eq!(m.contacts.len(), 1);
    }
    let m = model(&base);
    assert_eq!(m.contacts[0].formulation, rothe::model::Formulation::Mortar);
    assert_eq!(m.contacts[0].mu, 0.0);
}

#[test]
fn an_infeasible_contact_qp_cuts_the_step_then_stops_naming_the_pair_and_status() {
    // A block whose bottom nodes are driven down (prescribed y) into a V of two rigid
    // lines: once the bottom passes below the apex (step 7, t = 6e-5 s), no sideways
    // motion keeps a bottom node above both lines (the QP is infeasible). Every step
    // cut fails the same way; the run stops naming the step, the pair, Clarabel's
    // status and the worst gap, and keeps what it wrote.
    let text =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/vee.toml"))
            .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let sc = dir.path().join("vee.toml");
    std::fs::write(&sc, text).unwrap();
    let out = dir.path().join("out");
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_rothe"))
        .args(["run", sc.to_str().unwrap(), "--out", out.to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success(), "the run went through: {err}");
    assert!(!err.contains("panicked"), "{err}");
    for word in [
        "step 7",
        "3 step cuts",
        "vee_left",
        "vee_right",
        "Clarabel status",
        "worst gap",
    ] {
        assert!(err.contains(word), "`{word}` not in: {err}");
    }
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["status"], "failed");
    let history = std::fs::read_to_string(out.join("history.csv")).unwrap();
    assert!(
        history.lines().count() >= 2,
        "the initial state is kept: {history}"
    );
    assert!(out.join("vtk").read_dir().unwrap().count() >= 1);
}

#[test]
fn check_writes_the_matrices_and_the_gap_rows_in_matrix_market() {
    use nalgebra_sparse::io::load_coo_from_matrix_market_file;
    use nalgebra_sparse::CsrMatrix;
    let dir = tempfile::tempdir().unwrap();
    let sc = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/contact/two_blocks.toml");
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_rothe"))
        .args([
            "check",
            sc.to_str().unwrap(),
            "--matrices",
            dir.path().to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let load = |name: &str| -> CsrMatrix<f64> {
        CsrMatrix::from(&load_coo_from_matrix_market_file::<f64, _>(dir.path().join(name)).unwrap())
    };
    let (k, mass, k_eff, g) = (
        load("K.mtx"),
        load("M.mtx"),
        load("K_eff.mtx"),
        load("G.mtx"),
    );
    let m = model(&std::fs::read_to_string(&sc).unwrap());
    let n = m.mesh.n_dofs();
    assert_eq!((k.nrows(), k.ncols(), mass.nrows()), (n, n, n));
    let dense = |a: &CsrMatrix<f64>| {
        let mut d = vec![0.0; a.nrows() * a.ncols()];
        for (i, j, v) in a.triplet_iter() {
            d[i * a.ncols() + j] += v;
        }
        d
    };
    let (kd, md, ed) = (dense(&k), dense(&mass), dense(&k_eff));
    // K and M symmetric.
    let kmax = kd.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    for i in 0..n {
        for j in 0..i {
            assert!((kd[i * n + j] - kd[j * n + i]).abs() <= 1e-12 * kmax);
            assert!((md[i * n + j] - md[j * n + i]).abs() <= 1e-12 * md[i * n + i].abs().max(1.0));
        }
    }
    // The effective matrix of backward Euler on the free dofs: M/h² + K.
    let free: Vec<usize> = std::fs::read_to_string(dir.path().join("free_dofs.txt"))
        .unwrap()
        .lines()
        .map(|l| l.parse().unwrap())
        .collect();
    let nf = free.len();
    assert_eq!((k_eff.nrows(), nf), (n - m.constraints.len(), nf));
    let h = m.analysis.time.dt;
    for (a, &i) in free.iter().enumerate() {
        for (b, &j) in free.iter().enumerate() {
            let want = md[i * n + j] / (h * h) + kd[i * n + j];
            assert!((ed[a * nf + b] - want).abs() <= 1e-12 * want.abs().max(kmax));
        }
    }
    // G: one row per slave node of the steel block's bottom at the initial geometry
    // (mortar, the default: the node's weighted gap), its slave weights (the steel
    // block's nodes) summing to +n and its master weights to −n: each row's x and y
    // parts sum to zero (action and reaction), its normal is unit and vertical.
    assert_eq!((g.nrows(), g.ncols()), (13, n));
    for row in g.row_iter() {
        let (mut sx, mut sy, mut slave_y) = (0.0, 0.0, 0.0);
        for (&d, &v) in row.col_indices().iter().zip(row.values()) {
            if d % 2 == 0 {
                sx += v
            } else {
                sy += v;
                if m.mesh.node_body[d / 2] == 1 {
                    slave_y += v;
                }
            }
        }
        assert!(sx.abs() < 1e-15 && sy.abs() < 1e-15, "{row:?}");
        assert!((slave_y - 1.0).abs() < 1e-14, "{row:?}");
    }
}

/// A very stiff block 0.1 x 0.1 m (thickness 0.1 m, density 1000, mass 1 kg) falling
/// at `v0` onto a rigid line, its bottom `θ h v0` above it: the gap closes at the
/// fraction `θ` of the first step. `E` is high enough that the block moves as a rigid
/// mass over a step: its elastic energy under the impact force is `λ²/K`, a fraction
/// `1/(ωh)² ≈ 1e-6` of `m v0²`. The run is the contact step and the step after (a
/// body at rest with such a stiffness has no force to measure its residual against).
fn rigid_drop(theta: f64, h: f64, v0: f64) -> String {
    let gap = theta * h * v0;
    format!(
        r#"
[analysis]
t_end = {t_end:e}
dt = {h:e}
vtk_every = 0

[materials.rigid]
model = "elastic"
E = 1.0e13
nu = 0.0
rho = 1000.0

[[bodies]]
name = "block"
material = "rigid"
thickness = 0.1
velocity = [0.0, {vy:e}]
mesh = {{ kind = "rectangle", origin = [-0.05, {gap:e}], size = [0.1, 0.1], divisions = [1, 1] }}

[[contact]]
name = "wall"
slave = "block.bottom"
rigid_line = [[-1.0, 0.0], [1.0, 0.0]]
"#,
        t_end = 2.0 * h,
        vy = -v0,
    )
}

#[test]
fn a_rigid_mass_hitting_a_wall_splits_its_energy_as_the_closed_form_says() {
    // theory/contact.md, "The energy of an implicit impact": a rigid mass m at v0
    // whose gap closes at the fraction θ of the contact step. Contact step: v¹ = θ v0,
    // ΔD_contact = λ g⁰ = m v0² θ(1 − θ), ΔD_num = ½ m v0² (1 − θ)². The step after:
    // the mass still moves towards the wall at v¹ with g⁰ = 0, so v² = 0, ΔD_contact = 0,
    // ΔD_num = ½ m v0² θ². Over the impact D_contact = m v0² θ(1 − θ) and
    // D_num = ½ m v0² (θ² + (1 − θ)²).
    let (h, v0, m) = (1e-3, 1.0, 1.0);
    let e0 = 0.5 * m * v0 * v0;
    for theta in [0.1, 0.25, 0.5, 0.75, 0.9] {
        let model = model(&rigid_drop(theta, h, v0));
        assert_eq!(model.analysis.n_steps(), 2);
        let mut be = BackwardEuler::new(&model, Backend::Faer).unwrap();
        let mut s = be.initial_state();
        let mut steps = Vec::new();
        for _ in 0..2 {
            be.step_accepted(&mut s).unwrap();
            let d = s.ledger.dissipated();
            steps.push((d.contact, d.numerical, s.ledger.kinetic()));
            assert!(s.ledger.relative_residual() < 1e-9);
            assert!(s.contact.pairs[0].penetration <= model.analysis.contact.tolerance);
        }
        eprintln!("θ = {theta}: (D_contact, D_num, E_kin) after each step {steps:?}");
        let close = |got: f64, want: f64, what: &str| {
            assert!(
                (got - want).abs() < 1e-5 * e0,
                "θ = {theta}: {what} {got:.12e}, closed form {want:.12e}"
            );
        };
        let contact = m * v0 * v0 * theta * (1.0 - theta);
        let (c1, num1, kin1) = steps[0];
        close(c1, contact, "D_contact after the contact step");
        close(
            num1,
            e0 * (1.0 - theta).powi(2),
            "D_num after the contact step",
        );
        close(kin1, e0 * theta * theta, "E_kin after the contact step");
        let (c2, num2, kin2) = steps[1];
        close(c2, contact, "D_contact after the step after");
        close(
            num2,
            e0 * (theta * theta + (1.0 - theta).powi(2)),
            "D_num after the step after",
        );
        close(kin2, 0.0, "E_kin after the step after");
    }
}

#[test]
fn two_bars_meeting_within_a_step_split_the_impact_as_the_note_derives() {
    // theory/contact.md: two free bars, undeformed and approaching at v, whose gap
    // g⁰ = θ h v closes within a step. The step's free motion is h v⁰ (K v⁰ = 0), so
    // the active rows give λ = W⁻¹1 h v (1 − θ) (W = G S⁻¹ Gᵀ the condensed
    // compliance), the step's contact force F₁ = 1ᵀλ ∝ (1 − θ), and
    // ΔD_contact = λ·g⁰ = F₁ θ h v ∝ θ(1 − θ). Later steps keep the bars in contact
    // (g⁰ = 0) with aligned normals, so D_contact stays. Checked for several θ: the
    // booked D_contact equals F₁ θ h v, F₁/(1 − θ) and D_contact/(θ(1 − θ)) are the
    // same for every θ, and the ledger closes.
    let (h, v, n) = (2e-6, 1.0, 2);
    let mut per_theta = Vec::new();
    for theta in [0.2, 0.5, 0.8] {
        let gap = (n as f64 + theta) * h * v;
        let text = bars(h, "condensed").replace(
            "origin = [-1.0, 0.0]",
            &format!("origin = [{:.17e}, 0.0]", -1.0 - gap),
        );
        assert!(text.contains(&format!("{:.17e}", -1.0 - gap)));
        let m = model(&text);
        let mut be = BackwardEuler::new(&m, Backend::Faer).unwrap();
        let mut s = be.initial_state();
        let (mut f1, mut booked, mut first) = (None, 0.0, None);
        for step in 0..200 {
            be.step_accepted(&mut s).unwrap();
            assert!(s.ledger.relative_residual() < 1e-8);
            let c = s.ledger.dissipated().contact;
            let f = s.contact.pairs[0].force;
            if f > 0.0 && f1.is_none() {
                f1 = Some(f);
                booked = c;
                first = Some(step);
            } else if f1.is_some() {
                assert!(
                    (c - booked).abs() < 1e-9 * booked,
                    "θ = {theta}, step {step}: D_contact {c} moved from {booked} in persistent contact"
                );
            }
        }
        let f1 = f1.expect("the bars meet");
        assert_eq!(first, Some(n), "θ = {theta}: the gap closes in step {n}");
        let want = f1 * theta * h * v;
        eprintln!(
            "θ = {theta}: F₁ = {f1:.9e} N, D_contact = {booked:.9e} J (F₁ θ h v = {want:.9e})"
        );
        assert!(
            (booked - want).abs() < 1e-6 * want,
            "θ = {theta}: D_contact {booked} against F₁ θ h v = {want}"
        );
        per_theta.push((f1 / (1.0 - theta), booked / (theta * (1.0 - theta))));
    }
    let (f_ref, d_ref) = per_theta[0];
    for (f, d) in &per_theta {
        assert!((f - f_ref).abs() < 1e-6 * f_ref, "{per_theta:?}");
        assert!((d - d_ref).abs() < 1e-6 * d_ref, "{per_theta:?}");
    }
}

#[test]
fn a_master_may_be_given_as_one_table() {
    // `master = { set = ... }` and `master = { rigid_line = ... }` are the same pairs as
    // the short keys; a table naming none, two, or an unknown key is refused naming it.
    let base = drop_on("model = \"elastic\"");
    let pair = "master = \"base.top\"";
    let line = "rigid_line = [[0.0, 0.0], [1.2, 0.0]]";
    let same = |a: &str, b: &str| {
        let (ma, mb) = (model(&base.replace(pair, a)), model(&base.replace(pair, b)));
        assert_eq!(ma.contacts, mb.contacts, "{a} against {b}");
    };
    same(pair, "master = { set = \"base.top\" }");
    same(line, &format!("master = {{ {line} }}"));
    let refused = |to: &str, words: &[&str]| {
        let e = rothe::config::from_str(&base.replace(pair, to), Path::new("."))
            .unwrap_err()
            .to_string();
        assert!(words.iter().all(|w| e.contains(w)), "{to}: {e}");
    };
    refused("master = {}", &["contact[0].master", "names no master"]);
    refused(
        &format!("master = {{ set = \"base.top\", {line} }}"),
        &[
            "contact[0]",
            "exactly one",
            "`contact[0].master.rigid_line`",
        ],
    );
    refused(
        "master = { rigid_lin = [[0.0, 0.0], [1.2, 0.0]] }",
        &["rigid_lin"],
    );
    refused(
        "master = { rigid_line = [[0.0, 0.0], [0.0, 0.0]] }",
        &["contact[0].master.rigid_line", "zero length"],
    );
}
