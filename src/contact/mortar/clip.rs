//! Plane polygons for the solid's mortar integrals: the overlap of two convex
//! polygons (Sutherland–Hodgman), the local coordinates of a point in a triangle or a
//! bilinear quadrilateral, and a triangle rule exact to degree 5.

use crate::geometry::Vector;

type V2 = Vector<2>;

/// The most corners an overlap has: every edge of both faces (4 + 4) may cut once.
pub const MAX_CORNERS: usize = 8;

/// A convex polygon of at most [`MAX_CORNERS`] corners, counter-clockwise.
#[derive(Clone, Copy, Debug)]
pub struct Polygon {
    corners: [V2; MAX_CORNERS],
    len: usize,
}

impl Polygon {
    /// The polygon with corners `c` in order (at most [`MAX_CORNERS`]).
    pub fn new(c: &[V2]) -> Polygon {
        let mut p = Polygon {
            corners: [[0.0; 2]; MAX_CORNERS],
            len: c.len().min(MAX_CORNERS),
        };
        p.corners[..p.len].copy_from_slice(&c[..p.len]);
        p
    }

    /// The corners.
    pub fn corners(&self) -> &[V2] {
        &self.corners[..self.len]
    }

    /// The signed area (positive counter-clockwise).
    pub fn area(&self) -> f64 {
        let c = self.corners();
        let n = c.len();
        let mut twice = 0.0;
        for i in 0..n {
            let (a, b) = (c[i], c[(i + 1) % n]);
            twice += a[0] * b[1] - a[1] * b[0];
        }
        0.5 * twice
    }

    /// The same polygon, its corners in reverse order.
    pub fn reversed(&self) -> Polygon {
        let mut p = *self;
        p.corners[..p.len].reverse();
        p
    }

    /// The part of `self` inside the convex, counter-clockwise `clip`
    /// (Sutherland–Hodgman: `self` cut by the half-plane left of each of `clip`'s
    /// edges in turn). Empty, or degenerate, where they do not overlap.
    pub fn clipped_by(&self, clip: &Polygon) -> Polygon {
        let mut poly = *self;
        let c = clip.corners();
        let m = c.len();
        for i in 0..m {
            let (a, b) = (c[i], c[(i + 1) % m]);
            let e = [b[0] - a[0], b[1] - a[1]];
            let side = |p: V2| e[0] * (p[1] - a[1]) - e[1] * (p[0] - a[0]);
            let input = poly;
            poly.len = 0;
            let q = input.corners();
            let k = q.len();
            for j in 0..k {
                let (p0, p1) = (q[j], q[(j + 1) % k]);
                let (s0, s1) = (side(p0), side(p1));
                if s0 >= 0.0 {
                    poly.push(p0);
                }
                if (s0 >= 0.0) != (s1 >= 0.0) {
                    let t = s0 / (s0 - s1);
                    poly.push([p0[0] + t * (p1[0] - p0[0]), p0[1] + t * (p1[1] - p0[1])]);
                }
            }
            if poly.len < 3 {
                poly.len = 0;
                break;
            }
        }
        poly
    }

    /// Adds a corner (dropped when full: a convex clip of two quadrilaterals never
    /// fills it).
    fn push(&mut self, p: V2) {
        if self.len < MAX_CORNERS {
            self.corners[self.len] = p;
            self.len += 1;
        }
    }
}

/// The shape functions of a plane triangle or bilinear quadrilateral with corners
/// `c` (counter-clockwise) at the point `p` (the fourth 0 on a triangle): a
/// triangle's barycentric coordinates; a quadrilateral's `¼(1 ± ξ)(1 ± η)` at the
/// `(ξ, η)` Newton's iteration finds from the centre (a few steps for a point
/// inside a convex quadrilateral; one solve for a parallelogram, whose map is
/// affine).
pub fn shape_at(c: &[V2], p: V2) -> [f64; 4] {
    if c.len() == 3 {
        let (e1, e2) = (sub(c[1], c[0]), sub(c[2], c[0]));
        let d = sub(p, c[0]);
        let det = e1[0] * e2[1] - e1[1] * e2[0];
        let a = (d[0] * e2[1] - d[1] * e2[0]) / det;
        let b = (e1[0] * d[1] - e1[1] * d[0]) / det;
        return [1.0 - a - b, a, b, 0.0];
    }
    // A parallelogram's map is affine: one solve.
    let (e1, e2) = (sub(c[1], c[0]), sub(c[3], c[0]));
    let skew = sub(sub(c[2], c[1]), e2);
    let size = e1[0]
        .abs()
        .max(e1[1].abs())
        .max(e2[0].abs())
        .max(e2[1].abs());
    if skew[0].abs().max(skew[1].abs()) <= 1e-14 * size {
        let det = e1[0] * e2[1] - e1[1] * e2[0];
        if det != 0.0 {
            let d = sub(p, c[0]);
            let a = (d[0] * e2[1] - d[1] * e2[0]) / det;
            let b = (e1[0] * d[1] - e1[1] * d[0]) / det;
            return bilinear(2.0 * a - 1.0, 2.0 * b - 1.0);
        }
    }
    let (mut xi, mut eta) = (0.0f64, 0.0f64);
    for _ in 0..25 {
        let n = bilinear(xi, eta);
        let (dxi, deta) = (
            [-(1.0 - eta), 1.0 - eta, 1.0 + eta, -(1.0 + eta)],
            [-(1.0 - xi), -(1.0 + xi), 1.0 + xi, 1.0 - xi],
        );
        let mut r = [-p[0], -p[1]];
        let mut j = [[0.0; 2]; 2];
        for k in 0..4 {
            for i in 0..2 {
                r[i] += n[k] * c[k][i];
                j[i][0] += 0.25 * dxi[k] * c[k][i];
                j[i][1] += 0.25 * deta[k] * c[k][i];
            }
        }
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        if det == 0.0 {
            break;
        }
        let sx = (j[1][1] * r[0] - j[0][1] * r[1]) / det;
        let se = (j[0][0] * r[1] - j[1][0] * r[0]) / det;
        xi -= sx;
        eta -= se;
        if sx.abs().max(se.abs()) < 1e-14 {
            break;
        }
    }
    bilinear(xi, eta)
}

/// `¼(1 ± ξ)(1 ± η)` at the corners `(−1, −1), (1, −1), (1, 1), (−1, 1)`.
fn bilinear(xi: f64, eta: f64) -> [f64; 4] {
    [
        0.25 * (1.0 - xi) * (1.0 - eta),
        0.25 * (1.0 + xi) * (1.0 - eta),
        0.25 * (1.0 + xi) * (1.0 + eta),
        0.25 * (1.0 - xi) * (1.0 + eta),
    ]
}

fn sub(a: V2, b: V2) -> V2 {
    [a[0] - b[0], a[1] - b[1]]
}

/// A seven-point rule on a triangle, exact for polynomials of degree 5 (Radon's):
/// barycentric points and weights summing to 1 (multiply by the area).
pub fn triangle_rule() -> [([f64; 3], f64); 7] {
    let s = 15f64.sqrt();
    let (a1, a2) = ((6.0 - s) / 21.0, (6.0 + s) / 21.0);
    let (w1, w2) = ((155.0 - s) / 1200.0, (155.0 + s) / 1200.0);
    let (b1, b2) = (1.0 - 2.0 * a1, 1.0 - 2.0 * a2);
    [
        ([1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0], 9.0 / 40.0),
        ([a1, a1, b1], w1),
        ([a1, b1, a1], w1),
        ([b1, a1, a1], w1),
        ([a2, a2, b2], w2),
        ([a2, b2, a2], w2),
        ([b2, a2, a2], w2),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(lo: f64, hi: f64) -> Polygon {
        Polygon::new(&[[lo, lo], [hi, lo], [hi, hi], [lo, hi]])
    }

    #[test]
    fn overlaps_of_squares_and_a_triangle_have_their_areas() {
        let a = square(0.0, 1.0);
        assert!((a.clipped_by(&square(0.5, 2.0)).area() - 0.25).abs() < 1e-15);
        assert!((a.clipped_by(&square(-1.0, 2.0)).area() - 1.0).abs() < 1e-15);
        assert_eq!(a.clipped_by(&square(1.5, 2.0)).corners().len(), 0);
        // A triangle cutting the square's corner off: area ½ · 0.5².
        let t = Polygon::new(&[[0.5, 0.0], [1.5, 1.0], [0.5, 1.0]]);
        let o = a.clipped_by(&t);
        assert!((o.area() - (0.5 - 0.125)).abs() < 1e-15, "{}", o.area());
        // A square turned by 45° over the unit square: an octagon.
        let h = 0.75;
        let d = Polygon::new(&[
            [0.5, 0.5 - h],
            [0.5 + h, 0.5],
            [0.5, 0.5 + h],
            [0.5 - h, 0.5],
        ]);
        let o = a.clipped_by(&d);
        assert_eq!(o.corners().len(), 8);
        let cut = 4.0 * 0.5 * (1.0f64 - h).powi(2);
        assert!(
            (o.area() - (1.0 - cut)).abs() < 1e-14,
            "{} {}",
            o.area(),
            1.0 - cut
        );
    }

    #[test]
    fn shape_functions_reproduce_the_point_in_a_skewed_quadrilateral_and_a_triangle() {
        let q = [[0.0, 0.0], [2.0, 0.3], [2.5, 1.7], [-0.2, 1.0]];
        let g = [[0.0, 0.0], [2.0, 0.3], [1.8, 1.3], [-0.2, 1.0]];
        let t = [[0.0, 0.0], [2.0, 0.3], [-0.2, 1.0]];
        for c in [&q[..], &g[..], &t[..]] {
            for p in [[0.4, 0.3], [1.9, 1.2], [0.0, 0.0], [1.0, 0.5]] {
                let n = shape_at(c, p);
                let back = c
                    .iter()
                    .zip(n)
                    .fold([0.0, 0.0], |s, (x, w)| [s[0] + w * x[0], s[1] + w * x[1]]);
                assert!((n.iter().sum::<f64>() - 1.0).abs() < 1e-14);
                assert!((back[0] - p[0]).abs() < 1e-13 && (back[1] - p[1]).abs() < 1e-13);
            }
        }
    }

    #[test]
    fn the_triangle_rule_integrates_degree_five_exactly() {
        // ∫ over the unit triangle of x^a y^b = a! b! / (a + b + 2)!.
        let f = |n: u32| (1..=n).map(f64::from).product::<f64>();
        for a in 0..=5u32 {
            for b in 0..=(5 - a) {
                let q: f64 = triangle_rule()
                    .iter()
                    .map(|(p, w)| 0.5 * w * p[1].powi(a as i32) * p[2].powi(b as i32))
                    .sum();
                let exact = f(a) * f(b) / f(a + b + 2);
                assert!((q - exact).abs() < 1e-15, "x^{a} y^{b}: {q} vs {exact}");
            }
        }
    }
}
