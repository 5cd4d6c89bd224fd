//! A whole run as the `rothe run` command does it: build the integrator the analysis
//! asks for, march it to the end time, and hand every accepted state to the
//! recorder. Output is written as the run goes: `summary.json` exists from the first
//! step on with `status = "running"` and is refreshed at the VTK cadence and every few
//! seconds, so an interrupted run is never taken for a complete one; on failure it
//! records the error, and everything written before stays valid. A panic inside the
//! run is caught and reported as an internal error, with `status = "failed"`.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};

use crate::energy::Ledger;
use crate::error::{Error, Result};
use crate::linsolve::Backend;
use crate::material::store::StateStore;
use crate::model::{AnalysisKind, Model, TimeScheme};
use crate::output::checks::Checks;
use crate::output::recorder::{Recorder, Snapshot};
use crate::output::summary::{
    EnergySummary, MaterialSummary, RunStatus, SolverSummary, Summary, TimingSummary,
};
use crate::time::adaptive::{march_adaptive, AdaptiveControl};
use crate::time::backward_euler::BackwardEuler;
use crate::time::central_difference::CentralDifference;
use crate::time::march::{march, Marched, StepControl};
use crate::time::statics::Statics;
use crate::time::{Integrator, State};

/// How to run.
#[derive(Clone, Debug)]
pub struct RunOptions {
    /// Output directory (created if missing).
    pub out: PathBuf,
    /// Linear solver backend.
    pub backend: Backend,
    /// Show a progress bar on stderr.
    pub progress: bool,
    /// Refuse a factor whose memory estimate exceeds this many bytes, before it is
    /// allocated (`None`: no limit).
    pub memory_limit: Option<u64>,
    /// Also write every step's displacement to `fields.bin`
    /// ([`crate::output::fields`]), for the time study's error norms.
    pub record_fields: bool,
    /// Remove an earlier run's files from `out` (otherwise they are refused:
    /// [`crate::output::prepare`]).
    pub overwrite: bool,
    /// What a caller embedding the run keeps and watches (the Python module);
    /// the command line's runs take the default.
    pub hooks: Hooks,
}

/// What an embedding caller asks of a run besides its files.
#[derive(Clone, Debug, Default)]
pub struct Hooks {
    /// Write nothing (`out` is ignored): the run lives in memory only.
    pub no_files: bool,
    /// Keep the history's columns (and, with `record_fields`, every displacement)
    /// in memory for [`run_kept`] to return.
    pub keep: bool,
    /// Called after every accepted step; its answer may stop the run.
    pub observer: Option<Observer>,
}

/// What an observer sees after an accepted step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepInfo {
    /// The step just accepted.
    pub step: usize,
    /// Steps the run plans (`t_end / dt`).
    pub steps: usize,
    /// Its time (s).
    pub t: f64,
    /// Corrections the step took.
    pub iterations: usize,
    /// Kinetic energy (J).
    pub kinetic: f64,
    /// Stored energy (J).
    pub elastic: f64,
    /// Work of the loads and reactions (J).
    pub external_work: f64,
    /// Every dissipation line summed (J).
    pub dissipated: f64,
}

/// An observer's answer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Control {
    /// Go on.
    Continue,
    /// Stop cleanly here: the run ends `stopped`, its output valid up to this step.
    Stop,
    /// Stop because the user interrupted: the run ends `failed` (interrupted).
    Interrupt,
}

/// A run's observer (shared, callable from the thread the run marches on).
#[derive(Clone)]
pub struct Observer(pub std::sync::Arc<dyn Fn(&StepInfo) -> Control + Send + Sync>);

impl std::fmt::Debug for Observer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Observer")
    }
}

/// What [`run_kept`] returns besides the summary: the history's columns, the
/// recorded displacements (one state after the other) and the last state's
/// displacements and cell fields (stress, then each model's history fields).
#[derive(Clone, Debug, Default)]
pub struct Kept {
    /// `(history.csv column name, values)`.
    pub columns: Vec<(String, Vec<f64>)>,
    /// Every recorded state's displacements, `(states × dofs)` row by row (empty
    /// unless `record_fields`).
    pub fields: Vec<f64>,
    /// The last state's displacements.
    pub u: Vec<f64>,
    /// The last state's cell fields by name, with their components per cell.
    pub cells: Vec<(String, usize, Vec<f64>)>,
}

impl RunOptions {
    /// Options for a run into `out` on `backend`, quiet, without a memory limit,
    /// replacing an earlier run there (studies own their run directories).
    pub fn new(out: impl Into<PathBuf>, backend: Backend) -> Self {
        RunOptions {
            out: out.into(),
            backend,
            progress: false,
            memory_limit: None,
            record_fields: false,
            overwrite: true,
            hooks: Hooks::default(),
        }
    }
}

/// How often `summary.json` is refreshed while a run goes, besides the VTK cadence.
const SUMMARY_EVERY: Duration = Duration::from_secs(5);

fn progress(n: usize, show: bool) -> ProgressBar {
    if !show {
        return ProgressBar::hidden();
    }
    let pb = ProgressBar::new(n as u64);
    pb.set_style(
        ProgressStyle::with_template(
            "{elapsed_precise} [{bar:40}] step {pos}/{len} ({eta} left) {msg}",
        )
        .expect("valid template")
        .progress_chars("=> "),
    );
    pb
}

/// The recorder's view of `s`, with the Gauss-point state `points` built for output
/// when the state keeps it elsewhere.
fn snapshot<'a>(
    s: &'a State,
    points: Option<&'a [StateStore]>,
    iterations: usize,
    nl_residual: f64,
) -> Snapshot<'a> {
    Snapshot {
        step: s.step,
        t: s.t,
        u: &s.u,
        v: &s.v,
        ledger: &s.ledger,
        points: points.unwrap_or(&s.points),
        contact: &s.contact,
        iterations,
        nl_residual,
    }
}

/// The message of a caught panic.
pub fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a panic without a message".into())
}

/// Runs `model` and writes `history.csv`, `summary.json` and VTK files to `opts.out`.
pub fn run(model: &Model, opts: &RunOptions) -> Result<Summary> {
    run_kept(model, opts).map(|(summary, _)| summary)
}

/// Writes the summary where the run writes files.
fn write_summary(summary: &Summary, path: Option<&Path>) -> Result<()> {
    match path {
        Some(p) => summary.write(p),
        None => Ok(()),
    }
}

/// [`run`], with what `opts.hooks` asks: no files, the history and fields kept in
/// memory, an observer after every step. A run its observer stops ends `stopped`
/// (`Ok`); an interrupted one ends `failed` with [`Error::Interrupted`].
pub fn run_kept(model: &Model, opts: &RunOptions) -> Result<(Summary, Kept)> {
    let start = Instant::now();
    let files = !opts.hooks.no_files;
    // Held to the end of the run: one writer per directory.
    let _lock = if files {
        Some(crate::output::prepare(&opts.out, opts.overwrite)?)
    } else {
        None
    };
    let mut rec =
        Recorder::with_sinks(model, files.then_some(opts.out.as_path()), opts.hooks.keep)?;
    if opts.record_fields {
        if files {
            rec.record_fields(model, &opts.out)?;
        }
        if opts.hooks.keep {
            rec.keep_fields();
        }
    }
    let mut kept = Kept::default();
    let a = &model.analysis;
    let volume = crate::check::volume(model);
    for w in model.warnings.iter().chain(&volume.warnings) {
        eprintln!("warning: {w}");
    }
    let mut summary = Summary {
        status: RunStatus::Running,
        error: None,
        warnings: model
            .warnings
            .iter()
            .chain(&volume.warnings)
            .cloned()
            .collect(),
        dofs: model.mesh.n_dofs(),
        elements: model.mesh.n_elements(),
        steps: 0,
        t_end: 0.0,
        dt: a.time.dt,
        adaptive: a
            .time
            .adaptive
            .map(|_| crate::time::adaptive::AdaptiveReport::default()),
        scheme: (a.time.kind == AnalysisKind::Dynamic).then_some(a.time.scheme),
        rho_inf: (a.time.kind == AnalysisKind::Dynamic
            && a.time.scheme == TimeScheme::GeneralizedAlpha)
            .then_some(a.time.rho_inf),
        contact_predictor: (a.time.contact_predictor != crate::model::ContactPredictor::None)
            .then_some(a.time.contact_predictor),
        materials: model
            .materials
            .iter()
            .map(|m| (m.name.clone(), MaterialSummary::of(m)))
            .collect(),
        probes: Default::default(),
        contact: Default::default(),
        energy: EnergySummary::from(&Ledger::default()),
        checks: Checks::of(&Ledger::default()),
        timing: TimingSummary::zero(),
        solver: SolverSummary {
            backend: opts.backend.name().into(),
            factorizations: 0,
            reused_factors: 0,
            keep_factor: a.time.scheme.is_implicit() && a.iteration.refactor_rate.is_some(),
            fallbacks: 0,
            impact_steps: 0,
            impact_fallbacks: 0,
            iterations: 0,
            iterations_per_step: 0.0,
            max_step_iterations: 0,
            step_cuts: 0,
            factor_nnz: None,
        },
    };
    let summary_path = files.then(|| opts.out.join("summary.json"));
    let summary_path = summary_path.as_deref();
    write_summary(&summary, summary_path)?;
    // A watchdog or signal that ends the process marks this summary failed.
    let _registration = summary_path.map(crate::output::interrupt::register);
    // The march runs on a worker of the thread pool, so that its parallel passes
    // hand work to the other workers instead of waking the pool from outside and
    // blocking on it for each pass (which costs a pair of futex calls per pass and
    // keeps one more thread than cores runnable).
    let result = rayon::scope(|_| {
        catch_unwind(AssertUnwindSafe(|| match (a.time.kind, a.time.scheme) {
            (AnalysisKind::Dynamic, TimeScheme::CentralDifference) => CentralDifference::new(model)
                .and_then(|mut i| {
                    integrate(model, &mut i, opts, &mut rec, &mut summary, &mut kept)
                }),
            (
                AnalysisKind::Dynamic,
                TimeScheme::BackwardEuler | TimeScheme::Trapezoidal | TimeScheme::GeneralizedAlpha,
            ) => BackwardEuler::with_memory_limit(model, opts.backend, opts.memory_limit).and_then(
                |mut i| integrate(model, &mut i, opts, &mut rec, &mut summary, &mut kept),
            ),
            (AnalysisKind::Static, _) => {
                Statics::with_memory_limit(model, opts.backend, opts.memory_limit).and_then(
                    |mut i| integrate(model, &mut i, opts, &mut rec, &mut summary, &mut kept),
                )
            }
        }))
        .unwrap_or_else(|p| Err(Error::Internal(panic_message(p.as_ref()))))
    });
    summary.probes = rec.probes().clone();
    summary.timing.total_s = start.elapsed().as_secs_f64();
    let (columns, fields) = rec.take_kept();
    kept.columns = columns;
    kept.fields = fields;
    match result {
        Ok(()) => match summary
            .checks
            .first_failure(a.time.dt, true, energy_check_binds(model))
        {
            // A ledger that breaks the paper's checks over the whole run is no
            // completed run (theory/energy.md).
            Some((check, mut cause)) => {
                if a.time.kind == AnalysisKind::Static {
                    cause.push_str(
                        "; in statics a local softening band may have no equilibrium path \
                         under this control (a snap-back) at any step: make the damage \
                         nonlocal, or run it as dynamics",
                    );
                }
                let e = Error::Energy {
                    step: summary.steps,
                    t: summary.t_end,
                    check,
                    cause,
                };
                summary.status = RunStatus::Failed;
                summary.error = Some(e.to_string());
                write_summary(&summary, summary_path)?;
                Err(e)
            }
            None => {
                summary.status = RunStatus::Completed;
                for f in summary.checks.failures() {
                    let w = format!("energy check failed: {f} (theory/energy.md)");
                    eprintln!("warning: {}: {w}", opts.out.display());
                    summary.warnings.push(w);
                }
                write_summary(&summary, summary_path)?;
                Ok((summary, kept))
            }
        },
        Err(e @ Error::Stopped { .. }) => {
            summary.status = RunStatus::Stopped;
            summary.error = Some(e.to_string());
            write_summary(&summary, summary_path)?;
            Ok((summary, kept))
        }
        Err(e) => {
            summary.status = RunStatus::Failed;
            summary.error = Some(e.to_string());
            write_summary(&summary, summary_path)?;
            Err(e)
        }
    }
}

/// The summary's view of a state and an integrator.
/// `floor` is the energy checks' round-off floor (J), computed once per run.
fn fill<I: Integrator + ?Sized>(
    summary: &mut Summary,
    s: &State,
    (integrator, floor): (&I, f64),
    rec: &Recorder,
) {
    let facts = integrator.solver();
    let timing = integrator.timing();
    summary.steps = s.step;
    summary.t_end = s.t;
    summary.energy = EnergySummary::from(&s.ledger);
    summary.checks = checks_of(integrator.model(), s, floor);
    summary.probes = rec.probes().clone();
    summary.contact = rec.contact().clone();
    summary.timing.assembly_s = timing.assembly_s;
    summary.timing.factorization_s = timing.factorization_s;
    summary.timing.solve_s = timing.solve_s;
    summary.solver.backend = facts.backend.into();
    summary.solver.factorizations = facts.factorizations;
    summary.solver.reused_factors = facts.reused_factors;
    summary.solver.fallbacks = facts.fallbacks;
    summary.solver.impact_steps = facts.impact_steps;
    summary.solver.impact_fallbacks = facts.impact_fallbacks;
    summary.solver.factor_nnz = facts.factor_nnz;
}

/// Whether the check that no energy is created ends a run of `model` (central
/// differences) or is only reported ([`Checks::first_failure`]).
fn energy_check_binds(model: &Model) -> bool {
    let t = &model.analysis.time;
    t.kind == AnalysisKind::Dynamic && t.scheme == TimeScheme::CentralDifference
}

/// The energy checks of state `s` with the scheme's allowance and the model's
/// round-off `floor` (J).
fn checks_of(model: &Model, s: &State, floor: f64) -> Checks {
    let allowance = crate::output::checks::energy_allowance(model, s.step);
    Checks::with(&s.ledger, allowance, floor)
}

/// Steps between refreshes of the progress line's solver counts.
const PROGRESS_EVERY: usize = 50;

/// Iterations over the accepted steps.
#[derive(Default)]
struct Counts {
    iterations: usize,
    steps: usize,
    max: usize,
}

impl Counts {
    fn add(&mut self, iterations: usize) {
        self.iterations += iterations;
        self.steps += 1;
        self.max = self.max.max(iterations);
    }

    fn per_step(&self) -> f64 {
        self.iterations as f64 / self.steps.max(1) as f64
    }

    fn fill(&self, summary: &mut Summary, step_cuts: usize) {
        summary.solver.iterations = self.iterations;
        summary.solver.iterations_per_step = self.per_step();
        summary.solver.max_step_iterations = self.max;
        summary.solver.step_cuts = step_cuts;
    }

    /// The progress line's account of the solver.
    fn progress(&self, facts: &crate::time::SolverFacts) -> String {
        format!(
            "{:.2} iterations/step (max {}), {} factorisations, {} reused",
            self.per_step(),
            self.max,
            facts.factorizations,
            facts.reused_factors
        )
    }
}

/// Marches `integrator` from its initial state to the end time, recording every
/// accepted state and refreshing `summary.json`, and fills the summary (also when the
/// march fails part way).
fn integrate<I: Integrator>(
    model: &Model,
    integrator: &mut I,
    opts: &RunOptions,
    rec: &mut Recorder,
    summary: &mut Summary,
    kept: &mut Kept,
) -> Result<()> {
    let mut s = integrator.initial_state()?;
    // The energy checks' round-off floor, once per run (a pass over the elements).
    let floor = f64::EPSILON * crate::output::checks::reference_energy(model);
    // The Gauss-point state of a step the VTK series writes, when `s` keeps it in
    // nodal fields.
    let output_points = |integrator: &I, s: &State, rec: &Recorder| {
        rec.vtk_due(s.step, s.t)
            .then(|| integrator.output_points(s))
            .flatten()
    };
    let built = output_points(integrator, &s, rec);
    rec.record(model, &snapshot(&s, built.as_deref(), 0, 0.0))?;
    let summary_path = (!opts.hooks.no_files).then(|| opts.out.join("summary.json"));
    let summary_path = summary_path.as_deref();
    fill(summary, &s, (integrator, floor), rec);
    write_summary(summary, summary_path)?;
    let mut last_write = Instant::now();
    let n_steps = model.analysis.n_steps();
    let pb = progress(n_steps, opts.progress);
    let t_end = model.analysis.time.t_end;
    let mut counts = Counts::default();
    let mut step_cuts = 0;
    let adaptive = AdaptiveControl::of(model);
    let energy_binds = energy_check_binds(model);
    let adapted = std::cell::Cell::new(crate::time::adaptive::AdaptiveReport::default());
    let observe = |integrator: &I, s: &State, m: Marched| {
        match m {
            Marched::Step(report) => {
                counts.add(report.iterations);
                if s.step.is_multiple_of(PROGRESS_EVERY) {
                    let mut line = counts.progress(&integrator.solver());
                    if adaptive.is_some() {
                        let r = adapted.get();
                        line.push_str(&format!(
                            ", h = {:.3e} s, {} taken back",
                            integrator.h(),
                            r.steps_rejected
                        ));
                    }
                    pb.set_message(line);
                }
                let built = output_points(integrator, s, rec);
                let on_cadence = rec.vtk_due(s.step, s.t);
                let snap = snapshot(s, built.as_deref(), report.iterations, report.nl_residual);
                rec.record(model, &snap)?;
                // A ledger that breaks its own inequalities ends the run failed at the
                // step that broke it, its rows kept (theory/energy.md).
                if let Some((check, cause)) =
                    checks_of(model, s, floor).first_failure(integrator.h(), false, energy_binds)
                {
                    return Err(Error::Energy {
                        step: s.step,
                        t: s.t,
                        check,
                        cause,
                    });
                }
                pb.set_position(((s.t / t_end) * n_steps as f64) as u64);
                if on_cadence || last_write.elapsed() >= SUMMARY_EVERY {
                    fill(summary, s, (integrator, floor), rec);
                    counts.fill(summary, step_cuts);
                    if adaptive.is_some() {
                        summary.adaptive = Some(adapted.get());
                    }
                    write_summary(summary, summary_path)?;
                    last_write = Instant::now();
                }
                if let Some(o) = &opts.hooks.observer {
                    let l = &s.ledger;
                    let info = StepInfo {
                        step: s.step,
                        steps: n_steps,
                        t: s.t,
                        iterations: report.iterations,
                        kinetic: l.kinetic(),
                        elastic: l.elastic(),
                        external_work: l.external_work(),
                        dissipated: l.dissipated().total(),
                    };
                    match (o.0)(&info) {
                        Control::Continue => {}
                        Control::Stop => {
                            return Err(Error::Stopped {
                                step: s.step,
                                t: s.t,
                            })
                        }
                        Control::Interrupt => {
                            return Err(Error::Interrupted {
                                step: s.step,
                                t: s.t,
                            })
                        }
                    }
                }
            }
            Marched::Cut { h, reason } => {
                step_cuts += 1;
                pb.set_message(format!("step cut to h = {h:.3e} ({reason})"));
            }
            Marched::Rejected { h, eta, retry } => {
                pb.set_message(format!(
                    "h = {h:.3e} s: error {eta:.2e} above the tolerance, again at {retry:.3e} s"
                ));
            }
        }
        Ok(())
    };
    let outcome = match adaptive {
        None => march(integrator, &mut s, StepControl::of(model), observe),
        Some(control) => {
            let r = march_adaptive(integrator, &mut s, control, &adapted, observe);
            let adapted = adapted.get();
            summary.adaptive = Some(adapted);
            if let Some(w) = adapted.floor_warning() {
                eprintln!("warning: {w}");
                summary.warnings.push(w);
            }
            r
        }
    };
    pb.finish_and_clear();
    fill(summary, &s, (integrator, floor), rec);
    counts.fill(summary, step_cuts);
    if opts.hooks.keep {
        // The last state's fields, for the caller to read back.
        let built = if s.points.is_empty() {
            integrator.output_points(&s)
        } else {
            None
        };
        let points = built.as_deref().unwrap_or(&s.points);
        let stress = crate::output::post::cell_stress(model, &s.u, points);
        kept.cells = vec![(
            "stress".to_string(),
            6,
            stress.iter().flat_map(|c| c.iter().copied()).collect(),
        )];
        if !points.is_empty() {
            kept.cells.extend(
                crate::output::post::cell_history_fields(model, points)
                    .into_iter()
                    .map(|(name, v)| (name.to_string(), 1, v)),
            );
        }
        kept.u.clone_from(&s.u);
    }
    outcome
}
