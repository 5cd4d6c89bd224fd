//! Ten modes of W1 or W3 beside one factorisation of the same matrix:
//! `cargo run --release --example modes -- [w1|w3] [SIZE] [faer|cholmod] [COUNT] [SHIFT]`
//! (defaults w3, 20 for W3 (107k dofs) or 100 for W1 (81k dofs), faer, 10, the default shift). Prints
//! the factor's analysis and numeric factorisation, the Lanczos solves, the Sturm
//! check's LDLᵀ, the total (assembly included) and its ratio to one factorisation (analysis + numeric), and the lowest
//! frequencies.

#[path = "../benches/common/workload.rs"]
mod workload;

use rothe::linsolve::Backend;
use rothe::modal::{modes, ModalOptions};

fn main() -> rothe::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let which = args.first().map_or("w3", String::as_str);
    let size: Option<usize> = args.get(1).map(|s| s.parse().expect("SIZE is an integer"));
    let backend: Backend = args
        .get(2)
        .map(|s| s.parse().expect("backend is faer or cholmod"))
        .unwrap_or_default();
    let count: usize = args
        .get(3)
        .map_or(10, |s| s.parse().expect("COUNT is an integer"));
    let model = match which {
        "w1" => workload::w1(size.unwrap_or(100))?,
        "w3" => workload::w3(size.unwrap_or(20))?,
        other => panic!("unknown workload {other} (w1 or w3)"),
    };
    let shift: Option<f64> = args.get(4).map(|s| s.parse().expect("SHIFT is a number"));
    let opts = ModalOptions {
        count,
        shift,
        backend,
        ..Default::default()
    };
    // Best of three of each figure: this machine's timings move by 10-20 % run to
    // run, and a ratio of two single runs inherits both.
    let runs = (0..3)
        .map(|_| modes(&model, &opts))
        .collect::<rothe::Result<Vec<_>>>()?;
    let best =
        |f: &dyn Fn(&rothe::modal::Modes) -> f64| runs.iter().map(f).fold(f64::INFINITY, f64::min);
    let analysis = best(&|m| m.timing.analysis_s);
    let factorisation = best(&|m| m.timing.factorization_s);
    let solves = best(&|m| m.timing.solve_s);
    let sturm = best(&|m| m.sturm_s);
    let total = best(&|m| m.total_s);
    let m = &runs[0];
    let one = analysis + factorisation;
    println!(
        "{which} ({} free dofs), backend {backend:?}, {count} modes (best of 3)",
        m.n_free
    );
    println!("  analysis             {analysis:.3} s");
    println!("  factorisation        {factorisation:.3} s");
    println!(
        "  solves               {solves:.3} s ({} solves, {} Lanczos steps)",
        m.timing.solves, m.steps
    );
    println!("  Sturm check (LDLᵀ)   {sturm:.3} s");
    println!("  total                {total:.3} s");
    println!(
        "  total / one factorisation (analysis + numeric) = {:.2}",
        total / one
    );
    for (i, mode) in m.modes.iter().enumerate() {
        println!(
            "  mode {:>2}: f = {:.6e} Hz, residual {:.1e}",
            i + 1,
            mode.omega() / (2.0 * std::f64::consts::PI),
            mode.residual
        );
    }
    Ok(())
}
