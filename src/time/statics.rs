//! Static equilibrium `f_int(u) = f_ext(t)` at load steps `t = dt, 2 dt, ..., t_end`,
//! with prescribed displacements: the same equilibrium loop and effective-system
//! machinery as the dynamics, without inertia. Materials with history evolve over the
//! load steps (rates use `dt`), so a static run is quasi-static: linear elasticity
//! takes one solve per step, damage and plasticity iterate.

use super::implicit::{Core, Scheme};
use super::{Integrator, SolverFacts, State, StepOutcome, Timing};
use crate::error::{Error, Result};
use crate::linsolve::Backend;
use crate::model::Model;

/// Static equilibrium integrator.
pub struct Statics<'m> {
    core: Core<'m>,
}

impl<'m> Statics<'m> {
    /// Assembles `K`, analyses and factorises it (an unsupported body is an error
    /// that says so).
    pub fn new(model: &'m Model, backend: Backend) -> Result<Self> {
        Self::with_memory_limit(model, backend, None)
    }

    /// [`Statics::new`], refusing a factor whose memory estimate exceeds
    /// `memory_limit` bytes before it is allocated.
    pub fn with_memory_limit(
        model: &'m Model,
        backend: Backend,
        memory_limit: Option<u64>,
    ) -> Result<Self> {
        let scheme = Scheme::Static {
            dt: model.analysis.dt,
        };
        Ok(Statics {
            core: Core::new(model, backend, scheme, memory_limit)?,
        })
    }

    /// The unloaded state at `t = 0` with the prescribed displacements of `t = 0`.
    pub fn initial_state(&self) -> State {
        self.core.ops.initial_state(self.core.model)
    }
}

impl Integrator for Statics<'_> {
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
        Ok(Statics::initial_state(self))
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

/// A static solution.
#[derive(Clone, Debug)]
pub struct StaticSolution {
    /// Time (load level).
    pub t: f64,
    /// Displacements.
    pub u: Vec<f64>,
    /// Internal forces (equal to the external forces plus reactions).
    pub fint: Vec<f64>,
    /// Stored energy.
    pub elastic: f64,
}

/// Solves the static problem of `model` at the non-decreasing times `times`, one load
/// step from each to the next, starting unloaded at `t = 0`.
pub fn solve(model: &Model, backend: Backend, times: &[f64]) -> Result<Vec<StaticSolution>> {
    let mut st = Statics::new(model, backend)?;
    let mut s = st.initial_state();
    let mut out = Vec::with_capacity(times.len());
    for &t in times {
        let h = t - s.t;
        if h < 0.0 || !h.is_finite() {
            return Err(Error::config(
                "times",
                format!("static load times must not decrease, got {t} after {}", s.t),
            ));
        }
        // A repeated time is a zero load step: equilibrium at the same loads.
        st.set_step(h.max(f64::MIN_POSITIVE))?;
        st.step_accepted(&mut s)?;
        s.t = t;
        out.push(StaticSolution {
            t,
            u: s.u.clone(),
            fint: s.f_int.clone(),
            elastic: s.ledger.elastic(),
        });
    }
    Ok(out)
}
