//! Initial overlaps at any depth, at the reference geometry.
//!
//! Detection ([`super::detect`], [`super::master`]) looks for masters within a pair's
//! search radius, about one element: a slave sunk deeper into its master's body has
//! no candidate and would sit there with no force. This test needs no radius. A slave
//! node of a deformable pair overlaps when it lies inside an element of the master's
//! body (a tetrahedron, a hexahedron as six tetrahedra about its diagonal, a convex
//! polygon in the plane) farther than the contact tolerance from the master surface.
//! A rigid line or plane cuts its slave body when any node of that body (not only of
//! the slave set) lies behind it by more than the tolerance, within a line's ends: the
//! side a rigid master keeps is the one the body's centroid lies on, so a cut body
//! would be flung across, or the master would act as a ceiling that never touches.
//! `config::validate` refuses both with the pair, the node and the depth.

use rstar::{RTree, AABB};

use crate::mesh::{Mesh, Point};
use crate::model::{ContactPair, Master};

/// The deepest overlap of one pair side found at the reference geometry.
#[derive(Clone, Debug, PartialEq)]
pub struct Overlap {
    /// The pair.
    pub pair: usize,
    /// The node that lies where it may not.
    pub node: usize,
    /// How deep (m): the distance to the master surface, or behind the rigid master.
    pub depth: f64,
    /// What it lies in or behind, in words.
    pub what: String,
    /// How many nodes of the pair overlap by more than the tolerance.
    pub count: usize,
}

/// The deepest overlap over every pair deeper than `tolerance`, if any.
pub fn deepest(mesh: &Mesh, pairs: &[ContactPair], tolerance: f64) -> Option<Overlap> {
    let mut worst: Option<Overlap> = None;
    for (pi, pair) in pairs.iter().enumerate() {
        for side in &pair.sides {
            let found = match &side.master {
                Master::Rigid { a, b, n } => {
                    behind_line(mesh, side_body(mesh, side), *a, *b, *n, tolerance)
                }
                Master::Plane { point, n, .. } => {
                    behind_plane(mesh, side_body(mesh, side), *point, *n, tolerance)
                }
                Master::Segments(segments) => {
                    let body = mesh.node_body[segments[0][0]];
                    inside_body(mesh, body, &side.slaves, tolerance, |p| {
                        segments
                            .iter()
                            .map(|&[a, b]| {
                                super::master::segments::closest(
                                    [p[0], p[1]],
                                    crate::mesh::xy(mesh.coords[a]),
                                    crate::mesh::xy(mesh.coords[b]),
                                )
                                .1
                            })
                            .fold(f64::INFINITY, f64::min)
                    })
                }
                Master::Faces { faces, .. } => {
                    let body = mesh.node_body[faces[0][0]];
                    inside_body(mesh, body, &side.slaves, tolerance, |p| {
                        faces
                            .iter()
                            .filter_map(|f| {
                                super::master::projection::project(p, f, &|n| mesh.coords[n])
                            })
                            .map(|pr| pr.d2)
                            .fold(f64::INFINITY, f64::min)
                    })
                }
            };
            if let Some((node, depth, what, count)) = found {
                if worst.as_ref().is_none_or(|w| depth > w.depth) {
                    worst = Some(Overlap {
                        pair: pi,
                        node,
                        depth,
                        what,
                        count,
                    });
                }
            }
        }
    }
    worst
}

/// The body of a side's slaves.
fn side_body(mesh: &Mesh, side: &crate::model::ContactSide) -> usize {
    mesh.node_body[side.slaves[0]]
}

/// `(node, depth, words, count)` of the deepest of `hits`.
type Found = Option<(usize, f64, String, usize)>;

fn deepest_of(hits: impl Iterator<Item = (usize, f64)>, what: impl Fn(usize) -> String) -> Found {
    let mut count = 0;
    let mut best: Option<(usize, f64)> = None;
    for (n, d) in hits {
        count += 1;
        if best.is_none_or(|b| d > b.1) {
            best = Some((n, d));
        }
    }
    best.map(|(n, d)| (n, d, what(n), count))
}

/// Nodes of `body` behind the rigid line `a`-`b` (normal `n` towards the body) by more
/// than `tol`, within its ends.
fn behind_line(mesh: &Mesh, body: usize, a: [f64; 2], b: [f64; 2], n: [f64; 2], tol: f64) -> Found {
    let t = [b[0] - a[0], b[1] - a[1]];
    let l2 = t[0] * t[0] + t[1] * t[1];
    let hits = body_nodes(mesh, body).filter_map(|k| {
        let p = mesh.coords[k];
        let xi = ((p[0] - a[0]) * t[0] + (p[1] - a[1]) * t[1]) / l2;
        let gap = (p[0] - a[0]) * n[0] + (p[1] - a[1]) * n[1];
        (super::master::rigid::within_ends(xi) && gap < -tol).then_some((k, -gap))
    });
    deepest_of(hits, |_| {
        "behind its rigid line (the line cuts the slave body)".into()
    })
}

/// Nodes of `body` behind the rigid plane by more than `tol`.
fn behind_plane(mesh: &Mesh, body: usize, point: Point, n: Point, tol: f64) -> Found {
    let hits = body_nodes(mesh, body).filter_map(|k| {
        let gap = crate::geometry::dot(crate::geometry::sub(mesh.coords[k], point), n);
        (gap < -tol).then_some((k, -gap))
    });
    deepest_of(hits, |_| {
        "behind its rigid plane (the plane cuts the slave body)".into()
    })
}

fn body_nodes(mesh: &Mesh, body: usize) -> impl Iterator<Item = usize> + '_ {
    (0..mesh.coords.len()).filter(move |&k| mesh.node_body[k] == body)
}

/// Slaves inside an element of `body` and farther than `tol` from its master surface
/// (`distance2(p)`, the squared distance to it).
fn inside_body(
    mesh: &Mesh,
    body: usize,
    slaves: &[usize],
    tol: f64,
    distance2: impl Fn(Point) -> f64,
) -> Found {
    let solid = mesh.dim == 3;
    let mut items = Vec::new();
    for (bi, b) in mesh.blocks.iter().enumerate() {
        if b.body != body || b.elements.kind == crate::mesh::ElementKind::Bar2 {
            continue;
        }
        for e in 0..b.elements.len() {
            let pts = b.elements.element(e).iter().map(|&k| mesh.coords[k]);
            let bb = super::master::face_tree::bounding_box(pts, 0.0);
            items.push(rstar::primitives::GeomWithData::new(
                rstar::primitives::Rectangle::from_corners(bb.lower(), bb.upper()),
                (bi, e),
            ));
        }
    }
    let tree = RTree::bulk_load(items);
    let boundary = exterior(mesh, body);
    let mut element_of = std::collections::HashMap::new();
    let hits = slaves.iter().filter_map(|&s| {
        if mesh.node_body[s] == body {
            return None;
        }
        let p = mesh.coords[s];
        let (bi, e) = tree
            .locate_in_envelope_intersecting(AABB::from_point(p))
            .map(|g| g.data)
            .find(|&(bi, e)| {
                let nodes = mesh.blocks[bi].elements.element(e);
                let x: Vec<Point> = nodes.iter().map(|&k| mesh.coords[k]).collect();
                if solid {
                    inside_solid(p, &x)
                } else {
                    inside_polygon(p, &x)
                }
            })?;
        // Touching the master's body anywhere on its boundary (beside it, on a
        // face that is not the master's) is no overlap.
        if boundary
            .iter()
            .map(|b| b.distance2(p, mesh))
            .fold(f64::INFINITY, f64::min)
            <= tol * tol
        {
            return None;
        }
        let depth = distance2(p).sqrt();
        element_of.insert(s, (bi, e));
        (depth > tol).then_some((s, depth))
    });
    let found: Vec<(usize, f64)> = hits.collect();
    deepest_of(found.into_iter(), |s| {
        let (bi, e) = element_of[&s];
        format!(
            "inside the master's body (block {bi} element {e}; the depth is the distance to \
             the master surface)"
        )
    })
}

/// An edge (plane) or face (solid) on a body's boundary.
enum Facet {
    Edge([usize; 2]),
    Face(crate::mesh::Face),
}

impl Facet {
    fn distance2(&self, p: Point, mesh: &Mesh) -> f64 {
        let x = |n: usize| mesh.coords[n];
        match self {
            Facet::Edge([a, b]) => {
                super::master::segments::closest(
                    [p[0], p[1]],
                    crate::mesh::xy(x(*a)),
                    crate::mesh::xy(x(*b)),
                )
                .1
            }
            Facet::Face(f) => {
                super::master::projection::project(p, f, &x).map_or(f64::INFINITY, |pr| pr.d2)
            }
        }
    }
}

/// The facets of `body`'s continuum elements that no other of its elements shares:
/// its boundary.
fn exterior(mesh: &Mesh, body: usize) -> Vec<Facet> {
    let mut uses: std::collections::HashMap<Vec<usize>, (u32, Facet)> =
        std::collections::HashMap::new();
    for b in mesh.blocks.iter().filter(|b| b.body == body) {
        let kind = b.elements.kind;
        if kind == crate::mesh::ElementKind::Bar2 {
            continue;
        }
        for e in 0..b.elements.len() {
            let nodes = b.elements.element(e);
            let facets: Vec<Facet> = if kind.dim() == 3 {
                kind.faces()
                    .iter()
                    .map(|f| {
                        let mut face = [0; 4];
                        for (k, &a) in f.iter().enumerate() {
                            face[k] = nodes[a];
                        }
                        let face = crate::mesh::Face::from_corners(&face[..f.len()]);
                        Facet::Face(face.expect("an element face has three or four corners"))
                    })
                    .collect()
            } else {
                (0..nodes.len())
                    .map(|i| Facet::Edge([nodes[i], nodes[(i + 1) % nodes.len()]]))
                    .collect()
            };
            for f in facets {
                let mut key: Vec<usize> = match &f {
                    Facet::Edge(e) => e.to_vec(),
                    Facet::Face(f) => f.corners().to_vec(),
                };
                key.sort_unstable();
                uses.entry(key).or_insert((0, f)).0 += 1;
            }
        }
    }
    uses.into_values()
        .filter(|(n, _)| *n == 1)
        .map(|(_, f)| f)
        .collect()
}

/// Whether `p` lies in the polygon `x` (counter-clockwise, convex) or on its boundary.
fn inside_polygon(p: Point, x: &[Point]) -> bool {
    let n = x.len();
    (0..n).all(|i| {
        let (a, b) = (x[i], x[(i + 1) % n]);
        (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]) >= 0.0
    })
}

/// Whether `p` lies in the tetrahedron or hexahedron `x` (a hexahedron as the six
/// tetrahedra about its diagonal 0-6) or on its boundary.
fn inside_solid(p: Point, x: &[Point]) -> bool {
    if x.len() == 4 {
        return inside_tet(p, [x[0], x[1], x[2], x[3]]);
    }
    crate::mesh::solid::KUHN
        .iter()
        .any(|t| inside_tet(p, [x[t[0]], x[t[1]], x[t[2]], x[t[3]]]))
}

fn inside_tet(p: Point, t: [Point; 4]) -> bool {
    use crate::geometry::{dot, sub};
    let vol = |a: Point, b: Point, c: Point, d: Point| {
        dot(crate::geometry::cross(sub(b, a), sub(c, a)), sub(d, a))
    };
    let v = vol(t[0], t[1], t[2], t[3]);
    if v == 0.0 {
        return false;
    }
    let parts = [
        vol(p, t[1], t[2], t[3]),
        vol(t[0], p, t[2], t[3]),
        vol(t[0], t[1], p, t[3]),
        vol(t[0], t[1], t[2], p),
    ];
    parts.iter().all(|&w| w * v >= 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_point_is_inside_a_cube_and_its_tetrahedra_only_where_it_is() {
        let cube: Vec<Point> = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
            [0.0, 1.0, 1.0],
        ];
        for p in [
            [0.5, 0.5, 0.5],
            [0.9, 0.1, 0.2],
            [0.01, 0.99, 0.5],
            [1.0, 1.0, 1.0],
        ] {
            assert!(inside_solid(p, &cube), "{p:?}");
        }
        for p in [[1.01, 0.5, 0.5], [0.5, -0.01, 0.5], [0.5, 0.5, 1.2]] {
            assert!(!inside_solid(p, &cube), "{p:?}");
        }
        let square: Vec<Point> = cube[..4].to_vec();
        assert!(inside_polygon([0.3, 0.7, 0.0], &square));
        assert!(!inside_polygon([1.3, 0.7, 0.0], &square));
    }
}
