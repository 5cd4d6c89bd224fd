//! Rigid masters: a plane body's rigid line (a support of finite length) and a
//! solid's rigid plane (unbounded). A slave's row against either is its own position
//! along the master's fixed normal; no master node moves.

use super::{Impact, MasterSurface, Positions};
use crate::contact::collision::node_segment;
use crate::contact::rows::{Candidate, Contactee};
use crate::contact::state::{Slave, Target};
use crate::geometry::{dot, sub};
use crate::model::{ContactPair, Master};

/// How far (relative to its length) beyond its ends a rigid line still holds a node:
/// a node at the very end of a support moves sideways by micrometres (Poisson's
/// effect) and must not drop in and out of contact with it. A thousandth of the line
/// changes where the support ends far less than the node spacing does. A master
/// chain's ends ([`super::segments`]) and a face set's boundary
/// ([`super::faces`]) keep the same margin.
pub const RIGID_END_MARGIN: f64 = 1e-3;

/// How many contact tolerances below (or off) a rigid line's level a slave lies at
/// the start of a step when the line does not hold it: a slave the line holds lies
/// within one (accepted steps penetrate at most the tolerance); two leave room for
/// round-off. Both paths use it with [`beneath_rigid`] and [`held_rigid`].
pub const RIGID_DEPTH_TOLERANCES: f64 = 2.0;

/// Whether `ξ` lies within a rigid line's ends (and [`RIGID_END_MARGIN`]).
pub fn within_ends(xi: f64) -> bool {
    (-RIGID_END_MARGIN..=1.0 + RIGID_END_MARGIN).contains(&xi)
}

/// What a step knows from the committed state of the slaves at its masters' edges:
/// those that came around a rigid line's end or a face set's edge, and those a rigid
/// line held, as sorted lists.
#[derive(Clone, Debug, Default)]
pub struct EdgeHistory {
    /// Slaves that came around a line's end ([`beneath_rigid`]) or a face set's edge
    /// ([`super::faces::beneath_faces`]): not candidates.
    pub beneath: Vec<Slave>,
    /// Slaves the line held at the end of the last step: candidates even a little
    /// beyond the line's ends (within the pair's radius), so that a slave at the very
    /// end of a support, which slides outward as the body above it bends, stays on
    /// it instead of slipping off and coming back around the end.
    pub held: Vec<Slave>,
}

impl EdgeHistory {
    /// Whether slave `s` is passed over ([`EdgeHistory::beneath`]).
    pub fn is_beneath(&self, s: Slave) -> bool {
        self.beneath.binary_search(&s).is_ok()
    }

    fn held(&self, s: Slave) -> bool {
        self.held.binary_search(&s).is_ok()
    }
}

/// The slaves of rigid lines that came around a line's end: at the geometry
/// `x(node)` (committed: the start of a step) they lie below the line's level by
/// more than `depth`, and either beyond its ends or already so in `previous` (the
/// last step's list), sorted.
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

/// The slaves rigid lines hold at the geometry `x(node)` (committed): lying within
/// `depth` of the line's level, and within its ends or already held in `previous`
/// (a held slave that slides past an end stays held while it stays on the level),
/// sorted. The explicit path keeps this list itself; the implicit one takes it from
/// its active set.
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

/// A slave of a rigid line at some geometry.
struct RigidSlave {
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

/// A rigid line from `a` to `b` with unit normal `n` towards its slaves, at a
/// geometry of the slaves.
pub struct RigidLine<'a> {
    a: [f64; 2],
    b: [f64; 2],
    n: [f64; 2],
    x: Positions<'a>,
}

impl<'a> RigidLine<'a> {
    /// The line from `a` to `b` with normal `n`, its slaves at `x`.
    pub fn new(a: [f64; 2], b: [f64; 2], n: [f64; 2], x: Positions<'a>) -> Self {
        RigidLine { a, b, n, x }
    }

    /// The gap of `p` above the line's level and its position along the line (0
    /// and 1 at the ends).
    fn gap_and_along(&self, p: [f64; 2]) -> (f64, f64) {
        let (a, b, n) = (self.a, self.b, self.n);
        let t = [b[0] - a[0], b[1] - a[1]];
        let l2 = t[0] * t[0] + t[1] * t[1];
        (
            (p[0] - a[0]) * n[0] + (p[1] - a[1]) * n[1],
            ((p[0] - a[0]) * t[0] + (p[1] - a[1]) * t[1]) / l2,
        )
    }

    fn candidate(&self, slave: Slave, xi: f64, gap: f64) -> Candidate {
        Candidate::nodal::<2>(slave, Contactee::Rigid, &[], xi, gap, self.n)
    }
}

impl MasterSurface for RigidLine<'_> {
    fn detect(&self, slave: Slave, reach: f64, rigid: &EdgeHistory, out: &mut Vec<Candidate>) {
        if rigid.is_beneath(slave) {
            return;
        }
        let (gap, xi) = self.gap_and_along(self.x.at::<2>(slave.node));
        let within = within_ends(xi) || rigid.held(slave);
        if within && gap * gap <= reach * reach {
            out.push(self.candidate(slave, xi.clamp(0.0, 1.0), gap));
        }
    }

    fn nodes(&self) -> Option<Vec<usize>> {
        None
    }

    fn crossing(&self, slave: Slave, start: Positions, rigid: &EdgeHistory) -> Option<Candidate> {
        let (p0, p1) = (start.at::<2>(slave.node), self.x.at::<2>(slave.node));
        let ((g0, _), (g1, along1)) = (self.gap_and_along(p0), self.gap_and_along(p1));
        // Moving into the line and behind it at the end (a slave resting on it
        // starts at a gap of round-off, of either sign).
        if !(g1 < 0.0 && g1 < g0) || rigid.is_beneath(slave) {
            return None;
        }
        let c = if g0 > 0.0 { g0 / (g0 - g1) } else { 0.0 };
        let pc = [p0[0] + c * (p1[0] - p0[0]), p0[1] + c * (p1[1] - p0[1])];
        within_ends(self.gap_and_along(pc).1)
            .then(|| self.candidate(slave, along1.clamp(0.0, 1.0), g1))
    }

    fn impact(
        &self,
        slave: Slave,
        v: Positions,
        h: f64,
        reach: f64,
        rigid: &EdgeHistory,
    ) -> Option<Impact> {
        if rigid.is_beneath(slave) {
            return None;
        }
        let n = self.n;
        // Oriented so that the segment convention's normal is n.
        let (a, b) = if (self.b[1] - self.a[1]) * n[0] - (self.b[0] - self.a[0]) * n[1] >= 0.0 {
            (self.a, self.b)
        } else {
            (self.b, self.a)
        };
        // A held slave meets the line extended by the pair's radius.
        let (a, b) = if rigid.held(slave) {
            let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
            let e = [(b[0] - a[0]) / len * reach, (b[1] - a[1]) / len * reach];
            ([a[0] - e[0], a[1] - e[1]], [b[0] + e[0], b[1] + e[1]])
        } else {
            (a, b)
        };
        let s = slave.node;
        let c = node_segment(self.x.at::<2>(s), v.at::<2>(s), a, [0.0; 2], b, [0.0; 2], h)?;
        Some(Impact {
            t: c.t,
            target: Target::Rigid,
            corners: [(0, 0.0); 3],
            n_corners: 0,
            normal: [n[0], n[1], 0.0],
        })
    }
}

/// A rigid plane through `point` with unit normal `n` towards its slaves, at a
/// geometry of the slaves.
pub struct RigidPlane<'a> {
    point: [f64; 3],
    n: [f64; 3],
    x: Positions<'a>,
}

impl<'a> RigidPlane<'a> {
    /// The plane through `point` with normal `n`, its slaves at `x`.
    pub fn new(point: [f64; 3], n: [f64; 3], x: Positions<'a>) -> Self {
        RigidPlane { point, n, x }
    }

    fn gap(&self, p: [f64; 3]) -> f64 {
        dot(sub(p, self.point), self.n)
    }

    fn candidate(&self, slave: Slave, gap: f64) -> Candidate {
        Candidate::nodal::<3>(slave, Contactee::Rigid, &[], 0.0, gap, self.n)
    }
}

impl MasterSurface for RigidPlane<'_> {
    fn detect(&self, slave: Slave, reach: f64, _: &EdgeHistory, out: &mut Vec<Candidate>) {
        let gap = self.gap(self.x.at::<3>(slave.node));
        if gap * gap <= reach * reach {
            out.push(self.candidate(slave, gap));
        }
    }

    fn nodes(&self) -> Option<Vec<usize>> {
        None
    }

    fn crossing(&self, slave: Slave, start: Positions, _: &EdgeHistory) -> Option<Candidate> {
        let (g0, g1) = (
            self.gap(start.at::<3>(slave.node)),
            self.gap(self.x.at::<3>(slave.node)),
        );
        (g0 >= 0.0 && g1 < 0.0).then(|| self.candidate(slave, g1))
    }

    fn impact(
        &self,
        slave: Slave,
        v: Positions,
        h: f64,
        _: f64,
        _: &EdgeHistory,
    ) -> Option<Impact> {
        let (p, w) = (self.x.at::<3>(slave.node), v.at::<3>(slave.node));
        let g0 = self.gap(p);
        let vn = dot(w, self.n);
        // Reaching the plane from its side within the step (a node on it at the start
        // and moving in meets it at once).
        (g0 >= 0.0 && vn < 0.0 && g0 + h * vn <= 0.0).then(|| Impact {
            t: g0 / -vn,
            target: Target::Rigid,
            corners: [(0, 0.0); 3],
            n_corners: 0,
            normal: self.n,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{ContactPair, ContactSide};

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
                surface: crate::model::SlaveSurface::Nodes,
            }],
            radius: 0.1,
            friction: 0.0,
            mu: 0.0,
            formulation: crate::model::Formulation::NodeToSegment,
            mortar_basis: crate::model::MortarBasis::Dual,
            position_weight: 0.5,
        };
        let mut out = Vec::new();
        super::super::tests::detect(std::slice::from_ref(&pair), &coords, &mut out);
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
        let mut rigid = EdgeHistory {
            beneath,
            held: Vec::new(),
        };
        super::super::tests::detect_with(&pairs, &coords, &rigid, &mut out);
        assert!(out.is_empty());
        // A held slave stays a candidate beyond the line's end (node 1 at ξ = 2.2
        // is within the radius of the line's level).
        rigid.held = vec![Slave::new(0, 0, 1)];
        super::super::tests::detect_with(&pairs, &coords, &rigid, &mut out);
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
