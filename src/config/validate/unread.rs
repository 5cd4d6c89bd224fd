//! Keys a run will not read: each is a warning naming it and why, so that nothing a
//! user wrote is ignored in silence (README, "What a run gives you").

use crate::model::{AnalysisKind, Model, TimeScheme};

/// Keys the analysis will not read, each as a warning naming it: those only the
/// other time scheme reads (kept, so that `compare` can run one file both ways),
/// `omega` beside a given explicit step, the dynamic keys of a static analysis, the
/// fixed-step keys of an error-controlled run, the contact keys of a model without
/// contact and the iteration keys of a model whose step is one linear solve. A key
/// counts as given when the `[analysis]` table holds it (after variants and `--set`),
/// whatever its value.
pub(super) fn unread_keys(s: &crate::config::Scenario, model: &Model) -> Vec<String> {
    let a = &s.analysis;
    let mut w = Vec::new();
    // One warning per key, with the first reason found.
    let unread = |w: &mut Vec<String>, keys: &[&str], why: &str| {
        for key in keys {
            let head = format!("analysis.{key} is not read: ");
            if a.given.contains(*key) && !w.iter().any(|x| x.starts_with(&head)) {
                w.push(format!("{head}{why}"));
            }
        }
    };
    let explicit = a.scheme == TimeScheme::CentralDifference;
    let statics = a.kind == AnalysisKind::Static;
    if statics {
        unread(
            &mut w,
            &[
                "scheme",
                "rho_inf",
                "zeta",
                "rayleigh",
                "damping",
                "contact_predictor",
                "critical_step",
                "omega",
            ],
            "a static analysis has no time scheme, inertia or damping",
        );
        if model.gravity.is_none() {
            unread(
                &mut w,
                &["mass"],
                "a static analysis uses the mass only for gravity, and there is none",
            );
        }
        for b in &s.bodies {
            if b.velocity.len > 0 && b.velocity.xyz != [0.0; 3] {
                w.push(format!(
                    "bodies `{}`.velocity is not read: a static analysis has no initial \
                     velocity",
                    b.name
                ));
            }
        }
    } else if explicit {
        unread(
            &mut w,
            &[
                "contact_qp",
                "friction_guess",
                "iteration",
                "keep_factor",
                "refactor_rate",
                "viscoelastic_state",
                "tolerance",
                "max_iterations",
                "displacement_tolerance",
                "max_cuts",
                "dt_min",
                "ordering",
            ],
            "central differences solve nothing and iterate nothing (lumped mass, one \
             explicit update per step)",
        );
        if a.omega.is_some() && a.dt.is_some() {
            w.push(
                "analysis.omega sets the default explicit step only; the given analysis.dt \
                 replaces it, so omega is ignored"
                    .into(),
            );
        }
    } else {
        unread(
            &mut w,
            &["critical_step", "omega"],
            "central differences read it; the implicit schemes do not",
        );
        if a.adaptive.is_some() {
            unread(
                &mut w,
                &["dt_min", "max_cuts"],
                "error-controlled steps go down their own ladder (analysis.adaptive.dt_min)",
            );
        }
    }
    if !explicit && model.contacts.is_empty() {
        unread(
            &mut w,
            &[
                "contact_tolerance",
                "contact_qp",
                "friction_guess",
                "contact_predictor",
            ],
            "the model has no contact pair",
        );
    }
    if !explicit
        && !model
            .materials
            .iter()
            .any(|m| m.has_constant_tangent() && !m.is_linear_elastic())
    {
        unread(
            &mut w,
            &["viscoelastic_state"],
            "no material of the model is linear viscoelastic",
        );
    }
    if !explicit && model.materials.iter().all(|m| m.has_constant_tangent()) {
        unread(
            &mut w,
            &[
                "iteration",
                "displacement_tolerance",
                "keep_factor",
                "refactor_rate",
            ],
            "every material of the model has a constant tangent, so a step is one linear \
             solve on a factor kept from step to step",
        );
    }
    w
}
