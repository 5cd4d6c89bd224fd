//! Rankine-Hill plasticity in a solid: the principal-stress-space returns to each
//! face, edge, corner and the apex against the Karush-Kuhn-Tucker conditions and the
//! normal cone, plane-stress paths against the plane model, uniaxial curves and
//! plastic work against closed forms, objectivity, consistent tangents against
//! finite differences, and invariants along random paths.
#![allow(clippy::needless_range_loop)]

use crate::common;

use proptest::prelude::*;
use rothe::fe::frame::eigen_sym3;
use rothe::fe::Idealisation;
use rothe::material::{Material, PointResponse, StrainStep};

const E: f64 = 33e9;
const NU: f64 = 0.2;
const FT: f64 = 2.9e6;
const FC: f64 = 30e6;
const ET: f64 = 1.65e9;
const BILINEAR: &str = "tension = { law = \"bilinear\", strength = 2.9e6, post_yield_modulus = 1.65e9 }\ncompression = { law = \"bilinear\", strength = 30.0e6, post_yield_modulus = 1.65e9 }";
const SOFTENING: &str = "tension = { law = \"linear_softening\", strength = 2.9e6, fracture_energy = 140.0 }\ncompression = { law = \"ec2\", f_cm = 38e6, eps_c1 = 0.0022, eps_cu1 = 0.0035 }";

fn mat(laws: &str) -> Material {
    let spec: rothe::config::MaterialSpec = toml::from_str(&format!(
        "model = \"rankine_hill\"\n{laws}\nE = {E}\nnu = {NU}\nrho = 2400.0"
    ))
    .unwrap();
    rothe::config::material("m", "material", &spec).unwrap()
}

/// The bilinear strength `f_y + H κ`, `H = E E_t/(E − E_t)` (uniaxial slope `E_t`).
fn bilinear(fy: f64, kappa: f64) -> f64 {
    fy + E * ET / (E - ET) * kappa
}

/// One solid point update from `state_n` (element size 0.1).
fn point(
    m: &Material,
    eps_n: [f64; 6],
    eps: [f64; 6],
    state_n: &[f64],
) -> (PointResponse<6>, Vec<f64>) {
    common::point_update::<6, rothe::fe::Solid>(m, eps_n, eps, state_n)
}

/// The symmetric tensor of a Voigt vector whose shears are `shear` times the
/// tensor's.
fn tensor(v: &[f64], shear: f64) -> [[f64; 3]; 3] {
    let (a, b, c) = (v[2] / shear, v[4] / shear, v[5] / shear);
    [[v[0], a, c], [a, v[1], b], [c, b, v[3]]]
}

/// `Qᵀ diag(d) Q` as a Voigt strain (engineering shears), `Q`'s rows the axes.
fn strain_along(q: &[[f64; 3]; 3], d: [f64; 3]) -> [f64; 6] {
    let t = |i: usize, j: usize| (0..3).map(|k| d[k] * q[k][i] * q[k][j]).sum::<f64>();
    [
        t(0, 0),
        t(1, 1),
        2.0 * t(0, 1),
        t(2, 2),
        2.0 * t(1, 2),
        2.0 * t(2, 0),
    ]
}

/// A rotation (rows orthonormal) from three angles.
fn rotation(a: f64, b: f64, c: f64) -> [[f64; 3]; 3] {
    let rz = [
        [a.cos(), -a.sin(), 0.0],
        [a.sin(), a.cos(), 0.0],
        [0.0, 0.0, 1.0],
    ];
    let ry = [
        [b.cos(), 0.0, b.sin()],
        [0.0, 1.0, 0.0],
        [-b.sin(), 0.0, b.cos()],
    ];
    let rx = [
        [1.0, 0.0, 0.0],
        [0.0, c.cos(), -c.sin()],
        [0.0, c.sin(), c.cos()],
    ];
    let mul = |x: [[f64; 3]; 3], y: [[f64; 3]; 3]| -> [[f64; 3]; 3] {
        std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| x[i][k] * y[k][j]).sum()))
    };
    mul(mul(rz, ry), rx)
}

/// Which surfaces are active at a returned state (bilinear laws), checked against
/// the Karush-Kuhn-Tucker conditions and the normal cone: every yield function
/// `≤ 0`, the active ones `= 0`, and the plastic strain increment, written in the
/// trial frame `q` (the strain's principal axes, a virgin point), diagonal with
/// `Δεᵖ_a = λ_a + κ_c n_a` (`λ_a ≥ 0` the Rankine multipliers, summing to `κ_t`;
/// `n = ∂q/∂σ`). Returns the active Rankine directions and whether von Mises is.
fn kkt(r: &PointResponse<6>, st: &[f64], q: &[[f64; 3]; 3]) -> (Vec<usize>, bool) {
    let (kt, kc) = (st[6], st[7]);
    let yt = bilinear(FT, kt);
    let yc = bilinear(FC, kc);
    // Principal stresses in the trial frame (the return is coaxial): diagonal.
    let s = tensor(&r.sigma, 1.0);
    let sp: [[f64; 3]; 3] = std::array::from_fn(|a| {
        std::array::from_fn(|b| {
            (0..3)
                .map(|i| (0..3).map(|j| q[a][i] * s[i][j] * q[b][j]).sum::<f64>())
                .sum()
        })
    });
    let tol = 1e-7 * FC;
    for a in 0..3 {
        for b in 0..3 {
            if a != b {
                assert!(
                    sp[a][b].abs() < tol,
                    "stress coaxial with the trial: {sp:?}"
                );
            }
        }
    }
    let sv = [sp[0][0], sp[1][1], sp[2][2]];
    let qv =
        (sv.iter().map(|x| x * x).sum::<f64>() - sv[0] * sv[1] - sv[1] * sv[2] - sv[2] * sv[0])
            .sqrt();
    let n: [f64; 3] =
        std::array::from_fn(|a| (2.0 * sv[a] - (sv.iter().sum::<f64>() - sv[a])) / (2.0 * qv));
    let ep = tensor(&st[..6], 2.0);
    let epp: [[f64; 3]; 3] = std::array::from_fn(|a| {
        std::array::from_fn(|b| {
            (0..3)
                .map(|i| (0..3).map(|j| q[a][i] * ep[i][j] * q[b][j]).sum::<f64>())
                .sum()
        })
    });
    let scale = epp.iter().flatten().map(|x| x.abs()).fold(1e-12, f64::max);
    for a in 0..3 {
        for b in 0..3 {
            if a != b {
                assert!(
                    epp[a][b].abs() < 1e-9 * scale,
                    "plastic strain coaxial: {epp:?}"
                );
            }
        }
    }
    let vm_active = kc > 0.0;
    assert!(
        (qv - yc).abs() < tol || (!vm_active && qv < yc + tol),
        "von Mises: q = {qv}, σ̄_c = {yc}, κ_c = {kc}"
    );
    let mut rankine = Vec::new();
    let mut sum = 0.0;
    for a in 0..3 {
        let lam = epp[a][a] - kc * n[a];
        assert!(sv[a] <= yt + tol, "σ_{a} = {} above σ̄_t = {yt}", sv[a]);
        assert!(lam >= -1e-9 * scale, "λ_{a} = {lam} negative");
        if lam > 1e-9 * scale {
            assert!(
                (sv[a] - yt).abs() < tol,
                "active R{a}: σ = {} vs σ̄_t = {yt}",
                sv[a]
            );
            rankine.push(a);
        }
        sum += lam;
    }
    assert!((sum - kt).abs() < 1e-8 * scale, "Σλ = {sum} vs κ_t = {kt}");
    assert!(r.dissipation.plastic > 0.0);
    (rankine, vm_active)
}

#[test]
fn returns_to_every_face_edge_corner_and_the_apex_satisfy_kkt() {
    // Reference: the Karush-Kuhn-Tucker conditions of the composite criterion and
    // associated flow, checked from the returned stress and plastic strain alone
    // (see `kkt`). Each trial is a diagonal strain rotated by a generic rotation,
    // chosen to land beyond one face, edge or corner of principal stress space:
    // the active set found must be that one. The axes are sorted as the trial's
    // principal stresses, so the Rankine planes are numbered from the largest.
    let m = mat(BILINEAR);
    let q = rotation(0.3, -0.7, 1.1);
    for (d, want_r, want_vm) in [
        ([2e-4, 0.0, -1e-5], vec![0], false),             // Rankine face
        ([3e-4, 2.9e-4, -2e-5], vec![0, 1], false),       // Rankine edge
        ([3.0e-4, 2.9e-4, 2.8e-4], vec![0, 1, 2], false), // apex of the pyramid
        ([-2e-3, -2.1e-4, -2.0e-4], vec![], true),        // von Mises
        ([2e-3, -1e-3, -1.2e-3], vec![0], true),          // Rankine + von Mises
        ([2.5e-3, 2.4e-3, -2.0e-3], vec![0, 1], true),    // edge + von Mises
    ] {
        let eps = strain_along(&q, d);
        let (r, st) = point(&m, [0.0; 6], eps, &[0.0; 8]);
        assert_eq!(r.status, rothe::material::PointStatus::Ok);
        let (rankine, vm) = kkt(&r, &st, &q);
        assert_eq!(
            (rankine, vm),
            (want_r, want_vm),
            "active set for the strain {d:?}"
        );
    }
}

/// Newton on the free components of a solid point so that their stresses vanish,
/// with the others prescribed (`fixed[i]` true); returns the response, the full
/// strain and the new state.
fn mixed(
    m: &Material,
    eps_n: [f64; 6],
    mut eps: [f64; 6],
    fixed: [bool; 6],
    state_n: &[f64],
) -> (PointResponse<6>, [f64; 6], Vec<f64>) {
    let free: Vec<usize> = (0..6).filter(|&i| !fixed[i]).collect();
    for _ in 0..50 {
        let (r, st) = point(m, eps_n, eps, state_n);
        let res: f64 = free.iter().map(|&i| r.sigma[i].abs()).sum();
        if res < 1e-6 {
            return (r, eps, st);
        }
        // Solve the free block of the tangent (at most 4 unknowns) by elimination.
        let k = free.len();
        let mut a: Vec<Vec<f64>> = free
            .iter()
            .map(|&i| {
                free.iter()
                    .map(|&j| r.tangent[i][j])
                    .chain([-r.sigma[i]])
                    .collect()
            })
            .collect();
        for c in 0..k {
            let p = (c..k)
                .max_by(|&x, &y| a[x][c].abs().total_cmp(&a[y][c].abs()))
                .unwrap();
            a.swap(c, p);
            for rr in 0..k {
                if rr != c {
                    let f = a[rr][c] / a[c][c];
                    for cc in c..=k {
                        a[rr][cc] -= f * a[c][cc];
                    }
                }
            }
        }
        for (row, &i) in free.iter().enumerate() {
            eps[i] += a[row][k] / a[row][row];
        }
    }
    panic!("the mixed point did not converge at ε = {eps:?}");
}

#[test]
fn plane_stress_paths_of_a_solid_point_follow_the_plane_model() {
    // Reference: the plane-stress model is the solid one with σ_zz = σ_yz = σ_zx = 0
    // (σ3 = 0 is a principal stress, below σ̄_t, so the plane's two Rankine planes
    // and its von Mises ellipse are the solid's criterion on that subspace). Driving
    // ε_xx, ε_yy, γ_xy of a solid point through paths into every plane regime
    // (tension, compression, the corner, biaxial tension, unloading) with the
    // out-of-plane stresses held at zero, the stresses and hardening variables
    // follow the plane-stress point of the same material to 1e-6.
    for laws in [BILINEAR, SOFTENING] {
        let m = mat(laws);
        for end in [
            [4e-4, -5e-5, 1e-4],
            [-3e-3, -4e-4, 8e-4],
            [1.5e-3, -1.6e-3, 3e-4],
            [3e-4, 2.5e-4, 5e-5],
        ] {
            let steps = 80;
            let (mut e6n, mut h6) = ([0.0; 6], vec![0.0; 8]);
            let (mut e3n, mut h3) = ([0.0; 3], vec![0.0; 5]);
            for k in 1..=steps {
                // Out to `end` and back by a third (elastic unloading, then reloading).
                let f = if k <= 60 {
                    k as f64 / 60.0
                } else {
                    1.0 - (k - 60) as f64 / 60.0
                };
                let e3 = end.map(|x| f * x);
                let guess = [e3[0], e3[1], e3[2], e6n[3], 0.0, 0.0];
                let (r6, e6, n6) =
                    mixed(&m, e6n, guess, [true, true, true, false, false, false], &h6);
                let mut n3 = vec![0.0; 5];
                let r3 = m.update::<3, rothe::fe::PlaneStress>(
                    &StrainStep {
                        eps_n: e3n,
                        eps: e3,
                        dt: 1e-4,
                        length: 0.1,
                        tangent: true,
                    },
                    &h3,
                    &mut n3,
                );
                for i in 0..3 {
                    assert!(
                        (r6.sigma[i] - r3.sigma[i]).abs() < 1e-6 * FT,
                        "{end:?} step {k}: σ[{i}] solid {} vs plane {}",
                        r6.sigma[i],
                        r3.sigma[i]
                    );
                }
                // κ_c always; κ_t while the tensile strength lasts: once it is
                // exhausted (σ̄_t = 0 past κ_u = 2 G_f/(f_t h) of the softening law)
                // σ_zz = 0 lies on the solid's third Rankine plane, which may flow
                // (a crack parallel to the plane, at zero stress and no
                // dissipation) where the plane model has no such plane.
                let exhausted = laws == SOFTENING && h3[3] >= 2.0 * 140.0 / (FT * 0.1);
                assert!(
                    (n6[7] - n3[4]).abs() < 1e-9 * n3[4].abs().max(1e-6),
                    "{end:?} step {k}: κ_c"
                );
                if !exhausted {
                    assert!(
                        (n6[6] - n3[3]).abs() < 1e-9 * n3[3].abs().max(1e-6),
                        "{end:?} step {k}: κ_t solid {} vs plane {}",
                        n6[6],
                        n3[3]
                    );
                }
                assert!(
                    (r6.dissipation.plastic - r3.dissipation.plastic).abs()
                        < 1e-6 * r3.dissipation.plastic.abs().max(1.0),
                    "{end:?} step {k}: plastic dissipation"
                );
                (e6n, h6, e3n, h3) = (e6, n6, e3, n3);
            }
            assert!(h6[6] + h6[7] > 0.0, "{end:?}: the path yields");
        }
    }
}

#[test]
fn uniaxial_stress_in_a_solid_follows_the_bilinear_diagram_and_its_plastic_work() {
    // Reference: under uniaxial stress the bilinear laws give σ = E ε to f_y, then
    // f_y + E_t (ε − f_y/E), in tension (Rankine) and compression (von Mises, where
    // q = |σ|); the plastic work at the end of loading is ∫σ̄ dκ = f_y κ + ½Hκ²
    // exactly (the trapezoid is exact for a linear law); unloading is elastic.
    let m = mat(BILINEAR);
    let fixed = [true, false, false, false, false, false];
    for (fy, sign) in [(FT, 1.0), (FC, -1.0)] {
        let ey = fy / E;
        let (mut en, mut h) = ([0.0; 6], vec![0.0; 8]);
        let mut work = 0.0;
        let mut prev = 0.0;
        for k in 1..=600 {
            let e = if k <= 500 {
                5.0 * ey * k as f64 / 500.0
            } else {
                5.0 * ey - 0.5 * ey * (k - 500) as f64 / 100.0
            };
            let mut guess = en;
            guess[0] = sign * e;
            let (r, eps, st) = mixed(&m, en, guess, fixed, &h);
            let s = sign * r.sigma[0];
            if k <= 500 {
                let want = if e <= ey { E * e } else { fy + ET * (e - ey) };
                assert!((s - want).abs() < 1e-6 * fy, "ε = {e}: σ = {s} vs {want}");
                work += r.dissipation.plastic;
            } else {
                let slope = (s - prev) / (-0.5 * ey / 100.0);
                assert!((slope - E).abs() < 1e-5 * E, "unloading slope {slope}");
                assert_eq!(r.dissipation.plastic, 0.0);
            }
            if k == 500 {
                let kappa = if sign > 0.0 { st[6] } else { st[7] };
                let want = fy * kappa + 0.5 * E * ET / (E - ET) * kappa * kappa;
                assert!(
                    (work - want).abs() < 1e-9 * want,
                    "plastic work {work} vs {want}"
                );
            }
            prev = s;
            (en, h) = (eps, st);
        }
    }
}

#[test]
fn the_return_is_objective() {
    // Reference: an isotropic model commutes with rotations: σ(R ε Rᵀ) = R σ(ε) Rᵀ
    // and the plastic strain rotates alike, in every regime (face, edge, apex,
    // von Mises, corner), and from a rotated hardened history.
    let m = mat(BILINEAR);
    let r = rotation(-0.4, 0.9, 0.25);
    let rot = |v: &[f64], shear: f64| -> [f64; 6] {
        let t = tensor(v, shear);
        let rt: [[f64; 3]; 3] = std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                (0..3)
                    .map(|k| (0..3).map(|l| r[i][k] * t[k][l] * r[j][l]).sum::<f64>())
                    .sum()
            })
        });
        [
            rt[0][0],
            rt[1][1],
            shear * rt[0][1],
            rt[2][2],
            shear * rt[1][2],
            shear * rt[2][0],
        ]
    };
    let base = rotation(0.1, 0.2, 0.3);
    for d in [
        [2e-4, 0.0, -1e-5],
        [3e-4, 2.9e-4, -2e-5],
        [3.0e-4, 2.9e-4, 2.8e-4],
        [-2e-3, -2.1e-4, -2e-4],
        [1.2e-3, -1.5e-3, -1.4e-3],
    ] {
        let eps = strain_along(&base, d);
        let (a, sa) = point(&m, [0.0; 6], eps, &[0.0; 8]);
        let (b, sb) = point(&m, [0.0; 6], rot(&eps, 2.0), &[0.0; 8]);
        let want = rot(&a.sigma, 1.0);
        let wp = rot(&sa[..6], 2.0);
        for i in 0..6 {
            assert!(
                (b.sigma[i] - want[i]).abs() < 1e-6 * FT,
                "{d:?}: σ[{i}] {} vs {}",
                b.sigma[i],
                want[i]
            );
            assert!((sb[i] - wp[i]).abs() < 1e-12, "{d:?}: εᵖ[{i}]");
        }
        // A second step from the rotated histories.
        let eps2 = strain_along(&base, d.map(|x| 1.3 * x));
        let (a2, _) = point(&m, eps, eps2, &sa);
        let mut hist = wp.to_vec();
        hist.extend_from_slice(&sa[6..]);
        let (b2, _) = point(&m, rot(&eps, 2.0), rot(&eps2, 2.0), &hist);
        let want2 = rot(&a2.sigma, 1.0);
        for i in 0..6 {
            assert!(
                (b2.sigma[i] - want2[i]).abs() < 1e-6 * FT,
                "{d:?} second step σ[{i}]"
            );
        }
    }
}

#[test]
fn solid_consistent_tangents_match_finite_differences() {
    // Reference: central differences of the stress (δε = 1e-9) in the elastic
    // range, on each face, edge, corner and the apex, from virgin and hardened
    // histories, for the hardening and the softening laws.
    let q = rotation(0.3, -0.7, 1.1);
    let mut hardened = [0.0; 8];
    hardened[..6].copy_from_slice(&[1e-5, -2e-5, 1e-5, 5e-6, -4e-6, 3e-6]);
    hardened[6] = 2e-5;
    hardened[7] = 1e-4;
    for laws in [BILINEAR, SOFTENING] {
        let m = mat(laws);
        for (d, h) in [
            ([3e-5, 1e-5, 0.0], [0.0; 8]),
            ([2e-4, 0.0, -1e-5], [0.0; 8]),
            ([3e-4, 2.9e-4, -2e-5], [0.0; 8]),
            ([3.0e-4, 2.9e-4, 2.8e-4], [0.0; 8]),
            ([-2e-3, -2.1e-4, -2.0e-4], [0.0; 8]),
            ([2e-3, -1e-3, -1.2e-3], [0.0; 8]),
            ([2.5e-3, 2.4e-3, -2.0e-3], [0.0; 8]),
            ([4e-4, -1e-4, 1e-4], hardened),
            ([-2.5e-3, -1e-3, -5e-4], hardened),
        ] {
            let eps = strain_along(&q, d);
            common::assert_point_tangent::<6, rothe::fe::Solid>(&m, [0.0; 6], eps, &h, 1e-4 * E);
        }
    }
}

#[test]
fn jacobi_frames_agree_with_the_closed_form_principal_values() {
    // The eigenvalues of the frame (Jacobi) and of the closed form the yield check
    // reads agree, so a point judged plastic is returned in a consistent frame.
    let t = tensor(&[3e6, -1e6, 2e6, 5e5, -7e5, 1.5e6], 1.0);
    let (l, _) = eigen_sym3(t);
    let closed = rothe::fe::principal::principal_voigt6(&[3e6, -1e6, 2e6, 5e5, -7e5, 1.5e6], 1.0);
    for i in 0..3 {
        assert!((l[i] - closed[i]).abs() < 1e-8 * 3e6);
    }
}

proptest! {
    #![proptest_config(common::seeded(48, 0x5eed_0003))]

    #[test]
    fn random_solid_paths_stay_admissible(path in common::strain_paths::<6>(40)) {
        // After every return the principal stresses lie inside the criterion at
        // the new hardening variables, which never decrease, and the step's
        // plastic dissipation is non-negative (bilinear laws).
        let m = mat(BILINEAR);
        let (mut st_n, mut eps_n) = (vec![0.0; 8], [0.0; 6]);
        for eps in &path {
            let (r, st) = point(&m, eps_n, *eps, &st_n);
            prop_assert_eq!(r.status, rothe::material::PointStatus::Ok);
            let (l, _) = eigen_sym3(tensor(&r.sigma, 1.0));
            let q = (l.iter().map(|x| x * x).sum::<f64>() - l[0] * l[1] - l[1] * l[2] - l[2] * l[0]).max(0.0).sqrt();
            prop_assert!(l[0] <= bilinear(FT, st[6]) + 1e-6 * FT, "σ1 = {}", l[0]);
            prop_assert!(q <= bilinear(FC, st[7]) + 1e-6 * FC, "q = {}", q);
            prop_assert!(st[6] >= st_n[6] && st[7] >= st_n[7]);
            prop_assert!(r.dissipation.plastic >= 0.0);
            st_n = st;
            eps_n = *eps;
        }
    }
}

/// One plane-strain point update (element size 0.1).
fn plane_strain_point(
    m: &Material,
    eps_n: [f64; 3],
    eps: [f64; 3],
    state_n: &[f64],
) -> (PointResponse<3>, Vec<f64>) {
    common::point_update::<3, rothe::fe::PlaneStrain>(m, eps_n, eps, state_n)
}

#[test]
fn plane_strain_uniaxial_compression_follows_the_closed_form() {
    // Reference: plane strain with ε_yy = 0 is uniaxial strain (ε_yy = ε_zz = 0).
    // The lateral stresses are equal, von Mises reads q = |σ_xx − σ_l|, the flow
    // (−1, ½, ½)κ is deviatoric, so the mean stress stays K ε and
    // q = 2μ|ε| − 3μκ = f_y + Hκ: κ = (2μ|ε| − f_y)/(3μ + H) past yield,
    // σ_xx = Kε − ⅔q, σ_yy = Kε + ⅓q, εᵖ_zz = κ/2. Rankine stays inactive
    // (σ1 = σ_yy < 0). Backward Euler is exact on this radial path with a linear
    // law; unloading is elastic with the plane-strain modulus λ + 2μ.
    let m = mat(BILINEAR);
    let (mu, k) = (E / (2.0 * (1.0 + NU)), E / (3.0 * (1.0 - 2.0 * NU)));
    let h = E * ET / (E - ET);
    let (mut en, mut st) = ([0.0; 3], vec![0.0; 6]);
    let mut yielded = false;
    for step in 1..=120 {
        let e = -5e-3 * (step.min(100) as f64) / 100.0 + 1e-3 * (step.max(100) - 100) as f64 / 20.0;
        let eps = [e, 0.0, 0.0];
        let (r, next) = plane_strain_point(&m, en, eps, &st);
        if step <= 100 {
            let kappa = ((2.0 * mu * e.abs() - FC) / (3.0 * mu + h)).max(0.0);
            let q = 2.0 * mu * e.abs() - 3.0 * mu * kappa;
            let (sx, sy) = (k * e - 2.0 / 3.0 * q, k * e + q / 3.0);
            assert!(
                (r.sigma[0] - sx).abs() < 1e-6 * FC,
                "ε = {e}: σ_xx {} vs {sx}",
                r.sigma[0]
            );
            assert!(
                (r.sigma[1] - sy).abs() < 1e-6 * FC,
                "ε = {e}: σ_yy {} vs {sy}",
                r.sigma[1]
            );
            assert!(
                (next[4] - kappa).abs() < 1e-9 * kappa.max(1e-6),
                "κ_c {} vs {kappa}",
                next[4]
            );
            assert!(
                (next[5] - 0.5 * kappa).abs() < 1e-9 * kappa.max(1e-6),
                "εᵖ_zz {}",
                next[5]
            );
            assert_eq!(next[3], 0.0, "Rankine inactive");
            yielded |= kappa > 0.0;
        } else {
            // Unloading: Δσ_xx = (λ + 2μ) Δε.
            let c11 = k + 4.0 / 3.0 * mu;
            let (r0, _) = plane_strain_point(&m, en, en, &st);
            let slope = (r.sigma[0] - r0.sigma[0]) / (e - en[0]);
            assert!(
                (slope - c11).abs() < 1e-6 * c11,
                "unloading slope {slope} vs {c11}"
            );
            assert_eq!(next[4], st[4], "no flow on unloading");
        }
        (en, st) = (eps, next);
    }
    assert!(yielded);
}

#[test]
fn plane_strain_tangents_match_finite_differences() {
    // Reference: central differences (δε = 1e-9) of the plane-strain stress in the
    // elastic range, in tension (Rankine), compression (von Mises) and the
    // tension-compression corner, from virgin and hardened histories.
    let hardened = [1e-5, -2e-5, 1e-5, 2e-5, 1e-4, 5e-6];
    for laws in [BILINEAR, SOFTENING] {
        let m = mat(laws);
        for (eps, st) in [
            ([3e-5, 1e-5, 0.0], [0.0; 6]),
            ([3e-4, 5e-5, 1e-4], [0.0; 6]),
            ([-2e-3, -4e-4, 6e-4], [0.0; 6]),
            ([1.5e-3, -1.6e-3, 2e-4], [0.0; 6]),
            ([4e-4, -1e-4, 2e-4], hardened),
        ] {
            common::assert_point_tangent::<3, rothe::fe::PlaneStrain>(
                &m,
                [0.0; 3],
                eps,
                &st,
                1e-4 * E,
            );
        }
    }
}

#[test]
fn a_plane_strain_rankine_hill_run_closes_its_ledger() {
    // The Rankine-Hill cantilever of the regression set in plane strain: the run
    // reaches its end, yields (D_plastic > 0), and the ledger closes to the
    // iteration tolerance (1e-6 of the work, as in plane stress).
    use rothe::time::backward_euler::BackwardEuler;
    use rothe::time::Integrator;
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/regression/rankine_hill_cantilever.toml"),
    )
    .unwrap()
    .replace("[analysis]", "[analysis]\nplane = \"strain\"");
    let model = rothe::config::from_str(&text, std::path::Path::new(".")).unwrap();
    assert_eq!(model.idealisation, Idealisation::PlaneStrain);
    let mut be = BackwardEuler::new(&model, rothe::linsolve::Backend::Faer).unwrap();
    let mut s = be.initial_state();
    for _ in 0..model.analysis.n_steps() {
        be.step_accepted(&mut s).unwrap();
    }
    let rel = s.ledger.relative_residual();
    assert!(rel.abs() < 1e-6, "balance {rel:e}");
    assert!(
        s.ledger.dissipated().plastic > 0.0,
        "the plane-strain beam yields"
    );
}

#[test]
fn the_material_driver_takes_a_solid_point() {
    // Reference: a solid's point under uniaxial stress is the plane-stress point
    // under uniaxial stress (the two stress-free directions are alike), so
    // `rothe material` with `plane = "solid"` gives the plane-stress curve: σ_xx to
    // 1e-6 f_t at every step into hardening and back, the other five stresses at
    // zero, the plastic work alike. The file form writes six strain and six stress
    // columns and the solid's history names; a table of three-component strains
    // for a solid's point is refused naming the row.
    use rothe::point_driver::{run_file, run_path, run_solid_path, PathSpec};
    let m = mat(BILINEAR);
    let path = |plane: &str| -> PathSpec {
        toml::from_str(&format!(
            "kind = \"uniaxial_stress\"\nplane = \"{plane}\"\namplitude = 5e-4\nfunction = {{ kind = \"table\", points = [[0.0, 0.0], [1.0, 1.0], [1.5, 0.8]] }}\nt_end = 1.5\ndt = 0.01"
        ))
        .unwrap()
    };
    let plane = run_path(&m, &path("stress")).unwrap();
    let solid = run_solid_path(&m, &path("solid")).unwrap();
    assert_eq!(plane.len(), solid.len());
    for (p, s) in plane.iter().zip(&solid) {
        assert!(
            (p.response.sigma[0] - s.response.sigma[0]).abs() < 1e-6 * FT,
            "t = {}",
            p.t
        );
        for i in 1..6 {
            assert!(
                s.response.sigma[i].abs() < 1e-6 * FT,
                "t = {}: σ[{i}] = {}",
                s.t,
                s.response.sigma[i]
            );
        }
        assert!((p.dissipated[2] - s.dissipated[2]).abs() <= 1e-9 * p.dissipated[2].max(1.0));
    }
    assert!(solid.last().unwrap().dissipated[2] > 0.0, "the path yields");

    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("point.toml");
    std::fs::write(
        &file,
        format!(
            "[material]\nmodel = \"rankine_hill\"\n{BILINEAR}\nE = {E}\nnu = {NU}\nrho = 2400.0\n[path]\nkind = \"table\"\nplane = \"solid\"\nt_end = 1.0\ndt = 0.1\ntimes = [0.0, 1.0]\nstrains = [[0.0, 0.0, 0.0, 0.0, 0.0, 0.0], [3e-4, 2.9e-4, 0.0, 2.8e-4, 1e-5, 0.0]]\n"
        ),
    )
    .unwrap();
    let steps = run_file(&file, dir.path(), |_| {}).unwrap();
    assert_eq!(steps, 10);
    let csv = std::fs::read_to_string(dir.path().join("material.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert!(
        header.starts_with("t,eps_xx,eps_yy,gamma_xy,eps_zz,gamma_yz,gamma_zx,sig_xx,sig_yy,sig_xy,sig_zz,sig_yz,sig_zx,psi,eps_p_xx"),
        "{header}"
    );
    assert!(header.contains("kappa_t,kappa_c,D_viscous"), "{header}");
    assert_eq!(csv.lines().count(), 12);
    let bad = std::fs::read_to_string(&file)
        .unwrap()
        .replace("[0.0, 0.0, 0.0, 0.0, 0.0, 0.0]", "[0.0, 0.0, 0.0]");
    std::fs::write(&file, bad).unwrap();
    let e = run_file(&file, dir.path(), |_| {}).unwrap_err().to_string();
    assert!(
        e.contains("path.strains[0]") && e.contains("expected 6"),
        "{e}"
    );
}
