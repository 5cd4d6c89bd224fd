//! rothe's own triangular solves against faer's: one right-hand side, a block of
//! them, and the solve of a sparse right-hand side, on grid Laplacians, random
//! sparse SPD matrices of several patterns and sizes, and FE matrices of the W1
//! cantilever, with supernodal and simplicial factors.

use rothe::linsolve::faer_backend::FaerCholesky;
use rothe::linsolve::{LowerCsc, SymmetricSolver};

/// A deterministic pseudo-random sequence in [-0.5, 0.5).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }
}

/// The lower triangle of a symmetric matrix from its strictly-lower entries, made
/// SPD by a dominant diagonal.
fn spd(n: usize, lower: &[(usize, usize, f64)]) -> LowerCsc {
    let mut cols: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
    let mut diag = vec![1.0; n];
    for &(i, j, v) in lower {
        let (i, j) = (i.max(j), i.min(j));
        if i == j {
            continue;
        }
        cols[j].push((i, v));
        diag[i] += v.abs();
        diag[j] += v.abs();
    }
    let mut a = LowerCsc {
        n,
        col_ptr: vec![0],
        row_idx: Vec::new(),
        values: Vec::new(),
    };
    for (j, col) in cols.iter_mut().enumerate() {
        col.sort_by_key(|e| e.0);
        col.dedup_by_key(|e| e.0);
        a.row_idx.push(j);
        a.values.push(diag[j]);
        for &(i, v) in col.iter() {
            a.row_idx.push(i);
            a.values.push(v);
        }
        a.col_ptr.push(a.row_idx.len());
    }
    a
}

fn grid(m: usize) -> LowerCsc {
    let mut e = Vec::new();
    for j in 0..m * m {
        let (x, y) = (j % m, j / m);
        if x + 1 < m {
            e.push((j + 1, j, -1.0));
        }
        if y + 1 < m {
            e.push((j + m, j, -1.0));
        }
        if x + 1 < m && y + 1 < m {
            e.push((j + m + 1, j, -0.5));
        }
    }
    spd(m * m, &e)
}

fn random(n: usize, per_col: usize, band: Option<usize>, seed: u64) -> LowerCsc {
    let mut r = Rng(seed);
    let mut e = Vec::new();
    for j in 0..n {
        for _ in 0..per_col {
            let span = band.unwrap_or(n);
            let off = 1 + ((r.next() + 0.5) * span as f64) as usize;
            if j + off < n {
                e.push((j + off, j, r.next()));
            }
        }
    }
    spd(n, &e)
}

fn w1(ny: usize) -> LowerCsc {
    let model = crate::workload::w1(ny).unwrap();
    let h: f64 = 1e-5;
    crate::workload::effective_matrix(&model, 1.0 / (h * h), 1.0)
}

fn matrices() -> Vec<(String, LowerCsc)> {
    vec![
        ("grid 40".into(), grid(40)),
        ("grid 150".into(), grid(150)),
        ("random 500 banded".into(), random(500, 4, Some(30), 7)),
        ("random 6000 banded".into(), random(6000, 8, Some(150), 11)),
        ("random 1500 wide".into(), random(1500, 3, None, 13)),
        ("W1 ny=20".into(), w1(20)),
        ("W1 ny=40".into(), w1(40)),
    ]
}

fn rel(a: &[f64], b: &[f64]) -> f64 {
    let num = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    num / b.iter().map(|y| y.abs()).fold(f64::MIN_POSITIVE, f64::max)
}

fn factor(a: &LowerCsc) -> FaerCholesky {
    let mut f = FaerCholesky::new();
    f.analyze(a).unwrap();
    f.factorize(a).unwrap();
    f
}

#[test]
fn own_solves_agree_with_faers() {
    let mut supernodal = 0;
    for (name, a) in matrices() {
        let mut f = factor(&a);
        let (own, _) = f.supernodal().expect("rothe's own solver for every factor");
        // A simplicial factor runs as one-column supernodes.
        supernodal += usize::from(own.supernodes() < a.n);
        let mut r = Rng(3);
        for k in [1, 3, 8, 11] {
            let b: Vec<f64> = (0..a.n * k).map(|_| r.next()).collect();
            let mut mine = b.clone();
            f.solve_block_in_place(&mut mine, k).unwrap();
            let mut theirs = b.clone();
            f.solve_with_faer(&mut theirs, k).unwrap();
            let e = rel(&mine, &theirs);
            assert!(e < 1e-12, "{name}, k = {k}: {e:e}");
            // A block of k is the k single solves.
            for c in 0..k {
                let mut one = b[c * a.n..(c + 1) * a.n].to_vec();
                f.solve_in_place(&mut one).unwrap();
                assert!(rel(&one, &mine[c * a.n..(c + 1) * a.n]) < 1e-14, "{name}");
            }
        }
    }
    assert!(
        supernodal >= 3,
        "only {supernodal} of the matrices got a supernodal factor"
    );
}

#[test]
fn a_sparse_right_hand_side_gives_the_dense_forward_solve() {
    for (name, a) in matrices() {
        let mut f = factor(&a);
        let n = a.n;
        let (s, values) = f.supernodal().expect("own solver");
        let values = values.to_vec();
        for entries in [
            vec![(0, 1.0)],
            vec![(n / 2, -2.0), (n - 1, 0.5)],
            vec![(n / 3, 1.0), (n / 3 + 1, 1.0)],
        ] {
            let mut b = vec![0.0; n];
            for &(i, v) in &entries {
                b[i] += v;
            }
            let (mut dense, mut sparse) = (vec![0.0; n], vec![0.0; n]);
            s.forward_dense(&values, &b, &mut dense);
            let visited = s.forward_sparse(&values, &entries, &mut sparse);
            assert!(rel(&sparse, &dense) < 1e-14, "{name} {entries:?}");
            assert!(visited <= s.supernodes());
        }
        // The whole solve of a sparse right-hand side is the dense solve.
        let entries = [(n / 2, -2.0), (n - 1, 0.5), (n / 2, 1.0)];
        let mut b = vec![0.0; n];
        for &(i, v) in &entries {
            b[i] += v;
        }
        let mut dense = b.clone();
        s.solve_in_place(&values, &mut dense, 1);
        let mut sparse = vec![f64::NAN; n];
        s.solve_sparse(&values, &entries, &mut sparse);
        assert!(rel(&sparse, &dense) < 1e-14, "{name}: solve_sparse");
        // One nonzero on a leaf visits only its path to the root.
        let (mut y, total) = (vec![0.0; n], s.supernodes());
        let few = (0..n)
            .map(|i| s.forward_sparse(&values, &[(i, 1.0)], &mut y))
            .min()
            .unwrap();
        assert!(few < total || total == 1, "{name}: {few} of {total}");
    }
}

#[test]
fn the_two_thread_solve_gives_the_sequential_one() {
    // Large systems cut the elimination forest into two parts solved at once and a
    // top solved after (forward) and before (backward) them. W1 at ny = 60 (29k
    // unknowns) with faer's AMD and with rothe's nested dissection, and a grid.
    let model = crate::workload::w1(60).unwrap();
    let a = w1(60);
    let dofs =
        rothe::system::DofMap::new(model.mesh.n_dofs(), model.constraints.iter().map(|c| c.dof));
    let xy: Vec<[f64; 3]> = dofs
        .free
        .iter()
        .map(|&d| model.mesh.coords[d / 2])
        .collect();
    let nd = rothe::linsolve::ordering::nested_dissection(&xy, &a.col_ptr, &a.row_idx);
    let one_thread = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let two_threads = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    for (name, a, order) in [
        ("W1 ny=60 AMD", a.clone(), None),
        ("W1 ny=60 nested dissection", a, Some(nd)),
        ("grid 200", grid(200), None),
    ] {
        let mut f = FaerCholesky::new();
        if let Some(order) = order {
            f.set_ordering(order);
        }
        f.analyze(&a).unwrap();
        f.factorize(&a).unwrap();
        let shares = f.supernodal().unwrap().0.split_shares();
        let [p0, p1, top] = shares.unwrap_or_else(|| panic!("{name}: no cut"));
        assert!(p0 > 0.25 && p1 > 0.25 && top < 0.3, "{name}: {shares:?}");
        let mut r = Rng(5);
        for k in [1, 3, 8] {
            let b: Vec<f64> = (0..a.n * k).map(|_| r.next()).collect();
            let mut split = b.clone();
            two_threads.install(|| f.solve_block_in_place(&mut split, k).unwrap());
            let mut seq = b.clone();
            one_thread.install(|| f.solve_block_in_place(&mut seq, k).unwrap());
            let mut theirs = b.clone();
            f.solve_with_faer(&mut theirs, k).unwrap();
            assert!(
                rel(&split, &seq) < 1e-13,
                "{name}, k = {k}: split vs sequential"
            );
            assert!(
                rel(&split, &theirs) < 1e-12,
                "{name}, k = {k}: split vs faer"
            );
            // Repeated solves leave the buffers as they found them.
            let mut again = b.clone();
            two_threads.install(|| f.solve_block_in_place(&mut again, k).unwrap());
            assert_eq!(again, split, "{name}, k = {k}: a second solve differs");
        }
    }
}
