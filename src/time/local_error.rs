//! Local error estimates of the implicit schemes, the measure an error-controlled
//! step will be chosen by (`theory/adaptive.md`).
//!
//! The local error of a step is `e_u = u(t_{n+1}) − u_{n+1}`, the exact solution
//! through the step's start minus the step's result, to leading order:
//! - backward Euler (Milne's device): `e_u = −(h/2)(v_{n+1} − v_n)`;
//! - the Newmark family and generalized-α (Zienkiewicz and Xie's estimate, with
//!   generalized-α's shift of its accelerations): `e_u = −c h² (a_{n+1} − a_n)`,
//!   `c = β − 1/6 + (α_m − α_f)/2` (the trapezoidal rule: `1/12`).
//!
//! - the trapezoidal rule, which carries no acceleration (its averaged-force form):
//!   the same estimate with `a_{n+1} − a_n` replaced by the change of the mean
//!   accelerations `ā = Δv/h` of two successive steps, scaled to the step
//!   ([`mean_acceleration`]).
//!
//! Both are measured in the energy norm, relative to the energy of the state:
//! `η = √(½ e_uᵀ K e_u / E)`.

use super::generalized_alpha::Alpha;

/// Backward Euler's displacement error of a step (Milne's device):
/// `e = −(h/2)(v_new − v_old)`, written into `e`.
pub fn backward_euler(h: f64, v_old: &[f64], v_new: &[f64], e: &mut [f64]) {
    for ((e, a), b) in e.iter_mut().zip(v_old).zip(v_new) {
        *e = -0.5 * h * (b - a);
    }
}

/// The coefficient `c` of the Newmark family's displacement error
/// `e = −c h² (a_{n+1} − a_n)`: `c = β − 1/6 + (α_m − α_f)/2`. Generalized-α's
/// accelerations approximate `a(t_n + (α_m − α_f) h)` to second order, which shifts
/// Zienkiewicz and Xie's `β − 1/6` (plain Newmark, `α_m = α_f = 0`) by
/// `(α_m − α_f)/2`; the trapezoidal rule (`α_m = α_f = ½`, `β = ¼`) gives `1/12`.
pub fn newmark_coefficient(rho_inf: f64) -> f64 {
    coefficient(&Alpha::of(rho_inf))
}

pub(crate) fn coefficient(p: &Alpha) -> f64 {
    p.beta - 1.0 / 6.0 + 0.5 * (p.alpha_m - p.alpha_f)
}

/// The Newmark family's displacement error of a step: `e = −c h² (a_new − a_old)`
/// with `c` from [`newmark_coefficient`], written into `e`.
pub fn newmark(c: f64, h: f64, a_old: &[f64], a_new: &[f64], e: &mut [f64]) {
    for ((e, a), b) in e.iter_mut().zip(a_old).zip(a_new) {
        *e = -c * h * h * (b - a);
    }
}

/// The trapezoidal rule's displacement error of a step of size `h` from the mean
/// accelerations `ā = Δv/h` of the previous step (`abar_old`, size `h_old`) and of
/// this one (`abar_new`): `e = −c h² (ā_new − ā_old) · 2h/(h + h_old)`. The mean
/// accelerations approximate `ü` at the steps' midpoints, `(h + h_old)/2` apart, so
/// the scaled difference is `h u⃛`, what `a_{n+1} − a_n` is to leading order.
pub fn mean_acceleration(
    c: f64,
    (h_old, abar_old): (f64, &[f64]),
    (h, abar_new): (f64, &[f64]),
    e: &mut [f64],
) {
    let scale = -c * h * h * 2.0 * h / (h + h_old);
    for ((e, a), b) in e.iter_mut().zip(abar_old).zip(abar_new) {
        *e = scale * (b - a);
    }
}

/// What a run's error estimate carries from one accepted step to the next (the
/// trapezoidal rule's mean acceleration) and its scratch.
#[derive(Clone, Debug, Default)]
pub struct Estimator {
    /// The last accepted step's size and mean acceleration (empty before the first).
    previous: (f64, Vec<f64>),
    /// The judged step's mean acceleration, committed with the step.
    candidate: (f64, Vec<f64>),
    /// The error and `K e` (scratch).
    pub(crate) e: Vec<f64>,
    pub(crate) ke: Vec<f64>,
}

impl Estimator {
    /// The trapezoidal rule's error of the step `h` from `v_old` to `v_new` into
    /// `self.e`; `false` (nothing written) for the first step, which has no previous
    /// mean acceleration.
    pub(crate) fn trapezoidal(&mut self, h: f64, v_old: &[f64], v_new: &[f64]) -> bool {
        let (hc, abar) = &mut self.candidate;
        *hc = h;
        abar.clear();
        abar.extend(v_new.iter().zip(v_old).map(|(b, a)| (b - a) / h));
        let (h_old, old) = &self.previous;
        if old.len() != abar.len() {
            return false;
        }
        self.e.resize(abar.len(), 0.0);
        mean_acceleration(1.0 / 12.0, (*h_old, old), (h, abar), &mut self.e);
        true
    }

    /// The judged step stands: its mean acceleration becomes the previous one.
    pub fn commit(&mut self) {
        if !self.candidate.1.is_empty() {
            std::mem::swap(&mut self.previous, &mut self.candidate);
            self.candidate.1.clear();
        }
    }
}

/// The relative energy measure `η = √(½ eᵀ K e / E)` of an error `e`, given
/// `k_e = K e` and the state's energy `E > 0` (zero energy: `η` is the error's own
/// energy, `√(½ eᵀKe)`, which is then what a tolerance bounds).
pub fn energy_measure(e: &[f64], k_e: &[f64], energy: f64) -> f64 {
    let ee: f64 = 0.5 * e.iter().zip(k_e).map(|(a, b)| a * b).sum::<f64>();
    if energy > 0.0 {
        (ee.max(0.0) / energy).sqrt()
    } else {
        ee.max(0.0).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One step of generalized-α (`rho_inf`; 1: the trapezoidal rule) on
    /// `ẍ + ω²x = 0` from `(x, v, a)`.
    fn alpha_step(s: [f64; 3], w: f64, h: f64, rho_inf: f64) -> [f64; 3] {
        let p = Alpha::of(rho_inf);
        let [x0, v0, a0] = s;
        let xp = x0 + h * v0 + h * h * (0.5 - p.beta) * a0;
        let a1 = -(p.alpha_m * a0 + w * w * ((1.0 - p.alpha_f) * xp + p.alpha_f * x0))
            / ((1.0 - p.alpha_m) + w * w * (1.0 - p.alpha_f) * p.beta * h * h);
        let x1 = xp + p.beta * h * h * a1;
        let v1 = v0 + h * ((1.0 - p.gamma) * a0 + p.gamma * a1);
        [x1, v1, a1]
    }

    #[test]
    fn the_estimates_are_the_schemes_local_errors_to_leading_order() {
        // x = cos t from t₀ = 0.7 (a phase where every derivative is present): one
        // step from the exact state (generalized-α's acceleration taken, as its
        // sequence carries it, at t₀ + (α_m − α_f)h). The estimate over the true
        // displacement error tends to 1 as h halves.
        let t0 = 0.7f64;
        let ratio = |h: f64, scheme: Option<f64>| -> f64 {
            let (x0, v0) = (t0.cos(), -t0.sin());
            let exact = (t0 + h).cos();
            let mut e = [0.0];
            match scheme {
                None => {
                    // Backward Euler: (1 + h²) x₁ = x₀ + h v₀, v₁ = (x₁ − x₀)/h.
                    let x1 = (x0 + h * v0) / (1.0 + h * h);
                    let v1 = (x1 - x0) / h;
                    backward_euler(h, &[v0], &[v1], &mut e);
                    e[0] / (exact - x1)
                }
                Some(rho) => {
                    let p = Alpha::of(rho);
                    let a0 = -(t0 + (p.alpha_m - p.alpha_f) * h).cos();
                    let [x1, _, a1] = alpha_step([x0, v0, a0], 1.0, h, rho);
                    newmark(newmark_coefficient(rho), h, &[a0], &[a1], &mut e);
                    e[0] / (exact - x1)
                }
            }
        };
        for scheme in [None, Some(1.0), Some(0.8), Some(0.5), Some(0.0)] {
            let (a, b) = (ratio(0.02, scheme), ratio(0.01, scheme));
            assert!(
                (b - 1.0).abs() < 0.02 && (b - 1.0).abs() < (a - 1.0).abs(),
                "{scheme:?}: estimate / error {a} at h = 0.02, {b} at 0.01"
            );
        }
        assert!((newmark_coefficient(1.0) - 1.0 / 12.0).abs() < 1e-15);
    }

    #[test]
    fn the_mean_acceleration_estimate_is_the_trapezoidal_rules_local_error() {
        // A trapezoidal step on x = cos t from the exact state at t₀ = 0.7, after a
        // previous step of another size: the estimate from the two mean
        // accelerations over the step's true error tends to 1.
        let t0 = 0.7f64;
        let ratio = |h: f64, h_old: f64| -> f64 {
            let trap = |x0: f64, v0: f64, h: f64| {
                // x₁ = x₀ + h(v₀ + v₁)/2, v₁ = v₀ − h(x₀ + x₁)/2.
                let x1 = (x0 * (1.0 - h * h / 4.0) + h * v0) / (1.0 + h * h / 4.0);
                (x1, 2.0 * (x1 - x0) / h - v0)
            };
            // The previous step's mean acceleration between exact velocities.
            let abar_old = [((t0 - h_old).sin() - t0.sin()) / h_old];
            let (x0, v0) = (t0.cos(), -t0.sin());
            let (x1, v1) = trap(x0, v0, h);
            let abar = [(v1 - v0) / h];
            let mut e = [0.0];
            mean_acceleration(1.0 / 12.0, (h_old, &abar_old), (h, &abar), &mut e);
            e[0] / ((t0 + h).cos() - x1)
        };
        for h_old in [0.5, 1.0, 2.0] {
            let (a, b) = (ratio(0.02, 0.02 * h_old), ratio(0.01, 0.01 * h_old));
            assert!(
                (b - 1.0).abs() < 0.03 && (b - 1.0).abs() < (a - 1.0).abs(),
                "previous step {h_old} h: estimate / error {a} at h = 0.02, {b} at 0.01"
            );
        }
    }

    #[test]
    fn the_energy_measure_is_relative_to_the_states_energy() {
        // K = diag(2, 8), e = (1, 0.5): ½ eᵀKe = 2; against E = 8, η = ½.
        let e = [1.0, 0.5];
        let ke = [2.0, 4.0];
        assert!((energy_measure(&e, &ke, 8.0) - 0.5).abs() < 1e-15);
        assert!((energy_measure(&e, &ke, 0.0) - 2f64.sqrt()).abs() < 1e-15);
    }
}
