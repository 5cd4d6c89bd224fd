//! Mazars damage: `σ = (1 − D) C ε`, `D` non-decreasing, `D ≤ D_max < 1`.
//!
//! Two variants (see `theory/damage.md`):
//! - `Paper`: eqs. (11)-(13). Equivalent strains `ε_t = I/(2(1−2ν)) + √J/(2(1+ν))`,
//!   `ε_c = I/(5(1−2ν)) + 6√J/(5(1+ν))` from the three principal strains, their
//!   maxima over the history (from the thresholds), the triaxiality `r` of the
//!   effective stress `C ε`, `ε* = r ε_t* + (1−r) ε_c*`, and
//!   `D = 1 − (1−A) ε*_0/ε* − A exp(−B(ε* − ε*_0))` with `A, B, ε*_0` mixed by `r`
//!   (the reading of `NOTES.md`).
//! - `Classic` (Mazars 1984): `ε̃ = √Σ⟨ε_i⟩₊²`, `κ = max ε̃` from `κ_0`,
//!   `D = α_t^β D_t(κ) + α_c^β D_c(κ)` with the weights `α_t, α_c` from the split of the
//!   effective stress into its positive and negative parts.
//!
//! The strain of the third direction enters the invariants: `ε_zz = −ν/(1−ν)(ε_xx+ε_yy)`
//! in plane stress, 0 in plane strain. The update returns the secant `(1 − D) C` as
//! its tangent: the paper's fixed-point linearisation. Damage dissipation is
//! `ΔW_d = ½(Yⁿ + Yⁿ⁺¹) ΔD`, `Y = ½ ε:C:ε`.
//!
//! The equivalent strains that drive the damage ([`drivers`]) are the point's own
//! (local), or their nonlocal average over the neighbouring Gauss points
//! ([`Regularisation::Nonlocal`], averaged by `assembly::nonlocal` and handed to
//! [`update`]); [`Regularisation::CrackBand`] instead scales the tensile softening
//! with the element size so that a band dissipates the fracture energy
//! (`theory/damage.md`).

use super::point::{
    dot3, mul3, sig, Constitutive, Dissipation, Moduli, PointResponse, PointStatus, StrainStep,
    TangentKind, MAX_DRIVERS,
};
use crate::fe::StrainSpace;

/// Which Mazars law (`variant = "paper" | "classic"` in a scenario).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MazarsVariant {
    /// Eqs. (11)-(13) of the paper.
    #[default]
    Paper,
    /// Mazars (1984), as other FE codes ship it.
    Classic,
}

/// How a Mazars law is kept from depending on the mesh past its peak.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum Regularisation {
    /// None: the law of each point on its own strain (softening localises in one
    /// element; results past the peak depend on the mesh).
    #[default]
    Local,
    /// Crack band: the tensile law softens exponentially to zero (`A_t = 1`) with
    /// `B_t` set per element so that a band one element wide dissipates
    /// `fracture_energy` (N/m) per unit crack area.
    CrackBand {
        /// Fracture energy `G_f` (N/m).
        fracture_energy: f64,
    },
    /// Nonlocal integral averaging (Pijaudier-Cabot and Bažant): the equivalent
    /// strains are averaged over the Gauss points of the same body within `radius`
    /// with the bell weight `(1 − r²/R²)²`, normalised per point.
    Nonlocal {
        /// Interaction radius `R` (m).
        radius: f64,
    },
}

impl Regularisation {
    /// The name written to `summary.json` and printed by `check`.
    pub fn name(&self) -> &'static str {
        match self {
            Regularisation::Local => "local",
            Regularisation::CrackBand { .. } => "crack_band",
            Regularisation::Nonlocal { .. } => "nonlocal",
        }
    }
}

/// Mazars parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MazarsParams {
    /// Variant.
    pub variant: MazarsVariant,
    /// Tensile threshold `ε_t^0` (classic: `κ_0`).
    pub eps_t0: f64,
    /// Compressive threshold `ε_c^0` (paper variant only).
    pub eps_c0: f64,
    /// `A_t`.
    pub a_t: f64,
    /// `B_t`.
    pub b_t: f64,
    /// `A_c`.
    pub a_c: f64,
    /// `B_c`.
    pub b_c: f64,
    /// Exponent `β` of the classic weights.
    pub beta: f64,
    /// Cap `D_max < 1`.
    pub d_max: f64,
    /// Local, crack band or nonlocal.
    pub regularisation: Regularisation,
}

impl MazarsParams {
    /// `(A_t, B_t)` of a point in an element of size `h`: the parameters as given,
    /// or for the crack band `A_t = 1` and the `B_t` of [`crack_band_b`].
    #[inline]
    pub fn tension_law(&self, e: f64, h: f64) -> (f64, f64) {
        match self.regularisation {
            Regularisation::CrackBand { fracture_energy } => {
                (1.0, crack_band_b(e, self.eps_t0, fracture_energy, h))
            }
            _ => (self.a_t, self.b_t),
        }
    }
}

/// `B_t` of the exponential tension law `σ = E ε e^{−B(ε − ε₀)}` (`A_t = 1`) whose
/// energy per unit volume to full damage, `E(ε₀²/2 + ε₀/B + 1/B²)`, is `G_f/h`:
/// `1/B = (−ε₀ + √(4 G_f/(E h) − ε₀²))/2`. Finite while `h < 2 G_f E/f_t²`
/// (`f_t = E ε₀`), the crack-band limit `validate` checks.
#[inline]
pub fn crack_band_b(e: f64, eps0: f64, fracture_energy: f64, h: f64) -> f64 {
    let g = fracture_energy / (e * h);
    let x = 0.5 * (-eps0 + (4.0 * g - eps0 * eps0).max(0.0).sqrt());
    1.0 / x
}

/// The damage law `1 − (1−A) κ_0/κ − A exp(−B(κ − κ_0))` above the threshold.
#[inline]
pub fn damage_law(kappa: f64, kappa0: f64, a: f64, b: f64) -> f64 {
    if kappa <= kappa0 {
        0.0
    } else {
        1.0 - (1.0 - a) * kappa0 / kappa - a * (-b * (kappa - kappa0)).exp()
    }
}

/// The equivalent strains that drive the damage at strain `eps`, the quantities a
/// nonlocal material averages: `[ε_t, ε_c]` of eq. (11) (paper) or `[ε̃, 0]`,
/// `ε̃ = √Σ⟨ε_i⟩₊²` (classic).
#[inline]
pub fn drivers<const V: usize, K: StrainSpace<V>>(
    p: &MazarsParams,
    nu: f64,
    eps: &[f64; V],
) -> [f64; 2] {
    drivers_of(p, nu, &K::principal_strains(eps, nu))
}

/// [`drivers`] from the three principal strains `e`.
#[inline]
fn drivers_of(p: &MazarsParams, nu: f64, e: &[f64; 3]) -> [f64; 2] {
    match p.variant {
        MazarsVariant::Paper => {
            let i1 = e[0] + e[1] + e[2];
            let j = 0.5 * ((e[0] - e[1]).powi(2) + (e[1] - e[2]).powi(2) + (e[2] - e[0]).powi(2));
            let sj = j.max(0.0).sqrt();
            [
                i1 / (2.0 * (1.0 - 2.0 * nu)) + sj / (2.0 * (1.0 + nu)),
                i1 / (5.0 * (1.0 - 2.0 * nu)) + 6.0 * sj / (5.0 * (1.0 + nu)),
            ]
        }
        MazarsVariant::Classic => [
            e.iter().map(|x| x.max(0.0).powi(2)).sum::<f64>().sqrt(),
            0.0,
        ],
    }
}

/// Damage at strain `eps` (principal strains `e`) driven by the equivalent strains
/// `drv` (the point's own or their nonlocal average), given the history `(k1, k2)`
/// and the tension law `(a_t, b_t)`: returns `(D_candidate, k1', k2')`. The mixing
/// by the triaxiality `r` (paper) and the weights `α_t, α_c` (classic) are the
/// point's own.
#[allow(clippy::too_many_arguments)]
fn damage<const V: usize, K: StrainSpace<V>>(
    p: &MazarsParams,
    c: &[[f64; V]; V],
    nu: f64,
    eps: &[f64; V],
    e: &[f64; 3],
    drv: [f64; 2],
    (a_t, b_t): (f64, f64),
    k1: f64,
    k2: f64,
) -> (f64, f64, f64) {
    match p.variant {
        MazarsVariant::Paper => {
            let kt = k1.max(drv[0]).max(p.eps_t0);
            let kc = k2.max(drv[1]).max(p.eps_c0);
            let s = K::principal_elastic_stresses(c, &mul3(c, eps), e, nu);
            let den: f64 = s.iter().map(|x| x.abs()).sum();
            let r = if den > 0.0 {
                s.iter().map(|x| x.max(0.0)).sum::<f64>() / den
            } else {
                1.0
            };
            let es = r * kt + (1.0 - r) * kc;
            let es0 = r * p.eps_t0 + (1.0 - r) * p.eps_c0;
            let a = r * a_t + (1.0 - r) * p.a_c;
            let b = r * b_t + (1.0 - r) * p.b_c;
            (damage_law(es, es0, a, b), kt, kc)
        }
        MazarsVariant::Classic => {
            let et2: f64 = e.iter().map(|x| x.max(0.0).powi(2)).sum();
            let kappa = k1.max(drv[0]).max(p.eps_t0);
            let dt = damage_law(kappa, p.eps_t0, a_t, b_t);
            let dc = damage_law(kappa, p.eps_t0, p.a_c, p.b_c);
            // Weights from the strains of the positive / negative effective stresses.
            let s = K::principal_elastic_stresses(c, &mul3(c, eps), e, nu);
            let ee = K::young(c, nu);
            let (sp, sn): (f64, f64) = (
                s.iter().map(|x| x.max(0.0)).sum(),
                s.iter().map(|x| x.min(0.0)).sum(),
            );
            let (mut at, mut ac) = (0.0, 0.0);
            if et2 > 0.0 {
                for i in 0..3 {
                    let eti = ((1.0 + nu) * s[i].max(0.0) - nu * sp) / ee;
                    let eci = ((1.0 + nu) * s[i].min(0.0) - nu * sn) / ee;
                    let pos = e[i].max(0.0);
                    at += pos * eti;
                    ac += pos * eci;
                }
                at = (at / et2).clamp(0.0, 1.0);
                ac = (ac / et2).clamp(0.0, 1.0);
            }
            (at.powf(p.beta) * dt + ac.powf(p.beta) * dc, kappa, 0.0)
        }
    }
}

/// Mazars update. State: `[k1, k2, D]` (paper: `ε_t*, ε_c*`; classic: `κ, 0`).
/// `averaged` holds the nonlocal average of the [`drivers`] at this point (`None`:
/// the point's own).
#[allow(clippy::too_many_arguments)]
pub fn update<const V: usize, K: StrainSpace<V>>(
    p: &MazarsParams,
    c: &[[f64; V]; V],
    nu: f64,
    step: &StrainStep<V>,
    averaged: Option<[f64; 2]>,
    state_n: &[f64],
    state: &mut [f64],
) -> PointResponse<V> {
    let (k1n, k2n, dn) = (state_n[0], state_n[1], state_n[2]);
    let e = K::principal_strains(&step.eps, nu);
    let drv = averaged.unwrap_or_else(|| drivers_of(p, nu, &e));
    // Below both thresholds, now and before: the damage law gives 0 (its argument
    // is its threshold), so the point keeps its damage without the principal
    // stresses, the split and the exponentials (what `damage` returns there).
    let (k1, k2) = match p.variant {
        MazarsVariant::Paper => (k1n.max(drv[0]).max(p.eps_t0), k2n.max(drv[1]).max(p.eps_c0)),
        MazarsVariant::Classic => (k1n.max(drv[0]).max(p.eps_t0), 0.0),
    };
    if k1 == p.eps_t0 && (p.variant == MazarsVariant::Classic || k2 == p.eps_c0) {
        let d = dn.clamp(0.0, p.d_max);
        state[0] = k1;
        state[1] = k2;
        state[2] = d;
        return secant_response(c, step, dn, d);
    }
    let law = p.tension_law(K::young(c, nu), step.length);
    let (dcand, k1, k2) = damage::<V, K>(p, c, nu, &step.eps, &e, drv, law, k1n, k2n);
    let d = dcand.max(dn).clamp(0.0, p.d_max);
    state[0] = k1;
    state[1] = k2;
    state[2] = d;
    secant_response(c, step, dn, d)
}

/// The Mazars point with its history frozen at the committed state: `D = D⁰`,
/// `σ = (1 − D⁰)Cε` (the paper's first estimate of a step, `D(u_{s−1})`).
pub fn frozen<const V: usize>(
    c: &[[f64; V]; V],
    step: &StrainStep<V>,
    state_n: &[f64],
    state: &mut [f64],
) -> PointResponse<V> {
    state.copy_from_slice(&state_n[..state.len()]);
    secant_response(c, step, state_n[2], state_n[2])
}

/// Stress, secant, stored energy and the step's dissipation of a point whose damage
/// goes from `dn` to `d` (theory/damage.md, (M4)–(M6)).
fn secant_response<const V: usize>(
    c: &[[f64; V]; V],
    step: &StrainStep<V>,
    dn: f64,
    d: f64,
) -> PointResponse<V> {
    let ce = mul3(c, &step.eps);
    let y1 = 0.5 * dot3(&step.eps, &ce);
    let y0 = 0.5 * dot3(&step.eps_n, &mul3(c, &step.eps_n));
    let de: [f64; V] = std::array::from_fn(|i| step.eps[i] - step.eps_n[i]);
    let dd = d - dn;
    let w = 1.0 - d;
    PointResponse {
        sigma: ce.map(|x| w * x),
        // The secant, when the pass assembles it.
        tangent: if step.tangent {
            c.map(|row| row.map(|x| w * x))
        } else {
            *c
        },
        psi: w * y1,
        dissipation: Dissipation {
            damage: 0.5 * (y0 + y1) * dd,
            // σ¹:Δε − Δψ − ΔW_d in closed form (theory/damage.md).
            numerical: 0.5 * w * dot3(&de, &mul3(c, &de)) - 0.5 * dd * (y1 - y0),
            ..Default::default()
        },
        status: PointStatus::Ok,
    }
}

impl Constitutive for MazarsParams {
    fn name(&self) -> &'static str {
        "mazars"
    }

    fn parameters(&self) -> Vec<(&'static str, String)> {
        let p = self;
        let mut v = vec![
            ("variant", format!("{:?}", p.variant).to_lowercase()),
            ("eps_t0", sig(p.eps_t0)),
        ];
        if p.variant == MazarsVariant::Paper {
            v.push(("eps_c0", sig(p.eps_c0)));
        }
        match p.regularisation {
            Regularisation::CrackBand { fracture_energy } => {
                v.push(("A_t", "1 (crack band)".into()));
                v.push(("B_t", "per element from G_f (crack band)".into()));
                v.push(("fracture_energy", sig(fracture_energy)));
            }
            _ => {
                v.push(("A_t", sig(p.a_t)));
                v.push(("B_t", sig(p.b_t)));
            }
        }
        v.push(("A_c", sig(p.a_c)));
        v.push(("B_c", sig(p.b_c)));
        if p.variant == MazarsVariant::Classic {
            v.push(("beta", sig(p.beta)));
        }
        v.push(("d_max", format!("{}", p.d_max)));
        v.push(("regularisation", p.regularisation.name().into()));
        if let Regularisation::Nonlocal { radius } = p.regularisation {
            v.push(("radius", sig(radius)));
        }
        v
    }

    fn regularisation(&self) -> Option<&'static str> {
        Some(self.regularisation.name())
    }

    /// `[k1, k2, D]` (paper: `ε_t*, ε_c*`; classic: `κ, 0`).
    fn n_state(&self, _voigt: usize) -> usize {
        3
    }

    fn state_names(&self, _voigt: usize) -> &'static [&'static str] {
        match self.variant {
            MazarsVariant::Paper => &["eps_t_max", "eps_c_max", "damage"],
            MazarsVariant::Classic => &["kappa", "unused", "damage"],
        }
    }

    fn output_fields(&self, state: &[f64], _voigt: usize) -> (f64, f64) {
        (state[2], 0.0)
    }

    fn tangent_kind(&self) -> TangentKind {
        TangentKind::StateDependent
    }

    fn is_rate_independent(&self) -> bool {
        true
    }

    fn has_frozen_form(&self) -> bool {
        true
    }

    fn nonlocal_radius(&self) -> Option<f64> {
        match self.regularisation {
            Regularisation::Nonlocal { radius } => Some(radius),
            _ => None,
        }
    }

    fn n_drivers(&self) -> usize {
        2
    }

    fn drivers<const V: usize, K: StrainSpace<V>>(
        &self,
        moduli: Moduli,
        eps: &[f64; V],
    ) -> [f64; MAX_DRIVERS] {
        drivers::<V, K>(self, moduli.nu, eps)
    }

    /// A history maximum (or its threshold) below the bound.
    fn drivers_can_grow(&self, bound: [f64; MAX_DRIVERS], h: &[f64]) -> bool {
        match self.variant {
            MazarsVariant::Paper => {
                bound[0] > h[0].max(self.eps_t0) || bound[1] > h[1].max(self.eps_c0)
            }
            MazarsVariant::Classic => bound[0] > h[0].max(self.eps_t0),
        }
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
        update::<V, K>(self, c, moduli.nu, step, averaged, state_n, state)
    }

    /// `D = D⁰`: the secant of the last step.
    fn update_frozen<const V: usize, K: StrainSpace<V>>(
        &self,
        _moduli: Moduli,
        c: &[[f64; V]; V],
        step: &StrainStep<V>,
        state_n: &[f64],
        state: &mut [f64],
    ) -> PointResponse<V> {
        frozen(c, step, state_n, state)
    }

    /// The stress at the trial damage: with the strain unchanged neither the
    /// history maxima nor the damage grow (the local law at the committed strain
    /// returns at most the committed `D`; a nonlocal average is not re-evaluated for
    /// a prediction).
    fn predicted_stress<const V: usize, K: StrainSpace<V>>(
        &self,
        _moduli: Moduli,
        c: &[[f64; V]; V],
        eps: &[f64; V],
        state: &[f64],
        _dt: f64,
    ) -> [f64; V] {
        let w = 1.0 - state[2];
        let s = mul3(c, eps);
        s.map(|x| w * x)
    }
}
