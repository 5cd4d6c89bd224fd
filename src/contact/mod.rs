//! Contact: detection (geometry only) apart from enforcement.
//!
//! - [`detect`] finds, for the current geometry, the candidate constraints of every
//!   contact pair: slave node, closest master segment (or rigid line), `ξ`, gap and
//!   normal, as plain data ([`rows::Candidate`]), with an R-tree (`rstar`) over the
//!   master segments as the broad phase.
//! - [`implicit`] enforces impenetrability in the implicit schemes: per step a convex
//!   QP (solved with Clarabel) inside the equilibrium loop, as a
//!   [`crate::nonlinear::Correction`], condensed on the factor by default.
//! - [`kinematic`] enforces it in the explicit path: the paper's kinematic method
//!   (collision times from [`collision`], momentum-conserving impact impulses,
//!   friction interpolation, the weighted position update).
//!
//! The theory (the QP and its KKT conditions, the condensed dual, the
//! re-linearisation, the energy of an implicit impact) is in `theory/contact.md`.

pub mod collision;
mod compliance;
pub(crate) mod coulomb;
pub mod detect;
pub mod implicit;
pub mod kinematic;
pub mod mortar;
mod qp;
pub mod rows;
pub mod state;
pub mod sweep;

pub use implicit::ContactCorrection;
pub use rows::{gap_matrix, Candidate, Contactee};
pub use state::{ContactState, PairRecord};

/// The tributary area (length × thickness) of every node as a slave, for contact
/// pressures: half of every element edge joining two slave nodes of a side.
pub fn tributary_areas(model: &crate::model::Model) -> Vec<f64> {
    let mesh = &model.mesh;
    let mut area = vec![0.0; mesh.n_nodes()];
    for pair in &model.contacts {
        for side in &pair.sides {
            let mut is_slave = vec![false; mesh.n_nodes()];
            for &s in &side.slaves {
                is_slave[s] = true;
            }
            let mut seen = std::collections::BTreeSet::new();
            for b in &mesh.blocks {
                let t = model.bodies[b.body].thickness;
                for e in 0..b.elements.len() {
                    let nodes = b.elements.element(e);
                    for k in 0..nodes.len() {
                        let (p, q) = (nodes[k], nodes[(k + 1) % nodes.len()]);
                        if is_slave[p] && is_slave[q] && seen.insert((p.min(q), p.max(q))) {
                            let (xp, xq) = (mesh.coords[p], mesh.coords[q]);
                            let l = ((xp[0] - xq[0]).powi(2) + (xp[1] - xq[1]).powi(2)).sqrt();
                            area[p] += 0.5 * l * t;
                            area[q] += 0.5 * l * t;
                        }
                    }
                }
            }
        }
    }
    area
}
