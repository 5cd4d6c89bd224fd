//! The nodal-field path of the linear viscoelastic models (`viscoelastic_state =
//! "nodal"`, a step of matrix-vector products) against the Gauss-point path
//! (`"points"`): the same displacements, forces and ledger lines at every step to
//! round-off, and the Gauss-point state built from the fields for output equal to the
//! one the Gauss-point path keeps.

use rothe::linsolve::Backend;
use rothe::model::Model;
use rothe::time::backward_euler::BackwardEuler;
use rothe::time::statics::Statics;
use rothe::time::{Integrator, State};

/// The regression scenario with Rayleigh and mass damping, gravity, an initial
/// velocity, a prescribed displacement ramp and an elastic steel rebar (two material
/// groups), its concrete given by `concrete`, on the path `state`.
fn beam(concrete: &str, mass: &str, state: &str) -> Model {
    let text = std::fs::read_to_string("tests/regression/damped_lumped_gravity.toml")
        .unwrap()
        .replace(
            "model = \"kelvin_voigt\"\nE = 33e9\nnu = 0.2\nrho = 2500.0\nbeta = 1.0e6",
            &format!("{concrete}\nE = 33e9\nnu = 0.2\nrho = 2500.0"),
        )
        .replace("mass = \"lumped\"", &format!("mass = \"{mass}\""))
        .replace(
            "[analysis]\n",
            &format!("[analysis]\nviscoelastic_state = \"{state}\"\n"),
        );
    assert!(text.contains(concrete), "the concrete block was replaced");
    rothe::config::from_str(&text, std::path::Path::new(".")).unwrap()
}

/// The largest entry of `a − b` over the largest entry of `b`.
fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let diff = a
        .iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    if scale == 0.0 {
        diff
    } else {
        diff / scale
    }
}

/// The ledger lines a run books.
fn lines(s: &State) -> [f64; 7] {
    let l = &s.ledger;
    let d = l.dissipated();
    [
        l.kinetic(),
        l.elastic(),
        l.external_work(),
        d.viscous,
        d.numerical,
        d.mass,
        d.total(),
    ]
}

/// Steps both paths side by side, comparing every step, and the Gauss-point state
/// built from the fields every `every` steps.
fn compare<I: Integrator>(mut nodal: I, mut points: I, every: usize, what: &str) {
    let mut a = nodal.initial_state().unwrap();
    let mut b = points.initial_state().unwrap();
    assert!(
        a.points.is_empty() && !a.nodal.is_empty(),
        "{what}: nodal path"
    );
    assert!(
        !b.points.is_empty() && b.nodal.is_empty(),
        "{what}: points path"
    );
    let n = nodal.model().analysis.n_steps();
    for step in 0..=n {
        if step > 0 {
            nodal.step_accepted(&mut a).unwrap();
            points.step_accepted(&mut b).unwrap();
        }
        for (x, y, name) in [
            (&a.u, &b.u, "u"),
            (&a.v, &b.v, "v"),
            (&a.f_int, &b.f_int, "f_int"),
            (&a.f_ext, &b.f_ext, "f_ext"),
        ] {
            let d = rel_diff(x, y);
            assert!(d < 1e-11, "{what}, step {step}: {name} differs by {d:e}");
        }
        let (la, lb) = (lines(&a), lines(&b));
        let scale = a.ledger.scale();
        for (k, (x, y)) in la.iter().zip(&lb).enumerate() {
            assert!(
                (x - y).abs() <= 1e-11 * scale,
                "{what}, step {step}: ledger line {k} {x:e} vs {y:e} (scale {scale:e})"
            );
        }
        assert!(
            a.ledger.residual().abs() <= 1e-9 * scale,
            "{what}: ledger closes"
        );
        if step % every == 0 {
            let built = nodal
                .output_points(&a)
                .expect("the nodal path builds points");
            assert_eq!(built.len(), b.points.len());
            for (bi, (x, y)) in built.iter().zip(&b.points).enumerate() {
                let (x, y) = (x.committed(), y.committed());
                assert_eq!(x.n_points(), y.n_points());
                let (mut eps, mut sig, mut hist) = (vec![], vec![], vec![]);
                let (mut eps_b, mut sig_b, mut hist_b) = (vec![], vec![], vec![]);
                for g in 0..x.n_points() {
                    eps.extend(x.eps::<3>(g));
                    sig.extend(x.sigma::<3>(g));
                    hist.extend(x.history(g));
                    eps_b.extend(y.eps::<3>(g));
                    sig_b.extend(y.sigma::<3>(g));
                    hist_b.extend(y.history(g));
                    assert!(
                        x.dissipated(g).is_nan(),
                        "no cumulative density from fields"
                    );
                }
                for (p, q, name) in [
                    (&eps, &eps_b, "strain"),
                    (&sig, &sig_b, "stress"),
                    (&hist, &hist_b, "history"),
                ] {
                    assert_eq!(p.len(), q.len());
                    let d = rel_diff(p, q);
                    assert!(
                        d < 1e-10,
                        "{what}, step {step}, block {bi}: {name} by {d:e}"
                    );
                }
            }
        }
    }
    assert!(
        nodal.output_points(&a).is_some() && points.output_points(&b).is_none(),
        "{what}: only the nodal path builds points"
    );
}

const MODELS: [&str; 5] = [
    "model = \"kelvin_voigt\"\nbeta = 1.0e6",
    "model = \"kelvin_voigt\"\nalpha = 2.0e-5",
    "model = \"sls\"\nalpha = 0.5\nbeta = 1.0e-4",
    "model = \"maxwell\"\nbeta = 2.0e-4",
    "model = \"kelvin\"\nbeta = 1.0e-5",
];

#[test]
fn nodal_fields_give_the_gauss_point_path_step_by_step() {
    for concrete in MODELS {
        for mass in ["lumped", "consistent"] {
            let what = format!("{concrete} ({mass} mass)");
            let (ma, mb) = (
                beam(concrete, mass, "nodal"),
                beam(concrete, mass, "points"),
            );
            let a = BackwardEuler::new(&ma, Backend::Faer).unwrap();
            let b = BackwardEuler::new(&mb, Backend::Faer).unwrap();
            compare(a, b, 10, &what);
        }
    }
}

#[test]
fn nodal_fields_follow_a_step_change_and_statics() {
    // A step size change mid-run: the recursion's k = h α/β follows the new h.
    let concrete = MODELS[2];
    let (ma, mb) = (
        beam(concrete, "lumped", "nodal"),
        beam(concrete, "lumped", "points"),
    );
    let mut a = BackwardEuler::new(&ma, Backend::Faer).unwrap();
    let mut b = BackwardEuler::new(&mb, Backend::Faer).unwrap();
    let (mut sa, mut sb) = (a.initial_state(), b.initial_state());
    for k in 0..30 {
        if k == 10 {
            a.set_step(0.5 * ma.analysis.time.dt).unwrap();
            b.set_step(0.5 * mb.analysis.time.dt).unwrap();
        }
        a.step_accepted(&mut sa).unwrap();
        b.step_accepted(&mut sb).unwrap();
        let d = rel_diff(&sa.u, &sb.u);
        assert!(d < 1e-11, "step {k}: u differs by {d:e}");
        let (la, lb) = (lines(&sa), lines(&sb));
        for (x, y) in la.iter().zip(&lb) {
            assert!((x - y).abs() <= 1e-11 * sa.ledger.scale());
        }
    }

    // Statics: the material rates use the load step.
    let text = |state: &str| {
        std::fs::read_to_string("tests/regression/static_ramp.toml")
            .unwrap()
            .replacen(
                "model = \"elastic\"\nE = 30e9",
                "model = \"sls\"\nalpha = 1.0\nbeta = 0.3\nE = 30e9",
                1,
            )
            .replace(
                "[analysis]\n",
                &format!("[analysis]\nviscoelastic_state = \"{state}\"\n"),
            )
    };
    let ma = rothe::config::from_str(&text("nodal"), std::path::Path::new(".")).unwrap();
    let mb = rothe::config::from_str(&text("points"), std::path::Path::new(".")).unwrap();
    let a = Statics::new(&ma, Backend::Faer).unwrap();
    let b = Statics::new(&mb, Backend::Faer).unwrap();
    compare(a, b, 2, "static standard linear solid");
}

/// The cell arrays of a VTK file, read back as a VTK reader would.
fn cell_arrays(path: &std::path::Path) -> Vec<(String, Vec<f64>)> {
    let vtk = vtkio::Vtk::import(path).unwrap();
    let vtkio::model::DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
        panic!("not a grid")
    };
    let vtkio::model::Piece::Inline(piece) = &pieces[0] else {
        panic!("piece not inline")
    };
    piece
        .data
        .cell
        .iter()
        .filter_map(|a| match a {
            vtkio::model::Attribute::DataArray(d) => {
                Some((d.name.clone(), d.data.clone().cast_into::<f64>()?))
            }
            _ => None,
        })
        .collect()
}

#[test]
fn vtk_of_the_nodal_path_has_the_stress_of_the_gauss_point_path() {
    // The files users open: the same cell stresses either way; the cumulative
    // dissipation density is a field of the Gauss-point path only.
    let dir = tempfile::tempdir().unwrap();
    let mut arrays = Vec::new();
    for state in ["nodal", "points"] {
        let mut m = beam(MODELS[2], "lumped", state);
        m.analysis.output.vtk_every = 10;
        let out = dir.path().join(state);
        let summary =
            rothe::run::run(&m, &rothe::run::RunOptions::new(&out, Backend::Faer)).unwrap();
        assert_eq!(summary.status, rothe::output::summary::RunStatus::Completed);
        arrays.push(cell_arrays(&out.join("vtk/step_0000030.vtu")));
    }
    let get = |k: usize, name: &str| {
        arrays[k]
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.clone())
    };
    let (a, b) = (get(0, "stress").unwrap(), get(1, "stress").unwrap());
    assert_eq!(a.len(), b.len());
    assert!(a.iter().any(|x| x.abs() > 0.0));
    let d = rel_diff(&a, &b);
    assert!(d < 1e-10, "cell stress differs by {d:e}");
    assert!(get(0, "dissipation_density").is_none());
    let density = get(1, "dissipation_density").unwrap();
    assert!(density.iter().any(|&x| x > 0.0));
}
