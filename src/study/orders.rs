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
}
