//! Rankine-Hill plasticity, isotropic, in plane stress and in a solid (after
//! Lourenço, de Borst & Rots 1997, isotropic case): Rankine (maximum principal
//! stress) in tension, Hill in compression, which for an isotropic material is von
//! Mises. Associated flow, one hardening/softening variable per criterion.
//!
//! The return mapping works in the principal frame of the trial stress (isotropy
//! keeps the return coaxial), written once for `P` principal values (2 in plane
//! stress, 3 in a solid): surfaces `Ra: σa − σ̄_t(κ_t)` for each principal stress and
//! `VM: q(σ) − σ̄_c(κ_c)` with `q² = Σ σa² − Σ_{a<b} σa σb`; `κ_t = Σ Δλ_R`,
//! `κ_c = Δλ_VM`. Closest-point projection by Newton on `(σ, Δλ_active)` with an
//! active-set loop over the faces, the corners (R1+VM, R1+R2, R1+R2+VM, ...) and in
//! a solid the apex R1+R2+R3; consistent tangent from the local Jacobian plus the
//! spectral shear terms, rotated out of the frame ([`crate::fe::frame`]). Plastic dissipation: the paper's trapezoid
//! `½(σⁿ + σⁿ⁺¹):Δεᵖ` evaluated per surface as `½(σ̄(κⁿ) + σ̄(κⁿ⁺¹)) Δλ`, each stress
//! paired with its own flow direction. See `theory/plasticity.md`.

mod return_map;

pub use return_map::{n_state, update};

use super::hardening::{Hardening, PreparedLaw};
use super::point::{Constitutive, Moduli, PointResponse, StrainStep, TangentKind, MAX_DRIVERS};
use crate::fe::frame::{Frame, SolidFrame};
use crate::fe::{FrameUser, Idealisation, Solid, StrainSpace};

/// Rankine-Hill parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RankineHillParams {
    /// Tension law (Rankine surfaces).
    pub tension: Hardening,
    /// Compression law (von Mises surface).
    pub compression: Hardening,
    /// The laws' strengths before any plastic flow (`κ = 0`) at the material's
    /// Young's modulus: the elastic check of a point that never yielded reads them
    /// instead of evaluating the laws ([`RankineHillParams::new`] sets them).
    pub initial: [f64; 2],
    /// The tension and compression laws prepared for that modulus (the returns
    /// evaluate them at every iteration).
    pub prepared: [PreparedLaw; 2],
}

impl RankineHillParams {
    /// The parameters of the two laws for a material of Young's modulus `e`.
    pub fn new(tension: Hardening, compression: Hardening, e: f64) -> Self {
        RankineHillParams {
            tension,
            compression,
            initial: [tension.initial(e), compression.initial(e)],
            prepared: [tension.prepared(e), compression.prepared(e)],
        }
    }
}

/// The update of a point of the idealisation `K`: the return in `K`'s principal
/// frame ([`StrainSpace::with_frame`]); in plane strain, the solid's return with
/// `ε_zz = γ_yz = γ_zx = 0` (the out-of-plane axis stays principal, so the plastic
/// strain keeps no out-of-plane shear). The plane-strain state
/// `[εᵖ_xx, εᵖ_yy, γᵖ_xy, κ_t, κ_c, εᵖ_zz]` is the solid's `[εᵖ (6), κ_t, κ_c]`
/// rearranged; its stress and tangent are the in-plane rows and columns (`σ_zz` is
/// carried by the state, not output).
pub fn update_in<const V: usize, K: StrainSpace<V>>(
    p: &RankineHillParams,
    c: &[[f64; V]; V],
    e: f64,
    nu: f64,
    step: &StrainStep<V>,
    state_n: &[f64],
    state: &mut [f64],
) -> PointResponse<V> {
    if K::IDEALISATION != Idealisation::PlaneStrain {
        return K::with_frame(FramedReturn {
            p,
            c,
            e,
            nu,
            step,
            state_n,
            state,
        });
    }
    let widen = |x: &[f64; V]| [x[0], x[1], x[2], 0.0, 0.0, 0.0];
    let solid_step = StrainStep {
        eps_n: widen(&step.eps_n),
        eps: widen(&step.eps),
        dt: step.dt,
        length: step.length,
        tangent: step.tangent,
    };
    let s = state_n;
    let solid_n = [s[0], s[1], s[2], s[5], 0.0, 0.0, s[3], s[4]];
    let mut solid = [0.0; 8];
    let r = update::<6, 3, SolidFrame>(
        p,
        &Solid::elasticity(e, nu),
        e,
        nu,
        &solid_step,
        &solid_n,
        &mut solid,
    );
    for (k, &i) in [0, 1, 2, 6, 7, 3].iter().enumerate() {
        state[k] = solid[i];
    }
    PointResponse {
        sigma: std::array::from_fn(|i| r.sigma[i]),
        tangent: std::array::from_fn(|i| std::array::from_fn(|j| r.tangent[i][j])),
        psi: r.psi,
        dissipation: r.dissipation,
        status: r.status,
    }
}

/// The arguments of a return, run in the principal frame its space hands it.
struct FramedReturn<'a, const V: usize> {
    p: &'a RankineHillParams,
    c: &'a [[f64; V]; V],
    e: f64,
    nu: f64,
    step: &'a StrainStep<V>,
    state_n: &'a [f64],
    state: &'a mut [f64],
}

impl<const V: usize> FrameUser<V> for FramedReturn<'_, V> {
    type Output = PointResponse<V>;
    fn run<const P: usize, F: Frame<V, P>>(self) -> PointResponse<V> {
        update::<V, P, F>(
            self.p,
            self.c,
            self.e,
            self.nu,
            self.step,
            self.state_n,
            self.state,
        )
    }
}

impl Constitutive for RankineHillParams {
    fn name(&self) -> &'static str {
        "rankine_hill"
    }

    fn parameters(&self) -> Vec<(&'static str, String)> {
        vec![
            ("tension", self.tension.describe()),
            ("compression", self.compression.describe()),
        ]
    }

    /// A softening tension law is regularised by the crack band.
    fn regularisation(&self) -> Option<&'static str> {
        matches!(self.tension, Hardening::LinearSoftening { .. }).then_some("crack_band")
    }

    /// The plastic strains and `κ_t, κ_c`; the plane keeps a sixth value, `εᵖ_zz`,
    /// which plane strain's return through the solid's needs (zero in plane
    /// stress).
    fn n_state(&self, voigt: usize) -> usize {
        if voigt == 3 {
            n_state(voigt) + 1
        } else {
            n_state(voigt)
        }
    }

    fn state_names(&self, voigt: usize) -> &'static [&'static str] {
        if voigt == 3 {
            &[
                "eps_p_xx",
                "eps_p_yy",
                "gamma_p_xy",
                "kappa_t",
                "kappa_c",
                "eps_p_zz",
            ]
        } else {
            &[
                "eps_p_xx",
                "eps_p_yy",
                "gamma_p_xy",
                "eps_p_zz",
                "gamma_p_yz",
                "gamma_p_zx",
                "kappa_t",
                "kappa_c",
            ]
        }
    }

    /// The equivalent plastic strain `κ_t + κ_c`.
    fn output_fields(&self, state: &[f64], voigt: usize) -> (f64, f64) {
        (0.0, state[voigt] + state[voigt + 1])
    }

    fn tangent_kind(&self) -> TangentKind {
        TangentKind::StateDependent
    }

    fn is_rate_independent(&self) -> bool {
        true
    }

    fn update<const V: usize, K: StrainSpace<V>>(
        &self,
        moduli: Moduli,
        c: &[[f64; V]; V],
        step: &StrainStep<V>,
        _averaged: Option<[f64; MAX_DRIVERS]>,
        state_n: &[f64],
        state: &mut [f64],
    ) -> PointResponse<V> {
        update_in::<V, K>(self, c, moduli.e, moduli.nu, step, state_n, state)
    }
}
