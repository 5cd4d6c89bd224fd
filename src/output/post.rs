//! Post-processing fields from a displacement vector.

use crate::assembly::internal::points_per_element;
use crate::fe::{element, kinematics, stiffness_rule, strain};
use crate::material::store::StateStore;
use crate::material::StrainStep;
use crate::mesh::ElementKind;
use crate::model::Model;

/// Element-averaged stress `[σ_xx, σ_yy, σ_xy]` of every element, blocks in order
/// (bars: axial stress in the first slot): from the committed Gauss-point stresses
/// when `points` holds them, else from `u` with the elastic law.
pub fn cell_stress(model: &Model, u: &[f64], points: &[StateStore]) -> Vec<[f64; 3]> {
    let mut out = Vec::with_capacity(model.mesh.n_elements());
    if !points.is_empty() {
        for (block, store) in model.mesh.blocks.iter().zip(points) {
            let ng = points_per_element(block.elements.kind);
            for sig in store.sigma.chunks_exact(3 * ng) {
                let mut avg = [0.0; 3];
                for p in sig.chunks_exact(3) {
                    for i in 0..3 {
                        avg[i] += p[i] / ng as f64;
                    }
                }
                out.push(avg);
            }
        }
        return out;
    }
    for block in &model.mesh.blocks {
        let mat = &model.materials[block.material];
        let kind = block.elements.kind;
        let nn = kind.nodes();
        for e in 0..block.elements.len() {
            let nodes = block.elements.element(e);
            let x: Vec<[f64; 2]> = nodes.iter().map(|&n| model.mesh.coords[n]).collect();
            let ue: Vec<f64> = nodes
                .iter()
                .flat_map(|&n| [u[2 * n], u[2 * n + 1]])
                .collect();
            if kind == ElementKind::Bar2 {
                out.push([mat.e * element::bar_strain(&x, &ue), 0.0, 0.0]);
                continue;
            }
            let rule = stiffness_rule(kind);
            let mut avg = [0.0; 3];
            let mut st = [0.0; 0];
            for &(xi, _) in rule {
                let k = kinematics(kind, &x, xi);
                let eps = strain(&k, nn, &ue);
                let r = mat.update(
                    model.plane,
                    &StrainStep {
                        eps_n: eps,
                        eps,
                        dt: 1.0,
                        length: 1.0,
                    },
                    &[],
                    &mut st,
                );
                for i in 0..3 {
                    avg[i] += r.sigma[i] / rule.len() as f64;
                }
            }
            out.push(avg);
        }
    }
    out
}

/// Element averages of the point fields of materials with history: damage,
/// equivalent plastic strain `κ_t + κ_c`, and cumulative dissipation density (J/m³).
pub fn cell_history_fields(model: &Model, points: &[StateStore]) -> Vec<(&'static str, Vec<f64>)> {
    let (mut damage, mut eqp, mut diss) = (Vec::new(), Vec::new(), Vec::new());
    for (block, store) in model.mesh.blocks.iter().zip(points) {
        let mat = &model.materials[block.material];
        let ng = points_per_element(block.elements.kind);
        let ns = store.n_state;
        for e in 0..block.elements.len() {
            let (mut d, mut p, mut w) = (0.0, 0.0, 0.0);
            for g in e * ng..(e + 1) * ng {
                let (dd, pp) = mat.output_fields(&store.committed[g * ns..(g + 1) * ns]);
                d += dd / ng as f64;
                p += pp / ng as f64;
                w += store.dissipated[g] / ng as f64;
            }
            damage.push(d);
            eqp.push(p);
            diss.push(w);
        }
    }
    vec![
        ("damage", damage),
        ("equivalent_plastic_strain", eqp),
        ("dissipation_density", diss),
    ]
}
