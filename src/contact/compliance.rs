//! The compliance of the contact dofs, `S = (A⁻¹)_DD`, kept while the factor of `A`
//! does not change.
//!
//! The condensed QP needs `W = G A⁻¹ Gᵀ`. Its rows touch only the dofs `D` of the
//! slave nodes and of the master segments they face, so `W = G_D S G_Dᵀ` with `S` the
//! block of `A⁻¹` on `D`. While the factor stays (a linear material at a fixed step:
//! the matrix is factorised once for the whole run), `S` is worth keeping: a QP then
//! costs the products with `S` and one solve for the correction `A⁻¹Gᵀλ`, instead of
//! `m` solves for `Y = A⁻¹Gᵀ`. New dofs (a slave sliding onto a new segment) add
//! their columns (one blocked solve for all of them); a new factor clears it.

use crate::error::Result;
use crate::system::EffectiveSystem;

/// Marks a free equation that is no contact dof yet.
const NONE: usize = usize::MAX;

/// `S` for one factor.
#[derive(Default)]
struct Block {
    /// The factorisation `S` belongs to (`EffectiveSystem::factor_id`).
    generation: usize,
    /// The free equations in `D`, in the order of `S`'s rows and columns.
    eqs: Vec<usize>,
    /// Position of each free equation in `eqs` (`NONE` when not in `D`).
    slot: Vec<usize>,
    /// `S`, column-major `k x k`, `k = eqs.len()`.
    s: Vec<f64>,
}

/// `S = (A⁻¹)_DD` for the contact dofs met so far.
#[derive(Default)]
pub(crate) struct Compliance {
    /// `S` of the current factor.
    now: Block,
    /// `S` of earlier factors the system keeps (`EffectiveSystem::keeps_factors`: an
    /// error-controlled run's ladder), found again, grown in the same order, when
    /// its factor comes back.
    kept: Vec<Block>,
    // Workspace: new equations and their columns of `A⁻¹`; the slots a condensed
    // operator's rows touch, their positions among them, and `S G_Uᵀ`.
    fresh: Vec<usize>,
    cols: Vec<f64>,
    union: Vec<usize>,
    position: Vec<usize>,
    t: Vec<f64>,
}

impl Compliance {
    /// Whether `S` belongs to the current factor of `sys`.
    pub fn is_current(&self, sys: &EffectiveSystem) -> bool {
        let id = sys.factor_id();
        std::iter::once(&self.now)
            .chain(&self.kept)
            .any(|b| b.generation == id && !b.eqs.is_empty())
    }

    /// Makes `S` hold every free equation of `needed` for the current factor of `sys`
    /// (clearing it first when the factor changed).
    pub fn cover(&mut self, sys: &mut EffectiveSystem, needed: &[usize]) -> Result<()> {
        let n = sys.dofs().n_free();
        if self.now.generation != sys.factor_id() || self.now.slot.len() != n {
            let id = sys.factor_id();
            let fresh = match self.kept.iter().position(|b| b.generation == id) {
                // The factor came back: its S, as it was.
                Some(i) => self.kept.remove(i),
                None => Block {
                    generation: id,
                    slot: vec![NONE; n],
                    ..Default::default()
                },
            };
            let old = std::mem::replace(&mut self.now, fresh);
            if sys.keeps_factors() && !old.eqs.is_empty() && old.slot.len() == n {
                self.kept.push(old);
                // The ladder's, and an impact step's trapezoidal factor.
                if self.kept.len() > crate::model::KEPT_FACTORS + 2 {
                    self.kept.remove(0);
                }
            }
        }
        self.fresh.clear();
        for &e in needed {
            if self.now.slot[e] == NONE {
                self.now.slot[e] = self.now.eqs.len() + self.fresh.len();
                self.fresh.push(e);
            }
        }
        let f = self.fresh.len();
        if f == 0 {
            return Ok(());
        }
        // The new columns of A⁻¹ in one blocked solve.
        self.cols.clear();
        self.cols.resize(n * f, 0.0);
        for (j, &e) in self.fresh.iter().enumerate() {
            self.cols[j * n + e] = 1.0;
        }
        sys.solve_block(&mut self.cols, f)?;
        // Grow S from k x k to (k + f) x (k + f): the old block stays, the new rows
        // and columns come from the new columns of A⁻¹ (A⁻¹ is symmetric).
        let k = self.now.eqs.len();
        let k2 = k + f;
        let mut s = vec![0.0; k2 * k2];
        for j in 0..k {
            s[j * k2..j * k2 + k].copy_from_slice(&self.now.s[j * k..(j + 1) * k]);
        }
        self.now.eqs.extend_from_slice(&self.fresh);
        for jn in 0..f {
            let col = &self.cols[jn * n..(jn + 1) * n];
            let j = k + jn;
            for (i, &e) in self.now.eqs.iter().enumerate() {
                s[i + j * k2] = col[e];
                s[j + i * k2] = col[e];
            }
        }
        // The new-new block from the columns themselves (symmetrised).
        for jn in 0..f {
            for i_n in 0..f {
                let v = 0.5
                    * (self.cols[jn * n + self.fresh[i_n]] + self.cols[i_n * n + self.fresh[jn]]);
                s[(k + i_n) + (k + jn) * k2] = v;
            }
        }
        self.now.s = s;
        Ok(())
    }

    /// `W = G_R S G_Rᵀ` for the rows `rows` of `g` (their equations all covered),
    /// column-major `m × m` into `w`: first `T = S G_Rᵀ` on the union `U` of the rows'
    /// equations (`|U| · nnz(G_R)` products), then `W = G_R T` (`m · nnz(G_R)`, one
    /// triangle mirrored), instead of `S` entry by entry for every pair of rows
    /// (`nnz(G_j) · nnz(G_k)` each, which a mortar row of 54 entries makes 13 times
    /// node to face's cost).
    pub fn condense(
        &mut self,
        g: &nalgebra_sparse::CsrMatrix<f64>,
        rows: &[usize],
        w: &mut Vec<f64>,
    ) {
        let k = self.now.eqs.len();
        let m = rows.len();
        self.union.clear();
        for &i in rows {
            self.union
                .extend(g.row(i).col_indices().iter().map(|&e| self.now.slot[e]));
        }
        self.union.sort_unstable();
        self.union.dedup();
        let nu = self.union.len();
        self.position.resize(k, NONE);
        for (a, &u) in self.union.iter().enumerate() {
            self.position[u] = a;
        }
        self.t.clear();
        self.t.resize(nu * m, 0.0);
        for (j, &i) in rows.iter().enumerate() {
            let r = g.row(i);
            let tj = &mut self.t[j * nu..(j + 1) * nu];
            for (&e, &v) in r.col_indices().iter().zip(r.values()) {
                let c = self.now.slot[e];
                let col = &self.now.s[c * k..(c + 1) * k];
                for (ta, &ua) in tj.iter_mut().zip(&self.union) {
                    *ta += v * col[ua];
                }
            }
        }
        w.clear();
        w.resize(m * m, 0.0);
        for j in 0..m {
            let tj = &self.t[j * nu..(j + 1) * nu];
            for (l, &il) in rows.iter().enumerate().skip(j) {
                let r = g.row(il);
                let v: f64 = r
                    .col_indices()
                    .iter()
                    .zip(r.values())
                    .map(|(&f, &u)| u * tj[self.position[self.now.slot[f]]])
                    .sum();
                w[l + j * m] = v;
                w[j + l * m] = v;
            }
        }
    }
}
