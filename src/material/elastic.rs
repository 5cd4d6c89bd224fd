//! Linear elasticity `σ = C ε`.
//!
//! Stored energy `ψ = ½ ε:C:ε`; no physical dissipation. Backward Euler still loses
//! `½ Δε:C:Δε` per step (the `numerical` line): from
//! `σ_{n+1}:Δε = ψ_{n+1} − ψ_n + ½ Δε:C:Δε` (see `theory/energy.md`).

use super::{dot3, mul3, Dissipation, PointResponse, PointStatus, StrainStep};

/// Elastic update at one point.
pub fn update(c: &[[f64; 3]; 3], step: &StrainStep) -> PointResponse {
    let sigma = mul3(c, &step.eps);
    let de = [
        step.eps[0] - step.eps_n[0],
        step.eps[1] - step.eps_n[1],
        step.eps[2] - step.eps_n[2],
    ];
    PointResponse {
        sigma,
        tangent: *c,
        psi: 0.5 * dot3(&step.eps, &sigma),
        dissipation: Dissipation {
            numerical: 0.5 * dot3(&de, &mul3(c, &de)),
            ..Default::default()
        },
        status: PointStatus::Ok,
    }
}
