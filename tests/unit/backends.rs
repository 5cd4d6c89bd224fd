//! The linear solver backends: each solves SPD matrices to round-off, refactorises on
//! a fixed pattern, solves blocks of right-hand sides as the single solves, names the
//! column of a non-positive pivot, refuses bad input with an error (not a panic), and
//! uses a given elimination order as it is. With the `cholmod` feature, CHOLMOD and
//! faer also agree with each other on matrices, static and dynamic runs and their
//! ledgers. A plain `cargo test` runs the faer half.

use std::path::Path;
#[cfg(feature = "cholmod")]
use std::time::Instant;

use rothe::assembly::{Assembler, Mass};
#[cfg(feature = "cholmod")]
use rothe::linsolve::cholmod_backend::CholmodCholesky;
use rothe::linsolve::faer_backend::FaerCholesky;
use rothe::linsolve::{Backend, LowerCsc, SymmetricSolver};
use rothe::model::Model;
use rothe::system::{DofMap, ReducedMatrix};
#[cfg(feature = "cholmod")]
use rothe::time::backward_euler::BackwardEuler;
use rothe::time::statics;
#[cfg(feature = "cholmod")]
use rothe::time::Integrator;

const TOL: f64 = 1e-10;

/// A fresh solver of every backend this build has.
fn backends() -> Vec<Box<dyn SymmetricSolver>> {
    #[allow(unused_mut)] // pushed to only with the cholmod feature
    let mut v: Vec<Box<dyn SymmetricSolver>> = vec![Box::new(FaerCholesky::new())];
    #[cfg(feature = "cholmod")]
    v.push(Box::new(CholmodCholesky::new().expect("cholmod starts")));
    // In this process alone: an MPI session of one rank (tests/mpi.rs runs the
    // backend on two ranks through mpirun).
    #[cfg(feature = "mumps")]
    v.push(Box::new(
        rothe::linsolve::mumps::MumpsCholesky::new().expect("mumps starts"),
    ));
    v
}

/// `max|a − b| / max|b|`.
fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let num = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    let den = b.iter().map(|y| y.abs()).fold(0.0, f64::max);
    if den == 0.0 {
        num
    } else {
        num / den
    }
}

/// Lower triangle of the 5-point Laplacian on an `m × m` grid plus `shift · I`.
fn laplacian(m: usize, shift: f64) -> LowerCsc {
    let n = m * m;
    let mut col_ptr = vec![0];
    let mut row_idx = Vec::new();
    let mut values = Vec::new();
    for j in 0..n {
        let (x, y) = (j % m, j / m);
        row_idx.push(j);
        values.push(4.0 + shift);
        if x + 1 < m {
            row_idx.push(j + 1);
            values.push(-1.0);
        }
        if y + 1 < m {
            row_idx.push(j + m);
            values.push(-1.0);
        }
        col_ptr.push(row_idx.len());
    }
    LowerCsc {
        n,
        col_ptr,
        row_idx,
        values,
    }
}

/// A deterministic, non-trivial right-hand side.
fn rhs(n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| ((i as f64) * 0.37).sin() + 0.1 * (i % 7) as f64)
        .collect()
}

fn solve_with(solver: &mut dyn SymmetricSolver, a: &LowerCsc, b: &[f64]) -> Vec<f64> {
    solver.analyze(a).expect("analyze");
    solver.factorize(a).expect("factorize");
    let mut x = b.to_vec();
    solver.solve_in_place(&mut x).expect("solve");
    x
}

/// Relative residual `|A x − b|∞ / |b|∞`.
fn residual(a: &LowerCsc, x: &[f64], b: &[f64]) -> f64 {
    let mut ax = vec![0.0; a.n];
    a.sym_matvec(x, &mut ax);
    rel_diff(&ax, b)
}

fn cantilever_text(kind: &str, divisions: [usize; 2], t_end: f64) -> String {
    crate::workload::cantilever_scenario(
        divisions,
        1e-5,
        t_end,
        "model = \"elastic\"\nE = 30e9\nnu = 0.2\nrho = 2400.0",
        &format!("kind = \"{kind}\"\nplane = \"stress\"\nmass = \"consistent\"\nvtk_every = 0"),
    )
}

fn cantilever(kind: &str, divisions: [usize; 2], t_end: f64) -> Model {
    rothe::config::from_str(&cantilever_text(kind, divisions, t_end), Path::new("."))
        .expect("valid scenario")
}

use crate::workload::effective_matrix;

fn stiffness_matrix(model: &Model) -> LowerCsc {
    let n = model.mesh.n_dofs();
    let asm = Assembler::new(&model.mesh);
    let k = asm.stiffness(&model.mesh, &model.materials, model.idealisation);
    let dofs = DofMap::new(n, model.constraints.iter().map(|c| c.dof));
    let mut reduced = ReducedMatrix::new(&asm.pattern, &dofs);
    reduced.fill(&dofs, 0.0, &Mass::Lumped(vec![0.0; n]), &[(1.0, &k)]);
    reduced.csc
}

fn test_matrices() -> Vec<(&'static str, LowerCsc)> {
    let model = cantilever("dynamic", [20, 6], 1e-4);
    let h: f64 = 1e-5;
    vec![
        ("1x1", laplacian(1, 1.0)),
        ("laplacian 12x12 + 0.01 I", laplacian(12, 0.01)),
        ("laplacian 40x40 + 1e-3 I", laplacian(40, 1e-3)),
        (
            "cantilever K_eff",
            effective_matrix(&model, 1.0 / (h * h), 1.0),
        ),
        ("cantilever K", stiffness_matrix(&model)),
    ]
}

#[test]
fn every_backend_solves_spd_matrices() {
    for (name, a) in test_matrices() {
        let b = rhs(a.n);
        let mut reference: Option<Vec<f64>> = None;
        for mut solver in backends() {
            let x = solve_with(solver.as_mut(), &a, &b);
            let r = residual(&a, &x, &b);
            assert!(r < 1e-8, "{name}: {} residual {r:e}", solver.name());
            let nnz = solver.factor_nnz().unwrap();
            assert!(nnz >= a.row_idx.len(), "{name}: nnz(L) {nnz} below nnz(A)");
            match &reference {
                None => reference = Some(x),
                Some(x0) => {
                    let d = rel_diff(&x, x0);
                    assert!(
                        d < TOL,
                        "{name}: {} differs from faer by {d:e}",
                        solver.name()
                    );
                }
            }
        }
    }
}

#[test]
fn block_solves_equal_the_single_solves() {
    // Eight right-hand sides solved as one block (the factor is read once) give the
    // eight single solves.
    let model = cantilever("dynamic", [20, 6], 1e-4);
    let h: f64 = 1e-5;
    let a = effective_matrix(&model, 1.0 / (h * h), 1.0);
    let k = 8;
    let block: Vec<f64> = (0..a.n * k)
        .map(|i| ((i as f64) * 0.13).cos() + (i % 11) as f64 * 0.01)
        .collect();
    for mut solver in backends() {
        solver.analyze(&a).unwrap();
        solver.factorize(&a).unwrap();
        let mut x = block.clone();
        solver.solve_block_in_place(&mut x, k).unwrap();
        for c in 0..k {
            let mut y = block[c * a.n..(c + 1) * a.n].to_vec();
            solver.solve_in_place(&mut y).unwrap();
            let d = rel_diff(&x[c * a.n..(c + 1) * a.n], &y);
            assert!(d < 1e-13, "{}: column {c} differs by {d:e}", solver.name());
        }
        assert!(solver.solve_block_in_place(&mut x[1..], k).is_err());
    }
}

#[test]
fn a_given_ordering_is_used_as_it_is() {
    // The nested dissection handed to the solver is the order it factorises in, on
    // both backends: a comparison of the two compares factorisation codes.
    let model = cantilever("dynamic", [40, 10], 1e-4);
    let asm = Assembler::new(&model.mesh);
    let dofs = DofMap::new(model.mesh.n_dofs(), model.constraints.iter().map(|c| c.dof));
    let reduced = ReducedMatrix::new(&asm.pattern, &dofs);
    let order = reduced.nested_dissection(&dofs, &model.mesh.coords);
    let h: f64 = 1e-5;
    let a = effective_matrix(&model, 1.0 / (h * h), 1.0);
    let b = rhs(a.n);
    for mut solver in backends() {
        solver.set_ordering(order.clone());
        let x = solve_with(solver.as_mut(), &a, &b);
        if solver.name() == "mumps" {
            // MUMPS builds its assembly tree from the given order and postorders
            // it, which keeps the fill but not the sequence: its order is a
            // permutation, other than its own AMD one.
            let used = solver.ordering().expect("mumps reports its order");
            assert!(rothe::linsolve::inverse_order(&used).is_some());
            let mut amd = backends().pop().unwrap();
            solve_with(amd.as_mut(), &a, &b);
            assert_ne!(amd.ordering(), Some(used));
        } else {
            assert_eq!(
                solver.ordering().as_deref(),
                Some(&order[..]),
                "{}",
                solver.name()
            );
        }
        assert!(residual(&a, &x, &b) < 1e-8);
    }
}

#[test]
fn refactorisation_on_the_same_pattern() {
    let model = cantilever("dynamic", [20, 6], 1e-4);
    let a0 = effective_matrix(&model, 1e10, 1.0);
    let b = rhs(a0.n);
    for mut solver in backends() {
        let name = solver.name();
        solver.analyze(&a0).unwrap();
        let nnz0 = solver.factor_nnz();
        // Several value sets on one analysis: the step size changes as in `set_step`.
        for h in [1e-5, 3e-5, 1e-4, 2e-6] {
            let a = effective_matrix(&model, 1.0 / (h * h), 1.0);
            solver.factorize(&a).unwrap();
            let mut fresh = FaerCholesky::new();
            for scale in [1.0, -2.5] {
                let bs: Vec<f64> = b.iter().map(|v| v * scale).collect();
                let mut x = bs.clone();
                solver.solve_in_place(&mut x).unwrap();
                let x_ref = solve_with(&mut fresh, &a, &bs);
                let d = rel_diff(&x, &x_ref);
                assert!(
                    d < TOL,
                    "{name}: h = {h:e}, scale {scale}: differs by {d:e}"
                );
            }
        }
        assert_eq!(
            solver.factor_nnz(),
            nnz0,
            "{name}: refactorisation changed the pattern"
        );

        // Refactorising the Laplacian with new values too.
        let mut l = laplacian(30, 0.5);
        solver.analyze(&l).unwrap();
        for shift in [0.5, 1e-4, 10.0] {
            for (p, v) in l.values.iter_mut().enumerate() {
                if *v > 0.0 {
                    *v = 4.0 + shift + 1e-3 * (p % 5) as f64;
                }
            }
            solver.factorize(&l).unwrap();
            let mut x = rhs(l.n);
            solver.solve_in_place(&mut x).unwrap();
            let x_ref = solve_with(&mut FaerCholesky::new(), &l, &rhs(l.n));
            assert!(rel_diff(&x, &x_ref) < TOL, "{name}: shift {shift}");
        }
    }
}

#[test]
fn not_positive_definite_is_an_error() {
    for mut solver in backends() {
        let name = solver.name();
        // Indefinite: the Laplacian shifted below its smallest eigenvalue.
        let mut a = laplacian(10, -1.0);
        solver.analyze(&a).unwrap();
        let e = solver
            .factorize(&a)
            .expect_err("indefinite matrix must fail");
        let msg = e.to_string();
        assert!(msg.contains(name), "{msg}");
        assert!(msg.contains("not positive definite"), "{msg}");
        // MUMPS factorises through a negative pivot and counts them (INFOG(12)):
        // the count is the matrix's number of negative eigenvalues (Sylvester), 6
        // here; it cannot name a column.
        if name == "mumps" {
            assert!(msg.contains("6 negative pivots"), "{msg}");
        } else {
            assert!(msg.contains("column"), "{msg}");
        }
        assert!(
            matches!(e, rothe::Error::NotPositiveDefinite { .. }),
            "{e:?}"
        );
        // No solve with a failed factor.
        let mut x = rhs(a.n);
        assert!(solver.solve_in_place(&mut x).is_err());

        // The same analysis still works once the values are fixed.
        for v in a.values.iter_mut().filter(|v| **v > 0.0) {
            *v = 5.0;
        }
        solver.factorize(&a).unwrap();
        let b = rhs(a.n);
        let mut x = b.clone();
        solver.solve_in_place(&mut x).unwrap();
        assert!(residual(&a, &x, &b) < 1e-12);

        // A single negative pivot, named by its column: whatever the elimination
        // order, the first pivot to fail is that column's (the pivots eliminated
        // before it do not see its value).
        let mut d = laplacian(4, 1.0);
        let p = d.col_ptr[9];
        d.values[p] = -1.0;
        let mut fresh = backends().into_iter().find(|s| s.name() == name).unwrap();
        fresh.analyze(&d).unwrap();
        match fresh.factorize(&d) {
            // One diagonal entry changed is a rank-one change: one negative
            // eigenvalue, so one negative pivot.
            Err(rothe::Error::NotPositiveDefinite {
                column: None,
                message,
                ..
            }) if name == "mumps" => assert!(message.contains("1 negative pivot:"), "{message}"),
            Err(rothe::Error::NotPositiveDefinite {
                column, message, ..
            }) => {
                assert_eq!(column, Some(9), "{name}: {message}");
                assert!(message.contains("column 9"), "{message}");
            }
            other => panic!("{name}: expected a pivot error, got {other:?}"),
        }

        // The cantilever without its supports: singular stiffness.
        let mut free_model = cantilever("static", [8, 2], 1e-4);
        free_model.constraints.clear();
        let k = stiffness_matrix(&free_model);
        let mut fresh = backends().into_iter().find(|s| s.name() == name).unwrap();
        fresh.analyze(&k).unwrap();
        assert!(
            fresh.factorize(&k).is_err(),
            "{name}: singular stiffness must fail"
        );
        // The static driver reports it as an error too, naming the likely cause.
        let backend: Backend = name.parse().unwrap();
        let e = statics::solve(&free_model, backend, &[0.0]).unwrap_err();
        assert!(e.to_string().contains("supports"), "{e}");
    }
}

#[test]
fn bad_input_is_an_error() {
    for mut solver in backends() {
        let name = solver.name();
        let a = laplacian(5, 1.0);
        let mut x = rhs(a.n);
        assert!(
            solver.factorize(&a).is_err(),
            "{name}: factorize before analyze"
        );
        assert!(
            solver.solve_in_place(&mut x).is_err(),
            "{name}: solve before analyze"
        );
        assert!(solver.factor_nnz().is_none());
        solver.analyze(&a).unwrap();
        assert!(
            solver.solve_in_place(&mut x).is_err(),
            "{name}: solve before factorize"
        );
        solver.factorize(&a).unwrap();
        let mut short = vec![1.0; a.n - 1];
        assert!(
            solver.solve_in_place(&mut short).is_err(),
            "{name}: rhs length"
        );
        let mut x = rhs(a.n);
        solver.solve_in_place(&mut x).unwrap();
    }
}

#[cfg(feature = "cholmod")]
#[test]
fn cholmod_checks_the_pattern_it_is_given() {
    let a = laplacian(5, 1.0);
    let mut chol = CholmodCholesky::new().unwrap();
    let mut bad = a.clone();
    bad.row_idx[1] = 99;
    assert!(chol.analyze(&bad).is_err(), "row index out of range");
    let mut bad = a.clone();
    bad.row_idx[0] = 1;
    bad.row_idx[1] = 0;
    assert!(chol.analyze(&bad).is_err(), "unsorted / upper entries");
    let mut bad = a.clone();
    bad.col_ptr.pop();
    assert!(chol.analyze(&bad).is_err(), "short col_ptr");
    let mut bad = a.clone();
    bad.values.pop();
    assert!(chol.analyze(&bad).is_err(), "values length");

    chol.analyze(&a).unwrap();
    let other = laplacian(6, 1.0);
    assert!(chol.factorize(&other).is_err(), "pattern mismatch");
    let mut nan = a.clone();
    nan.values[3] = f64::NAN;
    assert!(chol.factorize(&nan).is_err(), "NaN value");
    chol.factorize(&a).unwrap();
    let mut x = rhs(a.n);
    chol.solve_in_place(&mut x).unwrap();

    // An empty system (everything constrained) is fine.
    let empty = LowerCsc {
        n: 0,
        col_ptr: vec![0],
        row_idx: vec![],
        values: vec![],
    };
    chol.analyze(&empty).unwrap();
    chol.factorize(&empty).unwrap();
    chol.solve_in_place(&mut []).unwrap();
}

#[cfg(feature = "cholmod")]
#[test]
fn static_cantilever_agrees() {
    let model = cantilever("static", [40, 10], 1e-3);
    let times = [0.0, 1e-3];
    let sf = statics::solve(&model, Backend::Faer, &times).unwrap();
    let sc = statics::solve(&model, Backend::Cholmod, &times).unwrap();
    for (f, c) in sf.iter().zip(&sc) {
        let d = rel_diff(&c.u, &f.u);
        assert!(d < TOL, "static displacements differ by {d:e}");
        assert!((c.elastic - f.elastic).abs() <= TOL * f.elastic.abs());
    }
    assert!(sf[1].u.iter().any(|&v| v != 0.0));
}

#[cfg(feature = "cholmod")]
#[test]
fn dynamic_cantilever_histories_agree() {
    let model = cantilever("dynamic", [40, 10], 2e-4);
    let mut bf = BackwardEuler::new(&model, Backend::Faer).unwrap();
    let mut bc = BackwardEuler::new(&model, Backend::Cholmod).unwrap();
    assert_eq!(bc.backend(), "cholmod");
    assert!(bc.factor_nnz().is_some());
    let mut sf = bf.initial_state();
    let mut sc = bc.initial_state();
    let steps = model.analysis.n_steps();
    assert_eq!(steps, 20);
    let mut worst: f64 = 0.0;
    for step in 1..=steps {
        bf.step_accepted(&mut sf).unwrap();
        bc.step_accepted(&mut sc).unwrap();
        let d = rel_diff(&sc.u, &sf.u);
        worst = worst.max(d);
        assert!(d < TOL, "step {step}: displacements differ by {d:e}");
        assert!(
            rel_diff(&sc.v, &sf.v) < TOL,
            "step {step}: velocities differ"
        );
        // The ledgers agree line by line, relative to the largest energy.
        let (lf, lc) = (&sf.ledger, &sc.ledger);
        let scale = lf.scale();
        let lines = |l: &rothe::energy::Ledger| {
            let d = l.dissipated();
            [
                l.kinetic(),
                l.elastic(),
                l.internal(),
                l.external_work(),
                d.numerical,
                d.mass,
                l.residual(),
            ]
        };
        for (k, (a, b)) in lines(lf).iter().zip(lines(lc)).enumerate() {
            assert!(
                (a - b).abs() <= TOL * scale,
                "step {step}: ledger line {k} differs: {a} vs {b}"
            );
        }
    }
    // A step-size change refactorises both on the same pattern.
    bf.set_step(5e-6).unwrap();
    bc.set_step(5e-6).unwrap();
    for _ in 0..5 {
        bf.step_accepted(&mut sf).unwrap();
        bc.step_accepted(&mut sc).unwrap();
        worst = worst.max(rel_diff(&sc.u, &sf.u));
    }
    assert!(worst < TOL, "after set_step: {worst:e}");
    eprintln!("dynamic: worst relative difference {worst:e}");
}

/// Probe displacement columns (`*_ux`, `*_uy`) of a `history.csv`.
#[cfg(feature = "cholmod")]
fn probe_columns(path: &Path) -> Vec<(String, Vec<f64>)> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let wanted: Vec<usize> = (0..header.len())
        .filter(|&c| header[c].ends_with("_ux") || header[c].ends_with("_uy"))
        .collect();
    let mut cols: Vec<(String, Vec<f64>)> = wanted
        .iter()
        .map(|&c| (header[c].to_string(), Vec::new()))
        .collect();
    for line in lines {
        let fields: Vec<&str> = line.split(',').collect();
        for (k, &c) in wanted.iter().enumerate() {
            cols[k].1.push(fields[c].trim().parse().unwrap());
        }
    }
    cols
}

#[cfg(feature = "cholmod")]
#[test]
fn full_run_histories_agree() {
    let model = cantilever("dynamic", [20, 5], 2e-4);
    let dir = tempfile::tempdir().unwrap();
    let mut histories = Vec::new();
    for backend in [Backend::Faer, Backend::Cholmod] {
        let out = dir.path().join(backend.name());
        let opts = rothe::run::RunOptions {
            out: out.clone(),
            backend,
            progress: false,
            memory_limit: None,
            record_fields: false,
            overwrite: true,
            hooks: Default::default(),
        };
        let summary = rothe::run::run(&model, &opts).unwrap();
        assert_eq!(summary.status, rothe::output::summary::RunStatus::Completed);
        assert_eq!(summary.solver.backend, backend.name());
        assert_eq!(summary.steps, 20);
        histories.push(probe_columns(&out.join("history.csv")));
    }
    let (hf, hc) = (&histories[0], &histories[1]);
    assert!(!hf.is_empty());
    for ((name, f), (_, c)) in hf.iter().zip(hc) {
        assert_eq!(f.len(), 21, "{name}: rows");
        // history.csv keeps 13 significant digits.
        let d = rel_diff(c, f);
        assert!(d < TOL, "{name}: histories differ by {d:e}");
    }
}

/// Factorisation and solve times of both backends on the same matrices; run with
/// `cargo test --release --features cholmod --test unit backends -- --ignored --nocapture`.
#[cfg(feature = "cholmod")]
#[test]
#[ignore]
fn timing_report() {
    let h: f64 = 1e-5;
    let cases = [
        ("cantilever 200x50 K_eff", {
            let m = cantilever("dynamic", [200, 50], 1e-4);
            effective_matrix(&m, 1.0 / (h * h), 1.0)
        }),
        ("cantilever 400x100 K_eff", {
            let m = cantilever("dynamic", [400, 100], 1e-4);
            effective_matrix(&m, 1.0 / (h * h), 1.0)
        }),
        ("laplacian 300x300", laplacian(300, 1e-3)),
    ];
    for (name, a) in cases {
        let mut solvers: Vec<Box<dyn SymmetricSolver>> = vec![
            Box::new(FaerCholesky::new()),
            Box::new(CholmodCholesky::new().unwrap()),
        ];
        let mut xs = Vec::new();
        for s in solvers.iter_mut() {
            let t = Instant::now();
            s.analyze(&a).unwrap();
            let t_an = t.elapsed().as_secs_f64();
            let reps = 5;
            let t = Instant::now();
            for _ in 0..reps {
                s.factorize(&a).unwrap();
            }
            let t_fac = t.elapsed().as_secs_f64() / reps as f64;
            let b = rhs(a.n);
            let mut x = b.clone();
            let t = Instant::now();
            let sreps = 20;
            for _ in 0..sreps {
                x.copy_from_slice(&b);
                s.solve_in_place(&mut x).unwrap();
            }
            let t_sol = t.elapsed().as_secs_f64() / sreps as f64;
            eprintln!(
                "{name} (n = {}, nnz(A) = {}): {:8} analyze {:7.2} ms, factorize {:7.2} ms, \
                 solve {:6.2} ms, nnz(L) {:?}",
                a.n,
                a.row_idx.len(),
                s.name(),
                1e3 * t_an,
                1e3 * t_fac,
                1e3 * t_sol,
                s.factor_nnz()
            );
            xs.push(x);
        }
        assert!(rel_diff(&xs[1], &xs[0]) < 1e-9);
    }
}

/// The memory check of a factorisation distributed over MPI ranks sums the ranks of
/// each node against that node's memory, adds rank 0's model on its node, and is off
/// under `--ignore-memory`.
#[test]
fn a_distributed_factor_is_checked_node_by_node() {
    use rothe::linsolve::distributed::{DistributedAnalysis, RankMemory};
    const GB: u64 = 1_000_000_000;
    let model = cantilever("dynamic", [8, 2], 1e-4);
    let rank = |rank: usize, node: &str, estimate: u64, available: u64| RankMemory {
        rank,
        node: node.into(),
        estimate,
        available: Some(available),
    };
    let analysis = |per_rank: Vec<RankMemory>| DistributedAnalysis {
        version: "test".into(),
        ranks: per_rank.len(),
        per_rank,
        ..Default::default()
    };
    let check = |d: &DistributedAnalysis, host: Option<u64>| {
        rothe::memory::check_distributed(&model, d, host, "the run")
    };
    // Each rank on a node of its own, each share fits.
    let spread = analysis(vec![
        rank(0, "a", GB, 100 * GB),
        rank(1, "b", 3 * GB, 4 * GB),
    ]);
    assert!(check(&spread, Some(100 * GB)).is_ok());
    // Node b too small for rank 1's share: refused, naming the node and the rank.
    let small = analysis(vec![
        rank(0, "a", GB, 100 * GB),
        rank(1, "b", 3 * GB, 2 * GB),
    ]);
    let e = check(&small, Some(100 * GB)).unwrap_err().to_string();
    assert!(e.contains("node b (ranks 1"), "{e}");
    assert!(e.contains("1 3.0 GB"), "{e}");
    // Two ranks sharing node b: each share fits, their sum does not.
    let shared = analysis(vec![
        rank(0, "a", GB, 100 * GB),
        rank(1, "b", 3 * GB / 2, 5 * GB / 2),
        rank(2, "b", 3 * GB / 2, 5 * GB / 2),
    ]);
    let e = check(&shared, Some(100 * GB)).unwrap_err().to_string();
    assert!(e.contains("node b (ranks 1, 2"), "{e}");
    // Rank 0's node: its share and the model against the limit given for it.
    let host = analysis(vec![rank(0, "a", 2 * GB, 100 * GB)]);
    assert!(check(&host, Some(3 * GB)).is_ok());
    let e = check(&host, Some(2 * GB)).unwrap_err().to_string();
    assert!(e.contains("rank 0's model"), "{e}");
    // `--ignore-memory`: no check.
    assert!(check(&small, None).is_ok());
}

/// `--backend mumps` in a build without the feature says how to get and run it.
#[cfg(not(feature = "mumps"))]
#[test]
fn mumps_without_the_feature_says_how_to_run_it() {
    let e = Backend::Mumps
        .solver()
        .err()
        .expect("no mumps in this build")
        .to_string();
    assert!(e.contains("--features mumps"), "{e}");
    assert!(e.contains("mpirun -n N"), "{e}");
    let e = rothe::linsolve::distributed::start(Backend::Mumps)
        .unwrap_err()
        .to_string();
    assert!(e.contains("libmumps-dev"), "{e}");
}
