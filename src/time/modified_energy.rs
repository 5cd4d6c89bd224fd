//! Generalized-α's modified energy: what the scheme stores besides `E_kin + E_el`,
//! so that `E_kin + E_el + E_alg` never grows in a step of a linear undamped system
//! (`theory/trapezoidal.md`, "The modified energy"). With `δ = γ − ½ = (1 − ρ∞)/(1 + ρ∞)`
//! and the out-of-balance `r = M a − (f_ext − f_int − C v + f_c)`,
//!
//! `E_alg = (δ/2) h v·r + δ² h² (¼ r·M⁻¹r + ¼ a·r + ⅜ a·M a)`,
//!
//! on the free dofs. The trapezoidal rule (`δ = 0`) stores none. `M⁻¹r` is carried
//! from step to step ([`State::m_inv_r`]): the step's own equation gives it but for
//! the change of the contact forces, so the mass solve that checks it starts from
//! that and has little or nothing to do.

use super::generalized_alpha::Alpha;
use super::operators::Operators;
use super::step_start::{mass_solve_from, out_of_balance};
use super::State;

/// The relative residual of `M y = r` at which the booking's mass solve stops: the
/// `r·M⁻¹r` term is then off by about this fraction of itself, below `1e-9` of
/// `E_alg`.
const SOLVE_TOLERANCE: f64 = 1e-9;

/// `M⁻¹r_{n+1}` as the step's equation gives it from `M⁻¹r_n` (`m_inv_r_n`, empty
/// for zero) and the accelerations: `M a_{n+1−α_m} + (1 − α_f) g_{n+1} + α_f g_n = 0`
/// with `r = M a + g` makes `r_{n+1} = c M (a_{n+1} − a_n) − κ r_n`, `c = (α_m −
/// α_f)/(1 − α_f)`, `κ = α_f/(1 − α_f)` (exact without contact, whose force sits at
/// the step's end alone: its change is left to the solve).
pub(crate) fn carried(alpha: &Alpha, a_np1: &[f64], a_n: &[f64], m_inv_r_n: &[f64]) -> Vec<f64> {
    let c = (alpha.alpha_m - alpha.alpha_f) / (1.0 - alpha.alpha_f);
    let kappa = alpha.alpha_f / (1.0 - alpha.alpha_f);
    (0..a_np1.len())
        .map(|d| c * (a_np1[d] - a_n[d]) - kappa * m_inv_r_n.get(d).copied().unwrap_or(0.0))
        .collect()
}

/// `E_alg` of the state `s` at generalized-α's step `ops.h()` with parameters
/// `alpha`, `M a` of the state, and `M⁻¹r` of the state: `guess` itself when `exact` (a step without
/// contact forces at either end, where [`carried`] is the equation's own), else
/// conjugate gradients from it to round-off of the forces; `contact` the contact
/// forces the state's acceleration saw.
pub(crate) fn of(
    ops: &Operators,
    alpha: &Alpha,
    s: &State,
    contact: Option<&[f64]>,
    guess: Vec<f64>,
    exact: bool,
) -> Booked {
    let delta = alpha.gamma - 0.5;
    let n = s.a.len();
    if delta == 0.0 || n == 0 {
        return Booked::default();
    }
    let h = ops.h();
    let mut ma = vec![0.0; n];
    ops.mass.matvec(&ops.asm.pattern, &s.a, &mut ma);
    let b = out_of_balance(ops, s, contact);
    let r: Vec<f64> = (0..n).map(|d| ops.free_mask[d] * ma[d] - b[d]).collect();
    let dot = |x: &[f64], y: &[f64]| -> f64 { x.iter().zip(y).map(|(a, b)| a * b).sum() };
    // r is a difference of forces: below their round-off it is not known, and the
    // solve need not go further. A solve that stops short leaves r·M⁻¹r a little
    // off: the booking's error, not the state's.
    let m_inv_r = if exact {
        guess
    } else {
        let floor = (SOLVE_TOLERANCE * dot(&r, &r).sqrt())
            .max(1e-13 * (dot(&ma, &ma).sqrt() + dot(&b, &b).sqrt()));
        mass_solve_from(ops, &r, guess, floor).0
    };
    let a_ma: f64 = (0..n).map(|d| ops.free_mask[d] * s.a[d] * ma[d]).sum();
    let e = 0.5 * delta * h * dot(&s.v, &r)
        + delta * delta * h * h * (0.25 * dot(&r, &m_inv_r) + 0.25 * dot(&s.a, &r) + 0.375 * a_ma);
    Booked {
        energy: e,
        ma,
        m_inv_r,
    }
}

/// What [`of`] finds of a state.
#[derive(Debug, Default)]
pub(crate) struct Booked {
    /// `E_alg`.
    pub energy: f64,
    /// `M a` (empty when `E_alg` is zero by the parameters).
    pub ma: Vec<f64>,
    /// `M⁻¹r` (likewise).
    pub m_inv_r: Vec<f64>,
}
