//! Large zeroed buffers filled eagerly.
//!
//! `vec![0.0; n]` gets lazily zeroed pages from the kernel, so the page faults land
//! later inside the parallel scatter or the numeric factorisation, where they contend
//! and cost more. Filling the buffer when it is created takes the faults up front: on
//! W1 (ny = 250) this halved the assembly time (0.56 s to 0.27 s) and cut the faer
//! factorisation from 1.9 s to 1.15 s. Buffers of 8 MB and more are filled on the
//! thread pool, where the faults of the first touch run on every core: on this
//! virtual machine a first touch costs several microseconds a page. The faer factor
//! of W1 at ny = 500 (2.1 GB of values, 0.34 GB of workspace): the first numeric
//! factorisation took 14.7–16.9 s against 4.7–5.3 s for the next one, the rest
//! being the first touch on one thread; filled on two threads first, 9.5–10.1 s, of
//! which the fill 4.9 s. (Transparent huge pages through
//! `madvise` were measured too and were slower here: the kernel's compaction stalls
//! outweighed the faults they save.)

/// A vector of `n` default values with every page already touched (on the thread
/// pool for large buffers, see [`try_zeroed`]).
pub fn zeroed<T: Copy + Default + Send>(n: usize) -> Vec<T> {
    match try_zeroed(n) {
        Some(v) => v,
        None => std::alloc::handle_alloc_error(
            std::alloc::Layout::array::<T>(n).unwrap_or(std::alloc::Layout::new::<T>()),
        ),
    }
}

/// Buffers of at least this many bytes are filled on the thread pool.
const PARALLEL_FILL_BYTES: usize = 8 << 20;

/// Bytes each task of a parallel fill takes.
const FILL_CHUNK_BYTES: usize = 1 << 20;

/// Writes zeros over the bytes of a fresh workspace (on the thread pool when it is
/// large), so that its page faults are taken here, on every core, and not one by one
/// inside the sequential code that uses it.
pub fn touch(buf: &mut [std::mem::MaybeUninit<u8>]) {
    use rayon::prelude::*;
    let fill = |part: &mut [std::mem::MaybeUninit<u8>]| {
        for b in part {
            b.write(0);
        }
    };
    if buf.len() >= PARALLEL_FILL_BYTES {
        buf.par_chunks_mut(FILL_CHUNK_BYTES).for_each(fill);
    } else {
        fill(buf);
    }
}

/// [`zeroed`], or `None` when the memory cannot be had. A large buffer is filled on
/// the thread pool: the page faults of its first touch then run on every core
/// (2 GiB on this 2-core machine: 0.46–0.66 s against 0.9–2.2 s on one thread).
pub fn try_zeroed<T: Copy + Default + Send>(n: usize) -> Option<Vec<T>> {
    use rayon::prelude::*;
    use std::mem::MaybeUninit;
    let mut v: Vec<T> = Vec::new();
    v.try_reserve_exact(n).ok()?;
    let fill = |part: &mut [MaybeUninit<T>]| {
        for x in part {
            x.write(T::default());
        }
    };
    let size = std::mem::size_of::<T>().max(1);
    let spare = &mut v.spare_capacity_mut()[..n];
    if n * size >= PARALLEL_FILL_BYTES {
        spare
            .par_chunks_mut((FILL_CHUNK_BYTES / size).max(1))
            .for_each(fill);
    } else {
        fill(spare);
    }
    // SAFETY: the capacity holds `n` elements and all `n` were written just above.
    unsafe { v.set_len(n) };
    Some(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zeroed_buffers_hold_zeros_on_the_pool_and_refuse_what_cannot_be_had() {
        // Below and above the size filled on the pool, odd lengths included.
        for n in [
            0usize,
            3,
            PARALLEL_FILL_BYTES / 8 - 1,
            3 * PARALLEL_FILL_BYTES / 8 + 5,
        ] {
            let v: Vec<f64> = zeroed(n);
            assert_eq!(v.len(), n);
            assert!(v.iter().all(|x| x.to_bits() == 0), "{n}");
            let w: Vec<u32> = try_zeroed(n).expect("small enough");
            assert!(w.len() == n && w.iter().all(|&x| x == 0));
        }
        // More than any machine has: `None`, not an abort.
        assert!(try_zeroed::<f64>(usize::MAX / 4).is_none());
        let mut buf = vec![std::mem::MaybeUninit::new(7u8); 2 * PARALLEL_FILL_BYTES + 3];
        touch(&mut buf);
        // SAFETY: every byte was initialised (to 7, then to 0 by `touch`).
        assert!(buf.iter().all(|b| unsafe { b.assume_init() } == 0));
    }
}
