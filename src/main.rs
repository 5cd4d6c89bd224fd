//! The `rothe` command: `run`, `check`, `study`, `compare`, `plot`, `report`,
//! `material`.
//!
//! Errors print as `error: <field or file>: <what is wrong>` and exit with status 1.
//! A panic never reaches the user as a Rust backtrace: it is reported as an internal
//! error naming the input file, and a run's `summary.json` says `failed`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand};
use rothe::config::{LoadOptions, Overrides};
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
        #[command(flatten)]
        scenario: ScenarioArgs,
        /// Output directory.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Linear solver backend: faer, cholmod or mumps (MPI: `mpirun -n N rothe run
        /// ... --backend mumps`).
        #[arg(long, default_value = "faer")]
        backend: Backend,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
        /// Also write the displacement of every step to fields.bin (the time study's
        /// error norms read it).
        #[arg(long)]
        record_fields: bool,
        /// Replace an earlier run in the output directory (its summary, history, VTK
        /// files, fields and plots are removed first); without it such a directory is
        /// refused.
        #[arg(long)]
        overwrite: bool,
    },
    /// Convergence studies: `time` (a sequence of steps), `mesh` (a sequence of mesh
    /// sizes), `collect` (tables and plots of an emitted sweep run elsewhere).
    Study {
        #[command(subcommand)]
        study: StudyCommand,
    },
    /// Run a scenario through the implicit path (backward Euler, contact QP) and the
    /// explicit path (central differences, kinematic contact) and set the two ledgers
    /// side by side.
    Compare {
        #[command(flatten)]
        scenario: ScenarioArgs,
        #[command(flatten)]
        sweep: SweepArgs,
        /// The implicit run's scheme: backward_euler, trapezoidal or generalized_alpha.
        #[arg(long, default_value = "backward_euler")]
        implicit_scheme: String,
    },
    /// Draw the charts of a run's output directory into DIR/plots (PNG and SVG).
    Plot {
        /// A run's output directory (with history.csv).
        dir: PathBuf,
    },
    /// Run the paper's two benchmarks (every model and mesh, implicit and explicit)
    /// and write report.md with tables and plots.
    Report {
        /// Directory holding two_blocks.toml, two_blocks_solid.toml and rc_beam_punch.toml.
        #[arg(long, default_value = "examples/benchmarks")]
        benchmarks: PathBuf,
        /// Benchmark 1's mesh sizes (m).
        #[arg(long, value_delimiter = ',', default_value = "0.2,0.15,0.1,0.05,0.025")]
        meshes: Vec<f64>,
        /// Benchmark 1's extra mesh sizes of the Mazars models, nonlocal and local (m),
        /// e.g. 0.0125 (about 18k Gauss points, 700 neighbours each: hours, not
        /// minutes, on two cores).
        #[arg(long, value_delimiter = ',', num_args = 0..)]
        damage_meshes: Vec<f64>,
        /// Benchmark 1's mesh of the implicit-against-explicit comparison (m).
        #[arg(long, default_value_t = 0.1)]
        compare_mesh: f64,
        /// Benchmark 2's element size (m); default the scenario's.
        #[arg(long)]
        beam_size: Option<f64>,
        /// Set one value of every run's scenario, `dotted.path=value` (repeatable).
        #[arg(long = "set", value_name = "PATH=VALUE")]
        sets: Vec<String>,
        #[command(flatten)]
        sweep: SweepArgs,
    },
    /// Drive one material point along a strain or stress path; writes material.csv.
    Material {
        /// Material-point file (TOML with [material] and [path]).
        file: PathBuf,
        /// Output directory.
        #[arg(long, default_value = "out")]
        out: PathBuf,
    },
    /// The lowest eigenfrequencies and mode shapes (shift-invert Lanczos on the run's
    /// factor, checked by a Sturm count), or those nearest a frequency: modes.csv,
    /// modes.json, modes.pvd and the charts in the output directory.
    Modes {
        #[command(flatten)]
        scenario: ScenarioArgs,
        /// Number of modes: the lowest, or the nearest --around.
        #[arg(long, default_value_t = 10)]
        count: usize,
        /// The shift σ (rad²/s², zero or negative); default −1e-7 tr K / tr M.
        #[arg(long, allow_hyphen_values = true, conflicts_with = "around")]
        shift: Option<f64>,
        /// The modes nearest this frequency (Hz) instead of the lowest (an LDLᵀ of
        /// K − (2πF)²M, faer whatever the backend).
        #[arg(long)]
        around: Option<f64>,
        /// Output directory.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Replace an earlier run's or modal analysis's files in the output
        /// directory (refused otherwise).
        #[arg(long)]
        overwrite: bool,
        /// Linear solver backend: faer, cholmod or mumps.
        #[arg(long, default_value = "faer")]
        backend: Backend,
    },
    /// Validate a scenario and print its size, steps and output volume, the explicit
    /// CFL step and the memory it needs, without solving.
    Check {
        #[command(flatten)]
        scenario: ScenarioArgs,
        /// Also write K, M, the first step's effective matrix and the contact gap
        /// rows G in Matrix Market format into this directory.
        #[arg(long)]
        matrices: Option<PathBuf>,
        /// The backend whose analysis sizes the factor: faer, cholmod, or mumps
        /// (MUMPS's own estimates of the factor and of each MPI rank's memory, under
        /// `mpirun -n N`).
        #[arg(long, default_value = "faer")]
        backend: Backend,
    },
}

/// The convergence studies.
#[derive(Subcommand)]
enum StudyCommand {
    /// The scenario for a sequence of steps h: errors of the Rothe interpolants
    /// against the finest run, observed orders, Richardson estimates.
    Time {
        #[command(flatten)]
        scenario: ScenarioArgs,
        /// The steps (s), comma separated.
        #[arg(long = "h", value_delimiter = ',', conflicts_with = "halvings")]
        h: Vec<f64>,
        /// Or: the scenario's step and N halvings of it.
        #[arg(long)]
        halvings: Option<usize>,
        /// The errors are measured against a reference run 2^K times finer than the
        /// finest step (0: against the finest run itself, whose last orders then lean
        /// high).
        #[arg(long, default_value_t = rothe::study::time_study::DEFAULT_REFERENCE_HALVINGS)]
        reference_halvings: usize,
        #[command(flatten)]
        sweep: SweepArgs,
    },
    /// An error-controlled scenario (`analysis.adaptive`) at a sequence of
    /// tolerances, beside fixed steps at the ladder's rungs: the error each reaches
    /// against a fixed-step reference, and the steps it took.
    Tolerance {
        #[command(flatten)]
        scenario: ScenarioArgs,
        /// The tolerances, comma separated.
        #[arg(long, value_delimiter = ',', required = true)]
        tolerances: Vec<f64>,
        /// Fixed-step runs at dt_max, dt_max/2, … dt_max/2^N beside them.
        #[arg(long, default_value_t = rothe::study::tolerance_study::DEFAULT_FIXED_HALVINGS)]
        fixed_halvings: usize,
        /// The reference's fixed step (s); default the ladder's bottom rung (it must
        /// divide it).
        #[arg(long)]
        reference_dt: Option<f64>,
        #[command(flatten)]
        sweep: SweepArgs,
    },
    /// The scenario for a sequence of mesh sizes (`meshing.element_size`).
    Mesh {
        #[command(flatten)]
        scenario: ScenarioArgs,
        /// The element sizes (m), comma separated.
        #[arg(long, value_delimiter = ',', required = true)]
        sizes: Vec<f64>,
        #[command(flatten)]
        sweep: SweepArgs,
    },
    /// Tables, plots and summary of a sweep whose runs were made elsewhere (from
    /// `--emit`): reads DIR/plan.json and DIR/runs/*.
    Collect {
        /// The study directory.
        dir: PathBuf,
    },
}

/// Where a sweep writes and how it runs.
#[derive(Args, Clone, Debug)]
struct SweepArgs {
    /// Output directory of the sweep.
    #[arg(long, default_value = "out/study")]
    out: PathBuf,
    /// Do not run: write DIR/runs.txt (one `rothe run` per line), DIR/slurm.sh (a job
    /// array) and DIR/plan.json, for `rothe study collect DIR` afterwards.
    #[arg(long, value_name = "DIR")]
    emit: Option<PathBuf>,
    /// Runs at once (default: the machine's cores).
    #[arg(long)]
    jobs: Option<usize>,
    /// No progress display.
    #[arg(long)]
    quiet: bool,
}

impl SweepArgs {
    /// Checks the plan, then emits it, or sweeps and collects it. Fails (non-zero
    /// exit) when a run failed, after collecting the others.
    fn execute(&self, plan: &rothe::study::Plan) -> rothe::Result<()> {
        if let Some(j) = self.jobs {
            if !(1..=MAX_JOBS).contains(&j) {
                return Err(rothe::Error::config(
                    "--jobs",
                    format!("{j}: give 1 to {MAX_JOBS} runs at once"),
                ));
            }
        }
        let (steps, bytes) = plan.preflight()?;
        eprintln!(
            "{} runs, {steps} steps in all, about {:.1} MB of output",
            plan.runs.len(),
            bytes as f64 / 1e6
        );
        if let Some(dir) = &self.emit {
            for f in plan.emit(dir)? {
                println!("wrote {}", f.display());
            }
            println!(
                "{} runs; run them (e.g. `sbatch {}`), then `rothe study collect {}`",
                plan.runs.len(),
                dir.join("slurm.sh").display(),
                dir.display()
            );
            return Ok(());
        }
        let mut opts = rothe::study::SweepOptions {
            progress: !self.quiet,
            ..Default::default()
        };
        if let Some(j) = self.jobs {
            opts.jobs = j;
        }
        let outcomes = rothe::study::sweep(plan, &self.out, &opts)?;
        let failed = outcomes.iter().filter(|o| o.error.is_some()).count();
        let collected = rothe::study::collect(&self.out)?;
        if plan.kind == rothe::study::StudyKind::Report {
            println!("wrote {}", self.out.join("report.md").display());
        } else {
            println!("{}", collected.markdown);
        }
        eprintln!(
            "{} runs ({failed} failed) in {:.1} s of run time; output in {}",
            outcomes.len(),
            outcomes.iter().map(|o| o.seconds).sum::<f64>(),
            self.out.display()
        );
        collected.all_completed()
    }
}

/// Most runs a sweep starts at once.
const MAX_JOBS: usize = 1024;

/// A scenario and how to read it: the file, its variants and overrides, and the
/// checks a user may lift.
#[derive(Args, Clone, Debug)]
struct ScenarioArgs {
    /// Scenario file (TOML).
    scenario: PathBuf,
    /// Select an option of one of the scenario's variant groups, `group=option`
    /// (repeatable), e.g. `--variant concrete=mazars`.
    #[arg(long = "variant", value_name = "GROUP=OPTION")]
    variants: Vec<String>,
    /// Set one value of the scenario, `dotted.path=value` (repeatable), e.g.
    /// `--set analysis.dt=5e-7 --set meshing.element_size=0.05`.
    #[arg(long = "set", value_name = "PATH=VALUE")]
    sets: Vec<String>,
    /// Remove one key of the scenario (its default applies), e.g. `--unset
    /// analysis.dt` for the explicit scheme's stable step (repeatable).
    #[arg(long = "unset", value_name = "PATH")]
    unsets: Vec<String>,
    /// Go on even when the memory estimate exceeds the memory available.
    #[arg(long)]
    ignore_memory: bool,
    /// Accept an explicit step above the critical (CFL) step, for stability
    /// studies.
    #[arg(long)]
    allow_unstable: bool,
}

impl ScenarioArgs {
    fn options(&self) -> LoadOptions {
        let mut opts = if self.ignore_memory {
            LoadOptions::unlimited()
        } else {
            LoadOptions::default()
        };
        opts.allow_unstable = self.allow_unstable;
        opts
    }

    /// [`Self::options`] for a run on `backend`: a distributed factor is left out of
    /// the checks while loading (MUMPS's analysis checks it per node).
    fn options_for(&self, backend: Backend) -> LoadOptions {
        let mut opts = self.options();
        opts.distributed_factor = backend == Backend::Mumps;
        opts
    }

    /// The model, loaded for a run on `backend`.
    fn load_for(&self, backend: Backend) -> rothe::Result<rothe::model::Model> {
        rothe::config::load_with_overrides(
            &self.scenario,
            &self.options_for(backend),
            &self.overrides()?,
        )
    }

    fn overrides(&self) -> rothe::Result<Overrides> {
        let mut ov = Overrides::none();
        for v in &self.variants {
            ov = ov.variant(v)?;
        }
        for p in &self.unsets {
            ov = ov.unset(p);
        }
        for s in &self.sets {
            ov = ov.set(s)?;
        }
        Ok(ov)
    }
}

fn run_command(
    scenario: &ScenarioArgs,
    out: &Path,
    backend: Backend,
    quiet: bool,
    record_fields: bool,
    overwrite: bool,
) -> rothe::Result<()> {
    let model = scenario.load_for(backend)?;
    let summary = run(
        &model,
        &RunOptions {
            out: out.to_path_buf(),
            backend,
            progress: !quiet,
            memory_limit: scenario.options().memory_limit,
            record_fields,
            overwrite,
            hooks: Default::default(),
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
    // An environment variable out of range is refused by name before any work.
    if let Err(e) = rothe::simd::Simd::asked() {
        eprintln!("error: {e}");
        return ExitCode::FAILURE;
    }
    let input = match &cli.command {
        Command::Run { scenario, .. }
        | Command::Check { scenario, .. }
        | Command::Modes { scenario, .. } => scenario.scenario.clone(),
        Command::Material { file, .. } => file.clone(),
        Command::Compare { scenario, .. } => scenario.scenario.clone(),
        Command::Study { study } => match study {
            StudyCommand::Time { scenario, .. }
            | StudyCommand::Mesh { scenario, .. }
            | StudyCommand::Tolerance { scenario, .. } => scenario.scenario.clone(),
            StudyCommand::Collect { dir } => dir.clone(),
        },
        Command::Plot { dir } => dir.clone(),
        Command::Report { benchmarks, .. } => benchmarks.clone(),
    };
    let backend = match &cli.command {
        Command::Run { backend, .. }
        | Command::Modes { backend, .. }
        | Command::Check { backend, .. } => *backend,
        _ => Backend::Faer,
    };
    // The MPI backend's ranks other than 0 serve rank 0's solves and stop here.
    match rothe::linsolve::distributed::start(backend) {
        Ok(rothe::linsolve::distributed::Role::Served) => return ExitCode::SUCCESS,
        Ok(_) => {}
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::FAILURE;
        }
    }
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
            record_fields,
            overwrite,
        } => run_command(&scenario, &out, backend, quiet, record_fields, overwrite),
        Command::Study { study } => study_command(study),
        Command::Compare {
            scenario,
            sweep,
            implicit_scheme,
        } => scenario
            .overrides()
            .and_then(|base| {
                if let Some(w) = rothe::study::compare::replaced_scheme(
                    &scenario.scenario,
                    &base,
                    &implicit_scheme,
                )? {
                    eprintln!("warning: {w}");
                }
                rothe::study::compare::plan(&scenario.scenario, &base, &implicit_scheme)
            })
            .and_then(|plan| sweep.execute(&plan)),
        Command::Plot { dir } => rothe::plot::plot_run(&dir).map(|files| {
            for f in files {
                println!("wrote {}", f.display());
            }
        }),
        Command::Report {
            benchmarks,
            meshes,
            damage_meshes,
            compare_mesh,
            beam_size,
            sets,
            sweep,
        } => report_command(
            benchmarks,
            (meshes, damage_meshes),
            compare_mesh,
            beam_size,
            &sets,
            sweep,
        ),
        Command::Material { file, out } => rothe::point_driver::run_file(&file, &out, |m| {
            for l in rothe::check::material_lines(m) {
                eprintln!("{l}");
            }
            if m.nonlocal_radius().is_some() {
                eprintln!(
                    "(a single point is a uniform field: its nonlocal average is its own strain)"
                );
            }
        })
        .map(|steps| {
            eprintln!(
                "{steps} steps; wrote {}",
                out.join("material.csv").display()
            );
        }),
        Command::Modes {
            scenario,
            count,
            shift,
            around,
            out,
            overwrite,
            backend,
        } => scenario.load_for(backend).and_then(|model| {
            // Held while the modes are found and written: one writer per directory.
            let _lock = rothe::output::prepare(&out, overwrite)?;
            let opts = rothe::modal::ModalOptions {
                count,
                shift,
                around,
                backend,
            };
            let modes = rothe::modal::modes(&model, &opts)?;
            println!(
                "{} modes of {} free dofs in {} Lanczos steps (shift {:.4e} rad²/s²)",
                modes.modes.len(),
                modes.n_free,
                modes.steps,
                modes.shift
            );
            let sturm = &modes.sturm;
            println!(
                "Sturm check: {} eigenvalues {} by the inertia of K − μM, all found",
                sturm.count,
                if sturm.below.is_finite() {
                    format!(
                        "in [{:.6e}, {:.6e}) Hz",
                        rothe::modal::hz(sturm.below),
                        rothe::modal::hz(sturm.above)
                    )
                } else {
                    format!("below {:.6e} Hz", rothe::modal::hz(sturm.above))
                }
            );
            if let Some(note) = rothe::modal::history_note(&model) {
                println!("note: {note}");
            }
            println!("mode  f (Hz)          omega (rad/s)   residual");
            for m in &modes.modes {
                let w = m.omega();
                println!(
                    "{:>4}  {:<14.6e}  {:<14.6e}  {:.1e}{}",
                    m.number,
                    w / (2.0 * std::f64::consts::PI),
                    w,
                    m.residual,
                    if m.rigid { "  rigid" } else { "" }
                );
            }
            for f in rothe::output::modes::write(&model, &modes, &out)? {
                println!("wrote {}", f.display());
            }
            Ok(())
        }),
        Command::Check {
            scenario,
            matrices,
            backend,
        } => {
            let limit = scenario.options().memory_limit;
            scenario.load_for(backend).and_then(|model| {
                let report = rothe::check::report_with(&model, limit, backend)?;
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
            rothe::output::interrupt::mark_failed(&out.join("summary.json"), &e.to_string());
        }
        Err(e)
    });
    rothe::linsolve::distributed::finish();
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn study_command(study: StudyCommand) -> rothe::Result<()> {
    match study {
        StudyCommand::Time {
            scenario,
            h,
            halvings,
            reference_halvings,
            sweep,
        } => {
            let base = scenario.overrides()?;
            let hs = match halvings {
                Some(n) => rothe::study::time_study::halvings(&scenario.scenario, &base, n)?,
                None => h,
            };
            let plan =
                rothe::study::time_study::plan(&scenario.scenario, &base, &hs, reference_halvings)?;
            sweep.execute(&plan)
        }
        StudyCommand::Tolerance {
            scenario,
            tolerances,
            fixed_halvings,
            reference_dt,
            sweep,
        } => {
            let base = scenario.overrides()?;
            let plan = rothe::study::tolerance_study::plan(
                &scenario.scenario,
                &base,
                &tolerances,
                fixed_halvings,
                reference_dt,
            )?;
            sweep.execute(&plan)
        }
        StudyCommand::Mesh {
            scenario,
            sizes,
            sweep,
        } => {
            let base = scenario.overrides()?;
            let plan = rothe::study::mesh_study::plan(&scenario.scenario, &base, &sizes)?;
            sweep.execute(&plan)
        }
        StudyCommand::Collect { dir } => rothe::study::collect(&dir).and_then(|c| {
            println!("{}", c.markdown);
            c.all_completed()
        }),
    }
}

fn report_command(
    benchmarks: PathBuf,
    (meshes, damage_meshes): (Vec<f64>, Vec<f64>),
    compare_mesh: f64,
    beam_size: Option<f64>,
    sets: &[String],
    mut sweep: SweepArgs,
) -> rothe::Result<()> {
    let mut base = Overrides::none();
    for s in sets {
        base = base.set(s)?;
    }
    let opts = rothe::study::report::ReportOptions {
        benchmarks,
        meshes,
        damage_meshes,
        compare_mesh,
        beam_size,
        base,
    };
    if sweep.out == Path::new("out/study") {
        sweep.out = PathBuf::from("out/report");
    }
    let plan = rothe::study::report::plan(&opts)?;
    sweep.execute(&plan)
}
