//! Static equilibrium `f_int(u) = f_ext(t)` at load steps `t = dt, 2 dt, ..., t_end`,
//! with prescribed displacements: the same equilibrium loop and effective-system
//! machinery as the dynamics, without inertia. Materials with history evolve over the
//! load steps (rates use `dt`), so a static run is quasi-static: linear elasticity
//! takes one solve per step, damage and plasticity iterate.

use super::implicit::{Implicit, Quasistatic};
use super::Integrator;
use crate::error::{Error, Result};
use crate::linsolve::Backend;
use crate::model::Model;

/// Static equilibrium integrator.
pub type Statics<'m> = Implicit<'m, Quasistatic>;

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
