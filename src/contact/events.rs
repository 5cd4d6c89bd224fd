//! Impacts as events of an error-controlled run (`theory/adaptive.md`): the first
//! time within the next step at which a slave of a pair that is not in contact
//! meets its master, every node moving at its velocity, as the explicit path's
//! sweep finds it (`MasterSurface::impact`). A pair in contact has no events: what
//! its slaves do is the step's contact problem, its accuracy the error estimate's.

use super::master::{rigid::EdgeHistory, surface, Positions};
use super::{ContactState, Slave};
use crate::model::Model;

/// The earliest time in `(0, h]` at which a slave of a pair with no contact in
/// `state` meets its master, from the displacements `u` and velocities `v`; `None`
/// when none does. A slave touching its master already (a hit at time 0) is the
/// step's contact problem, no event.
pub fn first_impact(
    model: &Model,
    u: &[f64],
    v: &[f64],
    h: f64,
    state: &ContactState,
) -> Option<f64> {
    if model.contacts.is_empty() || h.is_nan() || h <= 0.0 {
        return None;
    }
    let dim = model.mesh.dim;
    let x = super::positions(model, u);
    let (x, v) = (Positions::new(&x, dim), Positions::new(v, dim));
    let none = EdgeHistory::default();
    let mut first: Option<f64> = None;
    for (pi, pair) in model.contacts.iter().enumerate() {
        if touching(state, pi) {
            continue;
        }
        for (si, side) in pair.sides.iter().enumerate() {
            let master = surface(side, x);
            for &node in &side.slaves {
                let slave = Slave::new(pi, si, node);
                if let Some(hit) = master.impact(slave, v, h, pair.radius, &none) {
                    if hit.t > 0.0 && first.is_none_or(|t| hit.t < t) {
                        first = Some(hit.t);
                    }
                }
            }
        }
    }
    first
}

/// Whether the pair `pair` has a slave in contact in `state`.
pub fn touching(state: &ContactState, pair: usize) -> bool {
    state.active.iter().any(|(k, _)| k.slave.pair == pair)
}

/// Whether some pair came into contact between `before` and `after` (none of its
/// slaves touching before, one at least after): an impact.
pub fn impact_between(before: &ContactState, after: &ContactState, pairs: usize) -> bool {
    (0..pairs).any(|p| !touching(before, p) && touching(after, p))
}
