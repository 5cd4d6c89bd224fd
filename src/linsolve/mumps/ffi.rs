//! The Rust side of the binding to MUMPS's C interface: the functions of `shim.c`
//! (compiled by `build.rs` with the `mumps` feature), which wrap one
//! `DMUMPS_STRUC_C` behind an opaque handle so that nothing here depends on that
//! struct's layout. Indices into MUMPS's arrays (`ICNTL`, `INFOG`, …) are MUMPS's
//! own, 1-based.

use std::os::raw::{c_char, c_int};

/// An opaque MUMPS instance (`DMUMPS_STRUC_C` on the C side).
#[repr(C)]
pub struct Handle {
    _private: [u8; 0],
}

extern "C" {
    pub fn rothe_mumps_int_size() -> c_int;
    pub fn rothe_mumps_new(comm: c_int) -> *mut Handle;
    pub fn rothe_mumps_free(h: *mut Handle);
    pub fn rothe_mumps_set_icntl(h: *mut Handle, i: c_int, v: c_int);
    pub fn rothe_mumps_icntl(h: *const Handle, i: c_int) -> c_int;
    pub fn rothe_mumps_set_matrix(
        h: *mut Handle,
        n: c_int,
        nnz: i64,
        irn: *mut c_int,
        jcn: *mut c_int,
        a: *mut f64,
    );
    pub fn rothe_mumps_set_values(h: *mut Handle, a: *mut f64);
    pub fn rothe_mumps_set_perm_in(h: *mut Handle, perm: *mut c_int);
    pub fn rothe_mumps_set_rhs(h: *mut Handle, rhs: *mut f64, nrhs: c_int, lrhs: c_int);
    pub fn rothe_mumps_job(h: *mut Handle, job: c_int) -> c_int;
    pub fn rothe_mumps_info(h: *const Handle, i: c_int) -> c_int;
    pub fn rothe_mumps_infog(h: *const Handle, i: c_int) -> c_int;
    pub fn rothe_mumps_rinfog(h: *const Handle, i: c_int) -> f64;
    pub fn rothe_mumps_sym_perm(h: *const Handle, i: c_int) -> c_int;
    pub fn rothe_mumps_version(h: *const Handle) -> *const c_char;
}

/// MUMPS's `JOB` values used here.
pub mod job {
    /// Analysis (ordering, symbolic factorisation, mapping).
    pub const ANALYSE: i32 = 1;
    /// Numeric factorisation on the last analysis.
    pub const FACTOR: i32 = 2;
    /// Solve with the last factor.
    pub const SOLVE: i32 = 3;
}
