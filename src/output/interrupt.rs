//! Runs ended from outside their own thread: a watchdog or a signal handler that
//! must stop the process (the MPI backend's timeouts, a rank that died) first marks
//! every run in progress `failed` with its reason, so what the run wrote stays valid
//! and is never taken for a complete run.
//!
//! Every file write that such an ending could cut in half (a `history.csv` row and
//! its flush, a `summary.json` refresh) holds the [`hold`] lock; [`fail_runs`]
//! takes that lock and never gives it back, so after it no row or summary is written
//! before the process exits.

use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

static RUNS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
static WRITES: Mutex<()> = Mutex::new(());

fn lock<T>(m: &'static Mutex<T>) -> MutexGuard<'static, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// A run in progress, known by its `summary.json`; forgotten when dropped.
#[derive(Debug)]
pub struct Registration(PathBuf);

impl Drop for Registration {
    fn drop(&mut self) {
        let mut runs = lock(&RUNS);
        if let Some(i) = runs.iter().position(|p| *p == self.0) {
            runs.swap_remove(i);
        }
    }
}

/// Registers a run whose summary is `summary`, until the registration is dropped.
pub fn register(summary: &Path) -> Registration {
    lock(&RUNS).push(summary.to_path_buf());
    Registration(summary.to_path_buf())
}

/// Held while a file that [`fail_runs`] must not cut is written.
pub fn hold() -> MutexGuard<'static, ()> {
    lock(&WRITES)
}

/// Marks every registered run failed with `message` and keeps the write lock, so
/// that nothing more is written; the caller then ends the process.
pub fn fail_runs(message: &str) {
    let guard = lock(&WRITES);
    for path in lock(&RUNS).iter() {
        mark_failed(path, message);
    }
    std::mem::forget(guard);
}

/// Sets `status = "failed"` and `error` in the summary at `path` (made if missing),
/// atomically, keeping every other key.
pub fn mark_failed(path: &Path, message: &str) {
    let mut v: serde_json::Value = std::fs::read_to_string(path)
        .ok()
        .and_then(|s| serde_json::from_str(&s).ok())
        .unwrap_or_else(|| serde_json::json!({}));
    v["status"] = super::summary::RunStatus::Failed.as_str().into();
    v["error"] = message.into();
    // The counters of the last refresh may lag the history by thousands of steps:
    // the summary describes the history's last row (whole: its writes hold the
    // lock the caller holds or that no other writer takes any more).
    if let Some((steps, t)) = last_row(&path.with_file_name("history.csv")) {
        v["steps"] = steps.into();
        v["t_end"] = t.into();
    }
    if let Ok(text) = serde_json::to_string_pretty(&v) {
        let _ = std::fs::create_dir_all(path.parent().unwrap_or(Path::new(".")));
        let tmp = path.with_extension("json.failed");
        if std::fs::write(&tmp, text).is_ok() {
            let _ = std::fs::rename(&tmp, path);
        }
    }
}

/// The step count and time of a `history.csv`'s last row (rows after the header and
/// the initial state's), if it has one.
fn last_row(path: &Path) -> Option<(usize, f64)> {
    use std::io::BufRead;
    let file = std::fs::File::open(path).ok()?;
    let mut rows = 0usize;
    let mut last = String::new();
    for line in std::io::BufReader::new(file).lines() {
        let line = line.ok()?;
        if !line.is_empty() {
            rows += 1;
            last = line;
        }
    }
    let t: f64 = last.split(',').next()?.trim().parse().ok()?;
    Some((rows.checked_sub(2)?, t))
}
