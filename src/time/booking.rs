//! The booking of a converged implicit step: its ledger line (the work of the
//! loads and reactions, the kinetic and stored energy, the materials' dissipation,
//! the scheme's own loss, what contact and the predictor took) and the swap that
//! makes the iterate the new state. `theory/energy.md`, `theory/trapezoidal.md`.

use super::operators::{Operators, Response, Rule};
use super::step_problem::Scratch;
use super::State;
use crate::energy::{Dissipation, StepIncrements, StepWork};
use crate::system::DofMap;

/// Books the converged step and makes it the state. The last evaluation summed the
/// step's ledger terms with the applied loads; the reactions (the residual on the
/// constrained dofs) are added here, with their part of the work terms.
pub(crate) fn finish(
    ops: &Operators,
    dofs: &DofMap,
    w: &mut Scratch,
    s: &mut State,
    t1: f64,
    (contact, friction): (f64, f64),
    predictor: f64,
) {
    let mut sums = w.ledger_sums;
    let trapezoidal = ops.rule() == Rule::Trapezoidal;
    // The residual on a constrained dof is the reaction the step's equation needs:
    // at the end (backward Euler), or in the average ½(R_n + R_{n+1}) (trapezoidal).
    let end_weight = 1.0 / ops.rule().theta();
    for &d in &dofs.constrained {
        let reaction = end_weight * w.r[d];
        w.f_ext_np1[d] += reaction;
        // External work and load jump are linear in f_ext,n+1.
        sums.work[1] += w.du[d] * reaction;
        sums.work[2] += w.du[d] * reaction;
    }
    let work = StepWork::from_sums(sums.work);
    let alpha_f = match ops.rule() {
        Rule::GeneralizedAlpha(a) => Some(a.alpha_f),
        _ => None,
    };
    let (elastic_energy, mut material) = if ops.response == Response::Elastic {
        (
            ops.stored.of(&w.u_np1, &w.f_int_np1),
            Dissipation {
                numerical: match (trapezoidal, alpha_f) {
                    (true, _) => 0.0,
                    // Δu·f_int,n+1−α_f = ΔE_el + (1 − 2α_f) ½Δu·KΔu.
                    (_, Some(af)) => (1.0 - 2.0 * af) * sums.elastic_loss,
                    _ => sums.elastic_loss,
                },
                ..Default::default()
            },
        )
    } else {
        (w.totals.psi, w.totals.dissipation)
    };
    // The trapezoidal rule works with ½Δu·(f_int,n + f_int,n+1) where the points book
    // σ_{n+1}:Δε (their algorithmic loss is backward Euler's), and with the averaged
    // loads, so the load jump is no loss of it (theory/trapezoidal.md). Generalized-α
    // weighs the start by α_f: 2α_f of the jumps, and its inertia's own loss.
    let scheme_loss = if trapezoidal {
        if ops.response != Response::Elastic {
            material.numerical -= sums.internal_jump;
        }
        work.load_jump
    } else if let Some(af) = alpha_f {
        if ops.response != Response::Elastic {
            material.numerical -= 2.0 * af * sums.internal_jump;
        }
        sums.scheme_loss + 2.0 * af * work.load_jump
    } else {
        sums.scheme_loss
    };
    if let Rule::GeneralizedAlpha(a) = ops.rule() {
        // a_{n+1} from v_{n+1} = v_n + h((1 − γ) a_n + γ a_{n+1}).
        let h = ops.h();
        let g = a.gamma;
        w.a_np1.clear();
        w.a_np1.extend(
            w.v_np1
                .iter()
                .zip(&s.v)
                .zip(&s.a)
                .map(|((v1, v0), a0)| (v1 - v0 - h * (1.0 - g) * a0) / (h * g)),
        );
        std::mem::swap(&mut s.a, &mut w.a_np1);
    }
    s.ledger.record(&StepIncrements {
        kinetic: sums.kinetic,
        elastic: elastic_energy,
        work,
        material,
        scheme_loss,
        contact,
        friction,
        predictor,
    });
    std::mem::swap(&mut s.u, &mut w.u_np1);
    std::mem::swap(&mut s.f_int, &mut w.f_int_np1);
    std::mem::swap(&mut s.f_ext, &mut w.f_ext_np1);
    if ops.dynamic().is_some() {
        std::mem::swap(&mut s.v, &mut w.v_np1);
        std::mem::swap(&mut s.mv, &mut w.mv_np1);
    }
    if ops.response == Response::Nodal {
        std::mem::swap(&mut s.nodal, &mut w.nodal);
    } else {
        if !w.f_pred_np1.is_empty() {
            std::mem::swap(&mut s.f_pred, &mut w.f_pred_np1);
            s.f_pred_h = ops.h();
        }
        s.points.iter_mut().for_each(|p| p.commit());
    }
    s.t = t1;
    s.step += 1;
}
