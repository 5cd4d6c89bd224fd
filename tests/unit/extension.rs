//! Extension: a material model the crate does not know, written as a test fixture
//! in one file (`tests/fixtures/trivial_elastic.rs`) and registered with one call
//! (`Law::custom`), runs a plane and a solid cantilever through the Gauss-point
//! pass, the equilibrium loop and the ledger like a built-in model.
//!
//! Reference: the built-in elastic model on the same scenarios (which takes the
//! `K u` path instead of the Gauss points), so the histories agree to round-off:
//! every ledger line and probe within 1e-9 of its column's scale, and the ledger
//! of the custom run closing by itself.

#[path = "../fixtures/trivial_elastic.rs"]
mod trivial_elastic;

use std::path::Path;

use rothe::linsolve::Backend;
use rothe::material::Law;
use rothe::run::{run_kept, Hooks, RunOptions};
use trivial_elastic::TrivialElastic;

/// The history columns of `scenario` run in memory, with every material's law
/// replaced by `law` when given.
fn history(scenario: &str, law: Option<Law>) -> Vec<(String, Vec<f64>)> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(scenario);
    let mut model = rothe::config::load(&path).unwrap();
    if let Some(law) = law {
        for m in &mut model.materials {
            m.law = law.clone();
        }
    }
    let opts = RunOptions {
        out: Default::default(),
        backend: Backend::Faer,
        progress: false,
        memory_limit: None,
        record_fields: false,
        overwrite: true,
        hooks: Hooks {
            no_files: true,
            keep: true,
            observer: None,
        },
    };
    run_kept(&model, &opts).unwrap().1.columns
}

#[test]
fn a_law_registered_from_the_tests_runs_a_plane_and_a_solid_cantilever() {
    for scenario in [
        "tests/regression/elastic_cantilever.toml",
        "tests/regression/solid_elastic_cantilever.toml",
    ] {
        let builtin = history(scenario, None);
        let custom = history(scenario, Some(Law::custom(TrivialElastic)));
        let col = |h: &[(String, Vec<f64>)], name: &str| -> Vec<f64> {
            h.iter().find(|(n, _)| n == name).unwrap().1.clone()
        };
        let energy_scale = ["E_kin", "E_int", "W_ext"]
            .iter()
            .flat_map(|c| col(&builtin, c))
            .fold(0.0f64, |m, x| m.max(x.abs()));
        assert!(energy_scale > 0.0, "{scenario}: the cantilever moves");
        for name in ["E_kin", "E_int", "W_ext", "D_num", "tip_ux", "tip_uy"] {
            let (want, got) = (col(&builtin, name), col(&custom, name));
            let scale = if name.starts_with("tip") {
                want.iter().fold(0.0f64, |m, x| m.max(x.abs()))
            } else {
                energy_scale
            };
            for (i, (w, g)) in want.iter().zip(&got).enumerate() {
                assert!(
                    (w - g).abs() <= 1e-9 * scale,
                    "{scenario}: {name} at row {i} is {g} against the built-in {w}"
                );
            }
        }
        // The custom run's own ledger closes: W_ext = E_kin + E_int + D_num.
        let (k, e, w, d) = (
            col(&custom, "E_kin"),
            col(&custom, "E_int"),
            col(&custom, "W_ext"),
            col(&custom, "D_num"),
        );
        let last = k.len() - 1;
        let residual = w[last] - k[last] - e[last] - d[last];
        assert!(
            residual.abs() <= 1e-9 * energy_scale,
            "{scenario}: the ledger misses {residual:e}"
        );
    }
}
