//! Material-point verification of the viscoelastic models against closed forms, with
//! observed orders in the step size, energy per cycle against the analytic loss, the
//! exact point energy identity, and properties over random parameters and paths.
#![allow(clippy::needless_range_loop, clippy::too_many_arguments)]

use crate::common;

use proptest::prelude::*;
use rothe::config::MaterialSpec;
use rothe::fe::Idealisation;
use rothe::material::{Material, StrainStep};
use rothe::model::TimeFunction;
use rothe::point_driver::{run_path, Control, PathKind, PathSpec, PointRecord};

const E: f64 = 30e9;
const NU: f64 = 0.2;

fn mat(toml_text: &str) -> Material {
    let spec: MaterialSpec = toml::from_str(toml_text).unwrap();
    rothe::config::material("m", "material", &spec).unwrap()
}

fn path(
    kind: PathKind,
    control: Control,
    amplitude: f64,
    function: TimeFunction,
    t_end: f64,
    dt: f64,
) -> PathSpec {
    PathSpec {
        kind,
        plane: Idealisation::PlaneStress,
        control,
        amplitude,
        function,
        ratio: 1.0,
        t_end,
        dt,
        times: vec![],
        strains: vec![],
        length: 0.1,
    }
}

/// Largest deviation of `get(record)` from `exact(t)` over the path, relative to `scale`.
fn max_err(
    recs: &[PointRecord],
    get: impl Fn(&PointRecord) -> f64,
    exact: impl Fn(f64) -> f64,
    scale: f64,
) -> f64 {
    recs.iter()
        .skip(1)
        .map(|r| (get(r) - exact(r.t)).abs() / scale)
        .fold(0.0, f64::max)
}

/// Errors at dt, dt/2, dt/4, dt/8 and the observed orders between them.
fn orders(errs: &[f64]) -> Vec<f64> {
    errs.windows(2).map(|w| (w[0] / w[1]).log2()).collect()
}

fn study(
    m: &Material,
    kind: PathKind,
    control: Control,
    amp: f64,
    t_end: f64,
    get: impl Fn(&PointRecord) -> f64,
    exact: impl Fn(f64) -> f64,
    scale: f64,
) -> (Vec<f64>, Vec<f64>) {
    let errs: Vec<f64> = [40.0, 80.0, 160.0, 320.0]
        .iter()
        .map(|n| {
            let recs = run_path(
                m,
                &path(kind, control, amp, TimeFunction::Constant, t_end, t_end / n),
            )
            .unwrap();
            max_err(&recs, &get, &exact, scale)
        })
        .collect();
    (orders(&errs), errs)
}

#[test]
fn sls_relaxation_under_strain_step() {
    // Reference: SLS (eq. 10) in uniaxial stress with the strain held at ε0 from t = 0:
    // σ(t) = E ε0 (1 + α e^{−t α/β}). α = 0.5, β = 1e-3 s, over 5 relaxation times.
    let (alpha, beta, e0) = (0.5, 1e-3, 1e-4);
    let m = mat(&format!(
        "model = \"sls\"\nE = {E}\nnu = {NU}\nrho = 2400.0\nalpha = {alpha}\nbeta = {beta}"
    ));
    let (o, errs) = study(
        &m,
        PathKind::UniaxialStress,
        Control::Strain,
        e0,
        5.0 * beta / alpha,
        |r| r.response.sigma[0],
        |t| E * e0 * (1.0 + alpha * (-t * alpha / beta).exp()),
        E * e0,
    );
    assert!(
        o.iter().all(|o| (o - 1.0).abs() < 0.1),
        "orders {o:?} errors {errs:?}"
    );
    assert!(errs[3] < 5e-3);
}

#[test]
fn sls_creep_under_stress_step() {
    // Reference: SLS under σ0 held from t = 0: ε(t) = σ0/E (1 − α/(1+α) e^{−t/t_c}),
    // t_c = β(1+α)/α.
    let (alpha, beta, s0) = (0.5, 1e-3, 3e6);
    let m = mat(&format!(
        "model = \"sls\"\nE = {E}\nnu = {NU}\nrho = 2400.0\nalpha = {alpha}\nbeta = {beta}"
    ));
    let tc = beta * (1.0 + alpha) / alpha;
    let (o, errs) = study(
        &m,
        PathKind::UniaxialStress,
        Control::Stress,
        s0,
        5.0 * tc,
        |r| r.eps[0],
        |t| s0 / E * (1.0 - alpha / (1.0 + alpha) * (-t / tc).exp()),
        s0 / E,
    );
    assert!(
        o.iter().all(|o| (o - 1.0).abs() < 0.1),
        "orders {o:?} errors {errs:?}"
    );
}

#[test]
fn kelvin_voigt_creep() {
    // Reference: Kelvin-Voigt σ = C ε + α C ε̇ under σ0: ε(t) = σ0/E (1 − e^{−t/α}).
    let (alpha, s0) = (2e-3, 3e6);
    let m = mat(&format!(
        "model = \"kelvin_voigt\"\nE = {E}\nnu = {NU}\nrho = 2400.0\nalpha = {alpha}"
    ));
    let (o, errs) = study(
        &m,
        PathKind::UniaxialStress,
        Control::Stress,
        s0,
        5.0 * alpha,
        |r| r.eps[0],
        |t| s0 / E * (1.0 - (-t / alpha).exp()),
        s0 / E,
    );
    assert!(
        o.iter().all(|o| (o - 1.0).abs() < 0.1),
        "orders {o:?} errors {errs:?}"
    );
}

#[test]
fn maxwell_relaxation() {
    // Reference: Maxwell under ε0 held from t = 0: σ(t) = E ε0 e^{−t/β}.
    let (beta, e0) = (1e-3, 1e-4);
    let m = mat(&format!(
        "model = \"maxwell\"\nE = {E}\nnu = {NU}\nrho = 2400.0\nbeta = {beta}"
    ));
    let (o, errs) = study(
        &m,
        PathKind::UniaxialStress,
        Control::Strain,
        e0,
        5.0 * beta,
        |r| r.response.sigma[0],
        |t| E * e0 * (-t / beta).exp(),
        E * e0,
    );
    assert!(
        o.iter().all(|o| (o - 1.0).abs() < 0.1),
        "orders {o:?} errors {errs:?}"
    );
}

/// Viscous energy dissipated in the last of `cycles` cycles of ε_xx = ε0 sin ωt
/// (uniaxial strain), with `steps` steps per cycle.
fn loss_last_cycle(m: &Material, f: f64, e0: f64, cycles: usize, steps: usize) -> f64 {
    let p = path(
        PathKind::UniaxialStrain,
        Control::Strain,
        e0,
        TimeFunction::Harmonic {
            frequency: f,
            phase: 0.0,
        },
        cycles as f64 / f,
        1.0 / (f * steps as f64),
    );
    let recs = run_path(m, &p).unwrap();
    let n = recs.len() - 1;
    recs[n].dissipated[0] - recs[n - steps].dissipated[0]
}

#[test]
fn kelvin_voigt_identity_loss_per_cycle() {
    // Reference: η = β I under ε_xx = ε0 sin ωt loses π β ω ε0² per cycle (the
    // paper's β = 1e6 Pa·s). The backward-Euler estimate converges as the step shrinks.
    let (beta, f, e0) = (1e6, 50.0, 1e-4);
    let m = mat(&format!(
        "model = \"kelvin_voigt\"\nE = {E}\nnu = {NU}\nrho = 2400.0\nbeta = {beta}"
    ));
    let exact = std::f64::consts::PI * beta * 2.0 * std::f64::consts::PI * f * e0 * e0;
    let errs: Vec<f64> = [50, 100, 200, 400]
        .iter()
        .map(|&s| (loss_last_cycle(&m, f, e0, 2, s) - exact).abs() / exact)
        .collect();
    assert!(errs.windows(2).all(|w| w[1] < w[0]), "{errs:?}");
    assert!(errs[3] < 2e-3, "{errs:?}");
}

#[test]
fn sls_loss_per_cycle_matches_loss_modulus() {
    // Reference: in steady state the SLS branch (modulus α C11, relaxation t_r = β/α)
    // dissipates π E'' ε0² per cycle, E'' = α C11 ω t_r / (1 + ω² t_r²).
    let (alpha, beta, f, e0) = (0.5, 2e-3, 100.0, 1e-4);
    let m = mat(&format!(
        "model = \"sls\"\nE = {E}\nnu = {NU}\nrho = 2400.0\nalpha = {alpha}\nbeta = {beta}"
    ));
    let c11 = E / (1.0 - NU * NU);
    let (w, tr) = (2.0 * std::f64::consts::PI * f, beta / alpha);
    let e2 = alpha * c11 * w * tr / (1.0 + w * w * tr * tr);
    let exact = std::f64::consts::PI * e2 * e0 * e0;
    let errs: Vec<f64> = [100, 200, 400, 800]
        .iter()
        .map(|&s| (loss_last_cycle(&m, f, e0, 12, s) - exact).abs() / exact)
        .collect();
    assert!(errs.windows(2).all(|w| w[1] < w[0]), "{errs:?}");
    assert!(errs[3] < 1e-2, "{errs:?}");
}

#[test]
fn point_energy_identity_is_exact() {
    // σ_{n+1}:Δε = Δψ + ΔD_viscous + ΔD_num at every step, for every linear model,
    // along a biaxial harmonic path with a shear table on top.
    for text in [
        "model = \"elastic\"",
        "model = \"kelvin_voigt\"\nalpha = 1e-3",
        "model = \"kelvin_voigt\"\nbeta = 1e6",
        "model = \"sls\"\nalpha = 0.7\nbeta = 1e-3",
        "model = \"maxwell\"\nbeta = 1e-3",
        "model = \"kelvin\"\nbeta = 1e-3",
    ] {
        let m = mat(&format!("{text}\nE = {E}\nnu = {NU}\nrho = 2400.0"));
        let mut p = path(
            PathKind::Table,
            Control::Strain,
            0.0,
            TimeFunction::Constant,
            0.01,
            1e-4,
        );
        p.times = vec![0.0, 0.003, 0.006, 0.01];
        p.strains = vec![
            vec![0.0; 3],
            vec![1e-4, -3e-5, 2e-5],
            vec![-5e-5, 8e-5, -4e-5],
            vec![2e-5, 0.0, 1e-4],
        ];
        let recs = run_path(&m, &p).unwrap();
        let last = recs.last().unwrap();
        let d: f64 = last.dissipated.iter().sum();
        assert!(
            (last.work - last.response.psi - d).abs() <= 1e-12 * last.work.abs().max(d),
            "{text}: work {} psi {} D {d}",
            last.work,
            last.response.psi
        );
    }
}

fn rotate(e: [f64; 3], th: f64) -> [f64; 3] {
    // Tensor rotation of [ε_xx, ε_yy, γ_xy] by angle θ.
    let (c, s) = (th.cos(), th.sin());
    let exy = e[2] / 2.0;
    let xx = c * c * e[0] + s * s * e[1] + 2.0 * c * s * exy;
    let yy = s * s * e[0] + c * c * e[1] - 2.0 * c * s * exy;
    let xy = -c * s * e[0] + c * s * e[1] + (c * c - s * s) * exy;
    [xx, yy, 2.0 * xy]
}

fn rotate_stress(s: [f64; 3], th: f64) -> [f64; 3] {
    let r = rotate([s[0], s[1], 2.0 * s[2]], th);
    [r[0], r[1], r[2] / 2.0]
}

fn model_strategy() -> impl Strategy<Value = String> {
    prop_oneof![
        (1e-5f64..1e-2).prop_map(|a| format!("model = \"kelvin_voigt\"\nalpha = {a}")),
        (1e4f64..1e8).prop_map(|b| format!("model = \"kelvin_voigt\"\nbeta = {b}")),
        (0.05f64..5.0, 1e-5f64..1e-1)
            .prop_map(|(a, b)| format!("model = \"sls\"\nalpha = {a}\nbeta = {b}")),
        (1e-5f64..1e-1).prop_map(|b| format!("model = \"maxwell\"\nbeta = {b}")),
    ]
}

proptest! {
    #![proptest_config(common::seeded(64, 0x5eed_0001))]

    #[test]
    fn dissipation_is_non_negative_and_stress_objective(
        text in model_strategy(),
        e in 1e9f64..1e11,
        nu in -0.5f64..0.49,
        dt in 1e-6f64..1e-2,
        path in proptest::collection::vec(proptest::array::uniform3(-1e-3f64..1e-3), 2..12),
        theta in 0.0f64..std::f64::consts::PI,
    ) {
        let m = mat(&format!("{text}\nE = {e}\nnu = {nu}\nrho = 1000.0"));
        let ns = m.n_state(3);
        let (mut st_n, mut st) = (vec![0.0; ns], vec![0.0; ns]);
        let (mut rt_n, mut rt) = (vec![0.0; ns], vec![0.0; ns]);
        let (mut eps_n, mut reps_n) = ([0.0; 3], [0.0; 3]);
        for eps in &path {
            let reps = rotate(*eps, theta);
            let r = m.update::<3, rothe::fe::PlaneStress>(&StrainStep { eps_n, eps: *eps, dt, length: 0.1, tangent: true }, &st_n, &mut st);
            let q = m.update::<3, rothe::fe::PlaneStress>(&StrainStep { eps_n: reps_n, eps: reps, dt, length: 0.1, tangent: true }, &rt_n, &mut rt);
            let d = r.dissipation;
            prop_assert!(d.viscous >= 0.0 && d.numerical >= 0.0 && d.damage == 0.0 && d.plastic == 0.0);
            let want = rotate_stress(r.sigma, theta);
            let scale = r.sigma.iter().map(|x| x.abs()).fold(1e-6 * e * 1e-3, f64::max);
            for i in 0..3 {
                prop_assert!((q.sigma[i] - want[i]).abs() <= 1e-9 * scale, "component {}: {} vs {}", i, q.sigma[i], want[i]);
            }
            eps_n = *eps;
            reps_n = reps;
            st_n.clone_from(&st);
            rt_n.clone_from(&rt);
        }
    }
}

#[test]
fn predicted_stress_is_the_update_at_unchanged_strain() {
    // The shortcut the constant-tangent FE path uses must equal the full update.
    for text in [
        "model = \"elastic\"",
        "model = \"kelvin_voigt\"\nalpha = 1e-3",
        "model = \"sls\"\nalpha = 0.7\nbeta = 1e-3",
        "model = \"maxwell\"\nbeta = 1e-3",
    ] {
        let m = mat(&format!("{text}\nE = {E}\nnu = {NU}\nrho = 2400.0"));
        let ns = m.n_state(3);
        let (mut s1, mut s2) = (vec![0.0; ns], vec![0.0; ns]);
        let eps = [1e-4, -3e-5, 5e-5];
        m.update::<3, rothe::fe::PlaneStress>(
            &StrainStep {
                eps_n: [0.0; 3],
                eps,
                dt: 1e-4,
                length: 0.1,
                tangent: true,
            },
            &vec![0.0; ns],
            &mut s1,
        );
        let full = m
            .update::<3, rothe::fe::PlaneStress>(
                &StrainStep {
                    eps_n: eps,
                    eps,
                    dt: 1e-4,
                    length: 0.1,
                    tangent: true,
                },
                &s1,
                &mut s2,
            )
            .sigma;
        let quick = m.predicted_stress::<3, rothe::fe::PlaneStress>(&eps, &s1, 1e-4);
        for i in 0..3 {
            assert!(
                (full[i] - quick[i]).abs() <= 1e-12 * full[0].abs(),
                "{text}: {full:?} vs {quick:?}"
            );
        }
    }
}
