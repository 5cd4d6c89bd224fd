//! faer's sparse `L D Lᵀ` of a symmetric matrix that need not be positive definite
//! (`K − σM` with a shift inside the spectrum), without pivoting, and its inertia.
//!
//! By Sylvester's law of inertia the signs of `D` are those of the eigenvalues of
//! the matrix, so the number of negative pivots of `K − μM` is the number of
//! eigenvalues of `K x = λ M x` below `μ` (`M` positive definite): the Sturm count a
//! modal analysis checks its eigenvalues against (`theory/modal.md`). Without
//! pivoting a pivot can be small (a shift near an eigenvalue); an exactly zero one
//! is an error, and the solves' accuracy is judged by the residuals the caller
//! computes, as for any shift-invert solve.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::{LdltError, LdltRegularization};
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, LdltRef, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};

use super::LowerCsc;
use crate::error::{Error, Result};

const NAME: &str = "faer LDLᵀ";

/// The signs of a symmetric matrix's eigenvalues (or of its `LDLᵀ` pivots).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Inertia {
    /// Negative pivots.
    pub negative: usize,
    /// Positive pivots.
    pub positive: usize,
}

/// A symmetric indefinite factorisation with its analysis kept.
pub struct Ldlt {
    symbolic: SymbolicCholesky<usize>,
    values: Vec<f64>,
    scratch: MemBuffer,
    factorized: bool,
}

fn pattern(a: &LowerCsc) -> SymbolicSparseColMatRef<'_, usize> {
    SymbolicSparseColMatRef::new_checked(a.n, a.n, &a.col_ptr, None, &a.row_idx)
}

fn failed(message: String) -> Error {
    Error::Solver {
        backend: NAME,
        message,
    }
}

impl Ldlt {
    /// Analyses the pattern of the lower triangle `a` in the elimination order
    /// `order` (`order[k]` eliminated `k`-th; `None`: faer's AMD).
    pub fn analyze(a: &LowerCsc, order: Option<&[usize]>) -> Result<Self> {
        let inverse = order.and_then(super::inverse_order);
        let ordering = match (order, &inverse) {
            (Some(fwd), Some(inv)) if fwd.len() == a.n => {
                SymmetricOrdering::Custom(PermRef::new_checked(fwd, inv, a.n))
            }
            _ => SymmetricOrdering::Amd,
        };
        let symbolic =
            factorize_symbolic_cholesky(pattern(a), Side::Lower, ordering, Default::default())
                .map_err(|e| failed(format!("symbolic analysis failed: {e:?}")))?;
        let values = crate::buffers::try_zeroed(symbolic.len_val())
            .ok_or_else(|| failed("out of memory allocating the factor values".into()))?;
        let req = faer::dyn_stack::StackReq::any_of(&[
            symbolic.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default()),
            symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ]);
        let scratch = MemBuffer::try_new(req)
            .map_err(|_| failed("out of memory allocating the factor workspace".into()))?;
        Ok(Ldlt {
            symbolic,
            values,
            scratch,
            factorized: false,
        })
    }

    /// Factorises `a` (the analysed pattern) and returns the inertia of its pivots.
    pub fn factorize(&mut self, a: &LowerCsc) -> Result<Inertia> {
        self.factorized = false;
        let mat = SparseColMatRef::new(pattern(a), &a.values);
        let stack = MemStack::new(&mut self.scratch);
        let res = self.symbolic.factorize_numeric_ldlt::<f64>(
            &mut self.values,
            mat,
            Side::Lower,
            LdltRegularization::default(),
            Par::Seq,
            stack,
            Default::default(),
        );
        if let Err(LdltError::ZeroPivot { index }) = res {
            return Err(failed(format!(
                "zero pivot {index} of {}: the shift is an eigenvalue; move it",
                a.n
            )));
        }
        self.factorized = true;
        let mut inertia = Inertia::default();
        for d in self.pivots() {
            if d < 0.0 {
                inertia.negative += 1;
            } else if d > 0.0 {
                inertia.positive += 1;
            } else {
                return Err(failed("a zero pivot: the shift is an eigenvalue".into()));
            }
        }
        Ok(inertia)
    }

    /// The diagonal `D` of the last factorisation, in elimination order: the first
    /// entry of each column of a simplicial factor, the diagonal of each supernode's
    /// column-major block (`ncols + npattern` rows) of a supernodal one.
    fn pivots(&self) -> Vec<f64> {
        let v = &self.values;
        match self.symbolic.raw() {
            SymbolicCholeskyRaw::Simplicial(sm) => {
                sm.col_ptr()[..sm.nrows()].iter().map(|&p| v[p]).collect()
            }
            SymbolicCholeskyRaw::Supernodal(sn) => {
                let (begin, end) = (sn.supernode_begin(), sn.supernode_end());
                let (cp, below) = (sn.col_ptr_for_val(), sn.nnz_per_super());
                let mut d = Vec::with_capacity(sn.nrows());
                for s in 0..sn.n_supernodes() {
                    let ncols = end[s] - begin[s];
                    let ld = ncols + below[s];
                    d.extend((0..ncols).map(|j| v[cp[s] + j * ld + j]));
                }
                d
            }
        }
    }

    /// Overwrites `rhs` with `A⁻¹ rhs`.
    pub fn solve(&mut self, rhs: &mut [f64]) -> Result<()> {
        let n = self.symbolic.nrows();
        if !self.factorized || rhs.len() != n {
            return Err(failed(format!(
                "solve of {} values with a factor of order {n}{}",
                rhs.len(),
                if self.factorized {
                    ""
                } else {
                    " not factorised"
                }
            )));
        }
        let ldlt = LdltRef::<usize, f64>::new(&self.symbolic, &self.values);
        ldlt.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(rhs, n, 1),
            Par::Seq,
            MemStack::new(&mut self.scratch),
        );
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The largest error of `x` solved back from `b = A x` with the factor `f` of `a`.
    fn solve_error(f: &mut Ldlt, a: &LowerCsc) -> f64 {
        let x: Vec<f64> = (0..a.n).map(|i| (i as f64 * 0.7).sin()).collect();
        let mut b = vec![0.0; a.n];
        a.sym_matvec(&x, &mut b);
        f.solve(&mut b).unwrap();
        x.iter()
            .zip(&b)
            .map(|(p, q)| (p - q).abs())
            .fold(0.0, f64::max)
    }

    /// The lower triangle of the tridiagonal `n × n` matrix with `diag` and `off`.
    fn tridiagonal(n: usize, diag: impl Fn(usize) -> f64, off: f64) -> LowerCsc {
        let (mut col_ptr, mut row_idx, mut values) = (vec![0], Vec::new(), Vec::new());
        for j in 0..n {
            row_idx.push(j);
            values.push(diag(j));
            if j + 1 < n {
                row_idx.push(j + 1);
                values.push(off);
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
    fn the_inertia_counts_the_eigenvalues_below_a_shift_and_the_solve_inverts() {
        // The chain −1, 2, −1 shifted by μ: eigenvalues 2 − 2cos(kπ/(n+1)) − μ.
        for n in [7usize, 200] {
            for mu in [-0.5, 0.3, 1.7, 3.1, 4.5] {
                let a = tridiagonal(n, |_| 2.0 - mu, -1.0);
                let below = (1..=n)
                    .filter(|&k| {
                        2.0 - 2.0 * (k as f64 * std::f64::consts::PI / (n + 1) as f64).cos() < mu
                    })
                    .count();
                let mut f = Ldlt::analyze(&a, None).unwrap();
                let inertia = f.factorize(&a).unwrap();
                assert_eq!(inertia.negative, below, "n {n}, μ {mu}");
                assert_eq!(inertia.negative + inertia.positive, n);
                let err = solve_error(&mut f, &a);
                assert!(err < 1e-9, "n {n}, μ {mu}: solve error {err}");
            }
        }
    }

    #[test]
    fn the_inertia_of_a_supernodal_factor_counts_too() {
        // The 7-point Laplacian of an m³ grid minus μ: eigenvalues
        // Σ_k (2 − 2cos(i_k π/(m+1))) − μ; its factor has supernodes.
        let m = 14;
        let n = m * m * m;
        let h = std::f64::consts::PI / (m + 1) as f64;
        let ev: Vec<f64> = (1..=m).map(|i| 2.0 - 2.0 * (i as f64 * h).cos()).collect();
        for mu in [0.05, 1.3, 4.2, 7.9, 11.5] {
            let (mut col_ptr, mut row_idx, mut values) = (vec![0], Vec::new(), Vec::new());
            for j in 0..n {
                row_idx.push(j);
                values.push(6.0 - mu);
                for stride in [1, m, m * m] {
                    if (j / stride) % m + 1 < m {
                        row_idx.push(j + stride);
                        values.push(-1.0);
                    }
                }
                col_ptr.push(row_idx.len());
            }
            let a = LowerCsc {
                n,
                col_ptr,
                row_idx,
                values,
            };
            let mut f = Ldlt::analyze(&a, None).unwrap();
            assert!(
                matches!(f.symbolic.raw(), SymbolicCholeskyRaw::Supernodal(_)),
                "a supernodal factor"
            );
            let inertia = f.factorize(&a).unwrap();
            let mut below = 0;
            for &x in &ev {
                for &y in &ev {
                    below += ev.iter().filter(|&&z| x + y + z < mu).count();
                }
            }
            assert_eq!(inertia.negative, below, "μ {mu}");
            let err = solve_error(&mut f, &a);
            assert!(err < 1e-8, "μ {mu}: solve error {err}");
        }
    }
}
