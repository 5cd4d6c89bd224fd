//! Strength laws `σ̄(κ)` of one yield surface, with `H = dσ̄/dκ`: bilinear hardening,
//! the Eurocode 2 compression curve, and linear tension softening regularised by
//! the fracture energy and the element size (crack band).

/// A strength law in terms of the surface's plastic multiplier sum `κ`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Hardening {
    /// Yield at `strength`, then the uniaxial diagram rises with the post-yield
    /// modulus `E_t`: `σ̄ = f_y + H κ`, `H = E E_t/(E − E_t)`.
    Bilinear {
        /// Initial yield stress (Pa).
        strength: f64,
        /// Post-yield modulus `E_t` of the uniaxial diagram (Pa).
        post_yield_modulus: f64,
    },
    /// Eurocode 2 compression curve `σ/f_cm = (kη − η²)/(1 + (k−2)η)`, `η = ε/ε_c1`,
    /// `k = 1.05 E ε_c1/f_cm`, elastic up to where its secant meets `E`, followed to
    /// `ε_cu1` and constant beyond.
    Ec2 {
        /// Mean compressive strength (Pa).
        f_cm: f64,
        /// Strain at peak.
        eps_c1: f64,
        /// Ultimate strain.
        eps_cu1: f64,
    },
    /// Linear softening from `strength` to zero over the plastic strain
    /// `κ_u = 2 G_f / (f_t h)`, `h` the element size.
    LinearSoftening {
        /// Tensile strength (Pa).
        strength: f64,
        /// Fracture energy (N/m).
        fracture_energy: f64,
    },
}

fn ec2_curve(f_cm: f64, eps_c1: f64, k: f64, eps: f64) -> (f64, f64) {
    let eta = eps / eps_c1;
    let den = 1.0 + (k - 2.0) * eta;
    let s = f_cm * (k * eta - eta * eta) / den;
    let ds =
        f_cm / eps_c1 * ((k - 2.0 * eta) * den - (k * eta - eta * eta) * (k - 2.0)) / (den * den);
    (s, ds)
}

impl Hardening {
    /// The law and its parameters in the scenario's words, for `check` and `material`.
    pub fn describe(&self) -> String {
        match *self {
            Hardening::Bilinear {
                strength,
                post_yield_modulus,
            } => format!(
                "bilinear, strength = {}, post_yield_modulus = {}",
                super::point::sig(strength),
                super::point::sig(post_yield_modulus)
            ),
            Hardening::Ec2 {
                f_cm,
                eps_c1,
                eps_cu1,
            } => format!(
                "ec2, f_cm = {}, eps_c1 = {}, eps_cu1 = {}",
                super::point::sig(f_cm),
                super::point::sig(eps_c1),
                super::point::sig(eps_cu1)
            ),
            Hardening::LinearSoftening {
                strength,
                fracture_energy,
            } => format!(
                "linear_softening, strength = {}, fracture_energy = {}",
                super::point::sig(strength),
                super::point::sig(fracture_energy)
            ),
        }
    }

    /// Initial yield stress.
    pub fn initial(&self, e: f64) -> f64 {
        self.strength(0.0, e, 1.0).0
    }

    /// `(σ̄(κ), dσ̄/dκ)` for Young's modulus `e` and element size `h`.
    pub fn strength(&self, kappa: f64, e: f64, h: f64) -> (f64, f64) {
        match *self {
            Hardening::Bilinear {
                strength,
                post_yield_modulus,
            } => {
                let hh = e * post_yield_modulus / (e - post_yield_modulus);
                let y = strength + hh * kappa;
                // A softening diagram ends at zero strength.
                if y > 0.0 {
                    (y, hh)
                } else {
                    (0.0, 0.0)
                }
            }
            Hardening::LinearSoftening {
                strength,
                fracture_energy,
            } => {
                let ku = 2.0 * fracture_energy / (strength * h);
                if kappa < ku {
                    (strength * (1.0 - kappa / ku), -strength / ku)
                } else {
                    (0.0, 0.0)
                }
            }
            Hardening::Ec2 {
                f_cm,
                eps_c1,
                eps_cu1,
            } => Ec2Curve::new(f_cm, eps_c1, eps_cu1, e).strength(kappa),
        }
    }

    /// The law with what depends only on its parameters and `e` worked out once
    /// (the Eurocode 2 curve's constants); the others as they are.
    pub fn prepared(&self, e: f64) -> PreparedLaw {
        match *self {
            Hardening::Ec2 {
                f_cm,
                eps_c1,
                eps_cu1,
            } => PreparedLaw::Ec2(Ec2Curve::new(f_cm, eps_c1, eps_cu1, e)),
            law => PreparedLaw::Law(law),
        }
    }
}

/// A strength law ready for a material's Young's modulus ([`Hardening::prepared`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PreparedLaw {
    /// The Eurocode 2 curve with its constants.
    Ec2(Ec2Curve),
    /// A law that has nothing to prepare.
    Law(Hardening),
}

impl PreparedLaw {
    /// `(σ̄(κ), dσ̄/dκ)` for Young's modulus `e` (the one it was prepared for, when it
    /// was) and element size `h`: the same values as [`Hardening::strength`].
    #[inline]
    pub fn strength(&self, kappa: f64, e: f64, h: f64) -> (f64, f64) {
        match self {
            PreparedLaw::Ec2(c) => c.strength(kappa),
            PreparedLaw::Law(law) => law.strength(kappa, e, h),
        }
    }
}

/// The Eurocode 2 compression curve for one Young's modulus, with its constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ec2Curve {
    f_cm: f64,
    eps_c1: f64,
    e: f64,
    /// `k = 1.05 E ε_c1 / f_cm`.
    k: f64,
    /// The strain where the curve's secant meets `E` (yield).
    eps_y: f64,
    /// The strength at the ultimate strain, and its `κ`.
    s_cu: f64,
    kappa_cu: f64,
    /// `a = E ε_c1 (k − 2) + f_cm` of the quadratic below.
    a: f64,
}

impl Ec2Curve {
    /// The curve of `f_cm, ε_c1, ε_cu1` for Young's modulus `e`.
    pub fn new(f_cm: f64, eps_c1: f64, eps_cu1: f64, e: f64) -> Self {
        let k = 1.05 * e * eps_c1 / f_cm;
        // Yield where the secant of the curve meets E: k − η = (k/1.05)(1 + (k−2)η).
        let eta_y = (k - k / 1.05) / (1.0 + k / 1.05 * (k - 2.0));
        let (s_cu, _) = ec2_curve(f_cm, eps_c1, k, eps_cu1);
        Ec2Curve {
            f_cm,
            eps_c1,
            e,
            k,
            eps_y: eta_y * eps_c1,
            s_cu,
            kappa_cu: eps_cu1 - s_cu / e,
            a: e * eps_c1 * (k - 2.0) + f_cm,
        }
    }

    /// `(σ̄(κ), dσ̄/dκ)`, constant beyond the ultimate strain.
    #[inline]
    pub fn strength(&self, kappa: f64) -> (f64, f64) {
        let Ec2Curve {
            f_cm,
            eps_c1,
            e,
            k,
            eps_y,
            s_cu,
            kappa_cu,
            a,
        } = *self;
        if kappa >= kappa_cu {
            return (s_cu, 0.0);
        }
        // ε − σ(ε)/E = κ is, with η = ε/ε_c1 and the curve's denominator multiplied
        // out, the quadratic a η² + b η + c = 0 with a = E ε_c1 (k − 2) + f_cm > 0
        // (k² − 2k + 1.05 has no real root), b = E ε_c1 − E κ (k − 2) − f_cm k and
        // c = −E κ ≤ 0: its roots have opposite signs (or are 0 and η_y at κ = 0),
        // and the curve's branch is the positive one, taken in the form without
        // cancellation.
        let b = e * eps_c1 - e * kappa * (k - 2.0) - f_cm * k;
        let c = -e * kappa;
        let q = -0.5 * (b + b.signum() * (b * b - 4.0 * a * c).max(0.0).sqrt());
        let eta = if q == 0.0 { 0.0 } else { (q / a).max(c / q) };
        let eps = (eta * eps_c1).max(eps_y);
        let (s, ds) = ec2_curve(f_cm, eps_c1, k, eps);
        (s, ds / (1.0 - ds / e))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Eurocode 2 strength in closed form: at every `κ` up to the ultimate strain
    /// the strain `ε` it comes from satisfies `ε − σ(ε)/E = κ` (found here by
    /// bisection, independently of the quadratic), the strength is `σ(ε)`, and the
    /// slope is the finite difference of the strength.
    #[test]
    fn the_ec2_strength_inverts_the_plastic_strain_of_the_curve() {
        let (f_cm, eps_c1, eps_cu1) = (38e6, 2.2e-3, 3.5e-3);
        for e in [33e9, 25e9, 40e9] {
            let law = Hardening::Ec2 {
                f_cm,
                eps_c1,
                eps_cu1,
            };
            let k = 1.05 * e * eps_c1 / f_cm;
            let kap = |eps: f64| eps - ec2_curve(f_cm, eps_c1, k, eps).0 / e;
            let kappa_u = kap(eps_cu1);
            let eta_y = (k - k / 1.05) / (1.0 + k / 1.05 * (k - 2.0));
            let (s0, _) = law.strength(0.0, e, 1.0);
            assert!((s0 - e * eta_y * eps_c1).abs() <= 1e-9 * s0, "{s0}");
            for i in 0..40 {
                let kappa = kappa_u * i as f64 / 40.0;
                let (mut lo, mut hi) = (eta_y * eps_c1, eps_cu1);
                for _ in 0..200 {
                    let mid = 0.5 * (lo + hi);
                    if kap(mid) > kappa {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                let expected = ec2_curve(f_cm, eps_c1, k, 0.5 * (lo + hi)).0;
                let (s, h) = law.strength(kappa, e, 1.0);
                assert!(
                    (s - expected).abs() <= 1e-9 * f_cm,
                    "E = {e}, kappa = {kappa}: {s} against {expected}"
                );
                let dk = 1e-7 * kappa_u;
                let fd = (law.strength(kappa + dk, e, 1.0).0 - law.strength(kappa, e, 1.0).0) / dk;
                assert!(
                    (h - fd).abs() <= 1e-4 * h.abs() + 1e-6 * e,
                    "E = {e}, kappa = {kappa}: slope {h} against {fd}"
                );
            }
            // Beyond the ultimate strain the strength stays at the curve's end.
            let (s_end, h_end) = law.strength(2.0 * kappa_u, e, 1.0);
            assert_eq!(h_end, 0.0);
            assert!((s_end - ec2_curve(f_cm, eps_c1, k, eps_cu1).0).abs() <= 1e-9 * f_cm);
        }
    }
}
