//! faer's sparse Cholesky `L Lᵀ` through the low-level API, so the symbolic analysis
//! is done once, and the factor values and the scratch memory are owned here and
//! reused by every refactorisation and solve (no allocation per step). The ordering
//! is faer's AMD unless an elimination order was proposed with `set_ordering` (the
//! nested dissection of `super::ordering`). Runs sequentially: on two cores faer's
//! parallel factorisation measured slower.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::{LltError, LltRegularization};
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, LltRef, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};

use super::{check_block, not_analysed, LowerCsc, SymmetricSolver};
use crate::error::{Error, Result};

const NAME: &str = "faer";

/// faer sparse Cholesky with caller-owned buffers.
#[derive(Default)]
pub struct FaerCholesky {
    symbolic: Option<SymbolicCholesky<usize>>,
    l_values: Vec<f64>,
    factor_scratch: Option<MemBuffer>,
    solve_scratch: Option<MemBuffer>,
    /// Right-hand-side columns the solve scratch is sized for.
    solve_cols: usize,
    factorized: bool,
    ordering: Option<(Vec<usize>, Vec<usize>)>,
    /// rothe's own solves over the factor (a simplicial factor as supernodes of one
    /// column; `None` only if its layout is not the expected one).
    own: Option<super::supernodal::SupernodalSolver>,
}

impl FaerCholesky {
    /// A solver with nothing analysed yet.
    pub fn new() -> Self {
        Self::default()
    }

    fn pattern(a: &LowerCsc) -> SymbolicSparseColMatRef<'_, usize> {
        SymbolicSparseColMatRef::new_checked(a.n, a.n, &a.col_ptr, None, &a.row_idx)
    }

    /// The symbolic factor (supernodes, row indices, permutation) of the last
    /// analysis, and the numeric values of the last factorisation.
    pub fn factor(&self) -> Option<(&SymbolicCholesky<usize>, &[f64])> {
        match (&self.symbolic, self.factorized) {
            (Some(s), true) => Some((s, &self.l_values)),
            _ => None,
        }
    }

    /// Solves with faer's own triangular solves (the reference of rothe's
    /// supernodal ones, which the backend uses when the factor is supernodal).
    pub fn solve_with_faer(&mut self, rhs: &mut [f64], ncols: usize) -> Result<()> {
        if self.symbolic.is_none() || !self.factorized {
            return Err(not_analysed(NAME));
        }
        let n = self.symbolic.as_ref().map_or(0, |s| s.nrows());
        check_block(NAME, n, rhs, ncols)?;
        if n == 0 || ncols == 0 {
            return Ok(());
        }
        self.ensure_solve_scratch(ncols)?;
        let sym = self.symbolic.as_ref().expect("checked");
        let llt = LltRef::<usize, f64>::new(sym, &self.l_values);
        let stack = MemStack::new(self.solve_scratch.as_mut().expect("ensured"));
        llt.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(rhs, n, ncols),
            Par::Seq,
            stack,
        );
        Ok(())
    }

    /// rothe's own solver of the current factor (supernodal; a simplicial factor as
    /// one-column supernodes) and the factor's values (`None` before a
    /// factorisation).
    pub fn supernodal(&mut self) -> Option<(&mut super::supernodal::SupernodalSolver, &[f64])> {
        if !self.factorized {
            return None;
        }
        self.own.as_mut().map(|o| (o, self.l_values.as_slice()))
    }

    /// The original column eliminated `k`-th.
    fn original_column(&self, k: usize) -> usize {
        match self.symbolic.as_ref().and_then(|s| s.perm()) {
            Some(p) => p.arrays().0[k],
            None => k,
        }
    }

    fn ensure_solve_scratch(&mut self, ncols: usize) -> Result<()> {
        if ncols <= self.solve_cols && self.solve_scratch.is_some() {
            return Ok(());
        }
        let sym = self.symbolic.as_ref().ok_or_else(|| not_analysed(NAME))?;
        let req = StackReq::any_of(&[sym.solve_in_place_scratch::<f64>(ncols, Par::Seq)]);
        self.solve_scratch = Some(MemBuffer::try_new(req).map_err(|_| Error::Solver {
            backend: NAME,
            message: format!("out of memory allocating the solve workspace for {ncols} columns"),
        })?);
        self.solve_cols = ncols;
        Ok(())
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
        // The factor values and the workspace are allocated by the first numeric
        // factorisation, so the caller can check the memory the analysis implies
        // (`factor_nnz`) before it is taken.
        self.l_values = Vec::new();
        self.factor_scratch = None;
        self.own = match sym.raw() {
            SymbolicCholeskyRaw::Supernodal(sn) => {
                super::supernodal::SupernodalSolver::new(sn, sym.perm().map(|p| p.arrays().0))
            }
            SymbolicCholeskyRaw::Simplicial(sm) => {
                super::supernodal::SupernodalSolver::from_simplicial(
                    sm.col_ptr(),
                    sm.row_idx(),
                    sym.perm().map(|p| p.arrays().0),
                )
            }
        };
        self.symbolic = Some(sym);
        self.solve_scratch = None;
        self.solve_cols = 0;
        self.ensure_solve_scratch(1)?;
        self.factorized = false;
        Ok(())
    }

    fn factorize(&mut self, a: &LowerCsc) -> Result<()> {
        let sym = self.symbolic.as_ref().ok_or_else(|| not_analysed(NAME))?;
        self.factorized = false;
        let oom = |what: &str| Error::Solver {
            backend: NAME,
            message: format!("out of memory allocating the {what}"),
        };
        if self.l_values.len() != sym.len_val() {
            // First factorisation, or the values were handed out (`take_numeric`).
            self.l_values =
                crate::buffers::try_zeroed(sym.len_val()).ok_or_else(|| oom("factor values"))?;
        }
        if self.factor_scratch.is_none() {
            let freq = sym.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default());
            let mut scratch = MemBuffer::try_new(freq).map_err(|_| oom("factor workspace"))?;
            crate::buffers::touch(&mut scratch);
            self.factor_scratch = Some(scratch);
        }
        let mat = SparseColMatRef::new(Self::pattern(a), &a.values);
        let stack = MemStack::new(self.factor_scratch.as_mut().expect("set by analyze"));
        let simplicial = matches!(sym.raw(), SymbolicCholeskyRaw::Simplicial(_));
        let res = sym.factorize_numeric_llt::<f64>(
            &mut self.l_values,
            mat,
            Side::Lower,
            LltRegularization::default(),
            Par::Seq,
            stack,
            Default::default(),
        );
        if let Err(LltError::NonPositivePivot { index }) = res {
            // faer's simplicial code counts pivots from 1, its supernodal (dense)
            // code from 0 (checked by `pivot_column_is_named`).
            let k = if simplicial { index - 1 } else { index };
            let column = self.original_column(k);
            return Err(Error::NotPositiveDefinite {
                backend: NAME,
                column: Some(column),
                message: format!(
                    "numeric factorisation failed at column {column} (pivot {k} of {} in \
                     elimination order): the matrix is not positive definite",
                    a.n
                ),
            });
        }
        self.factorized = true;
        Ok(())
    }

    fn solve_block_in_place(&mut self, rhs: &mut [f64], ncols: usize) -> Result<()> {
        if self.symbolic.is_none() || !self.factorized {
            return Err(not_analysed(NAME));
        }
        let n = self.symbolic.as_ref().map_or(0, |s| s.nrows());
        check_block(NAME, n, rhs, ncols)?;
        if n == 0 || ncols == 0 {
            return Ok(());
        }
        if let Some(own) = &mut self.own {
            own.solve_in_place(&self.l_values, rhs, ncols);
            return Ok(());
        }
        self.solve_with_faer(rhs, ncols)
    }

    fn solve_sparse(&mut self, entries: &[(usize, f64)], out: &mut [f64]) -> Result<()> {
        if self.symbolic.is_none() || !self.factorized {
            return Err(not_analysed(NAME));
        }
        let n = self.symbolic.as_ref().map_or(0, |s| s.nrows());
        check_block(NAME, n, out, 1)?;
        if let Some(&(i, _)) = entries.iter().find(|(i, _)| *i >= n) {
            return Err(Error::Solver {
                backend: NAME,
                message: format!("sparse right-hand side entry {i} beyond the order {n}"),
            });
        }
        match &mut self.own {
            Some(own) => {
                own.solve_sparse(&self.l_values, entries, out);
                Ok(())
            }
            None => {
                super::scatter_entries(entries, out);
                self.solve_with_faer(out, 1)
            }
        }
    }

    fn set_ordering(&mut self, order: Vec<usize>) {
        match super::inverse_order(&order) {
            Some(inv) => self.ordering = Some((order, inv)),
            None => self.ordering = None,
        }
    }

    fn take_numeric(&mut self) -> Option<Vec<f64>> {
        if !self.factorized {
            return None;
        }
        self.factorized = false;
        Some(std::mem::take(&mut self.l_values))
    }

    fn put_numeric(&mut self, values: Vec<f64>) {
        if self.symbolic.as_ref().map(|s| s.len_val()) == Some(values.len()) {
            self.l_values = values;
            self.factorized = true;
        }
    }

    fn ordering(&self) -> Option<Vec<usize>> {
        let sym = self.symbolic.as_ref()?;
        Some(match sym.perm() {
            Some(p) => p.arrays().0.to_vec(),
            None => (0..sym.nrows()).collect(),
        })
    }

    fn factor_lower_entries(&self) -> Option<usize> {
        match &self.own {
            Some(own) => Some(own.lower_entries()),
            None => self.factor_nnz(),
        }
    }

    fn factor_nnz(&self) -> Option<usize> {
        let sym = self.symbolic.as_ref()?;
        Some(match sym.raw() {
            SymbolicCholeskyRaw::Simplicial(s) => s.len_val(),
            SymbolicCholeskyRaw::Supernodal(s) => s.len_val(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Tridiagonal `[-1, d_i, -1]` of size `n`, lower triangle.
    fn tridiagonal(d: &[f64]) -> LowerCsc {
        let n = d.len();
        let mut col_ptr = vec![0];
        let (mut row_idx, mut values) = (Vec::new(), Vec::new());
        for j in 0..n {
            row_idx.push(j);
            values.push(d[j]);
            if j + 1 < n {
                row_idx.push(j + 1);
                values.push(-1.0);
            }
            col_ptr.push(row_idx.len());
        }
        LowerCsc {
            n,
            col_ptr,
            row_idx,
            values,
        }
    }

    /// A dense SPD matrix of size `n` (forces faer's supernodal code) with one
    /// diagonal entry made negative.
    fn dense_with_bad_diagonal(n: usize, bad: usize) -> LowerCsc {
        let mut col_ptr = vec![0];
        let (mut row_idx, mut values) = (Vec::new(), Vec::new());
        for j in 0..n {
            for i in j..n {
                row_idx.push(i);
                values.push(if i == j {
                    if j == bad {
                        -1.0
                    } else {
                        2.0 * n as f64
                    }
                } else {
                    1.0
                });
            }
            col_ptr.push(row_idx.len());
        }
        LowerCsc {
            n,
            col_ptr,
            row_idx,
            values,
        }
    }

    #[test]
    fn a_dense_factor_counts_its_lower_triangle_without_the_padding() {
        // Dense: L has n (n + 1) / 2 nonzeros whatever the supernodes; faer also
        // stores the upper triangles of their diagonal blocks.
        let n = 120;
        let a = dense_with_bad_diagonal(n, n); // no bad pivot: `bad` out of range
        let mut f = FaerCholesky::new();
        f.analyze(&a).unwrap();
        assert!(matches!(
            f.symbolic.as_ref().unwrap().raw(),
            SymbolicCholeskyRaw::Supernodal(_)
        ));
        assert_eq!(f.factor_lower_entries(), Some(n * (n + 1) / 2));
        assert!(f.factor_nnz().unwrap() > n * (n + 1) / 2);
    }

    #[test]
    fn pivot_column_is_named() {
        // Simplicial: a long tridiagonal matrix with a negative diagonal entry. The
        // first bad pivot is at that column or one eliminated after it; for this
        // matrix with diagonal 4 elsewhere the breakdown is at the entry itself.
        let mut d = vec![4.0; 300];
        d[137] = -4.0;
        let a = tridiagonal(&d);
        let mut s = FaerCholesky::new();
        s.analyze(&a).unwrap();
        match s.factorize(&a) {
            Err(Error::NotPositiveDefinite { column, .. }) => assert_eq!(column, Some(137)),
            other => panic!("expected a pivot error, got {other:?}"),
        }
        // Supernodal: a dense block.
        let a = dense_with_bad_diagonal(120, 71);
        let mut s = FaerCholesky::new();
        s.analyze(&a).unwrap();
        match s.factorize(&a) {
            Err(Error::NotPositiveDefinite {
                column, message, ..
            }) => {
                assert_eq!(column, Some(71), "{message}")
            }
            other => panic!("expected a pivot error, got {other:?}"),
        }
    }

    #[test]
    fn a_block_solve_equals_the_single_solves() {
        let d: Vec<f64> = (0..200).map(|i| 3.0 + (i % 5) as f64).collect();
        let a = tridiagonal(&d);
        let mut s = FaerCholesky::new();
        s.analyze(&a).unwrap();
        s.factorize(&a).unwrap();
        let k = 5;
        let block: Vec<f64> = (0..200 * k).map(|i| ((i * 7) % 13) as f64 - 6.0).collect();
        let mut x = block.clone();
        s.solve_block_in_place(&mut x, k).unwrap();
        for c in 0..k {
            let mut y = block[c * 200..(c + 1) * 200].to_vec();
            s.solve_in_place(&mut y).unwrap();
            for i in 0..200 {
                assert!((y[i] - x[c * 200 + i]).abs() <= 1e-14 * y[i].abs().max(1.0));
            }
        }
        assert!(s.solve_block_in_place(&mut x[..10], k).is_err());
    }
}
