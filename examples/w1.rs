//! Workload W1 at any size and backend, printing the figures the README reports:
//! `cargo run --release --example w1 -- [NY] [faer|cholmod] [elastic|sls]` (defaults
//! 100, faer, elastic). Add `--features cholmod` for the CHOLMOD backend; `sls` puts
//! the standard linear solid in place of elasticity (Gauss-point history path).

use std::time::Instant;

use rothe::linsolve::Backend;
use rothe::time::backward_euler::BackwardEuler;

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
    let sls = args.get(2).map(|s| s == "sls").unwrap_or(false);
    let model = if sls {
        rothe::workload::w1_with(ny, rothe::workload::W1_SLS)?
    } else {
        rothe::workload::w1(ny)?
    };
    let setup_s = t0.elapsed().as_secs_f64();
    let mut be = BackwardEuler::new(&model, backend)?;
    let mut s = be.initial_state();
    let t_steps = Instant::now();
    let n = model.analysis.n_steps();
    let mut solves = 0;
    for _ in 0..n {
        solves += be.step(&mut s)?.iterations;
    }
    let steps_s = t_steps.elapsed().as_secs_f64();
    let tip = model.probes[0].node;
    let nnz_l = be.factor_nnz().unwrap_or(0);
    let n_el = model.mesh.n_elements();
    println!(
        "W1 ny = {ny} ({} dofs, {} elements), backend {}",
        model.mesh.n_dofs(),
        n_el,
        be.backend()
    );
    println!("  mesh + model setup   {setup_s:.3} s");
    println!(
        "  assembly (K, M, K_eff) {:.3} s  ({:.2e} elements/s)",
        be.timing.assembly_s,
        n_el as f64 / be.timing.assembly_s
    );
    println!(
        "  factorisation        {:.3} s  (nnz(L) = {:.2}M)",
        be.timing.factorization_s,
        nnz_l as f64 / 1e6
    );
    println!(
        "  mean step            {:.2} ms (solve {:.2} ms, rest {:.2} ms)",
        1e3 * steps_s / n as f64,
        1e3 * be.timing.solve_s / n as f64,
        1e3 * be.timing.step_other_s / n as f64
    );
    println!(
        "  factor stream bound  {:.2} ms per solve at 22 GB/s (2 x nnz(L) x 8 B)",
        1e3 * 2.0 * nnz_l as f64 * 8.0 / 22e9
    );
    println!("  peak RSS             {:.0} MB", peak_rss_mb());
    println!("  tip u_y(T)           {:.9e} m", s.u[2 * tip + 1]);
    println!(
        "  energy residual rel  {:.2e}",
        s.ledger.relative_residual()
    );
    println!("  solves per step      {:.2}", solves as f64 / n as f64);
    println!("  total                {:.3} s", t0.elapsed().as_secs_f64());
    Ok(())
}
