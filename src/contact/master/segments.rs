//! A plane body's master: a chain of segments, oriented with the body on their left.
//!
//! Detection. Broad phase: an R-tree (`rstar`) of the segments at the geometry at
//! hand, queried with the pair's search radius, so the search grows as `s log s`
//! with the number of segments, not as their square. Narrow phase: the closest point
//! of each segment in reach; the segment with the smallest distance wins (an
//! interior projection over an end point on a tie). The normal is the segment's own,
//! so the force of a frictionless contact is normal to the surface and does no work
//! on sliding; where the closest point is a convex vertex (a slave beyond both
//! segments' ends), it is the vertex normal (the normalised sum of the normals of
//! the segments meeting there).
//!
//! A piecewise-linear surface has a kink at every vertex. Where the kink is concave
//! (the next segment rises out of the plane of the first: a notch), a slave node
//! sitting in it is held by both segments, and picking one of them would make it
//! flip between the two normals from one iteration to the next, so the equilibrium
//! loop never settles. A slave within [`NEAR_VERTEX`] of a concave vertex therefore
//! gives two candidates, one per segment, each the half-plane of its segment's line:
//! the QP finds the force in the cone of the two normals that balances the node.
//!
//! The sweep and the explicit collisions take the time a node meets a moving
//! segment from [`crate::contact::collision::node_segment`].

use std::cell::OnceCell;
use std::collections::HashMap;

use rstar::primitives::{GeomWithData, Line, Rectangle};
use rstar::{RTree, RTreeObject};

use super::rigid::{within_ends, EdgeHistory};
use super::{Impact, MasterSurface, Positions};
use crate::contact::collision::node_segment;
use crate::contact::rows::{Candidate, Contactee};
use crate::contact::state::{Slave, Target};
use crate::geometry::{dot, lerp, outward, sub};

/// How close (relative to the segment's length) to a concave vertex a slave's
/// closest point must be for the segment on the other side of the vertex to hold it
/// too: a thousandth, far more than a node moves about a vertex within the
/// iterations of a step, far less than a segment.
pub const NEAR_VERTEX: f64 = 1e-3;

/// Projection of `p` on the line of the segment `a`-`b`: the unclamped `ξ` and the
/// distance² to the closest point of the segment (`ξ` clamped to `[0, 1]`).
pub fn closest(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> (f64, f64) {
    let d = [b[0] - a[0], b[1] - a[1]];
    let l2 = d[0] * d[0] + d[1] * d[1];
    let xi = if l2 > 0.0 {
        ((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / l2
    } else {
        0.0
    };
    let c = xi.clamp(0.0, 1.0);
    let q = [a[0] + c * d[0], a[1] + c * d[1]];
    (xi, (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2))
}

/// The topology of a master's segments at a geometry: each segment's outward normal
/// and its neighbours along the surface (the segment ending where it starts, the one
/// starting where it ends).
struct Chain {
    normal: Vec<[f64; 2]>,
    prev: Vec<Option<usize>>,
    next: Vec<Option<usize>>,
    /// Sum of the normals of the segments meeting at a node.
    at_node: HashMap<usize, [f64; 2]>,
}

impl Chain {
    fn new(segments: &[[usize; 2]], x: impl Fn(usize) -> [f64; 2]) -> Chain {
        let m = segments.len();
        let mut starting = HashMap::with_capacity(m);
        let mut at_node: HashMap<usize, [f64; 2]> = HashMap::with_capacity(m + 1);
        let mut normal = Vec::with_capacity(m);
        for (k, &[a, b]) in segments.iter().enumerate() {
            starting.insert(a, k);
            let n = outward(x(a), x(b)).0;
            normal.push(n);
            for v in [a, b] {
                let e = at_node.entry(v).or_insert([0.0, 0.0]);
                e[0] += n[0];
                e[1] += n[1];
            }
        }
        let next: Vec<Option<usize>> = segments
            .iter()
            .map(|&[_, b]| starting.get(&b).copied())
            .collect();
        let mut prev = vec![None; m];
        for (k, n) in next.iter().enumerate() {
            if let Some(&k2) = n.as_ref() {
                prev[k2] = Some(k);
            }
        }
        Chain {
            normal,
            prev,
            next,
            at_node,
        }
    }

    /// Whether the kink from segment `k` into the next one `k2` is concave: the far
    /// end of `k2` lies outside the line of `k`. No threshold: at a flat kink the two
    /// rows coincide, so a slave passes continuously from one row to two; any
    /// threshold would make that a jump (and a vertex whose kink hovers at it would
    /// switch from one iteration to the next).
    fn concave(
        &self,
        k: usize,
        k2: usize,
        segments: &[[usize; 2]],
        x: impl Fn(usize) -> [f64; 2],
    ) -> bool {
        let (v, c) = (x(segments[k][1]), x(segments[k2][1]));
        let n = self.normal[k];
        (c[0] - v[0]) * n[0] + (c[1] - v[1]) * n[1] > 0.0
    }

    /// The unit vertex normal at node `v`, if the normals there do not cancel.
    fn vertex_normal(&self, v: usize) -> Option<[f64; 2]> {
        let [nx, ny] = *self.at_node.get(&v)?;
        let l = (nx * nx + ny * ny).sqrt();
        (l > 0.0).then(|| [nx / l, ny / l])
    }
}

/// An R-tree of the segments, each as its line at one geometry.
type SegmentTree = RTree<GeomWithData<Line<[f64; 2]>, usize>>;

/// An R-tree of the boxes the segments sweep over a step.
type SweptTree = RTree<GeomWithData<Rectangle<[f64; 2]>, usize>>;

/// A chain of segments at a geometry.
pub struct SegmentChain<'a> {
    segments: &'a [[usize; 2]],
    x: Positions<'a>,
    chain: OnceCell<Chain>,
    tree: OnceCell<SegmentTree>,
    swept: OnceCell<SweptTree>,
}

impl<'a> SegmentChain<'a> {
    /// The chain `segments` at the geometry `x`.
    pub fn new(segments: &'a [[usize; 2]], x: Positions<'a>) -> Self {
        SegmentChain {
            segments,
            x,
            chain: OnceCell::new(),
            tree: OnceCell::new(),
            swept: OnceCell::new(),
        }
    }

    fn x(&self, n: usize) -> [f64; 2] {
        self.x.at::<2>(n)
    }

    /// The chain's normals and neighbours at the surface's geometry.
    fn chain(&self) -> &Chain {
        self.chain
            .get_or_init(|| Chain::new(self.segments, |n| self.x(n)))
    }

    /// The segments' lines at the surface's geometry.
    fn tree(&self) -> &SegmentTree {
        self.tree.get_or_init(|| {
            RTree::bulk_load(
                self.segments
                    .iter()
                    .enumerate()
                    .map(|(k, &[a, b])| GeomWithData::new(Line::new(self.x(a), self.x(b)), k))
                    .collect(),
            )
        })
    }

    /// The row of `slave` against segment `k` at `ξ` along `n`.
    fn candidate(&self, slave: Slave, k: usize, xi: f64, n: [f64; 2]) -> Candidate {
        let [a, b] = self.segments[k];
        let q = lerp(self.x(a), self.x(b), xi);
        Candidate::nodal::<2>(
            slave,
            Contactee::Segment {
                index: k,
                nodes: [a, b],
            },
            &[(a, 1.0 - xi), (b, xi)],
            xi,
            dot(sub(self.x(slave.node), q), n),
            n,
        )
    }
}

impl MasterSurface for SegmentChain<'_> {
    fn detect(&self, slave: Slave, reach: f64, _: &EdgeHistory, out: &mut Vec<Candidate>) {
        let (segments, chain) = (self.segments, self.chain());
        let x = |n: usize| self.x(n);
        let s = slave.node;
        let p = x(s);
        // (distance², interior, segment, ξ unclamped)
        let mut best: Option<(f64, bool, usize, f64)> = None;
        for hit in self.tree().locate_within_distance(p, reach * reach) {
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
        let Some((_, _, k, xi)) = best else {
            return;
        };
        // Past an end of the master's chain the slave's projection has left the
        // surface: it is beside the master, not on it, and no force holds it (a
        // margin of `RIGID_END_MARGIN` keeps a slave exactly at the end from
        // flickering on round-off).
        let off_end =
            (xi < 0.0 && chain.prev[k].is_none()) || (xi > 1.0 && chain.next[k].is_none());
        if off_end && !within_ends(xi) {
            return;
        }
        let [a, b] = segments[k];
        // The vertex near the closest point, and the segment beyond it when the kink
        // there is concave.
        let notch = if xi >= 1.0 - NEAR_VERTEX {
            chain.next[k].filter(|&k2| chain.concave(k, k2, segments, x))
        } else if xi <= NEAR_VERTEX {
            chain.prev[k].filter(|&k2| chain.concave(k2, k, segments, x))
        } else {
            None
        };
        let xi = xi.clamp(0.0, 1.0);
        match notch {
            Some(k2) => {
                // Two half-planes, each along its segment's normal.
                let [a2, b2] = segments[k2];
                let (xi2, _) = closest(p, x(a2), x(b2));
                let mut pair_of = [
                    self.candidate(slave, k, xi, chain.normal[k]),
                    self.candidate(slave, k2, xi2.clamp(0.0, 1.0), chain.normal[k2]),
                ];
                pair_of.sort_by_key(|c| c.key());
                out.extend(pair_of);
            }
            None => {
                let vertex = match () {
                    _ if xi <= 0.0 => Some(a),
                    _ if xi >= 1.0 => Some(b),
                    _ => None,
                };
                let n = vertex
                    .and_then(|v| chain.vertex_normal(v))
                    .unwrap_or(chain.normal[k]);
                out.push(self.candidate(slave, k, xi, n));
            }
        }
    }

    fn nodes(&self) -> Option<Vec<usize>> {
        Some(self.segments.iter().flatten().copied().collect())
    }

    fn crossing(&self, slave: Slave, start: Positions, _: &EdgeHistory) -> Option<Candidate> {
        let x0 = |n: usize| start.at::<2>(n);
        let x1 = |n: usize| self.x(n);
        let tree = self.swept.get_or_init(|| {
            RTree::bulk_load(
                self.segments
                    .iter()
                    .enumerate()
                    .map(|(k, &[a, b])| {
                        GeomWithData::new(swept_box(&[x0(a), x0(b), x1(a), x1(b)]), k)
                    })
                    .collect(),
            )
        });
        let s = slave.node;
        let (p0, p1) = (x0(s), x1(s));
        let envelope = swept_box(&[p0, p1]).envelope();
        let mut first: Option<(f64, usize)> = None;
        for hit in tree.locate_in_envelope_intersecting(envelope) {
            let [a, b] = self.segments[hit.data];
            if a == s || b == s {
                continue;
            }
            let motion = |n: usize| {
                let (q0, q1) = (x0(n), x1(n));
                (q0, [q1[0] - q0[0], q1[1] - q0[1]])
            };
            let ((a0, va), (b0, vb)) = (motion(a), motion(b));
            let vp = [p1[0] - p0[0], p1[1] - p0[1]];
            if let Some(h) = node_segment(p0, vp, a0, va, b0, vb, 1.0) {
                if first.is_none_or(|(t, _)| h.t < t) {
                    first = Some((h.t, hit.data));
                }
            }
        }
        let (_, k) = first?;
        let [a, b] = self.segments[k];
        let xi = closest(p1, x1(a), x1(b)).0.clamp(0.0, 1.0);
        Some(self.candidate(slave, k, xi, self.chain().normal[k]))
    }

    fn impact(
        &self,
        slave: Slave,
        v: Positions,
        h: f64,
        reach: f64,
        _: &EdgeHistory,
    ) -> Option<Impact> {
        let at = |n: usize| self.x(n);
        let vel = |n: usize| v.at::<2>(n);
        let s = slave.node;
        let mut best: Option<(f64, usize, f64)> = None;
        for hit in self.tree().locate_within_distance(at(s), reach * reach) {
            let [a, b] = self.segments[hit.data];
            if a == s || b == s {
                continue;
            }
            if let Some(c) = node_segment(at(s), vel(s), at(a), vel(a), at(b), vel(b), h) {
                if best.is_none_or(|(t, _, _)| c.t < t) {
                    best = Some((c.t, hit.data, c.xi));
                }
            }
        }
        let (t, k, xi) = best?;
        let [a, b] = self.segments[k];
        let (pa, pb, va, vb) = (at(a), at(b), vel(a), vel(b));
        let (n, _) = outward(
            [pa[0] + t * va[0], pa[1] + t * va[1]],
            [pb[0] + t * vb[0], pb[1] + t * vb[1]],
        );
        Some(Impact {
            t,
            target: Target::Facet(k),
            corners: [(a, 1.0 - xi), (b, xi), (0, 0.0)],
            n_corners: 2,
            normal: [n[0], n[1], 0.0],
        })
    }
}

/// The axis-aligned box around `points`, as an R-tree rectangle.
fn swept_box(points: &[[f64; 2]]) -> Rectangle<[f64; 2]> {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in points {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    Rectangle::from_corners(lo, hi)
}

#[cfg(test)]
mod tests {
    use super::super::tests::detect;
    use crate::contact::rows::Contactee;
    use crate::contact::state::Target;
    use crate::model::{ContactPair, ContactSide, Master};

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
                surface: crate::model::SlaveSurface::Nodes,
            }],
            radius: 1.0,
            friction: 0.0,
            mu: 0.0,
            formulation: crate::model::Formulation::NodeToSegment,
            mortar_basis: crate::model::MortarBasis::Dual,
            position_weight: 0.5,
        };
        let mut out = Vec::new();
        detect(&[pair], &coords, &mut out);
        assert_eq!(out.len(), 2, "node 5 is out of reach: {out:?}");
        let c3 = out.iter().find(|c| c.slave == 3).unwrap();
        assert_eq!(
            c3.master,
            Contactee::Segment {
                index: 1,
                nodes: [1, 2]
            }
        );
        assert!((c3.xi - 0.5).abs() < 1e-14 && (c3.gap - 0.3).abs() < 1e-14);
        assert_eq!(c3.normal, [0.0, 1.0, 0.0]);
        let c4 = out.iter().find(|c| c.slave == 4).unwrap();
        assert_eq!(
            c4.master,
            Contactee::Segment {
                index: 0,
                nodes: [0, 1]
            }
        );
        assert!((c4.gap + 0.01).abs() < 1e-14, "penetrating: {}", c4.gap);
        // The linearised row: +n on the slave, −(1−ξ)n and −ξn on the segment.
        let row: Vec<_> = c3.row().collect();
        assert_eq!(row.len(), 6);
        assert_eq!(row[1], (7, 1.0));
        assert_eq!(row[3], (3, -0.5));
        assert_eq!(row[5], (5, -0.5));
    }

    #[test]
    fn a_slave_in_a_notch_is_held_by_both_segments() {
        // Master top edge (body below, oriented right to left) with a concave kink at
        // node 1 (a notch: both neighbours higher) and a convex one at node 2 (the
        // surface turns flat there, below the line of the segment before).
        let coords = [
            [2.0, 0.1],  // 0
            [1.0, 0.0],  // 1: notch
            [0.0, 0.1],  // 2: convex
            [-1.0, 0.1], // 3
            [1.0, 1e-9], // 4: slave just above the notch
            [0.0, 0.15], // 5: slave above the convex vertex
        ];
        let pair = |slaves: Vec<usize>, segments: Vec<[usize; 2]>| ContactPair {
            name: "p".into(),
            sides: vec![ContactSide {
                slaves,
                master: Master::Segments(segments),
                surface: crate::model::SlaveSurface::Nodes,
            }],
            radius: 1.0,
            friction: 0.0,
            mu: 0.0,
            formulation: crate::model::Formulation::NodeToSegment,
            mortar_basis: crate::model::MortarBasis::Dual,
            position_weight: 0.5,
        };
        let mut out = Vec::new();
        detect(
            &[pair(vec![4, 5], vec![[0, 1], [1, 2], [2, 3]])],
            &coords,
            &mut out,
        );
        let at4: Vec<_> = out.iter().filter(|c| c.slave == 4).collect();
        assert_eq!(at4.len(), 2, "{out:?}");
        assert_eq!(at4[0].key().target, Target::Facet(0));
        assert_eq!(at4[1].key().target, Target::Facet(1));
        for c in &at4 {
            // Each along its own segment's normal, the gap that of its line.
            let n = c.normal;
            assert!((n[0] * n[0] + n[1] * n[1] - 1.0).abs() < 1e-14);
            assert!(c.gap > 0.0 && c.gap < 1e-9, "{c:?}");
        }
        // Segment 0 rises to the right (its normal leans left), segment 1 to the left.
        assert!(at4[0].normal[0] < 0.0 && at4[1].normal[0] > 0.0, "{at4:?}");
        // Vertex 2 is convex (node 3 lies below the line of segment [1, 2]): one
        // candidate.
        assert_eq!(out.iter().filter(|c| c.slave == 5).count(), 1, "{out:?}");

        // A convex corner: a slave beyond both segments' ends gets the vertex normal.
        let corner = [[1.0, 0.0], [0.0, 0.0], [0.0, -1.0], [-0.1, 0.1]];
        detect(&[pair(vec![3], vec![[0, 1], [1, 2]])], &corner, &mut out);
        assert_eq!(out.len(), 1);
        let h = std::f64::consts::FRAC_1_SQRT_2;
        assert!((out[0].normal[0] + h).abs() < 1e-14 && (out[0].normal[1] - h).abs() < 1e-14);
    }
}
