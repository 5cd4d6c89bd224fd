//! The `rothe` command: `run`, `check`.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use rothe::linsolve::Backend;
use rothe::run::{run, RunOptions};

#[derive(Parser)]
#[command(
    name = "rothe",
    version,
    about = "Backward-Euler (Rothe) FE dynamics with an exact energy ledger"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scenario and write history.csv, summary.json and VTK files.
    Run {
        /// Scenario file (TOML).
        scenario: PathBuf,
        /// Output directory.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Linear solver backend: faer or cholmod.
        #[arg(long, default_value = "faer")]
        backend: Backend,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
    },
    /// Drive one material point along a strain or stress path; writes material.csv.
    Material {
        /// Material-point file (TOML with [material] and [path]).
        file: PathBuf,
        /// Output directory.
        #[arg(long, default_value = "out")]
        out: PathBuf,
    },
    /// Validate a scenario and print its size, the explicit CFL step and a memory
    /// estimate, without solving.
    Check {
        /// Scenario file (TOML).
        scenario: PathBuf,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run { scenario, out, backend, quiet } => rothe::config::load(&scenario).and_then(|model| {
            let summary = run(&model, &RunOptions { out: out.clone(), backend, progress: !quiet })?;
            eprintln!(
                "{} steps, t = {:.6e} s, {} dofs; energy balance residual {:.2e} (relative {:.2e}); output in {}",
                summary.steps,
                summary.t_end,
                summary.dofs,
                summary.energy.balance_residual,
                summary.energy.balance_residual_rel,
                out.display()
            );
            Ok(())
        }),
        Command::Material { file, out } => rothe::material::point_driver::run_file(&file, &out).map(|records| {
            eprintln!("{} steps; wrote {}", records.len() - 1, out.join("material.csv").display());
        }),
        Command::Check { scenario } => rothe::config::load(&scenario).and_then(|model| check(&model)),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn check(model: &rothe::model::Model) -> rothe::Result<()> {
    use rothe::assembly::Pattern;
    use rothe::system::{DofMap, EffectiveSystem};
    let mesh = &model.mesh;
    let pattern = Pattern::new(mesh);
    let dofs = DofMap::new(mesh.n_dofs(), model.constraints.iter().map(|c| c.dof));
    let system = EffectiveSystem::new(
        &pattern,
        dofs,
        Backend::Faer,
        model.analysis.ordering,
        &mesh.coords,
    )?;
    let dofs = system.dofs();
    let nd = system.nested_dissection();
    let solver = &system;
    let nnz_l = solver.factor_nnz().unwrap_or(0);
    let nnz_a = system.matrix().row_idx.len();
    // K and M values (full storage) + adjacency, the reduced lower matrix, the factor.
    let bytes = 2 * pattern.nnz() * 8
        + pattern.adj.len() * 4
        + nnz_a * 16
        + nnz_l * 8
        + 12 * mesh.n_dofs() * 8;
    println!("bodies      {}", model.bodies.len());
    for (i, b) in model.bodies.iter().enumerate() {
        let els: usize = mesh
            .blocks
            .iter()
            .filter(|bl| bl.body == i)
            .map(|bl| bl.elements.len())
            .sum();
        println!(
            "  {:<12} {} elements, thickness {} m, velocity {:?} m/s",
            b.name, els, b.thickness, b.velocity
        );
    }
    println!("nodes       {}", mesh.n_nodes());
    println!("elements    {}", mesh.n_elements());
    println!("dofs        {} ({} free)", mesh.n_dofs(), dofs.n_free());
    println!(
        "steps       {} of h = {:e} s to T = {:e} s",
        model.analysis.n_steps(),
        model.analysis.dt,
        model.analysis.t_end
    );
    if let Some(c) = rothe::time::cfl::critical_step(model) {
        println!("CFL step    {:.4e} s (explicit central differences; block {}, element {}); h / CFL = {:.3}", c.dt, c.block, c.element, model.analysis.dt / c.dt);
    }
    println!(
        "nnz(K_eff)  {} (lower), nnz(L) {} (faer, {})",
        nnz_a,
        nnz_l,
        if nd { "nested dissection" } else { "AMD" }
    );
    println!("memory      about {:.1} MB", bytes as f64 / 1e6);
    Ok(())
}
