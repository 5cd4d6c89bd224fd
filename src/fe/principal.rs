//! Principal values and frames of plane Voigt tensors, and the strain components of
//! the third direction that the damage laws need.

/// Principal values `(a1 ≥ a2)` and angle `θ` of the first principal direction
/// `(cos θ, sin θ)` of a symmetric 2D tensor given by `xx, yy, xy` (tensor shear).
#[inline]
pub fn principal(xx: f64, yy: f64, xy: f64) -> (f64, f64, f64) {
    let c = 0.5 * (xx + yy);
    let d = 0.5 * (xx - yy);
    let r = (d * d + xy * xy).sqrt();
    (c + r, c - r, if r > 0.0 { 0.5 * xy.atan2(d) } else { 0.0 })
}

/// Principal values `(a1 ≥ a2)` alone (the same values as [`principal`], without
/// the angle's `atan2`: for checks that rarely need the frame).
#[inline]
pub fn principal_values(xx: f64, yy: f64, xy: f64) -> (f64, f64) {
    let c = 0.5 * (xx + yy);
    let d = 0.5 * (xx - yy);
    let r = (d * d + xy * xy).sqrt();
    (c + r, c - r)
}

/// The three eigenvalues, in decreasing order, of the symmetric tensor with
/// diagonal `d = [xx, yy, zz]` and off-diagonal `o = [xy, yz, zx]` (tensor
/// components): the trigonometric solution of the characteristic cubic about the
/// mean, exact to round-off for any symmetric tensor (a diagonal one returns its
/// diagonal sorted).
pub fn eigenvalues_sym3(d: [f64; 3], o: [f64; 3]) -> [f64; 3] {
    let p1 = o[0] * o[0] + o[1] * o[1] + o[2] * o[2];
    let mut e = if p1 == 0.0 {
        d
    } else {
        let q = (d[0] + d[1] + d[2]) / 3.0;
        let (a, b, c) = (d[0] - q, d[1] - q, d[2] - q);
        let p2 = a * a + b * b + c * c + 2.0 * p1;
        let p = (p2 / 6.0).sqrt();
        if p == 0.0 {
            [q; 3]
        } else {
            // B = (A − q I)/p; r = det(B)/2 ∈ [−1, 1].
            let det = a * (b * c - o[1] * o[1]) - o[0] * (o[0] * c - o[1] * o[2])
                + o[2] * (o[0] * o[1] - b * o[2]);
            let r = (det / (2.0 * p * p * p)).clamp(-1.0, 1.0);
            let phi = r.acos() / 3.0;
            let e1 = q + 2.0 * p * phi.cos();
            let e3 = q + 2.0 * p * (phi + 2.0 * std::f64::consts::PI / 3.0).cos();
            [e1, 3.0 * q - e1 - e3, e3]
        }
    };
    e.sort_by(|x, y| y.total_cmp(x));
    e
}

/// Principal values of a solid's Voigt vector `[xx, yy, s_xy, zz, s_yz, s_zx]`
/// whose shears are `shear_scale` times the tensor's (1/2 for engineering strains,
/// 1 for stresses).
pub fn principal_voigt6(v: &[f64], shear_scale: f64) -> [f64; 3] {
    eigenvalues_sym3(
        [v[0], v[1], v[3]],
        [shear_scale * v[2], shear_scale * v[4], shear_scale * v[5]],
    )
}

/// Principal stresses of a Voigt stress `[σ_xx, σ_yy, σ_xy]`.
#[inline]
pub fn principal_stress(s: &[f64; 3]) -> (f64, f64, f64) {
    principal(s[0], s[1], s[2])
}

/// Components in the frame rotated by `θ` of a Voigt strain (engineering shear).
#[inline]
pub fn strain_to_frame(e: &[f64; 3], theta: f64) -> [f64; 3] {
    let (s, c) = theta.sin_cos();
    [
        c * c * e[0] + s * s * e[1] + c * s * e[2],
        s * s * e[0] + c * c * e[1] - c * s * e[2],
        -2.0 * c * s * e[0] + 2.0 * c * s * e[1] + (c * c - s * s) * e[2],
    ]
}

/// The strain transformation matrix `T_ε(θ)` (engineering shear): `ε' = T_ε ε`.
#[inline]
pub fn strain_transform(theta: f64) -> [[f64; 3]; 3] {
    let (s, c) = theta.sin_cos();
    [
        [c * c, s * s, c * s],
        [s * s, c * c, -c * s],
        [-2.0 * c * s, 2.0 * c * s, c * c - s * s],
    ]
}

/// Voigt stress with principal values `a1, a2` along the frame at `θ`.
#[inline]
pub fn stress_from_principal(a1: f64, a2: f64, theta: f64) -> [f64; 3] {
    let (s, c) = theta.sin_cos();
    [
        c * c * a1 + s * s * a2,
        s * s * a1 + c * c * a2,
        c * s * (a1 - a2),
    ]
}

/// Voigt strain (engineering shear) with principal values `a1, a2` at `θ`.
#[inline]
pub fn strain_from_principal(a1: f64, a2: f64, theta: f64) -> [f64; 3] {
    let (s, c) = theta.sin_cos();
    [
        c * c * a1 + s * s * a2,
        s * s * a1 + c * c * a2,
        2.0 * c * s * (a1 - a2),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip() {
        let e = [1e-3, -4e-4, 6e-4];
        // Principal strains of a Voigt strain (engineering shear): tensor shear γ/2.
        let (a1, a2, th) = principal(e[0], e[1], 0.5 * e[2]);
        assert_eq!(principal_values(e[0], e[1], 0.5 * e[2]), (a1, a2));
        let back = strain_from_principal(a1, a2, th);
        for i in 0..3 {
            assert!((back[i] - e[i]).abs() < 1e-15);
        }
        let f = strain_to_frame(&e, th);
        assert!((f[0] - a1).abs() < 1e-15 && (f[1] - a2).abs() < 1e-15 && f[2].abs() < 1e-15);
        let s = [3e6, -1e6, 2e6];
        let (b1, b2, t2) = principal_stress(&s);
        let sb = stress_from_principal(b1, b2, t2);
        for i in 0..3 {
            assert!((sb[i] - s[i]).abs() < 1e-8);
        }
    }
}
