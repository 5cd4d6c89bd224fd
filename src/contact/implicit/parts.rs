//! The parts of the contact correction, each holding one concern: its setup,
//! where the step started, the active set with its multipliers and forces, the rows
//! of the QP at hand, and the workspace of the solves (with the compliance and the
//! dual QP kept between them).

use std::collections::BTreeMap;

use crate::contact::compliance::Compliance;
use crate::contact::master::rigid::EdgeHistory;
use crate::contact::qp::DualQp;
use crate::contact::rows::Candidate;
use crate::contact::state::Key;
use crate::model::{ContactPair, ContactQp, Model};

/// What a correction is set up with, fixed for the run.
pub(super) struct Setup<'m> {
    pub(super) model: &'m Model,
    pub(super) pairs: &'m [ContactPair],
    pub(super) tol: f64,
    /// The gap the coordinates resolve (m): [`super::GAP_ROUNDOFF`] ulps of the largest.
    pub(super) gap_floor: f64,
    pub(super) qp: ContactQp,
    /// Tributary area (length × thickness) of each node as a slave, for pressures.
    pub(super) area: Vec<f64>,
    /// The free-dof numbering (the system's).
    pub(super) dofs: crate::system::DofMap,
    /// The spatial dimension (dofs per node).
    pub(super) dim: usize,
    /// Whether any pair has friction.
    pub(super) frictional: bool,
    /// Whether a frictional QP tries the statuses of the last one first.
    pub(super) friction_guess: bool,
}

/// Where the step started.
#[derive(Default)]
pub(super) struct StepStart {
    /// Displacements at the start of the step (slips are measured from them).
    pub(super) u0: Vec<f64>,
    /// Node positions at the start of the step (the sweep's start).
    pub(super) x0: Vec<f64>,
    /// The step's lead `h v` on the free dofs and on all dofs.
    pub(super) lead: Vec<f64>,
    pub(super) lead_all: Vec<f64>,
    /// What the committed state knows of the rigid lines' slaves.
    pub(super) rigid: EdgeHistory,
    /// The slaves held at the start of the step (multipliers above the active
    /// threshold) and whether each sticks, sorted.
    pub(super) held: Vec<(crate::contact::state::Slave, bool)>,
}

/// The multipliers and the active set they make: what one QP hands to the next
/// evaluation, and a step to the next.
#[derive(Default)]
pub(super) struct ActiveSet {
    /// Current multipliers by key (positive ones only).
    pub(super) lambda: BTreeMap<Key, f64>,
    /// Current tangential multipliers by key (frictional rows), along the row's
    /// tangents (one in the plane, the second zero).
    pub(super) lambda_t: BTreeMap<Key, [f64; 2]>,
    /// Active constraints (multipliers above the threshold) of the previous QP (or of
    /// the last step) and of the last one, sorted. The active set has settled when
    /// the same slaves are held (a slave in a notch may share its force between
    /// two segments differently from one QP to the next).
    pub(super) previous: Vec<Key>,
    pub(super) current: Vec<Key>,
    /// Multipliers whose row left the candidates, passed on to the slave's row
    /// that remains.
    pub(super) moved: Vec<(Key, f64)>,
    /// Contact forces `Gᵀλ` at the current iterate (all dofs), their friction part,
    /// and whether the loop's residual includes them.
    pub(super) f_c: Vec<f64>,
    pub(super) f_t: Vec<f64>,
    pub(super) added: bool,
}

/// The candidates at the current iterate and the rows of its QP.
#[derive(Default)]
pub(super) struct RowSelection {
    /// Candidates at the current iterate.
    pub(super) cands: Vec<Candidate>,
    /// The QP's rows (candidate indices; tangential rows after the normal ones) and
    /// their predicted gaps or slips.
    pub(super) rows: Vec<usize>,
    pub(super) c: Vec<f64>,
    /// Normal rows of the last QP (the tangential ones follow them), and each
    /// tangential row's normal row and `μ`.
    pub(super) normal_rows: usize,
    pub(super) cones: Vec<(usize, f64)>,
    /// The gap of each candidate at the iterate (shifted back by the lead).
    pub(super) gaps: Vec<f64>,
    /// The guess of a frictional QP: the normal rows pressed at the last QP and how
    /// each frictional node ended there.
    pub(super) pressed: Vec<bool>,
    pub(super) guess_t: Vec<crate::contact::coulomb::Guess>,
    /// The multipliers the last QP (or the last step) ended with, which the guess
    /// reads.
    pub(super) last_lambda: BTreeMap<Key, f64>,
    pub(super) last_lambda_t: BTreeMap<Key, [f64; 2]>,
    /// `δ₀` kept for a second round of the QP, and the candidates a round forced in.
    pub(super) delta_start: Vec<f64>,
    pub(super) forced: Vec<usize>,
}

/// The workspace of the solves and what is kept between them.
#[derive(Default)]
pub(super) struct Workspace {
    /// Node positions at the iterate, and at `u + h v`.
    pub(super) x: Vec<f64>,
    pub(super) x_lead: Vec<f64>,
    pub(super) delta0: Vec<f64>,
    pub(super) y: Vec<f64>,
    pub(super) w: Vec<f64>,
    pub(super) lambda_rows: Vec<f64>,
    pub(super) needed: Vec<usize>,
    pub(super) push: Vec<f64>,
    pub(super) push_entries: Vec<(usize, f64)>,
    pub(super) guess: Vec<usize>,
    pub(super) guess_work: Vec<f64>,
    /// The compliance of the contact dofs, and the factorisation of the last QP.
    pub(super) compliance: Compliance,
    pub(super) qp_generation: usize,
    pub(super) dual: DualQp,
    /// What detection keeps across evaluations (a face master's tree).
    pub(super) kept: crate::contact::detect::Kept,
}
