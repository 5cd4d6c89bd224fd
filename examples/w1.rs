//! Workload W1 at any size and backend, printing the figures the README reports:
//! `cargo run --release --example w1 -- [NY] [faer|cholmod] [VARIANT] [ORDERING]`
//! (defaults 100, faer, elastic, auto). Add `--features cholmod` for the CHOLMOD
//! backend. VARIANT puts another material in place of elasticity: `sls`, `mazars`
//! (secant refactorised every iteration), `mazars-fixed` (one factorisation per step),
//! `rankine-hill` (Newton). ORDERING: `auto`, `amd` or `nested_dissection`.

#[path = "../benches/common/workload.rs"]
mod workload;

use std::time::Instant;

use rothe::linsolve::Backend;
use rothe::time::backward_euler::BackwardEuler;
use rothe::time::march::{march, Marched, StepControl};
use rothe::time::Integrator;

fn peak_rss_mb() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines().find(|l| l.starts_with("VmHWM")).map(|l| {
                l.split_whitespace()
                    .nth(1)
                    .unwrap_or("0")
                    .parse::<f64>()
                    .unwrap_or(0.0)
            })
        })
        .unwrap_or(0.0)
        / 1024.0
}

fn main() -> rothe::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let ny: usize = args
        .first()
        .map(|s| s.parse().expect("NY is a positive integer"))
        .unwrap_or(100);
    let backend: Backend = args
        .get(1)
        .map(|s| s.parse().expect("backend is faer or cholmod"))
        .unwrap_or_default();
    let t0 = Instant::now();
    let variant = args.get(2).map(String::as_str).unwrap_or("elastic");
    let mut model = workload::w1_variant(ny, variant)?;
    model.analysis.iteration.ordering = match args.get(3).map(String::as_str) {
        None | Some("auto") => rothe::model::Ordering::Auto,
        Some("amd") => rothe::model::Ordering::Amd,
        Some("nested_dissection") => rothe::model::Ordering::NestedDissection,
        Some(other) => panic!("ORDERING is auto, amd or nested_dissection, not {other}"),
    };
    let setup_s = t0.elapsed().as_secs_f64();
    let mut be = BackwardEuler::new(&model, backend)?;
    let mut s = be.initial_state();
    let t_steps = Instant::now();
    let (mut solves, mut n, mut cuts) = (0, 0, 0);
    march(&mut be, &mut s, StepControl::of(&model), |_, _, m| {
        match m {
            Marched::Step(r) => {
                solves += r.iterations;
                n += 1;
            }
            Marched::Cut { .. } | Marched::Rejected { .. } => cuts += 1,
        }
        Ok(())
    })?;
    let steps_s = t_steps.elapsed().as_secs_f64();
    let timing = be.timing();
    let tip = model.probes[0].node;
    let nnz_l = be.factor_nnz().unwrap_or(0);
    let n_el = model.mesh.n_elements();
    println!(
        "W1 ny = {ny} ({} dofs, {} elements), backend {}, variant {variant}",
        model.mesh.n_dofs(),
        n_el,
        be.backend()
    );
    println!("  mesh + model setup   {setup_s:.3} s");
    println!(
        "  assembly (K, M, K_eff) {:.3} s  ({:.2e} elements/s)",
        timing.assembly_s,
        n_el as f64 / timing.assembly_s
    );
    println!(
        "  factorisation        {:.3} s  (nnz(L) = {:.2}M, {} factorisations, {cuts} step cuts)",
        timing.factorization_s,
        nnz_l as f64 / 1e6,
        be.factorizations()
    );
    println!(
        "  mean step            {:.2} ms (solve {:.2} ms, rest {:.2} ms)",
        1e3 * steps_s / n as f64,
        1e3 * timing.solve_s / n as f64,
        1e3 * (steps_s - timing.solve_s) / n as f64
    );
    let total_s = t0.elapsed().as_secs_f64();
    println!("  peak RSS             {:.0} MB", peak_rss_mb());
    println!("  tip u_y(T)           {:.9e} m", s.u[2 * tip + 1]);
    println!(
        "  energy residual rel  {:.2e}",
        s.ledger.relative_residual()
    );
    println!("  solves per step      {:.2}", solves as f64 / n as f64);
    println!("  total                {total_s:.3} s");
    workload::print_stream_bounds(
        nnz_l,
        be.factor_lower_entries().unwrap_or(nnz_l),
        timing.solve_s / solves.max(1) as f64,
        steps_s / n.max(1) as f64,
    );
    Ok(())
}
