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

/// Generalized-α with spectral radius `rho_inf` (Chung and Hulbert's parameters,
/// `time::generalized_alpha`) on `ẍ + ω²x = 0`: the step maps `(x, h ẋ, h² ẍ)` by a
/// 3 × 3 amplification matrix, built here column by column from one step of each unit
/// state; `z` is its principal root, the eigenvalue of largest modulus (a complex
/// pair while `ωh` is finite, tending to `−ρ∞` as `ωh → ∞`), read as for the other
/// schemes.
pub fn generalized_alpha(omega: f64, h: f64, rho_inf: f64) -> StepEffect {
    let wh = omega * h;
    if wh == 0.0 {
        return StepEffect {
            damping: 0.0,
            period: 1.0,
        };
    }
    let p = crate::time::generalized_alpha::Alpha::of(rho_inf);
    let w2 = wh * wh;
    // One step of (x, v, a) scaled by h: (1−α_m) a₁ + α_m a₀ + ω²h²((1−α_f) x₁ +
    // α_f x₀) = 0 with Newmark's x₁ = x₀ + v₀ + (½−β) a₀ + β a₁, v₁ = v₀ + (1−γ) a₀ + γ a₁.
    let step = |x0: f64, v0: f64, a0: f64| {
        let x_pred = x0 + v0 + (0.5 - p.beta) * a0;
        let a1 = -(p.alpha_m * a0 + w2 * ((1.0 - p.alpha_f) * x_pred + p.alpha_f * x0))
            / ((1.0 - p.alpha_m) + w2 * (1.0 - p.alpha_f) * p.beta);
        let x1 = x_pred + p.beta * a1;
        let v1 = v0 + (1.0 - p.gamma) * a0 + p.gamma * a1;
        [x1, v1, a1]
    };
    let columns = [
        step(1.0, 0.0, 0.0),
        step(0.0, 1.0, 0.0),
        step(0.0, 0.0, 1.0),
    ];
    let a = nalgebra::Matrix3::from_fn(|i, j| columns[j][i]);
    let z = a
        .complex_eigenvalues()
        .iter()
        .copied()
        .max_by(|p, q| p.norm().total_cmp(&q.norm()).then(p.im.total_cmp(&q.im)))
        .expect("three eigenvalues");
    let ln = z.norm().ln();
    let arg = z.im.atan2(z.re).abs();
    StepEffect {
        damping: -ln / ln.hypot(arg),
        period: wh / arg,
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

    #[test]
    fn generalized_alpha_is_the_trapezoidal_rule_at_one_and_damps_to_rho_inf() {
        // ρ∞ = 1: α_m = α_f = ½, γ = ½, β = ¼, the trapezoidal rule's |z| = 1 and
        // period, at any ωh.
        for wh in [0.01, 0.3, 2.0, 50.0] {
            let (g, t) = (generalized_alpha(wh, 1.0, 1.0), trapezoidal(wh, 1.0));
            assert!(g.damping.abs() < 1e-12, "{wh}: {g:?}");
            assert!(
                (g.period / t.period - 1.0).abs() < 1e-10,
                "{wh}: {g:?} {t:?}"
            );
        }
        // Second order: ξ̄ = O((ωh)³), T̄/T − 1 = O((ωh)²).
        let (a, b) = (
            generalized_alpha(1.0, 0.01, 0.8),
            generalized_alpha(1.0, 0.005, 0.8),
        );
        let order = (a.damping / b.damping).log2();
        assert!((order - 3.0).abs() < 0.05, "damping order {order}");
        // ωh → ∞: |z| → ρ∞, z → −ρ∞, so ξ̄ = −ln ρ∞ / √(ln²ρ∞ + π²).
        let inf = generalized_alpha(1.0, 1e6, 0.5);
        let l = 0.5f64.ln();
        let expect = -l / l.hypot(std::f64::consts::PI);
        assert!(
            (inf.damping - expect).abs() < 1e-4,
            "{inf:?} against {expect}"
        );
    }
}
