//! Constitutive models with history at the Gauss points.
//!
//! A material update is a pure function of the last committed Gauss-point state and
//! the strain at the new step: it returns the stress, the consistent tangent, the
//! stored energy density and the step's dissipation by mechanism
//! ([`PointResponse`]), and writes the trial state. The caller commits trial states
//! only when a step is accepted ([`store::StateStore`]), so iterations and step
//! cuts leave no trace. Every model shares the isotropic elasticity `C(E, ν)` of
//! the idealisation chosen for the run: each function is generic over its
//! [`StrainSpace`] `K` (plane stress, plane strain or solid, `V` Voigt components).

pub mod elastic;
pub mod hardening;
pub mod identify;
pub mod linalg;
pub mod mazars;
pub mod point_driver;
pub mod rankine_hill;
pub mod store;
pub mod viscoelastic;

pub use hardening::Hardening;
pub use mazars::{MazarsParams, MazarsVariant, Regularisation};
pub use rankine_hill::RankineHillParams;

use crate::fe::StrainSpace;

/// Dissipation increments of one step at one point, per unit volume (the `contact`
/// and `mass` lines stay zero at a material point).
pub use crate::energy::Dissipation;

/// Whether a material update found its state.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PointStatus {
    /// The update is valid.
    #[default]
    Ok,
    /// The return mapping found no admissible state (an exhausted strength, or a
    /// softening too steep for the element): the response holds the trial stress and
    /// must not be accepted; the equilibrium loop reports it and the step is cut.
    ReturnFailed,
}

/// What one material update returns: `V = 3` Voigt components in the plane, 6 in a
/// solid (the order of `fe`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointResponse<const V: usize> {
    /// Stress `[σ_xx, σ_yy, σ_xy(, σ_zz, σ_yz, σ_zx)]` at the new step.
    pub sigma: [f64; V],
    /// Consistent tangent `∂σ_{n+1}/∂ε_{n+1}`.
    pub tangent: [[f64; V]; V],
    /// Stored (free) energy density at the new step.
    pub psi: f64,
    /// Dissipation increments of the step.
    pub dissipation: Dissipation,
    /// Whether the update succeeded.
    pub status: PointStatus,
}

impl<const V: usize> Default for PointResponse<V> {
    fn default() -> Self {
        PointResponse {
            sigma: [0.0; V],
            tangent: [[0.0; V]; V],
            psi: 0.0,
            dissipation: Dissipation::default(),
            status: PointStatus::Ok,
        }
    }
}

/// The strain step a material point is asked to take (`V` Voigt components).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StrainStep<const V: usize> {
    /// Strain at the last committed step.
    pub eps_n: [f64; V],
    /// Strain at the new step.
    pub eps: [f64; V],
    /// Time step size.
    pub dt: f64,
    /// Characteristic size of the element the point belongs to (m): the crack-band
    /// length of softening laws.
    pub length: f64,
}

/// The viscosity of a Kelvin-Voigt material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Viscosity {
    /// `η = α C` (stiffness-proportional, `α` in seconds): `σ = C ε + α C ε̇`.
    Proportional(f64),
    /// `η = β I` (identity viscosity, `β` in Pa·s), as in the paper's examples.
    Identity(f64),
}

/// Constitutive model with its parameters (beyond the elastic `E, ν, ρ`).
#[derive(Clone, Debug, PartialEq)]
pub enum Model {
    /// Linear elasticity `σ = C ε`.
    Elastic,
    /// Kelvin-Voigt `σ = C ε + η ε̇` (also the Kelvin limit of the SLS).
    KelvinVoigt(Viscosity),
    /// Standard linear solid (eq. 10): `σ = C ε + τ`, Maxwell branch spring `α C`,
    /// dashpot `β C` (`β` in seconds). With `parallel = false` the parallel spring
    /// is absent: the Maxwell model `σ = τ`.
    Sls {
        /// Branch stiffness ratio `α` (dimensionless).
        alpha: f64,
        /// Dashpot time `β` (s).
        beta: f64,
        /// Whether the parallel spring `C` is present.
        parallel: bool,
    },
    /// Mazars damage `σ = (1 − D) C ε`.
    Mazars(MazarsParams),
    /// Rankine-Hill plasticity (plane stress, or a solid's principal stress space).
    RankineHill(RankineHillParams),
}

impl<const V: usize> Default for StrainStep<V> {
    fn default() -> Self {
        StrainStep {
            eps_n: [0.0; V],
            eps: [0.0; V],
            dt: 0.0,
            length: 0.0,
        }
    }
}

/// The largest number of history values a model keeps per point (a solid's
/// Rankine-Hill point: six plastic strains and two hardening variables).
pub const MAX_STATE: usize = 8;

/// A material: elastic constants, density and constitutive model.
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
    /// The constitutive model.
    pub model: Model,
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
            model: Model::Elastic,
            identified_from: None,
        }
    }

    /// The model's name as a scenario writes it (`model = "..."`).
    pub fn model_name(&self) -> &'static str {
        match &self.model {
            Model::Elastic => "elastic",
            Model::KelvinVoigt(_) => "kelvin_voigt",
            Model::Sls { parallel: true, .. } => "sls",
            Model::Sls { .. } => "maxwell",
            Model::Mazars(_) => "mazars",
            Model::RankineHill(_) => "rankine_hill",
        }
    }

    /// The interaction radius of a nonlocal material (`None`: local).
    pub fn nonlocal_radius(&self) -> Option<f64> {
        match self.model {
            Model::Mazars(MazarsParams {
                regularisation: Regularisation::Nonlocal { radius },
                ..
            }) => Some(radius),
            _ => None,
        }
    }

    /// The regularisation of a softening material: `"local"`, `"crack_band"` or
    /// `"nonlocal"` for Mazars, `"crack_band"` for Rankine-Hill with a softening
    /// tension law, `None` for the others.
    pub fn regularisation(&self) -> Option<&'static str> {
        match self.model {
            Model::Mazars(p) => Some(p.regularisation.name()),
            Model::RankineHill(RankineHillParams {
                tension: Hardening::LinearSoftening { .. },
                ..
            }) => Some("crack_band"),
            _ => None,
        }
    }

    /// The model's parameters beyond `E, ν, ρ`, by name, for `check` and `material`.
    pub fn parameters(&self) -> Vec<(&'static str, String)> {
        let g = sig;
        match self.model {
            Model::Mazars(p) => {
                let mut v = vec![
                    ("variant", format!("{:?}", p.variant).to_lowercase()),
                    ("eps_t0", g(p.eps_t0)),
                ];
                if p.variant == MazarsVariant::Paper {
                    v.push(("eps_c0", g(p.eps_c0)));
                }
                match p.regularisation {
                    Regularisation::CrackBand { fracture_energy } => {
                        v.push(("A_t", "1 (crack band)".into()));
                        v.push(("B_t", "per element from G_f (crack band)".into()));
                        v.push(("fracture_energy", g(fracture_energy)));
                    }
                    _ => {
                        v.push(("A_t", g(p.a_t)));
                        v.push(("B_t", g(p.b_t)));
                    }
                }
                v.push(("A_c", g(p.a_c)));
                v.push(("B_c", g(p.b_c)));
                if p.variant == MazarsVariant::Classic {
                    v.push(("beta", g(p.beta)));
                }
                v.push(("d_max", format!("{}", p.d_max)));
                v.push(("regularisation", p.regularisation.name().into()));
                if let Regularisation::Nonlocal { radius } = p.regularisation {
                    v.push(("radius", g(radius)));
                }
                v
            }
            Model::RankineHill(p) => vec![
                ("tension", p.tension.describe()),
                ("compression", p.compression.describe()),
            ],
            _ => Vec::new(),
        }
    }

    /// Elasticity matrix `C` of the idealisation `K`.
    pub fn elasticity<const V: usize, K: StrainSpace<V>>(&self) -> [[f64; V]; V] {
        K::elasticity(self.e, self.nu)
    }

    /// The stiffness the material shows to a sudden strain (what an explicit step
    /// sees): `C`, and `(1 + α) C` for the standard linear solid (`α C` without the
    /// parallel spring), whose Maxwell branch answers at once.
    pub fn instantaneous_stiffness<const V: usize, K: StrainSpace<V>>(&self) -> [[f64; V]; V] {
        let c = self.elasticity::<V, K>();
        match self.model {
            Model::Sls {
                alpha, parallel, ..
            } => {
                let f = alpha + if parallel { 1.0 } else { 0.0 };
                c.map(|row| row.map(|x| f * x))
            }
            _ => c,
        }
    }

    /// The viscosity `η` of a Kelvin-Voigt material (`σ_v = η ε̇`, Voigt form on
    /// engineering strain), `None` for the others.
    pub fn viscosity<const V: usize, K: StrainSpace<V>>(&self) -> Option<[[f64; V]; V]> {
        match self.model {
            Model::KelvinVoigt(Viscosity::Proportional(alpha)) => {
                Some(self.elasticity::<V, K>().map(|row| row.map(|x| alpha * x)))
            }
            Model::KelvinVoigt(Viscosity::Identity(beta)) => {
                Some(viscoelastic::identity_viscosity(beta))
            }
            _ => None,
        }
    }

    /// True when the stress is `C ε` with no history: the stiffness is constant and
    /// the global force is `K u`, so no Gauss-point loop is needed per step.
    pub fn is_linear_elastic(&self) -> bool {
        matches!(self.model, Model::Elastic)
    }

    /// True when the stress depends on the strain path but not on its rate
    /// (elasticity, damage, plasticity): at an unchanged strain the committed
    /// stress is the stress of any step, so an implicit step starting at an
    /// unchanged displacement knows its internal force without a pass.
    pub fn is_rate_independent(&self) -> bool {
        matches!(
            self.model,
            Model::Elastic | Model::Mazars(_) | Model::RankineHill(_)
        )
    }

    /// Number of history values per point with `voigt` strain components (at most
    /// [`MAX_STATE`]; a standard linear solid keeps one dashpot strain per component).
    pub fn n_state(&self, voigt: usize) -> usize {
        match self.model {
            Model::Elastic | Model::KelvinVoigt(_) => 0,
            Model::Sls { .. } => voigt,
            Model::Mazars(_) => 3,
            // The plane keeps a sixth value, `εᵖ_zz`, which plane strain's return
            // through the solid's needs (zero in plane stress).
            Model::RankineHill(_) if voigt == 3 => rankine_hill::n_state(voigt) + 1,
            Model::RankineHill(_) => rankine_hill::n_state(voigt),
        }
    }

    /// Names of the history values of a point with `voigt` strain components
    /// (columns of `rothe material` output).
    pub fn state_names(&self, voigt: usize) -> &'static [&'static str] {
        match (&self.model, voigt) {
            (Model::Elastic | Model::KelvinVoigt(_), _) => &[],
            (Model::Sls { .. }, 3) => &["eps_d_xx", "eps_d_yy", "gamma_d_xy"],
            (Model::Sls { .. }, _) => &[
                "eps_d_xx",
                "eps_d_yy",
                "gamma_d_xy",
                "eps_d_zz",
                "gamma_d_yz",
                "gamma_d_zx",
            ],
            (
                Model::Mazars(MazarsParams {
                    variant: MazarsVariant::Paper,
                    ..
                }),
                _,
            ) => &["eps_t_max", "eps_c_max", "damage"],
            (Model::Mazars(_), _) => &["kappa", "unused", "damage"],
            (Model::RankineHill(_), 3) => &[
                "eps_p_xx",
                "eps_p_yy",
                "gamma_p_xy",
                "kappa_t",
                "kappa_c",
                "eps_p_zz",
            ],
            (Model::RankineHill(_), _) => &[
                "eps_p_xx",
                "eps_p_yy",
                "gamma_p_xy",
                "eps_p_zz",
                "gamma_p_yz",
                "gamma_p_zx",
                "kappa_t",
                "kappa_c",
            ],
        }
    }

    /// Damage and equivalent plastic strain `κ_t + κ_c` of the state of a point with
    /// `voigt` strain components, for output.
    pub fn output_fields(&self, state: &[f64], voigt: usize) -> (f64, f64) {
        match self.model {
            Model::Mazars(_) => (state[2], 0.0),
            Model::RankineHill(_) => (0.0, state[voigt] + state[voigt + 1]),
            _ => (0.0, 0.0),
        }
    }

    /// True when the consistent tangent does not depend on the strain or history
    /// (for a fixed step): the effective matrix is then factorised once.
    pub fn has_constant_tangent(&self) -> bool {
        matches!(
            self.model,
            Model::Elastic | Model::KelvinVoigt(_) | Model::Sls { .. }
        )
    }

    /// Initial history values.
    pub fn init_state(&self, state: &mut [f64]) {
        state.fill(0.0);
    }

    /// Stress of a step of size `dt` that leaves the strain at `eps`, from the history
    /// `state` (the trial state of the step just taken): what `update` would return
    /// with `eps_n = eps`, computed without the energy terms. For constant-tangent
    /// models the next step's stress is this plus `tangent · Δε`.
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
        match self.model {
            // The stress at the trial damage: with the strain unchanged neither the
            // history maxima nor the damage grow (the local law at the committed
            // strain returns at most the committed `D`; a nonlocal average is not
            // re-evaluated for a prediction).
            Model::Mazars(_) => {
                let w = 1.0 - state[2];
                let s = mul3(c, eps);
                s.map(|x| w * x)
            }
            Model::Elastic | Model::KelvinVoigt(_) | Model::RankineHill(_) => {
                let mut st = [0.0; MAX_STATE];
                self.update_with::<V, K>(
                    c,
                    &StrainStep {
                        eps_n: *eps,
                        eps: *eps,
                        dt,
                        length: 1.0,
                    },
                    state,
                    &mut st[..self.n_state(V)],
                )
                .sigma
            }
            Model::Sls {
                alpha,
                beta,
                parallel,
            } => {
                let k = dt * alpha / beta;
                let p = if parallel { 1.0 } else { 0.0 };
                let ee: [f64; V] = std::array::from_fn(|i| eps[i] - state[i]);
                let (ce, cee) = (mul3(c, eps), mul3(c, &ee));
                let a = alpha / (1.0 + k);
                std::array::from_fn(|i| p * ce[i] + a * cee[i])
            }
        }
    }

    /// The material update (see the module docs) in the idealisation `K`.
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
    /// where the model has such a form (Mazars: `D = D⁰`, the secant of the last
    /// step, the paper's first estimate); the ordinary update for the others.
    pub fn update_frozen<const V: usize, K: StrainSpace<V>>(
        &self,
        c: &[[f64; V]; V],
        step: &StrainStep<V>,
        state_n: &[f64],
        state: &mut [f64],
    ) -> PointResponse<V> {
        match self.model {
            Model::Mazars(_) => mazars::frozen(c, step, state_n, state),
            _ => self.update_with::<V, K>(c, step, state_n, state),
        }
    }

    /// Whether [`Material::update_frozen`] differs from the update (a state the
    /// first iterate of a step with prescribed increments must not evolve).
    pub fn has_frozen_form(&self) -> bool {
        matches!(self.model, Model::Mazars(_))
    }

    /// [`Material::update_with`] where the damage of a nonlocal material is driven by
    /// `averaged`, the nonlocal average of its equivalent strains at this point
    /// ([`mazars::drivers`]); `None` (and every other model) takes the point's own.
    pub fn update_driven<const V: usize, K: StrainSpace<V>>(
        &self,
        c: &[[f64; V]; V],
        step: &StrainStep<V>,
        averaged: Option<[f64; 2]>,
        state_n: &[f64],
        state: &mut [f64],
    ) -> PointResponse<V> {
        let c = *c;
        match self.model {
            Model::Elastic => elastic::update(&c, step),
            Model::KelvinVoigt(Viscosity::Proportional(alpha)) => {
                let eta = c.map(|row| row.map(|x| alpha * x));
                viscoelastic::kelvin_voigt(&c, &eta, step)
            }
            Model::KelvinVoigt(Viscosity::Identity(beta)) => {
                viscoelastic::kelvin_voigt(&c, &viscoelastic::identity_viscosity(beta), step)
            }
            Model::Sls {
                alpha,
                beta,
                parallel,
            } => viscoelastic::standard_linear_solid(
                &c,
                if parallel { 1.0 } else { 0.0 },
                alpha,
                beta,
                step,
                state_n,
                state,
            ),
            Model::Mazars(p) => {
                mazars::update::<V, K>(&p, &c, self.nu, step, averaged, state_n, state)
            }
            Model::RankineHill(p) => {
                rankine_hill::update_in::<V, K>(&p, &c, self.e, self.nu, step, state_n, state)
            }
        }
    }
}

/// `x` to four significant digits, in plain notation between 10⁻³ and 10⁵.
pub fn sig(x: f64) -> String {
    let a = x.abs();
    if x == 0.0 || !x.is_finite() {
        format!("{x}")
    } else if (1e-3..1e5).contains(&a) {
        let decimals = (3 - a.log10().floor() as i32).max(0) as usize;
        let t = format!("{x:.decimals$}");
        if t.contains('.') {
            t.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            t
        }
    } else {
        format!("{x:.3e}")
    }
}

/// `a · b` for Voigt vectors (summed from the first component on).
#[inline]
pub fn dot3<const V: usize>(a: &[f64; V], b: &[f64; V]) -> f64 {
    let mut s = a[0] * b[0];
    for i in 1..V {
        s += a[i] * b[i];
    }
    s
}

/// `C x` for a Voigt matrix (each row summed from its first column on).
#[inline]
pub fn mul3<const V: usize>(c: &[[f64; V]; V], x: &[f64; V]) -> [f64; V] {
    std::array::from_fn(|i| dot3(&c[i], x))
}
