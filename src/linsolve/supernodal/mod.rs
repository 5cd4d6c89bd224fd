//! Triangular solves of rothe's own over the supernodal Cholesky factor faer
//! computes (its supernodes, row indices and values): one dense right-hand side, a
//! block of them, and the forward solve of a sparse right-hand side, which visits
//! only the supernodes on the elimination-tree paths from its nonzeros to the root.
//!
//! Layout (faer's): supernode `s` owns the columns `[b_s, e_s)` of the permuted
//! factor; its values are one dense column-major block of `(n_s + p_s) × n_s`, the
//! lower triangle of the diagonal block `L_ss` on top of the `p_s` rows `L_ps` of
//! its pattern. Both solves read every supernode's values exactly once, column by
//! column, each column front to back (the forward solve uses column `j` for the
//! diagonal block and the pattern rows in one pass; the backward solve takes the
//! dot product of the same column), so the solve streams `2 nnz(L)` values, the
//! memory bound of a triangular solve. A block of `k` right-hand sides is held row
//! by row (`k` values of one row together), so each factor value meets all `k`
//! columns while it is in a register: `k` multiply-adds per value read.
//!
//! Theory and measurements: `theory/solves.md`.

mod kernels;
mod structure;
mod sweeps;

use faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky;
use kernels::{forward_node, Dir, Place, Plain};
use structure::{narrow, Supernode, TreeSplit, PARALLEL_ORDER};
use sweeps::{split_sweeps, Factor, Run};

/// A row index of the factor's pattern: 4 bytes, so that the sweeps stream half the
/// index bytes a `usize` would (systems of up to `u32::MAX` unknowns; larger ones
/// solve with faer's own code).
type Row = u32;

/// The geometry of one supernode.
/// The buffers of one block solve.
#[derive(Default)]
struct Workspace {
    /// Row-major work copy of the right-hand sides (`n × k`).
    x: Vec<f64>,
    /// Gathered or accumulated pattern rows (`max p_s × k`).
    tmp: Vec<f64>,
    /// A thread's updates of the top rows (`n × k`, zero outside a solve).
    far: Vec<f64>,
}

/// What a block solve reads of the factor's structure.
struct Structure<'a> {
    n: usize,
    /// The longest supernode pattern.
    max_pattern: usize,
    nodes: &'a [Supernode],
    rows: &'a [Row],
    perm: &'a [usize],
    /// `inverse[perm[i]] = i`.
    inverse: &'a [usize],
    /// The two-thread cut of the elimination forest, where it pays.
    split: Option<&'a TreeSplit>,
}

impl Structure<'_> {
    /// Solves the `k` column-major right-hand sides in `rhs`, `8, 4, 2, 1` at a
    /// time, in the workspaces `w`.
    fn solve_cols(&self, values: &[f64], rhs: &mut [f64], k: usize, w: &mut [Workspace; 2]) {
        let n = self.n;
        let mut col = 0;
        while col < k {
            let width = match k - col {
                r if r >= 8 => 8,
                r if r >= 4 => 4,
                r if r >= 2 => 2,
                _ => 1,
            };
            let block = &mut rhs[col * n..(col + width) * n];
            match width {
                8 => self.solve_block::<8>(values, block, w),
                4 => self.solve_block::<4>(values, block, w),
                2 => self.solve_block::<2>(values, block, w),
                _ => self.solve_block::<1>(values, block, w),
            }
            col += width;
        }
    }

    /// `K` right-hand sides: permute into the row-major work copy, solve, permute
    /// back.
    fn solve_block<const K: usize>(&self, values: &[f64], rhs: &mut [f64], w: &mut [Workspace; 2]) {
        let n = self.n;
        let [w0, w1] = w;
        let x = aligned(&mut w0.x, n * K);
        let threads = self.split.is_some();
        permute_in::<K>(self.perm, rhs, x, threads);
        let f = Factor {
            nodes: self.nodes,
            rows: self.rows,
            values,
        };
        let t0 = aligned(&mut w0.tmp, self.max_pattern * K);
        let t1 = aligned(&mut w1.tmp, self.max_pattern * K);
        match self.split {
            Some(split) => {
                let far = [aligned(&mut w0.far, n * K), aligned(&mut w1.far, n * K)];
                split_sweeps::<K>(&f, split, x, [t0, t1], far);
            }
            None => {
                f.sweep::<K>(Dir::Forward, Run::All, x, t0, &mut [], &[]);
                f.sweep::<K>(Dir::Backward, Run::All, x, t0, &mut [], &[]);
            }
        }
        permute_out::<K>(self.perm, self.inverse, x, rhs, threads);
    }
}

/// Rows of the work copy per parallel chunk of a permutation.
const PERMUTE_CHUNK: usize = 16_384;

/// `x[i K + c] = rhs[c n + perm[i]]`: the `K` column-major right-hand sides into
/// the row-major work copy in elimination order, on the rayon pool's threads if
/// `threads` (each on its own rows of `x`).
fn permute_in<const K: usize>(perm: &[usize], rhs: &[f64], x: &mut [f64], threads: bool) {
    use rayon::prelude::*;
    let n = perm.len();
    let rows = |(k, xs): (usize, &mut [f64])| {
        let lo = k * PERMUTE_CHUNK;
        for (r, &p) in xs.chunks_exact_mut(K).zip(&perm[lo..]) {
            for (c, v) in r.iter_mut().enumerate() {
                *v = rhs[c * n + p];
            }
        }
    };
    if threads {
        x.par_chunks_mut(PERMUTE_CHUNK * K)
            .enumerate()
            .for_each(rows);
    } else {
        x.chunks_mut(PERMUTE_CHUNK * K).enumerate().for_each(rows);
    }
}

/// `rhs[c n + perm[i]] = x[i K + c]`, the inverse of [`permute_in`]: one right-hand
/// side in chunks of the original order (`inverse[p]` the row of `x` to read), more
/// in two halves of the columns, each walking `x` in order.
fn permute_out<const K: usize>(
    perm: &[usize],
    inverse: &[usize],
    x: &[f64],
    rhs: &mut [f64],
    threads: bool,
) {
    use rayon::prelude::*;
    let n = perm.len();
    if !threads {
        for (i, &p) in perm.iter().enumerate() {
            for c in 0..K {
                rhs[c * n + p] = x[i * K + c];
            }
        }
    } else if K == 1 {
        rhs.par_chunks_mut(PERMUTE_CHUNK)
            .zip(inverse.par_chunks(PERMUTE_CHUNK))
            .for_each(|(out, inv)| {
                for (o, &i) in out.iter_mut().zip(inv) {
                    *o = x[i];
                }
            });
    } else {
        let half = K.div_ceil(2);
        rhs.par_chunks_mut(n * half)
            .enumerate()
            .for_each(|(h, cols)| {
                for (i, &p) in perm.iter().enumerate() {
                    for c in 0..cols.len() / n {
                        cols[c * n + p] = x[i * K + h * half + c];
                    }
                }
            });
    }
}

/// `len` values of `buf` from a 64-byte boundary on (the buffer grown as needed,
/// new values zero; a buffer that is zero stays zero wherever the window lands):
/// a row of eight right-hand sides is then one cache line, not two.
fn aligned(buf: &mut Vec<f64>, len: usize) -> &mut [f64] {
    const LINE: usize = 64 / std::mem::size_of::<f64>();
    if buf.len() < len + LINE {
        buf.resize(len + LINE, 0.0);
    }
    let off = buf.as_ptr().align_offset(64).min(LINE);
    &mut buf[off..off + len]
}

/// A supernodal factor's structure prepared for solves, and the workspace.
pub struct SupernodalSolver {
    n: usize,
    nodes: Vec<Supernode>,
    rows: Vec<Row>,
    /// The supernode holding each column.
    node_of: Vec<usize>,
    /// The parent supernode in the supernodal elimination tree (`usize::MAX` at a
    /// root).
    parent: Vec<usize>,
    /// `perm[i]`: the original index of the `i`-th eliminated unknown.
    perm: Vec<usize>,
    /// `inverse[perm[i]] = i`.
    inverse: Vec<usize>,
    /// Workspaces of the block solves (one per thread of a split solve).
    work: [Workspace; 2],
    /// The two-thread cut of the elimination forest (large systems).
    split: Option<TreeSplit>,
    /// The sparse solves' copy of the right-hand side (elimination order).
    x: Vec<f64>,
    /// Gathered or accumulated pattern rows of the sparse solves (as long as the
    /// longest supernode pattern).
    tmp: Vec<f64>,
    mark: Vec<bool>,
    reach: Vec<usize>,
}

impl SupernodalSolver {
    /// The solver of the factor with structure `sym` and elimination order `perm`
    /// (`None`: the identity); `None` for a system of more than `u32::MAX` unknowns.
    pub fn new(sym: &SymbolicSupernodalCholesky<usize>, perm: Option<&[usize]>) -> Option<Self> {
        let ns = sym.n_supernodes();
        let begin = sym.supernode_begin();
        let end = sym.supernode_end();
        let cp_rows = sym.col_ptr_for_row_idx();
        let cp_vals = sym.col_ptr_for_val();
        let nnz = sym.nnz_per_super();
        let nodes = (0..ns)
            .map(|s| Supernode {
                begin: begin[s],
                ncols: end[s] - begin[s],
                pattern: cp_rows[s],
                npattern: nnz[s],
                values: cp_vals[s],
            })
            .collect();
        let rows = narrow(sym.row_idx())?;
        Some(Self::from_nodes(sym.nrows(), nodes, rows, perm))
    }

    /// The solver of a simplicial factor (compressed columns `col_ptr`, `row_idx`,
    /// the diagonal first in every column), as supernodes of one column each: the
    /// same layout, a column being a `(1 + p) × 1` block. `None` when a column does
    /// not start with its diagonal.
    pub fn from_simplicial(
        col_ptr: &[usize],
        row_idx: &[usize],
        perm: Option<&[usize]>,
    ) -> Option<Self> {
        let n = col_ptr.len().checked_sub(1)?;
        let mut nodes = Vec::with_capacity(n);
        let mut pattern_rows = Vec::with_capacity(row_idx.len().saturating_sub(n));
        for j in 0..n {
            let (a, b) = (col_ptr[j], col_ptr[j + 1]);
            if b <= a || row_idx[a] != j {
                return None;
            }
            nodes.push(Supernode {
                begin: j,
                ncols: 1,
                pattern: pattern_rows.len(),
                npattern: b - a - 1,
                values: a,
            });
            pattern_rows.extend_from_slice(&row_idx[a + 1..b]);
        }
        Some(Self::from_nodes(n, nodes, narrow(&pattern_rows)?, perm))
    }

    fn from_nodes(n: usize, nodes: Vec<Supernode>, rows: Vec<Row>, perm: Option<&[usize]>) -> Self {
        let ns = nodes.len();
        let mut node_of = vec![0; n];
        for (s, sn) in nodes.iter().enumerate() {
            node_of[sn.begin..sn.begin + sn.ncols].fill(s);
        }
        let parent: Vec<usize> = nodes
            .iter()
            .map(|sn| {
                if sn.npattern == 0 {
                    usize::MAX
                } else {
                    node_of[rows[sn.pattern] as usize]
                }
            })
            .collect();
        let max_pattern = nodes.iter().map(|s| s.npattern).max().unwrap_or(0);
        let perm: Vec<usize> = perm.map_or_else(|| (0..n).collect(), <[usize]>::to_vec);
        let mut inverse = vec![0; n];
        for (i, &p) in perm.iter().enumerate() {
            inverse[p] = i;
        }
        let split = if n >= PARALLEL_ORDER {
            TreeSplit::new(&nodes, &parent, &rows)
        } else {
            None
        };
        SupernodalSolver {
            n,
            split,
            nodes,
            rows,
            node_of,
            parent,
            perm,
            inverse,
            work: Default::default(),
            x: Vec::new(),
            tmp: vec![0.0; max_pattern],
            mark: vec![false; ns],
            reach: Vec::new(),
        }
    }

    /// Order of the system.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Solves `A X = B` in place for the `k` column-major right-hand sides in
    /// `rhs` (`n × k`), with `values` the factor's numeric values.
    pub fn solve_in_place(&mut self, values: &[f64], rhs: &mut [f64], k: usize) {
        let n = self.n;
        debug_assert_eq!(rhs.len(), n * k);
        if n == 0 || k == 0 {
            return;
        }
        let st = Structure {
            n,
            max_pattern: self.tmp.len(),
            nodes: &self.nodes,
            rows: &self.rows,
            perm: &self.perm,
            inverse: &self.inverse,
            split: self
                .split
                .as_ref()
                .filter(|_| rayon::current_num_threads() > 1),
        };
        st.solve_cols(values, rhs, k, &mut self.work);
    }

    /// The forward solve of a sparse right-hand side: `y = L⁻¹ P b` for the `b`
    /// whose nonzeros are `entries` (original numbering), into `y` (length `n`, in
    /// elimination order; zero outside the reach). Only the supernodes on the
    /// elimination-tree paths from the nonzeros' supernodes to the root are
    /// visited; returns how many.
    pub fn forward_sparse(
        &mut self,
        values: &[f64],
        entries: &[(usize, f64)],
        y: &mut [f64],
    ) -> usize {
        debug_assert_eq!(y.len(), self.n);
        y.fill(0.0);
        self.reach.clear();
        for &(p, v) in entries {
            let i = self.inverse[p];
            y[i] += v;
            let mut s = self.node_of[i];
            while s != usize::MAX && !self.mark[s] {
                self.mark[s] = true;
                self.reach.push(s);
                s = self.parent[s];
            }
        }
        self.reach.sort_unstable();
        for &s in &self.reach {
            let sn = &self.nodes[s];
            let at = Place {
                lo: 0,
                split: sn.npattern,
            };
            forward_node::<1, Plain>(sn, &self.rows, values, y, &mut self.tmp, at, &mut []);
            self.mark[s] = false;
        }
        self.reach.len()
    }

    /// `x = A⁻¹ b` for the `b` whose nonzeros are `entries` (original numbering,
    /// repeated indices summed), into `out`: the forward solve visits only the
    /// reach of the nonzeros ([`Self::forward_sparse`]), the backward solve all
    /// supernodes. For right-hand sides on a few dofs (a contact correction
    /// `A⁻¹Gᵀλ`) it costs about half a dense solve.
    pub fn solve_sparse(&mut self, values: &[f64], entries: &[(usize, f64)], out: &mut [f64]) {
        let n = self.n;
        let mut y = std::mem::take(&mut self.x);
        y.resize(n, 0.0);
        self.forward_sparse(values, entries, &mut y[..n]);
        let f = Factor {
            nodes: &self.nodes,
            rows: &self.rows,
            values,
        };
        f.sweep::<1>(
            Dir::Backward,
            Run::All,
            &mut y[..n],
            &mut self.tmp,
            &mut [],
            &[],
        );
        for i in 0..n {
            out[self.perm[i]] = y[i];
        }
        self.x = y;
    }

    /// The dense forward solve `y = L⁻¹ P b` of one right-hand side (`y` in
    /// elimination order), the reference of [`Self::forward_sparse`].
    pub fn forward_dense(&mut self, values: &[f64], b: &[f64], y: &mut [f64]) {
        for i in 0..self.n {
            y[i] = b[self.perm[i]];
        }
        let f = Factor {
            nodes: &self.nodes,
            rows: &self.rows,
            values,
        };
        f.sweep::<1>(Dir::Forward, Run::All, y, &mut self.tmp, &mut [], &[]);
    }

    /// The shares of the factor's values in the two parts and the top of the
    /// two-thread cut of the elimination forest, if the solves use one.
    pub fn split_shares(&self) -> Option<[f64; 3]> {
        let split = self.split.as_ref()?;
        let w = |s: usize| {
            let sn = &self.nodes[s];
            (sn.ncols * (sn.ncols + sn.npattern)) as f64
        };
        let part = |p: &[(u32, u32)]| p.iter().map(|&(s, _)| w(s as usize)).sum::<f64>();
        let shares = [
            part(&split.parts[0]),
            part(&split.parts[1]),
            split.top.iter().map(|&s| w(s as usize)).sum(),
        ];
        let total: f64 = shares.iter().sum();
        Some(shares.map(|x| x / total))
    }

    /// Number of supernodes.
    pub fn supernodes(&self) -> usize {
        self.nodes.len()
    }

    /// Entries of the factor on and below the diagonal: the stored blocks less the
    /// unused upper triangles of their diagonal blocks (`n_s (n_s − 1) / 2` each).
    pub fn lower_entries(&self) -> usize {
        self.nodes
            .iter()
            .map(|sn| sn.ncols * (sn.ncols + 1) / 2 + sn.ncols * sn.npattern)
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn row_indices_beyond_u32_leave_the_solve_to_faer() {
        let fits = [0usize, 7, Row::MAX as usize];
        assert_eq!(narrow(&fits), Some(vec![0, 7, Row::MAX]));
        assert_eq!(narrow(&[3, Row::MAX as usize + 1]), None);
        // A simplicial factor whose pattern does not fit: no own solver.
        let col_ptr = [0usize, 2, 3];
        let too_far = [0usize, Row::MAX as usize + 1, 1];
        assert!(SupernodalSolver::from_simplicial(&col_ptr, &too_far, None).is_none());
        let fine = [0usize, 1, 1];
        assert_eq!(
            SupernodalSolver::from_simplicial(&col_ptr, &fine, None).map(|s| s.n()),
            Some(2)
        );
    }
}
