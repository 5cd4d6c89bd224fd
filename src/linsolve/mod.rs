//! Sparse symmetric positive-definite solvers behind one trait.
//!
//! The contract is "symbolic once, numeric many": [`SymmetricSolver::analyze`] orders
//! and analyses a sparsity pattern once, [`SymmetricSolver::factorize`] refactorises
//! when the values change, [`SymmetricSolver::solve_in_place`] solves one right-hand
//! side and [`SymmetricSolver::solve_block_in_place`] a block of them (the factor is
//! read once for the whole block), as often as needed. Matrices come as the lower
//! triangle in CSC form ([`LowerCsc`]). A non-positive pivot is
//! [`Error::NotPositiveDefinite`] with the column it happened at.
//!
//! Backends: [`faer_backend::FaerCholesky`] (default, pure Rust) and, with the
//! `cholmod` feature, `cholmod_backend::CholmodCholesky` (SuiteSparse). An
//! elimination order proposed with [`SymmetricSolver::set_ordering`] is used by both,
//! so the two compare factorisation codes on the same factor.

pub mod distributed;
pub mod faer_backend;
pub mod ldlt;
pub mod ordering;
pub mod supernodal;

#[cfg(feature = "cholmod")]
pub mod cholmod_backend;

#[cfg(feature = "mumps")]
pub mod mumps;

use crate::error::{Error, Result};

/// Lower triangle (diagonal included) of a symmetric matrix in compressed sparse
/// columns, rows sorted within each column.
#[derive(Clone, Debug, Default)]
pub struct LowerCsc {
    /// Dimension.
    pub n: usize,
    /// Column pointers, `n + 1` entries.
    pub col_ptr: Vec<usize>,
    /// Row indices, sorted in each column, all `>=` the column index.
    pub row_idx: Vec<usize>,
    /// Values, one per row index.
    pub values: Vec<f64>,
}

impl LowerCsc {
    /// `y = A x` using the lower triangle as a symmetric matrix.
    pub fn sym_matvec(&self, x: &[f64], y: &mut [f64]) {
        y.fill(0.0);
        for j in 0..self.n {
            let mut acc = 0.0;
            for p in self.col_ptr[j]..self.col_ptr[j + 1] {
                let i = self.row_idx[p];
                let a = self.values[p];
                y[i] += a * x[j];
                if i != j {
                    acc += a * x[i];
                }
            }
            y[j] += acc;
        }
    }

    /// Diagonal entry of column `j` (zero if not stored).
    pub fn diagonal(&self, j: usize) -> f64 {
        let range = self.col_ptr[j]..self.col_ptr[j + 1];
        match self.row_idx[range.clone()].binary_search(&j) {
            Ok(k) => self.values[range.start + k],
            Err(_) => 0.0,
        }
    }
}

/// Which backend to use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Backend {
    /// faer's sparse Cholesky (pure Rust, default).
    #[default]
    Faer,
    /// SuiteSparse CHOLMOD (cargo feature `cholmod`).
    Cholmod,
    /// MUMPS over MPI, distributed over the ranks (cargo feature `mumps`).
    Mumps,
}

impl std::str::FromStr for Backend {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "faer" => Ok(Backend::Faer),
            "cholmod" => Ok(Backend::Cholmod),
            "mumps" => Ok(Backend::Mumps),
            _ => Err(format!(
                "unknown backend `{s}` (expected faer, cholmod or mumps)"
            )),
        }
    }
}

impl Backend {
    /// Name as written in outputs.
    pub fn name(self) -> &'static str {
        match self {
            Backend::Faer => "faer",
            Backend::Cholmod => "cholmod",
            Backend::Mumps => "mumps",
        }
    }

    /// A fresh solver of this backend, or an error if it was not compiled in.
    pub fn solver(self) -> Result<Box<dyn SymmetricSolver>> {
        match self {
            Backend::Faer => Ok(Box::new(faer_backend::FaerCholesky::new())),
            #[cfg(feature = "cholmod")]
            Backend::Cholmod => Ok(Box::new(cholmod_backend::CholmodCholesky::new()?)),
            #[cfg(not(feature = "cholmod"))]
            Backend::Cholmod => Err(Error::Solver {
                backend: "cholmod",
                message: "this build has no CHOLMOD backend; rebuild with `--features cholmod`"
                    .into(),
            }),
            #[cfg(feature = "mumps")]
            Backend::Mumps => Ok(Box::new(mumps::MumpsCholesky::new()?)),
            #[cfg(not(feature = "mumps"))]
            Backend::Mumps => Err(Error::Solver {
                backend: "mumps",
                message: NO_MUMPS.into(),
            }),
        }
    }
}

/// Why a build without the `mumps` feature refuses `--backend mumps`, and how to run it.
pub const NO_MUMPS: &str = "this build has no MUMPS backend; install libmumps-dev and \
    libopenmpi-dev, rebuild with `cargo build --release --features mumps`, and run \
    `mpirun -n N target/release/rothe run SCENARIO --backend mumps`";

/// `out` zeroed, then the sparse entries (repeated indices summed) added.
pub fn scatter_entries(entries: &[(usize, f64)], out: &mut [f64]) {
    out.fill(0.0);
    for &(i, v) in entries {
        out[i] += v;
    }
}

/// A sparse symmetric positive-definite direct solver.
pub trait SymmetricSolver: Send {
    /// Backend name.
    fn name(&self) -> &'static str;
    /// Orders and analyses the pattern of `a` (values are not read).
    fn analyze(&mut self, a: &LowerCsc) -> Result<()>;
    /// Numeric factorisation of `a`, whose pattern must be the analysed one.
    fn factorize(&mut self, a: &LowerCsc) -> Result<()>;
    /// Overwrites `rhs` with `A⁻¹ rhs`.
    fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<()> {
        self.solve_block_in_place(rhs, 1)
    }
    /// `out = A⁻¹ b` for the sparse `b` whose nonzeros are `entries` (repeated
    /// indices summed). The faer backend's supernodal solve visits only the
    /// elimination-tree reach of the nonzeros in its forward sweep; the default is a
    /// dense solve.
    fn solve_sparse(&mut self, entries: &[(usize, f64)], out: &mut [f64]) -> Result<()> {
        scatter_entries(entries, out);
        self.solve_in_place(out)
    }
    /// Overwrites the `n x ncols` column-major block `rhs` with `A⁻¹ rhs`, reading
    /// the factor once for all columns.
    fn solve_block_in_place(&mut self, rhs: &mut [f64], ncols: usize) -> Result<()>;
    /// Number of nonzeros of the factor `L`, once analysed.
    fn factor_nnz(&self) -> Option<usize>;
    /// Entries of `L` on and below the diagonal (without a storage's padding above
    /// it), once analysed; [`Self::factor_nnz`] where the two are the same.
    fn factor_lower_entries(&self) -> Option<usize> {
        self.factor_nnz()
    }
    /// Proposes an elimination order (`order[k]` eliminated `k`-th) for the next
    /// [`SymmetricSolver::analyze`].
    fn set_ordering(&mut self, order: Vec<usize>);
    /// The elimination order the last analysis used (`order[k]` eliminated `k`-th),
    /// when the backend exposes it.
    fn ordering(&self) -> Option<Vec<usize>>;
    /// Moves the numeric factor out, leaving the solver unfactorised with its
    /// analysis, for a caller that keeps the factors of several matrices of one
    /// pattern (the steps of an error-controlled run); `None` where the backend
    /// cannot hand it out, and then nothing changes.
    fn take_numeric(&mut self) -> Option<Vec<f64>> {
        None
    }
    /// Makes `values`, which [`SymmetricSolver::take_numeric`] gave on the same
    /// analysis, the factor again.
    fn put_numeric(&mut self, values: Vec<f64>) {
        let _ = values;
    }
    /// A distributed backend's analysis: the factor's size and each rank's share of
    /// the memory; `None` for a backend in this process alone.
    fn distributed(&self) -> Option<&distributed::DistributedAnalysis> {
        None
    }
}

pub(crate) fn not_analysed(backend: &'static str) -> Error {
    Error::Solver {
        backend,
        message: "factorize/solve called before analyze".into(),
    }
}

/// Checks a right-hand-side block's shape.
pub(crate) fn check_block(
    backend: &'static str,
    n: usize,
    rhs: &[f64],
    ncols: usize,
) -> Result<()> {
    if rhs.len() != n * ncols {
        return Err(Error::Solver {
            backend,
            message: format!(
                "right-hand side block has {} entries, the matrix {n} rows x {ncols} columns",
                rhs.len()
            ),
        });
    }
    Ok(())
}

/// The inverse of an elimination order: `inv[order[k]] = k`; `None` unless `order`
/// is a permutation of `0..n`.
pub fn inverse_order(order: &[usize]) -> Option<Vec<usize>> {
    let mut inv = vec![usize::MAX; order.len()];
    for (k, &v) in order.iter().enumerate() {
        if v >= order.len() || inv[v] != usize::MAX {
            return None;
        }
        inv[v] = k;
    }
    Some(inv)
}
