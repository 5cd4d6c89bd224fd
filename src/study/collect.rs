//! Collecting a sweep: the runs' outputs read back ([`super::run_data`]), the study
//! kind's tables, plots and summary written from them, and the runs that did not
//! complete listed with their errors.

use std::path::Path;

use super::plan::{Plan, StudyKind};
use super::run_data::read_runs;
use crate::error::{Error, Result};

/// A collected study: its Markdown summary and the runs that did not complete.
pub struct Collected {
    /// The Markdown summary (also written to `study.md` or `report.md`).
    pub markdown: String,
    /// One line per run that did not complete: id, label, status and its own error.
    pub incomplete: Vec<String>,
    /// Runs in the plan.
    pub planned: usize,
}

impl Collected {
    /// `Ok` when every run completed, else [`Error::RunsFailed`] listing the others.
    pub fn all_completed(&self) -> Result<()> {
        if self.incomplete.is_empty() {
            return Ok(());
        }
        Err(Error::RunsFailed(format!(
            "{} of {} runs did not complete:\n  {}",
            self.incomplete.len(),
            self.planned,
            self.incomplete.join("\n  ")
        )))
    }
}

/// Collects the study in `dir`: reads `plan.json` and the runs' outputs and writes
/// the study's tables (`study.csv`), plots (`plots/`) and `study.md` (`report.md`
/// for the report), listing the runs that did not complete with their errors. A
/// plan none of whose runs left a summary (never run) is an error.
pub fn collect(dir: &Path) -> Result<Collected> {
    let plan = Plan::read(dir)?;
    let runs = read_runs(dir, &plan)?;
    if runs.iter().all(|r| r.summary.is_none()) {
        return Err(Error::RunsFailed(format!(
            "none of the {} planned runs in {} has a summary.json: run them first (runs.txt \
             or slurm.sh)",
            runs.len(),
            dir.join("runs").display()
        )));
    }
    let incomplete: Vec<String> = runs
        .iter()
        .filter(|r| !r.completed())
        .map(|r| {
            let error = r
                .summary
                .as_ref()
                .and_then(|s| s["error"].as_str())
                .map(|e| format!(": {e}"))
                .unwrap_or_default();
            format!("{} ({}): {}{error}", r.run.id, r.run.label, r.status_word())
        })
        .collect();
    let mut md = match plan.kind {
        StudyKind::Time => super::time_study::collect(dir, &runs)?,
        StudyKind::Mesh => super::mesh_study::collect(dir, &runs)?,
        StudyKind::Compare => super::compare::collect(dir, &runs)?,
        StudyKind::Report => super::report::collect(dir, &runs)?,
        StudyKind::Tolerance => super::tolerance_study::collect(dir, &runs)?,
    };
    if !incomplete.is_empty() {
        md.push_str("\n## Runs that did not complete\n\n");
        for m in &incomplete {
            md.push_str(&format!("- {m}\n"));
        }
    }
    let name = if plan.kind == StudyKind::Report {
        "report.md"
    } else {
        "study.md"
    };
    let path = dir.join(name);
    std::fs::write(&path, &md).map_err(|e| Error::io(&path, e))?;
    Ok(Collected {
        markdown: md,
        incomplete,
        planned: runs.len(),
    })
}
