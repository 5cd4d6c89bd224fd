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

/// Accepted steps in a row below the requested size after which a run whose rest
/// would take more than [`STALL_FACTOR`] times its planned step count at their mean
/// size stops as stalled: it crawls at its floor (theory/equilibrium.md).
const STALL_STRETCH: usize = 1000;

/// How many times its planned step count a crawling run may project before it is
/// stopped as stalled.
const STALL_FACTOR: f64 = 100.0;

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
    // The stretch of accepted steps below h0: their count and summed size, and why
    // the last step before it was cut.
    let (mut stretch, mut stretch_time) = (0usize, 0.0f64);
    let mut last_cut = String::new();
    let planned = (t_end / h0).ceil().max(1.0);
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
                if h_try < h0 * (1.0 - 1e-9) && s.t < t_end - 1e-6 * h0 {
                    stretch += 1;
                    stretch_time += h_try;
                    if stretch >= STALL_STRETCH {
                        let mean = stretch_time / stretch as f64;
                        let projected = (t_end - s.t) / mean;
                        if projected > STALL_FACTOR * planned {
                            return Err(Error::Stepping(format!(
                                "stalled at step {} (t = {:.6e} of {t_end:.6e}): the last \
                                 {stretch} steps averaged h = {mean:.3e} s ({:.1e} of dt) \
                                 and the rest would take {projected:.2e} more steps, over \
                                 {STALL_FACTOR}x the {planned} planned; the steps keep \
                                 failing: {last_cut}. Try a smaller dt (load step) or, past \
                                 a softening peak, nonlocal damage or dynamics",
                                s.step,
                                s.t,
                                mean / h0,
                            )));
                        }
                    }
                } else {
                    (stretch, stretch_time) = (0, 0.0);
                }
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
                last_cut.clone_from(&r.message);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::time::{SolverFacts, Timing};

    /// A static elastic bar whose steps converge only below `limit`: a run that
    /// can only crawl.
    struct Crawling<'m> {
        inner: crate::time::statics::Statics<'m>,
        limit: f64,
    }

    impl Integrator for Crawling<'_> {
        fn model(&self) -> &crate::model::Model {
            self.inner.model()
        }
        fn h(&self) -> f64 {
            self.inner.h()
        }
        fn set_step(&mut self, h: f64) -> Result<()> {
            self.inner.set_step(h)
        }
        fn initial_state(&mut self) -> Result<State> {
            Integrator::initial_state(&mut self.inner)
        }
        fn step(&mut self, s: &mut State) -> Result<StepOutcome> {
            if self.inner.h() > self.limit {
                return Ok(StepOutcome::Rejected(Rejection {
                    outcome: Outcome::NotConverged {
                        iterations: 30,
                        history: vec![1.0; 31],
                        worst: None,
                        constraints: Default::default(),
                    },
                    message: "no convergence (a step above the crawl's limit)".into(),
                }));
            }
            self.inner.step(s)
        }
        fn timing(&self) -> Timing {
            self.inner.timing()
        }
        fn solver(&self) -> SolverFacts {
            self.inner.solver()
        }
    }

    fn bar() -> crate::model::Model {
        crate::config::from_str(
            "[analysis]\nkind = \"static\"\nt_end = 1.0\ndt = 0.01\nvtk_every = 0\n\
             dt_min = 1e-12\nmax_cuts = 40\n\
             [materials.steel]\nmodel = \"elastic\"\nE = 210e9\nnu = 0.3\nrho = 7850.0\n\
             [[bodies]]\nname = \"bar\"\nmaterial = \"steel\"\nthickness = 0.1\n\
             mesh = { kind = \"rectangle\", size = [1.0, 0.1], divisions = [4, 1] }\n\
             [[supports]]\nset = \"bar.left\"\nfix = [\"x\", \"y\"]\n\
             [[prescribed]]\nset = \"bar.right\"\ncomponent = \"x\"\nvalue = 1e-4\n\
             function = { kind = \"ramp\", t0 = 0.0, t1 = 1.0 }\n",
            std::path::Path::new("."),
        )
        .unwrap()
    }

    fn run(limit: f64) -> (Result<()>, State) {
        let model = bar();
        let mut i = Crawling {
            inner: crate::time::statics::Statics::new(&model, crate::linsolve::Backend::Faer)
                .unwrap(),
            limit,
        };
        let mut s = Integrator::initial_state(&mut i).unwrap();
        let r = march(&mut i, &mut s, StepControl::of(&model), |_, _, _| Ok(()));
        (r, s)
    }

    #[test]
    fn a_run_that_crawls_at_its_floor_stops_as_stalled() {
        // Steps converge only below 1e-7 of the load: the rest would take 1e7 steps
        // against 100 planned. The run stops after the stretch, naming why.
        let (r, s) = run(1e-9);
        let e = r.unwrap_err().to_string();
        assert!(
            e.contains("stalled") && e.contains("above the crawl's limit"),
            "{e}"
        );
        assert!(s.step < 2 * STALL_STRETCH, "{} steps", s.step);
        // A run held at a quarter of its step for the whole way is slow, not
        // stalled: 400 steps, 4x the plan, and it completes.
        let (r, s) = run(0.0026);
        r.unwrap();
        assert!((s.t - 1.0).abs() < 1e-9 && s.step > 300, "{} steps", s.step);
    }
}
