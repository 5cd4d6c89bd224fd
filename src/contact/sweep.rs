//! The sweep of a step for crossings (implicit path): slaves whose motion over the
//! step carries them through a master farther than the radius search of
//! [`super::detect`] (or [`super::faces`] in a solid) reaches (theory/contact.md,
//! "Nothing crosses unseen"; theory/contact3d.md).

use rstar::primitives::GeomWithData;
use rstar::{RTree, RTreeObject};

use super::detect::{closest, segment_candidate, within_ends, Chain, RigidHistory};
use super::faces::{bounding_box, dot, face_candidate, face_tree, project, sub, Surface, V3};
use super::rows::{Candidate, Contactee, Weights};
use super::state::Slave;
use crate::model::{ContactPair, Master};

/// Whether slave `key` has a candidate among `found` (ordered by slave key: a binary
/// search, no set built on this per-iteration path).
fn known(found: &[Candidate], key: Slave) -> bool {
    found
        .binary_search_by_key(&key, Candidate::slave_key)
        .is_ok()
}

/// The slaves that moved, relative to their master (its nodes `master`), more than
/// half the pair's `radius` over the step (`travel(node)`: how far a node moved),
/// and are not `known` yet: those the radius search may have missed.
fn movers(
    slaves: &[usize],
    master: impl Iterator<Item = usize>,
    radius: f64,
    travel: impl Fn(usize) -> f64,
    known: impl Fn(usize) -> bool,
) -> Vec<usize> {
    let master_travel = master.map(&travel).fold(0.0, f64::max);
    slaves
        .iter()
        .copied()
        .filter(|&s| travel(s) + master_travel > 0.5 * radius && !known(s))
        .collect()
}

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
    let before = out.len();
    for (pi, pair) in pairs.iter().enumerate() {
        for (si, side) in pair.sides.iter().enumerate() {
            match &side.master {
                Master::Segments(segments) => {
                    let movers = movers(
                        &side.slaves,
                        segments.iter().flatten().copied(),
                        pair.radius,
                        |n| dist(x0(n), x1(n)),
                        |s| known(&out[..before], Slave::new(pi, si, s)),
                    );
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
                                Slave::new(pi, si, s),
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
                            || known(&out[..before], Slave::new(pi, si, s))
                            || rigid.beneath.binary_search(&Slave::new(pi, si, s)).is_ok()
                        {
                            continue;
                        }
                        let c = if g0 > 0.0 { g0 / (g0 - g1) } else { 0.0 };
                        let pc = [p0[0] + c * (p1[0] - p0[0]), p0[1] + c * (p1[1] - p0[1])];
                        if within_ends(along(pc)) {
                            out.push(Candidate::nodal(
                                Slave::new(pi, si, s),
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

/// Slaves whose motion over the step, from the geometry `x0(node)` to `x1(node)`,
/// carries them through a master face or rigid plane the search at `x1` does not
/// reach (they moved farther relative to it than the pair's radius), appended to
/// `out` as candidates at `x1` (behind the master), as [`crossed`] in the plane: a
/// face is swept with the node-triangle collision cubic
/// ([`super::collision::node_triangle`], the motion over the step taken as linear, a
/// quadrilateral as its two triangles), a plane by the gap changing sign.
/// Slaves that already have a candidate are skipped. `out` stays ordered by pair,
/// side and slave.
pub fn crossed_faces<X0, X1>(pairs: &[ContactPair], x0: X0, x1: X1, out: &mut Vec<Candidate>)
where
    X0: Fn(usize) -> V3,
    X1: Fn(usize) -> V3,
{
    let before = out.len();
    let dist = |a: V3, b: V3| dot(sub(a, b), sub(a, b)).sqrt();
    for (pi, pair) in pairs.iter().enumerate() {
        for (si, side) in pair.sides.iter().enumerate() {
            match &side.master {
                Master::Faces(faces) => {
                    let movers = movers(
                        &side.slaves,
                        faces.iter().flat_map(|f| f.corners().iter().copied()),
                        pair.radius,
                        |n| dist(x0(n), x1(n)),
                        |s| known(&out[..before], Slave::new(pi, si, s)),
                    );
                    if movers.is_empty() {
                        continue;
                    }
                    let surface = Surface::new(faces, &x1);
                    let tree = face_tree(faces, |n| [x0(n), x1(n)].into_iter(), 0.0);
                    for s in movers {
                        let (p0, p1) = (x0(s), x1(s));
                        let reach = bounding_box([p0, p1].into_iter(), 0.0);
                        let mut first: Option<(f64, usize)> = None;
                        for hit in tree.locate_in_envelope_intersecting(reach) {
                            let f = &faces[hit.data];
                            let c = f.corners();
                            if c.contains(&s) {
                                continue;
                            }
                            let triangles: &[[usize; 3]] = if c.len() == 3 {
                                &[[0, 1, 2]]
                            } else {
                                &[[0, 1, 2], [0, 2, 3]]
                            };
                            let motion = |n: usize| (x0(n), sub(x1(n), x0(n)));
                            for tri in triangles {
                                let [(a, va), (b, vb), (cc, vc)] = tri.map(|i| motion(c[i]));
                                let t = super::collision::node_triangle(
                                    p0,
                                    sub(p1, p0),
                                    a,
                                    va,
                                    b,
                                    vb,
                                    cc,
                                    vc,
                                    1.0,
                                );
                                if let Some(t) = t {
                                    if first.is_none_or(|(t0, _)| t.t < t0) {
                                        first = Some((t.t, hit.data));
                                    }
                                }
                            }
                        }
                        if let Some((_, k)) = first {
                            if let Some(pr) = project(p1, &faces[k], &x1) {
                                let normal = surface.normal(&faces[k], &pr);
                                out.push(face_candidate(
                                    Slave::new(pi, si, s),
                                    k,
                                    &faces[k],
                                    &pr,
                                    normal,
                                    &x1,
                                ));
                            }
                        }
                    }
                }
                Master::Plane { point, n, tangents } => {
                    for &s in &side.slaves {
                        let (g0, g1) = (dot(sub(x0(s), *point), *n), dot(sub(x1(s), *point), *n));
                        if g0 >= 0.0 && g1 < 0.0 && !known(&out[..before], Slave::new(pi, si, s)) {
                            let mut weights = Weights::EMPTY;
                            weights.add(s, 1.0);
                            out.push(Candidate {
                                pair: pi,
                                side: si,
                                slave: s,
                                master: Contactee::Rigid,
                                xi: 0.0,
                                gap: g1,
                                normal: *n,
                                tangents: *tangents,
                                dim: 3,
                                weights,
                                length: 0.0,
                            });
                        }
                    }
                }
                Master::Segments(_) | Master::Rigid { .. } => {}
            }
        }
    }
    if out.len() > before {
        out.sort_by_key(Candidate::slave_key);
    }
}
