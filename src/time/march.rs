//! Adaptive step control for any [`Integrator`]: a step the equilibrium loop rejects
//! is halved and retried from the same state; after four accepted steps at a reduced
//! size the step doubles back, never beyond the requested one. A step whose data is
//! not finite (`Outcome::NonFinite`) stops the march at once: a smaller step would
//! not help.

use super::{Integrator, Rejection, State, StepOutcome, StepReport};
use crate::error::{Error, Result};
use crate::nonlinear::Outcome;

/// What [`march`] reports to its observer.
pub enum Marched<'a> {
    /// A step was accepted.
    Step(&'a StepReport),
    /// A step was rejected and `h` was halved.
    Cut {
        /// The new step size.
        h: f64,
        /// Why the step failed.
        reason: &'a str,
    },
    /// An error-controlled step converged but its error measure exceeded the
    /// tolerance: it was taken back, to be tried again at `retry`.
    Rejected {
        /// The step's size.
        h: f64,
        /// Its relative error measure.
        eta: f64,
        /// The size tried next.
        retry: f64,
    },
}

/// How [`march`] may change the step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepControl {
    /// The requested step (never exceeded).
    pub h: f64,
    /// End time.
    pub t_end: f64,
    /// Halvings allowed in a row before the run stops.
    pub max_cuts: usize,
    /// The smallest step a cut may reach; a step that would need a smaller one stops
    /// the run as stalled.
    pub h_min: f64,
}

impl StepControl {
    /// The model's requested step, end time and cut limit.
    pub fn of(model: &crate::model::Model) -> Self {
        let a = &model.analysis;
        StepControl {
            h: a.time.dt,
            t_end: a.time.t_end,
            max_cuts: a.iteration.max_cuts,
            h_min: a.iteration.dt_min,
        }
    }
}

/// Accepted steps at a reduced size before the step doubles back.
const EASY_STEPS_TO_GROW: usize = 4;

/// Integrates `s` to `control.t_end` (see the module docs). `observe` sees the
/// integrator (for its timings and solver facts), the state and every accepted step
/// and every cut; an error from it stops the march. On failure the error names the
/// step and time, and `s` holds the last accepted state.
pub fn march<I, F>(
    integrator: &mut I,
    s: &mut State,
    control: StepControl,
    mut observe: F,
) -> Result<()>
where
    I: Integrator + ?Sized,
    F: FnMut(&I, &State, Marched) -> Result<()>,
{
    let StepControl {
        h: h0,
        t_end,
        max_cuts,
        h_min,
    } = control;
    let mut h = h0;
    let (mut cuts_in_row, mut easy) = (0usize, 0usize);
    // Summing the steps leaves the time a few ulps from t_end (6000 steps of 5e-7
    // s end 1.2e-15 s short): what is left below a millionth of a step is that
    // drift, not a step to take (one of 1e-15 s would only test the solver).
    while s.t < t_end - 1e-6 * h0 {
        let h_try = h.min(t_end - s.t);
        if (h_try - integrator.h()).abs() > 1e-12 * h0 {
            integrator.set_step(h_try)?;
        }
        match integrator.step(s)? {
            StepOutcome::Accepted(report) => {
                observe(integrator, s, Marched::Step(&report))?;
                cuts_in_row = 0;
                if h < h0 {
                    easy += 1;
                    if easy >= EASY_STEPS_TO_GROW {
                        h = (2.0 * h).min(h0);
                        easy = 0;
                    }
                }
            }
            StepOutcome::Rejected(Rejection {
                outcome:
                    Outcome::NonFinite {
                        quantity,
                        dof,
                        value,
                    },
                ..
            }) => {
                // Not the iteration's fault: a smaller step would not help.
                return Err(non_finite(integrator, s, quantity, dof, value));
            }
            StepOutcome::Rejected(r) if 0.5 * h < h_min => {
                return Err(Error::Stepping(format!(
                    "step {} (t = {:.6e}) stalls: it would need a step below \
                     analysis.dt_min = {h_min:.3e} s ({:.1e} of dt; {} steps so far): {}. \
                     Try a smaller dt (load step); with iteration = \"fixed\" or a kept \
                     factor past a softening peak, iteration = \"newton\" and \
                     keep_factor = false",
                    s.step + 1,
                    s.t + integrator.h(),
                    h_min / h0,
                    s.step,
                    r.message
                )));
            }
            StepOutcome::Rejected(r) if cuts_in_row < max_cuts => {
                cuts_in_row += 1;
                easy = 0;
                h *= 0.5;
                observe(
                    integrator,
                    s,
                    Marched::Cut {
                        h,
                        reason: &r.message,
                    },
                )?;
            }
            StepOutcome::Rejected(r) => {
                return Err(Error::Stepping(format!(
                    "step {} (t = {:.6e}) failed after {cuts_in_row} step cuts: {}",
                    s.step + 1,
                    s.t + integrator.h(),
                    r.message
                )));
            }
        }
    }
    Ok(())
}

/// The error of a step whose data was not finite, located.
pub(crate) fn non_finite<I: Integrator + ?Sized>(
    integrator: &I,
    s: &State,
    quantity: &str,
    dof: Option<usize>,
    value: f64,
) -> Error {
    Error::NonFinite {
        quantity: quantity.to_string(),
        value,
        location: dof.map(|d| integrator.model().describe_dof(d)),
        t: s.t + integrator.h(),
    }
}

/// Takes `n` steps of the current `h` (no cuts; a rejected step is an error): for
/// benches and studies. Returns the number of corrections.
pub fn march_steps<I: Integrator + ?Sized>(
    integrator: &mut I,
    s: &mut State,
    n: usize,
) -> Result<usize> {
    let mut solves = 0;
    for _ in 0..n {
        solves += integrator.step_accepted(s)?.iterations;
    }
    Ok(solves)
}
