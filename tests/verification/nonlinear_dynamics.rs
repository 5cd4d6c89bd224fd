//! Global runs with damage and plasticity: a bar pulled past its peak (damage
//! localises, dissipation bounded by the work of internal forces), ledgers closing to
//! the iteration tolerance for both ways of paying for the iterations, step cuts that
//! recover, and a failure that names the step and the node and keeps its output.
#![allow(clippy::needless_range_loop, clippy::too_many_arguments)]

use rothe::linsolve::Backend;
use rothe::run::{run, RunOptions};

const MAZARS: &str =
    "model = \"mazars\"\neps_t0 = 1.0e-4\nA_t = 1.0\nB_t = 1.0e4\nA_c = 1.2\nB_c = 1.5e3";
const RH: &str = "model = \"rankine_hill\"\ntension = { law = \"bilinear\", strength = 2.9e6, post_yield_modulus = 1.65e9 }\ncompression = { law = \"bilinear\", strength = 30.0e6, post_yield_modulus = 1.65e9 }";

fn cantilever(material: &str, extra: &str) -> String {
    crate::workload::cantilever_scenario(
        [16, 4],
        1e-5,
        1e-3,
        &format!("{material}\nE = 33e9\nnu = 0.2\nrho = 2400.0"),
        &format!("vtk_every = 0\n{extra}"),
    )
}

fn run_text(text: &str, dir: &std::path::Path) -> rothe::Result<rothe::output::summary::Summary> {
    let model = rothe::config::from_str(text, std::path::Path::new(".")).unwrap();
    run(
        &model,
        &RunOptions {
            out: dir.into(),
            backend: Backend::Faer,
            progress: false,
            memory_limit: None,
            record_fields: false,
            overwrite: true,
            hooks: Default::default(),
        },
    )
}

#[test]
fn bar_pulled_past_peak_localises_damage() {
    // A concrete bar 1 m x 0.1 m (20x2 Q4, Mazars, NOTES.md parameters) pulled at its
    // right end to 5 times the threshold strain over 2 ms: past the peak the damage
    // concentrates in a band while the rest unloads elastically, and the dissipated
    // energy stays below the work of the internal forces (the paper's check).
    let text = format!(
        r#"
[analysis]
t_end = 2.0e-3
dt = 2.0e-5
vtk_every = 0
[materials.concrete]
{MAZARS}
E = 33e9
nu = 0.2
rho = 2400.0
[[bodies]]
name = "bar"
material = "concrete"
thickness = 0.1
mesh = {{ kind = "rectangle", size = [1.0, 0.1], divisions = [20, 2] }}
[[supports]]
set = "bar.left"
fix = ["x"]
[[supports]]
set = "bar.bottom_left"
fix = ["y"]
[[prescribed]]
set = "bar.right"
component = "x"
value = 5.0e-4
function = {{ kind = "ramp", t0 = 0.0, t1 = 2.0e-3 }}
"#
    );
    let model = rothe::config::from_str(&text, std::path::Path::new(".")).unwrap();
    let mut be = rothe::time::backward_euler::BackwardEuler::new(&model, Backend::Faer).unwrap();
    let mut s = be.initial_state();
    let control = rothe::time::march::StepControl::of(&model);
    rothe::time::march::march(&mut be, &mut s, control, |_, s: &rothe::time::State, _| {
        let l = &s.ledger;
        assert!(
            l.residual().abs() <= 1e-6 * l.scale(),
            "t = {}: residual {} scale {}",
            s.t,
            l.residual(),
            l.scale()
        );
        Ok(())
    })
    .unwrap();
    let c = s.points[0].committed();
    let d: Vec<f64> = (0..c.n_points()).map(|g| c.history(g)[2]).collect();
    let dmax = d.iter().cloned().fold(0.0, f64::max);
    let banded = d.iter().filter(|&&x| x > 0.5).count();
    assert!(dmax > 0.9, "peak passed: max damage {dmax}");
    assert!(
        banded * 4 <= d.len(),
        "damage localised: {banded} of {} points above 0.5",
        d.len()
    );
    let l = &s.ledger;
    assert!(
        l.dissipated().damage > 0.0 && l.dissipated().damage <= l.internal(),
        "D {} vs E_int {}",
        l.dissipated().damage,
        l.internal()
    );
}

#[test]
fn ledgers_close_to_the_iteration_tolerance_both_ways() {
    // Cantilever under a step load of 1 MPa (beyond first cracking): Rankine-Hill with
    // Newton and the consistent tangent; Mazars with the paper's fixed point, paid
    // either by refactorising the secant every iteration or by keeping the step's
    // first factorisation. Both ways give the same answer to the tolerance.
    let dir = tempfile::tempdir().unwrap();
    for material in [RH, MAZARS] {
        let a = run_text(
            &cantilever(material, "iteration = \"newton\"\nkeep_factor = false"),
            &dir.path().join("a"),
        )
        .unwrap();
        let b = run_text(
            &cantilever(material, "iteration = \"fixed\"\nkeep_factor = false"),
            &dir.path().join("b"),
        )
        .unwrap();
        // The same two with the factor kept while the iterations converge on it.
        let c = run_text(
            &cantilever(material, "iteration = \"newton\""),
            &dir.path().join("c"),
        )
        .unwrap();
        let d = run_text(
            &cantilever(material, "iteration = \"fixed\""),
            &dir.path().join("d"),
        )
        .unwrap();
        for s in [&c, &d] {
            assert!(s.energy.balance_residual_rel < 1e-6);
            let u = s.probes["tip"].max_abs_uy;
            let ua = a.probes["tip"].max_abs_uy;
            assert!((u - ua).abs() < 1e-5 * ua, "{material}: kept {u} vs {ua}");
        }
        eprintln!(
            "{material}: factorisations newton {} (kept {}), fixed {} (kept {}) over {} steps",
            a.solver.factorizations,
            c.solver.factorizations,
            b.solver.factorizations,
            d.solver.factorizations,
            a.steps
        );
        assert!(c.solver.factorizations < a.solver.factorizations);
        assert!(d.solver.factorizations <= b.solver.factorizations);
        for s in [&a, &b] {
            assert!(
                s.energy.balance_residual_rel < 1e-6,
                "{material}: {}",
                s.energy.balance_residual_rel
            );
            assert!(
                s.energy.dissipated.plastic + s.energy.dissipated.damage > 0.0,
                "{material}: nothing dissipated"
            );
        }
        assert!(
            b.solver.factorizations <= b.steps + 1,
            "fixed: one factorisation per step"
        );
        assert!(
            a.solver.factorizations > a.steps,
            "newton: refactorised within steps"
        );
        let (ua, ub) = (a.probes["tip"].max_abs_uy, b.probes["tip"].max_abs_uy);
        assert!((ua - ub).abs() < 1e-5 * ua, "{material}: {ua} vs {ub}");
    }
}

#[test]
fn step_cuts_recover_and_failures_keep_their_output() {
    let dir = tempfile::tempdir().unwrap();
    // Too few iterations for the fixed point at h = 1e-5: the step is cut and grows back.
    let s = run_text(
        &cantilever(MAZARS, "iteration = \"fixed\"\nmax_iterations = 4"),
        &dir.path().join("cut"),
    )
    .unwrap();
    assert!(s.solver.step_cuts > 0, "expected step cuts");
    assert!(
        (s.t_end - 1e-3).abs() < 1e-12,
        "reached T despite the cuts: {}",
        s.t_end
    );
    assert!(s.energy.balance_residual_rel < 1e-6);
    // No cut allowed and one iteration: the run stops with a clear message, keeps the
    // history written so far and records the failure in summary.json.
    let out = dir.path().join("fail");
    let err = run_text(
        &cantilever(
            MAZARS,
            "iteration = \"fixed\"\nmax_iterations = 1\nmax_cuts = 0",
        ),
        &out,
    )
    .unwrap_err();
    let msg = err.to_string();
    for w in [
        "step",
        "no convergence",
        "relative residuals",
        "node",
        "element",
    ] {
        assert!(msg.contains(w), "`{w}` not in {msg}");
    }
    let hist = std::fs::read_to_string(out.join("history.csv")).unwrap();
    assert!(hist.lines().count() >= 2);
    assert!(hist
        .lines()
        .next()
        .unwrap()
        .contains("iterations,nl_residual"));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["status"], "failed");
    assert!(summary["error"]
        .as_str()
        .unwrap()
        .contains("no convergence"));
}

#[test]
fn vtk_carries_damage_plastic_strain_and_dissipation_density() {
    let dir = tempfile::tempdir().unwrap();
    for (material, field) in [(MAZARS, "damage"), (RH, "equivalent_plastic_strain")] {
        let out = dir.path().join(field);
        let text = cantilever(material, "").replace("vtk_every = 0", "vtk_every = 50");
        run_text(&text, &out).unwrap();
        // Read the file back as a VTK reader would and look at the cell arrays.
        let vtk = vtkio::Vtk::import(out.join("vtk/step_0000100.vtu")).unwrap();
        let vtkio::model::DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
            panic!("not a grid")
        };
        let vtkio::model::Piece::Inline(piece) = &pieces[0] else {
            panic!("piece not inline")
        };
        let array = |name: &str| -> Vec<f64> {
            piece
                .data
                .cell
                .iter()
                .find_map(|a| match a {
                    vtkio::model::Attribute::DataArray(d) if d.name == name => {
                        d.data.clone().cast_into::<f64>()
                    }
                    _ => None,
                })
                .unwrap_or_else(|| panic!("{field}: no {name} array"))
        };
        let values = array(field);
        assert_eq!(values.len(), 64, "one value per element");
        assert!(
            values.iter().cloned().fold(0.0, f64::max) > 0.0,
            "{field} is zero everywhere"
        );
        let density = array("dissipation_density");
        assert!(density.iter().all(|&w| w >= 0.0) && density.iter().any(|&w| w > 0.0));
        assert_eq!(array("stress").len(), 3 * 64);
    }
}

#[test]
fn a_nonlinear_model_that_stays_elastic_runs_as_the_elastic_one() {
    // Rankine-Hill and Mazars with strengths far above what the cantilever reaches:
    // every point stays elastic, so the tangent is the one at rest throughout, the
    // factor is kept (the same number of factorisations as the elastic model), and
    // the history is the elastic one to round-off.
    let strong_rh = "model = \"rankine_hill\"\ntension = { law = \"bilinear\", strength = 2.9e12, post_yield_modulus = 1.65e9 }\ncompression = { law = \"bilinear\", strength = 30.0e12, post_yield_modulus = 1.65e9 }";
    let strong_mazars =
        "model = \"mazars\"\neps_t0 = 1.0\nA_t = 1.0\nB_t = 1.0e4\nA_c = 1.2\nB_c = 1.5e3";
    let dir = tempfile::tempdir().unwrap();
    let read = |name: &str, material: &str, analysis: &str| {
        let out = dir.path().join(name);
        let s = run_text(&cantilever(material, analysis), &out).unwrap();
        let text = std::fs::read_to_string(out.join("history.csv")).unwrap();
        let header: Vec<String> = text
            .lines()
            .next()
            .unwrap()
            .split(',')
            .map(String::from)
            .collect();
        let col = header.iter().position(|h| h == "tip_uy").unwrap();
        let tip: Vec<f64> = text
            .lines()
            .skip(1)
            .map(|l| l.split(',').nth(col).unwrap().parse().unwrap())
            .collect();
        (s, tip)
    };
    let (elastic, tip_e) = read("elastic", "model = \"elastic\"", "");
    let scale = tip_e.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    assert!(scale > 0.0);
    // A run and the largest difference of its tip history from the elastic one.
    let against_elastic = |name: &str, material: &str, analysis: &str| {
        let (s, tip) = read(name, material, analysis);
        let worst = tip
            .iter()
            .zip(&tip_e)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f64, f64::max);
        (s, worst)
    };
    // With the factor kept while it serves (the default) no refactorisation is even
    // asked for: each step is one solve from the committed force, as elastic.
    for (name, material) in [("rh_kept", strong_rh), ("mazars_kept", strong_mazars)] {
        let (s, worst) = against_elastic(name, material, "");
        eprintln!(
            "{name}: {} factorisations, {} iterations (elastic {}, {}); largest tip difference {:.2e}",
            s.solver.factorizations,
            s.solver.iterations,
            elastic.solver.factorizations,
            elastic.solver.iterations,
            worst
        );
        assert!(worst <= 1e-12 * scale, "{name}: tip differs by {worst}");
        assert_eq!(s.solver.factorizations, elastic.solver.factorizations);
        assert_eq!(s.solver.iterations, elastic.solver.iterations, "{name}");
    }
    // Refactorising at every changed tangent (full Newton): the tangent is asked for
    // at every iteration and found unchanged, so the factor is kept all the same.
    for (name, material) in [("rh", strong_rh), ("mazars", strong_mazars)] {
        let (s, worst) = against_elastic(name, material, "keep_factor = false");
        eprintln!(
            "{name}: {} factorisations ({} kept), elastic {}; largest tip difference {:.2e} of {scale:.3e}",
            s.solver.factorizations, s.solver.reused_factors, elastic.solver.factorizations, worst
        );
        assert!(worst <= 1e-12 * scale, "{name}: tip differs by {worst}");
        assert_eq!(
            s.solver.factorizations, elastic.solver.factorizations,
            "{name}: the factor is remade"
        );
        assert!(s.solver.reused_factors > 0);
    }
}

/// A regression cantilever with its traction `from` raised to `to` (Pa), as a model.
fn loaded_cantilever(name: &str, from: &str, to: &str) -> rothe::model::Model {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/regression")
        .join(format!("{name}.toml"));
    let line = |t: &str| format!("value = [0.0, {t}]");
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains(&line(from)), "{name}: the load line moved");
    let text = text.replace(&line(from), &line(to));
    rothe::config::from_str(&text, std::path::Path::new(".")).unwrap()
}

#[test]
fn iterations_on_a_kept_factor_reach_full_newtons_answer_over_a_large_yielded_zone() {
    use rothe::time::backward_euler::BackwardEuler;
    use rothe::time::Integrator;
    // The regression cantilevers under twice their traction: the clamped end yields
    // (Rankine-Hill) or cracks (Mazars) over a large share of its points. Every step
    // of both methods meets the equilibrium tolerance; the kept factor is remade
    // only when an iteration contracts the residual by less than `refactor_rate`.
    let cases = [
        ("rankine_hill_cantilever", "-4.0e6", "-8.0e6", 3),
        ("mazars_cantilever", "-2.0e6", "-4.0e6", 2),
    ];
    for (name, from, to, history_slot) in cases {
        let mut runs = Vec::new();
        for rate in [None, Some(rothe::model::DEFAULT_REFACTOR_RATE)] {
            let mut model = loaded_cantilever(name, from, to);
            model.analysis.iteration.refactor_rate = rate;
            let tolerance = model.analysis.iteration.tolerance;
            let mut be = BackwardEuler::new(&model, Backend::Faer).unwrap();
            let mut s = be.initial_state();
            let mut iterations = 0;
            while s.step < model.analysis.n_steps() {
                let r = be.step_accepted(&mut s).unwrap();
                assert!(
                    r.nl_residual <= tolerance,
                    "{name} ({rate:?}): step {} ends at {:.2e}",
                    s.step,
                    r.nl_residual
                );
                iterations += r.iterations;
            }
            // Points past their elastic range: a plastic multiplier (κ_t) or damage.
            let store = &s.points[0];
            let yielded = (0..store.n_points())
                .filter(|&g| store.committed().history(g)[history_slot] > 0.0)
                .count();
            let factorizations = be.solver().factorizations;
            eprintln!(
                "{name} ({rate:?}): {yielded} of {} points past their elastic range, \
                 {iterations} iterations, {factorizations} factorisations",
                store.n_points()
            );
            assert!(
                yielded * 10 >= store.n_points(),
                "{name}: only {yielded} points yielded; the test needs a large zone"
            );
            runs.push((s.u.clone(), iterations, factorizations));
        }
        let (full, kept) = (&runs[0], &runs[1]);
        let scale = full.0.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let worst = full
            .0
            .iter()
            .zip(&kept.0)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f64, f64::max);
        eprintln!(
            "{name}: largest displacement difference {:.2e} of {scale:.3e}",
            worst
        );
        // Both stop below the residual tolerance 1e-8; their answers agree to it.
        assert!(
            worst <= 1e-7 * scale,
            "{name}: the answers differ by {worst}"
        );
        assert!(
            kept.2 < full.2,
            "{name}: {} factorisations kept against {} full",
            kept.2,
            full.2
        );
    }
}
