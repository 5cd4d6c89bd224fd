//! One planned run's output read back from `runs/<id>` (its `summary.json` and
//! `history.csv`), whether the in-process sweep or a cluster wrote it, and what the
//! study kinds read of it.

use std::path::{Path, PathBuf};

use serde_json::Value;

use super::plan::{Plan, PlannedRun};
use crate::error::{Error, Result};
use crate::output::summary::RunStatus;
use crate::plot::History;

/// One run's output as read back.
pub struct RunData {
    /// The planned run.
    pub run: PlannedRun,
    /// Its directory.
    pub dir: PathBuf,
    /// `summary.json` (`None` when missing).
    pub summary: Option<Value>,
    /// `history.csv` (`None` when missing).
    pub history: Option<History>,
}

impl RunData {
    /// What its `summary.json` says (`None`: no summary, or no status in it).
    pub fn status(&self) -> Option<RunStatus> {
        self.summary
            .as_ref()
            .and_then(|s| s["status"].as_str())
            .and_then(RunStatus::parse)
    }

    /// The status as a word for tables and messages: `completed`, `failed`,
    /// `running` (or killed) or `missing`.
    pub fn status_word(&self) -> &'static str {
        self.status().map_or("missing", RunStatus::as_str)
    }

    /// Whether the run completed.
    pub fn completed(&self) -> bool {
        self.status() == Some(RunStatus::Completed)
    }

    /// A number of the summary by its JSON pointer (`/energy/kinetic_0`).
    pub fn number(&self, pointer: &str) -> Option<f64> {
        self.summary
            .as_ref()
            .and_then(|s| s.pointer(pointer))
            .and_then(Value::as_f64)
    }

    /// The initial kinetic energy.
    pub fn kinetic_0(&self) -> f64 {
        self.number("/energy/kinetic_0").unwrap_or(0.0)
    }

    /// A dissipation line's final value (`viscous`, ..., `numerical`).
    pub fn dissipated(&self, line: &str) -> f64 {
        self.number(&format!("/energy/dissipated/{line}"))
            .unwrap_or(f64::NAN)
    }

    /// Total dissipation (every line).
    pub fn dissipated_total(&self) -> f64 {
        DISSIPATION_LINES.iter().map(|l| self.dissipated(l)).sum()
    }

    /// Material dissipation (viscous + damage + plastic).
    pub fn dissipated_material(&self) -> f64 {
        ["viscous", "damage", "plastic"]
            .iter()
            .map(|l| self.dissipated(l))
            .sum()
    }

    /// The smallest (most downward) vertical displacement of a probe.
    pub fn probe_min(&self, probe: &str) -> f64 {
        self.number(&format!("/probes/{probe}/min_uy"))
            .unwrap_or(f64::NAN)
    }

    /// The names of the probes.
    pub fn probes(&self) -> Vec<String> {
        self.summary
            .as_ref()
            .and_then(|s| s["probes"].as_object())
            .map(|o| o.keys().cloned().collect())
            .unwrap_or_default()
    }

    /// Whether both energy checks hold.
    pub fn checks_hold(&self) -> bool {
        let c = |k: &str| {
            self.summary
                .as_ref()
                .and_then(|s| s["checks"][k]["holds"].as_bool())
                .unwrap_or(false)
        };
        c("dissipation_within_internal_work") && c("dissipation_within_supplied_energy")
    }

    /// Wall time of the run (s), as its summary recorded it.
    pub fn seconds(&self) -> f64 {
        self.number("/timing/total_s").unwrap_or(f64::NAN)
    }

    /// The history column `name` (empty when missing).
    pub fn column(&self, name: &str) -> Vec<f64> {
        self.history
            .as_ref()
            .and_then(|h| h.column(name))
            .unwrap_or_default()
    }

    /// `(t [ms], column × factor)` points of the history.
    pub fn series(&self, name: &str, factor: f64) -> Vec<(f64, f64)> {
        self.column("t")
            .iter()
            .zip(self.column(name))
            .map(|(t, v)| (t * 1e3, v * factor))
            .collect()
    }

    /// The total dissipation against time, `(t [ms], ΣD / scale)`.
    pub fn dissipation_series(&self, scale: f64) -> Vec<(f64, f64)> {
        let cols: Vec<Vec<f64>> = DISSIPATION_COLUMNS.iter().map(|c| self.column(c)).collect();
        self.column("t")
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let d: f64 = cols.iter().map(|c| c.get(i).copied().unwrap_or(0.0)).sum();
                (t * 1e3, d / scale)
            })
            .collect()
    }
}

/// The dissipation lines of `summary.json`.
pub const DISSIPATION_LINES: [&str; 8] = [
    "viscous",
    "damage",
    "plastic",
    "contact",
    "friction",
    "predictor",
    "mass",
    "numerical",
];

/// The dissipation columns of `history.csv`.
pub const DISSIPATION_COLUMNS: [&str; 8] = [
    "D_viscous",
    "D_damage",
    "D_plastic",
    "D_contact",
    "D_friction",
    "D_predictor",
    "D_mass",
    "D_num",
];

/// Reads every planned run's output from `dir/runs/<id>`.
pub fn read_runs(dir: &Path, plan: &Plan) -> Result<Vec<RunData>> {
    plan.runs
        .iter()
        .map(|r| {
            let rd = Plan::run_dir(dir, r);
            let sp = rd.join("summary.json");
            let summary = match std::fs::read_to_string(&sp) {
                Ok(text) => Some(serde_json::from_str(&text).map_err(|e| {
                    Error::io(&sp, std::io::Error::other(format!("not JSON: {e}")))
                })?),
                Err(_) => None,
            };
            let hp = rd.join("history.csv");
            let history = if hp.is_file() {
                Some(History::read(&hp)?)
            } else {
                None
            };
            Ok(RunData {
                run: r.clone(),
                dir: rd,
                summary,
                history,
            })
        })
        .collect()
}
