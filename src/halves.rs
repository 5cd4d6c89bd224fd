//! Parallel passes whose sums repeat to the last bit.
//!
//! A pass over `n` entries is split in halves down to a leaf length, two halves at a
//! time on the thread pool, and the halves' results are combined left to right in the
//! fixed tree of the halving. The tree depends on `n` and the leaf length only, so a
//! pass gives the same sums in every run and on any number of threads, whichever
//! thread takes which half; a rayon `fold`/`reduce` groups its additions where the
//! pool's work stealing happens to split, which can differ from run to run. The
//! step's residual pass, the equilibrium loop's passes, the nodal-field and
//! Gauss-point passes and the work integrands all sum their ledger terms this way.

use std::ops::Range;

/// Entries per leaf of the vector passes (a few microseconds of work).
pub const VECTOR_LEAF: usize = 8192;

/// Runs `leaf` on the pieces of `parts` (`n` entries), halved by `split` down to at
/// most `leaf_len` entries, and combines their results left to right in the fixed
/// tree of the halving.
pub fn in_halves<S, R, Sp, L, C>(
    parts: S,
    n: usize,
    leaf_len: usize,
    split: &Sp,
    leaf: &L,
    combine: &C,
) -> R
where
    S: Send,
    R: Send,
    Sp: Fn(S, usize) -> (S, S) + Sync,
    L: Fn(S) -> R + Sync,
    C: Fn(R, R) -> R + Sync,
{
    if n <= leaf_len.max(1) {
        return leaf(parts);
    }
    let mid = n / 2;
    let (a, b) = split(parts, mid);
    let (ra, rb) = rayon::join(
        || in_halves(a, mid, leaf_len, split, leaf, combine),
        || in_halves(b, n - mid, leaf_len, split, leaf, combine),
    );
    combine(ra, rb)
}

/// [`in_halves`] over the index range `0..n`, for passes that write nothing or write
/// through their own means.
pub fn in_ranges<R, L, C>(n: usize, leaf_len: usize, leaf: &L, combine: &C) -> R
where
    R: Send,
    L: Fn(Range<usize>) -> R + Sync,
    C: Fn(R, R) -> R + Sync,
{
    let split = |r: Range<usize>, mid: usize| (r.start..r.start + mid, r.start + mid..r.end);
    in_halves(0..n, n, leaf_len, &split, leaf, combine)
}

/// A piece of `N` equally long mutable vectors starting at entry `lo`.
pub type Slices<'a, const N: usize> = (usize, [&'a mut [f64]; N]);

/// Cuts a [`Slices`] piece at `mid` entries (the `split` of passes that write
/// several vectors).
pub fn split_slices<const N: usize>(
    (lo, slices): Slices<'_, N>,
    mid: usize,
) -> (Slices<'_, N>, Slices<'_, N>) {
    let mut halves = slices.map(|s| {
        let (a, b) = s.split_at_mut(mid);
        (Some(a), Some(b))
    });
    let first = std::array::from_fn(|k| halves[k].0.take().expect("set just above"));
    let second = std::array::from_fn(|k| halves[k].1.take().expect("set just above"));
    ((lo, first), (lo + mid, second))
}

/// Elementwise sum of two arrays of sums (the `combine` of most passes).
pub fn add<const N: usize>(a: [f64; N], b: [f64; N]) -> [f64; N] {
    std::array::from_fn(|k| a[k] + b[k])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sums_in_halves_repeat_on_any_pool_and_visit_every_entry_once() {
        let n = 37 * VECTOR_LEAF + 19;
        let x: Vec<f64> = (0..n)
            .map(|i| ((i * 7919) % 10007) as f64 * 1e-3 - 5.0)
            .collect();
        let leaf = |r: Range<usize>| {
            let s: f64 = x[r.clone()].iter().map(|v| v * v).sum();
            (s, r.len(), r.start)
        };
        // Pieces arrive left to right: the second starts where the first ended.
        let combine = |a: (f64, usize, usize), b: (f64, usize, usize)| {
            assert_eq!(a.2 + a.1, b.2, "pieces out of order");
            (a.0 + b.0, a.1 + b.1, a.2)
        };
        let reference = in_ranges(n, VECTOR_LEAF, &leaf, &combine);
        assert_eq!((reference.1, reference.2), (n, 0));
        let plain: f64 = x.iter().map(|v| v * v).sum();
        assert!((reference.0 - plain).abs() <= 1e-12 * plain);
        for threads in [1, 2, 3, 4] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            for _ in 0..3 {
                let again = pool.install(|| in_ranges(n, VECTOR_LEAF, &leaf, &combine));
                assert_eq!(
                    again.0.to_bits(),
                    reference.0.to_bits(),
                    "{threads} threads"
                );
            }
        }
        // Fewer entries than a leaf: one piece; none: the leaf of the empty range.
        assert_eq!(in_ranges(5, VECTOR_LEAF, &leaf, &combine).1, 5);
        assert_eq!(in_ranges(0, VECTOR_LEAF, &leaf, &combine).1, 0);
        assert_eq!(add([1.0, 2.0], [3.0, 4.0]), [4.0, 6.0]);
        // Vectors cut together: every entry written once, by the piece that owns it.
        let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
        let written = in_halves(
            (0, [&mut a[..], &mut b[..]]),
            n,
            VECTOR_LEAF,
            &split_slices,
            &|(lo, [a, b]): Slices<2>| {
                for (i, (x, y)) in a.iter_mut().zip(b.iter_mut()).enumerate() {
                    *x = (lo + i) as f64;
                    *y += 1.0;
                }
                a.len()
            },
            &|p: usize, q: usize| p + q,
        );
        assert_eq!(written, n);
        assert!(a.iter().enumerate().all(|(i, &x)| x == i as f64));
        assert!(b.iter().all(|&y| y == 1.0));
    }
}
