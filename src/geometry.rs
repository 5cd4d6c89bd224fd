//! Small fixed vectors `[f64; D]` of the plane (`D = 2`) and of space (`D = 3`): the
//! arithmetic contact detection, the collision times, the surface normals and the
//! mesh's face areas share.
//!
//! Every sum runs left to right over the components (`a₀b₀ + a₁b₁ + a₂b₂`), as
//! written out by hand, so that a function here gives the same bits as the
//! expression it replaces; [`axpy`] alone is fused (`t.mul_add(y, x)`), as the
//! collision times' polynomials need.

/// A point or a vector of the plane or of space.
pub type Vector<const D: usize> = [f64; D];

/// `a − b`.
#[inline]
pub fn sub<const D: usize>(a: Vector<D>, b: Vector<D>) -> Vector<D> {
    std::array::from_fn(|i| a[i] - b[i])
}

/// `a + b`.
#[inline]
pub fn add<const D: usize>(a: Vector<D>, b: Vector<D>) -> Vector<D> {
    std::array::from_fn(|i| a[i] + b[i])
}

/// `s a`.
#[inline]
pub fn scale<const D: usize>(a: Vector<D>, s: f64) -> Vector<D> {
    std::array::from_fn(|i| a[i] * s)
}

/// `x + t y`, each component one fused multiply-add.
#[inline]
pub fn axpy<const D: usize>(x: Vector<D>, t: f64, y: Vector<D>) -> Vector<D> {
    std::array::from_fn(|i| t.mul_add(y[i], x[i]))
}

/// `a + t (b − a)`: the point at `t` on the segment from `a` to `b`.
#[inline]
pub fn lerp<const D: usize>(a: Vector<D>, b: Vector<D>, t: f64) -> Vector<D> {
    std::array::from_fn(|i| a[i] + t * (b[i] - a[i]))
}

/// `a · b`, summed left to right.
#[inline]
pub fn dot<const D: usize>(a: Vector<D>, b: Vector<D>) -> f64 {
    let mut s = a[0] * b[0];
    for i in 1..D {
        s += a[i] * b[i];
    }
    s
}

/// `|a|` as `√(a · a)`.
#[inline]
pub fn norm<const D: usize>(a: Vector<D>) -> f64 {
    dot(a, a).sqrt()
}

/// `|a − b|`.
#[inline]
pub fn distance<const D: usize>(a: Vector<D>, b: Vector<D>) -> f64 {
    norm(sub(a, b))
}

/// `a / |a|`; `None` for the zero vector and for one whose length overflows or is
/// NaN.
#[inline]
pub fn unit<const D: usize>(a: Vector<D>) -> Option<Vector<D>> {
    let l = norm(a);
    (l > 0.0 && l.is_finite()).then(|| std::array::from_fn(|i| a[i] / l))
}

/// `a × b` in space.
#[inline]
pub fn cross(a: Vector<3>, b: Vector<3>) -> Vector<3> {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `a₀b₁ − a₁b₀`: the plane's cross product (the `z` component of `a × b`).
#[inline]
pub fn perp_dot(a: Vector<2>, b: Vector<2>) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// `det[x, y, z] = (x × y) · z`.
#[inline]
pub fn det3(x: Vector<3>, y: Vector<3>, z: Vector<3>) -> f64 {
    dot(cross(x, y), z)
}

/// The outward unit normal `(Δy, −Δx)/L` of the segment from `a` to `b` of a body
/// lying on its left, and the segment's length `L`; zero (both) for a segment of no
/// length.
#[inline]
pub fn outward(a: Vector<2>, b: Vector<2>) -> (Vector<2>, f64) {
    let d = sub(b, a);
    let l = norm(d);
    if l > 0.0 {
        ([d[1] / l, -d[0] / l], l)
    } else {
        ([0.0, 0.0], 0.0)
    }
}

/// The area of the triangle `a b c` in space.
#[inline]
pub fn triangle_area(a: Vector<3>, b: Vector<3>, c: Vector<3>) -> f64 {
    0.5 * norm(cross(sub(b, a), sub(c, a)))
}

/// Two unit tangents orthonormal with the unit vector `n`: the coordinate axis
/// after `n`'s largest component (cyclically) projected on the plane normal to `n`,
/// and `n ×` it. A function of the normal alone, continuous while the largest
/// component stays the same (normals within 45° of an axis), so the tangents of a
/// slave passing from a face to its neighbour (the interpolated normal is
/// continuous there) are the same and its tangential forces keep their meaning.
/// Rigid planes take them at validation.
pub fn tangents(n: Vector<3>) -> [Vector<3>; 2] {
    let k = (0..3)
        .max_by(|&a, &b| n[a].abs().total_cmp(&n[b].abs()))
        .unwrap_or(0);
    let mut a = [0.0; 3];
    a[(k + 1) % 3] = 1.0;
    let an = dot(a, n);
    let t1 = unit(sub(a, [an * n[0], an * n[1], an * n[2]])).unwrap_or([1.0, 0.0, 0.0]);
    [t1, cross(n, t1)]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_functions_give_the_bits_of_the_expressions_written_out() {
        let (a, b, c) = (
            [0.1, -2.7, 1e-3],
            [3.3, 0.25, -7.5],
            [-1.0 / 3.0, 2.0 / 7.0, 5.0],
        );
        assert_eq!(
            dot(a, b).to_bits(),
            (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]).to_bits()
        );
        assert_eq!(
            norm(a).to_bits(),
            (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt().to_bits()
        );
        // A sum of negative zeros stays a negative zero.
        assert!(dot([-0.0, 0.0], [1.0, -1.0]).is_sign_negative());
        let x = cross(a, b);
        assert!(dot(x, a).abs() < 1e-14 && dot(x, b).abs() < 1e-14);
        assert_eq!(det3(a, b, c), dot(cross(a, b), c));
        assert_eq!(perp_dot([1.0, 0.0], [0.0, 1.0]), 1.0);
        let (n, l) = outward([0.0, 0.0], [2.0, 0.0]);
        assert_eq!((n, l), ([0.0, -1.0], 2.0));
        assert_eq!(outward([1.0, 1.0], [1.0, 1.0]), ([0.0, 0.0], 0.0));
        assert_eq!(unit([0.0; 3]), None);
        assert_eq!(unit([f64::NAN, 0.0]), None);
        assert_eq!(unit([3.0, 4.0]), Some([0.6, 0.8]));
        assert_eq!(lerp([1.0, 2.0], [3.0, 6.0], 0.5), [2.0, 4.0]);
        assert_eq!(axpy([1.0, 2.0], 2.0, [0.5, 0.25]), [2.0, 2.5]);
        assert_eq!(
            triangle_area([0.0; 3], [2.0, 0.0, 0.0], [0.0, 3.0, 0.0]),
            3.0
        );
    }

    #[test]
    fn tangents_are_orthonormal_with_the_normal() {
        for n in [
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
            [1.0, 0.0, 0.0],
            [0.3, -0.2, 0.9327379053088815],
        ] {
            let n = unit(n).unwrap();
            {
                let t = tangents(n);
                assert!(dot(t[0], n).abs() < 1e-15 && dot(t[1], n).abs() < 1e-15);
                assert!(dot(t[0], t[1]).abs() < 1e-15);
                assert!((dot(t[0], t[0]) - 1.0).abs() < 1e-15);
                assert!((dot(t[1], t[1]) - 1.0).abs() < 1e-15);
                // Right-handed: t1 × t2 = n.
                let c = cross(t[0], t[1]);
                assert!(dot(sub(c, n), sub(c, n)) < 1e-28);
            }
        }
    }
}
