//! The error-controlled march (`analysis.adaptive`, `theory/adaptive.md`): each
//! step is judged by the scheme's local error estimate after it converged and is
//! taken back (the state restored from a copy) when the estimate exceeds the
//! tolerance; the sizes are the ladder's rungs (`time::step_ladder`), and a step of
//! `2^j` bottom rungs starts only at a multiple of its own size, so the steps
//! nest, land on `t_end` and on the output times that are multiples of the bottom
//! rung, and each size's factor is found again (`EffectiveSystem::switch_factor`).
//! Impacts are events: a slave that would meet its master within the next step
//! shortens it, rung by rung, until the step that contains the first contact is a
//! bottom rung, and the following `impact_steps` steps stay there.

use super::local_error::Estimator;
use super::march::{non_finite, Marched};
use super::step_ladder::{Ladder, Verdict};
use super::{Integrator, Rejection, State, StepOutcome};
use crate::error::{Error, Result};
use crate::model::{Adaptive, TimeScheme};
use crate::nonlinear::Outcome;

/// What an error-controlled march needs besides the model's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AdaptiveControl {
    /// The ladder and the tolerance.
    pub settings: Adaptive,
    /// The first step's size (snapped to a rung).
    pub h_start: f64,
    /// End time.
    pub t_end: f64,
    /// Failed steps (not converged) in a row allowed before the run stops.
    pub max_cuts: usize,
    /// Times the steps land on: the multiples of this interval (VTK frames).
    pub land_every: Option<f64>,
}

impl AdaptiveControl {
    /// The control of `model`'s error-controlled steps (`None` for fixed steps).
    pub fn of(model: &crate::model::Model) -> Option<Self> {
        let a = &model.analysis;
        let settings = a.time.adaptive?;
        Some(AdaptiveControl {
            h_start: a.time.dt.min(settings.dt_max),
            settings,
            t_end: a.time.t_end,
            max_cuts: a.iteration.max_cuts,
            land_every: a.output.vtk_every_time,
        })
    }
}

/// What an error-controlled march did, filled as it goes.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct AdaptiveReport {
    /// Steps that stand.
    pub steps_accepted: usize,
    /// Steps taken back because their error exceeded the tolerance.
    pub steps_rejected: usize,
    /// Steps that did not converge and were retried smaller.
    pub steps_failed: usize,
    /// Steps that stand above the tolerance at the bottom rung (outside impacts).
    pub steps_at_floor: usize,
    /// Impacts landed on as events.
    pub impacts: usize,
    /// The smallest and the largest step that stands (s).
    pub dt_min_used: f64,
    /// See `dt_min_used`.
    pub dt_max_used: f64,
    /// The end of the first step in which a slave came into contact (s).
    pub first_impact_t: Option<f64>,
    /// The ladder's bottom rung (s).
    pub bottom_rung: f64,
}

impl AdaptiveReport {
    /// The warning a run gives when steps stood above the tolerance at the bottom
    /// rung.
    pub fn floor_warning(&self) -> Option<String> {
        (self.steps_at_floor > 0).then(|| {
            format!(
                "{} step(s) stood above analysis.adaptive.tolerance at the bottom rung \
                 {:.3e} s (outside impacts): lower analysis.adaptive.dt_min to meet the \
                 tolerance there",
                self.steps_at_floor, self.bottom_rung
            )
        })
    }
}

/// What an error-controlled run plans (`rothe check`): its ladder, the factors it
/// keeps, the bounds of its step count and its first impact from the initial motion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AdaptivePlan {
    /// The settings.
    pub settings: Adaptive,
    /// The bottom rung (s).
    pub bottom: f64,
    /// Rungs on the ladder.
    pub rungs: usize,
    /// Factors kept besides the current one.
    pub kept: usize,
    /// Steps if every step were the top rung, and if every step were the bottom.
    pub steps: (usize, usize),
    /// The first impact of a pair, every node moving at its initial velocity.
    pub first_impact: Option<f64>,
}

impl AdaptivePlan {
    /// The plan of `model`'s error-controlled steps (`None` for fixed steps).
    pub fn of(model: &crate::model::Model) -> Option<Self> {
        let a = model.analysis.time.adaptive?;
        let bottom = Ladder::new(a.dt_max, a.dt_min, a.tolerance, 1).dt_min;
        let t_end = model.analysis.time.t_end;
        let u0 = vec![0.0; model.mesh.n_dofs()];
        let v0 = model.initial_velocity();
        let contact = crate::contact::ContactState::initial(model, &u0);
        Some(AdaptivePlan {
            settings: a,
            bottom,
            rungs: a.rungs(),
            kept: a.kept_factors(),
            steps: (
                (t_end / a.dt_max).ceil() as usize,
                (t_end / bottom).ceil() as usize,
            ),
            first_impact: crate::contact::events::first_impact(model, &u0, &v0, t_end, &contact),
        })
    }
}

impl std::fmt::Display for AdaptivePlan {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "error-controlled, tolerance {:e} (energy norm); steps dt_max / 2^k from {:e} to \
             {:e} s ({} rung(s), {} factor(s) kept besides the current); between {} (all at \
             dt_max) and {} (all at the bottom) steps",
            self.settings.tolerance,
            self.settings.dt_max,
            self.bottom,
            self.rungs,
            self.kept,
            self.steps.0,
            self.steps.1
        )?;
        if let Some(t) = self.first_impact {
            write!(
                f,
                "; the first impact at about {t:.4e} s (the initial motion), then {} steps at \
                 the bottom",
                self.settings.impact_steps
            )?;
        }
        Ok(())
    }
}

/// The largest `j ≤ want` with a step of `2^j` ticks starting at tick `n` on a
/// multiple of its size and not longer than `room` ticks (`room ≥ 1`).
fn nested(n: u64, want: u32, room: u64) -> u32 {
    let mut j = want;
    while j > 0 && (!n.is_multiple_of(1u64 << j) || (1u64 << j) > room) {
        j -= 1;
    }
    j
}

/// The rung `j` (a step of `2^j` bottom rungs) of a size on the ladder.
fn level(ladder: &Ladder, bottom: u32, h: f64) -> u32 {
    bottom.saturating_sub(ladder.index(h))
}

/// Integrates `s` to `control.t_end` with error-controlled steps (see the module
/// docs). `observe` sees every step that stands, every step taken back and every
/// failed one retried smaller; `report` is current whenever `observe` is called
/// (so an observer may write it out) and when the march returns, also when it
/// fails part way, and `s` then holds the last step that stands.
pub fn march_adaptive<I, F>(
    integrator: &mut I,
    s: &mut State,
    control: AdaptiveControl,
    report: &std::cell::Cell<AdaptiveReport>,
    mut observe: F,
) -> Result<()>
where
    I: Integrator + ?Sized,
    F: FnMut(&I, &State, Marched) -> Result<()>,
{
    let mut current = report.get();
    let result = steps(integrator, s, control, &mut current, |i, s, m, r| {
        report.set(*r);
        observe(i, s, m)
    });
    report.set(current);
    result
}

/// [`march_adaptive`]'s loop, `observe` handed the report as it stands.
fn steps<I, F>(
    integrator: &mut I,
    s: &mut State,
    control: AdaptiveControl,
    report: &mut AdaptiveReport,
    mut observe: F,
) -> Result<()>
where
    I: Integrator + ?Sized,
    F: FnMut(&I, &State, Marched, &AdaptiveReport) -> Result<()>,
{
    let a = control.settings;
    let order = integrator.order().ok_or_else(|| {
        Error::Stepping(
            "the scheme has no local error estimate: error-controlled steps are the \
             implicit dynamic schemes'"
                .into(),
        )
    })?;
    let ladder = Ladder::new(a.dt_max, a.dt_min, a.tolerance, order);
    let tick = ladder.dt_min;
    report.bottom_rung = tick;
    let bottom = ladder.index(tick);
    let t0 = s.t;
    let ticks = |t: f64| ((t - t0) / tick * (1.0 + 1e-12)).floor() as u64;
    let end = ticks(control.t_end);
    // The trapezoidal rule's estimate needs a previous step: its first is the bottom.
    let trapezoidal = integrator.model().analysis.time.scheme == TimeScheme::Trapezoidal;
    let mut want = if trapezoidal {
        0
    } else {
        level(&ladder, bottom, ladder.rung(control.h_start))
    };
    // Output times on the ticks' grid: every `k` ticks.
    let landing = control
        .land_every
        .map(|e| (e, (e / tick).round() as u64))
        .filter(|&(every, k)| k > 0 && ((k as f64) * tick - every).abs() <= 1e-9 * every)
        .map(|(_, k)| k);
    // What is left of t_end beyond the last whole bottom rung: a step of its own would
    // be below the floor (a tenth of a nanosecond after a t_end of 0.0100000001 s),
    // so the step that lands on the last rung takes it along (judged as any other).
    let sliver = control.t_end - (t0 + end as f64 * tick) > 1e-9 * tick;
    let lands = |n: u64| landing.is_some_and(|k| n.is_multiple_of(k));
    let mut estimator = Estimator::default();
    let (mut n, mut hold, mut failed_in_row) = (0u64, 0usize, 0usize);
    let mut saved = s.clone();
    loop {
        // The room to the end, or to the next output time on the ticks' grid.
        let mut room = end.saturating_sub(n);
        if let Some(k) = landing {
            room = room.min(k - n % k);
        }
        let h = if room == 0 {
            // What is left of t_end below the bottom rung: one step, unjudged.
            let rest = control.t_end - s.t;
            if rest <= 1e-9 * tick {
                break;
            }
            rest
        } else {
            let mut j = nested(n, if hold > 0 { 0 } else { want }, room);
            let h = tick * (1u64 << j) as f64;
            if j > 0 {
                if let Some(th) = crate::contact::events::first_impact(
                    integrator.model(),
                    &s.u,
                    &s.v,
                    h,
                    &s.contact,
                ) {
                    // Land on the impact: the largest nested step short of it.
                    let jt = (th / tick).log2().floor().max(0.0) as u32;
                    j = nested(n, j.min(jt), room);
                }
            }
            tick * (1u64 << j) as f64
        };
        let on_ladder = room > 0;
        let rungs = (h / tick).round() as u64;
        let to_end = on_ladder && sliver && n + rungs == end && !lands(end);
        let h = if to_end { control.t_end - s.t } else { h };
        if (h - integrator.h()).abs() > 1e-12 * h {
            integrator.set_step(h)?;
        }
        saved.clone_from(s);
        match integrator.step(s)? {
            StepOutcome::Accepted(step) => {
                failed_in_row = 0;
                let eta = integrator.local_error(&saved, s, &mut estimator);
                let impact = crate::contact::events::impact_between(
                    &saved.contact,
                    &s.contact,
                    integrator.model().contacts.len(),
                );
                let at_bottom = h <= tick * (1.0 + 1e-12);
                let verdict = match eta {
                    _ if !on_ladder => Verdict::Accept { next: tick },
                    None => Verdict::Accept { next: h },
                    Some(eta) => ladder.judge(h, eta),
                };
                if let Verdict::Reject { retry } = verdict {
                    if !(impact && at_bottom) {
                        s.clone_from(&saved);
                        report.steps_rejected += 1;
                        want = level(&ladder, bottom, retry);
                        observe(
                            integrator,
                            s,
                            Marched::Rejected {
                                h,
                                eta: eta.unwrap_or(f64::NAN),
                                retry,
                            },
                            report,
                        )?;
                        continue;
                    }
                }
                estimator.commit();
                want = match verdict {
                    Verdict::Accept { next } if on_ladder => level(&ladder, bottom, next),
                    _ => 0,
                };
                if impact {
                    report.impacts += 1;
                    report.first_impact_t.get_or_insert(s.t);
                    hold = a.impact_steps;
                } else if hold > 0 {
                    hold -= 1;
                } else if verdict == Verdict::Floor {
                    report.steps_at_floor += 1;
                }
                if to_end {
                    n = end;
                    s.t = control.t_end;
                } else if on_ladder {
                    // The time on the ladder is a count of bottom rungs: no drift
                    // from summing the steps.
                    n += rungs;
                    s.t = t0 + n as f64 * tick;
                }
                report.steps_accepted += 1;
                if report.steps_accepted == 1 {
                    report.dt_min_used = h;
                    report.dt_max_used = h;
                } else {
                    report.dt_min_used = report.dt_min_used.min(h);
                    report.dt_max_used = report.dt_max_used.max(h);
                }
                observe(integrator, s, Marched::Step(&step), report)?;
            }
            StepOutcome::Rejected(Rejection {
                outcome:
                    Outcome::NonFinite {
                        quantity,
                        dof,
                        value,
                    },
                ..
            }) => return Err(non_finite(integrator, s, quantity, dof, value)),
            StepOutcome::Rejected(r) => {
                let j = level(&ladder, bottom, h);
                if j == 0 || !on_ladder || failed_in_row >= control.max_cuts {
                    return Err(Error::Stepping(format!(
                        "step {} (t = {:.6e}, h = {h:.3e}) failed{}: {}. Lower \
                         analysis.adaptive.dt_min, or see the message for the cause",
                        s.step + 1,
                        s.t + h,
                        if j == 0 {
                            " at the bottom rung of the ladder".to_string()
                        } else {
                            format!(" after {failed_in_row} smaller tries")
                        },
                        r.message
                    )));
                }
                failed_in_row += 1;
                report.steps_failed += 1;
                want = j - 1;
                observe(
                    integrator,
                    s,
                    Marched::Cut {
                        h: 0.5 * h,
                        reason: &r.message,
                    },
                    report,
                )?;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_nest_on_their_own_multiples() {
        // At tick 12 (= 4·3) a step of 8 would not start on a multiple of 8: 4.
        assert_eq!(nested(12, 3, 100), 2);
        assert_eq!(nested(16, 3, 100), 3);
        // Room for 5 ticks only: 4.
        assert_eq!(nested(16, 3, 5), 2);
        assert_eq!(nested(7, 5, 100), 0);
    }
}
