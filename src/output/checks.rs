//! The paper's energy checks on every run, as `summary.json`'s `checks`.
//!
//! The trapezoidal work of the internal forces is what the material stores plus what
//! it dissipates (`E_p,int = E_el + E_diss`, the paper's Section 4), so the material
//! dissipation cannot exceed it; and no run dissipates more than it was given (the
//! initial kinetic and stored energy plus the work of gravity, loads and supports).
//! Both are compared with a tolerance of the ledger's own accuracy: the largest
//! balance residual of the run plus `1e-9` of its largest energy. The first also
//! allows 1 % of `E_int`: the paper's `E_p,int` is the trapezoidal work
//! `Σ ½Δu·(f⁰ + f¹)`, while what backward Euler stores and dissipates is exactly
//! `Σ Δu·f¹` (≥ the material dissipation); the two differ by
//! `Σ ½Δu·(f¹ − f⁰)`, first order in `h` (0.1 % in benchmark 1's Kelvin-Voigt
//! runs, whose viscous force jumps at the impact). Derivation: `theory/benchmarks.md`.

use serde::Serialize;

use crate::energy::Ledger;

/// The share of `E_int` the first check allows for the trapezoidal rule's
/// first-order difference to the scheme's own internal work.
pub const TRAPEZOIDAL_ALLOWANCE: f64 = 0.01;

/// One inequality `lhs ≤ rhs` with its values.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub struct Check {
    /// Whether `lhs ≤ rhs + tolerance` (false for a non-finite value).
    pub holds: bool,
    /// The left side (J).
    pub lhs: f64,
    /// The right side (J).
    pub rhs: f64,
    /// The tolerance the comparison allows (J).
    pub tolerance: f64,
}

impl Check {
    fn of(lhs: f64, rhs: f64, tolerance: f64) -> Check {
        Check {
            holds: lhs <= rhs + tolerance,
            lhs,
            rhs,
            tolerance,
        }
    }
}

/// The checks of one run.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub struct Checks {
    /// Material dissipation (viscous + damage + plastic) ≤ `E_int`, the work of the
    /// internal forces (the paper's `E_diss ≤ E_p,int`).
    pub dissipation_within_internal_work: Check,
    /// All dissipation (every ledger line, the scheme's own loss and contact
    /// included) ≤ `E_kin⁰ + E_el⁰ + W_ext` (the paper's `E_diss ≤ E_kin⁰` plus the
    /// work of gravity).
    pub dissipation_within_supplied_energy: Check,
    /// The energy of the motion `E_kin + E_el` ≤ `E_kin⁰ + E_el⁰ + W_ext`: what the
    /// bodies hold never exceeds what they were given (no energy created, whatever
    /// the scheme's own line books).
    pub energy_within_supplied_energy: Check,
    /// No energy created at any step: the largest excess over the run of
    /// `E_kin + E_el` plus the physical dissipation (every ledger line but the
    /// scheme's own) over `E_kin⁰ + E_el⁰ + W_ext` ≤ 0. It fails where the scheme's
    /// own line went negative beyond the allowance (generalized-α at an impact) or a
    /// booking does not close (theory/energy.md, "No energy created").
    pub no_energy_created: Check,
    /// The step (counted from 1) of that largest excess; 0 when it never exceeded 0.
    pub energy_created_at_step: usize,
}

/// The energy scale of a model below which an energy is round-off: the kinetic
/// energy of all its mass crossing its own extent `L` (the bounding box's diagonal)
/// in the run's time `T`, `½ M (L/T)²`. The checks allow `ε` of it, so that a body
/// at rest whose energies are `1e-24 J` of round-off is no energy created
/// (theory/energy.md).
pub fn reference_energy(model: &crate::model::Model) -> f64 {
    let mesh = &model.mesh;
    let mut mass = 0.0;
    for (bi, b) in mesh.blocks.iter().enumerate() {
        let rho = model.materials[b.material].rho;
        for e in 0..b.elements.len() {
            let x = mesh.element_points(bi, e);
            let measure = if b.elements.kind == crate::mesh::ElementKind::Bar2 {
                crate::geometry::distance(x[0], x[1])
            } else {
                crate::fe::element::measure(b.elements.kind, &x).abs()
            };
            mass += rho * b.section * measure;
        }
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in &mesh.coords {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let extent2: f64 = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum();
    let t = model.analysis.time.t_end;
    let e = 0.5 * mass * extent2 / (t * t);
    if e.is_finite() {
        e
    } else {
        0.0
    }
}

/// How much energy a run may show beyond what it was given before the check that
/// no energy is created fails, as a share of the supplied energy: the scheme's own
/// bound (theory/energy.md).
/// - Central differences at `ρ = h/h_stable < 1` conserve `½ v_{n+½}ᵀ M v_{n+½} +
///   ½ u_nᵀ K u_{n+1}`, which differs from `E_kin + E_el` by up to a factor
///   `1/(1 − ρ²)` in the highest mode: `ρ²/(1 − ρ²)`. Above the stable step (a
///   stability study) the run may grow: 1, so that growth beyond twice the supply
///   ends it.
/// - The implicit schemes meet equilibrium to the iteration's relative tolerance at
///   each step: each step's residual can do work up to that share of the energies,
///   `tolerance × steps`.
pub fn energy_allowance(model: &crate::model::Model, steps: usize) -> f64 {
    let t = &model.analysis.time;
    match (t.kind, t.scheme, t.stable_dt) {
        (crate::model::AnalysisKind::Dynamic, crate::model::TimeScheme::CentralDifference, s) => {
            let rho = s.map_or(1.0, |s| t.dt / s);
            if rho < 1.0 {
                rho * rho / (1.0 - rho * rho)
            } else {
                1.0
            }
        }
        _ => model.analysis.iteration.tolerance * steps.max(1) as f64,
    }
}

impl Checks {
    /// The checks of a ledger, with no allowance for the scheme or round-off
    /// beyond the ledger's own accuracy.
    pub fn of(l: &Ledger) -> Checks {
        Checks::with(l, 0.0, 0.0)
    }

    /// The checks of a ledger whose energy may exceed the supply by `allowance`
    /// of it ([`energy_allowance`]) plus `floor` J of round-off (`ε` of
    /// [`reference_energy`]).
    pub fn with(l: &Ledger, allowance: f64, floor: f64) -> Checks {
        let tol = l.max_abs_residual() + 1e-9 * l.scale() + floor;
        let d = l.dissipated();
        let supply = (l.kinetic_0() + l.elastic_0() + l.external_work())
            .abs()
            .max(l.scale());
        let (created, step) = l.created();
        Checks {
            dissipation_within_internal_work: Check::of(
                d.material(),
                l.internal(),
                tol + TRAPEZOIDAL_ALLOWANCE * l.internal().abs(),
            ),
            dissipation_within_supplied_energy: Check::of(
                d.total(),
                l.kinetic_0() + l.elastic_0() + l.external_work(),
                tol,
            ),
            energy_within_supplied_energy: Check::of(
                l.kinetic() + l.elastic(),
                l.kinetic_0() + l.elastic_0() + l.external_work(),
                tol + allowance * supply,
            ),
            // A NaN excess must fail, not vanish behind `max`.
            no_energy_created: Check::of(
                if created.is_nan() {
                    created
                } else {
                    created.max(0.0)
                },
                0.0,
                tol + allowance * supply,
            ),
            energy_created_at_step: if created > 0.0 { step } else { 0 },
        }
    }

    /// The first failed check with what makes a run break it: the name as
    /// [`Checks::failures`] gives it, and the cause. `h` is the run's step. During
    /// the run (`finished` false) the checks of the supply are read; the material
    /// dissipation against `E_int`, which the paper states for the whole run (the
    /// trapezoidal `E_int` lags the scheme's own internal work by a first-order
    /// term that one step can exceed), only at the end.
    /// `energy_binds` says whether the check that no energy is created ends the run
    /// (central differences, whose bound [`energy_allowance`] derives); for the
    /// implicit schemes it is reported and warned of (their contact and
    /// generalized-α's modified energy have no derived bound yet, theory/energy.md).
    pub fn first_failure(
        &self,
        h: f64,
        finished: bool,
        energy_binds: bool,
    ) -> Option<(String, String)> {
        let c = &self.dissipation_within_internal_work;
        if finished && !c.holds {
            // The material dissipation is integrated to first order in the step
            // (theory/damage.md): its excess over the internal work shrinks in
            // proportion to h, so a step `h · allowance / excess` brings it within.
            let excess = (c.lhs - c.rhs).max(0.0);
            let allowance = (TRAPEZOIDAL_ALLOWANCE * c.rhs.abs()).max(f64::MIN_POSITIVE);
            let suggested = h * allowance / excess.max(allowance);
            return Some((
                self.line(0),
                format!(
                    "the materials dissipate more than the work of the internal forces, \
                     which no material can: the step ({h:.3e} s) is too coarse for the \
                     history's integral (damage or plastic increments far beyond the \
                     step's own strain); the dissipation's first-order error asks for a \
                     step of about {suggested:.1e} s (theory/damage.md)"
                ),
            ));
        }
        if !self.dissipation_within_supplied_energy.holds {
            return Some((
                self.line(1),
                "more energy was dissipated than was supplied: the ledger's lines are \
                 inconsistent at this step (theory/energy.md)"
                    .into(),
            ));
        }
        if energy_binds && !self.energy_within_supplied_energy.holds {
            return Some((
                self.line(2),
                format!(
                    "the bodies hold more energy than they were given: the scheme is \
                     unstable at this step ({h:.3e} s; an explicit step above the stable \
                     one) or created energy at an impact (theory/energy.md)"
                ),
            ));
        }
        None
    }

    /// The checks in order with their names.
    fn named(&self) -> [(&'static str, &Check); 4] {
        [
            (
                "dissipation_within_internal_work (material dissipation <= E_int)",
                &self.dissipation_within_internal_work,
            ),
            (
                "dissipation_within_supplied_energy (dissipation <= E_kin0 + E_el0 + W_ext)",
                &self.dissipation_within_supplied_energy,
            ),
            (
                "energy_within_supplied_energy (E_kin + E_el <= E_kin0 + E_el0 + W_ext)",
                &self.energy_within_supplied_energy,
            ),
            (
                "no_energy_created (E_kin + E_el + physical dissipation <= E_kin0 + E_el0 \
                 + W_ext at every step)",
                &self.no_energy_created,
            ),
        ]
    }

    /// Check `i` (in [`Checks::named`]'s order) as a `name: lhs > rhs` line.
    fn line(&self, i: usize) -> String {
        let (n, c) = self.named()[i];
        format!("{n}: {:.6e} J > {:.6e} J", c.lhs, c.rhs)
    }

    /// The failed checks as `name: lhs > rhs` lines; energy created says where and
    /// what it means.
    pub fn failures(&self) -> Vec<String> {
        (0..4)
            .filter(|&i| !self.named()[i].1.holds)
            .map(|i| match i {
                3 => format!(
                    "{} at step {}: the run gained energy (the scheme's own line fell below \
                     zero, as generalized-α's does at impacts, or a booking does not close)",
                    self.line(i),
                    self.energy_created_at_step
                ),
                _ => self.line(i),
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_check_fails_beyond_its_tolerance_and_on_nan() {
        assert!(Check::of(1.0, 1.0, 0.0).holds);
        assert!(Check::of(1.0 + 1e-12, 1.0, 1e-9).holds);
        assert!(!Check::of(1.1, 1.0, 1e-9).holds);
        assert!(!Check::of(f64::NAN, 1.0, 1e-9).holds);
        let fresh = Checks::of(&Ledger::new(2.0, 0.0));
        assert!(fresh.failures().is_empty());
        assert_eq!(fresh.dissipation_within_supplied_energy.rhs, 2.0);
    }

    /// A body of 2 J losing 1 J of kinetic energy in one step to an impact, whose
    /// contact line books `contact` and the scheme's line closes the balance.
    fn one_step(contact: f64) -> Ledger {
        let mut l = Ledger::new(2.0, 0.0);
        l.record(&crate::energy::StepIncrements {
            kinetic: 1.0,
            contact,
            scheme_loss: 1.0 - contact,
            ..Default::default()
        });
        l
    }

    #[test]
    fn a_booking_that_claims_more_than_was_lost_is_energy_created() {
        // The right booking (1 J to contact) and one that leaves some to the scheme
        // both close the balance and hold.
        for contact in [1.0, 0.7] {
            let c = Checks::of(&one_step(contact));
            assert!(c.no_energy_created.holds, "{contact}: {c:?}");
            assert_eq!(c.energy_created_at_step, 0);
        }
        // A contact line of 1.5 J where 1 J was lost closes the balance with a scheme
        // line of −0.5 J: the ledger closes, the energy of the motion is below the
        // supply, and only this check sees the 0.5 J created.
        let wrong = Checks::of(&one_step(1.5));
        assert!(wrong.dissipation_within_supplied_energy.holds);
        assert!(wrong.energy_within_supplied_energy.holds);
        assert!(!wrong.no_energy_created.holds, "{wrong:?}");
        assert!((wrong.no_energy_created.lhs - 0.5).abs() < 1e-15);
        assert_eq!(wrong.energy_created_at_step, 1);
        let lines = wrong.failures();
        assert!(
            lines.len() == 1
                && lines[0].contains("no_energy_created")
                && lines[0].contains("step 1"),
            "{lines:?}"
        );
    }
}
