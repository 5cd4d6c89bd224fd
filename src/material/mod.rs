//! Constitutive models with history at the Gauss points.
//!
//! A material update is a pure function of the last committed Gauss-point state and
//! the strain at the new step: it returns the stress, the consistent tangent, the
//! stored energy density and the step's dissipation by mechanism
//! ([`PointResponse`]), and writes the trial state. The caller commits trial states
//! only when a step is accepted ([`store::StateStore`]), so iterations and step
//! cuts leave no trace. Every model shares the isotropic elasticity `C(E, ν)` of
//! the idealisation chosen for the run: each update is generic over its
//! [`StrainSpace`] `K` (plane stress, plane strain or solid, `V` Voigt components).
//!
//! Floors: [`point`] is the vocabulary (the point's types and the [`Constitutive`]
//! interface); each model implements it in its own file ([`elastic`],
//! [`viscoelastic`], [`mazars`], [`rankine_hill`]); this file only dispatches over
//! them ([`Law`], [`Material`]). A new model is one file and one variant of [`Law`]
//! (ARCHITECTURE.md, "Where a material enters"); a model kept outside the crate is
//! its `Constitutive` implementation handed to [`Law::custom`] ([`custom`]).

pub mod custom;
pub mod elastic;
pub mod hardening;
pub mod identify;
pub mod linalg;
pub mod mazars;
pub mod point;
pub mod rankine_hill;
pub mod store;
pub mod viscoelastic;

pub use custom::CustomLaw;
pub use elastic::Elastic;
pub use hardening::Hardening;
pub use mazars::{MazarsParams, MazarsVariant, Regularisation};
pub use point::{
    dot3, mul3, sig, Constitutive, Dissipation, Moduli, PointFailure, PointResponse, PointStatus,
    StrainStep, TangentKind, MAX_DRIVERS, MAX_STATE,
};
pub use rankine_hill::RankineHillParams;
pub use viscoelastic::{Sls, Viscosity};

use crate::fe::StrainSpace;

/// The constitutive law of a material, with its parameters beyond `E, ν, ρ`: one
/// variant per model, each implementing [`Constitutive`] in its own file.
#[derive(Clone, Debug, PartialEq)]
pub enum Law {
    /// Linear elasticity `σ = C ε`.
    Elastic,
    /// Kelvin-Voigt `σ = C ε + η ε̇` (also the Kelvin limit of the SLS).
    KelvinVoigt(Viscosity),
    /// Standard linear solid (eq. 10), or the Maxwell model without its parallel
    /// spring.
    Sls(Sls),
    /// Mazars damage `σ = (1 − D) C ε`.
    Mazars(MazarsParams),
    /// Rankine-Hill plasticity (plane stress, plane strain through the solid's
    /// return, or a solid's principal stress space).
    RankineHill(RankineHillParams),
    /// A law defined outside the crate ([`Law::custom`]).
    Custom(CustomLaw),
}

impl Law {
    /// A law defined outside the crate, from its [`Constitutive`] implementation:
    /// the registration of a model the crate does not know (see [`custom`]).
    pub fn custom(law: impl Constitutive + Send + Sync + 'static) -> Law {
        Law::Custom(CustomLaw(std::sync::Arc::new(law)))
    }
}

/// Runs `$body` with `$l` bound to the model of `$law` as its [`Constitutive`]
/// implementation: the one dispatch over the models.
macro_rules! with_law {
    ($law:expr, $l:ident => $body:expr) => {
        match $law {
            Law::Elastic => {
                let $l = &Elastic;
                $body
            }
            Law::KelvinVoigt($l) => $body,
            Law::Sls($l) => $body,
            Law::Mazars($l) => $body,
            Law::RankineHill($l) => $body,
            Law::Custom($l) => $body,
        }
    };
}

/// A material: elastic constants, density and constitutive law.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Name as given in the scenario.
    pub name: String,
    /// Young's modulus.
    pub e: f64,
    /// Poisson's ratio.
    pub nu: f64,
    /// Mass density.
    pub rho: f64,
    /// The constitutive law.
    pub law: Law,
    /// Where the model's parameters came from when they were identified from the
    /// concrete's data (`identify` in a scenario): the source and the data, e.g.
    /// `C30/37 (EN 1992-1-1 Table 3.1, ...): E = ..., f_ct = ...`.
    pub identified_from: Option<String>,
}

impl Material {
    /// A linear elastic material.
    pub fn elastic(name: &str, e: f64, nu: f64, rho: f64) -> Self {
        Material {
            name: name.into(),
            e,
            nu,
            rho,
            law: Law::Elastic,
            identified_from: None,
        }
    }

    /// `E` and `ν`, as the updates take them.
    pub fn moduli(&self) -> Moduli {
        Moduli {
            e: self.e,
            nu: self.nu,
        }
    }

    /// The model's name as a scenario writes it (`model = "..."`).
    pub fn model_name(&self) -> &'static str {
        with_law!(&self.law, l => l.name())
    }

    /// The interaction radius of a nonlocal material (`None`: local).
    pub fn nonlocal_radius(&self) -> Option<f64> {
        with_law!(&self.law, l => l.nonlocal_radius())
    }

    /// The regularisation of a softening material (see
    /// [`Constitutive::regularisation`]).
    pub fn regularisation(&self) -> Option<&'static str> {
        with_law!(&self.law, l => l.regularisation())
    }

    /// The model's parameters beyond `E, ν, ρ`, by name, for `check` and `material`.
    pub fn parameters(&self) -> Vec<(&'static str, String)> {
        with_law!(&self.law, l => l.parameters())
    }

    /// Elasticity matrix `C` of the idealisation `K`.
    pub fn elasticity<const V: usize, K: StrainSpace<V>>(&self) -> [[f64; V]; V] {
        K::elasticity(self.e, self.nu)
    }

    /// The stiffness the material shows to a sudden strain (what an explicit step
    /// sees): `C` times [`Constitutive::instantaneous_factor`].
    pub fn instantaneous_stiffness<const V: usize, K: StrainSpace<V>>(&self) -> [[f64; V]; V] {
        let c = self.elasticity::<V, K>();
        let f = with_law!(&self.law, l => l.instantaneous_factor());
        if f == 1.0 {
            c
        } else {
            c.map(|row| row.map(|x| f * x))
        }
    }

    /// The viscosity `η` of a Kelvin-Voigt material (`σ_v = η ε̇`, Voigt form on
    /// engineering strain), `None` for the others.
    pub fn viscosity<const V: usize, K: StrainSpace<V>>(&self) -> Option<[[f64; V]; V]> {
        let c = self.elasticity::<V, K>();
        with_law!(&self.law, l => l.viscosity::<V, K>(&c))
    }

    /// True when the stress is `C ε` with no history: the stiffness is constant and
    /// the global force is `K u`, so no Gauss-point loop is needed per step.
    pub fn is_linear_elastic(&self) -> bool {
        self.tangent_kind() == TangentKind::Elastic
    }

    /// True when the consistent tangent does not depend on the strain or history
    /// (for a fixed step): the effective matrix is then factorised once.
    pub fn has_constant_tangent(&self) -> bool {
        self.tangent_kind() != TangentKind::StateDependent
    }

    /// How the tangent behaves.
    pub fn tangent_kind(&self) -> TangentKind {
        with_law!(&self.law, l => l.tangent_kind())
    }

    /// True when the stress depends on the strain path but not on its rate
    /// (elasticity, damage, plasticity): at an unchanged strain the committed
    /// stress is the stress of any step, so an implicit step starting at an
    /// unchanged displacement knows its internal force without a pass.
    pub fn is_rate_independent(&self) -> bool {
        with_law!(&self.law, l => l.is_rate_independent())
    }

    /// Number of history values per point with `voigt` strain components (at most
    /// [`MAX_STATE`]).
    pub fn n_state(&self, voigt: usize) -> usize {
        with_law!(&self.law, l => l.n_state(voigt))
    }

    /// Names of the history values of a point with `voigt` strain components
    /// (columns of `rothe material` output).
    pub fn state_names(&self, voigt: usize) -> &'static [&'static str] {
        with_law!(&self.law, l => l.state_names(voigt))
    }

    /// Damage and equivalent plastic strain `κ_t + κ_c` of the state of a point with
    /// `voigt` strain components, for output.
    pub fn output_fields(&self, state: &[f64], voigt: usize) -> (f64, f64) {
        with_law!(&self.law, l => l.output_fields(state, voigt))
    }

    /// Initial history values.
    pub fn init_state(&self, state: &mut [f64]) {
        state.fill(0.0);
    }

    /// Whether [`Material::update_frozen`] differs from the update (a state the
    /// first iterate of a step with prescribed increments must not evolve).
    pub fn has_frozen_form(&self) -> bool {
        with_law!(&self.law, l => l.has_frozen_form())
    }

    /// Nonlocal drivers per point ([`Constitutive::n_drivers`]).
    pub fn n_drivers(&self) -> usize {
        with_law!(&self.law, l => l.n_drivers())
    }

    /// The point's own nonlocal drivers at strain `eps` ([`Constitutive::drivers`]).
    pub fn drivers<const V: usize, K: StrainSpace<V>>(&self, eps: &[f64; V]) -> [f64; MAX_DRIVERS] {
        with_law!(&self.law, l => l.drivers::<V, K>(self.moduli(), eps))
    }

    /// Whether averaged drivers up to `bound` could move the history `history`
    /// ([`Constitutive::drivers_can_grow`]).
    pub fn drivers_can_grow(&self, bound: [f64; MAX_DRIVERS], history: &[f64]) -> bool {
        with_law!(&self.law, l => l.drivers_can_grow(bound, history))
    }

    /// Stress of a step of size `dt` that leaves the strain at `eps`, from the history
    /// `state` ([`Constitutive::predicted_stress`]).
    pub fn predicted_stress<const V: usize, K: StrainSpace<V>>(
        &self,
        eps: &[f64; V],
        state: &[f64],
        dt: f64,
    ) -> [f64; V] {
        self.predicted_stress_with::<V, K>(&self.elasticity::<V, K>(), eps, state, dt)
    }

    /// [`Material::predicted_stress`] with the elasticity matrix
    /// `c = self.elasticity::<V, K>()` computed by the caller (once per element block
    /// in the Gauss-point loop).
    pub fn predicted_stress_with<const V: usize, K: StrainSpace<V>>(
        &self,
        c: &[[f64; V]; V],
        eps: &[f64; V],
        state: &[f64],
        dt: f64,
    ) -> [f64; V] {
        with_law!(&self.law, l => l.predicted_stress::<V, K>(self.moduli(), c, eps, state, dt))
    }

    /// The material update ([`Constitutive::update`]) in the idealisation `K`.
    pub fn update<const V: usize, K: StrainSpace<V>>(
        &self,
        step: &StrainStep<V>,
        state_n: &[f64],
        state: &mut [f64],
    ) -> PointResponse<V> {
        self.update_with::<V, K>(&self.elasticity::<V, K>(), step, state_n, state)
    }

    /// [`Material::update`] with the elasticity matrix `c = self.elasticity::<V, K>()`
    /// computed by the caller (once per element block in the Gauss-point loop).
    pub fn update_with<const V: usize, K: StrainSpace<V>>(
        &self,
        c: &[[f64; V]; V],
        step: &StrainStep<V>,
        state_n: &[f64],
        state: &mut [f64],
    ) -> PointResponse<V> {
        self.update_driven::<V, K>(c, step, None, state_n, state)
    }

    /// [`Material::update_with`] with every history frozen at its committed value
    /// where the model has such a form ([`Constitutive::update_frozen`]).
    pub fn update_frozen<const V: usize, K: StrainSpace<V>>(
        &self,
        c: &[[f64; V]; V],
        step: &StrainStep<V>,
        state_n: &[f64],
        state: &mut [f64],
    ) -> PointResponse<V> {
        with_law!(&self.law, l => l.update_frozen::<V, K>(self.moduli(), c, step, state_n, state))
    }

    /// [`Material::update_with`] where the history of a nonlocal material is driven
    /// by `averaged`, the nonlocal average of its drivers at this point; `None` (and
    /// every local model) takes the point's own.
    pub fn update_driven<const V: usize, K: StrainSpace<V>>(
        &self,
        c: &[[f64; V]; V],
        step: &StrainStep<V>,
        averaged: Option<[f64; MAX_DRIVERS]>,
        state_n: &[f64],
        state: &mut [f64],
    ) -> PointResponse<V> {
        with_law!(&self.law, l => l.update::<V, K>(self.moduli(), c, step, averaged, state_n, state))
    }
}
