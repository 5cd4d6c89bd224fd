//! External load vectors: edge tractions, body forces, nodal forces.

use crate::fe::{kinematics, QuadPoint};
use crate::mesh::{ElementKind, Mesh};

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
        let (xa, xb) = (mesh.coords[a], mesh.coords[b]);
        let l = ((xb[0] - xa[0]).powi(2) + (xb[1] - xa[1]).powi(2)).sqrt();
        for n in [a, b] {
            f[2 * n] += 0.5 * q[0] * l * thickness;
            f[2 * n + 1] += 0.5 * q[1] * l * thickness;
        }
    }
}

/// Adds a force `p` to every node of `nodes`.
pub fn add_nodal(nodes: &[usize], p: [f64; 2], f: &mut [f64]) {
    for &n in nodes {
        f[2 * n] += p[0];
        f[2 * n + 1] += p[1];
    }
}

/// 3x3 Gauss rule on `[-1,1]^2`.
pub const QUAD_3X3: [QuadPoint; 9] = {
    const A: f64 = 0.774_596_669_241_483_4;
    const W0: f64 = 8.0 / 9.0;
    const W1: f64 = 5.0 / 9.0;
    [
        ([-A, -A], W1 * W1),
        ([0.0, -A], W0 * W1),
        ([A, -A], W1 * W1),
        ([-A, 0.0], W1 * W0),
        ([0.0, 0.0], W0 * W0),
        ([A, 0.0], W1 * W0),
        ([-A, A], W1 * W1),
        ([0.0, A], W0 * W1),
        ([A, A], W1 * W1),
    ]
};

/// 6-point rule on the reference triangle (exact for degree 4).
pub const TRI_6: [QuadPoint; 6] = {
    const A: f64 = 0.445_948_490_915_965;
    const B: f64 = 0.091_576_213_509_771;
    const WA: f64 = 0.223_381_589_678_011 / 2.0;
    const WB: f64 = 0.109_951_743_655_322 / 2.0;
    [
        ([A, A], WA),
        ([1.0 - 2.0 * A, A], WA),
        ([A, 1.0 - 2.0 * A], WA),
        ([B, B], WB),
        ([1.0 - 2.0 * B, B], WB),
        ([B, 1.0 - 2.0 * B], WB),
    ]
};

/// A higher-order rule for integrating smooth fields over an element (loads, errors).
pub fn accurate_rule(kind: ElementKind) -> &'static [QuadPoint] {
    match kind {
        ElementKind::Quad4 => &QUAD_3X3,
        ElementKind::Tri3 => &TRI_6,
        ElementKind::Bar2 => &TRI_6[..0],
    }
}

/// Adds `∫ Nᵀ b(x) t dA` over all continuum elements for a body force density `b(x)`
/// (force per volume), e.g. a manufactured-solution source.
pub fn add_body_force<F: Fn([f64; 2]) -> [f64; 2]>(mesh: &Mesh, b: F, f: &mut [f64]) {
    for block in &mesh.blocks {
        let kind = block.elements.kind;
        if kind == ElementKind::Bar2 {
            continue;
        }
        let nn = kind.nodes();
        for e in 0..block.elements.len() {
            let nodes = block.elements.element(e);
            let x: Vec<[f64; 2]> = nodes.iter().map(|&n| mesh.coords[n]).collect();
            for &(xi, w) in accurate_rule(kind) {
                let k = kinematics(kind, &x, xi);
                let mut p = [0.0; 2];
                for a in 0..nn {
                    p[0] += k.n[a] * x[a][0];
                    p[1] += k.n[a] * x[a][1];
                }
                let bv = b(p);
                let jw = w * k.det_j * block.section;
                for (a, &n) in nodes.iter().enumerate() {
                    f[2 * n] += k.n[a] * bv[0] * jw;
                    f[2 * n + 1] += k.n[a] * bv[1] * jw;
                }
            }
        }
    }
}
