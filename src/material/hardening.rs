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
                super::sig(strength),
                super::sig(post_yield_modulus)
            ),
            Hardening::Ec2 {
                f_cm,
                eps_c1,
                eps_cu1,
            } => format!(
                "ec2, f_cm = {}, eps_c1 = {}, eps_cu1 = {}",
                super::sig(f_cm),
                super::sig(eps_c1),
                super::sig(eps_cu1)
            ),
            Hardening::LinearSoftening {
                strength,
                fracture_energy,
            } => format!(
                "linear_softening, strength = {}, fracture_energy = {}",
                super::sig(strength),
                super::sig(fracture_energy)
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
            } => {
                let k = 1.05 * e * eps_c1 / f_cm;
                // Yield where the secant of the curve meets E: k − η = (k/1.05)(1 + (k−2)η).
                let eta_y = (k - k / 1.05) / (1.0 + k / 1.05 * (k - 2.0));
                let eps_y = eta_y * eps_c1;
                // Solve ε − σ(ε)/E = κ for ε on [ε_y, ε_cu1] (monotone there).
                let kap = |eps: f64| eps - ec2_curve(f_cm, eps_c1, k, eps).0 / e;
                if kappa >= kap(eps_cu1) {
                    return (ec2_curve(f_cm, eps_c1, k, eps_cu1).0, 0.0);
                }
                let (mut lo, mut hi) = (eps_y, eps_cu1);
                let mut eps = eps_y + kappa;
                for _ in 0..100 {
                    let (s, ds) = ec2_curve(f_cm, eps_c1, k, eps);
                    let g = eps - s / e - kappa;
                    if g.abs() < 1e-15 * eps_cu1 {
                        break;
                    }
                    if g > 0.0 {
                        hi = eps;
                    } else {
                        lo = eps;
                    }
                    let next = eps - g / (1.0 - ds / e);
                    eps = if next > lo && next < hi {
                        next
                    } else {
                        0.5 * (lo + hi)
                    };
                }
                let (s, ds) = ec2_curve(f_cm, eps_c1, k, eps);
                (s, ds / (1.0 - ds / e))
            }
        }
    }
}
