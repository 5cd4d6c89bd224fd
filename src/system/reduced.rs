//! The effective matrix restricted to the free dofs, with the map from its entries
//! to the shared full pattern, so refills cost one pass.

use rayon::prelude::*;

use super::DofMap;
use crate::assembly::{Mass, Pattern};
use crate::linsolve::LowerCsc;

/// The lower triangle of `Σ c_i A_i` on the free dofs, with the map from its entries to
/// the shared full pattern, so refills cost one pass.
pub struct ReducedMatrix {
    /// The matrix handed to the solver.
    pub csc: LowerCsc,
    /// Position in the full pattern of each entry.
    src: Vec<usize>,
    /// Free dof of each column (for lumped-mass diagonals).
    diag_pos: Vec<usize>,
}

impl ReducedMatrix {
    /// Builds the free-dof lower pattern of `pattern`.
    pub fn new(pattern: &Pattern, dofs: &DofMap) -> Self {
        let nf = dofs.n_free();
        let mut col_ptr = Vec::with_capacity(nf + 1);
        col_ptr.push(0);
        let cap = pattern.nnz() / 2 + pattern.n_dofs();
        let mut row_idx = Vec::with_capacity(cap);
        let mut src = Vec::with_capacity(cap);
        let mut diag_pos = Vec::with_capacity(nf);
        let d = pattern.dim;
        for n in 0..pattern.n_nodes {
            let nbrs = &pattern.adj[pattern.adj_ptr[n]..pattern.adj_ptr[n + 1]];
            for j in 0..d {
                let ec = dofs.eq[d * n + j];
                if ec == super::CONSTRAINED {
                    continue;
                }
                let c0 = pattern.col_start(n, j);
                for (k, &m) in nbrs.iter().enumerate() {
                    for i in 0..d {
                        let er = dofs.eq[d * m as usize + i];
                        if er != super::CONSTRAINED && er >= ec {
                            if er == ec {
                                diag_pos.push(row_idx.len());
                            }
                            row_idx.push(er);
                            src.push(c0 + d * k + i);
                        }
                    }
                }
                col_ptr.push(row_idx.len());
            }
        }
        let nnz = row_idx.len();
        ReducedMatrix {
            csc: LowerCsc {
                n: nf,
                col_ptr,
                row_idx,
                values: crate::buffers::zeroed(nnz),
            },
            src,
            diag_pos,
        }
    }

    /// Nested-dissection elimination order of the free dofs from the node coordinates.
    pub fn nested_dissection(&self, dofs: &DofMap, coords: &[[f64; 3]]) -> Vec<usize> {
        let dim = dofs.eq.len() / coords.len().max(1);
        let xy: Vec<[f64; 3]> = dofs.free.iter().map(|&d| coords[d / dim]).collect();
        crate::linsolve::ordering::nested_dissection(&xy, &self.csc.col_ptr, &self.csc.row_idx)
    }

    /// Refills the values with `c_m M + Σ (c_i, A_i)` restricted to the free dofs.
    pub fn fill(&mut self, dofs: &DofMap, c_m: f64, mass: &Mass, terms: &[(f64, &[f64])]) {
        let v = &mut self.csc.values;
        let src = &self.src;
        match terms {
            [(c, a)] => v
                .par_iter_mut()
                .zip(src.par_iter())
                .for_each(|(o, &s)| *o = c * a[s]),
            [(c, a), (d, b)] => v
                .par_iter_mut()
                .zip(src.par_iter())
                .for_each(|(o, &s)| *o = c * a[s] + d * b[s]),
            _ => v
                .par_iter_mut()
                .zip(src.par_iter())
                .for_each(|(o, &s)| *o = terms.iter().map(|(c, a)| c * a[s]).sum()),
        }
        match mass {
            Mass::Consistent(m) => {
                if c_m != 0.0 {
                    v.par_iter_mut()
                        .zip(src.par_iter())
                        .for_each(|(o, &s)| *o += c_m * m[s]);
                }
            }
            Mass::Lumped(d) => {
                for (eq, &p) in self.diag_pos.iter().enumerate() {
                    v[p] += c_m * d[dofs.free[eq]];
                }
            }
        }
    }
}
