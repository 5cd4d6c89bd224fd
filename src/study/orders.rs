//! Observed orders of convergence and Richardson's estimate of the true error.
//!
//! With errors `e_i` measured against the finest run at parameters `h_0 > h_1 >
//! ... > h_ref`, the observed order between two runs is `p = ln(e_i/e_{i+1}) /
//! ln(h_i/h_{i+1})`. The error against the reference understates the true error by
//! the reference's own error: if `e(h) ≈ C h^p`, then `‖u_h − u_ref‖ ≈ C (h^p −
//! h_ref^p)`, so the true error is about `‖u_h − u_ref‖ / (1 − (h_ref/h)^p)`.

/// The observed order between consecutive entries of `(h, e)` (one fewer than the
/// entries; `None` where an error is zero or not finite).
pub fn observed(h: &[f64], e: &[f64]) -> Vec<Option<f64>> {
    h.windows(2)
        .zip(e.windows(2))
        .map(|(h, e)| {
            let p = (e[0] / e[1]).ln() / (h[0] / h[1]).ln();
            (p.is_finite() && e[0] > 0.0 && e[1] > 0.0).then_some(p)
        })
        .collect()
}

/// Observed orders from successive differences: `d_j = ‖u_j − u_{j+1}‖` of a chain
/// of runs at `h_0 > h_1 > … > h_n` (`d` has `n` entries, `h` one more). Where
/// `u_h = u + C h^p`, `d_j = C (h_j^p − h_{j+1}^p)`, and the order of the pair `j`
/// is the `p` with `d_j/d_{j+1} = (h_j^p − h_{j+1}^p)/(h_{j+1}^p − h_{j+2}^p)`
/// (`log₂(d_j/d_{j+1})` when the steps halve), found by bisection on `[0.01, 8]`.
/// No run serves as the truth, so no reference biases the orders: errors measured
/// against a reference read `C (h^p − h_ref^p)`, and their plain ratio reads 1.22
/// for order one with the reference four times finer than the finest run. `None`
/// where a difference is zero or not finite, or no order in the bracket fits.
pub fn observed_from_differences(h: &[f64], d: &[f64]) -> Vec<Option<f64>> {
    (0..d.len().saturating_sub(1))
        .map(|j| {
            let (a, b) = (d[j], d[j + 1]);
            if !(a > 0.0 && b > 0.0 && a.is_finite() && b.is_finite()) {
                return None;
            }
            let (h0, h1, h2) = (h[j], h[j + 1], h[j + 2]);
            let target = (a / b).ln();
            let model = |p: f64| {
                let (x0, x1, x2) = (h0.powf(p), h1.powf(p), h2.powf(p));
                ((x0 - x1) / (x1 - x2)).ln()
            };
            let (mut lo, mut hi) = (0.01f64, 8.0f64);
            let (m_lo, m_hi) = (model(lo), model(hi));
            if !(m_lo.is_finite() && m_hi.is_finite() && m_lo <= target && target <= m_hi) {
                return None;
            }
            for _ in 0..100 {
                let mid = 0.5 * (lo + hi);
                if model(mid) < target {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            Some(0.5 * (lo + hi))
        })
        .collect()
}

/// Richardson's estimate of the true error of each entry, from its error against the
/// reference at `h_ref` and the order `p`.
pub fn richardson(h: &[f64], e: &[f64], h_ref: f64, p: f64) -> Vec<f64> {
    h.iter()
        .zip(e)
        .map(|(&h, &e)| e / (1.0 - (h_ref / h).powf(p)))
        .collect()
}

/// The order Richardson's estimate uses: the last observed one (of the two finest
/// runs), clamped to `[0.25, 4]`; the theory's order 1 when none is observed.
pub fn richardson_order(observed: &[Option<f64>]) -> f64 {
    observed
        .iter()
        .rev()
        .find_map(|p| *p)
        .map_or(1.0, |p| p.clamp(0.25, 4.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_order_errors_give_order_one_and_the_true_error() {
        // e = C (h - h_ref) for u_h = C h: the reference's own error removed.
        let (c, h_ref) = (3.0, 0.125);
        let h = [1.0, 0.5, 0.25];
        let e: Vec<f64> = h.iter().map(|h| c * (h - h_ref)).collect();
        let p = observed(&h, &e);
        assert!(p[0].unwrap() > 1.0 && p[1].unwrap() > 1.0);
        let r = richardson(&h, &e, h_ref, 1.0);
        for (hi, ri) in h.iter().zip(r) {
            assert!((ri - c * hi).abs() < 1e-12);
        }
        assert_eq!(richardson_order(&[None]), 1.0);
        assert_eq!(richardson_order(&[Some(9.0)]), 4.0);
        assert!(observed(&[1.0, 0.5], &[0.0, 1.0])[0].is_none());
    }

    #[test]
    fn successive_differences_read_the_power_laws_at_every_level() {
        // Steps halving and a last one four times finer (a study's reference): an
        // exact power law reads its order at every pair, where errors against the
        // last run read 1.22 for order one at the finest pair.
        let h = [8.0, 4.0, 2.0, 1.0, 0.25];
        for p in [1.0, 2.0, 0.5] {
            let u: Vec<f64> = h.iter().map(|x: &f64| 3.0 * x.powf(p)).collect();
            let d: Vec<f64> = u.windows(2).map(|w| (w[0] - w[1]).abs()).collect();
            let o = observed_from_differences(&h, &d);
            assert_eq!(o.len(), 3);
            for o in o {
                assert!((o.unwrap() - p).abs() < 1e-9, "{p}: {o:?}");
            }
        }
        let e: Vec<f64> = h[..4].iter().map(|x| x - 0.25).collect();
        let plain = observed(&h[..4], &e);
        assert!((plain[2].unwrap() - 1.222).abs() < 1e-3, "{plain:?}");
        assert!(observed_from_differences(&h, &[1.0, 0.0, 1.0, 1.0])[0].is_none());
    }
}
