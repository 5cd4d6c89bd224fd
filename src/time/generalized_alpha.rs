//! Chung and Hulbert's generalized-α (`analysis.scheme = "generalized_alpha"`): its
//! parameters from `ρ∞` and the step's coefficients. The vectors of the step's start
//! and the initial acceleration are `time::step_start`'s; the step itself is the
//! implicit one (`time::implicit`, `time::residual`); theory: `theory/trapezoidal.md`.

/// Generalized-α's parameters from `ρ∞` (Chung and Hulbert 1993):
/// `α_m = (2ρ∞ − 1)/(ρ∞ + 1)`, `α_f = ρ∞/(ρ∞ + 1)`, `γ = ½ − α_m + α_f`,
/// `β = ¼ (1 − α_m + α_f)²`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Alpha {
    pub alpha_m: f64,
    pub alpha_f: f64,
    pub beta: f64,
    pub gamma: f64,
}

impl Alpha {
    /// The parameters of spectral radius `rho_inf` at infinity.
    pub fn of(rho_inf: f64) -> Alpha {
        let alpha_m = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0);
        let alpha_f = rho_inf / (rho_inf + 1.0);
        let gamma = 0.5 - alpha_m + alpha_f;
        let beta = 0.25 * (1.0 - alpha_m + alpha_f).powi(2);
        Alpha {
            alpha_m,
            alpha_f,
            beta,
            gamma,
        }
    }

    /// The step's coefficients at step `h`.
    pub fn at(&self, h: f64) -> AlphaStep {
        let Alpha {
            alpha_m: am,
            alpha_f: af,
            beta: b,
            gamma: g,
        } = *self;
        AlphaStep {
            c_in: (1.0 - am) / (b * h * h),
            c_v: g / (b * h),
            w: 1.0 - af,
            p_v: (1.0 - am) / (b * h),
            p_a: (1.0 - am) * (0.5 - b) / b - am,
            q_v: 1.0 - g / b,
            q_a: h * (1.0 - g / (2.0 * b)),
            h,
            gamma: g,
        }
    }
}

/// Generalized-α's step in terms of `Δu`: `a_{n+1−α_m} = c_in Δu − (p_v v_n + p_a a_n)`,
/// `v_{n+1} = c_v Δu + q_v v_n + q_a a_n`, the forces' end weight `w = 1 − α_f`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct AlphaStep {
    pub c_in: f64,
    pub c_v: f64,
    pub w: f64,
    pub p_v: f64,
    pub p_a: f64,
    pub q_v: f64,
    pub q_a: f64,
    pub h: f64,
    pub gamma: f64,
}
