//! Studies as a user runs them: `rothe study time` shows first order in `h` on the
//! wave in a bar and on benchmark 1 (coarse); `rothe study collect` on an emitted
//! sweep run by hand gives the same tables as the in-process sweep; `rothe compare`
//! sets the two paths' ledgers side by side; `rothe plot` draws a run's charts; and
//! variants and overrides pick a model and a mesh without copying files.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common::rothe;

fn example(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(rel)
}

/// The rows of `study.csv` as maps from column to cell.
fn study_rows(dir: &Path) -> Vec<std::collections::BTreeMap<String, String>> {
    let text = std::fs::read_to_string(dir.join("study.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    lines
        .map(|l| {
            header
                .iter()
                .zip(l.split(','))
                .map(|(h, c)| (h.to_string(), c.to_string()))
                .collect()
        })
        .collect()
}

fn cell(row: &std::collections::BTreeMap<String, String>, col: &str) -> f64 {
    row[col]
        .parse()
        .unwrap_or_else(|_| panic!("{col} = {}", row[col]))
}

#[test]
fn time_study_of_the_wave_in_a_bar_reads_the_orders_of_its_interpolants() {
    // The wave bar as a 1D strip (50 x 1 Q4): its highest mode has ω h = 0.2-3 over
    // the steps studied. The errors
    // are measured against a reference four times finer than the finest step (the
    // default): against the finest run itself the last order would read 1.40
    // (theory/studies.md), and a half-order scheme would read 0.5-0.6.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("study");
    let (ok, md, err) = rothe(&[
        "study",
        "time",
        example("scenarios/wave_bar.toml").to_str().unwrap(),
        "--set",
        "analysis.t_end=3e-4",
        "--set",
        "analysis.vtk_every=0",
        "--set",
        "bodies.bar.mesh.divisions=[50, 1]",
        "--h",
        "8e-7,4e-7,2e-7,1e-7,5e-8",
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(ok, "{err}");
    assert!(
        md.contains("Time study") && md.contains("a run of its own"),
        "{md}"
    );
    let rows = study_rows(&out);
    assert_eq!(
        rows.len(),
        5,
        "the studied runs; the reference is not a row"
    );
    // Observed orders in L∞(0,T; L2). The piecewise-constant interpolant's error is
    // its own O(h) interpolation error: within [0.75, 1.15], the finest pair's at
    // least 0.9 (0.78, 0.81, 0.86, 0.99 measured). The piecewise-linear one, from
    // successive differences, reads the step load's front: below one (0.75, 0.75,
    // 0.74, 0.71 measured), where a reference-biased ratio climbed past 1.
    let order = |col: &str| -> Vec<f64> { rows[1..].iter().map(|r| cell(r, col)).collect() };
    let p = order("order_constant_Linf_L2");
    assert!(
        p.iter().all(|x| (0.75..1.15).contains(x)),
        "constant: {p:?}"
    );
    assert!(p[p.len() - 1] >= 0.9, "constant: {p:?}");
    let p = order("order_linear_Linf_L2");
    assert!(p.iter().all(|x| (0.6..0.9).contains(x)), "linear: {p:?}");
    // Errors fall monotonically and the energy bound max_s E_s is finite.
    let e: Vec<f64> = rows.iter().map(|r| cell(r, "err_linear_L2_H1")).collect();
    assert!(e.windows(2).all(|w| w[1] < w[0]), "{e:?}");
    assert!(rows.iter().all(|r| cell(r, "max_energy").is_finite()));
    for f in ["study.md", "plots/convergence.png", "plots/convergence.svg"] {
        assert!(out.join(f).is_file(), "{f}");
    }
}

#[test]
fn time_study_of_benchmark_1_climbs_to_first_order_through_the_impact() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("study");
    let (ok, _, err) = rothe(&[
        "study",
        "time",
        example("benchmarks/two_blocks.toml").to_str().unwrap(),
        "--set",
        "meshing.element_size=0.2",
        "--set",
        "analysis.t_end=3.5e-3",
        "--set",
        "analysis.vtk_every=0",
        "--h",
        "8e-6,4e-6,2e-6,1e-6,5e-7",
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(ok, "{err}");
    // The piecewise-constant interpolant climbs to 1 through the impact's
    // pre-asymptotic range (0.68, 0.78, 0.90, 1.08): the two finest pairs within
    // [0.85, 1.15], none below 0.6. The piecewise-linear one, from successive
    // differences, climbs from below (0.54, 0.63, 0.72, 0.81): the impact is not
    // smooth; each pair above the last, all within [0.45, 0.9].
    let rows = study_rows(&out);
    let order = |col: &str| -> Vec<f64> { rows[1..].iter().map(|r| cell(r, col)).collect() };
    let p = order("order_constant_Linf_L2");
    assert!(p.iter().all(|x| (0.6..1.15).contains(x)), "orders {p:?}");
    assert!(
        p[p.len() - 2..].iter().all(|x| (0.85..1.15).contains(x)),
        "orders {p:?}"
    );
    let p = order("order_linear_Linf_L2");
    assert!(p.iter().all(|x| (0.45..0.9).contains(x)), "linear {p:?}");
    assert!(p.windows(2).all(|w| w[1] > w[0]), "linear {p:?}");
}

#[test]
fn time_studies_of_a_smooth_load_read_order_one_and_two() {
    // The harmonically loaded cantilever: backward Euler reads 1.00 ± 0.05 and the
    // trapezoidal rule 2.00 ± 0.1 at every level in both norms of the linear
    // interpolant (successive differences; a reference-biased ratio read 1.22 for
    // order one), the constant interpolant 1 ± 0.1 for both (its O(h)).
    for (scheme, expect, band) in [
        ("backward_euler", 1.0, 0.05),
        ("trapezoidal", 2.0, 0.1),
        ("generalized_alpha", 2.0, 0.1),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("study");
        let (ok, _, err) = rothe(&[
            "study",
            "time",
            example("scenarios/smooth_cantilever.toml")
                .to_str()
                .unwrap(),
            "--set",
            &format!("analysis.scheme={scheme}"),
            "--h",
            "1e-5,5e-6,2.5e-6,1.25e-6",
            "--out",
            out.to_str().unwrap(),
            "--quiet",
        ]);
        assert!(ok, "{err}");
        let rows = study_rows(&out);
        for col in ["order_linear_Linf_L2", "order_linear_L2_H1"] {
            let p: Vec<f64> = rows[1..].iter().map(|r| cell(r, col)).collect();
            assert_eq!(p.len(), 3, "{scheme} {col}");
            assert!(
                p.iter().all(|x| (x - expect).abs() <= band),
                "{scheme} {col}: {p:?}"
            );
        }
        let p: Vec<f64> = rows[1..]
            .iter()
            .map(|r| cell(r, "order_constant_Linf_L2"))
            .collect();
        assert!(
            p.iter().all(|x| (x - 1.0).abs() <= 0.1),
            "{scheme} constant: {p:?}"
        );
    }
}

#[test]
fn an_emitted_sweep_run_by_hand_collects_to_the_in_process_tables() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = example("benchmarks/two_blocks.toml");
    let common = [
        "--variant",
        "concrete=rankine_hill",
        "--set",
        "analysis.t_end=3e-3",
        "--set",
        "analysis.dt=4e-6",
        "--set",
        "analysis.vtk_every=0",
        "--sizes",
        "0.2,0.15",
        "--quiet",
    ];
    let inproc = dir.path().join("inproc");
    let mut args = vec!["study", "mesh", scenario.to_str().unwrap()];
    args.extend(common);
    args.extend(["--out", inproc.to_str().unwrap()]);
    let (ok, _, err) = rothe(&args);
    assert!(ok, "{err}");
    // Emit, then run each line of runs.txt as a cluster task would.
    let emitted = dir.path().join("emitted");
    let mut args = vec!["study", "mesh", scenario.to_str().unwrap()];
    args.extend(common);
    args.extend(["--emit", emitted.to_str().unwrap()]);
    let (ok, out, err) = rothe(&args);
    assert!(ok, "{err}");
    assert!(out.contains("rothe study collect"), "{out}");
    let runs = std::fs::read_to_string(emitted.join("runs.txt")).unwrap();
    assert_eq!(runs.lines().count(), 2);
    assert!(std::fs::read_to_string(emitted.join("slurm.sh"))
        .unwrap()
        .contains("#SBATCH --array=1-2"));
    for line in runs.lines() {
        let cmd = line.replacen("rothe", env!("CARGO_BIN_EXE_rothe"), 1);
        let st = Command::new("sh").arg("-c").arg(&cmd).status().unwrap();
        assert!(st.success(), "{cmd}");
    }
    let (ok, _, err) = rothe(&["study", "collect", emitted.to_str().unwrap()]);
    assert!(ok, "{err}");
    // The same table, but for the wall times.
    let (a, b) = (study_rows(&inproc), study_rows(&emitted));
    assert_eq!(a.len(), 2);
    for (ra, rb) in a.iter().zip(&b) {
        for (k, v) in ra {
            if k != "seconds" {
                assert_eq!(v, &rb[k], "column {k}");
            }
        }
    }
    assert!(emitted.join("plots/probe_probe.png").is_file());
}

/// The implicit and explicit values of the row `name` of `compare.csv`.
fn compare_row(csv: &str, name: &str) -> Vec<f64> {
    let l = csv
        .lines()
        .find(|l| l.starts_with(name))
        .unwrap_or_else(|| panic!("no row `{name}` in:\n{csv}"));
    l.split(',')
        .skip(1)
        .take(2)
        .map(|c| c.parse().unwrap())
        .collect()
}

#[test]
fn compare_sets_the_implicit_and_explicit_ledgers_side_by_side() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cmp");
    let (ok, md, err) = rothe(&[
        "compare",
        example("benchmarks/two_blocks.toml").to_str().unwrap(),
        "--set",
        "meshing.element_size=0.2",
        "--set",
        "analysis.t_end=4e-3",
        "--set",
        "analysis.vtk_every=0",
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(ok, "{err}");
    for line in [
        "D_numerical [J]",
        "D_contact [J]",
        "D_total [J]",
        "balance residual [J]",
    ] {
        assert!(md.contains(line), "{line} missing:\n{md}");
    }
    let csv = std::fs::read_to_string(out.join("compare.csv")).unwrap();
    let row = |name: &str| compare_row(&csv, name);
    let k0 = row("E_kin0 [J]");
    assert_eq!(k0[0], k0[1]);
    // Both ledgers close; both paths lose energy at the impact.
    for r in row("balance residual [J]") {
        assert!(r.abs() < 1e-6 * k0[0], "{r}");
    }
    let d = row("D_total [J]");
    assert!(d[0] > 0.0 && d[1] > 0.0, "{d:?}");
    let steps = row("steps");
    assert!(
        steps[1] < steps[0],
        "the explicit run takes its own (larger) stable step"
    );
    assert!(out.join("plots/energies.png").is_file());
}

#[test]
fn compare_takes_a_second_order_scheme_with_its_keys_to_the_implicit_run_only() {
    // generalized-α with its radius and the contact predictor: the explicit run
    // reads neither (they are refused there), so they stay with the implicit one.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cmp");
    let (ok, md, err) = rothe(&[
        "compare",
        example("benchmarks/two_blocks.toml").to_str().unwrap(),
        "--implicit-scheme",
        "generalized_alpha",
        "--set",
        "analysis.rho_inf=0.5",
        "--set",
        "analysis.contact_predictor=stabilised",
        "--set",
        "meshing.element_size=0.2",
        "--set",
        "analysis.t_end=3e-3",
        "--set",
        "analysis.vtk_every=0",
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(ok, "{err}");
    assert!(md.contains("D_predictor [J]"), "{md}");
    let csv = std::fs::read_to_string(out.join("compare.csv")).unwrap();
    let v = compare_row(&csv, "D_predictor [J]");
    assert!(v[0] > 0.0 && v[1] == 0.0, "{v:?}");
    let summary: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(out.join("runs/implicit/summary.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(summary["scheme"], "generalized_alpha");
    assert_eq!(summary["rho_inf"], 0.5);
    assert_eq!(summary["contact_predictor"], "stabilised");
}

#[test]
fn plot_draws_a_runs_charts_and_variants_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run");
    let sc = example("benchmarks/two_blocks.toml");
    let (ok, _, err) = rothe(&[
        "run",
        sc.to_str().unwrap(),
        "--variant",
        "concrete=kelvin_voigt",
        "--set",
        "meshing.element_size=0.2",
        "--set",
        "analysis.t_end=3e-3",
        "--out",
        run.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(ok, "{err}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["dofs"], 2 * (8 * 4 + 4 * 4));
    for c in [
        "dissipation_within_internal_work",
        "dissipation_within_supplied_energy",
    ] {
        assert_eq!(summary["checks"][c]["holds"], true, "{c}");
        assert!(summary["checks"][c]["lhs"].as_f64().unwrap() > 0.0);
    }
    let (ok, out, err) = rothe(&["plot", run.to_str().unwrap()]);
    assert!(ok, "{err}");
    for f in ["probe_probe", "energies", "dissipation", "contact_impact"] {
        for ext in ["png", "svg"] {
            let p = run.join("plots").join(format!("{f}.{ext}"));
            assert!(
                p.is_file() && out.contains(p.to_str().unwrap()),
                "{}",
                p.display()
            );
        }
    }
    // An unknown option names the group's options; a bad --set names the path.
    let (ok, _, err) = rothe(&[
        "check",
        sc.to_str().unwrap(),
        "--variant",
        "concrete=granite",
    ]);
    assert!(
        !ok && err.contains("no option `granite`") && err.contains("mazars"),
        "{err}"
    );
    let (ok, _, err) = rothe(&[
        "check",
        sc.to_str().unwrap(),
        "--set",
        "meshing.element_size=-1",
    ]);
    assert!(!ok && err.contains("meshing.element_size"), "{err}");
}
