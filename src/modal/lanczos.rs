//! Shift-invert Lanczos in the mass inner product, with full reorthogonalisation.
//!
//! For `K x = λ M x` and a shift `σ` below the wanted eigenvalues, the operator
//! `S = (K − σM)⁻¹ M` is self-adjoint in the `M` inner product with eigenvalues
//! `θ = 1/(λ − σ)`: the lowest `λ` above `σ` are its largest `θ`, well separated, and
//! Lanczos finds them in a few dozen products, each one solve with the factor of
//! `K − σM`. Every new vector is orthogonalised against all earlier ones (classical
//! Gram–Schmidt in the `M` inner product, repeated when the first pass removed most
//! of the vector: "twice is enough", Daniel–Gragg–Kaufman–Stewart), so the basis stays
//! `M`-orthonormal to round-off and no spurious copies of converged pairs appear. The
//! Ritz pairs of the tridiagonal matrix are tested every few steps: a pair has
//! converged when its residual bound `|β_{j+1} s_j|` is below `tol · θ`.

use nalgebra::{DMatrix, SymmetricEigen};

/// What Lanczos found: the largest `θ` (decreasing) and their vectors
/// (`M`-orthonormal).
pub struct Ritz {
    /// `θ = 1/(λ − σ)`, largest first.
    pub theta: Vec<f64>,
    /// The vectors, one per `θ`.
    pub vectors: Vec<Vec<f64>>,
    /// Lanczos steps taken (operator applications).
    pub steps: usize,
}

/// What [`lanczos`] looks for.
#[derive(Clone, Copy, Debug)]
pub struct Wanted {
    /// Pairs.
    pub count: usize,
    /// At most this many steps.
    pub max_steps: usize,
    /// A pair has converged when its residual bound is below `tol · |θ|`.
    pub tol: f64,
    /// The largest `|θ|` (a shift inside the spectrum) instead of the largest `θ`.
    pub nearest: bool,
}

/// Why Lanczos stopped short.
#[derive(Debug)]
pub enum Shortfall {
    /// `converged` of the `wanted` pairs met the tolerance after `steps` steps.
    NotConverged {
        /// Pairs that converged.
        converged: usize,
        /// Steps taken.
        steps: usize,
    },
    /// The operator failed (its error).
    Operator(crate::error::Error),
}

/// The `wanted.count` largest eigenpairs (largest in magnitude when `nearest`: a
/// shift inside the spectrum, whose `θ` has both signs) of an `M`-self-adjoint
/// operator `S` on vectors of length `n` `M`-orthogonal to the `locked` ones (`M`-orthonormal eigenvectors found
/// before). `op` is handed `z = M q` and writes `S q` (for shift and invert,
/// `S q = (K − σM)⁻¹ z`: one solve); `mass` applies `M`. The start vector is fixed (deterministic), so a run repeats.
/// An invariant subspace found early (the whole space, when `n` is small) ends the
/// iteration with exact pairs.
///
/// One start vector meets each distinct eigenvalue once in exact arithmetic: of a
/// multiple one (a free body's rigid modes, a square section's two bending modes) it
/// may find fewer copies than there are. [`super::modes`] therefore checks the count
/// against the inertia of a factor (Sturm) and runs it again with what it found
/// locked for the ones missed.
pub fn lanczos(
    n: usize,
    wanted: &Wanted,
    locked: &[Vec<f64>],
    mut op: impl FnMut(&[f64], &mut [f64]) -> crate::error::Result<()>,
    mass: impl Fn(&[f64], &mut [f64]),
) -> Result<Ritz, Shortfall> {
    let Wanted {
        count,
        max_steps,
        tol,
        nearest,
    } = *wanted;
    let max_steps = max_steps.min(n.saturating_sub(locked.len()));
    // The locked vectors, then the Lanczos vectors, as the columns of one basis.
    let mut basis = Basis::new(n, locked.len() + max_steps.min(4 * count + 40));
    let mut my = vec![0.0; n];
    for x in locked {
        mass(x, &mut my);
        basis.push(x, &my);
    }
    let first = locked.len();
    let (mut alpha, mut beta) = (Vec::<f64>::new(), Vec::<f64>::new());
    // A fixed start with every component present (a low-discrepancy sequence).
    let mut v: Vec<f64> = (0..n)
        .map(|i| 0.5 + ((i as f64 + 1.0) * 0.618_033_988_749_895).fract())
        .collect();
    let mut mv = vec![0.0; n];
    let mut w = vec![0.0; n];
    loop {
        // Orthogonalise v against the basis and normalise it in M. The basis is
        // M-orthonormal, so ‖v‖²_M before a pass is ‖v‖²_M after it plus Σ c_i²: a
        // second pass only when the first removed most of v (Σ c_i² above what is
        // left: the DGKS criterion, the norm fell below 1/√2 of itself), where the
        // first pass's round-off matters; one product with M per pass.
        let mut b = 0.0;
        for _ in 0..2 {
            let removed = basis.project_out(&mut v);
            mass(&v, &mut mv);
            b = dot(&v, &mv).max(0.0).sqrt();
            if removed <= b * b {
                break;
            }
        }
        let j = basis.len() - first;
        if j > 0 {
            beta.push(b);
        }
        let scale_ref = alpha.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let exhausted = j > 0 && b <= 1e-13 * scale_ref.max(f64::MIN_POSITIVE);
        if exhausted || j == max_steps || (j > 0 && j >= count + 2) {
            // The Ritz pairs of T_j and their residual bounds.
            let t = tridiagonal(&alpha, &beta[..j - 1]);
            let eig = SymmetricEigen::new(t);
            let mut order: Vec<usize> = (0..j).collect();
            let key = |i: usize| {
                let th = eig.eigenvalues[i];
                if nearest {
                    th.abs()
                } else {
                    th
                }
            };
            order.sort_by(|&a, &b| key(b).total_cmp(&key(a)));
            let bound = if exhausted { 0.0 } else { b };
            let converged = order
                .iter()
                .take(count)
                .take_while(|&&i| {
                    let th = eig.eigenvalues[i];
                    (bound * eig.eigenvectors[(j - 1, i)]).abs() <= tol * th.abs()
                })
                .count();
            if converged >= count.min(j) && (converged == count || exhausted || j == max_steps) {
                let take: Vec<usize> = order.into_iter().take(count.min(j)).collect();
                let vectors = take
                    .iter()
                    .map(|&i| {
                        let mut x = vec![0.0; n];
                        for k in 0..j {
                            axpy(eig.eigenvectors[(k, i)], basis.column(first + k), &mut x);
                        }
                        x
                    })
                    .collect();
                return Ok(Ritz {
                    theta: take.iter().map(|&i| eig.eigenvalues[i]).collect(),
                    vectors,
                    steps: j,
                });
            }
            if exhausted || j == max_steps {
                return Err(Shortfall::NotConverged {
                    converged,
                    steps: j,
                });
            }
        }
        for (x, m) in v.iter_mut().zip(&mut mv) {
            *x /= b;
            *m /= b;
        }
        // The next direction: S q_j, its α, and the three-term recurrence (the
        // reorthogonalisation above removes the rest).
        op(&mv, &mut w).map_err(Shortfall::Operator)?;
        let a = dot(&w, &mv);
        alpha.push(a);
        basis.push(&v, &mv);
        std::mem::swap(&mut v, &mut w);
        axpy(-a, basis.column(first + j), &mut v);
        if j > 0 {
            axpy(-beta[j - 1], basis.column(first + j - 1), &mut v);
        }
    }
}

/// `M`-orthonormal vectors `q_i` and their products `M q_i`, as the columns of two
/// column-major `n × k` arrays, so that a Gram–Schmidt pass is two matrix-vector
/// products (vectorised) instead of `2k` separate sweeps.
struct Basis {
    n: usize,
    q: Vec<f64>,
    mq: Vec<f64>,
}

impl Basis {
    /// Room for `columns` vectors of length `n` (more grow the arrays).
    fn new(n: usize, columns: usize) -> Self {
        Basis {
            n,
            q: Vec::with_capacity(n * columns),
            mq: Vec::with_capacity(n * columns),
        }
    }

    fn len(&self) -> usize {
        self.q.len() / self.n.max(1)
    }

    fn push(&mut self, q: &[f64], mq: &[f64]) {
        self.q.extend_from_slice(q);
        self.mq.extend_from_slice(mq);
    }

    fn column(&self, i: usize) -> &[f64] {
        &self.q[i * self.n..(i + 1) * self.n]
    }

    /// One classical Gram–Schmidt pass in the `M` inner product: `c = Qᵀ M v`,
    /// `v ← v − Q c`; returns `Σ c_i²`, the `M`-norm² it removed.
    fn project_out(&self, v: &mut [f64]) -> f64 {
        use faer::linalg::matmul::matmul;
        use faer::{Accum, MatMut, MatRef, Par};
        let (n, k) = (self.n, self.len());
        if k == 0 {
            return 0.0;
        }
        let q = MatRef::from_column_major_slice(&self.q, n, k);
        let mq = MatRef::from_column_major_slice(&self.mq, n, k);
        let mut c = vec![0.0; k];
        {
            let vr = MatRef::from_column_major_slice(v, n, 1);
            let cm = MatMut::from_column_major_slice_mut(&mut c, k, 1);
            matmul(cm, Accum::Replace, mq.transpose(), vr, 1.0, Par::Seq);
        }
        let cr = MatRef::from_column_major_slice(&c, k, 1);
        let vm = MatMut::from_column_major_slice_mut(v, n, 1);
        matmul(vm, Accum::Add, q, cr, -1.0, Par::Seq);
        dot(&c, &c)
    }
}

fn tridiagonal(alpha: &[f64], beta: &[f64]) -> DMatrix<f64> {
    let j = alpha.len();
    let mut t = DMatrix::zeros(j, j);
    for i in 0..j {
        t[(i, i)] = alpha[i];
        if i + 1 < j {
            t[(i, i + 1)] = beta[i];
            t[(i + 1, i)] = beta[i];
        }
    }
    t
}

/// `aᵀb` in four interleaved partial sums: independent additions the processor
/// overlaps (and vectorises), where one running sum waits on each addition.
pub(super) fn dot(a: &[f64], b: &[f64]) -> f64 {
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let tail: f64 = ca
        .remainder()
        .iter()
        .zip(cb.remainder())
        .map(|(x, y)| x * y)
        .sum();
    let mut s = [0.0; 4];
    for (x, y) in ca.zip(cb) {
        for k in 0..4 {
            s[k] += x[k] * y[k];
        }
    }
    (s[0] + s[1]) + (s[2] + s[3]) + tail
}

fn axpy(c: f64, x: &[f64], y: &mut [f64]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi += c * xi;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_diagonal_pencil_gives_its_smallest_eigenvalues() {
        // K = diag(1..=n), M = diag(2): λ_i = i/2; shift −1: θ = 1/(λ + 1).
        let n = 60;
        let k: Vec<f64> = (1..=n).map(|i| i as f64).collect();
        let sigma = -1.0;
        let op = |x: &[f64], y: &mut [f64]| {
            for i in 0..n {
                y[i] = x[i] / (k[i] - sigma * 2.0);
            }
            Ok(())
        };
        let mass = |x: &[f64], y: &mut [f64]| {
            for i in 0..n {
                y[i] = 2.0 * x[i];
            }
        };
        let wanted = Wanted {
            count: 5,
            max_steps: 60,
            tol: 1e-12,
            nearest: false,
        };
        let r = lanczos(n, &wanted, &[], op, mass).unwrap_or_else(|_| panic!("converges"));
        for (i, th) in r.theta.iter().enumerate() {
            let lambda = sigma + 1.0 / th;
            assert!(
                (lambda - (i + 1) as f64 / 2.0).abs() < 1e-10,
                "{i}: {lambda}"
            );
        }
        // M-orthonormal.
        let mut mx = vec![0.0; n];
        for a in &r.vectors {
            mass(a, &mut mx);
            for b in &r.vectors {
                let d = dot(b, &mx);
                let same = std::ptr::eq(a, b);
                assert!((d - if same { 1.0 } else { 0.0 }).abs() < 1e-10, "{d}");
            }
        }
    }

    #[test]
    fn too_few_steps_say_how_many_pairs_converged_and_return_none() {
        // diag(1..=200), five pairs wanted in at most eight steps: a shortfall that
        // counts the converged, never the unconverged pairs as found.
        let n = 200;
        let op = |x: &[f64], y: &mut [f64]| {
            for i in 0..n {
                y[i] = x[i] / (i as f64 + 2.0);
            }
            Ok(())
        };
        let wanted = Wanted {
            count: 5,
            max_steps: 8,
            tol: 1e-12,
            nearest: false,
        };
        match lanczos(n, &wanted, &[], op, |x, y| y.copy_from_slice(x)) {
            Err(Shortfall::NotConverged { converged, steps }) => {
                assert!(converged < 5 && steps == 8, "{converged} in {steps}");
            }
            Err(Shortfall::Operator(e)) => panic!("{e}"),
            Ok(r) => panic!("{} pairs reported from 8 steps", r.theta.len()),
        }
    }
}
