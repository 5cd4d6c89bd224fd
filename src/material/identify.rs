//! Material identification from a concrete's own data: the Mazars parameters (both
//! variants) and the Rankine-Hill strength laws from `E, ν, f_ct, f_cm, ε_c1`, or
//! from a Eurocode 2 strength class.
//!
//! Mazars follows the identification code_aster's `DEFI_MATER_GC` uses for its
//! `MAZARS_UNIL` law (NOTES.md): the tensile peak `f_ct` at the threshold
//! `ε_t^0 = f_ct/E` (`A_t = 0.9`, `B_t = 1/ε_t^0`), the compressive threshold where
//! the lateral strains of uniaxial compression reach it, `ε_c^0 = ε_t^0/(ν√2)`, and
//! the compressive peak `f_cm` at `ε_c1` (`B_c = 1/ε_c1`, `A_c` from the peak value).
//! The classic law takes the same curves through its own equivalent strain
//! `ε̃ = ν√2 |ε|` in uniaxial compression, so its `B_c` is `1/(ν√2 ε_c1)`. Derivation
//! and checks: `theory/damage.md`, "Identification".

use super::mazars::MazarsVariant;
use super::Hardening;

/// The data a concrete is identified from (SI units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConcreteData {
    /// Young's modulus (Pa).
    pub e: f64,
    /// Poisson's ratio.
    pub nu: f64,
    /// Tensile strength `f_ct` (Pa).
    pub f_ct: f64,
    /// Mean compressive strength `f_cm` (Pa).
    pub f_cm: f64,
    /// Strain at the compressive peak `ε_c1` (positive).
    pub eps_c1: f64,
}

/// The strength classes of EN 1992-1-1 Table 3.1 with their `f_ck` (MPa).
pub const EC2_CLASSES: [(&str, f64); 14] = [
    ("C12/15", 12.0),
    ("C16/20", 16.0),
    ("C20/25", 20.0),
    ("C25/30", 25.0),
    ("C30/37", 30.0),
    ("C35/45", 35.0),
    ("C40/50", 40.0),
    ("C45/55", 45.0),
    ("C50/60", 50.0),
    ("C55/67", 55.0),
    ("C60/75", 60.0),
    ("C70/85", 70.0),
    ("C80/95", 80.0),
    ("C90/105", 90.0),
];

/// A Eurocode 2 strength class with the values of EN 1992-1-1 Table 3.1 (SI units).
#[derive(Clone, Debug, PartialEq)]
pub struct Ec2Class {
    /// Class name, e.g. `C30/37`.
    pub name: String,
    /// Characteristic cylinder strength `f_ck` (Pa).
    pub f_ck: f64,
    /// Mean compressive strength `f_cm = f_ck + 8 MPa` (Pa).
    pub f_cm: f64,
    /// Mean tensile strength `f_ctm` (Pa): `0.30 f_ck^{2/3}` up to C50/60,
    /// `2.12 ln(1 + f_cm/10)` above (MPa).
    pub f_ctm: f64,
    /// Secant modulus `E_cm = 22 (f_cm/10)^{0.3}` GPa (Pa).
    pub e_cm: f64,
    /// Strain at peak `ε_c1 = 0.7 f_cm^{0.31}` ‰, at most 2.8 ‰.
    pub eps_c1: f64,
    /// Ultimate strain `ε_cu1` ([`ec2_eps_cu1`]).
    pub eps_cu1: f64,
}

impl Ec2Class {
    /// The class called `name` (`C30/37`; case and spaces ignored), or `None`.
    pub fn named(name: &str) -> Option<Ec2Class> {
        let key: String = name
            .chars()
            .filter(|c| !c.is_whitespace())
            .collect::<String>()
            .to_uppercase();
        EC2_CLASSES
            .iter()
            .find(|(n, _)| *n == key)
            .map(|&(n, fck)| Ec2Class::of_fck(n, fck * 1e6))
    }

    /// The Table 3.1 relations for a characteristic strength `f_ck` (Pa).
    pub fn of_fck(name: &str, f_ck: f64) -> Ec2Class {
        let fck = f_ck / 1e6;
        let fcm = fck + 8.0;
        let fctm = if fck <= 50.0 {
            0.30 * fck.powf(2.0 / 3.0)
        } else {
            2.12 * (1.0 + fcm / 10.0).ln()
        };
        Ec2Class {
            name: name.to_string(),
            f_ck,
            f_cm: fcm * 1e6,
            f_ctm: fctm * 1e6,
            e_cm: 22.0 * (fcm / 10.0).powf(0.3) * 1e9,
            eps_c1: (0.7 * fcm.powf(0.31)).min(2.8) * 1e-3,
            eps_cu1: ec2_eps_cu1(fcm * 1e6),
        }
    }

    /// The names of every class, for messages.
    pub fn names() -> String {
        EC2_CLASSES
            .iter()
            .map(|(n, _)| *n)
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// Ultimate strain of the Eurocode 2 compression curve for a mean strength `f_cm`
/// (Pa): 3.5 ‰ up to `f_ck = 50 MPa`, `2.8 + 27((98 − f_cm)/100)⁴` ‰ above.
pub fn ec2_eps_cu1(f_cm: f64) -> f64 {
    let fcm = f_cm / 1e6;
    if fcm - 8.0 < 50.0 {
        3.5e-3
    } else {
        (2.8 + 27.0 * ((98.0 - fcm).max(0.0) / 100.0).powi(4)) * 1e-3
    }
}

/// Fracture energy of fib Model Code 2010 (5.1-9), `G_F = 73 f_cm^{0.18}` N/m with
/// `f_cm` in MPa: 140 N/m for C30/37, NOTES.md's value.
pub fn fib_fracture_energy(f_cm: f64) -> f64 {
    73.0 * (f_cm / 1e6).powf(0.18)
}

/// Identified Mazars parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MazarsIdentified {
    /// `ε_t^0` (classic: `κ_0`).
    pub eps_t0: f64,
    /// `ε_c^0` (paper variant; the classic law reaches it through `ν√2|ε|`).
    pub eps_c0: f64,
    /// `A_t`.
    pub a_t: f64,
    /// `B_t`.
    pub b_t: f64,
    /// `A_c`.
    pub a_c: f64,
    /// `B_c` (classic: on its equivalent strain, `1/(ν√2 ε_c1)`).
    pub b_c: f64,
}

/// `A_t` of the identification (code_aster's value): a tensile tail that keeps
/// `(1 − A_t) f_ct` of stress while the damage grows.
pub const IDENTIFIED_A_T: f64 = 0.9;

/// Identifies the Mazars parameters of `variant` from the concrete's data; an error
/// says which datum makes the identification impossible.
pub fn mazars(variant: MazarsVariant, d: &ConcreteData) -> Result<MazarsIdentified, String> {
    if d.nu <= 0.0 {
        return Err(format!(
            "the identification needs ν > 0 (the compressive threshold is ε_t0/(ν√2)), got ν = {}",
            d.nu
        ));
    }
    let eps_t0 = d.f_ct / d.e;
    let eps_c0 = eps_t0 / (d.nu * std::f64::consts::SQRT_2);
    if eps_c0 >= d.eps_c1 {
        return Err(format!(
            "eps_c1 = {:e} must exceed the compressive threshold f_ct/(E ν√2) = {eps_c0:e}",
            d.eps_c1
        ));
    }
    if d.f_cm <= d.e * eps_c0 {
        return Err(format!(
            "f_cm = {:e} must exceed the stress at the compressive threshold, E ε_c0 = {:e}",
            d.f_cm,
            d.e * eps_c0
        ));
    }
    if d.f_cm >= d.e * d.eps_c1 {
        return Err(format!(
            "f_cm = {:e} must lie below E ε_c1 = {:e}, the elastic stress at the peak \
             strain: damage can only lower the stress",
            d.f_cm,
            d.e * d.eps_c1
        ));
    }
    let b_c = 1.0 / d.eps_c1;
    let a_c = (d.f_cm / d.e - eps_c0) / (d.eps_c1 * (b_c * (eps_c0 - d.eps_c1)).exp() - eps_c0);
    let b_c = match variant {
        MazarsVariant::Paper => b_c,
        MazarsVariant::Classic => b_c / (d.nu * std::f64::consts::SQRT_2),
    };
    Ok(MazarsIdentified {
        eps_t0,
        eps_c0,
        a_t: IDENTIFIED_A_T,
        b_t: 1.0 / eps_t0,
        a_c,
        b_c,
    })
}

/// The Rankine-Hill laws of a concrete: linear tension softening from `f_ct` by the
/// fracture energy (crack band), the Eurocode 2 curve in compression.
pub fn rankine_hill(
    d: &ConcreteData,
    eps_cu1: f64,
    fracture_energy: f64,
) -> (Hardening, Hardening) {
    (
        Hardening::LinearSoftening {
            strength: d.f_ct,
            fracture_energy,
        },
        Hardening::Ec2 {
            f_cm: d.f_cm,
            eps_c1: d.eps_c1,
            eps_cu1,
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn notes_data_give_notes_parameters() {
        // NOTES.md: ε_t^0 = 8.788e-5, ε_c^0 = 3.107e-4, A_c = 1.353, B_c = 454.5.
        let d = ConcreteData {
            e: 33e9,
            nu: 0.2,
            f_ct: 2.9e6,
            f_cm: 38e6,
            eps_c1: 2.2e-3,
        };
        let m = mazars(MazarsVariant::Paper, &d).unwrap();
        assert!((m.eps_t0 - 8.788e-5).abs() < 1e-8);
        assert!((m.eps_c0 - 3.107e-4).abs() < 1e-7);
        assert!((m.a_c - 1.353).abs() < 1e-3);
        assert!((m.b_c - 454.5).abs() < 0.1);
        assert!((m.b_t - 11379.0).abs() < 1.0);
    }

    #[test]
    fn impossible_data_are_refused() {
        let d = ConcreteData {
            e: 33e9,
            nu: 0.2,
            f_ct: 2.9e6,
            f_cm: 38e6,
            eps_c1: 2e-4,
        };
        assert!(mazars(MazarsVariant::Paper, &d)
            .unwrap_err()
            .contains("eps_c1"));
        let d = ConcreteData { nu: 0.0, ..d };
        assert!(mazars(MazarsVariant::Paper, &d)
            .unwrap_err()
            .contains("ν > 0"));
    }
}
