//! The master surfaces of contact behind one interface.
//!
//! A pair's side holds its slaves against one master: a chain of segments of a
//! plane body ([`segments`]), a rigid line, the faces of a solid ([`faces`]) or a
//! rigid plane ([`rigid`]). Each is a [`MasterSurface`] at a geometry: it answers
//! what detection asks (the rows of a slave within reach, [`super::detect`]), what
//! the sweep of a step asks (the row of a slave whose motion crossed it beyond that
//! reach) and what the explicit path's collisions ask (the first impact of a slave
//! within a step: its time, the master's nodes and weights, the normal). The loops
//! over pairs, sides and slaves are written once, over this interface; the facet
//! kinds differ only in their geometry. [`surface`] is the one place that turns a
//! side's [`Master`] into its surface.
//!
//! The spatial trees a surface needs (the facets at its geometry, the facets swept
//! over a step, the facets grown by the reach of the explicit path) are built when
//! first asked for, so a surface asked for one thing pays for that one.

pub mod face_tree;
pub mod faces;
pub mod projection;
pub mod rigid;
pub mod segments;

use super::rows::Candidate;
use super::state::{Slave, Target};
use crate::model::{ContactSide, Master};
use rigid::EdgeHistory;

/// Node positions of one geometry, `dim` coordinates per node, flat (the layout of
/// the displacement vectors).
#[derive(Clone, Copy, Debug)]
pub struct Positions<'a> {
    x: &'a [f64],
    dim: usize,
}

impl<'a> Positions<'a> {
    /// The positions `x` of a `dim`-dimensional mesh (node `n`'s coordinates at
    /// `dim · n ..`).
    pub fn new(x: &'a [f64], dim: usize) -> Positions<'a> {
        Positions { x, dim }
    }

    /// How far node `n` lies from its position in `other`: `hypot` in the plane,
    /// `√(d · d)` in space.
    pub fn distance(&self, other: &Positions, n: usize) -> f64 {
        if self.dim == 2 {
            let (a, b) = (self.at::<2>(n), other.at::<2>(n));
            (a[0] - b[0]).hypot(a[1] - b[1])
        } else {
            crate::geometry::distance(self.at::<3>(n), other.at::<3>(n))
        }
    }

    /// Node `n` in a `D`-dimensional mesh.
    #[inline]
    pub fn at<const D: usize>(&self, n: usize) -> [f64; D] {
        std::array::from_fn(|i| self.x[D * n + i])
    }
}

/// A slave's first impact on a master within a step (the explicit path).
#[derive(Clone, Copy, Debug)]
pub struct Impact {
    /// Time of impact from the start of the step.
    pub t: f64,
    /// What it meets.
    pub target: Target,
    /// The master's nodes at the point of impact and their weights (none on a rigid
    /// master).
    pub corners: [(usize, f64); 3],
    /// Corners used.
    pub n_corners: usize,
    /// The unit normal of the impact, out of the master (`z = 0` in the plane).
    pub normal: [f64; 3],
}

impl Impact {
    /// The master's nodes and weights.
    pub fn corners(&self) -> &[(usize, f64)] {
        &self.corners[..self.n_corners]
    }
}

/// One side's master surface at a geometry: what detection, the sweep of a step and
/// the explicit collisions need of it.
pub trait MasterSurface {
    /// Appends the candidates of `slave` at the surface's geometry within `reach`
    /// (detection's narrow phase): none when it is out of reach or beside the
    /// master, one for the nearest facet, two where a notch or valley holds it.
    fn detect(&self, slave: Slave, reach: f64, rigid: &EdgeHistory, out: &mut Vec<Candidate>);

    /// The nodes whose motion, with the slave's, decides whether a slave may have
    /// crossed the master unseen (a deformable master's); `None` for a rigid master,
    /// every slave of which the sweep looks at.
    fn nodes(&self) -> Option<Vec<usize>>;

    /// The candidate at the surface's geometry of a slave whose motion from `start`
    /// crossed the master within the step (the sweep), if it did.
    fn crossing(&self, slave: Slave, start: Positions, rigid: &EdgeHistory) -> Option<Candidate>;

    /// The first impact of `slave` within a step of length `h` from the surface's
    /// geometry, every node moving at its velocity in `v` (the explicit path),
    /// looking `reach` about the slave.
    fn impact(
        &self,
        slave: Slave,
        v: Positions,
        h: f64,
        reach: f64,
        rigid: &EdgeHistory,
    ) -> Option<Impact>;
}

/// The surface of `side`'s master at the geometry `x`.
pub fn surface<'a>(side: &'a ContactSide, x: Positions<'a>) -> Box<dyn MasterSurface + 'a> {
    match &side.master {
        Master::Segments(segments) => Box::new(segments::SegmentChain::new(segments, x)),
        Master::Rigid { a, b, n } => Box::new(rigid::RigidLine::new(*a, *b, *n, x)),
        Master::Faces { faces, boundary } => Box::new(faces::FaceSurface::new(faces, boundary, x)),
        Master::Plane { point, n } => Box::new(rigid::RigidPlane::new(*point, *n, x)),
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use crate::contact::rows::Candidate;
    use crate::model::ContactPair;

    use super::rigid::EdgeHistory;
    use super::Positions;

    /// [`crate::contact::detect::detect`] at the node positions `coords`, with the
    /// rigid lines' history `rigid`.
    pub fn detect_with<const D: usize>(
        pairs: &[ContactPair],
        coords: &[[f64; D]],
        rigid: &EdgeHistory,
        out: &mut Vec<Candidate>,
    ) {
        let x: Vec<f64> = coords.iter().flatten().copied().collect();
        crate::contact::detect::detect(pairs, Positions::new(&x, D), rigid, None, out);
    }

    /// [`detect_with`] with no history.
    pub fn detect<const D: usize>(
        pairs: &[ContactPair],
        coords: &[[f64; D]],
        out: &mut Vec<Candidate>,
    ) {
        detect_with(pairs, coords, &EdgeHistory::default(), out);
    }
}
