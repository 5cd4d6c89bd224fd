//! Contact detection: geometry only. For every direction of every pair, the slave
//! nodes near the master surface, each with its closest master segment (or the rigid
//! line), the local coordinate `ξ` of the closest point, the gap along the master's
//! outward normal and that normal, in the current geometry.
//!
//! Broad phase: an R-tree (`rstar`) of the master segments, built for the geometry
//! at hand, queried with the pair's search radius, so the search grows as
//! `s log s` with the number of segments, not as their square. Narrow phase: the
//! closest point of each segment in reach; the segment with the smallest distance
//! wins (an interior projection over an end point on a tie).

use rstar::primitives::{GeomWithData, Line};
use rstar::RTree;

use crate::model::{ContactPair, Master};

/// What a slave node is in contact with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Contactee {
    /// A segment of a deformable body, nodes `[a, b]`.
    Segment([usize; 2]),
    /// The rigid line of the pair's side.
    Rigid,
}

/// A candidate constraint: the gap of one slave node to one master, linearised as
/// `g(u + δ) ≈ g + n·(δ_s − (1−ξ) δ_a − ξ δ_b)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Candidate {
    /// Pair index.
    pub pair: usize,
    /// Direction within the pair.
    pub side: usize,
    /// Slave node.
    pub slave: usize,
    /// Master segment or rigid line.
    pub master: Contactee,
    /// Local coordinate of the closest point on the segment, in `[0, 1]`.
    pub xi: f64,
    /// Gap along the normal (m): positive open, negative penetrating.
    pub gap: f64,
    /// Unit outward normal of the master.
    pub normal: [f64; 2],
}

impl Candidate {
    /// The key that follows a constraint across re-linearisations (its segment may
    /// change).
    pub fn key(&self) -> (usize, usize, usize) {
        (self.pair, self.side, self.slave)
    }

    /// The nonzeros `(dof, coefficient)` of the linearised gap row (all dofs).
    pub fn row(&self) -> ([(usize, f64); 6], usize) {
        let [nx, ny] = self.normal;
        let s = self.slave;
        let mut r = [(0usize, 0.0f64); 6];
        r[0] = (2 * s, nx);
        r[1] = (2 * s + 1, ny);
        match self.master {
            Contactee::Segment([a, b]) => {
                let (wa, wb) = (1.0 - self.xi, self.xi);
                r[2] = (2 * a, -wa * nx);
                r[3] = (2 * a + 1, -wa * ny);
                r[4] = (2 * b, -wb * nx);
                r[5] = (2 * b + 1, -wb * ny);
                (r, 6)
            }
            Contactee::Rigid => (r, 2),
        }
    }
}

/// Closest point of `p` on the segment `a`-`b`: `(ξ, distance²)`.
fn closest(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> (f64, f64) {
    let d = [b[0] - a[0], b[1] - a[1]];
    let l2 = d[0] * d[0] + d[1] * d[1];
    let xi = if l2 > 0.0 {
        (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let q = [a[0] + xi * d[0], a[1] + xi * d[1]];
    (xi, (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2))
}

/// Outward unit normal of a segment oriented with its body on the left.
fn outward(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    let d = [b[0] - a[0], b[1] - a[1]];
    let l = (d[0] * d[0] + d[1] * d[1]).sqrt();
    if l > 0.0 {
        [d[1] / l, -d[0] / l]
    } else {
        [0.0, 0.0]
    }
}

/// Candidates of every pair at the geometry `x(node)`, appended to `out` (cleared
/// first), ordered by pair, side and slave node.
pub fn detect<X>(pairs: &[ContactPair], x: X, out: &mut Vec<Candidate>)
where
    X: Fn(usize) -> [f64; 2],
{
    out.clear();
    for (pi, pair) in pairs.iter().enumerate() {
        let r2 = pair.radius * pair.radius;
        for (si, side) in pair.sides.iter().enumerate() {
            match &side.master {
                Master::Segments(segments) => {
                    let tree = RTree::bulk_load(
                        segments
                            .iter()
                            .enumerate()
                            .map(|(k, &[a, b])| GeomWithData::new(Line::new(x(a), x(b)), k))
                            .collect(),
                    );
                    for &s in &side.slaves {
                        let p = x(s);
                        let mut best: Option<(f64, bool, usize, f64)> = None;
                        for hit in tree.locate_within_distance(p, r2) {
                            let [a, b] = segments[hit.data];
                            if a == s || b == s {
                                continue;
                            }
                            let (xi, d2) = closest(p, x(a), x(b));
                            let interior = xi > 0.0 && xi < 1.0;
                            let better = match best {
                                None => true,
                                Some((bd2, bint, _, _)) => {
                                    d2 < bd2 * (1.0 - 1e-12) || (d2 <= bd2 && interior && !bint)
                                }
                            };
                            if better {
                                best = Some((d2, interior, hit.data, xi));
                            }
                        }
                        if let Some((_, _, k, xi)) = best {
                            let [a, b] = segments[k];
                            let (xa, xb) = (x(a), x(b));
                            let n = outward(xa, xb);
                            let q = [xa[0] + xi * (xb[0] - xa[0]), xa[1] + xi * (xb[1] - xa[1])];
                            out.push(Candidate {
                                pair: pi,
                                side: si,
                                slave: s,
                                master: Contactee::Segment([a, b]),
                                xi,
                                gap: (p[0] - q[0]) * n[0] + (p[1] - q[1]) * n[1],
                                normal: n,
                            });
                        }
                    }
                }
                Master::Rigid { a, b, n } => {
                    let t = [b[0] - a[0], b[1] - a[1]];
                    let l2 = t[0] * t[0] + t[1] * t[1];
                    for &s in &side.slaves {
                        let p = x(s);
                        let xi = ((p[0] - a[0]) * t[0] + (p[1] - a[1]) * t[1]) / l2;
                        let gap = (p[0] - a[0]) * n[0] + (p[1] - a[1]) * n[1];
                        let tol = 1e-9;
                        if (-tol..=1.0 + tol).contains(&xi) && gap * gap <= r2 {
                            out.push(Candidate {
                                pair: pi,
                                side: si,
                                slave: s,
                                master: Contactee::Rigid,
                                xi: xi.clamp(0.0, 1.0),
                                gap,
                                normal: *n,
                            });
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::ContactSide;

    #[test]
    fn closest_segment_gap_and_normal() {
        // Master: a bottom edge at y = 0 from x = 0 to 2 in two segments, oriented
        // with the body below (right to left), so the outward normal is +y.
        let coords = [
            [2.0, 0.0],
            [1.0, 0.0],
            [0.0, 0.0],
            [0.5, 0.3],
            [1.5, -0.01],
            [5.0, 0.1],
        ];
        let pair = ContactPair {
            name: "p".into(),
            sides: vec![ContactSide {
                slaves: vec![3, 4, 5],
                master: Master::Segments(vec![[0, 1], [1, 2]]),
            }],
            radius: 1.0,
        };
        let mut out = Vec::new();
        detect(&[pair], |n| coords[n], &mut out);
        assert_eq!(out.len(), 2, "node 5 is out of reach: {out:?}");
        let c3 = out.iter().find(|c| c.slave == 3).unwrap();
        assert_eq!(c3.master, Contactee::Segment([1, 2]));
        assert!((c3.xi - 0.5).abs() < 1e-14 && (c3.gap - 0.3).abs() < 1e-14);
        assert_eq!(c3.normal, [0.0, 1.0]);
        let c4 = out.iter().find(|c| c.slave == 4).unwrap();
        assert_eq!(c4.master, Contactee::Segment([0, 1]));
        assert!((c4.gap + 0.01).abs() < 1e-14, "penetrating: {}", c4.gap);
        // The linearised row: +n on the slave, −(1−ξ)n and −ξn on the segment.
        let (row, k) = c3.row();
        assert_eq!(k, 6);
        assert_eq!(row[1], (7, 1.0));
        assert_eq!(row[3], (3, -0.5));
        assert_eq!(row[5], (5, -0.5));
    }

    #[test]
    fn rigid_line_within_its_ends() {
        let coords = [[0.1, 0.2], [0.5, 0.05], [0.2, -0.001]];
        let pair = ContactPair {
            name: "s".into(),
            sides: vec![ContactSide {
                slaves: vec![0, 1, 2],
                master: Master::Rigid {
                    a: [0.0, 0.0],
                    b: [0.23, 0.0],
                    n: [0.0, 1.0],
                },
            }],
            radius: 0.1,
        };
        let mut out = Vec::new();
        detect(&[pair], |n| coords[n], &mut out);
        // Node 0 is beyond the radius, node 1 beyond the end of the line.
        assert_eq!(out.len(), 1);
        assert_eq!(out[0].slave, 2);
        assert!((out[0].gap + 0.001).abs() < 1e-15);
        assert_eq!(out[0].row().1, 2);
    }
}
