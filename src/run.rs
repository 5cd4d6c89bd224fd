//! A whole run as the `rothe run` command does it: build the integrator the analysis
//! asks for, march it to the end time, and hand every accepted state to the
//! recorder. Output is written as the run goes; on failure `summary.json` records the
//! error and everything written before stays valid.

use std::path::PathBuf;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};

use crate::energy::Ledger;
use crate::error::Result;
use crate::linsolve::Backend;
use crate::model::{AnalysisKind, Model};
use crate::output::recorder::{Recorder, Snapshot};
use crate::output::summary::{EnergySummary, SolverSummary, Summary, TimingSummary};
use crate::time::backward_euler::BackwardEuler;
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
}

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

fn snapshot(s: &State, iterations: usize, nl_residual: f64) -> Snapshot<'_> {
    Snapshot {
        step: s.step,
        t: s.t,
        u: &s.u,
        v: &s.v,
        ledger: &s.ledger,
        points: &s.points,
        iterations,
        nl_residual,
    }
}

/// Runs `model` and writes `history.csv`, `summary.json` and VTK files to `opts.out`.
pub fn run(model: &Model, opts: &RunOptions) -> Result<Summary> {
    let start = Instant::now();
    let mut rec = Recorder::new(model, &opts.out)?;
    let a = &model.analysis;
    let mut summary = Summary {
        status: "running".into(),
        error: None,
        dofs: model.mesh.n_dofs(),
        elements: model.mesh.n_elements(),
        steps: 0,
        t_end: 0.0,
        dt: a.dt,
        probes: Default::default(),
        energy: EnergySummary::from(&Ledger::default()),
        timing: TimingSummary::zero(),
        solver: SolverSummary {
            backend: opts.backend.name().into(),
            factorizations: 0,
            iterations: 0,
            step_cuts: 0,
            factor_nnz: None,
        },
    };
    let result = match a.kind {
        AnalysisKind::Dynamic => BackwardEuler::new(model, opts.backend)
            .and_then(|mut i| integrate(model, &mut i, opts, &mut rec, &mut summary)),
        AnalysisKind::Static => Statics::new(model, opts.backend)
            .and_then(|mut i| integrate(model, &mut i, opts, &mut rec, &mut summary)),
    };
    summary.probes = rec.probes().clone();
    summary.timing.total_s = start.elapsed().as_secs_f64();
    match result {
        Ok(()) => {
            summary.status = "completed".into();
            summary.write(&opts.out.join("summary.json"))?;
            Ok(summary)
        }
        Err(e) => {
            summary.status = "failed".into();
            summary.error = Some(e.to_string());
            summary.write(&opts.out.join("summary.json"))?;
            Err(e)
        }
    }
}

/// Marches `integrator` from its initial state to the end time, recording every
/// accepted state, and fills the summary (also when the march fails part way).
fn integrate<I: Integrator>(
    model: &Model,
    integrator: &mut I,
    opts: &RunOptions,
    rec: &mut Recorder,
    summary: &mut Summary,
) -> Result<()> {
    let mut s = integrator.initial_state()?;
    rec.record(model, &snapshot(&s, 0, 0.0))?;
    let n_steps = model.analysis.n_steps();
    let pb = progress(n_steps, opts.progress);
    let t_end = model.analysis.t_end;
    let (mut iterations, mut step_cuts) = (0, 0);
    let control = StepControl::of(model);
    let outcome = march(integrator, &mut s, control, |s, m| {
        match m {
            Marched::Step(report) => {
                iterations += report.iterations;
                rec.record(model, &snapshot(s, report.iterations, report.nl_residual))?;
                pb.set_position(((s.t / t_end) * n_steps as f64) as u64);
            }
            Marched::Cut { h, reason } => {
                step_cuts += 1;
                pb.set_message(format!("step cut to h = {h:.3e} ({reason})"));
            }
        }
        Ok(())
    });
    pb.finish_and_clear();
    let facts = integrator.solver();
    let timing = integrator.timing();
    summary.steps = s.step;
    summary.t_end = s.t;
    summary.energy = EnergySummary::from(&s.ledger);
    summary.timing = TimingSummary {
        assembly_s: timing.assembly_s,
        factorization_s: timing.factorization_s,
        solve_s: timing.solve_s,
        total_s: 0.0,
    };
    summary.solver = SolverSummary {
        backend: facts.backend.into(),
        factorizations: facts.factorizations,
        iterations,
        step_cuts,
        factor_nnz: facts.factor_nnz,
    };
    outcome
}
