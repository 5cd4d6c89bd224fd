//! Fuzzing the inputs: the example scenario and material-point files, mutated
//! (numbers replaced by 0, negatives, huge values, NaN and infinities; keys removed
//! or duplicated; arrays emptied; set names changed), then checked, run for a few
//! steps, or driven along their path. Every outcome must be a success or an error
//! message: never a panic, never a non-finite number reported as a success, never an
//! allocation beyond the memory limit (2 GB here, so a huge mesh is refused).
//!
//! The scenarios include the solids (box meshes, rigid planes, Coulomb cones) and a
//! Gmsh solid. Gmsh files are fuzzed too, a plane one and a solid one (the node and
//! element blocks of a real Gmsh mesh
//! with tags permuted, repeated, dropped or made sparse, coordinates and counts
//! corrupted, bytes cut off or flipped): read, a mesh must come out with every node
//! where its block put it, or an error. Command-line overrides (`--set`, `--unset`,
//! `--variant` with good and bad paths and values) are applied to the examples: a
//! model or an error, never a panic.
//!
//! `FUZZ_SHOW=1` prints every refusal. A few hundred seeded cases run by default;
//! `cargo test --release --test application fuzz -- --ignored` runs a long campaign (20,000
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
        distributed_factor: false,
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
    let mut integrator: Box<dyn Integrator> = match model.analysis.time.kind {
        AnalysisKind::Dynamic if model.analysis.time.scheme == TimeScheme::CentralDifference => {
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
    let Ok(spec) = toml::from_str::<rothe::point_driver::DriverFile>(text) else {
        return Ok(());
    };
    let Ok(mat) = rothe::config::material("point", "material", &spec.material) else {
        return Ok(());
    };
    let mut n = 0;
    let r = rothe::point_driver::run_path_with(&mat, &spec.path, |rec| {
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
    // Solids: box meshes, rigid planes, Coulomb cones, a Gmsh solid.
    scenarios.extend(examples("examples/solid"));
    scenarios.extend(examples("tests/data"));
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

/// A change to a Gmsh file.
#[derive(Clone, Debug)]
enum GmshMutation {
    /// Reverse the tags (and coordinates) of the `k`-th node block.
    Reverse(usize),
    /// Rotate the tag list of the `k`-th node block (coordinates stay: tags move).
    RotateTags(usize),
    /// Multiply every node tag (and every reference to it) by `f`.
    Sparse(u64),
    /// Give the `k`-th node line of a block the tag of the first.
    Repeat(usize),
    /// Replace the `k`-th number of the file by `v`.
    Number(usize, String),
    /// Cut the file after `k` bytes (modulo its length).
    Cut(usize),
    /// Flip byte `k` (modulo the length) to `b`.
    Flip(usize, u8),
}

fn gmsh_mutation() -> impl Strategy<Value = GmshMutation> {
    prop_oneof![
        (0..20usize).prop_map(GmshMutation::Reverse),
        (0..20usize).prop_map(GmshMutation::RotateTags),
        (2..50u64).prop_map(GmshMutation::Sparse),
        (0..200usize).prop_map(GmshMutation::Repeat),
        (
            0..3000usize,
            prop_oneof![
                Just("0".to_string()),
                Just("-1".to_string()),
                Just("99999999999999999999".to_string()),
                Just("nan".to_string()),
                Just("1e308".to_string()),
                Just("x".to_string()),
                Just("4".to_string()),
            ]
        )
            .prop_map(|(k, v)| GmshMutation::Number(k, v)),
        (0..20000usize).prop_map(GmshMutation::Cut),
        (0..20000usize, any::<u8>()).prop_map(|(k, b)| GmshMutation::Flip(k, b)),
    ]
}

/// A node block as text: its header line, its tag lines, its coordinate lines.
type TextBlock = (String, Vec<String>, Vec<String>);

/// The node blocks of an ASCII MSH 4.1 text: `(header line, tag lines, coordinate
/// lines)` each, with the text before and after `$Nodes`'s body.
fn node_blocks(text: &str) -> Option<(String, Vec<TextBlock>, String)> {
    let (head, rest) = text.split_once("$Nodes\n")?;
    let (body, tail) = rest.split_once("$EndNodes\n")?;
    let mut lines = body.lines();
    let first = lines.next()?.to_string();
    let mut blocks = Vec::new();
    while let Some(h) = lines.next() {
        let n: usize = h.split_whitespace().nth(3)?.parse().ok()?;
        let tags: Vec<String> = (0..n)
            .map(|_| lines.next().map(String::from))
            .collect::<Option<_>>()?;
        let xyz: Vec<String> = (0..n)
            .map(|_| lines.next().map(String::from))
            .collect::<Option<_>>()?;
        blocks.push((h.to_string(), tags, xyz));
    }
    Some((
        format!("{head}$Nodes\n{first}\n"),
        blocks,
        format!("$EndNodes\n{tail}"),
    ))
}

fn join_blocks(head: &str, blocks: &[TextBlock], tail: &str) -> String {
    let mut out = head.to_string();
    for (h, tags, xyz) in blocks {
        out += h;
        out.push('\n');
        for l in tags.iter().chain(xyz) {
            out += l;
            out.push('\n');
        }
    }
    out + tail
}

fn apply_gmsh(bytes: &[u8], m: &GmshMutation) -> Vec<u8> {
    let text = String::from_utf8_lossy(bytes).into_owned();
    let edit_blocks = |f: &dyn Fn(&mut Vec<TextBlock>)| -> Vec<u8> {
        match node_blocks(&text) {
            Some((head, mut blocks, tail)) => {
                f(&mut blocks);
                join_blocks(&head, &blocks, &tail).into_bytes()
            }
            None => bytes.to_vec(),
        }
    };
    match m {
        GmshMutation::Reverse(k) => edit_blocks(&|b| {
            let n = b.len();
            if n > 0 {
                let blk = &mut b[k % n];
                blk.1.reverse();
                blk.2.reverse();
            }
        }),
        GmshMutation::RotateTags(k) => edit_blocks(&|b| {
            let n = b.len();
            if n > 0 && !b[k % n].1.is_empty() {
                b[k % n].1.rotate_left(1);
            }
        }),
        GmshMutation::Repeat(k) => edit_blocks(&|b| {
            let n = b.len();
            if n > 0 {
                let blk = &mut b[k % n];
                if blk.1.len() > 1 {
                    let i = 1 + k % (blk.1.len() - 1);
                    blk.1[i] = blk.1[0].clone();
                }
            }
        }),
        GmshMutation::Sparse(f) => {
            // Every node tag and every element's node reference times f (the
            // element tags stay).
            let scale = |w: &str| {
                w.parse::<u64>()
                    .map(|t| (t * f).to_string())
                    .unwrap_or(w.into())
            };
            let mut t = String::from_utf8(edit_blocks(&|b| {
                for blk in b.iter_mut() {
                    for tag in blk.1.iter_mut() {
                        *tag = scale(tag.trim());
                    }
                }
            }))
            .unwrap_or_default();
            if let Some((head, rest)) = t.clone().split_once("$Elements\n") {
                if let Some((body, tail)) = rest.split_once("$EndElements\n") {
                    let mut lines = body.lines();
                    let mut out = format!("{head}$Elements\n{}\n", lines.next().unwrap_or(""));
                    while let Some(h) = lines.next() {
                        let n: usize = h
                            .split_whitespace()
                            .nth(3)
                            .and_then(|x| x.parse().ok())
                            .unwrap_or(0);
                        out += h;
                        out.push('\n');
                        for _ in 0..n {
                            let l = lines.next().unwrap_or("");
                            let mut w = l.split_whitespace();
                            let tag = w.next().unwrap_or("");
                            let rest: Vec<String> = w.map(scale).collect();
                            out += &format!("{tag} {}\n", rest.join(" "));
                        }
                    }
                    t = out + "$EndElements\n" + tail;
                }
            }
            t.into_bytes()
        }
        GmshMutation::Number(k, v) => {
            let mut count = 0;
            let mut out = String::new();
            let mut replaced = false;
            for line in text.split_inclusive('\n') {
                if line.starts_with('$') || line.contains('"') || replaced {
                    out += line;
                    continue;
                }
                let words: Vec<&str> = line.split_whitespace().collect();
                if count + words.len() > *k {
                    let mut w: Vec<String> = words.iter().map(|s| s.to_string()).collect();
                    w[k - count] = v.clone();
                    out += &(w.join(" ") + "\n");
                    replaced = true;
                } else {
                    out += line;
                }
                count += words.len();
            }
            out.into_bytes()
        }
        GmshMutation::Cut(k) => bytes[..k % bytes.len().max(1)].to_vec(),
        GmshMutation::Flip(k, b) => {
            let mut v = bytes.to_vec();
            if !v.is_empty() {
                let i = k % v.len();
                v[i] = *b;
            }
            v
        }
    }
}

/// Reads a mutated Gmsh file: an error, or a part whose every node sits where the
/// original file put the node of its tag (for mutations that keep the geometry).
fn exercise_gmsh(
    bytes: &[u8],
    keeps_geometry: bool,
    reference: &std::collections::HashMap<u64, [f64; 3]>,
    scale: u64,
) -> Result<(), String> {
    let part = match rothe::mesh::gmsh::parse(bytes).and_then(|p| p.check().map(|_| p)) {
        Ok(p) => p,
        Err(e) => {
            if std::env::var_os("FUZZ_SHOW").is_some() {
                eprintln!("refused: {e}");
            }
            return (!e.is_empty()).then_some(()).ok_or("empty error".into());
        }
    };
    if keeps_geometry {
        let tags = part.node_tags.as_ref().ok_or("no tags")?;
        for (t, x) in tags.iter().zip(&part.coords) {
            let want = reference
                .get(&(t / scale))
                .ok_or(format!("tag {t} unknown"))?;
            if want != x {
                return Err(format!("node tag {t} at {x:?}, its block says {want:?}"));
            }
        }
    }
    Ok(())
}

#[test]
fn mutated_gmsh_files_read_right_or_are_refused() {
    std::panic::set_hook(Box::new(|_| {}));
    for (file, seed) in [("plate_tri.msh", 0x5eed_0003), ("bar_hex.msh", 0x5eed_0005)] {
        gmsh_campaign(file, seed);
    }
}

/// The Gmsh campaign on one file of `tests/data` (a plane file and a solid one).
fn gmsh_campaign(file: &str, seed: u64) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(file);
    let original = std::fs::read(&path).unwrap();
    let reference: std::collections::HashMap<u64, [f64; 3]> = {
        let p = rothe::mesh::gmsh::parse(&original).unwrap();
        p.node_tags.unwrap().into_iter().zip(p.coords).collect()
    };
    let mut config = Config {
        cases: 300,
        failure_persistence: None,
        ..Config::default()
    };
    if std::env::var_os("PROPTEST_RNG_SEED").is_none() {
        config.rng_seed = proptest::test_runner::RngSeed::Fixed(seed);
    }
    let mut runner = TestRunner::new(config);
    runner
        .run(&gmsh_mutation(), |m| {
            let bytes = apply_gmsh(&original, &m);
            let (keeps, scale) = match &m {
                GmshMutation::Reverse(_) => (true, 1),
                GmshMutation::Sparse(f) => (true, *f),
                _ => (false, 1),
            };
            match catch_unwind(AssertUnwindSafe(|| {
                exercise_gmsh(&bytes, keeps, &reference, scale)
            })) {
                Ok(Ok(())) => Ok(()),
                Ok(Err(why)) => Err(TestCaseError::fail(format!("{m:?}: {why}"))),
                Err(p) => Err(TestCaseError::fail(format!(
                    "{m:?}: panic: {}",
                    rothe::run::panic_message(p.as_ref())
                ))),
            }
        })
        .unwrap_or_else(|e| {
            eprintln!("{e}");
            panic!("the Gmsh campaign failed: {e}")
        });
}

/// An override for the command line: good and bad paths and values.
fn override_case() -> impl Strategy<Value = (u8, String)> {
    let paths = prop_oneof![
        Just("analysis.dt"),
        Just("analysis.t_end"),
        Just("analysis.gravity"),
        Just("analysis.rayleigh"),
        Just("analysis.scheme"),
        Just("analysis.contact_qp"),
        Just("analysis.omega"),
        Just("analysis.rho_inf"),
        Just("analysis.contact_predictor"),
        Just("analysis.nothing"),
        Just("bodies.0.velocity"),
        Just("bodies.0.thickness"),
        Just("bodies.9.thickness"),
        Just("bodies.0.mesh.divisions"),
        Just("meshing.element_size"),
        Just("materials"),
        Just("contact.0.rigid_line"),
        Just("contact.0.rigid_plane"),
        Just("contact.0.mu"),
        Just("analysis.plane"),
        Just("analysis.dt_min"),
        Just("analysis.keep_factor"),
        Just("analysis.refactor_rate"),
        Just("analysis.iteration"),
        Just("materials.concrete.identify"),
        Just("materials.concrete.nonlocal"),
        Just("materials.concrete.fracture_energy"),
        Just("bodies.1.mesh.origin"),
        Just("probes.0.at"),
        Just("..x"),
    ];
    let values = prop_oneof![
        Just("1e-6"),
        Just("0"),
        Just("-1"),
        Just("nan"),
        Just("1e300"),
        Just("[1.0, 2.0]"),
        Just("[1.0, 2.0, 3.0]"),
        Just("[[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]]"),
        Just("\"central_difference\""),
        Just("\"trapezoidal\""),
        Just("\"generalized_alpha\""),
        Just("\"stabilised\""),
        Just("0.5"),
        Just("\"full\""),
        Just("\"solid\""),
        Just("1e-20"),
        Just("100.0"),
        Just("true"),
        Just("[0.0, -0.05, 0.0]"),
        Just("[0.3, 0.05]"),
        Just("{ class = \"C90/105\" }"),
        Just("{ radius = 1e-20 }"),
        Just("{ point = [0.0, 0.1, 0.0], normal = [0.0, 1e-200, 0.0] }"),
        Just("{ a = 1 }"),
        Just("text"),
    ];
    (
        0..3u8,
        (paths, values).prop_map(|(p, v)| format!("{p}={v}")),
    )
}

#[test]
fn command_line_overrides_give_a_model_or_an_error() {
    std::panic::set_hook(Box::new(|_| {}));
    let mut scenarios = examples("examples/scenarios");
    scenarios.extend(examples("examples/contact"));
    scenarios.extend(examples("examples/solid"));
    scenarios.extend(examples("examples/explicit"));
    let mut config = Config {
        cases: 300,
        failure_persistence: None,
        ..Config::default()
    };
    if std::env::var_os("PROPTEST_RNG_SEED").is_none() {
        config.rng_seed = proptest::test_runner::RngSeed::Fixed(0x5eed_0004);
    }
    let mut runner = TestRunner::new(config);
    let strategy = (
        0..scenarios.len(),
        proptest::collection::vec(override_case(), 1..4),
    );
    runner
        .run(&strategy, |(file, cases)| {
            let (path, _) = &scenarios[file];
            let outcome = catch_unwind(AssertUnwindSafe(|| {
                let mut ov = rothe::config::Overrides::none();
                for (kind, spec) in &cases {
                    ov = match kind {
                        0 => ov.set(spec)?,
                        1 => ov.unset(spec.split('=').next().unwrap_or("")),
                        _ => ov.variant(spec)?,
                    };
                }
                let opts = LoadOptions {
                    memory_limit: Some(LIMIT),
                    allow_unstable: false,
                    distributed_factor: false,
                };
                rothe::config::load_with_overrides(path, &opts, &ov).map(|_| ())
            }));
            match outcome {
                Ok(Ok(())) => Ok(()),
                Ok(Err(e)) if !e.to_string().is_empty() => {
                    if std::env::var_os("FUZZ_SHOW").is_some() {
                        eprintln!("refused: {e}");
                    }
                    Ok(())
                }
                Ok(Err(_)) => Err(TestCaseError::fail("an empty error")),
                Err(p) => Err(TestCaseError::fail(format!(
                    "{}: {cases:?}: panic: {}",
                    path.display(),
                    rothe::run::panic_message(p.as_ref())
                ))),
            }
        })
        .unwrap_or_else(|e| {
            eprintln!("{e}");
            panic!("the override campaign failed: {e}")
        });
}

/// An override of the keys the last rounds added (schemes, predictor, error-controlled
/// steps, Rayleigh targets, explicit step rules) with good and bad values.
fn settings_case() -> impl Strategy<Value = String> {
    prop_oneof![
        prop_oneof![
            Just("\"backward_euler\""),
            Just("\"trapezoidal\""),
            Just("\"generalized_alpha\""),
            Just("\"central_difference\""),
        ]
        .prop_map(|v| format!("analysis.scheme={v}")),
        prop_oneof![Just("\"none\""), Just("\"stabilised\"")]
            .prop_map(|v| format!("analysis.contact_predictor={v}")),
        prop_oneof![
            Just("0.0"),
            Just("0.5"),
            Just("0.8"),
            Just("1.0"),
            Just("2.0")
        ]
        .prop_map(|v| format!("analysis.rho_inf={v}")),
        prop_oneof![
            Just("{ tolerance = 1e-3 }"),
            Just("{ tolerance = 1e-5, dt_min = 1e-9 }"),
            Just("{ tolerance = 0.0 }"),
            Just("{ tolerance = 1e-4, dt_max = 1e-300 }"),
        ]
        .prop_map(|v| format!("analysis.adaptive={v}")),
        prop_oneof![
            Just("{ ratio = 0.02, modes = [1, 2] }"),
            Just("{ ratio = 0.05, modes = [1, 3] }"),
            Just("{ ratio = 0.02, frequencies = [100.0, 2000.0] }"),
            Just("{ ratio = 0.02, frequencies = [1e300, 1e300] }"),
            Just("{ ratio = 0.02, modes = [0, 2] }"),
            Just("{ ratio = 2.0, modes = [1, 2] }"),
        ]
        .prop_map(|v| format!("analysis.damping={v}")),
        prop_oneof![Just("\"element\""), Just("\"eigen\"")]
            .prop_map(|v| format!("analysis.critical_step={v}")),
        prop_oneof![Just("1e-6"), Just("5e-6"), Just("1e-5"), Just("1e-3")]
            .prop_map(|v| format!("analysis.dt={v}")),
        prop_oneof![Just("\"lumped\""), Just("\"consistent\"")]
            .prop_map(|v| format!("analysis.mass={v}")),
    ]
}

#[test]
fn the_last_rounds_settings_run_right_or_are_refused() {
    // Whole runs (in memory, 2e-4 s of the scenario) under random combinations of
    // the settings above: each is refused with a message, fails with a message, or
    // completes with a finite ledger that passes the checks that bind it. Never a
    // panic, never a `completed` run with E_kin + E_el beyond its supply under
    // central differences, never a material dissipation above the internal work.
    std::panic::set_hook(Box::new(|_| {}));
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let scenarios = [
        "examples/scenarios/cantilever.toml",
        "examples/contact/block_resting.toml",
        "examples/contact/bars_impact.toml",
        "examples/solid/cantilever.toml",
    ];
    let mut config = Config {
        cases: 60,
        failure_persistence: None,
        ..Config::default()
    };
    if std::env::var_os("PROPTEST_RNG_SEED").is_none() {
        config.rng_seed = proptest::test_runner::RngSeed::Fixed(0x5eed_0006);
    }
    let mut runner = TestRunner::new(config);
    let strategy = (
        0..scenarios.len(),
        proptest::collection::vec(settings_case(), 1..4),
    );
    let outcomes = std::sync::Mutex::new([0usize; 3]);
    runner
        .run(&strategy, |(file, sets)| {
            let path = root.join(scenarios[file]);
            let outcome = catch_unwind(AssertUnwindSafe(|| -> Result<usize, String> {
                let mut ov = rothe::config::Overrides::none()
                    .set("analysis.t_end=2e-4")
                    .and_then(|o| o.set("analysis.vtk_every=0"))
                    .map_err(|e| e.to_string())?;
                for spec in &sets {
                    ov = ov.set(spec).map_err(|e| e.to_string())?;
                }
                let opts = LoadOptions {
                    memory_limit: Some(LIMIT),
                    allow_unstable: false,
                    distributed_factor: false,
                };
                let model = match rothe::config::load_with_overrides(&path, &opts, &ov) {
                    Ok(m) => m,
                    Err(e) if !e.to_string().is_empty() => return Ok(0),
                    Err(_) => return Err("an empty refusal".into()),
                };
                let mut run = rothe::run::RunOptions::new("", Backend::Faer);
                run.memory_limit = Some(LIMIT);
                run.hooks.no_files = true;
                match rothe::run::run_kept(&model, &run) {
                    Err(e) if !e.to_string().is_empty() => Ok(1),
                    Err(_) => Err("an empty error".into()),
                    Ok((s, _)) => {
                        let e = &s.energy;
                        if !(e.kinetic.is_finite() && e.elastic.is_finite()) {
                            return Err(format!("completed with a non-finite ledger: {e:?}"));
                        }
                        if !s.checks.dissipation_within_internal_work.holds
                            || !s.checks.dissipation_within_supplied_energy.holds
                        {
                            return Err(format!("completed past its checks: {:?}", s.checks));
                        }
                        if model.analysis.time.scheme == TimeScheme::CentralDifference
                            && model.analysis.time.kind == AnalysisKind::Dynamic
                            && !s.checks.energy_within_supplied_energy.holds
                        {
                            return Err(format!("explicit run gained energy: {:?}", s.checks));
                        }
                        Ok(2)
                    }
                }
            }));
            match outcome {
                Ok(Ok(k)) => {
                    outcomes.lock().unwrap()[k] += 1;
                    Ok(())
                }
                Ok(Err(why)) => Err(TestCaseError::fail(format!(
                    "{}: {sets:?}: {why}",
                    scenarios[file]
                ))),
                Err(p) => Err(TestCaseError::fail(format!(
                    "{}: {sets:?}: panic: {}",
                    scenarios[file],
                    rothe::run::panic_message(p.as_ref())
                ))),
            }
        })
        .unwrap_or_else(|e| {
            eprintln!("{e}");
            panic!("the campaign failed: {e}")
        });
    let [refused, failed, completed] = *outcomes.lock().unwrap();
    eprintln!("refused {refused}, failed {failed}, completed {completed}");
    assert!(
        refused > 0 && completed > 0,
        "the campaign reaches both outcomes"
    );
}
