//! `analysis.adaptive` (error-controlled steps) and `analysis.vtk_every_time`
//! (`theory/adaptive.md`).

use super::checks::positive;
use crate::config::AnalysisSpec;
use crate::error::{Error, Result};
use crate::model::{Adaptive, AnalysisKind, Model, TimeScheme};

/// The default bottom of the ladder, relative to its top: ten halvings.
const DEFAULT_RUNGS_BELOW: i32 = 10;

/// The error-controlled steps `a` asks for, checked: `None` for fixed steps.
pub(super) fn adaptive(a: &AnalysisSpec) -> Result<Option<Adaptive>> {
    let Some(spec) = &a.adaptive else {
        return Ok(None);
    };
    if a.kind == AnalysisKind::Static {
        return Err(Error::config(
            "analysis.adaptive",
            "a static analysis has no time error to control: its load steps are dt, cut \
             back where a step fails; remove the key",
        ));
    }
    if a.scheme == TimeScheme::CentralDifference {
        return Err(Error::config(
            "analysis.adaptive",
            "central differences step at a fraction of the critical step, which bounds them \
             more tightly than any error estimate would; error-controlled steps are the \
             implicit schemes' (backward_euler, trapezoidal, generalized_alpha); remove the key",
        ));
    }
    if !(spec.tolerance.is_finite() && spec.tolerance > 0.0 && spec.tolerance < 1.0) {
        return Err(Error::config(
            "analysis.adaptive.tolerance",
            format!(
                "{:?}: the largest relative error measure of a step lies in (0, 1) \
                 (1e-4: a step's error carries a ten-thousandth of the energy's square root)",
                spec.tolerance
            ),
        ));
    }
    let dt_max = match (spec.dt_max, a.dt) {
        (Some(m), _) => m,
        (None, Some(dt)) => dt,
        (None, None) => {
            return Err(Error::config(
                "analysis.adaptive.dt_max",
                "missing, and so is analysis.dt it defaults to: give the largest step",
            ))
        }
    };
    positive("analysis.adaptive.dt_max", dt_max)?;
    if dt_max > a.t_end {
        return Err(Error::config(
            "analysis.adaptive.dt_max",
            format!("{dt_max:?} s exceeds t_end = {:?} s", a.t_end),
        ));
    }
    if let Some(dt) = a.dt.filter(|&dt| dt > dt_max * (1.0 + 1e-12)) {
        return Err(Error::config(
            "analysis.dt",
            format!(
                "the first step {dt:?} s exceeds analysis.adaptive.dt_max = {dt_max:?} s, \
                 the largest step the run may take"
            ),
        ));
    }
    let dt_min = spec
        .dt_min
        .unwrap_or(dt_max * 2f64.powi(-DEFAULT_RUNGS_BELOW));
    positive("analysis.adaptive.dt_min", dt_min)?;
    if dt_min > dt_max {
        return Err(Error::config(
            "analysis.adaptive.dt_min",
            format!("{dt_min:?} s exceeds dt_max = {dt_max:?} s: the ladder would be empty"),
        ));
    }
    if a.t_end / dt_min > 2f64.powi(53) {
        return Err(Error::config(
            "analysis.adaptive.dt_min",
            format!(
                "t_end / dt_min = {:e} steps does not fit a step counter; is dt_min in seconds?",
                a.t_end / dt_min
            ),
        ));
    }
    Ok(Some(Adaptive {
        tolerance: spec.tolerance,
        dt_max,
        dt_min,
        norm: spec.norm,
        impact_steps: spec.impact_steps,
    }))
}

/// `analysis.vtk_every_time`, checked.
pub(super) fn vtk_every_time(a: &AnalysisSpec) -> Result<Option<f64>> {
    let Some(every) = a.vtk_every_time else {
        return Ok(None);
    };
    positive("analysis.vtk_every_time", every)?;
    if every > a.t_end {
        return Err(Error::config(
            "analysis.vtk_every_time",
            format!(
                "{every:?} s exceeds t_end = {:?} s: no frame but the first would be written",
                a.t_end
            ),
        ));
    }
    Ok(Some(every))
}

/// Warns when the bottom rung of an error-controlled run with contact is above the
/// step an impact needs: the time a stress wave takes to cross the smallest
/// element (`L_e/c`, the CFL step), below which the implicit step resolves the
/// wave the impact sends (`theory/adaptive.md`).
pub(super) fn impact_warning(model: &mut Model) {
    let Some(a) = model.analysis.time.adaptive else {
        return;
    };
    if model.contacts.is_empty() {
        return;
    }
    let Some(c) = crate::time::cfl::critical_step(model) else {
        return;
    };
    let bottom = crate::time::step_ladder::Ladder::new(a.dt_max, a.dt_min, a.tolerance, 1).dt_min;
    if bottom > c.dt {
        model.warnings.push(format!(
            "analysis.adaptive.dt_min: the bottom rung {bottom:.3e} s is above {:.3e} s, the \
             time a stress wave takes to cross the smallest element (L_e/c, block {}, \
             element {}): impacts land on steps too long to resolve the wave they send; \
             lower dt_min",
            c.dt, c.block, c.element
        ));
    }
}
