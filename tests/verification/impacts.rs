//! Generalized-α through impacts (theory/trapezoidal.md, "Impact steps"): a step
//! that changes which slaves are held is taken by the trapezoidal rule, whose
//! energy identity holds with the contact force at the step's end, and the
//! acceleration carried on is the new state's equilibrium one. No energy is then
//! created at any step, at any ρ∞, with fixed and error-controlled steps, in the
//! plane and in a solid, against rigid and deformable masters; the check that says
//! so is the run's own (`summary.json`'s `no_energy_created`).

use rothe::linsolve::Backend;
use rothe::output::summary::RunStatus;

use crate::common::model;

/// A steel block dropped at 3 m/s under gravity from 0.5 mm onto `master`: in the
/// plane (a rigid line, or a concrete base) or as a solid (a rigid plane, or a
/// concrete base with mortar), with `rho_inf`, fixed or error-controlled steps
/// (tolerance 1e-3), and with or without the contact predictor.
fn drop(solid: bool, rigid: bool, rho_inf: f64, adaptive: bool, predictor: bool) -> String {
    let mut steps = if adaptive {
        "adaptive = { tolerance = 1.0e-3 }".to_string()
    } else {
        String::new()
    };
    if predictor {
        steps.push_str("\ncontact_predictor = \"stabilised\"");
    }
    let (block, base, master) = match (solid, rigid) {
        (false, true) => (
            "thickness = 0.1\nmesh = { kind = \"rectangle\", origin = [0.0, 0.0005], size = [0.2, 0.2], divisions = [4, 4] }",
            String::new(),
            "rigid_line = [[-1.0, 0.0], [1.0, 0.0]]",
        ),
        (false, false) => (
            "thickness = 0.1\nmesh = { kind = \"rectangle\", origin = [0.1, 0.3005], size = [0.2, 0.2], divisions = [4, 4] }",
            r#"[[bodies]]
name = "base"
material = "concrete"
thickness = 0.1
mesh = { kind = "rectangle", size = [0.4, 0.3], divisions = [6, 3] }
[[supports]]
set = "base.bottom"
fix = ["x", "y"]"#
                .to_string(),
            r#"master = "base.top""#,
        ),
        (true, true) => (
            r#"mesh = { kind = "box", origin = [0.0, 0.0005, 0.0], size = [0.1, 0.1, 0.1], divisions = [3, 3, 3] }"#,
            String::new(),
            "rigid_plane = { point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }",
        ),
        (true, false) => (
            r#"mesh = { kind = "box", origin = [0.05, 0.1005, 0.05], size = [0.1, 0.1, 0.1], divisions = [2, 2, 2] }"#,
            r#"[[bodies]]
name = "base"
material = "concrete"
mesh = { kind = "box", size = [0.2, 0.1, 0.2], divisions = [3, 1, 3] }
[[supports]]
set = "base.bottom"
fix = ["x", "y", "z"]"#
                .to_string(),
            "master = \"base.top\"\nmortar_basis = \"dual\"",
        ),
    };
    let (g, v) = if solid {
        ("[0.0, -9.81, 0.0]", "[0.0, -3.0, 0.0]")
    } else {
        ("[0.0, -9.81]", "[0.0, -3.0]")
    };
    format!(
        r#"
[analysis]
scheme = "generalized_alpha"
rho_inf = {rho_inf:?}
t_end = 1.0e-3
dt = 1.0e-5
vtk_every = 0
gravity = {g}
{steps}
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
name = "block"
material = "steel"
velocity = {v}
{block}
{base}
[[contact]]
name = "impact"
slave = "block.bottom"
{master}
"#
    )
}

#[test]
fn generalized_alpha_creates_no_energy_at_impacts() {
    let dir = tempfile::tempdir().unwrap();
    let mut k = 0;
    for (solid, rigid) in [(false, true), (false, false), (true, true), (true, false)] {
        // The predictor with deformable masters (its projection onto a rigid
        // master is not what it is built for: theory/trapezoidal.md).
        let predictors: &[bool] = if rigid { &[false] } else { &[false, true] };
        for (rho_inf, adaptive, &predictor) in [0.0, 0.5, 0.8]
            .into_iter()
            .flat_map(|r| [(r, false), (r, true)])
            .flat_map(|(r, a)| predictors.iter().map(move |p| (r, a, p)))
        {
            {
                let m = model(&drop(solid, rigid, rho_inf, adaptive, predictor));
                k += 1;
                let out = dir.path().join(format!("run{k}"));
                let summary =
                    rothe::run::run(&m, &rothe::run::RunOptions::new(&out, Backend::Faer)).unwrap();
                let case = format!(
                    "solid {solid}, rigid {rigid}, rho_inf {rho_inf}, adaptive {adaptive}, \
                     predictor {predictor}"
                );
                assert_eq!(summary.status, RunStatus::Completed, "{case}");
                // The impact happened, and was taken as one.
                assert!(summary.solver.impact_steps > 0, "{case}");
                assert!(summary.energy.dissipated.contact > 0.0, "{case}");
                // The largest excess over the run of E_kin + E_el + the physical
                // dissipation over the supply: round-off of the impact's energy
                // beside the ledger's own residual (theory/trapezoidal.md).
                let c = summary.checks.no_energy_created;
                let e0 = summary.energy.kinetic_0;
                let supply = e0 + summary.energy.external_work.abs();
                let bound = (summary.energy.balance_residual_rel + 1e-11) * supply;
                eprintln!(
                    "{case}: {} impact steps, created {:.2e} E_0 (bound {:.1e})",
                    summary.solver.impact_steps,
                    c.lhs / e0,
                    bound / e0
                );
                assert!(c.holds, "{case}: {c:?}");
                assert!(c.lhs <= bound, "{case}: created {} J > {bound} J", c.lhs);
            }
        }
    }
}

#[test]
fn generalized_alpha_creates_no_energy_in_a_frictional_oblique_impact() {
    // examples/contact/oblique_impact.toml: a block hitting a plate at 3 m/s along
    // and 2 m/s into it, μ = 0.3, sliding all through the contact. Steps that slide
    // under friction are impact steps too (theory/trapezoidal.md): taken as
    // ordinary generalized-α steps, this run created 0.2 J of 102.
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/contact/oblique_impact.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let dir = tempfile::tempdir().unwrap();
    for rho_inf in [0.0, 0.5, 0.8] {
        let t = text.replace(
            "dt = 1.0e-6",
            &format!("dt = 1.0e-6\nscheme = \"generalized_alpha\"\nrho_inf = {rho_inf:?}"),
        );
        let m = model(&t);
        let out = dir.path().join(format!("rho{rho_inf}"));
        let summary =
            rothe::run::run(&m, &rothe::run::RunOptions::new(&out, Backend::Faer)).unwrap();
        assert_eq!(summary.status, RunStatus::Completed);
        assert!(summary.energy.dissipated.friction > 0.1 * summary.energy.kinetic_0);
        let c = summary.checks.no_energy_created;
        // The trapezoidal rule itself leaves 2.6e-11 E_0 here (the gaps' and slips'
        // linearisation within the contact tolerance), impact steps 1.3e-11.
        let bound = (summary.energy.balance_residual_rel + 1e-10) * summary.energy.kinetic_0;
        eprintln!(
            "rho_inf {rho_inf}: {} impact steps, created {:.2e} J (bound {bound:.1e})",
            summary.solver.impact_steps, c.lhs
        );
        assert!(c.holds && c.lhs <= bound, "rho_inf {rho_inf}: {c:?}");
    }
}

#[test]
#[ignore = "about a minute: the fallback's end-to-end check (theory/trapezoidal.md)"]
fn an_impact_step_that_does_not_converge_is_taken_by_generalized_alpha() {
    // examples/contact/incline.toml (a block sliding down a rigid line under
    // friction) with error-controlled steps: every step slides, so every step is an
    // impact step, and at t = 6.86e-2 s the trapezoidal step's friction shift does
    // not settle at the bottom rung. Without the fallback the run stops there;
    // with it generalized-α takes that step, and nothing is created.
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/contact/incline.toml");
    let text = std::fs::read_to_string(path).unwrap().replace(
        "dt = 1.0e-3",
        "dt = 1.0e-3\nscheme = \"generalized_alpha\"\nadaptive = { tolerance = 1.0e-3 }",
    );
    let m = model(&text);
    let dir = tempfile::tempdir().unwrap();
    let summary =
        rothe::run::run(&m, &rothe::run::RunOptions::new(dir.path(), Backend::Faer)).unwrap();
    assert_eq!(summary.status, RunStatus::Completed);
    assert!(summary.solver.impact_fallbacks > 0, "{:?}", summary.solver);
    assert!(summary.checks.no_energy_created.holds);
}
