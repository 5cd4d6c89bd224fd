//! Mortar gap rows: one weighted gap per slave node, in the plane (segment to
//! segment, [`segments`]) and in a solid (face to face over clipped overlaps,
//! [`faces`]).
//!
//! For slave node `j` with the linear (bilinear) shape function `N_j` of the slave
//! surface, the weighted gap is
//!
//! `g̃_j = ∫ N_j n_j · (x_m(η(ξ)) − x_s(ξ)) dA = n_j · (Σ_l M_jl x_l − Σ_k D_jk x_k)`
//!
//! up to its sign convention below, with `D_jk = ∫ N_j N_k dA` over the slave nodes
//! `k` and `M_jl = ∫ N_j N̂_l dA` over the master nodes `l` (their shape functions
//! carried to the slave by the projection), both over the part of the slave surface
//! that faces the master. Each row is divided by `W_j = Σ_l M_jl = Σ_k D_jk` (the
//! covered integral of `N_j`), so its gap is in metres (a weighted average of the gap
//! over the support of `N_j`), its slave weights sum to 1 and its master weights to
//! −1, and its multiplier is the force the node's share of the interface carries
//! (`λ_j / W_j` is the pressure; in the plane `λ_j / (W_j t)`). A uniform pressure `p`
//! then gives every slave node `p ∫ N_k` and every master node `p ∫ N̂_l`: the
//! consistent loads of both sides, whatever the meshes (the contact patch test,
//! `theory/contact.md`, `theory/contact3d.md`).
//!
//! The row's normal is the master's outward normal averaged with the row's own master
//! weights (the normalised `Σ_l ∫ N_j n_m dA` over the master facets the node's
//! support faces), so that, as for node to segment, it points from the master towards
//! the slave and a frictionless force slides along the master without working on it.

pub mod clip;
pub mod faces;
pub mod segments;

pub use faces::rows as face_rows;
pub use segments::rows as segment_rows;

use super::rows::{Candidate, Contactee, Weights};
use super::state::Slave;

/// The least covered fraction of a slave node's shape-function integral for the node
/// to get a row: below it the node sees the master over a sliver of its support
/// only (a master edge ending just inside its facet), too little to weigh a gap
/// on. A millionth: far below any fraction a real overlap leaves.
pub const COVERED_FRACTION: f64 = 1e-6;

/// What one slave node gathers over its facets, in dimension `D`.
#[derive(Clone, Copy)]
struct Gathered<const D: usize> {
    weights: Weights,
    /// `W_j`, the covered integral of `N_j`.
    covered: f64,
    /// `∫ N_j dA` over the node's whole support.
    total: f64,
    /// The master's outward normals weighted as the row's master weights.
    master_normal: [f64; D],
    /// Entries that did not fit the row ([`super::rows::ROW_NODES`]).
    overflow: usize,
}

impl<const D: usize> Gathered<D> {
    /// Nothing gathered, for each of `n` slave nodes.
    fn empty(n: usize) -> Vec<Gathered<D>> {
        vec![
            Gathered {
                weights: Weights::EMPTY,
                covered: 0.0,
                total: 0.0,
                master_normal: [0.0; D],
                overflow: 0,
            };
            n
        ]
    }
}

/// The rows of what the slave nodes `slaves` of side `(pair, side)` gathered,
/// appended to `out` in slave order: the weights divided by the covered integral,
/// the normal the averaged master normal (`unit` normalises it; `None`, no row), the
/// gap `n · Σ w_k x_k`. A node whose covered fraction is below
/// [`COVERED_FRACTION`] gets none. Returns the most nodes a row needed.
fn finish<const D: usize, X: Fn(usize) -> [f64; D]>(
    (pair, side): (usize, usize),
    slaves: &[usize],
    gathered: &mut [Gathered<D>],
    unit: impl Fn([f64; D]) -> Option<[f64; D]>,
    x: &X,
    out: &mut Vec<Candidate>,
) -> usize {
    let needed = gathered
        .iter()
        .map(|g| g.weights.len() + g.overflow)
        .max()
        .unwrap_or(0);
    for (j, gj) in gathered.iter_mut().enumerate() {
        if gj.covered <= COVERED_FRACTION * gj.total || gj.total == 0.0 {
            continue;
        }
        let Some(n) = unit(gj.master_normal) else {
            continue;
        };
        gj.weights.scale(1.0 / gj.covered);
        let slave = Slave::new(pair, side, slaves[j]);
        let mut c = Candidate::nodal::<D>(slave, Contactee::Mortar, &[], 0.0, 0.0, n);
        c.weights = gj.weights;
        c.length = gj.covered;
        let p = c.combine(x);
        c.gap = crate::geometry::dot(p, n);
        out.push(c);
    }
    needed
}
