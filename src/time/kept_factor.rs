//! The kept-factor policy of a step whose tangent depends on the state (damage,
//! plasticity): the factor of the effective matrix is kept while the iterations
//! converge on it, reused outright while a new tangent equals the one it holds bit
//! for bit, remade after a slow iteration or at the next step's start after a slow
//! step, and given up for a full refactorisation when the iterations on it fail
//! (`analysis.refactor_rate`, `theory/nonlinear.md`).

use super::operators::Operators;
use crate::error::Result;
use crate::model::IterationMethod;
use crate::system::{EffectiveSystem, Factored};

/// What the kept factor holds and how it has served.
#[derive(Debug)]
pub(crate) struct KeptFactor {
    /// The tangent the factor holds, and the factorisation count and coefficients
    /// `(c_m, c_k, c_t)` it was made at: while a new tangent equals it bit for bit
    /// (every Gauss point kept its tangent: elastic, or on an unchanged damage
    /// state) the factor is kept instead of remade ([`KeptFactor::update`]).
    factored_kt: Vec<f64>,
    held: Option<(usize, (f64, f64, f64))>,
    /// Factorisations spared so.
    pub reused: usize,
    /// The last step took too many iterations on the factor (Newton) or contracted
    /// too slowly (the fixed point), so the next step's first evaluation
    /// refactorises.
    refresh_pending: bool,
    /// Steps whose iterations on a kept factor failed and were redone refactorising
    /// at every changed tangent.
    pub fallbacks: usize,
    /// The factor can be solved with (its last factorisation succeeded).
    pub valid: bool,
}

impl Default for KeptFactor {
    fn default() -> Self {
        KeptFactor {
            factored_kt: Vec::new(),
            held: None,
            reused: 0,
            refresh_pending: false,
            fallbacks: 0,
            valid: true,
        }
    }
}

impl KeptFactor {
    /// The factor of `sys` holds the tangent `kt` (the tangent at rest of the
    /// first factorisation), made at the coefficients `coefficients`.
    pub fn hold(&mut self, kt: Vec<f64>, sys: &EffectiveSystem, coefficients: (f64, f64, f64)) {
        self.factored_kt = kt;
        self.held = Some((sys.factor_id(), coefficients));
    }

    /// Whether the iteration asks for the tangent of this evaluation with the
    /// factor kept: Newton remakes it after a slow iteration, at the paper's first
    /// estimate (`frozen_first`: a secant solve gets its own factor) and at the
    /// start of a step after a slow one; the fixed point keeps one factor through a
    /// step and remakes it at the start of the next after a slow one.
    pub fn wants_tangent(
        &mut self,
        method: IterationMethod,
        first: bool,
        slow: bool,
        frozen_first: bool,
    ) -> bool {
        match method {
            IterationMethod::Newton => {
                slow || frozen_first
                    || !self.valid
                    || (first && std::mem::take(&mut self.refresh_pending))
            }
            IterationMethod::Fixed => {
                self.refresh_pending |= slow;
                !self.valid || (first && std::mem::take(&mut self.refresh_pending))
            }
        }
    }

    /// Keeps the factor when the new tangent `kt` is the one it holds (same factor,
    /// same coefficients, the same values bit for bit: the solve is then the one a
    /// refactorisation would give), and refactorises otherwise.
    pub fn update(
        &mut self,
        ops: &Operators,
        sys: &mut EffectiveSystem,
        kt: &[f64],
    ) -> Result<Factored> {
        let key = (sys.factor_id(), ops.coefficients());
        if self.held == Some(key) && self.factored_kt == kt {
            self.reused += 1;
            return Ok(Factored::Ok);
        }
        let f = ops.refactor(sys, kt)?;
        self.valid = f == Factored::Ok;
        self.held = None;
        if f == Factored::Ok {
            self.factored_kt.clear();
            self.factored_kt.extend_from_slice(kt);
            self.held = Some((sys.factor_id(), ops.coefficients()));
        }
        Ok(f)
    }

    /// A step converged in `iterations` on the kept factor: more than a refreshed
    /// factor would need means it no longer fits the state (points that yielded
    /// and now unload, a zone that stopped growing), so the next step remakes it.
    pub fn converged_in(&mut self, iterations: usize) {
        if iterations > crate::nonlinear::KEPT_ITERATIONS as usize + 1 {
            self.refresh_pending = true;
        }
    }
}
