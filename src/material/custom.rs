//! Laws defined outside the crate: any [`Constitutive`] implementation handed to
//! [`Law::custom`](super::Law::custom) runs like a built-in model (a test fixture,
//! a model under development in a user's own crate).
//!
//! A built-in model is one file and one variant of [`super::Law`], dispatched
//! statically. A law the crate does not know is kept behind an object-safe mirror of
//! [`Constitutive`] ([`DynConstitutive`], implemented for every `Constitutive`):
//! its point quantities cross as slices and the idealisation as its runtime value,
//! so each call copies the point's vectors once each way. [`CustomLaw`] implements
//! `Constitutive` again on top of it, so the Gauss-point pass, the point driver and
//! the nonlocal averaging see no difference. What does not cross: a custom law's own
//! `predicted_stress` and `viscosity` (the prediction is the update at an unchanged
//! strain, which is its definition; a custom law has no nodal-field form and runs
//! at the Gauss points).

use std::sync::Arc;

use super::point::{
    Constitutive, Dissipation, Moduli, PointResponse, PointStatus, StrainStep, TangentKind,
    MAX_DRIVERS,
};
use crate::fe::{Idealisation, StrainSpace};

/// What a point update hands back through the object-safe interface besides the
/// stress and tangent it writes.
pub type DynResponse = (f64, Dissipation, PointStatus);

/// The object-safe mirror of [`Constitutive`]: the same questions with the
/// idealisation as a value and the point's vectors as slices (`V` entries, the
/// tangent row by row). Implemented for every `Constitutive + Send + Sync`.
pub trait DynConstitutive: std::fmt::Debug + Send + Sync {
    /// [`Constitutive::name`].
    fn name(&self) -> &'static str;
    /// [`Constitutive::parameters`].
    fn parameters(&self) -> Vec<(&'static str, String)>;
    /// [`Constitutive::regularisation`].
    fn regularisation(&self) -> Option<&'static str>;
    /// [`Constitutive::n_state`].
    fn n_state(&self, voigt: usize) -> usize;
    /// [`Constitutive::state_names`].
    fn state_names(&self, voigt: usize) -> &'static [&'static str];
    /// [`Constitutive::output_fields`].
    fn output_fields(&self, state: &[f64], voigt: usize) -> (f64, f64);
    /// [`Constitutive::tangent_kind`].
    fn tangent_kind(&self) -> TangentKind;
    /// [`Constitutive::is_rate_independent`].
    fn is_rate_independent(&self) -> bool;
    /// [`Constitutive::has_frozen_form`].
    fn has_frozen_form(&self) -> bool;
    /// [`Constitutive::instantaneous_factor`].
    fn instantaneous_factor(&self) -> f64;
    /// [`Constitutive::nonlocal_radius`].
    fn nonlocal_radius(&self) -> Option<f64>;
    /// [`Constitutive::n_drivers`].
    fn n_drivers(&self) -> usize;
    /// [`Constitutive::drivers_can_grow`].
    fn drivers_can_grow(&self, bound: [f64; MAX_DRIVERS], history: &[f64]) -> bool;
    /// [`Constitutive::drivers`] in the idealisation `space`.
    fn drivers_in(&self, space: Idealisation, moduli: Moduli, eps: &[f64]) -> [f64; MAX_DRIVERS];
    /// [`Constitutive::update`] (or, with `frozen`, [`Constitutive::update_frozen`])
    /// in the idealisation `space`: writes the stress into `sigma` and the tangent
    /// into `tangent`.
    #[allow(clippy::too_many_arguments)]
    fn update_in(
        &self,
        space: Idealisation,
        frozen: bool,
        moduli: Moduli,
        c: &[f64],
        step: (&[f64], &[f64], f64, f64),
        averaged: Option<[f64; MAX_DRIVERS]>,
        state_n: &[f64],
        state: &mut [f64],
        sigma: &mut [f64],
        tangent: &mut [f64],
    ) -> DynResponse;
}

/// `x` (at least `V` entries) as an array.
fn array<const V: usize>(x: &[f64]) -> [f64; V] {
    std::array::from_fn(|i| x[i])
}

impl<T: Constitutive + Send + Sync> DynConstitutive for T {
    fn name(&self) -> &'static str {
        Constitutive::name(self)
    }
    fn parameters(&self) -> Vec<(&'static str, String)> {
        Constitutive::parameters(self)
    }
    fn regularisation(&self) -> Option<&'static str> {
        Constitutive::regularisation(self)
    }
    fn n_state(&self, voigt: usize) -> usize {
        Constitutive::n_state(self, voigt)
    }
    fn state_names(&self, voigt: usize) -> &'static [&'static str] {
        Constitutive::state_names(self, voigt)
    }
    fn output_fields(&self, state: &[f64], voigt: usize) -> (f64, f64) {
        Constitutive::output_fields(self, state, voigt)
    }
    fn tangent_kind(&self) -> TangentKind {
        Constitutive::tangent_kind(self)
    }
    fn is_rate_independent(&self) -> bool {
        Constitutive::is_rate_independent(self)
    }
    fn has_frozen_form(&self) -> bool {
        Constitutive::has_frozen_form(self)
    }
    fn instantaneous_factor(&self) -> f64 {
        Constitutive::instantaneous_factor(self)
    }
    fn nonlocal_radius(&self) -> Option<f64> {
        Constitutive::nonlocal_radius(self)
    }
    fn n_drivers(&self) -> usize {
        Constitutive::n_drivers(self)
    }
    fn drivers_can_grow(&self, bound: [f64; MAX_DRIVERS], history: &[f64]) -> bool {
        Constitutive::drivers_can_grow(self, bound, history)
    }
    fn drivers_in(&self, space: Idealisation, moduli: Moduli, eps: &[f64]) -> [f64; MAX_DRIVERS] {
        crate::dispatch_kinematics!(space, <D, V, K> =>
            Constitutive::drivers::<V, K>(self, moduli, &array::<V>(eps)))
    }
    fn update_in(
        &self,
        space: Idealisation,
        frozen: bool,
        moduli: Moduli,
        c: &[f64],
        (eps_n, eps, dt, length): (&[f64], &[f64], f64, f64),
        averaged: Option<[f64; MAX_DRIVERS]>,
        state_n: &[f64],
        state: &mut [f64],
        sigma: &mut [f64],
        tangent: &mut [f64],
    ) -> DynResponse {
        crate::dispatch_kinematics!(space, <D, V, K> => {
            let c: [[f64; V]; V] = std::array::from_fn(|i| array::<V>(&c[V * i..]));
            let step = StrainStep {
                eps_n: array::<V>(eps_n),
                eps: array::<V>(eps),
                dt,
                length,
                tangent: true,
            };
            let r = if frozen {
                self.update_frozen::<V, K>(moduli, &c, &step, state_n, state)
            } else {
                self.update::<V, K>(moduli, &c, &step, averaged, state_n, state)
            };
            sigma[..V].copy_from_slice(&r.sigma);
            for (row, out) in r.tangent.iter().zip(tangent.chunks_exact_mut(V)) {
                out.copy_from_slice(row);
            }
            (r.psi, r.dissipation, r.status)
        })
    }
}

/// A law the crate does not know, shared by every material that uses it.
#[derive(Clone, Debug)]
pub struct CustomLaw(pub Arc<dyn DynConstitutive>);

impl PartialEq for CustomLaw {
    /// The same law object.
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

impl CustomLaw {
    /// The update through the object-safe interface, at `V` components.
    #[allow(clippy::too_many_arguments)]
    fn update_as<const V: usize, K: StrainSpace<V>>(
        &self,
        frozen: bool,
        moduli: Moduli,
        c: &[[f64; V]; V],
        step: &StrainStep<V>,
        averaged: Option<[f64; MAX_DRIVERS]>,
        state_n: &[f64],
        state: &mut [f64],
    ) -> PointResponse<V> {
        let mut r = PointResponse::<V>::default();
        let mut tangent = [0.0; 36];
        (r.psi, r.dissipation, r.status) = self.0.update_in(
            K::IDEALISATION,
            frozen,
            moduli,
            c.as_flattened(),
            (&step.eps_n, &step.eps, step.dt, step.length),
            averaged,
            state_n,
            state,
            &mut r.sigma,
            &mut tangent[..V * V],
        );
        r.tangent = std::array::from_fn(|i| array::<V>(&tangent[V * i..]));
        r
    }
}

impl Constitutive for CustomLaw {
    fn name(&self) -> &'static str {
        self.0.name()
    }
    fn parameters(&self) -> Vec<(&'static str, String)> {
        self.0.parameters()
    }
    fn regularisation(&self) -> Option<&'static str> {
        self.0.regularisation()
    }
    fn n_state(&self, voigt: usize) -> usize {
        self.0.n_state(voigt)
    }
    fn state_names(&self, voigt: usize) -> &'static [&'static str] {
        self.0.state_names(voigt)
    }
    fn output_fields(&self, state: &[f64], voigt: usize) -> (f64, f64) {
        self.0.output_fields(state, voigt)
    }
    fn tangent_kind(&self) -> TangentKind {
        self.0.tangent_kind()
    }
    fn is_rate_independent(&self) -> bool {
        self.0.is_rate_independent()
    }
    fn has_frozen_form(&self) -> bool {
        self.0.has_frozen_form()
    }
    fn instantaneous_factor(&self) -> f64 {
        self.0.instantaneous_factor()
    }
    fn nonlocal_radius(&self) -> Option<f64> {
        self.0.nonlocal_radius()
    }
    fn n_drivers(&self) -> usize {
        self.0.n_drivers()
    }
    fn drivers<const V: usize, K: StrainSpace<V>>(
        &self,
        moduli: Moduli,
        eps: &[f64; V],
    ) -> [f64; MAX_DRIVERS] {
        self.0.drivers_in(K::IDEALISATION, moduli, eps)
    }
    fn drivers_can_grow(&self, bound: [f64; MAX_DRIVERS], history: &[f64]) -> bool {
        self.0.drivers_can_grow(bound, history)
    }
    fn update<const V: usize, K: StrainSpace<V>>(
        &self,
        moduli: Moduli,
        c: &[[f64; V]; V],
        step: &StrainStep<V>,
        averaged: Option<[f64; MAX_DRIVERS]>,
        state_n: &[f64],
        state: &mut [f64],
    ) -> PointResponse<V> {
        self.update_as::<V, K>(false, moduli, c, step, averaged, state_n, state)
    }
    fn update_frozen<const V: usize, K: StrainSpace<V>>(
        &self,
        moduli: Moduli,
        c: &[[f64; V]; V],
        step: &StrainStep<V>,
        state_n: &[f64],
        state: &mut [f64],
    ) -> PointResponse<V> {
        self.update_as::<V, K>(true, moduli, c, step, None, state_n, state)
    }
}
