//! MUMPS backend over MPI (cargo feature `mumps`): the factorisation and the solves
//! distributed over every MPI rank, behind the same [`SymmetricSolver`] contract as
//! the faer and CHOLMOD backends.
//!
//! Rank 0 holds the matrix and runs the whole run ([`session`] says how the other
//! ranks serve it). [`MumpsCholesky::analyze`] hands the lower triangle to MUMPS as a
//! centralised assembled matrix (`SYM = 1`: symmetric positive definite, `PAR = 1`:
//! the host works too) and runs the analysis (`JOB = 1`) once per pattern;
//! [`MumpsCholesky::factorize`] copies the new values into the same entries and runs
//! the numeric factorisation (`JOB = 2`) on the kept analysis; a solve (`JOB = 3`)
//! takes a block of dense right-hand sides on rank 0, which MUMPS overwrites with
//! the solution. Every rank keeps its part of the factor between calls.
//!
//! Ordering: an elimination order proposed with `set_ordering` (rothe's nested
//! dissection) is given to MUMPS (`ICNTL(7) = 1`, `PERM_IN`), so that the three
//! backends factorise the same permuted matrix; without one MUMPS orders by AMD
//! (`ICNTL(7) = 0`), as the other backends do. No scaling (`ICNTL(8) = 0`), no
//! iterative refinement: a plain Cholesky-type factorisation.
//!
//! A matrix that is not positive definite is [`Error::NotPositiveDefinite`], as with
//! the other backends: MUMPS's own refusal (`INFOG(1) = -10` or `-40`), a negative
//! pivot (`INFOG(12)`), or a null pivot found by its detection (`ICNTL(24) = 1`,
//! `INFOG(28)`). A workspace MUMPS estimated too small (`INFOG(1) = -8, -9, -14,
//! -15, -17, -20`) is retried with twice the relaxation `ICNTL(14)`, up to four times.
//!
//! MUMPS's messages are silenced (`ICNTL(1..4)`): failures come back as
//! [`Error::Solver`] with backend `"mumps"` and MUMPS's `INFOG(1)`, `INFOG(2)`.

mod ffi;
pub mod session;

use super::distributed::DistributedAnalysis;
use super::{check_block, not_analysed, LowerCsc, SymmetricSolver};
use crate::error::{Error, Result};
pub use session::{current, start, Session, HOW_TO_RUN};

/// The backend's name in outputs and messages.
pub const NAME: &str = "mumps";

/// Workspace errors retried with a larger `ICNTL(14)`.
const WORKSPACE_ERRORS: [i32; 6] = [-8, -9, -14, -15, -17, -20];

/// The settings every rank's instance gets (the host's matter; the others' are the
/// same so that nothing depends on which does).
fn configure(h: *mut ffi::Handle) {
    let set = |i: i32, v: i32| {
        // SAFETY: `h` is a live instance; 1 ≤ i ≤ 60.
        unsafe { ffi::rothe_mumps_set_icntl(h, i, v) }
    };
    // Messages off: errors come back through INFOG.
    set(1, -1);
    set(2, -1);
    set(3, -1);
    set(4, 0);
    // Centralised assembled matrix, dense centralised right-hand sides and solution.
    set(5, 0);
    set(18, 0);
    set(20, 0);
    set(21, 0);
    // AMD unless an order is given; no scaling; sequential analysis.
    set(7, 0);
    set(8, 0);
    set(28, 1);
    // No iterative refinement or error analysis; null pivots detected.
    set(10, 0);
    set(11, 0);
    set(24, 1);
}

fn err(message: impl Into<String>) -> Error {
    Error::Solver {
        backend: NAME,
        message: message.into(),
    }
}

/// Entries given by an `INFOG` pair that holds a count or, when negative, millions.
fn count(v: i32) -> u64 {
    if v < 0 {
        (-(v as i64)) as u64 * 1_000_000
    } else {
        v as u64
    }
}

/// MUMPS's distributed factorisation, the time loop's side (rank 0).
pub struct MumpsCholesky {
    session: &'static Session,
    id: i64,
    handle: *mut ffi::Handle,
    n: usize,
    irn: Vec<i32>,
    jcn: Vec<i32>,
    values: Vec<f64>,
    perm_in: Vec<i32>,
    proposed: Option<Vec<usize>>,
    analysed: bool,
    factorized: bool,
    analysis: Option<DistributedAnalysis>,
    order: Option<Vec<usize>>,
}

// SAFETY: the MUMPS instance is used only through `&mut self`, and every call into
// MUMPS goes through the session's lock (one thread of rank 0 at a time).
unsafe impl Send for MumpsCholesky {}

impl MumpsCholesky {
    /// A new solver on the process's MPI session (started now if need be: a
    /// process without `mpirun` is a session of one rank).
    pub fn new() -> Result<Self> {
        let session = start()?;
        if session.rank() != 0 {
            return Err(err(format!(
                "a solver was asked for on rank {}; only rank 0 makes solvers, the others serve",
                session.rank()
            )));
        }
        let (id, handle) = session.create()?;
        Ok(MumpsCholesky {
            session,
            id,
            handle,
            n: 0,
            irn: Vec::new(),
            jcn: Vec::new(),
            values: Vec::new(),
            perm_in: Vec::new(),
            proposed: None,
            analysed: false,
            factorized: false,
            analysis: None,
            order: None,
        })
    }

    fn infog(&self, i: i32) -> i32 {
        // SAFETY: a live instance; 1 ≤ i ≤ 80.
        unsafe { ffi::rothe_mumps_infog(self.handle, i) }
    }

    fn failure(&self, what: &str, info: i32) -> Error {
        let detail = self.infog(2);
        let meaning = match info {
            -5 | -7 | -13 => "out of memory on a rank",
            -6 => "the matrix is structurally singular",
            -8 | -9 | -14 | -15 | -17 | -20 => "the workspace MUMPS estimated is too small",
            -16 => "the matrix's order is out of range",
            -19 => "the memory limit ICNTL(23) is too small",
            -22 => "an array given to MUMPS is unusable",
            _ => "see INFOG(1) in MUMPS's user guide",
        };
        err(format!(
            "{what} failed: INFOG(1) = {info}, INFOG(2) = {detail} ({meaning})"
        ))
    }

    fn not_positive_definite(&self, message: String) -> Error {
        Error::NotPositiveDefinite {
            backend: NAME,
            column: None,
            message,
        }
    }
}

impl Drop for MumpsCholesky {
    fn drop(&mut self) {
        self.session.free(self.id, self.handle);
    }
}

impl SymmetricSolver for MumpsCholesky {
    fn name(&self) -> &'static str {
        NAME
    }

    fn analyze(&mut self, a: &LowerCsc) -> Result<()> {
        let n = a.n;
        if n > i32::MAX as usize - 1 {
            return Err(err(format!("{n} unknowns exceed MUMPS's 32-bit indices")));
        }
        self.n = n;
        let nnz = a.row_idx.len();
        self.irn.clear();
        self.jcn.clear();
        self.irn.reserve(nnz);
        self.jcn.reserve(nnz);
        for j in 0..n {
            for &i in &a.row_idx[a.col_ptr[j]..a.col_ptr[j + 1]] {
                self.irn.push(i as i32 + 1);
                self.jcn.push(j as i32 + 1);
            }
        }
        self.values.clear();
        self.values.resize(nnz, 0.0);
        self.perm_in.clear();
        let given = match self.proposed.take() {
            Some(order) if order.len() == n => {
                self.perm_in.resize(n, 0);
                for (k, &v) in order.iter().enumerate() {
                    self.perm_in[v] = k as i32 + 1;
                }
                true
            }
            _ => false,
        };
        self.analysed = false;
        self.factorized = false;
        self.analysis = None;
        self.order = None;
        if n == 0 {
            self.analysed = true;
            return Ok(());
        }
        let h = self.handle;
        let (irn, jcn, vals, perm) = (
            self.irn.as_mut_ptr(),
            self.jcn.as_mut_ptr(),
            self.values.as_mut_ptr(),
            self.perm_in.as_mut_ptr(),
        );
        let info = self
            .session
            .job(self.id, h, ffi::job::ANALYSE, "the MUMPS analysis", || {
                // SAFETY: `h` is live; the arrays are owned by `self` and not touched
                // until the next `analyze`.
                unsafe {
                    ffi::rothe_mumps_set_matrix(h, n as i32, nnz as i64, irn, jcn, vals);
                    ffi::rothe_mumps_set_icntl(h, 7, if given { 1 } else { 0 });
                    ffi::rothe_mumps_set_perm_in(
                        h,
                        if given { perm } else { std::ptr::null_mut() },
                    );
                }
            })?;
        if info < 0 {
            return Err(self.failure("the analysis", info));
        }
        let per_rank = self.session.report(self.id, h)?;
        // SAFETY: a live instance; the version string is NUL-terminated by MUMPS.
        let version = unsafe { std::ffi::CStr::from_ptr(ffi::rothe_mumps_version(h)) }
            .to_string_lossy()
            .trim()
            .to_string();
        self.analysis = Some(DistributedAnalysis {
            version,
            ranks: self.session.size() as usize,
            factor_entries: count(self.infog(20)),
            // SAFETY: a live instance.
            flops: unsafe { ffi::rothe_mumps_rinfog(h, 1) },
            per_rank,
            host_input: (nnz * (2 * 4 + 8) + n * 4) as u64,
        });
        let mut order = vec![usize::MAX; n];
        let mut complete = true;
        for i in 0..n {
            // SAFETY: a live instance after its analysis; 1 ≤ i + 1 ≤ n.
            let p = unsafe { ffi::rothe_mumps_sym_perm(h, i as i32 + 1) };
            if p < 1 || p as usize > n {
                complete = false;
                break;
            }
            order[p as usize - 1] = i;
        }
        self.order = (complete && !order.contains(&usize::MAX)).then_some(order);
        self.analysed = true;
        Ok(())
    }

    fn factorize(&mut self, a: &LowerCsc) -> Result<()> {
        if !self.analysed {
            return Err(not_analysed(NAME));
        }
        if a.n != self.n || a.values.len() != self.values.len() {
            return Err(err(
                "factorize: the matrix's pattern is not the analysed one",
            ));
        }
        self.factorized = false;
        if self.n == 0 {
            self.factorized = true;
            return Ok(());
        }
        self.values.copy_from_slice(&a.values);
        let h = self.handle;
        let vals = self.values.as_mut_ptr();
        let mut info = 0;
        for attempt in 0..=4 {
            info = self.session.job(
                self.id,
                h,
                ffi::job::FACTOR,
                "the MUMPS factorisation",
                || {
                    // SAFETY: `h` is live; `vals` is owned by `self`, same length as
                    // the analysed entries.
                    unsafe { ffi::rothe_mumps_set_values(h, vals) }
                },
            )?;
            if attempt < 4 && WORKSPACE_ERRORS.contains(&info) {
                // SAFETY: a live instance; ICNTL(14) is a percentage.
                unsafe {
                    let relax = ffi::rothe_mumps_icntl(h, 14).max(20);
                    ffi::rothe_mumps_set_icntl(h, 14, relax * 2);
                }
                continue;
            }
            break;
        }
        match info {
            -10 | -40 => {
                return Err(self.not_positive_definite(format!(
                    "numeric factorisation failed (MUMPS INFOG(1) = {info}, INFOG(2) = {}): \
                     the matrix is not positive definite",
                    self.infog(2)
                )))
            }
            i if i < 0 => return Err(self.failure("the factorisation", i)),
            _ => {}
        }
        let negative = self.infog(12);
        if negative > 0 {
            return Err(self.not_positive_definite(format!(
                "numeric factorisation: {negative} negative pivot{}: the matrix is not positive \
                 definite",
                if negative == 1 { "" } else { "s" }
            )));
        }
        let null = self.infog(28);
        if null > 0 {
            return Err(self.not_positive_definite(format!(
                "numeric factorisation: {null} null pivot{}: the matrix is singular to working \
                 precision",
                if null == 1 { "" } else { "s" }
            )));
        }
        self.factorized = true;
        Ok(())
    }

    fn solve_block_in_place(&mut self, rhs: &mut [f64], ncols: usize) -> Result<()> {
        if !self.factorized {
            return Err(not_analysed(NAME));
        }
        let n = self.n;
        check_block(NAME, n, rhs, ncols)?;
        if n == 0 || ncols == 0 {
            return Ok(());
        }
        if ncols > i32::MAX as usize {
            return Err(err(format!(
                "{ncols} right-hand sides exceed MUMPS's 32-bit indices"
            )));
        }
        let h = self.handle;
        let b = rhs.as_mut_ptr();
        let info = self
            .session
            .job(self.id, h, ffi::job::SOLVE, "the MUMPS solve", || {
                // SAFETY: `h` is live; `b` holds n × ncols values, column-major with
                // leading dimension n, and outlives the call.
                unsafe { ffi::rothe_mumps_set_rhs(h, b, ncols as i32, n as i32) }
            })?;
        if info < 0 {
            return Err(self.failure("the solve", info));
        }
        Ok(())
    }

    fn factor_nnz(&self) -> Option<usize> {
        self.analysis.as_ref().map(|a| a.factor_entries as usize)
    }

    fn set_ordering(&mut self, order: Vec<usize>) {
        self.proposed = Some(order);
    }

    fn ordering(&self) -> Option<Vec<usize>> {
        self.order.clone()
    }

    fn distributed(&self) -> Option<&DistributedAnalysis> {
        self.analysis.as_ref()
    }
}
