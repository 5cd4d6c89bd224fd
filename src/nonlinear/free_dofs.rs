//! The equilibrium loop's passes over the free dofs on the thread pool, in halves
//! of a fixed tree ([`crate::halves`]): the prediction of the right-hand side, the
//! gather of the residual and the update of the iterate by the correction.

use crate::halves::{in_halves, VECTOR_LEAF as LEAF};

/// Writes `value(d)` for every free dof `d = free[eq]` into `out[eq]` (sized to
/// `free` first) and folds `(d, value)` into a result per piece with `fold` from
/// `init`, the pieces' results combined by `combine` (the earlier piece first).
pub(crate) fn fill_free<R, V, F, C>(
    free: &[usize],
    out: &mut Vec<f64>,
    value: V,
    init: R,
    fold: F,
    combine: C,
) -> R
where
    R: Send + Copy + Sync,
    V: Fn(usize) -> f64 + Sync,
    F: Fn(R, usize, f64) -> R + Sync,
    C: Fn(R, R) -> R + Sync,
{
    if out.len() != free.len() {
        // Once per size: the loop reuses the buffer from step to step.
        out.clear();
        out.resize(free.len(), 0.0);
    }
    type Piece<'a> = (&'a [usize], &'a mut [f64]);
    fn split(p: Piece<'_>, mid: usize) -> (Piece<'_>, Piece<'_>) {
        let (f0, f1) = p.0.split_at(mid);
        let (o0, o1) = p.1.split_at_mut(mid);
        ((f0, o0), (f1, o1))
    }
    let leaf = |(f, o): Piece| {
        let mut acc = init;
        for (&d, slot) in f.iter().zip(o.iter_mut()) {
            let x = value(d);
            *slot = x;
            acc = fold(acc, d, x);
        }
        acc
    };
    in_halves(
        (free, &mut out[..]),
        free.len(),
        LEAF,
        &split,
        &leaf,
        &combine,
    )
}

/// Adds `delta[eq]` to `u` (and to `du` when given) at the free dof `free[eq]`
/// (`free` ascending, as [`crate::system::DofMap`] numbers them) and returns
/// `|delta|²`.
pub(crate) fn add_on_free(
    free: &[usize],
    delta: &[f64],
    u: &mut [f64],
    du: Option<&mut [f64]>,
) -> f64 {
    /// One piece: its equations, their corrections, the part of `u` (and `du`)
    /// from dof `base` on that holds their dofs.
    type Piece<'a> = (
        &'a [usize],
        &'a [f64],
        &'a mut [f64],
        Option<&'a mut [f64]>,
        usize,
    );
    debug_assert!(free.windows(2).all(|w| w[0] < w[1]));
    fn split(piece: Piece<'_>, mid: usize) -> (Piece<'_>, Piece<'_>) {
        let (f, c, u, du, base) = piece;
        // Dofs below `free[mid]` belong to the first half: `free` ascends.
        let cut = f[mid] - base;
        let (f0, f1) = f.split_at(mid);
        let (c0, c1) = c.split_at(mid);
        let (u0, u1) = u.split_at_mut(cut);
        let (du0, du1) = match du {
            Some(du) => {
                let (a, b) = du.split_at_mut(cut);
                (Some(a), Some(b))
            }
            None => (None, None),
        };
        ((f0, c0, u0, du0, base), (f1, c1, u1, du1, base + cut))
    }
    let leaf = |(f, c, u, mut du, base): Piece| {
        let mut c2 = 0.0;
        for (&d, &x) in f.iter().zip(c) {
            u[d - base] += x;
            if let Some(du) = du.as_deref_mut() {
                du[d - base] += x;
            }
            c2 += x * x;
        }
        c2
    };
    let n = free.len().min(delta.len());
    in_halves(
        (&free[..n], &delta[..n], u, du, 0),
        n,
        LEAF,
        &split,
        &leaf,
        &|a: f64, b: f64| a + b,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Free dofs of a model with every third dof fixed, and a correction on them.
    fn problem(n_dofs: usize) -> (Vec<usize>, Vec<f64>) {
        let free: Vec<usize> = (0..n_dofs).filter(|d| d % 3 != 1).collect();
        let delta = free.iter().map(|&d| (d as f64 * 0.37).sin()).collect();
        (free, delta)
    }

    #[test]
    fn the_update_on_the_pool_is_the_sequential_one() {
        for n_dofs in [10, LEAF + 7, 5 * LEAF + 3] {
            let (free, delta) = problem(n_dofs);
            let u0: Vec<f64> = (0..n_dofs).map(|d| d as f64).collect();
            let (mut u, mut du) = (u0.clone(), vec![1.0; n_dofs]);
            let c2 = add_on_free(&free, &delta, &mut u, Some(&mut du));
            let (mut u_seq, mut du_seq, mut c2_seq) = (u0.clone(), vec![1.0; n_dofs], 0.0);
            for (&d, &x) in free.iter().zip(&delta) {
                u_seq[d] += x;
                du_seq[d] += x;
                c2_seq += x * x;
            }
            assert_eq!(u, u_seq, "{n_dofs} dofs");
            assert_eq!(du, du_seq, "{n_dofs} dofs");
            assert!((c2 - c2_seq).abs() <= 1e-13 * c2_seq, "{c2} vs {c2_seq}");
            // Fixed dofs keep their values; without `du` the same `u`.
            let mut u_only = u0.clone();
            assert_eq!(add_on_free(&free, &delta, &mut u_only, None), c2);
            assert_eq!(u_only, u_seq);
        }
    }

    #[test]
    fn the_fill_folds_every_equation_in_order_and_repeats_its_sums() {
        let (free, _) = problem(7 * LEAF + 11);
        let value = |d: usize| ((d * d) % 1009) as f64 - 500.0;
        let run = |out: &mut Vec<f64>| {
            fill_free(
                &free,
                out,
                value,
                (0.0, usize::MAX, 0usize),
                // Sum of squares, the first dof and the count of the piece.
                |(s, first, k), d, x| (s + x * x, first.min(d), k + 1),
                |a, b| (a.0 + b.0, a.1.min(b.1), a.2 + b.2),
            )
        };
        let mut out = Vec::new();
        let (s, first, count) = run(&mut out);
        assert_eq!(count, free.len());
        assert_eq!(first, free[0]);
        let expected: Vec<f64> = free.iter().map(|&d| value(d)).collect();
        assert_eq!(out, expected);
        let s_seq: f64 = expected.iter().map(|x| x * x).sum();
        assert!((s - s_seq).abs() <= 1e-13 * s_seq);
        // The same sums to the last bit in every run, on a pool of any size.
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let again = pool.install(|| run(&mut out));
            assert_eq!(again.0.to_bits(), s.to_bits(), "{threads} threads");
        }
    }
}
