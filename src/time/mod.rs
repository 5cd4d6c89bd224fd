//! Time integration: the integrator interface, the state it advances, backward Euler
//! (Rothe) dynamics, static equilibrium, adaptive step control and the explicit
//! critical step estimate.
//!
//! An [`Integrator`] owns its matrices, solver and scratch; the [`State`] lives
//! outside it, so a step can be repeated or cut back by copying the state, and
//! [`march::march`] drives any integrator to the end time with step cuts. Start with
//! [`backward_euler::BackwardEuler`] ([`Implicit`]); its step equation goes through the one
//! equilibrium loop of [`crate::nonlinear`].

pub mod adaptive;
pub mod backward_euler;
mod booking;
pub mod central_difference;
pub mod cfl;
mod diagnostics;
mod export;
pub mod forces;
pub(crate) mod generalized_alpha;
mod implicit;
mod kept_factor;
pub mod local_error;
pub mod march;
mod modified_energy;
pub mod nodal;
mod operators;
mod predictor;
mod residual;
mod seat;
pub mod step_ladder;
mod step_problem;
mod step_start;
pub use export::first_matrices;
pub use implicit::{Dynamic, Implicit, ImplicitKind, Quasistatic};
pub mod statics;

use crate::energy::Ledger;
use crate::error::{Error, Result};
use crate::material::store::StateStore;
use crate::model::Model;
use crate::nonlinear::Outcome;

/// The state of a run after a step: what a step reads and writes, and what the
/// output records.
#[derive(Clone, Debug)]
pub struct State {
    /// Time.
    pub t: f64,
    /// Steps taken.
    pub step: usize,
    /// Displacements `u_n`.
    pub u: Vec<f64>,
    /// Velocities (backward Euler: `(u_n − u_{n−1})/h`; statics: zero).
    pub v: Vec<f64>,
    /// `M v`.
    pub mv: Vec<f64>,
    /// Accelerations `a_n` (central differences; empty for the implicit schemes).
    pub a: Vec<f64>,
    /// Internal forces `f_int(u_n)`.
    pub f_int: Vec<f64>,
    /// External forces including support reactions.
    pub f_ext: Vec<f64>,
    /// Energy ledger.
    pub ledger: Ledger,
    /// Gauss-point states per element block (empty when every material is linear
    /// elastic and the step runs on global matrices only).
    pub points: Vec<StateStore>,
    /// Internal force of the next step at unchanged displacement (constant-tangent
    /// materials with history; empty otherwise): `f_int(u) = f_pred + K_t (u − u_n)`.
    pub f_pred: Vec<f64>,
    /// The step size `f_pred` was predicted for.
    pub f_pred_h: f64,
    /// The contact state (multipliers, per-pair forces, gaps and pressures).
    pub contact: crate::contact::ContactState,
    /// Nodal fields of linear viscoelastic materials (empty unless the implicit
    /// schemes keep them there; then `points` is empty and the integrator builds
    /// the Gauss-point state for output, `Integrator::output_points`).
    pub nodal: nodal::NodalState,
    /// Generalized-α's `M⁻¹r` of the state, `r` its out-of-balance
    /// (`time::modified_energy`); empty for the other schemes.
    pub m_inv_r: Vec<f64>,
    /// Generalized-α's `M a_n`, kept from the booking of the step that made `a_n`
    /// for the next step's start (`time::step_start::history`); empty when not
    /// kept (then that start forms it). Whatever sets `a` empties it.
    pub ma: Vec<f64>,
}

/// What an accepted step reports besides the new state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepReport {
    /// Corrections (linear or constrained solves) taken.
    pub iterations: usize,
    /// Relative residual `sqrt(Σ r² / Σ (f_ext² + f_int² + (M a)²))` over the free
    /// dofs at the end of the step.
    pub nl_residual: f64,
}

/// A step that did not converge: the loop's outcome and a message locating it.
#[derive(Clone, Debug, PartialEq)]
pub struct Rejection {
    /// How the equilibrium loop ended.
    pub outcome: Outcome,
    /// What failed and where (node, coordinates, body, element).
    pub message: String,
}

/// What a step gave.
#[derive(Clone, Debug, PartialEq)]
pub enum StepOutcome {
    /// The state was advanced.
    Accepted(StepReport),
    /// The state is unchanged; step control may cut the step.
    Rejected(Rejection),
}

/// Wall-clock time spent per phase, in seconds.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct Timing {
    /// Pattern, colouring and matrix assembly.
    pub assembly_s: f64,
    /// Symbolic analysis and numeric factorisations.
    pub factorization_s: f64,
    /// Triangular solves.
    pub solve_s: f64,
    /// Everything else inside steps (material passes, matrix-vector products, ledger).
    pub step_other_s: f64,
}

/// Facts about an integrator's linear solver.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SolverFacts {
    /// Backend name.
    pub backend: &'static str,
    /// Numeric factorisations so far.
    pub factorizations: usize,
    /// Iterations that kept the factor because the tangent had not changed.
    pub reused_factors: usize,
    /// Steps redone refactorising at every changed tangent after the iterations on a
    /// kept factor failed.
    pub fallbacks: usize,
    /// Generalized-α's steps that changed which slaves are held, taken by the
    /// trapezoidal rule (`theory/trapezoidal.md`, "Impact steps").
    pub impact_steps: usize,
    /// Impact steps whose trapezoidal step did not converge, taken by
    /// generalized-α instead.
    pub impact_fallbacks: usize,
    /// Nonzeros of the factor.
    pub factor_nnz: Option<usize>,
}

/// A time scheme: advances a [`State`] it does not own by steps of a size it can
/// change.
pub trait Integrator {
    /// The model being integrated.
    fn model(&self) -> &Model;
    /// The current step size.
    fn h(&self) -> f64;
    /// Changes the step size (refactorising what depends on it).
    fn set_step(&mut self, h: f64) -> Result<()>;
    /// The state at `t = 0`.
    fn initial_state(&mut self) -> Result<State>;
    /// Advances `s` by one step `h`; on [`StepOutcome::Rejected`] `s` is unchanged.
    fn step(&mut self, s: &mut State) -> Result<StepOutcome>;
    /// Time per phase so far.
    fn timing(&self) -> Timing;
    /// The linear solver's facts.
    fn solver(&self) -> SolverFacts;
    /// The Gauss-point state of `s` for output when `s.points` does not hold it
    /// (state kept in nodal fields); `None` otherwise.
    fn output_points(&self, s: &State) -> Option<Vec<StateStore>> {
        let _ = s;
        None
    }

    /// The scheme's order `p` (its local error goes as `h^(p+1)`), when it has an
    /// error estimate for [`Integrator::local_error`]; `None` otherwise.
    fn order(&self) -> Option<u32> {
        None
    }

    /// The relative local error measure `η` of the step just taken from `before` to
    /// `after` (`theory/adaptive.md`), `estimator` carrying what the estimate needs
    /// of earlier steps; `None` when the scheme has no estimate, or none yet.
    fn local_error(
        &mut self,
        before: &State,
        after: &State,
        estimator: &mut local_error::Estimator,
    ) -> Option<f64> {
        let _ = (before, after, estimator);
        None
    }

    /// [`Integrator::step`] for callers that treat a rejected step as an error
    /// (tests, benches, fixed-step studies).
    fn step_accepted(&mut self, s: &mut State) -> Result<StepReport> {
        match self.step(s)? {
            StepOutcome::Accepted(r) => Ok(r),
            StepOutcome::Rejected(r) => Err(Error::Stepping(r.message)),
        }
    }
}

/// Dot product.
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
