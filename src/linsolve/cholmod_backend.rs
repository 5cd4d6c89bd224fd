//! SuiteSparse CHOLMOD backend (cargo feature `cholmod`): supernodal `L Lᵀ` through
//! the `cholmod_l_*` (64-bit index) interface of `suitesparse_sys`.
//!
//! Same contract as [`super::faer_backend::FaerCholesky`]: [`CholmodCholesky::analyze`]
//! runs `cholmod_l_analyze` once per pattern, [`CholmodCholesky::factorize`] copies
//! the new values into a buffer owned here and runs `cholmod_l_factorize` into the
//! same factor, [`CholmodCholesky::solve_in_place`] runs `cholmod_l_solve2`, whose
//! solution and workspaces (`X`, `Y`, `E`) CHOLMOD allocates on the first solve and
//! reuses afterwards, so a solve does not allocate.
//!
//! Ordering: CHOLMOD's default tries AMD and then METIS/NESDIS and keeps the best.
//! Here `nmethods = 1` with `method[0].ordering = CHOLMOD_AMD`, or, when an elimination
//! order was proposed with `set_ordering` (the nested dissection the faer backend
//! gets too), `CHOLMOD_GIVEN` through `cholmod_l_analyze_p`: both backends then
//! factorise the same permuted matrix, and their timings compare the factorisation
//! codes rather than the orderings. The factorisation is always supernodal (`CHOLMOD_SUPERNODAL`); its
//! dense kernels run on the system BLAS (OpenBLAS if installed).
//!
//! Threads: faer runs sequentially here, and so do CHOLMOD's own OpenMP loops. Debian's
//! CHOLMOD 3 asks for 4 OpenMP threads on each supernode's loops whatever
//! `OMP_NUM_THREADS` says; on a 2-core machine that made the factorisation about 3×
//! slower (thread wake-ups), so `serialise_openmp` sets `omp_set_max_active_levels(0)`
//! before each factorisation and solve. Depending on the libgomp version that setting
//! is per thread or process-wide; rothe has no other OpenMP user. BLAS threading
//! (`OPENBLAS_NUM_THREADS`) is left to the environment.
//!
//! CHOLMOD's own messages are silenced (`print = 0`): failures come back as
//! [`Error::Solver`] with backend `"cholmod"`.

use std::ffi::c_void;
use std::ptr;

use suitesparse_sys::{
    cholmod_common, cholmod_dense, cholmod_factor, cholmod_l_analyze, cholmod_l_analyze_p,
    cholmod_l_factorize, cholmod_l_finish, cholmod_l_free_dense, cholmod_l_free_factor,
    cholmod_l_rcond, cholmod_l_solve2, cholmod_l_start, cholmod_sparse, CHOLMOD_A, CHOLMOD_AMD,
    CHOLMOD_DOUBLE, CHOLMOD_GIVEN, CHOLMOD_LONG, CHOLMOD_NOT_POSDEF, CHOLMOD_OK, CHOLMOD_REAL,
    CHOLMOD_SUPERNODAL,
};

use super::{check_block, not_analysed, LowerCsc, SymmetricSolver};

/// Pivot ratio per unknown below which a factor is taken as singular (`n ε` in all:
/// the round-off pivots of a singular matrix lie near `ε` of the largest).
const SINGULAR_RCOND: f64 = f64::EPSILON;
use crate::error::{Error, Result};

const NAME: &str = "cholmod";

// CHOLMOD's `long` integer arrays (itype CHOLMOD_LONG) are `SuiteSparse_long`, which is
// 64 bits on the targets we build for; the index copies below are `i64`.
const _: () = assert!(std::mem::size_of::<std::os::raw::c_long>() == 8);

/// Turns CHOLMOD's OpenMP loops off on the calling thread (see the module doc).
///
/// Debian's CHOLMOD 3 is built with OpenMP and a compiled-in `num_threads(4)` on the
/// loops of its supernodal factorisation, which neither `OMP_NUM_THREADS` nor any
/// `cholmod_common` field overrides. `omp_set_max_active_levels(0)` makes every
/// parallel region run on one thread. The function is looked up at run time in the
/// already loaded libraries (libgomp comes in with libcholmod), so nothing changes
/// when CHOLMOD was built without OpenMP. Depending on its version libgomp keeps this
/// setting per process or per thread, hence a call before every CHOLMOD call that may
/// open a parallel region; it is one indirect call.
fn serialise_openmp() {
    use std::os::raw::{c_char, c_int};
    use std::sync::OnceLock;

    type SetLevels = unsafe extern "C" fn(c_int);
    static SET_LEVELS: OnceLock<Option<SetLevels>> = OnceLock::new();
    let f = SET_LEVELS.get_or_init(|| {
        #[cfg(target_os = "linux")]
        {
            extern "C" {
                fn dlsym(handle: *mut c_void, symbol: *const c_char) -> *mut c_void;
            }
            // SAFETY: `dlsym` with the default search handle (null on glibc and
            // musl) and a NUL-terminated name only reads; a non-null result is the
            // address of `void omp_set_max_active_levels(int)`, whose signature is
            // fixed by the OpenMP specification.
            unsafe {
                let sym = dlsym(ptr::null_mut(), c"omp_set_max_active_levels".as_ptr());
                (!sym.is_null()).then(|| std::mem::transmute::<*mut c_void, SetLevels>(sym))
            }
        }
        #[cfg(not(target_os = "linux"))]
        {
            None
        }
    });
    if let Some(set_levels) = f {
        // SAFETY: a valid `omp_set_max_active_levels` (see above); 0 is a valid
        // argument (no active parallel levels).
        unsafe { set_levels(0) };
    }
}

fn err(message: impl Into<String>) -> Error {
    Error::Solver {
        backend: NAME,
        message: message.into(),
    }
}

/// Name of a CHOLMOD `common.status` code, for messages.
fn status_name(status: i32) -> &'static str {
    match status {
        0 => "ok",
        -1 => "method not installed",
        -2 => "out of memory",
        -3 => "integer overflow",
        -4 => "invalid input",
        -5 => "GPU error",
        1 => "not positive definite",
        2 => "tiny diagonal entry",
        _ => "unknown status",
    }
}

/// CHOLMOD supernodal Cholesky with a persistent factor and solve workspaces.
pub struct CholmodCholesky {
    /// CHOLMOD's workspace and parameters; boxed because CHOLMOD keeps no pointer to it
    /// but it must stay at one address between `cholmod_l_start` and `cholmod_l_finish`.
    common: Box<cholmod_common>,
    /// The factor (symbolic after `analyze`, numeric after `factorize`), or null.
    factor: *mut cholmod_factor,
    /// Solution and workspaces of `cholmod_l_solve2`, allocated by CHOLMOD on the first
    /// solve and reused, or null.
    x: *mut cholmod_dense,
    y: *mut cholmod_dense,
    e: *mut cholmod_dense,
    /// Dimension of the analysed matrix.
    n: usize,
    /// Column pointers of the analysed pattern as CHOLMOD longs.
    col_ptr: Vec<i64>,
    /// Row indices of the analysed pattern as CHOLMOD longs.
    row_idx: Vec<i64>,
    /// Values of the matrix handed to CHOLMOD (refilled by every `factorize`).
    values: Vec<f64>,
    /// Right-hand side copy wrapped as the dense `B` of `cholmod_l_solve2`.
    b: Vec<f64>,
    /// Whether the factor holds a successful numeric factorisation.
    factorized: bool,
    /// Proposed elimination order for the next analysis, as CHOLMOD longs.
    given: Option<Vec<i64>>,
}

// SAFETY: the raw pointers are owned exclusively by this struct (CHOLMOD objects
// allocated through `common`, which is also owned); nothing is shared with another
// value or thread and CHOLMOD keeps no thread-local state tied to them. The solver is
// used from one thread at a time (`&mut self` for every call that touches CHOLMOD), so
// moving it to another thread is sound.
unsafe impl Send for CholmodCholesky {}

impl CholmodCholesky {
    /// A solver with nothing analysed yet: starts CHOLMOD and sets its parameters
    /// (supernodal, AMD only, silent).
    pub fn new() -> Result<Self> {
        // SAFETY: `cholmod_common` is a plain C struct of integers, floats, raw pointers
        // and an optional function pointer, for all of which all-zero bytes are valid;
        // `cholmod_l_start` then sets every field.
        let mut common: Box<cholmod_common> = Box::new(unsafe { std::mem::zeroed() });
        // SAFETY: `common` points to a valid, exclusively owned `cholmod_common` on the
        // heap, which does not move until `cholmod_l_finish` in `Drop`.
        let ok = unsafe { cholmod_l_start(&mut *common) };
        if ok == 0 {
            return Err(err(format!(
                "cholmod_l_start failed (status {})",
                common.status
            )));
        }
        common.print = 0;
        common.supernodal = CHOLMOD_SUPERNODAL as i32;
        common.nmethods = 1;
        common.method[0].ordering = CHOLMOD_AMD as i32;
        common.postorder = 1;
        Ok(CholmodCholesky {
            common,
            factor: ptr::null_mut(),
            x: ptr::null_mut(),
            y: ptr::null_mut(),
            e: ptr::null_mut(),
            n: 0,
            col_ptr: Vec::new(),
            row_idx: Vec::new(),
            values: Vec::new(),
            b: Vec::new(),
            factorized: false,
            given: None,
        })
    }

    /// Frees the factor and the solve workspaces (null pointers are left alone).
    fn free_all(&mut self) {
        for d in [&mut self.x, &mut self.y, &mut self.e] {
            if !d.is_null() {
                // SAFETY: `*d` was allocated by CHOLMOD with this `common` in
                // `cholmod_l_solve2` and is freed once: CHOLMOD nulls it.
                unsafe { cholmod_l_free_dense(d, &mut *self.common) };
                *d = ptr::null_mut();
            }
        }
        if !self.factor.is_null() {
            // SAFETY: the factor was returned by `cholmod_l_analyze` with this `common`
            // and is freed once: CHOLMOD nulls the pointer.
            unsafe { cholmod_l_free_factor(&mut self.factor, &mut *self.common) };
            self.factor = ptr::null_mut();
        }
        self.factorized = false;
    }

    /// A `cholmod_sparse` header over the owned pattern and value buffers: lower
    /// triangle (`stype = -1`), long indices, real double, sorted and packed. The
    /// buffers are not resized while a factor exists, so the pointers stay valid for
    /// the CHOLMOD call the header is built for.
    fn sparse_header(&mut self) -> cholmod_sparse {
        cholmod_sparse {
            nrow: self.n,
            ncol: self.n,
            nzmax: self.row_idx.len(),
            p: self.col_ptr.as_mut_ptr() as *mut c_void,
            i: self.row_idx.as_mut_ptr() as *mut c_void,
            nz: ptr::null_mut(),
            x: self.values.as_mut_ptr() as *mut c_void,
            z: ptr::null_mut(),
            stype: -1,
            itype: CHOLMOD_LONG as i32,
            xtype: CHOLMOD_REAL as i32,
            dtype: CHOLMOD_DOUBLE as i32,
            sorted: 1,
            packed: 1,
        }
    }

    /// Checks that `a` is a well-formed lower CSC matrix (CHOLMOD reads the arrays
    /// without bounds checks, so a bad index must not reach it).
    fn check_pattern(a: &LowerCsc) -> Result<()> {
        let n = a.n;
        if a.col_ptr.len() != n + 1 {
            return Err(err(format!(
                "col_ptr has {} entries, expected n + 1 = {}",
                a.col_ptr.len(),
                n + 1
            )));
        }
        if a.col_ptr[0] != 0 || a.col_ptr[n] != a.row_idx.len() {
            return Err(err(format!(
                "col_ptr must run from 0 to nnz = {} (got {} .. {})",
                a.row_idx.len(),
                a.col_ptr[0],
                a.col_ptr[n]
            )));
        }
        if a.values.len() != a.row_idx.len() {
            return Err(err(format!(
                "{} values for {} row indices",
                a.values.len(),
                a.row_idx.len()
            )));
        }
        for j in 0..n {
            let (start, end) = (a.col_ptr[j], a.col_ptr[j + 1]);
            if start > end {
                return Err(err(format!("col_ptr decreases at column {j}")));
            }
            let mut prev = None;
            for &i in &a.row_idx[start..end] {
                if i < j || i >= n {
                    return Err(err(format!(
                        "row index {i} in column {j} is outside the lower triangle of a \
                         {n}x{n} matrix"
                    )));
                }
                if prev.is_some_and(|p| i <= p) {
                    return Err(err(format!(
                        "row indices of column {j} are not strictly increasing"
                    )));
                }
                prev = Some(i);
            }
        }
        Ok(())
    }

    /// Whether `a` has exactly the analysed pattern.
    fn same_pattern(&self, a: &LowerCsc) -> bool {
        a.n == self.n
            && a.col_ptr.len() == self.col_ptr.len()
            && a.row_idx.len() == self.row_idx.len()
            && a.values.len() == self.row_idx.len()
            && a.col_ptr
                .iter()
                .zip(&self.col_ptr)
                .all(|(&x, &y)| x as i64 == y)
            && a.row_idx
                .iter()
                .zip(&self.row_idx)
                .all(|(&x, &y)| x as i64 == y)
    }
}

impl Drop for CholmodCholesky {
    fn drop(&mut self) {
        self.free_all();
        // SAFETY: `common` was started in `new` and is finished exactly once, after
        // every CHOLMOD object allocated with it has been freed.
        unsafe { cholmod_l_finish(&mut *self.common) };
    }
}

impl SymmetricSolver for CholmodCholesky {
    fn name(&self) -> &'static str {
        NAME
    }

    fn analyze(&mut self, a: &LowerCsc) -> Result<()> {
        Self::check_pattern(a)?;
        self.free_all();
        let to_long = |v: usize| {
            i64::try_from(v).map_err(|_| err(format!("index {v} does not fit CHOLMOD's long")))
        };
        self.n = a.n;
        self.col_ptr = a
            .col_ptr
            .iter()
            .map(|&v| to_long(v))
            .collect::<Result<_>>()?;
        self.row_idx = a
            .row_idx
            .iter()
            .map(|&v| to_long(v))
            .collect::<Result<_>>()?;
        // Values are not read by the analysis; zeros keep the buffer initialised.
        self.values = vec![0.0; a.row_idx.len()];
        self.b = vec![0.0; a.n];
        let mut header = self.sparse_header();
        let mut given = self.given.take().filter(|p| p.len() == a.n);
        self.common.method[0].ordering = if given.is_some() {
            CHOLMOD_GIVEN as i32
        } else {
            CHOLMOD_AMD as i32
        };
        // A given order is used as it is (the nested dissection of `super::ordering`
        // is postordered already), so both backends factorise the same permuted
        // matrix; CHOLMOD's own AMD order is postordered.
        self.common.postorder = i32::from(given.is_none());
        // SAFETY: `header` describes valid, checked arrays (n + 1 column pointers, nnz
        // in-range sorted row indices and nnz values) owned by `self` and alive for the
        // call; `common` was started in `new`; a given permutation holds n distinct
        // indices in 0..n (checked by `set_ordering`). The returned factor is owned by
        // `self`.
        self.factor = unsafe {
            match given.as_mut() {
                Some(p) => cholmod_l_analyze_p(
                    &mut header,
                    p.as_mut_ptr(),
                    ptr::null_mut(),
                    0,
                    &mut *self.common,
                ),
                None => cholmod_l_analyze(&mut header, &mut *self.common),
            }
        };
        self.given = given;
        if self.factor.is_null() || self.common.status < CHOLMOD_OK as i32 {
            let status = self.common.status;
            self.free_all();
            return Err(err(format!(
                "cholmod_l_analyze failed: {} (status {status})",
                status_name(status)
            )));
        }
        Ok(())
    }

    fn factorize(&mut self, a: &LowerCsc) -> Result<()> {
        if self.factor.is_null() {
            return Err(not_analysed(NAME));
        }
        if !self.same_pattern(a) {
            return Err(err(
                "factorize: the matrix pattern differs from the analysed one",
            ));
        }
        self.factorized = false;
        serialise_openmp();
        for (k, (dst, &src)) in self.values.iter_mut().zip(&a.values).enumerate() {
            if !src.is_finite() {
                return Err(err(format!("matrix entry {k} is not finite ({src})")));
            }
            *dst = src;
        }
        let mut header = self.sparse_header();
        // SAFETY: `header` points into buffers owned by `self` with the analysed
        // pattern (checked above), `self.factor` was produced by `cholmod_l_analyze`
        // for that pattern with this `common`, and nothing else aliases them.
        let ok = unsafe { cholmod_l_factorize(&mut header, self.factor, &mut *self.common) };
        let status = self.common.status;
        if ok == 0 || status < CHOLMOD_OK as i32 {
            return Err(err(format!(
                "cholmod_l_factorize failed: {} (status {status})",
                status_name(status)
            )));
        }
        // SAFETY: `self.factor` is non-null and valid (checked above); we only read
        // scalar fields and, if `minor < n`, entry `minor` of its size-n `Perm` array.
        let (minor, n, col) = unsafe {
            let f = &*self.factor;
            let col = if f.minor < f.n && !f.Perm.is_null() {
                Some(*(f.Perm as *const i64).add(f.minor))
            } else {
                None
            };
            (f.minor, f.n, col)
        };
        if status == CHOLMOD_NOT_POSDEF as i32 || minor < n {
            let at = match col {
                Some(c) => format!("at column {c} (pivot {minor} of {n} in elimination order)"),
                None => format!("at pivot {minor} of {n}"),
            };
            return Err(Error::NotPositiveDefinite {
                backend: NAME,
                column: col.map(|c| c as usize),
                message: format!(
                    "numeric factorisation failed {at}: the matrix is not positive definite"
                ),
            });
        }
        // A singular matrix can factorise with round-off pivots of either sign (which
        // one depends on the BLAS kernels of the machine): a pivot below `n ε` of
        // the largest (CHOLMOD's diagonal-ratio estimate of the reciprocal condition
        // number) is treated as the zero it stands for.
        // SAFETY: `self.factor` holds the numeric factorisation just computed with
        // `self.common`.
        let rcond = unsafe { cholmod_l_rcond(self.factor, &mut *self.common) };
        // A NaN estimate (a NaN in the matrix) counts as singular too.
        if rcond.is_nan() || rcond <= SINGULAR_RCOND * n.max(1) as f64 {
            return Err(Error::NotPositiveDefinite {
                backend: NAME,
                column: None,
                message: format!(
                    "numeric factorisation: the matrix is singular to working precision \
                     (smallest over largest pivot {rcond:.1e})"
                ),
            });
        }
        self.factorized = true;
        Ok(())
    }

    fn solve_block_in_place(&mut self, rhs: &mut [f64], ncols: usize) -> Result<()> {
        if self.factor.is_null() || !self.factorized {
            return Err(not_analysed(NAME));
        }
        let n = self.n;
        check_block(NAME, n, rhs, ncols)?;
        if n == 0 || ncols == 0 {
            return Ok(());
        }
        if self.b.len() < n * ncols {
            self.b.resize(n * ncols, 0.0);
        }
        self.b[..n * ncols].copy_from_slice(rhs);
        serialise_openmp();
        let mut b = cholmod_dense {
            nrow: n,
            ncol: ncols,
            nzmax: n * ncols,
            d: n,
            x: self.b.as_mut_ptr() as *mut c_void,
            z: ptr::null_mut(),
            xtype: CHOLMOD_REAL as i32,
            dtype: CHOLMOD_DOUBLE as i32,
        };
        // SAFETY: the factor is numeric and valid (factorized), `b` describes the
        // owned n-by-ncols column-major block in `self.b` (leading dimension n),
        // `x`/`y`/`e` are null or dense matrices CHOLMOD allocated with this `common`
        // in a previous call (it reallocates them if their shape does not fit), and no
        // sparse Bset/Xset is used.
        let ok = unsafe {
            cholmod_l_solve2(
                CHOLMOD_A as i32,
                self.factor,
                &mut b,
                ptr::null_mut(),
                &mut self.x,
                ptr::null_mut(),
                &mut self.y,
                &mut self.e,
                &mut *self.common,
            )
        };
        if ok == 0 || self.x.is_null() {
            let status = self.common.status;
            return Err(err(format!(
                "cholmod_l_solve2 failed: {} (status {status})",
                status_name(status)
            )));
        }
        // SAFETY: `self.x` is the n-by-ncols real double solution CHOLMOD just wrote
        // (checked below); its `x` array holds `d * ncols` doubles with leading
        // dimension `d >= n`, and does not overlap `rhs`.
        unsafe {
            let x = &*self.x;
            if x.nrow != n || x.ncol != ncols || x.x.is_null() || x.d < n {
                return Err(err(
                    "cholmod_l_solve2 returned a solution of the wrong shape",
                ));
            }
            let data = std::slice::from_raw_parts(x.x as *const f64, x.d * ncols);
            for c in 0..ncols {
                rhs[c * n..(c + 1) * n].copy_from_slice(&data[c * x.d..c * x.d + n]);
            }
        }
        Ok(())
    }

    fn set_ordering(&mut self, order: Vec<usize>) {
        self.given =
            super::inverse_order(&order).map(|_| order.iter().map(|&v| v as i64).collect());
    }

    fn ordering(&self) -> Option<Vec<usize>> {
        if self.factor.is_null() {
            return None;
        }
        // SAFETY: the factor is valid; `Perm` is null or holds n long entries.
        unsafe {
            let f = &*self.factor;
            if f.Perm.is_null() {
                return Some((0..f.n).collect());
            }
            let p = std::slice::from_raw_parts(f.Perm as *const i64, f.n);
            Some(p.iter().map(|&v| v as usize).collect())
        }
    }

    /// nnz(L) as the sum of `L->ColCount`: the exact column counts of the Cholesky
    /// factor for the chosen ordering, without the explicit zeros that relaxed
    /// supernode amalgamation stores (`xsize` would count those and the padding of
    /// the supernodes' dense blocks).
    fn factor_nnz(&self) -> Option<usize> {
        if self.factor.is_null() {
            return None;
        }
        // SAFETY: the factor is valid; its `ColCount` array has `n` long entries.
        let counts = unsafe {
            let f = &*self.factor;
            if f.ColCount.is_null() {
                return None;
            }
            std::slice::from_raw_parts(f.ColCount as *const i64, f.n)
        };
        Some(counts.iter().map(|&c| c.max(0) as usize).sum())
    }
}
