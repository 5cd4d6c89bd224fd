//! Meshes: nodes, blocks of elements of one kind, and named node and edge sets.
//!
//! A [`Part`] is the geometry of one body as a generator or a Gmsh file produces it;
//! a [`Mesh`] is the union of all parts of a model (node numbers offset, set names
//! prefixed by the body name, `beam.left`), plus the bar elements that share the
//! continuum's nodes. Start with [`structured::rectangle`] and [`Mesh::add_part`].

pub mod face;
pub mod gmsh;
pub mod msh41;
pub mod solid;
pub mod structured;

use std::collections::BTreeMap;

use crate::error::{Error, Result};
pub use crate::fe::{polygon_area, ElementKind};
pub use face::Face;

/// Elements of one kind with flattened connectivity (`nodes()` indices per element).
#[derive(Clone, Debug, PartialEq)]
pub struct Elements {
    /// Element kind of every element in the block.
    pub kind: ElementKind,
    /// Node indices, `kind.nodes()` per element.
    pub conn: Vec<usize>,
    /// The element tags of the file the elements came from (Gmsh), for messages;
    /// `None` for generated meshes, whose elements are named by their index.
    pub tags: Option<Vec<u64>>,
}

impl Elements {
    /// Number of elements.
    pub fn len(&self) -> usize {
        self.conn.len() / self.kind.nodes()
    }

    /// True when the block has no element.
    pub fn is_empty(&self) -> bool {
        self.conn.is_empty()
    }

    /// Node indices of element `e`.
    pub fn element(&self, e: usize) -> &[usize] {
        let n = self.kind.nodes();
        &self.conn[e * n..(e + 1) * n]
    }

    /// Elements of `kind` with connectivity `conn` and no file tags.
    pub fn new(kind: ElementKind, conn: Vec<usize>) -> Self {
        Elements {
            kind,
            conn,
            tags: None,
        }
    }

    /// How element `e` is named in messages: its file tag, or its index.
    pub fn name(&self, e: usize) -> String {
        match &self.tags {
            Some(t) => format!("element with Gmsh tag {}", t[e]),
            None => format!("element {e}"),
        }
    }
}

/// A point in space: `[x, y, z]`; plane models keep `z = 0`.
pub type Point = [f64; 3];

pub use crate::geometry::distance;

/// The in-plane coordinates `[x, y]` of a point.
#[inline]
pub fn xy(p: Point) -> [f64; 2] {
    [p[0], p[1]]
}

/// The shape of a continuum element, from the Jacobian of its reference map at its
/// corners and Gauss points.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shape {
    /// Positive Jacobian everywhere.
    Valid,
    /// Negative Jacobian everywhere: the nodes run clockwise (in a solid: the wrong
    /// handedness).
    Inverted,
    /// Zero area: coincident or collinear nodes.
    Degenerate,
    /// The Jacobian changes sign: a non-convex or self-intersecting quadrilateral.
    Distorted,
    /// Coordinates so large that its area (volume) overflows double precision.
    OutOfRange,
}

impl Shape {
    /// The shape of a continuum element with node coordinates `x` (bars: by length).
    pub fn of(kind: ElementKind, x: &[Point]) -> Shape {
        let size = kind
            .edges()
            .iter()
            .map(|&[a, b]| distance(x[a], x[b]))
            .fold(0.0, f64::max);
        // An edge whose square (cube, in a solid) overflows: no area, Jacobian or
        // matrix of the element is a number (coordinates of 1e200 m).
        if !size.is_finite() || !size.powi(kind.dim().max(2) as i32).is_finite() {
            return Shape::OutOfRange;
        }
        if kind == ElementKind::Bar2 {
            return if size > 0.0 {
                Shape::Valid
            } else {
                Shape::Degenerate
            };
        }
        if kind.dim() == 3 {
            let volume = crate::fe::element::measure(kind, x);
            if volume.is_nan() || volume.abs() <= 1e-12 * size * size * size {
                return Shape::Degenerate;
            }
        } else {
            let area = polygon_area(x);
            if area.is_nan() || area.abs() <= 1e-12 * size * size {
                return Shape::Degenerate;
            }
        }
        let (lo, hi) = crate::fe::jacobian_range(kind, x);
        if lo > 0.0 {
            Shape::Valid
        } else if hi < 0.0 {
            Shape::Inverted
        } else {
            Shape::Distorted
        }
    }

    /// What is wrong, for messages.
    pub fn describe(self) -> &'static str {
        match self {
            Shape::Valid => "valid",
            Shape::Inverted => {
                "inverted: its nodes run clockwise (they must run counter-clockwise; in a \
                 solid, the first face counter-clockwise seen from the opposite node or face)"
            }
            Shape::Degenerate => {
                "degenerate: its area (volume) is zero (coincident, collinear or coplanar nodes)"
            }
            Shape::Distorted => {
                "distorted: its Jacobian changes sign (a non-convex or self-intersecting element)"
            }
            Shape::OutOfRange => {
                "out of range: its coordinates are so large that its area (volume) \
                 overflows double precision (are the coordinates in metres?)"
            }
        }
    }
}

/// The geometry of one body: nodes, continuum elements and named sets.
#[derive(Clone, Debug)]
pub struct Part {
    /// The spatial dimension, 2 or 3 (plane parts keep `z = 0`).
    pub dim: usize,
    /// Node coordinates.
    pub coords: Vec<Point>,
    /// Element blocks (one per element kind present).
    pub blocks: Vec<Elements>,
    /// Named node sets.
    pub node_sets: BTreeMap<String, Vec<usize>>,
    /// Named boundary edge sets (node pairs, oriented with the body on the left).
    pub edge_sets: BTreeMap<String, Vec<[usize; 2]>>,
    /// Named boundary face sets of a solid (triangles and quadrilaterals,
    /// counter-clockwise seen from outside).
    pub face_sets: BTreeMap<String, Vec<Face>>,
    /// The node tags of the file the part came from (Gmsh), for messages.
    pub node_tags: Option<Vec<u64>>,
}

impl Default for Part {
    /// An empty plane part.
    fn default() -> Self {
        Part {
            dim: 2,
            coords: Vec::new(),
            blocks: Vec::new(),
            node_sets: BTreeMap::new(),
            edge_sets: BTreeMap::new(),
            face_sets: BTreeMap::new(),
            node_tags: None,
        }
    }
}

impl Part {
    fn node_name(&self, n: usize) -> String {
        let at = if self.dim == 2 {
            format!("{:?}", xy(self.coords[n]))
        } else {
            format!("{:?}", self.coords[n])
        };
        match &self.node_tags {
            Some(t) => format!("node with Gmsh tag {} at {at}", t[n]),
            None => format!("node {n} at {at}"),
        }
    }

    /// Checks that the coordinates are finite, that every node belongs to an element
    /// and that every element is valid ([`Shape`]); the error names the node or the
    /// element (by its file tag when the part came from a file).
    pub fn check(&self) -> std::result::Result<(), String> {
        if let Some(n) = self
            .coords
            .iter()
            .position(|c| !c.iter().all(|x| x.is_finite()))
        {
            return Err(format!("{} has a non-finite coordinate", self.node_name(n)));
        }
        let mut used = vec![false; self.coords.len()];
        for b in &self.blocks {
            for &n in &b.conn {
                used[n] = true;
            }
        }
        if let Some(n) = used.iter().position(|u| !u) {
            return Err(format!(
                "{} belongs to no element (remove it from the mesh, e.g. with Gmsh's \
                 `Mesh.SaveAll = 0` and physical groups for the elements)",
                self.node_name(n)
            ));
        }
        for b in &self.blocks {
            for e in 0..b.len() {
                let x: Vec<Point> = b.element(e).iter().map(|&n| self.coords[n]).collect();
                let shape = Shape::of(b.kind, &x);
                if shape != Shape::Valid {
                    return Err(format!(
                        "{} (nodes {:?}) is {}",
                        b.name(e),
                        b.element(e),
                        shape.describe()
                    ));
                }
            }
        }
        Ok(())
    }
}

/// What an element block is made of and how thick it is.
#[derive(Clone, Debug, PartialEq)]
pub struct Block {
    /// The elements.
    pub elements: Elements,
    /// Index of the body the block belongs to.
    pub body: usize,
    /// Index of the material in the model's material table.
    pub material: usize,
    /// Thickness for continuum elements, cross-section area for bars.
    pub section: f64,
}

/// The whole model's mesh: all bodies' nodes and element blocks.
#[derive(Clone, Debug)]
pub struct Mesh {
    /// The spatial dimension, 2 or 3: the number of displacement components per
    /// node (plane meshes keep `z = 0`).
    pub dim: usize,
    /// Node coordinates.
    pub coords: Vec<Point>,
    /// Body index of every node.
    pub node_body: Vec<usize>,
    /// Element blocks.
    pub blocks: Vec<Block>,
    /// Node sets, named `body.set`.
    pub node_sets: BTreeMap<String, Vec<usize>>,
    /// Edge sets, named `body.set`.
    pub edge_sets: BTreeMap<String, Vec<[usize; 2]>>,
    /// Face sets of solids, named `body.set` (see [`Part::face_sets`]).
    pub face_sets: BTreeMap<String, Vec<Face>>,
}

impl Default for Mesh {
    /// An empty plane mesh (its first part sets its dimension).
    fn default() -> Self {
        Mesh {
            dim: 2,
            coords: Vec::new(),
            node_body: Vec::new(),
            blocks: Vec::new(),
            node_sets: BTreeMap::new(),
            edge_sets: BTreeMap::new(),
            face_sets: BTreeMap::new(),
        }
    }
}

impl Mesh {
    /// Number of nodes.
    pub fn n_nodes(&self) -> usize {
        self.coords.len()
    }

    /// Number of degrees of freedom (`dim` per node).
    pub fn n_dofs(&self) -> usize {
        self.dim * self.coords.len()
    }

    /// Where node `n` is, for messages: `[x, y]` in the plane, `[x, y, z]` in a solid.
    pub fn position(&self, n: usize) -> String {
        if self.dim == 2 {
            format!("{:?}", self.xy(n))
        } else {
            format!("{:?}", self.coords[n])
        }
    }

    /// The in-plane coordinates of node `n`.
    #[inline]
    pub fn xy(&self, n: usize) -> [f64; 2] {
        xy(self.coords[n])
    }

    /// Number of elements over all blocks.
    pub fn n_elements(&self) -> usize {
        self.blocks.iter().map(|b| b.elements.len()).sum()
    }

    /// Adds a body's part; its sets become `body_name.set`. Returns the node offset.
    pub fn add_part(
        &mut self,
        part: &Part,
        body: usize,
        body_name: &str,
        material: usize,
        thickness: f64,
    ) -> usize {
        let off = self.coords.len();
        if off == 0 {
            self.dim = part.dim;
        }
        self.coords.extend_from_slice(&part.coords);
        self.node_body
            .extend(std::iter::repeat_n(body, part.coords.len()));
        for b in &part.blocks {
            self.blocks.push(Block {
                elements: Elements {
                    kind: b.kind,
                    conn: b.conn.iter().map(|&n| n + off).collect(),
                    tags: b.tags.clone(),
                },
                body,
                material,
                section: thickness,
            });
        }
        for (name, nodes) in &part.node_sets {
            self.node_sets.insert(
                format!("{body_name}.{name}"),
                nodes.iter().map(|&n| n + off).collect(),
            );
        }
        for (name, edges) in &part.edge_sets {
            self.edge_sets.insert(
                format!("{body_name}.{name}"),
                edges.iter().map(|e| [e[0] + off, e[1] + off]).collect(),
            );
        }
        for (name, faces) in &part.face_sets {
            self.face_sets.insert(
                format!("{body_name}.{name}"),
                faces.iter().map(|f| f.map(|n| n + off)).collect(),
            );
        }
        let all: Vec<usize> = (off..off + part.coords.len()).collect();
        self.node_sets.insert(format!("{body_name}.all"), all);
        off
    }

    /// Nodes of `body` lying on the segment `a`-`b` (within `tol`), ordered from `a`.
    pub fn nodes_on_segment(&self, body: usize, a: Point, b: Point, tol: f64) -> Vec<usize> {
        let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let len2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        let mut hits: Vec<(f64, usize)> = Vec::new();
        for (n, x) in self.coords.iter().enumerate() {
            if self.node_body[n] != body {
                continue;
            }
            let r = [x[0] - a[0], x[1] - a[1], x[2] - a[2]];
            let s = (r[0] * d[0] + r[1] * d[1] + r[2] * d[2]) / len2;
            let dist2 =
                (r[0] - s * d[0]).powi(2) + (r[1] - s * d[1]).powi(2) + (r[2] - s * d[2]).powi(2);
            if dist2 <= tol * tol && s >= -tol / len2.sqrt() && s <= 1.0 + tol / len2.sqrt() {
                hits.push((s, n));
            }
        }
        hits.sort_by(|p, q| p.0.total_cmp(&q.0));
        hits.into_iter().map(|(_, n)| n).collect()
    }

    /// The node nearest to `x`.
    pub fn nearest_node(&self, x: Point) -> Option<usize> {
        self.coords
            .iter()
            .enumerate()
            .map(|(n, c)| {
                (
                    n,
                    (c[0] - x[0]).powi(2) + (c[1] - x[1]).powi(2) + (c[2] - x[2]).powi(2),
                )
            })
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(n, _)| n)
    }

    /// Checks every element ([`Shape`]): an inverted, degenerate or distorted
    /// element is an error that names its body, the element (by its file tag when it
    /// has one) and its nodes.
    pub fn check_elements(&self, body_names: &[String]) -> Result<()> {
        for block in &self.blocks {
            for e in 0..block.elements.len() {
                let nodes = block.elements.element(e);
                let x: Vec<Point> = nodes.iter().map(|&n| self.coords[n]).collect();
                let shape = Shape::of(block.elements.kind, &x);
                if shape != Shape::Valid {
                    return Err(Error::Mesh(format!(
                        "body `{}`: {} (nodes {nodes:?}) is {}",
                        body_names.get(block.body).map_or("?", |s| s.as_str()),
                        block.elements.name(e),
                        shape.describe()
                    )));
                }
            }
        }
        Ok(())
    }

    /// The largest edge of the elements holding node `n` (0 for a node of no element).
    pub fn element_size_at(&self, n: usize) -> f64 {
        let mut size: f64 = 0.0;
        for b in &self.blocks {
            for e in 0..b.elements.len() {
                let nodes = b.elements.element(e);
                if nodes.contains(&n) {
                    for &[a, c] in b.elements.kind.edges() {
                        size = size.max(distance(self.coords[nodes[a]], self.coords[nodes[c]]));
                    }
                }
            }
        }
        size
    }

    /// The node coordinates of element `e` of `block`.
    pub(crate) fn element_points(&self, block: usize, e: usize) -> Vec<Point> {
        self.blocks[block]
            .elements
            .element(e)
            .iter()
            .map(|&n| self.coords[n])
            .collect()
    }

    /// The measure of continuum element `e` of `block`: its area in the plane, its
    /// volume in a solid.
    pub fn element_area(&self, block: usize, e: usize) -> f64 {
        let kind = self.blocks[block].elements.kind;
        let x = self.element_points(block, e);
        if kind.dim() == 3 {
            return crate::fe::element::measure(kind, &x);
        }
        polygon_area(&x).abs()
    }

    /// The crack-band size of element `e` of `block`: the square root of its area in
    /// the plane, the cube root of its volume in a solid. The element loop measures
    /// the same (`assembly::internal`, from its points' `Σ w det J`), and validation
    /// checks the crack-band limit with this one, so the two cannot disagree.
    pub fn crack_band_length(&self, block: usize, e: usize) -> f64 {
        let m = self.element_area(block, e).abs();
        if self.blocks[block].elements.kind.dim() == 3 {
            m.cbrt()
        } else {
            m.sqrt()
        }
    }

    /// Characteristic length of element `e` of `block` (the CFL estimate takes the minimum):
    /// for a triangle its smallest altitude, for a quadrilateral its area over its
    /// longest diagonal, for a bar its length; for a tetrahedron its smallest
    /// altitude, for a hexahedron `√3 V / d²` with `d` its longest body diagonal (a
    /// cube's `h/√3`, the counterpart of the quadrilateral's `h/√2`).
    pub fn element_length(&self, block: usize, e: usize) -> f64 {
        let b = &self.blocks[block];
        let x = self.element_points(block, e);
        let dist = distance;
        match b.elements.kind {
            ElementKind::Bar2 => dist(x[0], x[1]),
            ElementKind::Tri3 => {
                let area = 0.5
                    * ((x[1][0] - x[0][0]) * (x[2][1] - x[0][1])
                        - (x[2][0] - x[0][0]) * (x[1][1] - x[0][1]))
                        .abs();
                let lmax = dist(x[0], x[1]).max(dist(x[1], x[2])).max(dist(x[2], x[0]));
                2.0 * area / lmax
            }
            ElementKind::Quad4 => {
                let area = 0.5
                    * ((x[2][0] - x[0][0]) * (x[3][1] - x[1][1])
                        - (x[3][0] - x[1][0]) * (x[2][1] - x[0][1]))
                        .abs();
                let dmax = dist(x[0], x[2]).max(dist(x[1], x[3]));
                area / dmax
            }
            ElementKind::Tet4 => {
                let v = crate::fe::element::measure(ElementKind::Tet4, &x);
                let amax = ElementKind::Tet4
                    .faces()
                    .iter()
                    .map(|f| triangle_area(x[f[0]], x[f[1]], x[f[2]]))
                    .fold(0.0, f64::max);
                3.0 * v / amax
            }
            ElementKind::Hex8 => {
                let v = crate::fe::element::measure(ElementKind::Hex8, &x);
                let d = [[0, 6], [1, 7], [2, 4], [3, 5]]
                    .iter()
                    .map(|&[a, c]| dist(x[a], x[c]))
                    .fold(0.0, f64::max);
                3f64.sqrt() * v / (d * d)
            }
        }
    }
}

pub use crate::geometry::triangle_area;
