//! What a rejected step and a failed first factorisation say: the outcome of the
//! equilibrium loop as a message naming the time, the dof, node or element at
//! fault, and the likely cause of an effective matrix that is not positive
//! definite at the start.

use super::operators::{Operators, Scheme};
use crate::linsolve::LowerCsc;
use crate::model::Model;
use crate::nonlinear::Outcome;
use crate::system::DofMap;

/// A message for a rejected step: what failed, when, and where.
pub(crate) fn describe(model: &Model, outcome: &Outcome, t1: f64, h: f64) -> String {
    let when = format!("at t = {t1:.6e} (h = {h:.3e})");
    match outcome {
        Outcome::Converged { .. } => format!("converged {when}"),
        Outcome::NotConverged {
            iterations,
            history,
            worst,
            constraints,
        } => {
            let worst_text = worst
                .map(|(d, r)| {
                    format!(
                        "; largest residual {:.3e} N at {}",
                        r.abs(),
                        model.describe_dof(d)
                    )
                })
                .unwrap_or_default();
            let unheld = worst
                .as_ref()
                .and_then(|&(d, _)| unheld_load(model, d))
                .unwrap_or_default();
            format!(
                "no convergence {when} after {iterations} iterations; relative residuals {}{worst_text}{unheld}{}",
                residuals(history),
                contact_note(model, constraints)
            )
        }
        Outcome::NotPositiveDefinite { dof, message } => format!(
            "the effective matrix lost positive definiteness {when}{} ({message})",
            dof.map(|d| format!(" at {}", model.describe_dof(d)))
                .unwrap_or_default()
        ),
        Outcome::MaterialFailure(f) => format!(
            "the material update found no admissible state {when} at {}",
            model.describe_point(f.block, f.element)
        ),
        Outcome::ConstraintFailure(why) => format!("the constraint solve failed {when}: {why}"),
        Outcome::NonFinite {
            quantity,
            dof,
            value,
        } => format!(
            "{quantity} is {value} {when}{}",
            dof.map(|d| format!(" at {}", model.describe_dof(d)))
                .unwrap_or_default()
        ),
    }
}

/// What the contact reported at the last evaluation of a failed loop: the
/// constraint whose membership kept changing (pair, node), the penetration and the
/// open gap under force.
fn contact_note(model: &Model, c: &crate::nonlinear::ConstraintStatus) -> String {
    let mut parts = Vec::new();
    if let Some((pair, node)) = c.changed_at {
        let name = model.contacts.get(pair).map_or("?", |p| p.name.as_str());
        parts.push(format!(
            "the active set of pair `{name}` still changed at its slave {}",
            model.describe_node(node)
        ));
    }
    if c.penetration > 0.0 {
        parts.push(format!("penetration {:.3e} m", c.penetration));
    }
    if c.complementarity > 0.0 {
        parts.push(format!(
            "a force across an open gap of {:.3e} m",
            c.complementarity
        ));
    }
    if parts.is_empty() {
        String::new()
    } else {
        format!("; contact: {}", parts.join(", "))
    }
}

/// The relative residuals of a failed loop: all of them up to eight, else the first
/// three and the last three, and whether the last ones stagnate (within 1 %).
fn residuals(history: &[f64]) -> String {
    let show = |r: &[f64]| {
        r.iter()
            .map(|r| format!("{r:.2e}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    if history.len() <= 8 {
        return format!("[{}]", show(history));
    }
    let tail = &history[history.len() - 3..];
    let last = tail[2];
    let stagnant = tail.iter().all(|&r| (r - last).abs() <= 0.01 * last.abs());
    format!(
        "[{}, …, {}]{}",
        show(&history[..3]),
        show(tail),
        if stagnant {
            format!(" (stagnant at {last:.2e})")
        } else {
            String::new()
        }
    )
}

/// In statics, when a body that only contact holds is where a failed loop's largest
/// residual sits (that body, its pairs and what the load needs), or shares a pair
/// with the body where it sits (its position along the free motion is not
/// determined, and the pair's active set moves with it).
fn unheld_load(model: &Model, dof: usize) -> Option<String> {
    if model.analysis.time.kind != crate::model::AnalysisKind::Static {
        return None;
    }
    let mesh = &model.mesh;
    let on = |p: &crate::model::ContactPair, body: usize| {
        p.sides.iter().any(|s| {
            s.slaves.iter().any(|&n| mesh.node_body[n] == body)
                || s.master_nodes().iter().any(|&n| mesh.node_body[n] == body)
        })
    };
    let pairs_of = |body: usize| -> Vec<String> {
        model
            .contacts
            .iter()
            .filter(|p| on(p, body))
            .map(|p| format!("`{}`", p.name))
            .collect()
    };
    let residual_body = mesh.node_body[dof / mesh.dim];
    let unheld = super::seat::bodies_held_by_contact_only(model);
    let frictionless = model.contacts.iter().all(|p| p.mu == 0.0);
    let remedy = if frictionless {
        "friction (`mu`), "
    } else {
        ""
    };
    if !unheld.contains(&residual_body) {
        // A neighbour through a pair that only contact holds.
        let body = unheld.into_iter().find(|&b| {
            model
                .contacts
                .iter()
                .any(|p| on(p, b) && on(p, residual_body))
        })?;
        return Some(format!(
            "; body `{}` has a rigid motion that no support holds and is held by contact \
             pair(s) {} alone: statics does not determine its position along that motion, \
             and the pair's contact set moves with it. Add a support against that motion \
             (a roller), {remedy}or run it dynamically",
            model.bodies[body].name,
            pairs_of(body).join(", "),
        ));
    }
    Some(format!(
        "; body `{}` has no support against this motion and is held by contact pair(s) {} \
         alone, which cannot carry the load on it ({}): a static load without \
         equilibrium. Add a support, {remedy}or run it dynamically",
        model.bodies[residual_body].name,
        pairs_of(residual_body).join(", "),
        if frictionless {
            "frictionless contact carries only pressure across the surface"
        } else {
            "the contact's friction cone cannot hold it, or the load pulls it off"
        },
    ))
}

/// Why the initial effective matrix is not positive definite, as far as can be told:
/// a step size that takes the mass term out of the floating-point range, a free dof
/// with nothing on its diagonal (a node of no element), or, in statics, a body whose
/// supports do not stop its rigid motion.
pub(crate) fn likely_cause(
    model: &Model,
    ops: &Operators,
    k_eff: &LowerCsc,
    dofs: &DofMap,
) -> String {
    let (c_m, _, _) = ops.coefficients();
    if let Scheme::Dynamic { h, .. } = ops.scheme {
        if !c_m.is_finite() || c_m == 0.0 {
            return format!(
                "the step h = {h:e} s puts 1/h² = {:e} outside the floating-point range",
                1.0 / (h * h)
            );
        }
    }
    if let Some(eq) = (0..k_eff.n).find(|&j| k_eff.diagonal(j).is_nan() || k_eff.diagonal(j) <= 0.0)
    {
        return format!(
            "{} has a zero or negative diagonal entry: a node that no element holds, or a \
             material with no stiffness",
            model.describe_dof(dofs.free[eq])
        );
    }
    match ops.scheme {
        Scheme::Static { .. } => {
            let mut free_bodies = Vec::new();
            for (b, body) in model.bodies.iter().enumerate() {
                let mut held = [0usize; 3];
                let mut nodes = std::collections::BTreeSet::new();
                for c in &model.constraints {
                    let dim = model.mesh.dim;
                    if model.mesh.node_body[c.dof / dim] == b {
                        held[c.dof % dim] += 1;
                        nodes.insert(c.dof / dim);
                    }
                }
                let dim = model.mesh.dim;
                let why = if held[..dim].iter().all(|&h| h == 0) {
                    Some("has no supports".to_string())
                } else if let Some(c) = (0..dim).find(|&c| held[c] == 0) {
                    Some(format!("is free to move in {}", ["x", "y", "z"][c]))
                } else if nodes.len() < 2 {
                    Some("is held at one node only and free to rotate".to_string())
                } else {
                    None
                };
                if let Some(why) = why {
                    free_bodies.push(format!("body `{}` {why}", body.name));
                }
            }
            if free_bodies.is_empty() {
                "in a static analysis every body needs supports that stop its rigid motion".into()
            } else {
                format!(
                    "in a static analysis every body needs supports that stop its rigid motion, \
                     and {}",
                    free_bodies.join(", ")
                )
            }
        }
        Scheme::Dynamic { h, .. } => format!(
            "with h = {h:e} s the mass term 1/h² M is too small against the stiffness of an \
             unsupported body; use a smaller step or supports"
        ),
    }
}
