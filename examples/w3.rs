//! Workload W3, the solid counterpart of W1, end to end as a user runs it:
//! `cargo run --release --example w3 -- [N] [faer|cholmod|mumps]` (default 20: 107k
//! dofs; 34 gives 503k). Prints setup, assembly, factorisation, the mean step, the
//! tip deflection and the total wall time (the figure `benches/peers/w3_fenicsx.py`
//! prints for FEniCSx on the same problem). MUMPS on two ranks beside faer on two
//! threads: `cargo build --release --features mumps --example w3`, then
//! `mpirun -n 2 target/release/examples/w3 20 mumps` and
//! `target/release/examples/w3 20 faer`.

#[path = "../benches/common/workload.rs"]
mod workload;

use std::time::Instant;

use rothe::linsolve::Backend;
use rothe::time::backward_euler::BackwardEuler;
use rothe::time::march::{march, Marched, StepControl};
use rothe::time::Integrator;

fn main() -> rothe::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let n: usize = args
        .first()
        .map(|s| s.parse().expect("N is a positive integer"))
        .unwrap_or(20);
    let backend: Backend = args
        .get(1)
        .map(|s| s.parse().expect("backend is faer, cholmod or mumps"))
        .unwrap_or_default();
    // Under mpirun with mumps, the ranks other than 0 serve rank 0's solves.
    if rothe::linsolve::distributed::start(backend)? == rothe::linsolve::distributed::Role::Served {
        return Ok(());
    }
    let t0 = Instant::now();
    let model = workload::w3(n)?;
    let setup_s = t0.elapsed().as_secs_f64();
    let mut be = BackwardEuler::new(&model, backend)?;
    let mut s = be.initial_state();
    let t_steps = Instant::now();
    let mut steps = 0;
    march(&mut be, &mut s, StepControl::of(&model), |_, _, m| {
        if let Marched::Step(_) = m {
            steps += 1;
        }
        Ok(())
    })?;
    let steps_s = t_steps.elapsed().as_secs_f64();
    let timing = be.timing();
    let tip = model.probes[0].node;
    println!(
        "W3 n = {n} ({} dofs, {} hexahedra), backend {}",
        model.mesh.n_dofs(),
        model.mesh.n_elements(),
        be.backend()
    );
    println!("  mesh + model setup   {setup_s:.3} s");
    println!("  assembly             {:.3} s", timing.assembly_s);
    println!(
        "  factorisation        {:.3} s (nnz(L) = {:.1}M, {} factorisations)",
        timing.factorization_s,
        be.factor_nnz().unwrap_or(0) as f64 / 1e6,
        be.factorizations()
    );
    println!(
        "  mean step            {:.2} ms over {steps} steps",
        1e3 * steps_s / steps as f64
    );
    println!("  tip u_y(T)           {:.9e} m", s.u[3 * tip + 1]);
    println!(
        "  energy residual rel  {:.2e}",
        s.ledger.relative_residual()
    );
    println!("  total                {:.3} s", t0.elapsed().as_secs_f64());
    let nnz_l = be.factor_nnz().unwrap_or(0);
    let step_per = steps_s / steps.max(1) as f64;
    workload::print_stream_bounds(
        nnz_l,
        be.factor_lower_entries().unwrap_or(nnz_l),
        timing.solve_s / steps.max(1) as f64,
        step_per,
    );
    drop(be);
    rothe::linsolve::distributed::finish();
    Ok(())
}
