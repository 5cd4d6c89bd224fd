//! Solids: hexahedra and tetrahedra against closed forms and the plane model.
//! Each test opens with its reference, what it checks, mesh, loading and parameters.
#![allow(clippy::needless_range_loop)]

use crate::common;

use common::{load_from, model_of};
use rothe::assembly::loads::add_face_traction;
use rothe::fe::{Idealisation, StrainSpace};
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
        let mut model = model_of(&part, Idealisation::Solid, 210e9, 0.3, 7850.0, 1.0);
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
        let c = rothe::fe::Solid::elasticity(210e9, 0.3);
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
    let mut model = model_of(&part, Idealisation::Solid, 210e9, 0.0, 7850.0, 1.0);
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
    let mut pm = model_of(&plane, Idealisation::PlaneStress, 30e9, 0.2, 2400.0, t);
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
    let mut sm = model_of(&part, Idealisation::Solid, 30e9, 0.2, 2400.0, 1.0);
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

fn material(text: &str) -> rothe::material::Material {
    let spec: rothe::config::MaterialSpec =
        toml::from_str(&format!("{text}\nE = 33e9\nnu = 0.2\nrho = 2400.0")).unwrap();
    rothe::config::material("m", "material", &spec).unwrap()
}

const MAZARS: &str = "eps_t0 = 1.0e-4\nA_t = 1.0\nB_t = 1.0e4\nA_c = 1.2\nB_c = 1.5e3";

/// Drives a solid point and a plane-stress point through the uniaxial-stress strain
/// paths `ε_xx(t)` (lateral strains `−ν ε_xx`) and returns, per step, the solid's and
/// the plane's `(σ_xx, history)`.
/// Per step: the solid's stress, the plane's stress, the solid's and the plane's
/// history.
type Both = ([f64; 6], [f64; 3], Vec<f64>, Vec<f64>);

fn uniaxial_both(m: &rothe::material::Material, path: &[f64]) -> Vec<Both> {
    use rothe::material::StrainStep;
    let nu = m.nu;
    let ns = m.n_state(3);
    let (mut h3, mut h6) = (vec![0.0; ns], vec![0.0; ns]);
    let (mut e3n, mut e6n) = ([0.0; 3], [0.0; 6]);
    let mut out = Vec::new();
    for &e in path {
        let e3 = [e, -nu * e, 0.0];
        let e6 = [e, -nu * e, 0.0, -nu * e, 0.0, 0.0];
        let (mut n3, mut n6) = (vec![0.0; ns], vec![0.0; ns]);
        let r3 = m.update::<3, rothe::fe::PlaneStress>(
            &StrainStep {
                eps_n: e3n,
                eps: e3,
                dt: 1e-3,
                length: 0.1,
                tangent: true,
            },
            &h3,
            &mut n3,
        );
        let r6 = m.update::<6, rothe::fe::Solid>(
            &StrainStep {
                eps_n: e6n,
                eps: e6,
                dt: 1e-3,
                length: 0.1,
                tangent: true,
            },
            &h6,
            &mut n6,
        );
        out.push((r6.sigma, r3.sigma, n6.clone(), n3.clone()));
        (h3, h6, e3n, e6n) = (n3, n6, e3, e6);
    }
    out
}

#[test]
fn mazars_in_a_solid_gives_the_uniaxial_curves_of_plane_stress() {
    // Reference: in uniaxial stress the principal strains are (ε, −νε, −νε) whether
    // the third is the plane-stress out-of-plane strain or a solid's own, so both
    // variants of the solid Mazars point must follow the plane-stress curves: σ_xx
    // and the damage along tension to 1e-3 (softening) and compression to -8e-3,
    // with the solid's lateral stresses zero (uniaxial stress holds).
    for variant in ["paper", "classic"] {
        let m = material(&format!(
            "model = \"mazars\"\nvariant = \"{variant}\"\n{MAZARS}"
        ));
        for end in [1e-3, -8e-3] {
            let path: Vec<f64> = (1..=400).map(|k| end * k as f64 / 400.0).collect();
            let mut damaged = false;
            for (s6, s3, h6, h3) in uniaxial_both(&m, &path) {
                assert!(
                    (s6[0] - s3[0]).abs() <= 1e-9 * 33e9 * 1e-4,
                    "{variant} σ_xx {} vs {}",
                    s6[0],
                    s3[0]
                );
                assert!((h6[2] - h3[2]).abs() < 1e-12, "{variant} damage");
                for i in [1, 2, 3, 4, 5] {
                    assert!(
                        s6[i].abs() <= 1e-6 * s6[0].abs().max(1.0),
                        "σ[{i}] = {}",
                        s6[i]
                    );
                }
                damaged |= h6[2] > 0.5;
            }
            assert!(
                damaged,
                "{variant} to {end}: the path reaches the softening branch"
            );
        }
    }
}

#[test]
fn solid_linear_models_are_isotropic_and_their_tangents_are_exact() {
    // Reference: an isotropic model answers a shear γ_yz (or γ_zx) as it answers the
    // same γ_xy, and a plane-strain path in a solid as the plane-strain point does;
    // a hydrostatic strain e (1, 1, 1) gives σ = 3 K e on the normals for the
    // elastic model. Central differences of the stress (h = 1e-7 of the strain)
    // reproduce each model's tangent to 1e-6 (linear models: exactly up to round-off).
    use rothe::material::StrainStep;
    for text in [
        "model = \"elastic\"".to_string(),
        "model = \"kelvin_voigt\"\nalpha = 1.0e-3".to_string(),
        "model = \"kelvin_voigt\"\nbeta = 2.0e6".to_string(),
        "model = \"sls\"\nalpha = 0.5\nbeta = 1.0e-3".to_string(),
        "model = \"maxwell\"\nbeta = 1.0e-3".to_string(),
        format!("model = \"mazars\"\n{MAZARS}"),
    ] {
        let m = material(&text);
        let ns = m.n_state(6);
        let hist = vec![1e-5; ns];
        let step6 = |eps: [f64; 6]| StrainStep {
            eps_n: [0.0; 6],
            eps,
            dt: 1e-3,
            length: 0.1,
            tangent: true,
        };
        let update_from = |eps: [f64; 6], h: &[f64]| {
            let mut out = vec![0.0; ns];
            m.update::<6, rothe::fe::Solid>(&step6(eps), h, &mut out)
        };
        let zero = vec![0.0; ns];
        let update6 = |eps: [f64; 6]| update_from(eps, &zero);
        let g = 3e-5;
        let xy = update6([0.0, 0.0, g, 0.0, 0.0, 0.0]).sigma[2];
        let yz = update6([0.0, 0.0, 0.0, 0.0, g, 0.0]).sigma[4];
        let zx = update6([0.0, 0.0, 0.0, 0.0, 0.0, g]).sigma[5];
        assert!(
            (xy - yz).abs() <= 1e-12 * xy.abs() && (xy - zx).abs() <= 1e-12 * xy.abs(),
            "{text}: shears {xy} {yz} {zx}"
        );
        // The plane-strain path.
        let e3 = [2e-5, -1e-5, 3e-5];
        let mut o3 = vec![0.0; m.n_state(3)];
        let r3 = m.update::<3, rothe::fe::PlaneStrain>(
            &StrainStep {
                eps_n: [0.0; 3],
                eps: e3,
                dt: 1e-3,
                length: 0.1,
                tangent: true,
            },
            &vec![0.0; m.n_state(3)],
            &mut o3,
        );
        let r6 = update6([e3[0], e3[1], e3[2], 0.0, 0.0, 0.0]);
        for i in 0..3 {
            assert!(
                (r6.sigma[i] - r3.sigma[i]).abs() <= 1e-9 * r3.sigma[i].abs().max(1.0),
                "{text}: component {i}"
            );
        }
        // Finite-difference tangent at a general strain, from a history.
        let update6 = |eps: [f64; 6]| update_from(eps, &hist);
        let e = [2e-5, -1e-5, 3e-5, 1.5e-5, -2e-5, 1e-5];
        let base = update6(e);
        let h = 1e-7 * 3e-5;
        for j in 0..6 {
            let (mut ep, mut em) = (e, e);
            ep[j] += h;
            em[j] -= h;
            let (sp, sm) = (update6(ep).sigma, update6(em).sigma);
            for i in 0..6 {
                let fd = (sp[i] - sm[i]) / (2.0 * h);
                let scale = base.tangent[i][i].abs();
                let secant = text.contains("mazars");
                if !secant {
                    assert!(
                        (fd - base.tangent[i][j]).abs() <= 1e-6 * scale,
                        "{text}: tangent ({i}, {j}) {} vs {fd}",
                        base.tangent[i][j]
                    );
                }
            }
        }
    }
    // Hydrostatic: σ = 3K e.
    let m = material("model = \"elastic\"");
    let e = 1e-4;
    let r = m.update::<6, rothe::fe::Solid>(
        &StrainStep {
            eps_n: [0.0; 6],
            eps: [e, e, 0.0, e, 0.0, 0.0],
            dt: 1.0,
            length: 1.0,
            tangent: true,
        },
        &[],
        &mut [],
    );
    let k = 33e9 / (3.0 * (1.0 - 2.0 * 0.2));
    for i in [0, 1, 3] {
        assert!((r.sigma[i] - 3.0 * k * e).abs() < 1e-6 * 3.0 * k * e);
    }
}

/// `L2` and `H1`-seminorm errors of the statics solution against the manufactured
/// field `u = a sin(πx) sin(πy) sin(πz)` on the unit cube (zero on the boundary),
/// `n` cells each way, with its body force.
fn mms_errors(kind: ElementKind, n: usize) -> (f64, f64) {
    use rothe::assembly::loads::{accurate_rule, add_body_force};
    use std::f64::consts::PI;
    let (e, nu) = (1.0e3, 0.25);
    let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let mu = e / (2.0 * (1.0 + nu));
    let a = [1.0, 0.5, -0.7];
    let s = |x: f64| (PI * x).sin();
    let c = |x: f64| (PI * x).cos();
    let phi = |x: [f64; 3]| s(x[0]) * s(x[1]) * s(x[2]);
    let grad_phi = |x: [f64; 3]| {
        [
            PI * c(x[0]) * s(x[1]) * s(x[2]),
            PI * s(x[0]) * c(x[1]) * s(x[2]),
            PI * s(x[0]) * s(x[1]) * c(x[2]),
        ]
    };
    // Second derivatives of φ.
    let hess = |x: [f64; 3]| -> [[f64; 3]; 3] {
        let f = [[s(x[0]), c(x[0])], [s(x[1]), c(x[1])], [s(x[2]), c(x[2])]];
        std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                if i == j {
                    -PI * PI * phi(x)
                } else {
                    let k = 3 - i - j;
                    PI * PI * f[i][1] * f[j][1] * f[k][0]
                }
            })
        })
    };
    // b = −(μ Δu + (λ + μ) ∇(∇·u)), Δu = −3π² u.
    let body = |x: [f64; 3]| -> [f64; 3] {
        let h = hess(x);
        std::array::from_fn(|i| {
            3.0 * PI * PI * mu * a[i] * phi(x)
                - (lambda + mu) * (0..3).map(|j| a[j] * h[i][j]).sum::<f64>()
        })
    };
    let part = solid::uniform([0.0; 3], [1.0; 3], [n, n, n], kind);
    let mut model = model_of(&part, Idealisation::Solid, e, nu, 1.0, 1.0);
    let boundary: Vec<usize> = ["left", "right", "bottom", "top", "back", "front"]
        .iter()
        .flat_map(|s| model.mesh.node_sets[&format!("b.{s}")].clone())
        .collect();
    for comp in 0..3 {
        hold(&mut model, &boundary, comp, |_| 0.0);
    }
    let mut f = vec![0.0; model.mesh.n_dofs()];
    add_body_force(&model.mesh, body, &mut f);
    model.loads.push(load_from(&f, TimeFunction::Constant));
    let u = &statics::solve(&model, Backend::Faer, &[1.0]).unwrap()[0].u;
    let (mut l2, mut h1) = (0.0, 0.0);
    let block = &model.mesh.blocks[0];
    for el in 0..block.elements.len() {
        let nodes = block.elements.element(el);
        let x: Vec<[f64; 3]> = nodes.iter().map(|&k| model.mesh.coords[k]).collect();
        for &(xi, w) in accurate_rule(kind) {
            let k = rothe::fe::kinematics(kind, &x, xi);
            let (mut p, mut uh, mut gh) = ([0.0; 3], [0.0; 3], [[0.0; 3]; 3]);
            for (q, &nd) in nodes.iter().enumerate() {
                for i in 0..3 {
                    p[i] += k.n[q] * x[q][i];
                    uh[i] += k.n[q] * u[3 * nd + i];
                    for j in 0..3 {
                        gh[i][j] += k.dndx[q][j] * u[3 * nd + i];
                    }
                }
            }
            let (ph, gp) = (phi(p), grad_phi(p));
            let jw = w * k.det_j;
            for i in 0..3 {
                l2 += jw * (uh[i] - a[i] * ph).powi(2);
                for j in 0..3 {
                    h1 += jw * (gh[i][j] - a[i] * gp[j]).powi(2);
                }
            }
        }
    }
    (l2.sqrt(), h1.sqrt())
}

#[test]
fn manufactured_solutions_converge_at_orders_two_and_one_on_both_solid_kinds() {
    // Reference: a manufactured displacement u = a sin(πx) sin(πy) sin(πz) on the
    // unit cube, its body force from Navier's equations (E = 1000, ν = 0.25), zero
    // on the boundary. Trilinear and linear elements converge at order 2 in L2 and
    // 1 in H1 (asserted above 1.8 and 0.9 over the last halving of 4, 8, 16 cells).
    for kind in [ElementKind::Hex8, ElementKind::Tet4] {
        let errs: Vec<(f64, f64)> = [4, 8, 16].iter().map(|&n| mms_errors(kind, n)).collect();
        let order = |a: f64, b: f64| (a / b).log2();
        let (l2, h1) = (order(errs[1].0, errs[2].0), order(errs[1].1, errs[2].1));
        eprintln!("{kind:?}: errors {errs:?}, orders L2 {l2:.3} H1 {h1:.3}");
        assert!(l2 > 1.8, "{kind:?}: L2 order {l2}");
        assert!(h1 > 0.9, "{kind:?}: H1 order {h1}");
    }
}

/// The mean displacement of the loaded end of a solid bar (`L = 1`, 0.05 x 0.05,
/// `cells` hexahedra along it, ν = 0) clamped at x = 0 under a step compression `p`
/// on its other end, after `steps` backward-Euler steps of `dt`.
fn bar_end(cells: usize, dt: f64, steps: usize, p: f64) -> (f64, rothe::time::State) {
    use rothe::time::backward_euler::BackwardEuler;
    use rothe::time::Integrator;
    let part = solid::uniform(
        [0.0; 3],
        [1.0, 0.05, 0.05],
        [cells, 1, 1],
        ElementKind::Hex8,
    );
    let mut model = model_of(&part, Idealisation::Solid, 200e9, 0.0, 8000.0, 1.0);
    let left = model.mesh.node_sets["b.left"].clone();
    for c in 0..3 {
        hold(&mut model, &left, c, |_| 0.0);
    }
    let mut f = vec![0.0; model.mesh.n_dofs()];
    add_face_traction(
        &model.mesh,
        &model.mesh.face_sets["b.right"],
        [-p, 0.0, 0.0],
        &mut f,
    );
    model.loads.push(load_from(&f, TimeFunction::Constant));
    model.analysis.time.kind = rothe::model::AnalysisKind::Dynamic;
    model.analysis.time.dt = dt;
    model.analysis.time.t_end = dt * steps as f64;
    let mut be = BackwardEuler::new(&model, Backend::Faer).unwrap();
    let mut s = be.initial_state();
    for _ in 0..steps {
        be.step_accepted(&mut s).unwrap();
    }
    let right = &model.mesh.node_sets["b.right"];
    let u = right.iter().map(|&n| s.u[3 * n]).sum::<f64>() / right.len() as f64;
    (u, s)
}

#[test]
fn a_wave_in_a_solid_bar_moves_its_end_as_one_dimensional_theory_says() {
    // Reference: a step stress −p on the end of a bar (ν = 0, so one-dimensional)
    // sends a wave at c = √(E/ρ) = 5000 m/s; until it returns from the clamped end
    // (t < 2L/c = 0.4 ms) the loaded end moves at v = p/(ρc): u(t) = −p t/(ρ c).
    // At t = 0.7 L/c and L/c, 400 hexahedra, Courant numbers 1 and 1/2: backward
    // Euler smears the front but the end's mean motion must agree within 1 %.
    let (p, c, rho) = (1e6, 5000.0, 8000.0);
    for frac in [0.7f64, 1.0] {
        let t = frac / c;
        let want = -p * t / (rho * c);
        for k in [1, 2] {
            let steps = (400.0 * frac).round() as usize * k;
            let (u, _) = bar_end(400, t / steps as f64, steps, p);
            let error = (u - want).abs() / want.abs();
            eprintln!("t = {frac} L/c, {steps} steps: end displacement error {error:e}");
            assert!(error < 1e-2, "t = {frac} L/c, {steps} steps: {u} vs {want}");
        }
    }
}

#[test]
fn a_gmsh_solid_is_read_oriented_and_carries_uniaxial_stress_exactly() {
    // Reference: tests/data/bar_hex.msh, two unit hexahedra along x, one numbered
    // left-handed and the left face listed inwards. The reader must give both
    // positive volumes and outward face sets; pulled by 1 MPa on its right face and
    // held on its left, the bar is in uniaxial stress: σ_xx = 1 MPa in both cells,
    // every other component zero, u_x(x = 2) = 2 σ/E.
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let part = rothe::mesh::gmsh::read(&dir.join("bar_hex.msh")).unwrap();
    assert_eq!(part.dim, 3);
    part.check().unwrap();
    for (name, sign) in [("left", -1.0), ("right", 1.0)] {
        for f in &part.face_sets[name] {
            let x = |s: usize| part.coords[f[s]];
            let n = rothe::geometry::cross(
                rothe::geometry::sub(x(1), x(0)),
                rothe::geometry::sub(x(2), x(0)),
            );
            assert!(sign * n[0] > 0.0, "{name}: the face points inwards");
        }
    }
    let model = rothe::config::load(&dir.join("bar_hex.toml")).unwrap();
    let sol = &statics::solve(&model, Backend::Faer, &[1.0]).unwrap()[0];
    for s in rothe::output::post::cell_stress(&model, &sol.u, &[]) {
        assert!((s[0] - 1e6).abs() < 1e-6, "σ_xx {}", s[0]);
        for i in 1..6 {
            assert!(s[i].abs() < 1e-6, "σ[{i}] {}", s[i]);
        }
    }
    let right = &model.mesh.node_sets["bar.right"];
    for &n in right {
        assert!((sol.u[3 * n] - 2.0 * 1e6 / 210e9).abs() < 1e-15);
    }
}

#[test]
fn the_ledger_closes_for_every_solid_material() {
    // Reference: the discrete energy identity of backward Euler (theory/energy.md)
    // holds for every model whatever the dimension: on the solid cantilever of
    // examples/solid (16 x 4 x 4 hexahedra, 40 steps of 1e-5 s under a step traction
    // that cracks the clamped end of the Mazars beam and yields the root of the
    // Rankine-Hill one) the balance closes to 1e-12 of the work for the linear
    // models and to the iteration tolerance (1e-9) for Mazars and Rankine-Hill,
    // every dissipation line is non-negative, and the viscous, damage and plastic
    // models dissipate.
    use rothe::time::backward_euler::BackwardEuler;
    use rothe::time::Integrator;
    let base = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/solid/cantilever.toml"),
    )
    .unwrap();
    for (model_lines, tol, viscous) in [
        ("model = \"elastic\"", 1e-12, false),
        ("model = \"kelvin_voigt\"\nalpha = 1.0e-4", 1e-12, true),
        ("model = \"kelvin_voigt\"\nbeta = 1.0e6", 1e-12, true),
        ("model = \"sls\"\nalpha = 0.5\nbeta = 1.0e-4", 1e-12, true),
        ("model = \"maxwell\"\nbeta = 1.0e-3", 1e-12, true),
        (
            "model = \"mazars\"\nvariant = \"classic\"\nidentify = { class = \"C30/37\" }",
            1e-9,
            false,
        ),
        (
            "model = \"rankine_hill\"\ntension = { law = \"bilinear\", strength = 10e6, post_yield_modulus = 20e9 }\ncompression = { law = \"bilinear\", strength = 40e6, post_yield_modulus = 20e9 }",
            1e-9,
            false,
        ),
    ] {
        let text = base
            .replace("model = \"elastic\"", model_lines)
            .replace("t_end = 1.0e-2", "t_end = 4.0e-4")
            .replace("value = [0.0, -1.0e6, 0.0]", "value = [0.0, -3.0e6, 0.0]");
        let model = rothe::config::from_str(&text, std::path::Path::new(".")).unwrap();
        let mut be = BackwardEuler::new(&model, Backend::Faer).unwrap();
        let mut s = be.initial_state();
        for _ in 0..model.analysis.n_steps() {
            be.step_accepted(&mut s).unwrap();
        }
        let rel = s.ledger.relative_residual();
        assert!(rel.abs() < tol, "{model_lines}: balance {rel:e}");
        let d = *s.ledger.dissipated();
        for (line, v) in [
            ("viscous", d.viscous),
            ("damage", d.damage),
            ("plastic", d.plastic),
            ("numerical", d.numerical),
        ] {
            assert!(
                v >= -1e-9 * d.numerical.abs().max(1.0),
                "{model_lines}: {line} {v}"
            );
        }
        if viscous {
            assert!(d.viscous > 0.0, "{model_lines}: no viscous dissipation");
        }
        if model_lines.contains("mazars") {
            assert!(d.damage > 0.0, "the Mazars beam cracks");
        }
        if model_lines.contains("rankine") {
            assert!(d.plastic > 0.0, "the Rankine-Hill beam yields at its root");
        }
    }
}

#[test]
fn gravity_and_velocity_act_in_all_three_directions_of_a_free_solid() {
    // Reference: a free box (no supports) thrown with v0 = (0.5, 0, 2) m/s under
    // gravity g = (0, −9.81, 0) moves rigidly; backward Euler integrates the constant
    // acceleration exactly in its discrete form, v_n = v0 + n h g and
    // u_n = n h v0 + h² g n(n+1)/2, at every node (no strain, so K plays no part
    // but its round-off: E = 210 GPa against ρ/h², to 1e-9 of the 2 cm travelled).
    // The probe's z column in history.csv follows the same law.
    let text = r#"
[analysis]
t_end = 1.0e-2
dt = 1.0e-3
gravity = [0.0, -9.81, 0.0]
vtk_every = 0
[materials.steel]
model = "elastic"
E = 210e9
nu = 0.3
rho = 7850.0
[[bodies]]
name = "box"
material = "steel"
velocity = [0.5, 0.0, 2.0]
mesh = { kind = "box", size = [0.3, 0.2, 0.1], divisions = [3, 2, 2], element = "tet4" }
[[probes]]
name = "corner"
at = [0.3, 0.2, 0.1]
"#;
    use rothe::time::backward_euler::BackwardEuler;
    use rothe::time::Integrator;
    let model = rothe::config::from_str(text, std::path::Path::new(".")).unwrap();
    let mut be = BackwardEuler::new(&model, Backend::Faer).unwrap();
    let mut s = be.initial_state();
    let (h, n) = (1e-3, 10.0);
    for _ in 0..10 {
        be.step_accepted(&mut s).unwrap();
    }
    let want = [
        n * h * 0.5,
        h * h * -9.81 * n * (n + 1.0) / 2.0,
        n * h * 2.0,
    ];
    for node in 0..model.mesh.n_nodes() {
        for i in 0..3 {
            let got = s.u[3 * node + i];
            assert!(
                (got - want[i]).abs() < 1e-9 * 0.02,
                "node {node} component {i}: {got} vs {}",
                want[i]
            );
        }
    }
    // The same through the command line: the probe's uz column.
    let dir = tempfile::tempdir().unwrap();
    let sc = dir.path().join("throw.toml");
    std::fs::write(&sc, text).unwrap();
    let out = dir.path().join("out");
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_rothe"))
        .args([
            "run",
            sc.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--quiet",
        ])
        .status()
        .unwrap();
    assert!(status.success());
    let history = std::fs::read_to_string(out.join("history.csv")).unwrap();
    let header: Vec<&str> = history.lines().next().unwrap().split(',').collect();
    let col = header
        .iter()
        .position(|c| *c == "corner_uz")
        .expect("a uz column");
    let last: Vec<&str> = history.lines().last().unwrap().split(',').collect();
    let uz: f64 = last[col].parse().unwrap();
    assert!((uz - want[2]).abs() < 1e-9 * 0.02, "{uz}");
}

#[test]
fn a_bar_along_a_space_diagonal_carries_its_axial_stiffness() {
    // Reference: a steel bar (E = 210 GPa, A = 1e-4 m²) along the space diagonal of
    // a 1 m cube of a nearly void solid (E = 1 Pa), clamped on its left face, pulled
    // at the far corner by F = 10 kN along the diagonal: the corner moves
    // F L / (E A) along the bar (L = √3 m; the solid adds 1e-7 of the bar's
    // stiffness); across it the chain of bars is a mechanism that only the void
    // holds, so that motion is not the bar's. The bar's nodes are the cube's
    // diagonal nodes (one bar element per cell).
    let text = r#"
[analysis]
kind = "static"
t_end = 1.0
dt = 0.25
vtk_every = 0

[materials.void]
model = "elastic"
E = 1.0
nu = 0.0
rho = 1.0e-6

[materials.steel]
model = "elastic"
E = 210e9
nu = 0.3
rho = 7850.0

[[bodies]]
name = "cube"
material = "void"
mesh = { kind = "box", size = [1.0, 1.0, 1.0], divisions = [4, 4, 4] }

[[bars]]
name = "tie"
body = "cube"
material = "steel"
area = 1.0e-4
from = [0.0, 0.0, 0.0]
to = [1.0, 1.0, 1.0]

[[supports]]
set = "cube.left"
fix = ["x", "y", "z"]

[[loads]]
kind = "nodal"
set = "cube.top_right_front"
value = [5773.502691896258, 5773.502691896258, 5773.502691896258]
function = { kind = "ramp", t0 = 0.0, t1 = 1.0 }
"#;
    let model = rothe::config::from_str(text, std::path::Path::new(".")).unwrap();
    assert_eq!(
        model.mesh.blocks[1].elements.len(),
        4,
        "one bar element per cell"
    );
    let tip = model.mesh.node_sets["cube.top_right_front"][0];
    let u = &statics::solve(&model, Backend::Faer, &[1.0]).unwrap()[0].u;
    let want = 1e4 * 3f64.sqrt() / (210e9 * 1e-4);
    let along = (u[3 * tip] + u[3 * tip + 1] + u[3 * tip + 2]) / 3f64.sqrt();
    assert!((along - want).abs() < 1e-6 * want, "{along} vs {want}");
    // Each bar element carries F: its axial strain F/(EA) from the nodes' motion.
    let bars = &model.mesh.blocks[1].elements;
    for e in 0..bars.len() {
        let n = bars.element(e);
        let x = [model.mesh.coords[n[0]], model.mesh.coords[n[1]]];
        let ue: Vec<f64> = n
            .iter()
            .flat_map(|&k| (0..3).map(move |i| u[3 * k + i]))
            .collect();
        let eps = rothe::fe::element::bar_strain(&x, 3, &ue);
        let want = 1e4 / (210e9 * 1e-4);
        assert!((eps - want).abs() < 1e-6 * want, "bar {e}: {eps} vs {want}");
    }
}
