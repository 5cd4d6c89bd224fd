//! The one equilibrium loop every implicit step goes through.
//!
//! A step asks for `u_{n+1}` with `r(u_{n+1}) = 0`, where `r` is the step's residual
//! (for backward Euler `M(v − v_n)/h + C v + f_int(u) − f_ext`, for statics
//! `f_int(u) − f_ext`). Three parts meet here:
//! - a [`StepProblem`] gives the residual at a trial displacement from the committed
//!   state, and the tangent from the same Gauss-point pass when asked;
//! - a [`Correction`] turns the residual into a displacement change: one solve on the
//!   factor ([`LinearCorrection`]), or a constrained correction (contact) that also
//!   adds its constraint forces to the residual;
//! - a [`Convergence`] test on the residual, the last correction and the
//!   constraints' complementarity and active set.
//!
//! The loop's result is an [`Outcome`], not an error: converged, not converged (with
//! the residual history and the worst dof), the effective matrix not positive
//! definite (with the dof), a failed material update (with the point), or a failed
//! constraint solve. Step control (`time::march`) acts on it; `Error` is kept for
//! bad input and broken invariants.
//!
//! An affine problem (linear elasticity; linear viscoelasticity with its predicted
//! force) predicts its residual at the start without an evaluation, so the step costs
//! one solve and one evaluation that confirms it.

mod convergence;
mod correction;
mod free_dofs;

pub use convergence::{ConstraintStatus, Convergence};
pub use correction::{Corrected, Correction, LinearCorrection};

pub(crate) use free_dofs::{add_on_free, fill_free};

use crate::error::Result;
use crate::material::PointFailure;
use crate::system::{EffectiveSystem, Factored};

/// What an evaluation of the residual reports besides the residual itself.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Evaluation {
    /// `Σ (f_ext² + f_int² + inertia²)` over the free dofs: the scale of the relative
    /// residual.
    pub force_scale2: f64,
    /// `Σ (|f_ext| + |f_int| + |M v/h| + |M v_n/h| + |C v|)²` over all dofs (the
    /// reactions included): the size of the forces the residual is summed from, whose
    /// round-off bounds how small it can get ([`ROUNDOFF`]).
    pub magnitude2: f64,
    /// `|u − u_n|²` over the free dofs: the scale of the relative correction.
    pub increment2: f64,
    /// A tangent was assembled in the same pass ([`StepProblem::update_matrix`] can
    /// use it).
    pub tangent: bool,
    /// A material point whose update failed.
    pub failure: Option<PointFailure>,
    /// The evaluation kept the histories committed (a step's first estimate): it may
    /// start the iteration but never ends it.
    pub provisional: bool,
}

/// Relative round-off of a residual: an iterate whose residual is below `ROUNDOFF`
/// times the size of the terms it is summed from ([`Evaluation::magnitude2`]) is as
/// converged as double precision allows (a free flight at uniform velocity, a patch
/// test with no load on the free dofs), whatever its relative residual. Sums of a few
/// tens of products lose about `1e-14` of their terms' size; `1e-12` leaves a margin.
pub const ROUNDOFF: f64 = 1e-12;

/// Iterations on a kept factor its observed contraction may still need to reach the
/// tolerance before a refactorisation (and Newton's two or three iterations) pays.
pub const KEPT_ITERATIONS: i32 = 3;

/// The nonlinear problem of one step.
pub trait StepProblem {
    /// Whether one correction from the predicted residual is exact (affine problem
    /// with a constant, already factorised effective matrix).
    fn is_affine(&self) -> bool;
    /// Writes `−r(u)` at the start of the step on the free dofs (`free[eq]` the dof
    /// of equation `eq`) into `rhs` without evaluating the materials, and returns
    /// true; false when no exact prediction is at hand. An affine problem predicts
    /// its residual exactly for any step; a rate-independent one at an unchanged
    /// displacement, where its internal force is the committed one.
    fn predict(&mut self, u: &[f64], free: &[usize], rhs: &mut Vec<f64>) -> bool;
    /// Whether the evaluation of iteration `iteration` should assemble the tangent;
    /// `slow` says the last evaluation contracted the residual less than
    /// [`Convergence::refactor_rate`] asks of an iteration on a kept factor.
    fn wants_tangent(&mut self, iteration: usize, slow: bool) -> bool;
    /// Evaluates the residual at `u` (all dofs: on constrained dofs it is the reaction
    /// the supports must supply), with the tangent when `tangent`.
    fn evaluate(&mut self, u: &[f64], tangent: bool) -> Evaluation;
    /// The residual of the last evaluation or prediction.
    fn residual(&self) -> &[f64];
    /// The residual, for constraints to add their forces.
    fn residual_mut(&mut self) -> &mut [f64];
    /// Refills and refactorises the effective matrix with the last evaluation's
    /// tangent.
    fn update_matrix(&mut self, sys: &mut EffectiveSystem) -> Result<Factored>;

    /// Adds the correction `delta` (one entry per free dof, `free[eq]` its dof) to
    /// the iterate `u` and returns `|delta|²`. A problem that keeps quantities of the
    /// iterate (the increment `u − u_n`) updates them here in the same pass.
    fn apply_correction(&mut self, u: &mut [f64], free: &[usize], delta: &[f64]) -> f64 {
        add_on_free(free, delta, u, None)
    }
}

/// How the equilibrium loop ended.
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    /// The residual, the last correction and the constraints met the test.
    Converged {
        /// Corrections taken (linear solves or constrained solves).
        iterations: usize,
        /// Final relative residual.
        residual: f64,
    },
    /// The iteration limit was reached or the residual stopped being finite.
    NotConverged {
        /// Corrections taken.
        iterations: usize,
        /// Relative residual at each evaluation.
        history: Vec<f64>,
        /// The free dof with the largest residual and that residual (N).
        worst: Option<(usize, f64)>,
        /// What the constraints reported at the last evaluation.
        constraints: ConstraintStatus,
    },
    /// The effective matrix lost positive definiteness.
    NotPositiveDefinite {
        /// The dof whose column broke down, when known.
        dof: Option<usize>,
        /// The solver's message.
        message: String,
    },
    /// A material update found no admissible state.
    MaterialFailure(PointFailure),
    /// A constrained correction failed (e.g. the contact QP).
    ConstraintFailure(String),
    /// The residual of the start of the step (or of an affine problem) is not a
    /// finite number: the data of the step, not the iteration, is at fault, and a
    /// smaller step would not help.
    NonFinite {
        /// The quantity found non-finite first (the loop reports `residual`; the
        /// integrator names the vector it came from).
        quantity: &'static str,
        /// The dof where it was found.
        dof: Option<usize>,
        /// The value (NaN or an infinity).
        value: f64,
    },
}

impl Outcome {
    /// Whether the step converged.
    pub fn converged(&self) -> bool {
        matches!(self, Outcome::Converged { .. })
    }
}

/// Buffers the loop reuses from step to step (nothing is allocated per iteration).
#[derive(Clone, Debug, Default)]
pub struct Scratch {
    /// Right-hand side `−r` and then the correction, on the free dofs.
    rhs: Vec<f64>,
    /// Relative residual of each evaluation.
    history: Vec<f64>,
}

impl Scratch {
    /// Buffers for `n_free` equations and up to `max_iterations` iterations.
    pub fn new(n_free: usize, max_iterations: usize) -> Self {
        Scratch {
            rhs: Vec::with_capacity(n_free),
            history: Vec::with_capacity(max_iterations + 1),
        }
    }

    /// Relative residuals of the last solve, one per evaluation.
    pub fn history(&self) -> &[f64] {
        &self.history
    }
}

fn relative(r2: f64, scale2: f64) -> f64 {
    if scale2 > 0.0 {
        (r2 / scale2).sqrt()
    } else {
        r2.sqrt()
    }
}

/// Gathers `−r` on the free dofs into `rhs`; returns `Σ r²` and the free dof with
/// the largest `|r|` (the first of equal ones; the last NaN if there is one).
fn gather(r: &[f64], free: &[usize], rhs: &mut Vec<f64>) -> (f64, Option<(usize, f64)>) {
    /// Whether `b` (later) takes the place of `a` as the worst residual.
    fn worse(a: Option<(usize, f64)>, b: (usize, f64)) -> bool {
        a.is_none_or(|a| b.1.abs() > a.1.abs() || b.1.is_nan())
    }
    fill_free(
        free,
        rhs,
        |d| -r[d],
        (0.0, None),
        |(r2, worst), d, minus_x| {
            let x = -minus_x;
            (
                r2 + x * x,
                if worse(worst, (d, x)) {
                    Some((d, x))
                } else {
                    worst
                },
            )
        },
        |(a2, a), (b2, b)| (a2 + b2, if b.is_some_and(|b| worse(a, b)) { b } else { a }),
    )
}

/// Iterates `u` to equilibrium: see the module docs. On any outcome but
/// [`Outcome::Converged`] `u` holds the last iterate, which the caller discards.
pub fn solve<P, C>(
    problem: &mut P,
    correction: &mut C,
    sys: &mut EffectiveSystem,
    test: &Convergence,
    u: &mut [f64],
    scratch: &mut Scratch,
) -> Result<Outcome>
where
    P: StepProblem + ?Sized,
    C: Correction + ?Sized,
{
    scratch.history.clear();
    let affine = problem.is_affine();
    let mut iterations = 0;
    let mut last_correction: Option<f64> = None;
    let mut predicted = problem.predict(u, &sys.dofs().free, &mut scratch.rhs);
    // The first iterate of a predicted start comes from the data and the factor
    // alone, as an affine step's does.
    let predicted_start = predicted;
    // The last evaluation's `Σ r²`, and whether the iterations on the kept factor
    // contracted the residual too slowly.
    let mut previous: Option<f64> = None;
    let mut slow = false;
    // Whether the last evaluation met the test but for a change of the active set.
    let mut met_before = false;
    loop {
        if !predicted {
            let want = problem.wants_tangent(iterations, slow);
            let ev = problem.evaluate(u, want);
            if let Some(f) = ev.failure {
                return Ok(Outcome::MaterialFailure(f));
            }
            let constraints = correction.constrain(u, problem.residual_mut());
            let (r2, worst) = gather(problem.residual(), &sys.dofs().free, &mut scratch.rhs);
            let nl = relative(r2, ev.force_scale2);
            if scratch.history.len() < scratch.history.capacity() {
                scratch.history.push(nl);
            }
            let small_correction = affine
                || last_correction
                    .is_none_or(|c| c <= test.displacement_tolerance * ev.increment2.sqrt());
            let finite = nl.is_finite() && ev.magnitude2.is_finite() && ev.increment2.is_finite();
            if !finite && (iterations == 0 || affine || (predicted_start && iterations == 1)) {
                // Nothing an iteration did: the loads, the state or the materials.
                let (dof, value) = match worst {
                    Some((d, r)) if !r.is_finite() => (Some(d), r),
                    _ => (None, if nl.is_finite() { f64::INFINITY } else { nl }),
                };
                return Ok(Outcome::NonFinite {
                    quantity: "residual",
                    dof,
                    value,
                });
            }
            let at_roundoff = r2 <= ROUNDOFF * ROUNDOFF * ev.magnitude2;
            // An active set that still changes while the residual is at its
            // round-off floor, or stays within the tolerance across the change,
            // changes only by constraints whose gap and force are both within the
            // tolerances (checked here): the iterate meets equilibrium, no
            // penetration and complementarity as well as the solves can (the
            // residual's round-off, the contact QP's accuracy), and another
            // iteration would only flip them back (theory/equilibrium.md).
            let met = finite
                && !ev.provisional
                && ((nl <= test.tolerance && small_correction) || at_roundoff)
                && test.constraints_hold_at_floor(&constraints);
            let settled = test.constraints_hold(&constraints) || at_roundoff || met_before;
            met_before = met;
            if met && settled {
                return Ok(Outcome::Converged {
                    iterations,
                    residual: nl,
                });
            }
            if iterations >= test.max_iterations || !finite {
                return Ok(Outcome::NotConverged {
                    iterations,
                    history: scratch.history.clone(),
                    worst,
                    constraints,
                });
            }
            // The contraction of the residual itself: its relative value can stay
            // near 1 when the forces it is measured against vanish with it
            // (displacement control in statics).
            if let (Some(rate), Some(before)) = (test.refactor_rate, previous) {
                let rho = (r2 / before).sqrt();
                let projected = nl * rho.powi(KEPT_ITERATIONS);
                slow = !ev.tangent && (rho > rate || projected > test.tolerance);
            }
            previous = Some(r2);
            if ev.tangent {
                if let Factored::NotPositiveDefinite { dof, message } =
                    problem.update_matrix(sys)?
                {
                    return Ok(Outcome::NotPositiveDefinite { dof, message });
                }
            }
        }
        predicted = false;
        if let Corrected::Failed(why) = correction.correct(sys, u, &mut scratch.rhs)? {
            return Ok(Outcome::ConstraintFailure(why));
        }
        let c2 = problem.apply_correction(u, &sys.dofs().free, &scratch.rhs);
        last_correction = Some(c2.sqrt());
        iterations += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sequential rule `gather` keeps on the pool: the first of the largest
    /// `|r|`, unless there is a NaN, then the last NaN.
    fn worst_in_order(r: &[f64], free: &[usize]) -> Option<(usize, f64)> {
        let mut worst: Option<(usize, f64)> = None;
        for &d in free {
            let x = r[d];
            if worst.is_none_or(|w| x.abs() > w.1.abs() || x.is_nan()) {
                worst = Some((d, x));
            }
        }
        worst
    }

    #[test]
    fn the_gather_names_the_worst_dof_as_one_pass_in_order_would() {
        let n = 9 * crate::halves::VECTOR_LEAF + 5;
        let free: Vec<usize> = (0..n).filter(|d| d % 5 != 2).collect();
        let base: Vec<f64> = (0..n).map(|d| ((d * 7919) % 1000) as f64 * 1e-3).collect();
        let cases: [&[(usize, f64)]; 4] = [
            &[],
            // Equal peaks in different pieces: the first one counts.
            &[
                (3 * crate::halves::VECTOR_LEAF + 1, -7.0),
                (8 * crate::halves::VECTOR_LEAF, 7.0),
            ],
            // A NaN beats every number; of two NaNs the later one counts.
            &[(100, f64::NAN), (6 * crate::halves::VECTOR_LEAF + 3, 9.0)],
            &[
                (100, f64::NAN),
                (5 * crate::halves::VECTOR_LEAF + 4, f64::NAN),
                (n - 1, 1e9),
            ],
        ];
        for changes in cases {
            let mut r = base.clone();
            for &(d, x) in changes {
                r[d] = x;
            }
            let mut rhs = Vec::new();
            let (r2, worst) = gather(&r, &free, &mut rhs);
            let expected = worst_in_order(&r, &free);
            assert_eq!(
                worst.map(|w| (w.0, w.1.to_bits())),
                expected.map(|w| (w.0, w.1.to_bits())),
                "{changes:?}"
            );
            let rhs_expected: Vec<f64> = free.iter().map(|&d| -r[d]).collect();
            assert_eq!(
                rhs.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                rhs_expected.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
            );
            let r2_seq: f64 = free.iter().map(|&d| r[d] * r[d]).sum();
            if r2_seq.is_nan() {
                assert!(r2.is_nan());
            } else {
                assert!((r2 - r2_seq).abs() <= 1e-12 * r2_seq, "{r2} vs {r2_seq}");
            }
        }
    }
}
