//! The `rothe` command: `run`, `check`, `material`.
//!
//! Errors print as `error: <field or file>: <what is wrong>` and exit with status 1.
//! A panic never reaches the user as a Rust backtrace: it is reported as an internal
//! error naming the input file, and a run's `summary.json` says `failed`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use rothe::config::LoadOptions;
use rothe::linsolve::Backend;
use rothe::run::{panic_message, run, RunOptions};

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
        /// Run even when the memory estimate exceeds the memory available.
        #[arg(long)]
        ignore_memory: bool,
        /// Accept an explicit step above the critical (CFL) step, for stability
        /// studies.
        #[arg(long)]
        allow_unstable: bool,
    },
    /// Drive one material point along a strain or stress path; writes material.csv.
    Material {
        /// Material-point file (TOML with [material] and [path]).
        file: PathBuf,
        /// Output directory.
        #[arg(long, default_value = "out")]
        out: PathBuf,
    },
    /// Validate a scenario and print its size, steps and output volume, the explicit
    /// CFL step and the memory it needs, without solving.
    Check {
        /// Scenario file (TOML).
        scenario: PathBuf,
        /// Report even when the memory estimate exceeds the memory available.
        #[arg(long)]
        ignore_memory: bool,
        /// Accept an explicit step above the critical (CFL) step.
        #[arg(long)]
        allow_unstable: bool,
        /// Also write K, M, the first step's effective matrix and the contact gap
        /// rows G in Matrix Market format into this directory.
        #[arg(long)]
        matrices: Option<PathBuf>,
    },
}

fn load_options(ignore_memory: bool, allow_unstable: bool) -> LoadOptions {
    let mut opts = if ignore_memory {
        LoadOptions::unlimited()
    } else {
        LoadOptions::default()
    };
    opts.allow_unstable = allow_unstable;
    opts
}

fn run_command(
    scenario: &Path,
    out: &Path,
    backend: Backend,
    quiet: bool,
    ignore_memory: bool,
    allow_unstable: bool,
) -> rothe::Result<()> {
    let opts = load_options(ignore_memory, allow_unstable);
    let model = rothe::config::load_with(scenario, &opts)?;
    let summary = run(
        &model,
        &RunOptions {
            out: out.to_path_buf(),
            backend,
            progress: !quiet,
            memory_limit: opts.memory_limit,
        },
    )?;
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
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // A panic is reported below as an internal error, not printed by the default hook.
    std::panic::set_hook(Box::new(|_| {}));
    let input = match &cli.command {
        Command::Run { scenario, .. } | Command::Check { scenario, .. } => scenario.clone(),
        Command::Material { file, .. } => file.clone(),
    };
    let out_dir = match &cli.command {
        Command::Run { out, .. } => Some(out.clone()),
        _ => None,
    };
    let result = std::panic::catch_unwind(|| match cli.command {
        Command::Run {
            scenario,
            out,
            backend,
            quiet,
            ignore_memory,
            allow_unstable,
        } => run_command(
            &scenario,
            &out,
            backend,
            quiet,
            ignore_memory,
            allow_unstable,
        ),
        Command::Material { file, out } => rothe::material::point_driver::run_file(&file, &out)
            .map(|steps| {
                eprintln!(
                    "{steps} steps; wrote {}",
                    out.join("material.csv").display()
                );
            }),
        Command::Check {
            scenario,
            ignore_memory,
            allow_unstable,
            matrices,
        } => {
            let opts = load_options(ignore_memory, allow_unstable);
            rothe::config::load_with(&scenario, &opts).and_then(|model| {
                let report = rothe::check::report(&model, opts.memory_limit)?;
                print!("{report}");
                if let Some(dir) = matrices {
                    for f in rothe::check::write_matrices(&model, &dir)? {
                        println!("wrote       {}", f.display());
                    }
                }
                Ok(())
            })
        }
    });
    let result = result.unwrap_or_else(|p| {
        let e = rothe::Error::Internal(format!(
            "{} (input {})",
            panic_message(p.as_ref()),
            input.display()
        ));
        if let Some(out) = out_dir {
            mark_failed(&out.join("summary.json"), &e);
        }
        Err(e)
    });
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// After a panic outside the run's own guard: marks an existing `summary.json` as
/// failed with the error (or writes a minimal one).
fn mark_failed(path: &Path, e: &rothe::Error) {
    let mut v: serde_json::Value = std::fs::read_to_string(path)
        .ok()
        .and_then(|s| serde_json::from_str(&s).ok())
        .unwrap_or_else(|| serde_json::json!({}));
    v["status"] = "failed".into();
    v["error"] = e.to_string().into();
    if let Ok(text) = serde_json::to_string_pretty(&v) {
        let _ = std::fs::create_dir_all(path.parent().unwrap_or(Path::new(".")));
        let _ = std::fs::write(path, text);
    }
}
