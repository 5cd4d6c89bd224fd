/* The C side of rothe's MUMPS binding: one opaque handle around MUMPS's
 * DMUMPS_STRUC_C, so that the Rust side never depends on that struct's layout
 * (which changes between MUMPS versions). Every function here only sets or reads
 * fields and calls dmumps_c; the pointers handed in stay owned by the caller and
 * must outlive the next dmumps_c call that reads them. Indices are MUMPS's own,
 * 1-based (ICNTL(7) is icntl(h, 7)). */

#include <stdlib.h>
#include <string.h>
#include "dmumps_c.h"

typedef struct rothe_mumps {
    DMUMPS_STRUC_C id;
} rothe_mumps;

/* Size of MUMPS_INT in bytes, so that the Rust side can refuse a 64-bit-index build. */
int rothe_mumps_int_size(void) { return (int)sizeof(MUMPS_INT); }

/* A new instance on the Fortran communicator `comm` (JOB = -1), symmetric positive
 * definite (SYM = 1), the host taking part in the work (PAR = 1). Returns NULL when
 * out of memory; otherwise check rothe_mumps_infog(h, 1). */
rothe_mumps *rothe_mumps_new(int comm) {
    rothe_mumps *h = (rothe_mumps *)calloc(1, sizeof(rothe_mumps));
    if (!h) return NULL;
    h->id.comm_fortran = (MUMPS_INT)comm;
    h->id.sym = 1;
    h->id.par = 1;
    h->id.job = -1;
    dmumps_c(&h->id);
    return h;
}

/* JOB = -2 (frees MUMPS's own memory), then the handle. */
void rothe_mumps_free(rothe_mumps *h) {
    if (!h) return;
    h->id.job = -2;
    dmumps_c(&h->id);
    free(h);
}

void rothe_mumps_set_icntl(rothe_mumps *h, int i, int v) { h->id.icntl[i - 1] = (MUMPS_INT)v; }
int rothe_mumps_icntl(const rothe_mumps *h, int i) { return (int)h->id.icntl[i - 1]; }
void rothe_mumps_set_cntl(rothe_mumps *h, int i, double v) { h->id.cntl[i - 1] = v; }

/* The centralised assembled matrix (host only): n, nnz entries (irn, jcn, a). */
void rothe_mumps_set_matrix(rothe_mumps *h, int n, long long nnz, MUMPS_INT *irn,
                            MUMPS_INT *jcn, double *a) {
    h->id.n = (MUMPS_INT)n;
    h->id.nnz = (MUMPS_INT8)nnz;
    h->id.nz = 0;
    h->id.irn = irn;
    h->id.jcn = jcn;
    h->id.a = a;
}

/* The values only, same pattern (host only). */
void rothe_mumps_set_values(rothe_mumps *h, double *a) { h->id.a = a; }

/* A given pivot order (host only, read when ICNTL(7) = 1); NULL clears it. */
void rothe_mumps_set_perm_in(rothe_mumps *h, MUMPS_INT *perm) { h->id.perm_in = perm; }

/* The dense centralised right-hand sides, overwritten by the solution (host only). */
void rothe_mumps_set_rhs(rothe_mumps *h, double *rhs, int nrhs, int lrhs) {
    h->id.rhs = rhs;
    h->id.nrhs = (MUMPS_INT)nrhs;
    h->id.lrhs = (MUMPS_INT)lrhs;
}

/* Runs `job`; returns INFOG(1) (negative on error). */
int rothe_mumps_job(rothe_mumps *h, int job) {
    h->id.job = (MUMPS_INT)job;
    dmumps_c(&h->id);
    return (int)h->id.infog[0];
}

int rothe_mumps_info(const rothe_mumps *h, int i) { return (int)h->id.info[i - 1]; }
int rothe_mumps_infog(const rothe_mumps *h, int i) { return (int)h->id.infog[i - 1]; }
double rothe_mumps_rinfog(const rothe_mumps *h, int i) { return h->id.rinfog[i - 1]; }
double rothe_mumps_rinfo(const rothe_mumps *h, int i) { return h->id.rinfo[i - 1]; }

/* SYM_PERM(i) (1-based position of variable i in the pivot order), after the
 * analysis, host only; 0 when MUMPS has not filled it. */
int rothe_mumps_sym_perm(const rothe_mumps *h, int i) {
    return h->id.sym_perm ? (int)h->id.sym_perm[i - 1] : 0;
}

/* MUMPS's version string. */
const char *rothe_mumps_version(const rothe_mumps *h) { return h->id.version_number; }
