//! Principal frames of Voigt tensors for the isotropic return mappings: the plane's
//! (one angle `θ`, two principal values) and the solid's (a rotation `Q` whose rows
//! are the principal directions, three values). A return works on the principal
//! values alone and asks its frame to carry strains and stresses in and out and to
//! rotate the principal-frame tangent back (`C = Tᵀ C' T` with `ε' = T ε`).

use super::principal::{
    principal, principal_values, principal_voigt6, strain_from_principal, strain_to_frame,
    strain_transform, stress_from_principal,
};

/// The principal frame of a symmetric tensor with `V` Voigt components (engineering
/// shear for strains) and `P` principal values.
pub trait Frame<const V: usize, const P: usize>: Sized {
    /// Voigt positions of the normal components, in the order of the principal
    /// values.
    const NORMAL: [usize; P];
    /// The shears: Voigt position and the two principal directions it couples.
    const SHEARS: &'static [(usize, usize, usize)];

    /// Principal values of a Voigt stress, decreasing (for a yield check that may
    /// not need the frame).
    fn values(sigma: &[f64; V]) -> [f64; P];

    /// The frame of a Voigt stress and its principal values, decreasing.
    fn decompose(sigma: &[f64; V]) -> (Self, [f64; P]);

    /// A Voigt strain's components in this frame (Voigt layout, engineering shear).
    fn strain_to_frame(&self, e: &[f64; V]) -> [f64; V];

    /// The Voigt stress with principal values `a` along this frame.
    fn stress_from(&self, a: &[f64; P]) -> [f64; V];

    /// The Voigt strain with principal values `a` along this frame.
    fn strain_from(&self, a: &[f64; P]) -> [f64; V];

    /// The strain transformation `T` into this frame: `ε' = T ε`.
    fn transform(&self) -> [[f64; V]; V];
}

/// The plane's frame: the first principal direction at angle `θ` from `x`.
pub struct PlaneFrame {
    theta: f64,
}

impl Frame<3, 2> for PlaneFrame {
    const NORMAL: [usize; 2] = [0, 1];
    const SHEARS: &'static [(usize, usize, usize)] = &[(2, 0, 1)];

    fn values(s: &[f64; 3]) -> [f64; 2] {
        let (a, b) = principal_values(s[0], s[1], s[2]);
        [a, b]
    }

    fn decompose(s: &[f64; 3]) -> (Self, [f64; 2]) {
        let theta = principal(s[0], s[1], s[2]).2;
        (PlaneFrame { theta }, Self::values(s))
    }

    fn strain_to_frame(&self, e: &[f64; 3]) -> [f64; 3] {
        strain_to_frame(e, self.theta)
    }

    fn stress_from(&self, a: &[f64; 2]) -> [f64; 3] {
        stress_from_principal(a[0], a[1], self.theta)
    }

    fn strain_from(&self, a: &[f64; 2]) -> [f64; 3] {
        strain_from_principal(a[0], a[1], self.theta)
    }

    fn transform(&self) -> [[f64; 3]; 3] {
        strain_transform(self.theta)
    }
}

/// The tensor index pairs of a solid's Voigt components `[xx, yy, xy, zz, yz, zx]`.
pub const VOIGT6_PAIRS: [(usize, usize); 6] = [(0, 0), (1, 1), (0, 1), (2, 2), (1, 2), (2, 0)];

/// The solid's frame: a rotation whose rows are the principal directions, and its
/// strain transformation (built once: a return reads it twice).
pub struct SolidFrame {
    q: [[f64; 3]; 3],
    t: [[f64; 6]; 6],
}

impl SolidFrame {
    /// The frame with the given principal directions (rows, orthonormal).
    pub fn new(q: [[f64; 3]; 3]) -> Self {
        SolidFrame {
            q,
            t: strain_transformation(&q),
        }
    }

    /// `Σ_k a_k Q_ki Q_kj` in Voigt layout, shears times `shear`.
    fn compose(&self, a: &[f64; 3], shear: f64) -> [f64; 6] {
        std::array::from_fn(|v| {
            let (i, j) = VOIGT6_PAIRS[v];
            let s: f64 = (0..3).map(|k| a[k] * self.q[k][i] * self.q[k][j]).sum();
            if i == j {
                s
            } else {
                shear * s
            }
        })
    }
}

impl Frame<6, 3> for SolidFrame {
    const NORMAL: [usize; 3] = [0, 1, 3];
    const SHEARS: &'static [(usize, usize, usize)] = &[(2, 0, 1), (4, 1, 2), (5, 2, 0)];

    fn values(s: &[f64; 6]) -> [f64; 3] {
        principal_voigt6(s, 1.0)
    }

    fn decompose(s: &[f64; 6]) -> (Self, [f64; 3]) {
        let t = [[s[0], s[2], s[5]], [s[2], s[1], s[4]], [s[5], s[4], s[3]]];
        let (values, q) = eigen_sym3(t);
        (SolidFrame::new(q), values)
    }

    fn strain_to_frame(&self, e: &[f64; 6]) -> [f64; 6] {
        std::array::from_fn(|i| (0..6).map(|j| self.t[i][j] * e[j]).sum())
    }

    fn stress_from(&self, a: &[f64; 3]) -> [f64; 6] {
        self.compose(a, 1.0)
    }

    fn strain_from(&self, a: &[f64; 3]) -> [f64; 6] {
        self.compose(a, 2.0)
    }

    fn transform(&self) -> [[f64; 6]; 6] {
        self.t
    }
}

/// The 6x6 strain transformation into the frame whose rows are `q`:
/// `ε'_ab = Σ_ij Q_ai Q_bj ε_ij`; a Voigt shear `γ_ij = 2 ε_ij` enters through both
/// `ε_ij` and `ε_ji`, and a shear row is `γ'_ab = 2 ε'_ab`.
fn strain_transformation(q: &[[f64; 3]; 3]) -> [[f64; 6]; 6] {
    std::array::from_fn(|r| {
        let (a, b) = VOIGT6_PAIRS[r];
        let row_scale = if a == b { 1.0 } else { 2.0 };
        std::array::from_fn(|c| {
            let (i, j) = VOIGT6_PAIRS[c];
            let v = if i == j {
                q[a][i] * q[b][i]
            } else {
                0.5 * (q[a][i] * q[b][j] + q[a][j] * q[b][i])
            };
            row_scale * v
        })
    })
}

/// Eigenvalues (decreasing) and eigenvectors (the rows of the returned matrix,
/// orthonormal) of a symmetric 3x3 matrix, by cyclic Jacobi rotations: each
/// rotation zeroes one off-diagonal entry exactly, and the sweeps stop when the
/// off-diagonal part is below round-off of the diagonal. Accurate for repeated and
/// nearly repeated eigenvalues, where the closed form loses digits.
pub fn eigen_sym3(mut a: [[f64; 3]; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
    // Columns of `v` are the eigenvectors while rotating.
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _ in 0..32 {
        let off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
        let diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
        if off <= 1e-34 * diag || off == 0.0 {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            // The rotation angle φ with tan 2φ = 2 a_pq / (a_qq − a_pp), taken as the
            // smaller root t = tan φ for stability.
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            // A ← Jᵀ A J with J the rotation in the (p, q) plane.
            for k in 0..3 {
                let (akp, akq) = (a[k][p], a[k][q]);
                a[k][p] = c * akp - s * akq;
                a[k][q] = s * akp + c * akq;
            }
            for k in 0..3 {
                let (apk, aqk) = (a[p][k], a[q][k]);
                a[p][k] = c * apk - s * aqk;
                a[q][k] = s * apk + c * aqk;
            }
            for row in v.iter_mut() {
                let (vp, vq) = (row[p], row[q]);
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }
    let mut order = [0, 1, 2];
    order.sort_by(|&x, &y| a[y][y].total_cmp(&a[x][x]));
    let values = order.map(|k| a[k][k]);
    let vectors = order.map(|k| [v[0][k], v[1][k], v[2][k]]);
    (values, vectors)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check_decomposition(t: [[f64; 3]; 3]) {
        let (l, q) = eigen_sym3(t);
        assert!(l[0] >= l[1] && l[1] >= l[2]);
        let scale = t.iter().flatten().map(|x| x.abs()).fold(0.0, f64::max);
        for i in 0..3 {
            for j in 0..3 {
                let back: f64 = (0..3).map(|k| l[k] * q[k][i] * q[k][j]).sum();
                assert!(
                    (back - t[i][j]).abs() < 1e-14 * scale,
                    "entry {i}{j}: {back} vs {}",
                    t[i][j]
                );
                let dot: f64 = (0..3).map(|k| q[i][k] * q[j][k]).sum();
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((dot - want).abs() < 1e-14, "orthonormal {i}{j}");
            }
        }
    }

    #[test]
    fn jacobi_decomposes_distinct_repeated_and_diagonal_tensors() {
        check_decomposition([[4.0, 1.0, -2.0], [1.0, -3.0, 0.5], [-2.0, 0.5, 1.0]]);
        // A double eigenvalue (2, 2, 5 rotated) and a near-double one.
        check_decomposition([[3.0, 1.0, 1.0], [1.0, 3.0, 1.0], [1.0, 1.0, 3.0]]);
        check_decomposition([[3.0, 1.0, 1.0], [1.0, 3.0 + 1e-9, 1.0], [1.0, 1.0, 3.0]]);
        check_decomposition([[2.0, 0.0, 0.0], [0.0, -7.0, 0.0], [0.0, 0.0, 5.0]]);
        check_decomposition([[1e6, 3e5, 0.0], [3e5, 1e6, 0.0], [0.0, 0.0, 1e6]]);
    }

    #[test]
    fn the_solid_frame_carries_strain_and_stress_consistently() {
        // A rotated strain: its components in the frame of its own stress are
        // diagonal, composing the principal values back gives it again, and the
        // transformation is the one the components follow.
        let e = [1e-3, -4e-4, 6e-4, 2e-4, -3e-4, 5e-4];
        let tensor = [
            [e[0], 0.5 * e[2], 0.5 * e[5]],
            [0.5 * e[2], e[1], 0.5 * e[4]],
            [0.5 * e[5], 0.5 * e[4], e[3]],
        ];
        let (l, q) = eigen_sym3(tensor);
        let f = SolidFrame::new(q);
        let ef = f.strain_to_frame(&e);
        for (k, &n) in SolidFrame::NORMAL.iter().enumerate() {
            assert!((ef[n] - l[k]).abs() < 1e-17);
        }
        for &(s, _, _) in SolidFrame::SHEARS {
            assert!(ef[s].abs() < 1e-17);
        }
        let back = f.strain_from(&l);
        for i in 0..6 {
            assert!((back[i] - e[i]).abs() < 1e-17, "{i}");
        }
        // σ = Tᵀ σ' for the energy σ·ε to be frame independent.
        let sp = [3.0, -1.0, 0.0, 2.0, 0.0, 0.0];
        let s = f.stress_from(&[3.0, -1.0, 2.0]);
        let t = f.transform();
        for i in 0..6 {
            let ts: f64 = (0..6).map(|k| t[k][i] * sp[k]).sum();
            assert!((ts - s[i]).abs() < 1e-14, "{i}");
        }
    }
}
