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
use crate::model::MortarBasis;

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

/// The least Hadamard ratio `det G / Π G_ii` of a facet's covered Gram matrix
/// `G_ik = ∫ N_i N_k` for which the dual basis is built on it. A whole segment has
/// 0.75, a whole triangle 0.5, a whole rectangle 0.32, and a part that holds a
/// corner of the facet at least 0.25 (segment); only a cover that is a sliver
/// inside the facet, away from its corners, drives it to zero, where `G⁻¹` would
/// amplify round-off. Such a facet keeps the standard basis (theory/contact.md).
pub const DUAL_CONDITION: f64 = 1e-4;

/// What one slave facet (segment or face, `k ≤ 4` corners) gathers over the master
/// facets it faces, before its test functions are chosen: with the standard basis
/// everything goes straight into the nodes' rows; with the dual basis the integrals
/// of the standard shape functions are kept here and turned into those of the dual
/// ones, `φ_j = Σ_i a_ji N_i` with `A = diag(c) G⁻¹` (`c_i = ∫ N_i`, `G` the Gram
/// matrix, both over the facet's covered part), when the facet is done
/// ([`Facet::close`]). Then `∫ φ_j N_k = δ_jk c_j`: each row holds one slave node.
struct Facet<const D: usize> {
    basis: MortarBasis,
    /// The facet's corners as slots in the side's slave list.
    slots: [usize; 4],
    /// Its corners' node numbers.
    nodes: [usize; 4],
    k: usize,
    /// `∫ N_i N_k` over the covered part (dual basis).
    gram: [[f64; 4]; 4],
    /// `∫ N_i` over the covered part (dual basis).
    covered: [f64; 4],
    /// `∫ N_i n_m` (dual basis).
    normal: [[f64; D]; 4],
    /// `∫ N_i N̂_l` per master node `l` (dual basis).
    master: Vec<(usize, [f64; 4])>,
}

impl<const D: usize> Facet<D> {
    /// A facet of corners `nodes` at slots `slots` (first `k` of each).
    fn new(basis: MortarBasis, nodes: [usize; 4], slots: [usize; 4], k: usize) -> Facet<D> {
        Facet {
            basis,
            slots,
            nodes,
            k,
            gram: [[0.0; 4]; 4],
            covered: [0.0; 4],
            normal: [[0.0; D]; 4],
            master: Vec::new(),
        }
    }

    /// Corner `j`'s test function weighs `w` (`∫ N_j` over a piece of cover) where
    /// the master's outward normal is `n`.
    fn cover(&mut self, g: &mut [Gathered<D>], j: usize, w: f64, n: [f64; D]) {
        match self.basis {
            MortarBasis::Standard => {
                let gj = &mut g[self.slots[j]];
                gj.covered += w;
                for (a, b) in gj.master_normal.iter_mut().zip(n) {
                    *a += w * b;
                }
            }
            MortarBasis::Dual => {
                self.covered[j] += w;
                for (a, b) in self.normal[j].iter_mut().zip(n) {
                    *a += w * b;
                }
            }
        }
    }

    /// `∫ N_j N_k` over a piece grows by `w` (`k` a corner of this facet).
    fn slave(&mut self, g: &mut [Gathered<D>], j: usize, k: usize, w: f64) {
        match self.basis {
            MortarBasis::Standard => {
                let gj = &mut g[self.slots[j]];
                gj.overflow += usize::from(!gj.weights.add(self.nodes[k], w));
            }
            MortarBasis::Dual => self.gram[j][k] += w,
        }
    }

    /// `∫ N_j N̂_l` over a piece grows by `w` (`node` the master's node `l`).
    fn master(&mut self, g: &mut [Gathered<D>], j: usize, node: usize, w: f64) {
        match self.basis {
            MortarBasis::Standard => {
                let gj = &mut g[self.slots[j]];
                gj.overflow += usize::from(!gj.weights.add(node, -w));
            }
            MortarBasis::Dual => match self.master.iter_mut().find(|e| e.0 == node) {
                Some(e) => e.1[j] += w,
                None => {
                    let mut e = (node, [0.0; 4]);
                    e.1[j] = w;
                    self.master.push(e);
                }
            },
        }
    }

    /// The dual basis's coefficients `A = diag(c) G⁻¹`, or `None` where the covered
    /// Gram matrix is too close to singular ([`DUAL_CONDITION`]) or a corner is not
    /// covered at all.
    fn dual(&self) -> Option<[[f64; 4]; 4]> {
        let k = self.k;
        if self.covered[..k].iter().any(|&c| c <= 0.0) {
            return None;
        }
        // The k × k Gram matrix in a 4 × 4 one on the stack, the identity beyond k
        // (its determinant and its inverse's leading block are the k × k ones).
        let g = nalgebra::Matrix4::from_fn(|i, j| {
            if i < k && j < k {
                self.gram[i][j]
            } else {
                f64::from(u8::from(i == j))
            }
        });
        let diagonal: f64 = (0..k).map(|i| g[(i, i)]).product();
        let det = g.determinant();
        if !(diagonal > 0.0 && det / diagonal >= DUAL_CONDITION) {
            return None;
        }
        let inv = g.try_inverse()?;
        let mut a = [[0.0; 4]; 4];
        for (j, row) in a.iter_mut().enumerate().take(k) {
            for (i, aji) in row.iter_mut().enumerate().take(k) {
                *aji = self.covered[j] * inv[(j, i)];
            }
        }
        Some(a)
    }

    /// Adds the facet's dual rows to the nodes' (nothing left to add for the
    /// standard basis). A facet whose Gram matrix is near singular adds its
    /// standard rows.
    fn close(self, g: &mut [Gathered<D>]) {
        if self.basis == MortarBasis::Standard {
            return;
        }
        let k = self.k;
        let a = self.dual();
        for j in 0..k {
            let gj = &mut g[self.slots[j]];
            // The normal stays weighted by the standard shape function: positive
            // weights, a direction that needs no biorthogonality.
            gj.covered += self.covered[j];
            for (n, m) in gj.master_normal.iter_mut().zip(self.normal[j]) {
                *n += m;
            }
            match &a {
                Some(a) => {
                    // ∫ φ_j N_k = δ_jk c_j: the node's own weight only.
                    gj.overflow += usize::from(!gj.weights.add(self.nodes[j], self.covered[j]));
                    for (node, m) in &self.master {
                        let w: f64 = (0..k).map(|i| a[j][i] * m[i]).sum();
                        gj.overflow += usize::from(!gj.weights.add(*node, -w));
                    }
                }
                None => {
                    for kk in 0..k {
                        gj.overflow +=
                            usize::from(!gj.weights.add(self.nodes[kk], self.gram[j][kk]));
                    }
                    for (node, m) in &self.master {
                        gj.overflow += usize::from(!gj.weights.add(*node, -m[j]));
                    }
                }
            }
        }
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
