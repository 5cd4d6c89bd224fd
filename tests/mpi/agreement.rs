//! Histories with the MUMPS backend on one and two ranks against faer's, and a run
//! against its repeat: to the last bit on one rank, to round-off on two.

use super::*;

/// The largest difference between two histories of one scenario, relative to each
/// column's scale: the ledger's columns (`E_*`, `W_*`, `D_*`) to the largest energy
/// of the run (a ledger line is read against the energy in play), the others
/// (probes, contact forces and counts) to their own largest magnitude. The
/// iteration counts must be equal; the residual columns are round-off and left out.
fn worst_difference(a: &Path, b: &Path) -> (f64, String) {
    let (header, ra) = history(a);
    let (header_b, rb) = history(b);
    assert_eq!(header, header_b);
    assert_eq!(
        ra.len(),
        rb.len(),
        "{} against {}",
        a.display(),
        b.display()
    );
    let energy: Vec<bool> = header
        .iter()
        .map(|h| h.starts_with("E_") || h.starts_with("W_") || h.starts_with("D_"))
        .collect();
    let energy_scale = ra
        .iter()
        .flat_map(|r| r.iter().zip(&energy).filter(|e| *e.1).map(|e| e.0.abs()))
        .fold(0.0, f64::max);
    let mut worst = (0.0, String::new());
    for (j, name) in header.iter().enumerate() {
        if name == "iterations" {
            for (x, y) in ra.iter().zip(&rb) {
                assert_eq!(x[j], y[j], "iterations differ");
            }
            continue;
        }
        if name == "t" || name == "residual" || name == "nl_residual" {
            continue;
        }
        let scale = if energy[j] {
            energy_scale
        } else {
            ra.iter().chain(&rb).map(|r| r[j].abs()).fold(0.0, f64::max)
        };
        if scale == 0.0 {
            continue;
        }
        let d = ra
            .iter()
            .zip(&rb)
            .map(|(x, y)| (x[j] - y[j]).abs())
            .fold(0.0, f64::max)
            / scale;
        if d > worst.0 {
            worst = (d, name.clone());
        }
    }
    worst
}

/// Runs `args` with faer alone, and with mumps twice on one rank and twice on two;
/// asserts the histories agree with faer's to 1e-10, that the repeat on one rank is
/// the same file and the repeat on two agrees to 1e-13.
fn agrees(name: &str, args: &[&str]) {
    let _machine = exclusive();
    let dir = tempfile::tempdir().unwrap();
    let out = |tag: &str| dir.path().join(format!("{name}-{tag}"));
    let with = |tag: &str, backend: &str| -> Vec<String> {
        let mut v: Vec<String> = args.iter().map(|s| s.to_string()).collect();
        v.extend(
            [
                "--out",
                out(tag).to_str().unwrap(),
                "--quiet",
                "--backend",
                backend,
            ]
            .map(String::from),
        );
        v
    };
    let f = with("faer", "faer");
    let faer = alone(&f.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(faer.status.success(), "{name} faer: {}", stderr(&faer));
    for (ranks, tag) in [
        (1, "mumps1"),
        (1, "mumps1-again"),
        (2, "mumps2"),
        (2, "mumps2-again"),
    ] {
        let a = with(tag, "mumps");
        let o = launch(ranks, &a.iter().map(String::as_str).collect::<Vec<_>>());
        assert!(
            o.status.success(),
            "{name} on {ranks} ranks: {}",
            stderr(&o)
        );
        let s = summary(&out(tag));
        assert_eq!(s["status"], "completed");
        assert_eq!(s["solver"]["backend"], "mumps");
        let (d, column) = worst_difference(&out("faer"), &out(tag));
        eprintln!("{name}: mumps on {ranks} ranks against faer: {d:.2e} ({column})");
        assert!(
            d < 1e-10,
            "{name} on {ranks} ranks: {column} differs by {d:e}"
        );
    }
    // One rank: the same file to the last bit.
    let first = std::fs::read(out("mumps1").join("history.csv")).unwrap();
    let again = std::fs::read(out("mumps1-again").join("history.csv")).unwrap();
    assert!(
        first == again,
        "{name}: a repeat on 1 rank changed the history"
    );
    // Two ranks: MUMPS sums some contributions in the order they arrive, so a
    // repeat may move the last bits (theory/solves.md); every printed value of the
    // ledger, the probes and the forces stays within 1e-13 of its scale.
    let (d, column) = worst_difference(&out("mumps2"), &out("mumps2-again"));
    assert!(
        d < 1e-13,
        "{name}: a repeat on 2 ranks moved {column} by {d:e}"
    );
}

#[test]
fn w1_agrees_with_faer() {
    // W1's wall (consistent mass, a step traction), at 32 x 8 cells.
    let sc = examples("scenarios/cantilever.toml");
    agrees(
        "w1",
        &["run", sc.to_str().unwrap(), "--set", "analysis.t_end=5e-4"],
    );
}

#[test]
fn w3_agrees_with_faer() {
    let sc = examples("cluster/w3.toml");
    agrees(
        "w3",
        &[
            "run",
            sc.to_str().unwrap(),
            "--set",
            "bodies.0.mesh.divisions=[16,4,4]",
            "--set",
            "analysis.t_end=5e-4",
        ],
    );
}

/// Benchmark 1, coarse, through the impact: the contact QP condensed on the
/// distributed factor.
const BENCHMARK_1: [&str; 6] = [
    "--set",
    "analysis.t_end=4e-3",
    "--set",
    "analysis.dt=1e-5",
    "--set",
    "meshing.element_size=0.2",
];

#[test]
fn benchmark_1_with_contact_agrees_with_faer() {
    let sc = examples("benchmarks/two_blocks.toml");
    let mut args = vec!["run", sc.to_str().unwrap()];
    args.extend(BENCHMARK_1);
    agrees("benchmark1", &args);
}

#[test]
fn nonlinear_benchmark_1_agrees_with_faer() {
    // Nonlocal Mazars damage in the concrete: Newton iterations on refactorised
    // tangents, with contact.
    let sc = examples("benchmarks/two_blocks.toml");
    let mut args = vec!["run", sc.to_str().unwrap(), "--variant", "concrete=mazars"];
    args.extend(BENCHMARK_1);
    agrees("mazars", &args);
}
