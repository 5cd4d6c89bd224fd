//! A run's numbers do not depend on how the thread pool happens to split its work:
//! the same model run again, and on pools of 2 and 3 threads, gives the same ledger
//! and displacements to the last bit (every parallel sum goes through the fixed
//! trees of `rothe::halves`, and the solve's two-thread cut is fixed by the factor;
//! theory/equilibrium.md). On one thread the solve adds its updates in another order,
//! which agrees to round-off.

use rothe::linsolve::Backend;
use rothe::time::backward_euler::BackwardEuler;
use rothe::time::march::{march, StepControl};

/// The ledger's lines and `u` after `steps` steps of W1 (`ny`, the material
/// `variant`) on a pool of `threads`.
fn fingerprint(ny: usize, variant: &str, steps: usize, threads: usize) -> Vec<f64> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut model = crate::workload::w1_variant(ny, variant).unwrap();
        model.analysis.time.t_end = steps as f64 * model.analysis.time.dt;
        let mut be = BackwardEuler::new(&model, Backend::default()).unwrap();
        let mut s = be.initial_state();
        march(&mut be, &mut s, StepControl::of(&model), |_, _, _| Ok(())).unwrap();
        let l = &s.ledger;
        let mut values: Vec<f64> = [l.kinetic(), l.internal(), l.external_work(), l.elastic()]
            .into_iter()
            .chain(l.dissipated().lines().iter().map(|&(_, x)| x))
            .collect();
        values.extend(&s.u);
        values
    })
}

/// Entries of a fingerprint before `u`: four energies and the dissipation lines.
const LEDGER_LINES: usize = 10;

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

#[test]
fn ledgers_and_fields_repeat_to_the_last_bit_on_any_pool() {
    // ny = 50: 40k dofs, five leaves of the vector passes; the variants cover the
    // elastic pass, the nodal-field SLS pass, the Gauss-point pass and the nonlocal
    // averaging (40k points, about 110 neighbours each).
    for (variant, steps) in [
        ("elastic", 20),
        ("sls", 20),
        ("rankine-hill", 4),
        ("mazars-nonlocal", 4),
    ] {
        let two = fingerprint(50, variant, steps, 2);
        for (threads, what) in [(2, "again"), (3, "on 3 threads")] {
            assert!(
                bits(&fingerprint(50, variant, steps, threads)) == bits(&two),
                "{variant}: a run {what} differs from the first on 2 threads"
            );
        }
        // One thread: the ledger's lines and `u` each to 1e-9 of their size.
        let one = fingerprint(50, variant, steps, 1);
        let lines = LEDGER_LINES;
        for (part, (a, b)) in [
            ("ledger", (&one[..lines], &two[..lines])),
            ("u", (&one[lines..], &two[lines..])),
        ] {
            let scale = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            for (k, (x, y)) in a.iter().zip(b).enumerate() {
                assert!(
                    (x - y).abs() <= 1e-9 * scale,
                    "{variant}: {part}[{k}]: {x} on one thread, {y} on two"
                );
            }
        }
    }
}
