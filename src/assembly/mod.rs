//! Global assembly: element matrices scattered into the shared sparsity [`Pattern`],
//! in parallel by element colours (no two elements of a colour share a node, so
//! their scatters never touch the same column), plus load vectors.
//!
//! Start with [`Assembler::new`], then [`Assembler::stiffness`] and [`Assembler::mass`].

pub mod internal;
pub mod loads;
pub mod nonlocal;
pub mod pattern;

use rayon::prelude::*;

use crate::fe::element;
use crate::fe::{Idealisation, Kinematics, MAX_ELEMENT_DOFS, MAX_NODES};
use crate::material::Material;
use crate::mesh::{ElementKind, Mesh};
pub use pattern::{Pattern, Stored};

/// The coordinates of an element's nodes (the first `nodes.len()` entries).
#[inline(always)]
pub fn element_coords(mesh: &Mesh, nodes: &[usize]) -> [[f64; 3]; MAX_NODES] {
    let mut x = [[0.0; 3]; MAX_NODES];
    for (a, &n) in nodes.iter().enumerate() {
        x[a] = mesh.coords[n];
    }
    x
}

/// A nodal field's values at an element's nodes, `dim` per node (the first
/// `dim · nodes.len()` entries; all zero for an empty field).
#[inline(always)]
pub fn element_values(field: &[f64], nodes: &[usize], dim: usize) -> [f64; MAX_ELEMENT_DOFS] {
    let mut out = [0.0; MAX_ELEMENT_DOFS];
    if !field.is_empty() {
        for (a, &n) in nodes.iter().enumerate() {
            for i in 0..dim {
                out[dim * a + i] = field[dim * n + i];
            }
        }
    }
    out
}

/// The coordinates and displacements (`D` per node) of an element's nodes, and
/// their number.
#[inline(always)]
pub(crate) fn gather<const D: usize>(
    mesh: &Mesh,
    nodes: &[usize],
    u: &[f64],
) -> ([[f64; 3]; MAX_NODES], [f64; MAX_ELEMENT_DOFS], usize) {
    (
        element_coords(mesh, nodes),
        element_values(u, nodes, D),
        nodes.len(),
    )
}

/// Mass matrix: consistent (on the shared pattern) or lumped (a diagonal).
#[derive(Clone, Debug)]
pub enum Mass {
    /// Values on the shared pattern.
    Consistent(ConsistentMass),
    /// Diagonal entries, one per dof.
    Lumped(Vec<f64>),
}

/// A consistent mass matrix: its values on the shared pattern (it dereferences to
/// them), and, when every `d × d` node block is a multiple of the identity (a
/// scalar density on every element, as in all of rothe's elements), that multiple
/// per node pair in adjacency order, which the products read instead: `1/d²` of the
/// values (a quarter in the plane, a ninth in a solid), so `M x` streams that much
/// of the matrix.
#[derive(Clone, Debug)]
pub struct ConsistentMass {
    values: Vec<f64>,
    pairs: Option<Vec<f64>>,
}

impl ConsistentMass {
    /// The mass with `values` on `pattern`, its node-pair form found exactly (each
    /// block's off-diagonal entries zero and its diagonal entries equal).
    pub fn new(pattern: &Pattern, values: Vec<f64>) -> Self {
        let d = pattern.dim;
        let pairs = (0..pattern.n_nodes)
            .into_par_iter()
            .map(|n| {
                let len = pattern.adj_ptr[n + 1] - pattern.adj_ptr[n];
                let cols = pattern.node_columns(&values, n);
                (0..len)
                    .map(|k| {
                        let a = cols[0][d * k];
                        let is_pair = (0..d).all(|j| {
                            (0..d).all(|i| cols[j][d * k + i] == if i == j { a } else { 0.0 })
                        });
                        is_pair.then_some(a)
                    })
                    .collect::<Option<Vec<f64>>>()
            })
            .collect::<Option<Vec<Vec<f64>>>>()
            .map(|per_node| per_node.concat());
        ConsistentMass { values, pairs }
    }

    /// Whether the products use the node-pair form.
    pub fn has_pairs(&self) -> bool {
        self.pairs.is_some()
    }

    /// `y = M x`.
    pub fn matvec(&self, pattern: &Pattern, x: &[f64], y: &mut [f64]) {
        match &self.pairs {
            Some(m) => pattern.matvec_pairs(m, x, y),
            None => pattern.matvec(&self.values, x, y),
        }
    }
}

impl std::ops::Deref for ConsistentMass {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        &self.values
    }
}

impl Mass {
    /// `y = M x`.
    pub fn matvec(&self, pattern: &Pattern, x: &[f64], y: &mut [f64]) {
        match self {
            Mass::Consistent(m) => m.matvec(pattern, x, y),
            Mass::Lumped(d) => y
                .par_iter_mut()
                .zip(d.par_iter().zip(x.par_iter()))
                .for_each(|(y, (d, x))| *y = d * x),
        }
    }

    /// `y = A x` and `z = M w`, in one pass over the pattern for a consistent mass
    /// (its node-pair form where it has one).
    pub fn with_product(
        &self,
        pattern: &Pattern,
        a: &[f64],
        x: &[f64],
        y: &mut [f64],
        w: &[f64],
        z: &mut [f64],
    ) {
        match self {
            Mass::Consistent(m) => {
                let b = match &m.pairs {
                    Some(pairs) => Stored::Pairs(pairs),
                    None => Stored::Full(&m.values),
                };
                pattern.matvec2(a, x, y, b, w, z)
            }
            Mass::Lumped(_) => {
                pattern.matvec(a, x, y);
                self.matvec(pattern, w, z);
            }
        }
    }

    /// Row sums (the lumped diagonal for either kind).
    pub fn row_sums(&self, pattern: &Pattern) -> Vec<f64> {
        let ones = vec![1.0; pattern.n_dofs()];
        let mut y = vec![0.0; pattern.n_dofs()];
        self.matvec(pattern, &ones, &mut y);
        y
    }
}

/// Pattern plus element colours per block: built once per mesh. The neighbour table
/// of nonlocal materials is built at the first Gauss-point pass that needs it and
/// kept with the buffers of its passes.
pub struct Assembler {
    /// The shared sparsity pattern.
    pub pattern: Pattern,
    /// Element colours of every block.
    pub colours: Vec<Vec<Vec<usize>>>,
    /// The nonlocal table and its pass buffers (`None` until needed).
    nonlocal: std::sync::Mutex<Option<nonlocal::Nonlocal>>,
    /// The instruction set of the Gauss-point pass's element loop.
    simd: crate::simd::Simd,
}

#[derive(Clone, Copy)]
pub(crate) struct SharedValues(pub(crate) *mut f64);
// SAFETY: writes through the pointer happen only for elements of one colour at a
// time, which share no node and hence no column of the pattern.
unsafe impl Send for SharedValues {}
unsafe impl Sync for SharedValues {}

impl Assembler {
    /// Builds the pattern and the colouring of `mesh`.
    pub fn new(mesh: &Mesh) -> Self {
        let pattern = Pattern::new(mesh);
        let colours = mesh
            .blocks
            .iter()
            .map(|b| {
                pattern::colour_elements(&b.elements.conn, b.elements.kind.nodes(), mesh.n_nodes())
            })
            .collect();
        Assembler {
            pattern,
            colours,
            nonlocal: std::sync::Mutex::new(None),
            simd: crate::simd::Simd::detected(),
        }
    }

    /// The same assembler with the Gauss-point pass's element loop compiled for
    /// `simd` (the default is [`crate::simd::Simd::detected`]); a set the CPU lacks
    /// falls back to the baseline.
    pub fn with_simd(mut self, simd: crate::simd::Simd) -> Self {
        self.simd = if simd == crate::simd::Simd::Avx2 {
            crate::simd::Simd::available()
        } else {
            simd
        };
        self
    }

    /// The instruction set of the Gauss-point pass's element loop.
    pub fn simd(&self) -> crate::simd::Simd {
        self.simd
    }

    /// The nonlocal table of `materials` on `mesh`, built (or rebuilt, should the
    /// materials have changed) when missing, with the drivers averaged at `u` from
    /// the committed states `stores` ([`nonlocal::Nonlocal::evaluate`]); `None`
    /// inside when no material is nonlocal. The guard holds the buffers for the
    /// pass that reads them.
    pub fn nonlocal_at(
        &self,
        mesh: &Mesh,
        materials: &[Material],
        idealisation: Idealisation,
        u: &[f64],
        stores: &[crate::material::store::StateStore],
    ) -> std::sync::MutexGuard<'_, Option<nonlocal::Nonlocal>> {
        crate::dispatch_kinematics!(idealisation, <D, V, K> =>
            self.nonlocal_at_k::<D, V, K>(mesh, materials, u, stores))
    }

    /// [`Assembler::nonlocal_at`] in the idealisation `K`.
    pub(crate) fn nonlocal_at_k<const D: usize, const V: usize, K: Kinematics<D, V>>(
        &self,
        mesh: &Mesh,
        materials: &[Material],
        u: &[f64],
        stores: &[crate::material::store::StateStore],
    ) -> std::sync::MutexGuard<'_, Option<nonlocal::Nonlocal>> {
        let mut guard = self
            .nonlocal
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        if !materials.iter().any(|m| m.nonlocal_radius().is_some()) {
            *guard = None;
            return guard;
        }
        if !guard
            .as_ref()
            .is_some_and(|n| n.table.fits(mesh, materials))
        {
            *guard = nonlocal::Nonlocal::build(mesh, materials);
        }
        if let Some(n) = guard.as_mut() {
            n.evaluate::<D, V, K>(mesh, materials, u, stores);
        }
        guard
    }

    /// Assembles `Σ_e element(block, e, x_e, out)` where `out` is the row-major element
    /// matrix (`d nn x d nn`, `d` the mesh's dimension) of element `e`.
    pub fn assemble<F>(&self, mesh: &Mesh, element: F) -> Vec<f64>
    where
        F: Fn(usize, usize, &[[f64; 3]], &mut [f64]) + Sync,
    {
        let mut values = crate::buffers::zeroed(self.pattern.nnz());
        let shared = SharedValues(values.as_mut_ptr());
        for (bi, block) in mesh.blocks.iter().enumerate() {
            let nn = block.elements.kind.nodes();
            for colour in &self.colours[bi] {
                colour.par_chunks(256).for_each(|chunk| {
                    // Rebind the whole wrapper (not its raw-pointer field) so the closure
                    // captures a `Sync` value under edition-2021 disjoint captures.
                    #[allow(clippy::redundant_locals)]
                    let shared = shared;
                    let mut ke = [0.0; MAX_ELEMENT_DOFS * MAX_ELEMENT_DOFS];
                    for &e in chunk {
                        let nodes = block.elements.element(e);
                        let x = element_coords(mesh, nodes);
                        element(bi, e, &x[..nn], &mut ke);
                        self.scatter(nodes, &ke, shared);
                    }
                });
            }
        }
        values
    }

    /// Adds the element matrix `ke` (row-major, `d nn x d nn`) of `nodes` into the
    /// values behind `shared`.
    ///
    /// The caller guarantees that no other thread adds to the columns of `nodes`
    /// at the same time (elements of one colour share no node).
    #[inline]
    pub(crate) fn scatter(&self, nodes: &[usize], ke: &[f64], shared: SharedValues) {
        match self.pattern.dim {
            3 => self.scatter_d::<3>(nodes, ke, shared),
            _ => self.scatter_d::<2>(nodes, ke, shared),
        }
    }

    #[inline]
    fn scatter_d<const D: usize>(&self, nodes: &[usize], ke: &[f64], shared: SharedValues) {
        let nn = nodes.len();
        let nd = D * nn;
        let p = &self.pattern;
        for (b, &nb) in nodes.iter().enumerate() {
            let c: [usize; D] = std::array::from_fn(|j| p.col_start(nb, j));
            for (a, &na) in nodes.iter().enumerate() {
                let k = D * p.rank(nb, na);
                for (j, &cj) in c.iter().enumerate() {
                    for i in 0..D {
                        // SAFETY: the caller holds the columns of `nodes` exclusively.
                        unsafe {
                            *shared.0.add(cj + k + i) += ke[(D * a + i) * nd + D * b + j];
                        }
                    }
                }
            }
        }
    }

    /// Elastic stiffness `K` (bars: `EA/L` along the axis).
    pub fn stiffness(
        &self,
        mesh: &Mesh,
        materials: &[Material],
        idealisation: Idealisation,
    ) -> Vec<f64> {
        crate::dispatch_kinematics!(idealisation, <D, V, K> => self.stiffness_of::<D, V, K>(
            mesh,
            materials,
            |_| true,
            |m| m.elasticity::<V, K>(),
        ))
    }

    /// A stiffness-like matrix in the idealisation `K`: `Σ ∫ Bᵀ D B t dA` with
    /// `D = d(material)` over the blocks `in_block` selects (bars `E A / L`), zero
    /// elsewhere: the elastic stiffness, or a viscosity matrix with `d` the
    /// material's `η`.
    pub fn stiffness_of<const D: usize, const V: usize, K: Kinematics<D, V>>(
        &self,
        mesh: &Mesh,
        materials: &[Material],
        in_block: impl Fn(usize) -> bool + Sync,
        d: impl Fn(&Material) -> [[f64; V]; V],
    ) -> Vec<f64> {
        let ds: Vec<[[f64; V]; V]> = materials.iter().map(d).collect();
        self.assemble(mesh, |bi, _e, x, ke| {
            let block = &mesh.blocks[bi];
            let kind = block.elements.kind;
            if !in_block(bi) {
                let nd = D * kind.nodes();
                ke[..nd * nd].fill(0.0);
                return;
            }
            let mat = &materials[block.material];
            match kind {
                ElementKind::Bar2 => element::bar_stiffness(x, D, mat.e * block.section, ke),
                kind => element::continuum_stiffness::<D, V, K>(
                    kind,
                    x,
                    &ds[block.material],
                    block.section,
                    ke,
                ),
            }
        })
    }

    /// Mass matrix, consistent or row-sum lumped.
    pub fn mass(&self, mesh: &Mesh, materials: &[Material], lumped: bool) -> Mass {
        let dim = mesh.dim;
        let consistent = self.assemble(mesh, |bi, _e, x, me| {
            let block = &mesh.blocks[bi];
            let rho = materials[block.material].rho;
            match block.elements.kind {
                ElementKind::Bar2 => element::bar_mass(x, dim, rho * block.section, me),
                kind => element::continuum_mass(kind, x, rho * block.section, me),
            }
        });
        let m = Mass::Consistent(ConsistentMass::new(&self.pattern, consistent));
        if lumped {
            Mass::Lumped(m.row_sums(&self.pattern))
        } else {
            m
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The consistent mass of a model read from a test scenario.
    fn consistent_mass(scenario: &str) -> (Assembler, ConsistentMass) {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(scenario);
        let model = crate::config::load(&path).expect("the scenario loads");
        let asm = Assembler::new(&model.mesh);
        match asm.mass(&model.mesh, &model.materials, false) {
            Mass::Consistent(m) => (asm, m),
            Mass::Lumped(_) => unreachable!("asked for the consistent mass"),
        }
    }

    #[test]
    fn the_node_pair_mass_gives_the_full_products_bit_for_bit() {
        // Q4 cells; triangles with embedded bars of another density; hexahedra. The
        // fused products run in the copy `Simd::detected` picks, the separate ones in
        // the baseline build: equal bit for bit (theory/gauss_point_pass.md).
        for scenario in [
            "tests/regression/elastic_cantilever.toml",
            "tests/regression/damped_lumped_gravity.toml",
            "tests/regression/solid_elastic_cantilever.toml",
        ] {
            let (asm, m) = consistent_mass(scenario);
            assert!(m.has_pairs(), "{scenario}: every node block is m I");
            let p = &asm.pattern;
            let n = p.n_dofs();
            let x: Vec<f64> = (0..n).map(|i| ((i * 37) % 101) as f64 - 50.0).collect();
            let w: Vec<f64> = (0..n).map(|i| ((i * 11) % 23) as f64 * 1e-3).collect();
            let a: Vec<f64> = (0..p.nnz()).map(|i| ((i * 7) % 19) as f64 - 9.0).collect();
            let (mut full, mut pairs) = (vec![0.0; n], vec![0.0; n]);
            p.matvec(&m, &x, &mut full);
            m.matvec(p, &x, &mut pairs);
            assert!(full.iter().any(|&v| v != 0.0));
            assert_eq!(full, pairs, "{scenario}: M x");
            let (mut y_full, mut z_full) = (vec![0.0; n], vec![0.0; n]);
            let (mut y, mut z) = (vec![0.0; n], vec![0.0; n]);
            p.matvec2(&a, &x, &mut y_full, Stored::Full(&m), &w, &mut z_full);
            Mass::Consistent(m.clone()).with_product(p, &a, &x, &mut y, &w, &mut z);
            assert_eq!(y_full, y, "{scenario}: A x beside M w");
            assert_eq!(z_full, z, "{scenario}: M w beside A x");
            let (mut y_alone, mut z_alone) = (vec![0.0; n], vec![0.0; n]);
            p.matvec(&a, &x, &mut y_alone);
            p.matvec(&m, &w, &mut z_alone);
            assert_eq!(y_alone, y, "{scenario}: A x beside M w and alone");
            assert_eq!(z_alone, z, "{scenario}: M w beside A x and alone");
        }
    }

    #[test]
    fn a_mass_with_coupled_components_keeps_its_full_values() {
        let (asm, m) = consistent_mass("tests/regression/elastic_cantilever.toml");
        let mut values = m.to_vec();
        // Couple x and y in one block of node 3 (symmetrically): no longer m I.
        let p = &asm.pattern;
        let (a, b) = (p.position(3, 1, 3, 0), p.position(3, 0, 3, 1));
        values[a] = 1e-3;
        values[b] = 1e-3;
        let coupled = ConsistentMass::new(p, values.clone());
        assert!(!coupled.has_pairs());
        let n = p.n_dofs();
        let x: Vec<f64> = (0..n).map(|i| (i % 5) as f64).collect();
        let (mut want, mut got) = (vec![0.0; n], vec![0.0; n]);
        p.matvec(&values, &x, &mut want);
        coupled.matvec(p, &x, &mut got);
        assert_eq!(want, got);
        assert_ne!(got[6], {
            let mut plain = vec![0.0; n];
            m.matvec(p, &x, &mut plain);
            plain[6]
        });
    }
}
