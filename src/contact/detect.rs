//! Contact detection: geometry only. For every direction of every pair, the slave
//! nodes near the master surface, each with its closest master segment (or the rigid
//! line), the local coordinate `ξ` of the closest point, the gap along the master's
//! outward normal and that normal, in the current geometry.
//!
//! Broad phase: an R-tree (`rstar`) of the master segments, built for the geometry
//! at hand, queried with the pair's search radius, so the search grows as
//! `s log s` with the number of segments, not as their square. Narrow phase: the
//! closest point of each segment in reach; the segment with the smallest distance
//! wins (an interior projection over an end point on a tie). The normal is the
//! segment's own, so the force of a frictionless contact is normal to the surface
//! and does no work on sliding; where the closest point is a convex vertex (a slave
//! beyond both segments' ends), it is the vertex normal (the normalised sum of the
//! normals of the segments meeting there).
//!
//! A piecewise-linear surface has a kink at every vertex. Where the kink is concave
//! (the next segment rises out of the plane of the first: a notch), a slave node
//! sitting in it is held by both segments, and picking one of them would make it
//! flip between the two normals from one iteration to the next, so the equilibrium
//! loop never settles. A slave within [`NEAR_VERTEX`] of a concave vertex therefore
//! gives two candidates, one per segment, each the half-plane of its segment's line:
//! the QP finds the force in the cone of the two normals that balances the node.

use rstar::primitives::{GeomWithData, Line};
use rstar::RTree;

use crate::model::{ContactPair, Master};

use super::rows::{Candidate, Contactee};
use super::state::Slave;

/// How close (relative to the segment's length) to a concave vertex a slave's
/// closest point must be for the segment on the other side of the vertex to hold it
/// too: a thousandth, far more than a node moves about a vertex within the
/// iterations of a step, far less than a segment.
pub const NEAR_VERTEX: f64 = 1e-3;

/// How far (relative to its length) beyond its ends a rigid line still holds a node:
/// a node at the very end of a support moves sideways by micrometres (Poisson's
/// effect) and must not drop in and out of contact with it. A thousandth of the line
/// changes where the support ends far less than the node spacing does.
pub const RIGID_END_MARGIN: f64 = 1e-3;

/// Projection of `p` on the line of the segment `a`-`b`: the unclamped `ξ` and the
/// distance² to the closest point of the segment (`ξ` clamped to `[0, 1]`).
pub(super) fn closest(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> (f64, f64) {
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

/// The topology of a master's segments at the current geometry: each segment's
/// outward normal and its neighbours along the surface (the segment ending where it
/// starts, the one starting where it ends).
pub(super) struct Chain {
    pub(super) normal: Vec<[f64; 2]>,
    prev: Vec<Option<usize>>,
    next: Vec<Option<usize>>,
    /// Sum of the normals of the segments meeting at a node.
    at_node: std::collections::HashMap<usize, [f64; 2]>,
}

impl Chain {
    pub(super) fn new<X: Fn(usize) -> [f64; 2]>(segments: &[[usize; 2]], x: &X) -> Chain {
        let m = segments.len();
        let mut starting = std::collections::HashMap::with_capacity(m);
        let mut at_node: std::collections::HashMap<usize, [f64; 2]> =
            std::collections::HashMap::with_capacity(m + 1);
        let mut normal = Vec::with_capacity(m);
        for (k, &[a, b]) in segments.iter().enumerate() {
            starting.insert(a, k);
            let n = crate::geometry::outward(x(a), x(b)).0;
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
    fn concave<X: Fn(usize) -> [f64; 2]>(
        &self,
        k: usize,
        k2: usize,
        segments: &[[usize; 2]],
        x: &X,
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

/// How many contact tolerances below (or off) a rigid line's level a slave lies at
/// the start of a step when the line does not hold it: a slave the line holds lies
/// within one (accepted steps penetrate at most the tolerance); two leave room for
/// round-off. Both paths use it with [`beneath_rigid`] and [`held_rigid`].
pub const RIGID_DEPTH_TOLERANCES: f64 = 2.0;

/// The slaves of rigid lines that came around a line's end: at the geometry
/// `x(node)` (committed: the start of a step) they lie below the line's level by
/// more than `depth`, and either beyond its ends or already so in `previous` (the
/// last step's list), as sorted `(pair, side, slave)`.
///
/// A rigid line is a support of finite length. A slave just beyond its end is free
/// and may sink below the line's level (a beam rotating over the edge of its
/// support); if it later moves sideways back within the line's ends it passes beside
/// the support's end face, and a node-to-line constraint would instead fling it up
/// onto the line in one step: an impulse doing large positive work (`D_contact`
/// went to −12 `E_kin⁰` in benchmark 2's Kelvin-Voigt beam before this rule). Such a
/// slave stays passed over until it rises above the line's level again. A slave that
/// starts a run below a line within its ends is not passed over: the constraint
/// holds it (or reports an infeasible QP).
pub fn beneath_rigid<X>(pairs: &[ContactPair], x: X, depth: f64, previous: &[Slave]) -> Vec<Slave>
where
    X: Fn(usize) -> [f64; 2],
{
    let mut out = Vec::new();
    rigid_slaves(pairs, x, |r| {
        let beyond = !within_ends(r.xi);
        if r.gap < -depth && (beyond || previous.binary_search(&r.key).is_ok()) {
            out.push(r.key);
        }
    });
    out
}

/// A slave of a rigid line at some geometry.
struct RigidSlave {
    /// `(pair, side, slave)`.
    key: Slave,
    /// Distance above the line's level.
    gap: f64,
    /// Position along the line (0 and 1 at its ends).
    xi: f64,
    /// The pair's radius in units of the line's length.
    reach: f64,
}

/// Calls `f` for every slave of every rigid line, in key order.
fn rigid_slaves<X>(pairs: &[ContactPair], x: X, mut f: impl FnMut(RigidSlave))
where
    X: Fn(usize) -> [f64; 2],
{
    for (pi, pair) in pairs.iter().enumerate() {
        for (si, side) in pair.sides.iter().enumerate() {
            if let Master::Rigid { a, b, n } = &side.master {
                let t = [b[0] - a[0], b[1] - a[1]];
                let l2 = t[0] * t[0] + t[1] * t[1];
                for &s in &side.slaves {
                    let p = x(s);
                    f(RigidSlave {
                        key: Slave::new(pi, si, s),
                        gap: (p[0] - a[0]) * n[0] + (p[1] - a[1]) * n[1],
                        xi: ((p[0] - a[0]) * t[0] + (p[1] - a[1]) * t[1]) / l2,
                        reach: pair.radius / l2.sqrt(),
                    });
                }
            }
        }
    }
}

/// Whether `ξ` lies within a rigid line's ends (and [`RIGID_END_MARGIN`]).
pub(super) fn within_ends(xi: f64) -> bool {
    (-RIGID_END_MARGIN..=1.0 + RIGID_END_MARGIN).contains(&xi)
}

/// Candidates of every pair at the geometry `x(node)`, appended to `out` (cleared
/// first), ordered by pair, side and slave node (a slave in a notch gives two, by
/// segment).
pub fn detect<X>(pairs: &[ContactPair], x: X, out: &mut Vec<Candidate>)
where
    X: Fn(usize) -> [f64; 2],
{
    detect_except(pairs, x, &RigidHistory::default(), out)
}

/// The candidate of slave `key` against master
/// segment `k` with nodes `[a, b]` at the geometry `x`: the point at `ξ` on it and
/// the normal `n`.
pub(super) fn segment_candidate<X: Fn(usize) -> [f64; 2]>(
    key: Slave,
    k: usize,
    [a, b]: [usize; 2],
    x: &X,
    xi: f64,
    n: [f64; 2],
) -> Candidate {
    let (p, xa, xb) = (x(key.node), x(a), x(b));
    let q = [xa[0] + xi * (xb[0] - xa[0]), xa[1] + xi * (xb[1] - xa[1])];
    Candidate::nodal(
        key,
        Contactee::Segment {
            index: k,
            nodes: [a, b],
        },
        xi,
        (p[0] - q[0]) * n[0] + (p[1] - q[1]) * n[1],
        n,
    )
}

/// The slaves rigid lines hold at the geometry `x(node)` (committed): lying within
/// `depth` of the line's level, and within its ends or already held in `previous`
/// (a held slave that slides past an end stays held while it stays on the level),
/// as sorted `(pair, side, slave)`. The explicit path keeps this list itself; the
/// implicit one takes it from its active set.
pub fn held_rigid<X>(pairs: &[ContactPair], x: X, depth: f64, previous: &[Slave]) -> Vec<Slave>
where
    X: Fn(usize) -> [f64; 2],
{
    let mut out = Vec::new();
    rigid_slaves(pairs, x, |r| {
        let near = (-r.reach..=1.0 + r.reach).contains(&r.xi);
        if r.gap.abs() <= depth
            && near
            && (within_ends(r.xi) || previous.binary_search(&r.key).is_ok())
        {
            out.push(r.key);
        }
    });
    out
}

/// What a step knows of its rigid lines' slaves from the committed state, as sorted
/// `(pair, side, slave)` lists.
#[derive(Clone, Debug, Default)]
pub struct RigidHistory {
    /// Slaves that came around a line's end ([`beneath_rigid`]): not candidates.
    pub beneath: Vec<Slave>,
    /// Slaves the line held at the end of the last step: candidates even a little
    /// beyond the line's ends (within the pair's radius), so that a slave at the very
    /// end of a support, which slides outward as the body above it bends, stays on
    /// it instead of slipping off and coming back around the end.
    pub held: Vec<Slave>,
}

/// [`detect`] with what the committed state knows of the rigid lines' slaves.
pub fn detect_except<X>(pairs: &[ContactPair], x: X, rigid: &RigidHistory, out: &mut Vec<Candidate>)
where
    X: Fn(usize) -> [f64; 2],
{
    out.clear();
    for (pi, pair) in pairs.iter().enumerate() {
        let r2 = pair.radius * pair.radius;
        for (si, side) in pair.sides.iter().enumerate() {
            match &side.master {
                Master::Segments(segments) if !side.mortar.is_empty() => {
                    // Rows are sized for the initial geometry (validation); a mesh
                    // sliding far enough to bring more master nodes under one slave
                    // node keeps the first `ROW_NODES`.
                    super::mortar::rows(
                        (pi, si),
                        &side.slaves,
                        &side.mortar,
                        segments,
                        pair.radius,
                        &x,
                        out,
                    );
                }
                Master::Segments(segments) => {
                    let chain = Chain::new(segments, &x);
                    let tree = RTree::bulk_load(
                        segments
                            .iter()
                            .enumerate()
                            .map(|(k, &[a, b])| GeomWithData::new(Line::new(x(a), x(b)), k))
                            .collect(),
                    );
                    for &s in &side.slaves {
                        let p = x(s);
                        // (distance², interior, segment, ξ unclamped)
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
                        let Some((_, _, k, xi)) = best else {
                            continue;
                        };
                        // Past an end of the master's chain the slave's projection has
                        // left the surface: it is beside the master, not on it, and
                        // no force holds it (a margin of `RIGID_END_MARGIN` keeps a
                        // slave exactly at the end from flickering on round-off).
                        let off_end = (xi < 0.0 && chain.prev[k].is_none())
                            || (xi > 1.0 && chain.next[k].is_none());
                        if off_end && !within_ends(xi) {
                            continue;
                        }
                        let [a, b] = segments[k];
                        // The vertex near the closest point, and the segment beyond it
                        // when the kink there is concave.
                        let notch = if xi >= 1.0 - NEAR_VERTEX {
                            chain.next[k].filter(|&k2| chain.concave(k, k2, segments, &x))
                        } else if xi <= NEAR_VERTEX {
                            chain.prev[k].filter(|&k2| chain.concave(k2, k, segments, &x))
                        } else {
                            None
                        };
                        let candidate = |k: usize, xi: f64, n: [f64; 2]| {
                            segment_candidate(Slave::new(pi, si, s), k, segments[k], &x, xi, n)
                        };
                        let xi = xi.clamp(0.0, 1.0);
                        match notch {
                            Some(k2) => {
                                // Two half-planes, each along its segment's normal.
                                let [a2, b2] = segments[k2];
                                let (xi2, _) = closest(p, x(a2), x(b2));
                                let mut pair_of = [
                                    candidate(k, xi, chain.normal[k]),
                                    candidate(k2, xi2.clamp(0.0, 1.0), chain.normal[k2]),
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
                                out.push(candidate(k, xi, n));
                            }
                        }
                    }
                }
                Master::Rigid { a, b, n } => {
                    let t = [b[0] - a[0], b[1] - a[1]];
                    let l2 = t[0] * t[0] + t[1] * t[1];
                    for &s in &side.slaves {
                        if rigid.beneath.binary_search(&Slave::new(pi, si, s)).is_ok() {
                            continue;
                        }
                        let p = x(s);
                        let xi = ((p[0] - a[0]) * t[0] + (p[1] - a[1]) * t[1]) / l2;
                        let gap = (p[0] - a[0]) * n[0] + (p[1] - a[1]) * n[1];
                        let within = within_ends(xi)
                            || rigid.held.binary_search(&Slave::new(pi, si, s)).is_ok();
                        if within && gap * gap <= r2 {
                            out.push(Candidate::nodal(
                                Slave::new(pi, si, s),
                                Contactee::Rigid,
                                xi.clamp(0.0, 1.0),
                                gap,
                                *n,
                            ));
                        }
                    }
                }
                // A solid's masters: [`super::faces`].
                Master::Faces(_) | Master::Plane { .. } => {}
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
                mortar: Vec::new(),
                faces: Vec::new(),
                master_boundary: Vec::new(),
            }],
            radius: 1.0,
            friction: 0.0,
            mu: 0.0,
            formulation: crate::model::Formulation::NodeToSegment,
            position_weight: 0.5,
        };
        let mut out = Vec::new();
        detect(&[pair], |n| coords[n], &mut out);
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
                mortar: Vec::new(),
                faces: Vec::new(),
                master_boundary: Vec::new(),
            }],
            radius: 1.0,
            friction: 0.0,
            mu: 0.0,
            formulation: crate::model::Formulation::NodeToSegment,
            position_weight: 0.5,
        };
        let mut out = Vec::new();
        detect(
            &[pair(vec![4, 5], vec![[0, 1], [1, 2], [2, 3]])],
            |n| coords[n],
            &mut out,
        );
        let at4: Vec<_> = out.iter().filter(|c| c.slave == 4).collect();
        assert_eq!(at4.len(), 2, "{out:?}");
        assert_eq!(at4[0].key().target, super::super::state::Target::Facet(0));
        assert_eq!(at4[1].key().target, super::super::state::Target::Facet(1));
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
        detect(
            &[pair(vec![3], vec![[0, 1], [1, 2]])],
            |n| corner[n],
            &mut out,
        );
        assert_eq!(out.len(), 1);
        let h = std::f64::consts::FRAC_1_SQRT_2;
        assert!((out[0].normal[0] + h).abs() < 1e-14 && (out[0].normal[1] - h).abs() < 1e-14);
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
                mortar: Vec::new(),
                faces: Vec::new(),
                master_boundary: Vec::new(),
            }],
            radius: 0.1,
            friction: 0.0,
            mu: 0.0,
            formulation: crate::model::Formulation::NodeToSegment,
            position_weight: 0.5,
        };
        let mut out = Vec::new();
        detect(std::slice::from_ref(&pair), |n| coords[n], &mut out);
        // Node 0 is beyond the radius, node 1 beyond the end of the line.
        assert_eq!(out.len(), 1);
        assert_eq!(out[0].slave, 2);
        assert!((out[0].gap + 0.001).abs() < 1e-15);
        assert_eq!(out[0].row().count(), 2);
        // Node 2 lies below the line within its ends: held, not passed over, unless
        // it came around the end (it was passed over at the last step).
        let pairs = [pair];
        assert!(beneath_rigid(&pairs, |n| coords[n], 5e-4, &[]).is_empty());
        let beneath = beneath_rigid(&pairs, |n| coords[n], 5e-4, &[Slave::new(0, 0, 2)]);
        assert_eq!(beneath, [Slave::new(0, 0, 2)]);
        // Beyond the end and below: passed over.
        let beyond = [[0.1, 0.2], [0.3, -0.001], [0.2, 0.0]];
        assert_eq!(
            beneath_rigid(&pairs, |n| beyond[n], 5e-4, &[]),
            [Slave::new(0, 0, 1)]
        );
        let mut rigid = RigidHistory {
            beneath,
            held: Vec::new(),
        };
        detect_except(&pairs, |n| coords[n], &rigid, &mut out);
        assert!(out.is_empty());
        // A held slave stays a candidate beyond the line's end (node 1 at ξ = 2.2
        // is within the radius of the line's level).
        rigid.held = vec![Slave::new(0, 0, 1)];
        detect_except(&pairs, |n| coords[n], &rigid, &mut out);
        assert_eq!(out.len(), 1);
        assert_eq!((out[0].slave, out[0].xi), (1, 1.0));
        assert!(beneath_rigid(&pairs, |n| coords[n], 2e-3, &[Slave::new(0, 0, 2)]).is_empty());
        // Held: on the line's level within its ends, or past an end if held before.
        let on = [[0.1, 0.0], [0.2305, 0.0], [0.3, 0.0]];
        assert_eq!(
            held_rigid(&pairs, |n| on[n], 1e-6, &[]),
            [Slave::new(0, 0, 0)]
        );
        assert_eq!(
            held_rigid(
                &pairs,
                |n| on[n],
                1e-6,
                &[Slave::new(0, 0, 1), Slave::new(0, 0, 2)]
            ),
            [
                Slave::new(0, 0, 0),
                Slave::new(0, 0, 1),
                Slave::new(0, 0, 2)
            ]
        );
        let off = [[0.1, 0.01], [0.2305, 0.0], [0.5, 0.0]];
        assert_eq!(
            held_rigid(
                &pairs,
                |n| off[n],
                1e-6,
                &[Slave::new(0, 0, 1), Slave::new(0, 0, 2)]
            ),
            [Slave::new(0, 0, 1)]
        );
    }
}
