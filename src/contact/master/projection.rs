//! The closest point of a face to a point: a triangle's by its Voronoi regions, a
//! bilinear quadrilateral's by Gauss-Newton on its map, clamped to its edges; the
//! face's shape functions there, where the point lies on it, and the face's normal.
//! The narrow phase of a face master ([`super::faces`]) and of the overlap test.

use crate::geometry::{cross, dot, sub, unit};
use crate::mesh::Face;

type V3 = [f64; 3];

/// Where on a face its closest point to a slave lies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Region {
    /// Inside; `margin` the local distance to the nearest edge (0 on it).
    Interior {
        /// Distance to the nearest edge in local coordinates (a triangle's smallest
        /// barycentric coordinate, a quadrilateral's `1 − max(|ξ|, |η|)`).
        margin: f64,
    },
    /// On the edge from corner `i` to corner `i + 1` (cyclically).
    Edge(usize),
    /// At corner `i`.
    Corner(usize),
}

/// The closest point of a face to a slave: the corners' weights (the face's shape
/// functions there, summing to 1), the point, where it lies, and the face's unit
/// normal there.
#[derive(Clone, Copy, Debug)]
pub struct Projection {
    /// Shape function of each corner at the point (the fourth 0 on a triangle).
    pub weights: [f64; 4],
    /// The closest point.
    pub point: V3,
    /// Distance² from the slave.
    pub d2: f64,
    /// Where it lies.
    pub region: Region,
    /// The face's unit outward normal at the point.
    pub normal: V3,
}

/// The closest point of triangle `a, b, c` to `p` (Voronoi regions of the corners,
/// edges and the inside).
fn triangle(p: V3, [a, b, c]: [V3; 3]) -> Option<Projection> {
    let normal = unit(cross(sub(b, a), sub(c, a)))?;
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    let done = |w: [f64; 3], region| {
        let q = [
            w[0] * a[0] + w[1] * b[0] + w[2] * c[0],
            w[0] * a[1] + w[1] * b[1] + w[2] * c[1],
            w[0] * a[2] + w[1] * b[2] + w[2] * c[2],
        ];
        let d = sub(p, q);
        Some(Projection {
            weights: [w[0], w[1], w[2], 0.0],
            point: q,
            d2: dot(d, d),
            region,
            normal,
        })
    };
    if d1 <= 0.0 && d2 <= 0.0 {
        return done([1.0, 0.0, 0.0], Region::Corner(0));
    }
    let bp = sub(p, b);
    let (d3, d4) = (dot(ab, bp), dot(ac, bp));
    if d3 >= 0.0 && d4 <= d3 {
        return done([0.0, 1.0, 0.0], Region::Corner(1));
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return done([1.0 - v, v, 0.0], Region::Edge(0));
    }
    let cp = sub(p, c);
    let (d5, d6) = (dot(ab, cp), dot(ac, cp));
    if d6 >= 0.0 && d5 <= d6 {
        return done([0.0, 0.0, 1.0], Region::Corner(2));
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return done([1.0 - w, 0.0, w], Region::Edge(2));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return done([0.0, 1.0 - w, w], Region::Edge(1));
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    let u = 1.0 - v - w;
    done(
        [u, v, w],
        Region::Interior {
            margin: u.min(v).min(w),
        },
    )
}

/// Shape functions of the bilinear quadrilateral at `(ξ, η)` and their derivatives.
fn bilinear(xi: f64, eta: f64) -> ([f64; 4], [f64; 4], [f64; 4]) {
    let (sx, sy) = ([-1.0, 1.0, 1.0, -1.0], [-1.0, -1.0, 1.0, 1.0]);
    let mut n = [0.0; 4];
    let mut dx = [0.0; 4];
    let mut dy = [0.0; 4];
    for k in 0..4 {
        n[k] = 0.25 * (1.0 + sx[k] * xi) * (1.0 + sy[k] * eta);
        dx[k] = 0.25 * sx[k] * (1.0 + sy[k] * eta);
        dy[k] = 0.25 * sy[k] * (1.0 + sx[k] * xi);
    }
    (n, dx, dy)
}

fn combine4(w: [f64; 4], x: &[V3; 4]) -> V3 {
    let mut q = [0.0; 3];
    for k in 0..4 {
        for i in 0..3 {
            q[i] += w[k] * x[k][i];
        }
    }
    q
}

/// The closest point of the bilinear quadrilateral with corners `x` to `p`:
/// Gauss-Newton on `(ξ, η)` from the centre; outside `[−1, 1]²` the nearest point
/// of its four edges.
fn quadrilateral(p: V3, x: [V3; 4]) -> Option<Projection> {
    let (mut xi, mut eta) = (0.0f64, 0.0f64);
    for _ in 0..20 {
        let (n, dx, dy) = bilinear(xi, eta);
        let (q, tx, ty) = (combine4(n, &x), combine4(dx, &x), combine4(dy, &x));
        let r = sub(p, q);
        let (a, b, c) = (dot(tx, tx), dot(tx, ty), dot(ty, ty));
        let det = a * c - b * b;
        // A degenerate face (NaN counts as one).
        if det.is_nan() || det <= 0.0 {
            return None;
        }
        let (gx, gy) = (dot(tx, r), dot(ty, r));
        let (sx, sy) = ((c * gx - b * gy) / det, (a * gy - b * gx) / det);
        xi = (xi + sx).clamp(-2.0, 2.0);
        eta = (eta + sy).clamp(-2.0, 2.0);
        if sx.abs().max(sy.abs()) < 1e-14 {
            break;
        }
    }
    if xi.abs() <= 1.0 && eta.abs() <= 1.0 {
        let (n, dx, dy) = bilinear(xi, eta);
        let q = combine4(n, &x);
        let normal = unit(cross(combine4(dx, &x), combine4(dy, &x)))?;
        let d = sub(p, q);
        return Some(Projection {
            weights: n,
            point: q,
            d2: dot(d, d),
            region: Region::Interior {
                margin: 1.0 - xi.abs().max(eta.abs()),
            },
            normal,
        });
    }
    // The nearest point of the edges, the normal at the centre (where a convex
    // ridge's own normal does not replace it).
    let (_, dx, dy) = bilinear(0.0, 0.0);
    let normal = unit(cross(combine4(dx, &x), combine4(dy, &x)))?;
    let mut best: Option<Projection> = None;
    for e in 0..4 {
        let (a, b) = (x[e], x[(e + 1) % 4]);
        let d = sub(b, a);
        let l2 = dot(d, d);
        let s = if l2 > 0.0 {
            (dot(sub(p, a), d) / l2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let q = [a[0] + s * d[0], a[1] + s * d[1], a[2] + s * d[2]];
        let r = sub(p, q);
        let d2 = dot(r, r);
        if best.is_none_or(|b| d2 < b.d2) {
            let mut weights = [0.0; 4];
            weights[e] = 1.0 - s;
            weights[(e + 1) % 4] = s;
            let region = if s <= 0.0 {
                Region::Corner(e)
            } else if s >= 1.0 {
                Region::Corner((e + 1) % 4)
            } else {
                Region::Edge(e)
            };
            best = Some(Projection {
                weights,
                point: q,
                d2,
                region,
                normal,
            });
        }
    }
    best
}

/// The closest point of `face` (corner positions from `x`) to `p`; `None` for a
/// degenerate face.
pub fn project<X: Fn(usize) -> V3>(p: V3, face: &Face, x: &X) -> Option<Projection> {
    if face.is_triangle() {
        triangle(p, [x(face[0]), x(face[1]), x(face[2])])
    } else {
        quadrilateral(p, [x(face[0]), x(face[1]), x(face[2]), x(face[3])])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_triangle_and_a_quadrilateral_project_a_point_inside_and_beyond() {
        let tri = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let pr = triangle([0.25, 0.25, 0.5], tri).unwrap();
        assert!(matches!(pr.region, Region::Interior { .. }));
        assert!((pr.d2 - 0.25).abs() < 1e-15 && pr.normal == [0.0, 0.0, 1.0]);
        assert!((pr.weights[0] - 0.5).abs() < 1e-15 && (pr.weights[1] - 0.25).abs() < 1e-15);
        let pr = triangle([1.0, 1.0, 0.0], tri).unwrap();
        assert_eq!(pr.region, Region::Edge(1));
        assert!((pr.weights[1] - 0.5).abs() < 1e-15 && (pr.d2 - 0.5).abs() < 1e-15);
        assert_eq!(
            triangle([-1.0, -1.0, 1.0], tri).unwrap().region,
            Region::Corner(0)
        );
        // A warped quadrilateral: the projection is where the bilinear map's
        // tangents are normal to the distance.
        let quad = [
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.1],
            [2.0, 1.0, 0.0],
            [0.0, 1.0, 0.2],
        ];
        let p = [0.7, 0.4, 0.8];
        let pr = quadrilateral(p, quad).unwrap();
        let Region::Interior { .. } = pr.region else {
            panic!("{pr:?}")
        };
        let sum: f64 = pr.weights.iter().sum();
        assert!((sum - 1.0).abs() < 1e-14);
        let d = sub(p, pr.point);
        let (_, dx, dy) = {
            // local coordinates back from the weights
            let xi = pr.weights[1] + pr.weights[2] - pr.weights[0] - pr.weights[3];
            let eta = pr.weights[2] + pr.weights[3] - pr.weights[0] - pr.weights[1];
            bilinear(xi, eta)
        };
        assert!(dot(d, combine4(dx, &quad)).abs() < 1e-12);
        assert!(dot(d, combine4(dy, &quad)).abs() < 1e-12);
        // d is along the normal there.
        let c = cross(d, pr.normal);
        assert!(dot(c, c).sqrt() < 1e-12 * dot(d, d).sqrt());
        // Beyond an edge.
        let pr = quadrilateral([3.0, 0.5, 0.0], quad).unwrap();
        assert_eq!(pr.region, Region::Edge(1));
    }
}
