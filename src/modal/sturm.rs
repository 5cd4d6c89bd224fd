//! The search for eigenpairs behind [`super::modes`]: shift-invert Lanczos, then the
//! Sturm check that nothing in the range was missed, and Lanczos again with what
//! was found locked for what was (`theory/modal.md`).
//!
//! One start vector meets each distinct eigenvalue once in exact arithmetic, so of
//! a multiple one (a free body's rigid modes, a square section's two bending modes,
//! two identical parts) Lanczos may return fewer copies than there are, and nothing
//! in its own output shows it. The inertia of `K − μM` (the negative pivots of its
//! `LDLᵀ`, Sylvester's law) is the number of eigenvalues below `μ`: counted at both
//! ends of the range found, it says how many were missed.

use super::lanczos::{self, Shortfall};
use super::Sturm;
use crate::error::{Error, Result};

/// What to look for.
pub(super) struct Search {
    /// Pairs wanted.
    pub count: usize,
    /// The shift of the operator `(K − σM)⁻¹M`.
    pub sigma: f64,
    /// The `count` nearest `σ` (a shift inside the spectrum) instead of the lowest.
    pub nearest: bool,
    /// Eigenvalues below `σ` (the inertia of the factor at `σ`; 0 below the
    /// spectrum).
    pub below_sigma: usize,
    /// `tr K / tr M`: the scale of the eigenvalues, for margins at zero.
    pub scale: f64,
}

/// What was found.
pub(super) struct Found {
    /// `(λ, x)`, `λ` ascending, `x` `M`-orthonormal.
    pub pairs: Vec<(f64, Vec<f64>)>,
    /// Lanczos steps (operator applications) of all runs.
    pub steps: usize,
    /// The check passed.
    pub sturm: Sturm,
    /// The place in the spectrum of the first pair, from 1.
    pub first_number: usize,
}

/// The `count` lowest (or nearest `σ`) eigenpairs of the pencil whose shift-invert
/// operator is `op` (handed `M q`, writing `(K − σM)⁻¹ M q`) and mass `mass`, on
/// vectors of length `n`; `inertia(μ)` factorises `K − μM` and returns the `μ` it
/// used (moved off an eigenvalue if it had to) and the number of eigenvalues below.
pub(super) fn search(
    s: &Search,
    n: usize,
    mut op: impl FnMut(&[f64], &mut [f64]) -> Result<()>,
    mass: impl Fn(&[f64], &mut [f64]),
    mut inertia: impl FnMut(f64) -> Result<(f64, usize)>,
) -> Result<Found> {
    let max_steps = (20 * s.count + 60).min(n);
    let shortfall = |e: Shortfall| match e {
        Shortfall::Operator(e) => e,
        Shortfall::NotConverged { converged, steps } => Error::Modal(format!(
            "modal analysis: {converged} of {} modes converged in {steps} Lanczos steps; \
             ask for fewer, or give a shift nearer the wanted ones (--shift, --around)",
            s.count
        )),
    };
    let mut run = |count: usize, locked: &[Vec<f64>]| {
        let wanted = lanczos::Wanted {
            count,
            max_steps,
            tol: 1e-10,
            nearest: s.nearest,
        };
        lanczos::lanczos(n, &wanted, locked, &mut op, &mass).map_err(shortfall)
    };
    let first = run(s.count, &[])?;
    let mut steps = first.steps;
    let lambda = |th: f64| s.sigma + 1.0 / th;
    let mut pairs: Vec<(f64, Vec<f64>)> = first
        .theta
        .into_iter()
        .map(lambda)
        .zip(first.vectors)
        .collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    // The range found, widened by far more than the pairs' error and far less than
    // a distinct neighbour's distance.
    let margin = |l: f64| 1e-6 * l.abs() + 1e-9 * s.scale;
    let top = pairs.last().map_or(0.0, |p| p.0);
    let (above, below_above) = inertia(top + margin(top))?;
    let (below, below_below) = if s.nearest {
        inertia(pairs[0].0 - margin(pairs[0].0))?
    } else {
        (f64::NEG_INFINITY, 0)
    };
    let counted = below_above.saturating_sub(below_below);
    if counted < pairs.len() {
        return Err(Error::Modal(format!(
            "modal analysis: the inertia counts {counted} eigenvalues in [{below:e}, \
             {above:e}) rad²/s², Lanczos returned {}; the shift is too near an eigenvalue \
             for its factor (give another)",
            pairs.len()
        )));
    }
    let inside = |l: f64| l >= below && l < above;
    let mut missing = counted - pairs.len();
    while missing > 0 {
        let locked: Vec<Vec<f64>> = pairs.iter().map(|p| p.1.clone()).collect();
        let more = run(missing, &locked)?;
        steps += more.steps;
        let before = missing;
        for (th, x) in more.theta.into_iter().zip(more.vectors) {
            if inside(lambda(th)) && missing > 0 {
                pairs.push((lambda(th), x));
                missing -= 1;
            }
        }
        if missing == before {
            return Err(Error::Modal(format!(
                "modal analysis: the inertia counts {counted} eigenvalues in [{below:e}, \
                 {above:e}) rad²/s², Lanczos found {} of them",
                counted - missing
            )));
        }
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let all = pairs.clone();
    if s.nearest {
        // The `count` nearest σ: an interval of the spectrum around it.
        while pairs.len() > s.count {
            let (lo, hi) = (pairs[0].0, pairs[pairs.len() - 1].0);
            if (lo - s.sigma).abs() > (hi - s.sigma).abs() {
                pairs.remove(0);
            } else {
                pairs.pop();
            }
        }
    } else {
        pairs.truncate(s.count);
    }
    // A count that cuts between the copies of a repeated eigenvalue keeps them all:
    // which copy would be dropped is round-off, and a repeated mode is one mode
    // shape space (a square section's two bending modes), not one of its vectors.
    if let (Some(lo), Some(hi)) = (pairs.first().map(|p| p.0), pairs.last().map(|p| p.0)) {
        pairs = all
            .into_iter()
            .filter(|p| p.0 >= lo - margin(lo) && p.0 <= hi + margin(hi))
            .collect();
    }
    let first_number = if s.nearest {
        s.below_sigma + 1 - pairs.iter().filter(|p| p.0 < s.sigma).count()
    } else {
        1
    };
    Ok(Found {
        pairs,
        steps,
        sturm: Sturm {
            below,
            above,
            count: counted,
        },
        first_number,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The diagonal pencil `K = diag(k)`, `M = I`: its shift-invert operator, mass
    /// and inertia.
    fn diagonal(k: &[f64], s: &Search) -> Result<Found> {
        let sigma = s.sigma;
        search(
            s,
            k.len(),
            |x, y| {
                for i in 0..k.len() {
                    y[i] = x[i] / (k[i] - sigma);
                }
                Ok(())
            },
            |x, y| y.copy_from_slice(x),
            |mu| Ok((mu, k.iter().filter(|&&l| l < mu).count())),
        )
    }

    #[test]
    fn the_copies_of_a_multiple_eigenvalue_lanczos_cannot_see_are_found() {
        // diag(1, 1, 1, 2, 3, ...): the start vector's three components along the
        // triple eigenvalue stay in one direction in every Krylov vector, so one
        // Lanczos run returns λ = 1 once; the inertia below 1 + margin is 3 and
        // the runs with what was found locked return the other two copies.
        let k: Vec<f64> = [1.0, 1.0, 1.0]
            .into_iter()
            .chain((2..80).map(f64::from))
            .collect();
        let s = Search {
            count: 4,
            sigma: -0.5,
            nearest: false,
            below_sigma: 0,
            scale: 1.0,
        };
        let found = diagonal(&k, &s).unwrap();
        let lambdas: Vec<f64> = found.pairs.iter().map(|p| p.0).collect();
        for (got, want) in lambdas.iter().zip([1.0, 1.0, 1.0, 2.0]) {
            assert!((got - want).abs() < 1e-10, "{lambdas:?}");
        }
        assert!(found.sturm.count >= 4, "{:?}", found.sturm);
        // The nearest 3 to 2.6 in diag(1, 1, 1, 2, 3, 4, ...) are 2, 3, 4: numbered
        // 4, 5, 6 from the inertia at σ (4 below).
        let s = Search {
            count: 3,
            sigma: 2.6,
            nearest: true,
            below_sigma: 4,
            scale: 1.0,
        };
        let found = diagonal(&k, &s).unwrap();
        let lambdas: Vec<f64> = found.pairs.iter().map(|p| p.0).collect();
        for (got, want) in lambdas.iter().zip([2.0, 3.0, 4.0]) {
            assert!((got - want).abs() < 1e-10, "{lambdas:?}");
        }
        assert_eq!(found.first_number, 4);
    }
}
