//! SuiteSparse CHOLMOD backend (feature `cholmod`). Placeholder until implemented.

use super::{LowerCsc, SymmetricSolver};
use crate::error::{Error, Result};

/// CHOLMOD supernodal Cholesky.
pub struct CholmodCholesky;

impl CholmodCholesky {
    /// A new solver.
    pub fn new() -> Result<Self> {
        Err(Error::Solver {
            backend: "cholmod",
            message: "not implemented yet".into(),
        })
    }
}

impl SymmetricSolver for CholmodCholesky {
    fn name(&self) -> &'static str {
        "cholmod"
    }
    fn analyze(&mut self, _a: &LowerCsc) -> Result<()> {
        unreachable!()
    }
    fn factorize(&mut self, _a: &LowerCsc) -> Result<()> {
        unreachable!()
    }
    fn solve_in_place(&mut self, _rhs: &mut [f64]) -> Result<()> {
        unreachable!()
    }
    fn factor_nnz(&self) -> Option<usize> {
        None
    }
}
