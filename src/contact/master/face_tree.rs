//! The broad phase of a face master: an R-tree (`rstar`) of its faces' bounding
//! boxes, the set's topology (its corners numbered over its distinct nodes), and
//! what detection keeps of both from one evaluation to the next ([`KeptFaces`]).

use std::collections::HashMap;

use rstar::primitives::{GeomWithData, Rectangle};
use rstar::{RTree, AABB};

use super::Positions;
use crate::mesh::Face;

type V3 = [f64; 3];

/// The box of `points` grown by `pad` on every side.
pub fn bounding_box(points: impl Iterator<Item = V3>, pad: f64) -> AABB<V3> {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in points {
        for i in 0..3 {
            lo[i] = lo[i].min(p[i] - pad);
            hi[i] = hi[i].max(p[i] + pad);
        }
    }
    AABB::from_corners(lo, hi)
}

/// An R-tree of the faces, each by the box of the points `at(node)` yields for its
/// corners (one geometry, or the start and end of a step), grown by `pad`.
pub(super) type FaceTree = RTree<GeomWithData<Rectangle<V3>, usize>>;

/// See [`FaceTree`].
pub(super) fn face_tree<I: Iterator<Item = V3>>(
    faces: &[Face],
    at: impl Fn(usize) -> I,
    pad: f64,
) -> FaceTree {
    RTree::bulk_load(
        faces
            .iter()
            .enumerate()
            .map(|(k, f)| {
                let b = bounding_box(f.corners().iter().flat_map(|&n| at(n)), pad);
                GeomWithData::new(Rectangle::from_aabb(b), k)
            })
            .collect(),
    )
}

/// A face set's corners numbered over its distinct nodes: topology, found once for a
/// set and kept ([`KeptFaces`]), so the nodal normals of a geometry are sums into a
/// vector, not a map.
#[derive(Clone, Debug)]
pub struct Topology {
    /// Each face's corners by their number in `nodes`.
    pub(super) corners: Vec<[usize; 4]>,
    /// The distinct nodes, in the order the faces first name them.
    pub(super) nodes: Vec<usize>,
}

impl Topology {
    /// The topology of `faces`.
    pub fn new(faces: &[Face]) -> Topology {
        let mut number: HashMap<usize, usize> = HashMap::with_capacity(faces.len());
        let mut nodes = Vec::new();
        let corners = faces
            .iter()
            .map(|f| {
                let mut c = [0; 4];
                for (k, &v) in f.corners().iter().enumerate() {
                    c[k] = *number.entry(v).or_insert_with(|| {
                        nodes.push(v);
                        nodes.len() - 1
                    });
                }
                c
            })
            .collect();
        Topology { corners, nodes }
    }
}

/// What detection keeps of a face set from one evaluation to the next: its
/// [`Topology`] and an R-tree of its faces' boxes grown by a margin, with the node
/// positions the tree was built at. While no node has moved farther than the margin
/// from there, every face within a slave's reach now lies in the tree's boxes (its
/// box now lies within its grown one), so the query finds a superset of what a tree
/// of the current geometry finds, and the exact projection decides as before: the
/// same rows, bit for bit (the nearest face is chosen by distance and index, not
/// by the tree's order). Past the margin the tree is built again.
pub struct KeptFaces {
    pub(super) topology: Topology,
    pub(super) tree: FaceTree,
    /// The positions of `topology.nodes` the tree was built at.
    base: Vec<V3>,
    margin: f64,
}

impl KeptFaces {
    /// The tree of `faces` at `x`, grown by `margin`.
    pub fn new(faces: &[Face], x: Positions, margin: f64) -> KeptFaces {
        let topology = Topology::new(faces);
        let base = topology.nodes.iter().map(|&n| x.at::<3>(n)).collect();
        let tree = face_tree(faces, |n| std::iter::once(x.at::<3>(n)), margin);
        KeptFaces {
            topology,
            tree,
            base,
            margin,
        }
    }

    /// Builds the tree again at `x` if a node moved farther than the margin since
    /// it was built.
    pub fn refresh(&mut self, faces: &[Face], x: Positions) {
        let moved = self
            .topology
            .nodes
            .iter()
            .zip(&self.base)
            .any(|(&n, b)| crate::geometry::distance(x.at::<3>(n), *b) > self.margin);
        if moved {
            for (b, &n) in self.base.iter_mut().zip(&self.topology.nodes) {
                *b = x.at::<3>(n);
            }
            self.tree = face_tree(faces, |n| std::iter::once(x.at::<3>(n)), self.margin);
        }
    }

    /// The faces whose kept boxes meet the box from `lo` to `hi`, by index in
    /// increasing order, into `out` (cleared first): every face that reaches into
    /// the box now, and a few more (the mortar rows' broad phase).
    pub fn within(&self, lo: V3, hi: V3, out: &mut Vec<usize>) {
        out.clear();
        let b = AABB::from_corners(lo, hi);
        out.extend(self.tree.locate_in_envelope_intersecting(b).map(|h| h.data));
        out.sort_unstable();
    }
}
