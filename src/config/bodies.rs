//! The parts of a scenario that place bodies and act on them: bodies and their
//! meshes (rectangles, boxes, Gmsh files), bars, supports, prescribed
//! displacements, loads and probes.

use serde::Deserialize;

use super::exact;
use crate::mesh::ElementKind;
use crate::model::TimeFunction;

/// A body.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// Name; its sets are called `name.set`.
    pub name: String,
    /// Material name.
    pub material: String,
    /// Thickness (m) of its elements: required for plane bodies, absent for solids.
    #[serde(default)]
    pub thickness: Option<f64>,
    /// Initial velocity (m/s; two components, three in a solid). Default at rest.
    #[serde(default)]
    #[serde(deserialize_with = "exact::vector")]
    pub velocity: exact::Vector,
    /// Its mesh.
    pub mesh: MeshSpec,
}

/// Where a body's mesh comes from.
#[derive(Clone, Debug, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum MeshSpec {
    /// Structured rectangle.
    Rectangle {
        /// Lower left corner. Default the origin.
        #[serde(default)]
        #[serde(deserialize_with = "exact::array")]
        origin: [f64; 2],
        /// Width and height.
        #[serde(deserialize_with = "exact::array")]
        size: [f64; 2],
        /// Cells along x and y (equal cells). Give this, or `element_size` (here or in
        /// `[meshing]`).
        #[serde(default, deserialize_with = "exact::option_array")]
        divisions: Option<[usize; 2]>,
        /// Largest cell size (m): each side (each band between `x_lines` /
        /// `y_lines`) is cut into the fewest equal cells no larger than it. Overrides
        /// `[meshing] element_size` for this body.
        #[serde(default)]
        element_size: Option<f64>,
        /// Grid lines the mesh must have, as distances from `origin` along x
        /// (strictly inside, increasing): rebar lines, a probe's node, the edge of
        /// another body. Only with `element_size`.
        #[serde(default)]
        x_lines: Vec<f64>,
        /// The same along y.
        #[serde(default)]
        y_lines: Vec<f64>,
        /// `quad4` (default) or `tri3`.
        #[serde(default = "default_element")]
        element: ElementKind,
    },
    /// Structured box of hexahedra or tetrahedra (a solid).
    Box {
        /// The corner of least coordinates. Default the origin.
        #[serde(default)]
        #[serde(deserialize_with = "exact::array")]
        origin: [f64; 3],
        /// Lengths along x, y and z.
        #[serde(deserialize_with = "exact::array")]
        size: [f64; 3],
        /// Cells along x, y and z (equal cells). Give this, or `element_size` (here
        /// or in `[meshing]`).
        #[serde(default, deserialize_with = "exact::option_array")]
        divisions: Option<[usize; 3]>,
        /// Largest cell size (m), as the rectangle's.
        #[serde(default)]
        element_size: Option<f64>,
        /// Grid planes along x the mesh must have (distances from `origin`).
        #[serde(default)]
        x_lines: Vec<f64>,
        /// The same along y.
        #[serde(default)]
        y_lines: Vec<f64>,
        /// The same along z.
        #[serde(default)]
        z_lines: Vec<f64>,
        /// `hex8` (default) or `tet4`.
        #[serde(default = "default_solid_element")]
        element: ElementKind,
    },
    /// Gmsh v4.1 file, relative to the scenario file.
    Gmsh {
        /// Path of the `.msh` file.
        file: String,
    },
}

fn default_element() -> ElementKind {
    ElementKind::Quad4
}

fn default_solid_element() -> ElementKind {
    ElementKind::Hex8
}

/// Bars along a straight line through nodes of a body (perfect bond: shared nodes).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BarSpec {
    /// Name for messages.
    pub name: String,
    /// Body whose nodes the bars connect.
    pub body: String,
    /// Material name (elastic).
    pub material: String,
    /// Cross-section area (m²).
    pub area: f64,
    /// Start point of the line (as many coordinates as the model has dimensions).
    #[serde(deserialize_with = "exact::vector")]
    pub from: exact::Vector,
    /// End point of the line.
    #[serde(deserialize_with = "exact::vector")]
    pub to: exact::Vector,
}

/// A displacement component.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum Component {
    /// Horizontal.
    X,
    /// Vertical.
    Y,
    /// Out of the plane (solids only).
    Z,
}

impl Component {
    /// The component's index in a node's dofs.
    pub fn index(self) -> usize {
        match self {
            Component::X => 0,
            Component::Y => 1,
            Component::Z => 2,
        }
    }
}

/// `[[supports]]`: fixed components of a node set.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SupportSpec {
    /// Node set (`body.set`).
    pub set: String,
    /// Components held at zero.
    pub fix: Vec<Component>,
}

/// `[[prescribed]]`: a displacement history on a node set.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PrescribedSpec {
    /// Node set.
    pub set: String,
    /// Component.
    pub component: Component,
    /// Amplitude (m).
    pub value: f64,
    /// Time function (default constant).
    #[serde(default = "constant")]
    pub function: TimeFunction,
}

fn constant() -> TimeFunction {
    TimeFunction::Constant
}

/// `[[loads]]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum LoadSpec {
    /// Traction (Pa) on an edge set, times the body's thickness (plane), or on a
    /// face set (solid).
    Traction {
        /// Edge set (plane) or face set (solid).
        set: String,
        /// Traction vector (two components, or three in a solid).
        #[serde(deserialize_with = "exact::vector")]
        value: exact::Vector,
        /// Time function (default constant).
        #[serde(default = "constant")]
        function: TimeFunction,
    },
    /// A force (N) on each node of a node set.
    Nodal {
        /// Node set.
        set: String,
        /// Force vector per node (two components, or three in a solid).
        #[serde(deserialize_with = "exact::vector")]
        value: exact::Vector,
        /// Time function (default constant).
        #[serde(default = "constant")]
        function: TimeFunction,
    },
}

/// `[[probes]]`: a named node whose displacement goes to `history.csv`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeSpec {
    /// Column prefix.
    pub name: String,
    /// The node nearest this point (two coordinates, three in a solid).
    #[serde(default, deserialize_with = "exact::option_vector")]
    pub at: Option<exact::Vector>,
    /// Or the single node of this set.
    #[serde(default)]
    pub set: Option<String>,
}
