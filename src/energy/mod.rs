//! The energy ledger: every term of the discrete energy identity of a time scheme,
//! accumulated step by step where it happens.
//!
//! Testing the backward-Euler step equation `M(v₁−v₀)/h + C v₁ + f_int¹ = f_ext¹`
//! (reactions of supports included in `f_ext`) with `Δu = h v₁` and using
//! `(a−b)·a = ½|a|² − ½|b|² + ½|a−b|²` gives, exactly,
//!
//! `ΔE_kin + ΔE_el + ΔD_viscous + ΔD_damage + ΔD_plastic + ΔD_contact + ΔD_mass + ΔD_num = ΔW_ext`
//!
//! (with friction `ΔD_friction`, with the contact predictor of the second-order
//! schemes `ΔD_predictor`, and with generalized-α's stored energy `ΔE_alg`, on the
//! left too)
//!
//! with `ΔW_ext = ½Δu·(f_ext⁰+f_ext¹)` (trapezoidal), `ΔD_mass = Δu·C v₁` and the
//! scheme's own loss `ΔD_num = (scheme's kinetic loss) + (material algorithmic loss)
//! − ½Δu·(f_ext¹−f_ext⁰)`. The balance residual is the left side minus the right side;
//! it is round-off for linear problems and the iteration tolerance otherwise.
//! The trapezoidal work of the internal forces `E_int` is reported beside.
//! Derivation: `theory/energy.md`.
//!
//! The work terms every scheme shares are defined once ([`work::work_integrands`],
//! summed by [`work::step_work`] or inside a scheme's own pass over the step's
//! vectors); a scheme adds only its kinetic energy and its own loss, a constraint its
//! own line ([`StepIncrements`]).

pub mod work;

use std::ops::{Add, AddAssign};

use serde::Serialize;

pub use work::{step_work, work_integrands, StepVectors, StepWork};

/// Dissipation by mechanism: a step's increments at a material point (per unit
/// volume), their integral over the mesh, or a run's cumulative totals. Added with
/// `+=`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Dissipation {
    /// Viscous (material dashpots).
    pub viscous: f64,
    /// Damage.
    pub damage: f64,
    /// Plasticity.
    pub plastic: f64,
    /// Contact: the work the normal contact forces take out (impacts).
    pub contact: f64,
    /// Friction: the work of the tangential contact forces on the slip, `≥ 0`.
    pub friction: f64,
    /// The contact-stabilised predictor: the kinetic energy its projection of the
    /// free flight onto the admissible set removes before a step.
    pub predictor: f64,
    /// Mass and Rayleigh damping `∫ v·C v dt`.
    pub mass: f64,
    /// The time scheme's own numerical loss. At a material point:
    /// `σ_{n+1}:Δε − Δψ − (viscous + damage + plastic)`, in closed form for the
    /// elastic, viscoelastic and damage models (a sum of squares for the linear ones)
    /// and by that difference for plasticity.
    pub numerical: f64,
}

impl Dissipation {
    /// Sum over all mechanisms, numerical loss included.
    pub fn total(&self) -> f64 {
        self.viscous
            + self.damage
            + self.plastic
            + self.contact
            + self.friction
            + self.predictor
            + self.mass
            + self.numerical
    }

    /// Every line but the scheme's own (`numerical`): what the physics booked.
    pub fn physical(&self) -> f64 {
        self.total() - self.numerical
    }

    /// Physical material dissipation: viscous + damage + plastic.
    pub fn material(&self) -> f64 {
        self.viscous + self.damage + self.plastic
    }

    /// Every line multiplied by `w` (a quadrature weight).
    pub fn scaled(&self, w: f64) -> Dissipation {
        Dissipation {
            viscous: w * self.viscous,
            damage: w * self.damage,
            plastic: w * self.plastic,
            contact: w * self.contact,
            friction: w * self.friction,
            predictor: w * self.predictor,
            mass: w * self.mass,
            numerical: w * self.numerical,
        }
    }

    /// The lines as `(name, value)` pairs, in the order of `history.csv`.
    pub fn lines(&self) -> [(&'static str, f64); 8] {
        [
            ("viscous", self.viscous),
            ("damage", self.damage),
            ("plastic", self.plastic),
            ("contact", self.contact),
            ("friction", self.friction),
            ("predictor", self.predictor),
            ("mass", self.mass),
            ("numerical", self.numerical),
        ]
    }
}

impl AddAssign for Dissipation {
    fn add_assign(&mut self, o: Dissipation) {
        self.viscous += o.viscous;
        self.damage += o.damage;
        self.plastic += o.plastic;
        self.contact += o.contact;
        self.friction += o.friction;
        self.predictor += o.predictor;
        self.mass += o.mass;
        self.numerical += o.numerical;
    }
}

impl Add for Dissipation {
    type Output = Dissipation;
    fn add(mut self, o: Dissipation) -> Dissipation {
        self += o;
        self
    }
}

/// One step's increments, as a scheme forms them.
#[derive(Clone, Copy, Debug, Default)]
pub struct StepIncrements {
    /// Kinetic energy at the end of the step (the scheme's own).
    pub kinetic: f64,
    /// Stored energy at the end of the step.
    pub elastic: f64,
    /// The work terms every scheme shares ([`step_work`]).
    pub work: StepWork,
    /// Material dissipation increments (`numerical`: the material algorithmic loss).
    pub material: Dissipation,
    /// The scheme's own loss besides the material one (backward Euler:
    /// `½ |v₁ − v₀|²_M`).
    pub scheme_loss: f64,
    /// Energy taken out by constraints (contact) in the step.
    pub contact: f64,
    /// Energy taken out by friction in the step.
    pub friction: f64,
    /// Kinetic energy the contact predictor removed before the step.
    pub predictor: f64,
}

/// The running ledger. Fields are read through accessors; only [`Ledger::record`]
/// changes it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Ledger {
    kinetic_0: f64,
    elastic_0: f64,
    kinetic: f64,
    internal: f64,
    external_work: f64,
    elastic: f64,
    dissipated: Dissipation,
    residual: f64,
    scale: f64,
    max_abs_residual: f64,
    steps: usize,
    created: f64,
    created_step: usize,
    algorithmic_0: f64,
    algorithmic: f64,
}

impl Ledger {
    /// A ledger starting from kinetic energy `kinetic_0` and stored energy `elastic_0`.
    pub fn new(kinetic_0: f64, elastic_0: f64) -> Self {
        Ledger {
            kinetic_0,
            elastic_0,
            kinetic: kinetic_0,
            elastic: elastic_0,
            scale: kinetic_0.abs().max(elastic_0.abs()),
            ..Default::default()
        }
    }

    /// Books one step.
    pub fn record(&mut self, s: &StepIncrements) {
        self.kinetic = s.kinetic;
        self.internal += s.work.internal;
        self.external_work += s.work.external;
        self.elastic = s.elastic;
        let mut step = s.material;
        step.contact += s.contact;
        step.friction += s.friction;
        step.predictor += s.predictor;
        step.mass += s.work.damping;
        step.numerical += s.scheme_loss - s.work.load_jump;
        self.dissipated += step;
        self.update_residual();
        self.scale = self
            .scale
            .max(self.kinetic.abs())
            .max(self.elastic.abs())
            .max(self.external_work.abs())
            .max(self.internal.abs());
        // E_kin + E_el + D_physical − (E_kin⁰ + E_el⁰ + W_ext): what the bodies hold
        // and the physics took, beyond what they were given. 0 at the start.
        self.steps += 1;
        let created = (self.kinetic - self.kinetic_0)
            + (self.elastic - self.elastic_0)
            + self.dissipated.physical()
            - self.external_work;
        if created > self.created || created.is_nan() {
            self.created = created;
            self.created_step = self.steps;
        }
        // A NaN residual must not hide behind `max`.
        self.max_abs_residual = if self.residual.is_nan() {
            f64::NAN
        } else {
            self.max_abs_residual.max(self.residual.abs())
        };
    }

    /// `ΔE_kin + ΔE_el + ΔE_alg + D − W_ext`.
    fn update_residual(&mut self) {
        self.residual = (self.kinetic - self.kinetic_0)
            + (self.elastic - self.elastic_0)
            + (self.algorithmic - self.algorithmic_0)
            + self.dissipated.total()
            - self.external_work;
    }

    /// Sets the scheme's stored energy of the start (generalized-α's `E_alg`,
    /// `time::modified_energy`), before any step is booked.
    pub fn start_algorithmic(&mut self, e: f64) {
        self.algorithmic_0 = e;
        self.algorithmic = e;
    }

    /// Books the scheme's stored energy at the end of the step just recorded: its
    /// change leaves `D_num` (which the step's booking had charged with it), so
    /// that `D_num` is the loss of `E_kin + E_el + E_alg`. The residual is
    /// unchanged.
    pub fn book_algorithmic(&mut self, e: f64) {
        self.dissipated.numerical -= e - self.algorithmic;
        self.algorithmic = e;
        self.update_residual();
    }

    /// The scheme's stored energy `E_alg` (generalized-α's modified energy less
    /// `E_kin + E_el`; zero for the other schemes).
    pub fn algorithmic(&self) -> f64 {
        self.algorithmic
    }

    /// `E_alg` at the start.
    pub fn algorithmic_0(&self) -> f64 {
        self.algorithmic_0
    }

    /// Kinetic energy at the start.
    pub fn kinetic_0(&self) -> f64 {
        self.kinetic_0
    }
    /// Stored energy at the start.
    pub fn elastic_0(&self) -> f64 {
        self.elastic_0
    }
    /// Kinetic energy `½ vᵀ M v`.
    pub fn kinetic(&self) -> f64 {
        self.kinetic
    }
    /// Work of internal forces (trapezoidal), `E_int` of the paper.
    pub fn internal(&self) -> f64 {
        self.internal
    }
    /// Work of external forces and support reactions (trapezoidal).
    pub fn external_work(&self) -> f64 {
        self.external_work
    }
    /// Stored elastic energy.
    pub fn elastic(&self) -> f64 {
        self.elastic
    }
    /// Cumulative dissipation by mechanism.
    pub fn dissipated(&self) -> &Dissipation {
        &self.dissipated
    }
    /// Balance residual: `ΔE_kin + ΔE_el + D − W_ext`.
    pub fn residual(&self) -> f64 {
        self.residual
    }
    /// Largest energy seen (the scale of the relative residual).
    pub fn scale(&self) -> f64 {
        self.scale
    }
    /// The largest energy created over the run: the most `E_kin + E_el` plus the
    /// physical dissipation (every line but the scheme's own) ever stood above
    /// `E_kin⁰ + E_el⁰ + W_ext`, 0 if never, and the step (counted from 1) where it
    /// did. Equal to `residual − D_num − (E_alg − E_alg⁰)` at that step: a scheme's
    /// negative loss, or a booking that does not close, shows here
    /// (theory/energy.md).
    pub fn created(&self) -> (f64, usize) {
        (self.created, self.created_step)
    }

    /// Largest `|residual|` seen.
    pub fn max_abs_residual(&self) -> f64 {
        self.max_abs_residual
    }

    /// Largest `|residual|` relative to the largest energy seen.
    pub fn relative_residual(&self) -> f64 {
        if self.scale > 0.0 {
            self.max_abs_residual / self.scale
        } else {
            self.max_abs_residual
        }
    }

    /// The first ledger quantity that is not finite, by name.
    pub fn first_non_finite(&self) -> Option<(&'static str, f64)> {
        let scalars = [
            ("E_kin", self.kinetic),
            ("E_int", self.internal),
            ("W_ext", self.external_work),
            ("E_el", self.elastic),
        ];
        scalars
            .into_iter()
            .chain(self.dissipated.lines())
            .find(|(_, v)| !v.is_finite())
    }
}

/// The stored energy `½ uᵀ f_int` of linear elastic bodies (`f_int = K u`), with each
/// body's mean translation taken out of `u`: `½ Σ_b (u − r_b)ᵀ f_int`. `K` annihilates
/// a translation, so this is the same quantity, but `f_int` carries round-off of the
/// order `ε |K| |u|`, and dotted with a large rigid motion (a cube dropped 1 m, strains
/// of 1e-6) that round-off outweighs the strain energy and can turn it negative.
/// Without the translation the error is relative `ε |u| / |u − r|`, far below any
/// strain a model resolves, and the last round-off below zero is clipped: stored
/// energy is never negative. (The Gauss-point path computes `ψ` from the strains.)
#[derive(Clone, Debug)]
pub struct StoredEnergy {
    dim: usize,
    /// Body of each node.
    body: Vec<usize>,
    /// Nodes per body.
    count: Vec<f64>,
}

impl StoredEnergy {
    /// The bodies of `mesh`.
    pub fn new(mesh: &crate::mesh::Mesh) -> Self {
        let n_bodies = mesh.node_body.iter().copied().max().map_or(0, |b| b + 1);
        let mut count = vec![0.0; n_bodies];
        for &b in &mesh.node_body {
            count[b] += 1.0;
        }
        StoredEnergy {
            dim: mesh.dim,
            body: mesh.node_body.clone(),
            count,
        }
    }

    /// `½ Σ_b (u − r_b)ᵀ f_int` for displacements `u` and internal forces `f_int`
    /// (all dofs).
    pub fn of(&self, u: &[f64], f_int: &[f64]) -> f64 {
        let d = self.dim;
        let mut mean = vec![0.0; self.count.len() * d];
        for (n, &b) in self.body.iter().enumerate() {
            for k in 0..d {
                mean[b * d + k] += u[d * n + k];
            }
        }
        for (b, &c) in self.count.iter().enumerate() {
            for k in 0..d {
                mean[b * d + k] /= c.max(1.0);
            }
        }
        let mut e = 0.0;
        for (n, &b) in self.body.iter().enumerate() {
            for k in 0..d {
                e += (u[d * n + k] - mean[b * d + k]) * f_int[d * n + k];
            }
        }
        // A quadratic form of the positive semi-definite `K`: below zero only by
        // round-off, which is clipped.
        (0.5 * e).max(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dissipation_adds_by_line() {
        let a = Dissipation {
            viscous: 1.0,
            damage: 2.0,
            plastic: 3.0,
            contact: 4.0,
            friction: 7.0,
            predictor: 8.0,
            mass: 5.0,
            numerical: 6.0,
        };
        let mut b = a.scaled(0.5);
        b += a;
        assert_eq!(b.plastic, 4.5);
        assert_eq!(b.friction, 10.5);
        assert_eq!(b.predictor, 12.0);
        assert_eq!((a + a).total(), 72.0);
        assert_eq!(a.material(), 6.0);
    }

    #[test]
    fn ledger_books_scheme_and_constraint_lines() {
        let mut l = Ledger::new(10.0, 0.0);
        l.record(&StepIncrements {
            kinetic: 4.0,
            elastic: 3.0,
            work: StepWork {
                internal: 3.5,
                external: 0.0,
                load_jump: 0.0,
                damping: 1.0,
            },
            material: Dissipation {
                numerical: 0.5,
                ..Default::default()
            },
            scheme_loss: 0.5,
            contact: 1.0,
            friction: 0.0,
            predictor: 0.0,
        });
        // ΔE_kin + ΔE_el + D − W = −6 + 3 + (1 + 1 + 1) − 0 = 0.
        assert_eq!(l.residual(), 0.0);
        assert_eq!(l.dissipated().numerical, 1.0);
        assert_eq!(l.dissipated().contact, 1.0);
        assert_eq!(l.dissipated().mass, 1.0);
        assert!(l.first_non_finite().is_none());
        l.record(&StepIncrements {
            kinetic: f64::NAN,
            ..Default::default()
        });
        assert_eq!(l.first_non_finite().map(|p| p.0), Some("E_kin"));
        assert!(l.relative_residual().is_nan());
    }
}
