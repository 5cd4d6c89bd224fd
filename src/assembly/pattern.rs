//! The sparsity pattern of all global matrices, built once from the connectivity.
//!
//! Storage is node-blocked compressed columns over all dofs (full symmetric storage):
//! column `2n+j` (node `n`, component `j`) holds, for each neighbour `m` of `n` in
//! ascending order, the rows `2m` and `2m+1`. Row indices are therefore never stored:
//! they follow from the node adjacency, and the position of `(2m+i, 2n+j)` is
//! `col_ptr[2n+j] + 2k + i` with `k` the rank of `m` among the neighbours of `n`.
//! Mass and stiffness share one pattern.

use rayon::prelude::*;

use crate::mesh::Mesh;

/// Node-blocked sparsity pattern shared by the mass and stiffness matrices.
#[derive(Clone, Debug)]
pub struct Pattern {
    /// Number of nodes.
    pub n_nodes: usize,
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
            adj_ptr,
            adj,
        }
    }

    /// Number of dofs.
    pub fn n_dofs(&self) -> usize {
        2 * self.n_nodes
    }

    /// Number of stored entries (full symmetric storage).
    pub fn nnz(&self) -> usize {
        4 * self.adj.len()
    }

    /// Start of column `2n + j`.
    #[inline]
    pub fn col_start(&self, n: usize, j: usize) -> usize {
        4 * self.adj_ptr[n] + 2 * j * (self.adj_ptr[n + 1] - self.adj_ptr[n])
    }

    /// Rank of node `m` among the neighbours of `n` (panics if not a neighbour).
    #[inline]
    pub fn rank(&self, n: usize, m: usize) -> usize {
        let l = &self.adj[self.adj_ptr[n]..self.adj_ptr[n + 1]];
        l.iter()
            .position(|&x| x as usize == m)
            .expect("node pair outside the sparsity pattern")
    }

    /// Position of entry `(2m+i, 2n+j)` in a value array.
    #[inline]
    pub fn position(&self, m: usize, i: usize, n: usize, j: usize) -> usize {
        self.col_start(n, j) + 2 * self.rank(n, m) + i
    }

    /// `y = A x` for a matrix stored on this pattern (symmetric, full storage),
    /// in parallel over nodes.
    pub fn matvec(&self, a: &[f64], x: &[f64], y: &mut [f64]) {
        y.par_chunks_mut(2).enumerate().for_each(|(n, yn)| {
            let (c0, c1) = self.node_columns(a, n);
            let (mut s0, mut s1) = (0.0, 0.0);
            for (k, &m) in self.neighbours(n).iter().enumerate() {
                let (p, q) = block_terms(c0, c1, k, x, m);
                s0 += p;
                s1 += q;
            }
            (yn[0], yn[1]) = (s0, s1);
        });
    }

    /// `y = M x` for a matrix whose 2×2 node blocks are `m_k I`, `m` holding one
    /// value per node pair in adjacency order (the sums of [`Self::matvec`] on the
    /// full values, whose zero entries add nothing).
    pub fn matvec_pairs(&self, m: &[f64], x: &[f64], y: &mut [f64]) {
        y.par_chunks_mut(2).enumerate().for_each(|(n, yn)| {
            let lo = self.adj_ptr[n];
            let (mut s0, mut s1) = (0.0, 0.0);
            for (k, &j) in self.neighbours(n).iter().enumerate() {
                let (p, q) = pair_terms(m[lo + k], x, j);
                s0 += p;
                s1 += q;
            }
            (yn[0], yn[1]) = (s0, s1);
        });
    }

    /// `y = A x` and `z = B w` in one pass over the pattern (the adjacency and each
    /// neighbour read once for both), `B` on the pattern or in node-pair form.
    pub fn matvec2(
        &self,
        a: &[f64],
        x: &[f64],
        y: &mut [f64],
        b: Stored,
        w: &[f64],
        z: &mut [f64],
    ) {
        match b {
            Stored::Full(b) => self.fused::<false>(a, x, y, b, w, z),
            Stored::Pairs(m) => self.fused::<true>(a, x, y, m, w, z),
        }
    }

    /// [`Self::matvec2`] with `b` in node-pair form if `PAIRS`, else on the pattern.
    fn fused<const PAIRS: bool>(
        &self,
        a: &[f64],
        x: &[f64],
        y: &mut [f64],
        b: &[f64],
        w: &[f64],
        z: &mut [f64],
    ) {
        y.par_chunks_mut(2)
            .zip(z.par_chunks_mut(2))
            .enumerate()
            .for_each(|(n, (yn, zn))| {
                let lo = self.adj_ptr[n];
                let (a0, a1) = self.node_columns(a, n);
                let (b0, b1) = if PAIRS {
                    (&[][..], &[][..])
                } else {
                    self.node_columns(b, n)
                };
                let (mut s0, mut s1, mut t0, mut t1) = (0.0, 0.0, 0.0, 0.0);
                for (k, &j) in self.neighbours(n).iter().enumerate() {
                    let (p, q) = block_terms(a0, a1, k, x, j);
                    s0 += p;
                    s1 += q;
                    let (p, q) = if PAIRS {
                        pair_terms(b[lo + k], w, j)
                    } else {
                        block_terms(b0, b1, k, w, j)
                    };
                    t0 += p;
                    t1 += q;
                }
                (yn[0], yn[1], zn[0], zn[1]) = (s0, s1, t0, t1);
            });
    }

    /// The neighbours of node `n` (itself included), ascending.
    #[inline]
    fn neighbours(&self, n: usize) -> &[u32] {
        &self.adj[self.adj_ptr[n]..self.adj_ptr[n + 1]]
    }

    /// The two columns of node `n` of a matrix `a` stored on this pattern.
    #[inline]
    pub(crate) fn node_columns<'a>(&self, a: &'a [f64], n: usize) -> (&'a [f64], &'a [f64]) {
        let len = 2 * (self.adj_ptr[n + 1] - self.adj_ptr[n]);
        let c = 4 * self.adj_ptr[n];
        (&a[c..c + len], &a[c + len..c + 2 * len])
    }
}

/// How the second matrix of [`Pattern::matvec2`] is stored.
#[derive(Clone, Copy, Debug)]
pub enum Stored<'a> {
    /// Values on the pattern.
    Full(&'a [f64]),
    /// One value per node pair (2×2 blocks `m_k I`), in adjacency order.
    Pairs(&'a [f64]),
}

/// The contributions of neighbour `m` (its `k`-th) to both rows of a node: the
/// node's columns `c0, c1` times `x` at `m` (both of `x`'s values loaded once).
#[inline(always)]
fn block_terms(c0: &[f64], c1: &[f64], k: usize, x: &[f64], m: u32) -> (f64, f64) {
    let m = 2 * m as usize;
    let (x0, x1) = (x[m], x[m + 1]);
    (
        c0[2 * k] * x0 + c0[2 * k + 1] * x1,
        c1[2 * k] * x0 + c1[2 * k + 1] * x1,
    )
}

/// The contributions of neighbour `m` to both rows of a node for a block `mk I`.
#[inline(always)]
fn pair_terms(mk: f64, x: &[f64], m: u32) -> (f64, f64) {
    let m = 2 * m as usize;
    (mk * x[m], mk * x[m + 1])
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
