//! Solids: hexahedra and tetrahedra against closed forms and the plane model.
//! Each test opens with its reference, what it checks, mesh, loading and parameters.
#![allow(clippy::needless_range_loop)]

mod common;

use common::{load_from, model_of};
use rothe::assembly::loads::add_face_traction;
use rothe::fe::{elasticity_solid, Plane};
use rothe::linsolve::Backend;
use rothe::mesh::{solid, structured, ElementKind, Part};
use rothe::model::{Constraint, Model, TimeFunction};
use rothe::time::statics;

/// Holds component `comp` of `nodes` at `value(x)` in a solid.
fn hold(model: &mut Model, nodes: &[usize], comp: usize, value: impl Fn([f64; 3]) -> f64) {
    for &n in nodes {
        model.constraints.push(Constraint {
            dof: 3 * n + comp,
            value: value(model.mesh.coords[n]),
            function: TimeFunction::Constant,
        });
    }
    model.constraints.sort_by_key(|c| c.dof);
    model.constraints.dedup_by_key(|c| c.dof);
}

/// A 3x3x3-cell box on [0,2]³ with every interior node moved off the grid.
fn distorted_box(kind: ElementKind) -> Part {
    let mut p = solid::uniform([0.0; 3], [2.0; 3], [3, 3, 3], kind);
    let interior: Vec<usize> = (0..p.coords.len())
        .filter(|&n| p.coords[n].iter().all(|&c| c > 1e-9 && c < 2.0 - 1e-9))
        .collect();
    assert_eq!(interior.len(), 8);
    for (k, &n) in interior.iter().enumerate() {
        let s = [0.13, -0.09, 0.07, -0.11, 0.05, 0.12, -0.06, 0.1];
        for i in 0..3 {
            p.coords[n][i] += s[(k + i) % 8];
        }
    }
    p.check().expect("the distorted box stays valid");
    p
}

#[test]
fn patch_tests_reproduce_a_linear_field_on_distorted_hexahedra_and_tetrahedra() {
    // Reference: a complete, consistent element reproduces any linear displacement
    // u = a + B x exactly. Boundary nodes take it; the interior nodes (moved off the
    // grid) are free and must land on it; the stress is C ε at every element.
    // E = 210 GPa, ν = 0.3.
    let a = [1e-4, -2e-4, 3e-4];
    let b = [
        [2e-4, 1e-4, -3e-5],
        [-5e-5, 1.5e-4, 4e-5],
        [7e-5, -2e-5, -1e-4],
    ];
    let exact = |x: [f64; 3]| -> [f64; 3] {
        std::array::from_fn(|i| a[i] + (0..3).map(|j| b[i][j] * x[j]).sum::<f64>())
    };
    for kind in [ElementKind::Hex8, ElementKind::Tet4] {
        let part = distorted_box(kind);
        let mut model = model_of(&part, Plane::Solid, 210e9, 0.3, 7850.0, 1.0);
        let boundary: Vec<usize> = ["left", "right", "bottom", "top", "back", "front"]
            .iter()
            .flat_map(|s| model.mesh.node_sets[&format!("b.{s}")].clone())
            .collect();
        for c in 0..3 {
            hold(&mut model, &boundary, c, |x| exact(x)[c]);
        }
        let sol = &statics::solve(&model, Backend::Faer, &[1.0]).unwrap()[0];
        for (n, &x) in model.mesh.coords.iter().enumerate() {
            let e = exact(x);
            for i in 0..3 {
                assert!(
                    (sol.u[3 * n + i] - e[i]).abs() < 1e-15,
                    "{kind:?} node {n} component {i}: {} vs {}",
                    sol.u[3 * n + i],
                    e[i]
                );
            }
        }
        let eps = [
            b[0][0],
            b[1][1],
            b[0][1] + b[1][0],
            b[2][2],
            b[1][2] + b[2][1],
            b[2][0] + b[0][2],
        ];
        let c = elasticity_solid(210e9, 0.3);
        for s in rothe::output::post::cell_stress(&model, &sol.u, &[]) {
            for i in 0..6 {
                let want: f64 = (0..6).map(|j| c[i][j] * eps[j]).sum();
                assert!(
                    (s[i] - want).abs() < 1e-9 * 1e8,
                    "{kind:?} stress {i}: {} vs {want}",
                    s[i]
                );
            }
        }
    }
}

/// The static tip deflection (mean over the free end's nodes) of a cantilever box
/// `l x h x t`, clamped at x = 0, under a uniform downward traction `q` on its top.
fn cantilever_tip(kind: ElementKind, l: f64, h: f64, t: f64, div: [usize; 3], q: f64) -> f64 {
    let part = solid::uniform([0.0; 3], [l, h, t], div, kind);
    let mut model = model_of(&part, Plane::Solid, 210e9, 0.0, 7850.0, 1.0);
    let left = model.mesh.node_sets["b.left"].clone();
    for c in 0..3 {
        hold(&mut model, &left, c, |_| 0.0);
    }
    let mut f = vec![0.0; model.mesh.n_dofs()];
    add_face_traction(
        &model.mesh,
        &model.mesh.face_sets["b.top"],
        [0.0, -q, 0.0],
        &mut f,
    );
    model.loads.push(load_from(&f, TimeFunction::Constant));
    let u = &statics::solve(&model, Backend::Faer, &[1.0]).unwrap()[0].u;
    let right = &model.mesh.node_sets["b.right"];
    right.iter().map(|&n| u[3 * n + 1]).sum::<f64>() / right.len() as f64
}

#[test]
fn a_solid_cantilever_converges_to_beam_theory() {
    // Reference: a cantilever under a uniform load w = q t per length deflects
    // w L⁴ / (8 E I) (bending, Euler-Bernoulli) + w L² / (2 κ G A) (shear,
    // Timoshenko, κ = 5/6); ν = 0 so that the beam's plane sections carry no
    // transverse strain. L = 2 m, h = t = 0.2 m, q = 1 MPa. Fully integrated
    // hexahedra lock in bending at coarse meshes (33 % on one element through the
    // depth); the error must fall at every refinement, at an observed order near 2
    // at the end, and end within 1 % with eight elements through the depth.
    let (l, h, t, q): (f64, f64, f64, f64) = (2.0, 0.2, 0.2, 1e6);
    let (e, g): (f64, f64) = (210e9, 105e9);
    let w = q * t;
    let i = t * h.powi(3) / 12.0;
    let theory = -(w * l.powi(4) / (8.0 * e * i) + w * l * l / (2.0 * 5.0 / 6.0 * g * h * t));
    let mut errors = Vec::new();
    for m in [1, 2, 4, 8] {
        let tip = cantilever_tip(ElementKind::Hex8, l, h, t, [10 * m, m, m], q);
        errors.push((tip - theory).abs() / theory.abs());
    }
    assert!(
        errors.windows(2).all(|e| e[1] < e[0]),
        "errors {errors:?} do not fall"
    );
    let order = (errors[2] / errors[3]).log2();
    assert!(order > 1.5, "order {order} from {errors:?}");
    assert!(errors[3] < 0.01, "finest error {:?}", errors);
}

#[test]
fn a_hexahedral_plate_one_element_thick_matches_plane_stress() {
    // Reference: the plane-stress cantilever wall (Q4, the same in-plane grid,
    // thickness t) under an in-plane traction on its top edge. A box one element
    // thick, free in z except one line that removes the rigid motion, carries the
    // same in-plane load as a traction on its top face: its mean tip deflection
    // must agree with the plane-stress one. 2 x 0.5 m, t = 0.1 m, 16 x 4 cells,
    // E = 30 GPa, ν = 0.2, q = 1 MPa.
    let (l, h, t, q) = (2.0, 0.5, 0.1, 1e6);
    let plane = structured::rectangle([0.0; 2], [l, h], 16, 4, ElementKind::Quad4);
    let mut pm = model_of(&plane, Plane::Stress, 30e9, 0.2, 2400.0, t);
    let left = pm.mesh.node_sets["b.left"].clone();
    common::prescribe(&mut pm, &left, 0, |_| 0.0);
    common::prescribe(&mut pm, &left, 1, |_| 0.0);
    let mut f = vec![0.0; pm.mesh.n_dofs()];
    rothe::assembly::loads::add_edge_traction(
        &pm.mesh,
        &pm.mesh.edge_sets["b.top"],
        [0.0, -q],
        t,
        &mut f,
    );
    pm.loads.push(load_from(&f, TimeFunction::Constant));
    let up = &statics::solve(&pm, Backend::Faer, &[1.0]).unwrap()[0].u;
    let right = &pm.mesh.node_sets["b.right"];
    let tip_plane = right.iter().map(|&n| up[2 * n + 1]).sum::<f64>() / right.len() as f64;

    let part = solid::uniform([0.0; 3], [l, h, t], [16, 4, 1], ElementKind::Hex8);
    let mut sm = model_of(&part, Plane::Solid, 30e9, 0.2, 2400.0, 1.0);
    let left = sm.mesh.node_sets["b.left"].clone();
    hold(&mut sm, &left, 0, |_| 0.0);
    hold(&mut sm, &left, 1, |_| 0.0);
    let back = sm.mesh.node_sets["b.left_back"].clone();
    hold(&mut sm, &back, 2, |_| 0.0);
    let mut f = vec![0.0; sm.mesh.n_dofs()];
    add_face_traction(
        &sm.mesh,
        &sm.mesh.face_sets["b.top"],
        [0.0, -q, 0.0],
        &mut f,
    );
    sm.loads.push(load_from(&f, TimeFunction::Constant));
    let us = &statics::solve(&sm, Backend::Faer, &[1.0]).unwrap()[0].u;
    let right = &sm.mesh.node_sets["b.right"];
    let tip_solid = right.iter().map(|&n| us[3 * n + 1]).sum::<f64>() / right.len() as f64;
    let rel = (tip_solid - tip_plane).abs() / tip_plane.abs();
    eprintln!("plane {tip_plane:e}, solid {tip_solid:e}, relative {rel:e}");
    assert!(tip_plane < 0.0 && tip_solid < 0.0);
    assert!(rel < 5e-3, "solid {tip_solid} vs plane stress {tip_plane}");
}
