//! Fuzzing the inputs: the example scenario and material-point files, mutated
//! (numbers replaced by 0, negatives, huge values, NaN and infinities; keys removed
//! or duplicated; arrays emptied; set names changed), then checked, run for a few
//! steps, or driven along their path. Every outcome must be a success or an error
//! message: never a panic, never a non-finite number reported as a success, never an
//! allocation beyond the memory limit (2 GB here, so a huge mesh is refused).
//!
//! `FUZZ_SHOW=1` prints every refusal. A few hundred seeded cases run by default;
//! `cargo test --release --test fuzz -- --ignored` runs a long campaign (20,000
//! cases, about 15 s).

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use rothe::config::LoadOptions;
use rothe::linsolve::Backend;
use rothe::model::{AnalysisKind, TimeScheme};
use rothe::time::backward_euler::BackwardEuler;
use rothe::time::central_difference::CentralDifference;
use rothe::time::statics::Statics;
use rothe::time::{Integrator, StepOutcome};

const LIMIT: u64 = 2_000_000_000;

fn examples(dir: &str) -> Vec<(PathBuf, String)> {
    let d = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
    let mut v: Vec<(PathBuf, String)> = std::fs::read_dir(&d)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .map(|p| {
            let t = std::fs::read_to_string(&p).unwrap();
            (p, t)
        })
        .collect();
    v.sort();
    v
}

/// What to do to one file.
#[derive(Clone, Debug)]
enum Mutation {
    /// Replace the `k`-th number (modulo their count) by `value`.
    Number(usize, f64),
    /// Multiply the `k`-th number by a factor near one (mostly a valid file, which
    /// then runs).
    Scale(usize, f64),
    /// Remove the `k`-th key.
    Remove(usize),
    /// Empty the `k`-th array.
    Empty(usize),
    /// Rename the `k`-th string that names a set or a material.
    Rename(usize),
    /// Duplicate the `k`-th line (a duplicated key is a parse error).
    Duplicate(usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let values = prop_oneof![
        Just(0.0),
        Just(-1.0),
        Just(-1e-3),
        Just(1e300),
        Just(-1e300),
        Just(1e12),
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(f64::NEG_INFINITY),
        Just(1e-300),
        Just(2.5),
    ];
    prop_oneof![
        6 => (0usize..200, values).prop_map(|(k, v)| Mutation::Number(k, v)),
        3 => (0usize..200, 0.5f64..2.0).prop_map(|(k, f)| Mutation::Scale(k, f)),
        2 => (0usize..200).prop_map(Mutation::Remove),
        1 => (0usize..200).prop_map(Mutation::Empty),
        1 => (0usize..200).prop_map(Mutation::Rename),
        1 => (0usize..200).prop_map(Mutation::Duplicate),
    ]
}

/// Whether `x` is a candidate of mutation `m`.
fn candidate(m: &Mutation, x: &toml::Value) -> bool {
    match (m, x) {
        (
            Mutation::Number(..) | Mutation::Scale(..),
            toml::Value::Integer(_) | toml::Value::Float(_),
        ) => true,
        (Mutation::Remove(_), toml::Value::Table(t)) => !t.is_empty(),
        (Mutation::Empty(_), toml::Value::Array(a)) => !a.is_empty(),
        (Mutation::Rename(_), toml::Value::String(_)) => true,
        _ => false,
    }
}

/// Walks the tree in a fixed order, counting candidates; mutates the one numbered
/// `target`.
fn walk(x: &mut toml::Value, m: &Mutation, target: Option<usize>, count: &mut usize) {
    if candidate(m, x) {
        if Some(*count) == target {
            match (m, &mut *x) {
                (Mutation::Number(_, value), x) => {
                    *x = if matches!(x, toml::Value::Integer(_)) && value.is_finite() {
                        toml::Value::Integer(value.clamp(-9e18, 9e18) as i64)
                    } else {
                        toml::Value::Float(*value)
                    }
                }
                (Mutation::Scale(_, f), toml::Value::Integer(i)) => {
                    *i = ((*i as f64) * f).round() as i64
                }
                (Mutation::Scale(_, f), toml::Value::Float(x)) => *x *= f,
                (Mutation::Remove(k), toml::Value::Table(t)) => {
                    let key = t.keys().nth(k % t.len()).cloned().unwrap();
                    t.remove(&key);
                }
                (Mutation::Empty(_), toml::Value::Array(a)) => a.clear(),
                (Mutation::Rename(_), toml::Value::String(s)) => s.push_str(".x"),
                _ => {}
            }
        }
        *count += 1;
    }
    match x {
        toml::Value::Table(t) => {
            for (_, v) in t.iter_mut() {
                walk(v, m, target, count);
            }
        }
        toml::Value::Array(a) => {
            for v in a.iter_mut() {
                walk(v, m, target, count);
            }
        }
        _ => {}
    }
}

fn apply(text: &str, m: &Mutation) -> String {
    let k = match m {
        Mutation::Duplicate(k) => {
            let lines: Vec<&str> = text.lines().collect();
            let k = k % lines.len();
            let mut out = lines.clone();
            out.insert(k, lines[k]);
            return out.join("\n");
        }
        Mutation::Number(k, _)
        | Mutation::Scale(k, _)
        | Mutation::Remove(k)
        | Mutation::Empty(k)
        | Mutation::Rename(k) => *k,
    };
    let Ok(mut v) = toml::from_str::<toml::Value>(text) else {
        return text.to_string();
    };
    let mut count = 0;
    walk(&mut v, m, None, &mut count);
    if count == 0 {
        return text.to_string();
    }
    let mut seen = 0;
    walk(&mut v, m, Some(k % count), &mut seen);
    toml::to_string(&v).unwrap_or_default()
}

/// Checks, then runs a few steps of, a scenario text; panics are the failures.
fn exercise_scenario(text: &str, dir: &Path) -> Result<(), String> {
    let opts = LoadOptions {
        memory_limit: Some(LIMIT),
        allow_unstable: false,
    };
    let model = match rothe::config::from_str_with(text, dir, &opts) {
        Ok(m) => m,
        Err(e) => {
            if std::env::var_os("FUZZ_SHOW").is_some() {
                eprintln!("refused: {e}");
            }
            REFUSED.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            return (!e.to_string().is_empty())
                .then_some(())
                .ok_or("empty error".into());
        }
    };
    STEPPED.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    if rothe::check::report(&model, Some(LIMIT)).is_err() {
        return Ok(());
    }
    let mut integrator: Box<dyn Integrator> = match model.analysis.kind {
        AnalysisKind::Dynamic if model.analysis.scheme == TimeScheme::CentralDifference => {
            match CentralDifference::new(&model) {
                Ok(i) => Box::new(i),
                Err(_) => return Ok(()),
            }
        }
        AnalysisKind::Dynamic => {
            match BackwardEuler::with_memory_limit(&model, Backend::Faer, Some(LIMIT)) {
                Ok(i) => Box::new(i),
                Err(_) => return Ok(()),
            }
        }
        AnalysisKind::Static => {
            match Statics::with_memory_limit(&model, Backend::Faer, Some(LIMIT)) {
                Ok(i) => Box::new(i),
                Err(_) => return Ok(()),
            }
        }
    };
    let Ok(mut s) = integrator.initial_state() else {
        return Ok(());
    };
    for _ in 0..3 {
        match integrator.step(&mut s) {
            Ok(StepOutcome::Accepted(r)) => {
                if !r.nl_residual.is_finite()
                    || s.u.iter().any(|x| !x.is_finite())
                    || s.ledger.first_non_finite().is_some()
                {
                    return Err(format!("a non-finite state accepted: {r:?}"));
                }
            }
            Ok(StepOutcome::Rejected(r)) => {
                if r.message.is_empty() {
                    return Err("a rejection without a message".into());
                }
                break;
            }
            Err(e) => {
                if e.to_string().is_empty() {
                    return Err("an empty error".into());
                }
                break;
            }
        }
    }
    Ok(())
}

/// Drives a material-point file for at most a few hundred steps.
fn exercise_material(text: &str) -> Result<(), String> {
    let Ok(spec) = toml::from_str::<rothe::material::point_driver::DriverFile>(text) else {
        return Ok(());
    };
    let Ok(mat) = rothe::config::material("point", "material", &spec.material) else {
        return Ok(());
    };
    let mut n = 0;
    let r = rothe::material::point_driver::run_path_with(&mat, &spec.path, |rec| {
        if rec.response.sigma.iter().any(|x| !x.is_finite()) {
            return Err(rothe::Error::Internal("non-finite stress passed on".into()));
        }
        n += 1;
        if n > 300 {
            return Err(rothe::Error::Stepping("enough".into()));
        }
        Ok(())
    });
    match r {
        Err(rothe::Error::Internal(m)) => Err(m),
        _ => Ok(()),
    }
}

static STEPPED: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
static REFUSED: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

fn campaign(cases: u32) {
    let mut scenarios = examples("examples/scenarios");
    scenarios.extend(examples("examples/contact"));
    scenarios.extend(examples("examples/explicit"));
    let materials = examples("examples/materials");
    let all: Vec<(PathBuf, String, bool)> = scenarios
        .into_iter()
        .map(|(p, t)| (p, t, true))
        .chain(materials.into_iter().map(|(p, t)| (p, t, false)))
        .collect();
    let mut config = Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    };
    // The same cases every run (CI is reproducible); `PROPTEST_RNG_SEED` explores
    // others.
    if std::env::var_os("PROPTEST_RNG_SEED").is_none() {
        config.rng_seed = proptest::test_runner::RngSeed::Fixed(0x5eed_0002);
    }
    let mut runner = TestRunner::new(config);
    let strategy = (0..all.len(), proptest::collection::vec(mutation(), 1..3));
    runner
        .run(&strategy, |(file, mutations)| {
            let (path, text, is_scenario) = &all[file];
            let mut t = text.clone();
            for m in &mutations {
                t = apply(&t, m);
            }
            let dir = path.parent().unwrap().to_path_buf();
            let outcome = catch_unwind(AssertUnwindSafe(|| {
                if *is_scenario {
                    exercise_scenario(&t, &dir)
                } else {
                    exercise_material(&t)
                }
            }));
            match outcome {
                Ok(Ok(())) => Ok(()),
                Ok(Err(why)) => Err(TestCaseError::fail(format!(
                    "{}: {why}\n{t}",
                    path.display()
                ))),
                Err(p) => Err(TestCaseError::fail(format!(
                    "{}: panic: {}\n{t}",
                    path.display(),
                    rothe::run::panic_message(p.as_ref())
                ))),
            }
        })
        .unwrap_or_else(|e| {
            // The hook is quiet: say what failed before failing.
            eprintln!("{e}");
            panic!("the campaign failed: {e}")
        });
    let (stepped, refused) = (
        STEPPED.load(std::sync::atomic::Ordering::Relaxed),
        REFUSED.load(std::sync::atomic::Ordering::Relaxed),
    );
    eprintln!("scenarios run {stepped}, refused {refused}; the rest material paths");
    assert!(
        stepped > 0 && refused > 0,
        "the campaign reaches both outcomes"
    );
}

#[test]
fn mutated_examples_never_panic_or_pass_non_finite_results() {
    // Quiet the default hook: the panics are caught and reported as failures.
    std::panic::set_hook(Box::new(|_| {}));
    campaign(300);
}

#[test]
#[ignore]
fn mutated_examples_long_campaign() {
    std::panic::set_hook(Box::new(|_| {}));
    campaign(20_000);
}
