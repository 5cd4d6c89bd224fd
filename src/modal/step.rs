//! What a step of a time scheme does to an undamped mode: its numerical damping
//! ratio and its period ratio (`theory/modal.md`).

/// What a step `h` of a scheme does to an undamped mode of frequency `ω`: its
/// numerical damping ratio and the ratio of the computed to the true period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepEffect {
    /// `ξ̄ = −ln|z| / √(ln²|z| + arg² z)` of the step's amplification `z`.
    pub damping: f64,
    /// `T̄ / T = ωh / arg z`.
    pub period: f64,
}

/// Backward Euler on `ẍ + ω²x = 0`: `z = 1/(1 − iωh)`, so `|z| = (1 + ω²h²)^(−½)` and
/// `arg z = arctan(ωh)` (`theory/scheme.md`, eq. 6 read mode by mode).
pub fn backward_euler(omega: f64, h: f64) -> StepEffect {
    let wh = omega * h;
    if wh == 0.0 {
        return StepEffect {
            damping: 0.0,
            period: 1.0,
        };
    }
    let ln = -0.5 * wh.mul_add(wh, 1.0).ln();
    let arg = wh.atan();
    StepEffect {
        damping: -ln / ln.hypot(arg),
        period: wh / arg,
    }
}

/// The trapezoidal rule: `|z| = 1`, `arg z = 2 arctan(ωh/2)`.
pub fn trapezoidal(omega: f64, h: f64) -> StepEffect {
    let wh = omega * h;
    StepEffect {
        damping: 0.0,
        period: if wh == 0.0 {
            1.0
        } else {
            wh / (2.0 * (0.5 * wh).atan())
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn backward_eulers_damping_and_period_have_their_limits() {
        // Small ωh: ξ ≈ ωh/2, T̄/T ≈ 1 + (ωh)²/3; large: ξ → 1... of a decaying mode.
        let e = backward_euler(1.0, 1e-3);
        assert!((e.damping - 5e-4).abs() < 1e-9, "{e:?}");
        assert!((e.period - (1.0 + 1e-6 / 3.0)).abs() < 1e-12, "{e:?}");
        let t = trapezoidal(1.0, 1e-3);
        assert!((t.period - (1.0 + 1e-6 / 12.0)).abs() < 1e-12, "{t:?}");
        let big = backward_euler(1.0, 1e3);
        assert!(big.damping > 0.9 && big.period > 600.0, "{big:?}");
    }
}
