//! The rows of contact: what every formulation hands to the QP. A row is a gap
//! `g = n · Σ_k w_k x_k` over a few nodes `k` with weights `w_k` (slave weights
//! summing to 1, master ones to −1) along a normal `n`, and its tangential twins
//! along the tangents of the contact plane: in the plane the one `t = (n_y, −n_x)`,
//! in a solid two orthonormal `t₁, t₂` ([`crate::geometry::tangents`]). Node to segment
//! ([`super::master::segments`]), node to face ([`super::master::faces`]) and mortar
//! ([`super::mortar`]) build them, the implicit correction, friction and the ledger
//! read them the same way. Here too the sparse gap matrices of a set of rows.

use super::state::{Key, Slave, Target};

/// What a slave node is in contact with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Contactee {
    /// Segment `index` of the side's master, nodes `[a, b]`.
    Segment {
        /// Index among the side's master segments.
        index: usize,
        /// End nodes.
        nodes: [usize; 2],
    },
    /// Face `index` of the side's master (a solid's triangle or quadrilateral).
    Face {
        /// Index among the side's master faces.
        index: usize,
        /// The face.
        nodes: crate::mesh::Face,
    },
    /// The rigid line (plane: rigid plane) of the pair's side.
    Rigid,
    /// The master segments the slave node's shape function sees (mortar: the
    /// weighted gap of the node, [`super::mortar`]).
    Mortar,
}

/// The most nodes one gap row spans: a mortar row holds the slave node, its
/// neighbours on its segments (faces) and the master nodes facing them. Validation
/// refuses a mortar pair whose rows need more at the initial geometry: in the plane a
/// master locally more than about 20 times finer than the slave, in a solid of
/// quadrilaterals one about 2.4 times finer in both directions (9 slave nodes and a
/// 6 × 6 patch of master nodes; the patch test's 7 × 5 master under a 4 × 4 slave
/// needs 33).
pub const ROW_NODES: usize = 48;

/// The nodes of a gap row and their weights: the gap is
/// `n · Σ w_k x_k` (slave weights summing to 1, master weights to −1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Weights {
    len: u8,
    entries: [(u32, f64); ROW_NODES],
}

impl Weights {
    /// No nodes.
    pub const EMPTY: Weights = Weights {
        len: 0,
        entries: [(0, 0.0); ROW_NODES],
    };

    /// Adds `w` to node `node`'s weight (a new entry if it has none). False, and
    /// nothing added, when the row is full.
    pub fn add(&mut self, node: usize, w: f64) -> bool {
        let n = self.len as usize;
        if let Some(e) = self.entries[..n].iter_mut().find(|e| e.0 as usize == node) {
            e.1 += w;
            return true;
        }
        if n == ROW_NODES {
            return false;
        }
        self.entries[n] = (node as u32, w);
        self.len += 1;
        true
    }

    /// `(node, weight)` pairs.
    pub fn iter(&self) -> impl Iterator<Item = (usize, f64)> + '_ {
        self.entries[..self.len as usize]
            .iter()
            .map(|&(n, w)| (n as usize, w))
    }

    /// Multiplies every weight by `f`.
    pub fn scale(&mut self, f: f64) {
        for e in &mut self.entries[..self.len as usize] {
            e.1 *= f;
        }
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.len as usize
    }

    /// Whether the row has no node.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

/// A candidate constraint: the gap of one slave node to its master, linearised as
/// `g(u + δ) ≈ g + n · Σ w_k δ_k` over the row's nodes (node to segment: `+1` on the
/// slave, `−(1−ξ)` and `−ξ` on the segment's ends; mortar: the normalised integrals
/// of the slave node's shape function, [`super::mortar`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Candidate {
    /// Pair index.
    pub pair: usize,
    /// Direction within the pair.
    pub side: usize,
    /// Slave node.
    pub slave: usize,
    /// Master segment, rigid line or the mortar projection.
    pub master: Contactee,
    /// Local coordinate of the closest point on the segment, in `[0, 1]` (0 for a
    /// mortar row).
    pub xi: f64,
    /// Gap along the normal (m): positive open, negative penetrating.
    pub gap: f64,
    /// Unit outward normal of the master (mortar: opposite to the slave's nodal
    /// normal); `z = 0` in the plane.
    pub normal: [f64; 3],
    /// The unit tangents of the contact plane: in the plane the one
    /// `(n_y, −n_x, 0)` (the second zero), in a solid two, orthonormal with `n`.
    pub tangents: [[f64; 3]; 2],
    /// The spatial dimension of the row (2 or 3): dofs `dim · node + i`.
    pub dim: u8,
    /// The row's nodes and weights.
    pub weights: Weights,
    /// The length (m) the row's gap stands for: the slave's tributary length, the
    /// integral of its shape function over the part facing the master (mortar), or
    /// 0 (node to segment: the tributary length of the node is used).
    pub length: f64,
}

impl Candidate {
    /// The key of the constraint: its slave and the master facet, rigid master or
    /// mortar projection it meets.
    pub fn key(&self) -> Key {
        let target = match self.master {
            Contactee::Segment { index, .. } | Contactee::Face { index, .. } => {
                Target::Facet(index)
            }
            Contactee::Rigid => Target::Rigid,
            Contactee::Mortar => Target::Mortar,
        };
        Key {
            slave: self.slave_key(),
            target,
        }
    }

    /// The slave's key: pair, side, slave node.
    pub fn slave_key(&self) -> Slave {
        Slave::new(self.pair, self.side, self.slave)
    }

    /// The unit tangent `t = (n_y, −n_x)` of a plane row: the direction of its
    /// tangential row and of the friction force on the slave.
    pub fn tangent(&self) -> [f64; 2] {
        [self.normal[1], -self.normal[0]]
    }

    /// The number of tangential rows: 1 in the plane, 2 in a solid.
    pub fn n_tangents(&self) -> usize {
        self.dim as usize - 1
    }

    /// The nonzeros `(dof, coefficient)` of the linearised gap row (all dofs).
    pub fn row(&self) -> impl Iterator<Item = (usize, f64)> + '_ {
        self.along(self.normal)
    }

    /// The nonzeros of tangential row `j`: the relative tangential displacement of
    /// the slave and its master along `t_j`, `t_j · Σ w_k δ_k`.
    pub fn tangent_row(&self, j: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        self.along(self.tangents[j])
    }

    /// `d · Σ w_k δ_k` as `(dof, coefficient)`, `dim` per node.
    fn along(&self, d: [f64; 3]) -> impl Iterator<Item = (usize, f64)> + '_ {
        let dim = self.dim as usize;
        self.weights
            .iter()
            .flat_map(move |(n, w)| (0..dim).map(move |i| (dim * n + i, w * d[i])))
    }

    /// `Σ w_k p_k` of the nodal vectors `p(node)`.
    pub fn combine<const D: usize>(&self, p: impl Fn(usize) -> [f64; D]) -> [f64; D] {
        self.weights.iter().fold([0.0; D], |mut a, (n, w)| {
            let q = p(n);
            for (ai, qi) in a.iter_mut().zip(q) {
                *ai += w * qi;
            }
            a
        })
    }

    /// The tangential components `t_j · Σ w_k p_k` of the nodal vectors `p(node)`
    /// (`dim` components each; the second zero in the plane).
    pub fn tangential(&self, p: impl Fn(usize, usize) -> f64) -> [f64; 2] {
        let dim = self.dim as usize;
        let mut d = [0.0; 3];
        for (n, w) in self.weights.iter() {
            for (i, di) in d.iter_mut().enumerate().take(dim) {
                *di += w * p(n, i);
            }
        }
        let mut out = [0.0; 2];
        for (j, o) in out.iter_mut().enumerate().take(self.n_tangents()) {
            *o = (0..dim).map(|i| d[i] * self.tangents[j][i]).sum();
        }
        out
    }

    /// A node-to-master row of `slave`: the weights `+1` on the slave and `−w` on each
    /// of the master's `corners` `(node, w)` (a segment's ends `1 − ξ` and `ξ`, a
    /// face's shape functions at the projection, none on a rigid master), the gap
    /// `gap` along the unit `normal` and the tangents of its contact plane: in the
    /// plane (`D = 2`) the one `(n_y, −n_x)`, in a solid the two of
    /// [`crate::geometry::tangents`]. `xi` is a segment's local coordinate (0 else).
    pub fn nodal<const D: usize>(
        slave: Slave,
        master: Contactee,
        corners: &[(usize, f64)],
        xi: f64,
        gap: f64,
        normal: [f64; D],
    ) -> Candidate {
        let mut weights = Weights::EMPTY;
        weights.add(slave.node, 1.0);
        for &(node, w) in corners {
            weights.add(node, -w);
        }
        let (normal, tangents) = if D == 2 {
            let n = [normal[0], normal[1], 0.0];
            (n, [[n[1], -n[0], 0.0], [0.0; 3]])
        } else {
            let n = [normal[0], normal[1], normal[2]];
            (n, crate::geometry::tangents(n))
        };
        Candidate {
            pair: slave.pair,
            side: slave.side,
            slave: slave.node,
            master,
            xi,
            gap,
            normal,
            tangents,
            dim: D as u8,
            weights,
            length: 0.0,
        }
    }
}

/// The linearised gap rows `G` of `cands` as a CSR matrix: one row per candidate,
/// columns the dofs numbered by `columns` (`columns[d]` the column of dof `d`, or
/// `usize::MAX` to leave the dof out: a constrained one), `ncols` columns.
pub fn gap_matrix(
    cands: &[Candidate],
    columns: &[usize],
    ncols: usize,
) -> nalgebra_sparse::CsrMatrix<f64> {
    rows_matrix(cands, columns, ncols, false)
}

/// The gap rows of `cands` followed by their tangential rows (rows
/// `cands.len() + (dim − 1) i + j` for tangent `j` of candidate `i`), as
/// [`gap_matrix`].
pub fn gap_and_tangent_matrix(
    cands: &[Candidate],
    columns: &[usize],
    ncols: usize,
) -> nalgebra_sparse::CsrMatrix<f64> {
    rows_matrix(cands, columns, ncols, true)
}

/// The gap rows, and the tangential rows after them when `tangents`.
fn rows_matrix(
    cands: &[Candidate],
    columns: &[usize],
    ncols: usize,
    tangents: bool,
) -> nalgebra_sparse::CsrMatrix<f64> {
    let per = cands.first().map_or(1, |c| c.dim as usize);
    let n = if tangents { per } else { 1 } * cands.len();
    let mut offsets = Vec::with_capacity(n + 1);
    let mut cols = Vec::with_capacity(6 * n);
    let mut values = Vec::with_capacity(6 * n);
    offsets.push(0);
    for c in cands {
        gap_row(c.row(), columns, &mut cols, &mut values);
        offsets.push(cols.len());
    }
    if tangents {
        for c in cands {
            for j in 0..c.n_tangents() {
                gap_row(c.tangent_row(j), columns, &mut cols, &mut values);
                offsets.push(cols.len());
            }
        }
    }
    nalgebra_sparse::CsrMatrix::try_from_unsorted_csr_data(n, ncols, offsets, cols, values)
        .expect("distinct in-range columns per row")
}

/// Appends one row's entries, summed by column, leaving out dofs without a column.
fn gap_row(
    row: impl Iterator<Item = (usize, f64)>,
    columns: &[usize],
    cols: &mut Vec<usize>,
    values: &mut Vec<f64>,
) {
    let start = cols.len();
    for (d, v) in row {
        let j = columns[d];
        if j != usize::MAX {
            match cols[start..].iter().position(|&x| x == j) {
                Some(p) => values[start + p] += v,
                None => {
                    cols.push(j);
                    values.push(v);
                }
            }
        }
    }
}
