//! Reference elements, quadrature and the element matrices of plane (2D) and solid
//! (3D) elasticity.
//!
//! Voigt order everywhere: in the plane, strain `[ε_xx, ε_yy, γ_xy]` (engineering
//! shear `γ_xy = 2 ε_xy`) and stress `[σ_xx, σ_yy, σ_xy]`; in solids the plane's
//! three components come first, then the out-of-plane ones,
//! `[ε_xx, ε_yy, γ_xy, ε_zz, γ_yz, γ_zx]` (so a plane-strain vector is a solid one
//! with its last three components zero). Element dofs are ordered
//! `[u_0x, u_0y, (u_0z,) u_1x, ...]`. See `theory/discretisation.md` and
//! `theory/solids.md`.

pub mod element;
pub mod frame;
pub mod kinematics;
pub mod principal;

pub use kinematics::{
    FrameUser, Idealisation, Kinematics, PlaneStrain, PlaneStress, Solid, StrainSpace,
    STRAIN_NAMES, STRESS_NAMES,
};

/// The element types rothe knows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ElementKind {
    /// Bilinear quadrilateral, nodes counter-clockwise, 2x2 Gauss.
    Quad4,
    /// Linear (constant-strain) triangle, nodes counter-clockwise, 1 Gauss point.
    Tri3,
    /// Two-node bar (truss) carrying axial force only.
    Bar2,
    /// Trilinear hexahedron, 2x2x2 Gauss: nodes 0-3 one face, counter-clockwise seen
    /// from the side of the opposite face, nodes 4-7 opposite them in the same order
    /// (Gmsh's and VTK's numbering).
    Hex8,
    /// Linear (constant-strain) tetrahedron, 1 Gauss point: node 3 on the side
    /// where `(x1 − x0) × (x2 − x0)` points.
    Tet4,
}

/// The most nodes an element has (Hex8).
pub const MAX_NODES: usize = 8;

/// The most dofs an element has (Hex8: 8 nodes x 3).
pub const MAX_ELEMENT_DOFS: usize = 24;

impl ElementKind {
    /// Number of nodes of one element.
    pub fn nodes(self) -> usize {
        match self {
            ElementKind::Quad4 => 4,
            ElementKind::Tri3 => 3,
            ElementKind::Bar2 => 2,
            ElementKind::Hex8 => 8,
            ElementKind::Tet4 => 4,
        }
    }

    /// The spatial dimension of a continuum kind (bars live in any: 0).
    pub fn dim(self) -> usize {
        match self {
            ElementKind::Quad4 | ElementKind::Tri3 => 2,
            ElementKind::Hex8 | ElementKind::Tet4 => 3,
            ElementKind::Bar2 => 0,
        }
    }

    /// Number of material points of one element: the points of its stiffness rule
    /// (bars: one).
    pub fn points(self) -> usize {
        match self {
            ElementKind::Bar2 => 1,
            k => stiffness_rule(k).len(),
        }
    }

    /// The element's edges as pairs of local node indices (for plane kinds, the
    /// boundary in node order).
    pub fn edges(self) -> &'static [[usize; 2]] {
        match self {
            ElementKind::Quad4 => &[[0, 1], [1, 2], [2, 3], [3, 0]],
            ElementKind::Tri3 => &[[0, 1], [1, 2], [2, 0]],
            ElementKind::Bar2 => &[[0, 1]],
            ElementKind::Hex8 => &[
                [0, 1],
                [1, 2],
                [2, 3],
                [3, 0],
                [4, 5],
                [5, 6],
                [6, 7],
                [7, 4],
                [0, 4],
                [1, 5],
                [2, 6],
                [3, 7],
            ],
            ElementKind::Tet4 => &[[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]],
        }
    }

    /// The faces of a solid kind as local node lists, each counter-clockwise seen
    /// from outside (empty for plane kinds and bars).
    pub fn faces(self) -> &'static [&'static [usize]] {
        match self {
            ElementKind::Hex8 => &[
                &[0, 3, 2, 1],
                &[4, 5, 6, 7],
                &[0, 1, 5, 4],
                &[1, 2, 6, 5],
                &[2, 3, 7, 6],
                &[3, 0, 4, 7],
            ],
            ElementKind::Tet4 => &[&[0, 2, 1], &[0, 1, 3], &[1, 2, 3], &[2, 0, 3]],
            _ => &[],
        }
    }

    /// The reference coordinates of the nodes (for shape checks at the corners).
    pub fn corners(self) -> &'static [[f64; 3]] {
        match self {
            ElementKind::Quad4 => &[
                [-1.0, -1.0, 0.0],
                [1.0, -1.0, 0.0],
                [1.0, 1.0, 0.0],
                [-1.0, 1.0, 0.0],
            ],
            ElementKind::Hex8 => &HEX_CORNERS,
            _ => &[],
        }
    }
}

/// The reference nodes of the hexahedron on `[-1,1]^3`.
const HEX_CORNERS: [[f64; 3]; 8] = [
    [-1.0, -1.0, -1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0],
    [-1.0, 1.0, -1.0],
    [-1.0, -1.0, 1.0],
    [1.0, -1.0, 1.0],
    [1.0, 1.0, 1.0],
    [-1.0, 1.0, 1.0],
];

/// A quadrature point: reference coordinates (plane kinds keep the third zero) and
/// weight.
pub type QuadPoint = ([f64; 3], f64);

const G: f64 = 0.577_350_269_189_625_8; // 1/sqrt(3)

/// 2x2 Gauss rule on `[-1,1]^2` (exact for bicubic integrands).
pub const QUAD_2X2: [QuadPoint; 4] = [
    ([-G, -G, 0.0], 1.0),
    ([G, -G, 0.0], 1.0),
    ([G, G, 0.0], 1.0),
    ([-G, G, 0.0], 1.0),
];

/// One-point rule on the reference triangle `(0,0),(1,0),(0,1)` (exact for linears).
pub const TRI_1: [QuadPoint; 1] = [([1.0 / 3.0, 1.0 / 3.0, 0.0], 0.5)];

/// Three-point rule on the reference triangle (exact for quadratics).
pub const TRI_3: [QuadPoint; 3] = [
    ([1.0 / 6.0, 1.0 / 6.0, 0.0], 1.0 / 6.0),
    ([2.0 / 3.0, 1.0 / 6.0, 0.0], 1.0 / 6.0),
    ([1.0 / 6.0, 2.0 / 3.0, 0.0], 1.0 / 6.0),
];

/// 2x2x2 Gauss rule on `[-1,1]^3` (exact for tricubic integrands), in the order of
/// the hexahedron's nodes.
pub const HEX_2X2X2: [QuadPoint; 8] = [
    ([-G, -G, -G], 1.0),
    ([G, -G, -G], 1.0),
    ([G, G, -G], 1.0),
    ([-G, G, -G], 1.0),
    ([-G, -G, G], 1.0),
    ([G, -G, G], 1.0),
    ([G, G, G], 1.0),
    ([-G, G, G], 1.0),
];

/// One-point rule on the reference tetrahedron `(0,0,0),(1,0,0),(0,1,0),(0,0,1)`
/// (exact for linears).
pub const TET_1: [QuadPoint; 1] = [([0.25, 0.25, 0.25], 1.0 / 6.0)];

const TA: f64 = 0.585_410_196_624_968_5; // (5 + 3 sqrt 5) / 20
const TB: f64 = 0.138_196_601_125_010_5; // (5 - sqrt 5) / 20

/// Four-point rule on the reference tetrahedron (exact for quadratics).
pub const TET_4: [QuadPoint; 4] = [
    ([TB, TB, TB], 1.0 / 24.0),
    ([TA, TB, TB], 1.0 / 24.0),
    ([TB, TA, TB], 1.0 / 24.0),
    ([TB, TB, TA], 1.0 / 24.0),
];

/// The stiffness / internal-force rule of an element kind.
pub fn stiffness_rule(kind: ElementKind) -> &'static [QuadPoint] {
    match kind {
        ElementKind::Quad4 => &QUAD_2X2,
        ElementKind::Tri3 => &TRI_1,
        ElementKind::Bar2 => &TRI_1[..0],
        ElementKind::Hex8 => &HEX_2X2X2,
        ElementKind::Tet4 => &TET_1,
    }
}

/// The consistent-mass rule (exact for the element's `N_a N_b det J`).
pub fn mass_rule(kind: ElementKind) -> &'static [QuadPoint] {
    match kind {
        ElementKind::Quad4 => &QUAD_2X2,
        ElementKind::Tri3 => &TRI_3,
        ElementKind::Bar2 => &TRI_1[..0],
        // 2x2x2 integrates N_a N_b det J exactly for a parallelepiped and to the
        // rule's order otherwise (the usual choice).
        ElementKind::Hex8 => &HEX_2X2X2,
        ElementKind::Tet4 => &TET_4,
    }
}

/// Shape functions and their reference derivatives at `xi` (first `kind.nodes()`
/// used; plane kinds leave the third derivative zero).
#[inline]
pub fn shape(kind: ElementKind, xi: [f64; 3]) -> ([f64; MAX_NODES], [[f64; 3]; MAX_NODES]) {
    let mut n = [0.0; MAX_NODES];
    let mut d = [[0.0; 3]; MAX_NODES];
    match kind {
        ElementKind::Hex8 => {
            for (a, c) in HEX_CORNERS.iter().enumerate() {
                let f = [1.0 + c[0] * xi[0], 1.0 + c[1] * xi[1], 1.0 + c[2] * xi[2]];
                n[a] = 0.125 * f[0] * f[1] * f[2];
                d[a] = [
                    0.125 * c[0] * f[1] * f[2],
                    0.125 * f[0] * c[1] * f[2],
                    0.125 * f[0] * f[1] * c[2],
                ];
            }
        }
        ElementKind::Tet4 => {
            n[..4].copy_from_slice(&[1.0 - xi[0] - xi[1] - xi[2], xi[0], xi[1], xi[2]]);
            d[..4].copy_from_slice(&[
                [-1.0, -1.0, -1.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
            ]);
        }
        _ => {
            let (n2, d2) = shape_plane(kind, [xi[0], xi[1]]);
            for a in 0..4 {
                n[a] = n2[a];
                d[a] = [d2[a][0], d2[a][1], 0.0];
            }
        }
    }
    (n, d)
}

/// Shape functions and their reference derivatives of a plane kind at `xi`.
#[inline]
fn shape_plane(kind: ElementKind, xi: [f64; 2]) -> ([f64; 4], [[f64; 2]; 4]) {
    match kind {
        ElementKind::Quad4 => {
            let (r, s) = (xi[0], xi[1]);
            let n = [
                0.25 * (1.0 - r) * (1.0 - s),
                0.25 * (1.0 + r) * (1.0 - s),
                0.25 * (1.0 + r) * (1.0 + s),
                0.25 * (1.0 - r) * (1.0 + s),
            ];
            let d = [
                [-0.25 * (1.0 - s), -0.25 * (1.0 - r)],
                [0.25 * (1.0 - s), -0.25 * (1.0 + r)],
                [0.25 * (1.0 + s), 0.25 * (1.0 + r)],
                [-0.25 * (1.0 + s), 0.25 * (1.0 - r)],
            ];
            (n, d)
        }
        ElementKind::Tri3 => {
            let (r, s) = (xi[0], xi[1]);
            (
                [1.0 - r - s, r, s, 0.0],
                [[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0], [0.0, 0.0]],
            )
        }
        _ => unreachable!("bars and solids have no plane shape functions"),
    }
}

/// Shape functions, physical derivatives and Jacobian determinant at one point.
#[derive(Clone, Copy, Debug)]
pub struct PointKinematics {
    /// Shape function values.
    pub n: [f64; MAX_NODES],
    /// `∂N_a/∂x`, `∂N_a/∂y`, `∂N_a/∂z` (the last zero for plane kinds).
    pub dndx: [[f64; 3]; MAX_NODES],
    /// Jacobian determinant of the reference map (an area ratio in the plane, a
    /// volume ratio in a solid).
    pub det_j: f64,
}

/// Shape function values and reference derivatives at one point of a rule.
pub type ReferenceShape = ([f64; MAX_NODES], [[f64; 3]; MAX_NODES]);

/// [`shape`] at every point of `kind`'s stiffness rule, computed once per kind (the
/// Gauss-point passes read them instead of evaluating the shape functions at every
/// point of every element).
pub fn rule_shapes(kind: ElementKind) -> &'static [ReferenceShape] {
    use std::sync::OnceLock;
    static TABLES: [OnceLock<Vec<ReferenceShape>>; 5] = [
        OnceLock::new(),
        OnceLock::new(),
        OnceLock::new(),
        OnceLock::new(),
        OnceLock::new(),
    ];
    let slot = match kind {
        ElementKind::Quad4 => 0,
        ElementKind::Tri3 => 1,
        ElementKind::Bar2 => 2,
        ElementKind::Hex8 => 3,
        ElementKind::Tet4 => 4,
    };
    TABLES[slot].get_or_init(|| {
        if kind == ElementKind::Bar2 {
            return Vec::new();
        }
        stiffness_rule(kind)
            .iter()
            .map(|&(xi, _)| shape(kind, xi))
            .collect()
    })
}

impl PointKinematics {
    /// All zero (a placeholder to be overwritten).
    pub const ZERO: PointKinematics = PointKinematics {
        n: [0.0; MAX_NODES],
        dndx: [[0.0; 3]; MAX_NODES],
        det_j: 0.0,
    };
}

/// Evaluates shape functions and physical gradients at `xi` for nodes `x`.
#[inline]
pub fn kinematics(kind: ElementKind, x: &[[f64; 3]], xi: [f64; 3]) -> PointKinematics {
    kinematics_from(kind, x, &shape(kind, xi))
}

/// [`kinematics()`] from the shape values and reference derivatives `reference` of the
/// point (as [`rule_shapes`] holds them).
#[inline(always)]
pub fn kinematics_from(
    kind: ElementKind,
    x: &[[f64; 3]],
    reference: &ReferenceShape,
) -> PointKinematics {
    match kind {
        ElementKind::Hex8 => return kinematics_solid::<8>(x, reference),
        ElementKind::Tet4 => return kinematics_solid::<4>(x, reference),
        _ => {}
    }
    let (n2, d) = reference;
    let nn = kind.nodes();
    let mut j = [[0.0; 2]; 2]; // j[i][k] = ∂x_i/∂ξ_k
    for a in 0..nn {
        for i in 0..2 {
            for k in 0..2 {
                j[i][k] += x[a][i] * d[a][k];
            }
        }
    }
    let det_j = j[0][0] * j[1][1] - j[0][1] * j[1][0];
    let inv = 1.0 / det_j;
    // ξ_k,x_i = (J^-1)_{k i}
    let ji = [
        [j[1][1] * inv, -j[0][1] * inv],
        [-j[1][0] * inv, j[0][0] * inv],
    ];
    let mut dndx = [[0.0; 3]; MAX_NODES];
    let mut n = [0.0; MAX_NODES];
    for a in 0..nn {
        n[a] = n2[a];
        for i in 0..2 {
            dndx[a][i] = d[a][0] * ji[0][i] + d[a][1] * ji[1][i];
        }
    }
    PointKinematics { n, dndx, det_j }
}

/// [`kinematics`] of a solid kind of `N` nodes: the 3x3 Jacobian inverted by
/// cofactors (loops of a known length, which the compiler unrolls).
#[inline(always)]
fn kinematics_solid<const N: usize>(x: &[[f64; 3]], reference: &ReferenceShape) -> PointKinematics {
    let (n, d) = reference;
    let x = &x[..N];
    let mut j = [[0.0; 3]; 3]; // j[i][k] = ∂x_i/∂ξ_k
    for a in 0..N {
        for i in 0..3 {
            for k in 0..3 {
                j[i][k] += x[a][i] * d[a][k];
            }
        }
    }
    let (inv, det_j) = inverse3(&j);
    // ∂N_a/∂x_i = Σ_k ∂N_a/∂ξ_k (J⁻¹)_{k i}
    let mut dndx = [[0.0; 3]; MAX_NODES];
    for a in 0..N {
        for i in 0..3 {
            dndx[a][i] = d[a][0] * inv[0][i] + d[a][1] * inv[1][i] + d[a][2] * inv[2][i];
        }
    }
    PointKinematics { n: *n, dndx, det_j }
}

/// The inverse and determinant of a 3x3 matrix (cofactors; the inverse is not
/// finite when the determinant vanishes).
#[inline]
pub fn inverse3(j: &[[f64; 3]; 3]) -> ([[f64; 3]; 3], f64) {
    let c00 = j[1][1] * j[2][2] - j[1][2] * j[2][1];
    let c01 = j[1][2] * j[2][0] - j[1][0] * j[2][2];
    let c02 = j[1][0] * j[2][1] - j[1][1] * j[2][0];
    let det = j[0][0] * c00 + j[0][1] * c01 + j[0][2] * c02;
    let r = 1.0 / det;
    let inv = [
        [
            c00 * r,
            (j[0][2] * j[2][1] - j[0][1] * j[2][2]) * r,
            (j[0][1] * j[1][2] - j[0][2] * j[1][1]) * r,
        ],
        [
            c01 * r,
            (j[0][0] * j[2][2] - j[0][2] * j[2][0]) * r,
            (j[0][2] * j[1][0] - j[0][0] * j[1][2]) * r,
        ],
        [
            c02 * r,
            (j[0][1] * j[2][0] - j[0][0] * j[2][1]) * r,
            (j[0][0] * j[1][1] - j[0][1] * j[1][0]) * r,
        ],
    ];
    (inv, det)
}

/// Smallest and largest Jacobian determinant over the element's corners and Gauss
/// points (a non-positive minimum means an inverted, degenerate or distorted
/// element; see `mesh::Shape`).
pub fn jacobian_range(kind: ElementKind, x: &[[f64; 3]]) -> (f64, f64) {
    let centroid: &[[f64; 3]] = match kind {
        ElementKind::Tet4 => &[[0.25, 0.25, 0.25]],
        _ => &[[1.0 / 3.0, 1.0 / 3.0, 0.0]],
    };
    let corners = match kind {
        ElementKind::Quad4 | ElementKind::Hex8 => kind.corners(),
        _ => centroid,
    };
    corners
        .iter()
        .chain(stiffness_rule(kind).iter().map(|q| &q.0))
        .map(|&xi| kinematics(kind, x, xi).det_j)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), j| {
            (lo.min(j), hi.max(j))
        })
}

/// The signed area of the polygon `x` (positive when its vertices run
/// counter-clockwise).
#[inline]
pub fn polygon_area(x: &[[f64; 3]]) -> f64 {
    0.5 * (0..x.len())
        .map(|a| {
            let b = (a + 1) % x.len();
            x[a][0] * x[b][1] - x[b][0] * x[a][1]
        })
        .sum::<f64>()
}
