//! No allocation inside the step loop: after a first step (which may size buffers),
//! steps of every material model allocate nothing the size of the problem. The
//! counting allocator below sees every heap allocation of this test binary.
//!
//! Rayon's job queue takes a small block now and then as parallel loops are
//! injected into its pool; those are bounded in size and number. The test allows
//! allocations below 4 KiB, at most 8 per step on average, and none larger.

#[path = "../benches/common/workload.rs"]
mod workload;

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use rothe::linsolve::Backend;
use rothe::time::backward_euler::BackwardEuler;
use rothe::time::Integrator;

struct Counting;

static SMALL: AtomicUsize = AtomicUsize::new(0);
static LARGE: AtomicUsize = AtomicUsize::new(0);
static LARGEST: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards to the system allocator; the counters are atomics.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if layout.size() >= 4096 {
            LARGE.fetch_add(1, Ordering::Relaxed);
            LARGEST.fetch_max(layout.size(), Ordering::Relaxed);
        } else {
            SMALL.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

const VARIANTS: [&str; 6] = [
    "elastic",
    "sls",
    "mazars",
    "mazars-fixed",
    "mazars-nonlocal",
    "rankine-hill",
];

#[test]
fn steps_allocate_nothing_the_size_of_the_problem() {
    for variant in VARIANTS {
        // W1 at ny = 12 (48 x 12 Q4, 1250 dofs): the damage and plasticity variants
        // iterate from the first steps on.
        let model = workload::w1_variant(12, variant).unwrap();
        let mut be = BackwardEuler::new(&model, Backend::Faer).unwrap();
        let mut s = be.initial_state();
        be.step_accepted(&mut s).unwrap();
        let steps = 10;
        let (small0, large0) = (SMALL.load(Ordering::Relaxed), LARGE.load(Ordering::Relaxed));
        LARGEST.store(0, Ordering::Relaxed);
        let mut iterations = 0;
        for _ in 0..steps {
            iterations += be.step_accepted(&mut s).unwrap().iterations;
        }
        let small = SMALL.load(Ordering::Relaxed) - small0;
        let large = LARGE.load(Ordering::Relaxed) - large0;
        assert_eq!(
            large,
            0,
            "{variant}: {large} allocations of 4 KiB or more in {steps} steps (largest {} B)",
            LARGEST.load(Ordering::Relaxed)
        );
        assert!(
            small <= 8 * steps,
            "{variant}: {small} small allocations in {steps} steps ({iterations} iterations)"
        );
        eprintln!("{variant}: {small} small allocations in {steps} steps, {iterations} iterations");
    }
}
