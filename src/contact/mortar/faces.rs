//! Mortar in a solid: face to face ([`super`] has the weighted gap).
//!
//! Each slave face (triangle or bilinear quadrilateral) is taken in its own plane:
//! the plane through its corners' centre with the face's normal (a triangle's, or a
//! quadrilateral's from its diagonals), the slave's corners and every facing master
//! face's corners projected onto it along that normal. Where the two plane polygons
//! overlap ([`super::clip::Polygon::clipped_by`]) the overlap is cut into a fan of
//! triangles and integrated by a seven-point rule exact to degree 5: at each point
//! the slave's and the master's shape functions are those of the projected faces
//! there ([`super::clip::shape_at`]), so for flat faces of straight-sided elements
//! the products `N_j N̂_l` (of degree 4 at most on parallelograms) are integrated
//! exactly, and on any faces the slave weights of a row sum to 1 and the master
//! weights to −1. The integral is over the projected slave face: the slave face's
//! own area when it is flat, as a box mesh's and a tetrahedral mesh's faces are.
//! Per overlap the products are summed in small local arrays and added to the rows
//! once, and master faces are taken in increasing index, so the rows do not depend
//! on the tree's order.

use super::clip::{shape_at, triangle_rule, Polygon};
use super::{finish, Facet, Gathered};
use crate::contact::master::face_tree::KeptFaces;
use crate::contact::master::Positions;
use crate::contact::rows::Candidate;
use crate::geometry::{cross, dot, sub, tangents, unit};
use crate::mesh::Face;
use crate::model::MortarBasis;

type V3 = [f64; 3];

/// A face at a geometry: its corners' positions, their centre and its unit normal.
struct Placed {
    x: [V3; 4],
    k: usize,
    centre: V3,
    normal: V3,
}

impl Placed {
    /// `f` at `x`; `None` for a face with no normal (collapsed).
    fn new(f: &Face, x: Positions) -> Option<Placed> {
        let c = f.corners();
        let k = c.len();
        let mut p = [[0.0; 3]; 4];
        for (pi, &n) in p.iter_mut().zip(c) {
            *pi = x.at::<3>(n);
        }
        let normal = if k == 3 {
            unit(cross(sub(p[1], p[0]), sub(p[2], p[0])))?
        } else {
            unit(cross(sub(p[2], p[0]), sub(p[3], p[1])))?
        };
        let mut centre = [0.0; 3];
        for q in &p[..k] {
            for i in 0..3 {
                centre[i] += q[i] / k as f64;
            }
        }
        Some(Placed {
            x: p,
            k,
            centre,
            normal,
        })
    }

    /// The point of the face (in space) with the corners' weights `w`.
    fn point(&self, w: &[f64; 4]) -> V3 {
        let mut p = [0.0; 3];
        for (q, &wi) in self.x[..self.k].iter().zip(w) {
            for i in 0..3 {
                p[i] += wi * q[i];
            }
        }
        p
    }
}

/// The mortar rows of one side (`key`: pair and side) against the master `faces` at
/// the geometry `x`, appended to `out` in slave order. `slaves` are the side's slave
/// nodes (sorted), `slave_faces` its slave surface, `basis` its test functions;
/// `kept` the master's kept tree
/// (its broad phase); master faces farther than `radius` from a slave face (along
/// its normal at the overlap's corners) are not integrated. Returns the most nodes a
/// row needed (more than [`crate::contact::rows::ROW_NODES`] means rows were cut:
/// validation refuses such a pair at the initial geometry).
#[allow(clippy::too_many_arguments)]
pub fn rows(
    key: (usize, usize),
    slaves: &[usize],
    slave_faces: &[Face],
    faces: &[Face],
    kept: &KeptFaces,
    radius: f64,
    basis: MortarBasis,
    x: Positions,
    out: &mut Vec<Candidate>,
) -> usize {
    let mut gathered = Gathered::<3>::empty(slaves.len());
    let slot = |n: usize| slaves.binary_search(&n).ok();
    let rule = triangle_rule();
    let mut near = Vec::new();
    for sf in slave_faces {
        let Some(s) = Placed::new(sf, x) else {
            continue;
        };
        let mut slots = [0; 4];
        if sf
            .corners()
            .iter()
            .zip(&mut slots)
            .any(|(&n, j)| slot(n).map(|k| *j = k).is_none())
        {
            continue;
        }
        let [t1, t2] = tangents(s.normal);
        let plane = |p: V3| {
            let d = sub(p, s.centre);
            [dot(d, t1), dot(d, t2)]
        };
        let sc: Vec<[f64; 2]> = s.x[..s.k].iter().map(|&p| plane(p)).collect();
        let slave_poly = Polygon::new(&sc);
        let area = slave_poly.area();
        if area <= 0.0 {
            continue;
        }
        for &j in &slots[..s.k] {
            gathered[j].total += area / s.k as f64;
        }
        let mut nodes = [0; 4];
        nodes[..s.k].copy_from_slice(sf.corners());
        let mut facet = Facet::new(basis, nodes, slots, s.k);
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in &s.x[..s.k] {
            for i in 0..3 {
                lo[i] = lo[i].min(p[i] - radius);
                hi[i] = hi[i].max(p[i] + radius);
            }
        }
        kept.within(lo, hi, &mut near);
        for &mi in &near {
            let mf = &faces[mi];
            if mf.corners().iter().any(|n| sf.corners().contains(n)) {
                continue;
            }
            let Some(m) = Placed::new(mf, x) else {
                continue;
            };
            // Only a master facing the slave (normals opposed) carries it.
            if dot(m.normal, s.normal) >= 0.0 {
                continue;
            }
            let mc: Vec<[f64; 2]> = m.x[..m.k].iter().map(|&p| plane(p)).collect();
            // Seen from the slave's side the master runs clockwise.
            let master_poly = Polygon::new(&mc).reversed();
            if master_poly.area() <= 0.0 {
                continue;
            }
            let overlap = slave_poly.clipped_by(&master_poly);
            if overlap.corners().len() < 3 || overlap.area() <= 1e-12 * area {
                continue;
            }
            let gap_at = |p: [f64; 2]| {
                let (ws, wm) = (shape_at(&sc, p), shape_at(&mc, p));
                dot(sub(m.point(&wm), s.point(&ws)), s.normal)
            };
            if overlap.corners().iter().all(|&p| gap_at(p).abs() > radius) {
                continue;
            }
            // ∫ N_j N_k and ∫ N_j N̂_l over the overlap, and ∫ N_j.
            let mut d = [[0.0; 4]; 4];
            let mut mm = [[0.0; 4]; 4];
            let mut covered = [0.0; 4];
            let oc = overlap.corners();
            for i in 1..oc.len() - 1 {
                let tri = Polygon::new(&[oc[0], oc[i], oc[i + 1]]);
                let a = tri.area();
                if a <= 0.0 {
                    continue;
                }
                for (b, w) in &rule {
                    let p = [
                        b[0] * oc[0][0] + b[1] * oc[i][0] + b[2] * oc[i + 1][0],
                        b[0] * oc[0][1] + b[1] * oc[i][1] + b[2] * oc[i + 1][1],
                    ];
                    let (ns, nm) = (shape_at(&sc, p), shape_at(&mc, p));
                    for j in 0..s.k {
                        let wj = a * w * ns[j];
                        covered[j] += wj;
                        for k in 0..s.k {
                            d[j][k] += wj * ns[k];
                        }
                        for l in 0..m.k {
                            mm[j][l] += wj * nm[l];
                        }
                    }
                }
            }
            for j in 0..s.k {
                facet.cover(&mut gathered, j, covered[j], m.normal);
                for (k, &dk) in d[j][..s.k].iter().enumerate() {
                    facet.slave(&mut gathered, j, k, dk);
                }
                for (&node, &ml) in mf.corners().iter().zip(&mm[j]) {
                    facet.master(&mut gathered, j, node, ml);
                }
            }
        }
        facet.close(&mut gathered);
    }
    finish(key, slaves, &mut gathered, unit, &|n| x.at::<3>(n), out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A grid of `n × m` quadrilaterals over the unit square in x and z at height
    /// `y`, node numbers from `first`: nodes and faces, the faces' normals down
    /// (`down`, a body above) or up; `triangles` cuts each in two.
    fn grid(
        (n, m): (usize, usize),
        y: f64,
        first: usize,
        down: bool,
        triangles: bool,
    ) -> (Vec<V3>, Vec<Face>) {
        let id = |i: usize, k: usize| first + k * (n + 1) + i;
        let mut x = Vec::new();
        for k in 0..=m {
            for i in 0..=n {
                x.push([i as f64 / n as f64, y, k as f64 / m as f64]);
            }
        }
        let mut faces = Vec::new();
        for k in 0..m {
            for i in 0..n {
                let mut c = [id(i, k), id(i + 1, k), id(i + 1, k + 1), id(i, k + 1)];
                if !down {
                    c.reverse();
                }
                if triangles {
                    faces.push(Face::triangle([c[0], c[1], c[2]]));
                    faces.push(Face::triangle([c[0], c[2], c[3]]));
                } else {
                    faces.push(Face::quadrilateral(c));
                }
            }
        }
        (x, faces)
    }

    /// The rows of a slave grid `gap` above a master grid whose nodes `moved` places;
    /// the flat positions, the slaves' count and the rows.
    fn rows_of(
        slave: (usize, usize),
        master: (usize, usize),
        gap: f64,
        tri: [bool; 2],
        basis: MortarBasis,
        moved: impl Fn(V3) -> V3,
    ) -> (Vec<f64>, usize, Vec<Candidate>) {
        let (mut xs, sf) = grid(slave, gap, 0, true, tri[0]);
        let ns = xs.len();
        let (xm, mf) = grid(master, 0.0, ns, false, tri[1]);
        xs.extend(xm.into_iter().map(moved));
        let flat: Vec<f64> = xs.iter().flatten().copied().collect();
        let x = Positions::new(&flat, 3);
        let kept = KeptFaces::new(&mf, x, 0.0);
        let slaves: Vec<usize> = (0..ns).collect();
        let mut out = Vec::new();
        rows((0, 0), &slaves, &sf, &mf, &kept, 0.5, basis, x, &mut out);
        (flat, ns, out)
    }

    #[test]
    fn weighted_gaps_of_parallel_grids_are_the_gap_and_loads_are_consistent() {
        let cases = [
            ((2, 3), (3, 2), [false, false]),
            ((3, 3), (4, 5), [false, true]),
            ((4, 2), (3, 3), [true, false]),
            ((2, 2), (5, 3), [true, true]),
        ];
        for ((slave, master, tri), basis) in cases
            .into_iter()
            .flat_map(|c| [MortarBasis::Standard, MortarBasis::Dual].map(|b| (c, b)))
        {
            let (flat, ns, out) = rows_of(slave, master, 0.01, tri, basis, |p| p);
            assert_eq!(out.len(), ns, "{slave:?} on {master:?}");
            let mut load = vec![0.0; flat.len() / 3];
            let pos = |n: usize| [flat[3 * n], flat[3 * n + 1], flat[3 * n + 2]];
            for c in &out {
                assert!((c.gap - 0.01).abs() < 1e-14, "{c:?}");
                assert!((c.normal[1] - 1.0).abs() < 1e-14);
                // The master's shape functions at the projected point reproduce it:
                // no tangential offset between the row's slave and master points.
                let d = c.combine(pos);
                assert!(d[0].abs() < 1e-14 && d[2].abs() < 1e-14, "{d:?}");
                let (sum_s, sum_m) =
                    c.weights.iter().fold(
                        (0.0, 0.0),
                        |(s, m), (n, w)| {
                            if n < ns {
                                (s + w, m)
                            } else {
                                (s, m + w)
                            }
                        },
                    );
                assert!((sum_s - 1.0).abs() < 1e-14 && (sum_m + 1.0).abs() < 1e-14);
                // A unit pressure: λ_j = W_j; the slave pushed up, the master down.
                for (n, w) in c.weights.iter() {
                    load[n] += c.length * w;
                }
            }
            // Consistent loads: the integral of each node's shape function, a
            // k-th of each flat k-cornered face's area at its corners (the grids'
            // quadrilaterals are rectangles).
            let mut expect = vec![0.0; load.len()];
            let (sf, mf) = (
                grid(slave, 0.0, 0, true, tri[0]).1,
                grid(master, 0.0, ns, false, tri[1]).1,
            );
            let pos = |n: usize| [flat[3 * n], 0.0, flat[3 * n + 2]];
            for (faces, sign) in [(&sf, 1.0), (&mf, -1.0)] {
                for f in faces {
                    let c = f.corners();
                    let p: Vec<V3> = c.iter().map(|&n| pos(n)).collect();
                    let a = if c.len() == 3 {
                        crate::geometry::triangle_area(p[0], p[1], p[2])
                    } else {
                        crate::geometry::norm(cross(sub(p[2], p[0]), sub(p[3], p[1]))) / 2.0
                    };
                    for &n in c {
                        expect[n] += sign * a / c.len() as f64;
                    }
                }
            }
            for (node, (&f, &e)) in load.iter().zip(&expect).enumerate() {
                assert!(
                    (f - e).abs() < 1e-14,
                    "{slave:?} on {master:?} {tri:?}: node {node}: {f} vs {e}"
                );
            }
        }
    }

    #[test]
    fn the_row_normal_is_the_masters_so_frictionless_sliding_does_no_work() {
        // A flat slave grid over a master tilted by 0.1 rad about z: every row acts
        // along the master's normal, so a slide of the slave along the master changes
        // no row's linearised gap.
        let tilt: f64 = 0.1;
        let (_, ns, out) = rows_of(
            (3, 2),
            (4, 3),
            0.2,
            [false, false],
            MortarBasis::Dual,
            |p| [p[0], p[0] * tilt.tan(), p[2]],
        );
        assert_eq!(out.len(), ns);
        for c in &out {
            let n = [-tilt.sin(), tilt.cos(), 0.0];
            for i in 0..3 {
                assert!((c.normal[i] - n[i]).abs() < 1e-14, "{c:?}");
            }
            for t in [[tilt.cos(), tilt.sin(), 0.0], [0.0, 0.0, 1.0]] {
                let dg: f64 = c
                    .row()
                    .filter(|&(d, _)| d / 3 < ns)
                    .map(|(d, v)| v * t[d % 3])
                    .sum();
                assert!(dg.abs() < 1e-14, "{dg}");
            }
        }
    }

    #[test]
    fn a_master_under_part_of_the_slave_weights_what_it_covers() {
        // The master grid shifted by 0.3 in x: slave nodes at x = 0 and 1/3 see it
        // over part of their support only, and a node beyond its end gets no row.
        let (flat, _, out) = rows_of(
            (3, 1),
            (2, 2),
            0.1,
            [false, false],
            MortarBasis::Standard,
            |p| [p[0] + 0.5, p[1], p[2]],
        );
        // Nodes at x = 0 get none; at x = 1/3 the master covers [0.5, 2/3] of the
        // support [0, 2/3] of a hat 3x: ∫ over the cover of (2 − 3x) in x, times ½ in
        // z (the slave's one row of cells, its nodes on z = 0 and 1: ½ each).
        let xs_of: Vec<f64> = out.iter().map(|c| flat[3 * c.slave]).collect();
        assert!(xs_of.iter().all(|&v| v > 0.3), "{xs_of:?}");
        for c in &out {
            assert!((c.gap - 0.1).abs() < 1e-14, "{c:?}");
        }
        let third = out.iter().find(|c| c.slave == 1).expect("node at x = 1/3");
        let hat: f64 = {
            let (a, b) = (0.5f64, 2.0 / 3.0);
            let f = |x: f64| 2.0 * x - 1.5 * x * x;
            f(b) - f(a)
        };
        assert!(
            (third.length - 0.5 * hat).abs() < 1e-14,
            "{} vs {}",
            third.length,
            0.5 * hat
        );
    }

    #[test]
    fn a_dual_row_holds_its_own_slave_node_and_reproduces_a_linear_gap() {
        // Slave grids (quadrilaterals, triangles) over a master plane tilted about z
        // so that the vertical gap is 0.1 + 0.2 x: each dual row holds its own slave
        // node with weight 1 and its gap is the gap at the node, as the dual basis
        // reproduces linear fields; the standard rows couple neighbours.
        for tri in [false, true] {
            for basis in [MortarBasis::Standard, MortarBasis::Dual] {
                let (flat, ns, out) = rows_of((3, 2), (2, 3), 0.1, [tri, false], basis, |p| {
                    [p[0], -0.2 * p[0], p[2]]
                });
                assert_eq!(out.len(), ns);
                for c in &out {
                    let own: Vec<(usize, f64)> =
                        c.weights.iter().filter(|&(n, _)| n < ns).collect();
                    let at_node = (0.1 + 0.2 * flat[3 * c.slave]) / 1.04f64.sqrt();
                    if basis == MortarBasis::Dual {
                        assert_eq!(own.len(), 1, "{c:?}");
                        assert_eq!(own[0].0, c.slave);
                        assert!((own[0].1 - 1.0).abs() < 1e-14, "{c:?}");
                        assert!((c.gap - at_node).abs() < 1e-13, "{} vs {at_node}", c.gap);
                    } else {
                        assert!(own.len() > 1, "{c:?}");
                    }
                }
            }
        }
    }
}
