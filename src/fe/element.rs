//! Element matrices and vectors: stiffness, consistent and lumped mass, internal
//! force, for continuum elements (Quad4, Tri3) and bars. All write into caller-owned
//! slices (row-major `n_dof x n_dof`), so the assembly loop allocates nothing.

use super::{kinematics, mass_rule, stiffness_rule, ElementKind, PointKinematics};

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

/// Continuum element stiffness `∫ Bᵀ D B t dA` into `ke` (zeroed here).
pub fn continuum_stiffness(
    kind: ElementKind,
    x: &[[f64; 2]],
    d: &[[f64; 3]; 3],
    thickness: f64,
    ke: &mut [f64],
) {
    let nn = kind.nodes();
    ke[..4 * nn * nn].fill(0.0);
    for &(xi, w) in stiffness_rule(kind) {
        let k = kinematics(kind, x, xi);
        add_btdb(&k, nn, d, w * k.det_j * thickness, ke);
    }
}

/// Continuum consistent mass `∫ ρ Nᵀ N t dA` into `me` (zeroed here).
pub fn continuum_mass(kind: ElementKind, x: &[[f64; 2]], rho_t: f64, me: &mut [f64]) {
    let nn = kind.nodes();
    let nd = 2 * nn;
    me[..nd * nd].fill(0.0);
    for &(xi, w) in mass_rule(kind) {
        let k = kinematics(kind, x, xi);
        let f = w * k.det_j * rho_t;
        for a in 0..nn {
            for b in 0..nn {
                let m = f * k.n[a] * k.n[b];
                me[2 * a * nd + 2 * b] += m;
                me[(2 * a + 1) * nd + 2 * b + 1] += m;
            }
        }
    }
}

/// Unit axis and length of a bar.
#[inline]
pub fn bar_axis(x: &[[f64; 2]]) -> ([f64; 2], f64) {
    let d = [x[1][0] - x[0][0], x[1][1] - x[0][1]];
    let l = (d[0] * d[0] + d[1] * d[1]).sqrt();
    ([d[0] / l, d[1] / l], l)
}

/// Bar stiffness `EA/L (e⊗e)` in the 4x4 block pattern, into `ke` (row-major 4x4).
pub fn bar_stiffness(x: &[[f64; 2]], ea: f64, ke: &mut [f64]) {
    let (e, l) = bar_axis(x);
    let k = ea / l;
    for i in 0..2 {
        for j in 0..2 {
            let v = k * e[i] * e[j];
            ke[i * 4 + j] = v;
            ke[(i + 2) * 4 + j + 2] = v;
            ke[i * 4 + j + 2] = -v;
            ke[(i + 2) * 4 + j] = -v;
        }
    }
}

/// Bar consistent mass `ρAL/6 [2 1; 1 2]` per direction, into `me` (4x4).
pub fn bar_mass(x: &[[f64; 2]], rho_a: f64, me: &mut [f64]) {
    let (_, l) = bar_axis(x);
    let m = rho_a * l / 6.0;
    me[..16].fill(0.0);
    for i in 0..2 {
        me[i * 4 + i] = 2.0 * m;
        me[(i + 2) * 4 + i + 2] = 2.0 * m;
        me[i * 4 + i + 2] = m;
        me[(i + 2) * 4 + i] = m;
    }
}

/// Axial strain of a bar from its element displacements.
#[inline]
pub fn bar_strain(x: &[[f64; 2]], ue: &[f64]) -> f64 {
    let (e, l) = bar_axis(x);
    ((ue[2] - ue[0]) * e[0] + (ue[3] - ue[1]) * e[1]) / l
}
