//! External forces: loads scaled by their time functions, and gravity.

use crate::assembly::{Mass, Pattern};
use crate::model::Model;

/// External forces at time `t` (loads and gravity; reactions not included) into `f`.
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
pub fn gravity_force(model: &Model, mass: &Mass, pattern: &Pattern) -> Option<Vec<f64>> {
    model.gravity.map(|g| {
        let dim = model.mesh.dim;
        let field: Vec<f64> = (0..model.mesh.n_dofs()).map(|d| g[d % dim]).collect();
        let mut f = vec![0.0; field.len()];
        mass.matvec(pattern, &field, &mut f);
        f
    })
}
