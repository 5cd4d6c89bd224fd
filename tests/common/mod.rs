//! Shared builders for the integration tests.
#![allow(dead_code)]

use rothe::fe::Idealisation;
use rothe::material::Material;
use rothe::mesh::{Mesh, Part};
use rothe::model::{Analysis, AnalysisKind, Body, Constraint, Load, Model, TimeFunction};

/// A one-body model of `part` made of one elastic material, static by default.
pub fn model_of(
    part: &Part,
    idealisation: Idealisation,
    e: f64,
    nu: f64,
    rho: f64,
    thickness: f64,
) -> Model {
    let mut mesh = Mesh::default();
    mesh.add_part(part, 0, "b", 0, thickness);
    Model {
        mesh,
        materials: vec![Material::elastic("m", e, nu, rho)],
        idealisation,
        bodies: vec![Body {
            name: "b".into(),
            velocity: [0.0; 3],
            thickness,
        }],
        constraints: Vec::new(),
        loads: Vec::new(),
        gravity: None,
        probes: Vec::new(),
        contacts: Vec::new(),
        warnings: Vec::new(),
        analysis: Analysis {
            time: rothe::model::TimeSettings {
                kind: AnalysisKind::Static,
                scheme: rothe::model::TimeScheme::BackwardEuler,
                omega: 0.9,
                critical_step: Default::default(),
                rho_inf: 0.8,
                contact_predictor: Default::default(),
                dt: 1.0,
                stable_dt: None,
                t_end: 1.0,
                lumped_mass: false,
                viscoelastic_state: rothe::model::ViscoelasticState::Nodal,
                adaptive: None,
            },
            damping: rothe::model::Damping {
                zeta: 0.0,
                rayleigh: [0.0, 0.0],
                targets: None,
            },
            iteration: rothe::model::IterationSettings {
                tolerance: 1e-8,
                max_iterations: 30,
                displacement_tolerance: 1e-6,
                method: rothe::model::IterationMethod::Newton,
                refactor_rate: Some(rothe::model::DEFAULT_REFACTOR_RATE),
                max_cuts: 8,
                dt_min: 0.0,
                ordering: rothe::model::Ordering::Auto,
            },
            contact: rothe::model::ContactSettings {
                tolerance: 1e-6,
                qp: rothe::model::ContactQp::Condensed,
                friction_guess: true,
            },
            output: rothe::model::OutputSettings {
                vtk_every: 0,
                vtk_every_time: None,
            },
        },
    }
}

/// Holds component `comp` of `nodes` at `value(x)` (constant in time).
pub fn prescribe(model: &mut Model, nodes: &[usize], comp: usize, value: impl Fn([f64; 2]) -> f64) {
    for &n in nodes {
        let v = value(model.mesh.xy(n));
        model.constraints.push(Constraint {
            dof: 2 * n + comp,
            value: v,
            function: TimeFunction::Constant,
        });
    }
    model.constraints.sort_by_key(|c| c.dof);
    model.constraints.dedup_by_key(|c| c.dof);
}

/// A load from a dense force vector.
pub fn load_from(f: &[f64], function: TimeFunction) -> Load {
    Load {
        label: "test".into(),
        entries: f
            .iter()
            .enumerate()
            .filter(|(_, v)| **v != 0.0)
            .map(|(d, v)| (d, *v))
            .collect(),
        function,
    }
}

/// Observed order from errors at successive halvings.
pub fn orders(errors: &[f64]) -> Vec<f64> {
    errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect()
}

/// `cases` proptest cases from the fixed `seed` (the same cases every run, so CI is
/// reproducible); set `PROPTEST_RNG_SEED` to explore others.
pub fn seeded(cases: u32, seed: u64) -> proptest::test_runner::Config {
    let mut c = proptest::test_runner::Config::with_cases(cases);
    if std::env::var_os("PROPTEST_RNG_SEED").is_none() {
        c.rng_seed = proptest::test_runner::RngSeed::Fixed(seed);
    }
    c
}

/// Strain paths of `V` components: 2 to `max_len − 1` points, each a random
/// increment of at most 2e-4 per component from the last (from zero).
pub fn strain_paths<const V: usize>(
    max_len: usize,
) -> impl proptest::strategy::Strategy<Value = Vec<[f64; V]>> {
    use proptest::strategy::Strategy;
    proptest::collection::vec(proptest::array::uniform::<_, V>(-2e-4f64..2e-4), 2..max_len)
        .prop_map(|incs| {
            let mut e = [0.0; V];
            incs.iter()
                .map(|d| {
                    for i in 0..V {
                        e[i] += d[i];
                    }
                    e
                })
                .collect()
        })
}

/// Asserts that `tangent` is the derivative of `stress` at `eps`: central
/// differences with steps `δε = 1e-9`, every entry to `tol` (a stiffness).
pub fn assert_tangent_is_the_derivative<const V: usize>(
    tangent: &[[f64; V]; V],
    eps: [f64; V],
    stress: impl Fn([f64; V]) -> [f64; V],
    tol: f64,
) {
    let h = 1e-9;
    for j in 0..V {
        let (mut ep, mut em) = (eps, eps);
        ep[j] += h;
        em[j] -= h;
        let (sp, sm) = (stress(ep), stress(em));
        for i in 0..V {
            let fd = (sp[i] - sm[i]) / (2.0 * h);
            assert!(
                (fd - tangent[i][j]).abs() < tol,
                "D[{i}][{j}] = {} vs finite difference {fd} at ε = {eps:?}",
                tangent[i][j]
            );
        }
    }
}

/// One material-point update of `m` from `state_n` to the strain `eps` (step 1e-4 s,
/// element size 0.1 m) in the idealisation `K`: the response and the new
/// state (as many values as `state_n`).
pub fn point_update<const V: usize, K: rothe::fe::StrainSpace<V>>(
    m: &Material,
    eps_n: [f64; V],
    eps: [f64; V],
    state_n: &[f64],
) -> (rothe::material::PointResponse<V>, Vec<f64>) {
    let mut st = vec![0.0; state_n.len()];
    let r = m.update::<V, K>(
        &rothe::material::StrainStep {
            eps_n,
            eps,
            dt: 1e-4,
            length: 0.1,
            tangent: true,
        },
        state_n,
        &mut st,
    );
    (r, st)
}

/// Asserts that the consistent tangent of `m`'s update from `state_n` (strain
/// `eps_n` to `eps`) in the idealisation `K` is the derivative of its stress:
/// central differences with δε = 1e-9, within `tol`. The one tangent check of every
/// model in plane stress, plane strain and solids.
pub fn assert_point_tangent<const V: usize, K: rothe::fe::StrainSpace<V>>(
    m: &Material,
    eps_n: [f64; V],
    eps: [f64; V],
    state_n: &[f64],
    tol: f64,
) {
    let (r, _) = point_update::<V, K>(m, eps_n, eps, state_n);
    assert_tangent_is_the_derivative(
        &r.tangent,
        eps,
        |e| point_update::<V, K>(m, eps_n, e, state_n).0.sigma,
        tol,
    );
}

/// The model of a scenario given as text (mesh paths relative to the working
/// directory); panics with the validation error.
pub fn model(text: &str) -> Model {
    rothe::config::from_str(text, std::path::Path::new(".")).unwrap()
}

/// Runs the `rothe` command with `args`: whether it succeeded, its standard output
/// and its standard error.
pub fn rothe(args: &[&str]) -> (bool, String, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_rothe"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

/// `rothe CMD SCENARIO --out OUT --quiet EXTRA…`: whether it succeeded, and its
/// standard error.
pub fn rothe_quiet(
    cmd: &str,
    sc: &std::path::Path,
    out: &std::path::Path,
    extra: &[&str],
) -> (bool, String) {
    let mut args = vec![
        cmd,
        sc.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ];
    args.extend_from_slice(extra);
    let (ok, _, err) = rothe(&args);
    (ok, err)
}

/// Writes the scenario `text` to `dir/name` and returns its path.
pub fn scenario(dir: &std::path::Path, name: &str, text: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}
