//! The explicit path's collisions in a solid: the paper's cubic of a node against
//! a moving triangle (a quadrilateral face as its two triangles), or the time a node
//! reaches a rigid plane, and the rows of such an impact (`theory/contact3d.md`).

use super::{Dofs, KinematicContact, Row, ROW_DOFS};
use crate::contact::collision::node_triangle;
use crate::contact::state::{Key, Slave, Target};
use crate::geometry::{add, cross, dot, norm, scale, sub};
use crate::model::Master;

/// A solid's row along `d`: `+d` on the slave, `−w_k d` on the corners `nodes`.
fn row_of_face(slave: usize, nodes: &[(usize, f64)], d: [f64; 3]) -> Dofs {
    let mut r = ([(0usize, 0.0f64); ROW_DOFS], 0);
    let mut push = |node: usize, w: f64| {
        for (i, di) in d.iter().enumerate() {
            r.0[r.1] = (3 * node + i, w * di);
            r.1 += 1;
        }
    };
    push(slave, 1.0);
    for &(node, w) in nodes {
        push(node, -w);
    }
    r
}

/// A slave's earliest impact in a solid: when, on which face (or the rigid plane)
/// at which corners and weights, along which normal.
#[derive(Clone, Copy, Debug)]
struct SolidHit {
    slave: usize,
    t_c: f64,
    target: Target,
    /// The triangle's corners and their barycentric weights (none on a plane).
    corners: [(usize, f64); 3],
    n_corners: usize,
    normal: [f64; 3],
}

/// The rows of a solid's impact along the normal `n`: the normal one and its two
/// tangents.
fn solid_rows(slave: usize, nodes: &[(usize, f64)], n: [f64; 3]) -> (Dofs, [Dofs; 2], usize) {
    let t = crate::contact::faces::plane_tangents(n);
    (
        row_of_face(slave, nodes, n),
        [
            row_of_face(slave, nodes, t[0]),
            row_of_face(slave, nodes, t[1]),
        ],
        2,
    )
}

impl KinematicContact<'_> {
    /// The earliest collision of every slave node of a solid within the step: the
    /// paper's cubic of a node against a moving triangle (a quadrilateral face as
    /// its two triangles), or the time it reaches a rigid plane.
    pub(super) fn solid_collisions(&mut self, u: &[f64], v: &[f64], h: f64) {
        let coords = &self.model.mesh.coords;
        let at = |n: usize| {
            let c = coords[n];
            [c[0] + u[3 * n], c[1] + u[3 * n + 1], c[2] + u[3 * n + 2]]
        };
        let vel = |n: usize| [v[3 * n], v[3 * n + 1], v[3 * n + 2]];
        for (pi, pair) in self.model.contacts.iter().enumerate() {
            for (si, side) in pair.sides.iter().enumerate() {
                let mut hits: Vec<SolidHit> = Vec::new();
                match &side.master {
                    Master::Faces(faces) => {
                        let r = pair.radius;
                        // Reach: the faces' boxes grown by the pair's radius.
                        let tree =
                            crate::contact::faces::face_tree(faces, |n| std::iter::once(at(n)), r);
                        for &s in &side.slaves {
                            let p = at(s);
                            let mut best: Option<SolidHit> = None;
                            for hit in tree.locate_all_at_point(p) {
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
                                for tri in triangles {
                                    let [a, b, cc] = tri.map(|i| c[i]);
                                    let Some(t) = node_triangle(
                                        p,
                                        vel(s),
                                        at(a),
                                        vel(a),
                                        at(b),
                                        vel(b),
                                        at(cc),
                                        vel(cc),
                                        h,
                                    ) else {
                                        continue;
                                    };
                                    if best.as_ref().is_some_and(|b| b.t_c <= t.t) {
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
                                    best = Some(SolidHit {
                                        slave: s,
                                        t_c: t.t,
                                        target: Target::Facet(hit.data),
                                        corners: [(a, t.bary[0]), (b, t.bary[1]), (cc, t.bary[2])],
                                        n_corners: 3,
                                        normal: nn.map(|c| c / l),
                                    });
                                }
                            }
                            hits.extend(best);
                        }
                    }
                    Master::Plane { point, n, .. } => {
                        for &s in &side.slaves {
                            let (p, w) = (at(s), vel(s));
                            let g0 = dot(sub(p, *point), *n);
                            let vn = dot(w, *n);
                            // Reaching the plane from its side within the step (a node
                            // on it at the start and moving in meets it at once).
                            if g0 >= 0.0 && vn < 0.0 && g0 + h * vn <= 0.0 {
                                hits.push(SolidHit {
                                    slave: s,
                                    t_c: g0 / -vn,
                                    target: Target::Rigid,
                                    corners: [(0, 0.0); 3],
                                    n_corners: 0,
                                    normal: *n,
                                });
                            }
                        }
                    }
                    Master::Segments(_) | Master::Rigid { .. } => {}
                }
                for hit in hits {
                    let (normal, tangents, n_tangents) =
                        solid_rows(hit.slave, &hit.corners[..hit.n_corners], hit.normal);
                    self.rows.push(Row {
                        key: Key {
                            slave: Slave::new(pi, si, hit.slave),
                            target: hit.target,
                        },
                        t_c: hit.t_c,
                        normal,
                        tangents,
                        n_tangents,
                        beta: pair.friction,
                        mu: pair.mu,
                        weight: pair.position_weight,
                    });
                }
            }
        }
    }
}
