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

/// A row index of the factor's pattern: 4 bytes, so that the sweeps stream half the
/// index bytes a `usize` would (systems of up to `u32::MAX` unknowns; larger ones
/// solve with faer's own code).
type Row = u32;

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

/// The row indices as [`Row`]s, `None` if one does not fit.
fn narrow(rows: &[usize]) -> Option<Vec<Row>> {
    rows.iter().map(|&r| Row::try_from(r).ok()).collect()
}

/// Systems of at least this order are worth a second thread.
const PARALLEL_ORDER: usize = 20_000;

/// The cut of the elimination forest stops refining once its time (the heavier
/// part plus the top, in values) is within this share of half the factor above it.
const MAX_IMBALANCE: f64 = 0.04;

/// The top of a cut holds at most this share of the factor.
const MAX_TOP: f64 = 0.3;

/// A cut is used only if its time is at most this share of the sequential one.
const MIN_GAIN: f64 = 0.8;

/// The elimination forest cut for two threads: two sets of whole subtrees, each
/// over a contiguous range of columns (the supernodes are in postorder), and the
/// supernodes above them (the top). A sweep runs the two parts at once, each on its
/// own part of `x`, and the top alone: forward after the parts (their updates of
/// top rows collected in a buffer per thread and added in), backward before them
/// (the parts read the top rows from a copy).
#[derive(Debug)]
struct TreeSplit {
    /// The first column of the second part.
    mid: usize,
    /// Each part's `(supernode, split)` in order: the pattern rows from position
    /// `split` on lie above the supernode's subtree, in the top.
    parts: [Vec<(u32, u32)>; 2],
    /// The top's supernodes in order.
    top: Vec<u32>,
    /// The top's columns.
    top_cols: Vec<u32>,
}

impl TreeSplit {
    /// The split of the forest `parent` of `nodes`, if it is in postorder and has
    /// two balanced parts below a small top.
    fn new(nodes: &[Supernode], parent: &[usize], rows: &[Row]) -> Option<Self> {
        let ns = nodes.len();
        let mut children = vec![Vec::new(); ns];
        let mut roots = Vec::new();
        for (s, &p) in parent.iter().enumerate() {
            if p == usize::MAX {
                roots.push(s);
            } else if p <= s {
                return None;
            } else {
                children[p].push(s);
            }
        }
        // Subtree weights (values stored) and first supernodes; postorder check.
        let mut weight = vec![0.0f64; ns];
        let mut first = (0..ns).collect::<Vec<_>>();
        let mut size = vec![1usize; ns];
        for s in 0..ns {
            let sn = &nodes[s];
            weight[s] += (sn.ncols * (sn.ncols + sn.npattern)) as f64;
            if s + 1 < first[s] + size[s] {
                return None;
            }
            if s + 1 - first[s] != size[s] {
                return None;
            }
            let p = parent[s];
            if p != usize::MAX {
                weight[p] += weight[s];
                first[p] = first[p].min(first[s]);
                size[p] += size[s];
            }
        }
        let total: f64 = roots.iter().map(|&r| weight[r]).sum();
        let own = |t: usize| (nodes[t].ncols * (nodes[t].ncols + nodes[t].npattern)) as f64;
        // Cut the heaviest subtree of the frontier while the top stays light; keep
        // the cut whose time, the heavier part plus the top, is least.
        let mut frontier = roots;
        let mut top = Vec::new();
        let mut top_weight = 0.0;
        let mut best: Option<(f64, usize, Vec<usize>, Vec<usize>)> = None;
        loop {
            let mut prefix = 0.0;
            let (mut cost, mut at) = (f64::INFINITY, 0);
            for (i, &r) in frontier.iter().enumerate().take(frontier.len() - 1) {
                prefix += weight[r];
                let c = prefix.max(total - top_weight - prefix) + top_weight;
                if c < cost {
                    (cost, at) = (c, i + 1);
                }
            }
            if at > 0 && best.as_ref().is_none_or(|b| cost < b.0) {
                best = Some((cost, at, frontier.clone(), top.clone()));
            }
            if cost <= (0.5 + MAX_IMBALANCE) * total {
                break;
            }
            let Some(heaviest) = frontier
                .iter()
                .enumerate()
                .filter(|(_, &r)| !children[r].is_empty())
                .max_by(|a, b| weight[*a.1].total_cmp(&weight[*b.1]))
                .map(|(i, _)| i)
            else {
                break;
            };
            let r = frontier.remove(heaviest);
            top.push(r);
            top_weight += own(r);
            if top_weight > MAX_TOP * total {
                break;
            }
            frontier.splice(heaviest..heaviest, children[r].iter().copied());
        }
        let (cost, cut, frontier, mut top) = best?;
        if cost > MIN_GAIN * total {
            return None;
        }
        let mid = nodes[first[frontier[cut]]].begin;
        let part = |roots: &[usize]| {
            let mut out = Vec::new();
            for &r in roots {
                let hi = nodes[r].begin + nodes[r].ncols;
                for s in first[r]..=r {
                    let sn = &nodes[s];
                    let pattern = &rows[sn.pattern..sn.pattern + sn.npattern];
                    out.push((
                        s as u32,
                        pattern.partition_point(|&row| (row as usize) < hi) as u32,
                    ));
                }
            }
            out
        };
        top.sort_unstable();
        let top_cols = top
            .iter()
            .flat_map(|&t| (nodes[t].begin..nodes[t].begin + nodes[t].ncols).map(|c| c as u32))
            .collect();
        Some(TreeSplit {
            mid,
            parts: [part(&frontier[..cut]), part(&frontier[cut..])],
            top: top.into_iter().map(|t| t as u32).collect(),
            top_cols,
        })
    }
}

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

/// How a kernel multiplies and adds: plainly (`a·b + c`, two roundings) or fused
/// (`mul_add`, one rounding; only where the CPU has FMA, where it is one
/// instruction).
trait MulAdd {
    /// Whether this is the fused flavour (AVX2 and FMA are available).
    const FUSED: bool;
    fn mul_add(a: f64, b: f64, c: f64) -> f64;
}

struct Plain;
impl MulAdd for Plain {
    const FUSED: bool = false;
    #[inline(always)]
    fn mul_add(a: f64, b: f64, c: f64) -> f64 {
        a * b + c
    }
}

#[cfg(target_arch = "x86_64")]
struct Fused;
#[cfg(target_arch = "x86_64")]
impl MulAdd for Fused {
    const FUSED: bool = true;
    #[inline(always)]
    fn mul_add(a: f64, b: f64, c: f64) -> f64 {
        a.mul_add(b, c)
    }
}

/// Independent partial sums of the backward solve's dot products: a single chain
/// of dependent additions would wait on the adder's latency instead of memory.
const LANES: usize = 4;

/// Where a supernode's step reads and writes `x`: the rows from `lo` on are in `x`
/// (row `r` at `(r − lo) K`), and the pattern rows from position `split` on (rows
/// above the subtree a thread owns) are in `far` instead (row `r` at `r K`): the
/// forward step adds its updates of them there, the backward step reads them there.
/// A sequential sweep has `lo = 0`, `split = p_s` and an empty `far`.
#[derive(Clone, Copy)]
struct Place {
    lo: usize,
    split: usize,
}

/// Forward step of one supernode on `K` row-major right-hand sides:
/// `x_s ← L_ss⁻¹ x_s`, `x_p ← x_p − L_ps x_s`, one pass over each column, in memory
/// order.
#[inline(always)]
fn forward_node<const K: usize, M: MulAdd>(
    sn: &Supernode,
    rows: &[Row],
    values: &[f64],
    x: &mut [f64],
    tmp: &mut [f64],
    at: Place,
    far: &mut [f64],
) {
    let (ns, np) = (sn.ncols, sn.npattern);
    let b = sn.begin - at.lo;
    let ld = ns + np;
    let pattern = &rows[sn.pattern..sn.pattern + np];
    let (near_rows, far_rows) = pattern.split_at(at.split);
    if ns == 1 {
        // One column (a simplicial factor's): straight into x, no buffer.
        let col = &values[sn.values..sn.values + ld];
        prefetch_ahead(col, Dir::Forward);
        let inv = 1.0 / col[0];
        let xj: [f64; K] = std::array::from_fn(|c| x[b * K + c] * inv);
        x[b * K..(b + 1) * K].copy_from_slice(&xj);
        let (near, rest) = col[1..].split_at(at.split);
        for (&l, &row) in near.iter().zip(near_rows) {
            let r = row as usize - at.lo;
            for c in 0..K {
                x[r * K + c] = M::mul_add(l, -xj[c], x[r * K + c]);
            }
        }
        for (&l, &row) in rest.iter().zip(far_rows) {
            let row = row as usize;
            for c in 0..K {
                far[row * K + c] = M::mul_add(l, -xj[c], far[row * K + c]);
            }
        }
        return;
    }
    let tmp = &mut tmp[..np * K];
    let block = &values[sn.values..sn.values + ld * ns];
    for j in 0..ns {
        let col = &block[j * ld..(j + 1) * ld];
        prefetch_ahead(col, Dir::Forward);
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
        if j == 0 {
            // The first column sets the buffer (`l x_j` is `fma(l, x_j, 0)` exactly).
            for (t, &l) in tmp.chunks_exact_mut(K).zip(&col[ns..]) {
                for c in 0..K {
                    t[c] = l * xj[c];
                }
            }
        } else {
            for (t, &l) in tmp.chunks_exact_mut(K).zip(&col[ns..]) {
                for c in 0..K {
                    t[c] = M::mul_add(l, xj[c], t[c]);
                }
            }
        }
    }
    let (near, rest) = tmp.split_at(at.split * K);
    for (t, &row) in near.chunks_exact(K).zip(near_rows) {
        let r = row as usize - at.lo;
        for c in 0..K {
            x[r * K + c] -= t[c];
        }
    }
    for (t, &row) in rest.chunks_exact(K).zip(far_rows) {
        let row = row as usize;
        for c in 0..K {
            far[row * K + c] -= t[c];
        }
    }
}

/// Backward step of one supernode: `x_s ← L_ssᵀ⁻¹ (x_s − L_psᵀ x_p)`, last column
/// first, each column from its last row up (the whole backward sweep reads the
/// factor as one descending stream).
#[inline(always)]
fn backward_node<const K: usize, M: MulAdd>(
    sn: &Supernode,
    rows: &[Row],
    values: &[f64],
    x: &mut [f64],
    tmp: &mut [f64],
    at: Place,
    far: &[f64],
) {
    let (ns, np) = (sn.ncols, sn.npattern);
    let b = sn.begin - at.lo;
    let ld = ns + np;
    let pattern = &rows[sn.pattern..sn.pattern + np];
    let (near_rows, far_rows) = pattern.split_at(at.split);
    if ns == 1 {
        let col = &values[sn.values..sn.values + ld];
        prefetch_ahead(col, Dir::Backward);
        let (near, rest) = col[1..].split_at(at.split);
        let mut acc = [[0.0; K]; LANES];
        for (k, (&l, &row)) in rest.iter().zip(far_rows).enumerate().rev() {
            let row = row as usize;
            let lane = k % LANES;
            for c in 0..K {
                acc[lane][c] = M::mul_add(l, far[row * K + c], acc[lane][c]);
            }
        }
        for (k, (&l, &row)) in near.iter().zip(near_rows).enumerate().rev() {
            let lane = k % LANES;
            let r = row as usize - at.lo;
            for c in 0..K {
                acc[lane][c] = M::mul_add(l, x[r * K + c], acc[lane][c]);
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
    let (near_t, far_t) = tmp.split_at_mut(at.split * K);
    for (t, &row) in near_t.chunks_exact_mut(K).zip(near_rows) {
        let r = row as usize - at.lo;
        t.copy_from_slice(&x[r * K..(r + 1) * K]);
    }
    for (t, &row) in far_t.chunks_exact_mut(K).zip(far_rows) {
        let row = row as usize;
        t.copy_from_slice(&far[row * K..(row + 1) * K]);
    }
    let block = &values[sn.values..sn.values + ld * ns];
    // Last column first, each column from its last row up: the whole backward sweep
    // reads the factor as one descending stream, which the hardware prefetcher
    // follows (columns read upwards one by one would make a saw-tooth it does not).
    for j in (0..ns).rev() {
        let col = &block[j * ld..(j + 1) * ld];
        prefetch_ahead(col, Dir::Backward);
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

/// How far ahead of the column being read, in values (16 KiB), a sweep asks for
/// the factor's cache lines.
const PREFETCH_AHEAD: usize = 2048;

/// Asks for the cache lines `PREFETCH_AHEAD` values past `col` in the sweep's
/// direction to be brought into the level-2 cache (not level 1, whose few miss
/// buffers the demand loads need: prefetching into it measured slower, as did
/// non-temporal prefetches). Measured on W1 with alternating solves in one
/// process (medians of 20): a block of 8 10–15 % faster (ny = 100: 17.0 → 14.3–15.2
/// ms, ny = 250: 131.5 → 117–119 ms at distances of 512 to 8192 values); one
/// right-hand side within the noise (−4 % to +10 % over three such runs).
#[inline(always)]
fn prefetch_ahead(col: &[f64], dir: Dir) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T1};
        let start = match dir {
            Dir::Forward => col.as_ptr().wrapping_add(PREFETCH_AHEAD),
            Dir::Backward => col.as_ptr().wrapping_sub(PREFETCH_AHEAD),
        }
        .cast::<i8>();
        for line in (0..std::mem::size_of_val(col)).step_by(64) {
            // SAFETY: a prefetch is a hint that never faults, whatever the address
            // (which `wrapping_*` computed without dereferencing).
            unsafe { _mm_prefetch::<_MM_HINT_T1>(start.wrapping_add(line)) };
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (col, dir);
}

/// `acc[lane][c] += Σ_r l[r] · y[r K + c]`, from the last row to the first.
#[inline(always)]
fn dot_rows_rev<const K: usize, M: MulAdd>(l: &[f64], y: &[f64], acc: &mut [[f64; K]; LANES]) {
    #[cfg(target_arch = "x86_64")]
    if K == 8 && M::FUSED {
        // Eight columns: explicit vectors (LLVM kept the generic loop's 32
        // accumulators in half registers and spilled them every row).
        assert!(y.len() >= l.len() * 8);
        let acc8 = acc.as_mut_ptr().cast::<[[f64; 8]; LANES]>();
        // SAFETY: `K == 8`, so `acc` is a `[[f64; 8]; LANES]`; `M::FUSED` is only
        // used inside functions compiled with AVX2 and FMA, after they were
        // detected; `y` holds 8 values per row of `l` (asserted).
        unsafe { dot8_rows_rev(l, y, &mut *acc8) };
        return;
    }
    let mut lc = l.rchunks_exact(LANES);
    let mut yc = y.rchunks_exact(LANES * K);
    for (ls, ys) in (&mut lc).zip(&mut yc) {
        for lane in 0..LANES {
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

/// [`dot_rows_rev`] for eight right-hand sides with AVX2 vectors: the same
/// products in the same order per lane (bit-identical).
///
/// # Safety
/// The CPU must have AVX2 and FMA, and `y.len() >= 8 l.len()`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn dot8_rows_rev(l: &[f64], y: &[f64], acc: &mut [[f64; 8]; LANES]) {
    use std::arch::x86_64::{
        __m256d, _mm256_fmadd_pd, _mm256_loadu_pd, _mm256_set1_pd, _mm256_storeu_pd,
    };
    let (lp, yp) = (l.as_ptr(), y.as_ptr());
    let mut a: [[__m256d; 2]; LANES] = std::array::from_fn(|q| {
        [
            _mm256_loadu_pd(acc[q].as_ptr()),
            _mm256_loadu_pd(acc[q].as_ptr().add(4)),
        ]
    });
    // Rows in chunks of `LANES` from the end, row `r + q` of a chunk into lane `q`;
    // the first `len % LANES` rows, last first, into lane 0.
    let mut r = l.len();
    while r >= LANES {
        r -= LANES;
        for (q, aq) in a.iter_mut().enumerate() {
            let lv = _mm256_set1_pd(*lp.add(r + q));
            let row = yp.add((r + q) * 8);
            aq[0] = _mm256_fmadd_pd(lv, _mm256_loadu_pd(row), aq[0]);
            aq[1] = _mm256_fmadd_pd(lv, _mm256_loadu_pd(row.add(4)), aq[1]);
        }
    }
    while r > 0 {
        r -= 1;
        let lv = _mm256_set1_pd(*lp.add(r));
        let row = yp.add(r * 8);
        a[0][0] = _mm256_fmadd_pd(lv, _mm256_loadu_pd(row), a[0][0]);
        a[0][1] = _mm256_fmadd_pd(lv, _mm256_loadu_pd(row.add(4)), a[0][1]);
    }
    for (q, aq) in a.iter().enumerate() {
        _mm256_storeu_pd(acc[q].as_mut_ptr(), aq[0]);
        _mm256_storeu_pd(acc[q].as_mut_ptr().add(4), aq[1]);
    }
}

/// The direction of a sweep.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Dir {
    /// `L⁻¹`, supernodes in order.
    Forward,
    /// `L⁻ᵀ`, supernodes in reverse.
    Backward,
}

/// The supernodes a sweep visits.
#[derive(Clone, Copy)]
enum Run<'a> {
    /// All of them, on the whole `x`.
    All,
    /// The listed ones, on the whole `x`.
    Listed(&'a [u32]),
    /// One thread's subtrees: `(supernode, split)` in order, on the part of `x` from
    /// column `lo` on, rows above the subtrees in `far` (see [`Place`]).
    Part { lo: usize, nodes: &'a [(u32, u32)] },
}

/// A sweep over `run`, for one kernel flavour: a forward sweep adds its updates of
/// far rows to `far_out`, a backward sweep reads them from `far_in`.
#[inline(always)]
fn sweep<const K: usize, M: MulAdd>(
    dir: Dir,
    run: Run,
    f: &Factor,
    x: &mut [f64],
    tmp: &mut [f64],
    far_out: &mut [f64],
    far_in: &[f64],
) {
    let (nodes, rows, values) = (f.nodes, f.rows, f.values);
    #[inline(always)]
    fn whole(sn: &Supernode) -> Place {
        Place {
            lo: 0,
            split: sn.npattern,
        }
    }
    // Direct calls (no closures): every kernel must inline into the caller compiled
    // for AVX2 and FMA, or `mul_add` becomes a call to the software `fma`.
    match (dir, run) {
        (Dir::Forward, Run::All) => {
            for sn in nodes {
                forward_node::<K, M>(sn, rows, values, x, tmp, whole(sn), &mut []);
            }
        }
        (Dir::Backward, Run::All) => {
            for sn in nodes.iter().rev() {
                backward_node::<K, M>(sn, rows, values, x, tmp, whole(sn), far_in);
            }
        }
        (Dir::Forward, Run::Listed(ids)) => {
            for &s in ids {
                let sn = &nodes[s as usize];
                forward_node::<K, M>(sn, rows, values, x, tmp, whole(sn), &mut []);
            }
        }
        (Dir::Backward, Run::Listed(ids)) => {
            for &s in ids.iter().rev() {
                let sn = &nodes[s as usize];
                backward_node::<K, M>(sn, rows, values, x, tmp, whole(sn), far_in);
            }
        }
        (Dir::Forward, Run::Part { lo, nodes: ids }) => {
            for &(s, split) in ids {
                let at = Place {
                    lo,
                    split: split as usize,
                };
                let sn = &nodes[s as usize];
                forward_node::<K, M>(sn, rows, values, x, tmp, at, far_out);
            }
        }
        (Dir::Backward, Run::Part { lo, nodes: ids }) => {
            for &(s, split) in ids.iter().rev() {
                let at = Place {
                    lo,
                    split: split as usize,
                };
                let sn = &nodes[s as usize];
                backward_node::<K, M>(sn, rows, values, x, tmp, at, far_in);
            }
        }
    }
}

/// Both sweeps of a block of `K` row-major right-hand sides `x` on two threads, cut
/// by `split`, with one `tmp` and one `far` buffer per thread (`far` zero on entry
/// and on return).
fn split_sweeps<const K: usize>(
    f: &Factor,
    split: &TreeSplit,
    x: &mut [f64],
    tmp: [&mut [f64]; 2],
    far: [&mut [f64]; 2],
) {
    let [t0, t1] = tmp;
    let [f0, f1] = far;
    let mid = split.mid;
    {
        let (x0, x1) = x.split_at_mut(mid * K);
        let (p0, p1) = (&split.parts[0], &split.parts[1]);
        rayon::join(
            || {
                f.sweep::<K>(
                    Dir::Forward,
                    Run::Part { lo: 0, nodes: p0 },
                    x0,
                    t0,
                    f0,
                    &[],
                )
            },
            || {
                f.sweep::<K>(
                    Dir::Forward,
                    Run::Part { lo: mid, nodes: p1 },
                    x1,
                    t1,
                    f1,
                    &[],
                )
            },
        );
    }
    for &c in &split.top_cols {
        let i = c as usize * K;
        for j in i..i + K {
            x[j] += f0[j] + f1[j];
            f1[j] = 0.0;
        }
    }
    let top = Run::Listed(&split.top);
    f.sweep::<K>(Dir::Forward, top, x, t0, &mut [], &[]);
    f.sweep::<K>(Dir::Backward, top, x, t0, &mut [], &[]);
    // The parts read the top rows from `f0`.
    for &c in &split.top_cols {
        let i = c as usize * K;
        f0[i..i + K].copy_from_slice(&x[i..i + K]);
    }
    {
        let far: &[f64] = f0;
        let (x0, x1) = x.split_at_mut(mid * K);
        let (p0, p1) = (&split.parts[0], &split.parts[1]);
        rayon::join(
            || {
                f.sweep::<K>(
                    Dir::Backward,
                    Run::Part { lo: 0, nodes: p0 },
                    x0,
                    t0,
                    &mut [],
                    far,
                )
            },
            || {
                f.sweep::<K>(
                    Dir::Backward,
                    Run::Part { lo: mid, nodes: p1 },
                    x1,
                    t1,
                    &mut [],
                    far,
                )
            },
        );
    }
    for &c in &split.top_cols {
        let i = c as usize * K;
        f0[i..i + K].fill(0.0);
    }
}

/// [`sweep`] compiled for AVX2 with FMA.
///
/// # Safety
/// The CPU must have AVX2 and FMA (checked by the caller).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn sweep_avx2<const K: usize>(
    dir: Dir,
    run: Run,
    f: &Factor,
    x: &mut [f64],
    tmp: &mut [f64],
    far_out: &mut [f64],
    far_in: &[f64],
) {
    sweep::<K, Fused>(dir, run, f, x, tmp, far_out, far_in)
}

/// What one sweep reads besides `x` and its buffers.
#[derive(Clone, Copy)]
struct Factor<'a> {
    nodes: &'a [Supernode],
    rows: &'a [Row],
    values: &'a [f64],
}

impl Factor<'_> {
    /// [`sweep`] with the fastest kernels this CPU runs.
    fn sweep<const K: usize>(
        &self,
        dir: Dir,
        run: Run,
        x: &mut [f64],
        tmp: &mut [f64],
        far_out: &mut [f64],
        far_in: &[f64],
    ) {
        #[cfg(target_arch = "x86_64")]
        {
            if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
                // SAFETY: both features were just detected.
                unsafe { sweep_avx2::<K>(dir, run, self, x, tmp, far_out, far_in) };
                return;
            }
        }
        sweep::<K, Plain>(dir, run, self, x, tmp, far_out, far_in)
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
