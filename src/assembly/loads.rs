//! External load vectors: edge (plane) and face (solid) tractions, body forces,
//! nodal forces.

use std::sync::OnceLock;

use crate::fe::{kinematics, QuadPoint};
use crate::mesh::{triangle_area, ElementKind, Face, Mesh};

/// Consistent nodal forces of a uniform traction `q` (force per area) on the edges
/// `edges`, for a wall of thickness `thickness`: each node of an edge of length `L`
/// gets `q L t / 2`. Adds into `f`.
pub fn add_edge_traction(
    mesh: &Mesh,
    edges: &[[usize; 2]],
    q: [f64; 2],
    thickness: f64,
    f: &mut [f64],
) {
    for &[a, b] in edges {
        let l = crate::mesh::distance(mesh.coords[a], mesh.coords[b]);
        for n in [a, b] {
            f[2 * n] += 0.5 * q[0] * l * thickness;
            f[2 * n + 1] += 0.5 * q[1] * l * thickness;
        }
    }
}

/// Consistent nodal forces of a uniform traction `q` (force per area) on the faces
/// `faces` of a solid (triangles and quadrilaterals): a triangle gives each node a third of `q A`; a
/// quadrilateral `∫ N_a q dA` over its bilinear surface, 2x2 Gauss (exact for a
/// parallelogram). Adds into `f` (three dofs per node).
pub fn add_face_traction(mesh: &Mesh, faces: &[Face], q: [f64; 3], f: &mut [f64]) {
    for face in faces {
        if face.is_triangle() {
            let a = triangle_area(
                mesh.coords[face[0]],
                mesh.coords[face[1]],
                mesh.coords[face[2]],
            );
            for &n in face.corners() {
                for i in 0..3 {
                    f[3 * n + i] += q[i] * a / 3.0;
                }
            }
            continue;
        }
        for (a, w) in quad_face_weights(mesh, face).into_iter().enumerate() {
            for i in 0..3 {
                f[3 * face[a] + i] += q[i] * w;
            }
        }
    }
}

/// `∫ N_a dA` over the bilinear surface through the four nodes of `face` (2x2 Gauss).
pub fn quad_face_weights(mesh: &Mesh, face: &Face) -> [f64; 4] {
    let x: [[f64; 3]; 4] = std::array::from_fn(|a| mesh.coords[face[a]]);
    let mut out = [0.0; 4];
    for &(xi, w) in &crate::fe::QUAD_2X2 {
        let (r, s) = (xi[0], xi[1]);
        let n = [
            0.25 * (1.0 - r) * (1.0 - s),
            0.25 * (1.0 + r) * (1.0 - s),
            0.25 * (1.0 + r) * (1.0 + s),
            0.25 * (1.0 - r) * (1.0 + s),
        ];
        let dr = [
            -0.25 * (1.0 - s),
            0.25 * (1.0 - s),
            0.25 * (1.0 + s),
            -0.25 * (1.0 + s),
        ];
        let ds = [
            -0.25 * (1.0 - r),
            -0.25 * (1.0 + r),
            0.25 * (1.0 + r),
            0.25 * (1.0 - r),
        ];
        let mut tr = [0.0; 3];
        let mut ts = [0.0; 3];
        for a in 0..4 {
            for i in 0..3 {
                tr[i] += dr[a] * x[a][i];
                ts[i] += ds[a] * x[a][i];
            }
        }
        let da = crate::geometry::norm(crate::geometry::cross(tr, ts)) * w;
        for a in 0..4 {
            out[a] += n[a] * da;
        }
    }
    out
}

/// Adds a force `p` (its first `dim` components) to every node of `nodes`.
pub fn add_nodal(dim: usize, nodes: &[usize], p: [f64; 3], f: &mut [f64]) {
    for &n in nodes {
        for i in 0..dim {
            f[dim * n + i] += p[i];
        }
    }
}

/// 3x3 Gauss rule on `[-1,1]^2`.
pub const QUAD_3X3: [QuadPoint; 9] = {
    const A: f64 = 0.774_596_669_241_483_4;
    const W0: f64 = 8.0 / 9.0;
    const W1: f64 = 5.0 / 9.0;
    [
        ([-A, -A, 0.0], W1 * W1),
        ([0.0, -A, 0.0], W0 * W1),
        ([A, -A, 0.0], W1 * W1),
        ([-A, 0.0, 0.0], W1 * W0),
        ([0.0, 0.0, 0.0], W0 * W0),
        ([A, 0.0, 0.0], W1 * W0),
        ([-A, A, 0.0], W1 * W1),
        ([0.0, A, 0.0], W0 * W1),
        ([A, A, 0.0], W1 * W1),
    ]
};

/// 6-point rule on the reference triangle (exact for degree 4).
pub const TRI_6: [QuadPoint; 6] = {
    const A: f64 = 0.445_948_490_915_965;
    const B: f64 = 0.091_576_213_509_771;
    const WA: f64 = 0.223_381_589_678_011 / 2.0;
    const WB: f64 = 0.109_951_743_655_322 / 2.0;
    [
        ([A, A, 0.0], WA),
        ([1.0 - 2.0 * A, A, 0.0], WA),
        ([A, 1.0 - 2.0 * A, 0.0], WA),
        ([B, B, 0.0], WB),
        ([1.0 - 2.0 * B, B, 0.0], WB),
        ([B, 1.0 - 2.0 * B, 0.0], WB),
    ]
};

/// The 3x3x3 Gauss points of `[-1,1]^3` as `(ξ, w)`.
fn cube_3x3x3() -> Vec<QuadPoint> {
    const A: f64 = 0.774_596_669_241_483_4;
    let g = [(-A, 5.0 / 9.0), (0.0, 8.0 / 9.0), (A, 5.0 / 9.0)];
    let mut out = Vec::with_capacity(27);
    for &(c, wc) in &g {
        for &(b, wb) in &g {
            for &(a, wa) in &g {
                out.push(([a, b, c], wa * wb * wc));
            }
        }
    }
    out
}

/// The 3x3x3 rule on the hexahedron (exact for degree 5 per direction).
fn hex_27() -> &'static [QuadPoint] {
    static RULE: OnceLock<Vec<QuadPoint>> = OnceLock::new();
    RULE.get_or_init(cube_3x3x3)
}

/// 27 points on the reference tetrahedron: the cube's 3x3x3 rule collapsed onto
/// it (Duffy), exact for polynomials of degree 5 and more.
fn tet_27() -> &'static [QuadPoint] {
    static RULE: OnceLock<Vec<QuadPoint>> = OnceLock::new();
    RULE.get_or_init(|| {
        cube_3x3x3()
            .into_iter()
            .map(|(p, w)| {
                let (u, v, t) = (0.5 * (p[0] + 1.0), 0.5 * (p[1] + 1.0), 0.5 * (p[2] + 1.0));
                // (u, v, t) in the unit cube -> the tetrahedron.
                let x = u * (1.0 - v) * (1.0 - t);
                let y = v * (1.0 - t);
                let z = t;
                let jac = (1.0 - v) * (1.0 - t) * (1.0 - t);
                ([x, y, z], w * 0.125 * jac)
            })
            .collect()
    })
}

/// A higher-order rule for integrating smooth fields over an element (loads, errors).
pub fn accurate_rule(kind: ElementKind) -> &'static [QuadPoint] {
    match kind {
        ElementKind::Quad4 => &QUAD_3X3,
        ElementKind::Tri3 => &TRI_6,
        ElementKind::Bar2 => &TRI_6[..0],
        ElementKind::Hex8 => hex_27(),
        ElementKind::Tet4 => tet_27(),
    }
}

/// Adds `∫ Nᵀ b(x) t dA` (solids: `∫ Nᵀ b dV`) over all continuum elements for a
/// body force density `b(x)` (force per volume), e.g. a manufactured-solution
/// source; `D` is the mesh's dimension.
pub fn add_body_force<const D: usize, F: Fn([f64; D]) -> [f64; D]>(
    mesh: &Mesh,
    b: F,
    f: &mut [f64],
) {
    assert_eq!(D, mesh.dim, "a body force of the mesh's dimension");
    for block in &mesh.blocks {
        let kind = block.elements.kind;
        if kind == ElementKind::Bar2 {
            continue;
        }
        let nn = kind.nodes();
        for e in 0..block.elements.len() {
            let nodes = block.elements.element(e);
            let x: Vec<[f64; 3]> = nodes.iter().map(|&n| mesh.coords[n]).collect();
            for &(xi, w) in accurate_rule(kind) {
                let k = kinematics(kind, &x, xi);
                let mut p = [0.0; D];
                for a in 0..nn {
                    for i in 0..D {
                        p[i] += k.n[a] * x[a][i];
                    }
                }
                let bv = b(p);
                let jw = w * k.det_j * block.section;
                for (a, &n) in nodes.iter().enumerate() {
                    for i in 0..D {
                        f[D * n + i] += k.n[a] * bv[i] * jw;
                    }
                }
            }
        }
    }
}
