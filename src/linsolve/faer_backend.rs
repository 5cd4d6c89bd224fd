//! faer's sparse Cholesky `L Lᵀ` through the low-level API, so the symbolic analysis
//! is done once, and the factor values and the scratch memory are owned here and
//! reused by every refactorisation and solve (no allocation per step). The ordering
//! is faer's AMD unless an elimination order was proposed with `set_ordering` (the
//! nested dissection of `super::ordering`). Runs sequentially: on two cores faer's
//! parallel factorisation measured slower.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, LltRef, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};

use super::{not_analysed, LowerCsc, SymmetricSolver};
use crate::error::{Error, Result};

const NAME: &str = "faer";

/// faer sparse Cholesky with caller-owned buffers.
#[derive(Default)]
pub struct FaerCholesky {
    symbolic: Option<SymbolicCholesky<usize>>,
    l_values: Vec<f64>,
    factor_scratch: Option<MemBuffer>,
    solve_scratch: Option<MemBuffer>,
    factorized: bool,
    ordering: Option<(Vec<usize>, Vec<usize>)>,
}

impl FaerCholesky {
    /// A solver with nothing analysed yet.
    pub fn new() -> Self {
        Self::default()
    }

    fn pattern(a: &LowerCsc) -> SymbolicSparseColMatRef<'_, usize> {
        SymbolicSparseColMatRef::new_checked(a.n, a.n, &a.col_ptr, None, &a.row_idx)
    }
}

impl SymmetricSolver for FaerCholesky {
    fn name(&self) -> &'static str {
        NAME
    }

    fn analyze(&mut self, a: &LowerCsc) -> Result<()> {
        let ordering = match &self.ordering {
            Some((fwd, inv)) if fwd.len() == a.n => {
                SymmetricOrdering::Custom(PermRef::new_checked(fwd, inv, a.n))
            }
            _ => SymmetricOrdering::Amd,
        };
        let sym = factorize_symbolic_cholesky(
            Self::pattern(a),
            Side::Lower,
            ordering,
            Default::default(),
        )
        .map_err(|e| Error::Solver {
            backend: NAME,
            message: format!("symbolic analysis failed: {e:?}"),
        })?;
        let oom = |what: &str| Error::Solver {
            backend: NAME,
            message: format!("out of memory allocating the {what}"),
        };
        self.l_values = crate::memory::zeroed(sym.len_val());
        let freq = sym.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default());
        let sreq = StackReq::any_of(&[sym.solve_in_place_scratch::<f64>(1, Par::Seq)]);
        self.factor_scratch = Some(MemBuffer::try_new(freq).map_err(|_| oom("factor workspace"))?);
        self.solve_scratch = Some(MemBuffer::try_new(sreq).map_err(|_| oom("solve workspace"))?);
        self.symbolic = Some(sym);
        self.factorized = false;
        Ok(())
    }

    fn factorize(&mut self, a: &LowerCsc) -> Result<()> {
        let sym = self.symbolic.as_ref().ok_or_else(|| not_analysed(NAME))?;
        let mat = SparseColMatRef::new(Self::pattern(a), &a.values);
        let stack = MemStack::new(self.factor_scratch.as_mut().expect("set by analyze"));
        sym.factorize_numeric_llt::<f64>(
            &mut self.l_values,
            mat,
            Side::Lower,
            LltRegularization::default(),
            Par::Seq,
            stack,
            Default::default(),
        )
        .map_err(|e| Error::Solver {
            backend: NAME,
            message: format!(
                "numeric factorisation failed ({e:?}): the effective matrix is not positive \
                 definite (a body without supports in a static run, or a bad material)"
            ),
        })?;
        self.factorized = true;
        Ok(())
    }

    fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<()> {
        let sym = self.symbolic.as_ref().ok_or_else(|| not_analysed(NAME))?;
        if !self.factorized {
            return Err(not_analysed(NAME));
        }
        let n = rhs.len();
        let llt = LltRef::<usize, f64>::new(sym, &self.l_values);
        let stack = MemStack::new(self.solve_scratch.as_mut().expect("set by analyze"));
        llt.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(rhs, n, 1),
            Par::Seq,
            stack,
        );
        Ok(())
    }

    fn set_ordering(&mut self, order: Vec<usize>) {
        let mut inv = vec![0usize; order.len()];
        for (k, &v) in order.iter().enumerate() {
            inv[v] = k;
        }
        self.ordering = Some((order, inv));
    }

    fn factor_nnz(&self) -> Option<usize> {
        let sym = self.symbolic.as_ref()?;
        Some(match sym.raw() {
            SymbolicCholeskyRaw::Simplicial(s) => s.len_val(),
            SymbolicCholeskyRaw::Supernodal(s) => s.len_val(),
        })
    }
}
