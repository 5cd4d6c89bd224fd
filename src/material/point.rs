//! The vocabulary of a material point, below every model: what an update is given
//! ([`StrainStep`], [`Moduli`]), what it returns ([`PointResponse`]), and the one
//! interface each model's file implements ([`Constitutive`]). `material/mod.rs`
//! dispatches over the models; nothing here knows them.

use crate::fe::StrainSpace;

/// Dissipation increments of one step at one point, per unit volume (the `contact`
/// and `mass` lines stay zero at a material point).
pub use crate::energy::Dissipation;

/// The largest number of history values a model keeps per point (a solid's
/// Rankine-Hill point: six plastic strains and two hardening variables).
pub const MAX_STATE: usize = 8;

/// The largest number of nonlocal drivers a point has (Mazars: `[ε_t, ε_c]`): the
/// stride of the nonlocal averaging's buffers.
pub const MAX_DRIVERS: usize = 2;

/// A material point whose update failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PointFailure {
    /// Element block.
    pub block: usize,
    /// Element within the block.
    pub element: usize,
    /// Point within the block.
    pub point: usize,
}

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
    /// Whether the consistent tangent is wanted. A pass that assembles no tangent
    /// asks for none, and a model may then skip it: the response's `tangent` is
    /// unspecified (the models here leave their elastic `C`) and must not be read.
    /// The stress, history, energy and dissipation are the same bit for bit either
    /// way.
    pub tangent: bool,
}

impl<const V: usize> Default for StrainStep<V> {
    fn default() -> Self {
        StrainStep {
            eps_n: [0.0; V],
            eps: [0.0; V],
            dt: 0.0,
            length: 0.0,
            tangent: true,
        }
    }
}

/// The elastic constants every model shares (its `C(E, ν)` in the run's
/// idealisation is handed to the update beside them).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Moduli {
    /// Young's modulus.
    pub e: f64,
    /// Poisson's ratio.
    pub nu: f64,
}

/// How a model's consistent tangent behaves, which decides how the global problem
/// is solved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TangentKind {
    /// `σ = C ε` with no history: the global force is `K u`, no Gauss-point loop.
    Elastic,
    /// Independent of the strain and history for a fixed step (viscoelasticity):
    /// the effective matrix is factorised once.
    Constant,
    /// Depends on the state (damage, plasticity): iterated.
    StateDependent,
}

/// A constitutive model with history at its Gauss points: one implementation per
/// file in `material/`, dispatched by [`super::Law`].
///
/// An update is a pure function of the committed history `state_n` and the new
/// strain: it returns the stress, the consistent tangent, the stored energy density
/// and the step's dissipation by mechanism (with the scheme's own `numerical` line,
/// so that `σ_{n+1}:Δε = Δψ + ΔD` holds exactly), and writes the trial history into
/// `state`. The idealisation `K` (`V` Voigt components) is a type parameter, so one
/// implementation serves plane stress, plane strain and solids.
pub trait Constitutive: std::fmt::Debug {
    /// The name a scenario writes (`model = "..."`).
    fn name(&self) -> &'static str;

    /// One line per parameter beyond `E, ν, ρ`, by name (`rothe check`, `rothe
    /// material`).
    fn parameters(&self) -> Vec<(&'static str, String)> {
        Vec::new()
    }

    /// The regularisation of a softening model (`"local"`, `"crack_band"`,
    /// `"nonlocal"`), `None` for the others.
    fn regularisation(&self) -> Option<&'static str> {
        None
    }

    /// History values per point with `voigt` strain components (at most
    /// [`MAX_STATE`]).
    fn n_state(&self, _voigt: usize) -> usize {
        0
    }

    /// Names of those history values (columns of `rothe material` output).
    fn state_names(&self, _voigt: usize) -> &'static [&'static str] {
        &[]
    }

    /// Damage and equivalent plastic strain of a point's history, for output.
    fn output_fields(&self, _state: &[f64], _voigt: usize) -> (f64, f64) {
        (0.0, 0.0)
    }

    /// How the tangent behaves.
    fn tangent_kind(&self) -> TangentKind;

    /// True when the stress depends on the strain path but not on its rate: at an
    /// unchanged strain the committed stress is the stress of any step.
    fn is_rate_independent(&self) -> bool;

    /// Whether [`Constitutive::update_frozen`] differs from the update.
    fn has_frozen_form(&self) -> bool {
        false
    }

    /// The stiffness a sudden strain meets, as a multiple of `C` (what an explicit
    /// step sees): 1 unless a branch answers at once (the standard linear solid's).
    fn instantaneous_factor(&self) -> f64 {
        1.0
    }

    /// The viscosity `η` (`σ_v = η ε̇`, Voigt form on engineering strain) of a
    /// Kelvin-Voigt model, from its `c`; `None` for the others.
    fn viscosity<const V: usize, K: StrainSpace<V>>(
        &self,
        _c: &[[f64; V]; V],
    ) -> Option<[[f64; V]; V]> {
        None
    }

    /// The interaction radius of a nonlocal model (`None`: local).
    fn nonlocal_radius(&self) -> Option<f64> {
        None
    }

    /// How many drivers (the strain measures a nonlocal model averages) a point
    /// has, at most [`MAX_DRIVERS`].
    fn n_drivers(&self) -> usize {
        0
    }

    /// The point's own drivers at strain `eps` (the first [`Constitutive::n_drivers`]
    /// entries; the rest zero).
    fn drivers<const V: usize, K: StrainSpace<V>>(
        &self,
        _moduli: Moduli,
        _eps: &[f64; V],
    ) -> [f64; MAX_DRIVERS] {
        [0.0; MAX_DRIVERS]
    }

    /// Whether averaged drivers no larger than `bound` could move the committed
    /// history `history` (false: the average need not be formed for that point).
    fn drivers_can_grow(&self, _bound: [f64; MAX_DRIVERS], _history: &[f64]) -> bool {
        true
    }

    /// The update (see the trait's docs) with the elasticity `c` of the
    /// idealisation `K`; `averaged` holds the nonlocal average of the drivers at this
    /// point when the model is nonlocal (`None`: the point's own).
    #[allow(clippy::too_many_arguments)]
    fn update<const V: usize, K: StrainSpace<V>>(
        &self,
        moduli: Moduli,
        c: &[[f64; V]; V],
        step: &StrainStep<V>,
        averaged: Option<[f64; MAX_DRIVERS]>,
        state_n: &[f64],
        state: &mut [f64],
    ) -> PointResponse<V>;

    /// The update with every history frozen at its committed value where the model
    /// has such a form (the paper's first estimate of a step); the update otherwise.
    fn update_frozen<const V: usize, K: StrainSpace<V>>(
        &self,
        moduli: Moduli,
        c: &[[f64; V]; V],
        step: &StrainStep<V>,
        state_n: &[f64],
        state: &mut [f64],
    ) -> PointResponse<V> {
        self.update::<V, K>(moduli, c, step, None, state_n, state)
    }

    /// The stress of a step of size `dt` that leaves the strain at `eps`, from the
    /// history `state` (the trial state of the step just taken): what the update
    /// returns with `eps_n = eps`. For constant-tangent models the next step's stress
    /// is this plus `tangent · Δε`.
    fn predicted_stress<const V: usize, K: StrainSpace<V>>(
        &self,
        moduli: Moduli,
        c: &[[f64; V]; V],
        eps: &[f64; V],
        state: &[f64],
        dt: f64,
    ) -> [f64; V] {
        let mut st = [0.0; MAX_STATE];
        let step = StrainStep {
            eps_n: *eps,
            eps: *eps,
            dt,
            length: 1.0,
            tangent: false,
        };
        self.update::<V, K>(moduli, c, &step, None, state, &mut st[..self.n_state(V)])
            .sigma
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
