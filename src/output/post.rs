//! Post-processing fields for output: element stresses and the element averages of
//! the point fields of materials with history.
//!
//! Stresses come from the committed Gauss-point state when the model has one; for
//! models made only of linear elastic materials there is no point state (the state is
//! `u`), and the stress is `C ε(u)` at the element's Gauss points. Averages over an
//! element's points are weighted by their quadrature weights (`w det J`), so they are
//! the element means of the fields.

use crate::assembly::internal::points_per_element;
use crate::assembly::{element_coords, element_values};
use crate::fe::{element, kinematics, stiffness_rule, ElementKind, Kinematics, MAX_NODES};
use crate::material::mul3;
use crate::material::store::StateStore;
use crate::mesh::Mesh;
use crate::model::Model;

/// Quadrature weights `w det J` of the points of element `e` of `block` (bars: one
/// point of weight 1).
fn point_weights(mesh: &Mesh, block: usize, e: usize, out: &mut [f64; MAX_NODES]) -> usize {
    let b = &mesh.blocks[block];
    let kind = b.elements.kind;
    if kind == ElementKind::Bar2 {
        out[0] = 1.0;
        return 1;
    }
    let nodes = b.elements.element(e);
    let x = element_coords(mesh, nodes);
    let rule = stiffness_rule(kind);
    for (q, &(xi, w)) in rule.iter().enumerate() {
        out[q] = w * kinematics(kind, &x[..nodes.len()], xi).det_j;
    }
    rule.len()
}

/// Weighted mean of `f(point)` over the points of element `e`.
fn element_mean<const V: usize>(
    mesh: &Mesh,
    block: usize,
    e: usize,
    ng: usize,
    mut f: impl FnMut(usize) -> [f64; V],
) -> [f64; V] {
    let mut w = [0.0; MAX_NODES];
    let n = point_weights(mesh, block, e, &mut w);
    debug_assert_eq!(n, ng);
    let total: f64 = w[..n].iter().sum();
    let mut avg = [0.0; V];
    for q in 0..n {
        let v = f(e * ng + q);
        for i in 0..V {
            avg[i] += w[q] / total * v[i];
        }
    }
    avg
}

/// Element-mean stress of every element, blocks in order, in the Voigt order of
/// `fe` (plane: `[σ_xx, σ_yy, σ_xy]` and three zeros; solid:
/// `[σ_xx, σ_yy, σ_xy, σ_zz, σ_yz, σ_zx]`; bars: axial stress in the first slot):
/// from the committed Gauss-point stresses when `points` holds them, else `C ε(u)`.
pub fn cell_stress(model: &Model, u: &[f64], points: &[StateStore]) -> Vec<[f64; 6]> {
    let mesh = &model.mesh;
    let mut out = Vec::with_capacity(mesh.n_elements());
    for (bi, block) in mesh.blocks.iter().enumerate() {
        let ng = block.elements.kind.points();
        if let Some(store) = points.get(bi) {
            let c = store.committed();
            for e in 0..block.elements.len() {
                out.push(element_mean(mesh, bi, e, ng, |g| c.sigma6(g)));
            }
            continue;
        }
        crate::dispatch_kinematics!(model.idealisation, <D, V, K> =>
            elastic_cell_stress::<D, V, K>(model, u, bi, &mut out));
    }
    out
}

/// The element-mean `C ε(u)` of block `bi`'s elements in the idealisation `K`
/// (bars: `E ε` in the first slot), padded to six components, onto `out`.
fn elastic_cell_stress<const D: usize, const V: usize, K: Kinematics<D, V>>(
    model: &Model,
    u: &[f64],
    bi: usize,
    out: &mut Vec<[f64; 6]>,
) {
    let mesh = &model.mesh;
    let block = &mesh.blocks[bi];
    let kind = block.elements.kind;
    let (ng, nn) = (kind.points(), kind.nodes());
    let mat = &model.materials[block.material];
    let pad = |s: [f64; V]| -> [f64; 6] { std::array::from_fn(|i| if i < V { s[i] } else { 0.0 }) };
    let d = mat.elasticity::<V, K>();
    for e in 0..block.elements.len() {
        let nodes = block.elements.element(e);
        let x = element_coords(mesh, nodes);
        let ue = element_values(u, nodes, D);
        if kind == ElementKind::Bar2 {
            let eps = element::bar_strain(&x[..2], D, &ue[..2 * D]);
            out.push(pad(std::array::from_fn(|i| {
                if i == 0 {
                    mat.e * eps
                } else {
                    0.0
                }
            })));
            continue;
        }
        let rule = stiffness_rule(kind);
        out.push(pad(element_mean(mesh, bi, e, ng, |g| {
            let k = kinematics(kind, &x[..nn], rule[g - e * ng].0);
            mul3(&d, &K::strain(&k, nn, &ue))
        })));
    }
}

/// Element means of the point fields of materials with history: damage, equivalent
/// plastic strain `κ_t + κ_c`, and cumulative dissipation density (J/m³). A state
/// built from nodal fields has no cumulative dissipation density (NaN at every
/// point): that field is left out.
pub fn cell_history_fields(model: &Model, points: &[StateStore]) -> Vec<(&'static str, Vec<f64>)> {
    let mesh = &model.mesh;
    let (mut damage, mut eqp, mut diss) = (Vec::new(), Vec::new(), Vec::new());
    for (bi, (block, store)) in mesh.blocks.iter().zip(points).enumerate() {
        let mat = &model.materials[block.material];
        let ng = points_per_element(block.elements.kind);
        let c = store.committed();
        for e in 0..block.elements.len() {
            let m = element_mean(mesh, bi, e, ng, |g| {
                let (d, p) = mat.output_fields(c.history(g), c.layout().voigt);
                [d, p, c.dissipated(g)]
            });
            damage.push(m[0]);
            eqp.push(m[1]);
            diss.push(m[2]);
        }
    }
    let mut fields = vec![("damage", damage), ("equivalent_plastic_strain", eqp)];
    if !diss.iter().all(|x| x.is_nan()) {
        fields.push(("dissipation_density", diss));
    }
    fields
}
