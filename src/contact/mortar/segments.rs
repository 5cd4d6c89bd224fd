//! Mortar in the plane: segment to segment ([`super`] has the weighted gap).
//!
//! Projection: per slave segment, along its own normal (the master's ends are
//! projected orthogonally onto the slave segment's line, and between them the map
//! from slave to master coordinate is affine), so the products `N_j N̂_l` are
//! quadratic in the slave coordinate and two Gauss points integrate them exactly.
//! The row's normal is the master's (the slave's nodal normal instead made a tilted
//! master's sliding slave book `D_contact` falling by 2 mJ a step in benchmark 2).

use rstar::primitives::{GeomWithData, Line, Rectangle};
use rstar::{RTree, RTreeObject};

use super::{finish, Facet, Gathered};
use crate::contact::rows::Candidate;
use crate::model::MortarBasis;

/// Outward unit normal of a segment with its body on the left, and its length (as
/// `hypot`, whose last bits the mortar rows have always had; detection's
/// [`crate::geometry::outward`] takes `√(Δx² + Δy²)`).
fn outward(a: [f64; 2], b: [f64; 2]) -> ([f64; 2], f64) {
    let d = crate::geometry::sub(b, a);
    let l = d[0].hypot(d[1]);
    if l > 0.0 {
        ([d[1] / l, -d[0] / l], l)
    } else {
        ([0.0, 0.0], 0.0)
    }
}

/// The mortar rows of one side (`key`: pair and side) against the master
/// `segments` at the geometry `x`, appended to `out` in slave order. `slaves` are the
/// side's slave nodes (sorted), `slave_segments` its slave surface, `basis` the
/// slave's test functions; master segments farther than `radius` from a slave
/// segment are not looked at. Returns the most
/// nodes a row needed (more than [`crate::contact::rows::ROW_NODES`] means rows were cut:
/// validation refuses such a pair at the initial geometry).
#[allow(clippy::too_many_arguments)]
pub fn rows<X: Fn(usize) -> [f64; 2]>(
    key: (usize, usize),
    slaves: &[usize],
    slave_segments: &[[usize; 2]],
    segments: &[[usize; 2]],
    radius: f64,
    basis: MortarBasis,
    x: &X,
    out: &mut Vec<Candidate>,
) -> usize {
    let mut gathered = Gathered::<2>::empty(slaves.len());
    let slot = |n: usize| slaves.binary_search(&n).ok();
    let tree = RTree::bulk_load(
        segments
            .iter()
            .enumerate()
            .map(|(k, &[a, b])| GeomWithData::new(Line::new(x(a), x(b)), k))
            .collect(),
    );
    // Gauss points on [0, 1].
    let g = 0.5 / 3f64.sqrt();
    let gauss = [0.5 - g, 0.5 + g];
    for &[s1, s2] in slave_segments {
        let (p1, p2) = (x(s1), x(s2));
        let (nu, len) = outward(p1, p2);
        if len == 0.0 {
            continue;
        }
        let (Some(j1), Some(j2)) = (slot(s1), slot(s2)) else {
            continue;
        };
        for j in [j1, j2] {
            gathered[j].total += 0.5 * len;
        }
        let mut facet = Facet::new(basis, [s1, s2, 0, 0], [j1, j2, 0, 0], 2);
        let d = [p2[0] - p1[0], p2[1] - p1[1]];
        let along = |q: [f64; 2]| ((q[0] - p1[0]) * d[0] + (q[1] - p1[1]) * d[1]) / (len * len);
        let lo = [p1[0].min(p2[0]) - radius, p1[1].min(p2[1]) - radius];
        let hi = [p1[0].max(p2[0]) + radius, p1[1].max(p2[1]) + radius];
        let reach = Rectangle::from_corners(lo, hi).envelope();
        for hit in tree.locate_in_envelope_intersecting(reach) {
            let [m1, m2] = segments[hit.data];
            if [m1, m2].iter().any(|&m| m == s1 || m == s2) {
                continue;
            }
            let (q1, q2) = (x(m1), x(m2));
            let (m_normal, lm) = outward(q1, q2);
            // Only a master facing the slave (normals opposed) carries it.
            if lm == 0.0 || m_normal[0] * nu[0] + m_normal[1] * nu[1] >= 0.0 {
                continue;
            }
            let (e1, e2) = (along(q1), along(q2));
            if e1 == e2 {
                continue;
            }
            let (a, b) = (e1.min(e2).max(0.0), e1.max(e2).min(1.0));
            if b - a <= 1e-12 {
                continue;
            }
            // The gap along the slave normal at the overlap's ends: beyond the radius
            // on both, the master is out of reach.
            let eta = |xi: f64| (xi - e1) / (e2 - e1);
            let gap_at = |xi: f64| {
                let (e, s) = (eta(xi), xi);
                let xs = [p1[0] + s * d[0], p1[1] + s * d[1]];
                let xm = [q1[0] + e * (q2[0] - q1[0]), q1[1] + e * (q2[1] - q1[1])];
                -((xs[0] - xm[0]) * nu[0] + (xs[1] - xm[1]) * nu[1])
            };
            if gap_at(a).abs() > radius && gap_at(b).abs() > radius {
                continue;
            }
            for &gp in &gauss {
                let xi = a + (b - a) * gp;
                let w = 0.5 * (b - a) * len;
                let e = eta(xi);
                let ns = [1.0 - xi, xi];
                let nm = [1.0 - e, e];
                for (j, &nj) in ns.iter().enumerate() {
                    let wj = w * nj;
                    facet.cover(&mut gathered, j, wj, m_normal);
                    for (k, &nk) in ns.iter().enumerate() {
                        facet.slave(&mut gathered, j, k, wj * nk);
                    }
                    for (&node, &nl) in [m1, m2].iter().zip(&nm) {
                        facet.master(&mut gathered, j, node, wj * nl);
                    }
                }
            }
        }
        facet.close(&mut gathered);
    }
    let unit = |m: [f64; 2]| {
        let l = m[0].hypot(m[1]);
        (l != 0.0).then(|| [m[0] / l, m[1] / l])
    };
    finish(key, slaves, &mut gathered, unit, x, out)
}

#[cfg(test)]
mod tests {
    use super::*;

    const BASES: [MortarBasis; 2] = [MortarBasis::Standard, MortarBasis::Dual];

    /// Nodes, slave nodes, slave segments, master segments.
    type Strips = (Vec<[f64; 2]>, Vec<usize>, Vec<[usize; 2]>, Vec<[usize; 2]>);

    /// A slave strip of `ns` segments on top of a master strip of `nm`, both on
    /// [0, 1], the slave `gap` above: nodes, slave segments (body above, on the left
    /// of segments running left to right), master segments (body below: right to
    /// left).
    fn strips(ns: usize, nm: usize, gap: f64) -> Strips {
        let mut x = Vec::new();
        for i in 0..=ns {
            x.push([i as f64 / ns as f64, gap]);
        }
        for i in 0..=nm {
            x.push([i as f64 / nm as f64, 0.0]);
        }
        let slaves: Vec<usize> = (0..=ns).collect();
        let slave_segs = (0..ns).map(|i| [i, i + 1]).collect();
        let master_segs = (0..nm).map(|i| [ns + 2 + i, ns + 1 + i]).collect();
        (x, slaves, slave_segs, master_segs)
    }

    #[test]
    fn weighted_gaps_of_parallel_strips_are_the_gap_and_loads_are_consistent() {
        for ((ns, nm), basis) in [(2, 3), (3, 2), (4, 4), (5, 2)]
            .into_iter()
            .flat_map(|c| BASES.map(|b| (c, b)))
        {
            let (x, slaves, ss, ms) = strips(ns, nm, 0.01);
            let mut out = Vec::new();
            rows((0, 0), &slaves, &ss, &ms, 0.5, basis, &|n| x[n], &mut out);
            assert_eq!(out.len(), ns + 1);
            let mut master_load = vec![0.0; x.len()];
            let mut slave_load = vec![0.0; x.len()];
            for c in &out {
                assert!((c.gap - 0.01).abs() < 1e-14, "{c:?}");
                assert!((c.normal[1] - 1.0).abs() < 1e-14);
                let (sum_s, sum_m) = c.weights.iter().fold((0.0, 0.0), |(s, m), (n, w)| {
                    if n <= ns {
                        (s + w, m)
                    } else {
                        (s, m + w)
                    }
                });
                assert!((sum_s - 1.0).abs() < 1e-14 && (sum_m + 1.0).abs() < 1e-14);
                // A unit pressure: λ_j = W_j.
                for (n, w) in c.weights.iter() {
                    if n <= ns {
                        slave_load[n] += c.length * w;
                    } else {
                        master_load[n] -= c.length * w;
                    }
                }
            }
            // Consistent nodal loads: half a segment at the ends, a whole inside.
            for (n, &f) in master_load.iter().enumerate().skip(ns + 1) {
                let k = n - ns - 1;
                let expect = if k == 0 || k == nm { 0.5 } else { 1.0 } / nm as f64;
                assert!((f - expect).abs() < 1e-14, "{ns}/{nm}: master {k}: {f}");
            }
            for (n, &f) in slave_load.iter().enumerate().take(ns + 1) {
                let expect = if n == 0 || n == ns { 0.5 } else { 1.0 } / ns as f64;
                assert!((f - expect).abs() < 1e-14, "{ns}/{nm}: slave {n}: {f}");
            }
        }
    }

    #[test]
    fn the_row_normal_is_the_masters_so_frictionless_sliding_does_no_work() {
        // A flat slave strip over a master tilted by 0.1 rad: every row's force acts
        // along the master's normal, so sliding along the master (δ ∥ its tangent)
        // changes no row's linearised gap and a frictionless force does no work on it.
        let (ns, nm) = (3, 4);
        let (mut x, slaves, ss, ms) = strips(ns, nm, 0.2);
        let tilt: f64 = 0.1;
        for p in x.iter_mut().skip(ns + 1) {
            p[1] = p[0] * tilt.tan();
        }
        let mut out = Vec::new();
        rows(
            (0, 0),
            &slaves,
            &ss,
            &ms,
            1.0,
            MortarBasis::Dual,
            &|n| x[n],
            &mut out,
        );
        assert_eq!(out.len(), ns + 1);
        let (nx, ny) = (-tilt.sin(), tilt.cos());
        for c in &out {
            assert!(
                (c.normal[0] - nx).abs() < 1e-14 && (c.normal[1] - ny).abs() < 1e-14,
                "{c:?}"
            );
            // A slide of the slave along the master: δ = t on every slave node.
            let t = [tilt.cos(), tilt.sin()];
            let dg: f64 = c
                .row()
                .filter(|&(d, _)| d / 2 <= ns)
                .map(|(d, v)| v * t[d % 2])
                .sum();
            assert!(dg.abs() < 1e-14, "{dg}");
        }
    }

    #[test]
    fn a_tilted_master_gives_the_averaged_gap_and_partial_cover_is_weighted() {
        // The master from x = 0.25 to 1 at height 0, the slave over [0, 1] at 0.1:
        // node 0 is not covered, node 1 (x = 0.5) half of its left segment.
        for basis in BASES {
            partial_cover(basis);
        }
    }

    fn partial_cover(basis: MortarBasis) {
        let x = [[1.0, 0.1], [0.5, 0.1], [0.0, 0.1], [0.25, 0.0], [1.0, 0.0]];
        let mut out = Vec::new();
        rows(
            (0, 0),
            &[0, 1, 2],
            &[[2, 1], [1, 0]],
            &[[4, 3]],
            0.5,
            basis,
            &|n| x[n],
            &mut out,
        );
        let slaves: Vec<usize> = out.iter().map(|c| c.slave).collect();
        assert_eq!(slaves, [0, 1, 2]);
        for c in &out {
            assert!((c.gap - 0.1).abs() < 1e-14, "{c:?}");
        }
        // Node 2 (x = 0) sees the master over [0.25, 0.5] of its segment, where its
        // shape function is 1 - 2x: its integral 1/16.
        assert!((out[2].length - 1.0 / 16.0).abs() < 1e-14, "{:?}", out[2]);
        assert!((out[0].length - 0.25).abs() < 1e-14);
    }

    #[test]
    fn a_dual_row_holds_its_own_slave_node_and_reproduces_a_linear_gap() {
        // A slave strip of 3 segments over a master of 2 tilted so that the gap is
        // linear along the slave, 0.1 + 0.2 x. The dual rows hold one slave node each
        // (weight 1), and as the dual basis reproduces constants, each row's gap is
        // the gap at its node exactly. The standard rows average the gap over the
        // node's hat and couple neighbours.
        let (ns, nm) = (3, 2);
        let (mut x, slaves, ss, ms) = strips(ns, nm, 0.1);
        for p in x.iter_mut().skip(ns + 1) {
            p[1] = -0.2 * p[0];
        }
        for basis in BASES {
            let mut out = Vec::new();
            rows((0, 0), &slaves, &ss, &ms, 1.0, basis, &|n| x[n], &mut out);
            assert_eq!(out.len(), ns + 1);
            for c in &out {
                let slave_nodes: Vec<(usize, f64)> =
                    c.weights.iter().filter(|&(n, _)| n <= ns).collect();
                let xs = x[c.slave][0];
                // The gap along the master's normal at the node: the vertical gap
                // 0.1 + 0.2 x times the cosine of the master's slope.
                let at_node = (0.1 + 0.2 * xs) / (1.0 + 0.04f64).sqrt();
                match basis {
                    MortarBasis::Dual => {
                        assert_eq!(slave_nodes, [(c.slave, 1.0)], "{c:?}");
                        assert!((c.gap - at_node).abs() < 1e-14, "{} vs {at_node}", c.gap);
                    }
                    MortarBasis::Standard => {
                        let interior = c.slave != 0 && c.slave != ns;
                        assert!(slave_nodes.len() > 1, "{c:?}");
                        // The hat's average of a linear gap is the node's value
                        // inside, off it at the ends.
                        assert_eq!((c.gap - at_node).abs() < 1e-14, interior, "{c:?}");
                    }
                }
            }
        }
    }
}
