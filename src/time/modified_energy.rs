//! Generalized-α's modified energy: what the scheme stores besides `E_kin + E_el`,
//! so that `E_kin + E_el + E_alg` never grows in a step of a linear undamped system
//! (`theory/trapezoidal.md`, "The modified energy"). With `δ = γ − ½ = (1 − ρ∞)/(1 + ρ∞)`
//! and the out-of-balance `r = M a − (f_ext − f_int − C v + f_c)`,
//!
//! `E_alg = (δ/2) h v·r + δ² h² (¼ r·M⁻¹r + ¼ a·r + ⅜ a·M a)`,
//!
//! on the free dofs. The trapezoidal rule (`δ = 0`) stores none.

use super::generalized_alpha::Alpha;
use super::operators::Operators;
use super::step_start::{mass_solve, out_of_balance};
use super::State;

/// `E_alg` of the state `s` at generalized-α's step `ops.h()` with parameters
/// `alpha`; `contact` the contact forces the state's acceleration saw.
pub(crate) fn of(ops: &Operators, alpha: &Alpha, s: &State, contact: Option<&[f64]>) -> f64 {
    let delta = alpha.gamma - 0.5;
    if delta == 0.0 || s.a.is_empty() {
        return 0.0;
    }
    let h = ops.h();
    let n = s.a.len();
    let mut ma = vec![0.0; n];
    ops.mass.matvec(&ops.asm.pattern, &s.a, &mut ma);
    let b = out_of_balance(ops, s, contact);
    let r: Vec<f64> = (0..n).map(|d| ops.free_mask[d] * ma[d] - b[d]).collect();
    // A mass solve that stops short leaves r·M⁻¹r a little low: the booking's
    // error, not the state's (the tolerance is round-off for any FE mass).
    let (m_inv_r, _) = mass_solve(ops, &r);
    let dot = |x: &[f64], y: &[f64]| -> f64 { x.iter().zip(y).map(|(a, b)| a * b).sum() };
    let a_ma: f64 = (0..n).map(|d| ops.free_mask[d] * s.a[d] * ma[d]).sum();
    0.5 * delta * h * dot(&s.v, &r)
        + delta * delta * h * h * (0.25 * dot(&r, &m_inv_r) + 0.25 * dot(&s.a, &r) + 0.375 * a_ma)
}
