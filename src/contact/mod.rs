//! Contact: detection (geometry only) apart from enforcement.
//!
//! - [`detect`] finds, for the current geometry, the candidate constraints of every
//!   contact pair: slave node, closest master segment (or rigid line), `ξ`, gap and
//!   normal, as plain data ([`detect::Candidate`]), with an R-tree (`rstar`) over the
//!   master segments as the broad phase.
//! - [`implicit`] enforces impenetrability in the implicit schemes: per step a convex
//!   QP (solved with Clarabel) inside the equilibrium loop, as a
//!   [`crate::nonlinear::Correction`], condensed on the factor by default.
//!
//! The theory (the QP and its KKT conditions, the condensed dual, the
//! re-linearisation, the energy of an implicit impact) is in `theory/contact.md`.

mod compliance;
pub mod detect;
pub mod implicit;
mod qp;

pub use detect::{gap_matrix, Candidate, Contactee};
pub use implicit::{ContactCorrection, ContactState, PairRecord};
