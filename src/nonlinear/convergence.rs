//! The convergence test of the equilibrium loop.

/// What constraints (contact) report about an iterate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConstraintStatus {
    /// Largest penetration (negative gap magnitude) at the iterate (m).
    pub penetration: f64,
    /// Complementarity: the largest gap (m) across which a force still acts (zero
    /// when every force acts on a closed gap).
    pub complementarity: f64,
    /// Whether the active set differs from the previous iterate's.
    pub active_set_changed: bool,
    /// A constraint that entered or left the active set, as `(pair, slave node)`,
    /// for the message of a step whose contact did not settle.
    pub changed_at: Option<(usize, usize)>,
}

impl ConstraintStatus {
    /// No constraints, or all satisfied.
    pub const SATISFIED: ConstraintStatus = ConstraintStatus {
        penetration: 0.0,
        complementarity: 0.0,
        active_set_changed: false,
        changed_at: None,
    };
}

impl Default for ConstraintStatus {
    fn default() -> Self {
        ConstraintStatus::SATISFIED
    }
}

/// Tolerances of the equilibrium loop.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Convergence {
    /// Relative residual `|r| / |(f_ext, f_int, inertia)|` over the free dofs.
    pub tolerance: f64,
    /// Last correction relative to the step's displacement increment (for problems
    /// that are not affine).
    pub displacement_tolerance: f64,
    /// Corrections allowed per step.
    pub max_iterations: usize,
    /// Largest penetration accepted (m).
    pub penetration_tolerance: f64,
    /// Largest open gap under a force accepted (m).
    pub complementarity_tolerance: f64,
    /// Keep the factor while each evaluation's relative residual is at most this
    /// ratio of the one before (modified Newton): a slower iteration has the next
    /// evaluation assemble its tangent and refactorise. `None`: the problem's
    /// tangent is refactorised whenever it asks for one (full Newton).
    pub refactor_rate: Option<f64>,
}

impl Convergence {
    /// Whether the constraints of an iterate are met: no penetration beyond the
    /// tolerance, complementarity, and an active set that did not change.
    pub fn constraints_hold(&self, c: &ConstraintStatus) -> bool {
        c.penetration <= self.penetration_tolerance
            && c.complementarity <= self.complementarity_tolerance
            && !c.active_set_changed
    }

    /// Whether the constraints of an iterate whose residual is at round-off are
    /// met: no penetration and complementarity within the tolerances, whatever the
    /// active set did (it changes there only by constraints at zero gap and zero
    /// force).
    pub fn constraints_hold_at_floor(&self, c: &ConstraintStatus) -> bool {
        c.penetration <= self.penetration_tolerance
            && c.complementarity <= self.complementarity_tolerance
    }
}
