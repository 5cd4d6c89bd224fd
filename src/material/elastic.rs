//! Linear elasticity `σ = C ε`.
//!
//! Stored energy `ψ = ½ ε:C:ε`; no physical dissipation. Backward Euler still loses
//! `½ Δε:C:Δε` per step (the `numerical` line): from
//! `σ_{n+1}:Δε = ψ_{n+1} − ψ_n + ½ Δε:C:Δε` (see `theory/energy.md`).

use super::point::{
    dot3, mul3, Constitutive, Dissipation, Moduli, PointResponse, PointStatus, StrainStep,
    TangentKind, MAX_DRIVERS,
};
use crate::fe::StrainSpace;

/// Linear elasticity: no parameters beyond `E, ν`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Elastic;

impl Constitutive for Elastic {
    fn name(&self) -> &'static str {
        "elastic"
    }

    fn tangent_kind(&self) -> TangentKind {
        TangentKind::Elastic
    }

    fn is_rate_independent(&self) -> bool {
        true
    }

    fn update<const V: usize, K: StrainSpace<V>>(
        &self,
        _moduli: Moduli,
        c: &[[f64; V]; V],
        step: &StrainStep<V>,
        _averaged: Option<[f64; MAX_DRIVERS]>,
        _state_n: &[f64],
        _state: &mut [f64],
    ) -> PointResponse<V> {
        update(c, step)
    }
}

/// Elastic update at one point (`V` Voigt components).
pub fn update<const V: usize>(c: &[[f64; V]; V], step: &StrainStep<V>) -> PointResponse<V> {
    let sigma = mul3(c, &step.eps);
    let de: [f64; V] = std::array::from_fn(|i| step.eps[i] - step.eps_n[i]);
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
