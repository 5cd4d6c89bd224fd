//! The energy ledger: every term of the discrete energy identity of backward Euler,
//! accumulated step by step where it happens.
//!
//! Testing the step equation `M(v₁−v₀)/h + C v₁ + f_int¹ = f_ext¹` (reactions of
//! supports included in `f_ext`) with `Δu = h v₁` and using
//! `(a−b)·a = ½|a|² − ½|b|² + ½|a−b|²` gives, exactly,
//!
//! `ΔE_kin + ΔE_el + ΔD_viscous + ΔD_damage + ΔD_plastic + ΔD_contact + ΔD_mass + ΔD_num = ΔW_ext`
//!
//! with `ΔW_ext = ½Δu·(f_ext⁰+f_ext¹)` (trapezoidal), `ΔD_mass = Δu·C v₁` and the
//! scheme's own loss `ΔD_num = ½|v₁−v₀|²_M + (material algorithmic loss) −
//! ½Δu·(f_ext¹−f_ext⁰)`. The balance residual is the left side minus the right side;
//! it is round-off for linear problems and the iteration tolerance otherwise.
//! The trapezoidal work of the internal forces `E_int` is reported beside.
//! Derivation: `theory/energy.md`.

use serde::Serialize;

/// Cumulative dissipation by mechanism.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Dissipated {
    /// Viscous (material dashpots).
    pub viscous: f64,
    /// Damage.
    pub damage: f64,
    /// Plasticity.
    pub plastic: f64,
    /// Contact.
    pub contact: f64,
    /// Mass and Rayleigh damping `∫ v·C v dt`.
    pub mass: f64,
    /// The time scheme's own numerical loss.
    pub numerical: f64,
}

impl Dissipated {
    /// Sum over all mechanisms, numerical loss included.
    pub fn total(&self) -> f64 {
        self.viscous + self.damage + self.plastic + self.contact + self.mass + self.numerical
    }
}

/// The running ledger.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Ledger {
    /// Kinetic energy at the start.
    pub kinetic_0: f64,
    /// Stored elastic energy at the start.
    pub elastic_0: f64,
    /// Kinetic energy `½ vᵀ M v`.
    pub kinetic: f64,
    /// Work of internal forces (trapezoidal).
    pub internal: f64,
    /// Work of external forces and support reactions (trapezoidal).
    pub external_work: f64,
    /// Stored elastic energy.
    pub elastic: f64,
    /// Dissipation by mechanism.
    pub dissipated: Dissipated,
    /// Balance residual: `ΔE_kin + ΔE_el + D − W_ext`.
    pub residual: f64,
    /// Largest energy seen (for the relative residual).
    pub scale: f64,
    /// Largest `|residual|` seen.
    pub max_abs_residual: f64,
}

/// One step's increments, computed by the time integrator.
#[derive(Clone, Copy, Debug, Default)]
pub struct StepIncrements {
    /// `½ v₁ᵀ M v₁`.
    pub kinetic: f64,
    /// `½ Δu·(f_int⁰ + f_int¹)`.
    pub internal_work: f64,
    /// `½ Δu·(f_ext⁰ + f_ext¹)`.
    pub external_work: f64,
    /// Stored energy at the end of the step.
    pub elastic: f64,
    /// Material dissipation increments (numerical: material algorithmic loss).
    pub material: crate::material::Dissipation,
    /// Contact dissipation increment.
    pub contact: f64,
    /// `Δu · C v₁`.
    pub mass_damping: f64,
    /// `½ |v₁ − v₀|²_M`.
    pub kinetic_loss: f64,
    /// `½ Δu·(f_ext¹ − f_ext⁰)`, subtracted from the numerical loss.
    pub load_jump: f64,
}

impl Ledger {
    /// A ledger starting from kinetic energy `kinetic_0` and stored energy `elastic_0`.
    pub fn new(kinetic_0: f64, elastic_0: f64) -> Self {
        Ledger {
            kinetic_0,
            elastic_0,
            kinetic: kinetic_0,
            elastic: elastic_0,
            scale: kinetic_0.max(elastic_0),
            ..Default::default()
        }
    }

    /// Books one step.
    pub fn record(&mut self, s: &StepIncrements) {
        self.kinetic = s.kinetic;
        self.internal += s.internal_work;
        self.external_work += s.external_work;
        self.elastic = s.elastic;
        let d = &mut self.dissipated;
        d.viscous += s.material.viscous;
        d.damage += s.material.damage;
        d.plastic += s.material.plastic;
        d.contact += s.contact;
        d.mass += s.mass_damping;
        d.numerical += s.kinetic_loss + s.material.numerical - s.load_jump;
        self.residual = (self.kinetic - self.kinetic_0)
            + (self.elastic - self.elastic_0)
            + self.dissipated.total()
            - self.external_work;
        self.scale = self
            .scale
            .max(self.kinetic)
            .max(self.elastic)
            .max(self.external_work.abs())
            .max(self.internal.abs());
        self.max_abs_residual = self.max_abs_residual.max(self.residual.abs());
    }

    /// Largest `|residual|` relative to the largest energy seen.
    pub fn relative_residual(&self) -> f64 {
        if self.scale > 0.0 {
            self.max_abs_residual / self.scale
        } else {
            0.0
        }
    }
}
