//! `rothe study tolerance`: an error-controlled scenario at a sequence of
//! tolerances, beside fixed-step runs of the same scheme at the ladder's rungs and
//! a fixed-step reference, so that the error each reaches is read against the
//! steps it took (`theory/adaptive.md`).
//!
//! Every run records its fields. An error-controlled run's states lie on the
//! ladder's bottom rung, a fixed run's on its own step: both on the reference's
//! grid when the reference step divides them, and the errors of their
//! piecewise-linear interpolants are those of the time study
//! (`time_study::errors`, `L∞(0,T; L2)` and `L2(0,T; H1)`). Besides the norms: the
//! peak deflection of the first probe, the duration of the first pair's contact
//! and the final kinetic and stored energies, each relative to the reference's.

use std::path::Path;

use super::plan::{Plan, PlannedRun, StudyKind};
use super::run_data::RunData;
use super::table::{num, Table};
use super::time_study::REFERENCE_ID;
use crate::config::{load_with_overrides, LoadOptions, Overrides};
use crate::error::{Error, Result};
use crate::plot::{draw, Figure, Series, Style};

/// Fixed-step runs beside the tolerances, by default: the top rung and 6 halvings.
pub const DEFAULT_FIXED_HALVINGS: usize = 6;

/// The plan: one run per tolerance (`tol{i}`), fixed-step runs at
/// `dt_max / 2^k`, `k = 0..=fixed_halvings` (`fixed{k}`, the scenario's
/// `analysis.adaptive` removed), and the reference at `reference_dt` (default:
/// the ladder's bottom rung).
pub fn plan(
    scenario: &Path,
    base: &Overrides,
    tolerances: &[f64],
    fixed_halvings: usize,
    reference_dt: Option<f64>,
) -> Result<Plan> {
    let scenario = super::plan::absolute(scenario)?;
    let model = load_with_overrides(&scenario, &LoadOptions::default(), base)?;
    let Some(a) = model.analysis.time.adaptive else {
        return Err(Error::config(
            "analysis.adaptive",
            "a tolerance study varies analysis.adaptive.tolerance, and the scenario has \
             fixed steps: give analysis.adaptive (e.g. --set analysis.adaptive.dt_max=1e-5)",
        ));
    };
    if tolerances.is_empty() || tolerances.len() > super::plan::MAX_SIZES {
        return Err(Error::config(
            "--tolerances",
            format!(
                "give 1 to {} tolerances, got {}",
                super::plan::MAX_SIZES,
                tolerances.len()
            ),
        ));
    }
    if let Some(t) = tolerances
        .iter()
        .find(|t| !(t.is_finite() && **t > 0.0 && **t < 1.0))
    {
        return Err(Error::config(
            "--tolerances",
            format!("{t}: a tolerance lies in (0, 1)"),
        ));
    }
    if fixed_halvings > super::time_study::MAX_HALVINGS {
        return Err(Error::config(
            "--fixed-halvings",
            format!(
                "{fixed_halvings}: at most {}",
                super::time_study::MAX_HALVINGS
            ),
        ));
    }
    let bottom = crate::time::step_ladder::Ladder::new(a.dt_max, a.dt_min, a.tolerance, 1).dt_min;
    let h_ref = reference_dt.unwrap_or(bottom);
    if !(h_ref.is_finite() && h_ref > 0.0) || (bottom / h_ref).fract().abs() > 1e-9 {
        return Err(Error::config(
            "--reference-dt",
            format!(
                "{h_ref:e} s must divide the ladder's bottom rung {bottom:e} s, so that every \
                 state of the studied runs is a state of the reference"
            ),
        ));
    }
    let set = |k: &str| Overrides::none().set(k).expect("k=v");
    let fixed_base = without_adaptive(&scenario, base)?;
    let fixed = |id: String, h: f64, label: String| PlannedRun {
        id,
        scenario: scenario.clone(),
        overrides: fixed_base.then(&set(&format!("analysis.dt={h:e}"))),
        param: h,
        label,
        record_fields: true,
    };
    let mut runs: Vec<PlannedRun> = tolerances
        .iter()
        .enumerate()
        .map(|(i, &tol)| PlannedRun {
            id: format!("tol{i}"),
            scenario: scenario.clone(),
            overrides: base.then(&set(&format!("analysis.adaptive.tolerance={tol:e}"))),
            param: tol,
            label: format!("tolerance {tol:.0e}"),
            record_fields: true,
        })
        .collect();
    for k in 0..=fixed_halvings {
        let h = a.dt_max / f64::powi(2.0, k as i32);
        runs.push(fixed(
            format!("fixed{k}"),
            h,
            format!("fixed h = {h:.3e} s"),
        ));
    }
    runs.push(fixed(
        REFERENCE_ID.into(),
        h_ref,
        format!("reference, h = {h_ref:.3e} s"),
    ));
    Ok(Plan {
        kind: StudyKind::Tolerance,
        runs,
    })
}

/// `base` without error-controlled steps: its `--set analysis.adaptive.*` dropped,
/// and the scenario's own `analysis.adaptive` unset when it has one.
fn without_adaptive(scenario: &Path, base: &Overrides) -> Result<Overrides> {
    let mut stripped = base.clone();
    stripped
        .sets
        .retain(|(path, _)| !path.starts_with("analysis.adaptive"));
    let unset = stripped.clone().unset("analysis.adaptive");
    for o in [unset, stripped] {
        if let Ok(m) = load_with_overrides(scenario, &LoadOptions::default(), &o) {
            if m.analysis.time.adaptive.is_none() {
                return Ok(o);
            }
        }
    }
    Err(Error::config(
        "analysis.adaptive",
        "the fixed-step runs could not be made from the scenario without it",
    ))
}

/// The quantities of a run the study compares with the reference's.
#[derive(Clone, Copy, Debug)]
struct Quantities {
    peak: f64,
    duration: f64,
    kinetic: f64,
    elastic: f64,
}

fn quantities(r: &RunData) -> Quantities {
    let probe = r.probes().into_iter().next();
    let pair_force = r
        .history
        .as_ref()
        .and_then(|h| h.columns.iter().find(|n| n.ends_with("_force")).cloned());
    let t = r.column("t");
    let duration = pair_force.map_or(f64::NAN, |c| {
        let f = r.column(&c);
        let on: Vec<f64> = t
            .iter()
            .zip(&f)
            .filter(|(_, f)| f.abs() > 0.0)
            .map(|(t, _)| *t)
            .collect();
        match (on.first(), on.last()) {
            (Some(a), Some(b)) => b - a,
            _ => 0.0,
        }
    });
    let last = |c: &str| r.column(c).last().copied().unwrap_or(f64::NAN);
    Quantities {
        peak: probe.map_or(f64::NAN, |p| r.probe_min(&p).abs()),
        duration,
        kinetic: last("E_kin"),
        elastic: last("E_el"),
    }
}

/// The fewest steps of a fixed-step run whose error is at most `e`
/// (`Ok(steps)`), or, when none reaches it, `Err(most)`: the most steps any fixed
/// run took, a lower bound. The fixed runs' errors need not fall monotonically
/// (contact makes them erratic), so no curve is fitted through them.
fn fixed_steps_for(e: f64, fixed: &[(f64, f64)]) -> std::result::Result<f64, f64> {
    fixed
        .iter()
        .filter(|(_, fe)| *fe <= e)
        .map(|(s, _)| *s)
        .reduce(f64::min)
        .ok_or_else(|| fixed.iter().map(|(s, _)| *s).fold(0.0, f64::max))
}

/// Tables, plot and summary of a collected tolerance study.
pub fn collect(dir: &Path, runs: &[RunData]) -> Result<String> {
    let Some(reference) = runs
        .iter()
        .find(|r| r.run.id == REFERENCE_ID && r.completed())
    else {
        return Err(Error::Stepping(
            "the tolerance study's reference run did not complete".into(),
        ));
    };
    let done: Vec<&RunData> = runs
        .iter()
        .filter(|r| r.completed() && r.run.id != REFERENCE_ID)
        .collect();
    let (_, errs) = super::time_study::against_reference(reference, &done)?;
    let q_ref = quantities(reference);
    let rel = |a: f64, b: f64| ((a - b) / b).abs();
    let mut table = Table::new(&[
        "run",
        "tolerance",
        "h",
        "steps",
        "rejected",
        "seconds",
        "err_linear_Linf_L2",
        "err_linear_L2_H1",
        "peak_rel_err",
        "contact_duration_rel_err",
        "E_kin_rel_err",
        "E_el_rel_err",
    ]);
    let mut adaptive: Vec<(f64, f64, f64)> = Vec::new();
    let mut fixed: Vec<(f64, f64)> = Vec::new();
    for (r, e) in done.iter().zip(&errs) {
        let q = quantities(r);
        let steps = r.number("/steps").unwrap_or(f64::NAN);
        let is_fixed = r.run.id.starts_with("fixed");
        if is_fixed {
            fixed.push((steps, e.linear_l2_h1));
        } else {
            adaptive.push((r.run.param, steps, e.linear_l2_h1));
        }
        table.push(vec![
            r.run.id.clone(),
            if is_fixed {
                "-".into()
            } else {
                format!("{:e}", r.run.param)
            },
            if is_fixed {
                format!("{:e}", r.run.param)
            } else {
                "-".into()
            },
            num(Some(steps)),
            num(r.number("/steps_rejected")),
            num(Some(r.seconds())),
            num(Some(e.linear_linf_l2)),
            num(Some(e.linear_l2_h1)),
            num(Some(rel(q.peak, q_ref.peak))),
            num(Some(rel(q.duration, q_ref.duration))),
            num(Some(rel(q.kinetic, q_ref.kinetic))),
            num(Some(rel(q.elastic, q_ref.elastic))),
        ]);
    }
    table.write_csv(&dir.join("study.csv"))?;
    fixed.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut fig = Figure::new(
        "Error against steps: error-controlled and fixed",
        "steps",
        "error of the piecewise-linear interpolant, L2(0,T;H1)",
    )
    .log_log();
    let xy = |v: Vec<(f64, f64)>| v.into_iter().filter(|(s, e)| *s > 0.0 && *e > 0.0);
    fig = fig.with(Series::new(
        "error-controlled",
        xy(adaptive.iter().map(|&(_, s, e)| (s, e)).collect()).collect(),
        Style::LineWithMarkers,
    ));
    fig = fig.with(Series::new(
        "fixed steps",
        xy(fixed.clone()).collect(),
        Style::LineWithMarkers,
    ));
    draw(&fig, &dir.join("plots").join("efficiency"))?;
    let mut gains = Table::new(&[
        "tolerance",
        "steps",
        "L2H1 error",
        "fixed steps for that error",
        "ratio",
    ]);
    for &(tol, steps, e) in &adaptive {
        let (f, ratio) = match fixed_steps_for(e, &fixed) {
            Ok(f) => (num(Some(f)), num(Some(f / steps))),
            Err(most) => (
                format!("> {}", num(Some(most))),
                format!("> {}", num(Some(most / steps))),
            ),
        };
        gains.push(vec![
            format!("{tol:.0e}"),
            num(Some(steps)),
            num(Some(e)),
            f,
            ratio,
        ]);
    }
    let mut md = format!(
        "# Tolerance study: {}\n\nReference: fixed steps of {:e} s. Errors of the \
         piecewise-linear interpolants against the reference's; relative errors of the \
         first probe's peak deflection, the first pair's contact duration and the final \
         energies. Table: `study.csv`; plot: `plots/efficiency.png`.\n\n",
        reference.run.scenario.display(),
        reference.run.param
    );
    md.push_str(&table.markdown());
    md.push_str(
        "\nThe fewest steps of a fixed-step run whose error is at most each \
         tolerance's (`>`: no fixed run reached it; the most steps any took):\n\n",
    );
    md.push_str(&gains.markdown());
    md.push_str("\n![efficiency](plots/efficiency.png)\n");
    Ok(md)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fewest_fixed_steps_that_reach_an_error() {
        // Erratic errors: 750 steps reach 2e-5 though 1500 do not.
        let fixed = [
            (375.0, 3e-5),
            (750.0, 1.5e-5),
            (1500.0, 2.3e-5),
            (3000.0, 8e-6),
        ];
        assert_eq!(fixed_steps_for(2e-5, &fixed), Ok(750.0));
        assert_eq!(fixed_steps_for(8e-6, &fixed), Ok(3000.0));
        assert_eq!(fixed_steps_for(1e-6, &fixed), Err(3000.0));
    }
}
