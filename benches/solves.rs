//! The triangular solves at the memory bound: STREAM-triad and plain-read probes
//! of this machine's bandwidth, and one solve, a block of 8 and the sparse forward solve on
//! W1's effective matrix, rothe's own supernodal solves against faer's. Each group
//! prints the bytes the factor streams (`2 nnz(L) · 8 B` per solve) so the ratio to
//! the triad bandwidth can be read off the same run.

#[path = "common/workload.rs"]
mod workload;

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use rothe::linsolve::faer_backend::FaerCholesky;
use rothe::linsolve::SymmetricSolver;

/// `a = b + s c` over arrays far larger than the caches: 24 bytes moved per element
/// (two loads, one store; a write-allocate adds 8 more on machines without
/// streaming stores, which this counts as the STREAM convention does not), and a
/// plain read of one array (one sequential stream per thread, as a triangular
/// solve reads its factor).
fn triad(c: &mut Criterion) {
    use crate::workload::{read_sum, triad};
    let n = 1 << 24; // 3 arrays of 128 MB
    let b = vec![1.0f64; n];
    let cc = vec![2.0f64; n];
    let mut a = vec![0.0f64; n];
    let mut g = c.benchmark_group("stream");
    g.sample_size(10);
    g.throughput(Throughput::Bytes(24 * n as u64));
    g.bench_function("triad", |bench| bench.iter(|| triad(&mut a, &b, &cc, n)));
    // On all cores (STREAM's convention): the two-thread solve draws on this.
    let chunk = n.div_ceil(rayon::current_num_threads());
    g.bench_function("triad_all_cores", |bench| {
        bench.iter(|| triad(&mut a, &b, &cc, chunk))
    });
    let long: Vec<f64> = (0..4 * n).map(|i| (i % 7) as f64).collect();
    g.throughput(Throughput::Bytes(8 * long.len() as u64));
    g.bench_function("read", |bench| {
        bench.iter(|| black_box(read_sum(&long, long.len())))
    });
    let chunk = long.len().div_ceil(rayon::current_num_threads());
    g.bench_function("read_all_cores", |bench| {
        bench.iter(|| black_box(read_sum(&long, chunk)))
    });
    g.finish();
}

fn w1_factor(ny: usize) -> (FaerCholesky, usize, usize) {
    let model = workload::w1(ny).unwrap();
    let h = model.analysis.time.dt;
    let a = workload::effective_matrix(&model, 1.0 / (h * h), 1.0);
    let mut f = FaerCholesky::new();
    f.analyze(&a).unwrap();
    f.factorize(&a).unwrap();
    let nnz = f.factor_nnz().unwrap();
    (f, a.n, nnz)
}

fn solves(c: &mut Criterion) {
    let mut g = c.benchmark_group("w1_solve");
    g.sample_size(10);
    for ny in [100usize, 250] {
        let (mut f, n, nnz) = w1_factor(ny);
        let bytes = 2 * nnz as u64 * 8;
        eprintln!(
            "W1 ny = {ny}: n = {n}, nnz(L) = {nnz}, one solve streams {:.1} MB",
            bytes as f64 / 1e6
        );
        let b: Vec<f64> = (0..8 * n).map(|i| ((i as f64) * 0.37).sin()).collect();
        g.throughput(Throughput::Bytes(bytes));
        let mut x = b[..n].to_vec();
        g.bench_with_input(BenchmarkId::new("own_1", ny), &ny, |bench, _| {
            bench.iter(|| f.solve_block_in_place(&mut x, 1).unwrap())
        });
        g.bench_with_input(BenchmarkId::new("faer_1", ny), &ny, |bench, _| {
            bench.iter(|| f.solve_with_faer(&mut x, 1).unwrap())
        });
        let mut x8 = b.clone();
        g.bench_with_input(BenchmarkId::new("own_8", ny), &ny, |bench, _| {
            bench.iter(|| f.solve_block_in_place(&mut x8, 8).unwrap())
        });
        g.bench_with_input(BenchmarkId::new("faer_8", ny), &ny, |bench, _| {
            bench.iter(|| f.solve_with_faer(&mut x8, 8).unwrap())
        });
        if let Some((s, values)) = f.supernodal() {
            let values = values.to_vec();
            let mut y = vec![0.0; n];
            let b1 = b[..n].to_vec();
            g.bench_with_input(
                BenchmarkId::new("own_forward_dense", ny),
                &ny,
                |bench, _| bench.iter(|| s.forward_dense(&values, &b1, &mut y)),
            );
            // A contact-like right-hand side: a few dofs at the free end.
            let entries: Vec<(usize, f64)> = (0..6).map(|k| (n - 1 - 2 * k, 1.0)).collect();
            g.bench_with_input(
                BenchmarkId::new("own_forward_sparse_6", ny),
                &ny,
                |bench, _| bench.iter(|| s.forward_sparse(&values, &entries, &mut y)),
            );
        }
    }
    g.finish();
}

criterion_group!(benches, triad, solves);
criterion_main!(benches);
