//! A whole run as the `rothe run` command does it: integrator, time loop, ledger and
//! output files. Output is written as the run goes; on failure `summary.json` records
//! the error and everything written before stays valid.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};

use crate::energy::{Ledger, StepIncrements};
use crate::error::{Error, Result};
use crate::linsolve::Backend;
use crate::material::store::StateStore;
use crate::model::{AnalysisKind, Model};
use crate::output::history::History;
use crate::output::post::cell_stress;
use crate::output::summary::{EnergySummary, ProbeSummary, SolverSummary, Summary, TimingSummary};
use crate::output::vtk::VtkSeries;
use crate::time::backward_euler::{BackwardEuler, DynState, StepReport};
use crate::time::{statics, Timing};

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

struct Recorder {
    history: History,
    vtk: Option<VtkSeries>,
    probes: BTreeMap<String, ProbeSummary>,
    samples: Vec<[f64; 2]>,
}

impl Recorder {
    fn new(model: &Model, opts: &RunOptions) -> Result<Self> {
        std::fs::create_dir_all(&opts.out).map_err(|e| Error::io(&opts.out, e))?;
        let names: Vec<String> = model.probes.iter().map(|p| p.name.clone()).collect();
        let history = History::create(&opts.out.join("history.csv"), &names)?;
        let vtk = if model.analysis.vtk_every > 0 {
            Some(VtkSeries::new(&opts.out, &model.mesh)?)
        } else {
            None
        };
        let probes = names
            .iter()
            .map(|n| (n.clone(), ProbeSummary::default()))
            .collect();
        Ok(Recorder {
            history,
            vtk,
            probes,
            samples: Vec::new(),
        })
    }

    fn record(
        &mut self,
        model: &Model,
        t: f64,
        ledger: &Ledger,
        it: usize,
        nl: f64,
        u: &[f64],
    ) -> Result<()> {
        self.samples.clear();
        for p in &model.probes {
            let s = [u[2 * p.node], u[2 * p.node + 1]];
            self.probes
                .get_mut(&p.name)
                .expect("probe registered")
                .sample(s[1]);
            self.samples.push(s);
        }
        self.history.row(t, ledger, it, nl, &self.samples)
    }

    fn vtk(
        &mut self,
        model: &Model,
        step: usize,
        t: f64,
        u: &[f64],
        v: &[f64],
        points: &[StateStore],
    ) -> Result<()> {
        if let Some(vtk) = &mut self.vtk {
            if step % model.analysis.vtk_every == 0 {
                let extra = if points.is_empty() {
                    Vec::new()
                } else {
                    crate::output::post::cell_history_fields(model, points)
                };
                vtk.write(step, t, u, v, &cell_stress(model, u, points), &extra)?;
            }
        }
        Ok(())
    }
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

/// Runs `model` and writes `history.csv`, `summary.json` and VTK files to `opts.out`.
pub fn run(model: &Model, opts: &RunOptions) -> Result<Summary> {
    let start = Instant::now();
    let mut rec = Recorder::new(model, opts)?;
    let a = &model.analysis;
    let n_steps = a.n_steps();
    let mut summary = Summary {
        status: "running".into(),
        error: None,
        dofs: model.mesh.n_dofs(),
        elements: model.mesh.n_elements(),
        steps: 0,
        t_end: 0.0,
        dt: a.dt,
        probes: BTreeMap::new(),
        energy: EnergySummary::from(&Ledger::default()),
        timing: TimingSummary::new(&Timing::default(), 0.0),
        solver: SolverSummary {
            backend: opts.backend.name().into(),
            factorizations: 0,
            iterations: 0,
            step_cuts: 0,
            factor_nnz: None,
        },
    };
    let result = match a.kind {
        AnalysisKind::Dynamic => run_dynamic(model, opts, n_steps, &mut rec, &mut summary),
        AnalysisKind::Static => run_static(model, opts, n_steps, &mut rec, &mut summary),
    };
    summary.probes = rec.probes.clone();
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

fn run_dynamic(
    model: &Model,
    opts: &RunOptions,
    n_steps: usize,
    rec: &mut Recorder,
    summary: &mut Summary,
) -> Result<()> {
    let mut be = BackwardEuler::new(model, opts.backend)?;
    let mut s = be.initial_state();
    summary.solver.factor_nnz = be.factor_nnz();
    rec.record(model, 0.0, &s.ledger, 0, 0.0, &s.u)?;
    rec.vtk(model, 0, 0.0, &s.u, &s.v, &s.points)?;
    let pb = progress(n_steps, opts.progress);
    let t_end = model.analysis.t_end;
    let mut step_cuts = 0;
    let outcome = march(&mut be, &mut s, |s, report| {
        match report {
            Marched::Step(report) => {
                summary.solver.iterations += report.iterations;
                rec.record(
                    model,
                    s.t,
                    &s.ledger,
                    report.iterations,
                    report.nl_residual,
                    &s.u,
                )?;
                rec.vtk(model, s.step, s.t, &s.u, &s.v, &s.points)?;
                pb.set_position(((s.t / t_end) * n_steps as f64) as u64);
            }
            Marched::Cut { h, reason } => {
                step_cuts += 1;
                pb.set_message(format!("step cut to h = {h:.3e} ({reason})"));
            }
        }
        Ok(())
    });
    summary.solver.step_cuts = step_cuts;
    pb.finish_and_clear();
    summary.steps = s.step;
    summary.t_end = s.t;
    summary.energy = EnergySummary::from(&s.ledger);
    summary.timing = TimingSummary::new(&be.timing, 0.0);
    summary.solver.backend = be.backend().into();
    summary.solver.factorizations = be.factorizations;
    outcome
}

/// What [`march`] reports to its observer.
pub enum Marched<'a> {
    /// A step was accepted.
    Step(&'a StepReport),
    /// A step did not converge and `h` was halved.
    Cut {
        /// The new step size.
        h: f64,
        /// Why the step failed.
        reason: String,
    },
}

/// Integrates `s` to the model's `t_end` with adaptive steps: a step that does not
/// converge is halved (up to `max_cuts` times in a row) and retried from the same
/// state; after four accepted steps at a reduced size the step doubles back, never
/// beyond the requested `dt`. `observe` sees every accepted step and every cut; an
/// error from it stops the march. On failure the error names the step and time, and
/// `s` holds the last accepted state.
pub fn march<F>(be: &mut BackwardEuler, s: &mut DynState, mut observe: F) -> Result<()>
where
    F: FnMut(&DynState, Marched) -> Result<()>,
{
    let a = &be.model().analysis;
    let (h0, t_end, max_cuts) = (a.dt, a.t_end, a.max_cuts);
    let mut h = h0;
    let (mut cuts_in_row, mut easy) = (0usize, 0usize);
    while s.t < t_end - 1e-9 * h0 {
        let h_try = h.min(t_end - s.t);
        if (h_try - be.h).abs() > 1e-12 * h0 {
            be.set_step(h_try)?;
        }
        match be.step(s) {
            Ok(report) => {
                observe(s, Marched::Step(&report))?;
                cuts_in_row = 0;
                if h < h0 {
                    easy += 1;
                    if easy >= 4 {
                        h = (2.0 * h).min(h0);
                        easy = 0;
                    }
                }
            }
            Err(Error::Stepping(msg)) if cuts_in_row < max_cuts => {
                cuts_in_row += 1;
                easy = 0;
                h *= 0.5;
                observe(s, Marched::Cut { h, reason: msg })?;
            }
            Err(e) => {
                let why = match e {
                    Error::Stepping(m) => m,
                    other => other.to_string(),
                };
                return Err(Error::Stepping(format!(
                    "step {} (t = {:.6e}) failed after {cuts_in_row} step cuts: {why}",
                    s.step + 1,
                    s.t + be.h
                )));
            }
        }
    }
    Ok(())
}

/// Takes `n` accepted steps of the current `h` (no cuts): for benches and studies.
/// Returns the number of linear solves.
pub fn march_steps(be: &mut BackwardEuler, s: &mut DynState, n: usize) -> Result<usize> {
    let mut solves = 0;
    for _ in 0..n {
        solves += be.step(s)?.iterations;
    }
    Ok(solves)
}

fn run_static(
    model: &Model,
    opts: &RunOptions,
    n_steps: usize,
    rec: &mut Recorder,
    summary: &mut Summary,
) -> Result<()> {
    let times: Vec<f64> = (1..=n_steps)
        .map(|k| k as f64 * model.analysis.dt)
        .collect();
    let sols = statics::solve(model, opts.backend, &times)?;
    let mut ledger = Ledger::new(0.0, 0.0);
    let n = model.mesh.n_dofs();
    let (mut u0, mut f0) = (vec![0.0; n], vec![0.0; n]);
    let zero = vec![0.0; n];
    for (k, sol) in sols.iter().enumerate() {
        // Static steps: W_ext (reactions included, f = K u) against stored energy.
        let mut inc = StepIncrements {
            elastic: sol.elastic,
            ..Default::default()
        };
        for i in 0..n {
            let du = sol.u[i] - u0[i];
            inc.external_work += 0.5 * du * (f0[i] + sol.fint[i]);
            inc.internal_work += 0.5 * du * (f0[i] + sol.fint[i]);
        }
        ledger.record(&inc);
        rec.record(model, times[k], &ledger, 1, 0.0, &sol.u)?;
        rec.vtk(model, k + 1, times[k], &sol.u, &zero, &[])?;
        u0.clone_from(&sol.u);
        f0.clone_from(&sol.fint);
        summary.solver.iterations += 1;
    }
    summary.steps = sols.len();
    summary.t_end = times.last().copied().unwrap_or(0.0);
    summary.energy = EnergySummary::from(&ledger);
    if let Some(s) = sols.first() {
        summary.timing = TimingSummary::new(&s.timing, 0.0);
        summary.timing.solve_s = sols.iter().map(|s| s.timing.solve_s).sum();
    }
    summary.solver.factorizations = 1;
    Ok(())
}
