//! Backward Euler (Rothe) dynamics in displacement form, eq. (9) of the paper:
//!
//! `M (u_s − 2u_{s−1} + u_{s−2})/h² + C (u_s − u_{s−1})/h + f_int(u_s) = f_ext(t_s)`,
//! `C = (zeta + a_m) M + a_k K`, with `v_s = (u_s − u_{s−1})/h` carried as state so
//! `u_{−1} = u_0 − h v_0` holds for an initial velocity `v_0`.
//!
//! Every step goes through the equilibrium loop of [`crate::nonlinear`] with the
//! effective matrix `K_eff = (1/h² + (zeta+a_m)/h) M + (1 + a_k/h) K` (linear
//! elasticity; with history materials `a_k/h K + K_t`), factorised once while it does
//! not change. For linear elasticity and linear viscoelasticity the step is affine:
//! the residual at the start is predicted from the carried forces, one solve is
//! exact, and one evaluation (a fused `K Δu, M v` pass, or one Gauss-point pass)
//! confirms it and gives the new state. See `theory/scheme.md` and
//! `theory/energy.md`.

use super::implicit::Core;
use super::operators::{Rule, Scheme};
use super::{Integrator, SolverFacts, State, StepOutcome, Timing};
use crate::assembly::{Assembler, Mass};
use crate::error::Result;
use crate::linsolve::Backend;
use crate::model::Model;
use crate::system::{DofMap, EffectiveSystem};

/// The implicit dynamic integrator: backward Euler, or the trapezoidal rule when
/// `analysis.scheme` says so (the same matrices, loop, contact and ledger; only the
/// step's weights differ, [`Rule`]). Matrices, solver and scratch.
pub struct BackwardEuler<'m> {
    core: Core<'m>,
}

impl<'m> BackwardEuler<'m> {
    /// Assembles `K`, `M`, the effective matrix, analyses and factorises it.
    pub fn new(model: &'m Model, backend: Backend) -> Result<Self> {
        Self::with_memory_limit(model, backend, None)
    }

    /// [`BackwardEuler::new`], refusing a factor whose memory estimate exceeds
    /// `memory_limit` bytes before it is allocated.
    pub fn with_memory_limit(
        model: &'m Model,
        backend: Backend,
        memory_limit: Option<u64>,
    ) -> Result<Self> {
        let a = &model.analysis;
        let scheme = Scheme::Dynamic {
            h: a.time.dt,
            damp_m: a.damping.zeta + a.damping.rayleigh[0],
            damp_k: a.damping.rayleigh[1],
            rule: Rule::of(&a.time),
        };
        Ok(BackwardEuler {
            core: Core::new(model, backend, scheme, memory_limit)?,
        })
    }

    /// Solver backend name.
    pub fn backend(&self) -> &'static str {
        self.core.sys.backend()
    }

    /// Number of nonzeros of the Cholesky factor.
    pub fn factor_nnz(&self) -> Option<usize> {
        self.core.sys.factor_nnz()
    }

    /// Entries of the Cholesky factor on and below the diagonal.
    pub fn factor_lower_entries(&self) -> Option<usize> {
        self.core.sys.factor_lower_entries()
    }

    /// Numeric factorisations so far.
    pub fn factorizations(&self) -> usize {
        self.core.sys.factorizations()
    }

    /// The state at `t = 0`: prescribed displacements, bodies' initial velocities,
    /// history materials at rest.
    pub fn initial_state(&self) -> State {
        self.core.ops.initial_state(self.core.model)
    }

    /// The elastic stiffness on the shared pattern.
    pub fn stiffness(&self) -> &[f64] {
        &self.core.ops.k
    }

    /// The mass matrix.
    pub fn mass(&self) -> &Mass {
        &self.core.ops.mass
    }

    /// The assembler (pattern and colours).
    pub fn assembler(&self) -> &Assembler {
        &self.core.ops.asm
    }

    /// The free-dof numbering.
    pub fn dofs(&self) -> &DofMap {
        self.core.sys.dofs()
    }

    /// Relative residuals of the last step's equilibrium iterations, one per
    /// evaluation of the residual.
    pub fn residual_history(&self) -> &[f64] {
        self.core.scratch.history()
    }

    /// Time and counts of the contact correction, when the model has contact.
    pub fn contact_stats(&self) -> Option<crate::contact::implicit::ContactStats> {
        match &self.core.correction {
            super::implicit::Corrector::Contact(c) => Some(c.stats()),
            super::implicit::Corrector::Linear(_) => None,
        }
    }

    /// The effective system (matrix, factor, solves).
    pub fn system(&mut self) -> &mut EffectiveSystem {
        &mut self.core.sys
    }
}

impl Integrator for BackwardEuler<'_> {
    fn model(&self) -> &Model {
        self.core.model
    }

    fn h(&self) -> f64 {
        self.core.ops.h()
    }

    fn set_step(&mut self, h: f64) -> Result<()> {
        self.core.set_step(h)
    }

    fn initial_state(&mut self) -> Result<State> {
        Ok(BackwardEuler::initial_state(self))
    }

    fn step(&mut self, s: &mut State) -> Result<StepOutcome> {
        self.core.step(s)
    }

    fn timing(&self) -> Timing {
        self.core.timing()
    }

    fn output_points(&self, s: &State) -> Option<Vec<crate::material::store::StateStore>> {
        self.core.ops.output_points(self.core.model, s)
    }

    fn solver(&self) -> SolverFacts {
        self.core.solver()
    }
}
