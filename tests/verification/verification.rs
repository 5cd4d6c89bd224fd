//! Verification against analytic and manufactured solutions and conservation laws.
//! Each test opens with its reference, what it checks, mesh, loading and parameters.
#![allow(clippy::needless_range_loop, clippy::too_many_arguments)]

use crate::common;

use common::{load_from, model_of, orders, prescribe};
use rothe::assembly::loads::{accurate_rule, add_body_force};
use rothe::fe::{kinematics, Idealisation, StrainSpace};
use rothe::linsolve::Backend;
use rothe::mesh::{structured, ElementKind, Part};
use rothe::model::{AnalysisKind, TimeFunction};
use rothe::time::backward_euler::BackwardEuler;
use rothe::time::statics;
use rothe::time::Integrator;

/// A 4x4-node patch on [0,2]² with its four interior nodes moved off the grid.
fn distorted_patch(kind: ElementKind) -> Part {
    let mut p = structured::rectangle([0.0, 0.0], [2.0, 2.0], 3, 3, kind);
    let shifts = [
        (5, [0.11, -0.07]),
        (6, [-0.05, 0.13]),
        (9, [0.09, 0.06]),
        (10, [-0.12, -0.04]),
    ];
    for (n, d) in shifts {
        p.coords[n][0] += d[0];
        p.coords[n][1] += d[1];
    }
    p
}

fn patch_test(kind: ElementKind) {
    // Reference: any linear displacement field is reproduced exactly by a consistent,
    // complete element (the patch test). Boundary nodes take u = a + B x; the interior
    // nodes are free; the stress must be C ε everywhere. E = 210e9, ν = 0.3, plane stress.
    let part = distorted_patch(kind);
    let mut model = model_of(&part, Idealisation::PlaneStress, 210e9, 0.3, 7850.0, 0.1);
    let exact = |x: [f64; 2]| {
        [
            1e-3 + 2e-4 * x[0] - 1e-4 * x[1],
            -5e-4 + 3e-4 * x[0] + 1.5e-4 * x[1],
        ]
    };
    let boundary: Vec<usize> = ["b.left", "b.right", "b.top", "b.bottom"]
        .iter()
        .flat_map(|s| model.mesh.node_sets[*s].clone())
        .collect();
    prescribe(&mut model, &boundary, 0, |x| exact(x)[0]);
    prescribe(&mut model, &boundary, 1, |x| exact(x)[1]);
    let sol = &statics::solve(&model, Backend::Faer, &[1.0]).unwrap()[0];
    for (n, x) in model.mesh.coords.iter().enumerate() {
        let e = exact([x[0], x[1]]);
        assert!((sol.u[2 * n] - e[0]).abs() < 1e-14, "node {n} ux");
        assert!((sol.u[2 * n + 1] - e[1]).abs() < 1e-14, "node {n} uy");
    }
    let eps = [2e-4, 1.5e-4, -1e-4 + 3e-4];
    let c = rothe::fe::PlaneStress::elasticity(210e9, 0.3);
    for s in rothe::output::post::cell_stress(&model, &sol.u, &[]) {
        for i in 0..3 {
            let want: f64 = (0..3).map(|j| c[i][j] * eps[j]).sum();
            assert!(
                (s[i] - want).abs() < 1e-9 * want.abs().max(1e3),
                "stress {i}: {} vs {want}",
                s[i]
            );
        }
    }
    // Interior equilibrium: the internal force vanishes at free nodes.
    let free_max = model
        .mesh
        .coords
        .iter()
        .enumerate()
        .filter(|(n, _)| !boundary.contains(n))
        .map(|(n, _)| sol.fint[2 * n].abs().max(sol.fint[2 * n + 1].abs()))
        .fold(0.0, f64::max);
    assert!(free_max < 1e-6, "interior residual force {free_max}");
}

#[test]
fn patch_test_q4_distorted() {
    patch_test(ElementKind::Quad4);
}

#[test]
fn patch_test_t3() {
    patch_test(ElementKind::Tri3);
}

#[test]
fn cantilever_static_vs_timoshenko() {
    // Reference: Timoshenko beam, tip deflection δ = P L³/(3EI) + P L/(κ G A), κ = 5/6.
    // Plane stress cantilever L = 5, H = 0.5, t = 0.1, E = 30e9, ν = 0.25, left edge
    // clamped, total shear P = 1e4 N as a uniform traction on the right edge. Q4 meshes
    // 40x4, 80x8, 160x16: the error falls with refinement and ends within 2 %.
    let (l, h, t, e, nu, p): (f64, f64, f64, f64, f64, f64) = (5.0, 0.5, 0.1, 30e9, 0.25, 1e4);
    let i = t * h * h * h / 12.0;
    let g = e / (2.0 * (1.0 + nu));
    let delta = p * l.powi(3) / (3.0 * e * i) + p * l / (5.0 / 6.0 * g * t * h);
    let mut errs = Vec::new();
    for n in [4usize, 8, 16] {
        let part = structured::rectangle([0.0, 0.0], [l, h], 10 * n, n, ElementKind::Quad4);
        let mut model = model_of(&part, Idealisation::PlaneStress, e, nu, 2400.0, t);
        let left = model.mesh.node_sets["b.left"].clone();
        prescribe(&mut model, &left, 0, |_| 0.0);
        prescribe(&mut model, &left, 1, |_| 0.0);
        let mut f = vec![0.0; model.mesh.n_dofs()];
        let right = model.mesh.edge_sets["b.right"].clone();
        rothe::assembly::loads::add_edge_traction(
            &model.mesh,
            &right,
            [0.0, -p / (h * t)],
            t,
            &mut f,
        );
        model.loads.push(load_from(&f, TimeFunction::Constant));
        let sol = &statics::solve(&model, Backend::Faer, &[1.0]).unwrap()[0];
        let tip = model.mesh.nearest_node([l, h / 2.0, 0.0]).unwrap();
        errs.push((-sol.u[2 * tip + 1] - delta).abs() / delta);
    }
    assert!(errs[0] > errs[1] && errs[1] > errs[2], "errors {errs:?}");
    assert!(errs[2] < 0.02, "finest error {errs:?}");
}

/// Manufactured solution on the unit square (zero on the boundary).
fn mms_u(x: [f64; 2]) -> ([f64; 2], [[f64; 2]; 2]) {
    use std::f64::consts::PI;
    let (sx, cx, sy, cy) = (
        (PI * x[0]).sin(),
        (PI * x[0]).cos(),
        (PI * x[1]).sin(),
        (PI * x[1]).cos(),
    );
    let (s2x, c2x) = ((2.0 * PI * x[0]).sin(), (2.0 * PI * x[0]).cos());
    let a = 1e-3;
    (
        [a * sx * sy, a * s2x * sy],
        [
            [a * PI * cx * sy, a * PI * sx * cy],
            [a * 2.0 * PI * c2x * sy, a * PI * s2x * cy],
        ],
    )
}

/// Body force `b = −div(C ε(u))` of the manufactured solution.
fn mms_b(x: [f64; 2], c: &[[f64; 3]; 3]) -> [f64; 2] {
    use std::f64::consts::PI;
    let a = 1e-3;
    let (sx, cx, sy, cy) = (
        (PI * x[0]).sin(),
        (PI * x[0]).cos(),
        (PI * x[1]).sin(),
        (PI * x[1]).cos(),
    );
    let (s2x, c2x) = ((2.0 * PI * x[0]).sin(), (2.0 * PI * x[0]).cos());
    let (p2, q2) = (PI * PI, 2.0 * PI * PI);
    // Second derivatives.
    let ux_xx = -a * p2 * sx * sy;
    let ux_yy = -a * p2 * sx * sy;
    let ux_xy = a * p2 * cx * cy;
    let uy_xx = -a * 4.0 * p2 * s2x * sy;
    let uy_yy = -a * p2 * s2x * sy;
    let uy_xy = a * q2 * c2x * cy;
    let (c11, c12, c33) = (c[0][0], c[0][1], c[2][2]);
    [
        -(c11 * ux_xx + c12 * uy_xy + c33 * (ux_yy + uy_xy)),
        -(c33 * (ux_xy + uy_xx) + c12 * ux_xy + c11 * uy_yy),
    ]
}

fn mms_orders(kind: ElementKind) -> (Vec<f64>, Vec<f64>) {
    // Reference: manufactured solution u = 1e-3 (sin πx sin πy, sin 2πx sin πy) on the
    // unit square, plane stress E = 1e9, ν = 0.3, body force from −div σ(u), all edges
    // fixed. Meshes 8², 16², 32²; errors in L2 and the H1 seminorm by a 3x3 / 6-point
    // rule. Linear elements: L2 order 2, H1 order 1.
    let (e, nu) = (1e9, 0.3);
    let c = rothe::fe::PlaneStress::elasticity(e, nu);
    let (mut l2s, mut h1s) = (Vec::new(), Vec::new());
    for n in [8usize, 16, 32] {
        let part = structured::rectangle([0.0, 0.0], [1.0, 1.0], n, n, kind);
        let mut model = model_of(&part, Idealisation::PlaneStress, e, nu, 1.0, 1.0);
        let boundary: Vec<usize> = ["b.left", "b.right", "b.top", "b.bottom"]
            .iter()
            .flat_map(|s| model.mesh.node_sets[*s].clone())
            .collect();
        prescribe(&mut model, &boundary, 0, |_| 0.0);
        prescribe(&mut model, &boundary, 1, |_| 0.0);
        let mut f = vec![0.0; model.mesh.n_dofs()];
        add_body_force(&model.mesh, |x| mms_b(x, &c), &mut f);
        model.loads.push(load_from(&f, TimeFunction::Constant));
        let u = &statics::solve(&model, Backend::Faer, &[1.0]).unwrap()[0].u;
        let (mut l2, mut h1) = (0.0, 0.0);
        let block = &model.mesh.blocks[0];
        for el in 0..block.elements.len() {
            let nodes = block.elements.element(el);
            let x: Vec<[f64; 3]> = nodes.iter().map(|&n| model.mesh.coords[n]).collect();
            for &(xi, w) in accurate_rule(kind) {
                let k = kinematics(kind, &x, xi);
                let (mut p, mut uh, mut gh) = ([0.0; 2], [0.0; 2], [[0.0; 2]; 2]);
                for (a, &nd) in nodes.iter().enumerate() {
                    for i in 0..2 {
                        p[i] += k.n[a] * x[a][i];
                        uh[i] += k.n[a] * u[2 * nd + i];
                        for j in 0..2 {
                            gh[i][j] += k.dndx[a][j] * u[2 * nd + i];
                        }
                    }
                }
                let (ue, ge) = mms_u(p);
                let jw = w * k.det_j;
                l2 += jw * ((uh[0] - ue[0]).powi(2) + (uh[1] - ue[1]).powi(2));
                h1 += jw
                    * (0..2)
                        .flat_map(|i| (0..2).map(move |j| (i, j)))
                        .map(|(i, j)| (gh[i][j] - ge[i][j]).powi(2))
                        .sum::<f64>();
            }
        }
        l2s.push(l2.sqrt());
        h1s.push(h1.sqrt());
    }
    (orders(&l2s), orders(&h1s))
}

#[test]
fn mms_spatial_order_q4() {
    let (l2, h1) = mms_orders(ElementKind::Quad4);
    assert!(
        l2.iter().all(|o| (o - 2.0).abs() < 0.15),
        "L2 orders {l2:?}"
    );
    assert!(h1.iter().all(|o| (o - 1.0).abs() < 0.1), "H1 orders {h1:?}");
}

#[test]
fn mms_spatial_order_t3() {
    let (l2, h1) = mms_orders(ElementKind::Tri3);
    assert!(
        l2.iter().all(|o| (o - 2.0).abs() < 0.15),
        "L2 orders {l2:?}"
    );
    assert!(h1.iter().all(|o| (o - 1.0).abs() < 0.1), "H1 orders {h1:?}");
}

/// The wave-in-a-bar model: a strip 1 x 0.1 (20x2 Q4), E = 1e4, ν = 0, ρ = 1
/// (c = 100, transit time 0.01), left edge held in x, its lower corner in y, a
/// traction `sin(2π·50 t)` on the right edge: the wave it sends runs to the fixed end
/// and back. (A step load also converges at order 1, but reaches the asymptotic regime
/// only once `ω_max h ≪ 1`, beyond the steps a test can afford.)
fn bar_model(lumped: bool, dt: f64, t_end: f64) -> rothe::model::Model {
    let part = structured::rectangle([0.0, 0.0], [1.0, 0.1], 20, 2, ElementKind::Quad4);
    let mut model = model_of(&part, Idealisation::PlaneStress, 1e4, 0.0, 1.0, 1.0);
    let left = model.mesh.node_sets["b.left"].clone();
    prescribe(&mut model, &left, 0, |_| 0.0);
    let corner = model.mesh.node_sets["b.bottom_left"].clone();
    prescribe(&mut model, &corner, 1, |_| 0.0);
    let mut f = vec![0.0; model.mesh.n_dofs()];
    let right = model.mesh.edge_sets["b.right"].clone();
    rothe::assembly::loads::add_edge_traction(&model.mesh, &right, [1.0, 0.0], 1.0, &mut f);
    model.loads.push(load_from(
        &f,
        TimeFunction::Harmonic {
            frequency: 50.0,
            phase: 0.0,
        },
    ));
    model.analysis.time.kind = AnalysisKind::Dynamic;
    model.analysis.time.lumped_mass = lumped;
    model.analysis.time.dt = dt;
    model.analysis.time.t_end = t_end;
    model
}

fn final_displacement(model: &rothe::model::Model) -> Vec<f64> {
    let mut be = BackwardEuler::new(model, Backend::Faer).unwrap();
    let mut s = be.initial_state();
    for _ in 0..model.analysis.n_steps() {
        be.step_accepted(&mut s).unwrap();
    }
    s.u
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

#[test]
fn wave_temporal_order_vs_reference() {
    // Reference: the same bar with h = T/8192 (Rothe sequence limit). Steps T/64 …
    // T/512 at T = 0.015 (one and a half transits): backward Euler is first order.
    let t_end = 0.015;
    let reference = final_displacement(&bar_model(false, t_end / 8192.0, t_end));
    let errs: Vec<f64> = [64.0, 128.0, 256.0, 512.0]
        .iter()
        .map(|m| {
            max_diff(
                &final_displacement(&bar_model(false, t_end / m, t_end)),
                &reference,
            )
        })
        .collect();
    let o = orders(&errs);
    assert!(
        o.iter().all(|o| (o - 1.0).abs() < 0.2),
        "orders {o:?} errors {errs:?}"
    );
}

#[test]
fn wave_temporal_order_vs_modal() {
    // Reference: the exact solution of the semi-discrete system M ü + K u = f sin Ωt
    // from rest, by modes (lumped M, dense eigen-decomposition of M^-½ K M^-½).
    // Backward Euler converges to it at order 1 as h → 0.
    use faer::{Mat, Side};
    let t_end = 0.015;
    let model = bar_model(true, t_end / 64.0, t_end);
    let be = BackwardEuler::new(&model, Backend::Faer).unwrap();
    let free = be.dofs().free.clone();
    let nf = free.len();
    let p = &be.assembler().pattern;
    let mdiag = match be.mass() {
        rothe::assembly::Mass::Lumped(d) => d.clone(),
        _ => unreachable!(),
    };
    let mut kd = Mat::<f64>::zeros(nf, nf);
    for n in 0..p.n_nodes {
        for j in 0..2 {
            let c = be.dofs().eq[2 * n + j];
            if c == usize::MAX {
                continue;
            }
            for (k, &m) in p.adj[p.adj_ptr[n]..p.adj_ptr[n + 1]].iter().enumerate() {
                for i in 0..2 {
                    let r = be.dofs().eq[2 * m as usize + i];
                    if r != usize::MAX {
                        let v = be.stiffness()[p.col_start(n, j) + 2 * k + i];
                        kd[(r, c)] = v / (mdiag[free[r]] * mdiag[free[c]]).sqrt();
                    }
                }
            }
        }
    }
    let eig = kd.self_adjoint_eigen(Side::Lower).unwrap();
    let (phi, lam) = (eig.U(), eig.S().column_vector());
    let f: Vec<f64> = {
        let mut f = vec![0.0; model.mesh.n_dofs()];
        for &(d, v) in &model.loads[0].entries {
            f[d] = v;
        }
        f
    };
    // Modal solution in scaled coordinates y = M^½ u: for q̈ + ω² q = p sin Ωt from
    // rest, q = p (sin Ωt − (Ω/ω) sin ωt) / (ω² − Ω²).
    let big_omega = 2.0 * std::f64::consts::PI * 50.0;
    let g: Vec<f64> = free.iter().map(|&d| f[d] / mdiag[d].sqrt()).collect();
    let mut y = vec![0.0; nf];
    for i in 0..nf {
        let w = lam[i].sqrt();
        let proj: f64 = (0..nf).map(|r| phi[(r, i)] * g[r]).sum();
        let amp = proj * ((big_omega * t_end).sin() - big_omega / w * (w * t_end).sin())
            / (w * w - big_omega * big_omega);
        for r in 0..nf {
            y[r] += phi[(r, i)] * amp;
        }
    }
    let mut exact = vec![0.0; model.mesh.n_dofs()];
    for (r, &d) in free.iter().enumerate() {
        exact[d] = y[r] / mdiag[d].sqrt();
    }
    let errs: Vec<f64> = [64.0, 128.0, 256.0, 512.0, 1024.0]
        .iter()
        .map(|m| {
            max_diff(
                &final_displacement(&bar_model(true, t_end / m, t_end)),
                &exact,
            )
        })
        .collect();
    let o = orders(&errs);
    assert!(
        o[1..].iter().all(|o| (o - 1.0).abs() < 0.2),
        "orders {o:?} errors {errs:?}"
    );
    assert!(
        errs[4] < 0.1 * max_diff(&exact, &vec![0.0; exact.len()]),
        "not converging to the modal solution"
    );
}

/// Runs a scenario text with the library, checking the ledger after every step:
/// the relative balance residual stays at round-off and every dissipation line
/// (viscous, damage, plastic, contact, mass) is non-decreasing; with
/// `constant_loads` (loads constant in time, supports fixed) the scheme's numerical
/// loss is non-decreasing too: each of its increments is then a sum of squares,
/// `½|Δv|²_M + ½ Δu·K Δu` (theory/energy.md). Returns the final state's ledger.
fn run_ledger_with(text: &str, constant_loads: bool) -> rothe::energy::Ledger {
    let model = rothe::config::from_str(text, std::path::Path::new(".")).unwrap();
    let mut be = BackwardEuler::new(&model, Backend::Faer).unwrap();
    let mut s = be.initial_state();
    let mut prev = s.ledger;
    for _ in 0..model.analysis.n_steps() {
        be.step_accepted(&mut s).unwrap();
        let l = &s.ledger;
        assert!(
            l.residual().abs() <= 1e-10 * l.scale(),
            "step {}: residual {} scale {}",
            s.step,
            l.residual(),
            l.scale()
        );
        assert!(l.dissipated().mass >= prev.dissipated().mass - 1e-12 * l.scale());
        let (d, d0) = (l.dissipated(), prev.dissipated());
        for (k, ((name, now), (_, before))) in d.lines().iter().zip(d0.lines()).enumerate() {
            let physical = k < 5;
            if physical || constant_loads {
                assert!(
                    *now >= before - 1e-12 * l.scale(),
                    "step {}: {name} fell from {before} to {now}",
                    s.step
                );
            }
        }
        prev = *l;
    }
    s.ledger
}

fn run_ledger(text: &str) -> rothe::energy::Ledger {
    run_ledger_with(text, true)
}

fn cantilever() -> String {
    crate::workload::cantilever_scenario(
        [16, 4],
        2e-5,
        2e-3,
        "model = \"elastic\"\nE = 30e9\nnu = 0.2\nrho = 2400.0",
        "vtk_every = 0",
    )
}

#[test]
fn ledger_closes_undamped() {
    // Reference: the exact discrete energy identity of backward Euler (theory/energy.md).
    // Cantilever 2 x 0.5 x 0.2, 16x4 Q4, E = 30e9, ν = 0.2, ρ = 2400, step traction
    // 1 MPa on the top edge, h = 2e-5, 100 steps. No damping: all loss is numerical,
    // and for a linear step it is a sum of squares, hence positive.
    let l = run_ledger(&cantilever());
    assert_eq!(l.dissipated().mass, 0.0);
    assert!(l.dissipated().numerical > 0.0);
    assert!(
        (l.internal() - l.elastic()).abs() < 1e-10 * l.scale(),
        "E_int {} vs E_el {}",
        l.internal(),
        l.elastic()
    );
    // Free vibration from an initial velocity: total energy only decreases.
    let free = cantilever()
        .replace("value = [0.0, -1.0e6]", "value = [0.0, 0.0]")
        .replace(
            "thickness = 0.2\n",
            "thickness = 0.2\nvelocity = [0.0, -1.0]\n",
        );
    let l = run_ledger(&free);
    assert!(l.kinetic_0() > 0.0 && l.kinetic() + l.elastic() < l.kinetic_0());
    assert!(
        (l.kinetic() + l.elastic() + l.dissipated().numerical - l.kinetic_0()).abs()
            < 1e-10 * l.scale()
    );
}

#[test]
fn ledger_closes_with_mass_and_rayleigh_damping() {
    // Same cantilever with zeta = 50 1/s and Rayleigh a_m = 10 1/s, a_k = 1e-5 s: the
    // mass-damping line takes the physical loss, and the balance still closes.
    let text = cantilever().replace(
        "vtk_every = 0",
        "vtk_every = 0\nzeta = 50.0\nrayleigh = [10.0, 1.0e-5]",
    );
    let l = run_ledger(&text);
    assert!(l.dissipated().mass > 0.0);
    let undamped = run_ledger(&cantilever());
    assert!(l.kinetic() + l.elastic() < undamped.kinetic() + undamped.elastic());
}

#[test]
fn ledger_closes_with_prescribed_motion_and_bars() {
    // Prescribed displacement history (a ramp on the right edge) does work through the
    // support reactions, which enter W_ext; plus gravity, an initial velocity, lumped
    // mass and a steel bar along the bottom sharing the concrete's nodes.
    let text = cantilever()
        .replace(
            "vtk_every = 0",
            "vtk_every = 0\nmass = \"lumped\"\ngravity = [0.0, -9.81]",
        )
        .replace(
            "thickness = 0.2\n",
            "thickness = 0.2\nvelocity = [0.5, 0.0]\n",
        )
        + r#"
[materials.steel]
model = "elastic"
E = 200e9
nu = 0.3
rho = 7850.0
[[bars]]
name = "rebar"
body = "beam"
material = "steel"
area = 7.854e-5
from = [0.0, 0.0]
to = [2.0, 0.0]
[[prescribed]]
set = "beam.right"
component = "y"
value = 1.0e-4
function = { kind = "ramp", t0 = 0.0, t1 = 1.0e-3 }
"#;
    let model = rothe::config::from_str(&text, std::path::Path::new(".")).unwrap();
    assert_eq!(model.mesh.blocks.len(), 2, "the bar block is there");
    // Prescribed motion: the load-jump term may take back numerical loss.
    let l = run_ledger_with(&text, false);
    assert!(l.external_work().abs() > 0.0);
}

#[test]
fn lumped_and_consistent_mass_conserve_momentum_free_flight() {
    // A free body (no supports, no loads) with initial velocity (3, -2) m/s translates
    // rigidly: momentum Σ M v is conserved to round-off, u = v0 t, and nothing is lost.
    for mass in ["consistent", "lumped"] {
        let text = format!(
            r#"
[analysis]
t_end = 1.0e-3
dt = 1.0e-4
mass = "{mass}"
vtk_every = 0
[materials.steel]
model = "elastic"
E = 210e9
nu = 0.3
rho = 7850.0
[[bodies]]
name = "block"
material = "steel"
thickness = 0.2
velocity = [3.0, -2.0]
mesh = {{ kind = "rectangle", size = [0.6, 0.6], divisions = [3, 3], element = "tri3" }}
"#
        );
        let model = rothe::config::from_str(&text, std::path::Path::new(".")).unwrap();
        let mut be = BackwardEuler::new(&model, Backend::Faer).unwrap();
        let mut s = be.initial_state();
        let p0 = [
            s.mv.iter().step_by(2).sum::<f64>(),
            s.mv.iter().skip(1).step_by(2).sum::<f64>(),
        ];
        for _ in 0..10 {
            be.step_accepted(&mut s).unwrap();
        }
        let p = [
            s.mv.iter().step_by(2).sum::<f64>(),
            s.mv.iter().skip(1).step_by(2).sum::<f64>(),
        ];
        for i in 0..2 {
            assert!(
                (p[i] - p0[i]).abs() < 1e-12 * p0[i].abs(),
                "{mass}: momentum {p:?} vs {p0:?}"
            );
        }
        for n in 0..model.mesh.n_nodes() {
            assert!(
                (s.u[2 * n] - 3.0 * s.t).abs() < 1e-12
                    && (s.u[2 * n + 1] + 2.0 * s.t).abs() < 1e-12
            );
        }
        assert!((s.ledger.kinetic() - s.ledger.kinetic_0()).abs() < 1e-12 * s.ledger.kinetic_0());
    }
}

#[test]
fn orderings_give_the_same_solution() {
    // The fill-reducing ordering changes the factor, not the answer: the static
    // cantilever solved with AMD and with nested dissection agrees to round-off.
    let mut sols = Vec::new();
    for ordering in [
        rothe::model::Ordering::Amd,
        rothe::model::Ordering::NestedDissection,
    ] {
        let part = structured::rectangle([0.0, 0.0], [5.0, 0.5], 200, 20, ElementKind::Quad4);
        let mut model = model_of(&part, Idealisation::PlaneStress, 30e9, 0.25, 2400.0, 0.1);
        model.analysis.iteration.ordering = ordering;
        let left = model.mesh.node_sets["b.left"].clone();
        prescribe(&mut model, &left, 0, |_| 0.0);
        prescribe(&mut model, &left, 1, |_| 0.0);
        let mut f = vec![0.0; model.mesh.n_dofs()];
        rothe::assembly::loads::add_body_force(&model.mesh, |_| [0.0, -1e4], &mut f);
        model.loads.push(load_from(&f, TimeFunction::Constant));
        sols.push(
            statics::solve(&model, Backend::Faer, &[1.0])
                .unwrap()
                .remove(0)
                .u,
        );
    }
    let scale = sols[0].iter().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(max_diff(&sols[0], &sols[1]) < 1e-10 * scale);
}
