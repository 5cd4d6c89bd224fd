//! Time integration: backward Euler (Rothe) dynamics and static equilibrium, the
//! free-dof system they solve, and the explicit critical step estimate.
//!
//! Start with [`backward_euler::BackwardEuler`]: it owns the matrices, the solver and
//! scratch; the state ([`backward_euler::DynState`]) lives outside it, so a step can
//! be repeated or cut back by copying the state.

pub mod backward_euler;
pub mod cfl;
pub mod statics;
pub mod system;

use crate::model::Model;

/// Wall-clock time spent per phase, in seconds.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct Timing {
    /// Pattern, colouring and matrix assembly.
    pub assembly_s: f64,
    /// Symbolic analysis and numeric factorisations.
    pub factorization_s: f64,
    /// Triangular solves.
    pub solve_s: f64,
    /// Everything else inside steps (matrix-vector products, ledger).
    pub step_other_s: f64,
}

/// External forces at time `t` (loads and gravity; reactions not included).
pub fn external_force(model: &Model, gravity: Option<&[f64]>, t: f64, f: &mut [f64]) {
    match gravity {
        Some(g) => f.copy_from_slice(g),
        None => f.fill(0.0),
    }
    for load in &model.loads {
        let s = load.function.at(t);
        if s != 0.0 {
            for &(d, v) in &load.entries {
                f[d] += s * v;
            }
        }
    }
}

/// Gravity force `M g` (exact for a constant acceleration field), if any.
pub fn gravity_force(
    model: &Model,
    mass: &crate::assembly::Mass,
    pattern: &crate::assembly::Pattern,
) -> Option<Vec<f64>> {
    model.gravity.map(|g| {
        let field: Vec<f64> = (0..model.mesh.n_dofs()).map(|d| g[d % 2]).collect();
        let mut f = vec![0.0; field.len()];
        mass.matvec(pattern, &field, &mut f);
        f
    })
}
