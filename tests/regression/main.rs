//! Regression: small runs whose histories are kept as reference data
//! (`tests/regression/NAME.csv` beside `NAME.toml`), so any change of results shows.
//! Each reference row is matched by its time to a row of the run's `history.csv`;
//! every kept column (ledger lines and probe displacements) must agree to the
//! tolerance of its scenario, relative to the column's largest value.
//!
//! The references were written by the code before the equilibrium loop was
//! reshaped (commit 932f280), so the reshaped code is checked against it; the
//! contact, friction, explicit and nonlocal cases were added before the house is
//! reshaped around a dimension, for the same purpose. To rewrite them after a change
//! of results that is understood and right:
//! `ROTHE_BLESS=1 cargo test --release --test regression` (all of them) or
//! `ROTHE_BLESS=name,name ...` (those cases only), and say in the commit which
//! results moved, by how much and why.
//!
//! The solid cases (an H8 cantilever, Rankine-Hill in a solid, implicit contact of
//! two solids with friction, the explicit drop on tetrahedra) were added before the
//! dimension became one type. A reshaping that must not change results is checked
//! bit for bit, beyond the tolerances: `ROTHE_BITS=DIR cargo test --release --test
//! regression -- --ignored bits` writes every case's history columns and final
//! displacements as the bits of each number (`DIR/NAME.bits`, the kept-factor runs
//! as `NAME.kept.bits`); run it before and after, then `diff -r` the two folders.

mod reproducible;
#[path = "../../benches/common/workload.rs"]
mod workload;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use rothe::linsolve::Backend;
use rothe::run::{run, run_kept, Hooks, RunOptions};

/// The scenarios and their tolerances: linear runs agree to round-off, runs that
/// iterate agree far below their equilibrium tolerance (1e-8 on the residual):
/// the iterations themselves must not change. Runs whose contact forces come from
/// Clarabel (the cone programs of friction, the explicit impacts)
/// agree to its tolerance on the scaled data (1e-9), so to 1e-8 of a column; with
/// mortar's rows (54 entries each in a solid) the cone programs pass on more of it:
/// summing `W` in another order moved `D_contact` (2e-5 of the energy, a sum of
/// small terms of both signs) by 9e-7 of itself and the other columns by at most
/// 2e-8.
const CASES: [(&str, f64); 15] = [
    ("elastic_cantilever", 1e-10),
    ("damped_lumped_gravity", 1e-10),
    ("sls_wave_bar", 1e-10),
    ("static_ramp", 1e-10),
    ("mazars_cantilever", 1e-9),
    ("rankine_hill_cantilever", 1e-9),
    ("nonlocal_mazars", 1e-9),
    ("contact_impact", 1e-8),
    ("rigid_line_friction", 1e-8),
    ("explicit_contact_friction", 1e-8),
    ("solid_elastic_cantilever", 1e-10),
    ("solid_rankine_hill_cantilever", 1e-9),
    ("solid_contact_friction", 1e-8),
    ("solid_contact_mortar", 1e-6),
    ("solid_explicit_drop", 1e-8),
];

/// Columns kept in the references.
fn kept(name: &str) -> bool {
    matches!(
        name,
        "t" | "E_kin"
            | "E_int"
            | "W_ext"
            | "E_el"
            | "D_viscous"
            | "D_damage"
            | "D_plastic"
            | "D_contact"
            | "D_friction"
            | "D_mass"
            | "D_num"
    ) || name.ends_with("_ux")
        || name.ends_with("_uy")
}

/// Columns by name of a CSV file (kept columns only).
fn read_csv(path: &Path) -> BTreeMap<String, Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let mut cols: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    for line in lines {
        for (name, v) in header.iter().zip(line.split(',')) {
            if kept(name) {
                cols.entry(name.to_string())
                    .or_default()
                    .push(v.trim().parse().unwrap());
            }
        }
    }
    cols
}

#[allow(clippy::needless_range_loop)] // rows across several columns
fn write_csv(path: &Path, cols: &BTreeMap<String, Vec<f64>>) {
    let names: Vec<&String> = std::iter::once(cols.keys().find(|k| *k == "t").unwrap())
        .chain(cols.keys().filter(|k| *k != "t"))
        .collect();
    let mut out = names
        .iter()
        .map(|s| s.as_str())
        .collect::<Vec<_>>()
        .join(",")
        + "\n";
    for i in 0..cols["t"].len() {
        let row: Vec<String> = names
            .iter()
            .map(|n| format!("{:.12e}", cols[*n][i]))
            .collect();
        out += &row.join(",");
        out += "\n";
    }
    std::fs::write(path, out).unwrap();
}

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/regression")
}

/// The nonlinear cases again with the factor kept while the iterations converge on
/// it (`analysis.keep_factor`, the default; the cases above run with
/// `keep_factor = false`, full Newton, which wrote the references). A modified
/// Newton iteration may stop anywhere below the equilibrium tolerance where full
/// Newton lands near round-off; on these cantilevers both stay far below it
/// (largest difference 8e-13 of the column's scale), so the same bound holds.
const KEPT_CASES: [(&str, f64); 3] = [
    ("mazars_cantilever", 1e-9),
    ("rankine_hill_cantilever", 1e-9),
    ("nonlocal_mazars", 1e-9),
];

#[test]
fn histories_match_their_references() {
    compare_with_references(&CASES, false);
}

#[test]
fn kept_factor_histories_match_the_references_to_the_iteration_tolerance() {
    compare_with_references(&KEPT_CASES, true);
}

/// Runs each case (with the factor kept while it serves when `kept`, refactorising
/// at every changed tangent otherwise) and compares its history with the reference.
fn compare_with_references(cases: &[(&str, f64)], kept: bool) {
    // `ROTHE_BLESS=1` rewrites every reference, `ROTHE_BLESS=a,b` those cases only.
    let blessed = std::env::var("ROTHE_BLESS").ok();
    let bless = |name: &str| {
        !kept
            && blessed
                .as_deref()
                .is_some_and(|b| b == "1" || b.split(',').any(|n| n.trim() == name))
    };
    let tmp = tempfile::tempdir().unwrap();
    let mut largest: f64 = 0.0;
    for &(name, tol) in cases {
        let mut model = rothe::config::load(&dir().join(format!("{name}.toml"))).unwrap();
        if !kept {
            model.analysis.iteration.refactor_rate = None;
        }
        let out = tmp.path().join(name);
        run(
            &model,
            &RunOptions {
                out: out.clone(),
                backend: Backend::Faer,
                progress: false,
                memory_limit: None,
                record_fields: false,
                overwrite: true,
                hooks: Default::default(),
            },
        )
        .unwrap();
        let got = read_csv(&out.join("history.csv"));
        let reference = dir().join(format!("{name}.csv"));
        if bless(name) {
            write_csv(&reference, &got);
            continue;
        }
        let want = read_csv(&reference);
        let t_got = &got["t"];
        // Energy lines share one scale (the largest energy), so a line that is
        // round-off in one version and exactly zero in the other compares.
        let max_of = |v: &Vec<f64>| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let energy = |c: &str| c.starts_with('E') || c.starts_with('W') || c.starts_with('D');
        let energy_scale = want
            .iter()
            .filter(|(c, _)| energy(c))
            .map(|(_, v)| max_of(v))
            .fold(0.0, f64::max);
        for (col, values) in &want {
            let scale = if energy(col) {
                energy_scale
            } else {
                max_of(values)
            };
            let have = got
                .get(col)
                .unwrap_or_else(|| panic!("{name}: column {col} is gone"));
            for (i, (&t, &v)) in want["t"].iter().zip(values).enumerate() {
                let j = t_got
                    .iter()
                    .position(|&x| (x - t).abs() <= 1e-9 * t.abs().max(1e-12))
                    .unwrap_or_else(|| panic!("{name}: no row at t = {t}"));
                largest = largest.max((have[j] - v).abs() / scale.max(1e-300));
                assert!(
                    (have[j] - v).abs() <= tol * scale + 1e-300,
                    "{name}: {col} at row {i} (t = {t:e}) is {} against {v} (scale {scale:e}, tolerance {tol:e})",
                    have[j]
                );
            }
        }
        assert!(want["t"].len() >= 10, "{name}: reference too short");
    }
    eprintln!("largest relative difference from the references: {largest:.2e}");
}

/// Every case's history columns (all of them, at full precision) and final
/// displacements as the bits of each number, into `$ROTHE_BITS/NAME.bits` (the
/// kept-factor runs into `NAME.kept.bits`): the record a reshaping is compared with
/// bit for bit (`diff -r` of two such folders). Ignored: it asserts nothing by
/// itself and runs only when asked, with `ROTHE_BITS` set.
#[test]
#[ignore]
fn bits() {
    let dir_out =
        PathBuf::from(std::env::var("ROTHE_BITS").expect("ROTHE_BITS=DIR names the folder"));
    std::fs::create_dir_all(&dir_out).unwrap();
    let runs = CASES
        .iter()
        .map(|&(name, _)| (name, false))
        .chain(KEPT_CASES.iter().map(|&(name, _)| (name, true)));
    for (name, kept) in runs {
        let mut model = rothe::config::load(&dir().join(format!("{name}.toml"))).unwrap();
        if !kept {
            model.analysis.iteration.refactor_rate = None;
        }
        let opts = RunOptions {
            out: PathBuf::new(),
            backend: Backend::Faer,
            progress: false,
            memory_limit: None,
            record_fields: false,
            overwrite: true,
            hooks: Hooks {
                no_files: true,
                keep: true,
                observer: None,
            },
        };
        let (_, kept_data) = run_kept(&model, &opts).unwrap();
        let mut text = String::new();
        let hex = |v: &[f64]| {
            v.iter()
                .map(|x| format!("{:016x}", x.to_bits()))
                .collect::<Vec<_>>()
                .join(" ")
        };
        for (col, values) in &kept_data.columns {
            text += &format!("{col}: {}\n", hex(values));
        }
        text += &format!("u: {}\n", hex(&kept_data.u));
        let file = if kept {
            format!("{name}.kept.bits")
        } else {
            format!("{name}.bits")
        };
        std::fs::write(dir_out.join(file), text).unwrap();
    }
}
