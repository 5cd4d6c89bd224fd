//! Element matrices and vectors: stiffness, consistent and lumped mass, internal
//! force, for continuum elements (Quad4, Tri3, Hex8, Tet4) and bars. All write into
//! caller-owned slices (row-major `n_dof x n_dof`, `n_dof = dim x nodes`), so the
//! assembly loop allocates nothing.

use super::{
    kinematics, mass_rule, stiffness_rule, ElementKind, Kinematics, PointKinematics,
    MAX_ELEMENT_DOFS,
};

/// The measure of a continuum element: its area (plane kinds, from the Jacobian) or
/// volume (solids), signed by the Jacobian.
pub fn measure(kind: ElementKind, x: &[[f64; 3]]) -> f64 {
    stiffness_rule(kind)
        .iter()
        .map(|&(xi, w)| w * kinematics(kind, x, xi).det_j)
        .sum()
}

/// Continuum element stiffness `∫ Bᵀ D B t dA` (plane, `t` the thickness) or
/// `∫ Bᵀ D B dV` (solid, `t = 1`) into `ke` (zeroed here).
pub fn continuum_stiffness<const D: usize, const V: usize, K: Kinematics<D, V>>(
    kind: ElementKind,
    x: &[[f64; 3]],
    d: &[[f64; V]; V],
    thickness: f64,
    ke: &mut [f64],
) {
    let nn = kind.nodes();
    let nd = D * nn;
    ke[..nd * nd].fill(0.0);
    for &(xi, w) in stiffness_rule(kind) {
        let k = kinematics(kind, x, xi);
        K::add_btdb(&k, nn, d, w * k.det_j * thickness, ke);
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

/// Adds one material point's `w Bᵀ σ` to the element force `fe` in the
/// idealisation `K` (`k` its kinematics), or, for a bar (`k = None`, nodes `x`),
/// the axial force `σ w / L` along it.
#[inline]
pub fn add_point_force<const D: usize, const V: usize, K: Kinematics<D, V>>(
    k: Option<&PointKinematics>,
    x: &[[f64; 3]],
    nn: usize,
    w: f64,
    sigma: &[f64; V],
    fe: &mut [f64; MAX_ELEMENT_DOFS],
) {
    match k {
        Some(k) => K::add_bt_sigma(k, nn, w, sigma, fe),
        None => {
            let (ax, l) = bar_axis(x);
            let n = sigma[0] * w / l;
            for i in 0..D {
                fe[i] -= n * ax[i];
                fe[D + i] += n * ax[i];
            }
        }
    }
}

/// Adds one material point's `w Bᵀ D B` to the element matrix `ke` in the
/// idealisation `K`, or sets a bar's stiffness `D₀₀ w / L` along its axis.
#[inline]
pub fn add_point_tangent<const D: usize, const V: usize, K: Kinematics<D, V>>(
    k: Option<&PointKinematics>,
    x: &[[f64; 3]],
    nn: usize,
    w: f64,
    d: &[[f64; V]; V],
    ke: &mut [f64],
) {
    match k {
        Some(k) => K::add_btdb(k, nn, d, w, ke),
        None => bar_stiffness(x, D, d[0][0] * w / bar_axis(x).1, ke),
    }
}
