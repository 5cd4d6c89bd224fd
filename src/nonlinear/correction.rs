//! Corrections: how a residual becomes a displacement change.

use crate::error::Result;
use crate::system::EffectiveSystem;

use super::ConstraintStatus;

/// What a correction did.
#[derive(Clone, Debug, PartialEq)]
pub enum Corrected {
    /// `rhs` holds the correction.
    Ok,
    /// The correction could not be computed (the reason, for the step report).
    Failed(String),
}

/// Turns the residual of an iterate into a displacement change.
pub trait Correction {
    /// Adds the constraint forces at the iterate `u` into the residual `r` (all
    /// dofs) and reports the constraints' state. Without constraints: nothing.
    fn constrain(&mut self, _u: &[f64], _r: &mut [f64]) -> ConstraintStatus {
        ConstraintStatus::SATISFIED
    }

    /// Overwrites `rhs` (`−r` on the free dofs, constraint forces included) with the
    /// correction `δ` on the free dofs, at the iterate `u`.
    fn correct(
        &mut self,
        sys: &mut EffectiveSystem,
        u: &[f64],
        rhs: &mut [f64],
    ) -> Result<Corrected>;
}

/// One solve on the factor: `δ = A⁻¹ (−r)`.
#[derive(Clone, Copy, Debug, Default)]
pub struct LinearCorrection;

impl Correction for LinearCorrection {
    fn correct(
        &mut self,
        sys: &mut EffectiveSystem,
        _u: &[f64],
        rhs: &mut [f64],
    ) -> Result<Corrected> {
        sys.solve(rhs)?;
        Ok(Corrected::Ok)
    }
}
