//! The sparsity pattern of all global matrices, built once from the connectivity.
//!
//! Storage is node-blocked compressed columns over all dofs (full symmetric storage):
//! with `d` dofs per node (the mesh's dimension), column `d n + j` (node `n`,
//! component `j`) holds, for each neighbour `m` of `n` in ascending order, the rows
//! `d m .. d m + d`. Row indices are therefore never stored: they follow from the
//! node adjacency, and the position of `(d m + i, d n + j)` is
//! `col_ptr[d n + j] + d k + i` with `k` the rank of `m` among the neighbours of
//! `n`. Mass and stiffness share one pattern. The products are written once for a
//! dimension `D` (a const parameter) and dispatched on the pattern's `dim`.

use rayon::prelude::*;

use crate::mesh::Mesh;

/// Nodes a task of [`Pattern::matvec2`] takes.
const FUSED_NODES: usize = 256;

/// Below this many nodes a product runs on the calling thread: handing a few
/// hundred rows to the pool costs more than the rows (the threads' wake-up and the
/// caller's wait), measured in `theory/solves.md`.
pub const SERIAL_NODES: usize = 1024;

/// What both products of [`Pattern::matvec2`] read: `y = A x`, `z = B w` (`B` as
/// full blocks, or one value per node pair).
#[derive(Clone, Copy)]
struct Operands<'a> {
    a: &'a [f64],
    x: &'a [f64],
    b: &'a [f64],
    w: &'a [f64],
}

/// Node-blocked symmetric sparsity pattern (see the module docs).
#[derive(Clone, Debug)]
pub struct Pattern {
    /// Number of nodes.
    pub n_nodes: usize,
    /// Dofs per node (the mesh's dimension, 2 or 3).
    pub dim: usize,
    /// Offsets into `adj` per node (`n_nodes + 1`).
    pub adj_ptr: Vec<usize>,
    /// Sorted neighbour lists (each node is its own neighbour).
    pub adj: Vec<u32>,
}

impl Pattern {
    /// Builds the node adjacency of every element block of `mesh`.
    pub fn new(mesh: &Mesh) -> Self {
        let n = mesh.n_nodes();
        // node -> elements' nodes, via counting.
        let mut count = vec![0usize; n + 1];
        for b in &mesh.blocks {
            let nn = b.elements.kind.nodes();
            for &v in &b.elements.conn {
                count[v + 1] += nn;
            }
        }
        for i in 0..n {
            count[i + 1] += count[i];
        }
        let mut fill = count.clone();
        let mut raw = vec![0u32; count[n]];
        for b in &mesh.blocks {
            let nn = b.elements.kind.nodes();
            for el in b.elements.conn.chunks_exact(nn) {
                for &v in el {
                    for &w in el {
                        raw[fill[v]] = w as u32;
                        fill[v] += 1;
                    }
                }
            }
        }
        let lists: Vec<Vec<u32>> = (0..n)
            .into_par_iter()
            .map(|v| {
                let mut l = raw[count[v]..count[v + 1]].to_vec();
                l.push(v as u32);
                l.sort_unstable();
                l.dedup();
                l
            })
            .collect();
        let mut adj_ptr = Vec::with_capacity(n + 1);
        adj_ptr.push(0);
        let mut adj = Vec::with_capacity(lists.iter().map(Vec::len).sum());
        for l in &lists {
            adj.extend_from_slice(l);
            adj_ptr.push(adj.len());
        }
        Pattern {
            n_nodes: n,
            dim: mesh.dim,
            adj_ptr,
            adj,
        }
    }

    /// Number of dofs.
    pub fn n_dofs(&self) -> usize {
        self.dim * self.n_nodes
    }

    /// Number of stored values (`d²` per node pair).
    pub fn nnz(&self) -> usize {
        self.dim * self.dim * self.adj.len()
    }

    /// Start of column `d n + j` in the value array.
    #[inline]
    pub fn col_start(&self, n: usize, j: usize) -> usize {
        let d = self.dim;
        d * d * self.adj_ptr[n] + d * j * (self.adj_ptr[n + 1] - self.adj_ptr[n])
    }

    /// Rank of node `m` among the neighbours of node `n`.
    #[inline]
    pub fn rank(&self, n: usize, m: usize) -> usize {
        let l = &self.adj[self.adj_ptr[n]..self.adj_ptr[n + 1]];
        l.iter()
            .position(|&x| x as usize == m)
            .expect("node pair outside the sparsity pattern")
    }

    /// Position of entry `(d m + i, d n + j)` in the value array.
    #[inline]
    pub fn position(&self, m: usize, i: usize, n: usize, j: usize) -> usize {
        self.col_start(n, j) + self.dim * self.rank(n, m) + i
    }

    /// `y = A x` for a matrix stored on this pattern (symmetric storage, so row
    /// `d n + j` is column `d n + j`). Parallel over nodes, one node's rows per task,
    /// from [`SERIAL_NODES`] nodes on; each row is summed in the same order either way.
    pub fn matvec(&self, a: &[f64], x: &[f64], y: &mut [f64]) {
        match self.dim {
            3 => self.matvec_d::<3>(a, x, y),
            _ => self.matvec_d::<2>(a, x, y),
        }
    }

    fn matvec_d<const D: usize>(&self, a: &[f64], x: &[f64], y: &mut [f64]) {
        let row = |(n, yn): (usize, &mut [f64])| {
            let cols = self.node_columns_d::<D>(a, n);
            let mut s = [0.0; D];
            for (k, &m) in self.neighbours(n).iter().enumerate() {
                let t = block_terms::<D>(&cols, k, x, m);
                for j in 0..D {
                    s[j] += t[j];
                }
            }
            yn.copy_from_slice(&s);
        };
        if y.len() < D * SERIAL_NODES {
            y.chunks_mut(D).enumerate().for_each(row);
        } else {
            y.par_chunks_mut(D).enumerate().for_each(row);
        }
    }

    /// `y = M x` for a matrix whose node blocks are all `m_nk I` (see
    /// [`crate::assembly::ConsistentMass`]), `m` one value per node pair.
    pub fn matvec_pairs(&self, m: &[f64], x: &[f64], y: &mut [f64]) {
        match self.dim {
            3 => self.matvec_pairs_d::<3>(m, x, y),
            _ => self.matvec_pairs_d::<2>(m, x, y),
        }
    }

    fn matvec_pairs_d<const D: usize>(&self, m: &[f64], x: &[f64], y: &mut [f64]) {
        let row = |(n, yn): (usize, &mut [f64])| {
            let lo = self.adj_ptr[n];
            let mut s = [0.0; D];
            for (k, &j) in self.neighbours(n).iter().enumerate() {
                let t = pair_terms::<D>(m[lo + k], x, j);
                for i in 0..D {
                    s[i] += t[i];
                }
            }
            yn.copy_from_slice(&s);
        };
        if y.len() < D * SERIAL_NODES {
            y.chunks_mut(D).enumerate().for_each(row);
        } else {
            y.par_chunks_mut(D).enumerate().for_each(row);
        }
    }

    /// `y = A x` and `z = B w` in one pass over the pattern (both matrices on it):
    /// the adjacency is read once for two products. Each output is summed in the
    /// order of [`Pattern::matvec`], so both equal separate products bit for bit.
    pub fn matvec2(
        &self,
        a: &[f64],
        x: &[f64],
        y: &mut [f64],
        b: Stored,
        w: &[f64],
        z: &mut [f64],
    ) {
        match (self.dim, b) {
            (3, Stored::Full(b)) => self.fused::<3, false>(a, x, y, b, w, z),
            (3, Stored::Pairs(m)) => self.fused::<3, true>(a, x, y, m, w, z),
            (_, Stored::Full(b)) => self.fused::<2, false>(a, x, y, b, w, z),
            (_, Stored::Pairs(m)) => self.fused::<2, true>(a, x, y, m, w, z),
        }
    }

    fn fused<const D: usize, const PAIRS: bool>(
        &self,
        a: &[f64],
        x: &[f64],
        y: &mut [f64],
        b: &[f64],
        w: &[f64],
        z: &mut [f64],
    ) {
        let ops = Operands { a, x, b, w };
        let simd = crate::simd::Simd::detected();
        let chunk = |(c, (y, z)): (usize, (&mut [f64], &mut [f64]))| {
            let first = c * FUSED_NODES;
            match simd {
                #[cfg(target_arch = "x86_64")]
                // SAFETY: `Simd::detected` names AVX2 only where the CPU has it.
                crate::simd::Simd::Avx2 => unsafe {
                    self.fused_nodes_avx2::<D, PAIRS>(first, &ops, y, z)
                },
                _ => self.fused_nodes::<D, PAIRS>(first, &ops, y, z),
            }
        };
        if y.len() < D * SERIAL_NODES {
            y.chunks_mut(D * FUSED_NODES)
                .zip(z.chunks_mut(D * FUSED_NODES))
                .enumerate()
                .for_each(chunk);
        } else {
            y.par_chunks_mut(D * FUSED_NODES)
                .zip(z.par_chunks_mut(D * FUSED_NODES))
                .enumerate()
                .for_each(chunk);
        }
    }

    /// [`Pattern::fused_nodes`] compiled for AVX2 (the same operations in the same
    /// order: the same bits).
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn fused_nodes_avx2<const D: usize, const PAIRS: bool>(
        &self,
        first: usize,
        ops: &Operands,
        y: &mut [f64],
        z: &mut [f64],
    ) {
        self.fused_nodes::<D, PAIRS>(first, ops, y, z)
    }

    /// The rows of the nodes from `first` on (as many as `y` holds) of both
    /// products of [`Pattern::matvec2`].
    #[inline(always)]
    fn fused_nodes<const D: usize, const PAIRS: bool>(
        &self,
        first: usize,
        ops: &Operands,
        y: &mut [f64],
        z: &mut [f64],
    ) {
        let Operands { a, x, b, w } = *ops;
        for (i, (yn, zn)) in y.chunks_exact_mut(D).zip(z.chunks_exact_mut(D)).enumerate() {
            let n = first + i;
            let lo = self.adj_ptr[n];
            let ac = self.node_columns_d::<D>(a, n);
            let bc = if PAIRS {
                [&[][..]; D]
            } else {
                self.node_columns_d::<D>(b, n)
            };
            let (mut s, mut t) = ([0.0; D], [0.0; D]);
            for (k, &j) in self.neighbours(n).iter().enumerate() {
                let p = block_terms::<D>(&ac, k, x, j);
                for i in 0..D {
                    s[i] += p[i];
                }
                let q = if PAIRS {
                    pair_terms::<D>(b[lo + k], w, j)
                } else {
                    block_terms::<D>(&bc, k, w, j)
                };
                for i in 0..D {
                    t[i] += q[i];
                }
            }
            yn.copy_from_slice(&s);
            zn.copy_from_slice(&t);
        }
    }

    #[inline]
    fn neighbours(&self, n: usize) -> &[u32] {
        &self.adj[self.adj_ptr[n]..self.adj_ptr[n + 1]]
    }

    /// The `d` stored columns of node `n` (each `d · neighbours` long).
    #[inline]
    pub(crate) fn node_columns<'a>(&self, a: &'a [f64], n: usize) -> Vec<&'a [f64]> {
        let d = self.dim;
        let len = d * (self.adj_ptr[n + 1] - self.adj_ptr[n]);
        let c = d * d * self.adj_ptr[n];
        (0..d).map(|j| &a[c + j * len..c + (j + 1) * len]).collect()
    }

    #[inline(always)]
    fn node_columns_d<'a, const D: usize>(&self, a: &'a [f64], n: usize) -> [&'a [f64]; D] {
        let len = D * (self.adj_ptr[n + 1] - self.adj_ptr[n]);
        let c = D * D * self.adj_ptr[n];
        std::array::from_fn(|j| &a[c + j * len..c + (j + 1) * len])
    }
}

/// A second matrix of [`Pattern::matvec2`]: full node blocks, or one value per node
/// pair (`m I` blocks).
#[derive(Clone, Copy, Debug)]
pub enum Stored<'a> {
    /// Values on the pattern.
    Full(&'a [f64]),
    /// One value per node pair.
    Pairs(&'a [f64]),
}

/// The contributions of neighbour `m` (rank `k`) to the `D` rows of a node.
#[inline(always)]
fn block_terms<const D: usize>(cols: &[&[f64]; D], k: usize, x: &[f64], m: u32) -> [f64; D] {
    let m = D * m as usize;
    std::array::from_fn(|j| {
        let c = &cols[j][D * k..D * k + D];
        let mut s = c[0] * x[m];
        for i in 1..D {
            s += c[i] * x[m + i];
        }
        s
    })
}

/// The contributions of neighbour `m` to the `D` rows of a node for a block `mk I`.
#[inline(always)]
fn pair_terms<const D: usize>(mk: f64, x: &[f64], m: u32) -> [f64; D] {
    let m = D * m as usize;
    std::array::from_fn(|i| mk * x[m + i])
}

/// Greedy colouring of the elements of one block so that no two elements of a colour
/// share a node: elements of one colour can be scattered in parallel without races.
/// The first 64 colours are tracked with a bit mask per node; a node shared by more
/// elements than that (a fan of triangles around one node) takes further colours from
/// a list kept for it, so any mesh can be coloured.
pub fn colour_elements(conn: &[usize], nn: usize, n_nodes: usize) -> Vec<Vec<usize>> {
    let n_el = conn.len() / nn;
    let mut node_mask = vec![0u64; n_nodes];
    let mut node_extra: Vec<Vec<u32>> = Vec::new();
    let mut colours: Vec<Vec<usize>> = Vec::new();
    for e in 0..n_el {
        let nodes = &conn[e * nn..(e + 1) * nn];
        let used = nodes.iter().fold(0u64, |acc, &v| acc | node_mask[v]);
        let c = if used != u64::MAX {
            (!used).trailing_zeros() as usize
        } else {
            if node_extra.is_empty() {
                node_extra = vec![Vec::new(); n_nodes];
            }
            (64..)
                .find(|&c| nodes.iter().all(|&v| !node_extra[v].contains(&(c as u32))))
                .expect("a free colour exists")
        };
        if c == colours.len() {
            colours.push(Vec::new());
        }
        colours[c].push(e);
        for &v in nodes {
            if c < 64 {
                node_mask[v] |= 1 << c;
            } else {
                node_extra[v].push(c as u32);
            }
        }
    }
    colours
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fan_of_more_than_64_elements_is_coloured() {
        // 100 triangles around node 0: every element needs its own colour.
        let m = 100;
        let conn: Vec<usize> = (0..m).flat_map(|k| [0, 1 + k, 1 + (k + 1) % m]).collect();
        let colours = colour_elements(&conn, 3, m + 1);
        assert_eq!(colours.len(), m);
        let mut seen = vec![false; m];
        for colour in &colours {
            let mut nodes: Vec<usize> = colour
                .iter()
                .flat_map(|&e| conn[3 * e..3 * e + 3].to_vec())
                .collect();
            let len = nodes.len();
            nodes.sort_unstable();
            nodes.dedup();
            assert_eq!(nodes.len(), len, "a colour shares a node");
            for &e in colour {
                seen[e] = true;
            }
        }
        assert!(seen.iter().all(|&x| x));
    }
}
