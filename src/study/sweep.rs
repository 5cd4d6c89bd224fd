//! The in-process sweep: the plan's independent runs on the machine's cores, with
//! one progress display. Each run is an ordinary `rothe run` into its own directory
//! (the same files a cluster job writes), so collecting is the same either way. A
//! run that fails is reported and the others go on.

use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;

use super::plan::{Plan, PlannedRun};
use crate::config::{load_with_overrides, LoadOptions};
use crate::error::{Error, Result};
use crate::linsolve::Backend;
use crate::run::{run, RunOptions};

/// How to sweep.
#[derive(Clone, Debug)]
pub struct SweepOptions {
    /// Runs at once (default: the machine's cores).
    pub jobs: usize,
    /// Show the progress display on stderr.
    pub progress: bool,
    /// Backend of every run.
    pub backend: Backend,
}

impl Default for SweepOptions {
    fn default() -> Self {
        SweepOptions {
            jobs: std::thread::available_parallelism().map_or(1, |n| n.get()),
            progress: false,
            backend: Backend::Faer,
        }
    }
}

/// One run's outcome: its wall time, or the error.
#[derive(Debug)]
pub struct RunOutcome {
    /// The run's id.
    pub id: String,
    /// Wall time (s).
    pub seconds: f64,
    /// The error, if it failed.
    pub error: Option<String>,
}

fn one(dir: &Path, r: &PlannedRun, backend: Backend) -> Result<()> {
    let model = load_with_overrides(&r.scenario, &LoadOptions::default(), &r.overrides)?;
    let mut opts = RunOptions::new(Plan::run_dir(dir, r), backend);
    opts.record_fields = r.record_fields;
    run(&model, &opts).map(|_| ())
}

/// Writes `dir/plan.json` and runs every run of `plan` into `dir/runs/<id>`.
/// Runs are started longest first (by their order in the plan, which puts the
/// finest last) so the cores stay busy; the outcomes come back in plan order.
pub fn sweep(plan: &Plan, dir: &Path, opts: &SweepOptions) -> Result<Vec<RunOutcome>> {
    plan.write(dir)?;
    let n = plan.runs.len();
    let pb = if opts.progress {
        let pb = ProgressBar::new(n as u64);
        pb.set_style(
            ProgressStyle::with_template("{elapsed_precise} [{bar:30}] {pos}/{len} runs {msg}")
                .expect("valid template")
                .progress_chars("=> "),
        );
        pb
    } else {
        ProgressBar::hidden()
    };
    let running = AtomicUsize::new(0);
    let outcomes: Mutex<Vec<Option<RunOutcome>>> = Mutex::new((0..n).map(|_| None).collect());
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.jobs.max(1))
        .build()
        .map_err(|e| Error::Internal(format!("thread pool: {e}")))?;
    let order: Vec<usize> = (0..n).rev().collect();
    pool.install(|| {
        order.par_iter().with_max_len(1).for_each(|&i| {
            let r = &plan.runs[i];
            running.fetch_add(1, Ordering::Relaxed);
            pb.set_message(format!(
                "({} running) {}",
                running.load(Ordering::Relaxed),
                r.label
            ));
            let start = Instant::now();
            let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                one(dir, r, opts.backend)
            }))
            .unwrap_or_else(|p| Err(Error::Internal(crate::run::panic_message(p.as_ref()))));
            let seconds = start.elapsed().as_secs_f64();
            running.fetch_sub(1, Ordering::Relaxed);
            let error = result.err().map(|e| e.to_string());
            if let Some(e) = &error {
                // A failure is printed whether or not the progress display shows.
                pb.suspend(|| eprintln!("run {} ({}) failed: {e}", r.id, r.label));
            } else {
                pb.println(format!("run {} ({}) done in {seconds:.1} s", r.id, r.label));
            }
            pb.inc(1);
            outcomes.lock().expect("no poisoned lock")[i] = Some(RunOutcome {
                id: r.id.clone(),
                seconds,
                error,
            });
        })
    });
    pb.finish_and_clear();
    Ok(outcomes
        .into_inner()
        .expect("no poisoned lock")
        .into_iter()
        .map(|o| o.expect("every run reports"))
        .collect())
}
