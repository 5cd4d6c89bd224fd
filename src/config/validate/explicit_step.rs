//! The explicit path's step: its default and the refusal of a step above the
//! stable one (`time::cfl`, `modal::exact_stable_step`, `theory/explicit.md`).

use super::step_count;
use crate::config::LoadOptions;
use crate::error::{Error, Result};
use crate::model::{CriticalStepRule, Model};

/// Central differences: the step defaults to `ω` times the paper's critical step
/// `L_e/c` (never above `ω` times the stable step); a given step above the stable
/// step `min_e 2/ω_e` is refused (unless `allow_unstable`), naming the limit and the
/// element that sets it (`time::cfl`, `theory/explicit.md`). With
/// `critical_step = "eigen"` the stable step is the mesh's own (`modal::exact_stable_step`)
/// and the default step `ω` times it.
pub(super) fn explicit_step(model: &mut Model, dt: Option<f64>, opts: &LoadOptions) -> Result<()> {
    let (Some(paper), Some(stable)) = (
        crate::time::cfl::critical_step(model),
        crate::time::cfl::stable_step(model),
    ) else {
        return Err(Error::config(
            "bodies",
            "no element to set the critical step",
        ));
    };
    let eigen = match model.analysis.time.critical_step {
        CriticalStepRule::Eigen => Some(
            crate::modal::exact_stable_step(model)
                .map_err(|e| Error::config("analysis.critical_step", e.to_string()))?,
        ),
        CriticalStepRule::Element => None,
    };
    let where_ = model.describe_point(stable.block, stable.element);
    let a = &mut model.analysis;
    let (limit, what) = match eigen {
        Some(e) => (
            e.dt,
            format!(
                "the mesh's own limit 2/(√(ω_max² + c²/4) + c/2), ω_max = {:.6e} rad/s, \
                 c = {:.6e} 1/s (critical_step = \"eigen\"); the element bound is {:.6e} s",
                e.omega_max, e.damping_rate, stable.dt
            ),
        ),
        None => (stable.dt, format!("2/ω_max of {where_}")),
    };
    a.time.stable_dt = Some(limit);
    match dt {
        None => {
            a.time.dt = a.time.omega
                * match eigen {
                    Some(e) => e.dt,
                    None => paper.dt.min(stable.dt),
                };
            step_count("analysis.dt", a.time.t_end, a.time.dt)?;
        }
        Some(h) if h > limit && !opts.allow_unstable => {
            return Err(Error::config(
                "analysis.dt",
                format!(
                    "{h:?} s exceeds the stable step {limit:.6e} s of central differences \
                     ({what}; the paper's estimate L_e/c is {:.6e} s); omit dt for omega x \
                     the estimate, or run with --allow-unstable for a stability study",
                    paper.dt
                ),
            ));
        }
        Some(_) => {}
    }
    // Equal steps under prescribed motion: central differences carry the half-step
    // velocity of a prescribed dof from one step to the next, so a shortened last
    // step would prescribe it over the wrong interval and the ledger would miss
    // (theory/explicit.md). The step is lowered (never raised: stability) until it
    // divides t_end.
    // Supports (value 0) have no half-step velocity to break.
    let (t_end, h) = (model.analysis.time.t_end, model.analysis.time.dt);
    let n = (t_end / h * (1.0 - 1e-9)).ceil().max(1.0);
    let even = t_end / n;
    let moving = model.constraints.iter().any(|c| c.value != 0.0);
    if moving && h - even > 1e-9 * h {
        if dt.is_some() {
            model.warnings.push(format!(
                "analysis.dt = {h:?} s does not divide t_end = {t_end:?} s; central \
                 differences take {n} equal steps of {even:.6e} s instead (a shortened \
                 last step would break the prescribed motion's half-step velocities)"
            ));
        }
        model.analysis.time.dt = even;
    }
    Ok(())
}
