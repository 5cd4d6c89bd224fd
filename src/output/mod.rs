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

/// What a modal analysis (`rothe modes`) writes into its output directory (its mode
/// shapes go into `vtk/`, which [`RUN_FILES`] names).
pub const MODES_FILES: [&str; 7] = [
    "modes.csv",
    "modes.json",
    "modes.pvd",
    "spectrum.png",
    "spectrum.svg",
    "step_effect.png",
    "step_effect.svg",
];

/// The lock file an output directory's writer holds (an advisory `flock`, released
/// when the process ends, however it ends).
pub const LOCK_FILE: &str = ".rothe.lock";

/// An output directory held by one writer: a second run, modal analysis or study
/// into the same directory is refused while this lives (another process or another
/// thread alike).
#[derive(Debug)]
pub struct OutputLock {
    _file: std::fs::File,
}

/// Makes `out` ready for a new run or modal analysis and holds it: created if
/// missing; an error if it is a file or another writer holds it; if it holds an
/// earlier run's or modal analysis's files, they are removed when `overwrite`,
/// refused otherwise, so that no stale `fields.bin`, VTK file or plot sits beside
/// the new summary and no `.pvd` names files that are gone. Files rothe does not
/// write are left alone.
pub fn prepare(out: &Path, overwrite: bool) -> Result<OutputLock> {
    if out.as_os_str().is_empty() {
        return Err(Error::config(
            "--out",
            "an empty path: name the output directory (`.` for the working directory)",
        ));
    }
    if out.exists() && !out.is_dir() {
        return Err(Error::config(
            "--out",
            format!("`{}` is a file, not a directory", out.display()),
        ));
    }
    std::fs::create_dir_all(out).map_err(|e| Error::io(out, e))?;
    let lock_path = out.join(LOCK_FILE);
    let file = std::fs::OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(&lock_path)
        .map_err(|e| Error::io(&lock_path, e))?;
    match file.try_lock() {
        Ok(()) => {}
        Err(std::fs::TryLockError::WouldBlock) => {
            return Err(Error::config(
                "--out",
                format!(
                    "`{}` is being written by another run or modal analysis (it holds \
                     `{LOCK_FILE}`): wait for it to end, or choose another directory",
                    out.display()
                ),
            ))
        }
        // A file system without locks (some network mounts): the run goes on
        // unguarded rather than not at all.
        Err(std::fs::TryLockError::Error(e)) if e.kind() == std::io::ErrorKind::Unsupported => {}
        Err(std::fs::TryLockError::Error(e)) => return Err(Error::io(&lock_path, e)),
    }
    let lock = OutputLock { _file: file };
    let found: Vec<&str> = RUN_FILES
        .iter()
        .chain(&MODES_FILES)
        .copied()
        .filter(|f| out.join(f).symlink_metadata().is_ok())
        .collect();
    if found.is_empty() {
        return Ok(lock);
    }
    if !overwrite {
        return Err(Error::config(
            "--out",
            format!(
                "`{}` holds an earlier run or modal analysis ({}): pass --overwrite to \
                 replace it, or choose another directory",
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
    Ok(lock)
}
