//! Sweeps over the supernodes: one thread over all of them, or two threads over the
//! halves of the elimination forest and then its top.

use super::kernels::*;
use super::structure::{Supernode, TreeSplit};
use super::Row;

/// The supernodes a sweep visits.
#[derive(Clone, Copy)]
pub(super) enum Run<'a> {
    /// All of them, on the whole `x`.
    All,
    /// The listed ones, on the whole `x`.
    Listed(&'a [u32]),
    /// One thread's subtrees: `(supernode, split)` in order, on the part of `x` from
    /// column `lo` on, rows above the subtrees in `far` (see [`Place`]).
    Part { lo: usize, nodes: &'a [(u32, u32)] },
}

/// A sweep over `run`, for one kernel flavour: a forward sweep adds its updates of
/// far rows to `far_out`, a backward sweep reads them from `far_in`.
#[inline(always)]
pub(super) fn sweep<const K: usize, M: MulAdd>(
    dir: Dir,
    run: Run,
    f: &Factor,
    x: &mut [f64],
    tmp: &mut [f64],
    far_out: &mut [f64],
    far_in: &[f64],
) {
    let (nodes, rows, values) = (f.nodes, f.rows, f.values);
    #[inline(always)]
    pub(super) fn whole(sn: &Supernode) -> Place {
        Place {
            lo: 0,
            split: sn.npattern,
        }
    }
    // Direct calls (no closures): every kernel must inline into the caller compiled
    // for AVX2 and FMA, or `mul_add` becomes a call to the software `fma`.
    match (dir, run) {
        (Dir::Forward, Run::All) => {
            for sn in nodes {
                forward_node::<K, M>(sn, rows, values, x, tmp, whole(sn), &mut []);
            }
        }
        (Dir::Backward, Run::All) => {
            for sn in nodes.iter().rev() {
                backward_node::<K, M>(sn, rows, values, x, tmp, whole(sn), far_in);
            }
        }
        (Dir::Forward, Run::Listed(ids)) => {
            for &s in ids {
                let sn = &nodes[s as usize];
                forward_node::<K, M>(sn, rows, values, x, tmp, whole(sn), &mut []);
            }
        }
        (Dir::Backward, Run::Listed(ids)) => {
            for &s in ids.iter().rev() {
                let sn = &nodes[s as usize];
                backward_node::<K, M>(sn, rows, values, x, tmp, whole(sn), far_in);
            }
        }
        (Dir::Forward, Run::Part { lo, nodes: ids }) => {
            for &(s, split) in ids {
                let at = Place {
                    lo,
                    split: split as usize,
                };
                let sn = &nodes[s as usize];
                forward_node::<K, M>(sn, rows, values, x, tmp, at, far_out);
            }
        }
        (Dir::Backward, Run::Part { lo, nodes: ids }) => {
            for &(s, split) in ids.iter().rev() {
                let at = Place {
                    lo,
                    split: split as usize,
                };
                let sn = &nodes[s as usize];
                backward_node::<K, M>(sn, rows, values, x, tmp, at, far_in);
            }
        }
    }
}

/// Both sweeps of a block of `K` row-major right-hand sides `x` on two threads, cut
/// by `split`, with one `tmp` and one `far` buffer per thread (`far` zero on entry
/// and on return).
pub(super) fn split_sweeps<const K: usize>(
    f: &Factor,
    split: &TreeSplit,
    x: &mut [f64],
    tmp: [&mut [f64]; 2],
    far: [&mut [f64]; 2],
) {
    let [t0, t1] = tmp;
    let [f0, f1] = far;
    let mid = split.mid;
    {
        let (x0, x1) = x.split_at_mut(mid * K);
        let (p0, p1) = (&split.parts[0], &split.parts[1]);
        rayon::join(
            || {
                f.sweep::<K>(
                    Dir::Forward,
                    Run::Part { lo: 0, nodes: p0 },
                    x0,
                    t0,
                    f0,
                    &[],
                )
            },
            || {
                f.sweep::<K>(
                    Dir::Forward,
                    Run::Part { lo: mid, nodes: p1 },
                    x1,
                    t1,
                    f1,
                    &[],
                )
            },
        );
    }
    for &c in &split.top_cols {
        let i = c as usize * K;
        for j in i..i + K {
            x[j] += f0[j] + f1[j];
            f1[j] = 0.0;
        }
    }
    let top = Run::Listed(&split.top);
    f.sweep::<K>(Dir::Forward, top, x, t0, &mut [], &[]);
    f.sweep::<K>(Dir::Backward, top, x, t0, &mut [], &[]);
    // The parts read the top rows from `f0`.
    for &c in &split.top_cols {
        let i = c as usize * K;
        f0[i..i + K].copy_from_slice(&x[i..i + K]);
    }
    {
        let far: &[f64] = f0;
        let (x0, x1) = x.split_at_mut(mid * K);
        let (p0, p1) = (&split.parts[0], &split.parts[1]);
        rayon::join(
            || {
                f.sweep::<K>(
                    Dir::Backward,
                    Run::Part { lo: 0, nodes: p0 },
                    x0,
                    t0,
                    &mut [],
                    far,
                )
            },
            || {
                f.sweep::<K>(
                    Dir::Backward,
                    Run::Part { lo: mid, nodes: p1 },
                    x1,
                    t1,
                    &mut [],
                    far,
                )
            },
        );
    }
    for &c in &split.top_cols {
        let i = c as usize * K;
        f0[i..i + K].fill(0.0);
    }
}

/// [`sweep`] compiled for AVX2 with FMA.
///
/// # Safety
/// The CPU must have AVX2 and FMA (checked by the caller).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
pub(super) unsafe fn sweep_avx2<const K: usize>(
    dir: Dir,
    run: Run,
    f: &Factor,
    x: &mut [f64],
    tmp: &mut [f64],
    far_out: &mut [f64],
    far_in: &[f64],
) {
    sweep::<K, Fused>(dir, run, f, x, tmp, far_out, far_in)
}

/// What one sweep reads besides `x` and its buffers.
#[derive(Clone, Copy)]
pub(super) struct Factor<'a> {
    pub(super) nodes: &'a [Supernode],
    pub(super) rows: &'a [Row],
    pub(super) values: &'a [f64],
}

impl Factor<'_> {
    /// [`sweep`] with the fastest kernels this CPU runs.
    pub(super) fn sweep<const K: usize>(
        &self,
        dir: Dir,
        run: Run,
        x: &mut [f64],
        tmp: &mut [f64],
        far_out: &mut [f64],
        far_in: &[f64],
    ) {
        #[cfg(target_arch = "x86_64")]
        {
            if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
                // SAFETY: both features were just detected.
                unsafe { sweep_avx2::<K>(dir, run, self, x, tmp, far_out, far_in) };
                return;
            }
        }
        sweep::<K, Plain>(dir, run, self, x, tmp, far_out, far_in)
    }
}
