//! Reference elements, quadrature and the element matrices of plane (2D) elasticity.
//!
//! Voigt order everywhere: strain `[ε_xx, ε_yy, γ_xy]` (engineering shear
//! `γ_xy = 2 ε_xy`), stress `[σ_xx, σ_yy, σ_xy]`. Element dofs are ordered
//! `[u_0x, u_0y, u_1x, u_1y, ...]`. See `theory/discretisation.md`.

pub mod element;

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
}

impl ElementKind {
    /// Number of nodes of one element.
    pub fn nodes(self) -> usize {
        match self {
            ElementKind::Quad4 => 4,
            ElementKind::Tri3 => 3,
            ElementKind::Bar2 => 2,
        }
    }
}

/// In-plane idealisation of the third direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Plane {
    /// `σ_zz = 0`: thin walls (the paper's "shell" elements); a thickness multiplies.
    #[default]
    Stress,
    /// `ε_zz = 0`: long bodies; the thickness is the length represented.
    Strain,
}

/// A quadrature point: reference coordinates and weight.
pub type QuadPoint = ([f64; 2], f64);

const G: f64 = 0.577_350_269_189_625_8; // 1/sqrt(3)

/// 2x2 Gauss rule on `[-1,1]^2` (exact for bicubic integrands).
pub const QUAD_2X2: [QuadPoint; 4] = [
    ([-G, -G], 1.0),
    ([G, -G], 1.0),
    ([G, G], 1.0),
    ([-G, G], 1.0),
];

/// One-point rule on the reference triangle `(0,0),(1,0),(0,1)` (exact for linears).
pub const TRI_1: [QuadPoint; 1] = [([1.0 / 3.0, 1.0 / 3.0], 0.5)];

/// Three-point rule on the reference triangle (exact for quadratics).
pub const TRI_3: [QuadPoint; 3] = [
    ([1.0 / 6.0, 1.0 / 6.0], 1.0 / 6.0),
    ([2.0 / 3.0, 1.0 / 6.0], 1.0 / 6.0),
    ([1.0 / 6.0, 2.0 / 3.0], 1.0 / 6.0),
];

/// The stiffness / internal-force rule of an element kind.
pub fn stiffness_rule(kind: ElementKind) -> &'static [QuadPoint] {
    match kind {
        ElementKind::Quad4 => &QUAD_2X2,
        ElementKind::Tri3 => &TRI_1,
        ElementKind::Bar2 => &TRI_1[..0],
    }
}

/// The consistent-mass rule (exact for the element's `N_a N_b det J`).
pub fn mass_rule(kind: ElementKind) -> &'static [QuadPoint] {
    match kind {
        ElementKind::Quad4 => &QUAD_2X2,
        ElementKind::Tri3 => &TRI_3,
        ElementKind::Bar2 => &TRI_1[..0],
    }
}

/// Shape functions and their reference derivatives at `xi` (first `kind.nodes()` used).
#[inline]
pub fn shape(kind: ElementKind, xi: [f64; 2]) -> ([f64; 4], [[f64; 2]; 4]) {
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
        ElementKind::Bar2 => unreachable!("bars have no 2D shape functions"),
    }
}

/// Shape functions, physical derivatives and Jacobian determinant at one point.
#[derive(Clone, Copy, Debug)]
pub struct PointKinematics {
    /// Shape function values.
    pub n: [f64; 4],
    /// `∂N_a/∂x`, `∂N_a/∂y`.
    pub dndx: [[f64; 2]; 4],
    /// Jacobian determinant of the reference map.
    pub det_j: f64,
}

/// Evaluates shape functions and physical gradients at `xi` for nodes `x`.
#[inline]
pub fn kinematics(kind: ElementKind, x: &[[f64; 2]], xi: [f64; 2]) -> PointKinematics {
    let (n, d) = shape(kind, xi);
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
    let mut dndx = [[0.0; 2]; 4];
    for a in 0..nn {
        for i in 0..2 {
            dndx[a][i] = d[a][0] * ji[0][i] + d[a][1] * ji[1][i];
        }
    }
    PointKinematics { n, dndx, det_j }
}

/// Smallest and largest Jacobian determinant over the element's corners and Gauss
/// points (a non-positive minimum means an inverted, degenerate or distorted
/// element; see `mesh::Shape`).
pub fn jacobian_range(kind: ElementKind, x: &[[f64; 2]]) -> (f64, f64) {
    let corners: &[[f64; 2]] = match kind {
        ElementKind::Quad4 => &[[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]],
        _ => &[[1.0 / 3.0, 1.0 / 3.0]],
    };
    corners
        .iter()
        .chain(stiffness_rule(kind).iter().map(|q| &q.0))
        .map(|&xi| kinematics(kind, x, xi).det_j)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), j| {
            (lo.min(j), hi.max(j))
        })
}

/// Isotropic linear elasticity matrix (Voigt, engineering shear) for `plane`.
pub fn elasticity(e: f64, nu: f64, plane: Plane) -> [[f64; 3]; 3] {
    match plane {
        Plane::Stress => {
            let c = e / (1.0 - nu * nu);
            [
                [c, c * nu, 0.0],
                [c * nu, c, 0.0],
                [0.0, 0.0, c * 0.5 * (1.0 - nu)],
            ]
        }
        Plane::Strain => {
            let c = e / ((1.0 + nu) * (1.0 - 2.0 * nu));
            [
                [c * (1.0 - nu), c * nu, 0.0],
                [c * nu, c * (1.0 - nu), 0.0],
                [0.0, 0.0, c * 0.5 * (1.0 - 2.0 * nu)],
            ]
        }
    }
}

/// Strain `[ε_xx, ε_yy, γ_xy]` at a point from the element displacements `ue`.
#[inline]
pub fn strain(k: &PointKinematics, nn: usize, ue: &[f64]) -> [f64; 3] {
    let mut eps = [0.0; 3];
    for a in 0..nn {
        let (dx, dy) = (k.dndx[a][0], k.dndx[a][1]);
        let (ux, uy) = (ue[2 * a], ue[2 * a + 1]);
        eps[0] += dx * ux;
        eps[1] += dy * uy;
        eps[2] += dy * ux + dx * uy;
    }
    eps
}
