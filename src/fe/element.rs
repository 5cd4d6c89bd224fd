//! Element matrices and vectors: stiffness, consistent and lumped mass, internal
//! force, for continuum elements (Quad4, Tri3, Hex8, Tet4) and bars. All write into
//! caller-owned slices (row-major `n_dof x n_dof`, `n_dof = dim x nodes`), so the
//! assembly loop allocates nothing.

use super::{kinematics, mass_rule, stiffness_rule, ElementKind, PointKinematics};

/// An elasticity matrix in Voigt form: the plane's 3x3 or the solid's 6x6. Its
/// `Bᵀ D B` and `Bᵀ σ` are the element kernels of its dimension.
pub trait Voigt: Copy + Sync {
    /// Adds `w Bᵀ D B` at one point to the element matrix `ke` (row-major).
    fn add_btdb(&self, k: &PointKinematics, nn: usize, w: f64, ke: &mut [f64]);
}

impl Voigt for [[f64; 3]; 3] {
    #[inline]
    fn add_btdb(&self, k: &PointKinematics, nn: usize, w: f64, ke: &mut [f64]) {
        add_btdb(k, nn, self, w, ke)
    }
}

impl Voigt for [[f64; 6]; 6] {
    #[inline]
    fn add_btdb(&self, k: &PointKinematics, nn: usize, w: f64, ke: &mut [f64]) {
        add_btdb_solid(k, nn, self, w, ke)
    }
}

/// The rows of `B` of node `a` of a solid: `B_a` is 6x3, row `i` the Voigt
/// component `i` (order of `fe`).
#[inline]
fn b_solid(g: [f64; 3]) -> [[f64; 3]; 6] {
    let [x, y, z] = g;
    [
        [x, 0.0, 0.0],
        [0.0, y, 0.0],
        [y, x, 0.0],
        [0.0, 0.0, z],
        [0.0, z, y],
        [z, 0.0, x],
    ]
}

/// Adds `w Bᵀ D B` of a solid at one point to `ke` (row-major, `3nn x 3nn`).
#[inline]
pub fn add_btdb_solid(k: &PointKinematics, nn: usize, d: &[[f64; 6]; 6], w: f64, ke: &mut [f64]) {
    let nd = 3 * nn;
    for b in 0..nn {
        let bb = b_solid(k.dndx[b]);
        // D B_b (6x3)
        let mut db = [[0.0; 3]; 6];
        for i in 0..6 {
            for j in 0..3 {
                db[i][j] = (0..6).map(|l| d[i][l] * bb[l][j]).sum();
            }
        }
        for a in 0..nn {
            let ba = b_solid(k.dndx[a]);
            for r in 0..3 {
                for c in 0..3 {
                    let v: f64 = (0..6).map(|l| ba[l][r] * db[l][c]).sum();
                    ke[(3 * a + r) * nd + 3 * b + c] += w * v;
                }
            }
        }
    }
}

/// The measure of a continuum element: its area (plane kinds, from the Jacobian) or
/// volume (solids), signed by the Jacobian.
pub fn measure(kind: ElementKind, x: &[[f64; 3]]) -> f64 {
    stiffness_rule(kind)
        .iter()
        .map(|&(xi, w)| w * kinematics(kind, x, xi).det_j)
        .sum()
}

/// Adds `w Bᵀ D B` at one point to the element matrix `ke` (row-major, `2nn x 2nn`).
#[inline]
pub fn add_btdb(k: &PointKinematics, nn: usize, d: &[[f64; 3]; 3], w: f64, ke: &mut [f64]) {
    let nd = 2 * nn;
    for a in 0..nn {
        let (ax, ay) = (k.dndx[a][0], k.dndx[a][1]);
        // Rows of Bᵀ for node a: dof x -> [ax, 0, ay], dof y -> [0, ay, ax]
        // (D B)_b columns: for node b, x: D[:,0]*bx + D[:,2]*by, y: D[:,1]*by + D[:,2]*bx
        for b in 0..nn {
            let (bx, by) = (k.dndx[b][0], k.dndx[b][1]);
            let mut dbx = [0.0; 3];
            let mut dby = [0.0; 3];
            for i in 0..3 {
                dbx[i] = d[i][0] * bx + d[i][2] * by;
                dby[i] = d[i][1] * by + d[i][2] * bx;
            }
            let kxx = ax * dbx[0] + ay * dbx[2];
            let kxy = ax * dby[0] + ay * dby[2];
            let kyx = ay * dbx[1] + ax * dbx[2];
            let kyy = ay * dby[1] + ax * dby[2];
            let r = 2 * a;
            let c = 2 * b;
            ke[r * nd + c] += w * kxx;
            ke[r * nd + c + 1] += w * kxy;
            ke[(r + 1) * nd + c] += w * kyx;
            ke[(r + 1) * nd + c + 1] += w * kyy;
        }
    }
}

/// Continuum element stiffness `∫ Bᵀ D B t dA` (plane, `t` the thickness) or
/// `∫ Bᵀ D B dV` (solid, `t = 1`) into `ke` (zeroed here).
pub fn continuum_stiffness<D: Voigt>(
    kind: ElementKind,
    x: &[[f64; 3]],
    d: &D,
    thickness: f64,
    ke: &mut [f64],
) {
    let nn = kind.nodes();
    let nd = kind.dim() * nn;
    ke[..nd * nd].fill(0.0);
    for &(xi, w) in stiffness_rule(kind) {
        let k = kinematics(kind, x, xi);
        d.add_btdb(&k, nn, w * k.det_j * thickness, ke);
    }
}

/// Continuum consistent mass `∫ ρ Nᵀ N t dA` (solids: `dV`) into `me` (zeroed here).
pub fn continuum_mass(kind: ElementKind, x: &[[f64; 3]], rho_t: f64, me: &mut [f64]) {
    let nn = kind.nodes();
    let dim = kind.dim();
    let nd = dim * nn;
    me[..nd * nd].fill(0.0);
    for &(xi, w) in mass_rule(kind) {
        let k = kinematics(kind, x, xi);
        let f = w * k.det_j * rho_t;
        for a in 0..nn {
            for b in 0..nn {
                let m = f * k.n[a] * k.n[b];
                for i in 0..dim {
                    me[(dim * a + i) * nd + dim * b + i] += m;
                }
            }
        }
    }
}

/// Unit axis and length of a bar.
#[inline]
pub fn bar_axis(x: &[[f64; 3]]) -> ([f64; 3], f64) {
    let d = [x[1][0] - x[0][0], x[1][1] - x[0][1], x[1][2] - x[0][2]];
    let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    ([d[0] / l, d[1] / l, d[2] / l], l)
}

/// Bar stiffness `EA/L (e⊗e)` in the `2d x 2d` block pattern of a mesh of dimension
/// `dim`, into `ke` (row-major).
pub fn bar_stiffness(x: &[[f64; 3]], dim: usize, ea: f64, ke: &mut [f64]) {
    let (e, l) = bar_axis(x);
    let k = ea / l;
    let nd = 2 * dim;
    for i in 0..dim {
        for j in 0..dim {
            let v = k * e[i] * e[j];
            ke[i * nd + j] = v;
            ke[(i + dim) * nd + j + dim] = v;
            ke[i * nd + j + dim] = -v;
            ke[(i + dim) * nd + j] = -v;
        }
    }
}

/// Bar consistent mass `ρAL/6 [2 1; 1 2]` per direction, into `me` (`2d x 2d`).
pub fn bar_mass(x: &[[f64; 3]], dim: usize, rho_a: f64, me: &mut [f64]) {
    let (_, l) = bar_axis(x);
    let m = rho_a * l / 6.0;
    let nd = 2 * dim;
    me[..nd * nd].fill(0.0);
    for i in 0..dim {
        me[i * nd + i] = 2.0 * m;
        me[(i + dim) * nd + i + dim] = 2.0 * m;
        me[i * nd + i + dim] = m;
        me[(i + dim) * nd + i] = m;
    }
}

/// Axial strain of a bar from its element displacements (`dim` per node).
#[inline]
pub fn bar_strain(x: &[[f64; 3]], dim: usize, ue: &[f64]) -> f64 {
    let (e, l) = bar_axis(x);
    (0..dim).fold(0.0, |s, i| s + (ue[dim + i] - ue[i]) * e[i]) / l
}
