//! Linear viscoelasticity: Kelvin-Voigt and the standard linear solid of eq. (10),
//! with the Maxwell and Kelvin limits. All updates are backward Euler, exact in the
//! energy split `σ_{n+1}:Δε = Δψ + ΔD_viscous + ΔD_num` (see `theory/viscoelasticity.md`).

use super::point::{
    dot3, mul3, Constitutive, Dissipation, Moduli, PointResponse, PointStatus, StrainStep,
    TangentKind, MAX_DRIVERS,
};
use crate::fe::StrainSpace;

/// The viscosity of a Kelvin-Voigt material, which is the whole model:
/// `σ = C ε + η ε̇`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Viscosity {
    /// `η = α C` (stiffness-proportional, `α` in seconds): `σ = C ε + α C ε̇`.
    Proportional(f64),
    /// `η = β I` (identity viscosity, `β` in Pa·s), as in the paper's examples.
    Identity(f64),
}

impl Constitutive for Viscosity {
    fn name(&self) -> &'static str {
        "kelvin_voigt"
    }

    fn tangent_kind(&self) -> TangentKind {
        TangentKind::Constant
    }

    fn is_rate_independent(&self) -> bool {
        false
    }

    fn viscosity<const V: usize, K: StrainSpace<V>>(
        &self,
        c: &[[f64; V]; V],
    ) -> Option<[[f64; V]; V]> {
        Some(match *self {
            Viscosity::Proportional(alpha) => c.map(|row| row.map(|x| alpha * x)),
            Viscosity::Identity(beta) => identity_viscosity(beta),
        })
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
        let eta = self
            .viscosity::<V, K>(c)
            .expect("a Kelvin-Voigt model has a viscosity");
        kelvin_voigt(c, &eta, step)
    }
}

/// The standard linear solid of eq. (10): `σ = p C ε + τ`, a Maxwell branch of
/// spring `α C` and dashpot `β C`; without the parallel spring (`p = 0`) the Maxwell
/// model `σ = τ`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sls {
    /// Branch stiffness ratio `α` (dimensionless).
    pub alpha: f64,
    /// Dashpot time `β` (s).
    pub beta: f64,
    /// Whether the parallel spring `C` is present.
    pub parallel: bool,
}

impl Sls {
    /// `p`: 1 with the parallel spring, 0 without.
    fn p(&self) -> f64 {
        if self.parallel {
            1.0
        } else {
            0.0
        }
    }
}

impl Constitutive for Sls {
    fn name(&self) -> &'static str {
        if self.parallel {
            "sls"
        } else {
            "maxwell"
        }
    }

    /// One dashpot strain per component.
    fn n_state(&self, voigt: usize) -> usize {
        voigt
    }

    fn state_names(&self, voigt: usize) -> &'static [&'static str] {
        const NAMES: [&str; 6] = [
            "eps_d_xx",
            "eps_d_yy",
            "gamma_d_xy",
            "eps_d_zz",
            "gamma_d_yz",
            "gamma_d_zx",
        ];
        &NAMES[..voigt]
    }

    fn tangent_kind(&self) -> TangentKind {
        TangentKind::Constant
    }

    fn is_rate_independent(&self) -> bool {
        false
    }

    /// `(p + α) C`: the Maxwell branch answers at once.
    fn instantaneous_factor(&self) -> f64 {
        self.alpha + self.p()
    }

    fn update<const V: usize, K: StrainSpace<V>>(
        &self,
        _moduli: Moduli,
        c: &[[f64; V]; V],
        step: &StrainStep<V>,
        _averaged: Option<[f64; MAX_DRIVERS]>,
        state_n: &[f64],
        state: &mut [f64],
    ) -> PointResponse<V> {
        standard_linear_solid(c, self.p(), self.alpha, self.beta, step, state_n, state)
    }

    /// `p C ε + α/(1 + k) C (ε − ε_d)`, `k = h α/β`, from the dashpot strain
    /// `ε_d` of `state`.
    fn predicted_stress<const V: usize, K: StrainSpace<V>>(
        &self,
        _moduli: Moduli,
        c: &[[f64; V]; V],
        eps: &[f64; V],
        state: &[f64],
        dt: f64,
    ) -> [f64; V] {
        let k = dt * self.alpha / self.beta;
        let p = self.p();
        let ee: [f64; V] = std::array::from_fn(|i| eps[i] - state[i]);
        let (ce, cee) = (mul3(c, eps), mul3(c, &ee));
        let a = self.alpha / (1.0 + k);
        std::array::from_fn(|i| p * ce[i] + a * cee[i])
    }
}

/// Whether Voigt component `i` is a shear (engineering `γ`): the plane's third, a
/// solid's third, fifth and sixth (order of `fe`).
#[inline]
fn is_shear(i: usize) -> bool {
    matches!(i, 2 | 4 | 5)
}

/// Voigt matrix of the identity viscosity `η = β I` acting on engineering strain
/// rates: `σ = β ε̇` componentwise, so `σ_xy = β γ̇_xy / 2` (each shear).
pub fn identity_viscosity<const V: usize>(beta: f64) -> [[f64; V]; V] {
    std::array::from_fn(|i| {
        std::array::from_fn(|j| match (i == j, is_shear(i)) {
            (true, true) => 0.5 * beta,
            (true, false) => beta,
            _ => 0.0,
        })
    })
}

fn sub<const V: usize>(a: &[f64; V], b: &[f64; V]) -> [f64; V] {
    std::array::from_fn(|i| a[i] - b[i])
}

fn add_scaled<const V: usize>(
    m: &[[f64; V]; V],
    a: f64,
    n: &[[f64; V]; V],
    b: f64,
) -> [[f64; V]; V] {
    std::array::from_fn(|i| std::array::from_fn(|j| a * m[i][j] + b * n[i][j]))
}

/// Kelvin-Voigt `σ = C ε + η ε̇`, `ε̇ ≈ (ε − ε_n)/h`. History-free (the committed
/// strain is the store's). Tangent `C + η/h`; `ΔD_viscous = Δε:η:Δε/h`;
/// `ΔD_num = ½ Δε:C:Δε`.
pub fn kelvin_voigt<const V: usize>(
    c: &[[f64; V]; V],
    eta: &[[f64; V]; V],
    step: &StrainStep<V>,
) -> PointResponse<V> {
    let de = sub(&step.eps, &step.eps_n);
    let ce = mul3(c, &step.eps);
    let eta_de = mul3(eta, &de);
    let h = step.dt;
    let sigma: [f64; V] = std::array::from_fn(|i| ce[i] + eta_de[i] / h);
    PointResponse {
        sigma,
        tangent: add_scaled(c, 1.0, eta, 1.0 / h),
        psi: 0.5 * dot3(&step.eps, &ce),
        dissipation: Dissipation {
            viscous: dot3(&de, &eta_de) / h,
            numerical: 0.5 * dot3(&de, &mul3(c, &de)),
            ..Default::default()
        },
        status: PointStatus::Ok,
    }
}

/// Standard linear solid: `σ = p C ε + τ` with a Maxwell branch of spring `α C` and
/// dashpot `β C` (`β` in seconds), `p = 1` (SLS) or `p = 0` (Maxwell). State: the
/// dashpot strain `ε_d`; backward Euler `ε_d¹ = (ε_d⁰ + k ε)/(1 + k)`, `k = h α/β`,
/// so `τ = α C (ε − ε_d⁰)/(1 + k)`, the paper's eq. (10) second line.
pub fn standard_linear_solid<const V: usize>(
    c: &[[f64; V]; V],
    parallel: f64,
    alpha: f64,
    beta: f64,
    step: &StrainStep<V>,
    eps_d_n: &[f64],
    eps_d: &mut [f64],
) -> PointResponse<V> {
    let h = step.dt;
    let k = h * alpha / beta;
    let inv = 1.0 / (1.0 + k);
    let ed_n: [f64; V] = std::array::from_fn(|i| eps_d_n[i]);
    let ed: [f64; V] = std::array::from_fn(|i| (ed_n[i] + k * step.eps[i]) * inv);
    eps_d[..V].copy_from_slice(&ed);
    // Four products with C; every other one follows by linearity.
    let ce = mul_iso(c, &step.eps);
    let ce_n = mul_iso(c, &step.eps_n);
    let ced = mul_iso(c, &ed);
    let ced_n = mul_iso(c, &ed_n);
    let ee = sub(&step.eps, &ed); // branch elastic strain
    let c_ee = sub(&ce, &ced);
    let de = sub(&step.eps, &step.eps_n);
    let c_de = sub(&ce, &ce_n);
    let ded = sub(&ed, &ed_n);
    let c_ded = sub(&ced, &ced_n);
    let dee = sub(&de, &ded);
    let c_dee = sub(&c_de, &c_ded);
    let sigma: [f64; V] = std::array::from_fn(|i| parallel * ce[i] + alpha * c_ee[i]);
    PointResponse {
        sigma,
        tangent: add_scaled(c, parallel, c, alpha * inv),
        psi: 0.5 * parallel * dot3(&step.eps, &ce) + 0.5 * alpha * dot3(&ee, &c_ee),
        dissipation: Dissipation {
            viscous: beta * dot3(&ded, &c_ded) / h,
            numerical: 0.5 * parallel * dot3(&de, &c_de) + 0.5 * alpha * dot3(&dee, &c_dee),
            ..Default::default()
        },
        status: PointStatus::Ok,
    }
}

/// `C x` for an isotropic elasticity matrix: no normal-shear coupling, the shears
/// on the diagonal (the normal rows summed over the normal columns in order).
#[inline]
fn mul_iso<const V: usize>(c: &[[f64; V]; V], x: &[f64; V]) -> [f64; V] {
    std::array::from_fn(|i| {
        if is_shear(i) {
            return c[i][i] * x[i];
        }
        let mut s = c[i][0] * x[0];
        for j in 1..V {
            if !is_shear(j) {
                s += c[i][j] * x[j];
            }
        }
        s
    })
}
