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

use faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky;

/// The geometry of one supernode.
#[derive(Clone, Copy, Debug)]
struct Supernode {
    /// First column.
    begin: usize,
    /// Number of columns.
    ncols: usize,
    /// Offset of its pattern in `rows`.
    pattern: usize,
    /// Length of its pattern.
    npattern: usize,
    /// Offset of its values.
    values: usize,
}

/// Blocks of at least this many right-hand sides are split over two threads.
const PARALLEL_COLUMNS: usize = 8;

/// Systems of at least this order are worth a second thread.
const PARALLEL_ORDER: usize = 20_000;

/// The buffers of one block solve.
#[derive(Default)]
struct Workspace {
    /// Row-major work copy of the right-hand sides (`n × k`).
    x: Vec<f64>,
    /// Gathered or accumulated pattern rows (`max p_s × k`).
    tmp: Vec<f64>,
}

/// What a block solve reads of the factor's structure.
struct Structure<'a> {
    n: usize,
    /// The longest supernode pattern.
    max_pattern: usize,
    nodes: &'a [Supernode],
    rows: &'a [usize],
    perm: &'a [usize],
}

impl Structure<'_> {
    /// Solves the `k` column-major right-hand sides in `rhs`, `8, 4, 2, 1` at a
    /// time, in the workspace `w`.
    fn solve_cols(&self, values: &[f64], rhs: &mut [f64], k: usize, w: &mut Workspace) {
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
    fn solve_block<const K: usize>(&self, values: &[f64], rhs: &mut [f64], w: &mut Workspace) {
        let n = self.n;
        w.x.resize(n * K, 0.0);
        for i in 0..n {
            let p = self.perm[i];
            for c in 0..K {
                w.x[i * K + c] = rhs[c * n + p];
            }
        }
        w.tmp.resize(w.tmp.len().max(self.max_pattern * K), 0.0);
        sweeps_best::<K>(
            Sweeps::Both,
            self.nodes,
            self.rows,
            values,
            &mut w.x,
            &mut w.tmp,
        );
        for i in 0..n {
            let p = self.perm[i];
            for c in 0..K {
                rhs[c * n + p] = w.x[i * K + c];
            }
        }
    }
}

/// A supernodal factor's structure prepared for solves, and the workspace.
pub struct SupernodalSolver {
    n: usize,
    nodes: Vec<Supernode>,
    rows: Vec<usize>,
    /// The supernode holding each column.
    node_of: Vec<usize>,
    /// The parent supernode in the supernodal elimination tree (`usize::MAX` at a
    /// root).
    parent: Vec<usize>,
    /// `perm[i]`: the original index of the `i`-th eliminated unknown.
    perm: Vec<usize>,
    /// `inverse[perm[i]] = i`.
    inverse: Vec<usize>,
    /// Workspaces of the block solves (two: a wide block runs as two halves).
    work: [Workspace; 2],
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
    /// (`None`: the identity).
    pub fn new(sym: &SymbolicSupernodalCholesky<usize>, perm: Option<&[usize]>) -> Self {
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
        Self::from_nodes(sym.nrows(), nodes, sym.row_idx().to_vec(), perm)
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
        Some(Self::from_nodes(n, nodes, pattern_rows, perm))
    }

    fn from_nodes(
        n: usize,
        nodes: Vec<Supernode>,
        rows: Vec<usize>,
        perm: Option<&[usize]>,
    ) -> Self {
        let ns = nodes.len();
        let mut node_of = vec![0; n];
        for (s, sn) in nodes.iter().enumerate() {
            node_of[sn.begin..sn.begin + sn.ncols].fill(s);
        }
        let parent = nodes
            .iter()
            .map(|sn| {
                if sn.npattern == 0 {
                    usize::MAX
                } else {
                    node_of[rows[sn.pattern]]
                }
            })
            .collect();
        let max_pattern = nodes.iter().map(|s| s.npattern).max().unwrap_or(0);
        let perm: Vec<usize> = perm.map_or_else(|| (0..n).collect(), <[usize]>::to_vec);
        let mut inverse = vec![0; n];
        for (i, &p) in perm.iter().enumerate() {
            inverse[p] = i;
        }
        SupernodalSolver {
            n,
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
        };
        if k >= PARALLEL_COLUMNS && n >= PARALLEL_ORDER && rayon::current_num_threads() > 1 {
            // Two halves of the block on two threads, each with its own workspace:
            // wide blocks are bound by the multiply-adds, not by the factor's stream.
            let half = k / 2;
            let (left, right) = rhs.split_at_mut(half * n);
            let (w0, w1) = self.work.split_at_mut(1);
            rayon::join(
                || st.solve_cols(values, left, half, &mut w0[0]),
                || st.solve_cols(values, right, k - half, &mut w1[0]),
            );
        } else {
            st.solve_cols(values, rhs, k, &mut self.work[0]);
        }
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
            forward_node::<1, Plain>(&self.nodes[s], &self.rows, values, y, &mut self.tmp);
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
        sweeps_best::<1>(
            Sweeps::Backward,
            &self.nodes,
            &self.rows,
            values,
            &mut y[..n],
            &mut self.tmp,
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
        for sn in &self.nodes {
            forward_node::<1, Plain>(sn, &self.rows, values, y, &mut self.tmp);
        }
    }

    /// The number of supernodes.
    pub fn supernodes(&self) -> usize {
        self.nodes.len()
    }
}

/// How a kernel multiplies and adds: plainly (`a·b + c`, two roundings) or fused
/// (`mul_add`, one rounding; only where the CPU has FMA, where it is one
/// instruction).
trait MulAdd {
    fn mul_add(a: f64, b: f64, c: f64) -> f64;
}

struct Plain;
impl MulAdd for Plain {
    #[inline(always)]
    fn mul_add(a: f64, b: f64, c: f64) -> f64 {
        a * b + c
    }
}

#[cfg(target_arch = "x86_64")]
struct Fused;
#[cfg(target_arch = "x86_64")]
impl MulAdd for Fused {
    #[inline(always)]
    fn mul_add(a: f64, b: f64, c: f64) -> f64 {
        a.mul_add(b, c)
    }
}

/// Independent partial sums of the backward solve's dot products: a single chain
/// of dependent additions would wait on the adder's latency instead of memory.
const LANES: usize = 4;

/// Forward step of one supernode on `K` row-major right-hand sides:
/// `x_s ← L_ss⁻¹ x_s`, `x_p ← x_p − L_ps x_s`, one pass over each column, in memory
/// order.
#[inline(always)]
fn forward_node<const K: usize, M: MulAdd>(
    sn: &Supernode,
    rows: &[usize],
    values: &[f64],
    x: &mut [f64],
    tmp: &mut [f64],
) {
    let (b, ns, np) = (sn.begin, sn.ncols, sn.npattern);
    let ld = ns + np;
    if ns == 1 {
        // One column (a simplicial factor's): straight into x, no buffer.
        let col = &values[sn.values..sn.values + ld];
        let inv = 1.0 / col[0];
        let xj: [f64; K] = std::array::from_fn(|c| x[b * K + c] * inv);
        x[b * K..(b + 1) * K].copy_from_slice(&xj);
        for (&l, &row) in col[1..].iter().zip(&rows[sn.pattern..sn.pattern + np]) {
            for c in 0..K {
                x[row * K + c] = M::mul_add(l, -xj[c], x[row * K + c]);
            }
        }
        return;
    }
    let tmp = &mut tmp[..np * K];
    tmp.fill(0.0);
    let block = &values[sn.values..sn.values + ld * ns];
    for j in 0..ns {
        let col = &block[j * ld..(j + 1) * ld];
        let inv = 1.0 / col[j];
        let mut xj = [0.0; K];
        for c in 0..K {
            xj[c] = x[(b + j) * K + c] * inv;
            x[(b + j) * K + c] = xj[c];
        }
        let neg: [f64; K] = std::array::from_fn(|c| -xj[c]);
        for i in j + 1..ns {
            let l = col[i];
            let xi = &mut x[(b + i) * K..(b + i + 1) * K];
            for c in 0..K {
                xi[c] = M::mul_add(l, neg[c], xi[c]);
            }
        }
        for (t, &l) in tmp.chunks_exact_mut(K).zip(&col[ns..]) {
            for c in 0..K {
                t[c] = M::mul_add(l, xj[c], t[c]);
            }
        }
    }
    for (t, &row) in tmp.chunks_exact(K).zip(&rows[sn.pattern..sn.pattern + np]) {
        for c in 0..K {
            x[row * K + c] -= t[c];
        }
    }
}

/// Backward step of one supernode: `x_s ← L_ssᵀ⁻¹ (x_s − L_psᵀ x_p)`, last column
/// first, each column from its last row up (the whole backward sweep reads the
/// factor as one descending stream).
#[inline(always)]
fn backward_node<const K: usize, M: MulAdd>(
    sn: &Supernode,
    rows: &[usize],
    values: &[f64],
    x: &mut [f64],
    tmp: &mut [f64],
) {
    let (b, ns, np) = (sn.begin, sn.ncols, sn.npattern);
    let ld = ns + np;
    if ns == 1 {
        let col = &values[sn.values..sn.values + ld];
        let mut acc = [[0.0; K]; LANES];
        let pattern = &rows[sn.pattern..sn.pattern + np];
        for (k, (&l, &row)) in col[1..].iter().zip(pattern).enumerate().rev() {
            let lane = k % LANES;
            for c in 0..K {
                acc[lane][c] = M::mul_add(l, x[row * K + c], acc[lane][c]);
            }
        }
        let inv = 1.0 / col[0];
        for c in 0..K {
            let sum: f64 = acc.iter().map(|a| a[c]).sum();
            x[b * K + c] = (x[b * K + c] - sum) * inv;
        }
        return;
    }
    let tmp = &mut tmp[..np * K];
    for (t, &row) in tmp
        .chunks_exact_mut(K)
        .zip(&rows[sn.pattern..sn.pattern + np])
    {
        t.copy_from_slice(&x[row * K..(row + 1) * K]);
    }
    let block = &values[sn.values..sn.values + ld * ns];
    // Last column first, each column from its last row up: the whole backward sweep
    // reads the factor as one descending stream, which the hardware prefetcher
    // follows (columns read upwards one by one would make a saw-tooth it does not).
    for j in (0..ns).rev() {
        let col = &block[j * ld..(j + 1) * ld];
        let mut acc = [[0.0; K]; LANES];
        dot_rows_rev::<K, M>(&col[ns..], tmp, &mut acc);
        dot_rows_rev::<K, M>(&col[j + 1..ns], &x[(b + j + 1) * K..(b + ns) * K], &mut acc);
        let inv = 1.0 / col[j];
        for c in 0..K {
            let sum: f64 = acc.iter().map(|a| a[c]).sum();
            x[(b + j) * K + c] = (x[(b + j) * K + c] - sum) * inv;
        }
    }
}

/// `acc[lane][c] += Σ_r l[r] · y[r K + c]`, from the last row to the first.
#[inline(always)]
fn dot_rows_rev<const K: usize, M: MulAdd>(l: &[f64], y: &[f64], acc: &mut [[f64; K]; LANES]) {
    let mut lc = l.rchunks_exact(LANES);
    let mut yc = y.rchunks_exact(LANES * K);
    for (ls, ys) in (&mut lc).zip(&mut yc) {
        for lane in (0..LANES).rev() {
            for c in 0..K {
                acc[lane][c] = M::mul_add(ls[lane], ys[lane * K + c], acc[lane][c]);
            }
        }
    }
    for (r, &lv) in lc.remainder().iter().enumerate().rev() {
        for c in 0..K {
            acc[0][c] = M::mul_add(lv, yc.remainder()[r * K + c], acc[0][c]);
        }
    }
}

/// Which sweeps a solve makes.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Sweeps {
    /// Forward and backward: `A⁻¹`.
    Both,
    /// Backward only (after a sparse forward solve).
    Backward,
}

/// The sweeps over all supernodes, for one kernel flavour.
#[inline(always)]
fn sweeps<const K: usize, M: MulAdd>(
    which: Sweeps,
    nodes: &[Supernode],
    rows: &[usize],
    values: &[f64],
    x: &mut [f64],
    tmp: &mut [f64],
) {
    if which == Sweeps::Both {
        for sn in nodes {
            forward_node::<K, M>(sn, rows, values, x, tmp);
        }
    }
    for sn in nodes.iter().rev() {
        backward_node::<K, M>(sn, rows, values, x, tmp);
    }
}

/// [`sweeps`] compiled for AVX2 with FMA.
///
/// # Safety
/// The CPU must have AVX2 and FMA (checked by the caller).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn sweeps_avx2<const K: usize>(
    which: Sweeps,
    nodes: &[Supernode],
    rows: &[usize],
    values: &[f64],
    x: &mut [f64],
    tmp: &mut [f64],
) {
    sweeps::<K, Fused>(which, nodes, rows, values, x, tmp)
}

/// [`sweeps`] with the fastest kernels this CPU runs.
fn sweeps_best<const K: usize>(
    which: Sweeps,
    nodes: &[Supernode],
    rows: &[usize],
    values: &[f64],
    x: &mut [f64],
    tmp: &mut [f64],
) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
            // SAFETY: both features were just detected.
            unsafe { sweeps_avx2::<K>(which, nodes, rows, values, x, tmp) };
            return;
        }
    }
    sweeps::<K, Plain>(which, nodes, rows, values, x, tmp)
}
