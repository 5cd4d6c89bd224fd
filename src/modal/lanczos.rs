//! Shift-invert Lanczos in the mass inner product, with full reorthogonalisation.
//!
//! For `K x = λ M x` and a shift `σ` below the wanted eigenvalues, the operator
//! `S = (K − σM)⁻¹ M` is self-adjoint in the `M` inner product with eigenvalues
//! `θ = 1/(λ − σ)`: the lowest `λ` above `σ` are its largest `θ`, well separated, and
//! Lanczos finds them in a few dozen products, each one solve with the factor of
//! `K − σM`. Every new vector is orthogonalised against all earlier ones twice
//! (classical Gram–Schmidt in the `M` inner product, repeated), so the basis stays
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

/// The `count` largest eigenpairs of an `M`-self-adjoint operator `S` on vectors of
/// length `n` `M`-orthogonal to the `locked` ones (`M`-orthonormal eigenvectors found
/// before). `op` is handed `z = M q` and writes `S q` (for shift and invert,
/// `S q = (K − σM)⁻¹ z`: one solve); `mass` applies `M`; at most `max_steps` steps,
/// converged to `tol`. The start vector is fixed (deterministic), so a run repeats.
/// An invariant subspace found early (the whole space, when `n` is small) ends the
/// iteration with exact pairs.
///
/// One start vector meets each distinct eigenvalue once in exact arithmetic: of a
/// multiple one (a free body's rigid modes, a square section's two bending modes) it
/// may find fewer copies than there are. [`super::modes`] therefore runs it again
/// with what it found locked until nothing new enters.
pub fn lanczos(
    n: usize,
    count: usize,
    max_steps: usize,
    tol: f64,
    locked: &[Vec<f64>],
    mut op: impl FnMut(&[f64], &mut [f64]) -> crate::error::Result<()>,
    mass: impl Fn(&[f64], &mut [f64]),
) -> Result<Ritz, Shortfall> {
    let max_steps = max_steps.min(n.saturating_sub(locked.len()));
    let m_locked: Vec<Vec<f64>> = locked
        .iter()
        .map(|x| {
            let mut y = vec![0.0; n];
            mass(x, &mut y);
            y
        })
        .collect();
    let mut q: Vec<Vec<f64>> = Vec::new();
    let mut mq: Vec<Vec<f64>> = Vec::new();
    let (mut alpha, mut beta) = (Vec::<f64>::new(), Vec::<f64>::new());
    // A fixed start with every component present (a low-discrepancy sequence).
    let mut v: Vec<f64> = (0..n)
        .map(|i| 0.5 + ((i as f64 + 1.0) * 0.618_033_988_749_895).fract())
        .collect();
    let mut mv = vec![0.0; n];
    let mut w = vec![0.0; n];
    loop {
        // Orthogonalise v against the basis (twice) and normalise it in M.
        for _ in 0..2 {
            mass(&v, &mut mv);
            for (qi, mqi) in locked.iter().zip(&m_locked).chain(q.iter().zip(&mq)) {
                let c = dot(mqi, &v);
                axpy(-c, qi, &mut v);
            }
        }
        mass(&v, &mut mv);
        let b = dot(&v, &mv).max(0.0).sqrt();
        let j = q.len();
        if j > 0 {
            beta.push(b);
        }
        let scale_ref = alpha.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let exhausted = j > 0 && b <= 1e-13 * scale_ref.max(f64::MIN_POSITIVE);
        if exhausted || j == max_steps || (j > 0 && j % 5 == 0 && j >= count) {
            // The Ritz pairs of T_j and their residual bounds.
            let t = tridiagonal(&alpha, &beta[..j - 1]);
            let eig = SymmetricEigen::new(t);
            let mut order: Vec<usize> = (0..j).collect();
            order.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
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
                        for (k, qk) in q.iter().enumerate() {
                            axpy(eig.eigenvectors[(k, i)], qk, &mut x);
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
        q.push(std::mem::take(&mut v));
        mq.push(mv.clone());
        v = w.clone();
        axpy(-a, &q[j], &mut v);
        if j > 0 {
            axpy(-beta[j - 1], &q[j - 1], &mut v);
        }
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

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
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
        let r = lanczos(n, 5, 60, 1e-12, &[], op, mass).unwrap_or_else(|_| panic!("converges"));
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
}
