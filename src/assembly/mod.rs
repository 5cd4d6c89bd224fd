//! Global assembly: element matrices scattered into the shared sparsity [`Pattern`],
//! in parallel by element colours (no two elements of a colour share a node, so
//! their scatters never touch the same column), plus load vectors.
//!
//! Start with [`Assembler::new`], then [`Assembler::stiffness`] and [`Assembler::mass`].

pub mod internal;
pub mod loads;
pub mod pattern;

use rayon::prelude::*;

use crate::fe::{element, Plane};
use crate::material::Material;
use crate::mesh::{ElementKind, Mesh};
pub use pattern::Pattern;

/// Mass matrix: consistent (on the shared pattern) or lumped (a diagonal).
#[derive(Clone, Debug)]
pub enum Mass {
    /// Values on the shared pattern.
    Consistent(Vec<f64>),
    /// Diagonal entries, one per dof.
    Lumped(Vec<f64>),
}

impl Mass {
    /// `y = M x`.
    pub fn matvec(&self, pattern: &Pattern, x: &[f64], y: &mut [f64]) {
        match self {
            Mass::Consistent(v) => pattern.matvec(v, x, y),
            Mass::Lumped(d) => y
                .par_iter_mut()
                .zip(d.par_iter().zip(x.par_iter()))
                .for_each(|(y, (d, x))| *y = d * x),
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

/// Pattern plus element colours per block: built once per mesh.
pub struct Assembler {
    /// The shared sparsity pattern.
    pub pattern: Pattern,
    /// Element colours of every block.
    pub colours: Vec<Vec<Vec<usize>>>,
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
        Assembler { pattern, colours }
    }

    /// Assembles `Σ_e element(block, e, x_e, out)` where `out` is the row-major element
    /// matrix (`2nn x 2nn`) of element `e`.
    pub fn assemble<F>(&self, mesh: &Mesh, element: F) -> Vec<f64>
    where
        F: Fn(usize, usize, &[[f64; 2]], &mut [f64]) + Sync,
    {
        let mut values = crate::memory::zeroed(self.pattern.nnz());
        let shared = SharedValues(values.as_mut_ptr());
        for (bi, block) in mesh.blocks.iter().enumerate() {
            let nn = block.elements.kind.nodes();
            for colour in &self.colours[bi] {
                colour.par_chunks(256).for_each(|chunk| {
                    // Capture the whole wrapper (Send + Sync), not its raw-pointer field.
                    #[allow(clippy::redundant_locals)]
                    let shared = shared;
                    let mut ke = [0.0; 64];
                    let mut x = [[0.0; 2]; 4];
                    for &e in chunk {
                        let nodes = block.elements.element(e);
                        for (a, &n) in nodes.iter().enumerate() {
                            x[a] = mesh.coords[n];
                        }
                        element(bi, e, &x[..nn], &mut ke);
                        self.scatter(nodes, &ke, shared);
                    }
                });
            }
        }
        values
    }

    #[inline]
    pub(crate) fn scatter(&self, nodes: &[usize], ke: &[f64], shared: SharedValues) {
        let nn = nodes.len();
        let nd = 2 * nn;
        let p = &self.pattern;
        for (b, &nb) in nodes.iter().enumerate() {
            let c0 = p.col_start(nb, 0);
            let c1 = p.col_start(nb, 1);
            for (a, &na) in nodes.iter().enumerate() {
                let k = 2 * p.rank(nb, na);
                // SAFETY: columns of node `nb` are written only by elements holding
                // `nb`, and no two elements of the running colour share a node.
                unsafe {
                    *shared.0.add(c0 + k) += ke[2 * a * nd + 2 * b];
                    *shared.0.add(c0 + k + 1) += ke[(2 * a + 1) * nd + 2 * b];
                    *shared.0.add(c1 + k) += ke[2 * a * nd + 2 * b + 1];
                    *shared.0.add(c1 + k + 1) += ke[(2 * a + 1) * nd + 2 * b + 1];
                }
            }
        }
    }

    /// Elastic stiffness `K` (bars: `EA/L` along the axis).
    pub fn stiffness(&self, mesh: &Mesh, materials: &[Material], plane: Plane) -> Vec<f64> {
        let ds: Vec<[[f64; 3]; 3]> = materials.iter().map(|m| m.c(plane)).collect();
        self.assemble(mesh, |bi, _e, x, ke| {
            let block = &mesh.blocks[bi];
            let mat = &materials[block.material];
            match block.elements.kind {
                ElementKind::Bar2 => element::bar_stiffness(x, mat.e * block.section, ke),
                kind => {
                    element::continuum_stiffness(kind, x, &ds[block.material], block.section, ke)
                }
            }
        })
    }

    /// A stiffness-like matrix `∫ Bᵀ D B t dA` with one `D` per material (bars skipped),
    /// for viscosity matrices and the like.
    pub fn continuum_matrix(&self, mesh: &Mesh, d_of_material: &[[[f64; 3]; 3]]) -> Vec<f64> {
        self.assemble(mesh, |bi, _e, x, ke| {
            let block = &mesh.blocks[bi];
            match block.elements.kind {
                ElementKind::Bar2 => ke[..16].fill(0.0),
                kind => element::continuum_stiffness(
                    kind,
                    x,
                    &d_of_material[block.material],
                    block.section,
                    ke,
                ),
            }
        })
    }

    /// Mass matrix, consistent or row-sum lumped.
    pub fn mass(&self, mesh: &Mesh, materials: &[Material], lumped: bool) -> Mass {
        let consistent = self.assemble(mesh, |bi, _e, x, me| {
            let block = &mesh.blocks[bi];
            let rho = materials[block.material].rho;
            match block.elements.kind {
                ElementKind::Bar2 => element::bar_mass(x, rho * block.section, me),
                kind => element::continuum_mass(kind, x, rho * block.section, me),
            }
        });
        if lumped {
            let m = Mass::Consistent(consistent);
            Mass::Lumped(m.row_sums(&self.pattern))
        } else {
            Mass::Consistent(consistent)
        }
    }
}
