//! The sweep of a step for crossings (implicit path): slaves whose motion over the
//! step carries them through a master farther than the radius search of
//! [`super::detect`] reaches (theory/contact.md, "Nothing crosses unseen").

use rstar::primitives::GeomWithData;
use rstar::{RTree, RTreeObject};

use super::detect::{closest, segment_candidate, within_ends, Chain, RigidHistory};
use super::rows::{Candidate, Contactee};
use crate::model::{ContactPair, Master};

/// Slaves whose motion over the step, from the geometry `x0(node)` to `x1(node)`,
/// crosses a master the search at `x1` does not reach (the slave and the master moved
/// farther relative to each other than the pair's radius, as at very high speed),
/// appended to `out` as candidates at `x1` (their gap negative: behind the master),
/// so that nothing passes through a master unseen. A deformable master is swept with
/// the explicit path's collision times ([`super::collision::node_segment`], the
/// motion over the step taken as linear); a rigid line by the gap falling below zero
/// over the step with the crossing point within its ends. Slaves that already have a
/// candidate in `out`, that started behind a rigid line, or that moved too little to
/// escape the radius search are skipped. `out` stays ordered by pair, side and slave.
pub fn crossed<X0, X1>(
    pairs: &[ContactPair],
    x0: X0,
    x1: X1,
    rigid: &RigidHistory,
    out: &mut Vec<Candidate>,
) where
    X0: Fn(usize) -> [f64; 2],
    X1: Fn(usize) -> [f64; 2],
{
    let dist = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    // `out` is ordered by slave key: a binary search tells a known slave (and no
    // set is built on this per-iteration path).
    let before = out.len();
    let known = |out: &[Candidate], key: (usize, usize, usize)| {
        out[..before]
            .binary_search_by_key(&key, Candidate::slave_key)
            .is_ok()
    };
    for (pi, pair) in pairs.iter().enumerate() {
        for (si, side) in pair.sides.iter().enumerate() {
            match &side.master {
                Master::Segments(segments) => {
                    let master_travel = segments
                        .iter()
                        .flatten()
                        .map(|&n| dist(x0(n), x1(n)))
                        .fold(0.0, f64::max);
                    let movers: Vec<usize> = side
                        .slaves
                        .iter()
                        .copied()
                        .filter(|&s| {
                            dist(x0(s), x1(s)) + master_travel > 0.5 * pair.radius
                                && !known(out, (pi, si, s))
                        })
                        .collect();
                    if movers.is_empty() {
                        continue;
                    }
                    let chain = Chain::new(segments, &x1);
                    let tree = RTree::bulk_load(
                        segments
                            .iter()
                            .enumerate()
                            .map(|(k, &[a, b])| {
                                GeomWithData::new(swept_box(&[x0(a), x0(b), x1(a), x1(b)]), k)
                            })
                            .collect(),
                    );
                    for s in movers {
                        let (p0, p1) = (x0(s), x1(s));
                        let envelope = swept_box(&[p0, p1]).envelope();
                        let mut first: Option<(f64, usize)> = None;
                        for hit in tree.locate_in_envelope_intersecting(envelope) {
                            let [a, b] = segments[hit.data];
                            if a == s || b == s {
                                continue;
                            }
                            let motion = |n: usize| {
                                let (q0, q1) = (x0(n), x1(n));
                                (q0, [q1[0] - q0[0], q1[1] - q0[1]])
                            };
                            let ((a0, va), (b0, vb)) = (motion(a), motion(b));
                            let vp = [p1[0] - p0[0], p1[1] - p0[1]];
                            if let Some(h) =
                                super::collision::node_segment(p0, vp, a0, va, b0, vb, 1.0)
                            {
                                if first.is_none_or(|(t, _)| h.t < t) {
                                    first = Some((h.t, hit.data));
                                }
                            }
                        }
                        if let Some((_, k)) = first {
                            let [a, b] = segments[k];
                            let xi = closest(p1, x1(a), x1(b)).0.clamp(0.0, 1.0);
                            out.push(segment_candidate(
                                (pi, si, s),
                                k,
                                segments[k],
                                &x1,
                                xi,
                                chain.normal[k],
                            ));
                        }
                    }
                }
                Master::Rigid { a, b, n } => {
                    let t = [b[0] - a[0], b[1] - a[1]];
                    let l2 = t[0] * t[0] + t[1] * t[1];
                    let gap = |p: [f64; 2]| (p[0] - a[0]) * n[0] + (p[1] - a[1]) * n[1];
                    let along = |p: [f64; 2]| ((p[0] - a[0]) * t[0] + (p[1] - a[1]) * t[1]) / l2;
                    for &s in &side.slaves {
                        let (p0, p1) = (x0(s), x1(s));
                        let (g0, g1) = (gap(p0), gap(p1));
                        // Moving into the line and behind it at the end (a slave resting
                        // on it starts at a gap of round-off, of either sign).
                        if !(g1 < 0.0 && g1 < g0)
                            || known(out, (pi, si, s))
                            || rigid.beneath.binary_search(&(pi, si, s)).is_ok()
                        {
                            continue;
                        }
                        let c = if g0 > 0.0 { g0 / (g0 - g1) } else { 0.0 };
                        let pc = [p0[0] + c * (p1[0] - p0[0]), p0[1] + c * (p1[1] - p0[1])];
                        if within_ends(along(pc)) {
                            out.push(Candidate::nodal(
                                (pi, si, s),
                                Contactee::Rigid,
                                along(p1).clamp(0.0, 1.0),
                                g1,
                                *n,
                            ));
                        }
                    }
                }
                // A solid's masters are swept by [`super::faces`].
                Master::Faces(_) | Master::Plane { .. } => {}
            }
        }
    }
    if out.len() > before {
        out.sort_by_key(Candidate::slave_key);
    }
}

/// The axis-aligned box around `points`, as an R-tree rectangle.
fn swept_box(points: &[[f64; 2]]) -> rstar::primitives::Rectangle<[f64; 2]> {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in points {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    rstar::primitives::Rectangle::from_corners(lo, hi)
}
