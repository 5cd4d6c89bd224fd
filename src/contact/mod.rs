//! Contact: detection (geometry only) apart from enforcement.
//!
//! - [`master`] holds the master surfaces (segment chains, rigid lines, face sets,
//!   rigid planes) behind one interface, [`master::MasterSurface`]: a slave's rows
//!   within reach, its row after crossing the master over a step, its first impact
//!   within a step. [`detect`] is the one loop over pairs, sides and slaves that
//!   asks it, in the plane and in a solid, giving rows of one shape
//!   ([`rows::Candidate`]); [`mortar`] gives a mortar side's weighted gaps.
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
pub mod events;
pub mod implicit;
pub mod kinematic;
pub mod master;
pub mod mortar;
pub mod overlap;
mod qp;
pub mod rows;
pub mod state;

pub use implicit::ContactCorrection;
pub use master::Positions;
pub use rows::{gap_matrix, Candidate, Contactee};
pub use state::{ContactState, Key, PairRecord, Slave, Target};

/// The node positions `X + u` of a model at displacements `u` (all dofs), flat.
pub fn positions(model: &crate::model::Model, u: &[f64]) -> Vec<f64> {
    let dim = model.mesh.dim;
    model
        .mesh
        .coords
        .iter()
        .enumerate()
        .flat_map(|(n, c)| (0..dim).map(move |i| c[i] + u[dim * n + i]))
        .collect()
}

/// The candidates of every pair at displacements `u` (all dofs), with no history of
/// the rigid lines ([`detect::detect`]).
pub fn candidates(model: &crate::model::Model, u: &[f64], out: &mut Vec<Candidate>) {
    let x = positions(model, u);
    detect::detect(
        &model.contacts,
        Positions::new(&x, model.mesh.dim),
        &Default::default(),
        None,
        out,
    );
}

/// The tributary area (length × thickness) of every node as a slave, for contact
/// pressures: half of every element edge joining two slave nodes of a side. In a
/// solid, the share of the slave faces' areas (a third of a triangle, a quarter of a
/// quadrilateral: the integrals of its shape functions over a parallelogram); zero
/// on a slave node set, which has no faces.
pub fn tributary_areas(model: &crate::model::Model) -> Vec<f64> {
    use crate::geometry::{cross, distance, norm, sub};
    let mesh = &model.mesh;
    let mut area = vec![0.0; mesh.n_nodes()];
    if mesh.dim == 3 {
        for side in model.contacts.iter().flat_map(|p| &p.sides) {
            let crate::model::SlaveSurface::Faces(faces) = &side.surface else {
                continue;
            };
            for f in faces {
                let c = f.corners();
                let x = |k: usize| mesh.coords[c[k % c.len()]];
                // Half the cross product of the diagonals (of two edges for a
                // triangle).
                let (p, q) = if c.len() == 3 {
                    (sub(x(1), x(0)), sub(x(2), x(0)))
                } else {
                    (sub(x(2), x(0)), sub(x(3), x(1)))
                };
                let a = 0.5 * norm(cross(p, q));
                for &v in c {
                    area[v] += a / c.len() as f64;
                }
            }
        }
        return area;
    }
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
                            let l = distance(mesh.xy(p), mesh.xy(q));
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
