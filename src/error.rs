//! One error type for the whole crate.
//!
//! Invalid input and broken invariants are errors that carry the place and the value
//! (a scenario field path, an element index, a pivot). A solve that ran and did not
//! converge is not an error but an outcome the caller acts on (see `time`).

use std::path::PathBuf;

/// Everything that can go wrong in rothe, each variant naming where.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A scenario or material file field is missing, unknown or out of range.
    #[error("{field}: {message}")]
    Config {
        /// Dotted path of the field, e.g. `materials.concrete.nu`.
        field: String,
        /// What is wrong with it.
        message: String,
    },
    /// The mesh is unusable: an inverted or degenerate element, a bad set, a bad file.
    #[error("mesh: {0}")]
    Mesh(String),
    /// The linear solver failed (e.g. the matrix is not positive definite).
    #[error("linear solver ({backend}): {message}")]
    Solver {
        /// Backend name.
        backend: &'static str,
        /// What failed.
        message: String,
    },
    /// A factorisation met a non-positive pivot: the matrix is not positive definite.
    #[error("linear solver ({backend}): {message}")]
    NotPositiveDefinite {
        /// Backend name.
        backend: &'static str,
        /// The column of the matrix handed to the solver (its own numbering) at
        /// which the factorisation broke down, when the backend tells.
        column: Option<usize>,
        /// What failed, with the pivot.
        message: String,
    },
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file involved.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The time integration could not continue.
    #[error("time stepping: {0}")]
    Stepping(String),
    /// A modal analysis (eigenpairs, the mesh's stable step) could not find what
    /// was asked.
    #[error("modal analysis: {0}")]
    Modal(String),
    /// The model would not fit in the memory available.
    #[error("memory: {message}")]
    Memory {
        /// The estimate and what is available.
        message: String,
    },
    /// A quantity of the state stopped being a finite number.
    #[error("non-finite value at t = {t:.6e}: {quantity} is {value}{}", .location.as_ref().map(|l| format!(" at {l}")).unwrap_or_default())]
    NonFinite {
        /// Which quantity (`u`, `f_int`, a ledger line, ...).
        quantity: String,
        /// Its value (NaN or an infinity).
        value: f64,
        /// Where: the dof (node, coordinates, body, element), when it is one dof.
        location: Option<String>,
        /// Time of the step.
        t: f64,
    },
    /// Runs of a study or sweep did not complete (each listed with its own error);
    /// what the others gave was collected.
    #[error("{0}")]
    RunsFailed(String),
    /// The run's observer asked it to stop (a progress callback), after `step`.
    #[error("stopped by the caller after step {step} (t = {t:.6e} s)")]
    Stopped {
        /// The last accepted step.
        step: usize,
        /// Its time.
        t: f64,
    },
    /// The run was interrupted (Ctrl-C) after `step`.
    #[error("interrupted after step {step} (t = {t:.6e} s)")]
    Interrupted {
        /// The last accepted step.
        step: usize,
        /// Its time.
        t: f64,
    },
    /// The ledger broke one of its own inequalities (energy created, or more
    /// dissipated than the work put in) at `step`: the numbers cannot be right.
    #[error("energy check failed at step {step} (t = {t:.6e} s): {check}; {cause}")]
    Energy {
        /// The step whose ledger broke the check.
        step: usize,
        /// Its time.
        t: f64,
        /// The check, as `name: lhs > rhs`.
        check: String,
        /// What makes a run break it and what to change.
        cause: String,
    },
    /// A bug: something that must not happen did (a panic caught at the top).
    #[error("internal error (please report it with the input file): {0}")]
    Internal(String),
}

impl Error {
    /// Shorthand for a configuration error at `field`.
    pub fn config(field: impl Into<String>, message: impl Into<String>) -> Self {
        Error::Config {
            field: field.into(),
            message: message.into(),
        }
    }

    /// Shorthand for an I/O error on `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }
}

/// Result with the crate's error.
pub type Result<T, E = Error> = std::result::Result<T, E>;
