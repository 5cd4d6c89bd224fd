//! The per-supernode kernels of the sweeps: the forward step, the backward step's
//! dot products (plain, and fused with AVX2 where the CPU has it), prefetching.

use super::structure::Supernode;
use super::Row;

/// The direction of a sweep.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Dir {
    /// `L⁻¹`, supernodes in order.
    Forward,
    /// `L⁻ᵀ`, supernodes in reverse.
    Backward,
}

/// How a kernel multiplies and adds: plainly (`a·b + c`, two roundings) or fused
/// (`mul_add`, one rounding; only where the CPU has FMA, where it is one
/// instruction).
pub(super) trait MulAdd {
    /// Whether this is the fused flavour (AVX2 and FMA are available).
    const FUSED: bool;
    fn mul_add(a: f64, b: f64, c: f64) -> f64;
}

pub(super) struct Plain;
impl MulAdd for Plain {
    const FUSED: bool = false;
    #[inline(always)]
    fn mul_add(a: f64, b: f64, c: f64) -> f64 {
        a * b + c
    }
}

#[cfg(target_arch = "x86_64")]
pub(super) struct Fused;
#[cfg(target_arch = "x86_64")]
impl MulAdd for Fused {
    const FUSED: bool = true;
    #[inline(always)]
    fn mul_add(a: f64, b: f64, c: f64) -> f64 {
        a.mul_add(b, c)
    }
}

/// Independent partial sums of the backward solve's dot products: a single chain
/// of dependent additions would wait on the adder's latency instead of memory.
pub(super) const LANES: usize = 4;

/// Where a supernode's step reads and writes `x`: the rows from `lo` on are in `x`
/// (row `r` at `(r − lo) K`), and the pattern rows from position `split` on (rows
/// above the subtree a thread owns) are in `far` instead (row `r` at `r K`): the
/// forward step adds its updates of them there, the backward step reads them there.
/// A sequential sweep has `lo = 0`, `split = p_s` and an empty `far`.
#[derive(Clone, Copy)]
pub(super) struct Place {
    pub(super) lo: usize,
    pub(super) split: usize,
}

/// Forward step of one supernode on `K` row-major right-hand sides:
/// `x_s ← L_ss⁻¹ x_s`, `x_p ← x_p − L_ps x_s`, one pass over each column, in memory
/// order.
#[inline(always)]
pub(super) fn forward_node<const K: usize, M: MulAdd>(
    sn: &Supernode,
    rows: &[Row],
    values: &[f64],
    x: &mut [f64],
    tmp: &mut [f64],
    at: Place,
    far: &mut [f64],
) {
    let (ns, np) = (sn.ncols, sn.npattern);
    let b = sn.begin - at.lo;
    let ld = ns + np;
    let pattern = &rows[sn.pattern..sn.pattern + np];
    let (near_rows, far_rows) = pattern.split_at(at.split);
    if ns == 1 {
        // One column (a simplicial factor's): straight into x, no buffer.
        let col = &values[sn.values..sn.values + ld];
        prefetch_ahead(col, Dir::Forward);
        let inv = 1.0 / col[0];
        let xj: [f64; K] = std::array::from_fn(|c| x[b * K + c] * inv);
        x[b * K..(b + 1) * K].copy_from_slice(&xj);
        let (near, rest) = col[1..].split_at(at.split);
        for (&l, &row) in near.iter().zip(near_rows) {
            let r = row as usize - at.lo;
            for c in 0..K {
                x[r * K + c] = M::mul_add(l, -xj[c], x[r * K + c]);
            }
        }
        for (&l, &row) in rest.iter().zip(far_rows) {
            let row = row as usize;
            for c in 0..K {
                far[row * K + c] = M::mul_add(l, -xj[c], far[row * K + c]);
            }
        }
        return;
    }
    let tmp = &mut tmp[..np * K];
    let block = &values[sn.values..sn.values + ld * ns];
    for j in 0..ns {
        let col = &block[j * ld..(j + 1) * ld];
        prefetch_ahead(col, Dir::Forward);
        let inv = 1.0 / col[j];
        let mut xj = [0.0; K];
        for c in 0..K {
            xj[c] = x[(b + j) * K + c] * inv;
            x[(b + j) * K + c] = xj[c];
        }
        let neg: [f64; K] = std::array::from_fn(|c| -xj[c]);
        for i in j + 1..ns {
            let l = col[i];
            let xi = &mut x[(b + i) * K..(b + i + 1) * K];
            for c in 0..K {
                xi[c] = M::mul_add(l, neg[c], xi[c]);
            }
        }
        if j == 0 {
            // The first column sets the buffer (`l x_j` is `fma(l, x_j, 0)` exactly).
            for (t, &l) in tmp.chunks_exact_mut(K).zip(&col[ns..]) {
                for c in 0..K {
                    t[c] = l * xj[c];
                }
            }
        } else {
            for (t, &l) in tmp.chunks_exact_mut(K).zip(&col[ns..]) {
                for c in 0..K {
                    t[c] = M::mul_add(l, xj[c], t[c]);
                }
            }
        }
    }
    let (near, rest) = tmp.split_at(at.split * K);
    for (t, &row) in near.chunks_exact(K).zip(near_rows) {
        let r = row as usize - at.lo;
        for c in 0..K {
            x[r * K + c] -= t[c];
        }
    }
    for (t, &row) in rest.chunks_exact(K).zip(far_rows) {
        let row = row as usize;
        for c in 0..K {
            far[row * K + c] -= t[c];
        }
    }
}

/// Backward step of one supernode: `x_s ← L_ssᵀ⁻¹ (x_s − L_psᵀ x_p)`, last column
/// first, each column from its last row up (the whole backward sweep reads the
/// factor as one descending stream).
#[inline(always)]
pub(super) fn backward_node<const K: usize, M: MulAdd>(
    sn: &Supernode,
    rows: &[Row],
    values: &[f64],
    x: &mut [f64],
    tmp: &mut [f64],
    at: Place,
    far: &[f64],
) {
    let (ns, np) = (sn.ncols, sn.npattern);
    let b = sn.begin - at.lo;
    let ld = ns + np;
    let pattern = &rows[sn.pattern..sn.pattern + np];
    let (near_rows, far_rows) = pattern.split_at(at.split);
    if ns == 1 {
        let col = &values[sn.values..sn.values + ld];
        prefetch_ahead(col, Dir::Backward);
        let (near, rest) = col[1..].split_at(at.split);
        let mut acc = [[0.0; K]; LANES];
        for (k, (&l, &row)) in rest.iter().zip(far_rows).enumerate().rev() {
            let row = row as usize;
            let lane = k % LANES;
            for c in 0..K {
                acc[lane][c] = M::mul_add(l, far[row * K + c], acc[lane][c]);
            }
        }
        for (k, (&l, &row)) in near.iter().zip(near_rows).enumerate().rev() {
            let lane = k % LANES;
            let r = row as usize - at.lo;
            for c in 0..K {
                acc[lane][c] = M::mul_add(l, x[r * K + c], acc[lane][c]);
            }
        }
        let inv = 1.0 / col[0];
        for c in 0..K {
            let sum: f64 = acc.iter().map(|a| a[c]).sum();
            x[b * K + c] = (x[b * K + c] - sum) * inv;
        }
        return;
    }
    let tmp = &mut tmp[..np * K];
    let (near_t, far_t) = tmp.split_at_mut(at.split * K);
    for (t, &row) in near_t.chunks_exact_mut(K).zip(near_rows) {
        let r = row as usize - at.lo;
        t.copy_from_slice(&x[r * K..(r + 1) * K]);
    }
    for (t, &row) in far_t.chunks_exact_mut(K).zip(far_rows) {
        let row = row as usize;
        t.copy_from_slice(&far[row * K..(row + 1) * K]);
    }
    let block = &values[sn.values..sn.values + ld * ns];
    // Last column first, each column from its last row up: the whole backward sweep
    // reads the factor as one descending stream, which the hardware prefetcher
    // follows (columns read upwards one by one would make a saw-tooth it does not).
    for j in (0..ns).rev() {
        let col = &block[j * ld..(j + 1) * ld];
        prefetch_ahead(col, Dir::Backward);
        let mut acc = [[0.0; K]; LANES];
        dot_rows_rev::<K, M>(&col[ns..], tmp, &mut acc);
        dot_rows_rev::<K, M>(&col[j + 1..ns], &x[(b + j + 1) * K..(b + ns) * K], &mut acc);
        let inv = 1.0 / col[j];
        for c in 0..K {
            let sum: f64 = acc.iter().map(|a| a[c]).sum();
            x[(b + j) * K + c] = (x[(b + j) * K + c] - sum) * inv;
        }
    }
}

/// How far ahead of the column being read, in values (16 KiB), a sweep asks for
/// the factor's cache lines.
pub(super) const PREFETCH_AHEAD: usize = 2048;

/// Asks for the cache lines `PREFETCH_AHEAD` values past `col` in the sweep's
/// direction to be brought into the level-2 cache (not level 1, whose few miss
/// buffers the demand loads need: prefetching into it measured slower, as did
/// non-temporal prefetches). Measured on W1 with alternating solves in one
/// process (medians of 20): a block of 8 10–15 % faster (ny = 100: 17.0 → 14.3–15.2
/// ms, ny = 250: 131.5 → 117–119 ms at distances of 512 to 8192 values); one
/// right-hand side within the noise (−4 % to +10 % over three such runs).
#[inline(always)]
pub(super) fn prefetch_ahead(col: &[f64], dir: Dir) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T1};
        let start = match dir {
            Dir::Forward => col.as_ptr().wrapping_add(PREFETCH_AHEAD),
            Dir::Backward => col.as_ptr().wrapping_sub(PREFETCH_AHEAD),
        }
        .cast::<i8>();
        for line in (0..std::mem::size_of_val(col)).step_by(64) {
            // SAFETY: a prefetch is a hint that never faults, whatever the address
            // (which `wrapping_*` computed without dereferencing).
            unsafe { _mm_prefetch::<_MM_HINT_T1>(start.wrapping_add(line)) };
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (col, dir);
}

/// `acc[lane][c] += Σ_r l[r] · y[r K + c]`, from the last row to the first.
#[inline(always)]
pub(super) fn dot_rows_rev<const K: usize, M: MulAdd>(
    l: &[f64],
    y: &[f64],
    acc: &mut [[f64; K]; LANES],
) {
    #[cfg(target_arch = "x86_64")]
    if K == 8 && M::FUSED {
        // Eight columns: explicit vectors (LLVM kept the generic loop's 32
        // accumulators in half registers and spilled them every row).
        assert!(y.len() >= l.len() * 8);
        let acc8 = acc.as_mut_ptr().cast::<[[f64; 8]; LANES]>();
        // SAFETY: `K == 8`, so `acc` is a `[[f64; 8]; LANES]`; `M::FUSED` is only
        // used inside functions compiled with AVX2 and FMA, after they were
        // detected; `y` holds 8 values per row of `l` (asserted).
        unsafe { dot8_rows_rev(l, y, &mut *acc8) };
        return;
    }
    #[cfg(target_arch = "x86_64")]
    if K == 1 && M::FUSED {
        // One column: the four lanes are one vector (LLVM kept them in scalar
        // registers, one fused multiply-add a row).
        assert_eq!(y.len(), l.len());
        let acc1 = acc.as_mut_ptr().cast::<[f64; LANES]>();
        // SAFETY: `K == 1`, so `acc` is `LANES` single values in a row; `M::FUSED`
        // is only used inside functions compiled with AVX2 and FMA, after they were
        // detected; `y` holds a value per row of `l` (asserted).
        unsafe { dot1_rows_rev(l, y, &mut *acc1) };
        return;
    }
    let mut lc = l.rchunks_exact(LANES);
    let mut yc = y.rchunks_exact(LANES * K);
    for (ls, ys) in (&mut lc).zip(&mut yc) {
        for lane in 0..LANES {
            for c in 0..K {
                acc[lane][c] = M::mul_add(ls[lane], ys[lane * K + c], acc[lane][c]);
            }
        }
    }
    for (r, &lv) in lc.remainder().iter().enumerate().rev() {
        for c in 0..K {
            acc[0][c] = M::mul_add(lv, yc.remainder()[r * K + c], acc[0][c]);
        }
    }
}

/// [`dot_rows_rev`] for one right-hand side with an AVX2 vector of the four lanes:
/// lane `q` takes row `r + q` of each chunk of four from the end, as the generic
/// loop does, and the first `len % LANES` rows, last first, go into lane 0; the same
/// fused products in the same order per lane (bit-identical).
///
/// # Safety
/// The CPU must have AVX2 and FMA, and `y.len() >= l.len()` (the callers pass
/// equal lengths, which the generic loop's pairing from the end assumes).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
pub(super) unsafe fn dot1_rows_rev(l: &[f64], y: &[f64], acc: &mut [f64; LANES]) {
    use std::arch::x86_64::{_mm256_fmadd_pd, _mm256_loadu_pd, _mm256_storeu_pd};
    let (lp, yp) = (l.as_ptr(), y.as_ptr());
    let mut a = _mm256_loadu_pd(acc.as_ptr());
    let mut r = l.len();
    while r >= LANES {
        r -= LANES;
        a = _mm256_fmadd_pd(_mm256_loadu_pd(lp.add(r)), _mm256_loadu_pd(yp.add(r)), a);
    }
    _mm256_storeu_pd(acc.as_mut_ptr(), a);
    while r > 0 {
        r -= 1;
        acc[0] = (*lp.add(r)).mul_add(*yp.add(r), acc[0]);
    }
}

/// [`dot_rows_rev`] for eight right-hand sides with AVX2 vectors: the same
/// products in the same order per lane (bit-identical).
///
/// # Safety
/// The CPU must have AVX2 and FMA, and `y.len() >= 8 l.len()`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
pub(super) unsafe fn dot8_rows_rev(l: &[f64], y: &[f64], acc: &mut [[f64; 8]; LANES]) {
    use std::arch::x86_64::{
        __m256d, _mm256_fmadd_pd, _mm256_loadu_pd, _mm256_set1_pd, _mm256_storeu_pd,
    };
    let (lp, yp) = (l.as_ptr(), y.as_ptr());
    let mut a: [[__m256d; 2]; LANES] = std::array::from_fn(|q| {
        [
            _mm256_loadu_pd(acc[q].as_ptr()),
            _mm256_loadu_pd(acc[q].as_ptr().add(4)),
        ]
    });
    // Rows in chunks of `LANES` from the end, row `r + q` of a chunk into lane `q`;
    // the first `len % LANES` rows, last first, into lane 0.
    let mut r = l.len();
    while r >= LANES {
        r -= LANES;
        for (q, aq) in a.iter_mut().enumerate() {
            let lv = _mm256_set1_pd(*lp.add(r + q));
            let row = yp.add((r + q) * 8);
            aq[0] = _mm256_fmadd_pd(lv, _mm256_loadu_pd(row), aq[0]);
            aq[1] = _mm256_fmadd_pd(lv, _mm256_loadu_pd(row.add(4)), aq[1]);
        }
    }
    while r > 0 {
        r -= 1;
        let lv = _mm256_set1_pd(*lp.add(r));
        let row = yp.add(r * 8);
        a[0][0] = _mm256_fmadd_pd(lv, _mm256_loadu_pd(row), a[0][0]);
        a[0][1] = _mm256_fmadd_pd(lv, _mm256_loadu_pd(row.add(4)), a[0][1]);
    }
    for (q, aq) in a.iter().enumerate() {
        _mm256_storeu_pd(acc[q].as_mut_ptr(), aq[0]);
        _mm256_storeu_pd(acc[q].as_mut_ptr().add(4), aq[1]);
    }
}
