//! Inner products of displacement fields on a mesh: `L2(Ω)` and `H1(Ω)`
//! (`(x, y)_H1 = ∫ x·y + ∇x:∇y dΩ`), by the mass quadrature of every continuum
//! element, which is exact for the products of its shape functions: 2×2 Gauss on a
//! parallelogram Q4 (bilinear times bilinear), the three-point rule on a T3 (linear
//! times linear, quadratic). The one-point stiffness rule of a T3 would see only the
//! centroid, where a linear field with nodal values `(1, −1, 0)` vanishes although
//! its `∫ u² = A/6`: a seminorm. Bars are lines of the continuum's nodes and add
//! nothing. The domain is the plane section (no thickness weight): the norms of the
//! Rothe theory on `Ω ⊂ R²`.

use crate::fe::{kinematics, mass_rule, ElementKind, MAX_NODES};
use crate::mesh::Mesh;

/// One Gauss point: weight × det J, shape values and gradients, element nodes.
struct Point {
    w: f64,
    n: [f64; MAX_NODES],
    dndx: [[f64; 3]; MAX_NODES],
    nodes: [usize; MAX_NODES],
    nn: usize,
}

/// The quadrature of a mesh, computed once and reused for every inner product.
pub struct Norms {
    points: Vec<Point>,
    /// Dofs per node.
    dim: usize,
}

/// `(x, y)` in `L2` and in `H1`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Products {
    /// `∫ x·y`.
    pub l2: f64,
    /// `∫ x·y + ∇x:∇y`.
    pub h1: f64,
}

impl Norms {
    /// The quadrature of every continuum element of `mesh`.
    pub fn new(mesh: &Mesh) -> Self {
        let mut points = Vec::new();
        for b in &mesh.blocks {
            let kind = b.elements.kind;
            if kind == ElementKind::Bar2 {
                continue;
            }
            let nn = kind.nodes();
            for e in 0..b.elements.len() {
                let conn = b.elements.element(e);
                let x: Vec<[f64; 3]> = conn.iter().map(|&n| mesh.coords[n]).collect();
                let mut nodes = [0; MAX_NODES];
                nodes[..nn].copy_from_slice(conn);
                for &(xi, w) in mass_rule(kind) {
                    let k = kinematics(kind, &x, xi);
                    points.push(Point {
                        w: w * k.det_j,
                        n: k.n,
                        dndx: k.dndx,
                        nodes,
                        nn,
                    });
                }
            }
        }
        Norms {
            points,
            dim: mesh.dim,
        }
    }

    /// `(x, y)` for two nodal displacement vectors (`dim` dofs per node).
    pub fn products(&self, x: &[f64], y: &[f64]) -> Products {
        self.triple(x, y)[1]
    }

    /// `(x, x)`, `(x, y)` and `(y, y)` in one pass over the points: each the same
    /// sum, in the same order, as [`Norms::products`] of the pair.
    pub fn triple(&self, x: &[f64], y: &[f64]) -> [Products; 3] {
        let dim = self.dim;
        let mut p = [Products::default(); 3];
        for q in &self.points {
            let (mut vx, mut vy) = ([0.0; 3], [0.0; 3]);
            let (mut gx, mut gy) = ([[0.0; 3]; 3], [[0.0; 3]; 3]);
            for a in 0..q.nn {
                let d = dim * q.nodes[a];
                for c in 0..dim {
                    vx[c] += q.n[a] * x[d + c];
                    vy[c] += q.n[a] * y[d + c];
                    for k in 0..dim {
                        gx[c][k] += q.dndx[a][k] * x[d + c];
                        gy[c][k] += q.dndx[a][k] * y[d + c];
                    }
                }
            }
            for (out, (a, b, ga, gb)) in p.iter_mut().zip([
                (&vx, &vx, &gx, &gx),
                (&vx, &vy, &gx, &gy),
                (&vy, &vy, &gy, &gy),
            ]) {
                let mut v = a[0] * b[0];
                for c in 1..dim {
                    v += a[c] * b[c];
                }
                let mut g = ga[0][0] * gb[0][0];
                for c in 0..dim {
                    for k in 0..dim {
                        if c + k > 0 {
                            g += ga[c][k] * gb[c][k];
                        }
                    }
                }
                out.l2 += q.w * v;
                out.h1 += q.w * (v + g);
            }
        }
        p
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{structured, Part};

    #[test]
    fn norms_of_linear_fields_are_exact() {
        // u = (x, 0) on [0,2]x[0,1]: ∫|u|² = ∫x² = 8/3 · 1, ∫|∇u|² = 2.
        let mut mesh = Mesh::default();
        let part = structured::rectangle([0.0, 0.0], [2.0, 1.0], 4, 3, ElementKind::Quad4);
        mesh.add_part(&part, 0, "b", 0, 1.0);
        let u: Vec<f64> = mesh.coords.iter().flat_map(|c| [c[0], 0.0]).collect();
        let p = Norms::new(&mesh).products(&u, &u);
        // Bilinear interpolation of x² is not exact, but of the product x·x at 2x2
        // Gauss points of a linear field it is.
        assert!((p.l2 - 8.0 / 3.0).abs() < 1e-12, "{}", p.l2);
        assert!((p.h1 - p.l2 - 2.0).abs() < 1e-12, "{}", p.h1);
        let v: Vec<f64> = mesh.coords.iter().flat_map(|c| [0.0, c[1]]).collect();
        let q = Norms::new(&mesh).products(&u, &v);
        assert!(q.l2.abs() < 1e-14 && q.h1.abs() < 1e-14);
    }

    #[test]
    fn norms_of_linear_fields_on_triangles_are_exact() {
        // One T3 of area A = 1/2 with the nodal values (1, −1, 0) in x: the field
        // u = 1 − 2x − y vanishes at the centroid, yet ∫u² = A/6 (the mass matrix
        // A/12 (1 + δ_ab) applied to (1, −1, 0)) and ∫|∇u|² = A |(−2, −1)|² = 5A.
        let part = Part {
            dim: 2,
            coords: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            blocks: vec![crate::mesh::Elements::new(ElementKind::Tri3, vec![0, 1, 2])],
            ..Default::default()
        };
        let mut mesh = Mesh::default();
        mesh.add_part(&part, 0, "b", 0, 1.0);
        let u = [1.0, 0.0, -1.0, 0.0, 0.0, 0.0];
        let p = Norms::new(&mesh).products(&u, &u);
        let a = 0.5;
        assert!((p.l2 - a / 6.0).abs() < 1e-15, "{}", p.l2);
        assert!((p.h1 - p.l2 - a * 5.0).abs() < 1e-14, "{}", p.h1);
        // The linear fields of the Q4 test on triangles: ∫x² = 8/3 on [0,2]x[0,1].
        let mut mesh = Mesh::default();
        let part = structured::rectangle([0.0, 0.0], [2.0, 1.0], 4, 3, ElementKind::Tri3);
        mesh.add_part(&part, 0, "b", 0, 1.0);
        let u: Vec<f64> = mesh.coords.iter().flat_map(|c| [c[0], 0.0]).collect();
        let p = Norms::new(&mesh).products(&u, &u);
        assert!((p.l2 - 8.0 / 3.0).abs() < 1e-12, "{}", p.l2);
        assert!((p.h1 - p.l2 - 2.0).abs() < 1e-12, "{}", p.h1);
    }
}
