//! A solid's master: a set of faces of another solid (triangles and bilinear
//! quadrilaterals), numbered counter-clockwise seen from outside.
//!
//! Broad phase: an R-tree (`rstar`) of the faces' bounding boxes
//! ([`super::face_tree`], kept across evaluations by detection), queried with the
//! box of the pair's search radius about each slave. Narrow phase: the closest point
//! of each face in reach (a triangle's by its Voronoi regions, a quadrilateral's by
//! Gauss-Newton on its bilinear map, clamped to its edges); the nearest face wins
//! (an interior projection over one on the face's boundary on a tie).
//!
//! The row of a slave is that of its nearest face: the gap along the surface's
//! normal at the closest point, the weights `+1` on the slave and `−N_k(ξ, η)` on
//! the face's corners (its own shape functions, so the linearised gap moves with the
//! face as the elements do). The normal is the surface's smoothed one: the nodal
//! normals (the normalised sum of the unit normals of the faces meeting at a node)
//! interpolated with the same shape functions, so it is continuous over edges and
//! corners and a slave over an edge does not flip between two faces' normals from
//! one iteration to the next; on a flat surface it is the surface's own. Where a
//! neighbouring face rises out of the plane of the nearest one by more than
//! [`VALLEY_SINE`] (a valley) and the slave lies within [`NEAR_EDGE`] of their
//! common boundary, both faces hold it, each as the half-space of its own plane, as
//! the plane's notches are (`theory/contact3d.md`).
//!
//! The sweep and the explicit collisions take the time a node meets a moving
//! triangle (a quadrilateral as its two) from
//! [`crate::contact::collision::node_triangle`].

use std::cell::OnceCell;

use rstar::AABB;

use super::face_tree::{bounding_box, face_tree, FaceTree};
use super::face_tree::{KeptFaces, Topology};

pub use super::projection::{project, Projection, Region};
use super::rigid::{EdgeHistory, RIGID_END_MARGIN};
use super::{Impact, MasterSurface, Positions};
use crate::contact::collision::node_triangle;
use crate::contact::rows::{Candidate, Contactee};
use crate::contact::state::{Slave, Target};
use crate::geometry::{add, norm, scale};
use crate::mesh::Face;

/// How close (in the face's local coordinates, relative to its size) to an edge a
/// slave's closest point must be for a face rising beyond that edge to hold it too:
/// a thousandth, as [`super::segments::NEAR_VERTEX`] in the plane.
pub const NEAR_EDGE: f64 = 1e-3;

/// How steeply (the sine of the angle) a neighbouring face must rise out of the
/// plane of the nearest one for a slave at their common edge to be held by both: a
/// hundredth (about 0.6°). Below it the valley is flat enough for one row along the
/// edge's normal: the normals of the faces differ by less than the angle, so a slave
/// passing from one to the other moves the row by as little; above it, two half-spaces
/// hold the slave where one row would flip between the faces. Without a threshold a
/// slave over a vertex of a flat surface pressed in by round-off would get four
/// nearly equal rows, which make the condensed matrix singular.
pub const VALLEY_SINE: f64 = 1e-2;

type V3 = [f64; 3];

use crate::geometry::{cross, unit};
use crate::geometry::{dot, sub};

/// The faces' unit normals at their centres and the nodal normals of the surface:
/// at each node the normalised sum of the unit normals of the faces meeting there.
struct Surface {
    normal: Vec<V3>,
    /// By the set's node numbering ([`Topology`]).
    at_node: Vec<V3>,
}

impl Surface {
    fn new<X: Fn(usize) -> V3>(faces: &[Face], topology: &Topology, x: &X) -> Surface {
        let mut normal = Vec::with_capacity(faces.len());
        let mut at_node = vec![[0.0; 3]; topology.nodes.len()];
        for (f, local) in faces.iter().zip(&topology.corners) {
            let c = f.corners();
            let n = if c.len() == 3 {
                cross(sub(x(c[1]), x(c[0])), sub(x(c[2]), x(c[0])))
            } else {
                cross(sub(x(c[2]), x(c[0])), sub(x(c[3]), x(c[1])))
            };
            let n = unit(n).unwrap_or([0.0; 3]);
            normal.push(n);
            for &v in &local[..c.len()] {
                let e = &mut at_node[v];
                for i in 0..3 {
                    e[i] += n[i];
                }
            }
        }
        for v in &mut at_node {
            *v = unit(*v).unwrap_or([0.0; 3]);
        }
        Surface { normal, at_node }
    }

    /// The row's normal at a projection on `face`: the nodal normals interpolated
    /// with the face's shape functions there, normalised. Continuous over the whole
    /// surface (two faces sharing an edge interpolate the same two nodal normals
    /// along it), so a slave passing from a face to its neighbour, or lying over
    /// their edge, meets one normal from either side and does not flip between the
    /// faces' own from one iteration to the next; on a flat surface it is the
    /// surface's normal. Over a convex ridge or corner it is the ridge's or corner's
    /// mean normal.
    fn normal(&self, local: &[usize], pr: &Projection) -> V3 {
        let mut n = [0.0; 3];
        for (k, &v) in local.iter().enumerate() {
            let m = self.at_node[v];
            for i in 0..3 {
                n[i] += pr.weights[k] * m[i];
            }
        }
        unit(n).unwrap_or(pr.normal)
    }
}

/// The boundary edges of a face set: the sorted node pairs that one face only has,
/// sorted. Where a master surface ends (validation stores them with the side).
pub fn boundary_edges(faces: &[Face]) -> Vec<[usize; 2]> {
    let mut edges: Vec<[usize; 2]> = faces
        .iter()
        .flat_map(|f| {
            let c = f.corners();
            (0..c.len()).map(move |i| {
                let (a, b) = (c[i], c[(i + 1) % c.len()]);
                [a.min(b), a.max(b)]
            })
        })
        .collect();
    edges.sort_unstable();
    edges
        .chunk_by(|a, b| a == b)
        .filter(|run| run.len() == 1)
        .map(|run| run[0])
        .collect()
}

/// Whether the projection `pr` of `p` on `face` lies on the master surface's
/// boundary (`edges`, sorted, and their sorted nodes `rim`: an edge of one face
/// only, or a corner on one) with `p` beyond it: the slave's projection has left the
/// master surface, and no force holds it. The margin, a thousandth of the face's
/// longest edge ([`RIGID_END_MARGIN`]), keeps a slave exactly at the edge from
/// flickering on round-off.
fn beyond_boundary<X: Fn(usize) -> V3>(
    (edges, rim): (&[[usize; 2]], &[usize]),
    p: V3,
    face: &Face,
    pr: &Projection,
    x: &X,
) -> bool {
    let c = face.corners();
    let on_edge = match pr.region {
        Region::Edge(i) => {
            let (a, b) = (c[i], c[(i + 1) % c.len()]);
            edges.binary_search(&[a.min(b), a.max(b)]).is_ok()
        }
        Region::Corner(i) => rim.binary_search(&c[i]).is_ok(),
        Region::Interior { .. } => false,
    };
    if !on_edge {
        return false;
    }
    let d = sub(p, pr.point);
    let dn = dot(d, pr.normal);
    let t2 = (dot(d, d) - dn * dn).max(0.0);
    let longest = (0..c.len())
        .map(|i| {
            let e = sub(x(c[(i + 1) % c.len()]), x(c[i]));
            dot(e, e)
        })
        .fold(0.0, f64::max);
    t2 > RIGID_END_MARGIN.powi(2) * longest
}

/// A set of faces at a geometry.
pub struct FaceSurface<'a> {
    faces: &'a [Face],
    /// The set's boundary edges (sorted) and their nodes (sorted): where it ends.
    edges: &'a [[usize; 2]],
    rim: Vec<usize>,
    x: Positions<'a>,
    /// What detection keeps across evaluations, if it keeps anything.
    kept: Option<&'a KeptFaces>,
    topology: OnceCell<Topology>,
    surface: OnceCell<Surface>,
    tree: OnceCell<FaceTree>,
    swept: OnceCell<FaceTree>,
    grown: OnceCell<FaceTree>,
}

impl<'a> FaceSurface<'a> {
    /// The faces `faces` with the boundary `edges` ([`boundary_edges`]) at the
    /// geometry `x`.
    pub fn new(faces: &'a [Face], edges: &'a [[usize; 2]], x: Positions<'a>) -> Self {
        let mut rim: Vec<usize> = edges.iter().flatten().copied().collect();
        rim.sort_unstable();
        rim.dedup();
        FaceSurface {
            faces,
            edges,
            rim,
            x,
            kept: None,
            topology: OnceCell::new(),
            surface: OnceCell::new(),
            tree: OnceCell::new(),
            swept: OnceCell::new(),
            grown: OnceCell::new(),
        }
    }

    /// The same, its topology and detection's tree taken from `kept` (built for
    /// these faces and refreshed for `x`).
    pub fn kept(mut self, kept: &'a KeptFaces) -> Self {
        self.kept = Some(kept);
        self
    }

    /// The faces within `r` of slave `s` with their projections, and the nearest
    /// (interior over boundary on a tie, then by index, so the choice does not depend
    /// on the tree's order).
    #[allow(clippy::type_complexity)]
    fn nearest(&self, s: usize, r: f64) -> (Vec<(usize, Projection)>, Option<(usize, Projection)>) {
        let faces = self.faces;
        let x = |n: usize| self.x(n);
        let tree = match self.kept {
            Some(k) => &k.tree,
            None => self
                .tree
                .get_or_init(|| face_tree(faces, |n| std::iter::once(x(n)), 0.0)),
        };
        let p = x(s);
        let reach = AABB::from_corners(
            [p[0] - r, p[1] - r, p[2] - r],
            [p[0] + r, p[1] + r, p[2] + r],
        );
        let mut near: Vec<(usize, Projection)> = Vec::new();
        for hit in tree.locate_in_envelope_intersecting(reach) {
            let f = &faces[hit.data];
            if f.corners().contains(&s) {
                continue;
            }
            if let Some(pr) = project(p, f, &x) {
                if pr.d2 <= r * r {
                    near.push((hit.data, pr));
                }
            }
        }
        let rank = |(k, pr): &(usize, Projection)| {
            (pr.d2, !matches!(pr.region, Region::Interior { .. }), *k)
        };
        let best = near
            .iter()
            .min_by(|a, b| {
                let (ra, rb) = (rank(a), rank(b));
                if ra.0 < rb.0 * (1.0 - 1e-12) {
                    std::cmp::Ordering::Less
                } else if rb.0 < ra.0 * (1.0 - 1e-12) {
                    std::cmp::Ordering::Greater
                } else {
                    (ra.1, ra.2).cmp(&(rb.1, rb.2))
                }
            })
            .copied();
        (near, best)
    }

    /// Whether slave `s` lies below the surface's level by more than `depth` (along
    /// its nearest face's normal, within `r`) and either beyond the set's boundary or
    /// passed over already (`before`): a node that came around the master's edge,
    /// beside its end face, which a row would fling up onto the surface in one step
    /// (the face set's form of the rigid line's rule, [`super::rigid::beneath_rigid`]).
    pub fn passed_over(&self, s: usize, r: f64, depth: f64, before: bool) -> bool {
        let x = |n: usize| self.x(n);
        let Some((k, pr)) = self.nearest(s, r).1 else {
            return false;
        };
        let p = x(s);
        let gap = dot(sub(p, pr.point), pr.normal);
        gap < -depth
            && (before || beyond_boundary((self.edges, &self.rim), p, &self.faces[k], &pr, &x))
    }

    fn x(&self, n: usize) -> V3 {
        self.x.at::<3>(n)
    }

    fn topology(&self) -> &Topology {
        match self.kept {
            Some(k) => &k.topology,
            None => self.topology.get_or_init(|| Topology::new(self.faces)),
        }
    }

    /// The faces' and the nodes' normals at the surface's geometry.
    fn surface(&self) -> &Surface {
        self.surface
            .get_or_init(|| Surface::new(self.faces, self.topology(), &|n| self.x(n)))
    }

    /// The smoothed normal at a projection `pr` on face `k`.
    fn smooth_normal(&self, k: usize, pr: &Projection) -> V3 {
        let local = &self.topology().corners[k][..self.faces[k].corners().len()];
        self.surface().normal(local, pr)
    }

    /// The row of `slave` against face `index` at its projection `pr`, along
    /// `normal`.
    fn candidate(&self, slave: Slave, index: usize, pr: &Projection, normal: V3) -> Candidate {
        let face = &self.faces[index];
        let mut corners = [(0, 0.0); 4];
        for (k, &v) in face.corners().iter().enumerate() {
            corners[k] = (v, pr.weights[k]);
        }
        Candidate::nodal::<3>(
            slave,
            Contactee::Face {
                index,
                nodes: *face,
            },
            &corners[..face.corners().len()],
            0.0,
            dot(sub(self.x(slave.node), pr.point), normal),
            normal,
        )
    }
}

/// The triangles of a face, as corner indices (a quadrilateral's two about its
/// first diagonal).
fn triangles(face: &Face) -> &'static [[usize; 3]] {
    if face.is_triangle() {
        &[[0, 1, 2]]
    } else {
        &[[0, 1, 2], [0, 2, 3]]
    }
}

impl MasterSurface for FaceSurface<'_> {
    fn detect(&self, slave: Slave, r: f64, rigid: &EdgeHistory, out: &mut Vec<Candidate>) {
        if rigid.is_beneath(slave) {
            return;
        }
        let faces = self.faces;
        let x = |n: usize| self.x(n);
        let s = slave.node;
        let p = x(s);
        let (near, best) = self.nearest(s, r);
        let Some(best) = best else {
            return;
        };
        let (k, pr) = best;
        if beyond_boundary((self.edges, &self.rim), p, &faces[k], &pr, &x) {
            return;
        }
        // Faces rising beyond the edge or corner the point is at (or near): a
        // valley, each face its own half-space.
        let on_boundary = match pr.region {
            Region::Interior { margin } => margin <= NEAR_EDGE,
            _ => true,
        };
        let mut held: Vec<usize> = Vec::new();
        if on_boundary {
            let nk = self.surface().normal[k];
            let own = faces[k].corners();
            let shared = |f: usize| faces[f].corners().iter().any(|v| own.contains(v));
            for (f, prf) in &near {
                if *f == k || !shared(*f) {
                    continue;
                }
                let inside = match prf.region {
                    Region::Interior { .. } => true,
                    _ => prf.d2 <= pr.d2 * (1.0 + 1e-9) + f64::MIN_POSITIVE,
                };
                // The corners of the neighbour it does not share with the nearest
                // face (a shared one lies on the boundary, where round-off decides
                // the sign).
                let rises = faces[*f]
                    .corners()
                    .iter()
                    .filter(|v| !own.contains(v))
                    .any(|&v| {
                        let d = sub(x(v), pr.point);
                        dot(d, nk) > VALLEY_SINE * dot(d, d).sqrt()
                    });
                if inside && rises {
                    held.push(*f);
                }
            }
        }
        if held.is_empty() {
            let normal = self.smooth_normal(k, &pr);
            out.push(self.candidate(slave, k, &pr, normal));
        } else {
            held.push(k);
            held.sort_unstable();
            for f in held {
                let prf = near.iter().find(|(g, _)| *g == f).map(|(_, p)| *p);
                if let Some(prf) = prf {
                    out.push(self.candidate(slave, f, &prf, prf.normal));
                }
            }
        }
    }

    fn nodes(&self) -> Option<Vec<usize>> {
        Some(
            self.faces
                .iter()
                .flat_map(|f| f.corners().iter().copied())
                .collect(),
        )
    }

    fn crossing(&self, slave: Slave, start: Positions, rigid: &EdgeHistory) -> Option<Candidate> {
        if rigid.is_beneath(slave) {
            return None;
        }
        let x0 = |n: usize| start.at::<3>(n);
        let x1 = |n: usize| self.x(n);
        let faces = self.faces;
        let tree = self
            .swept
            .get_or_init(|| face_tree(faces, |n| [x0(n), x1(n)].into_iter(), 0.0));
        let s = slave.node;
        let (p0, p1) = (x0(s), x1(s));
        let reach = bounding_box([p0, p1].into_iter(), 0.0);
        let mut first: Option<(f64, usize)> = None;
        for hit in tree.locate_in_envelope_intersecting(reach) {
            let f = &faces[hit.data];
            let c = f.corners();
            if c.contains(&s) {
                continue;
            }
            let motion = |n: usize| (x0(n), sub(x1(n), x0(n)));
            for tri in triangles(f) {
                let [(a, va), (b, vb), (cc, vc)] = tri.map(|i| motion(c[i]));
                let t = node_triangle(p0, sub(p1, p0), a, va, b, vb, cc, vc, 1.0);
                if let Some(t) = t {
                    if first.is_none_or(|(t0, _)| t.t < t0) {
                        first = Some((t.t, hit.data));
                    }
                }
            }
        }
        let (_, k) = first?;
        let pr = project(p1, &faces[k], &x1)?;
        let normal = self.smooth_normal(k, &pr);
        Some(self.candidate(slave, k, &pr, normal))
    }

    fn impact(
        &self,
        slave: Slave,
        v: Positions,
        h: f64,
        r: f64,
        rigid: &EdgeHistory,
    ) -> Option<Impact> {
        if rigid.is_beneath(slave) {
            return None;
        }
        let faces = self.faces;
        let at = |n: usize| self.x(n);
        let vel = |n: usize| v.at::<3>(n);
        // Reach: the faces' boxes grown by the pair's radius.
        let tree = self
            .grown
            .get_or_init(|| face_tree(faces, |n| std::iter::once(at(n)), r));
        let s = slave.node;
        let p = at(s);
        let mut best: Option<Impact> = None;
        for hit in tree.locate_all_at_point(p) {
            let c = faces[hit.data].corners();
            if c.contains(&s) {
                continue;
            }
            for tri in triangles(&faces[hit.data]) {
                let [a, b, cc] = tri.map(|i| c[i]);
                let Some(t) =
                    node_triangle(p, vel(s), at(a), vel(a), at(b), vel(b), at(cc), vel(cc), h)
                else {
                    continue;
                };
                if best.as_ref().is_some_and(|b| b.t <= t.t) {
                    continue;
                }
                // The triangle's outward normal at the impact.
                let x = |n: usize| add(at(n), scale(vel(n), t.t));
                let (xa, xb, xc) = (x(a), x(b), x(cc));
                let nn = cross(sub(xb, xa), sub(xc, xa));
                let l = norm(nn);
                // A degenerate triangle (NaN counts as one).
                if l.is_nan() || l <= 0.0 {
                    continue;
                }
                best = Some(Impact {
                    t: t.t,
                    target: Target::Facet(hit.data),
                    corners: [(a, t.bary[0]), (b, t.bary[1]), (cc, t.bary[2])],
                    n_corners: 3,
                    normal: nn.map(|c| c / l),
                });
            }
        }
        best
    }
}

/// The slaves of face masters that came around a master's edge: at the geometry
/// `x` (committed: the start of a step) they lie below the face set's level by more
/// than `depth`, and either beyond its boundary or already so in `previous` (the last
/// step's list), sorted. As a rigid line's ([`super::rigid::beneath_rigid`]): a
/// slave past a master's edge is free and may sink beside the master's end face (a
/// beam rotating over the edge of a support); a row would fling it up onto the
/// surface in one step when it comes back over the edge (benchmark 2 as solids,
/// one way: `D_contact` −16 `E_kin⁰`, theory/benchmarks.md). Such a slave stays
/// passed over until it rises above the level again. Node-to-face sides only: a
/// mortar side's rows weigh only the part of a slave face that faces the master.
pub fn beneath_faces(
    pairs: &[crate::model::ContactPair],
    x: Positions,
    depth: f64,
    previous: &[Slave],
) -> Vec<Slave> {
    let mut out = Vec::new();
    for (pi, pair) in pairs.iter().enumerate() {
        for (si, side) in pair.sides.iter().enumerate() {
            // A mortar side integrates over what its slave faces see of the master:
            // no node of it is held by this rule.
            if pair.formulation == crate::model::Formulation::Mortar {
                continue;
            }
            if let crate::model::Master::Faces { faces, boundary } = &side.master {
                let surface = FaceSurface::new(faces, boundary, x);
                for &s in &side.slaves {
                    let key = Slave::new(pi, si, s);
                    let before = previous.binary_search(&key).is_ok();
                    if surface.passed_over(s, pair.radius, depth, before) {
                        out.push(key);
                    }
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::tests::detect;
    use super::*;

    fn side(slaves: Vec<usize>, faces: Vec<Face>) -> crate::model::ContactPair {
        crate::model::ContactPair {
            name: "p".into(),
            sides: vec![crate::model::ContactSide {
                slaves,
                master: crate::model::Master::Faces {
                    faces,
                    boundary: Vec::new(),
                },
                surface: crate::model::SlaveSurface::Nodes,
            }],
            radius: 1.0,
            friction: 0.0,
            mu: 0.0,
            formulation: crate::model::Formulation::NodeToSegment,
            mortar_basis: crate::model::MortarBasis::Dual,
            position_weight: 0.5,
        }
    }

    #[test]
    fn a_slave_in_a_valley_is_held_by_both_faces_and_one_over_a_ridge_by_one() {
        // Two quadrilaterals meeting along the z axis (nodes 0, 1), rising to
        // either side by `rise` over a unit run: a valley for rise > 0, a ridge for
        // rise < 0 (outward normals up).
        let geometry = |rise: f64| {
            vec![
                [0.0, 0.0, 0.0],
                [0.0, 0.0, 1.0],
                [1.0, rise, 1.0],
                [1.0, rise, 0.0],
                [-1.0, rise, 0.0],
                [-1.0, rise, 1.0],
                [0.0, 1e-9, 0.5], // slave over the common edge
            ]
        };
        let faces = vec![
            Face::quadrilateral([0, 1, 2, 3]),
            Face::quadrilateral([1, 0, 4, 5]),
        ];
        let mut out = Vec::new();
        let x = geometry(0.2);
        detect(&[side(vec![6], faces.clone())], &x, &mut out);
        assert_eq!(out.len(), 2, "{out:?}");
        for c in &out {
            // Each along its own face's normal (leaning away from the other face).
            assert!(c.normal[1] > 0.9 && c.normal[0].abs() > 0.1, "{c:?}");
        }
        assert!(out[0].normal[0] * out[1].normal[0] < 0.0);
        // A ridge: one row along the ridge's mean normal (straight up).
        let x = geometry(-0.2);
        detect(&[side(vec![6], faces.clone())], &x, &mut out);
        assert_eq!(out.len(), 1, "{out:?}");
        assert!(out[0].normal[0].abs() < 1e-12 && (out[0].normal[1] - 1.0).abs() < 1e-12);
        // A nearly flat valley (below VALLEY_SINE): one row, continuous normal.
        let x = geometry(1e-4);
        detect(&[side(vec![6], faces)], &x, &mut out);
        assert_eq!(out.len(), 1, "{out:?}");
        assert!(out[0].normal[0].abs() < 1e-12);
    }

    #[test]
    fn a_kept_tree_gives_the_rows_of_a_fresh_one_as_the_geometry_moves() {
        // The valley of two faces, its slave over the common edge, reshaped and carried
        // step by step farther than the kept tree's margin: detection with the kept
        // tree and topology gives the same rows, bit for bit, as detection without.
        let faces = vec![
            Face::quadrilateral([0, 1, 2, 3]),
            Face::quadrilateral([1, 0, 4, 5]),
        ];
        let pairs = [side(vec![6], faces)];
        let mut kept = crate::contact::detect::Kept::default();
        let (mut with, mut without) = (Vec::new(), Vec::new());
        for k in 0..40 {
            let (rise, shift) = (0.2 - 0.01 * k as f64, 0.003 * k as f64);
            let x: Vec<f64> = [
                [0.0, 0.0, 0.0],
                [0.0, 0.0, 1.0],
                [1.0, rise, 1.0],
                [1.0, rise, 0.0],
                [-1.0, rise, 0.0],
                [-1.0, rise, 1.0],
                [shift, 1e-9 + 0.001 * k as f64, 0.5],
            ]
            .iter()
            // The whole valley carried along x, past the tree's boxes.
            .flat_map(|p| [p[0] + 0.5 * k as f64, p[1], p[2]])
            .collect();
            let x = Positions::new(&x, 3);
            let none = EdgeHistory::default();
            crate::contact::detect::detect(&pairs, x, &none, Some(&mut kept), &mut with);
            crate::contact::detect::detect(&pairs, x, &none, None, &mut without);
            assert!(!without.is_empty(), "step {k}");
            assert_eq!(with, without, "step {k}");
        }
    }

    #[test]
    fn a_slave_that_came_around_a_face_sets_edge_is_passed_over() {
        // One face y = 0 over 0 ≤ x, z ≤ 1 (normal +y); depth 1e-3.
        let faces = [Face::quadrilateral([0, 1, 2, 3])];
        let edges = boundary_edges(&faces);
        let at = |slave: [f64; 3]| -> Vec<f64> {
            [
                [0.0, 0.0, 0.0],
                [0.0, 0.0, 1.0],
                [1.0, 0.0, 1.0],
                [1.0, 0.0, 0.0],
                slave,
            ]
            .iter()
            .flatten()
            .copied()
            .collect()
        };
        let passed = |slave: [f64; 3], before: bool| {
            let x = at(slave);
            FaceSurface::new(&faces, &edges, Positions::new(&x, 3))
                .passed_over(4, 1.0, 1e-3, before)
        };
        // Beside the edge and below the level: passed over, whatever came before.
        assert!(passed([1.01, -0.01, 0.5], false));
        // Back over the face, still below: passed over only if it was.
        assert!(passed([0.9, -0.01, 0.5], true));
        assert!(!passed([0.9, -0.01, 0.5], false));
        // Within the depth, or above the level: held again.
        assert!(!passed([0.9, -0.5e-3, 0.5], true));
        assert!(!passed([1.01, 0.01, 0.5], true));
    }
}
