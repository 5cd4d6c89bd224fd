//! `analysis.adaptive`, the table of error-controlled steps as a scenario gives it
//! (checked by `validate::adaptive`; `theory/adaptive.md`).

use serde::Deserialize;

/// `analysis.adaptive`: error-controlled steps.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AdaptiveSpec {
    /// The largest relative error measure a step may have. Default 1e-4.
    #[serde(default = "default_adaptive_tolerance")]
    pub tolerance: f64,
    /// The smallest step wanted (s): the bottom rung is the largest `dt_max / 2^k`
    /// not below it. Default `dt_max / 2¹⁰`.
    #[serde(default)]
    pub dt_min: Option<f64>,
    /// The largest step (s), the ladder's top. Default `analysis.dt`.
    #[serde(default)]
    pub dt_max: Option<f64>,
    /// How a step's error is measured: `energy` (the only one, the default).
    #[serde(default)]
    pub norm: crate::model::ErrorNorm,
    /// Steps held at the bottom rung after an impact before the step may grow.
    /// Default 10.
    #[serde(default = "default_impact_steps")]
    pub impact_steps: usize,
}

fn default_adaptive_tolerance() -> f64 {
    1e-4
}

fn default_impact_steps() -> usize {
    10
}
