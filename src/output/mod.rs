//! Output files, written as the run goes so a run stopped part way leaves valid files:
//! `history.csv` (one flushed row per step), VTK `.vtu` files with a `.pvd`
//! collection rewritten after each, and `summary.json` at the end (also on failure,
//! with the error).

pub mod checks;
pub mod fields;
pub mod history;
pub mod interrupt;
pub mod modes;
pub mod post;
pub mod recorder;
pub mod summary;
pub mod vtk;

use std::path::Path;

use crate::error::{Error, Result};

/// What a run writes into its output directory (files and directories).
pub const RUN_FILES: [&str; 7] = [
    "summary.json",
    "summary.json.tmp",
    "history.csv",
    "result.pvd",
    "fields.bin",
    "vtk",
    "plots",
];

/// Makes `out` ready for a new run: created if missing; an error if it is a file;
/// if it holds an earlier run's files, they are removed when `overwrite`, refused
/// otherwise, so that no stale `fields.bin`, VTK file or plot sits beside the new
/// summary. Files a run does not write are left alone.
pub fn prepare(out: &Path, overwrite: bool) -> Result<()> {
    if out.exists() && !out.is_dir() {
        return Err(Error::config(
            "--out",
            format!("`{}` is a file, not a directory", out.display()),
        ));
    }
    std::fs::create_dir_all(out).map_err(|e| Error::io(out, e))?;
    let found: Vec<&str> = RUN_FILES
        .iter()
        .copied()
        .filter(|f| out.join(f).symlink_metadata().is_ok())
        .collect();
    if found.is_empty() {
        return Ok(());
    }
    if !overwrite {
        return Err(Error::config(
            "--out",
            format!(
                "`{}` holds an earlier run ({}): pass --overwrite to replace it, or choose \
                 another directory",
                out.display(),
                found.join(", ")
            ),
        ));
    }
    for f in found {
        let p = out.join(f);
        let removed = if p.is_dir() {
            std::fs::remove_dir_all(&p)
        } else {
            std::fs::remove_file(&p)
        };
        removed.map_err(|e| Error::io(&p, e))?;
    }
    Ok(())
}
