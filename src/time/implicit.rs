//! The implicit integrator, written once for backward Euler, the trapezoidal rule,
//! generalized-α and statics ([`Implicit`]): the parts every implicit scheme holds
//! ([`Core`]: operators, effective system, scratch, the correction, the predictor)
//! and one step through the equilibrium loop ([`step`]). The step problem is
//! `time::step_problem`'s, the kept factor `time::kept_factor`'s, the booking
//! `time::booking`'s. `theory/scheme.md`.

use std::marker::PhantomData;
use std::time::Instant;

use super::diagnostics::{describe, likely_cause};
use super::forces::external_force;
use super::operators::{Operators, Response, Rule, Scheme};
use super::predictor::Predictor;
use super::step_problem::{ImplicitStep, Scratch};
use super::{Integrator, Rejection, SolverFacts, State, StepOutcome, StepReport, Timing};
use crate::assembly::{Assembler, Mass};
use crate::contact::ContactCorrection;
use crate::error::{Error, Result};
use crate::linsolve::Backend;
use crate::model::{ContactPredictor, Model};
use crate::nonlinear::{self, Convergence, Correction, LinearCorrection, Outcome};
use crate::system::{DofMap, EffectiveSystem, Factored};

/// How an implicit step corrects its iterates: one solve, or the contact QP.
pub(crate) enum Corrector<'m> {
    /// No constraints: one solve on the factor.
    Linear(LinearCorrection),
    /// Contact pairs and unilateral supports.
    Contact(Box<ContactCorrection<'m>>),
}

impl Corrector<'_> {
    fn begin_step(&mut self, s: &State, h: Option<f64>) {
        if let Corrector::Contact(c) = self {
            c.begin_step(&s.contact, &s.u, h.map(|h| (h, s.v.as_slice())));
        }
    }

    /// Whether the converged iterate holds other slaves than the step's start, or
    /// slides under friction ([`ContactCorrection::held_changed`],
    /// [`ContactCorrection::sliding`]).
    fn held_changed(&self) -> bool {
        match self {
            Corrector::Linear(_) => false,
            Corrector::Contact(c) => c.held_changed() || c.sliding(None),
        }
    }

    /// Whether the committed state `s` has a slave sliding under friction.
    fn sliding_at(&self, s: &State) -> bool {
        match self {
            Corrector::Linear(_) => false,
            Corrector::Contact(c) => c.sliding(Some(&s.contact)),
        }
    }

    /// The contact forces of the last iterate (none without contact).
    fn contact_force(&self) -> Option<&[f64]> {
        match self {
            Corrector::Linear(_) => None,
            Corrector::Contact(c) => Some(c.contact_force()),
        }
    }

    /// The energy the constraints took in the accepted step (`−Δu·f` of the normal
    /// and of the friction forces), with their state written into `s.contact`.
    fn finish(&mut self, du: &[f64], s: &mut State) -> (f64, f64) {
        match self {
            Corrector::Linear(_) => (0.0, 0.0),
            Corrector::Contact(c) => {
                let (normal, friction) = c.finish(du, &mut s.contact);
                (-normal, -friction)
            }
        }
    }
}

impl Correction for Corrector<'_> {
    fn constrain(&mut self, u: &[f64], r: &mut [f64]) -> nonlinear::ConstraintStatus {
        match self {
            Corrector::Linear(c) => c.constrain(u, r),
            Corrector::Contact(c) => c.constrain(u, r),
        }
    }

    fn correct(
        &mut self,
        sys: &mut EffectiveSystem,
        u: &[f64],
        rhs: &mut [f64],
    ) -> Result<nonlinear::Corrected> {
        match self {
            Corrector::Linear(c) => c.correct(sys, u, rhs),
            Corrector::Contact(c) => c.correct(sys, u, rhs),
        }
    }
}

/// What [`step`] gave: an outcome, or a converged step that changed which slaves
/// are held, left uncommitted when the caller asked for that ([`step`]'s
/// `impacts`).
enum Stepped {
    Done(StepOutcome),
    HeldChanged,
}

/// Runs one implicit step from `s` to `t + h` with `correction`; on acceptance `s`
/// holds the new state and its ledger line, on rejection `s` is unchanged. With
/// `impacts`, a step that converged to another set of held slaves is not
/// committed either (`s` unchanged, [`Stepped::HeldChanged`]).
#[allow(clippy::too_many_arguments)]
fn step(
    model: &Model,
    ops: &Operators,
    sys: &mut EffectiveSystem,
    w: &mut Scratch,
    correction: &mut Corrector,
    mut predictor: Option<&mut Predictor>,
    impacts: bool,
    s: &mut State,
) -> Result<Stepped> {
    let h = ops.h();
    let t1 = s.t + h;
    external_force(model, ops.gravity.as_deref(), t1, &mut w.f_ext_np1);
    // The contact-stabilised predictor: the step starts from the velocity of the
    // free flight projected onto the admissible set (restored if the step fails).
    let mut predicted = 0.0;
    if let Some(p) = predictor.as_deref_mut() {
        match p.project(ops, s)? {
            Ok(loss) => predicted = loss,
            Err(outcome) => {
                let message = format!(
                    "the contact predictor's projection of the free flight: {}",
                    describe(model, &outcome, t1, h)
                );
                return Ok(Stepped::Done(StepOutcome::Rejected(Rejection {
                    outcome,
                    message,
                })));
            }
        }
    }
    if let Rule::GeneralizedAlpha(a) = ops.rule() {
        super::step_start::history(ops, &a, s, &mut w.alpha);
    }
    let mut u = std::mem::take(&mut w.u_np1);
    let corrections_before = w.corrections;
    let moving = start_iterate(model, s, t1, &mut u, &mut w.du);
    let mut nl = std::mem::take(&mut w.nl);
    let frozen_first = moving
        && matches!(ops.response, Response::StateDependent(_))
        && model.materials.iter().any(|m| m.has_frozen_form());
    let kept =
        ops.test.refactor_rate.is_some() && matches!(ops.response, Response::StateDependent(_));
    let mut attempt = |kept: bool, u: &mut [f64], w: &mut Scratch, s: &mut State| {
        correction.begin_step(s, ops.dynamic().map(|(h, _, _)| h));
        let mut problem = ImplicitStep {
            model,
            ops,
            s,
            w,
            moving,
            frozen_first,
            kept,
            first: true,
        };
        let test = Convergence {
            refactor_rate: ops.test.refactor_rate.filter(|_| kept),
            ..ops.test
        };
        nonlinear::solve(&mut problem, correction, sys, &test, u, &mut nl)
    };
    let mut outcome = attempt(kept, &mut u, w, s)?;
    if kept
        && matches!(
            outcome,
            Outcome::NotConverged { .. }
                | Outcome::MaterialFailure(_)
                | Outcome::ConstraintFailure(_)
                | Outcome::NotPositiveDefinite { .. }
        )
    {
        // The iterations on a kept factor failed where refactorising at every
        // changed tangent may not: the step again from its start, as full Newton
        // (or the fixed point with a factor per step) would take it.
        w.factor.fallbacks += 1;
        start_iterate(model, s, t1, &mut u, &mut w.du);
        outcome = attempt(false, &mut u, w, s)?;
    }
    w.u_np1 = u;
    w.nl = nl;
    let report = match outcome {
        Outcome::Converged {
            residual,
            iterations,
        } => {
            if kept {
                w.factor.converged_in(iterations);
            }
            StepReport {
                iterations: w.corrections - corrections_before,
                nl_residual: residual,
            }
        }
        Outcome::NonFinite { dof, value, .. } => {
            // Name the vector the non-finite value came from: the loads first, then
            // the committed state, then what the evaluation produced.
            let found = first_non_finite(&[
                ("f_ext (applied loads)", &w.f_ext_np1),
                ("u (committed)", &s.u),
                ("v (committed)", &s.v),
                ("f_int (committed)", &s.f_int),
                ("f_int", &w.f_int_np1),
                ("M v", &w.mv_np1),
                ("residual", &w.r),
            ]);
            // Every entry finite, yet a sum over them is not: the forces are too large
            // for their squares (beyond about 1e154).
            let (quantity, dof, value) = found.unwrap_or((
                if dof.is_some() {
                    "residual"
                } else {
                    "the sum of the squared forces (forces beyond 1e154 overflow their squares)"
                },
                dof,
                value,
            ));
            let outcome = Outcome::NonFinite {
                quantity,
                dof,
                value,
            };
            let message = describe(model, &outcome, t1, h);
            if let Some(p) = predictor {
                p.restore(s);
            }
            return Ok(Stepped::Done(StepOutcome::Rejected(Rejection {
                outcome,
                message,
            })));
        }
        other => {
            if let Some(p) = predictor {
                p.restore(s);
            }
            let message = describe(model, &other, t1, h);
            return Ok(Stepped::Done(StepOutcome::Rejected(Rejection {
                outcome: other,
                message,
            })));
        }
    };
    if impacts && correction.held_changed() {
        if let Some(p) = predictor {
            p.restore(s);
        }
        return Ok(Stepped::HeldChanged);
    }
    let contact = correction.finish(&w.du, s);
    super::booking::finish(ops, sys.dofs(), w, s, t1, contact, predicted);
    if let Some((quantity, value)) = s.ledger.first_non_finite() {
        return Err(Error::NonFinite {
            quantity: format!("the ledger line {quantity}"),
            value,
            location: None,
            t: t1,
        });
    }
    Ok(Stepped::Done(StepOutcome::Accepted(report)))
}

/// Sets the start of a step's iteration: `u` is `u_n` with the prescribed values of
/// `t1`, `du` its increment `Δu_c` (zero on the free dofs). Returns whether a
/// prescribed value moves.
fn start_iterate(model: &Model, s: &State, t1: f64, u: &mut [f64], du: &mut [f64]) -> bool {
    u.copy_from_slice(&s.u);
    du.fill(0.0);
    let mut moving = false;
    for c in &model.constraints {
        let target = c.at(t1);
        if target != s.u[c.dof] {
            u[c.dof] = target;
            du[c.dof] = target - s.u[c.dof];
            moving = true;
        }
    }
    moving
}

/// The first non-finite entry of the named vectors, in order.
fn first_non_finite(
    vectors: &[(&'static str, &[f64])],
) -> Option<(&'static str, Option<usize>, f64)> {
    vectors.iter().find_map(|(name, v)| {
        v.iter()
            .position(|x| !x.is_finite())
            .map(|d| (*name, Some(d), v[d]))
    })
}

/// The integrator parts every implicit scheme holds.
pub(crate) struct Core<'m> {
    pub model: &'m Model,
    pub ops: Operators,
    pub sys: EffectiveSystem,
    pub scratch: Scratch,
    pub correction: Corrector<'m>,
    /// The contact-stabilised predictor, when the scenario asks for it.
    pub predictor: Option<Predictor<'m>>,
    pub assembly_s: f64,
    /// Time inside steps besides solves and refactorisations.
    pub step_other_s: f64,
    /// Generalized-α's steps taken by the trapezoidal rule (impact steps).
    pub impact_steps: usize,
    /// Impact steps whose trapezoidal step failed and that generalized-α took.
    pub impact_fallbacks: usize,
}

impl<'m> Core<'m> {
    /// Assembles, analyses and factorises; a matrix that is not positive definite
    /// from the start is an error traced to its likely cause, and a factor that would
    /// not fit in `memory_limit` bytes is refused before it is allocated.
    pub fn new(
        model: &'m Model,
        backend: Backend,
        scheme: Scheme,
        memory_limit: Option<u64>,
    ) -> Result<Self> {
        let t0 = Instant::now();
        let mut ops = Operators::new(model, scheme);
        let assembly_s = t0.elapsed().as_secs_f64();
        let (mut sys, mut factored, kt_at_rest) =
            ops.initial_system(model, backend, memory_limit)?;
        if matches!(ops.rule(), super::operators::Rule::GeneralizedAlpha(_))
            && factored == Factored::Ok
        {
            ops.a0 = super::step_start::initial_acceleration(model, &ops, &mut sys)?;
            factored = ops.refactor(&mut sys, &ops.kt)?;
        }
        if let Factored::NotPositiveDefinite { dof, message } = factored {
            return Err(Error::Solver {
                backend: sys.backend(),
                message: format!(
                    "the initial effective matrix is not positive definite{} ({message}); {}",
                    dof.map(|d| format!(" at {}", model.describe_dof(d)))
                        .unwrap_or_default(),
                    likely_cause(model, &ops, sys.matrix(), sys.dofs())
                ),
            });
        }
        // The ladder's factors, each step size's kept for when the run returns to
        // it, and generalized-α's impact steps' trapezoidal factor (counted in the
        // memory estimate, `memory::of_model`).
        let kept = model.analysis.time.adaptive.map_or(0, |a| a.kept_factors())
            + usize::from(model.takes_impact_steps());
        if kept > 0 {
            sys.keep_factors(kept);
            sys.label_factor(ops.h().to_bits());
        }
        let predictor = (ops.dynamic().is_some()
            && model.analysis.time.contact_predictor == ContactPredictor::Stabilised)
            .then(|| Predictor::new(model, &ops, backend))
            .transpose()?;
        let mut scratch = Scratch::new(model.mesh.n_dofs(), &ops, sys.dofs().n_free());
        if let Some(kt) = kt_at_rest {
            // The factor holds the tangent at rest: kept while the points stay there.
            scratch.factor.hold(kt, &sys, ops.coefficients());
        }
        Ok(Core {
            model,
            ops,
            sys,
            scratch,
            correction: if model.contacts.is_empty() {
                Corrector::Linear(LinearCorrection)
            } else {
                Corrector::Contact(Box::new(ContactCorrection::new(model)))
            },
            predictor,
            assembly_s,
            step_other_s: 0.0,
            impact_steps: 0,
            impact_fallbacks: 0,
        })
    }

    /// One step (see [`step`]), timed.
    pub fn step(&mut self, s: &mut State) -> Result<StepOutcome> {
        let t = Instant::now();
        let before = self.sys.timing();
        // Generalized-α takes a step that changes which slaves are held by the
        // trapezoidal rule (theory/trapezoidal.md, "Impact steps").
        let impacts = self.model.takes_impact_steps();
        let impact_steps = self.impact_steps;
        let a_n = matches!(self.ops.rule(), Rule::GeneralizedAlpha(_)).then(|| s.a.clone());
        let in_contact_before = !s.contact.active.is_empty();
        // A step that starts sliding under friction is one at once.
        let r = if impacts && self.correction.sliding_at(s) {
            self.impact_step(s)
        } else {
            match self.attempt(impacts, s) {
                Ok(Stepped::Done(o)) => Ok(o),
                Ok(Stepped::HeldChanged) => self.impact_step(s),
                Err(e) => Err(e),
            }
        };
        if let (Ok(StepOutcome::Accepted(_)), Rule::GeneralizedAlpha(a), Some(a_n)) =
            (&r, self.ops.rule(), a_n)
        {
            if self.impact_steps == impact_steps {
                let guess = super::modified_energy::carried(&a, &s.a, &a_n, &s.m_inv_r);
                let contact = self.correction.contact_force();
                let exact =
                    !in_contact_before && contact.is_none_or(|f| f.iter().all(|x| *x == 0.0));
                let booked = super::modified_energy::of(&self.ops, &a, s, contact, guess, exact);
                s.ledger.book_algorithmic(booked.energy);
                s.m_inv_r = booked.m_inv_r;
                s.ma = booked.ma;
            } else {
                // An impact step carries the equilibrium acceleration: r = 0. Its
                // E_alg line stays as it was (theory/trapezoidal.md).
                s.m_inv_r = vec![0.0; s.a.len()];
                s.ma.clear();
            }
        }
        let after = self.sys.timing();
        self.step_other_s += t.elapsed().as_secs_f64()
            - (after.solve_s - before.solve_s)
            - (after.factorization_s - before.factorization_s);
        r
    }

    /// One step from `s` by the current rule ([`step`]; `impacts`: a change of the
    /// held slaves is left uncommitted).
    fn attempt(&mut self, impacts: bool, s: &mut State) -> Result<Stepped> {
        step(
            self.model,
            &self.ops,
            &mut self.sys,
            &mut self.scratch,
            &mut self.correction,
            self.predictor.as_mut(),
            impacts,
            s,
        )
    }

    /// Generalized-α's impact step: the step from `s` again by the trapezoidal
    /// rule, whose energy identity holds through a change of the held slaves with
    /// the contact force at the step's end, and the acceleration the next steps
    /// carry from the equilibrium of the new state, contact forces included (a
    /// mass solve by conjugate gradients, no factorisation;
    /// `theory/trapezoidal.md`, "Impact steps"). The rule and its factor are
    /// generalized-α's again afterwards, whatever the step gave. When the
    /// trapezoidal step fails to converge, the step is taken by generalized-α as
    /// it first was (`impact_fallbacks`; the run's `no_energy_created` check then
    /// says whether it created energy) rather than cut.
    fn impact_step(&mut self, s: &mut State) -> Result<StepOutcome> {
        let alpha = self.ops.rule();
        self.ops.set_rule(Rule::Trapezoidal);
        let outcome = self.refit().and_then(|()| {
            let Stepped::Done(o) = self.attempt(false, s)? else {
                unreachable!("a step that may change the held slaves is committed")
            };
            if matches!(o, StepOutcome::Accepted(_)) {
                s.a =
                    super::step_start::acceleration(&self.ops, s, self.correction.contact_force())?;
                self.impact_steps += 1;
            }
            Ok(o)
        });
        self.ops.set_rule(alpha);
        let back = self.refit();
        let o = outcome?;
        back?;
        if matches!(o, StepOutcome::Rejected(_)) {
            if let Stepped::Done(fallback @ StepOutcome::Accepted(_)) = self.attempt(false, s)? {
                self.impact_fallbacks += 1;
                return Ok(fallback);
            }
        }
        Ok(o)
    }

    /// Changes the step size; refactorises what depends on it.
    pub fn set_step(&mut self, h: f64) -> Result<()> {
        if h == self.ops.h() {
            return Ok(());
        }
        self.ops.set_h(self.model, h);
        self.refit()
    }

    /// Refactorises what depends on the step size and the rule, after either
    /// changed. A factor is labelled by the step size's bits, with the sign bit set
    /// for the trapezoidal rule of generalized-α's impact steps (a step size is
    /// positive, so the two never meet).
    fn refit(&mut self) -> Result<()> {
        let h = self.ops.h();
        let static_elastic = matches!(self.ops.scheme, Scheme::Static { .. })
            && self.ops.response == Response::Elastic;
        let state_dependent = matches!(self.ops.response, Response::StateDependent(_));
        if static_elastic || (state_dependent && self.ops.test.refactor_rate.is_none()) {
            // The static stiffness does not depend on the load step; a state-dependent
            // matrix refactorised at every changed tangent is rebuilt at the next
            // step anyway.
            return Ok(());
        }
        if state_dependent {
            // A kept factor belongs to its step size (the mass term `M/h²`): the
            // tangent at rest of the new size replaces it, and the iterations remake
            // it from there when they need to.
            let f = self.ops.refactor(&mut self.sys, &self.ops.kt)?;
            self.scratch.factor.valid = f == Factored::Ok;
            return Ok(());
        }
        // A size the run had before finds its factor kept (an error-controlled run's
        // ladder); the matrix is refilled all the same, so that it is the factor's.
        let impact = self.ops.rule() == Rule::Trapezoidal && self.model.takes_impact_steps();
        let key = h.to_bits() | if impact { 1 << 63 } else { 0 };
        self.ops.refill(&mut self.sys, &self.ops.kt);
        if self.sys.switch_factor(key) {
            return Ok(());
        }
        match self.sys.factorize()? {
            Factored::Ok => {
                self.sys.label_factor(key);
                Ok(())
            }
            Factored::NotPositiveDefinite { message, .. } => Err(Error::Stepping(format!(
                "the effective matrix for h = {h:e} is not positive definite ({message})"
            ))),
        }
    }

    /// The scheme's order, for the error-controlled step (dynamics only).
    pub fn order(&self) -> Option<u32> {
        match (self.ops.dynamic(), self.ops.rule()) {
            (None, _) => None,
            (Some(_), Rule::BackwardEuler) => Some(1),
            (Some(_), _) => Some(2),
        }
    }

    /// The local error measure of the step from `before` to `after`
    /// (`theory/adaptive.md`): the displacement error of the scheme's estimate, zero
    /// on the constrained dofs (their motion is prescribed), in the energy norm of
    /// the elastic stiffness relative to the state's mechanical energy.
    pub fn local_error(
        &mut self,
        before: &State,
        after: &State,
        est: &mut super::local_error::Estimator,
    ) -> Option<f64> {
        use super::local_error as le;
        self.ops.dynamic()?;
        let h = after.t - before.t;
        let n = after.u.len();
        est.e.resize(n, 0.0);
        match self.ops.rule() {
            Rule::BackwardEuler => le::backward_euler(h, &before.v, &after.v, &mut est.e),
            Rule::GeneralizedAlpha(a) => {
                le::newmark(le::coefficient(&a), h, &before.a, &after.a, &mut est.e)
            }
            Rule::Trapezoidal => {
                if !est.trapezoidal(h, &before.v, &after.v) {
                    return None;
                }
            }
        }
        for &d in &self.sys.dofs().constrained {
            est.e[d] = 0.0;
        }
        est.ke.resize(n, 0.0);
        self.ops
            .asm
            .pattern
            .matvec(&self.ops.k, &est.e, &mut est.ke);
        let energy = after.ledger.kinetic() + after.ledger.elastic();
        Some(le::energy_measure(&est.e, &est.ke, energy))
    }

    /// Time per phase.
    pub fn timing(&self) -> Timing {
        let t = self.sys.timing();
        Timing {
            assembly_s: self.assembly_s,
            factorization_s: t.analysis_s + t.factorization_s,
            solve_s: t.solve_s,
            step_other_s: self.step_other_s,
        }
    }

    /// Solver facts.
    pub fn solver(&self) -> SolverFacts {
        SolverFacts {
            backend: self.sys.backend(),
            factorizations: self.sys.factorizations(),
            reused_factors: self.scratch.factor.reused,
            fallbacks: self.scratch.factor.fallbacks,
            impact_steps: self.impact_steps,
            impact_fallbacks: self.impact_fallbacks,
            factor_nnz: self.sys.factor_nnz(),
        }
    }
}

/// Which implicit problem an [`Implicit`] integrator solves: the dynamics of the
/// model's scheme ([`Dynamic`]) or static equilibrium ([`Quasistatic`]).
pub trait ImplicitKind {
    /// Static equilibrium (no inertia) rather than dynamics.
    const STATIC: bool;
}

/// Dynamics by the implicit scheme the model's `analysis.scheme` names (backward
/// Euler, the trapezoidal rule, generalized-α).
#[derive(Clone, Copy, Debug)]
pub struct Dynamic;

impl ImplicitKind for Dynamic {
    const STATIC: bool = false;
}

/// Static equilibrium at load steps.
#[derive(Clone, Copy, Debug)]
pub struct Quasistatic;

impl ImplicitKind for Quasistatic {
    const STATIC: bool = true;
}

/// An implicit integrator: matrices, solver and scratch of one model
/// ([`super::backward_euler::BackwardEuler`] and [`super::statics::Statics`] are its
/// two kinds).
pub struct Implicit<'m, S: ImplicitKind> {
    core: Core<'m>,
    kind: PhantomData<S>,
}

impl<'m, S: ImplicitKind> Implicit<'m, S> {
    /// Assembles `K` (and `M`), the effective matrix, analyses and factorises it
    /// (a body nothing holds is an error that says so).
    pub fn new(model: &'m Model, backend: Backend) -> Result<Self> {
        Self::with_memory_limit(model, backend, None)
    }

    /// [`Implicit::new`], refusing a factor whose memory estimate exceeds
    /// `memory_limit` bytes before it is allocated.
    pub fn with_memory_limit(
        model: &'m Model,
        backend: Backend,
        memory_limit: Option<u64>,
    ) -> Result<Self> {
        let a = &model.analysis;
        let scheme = if S::STATIC {
            Scheme::Static { dt: a.time.dt }
        } else {
            Scheme::Dynamic {
                h: a.time.dt,
                damp_m: a.damping.zeta + a.damping.rayleigh[0],
                damp_k: a.damping.rayleigh[1],
                rule: Rule::of(&a.time),
            }
        };
        Ok(Implicit {
            core: Core::new(model, backend, scheme, memory_limit)?,
            kind: PhantomData,
        })
    }

    /// Solver backend name.
    pub fn backend(&self) -> &'static str {
        self.core.sys.backend()
    }

    /// Number of nonzeros of the Cholesky factor.
    pub fn factor_nnz(&self) -> Option<usize> {
        self.core.sys.factor_nnz()
    }

    /// Entries of the Cholesky factor on and below the diagonal.
    pub fn factor_lower_entries(&self) -> Option<usize> {
        self.core.sys.factor_lower_entries()
    }

    /// Numeric factorisations so far.
    pub fn factorizations(&self) -> usize {
        self.core.sys.factorizations()
    }

    /// The state at `t = 0`: prescribed displacements, bodies' initial velocities,
    /// history materials at rest.
    pub fn initial_state(&self) -> State {
        let ops = &self.core.ops;
        let mut s = ops.initial_state(self.core.model);
        if let Rule::GeneralizedAlpha(a) = ops.rule() {
            let booked = super::modified_energy::of(ops, &a, &s, None, vec![0.0; s.a.len()], false);
            s.ledger.start_algorithmic(booked.energy);
            s.m_inv_r = booked.m_inv_r;
            s.ma = booked.ma;
        }
        s
    }

    /// The elastic stiffness on the shared pattern.
    pub fn stiffness(&self) -> &[f64] {
        &self.core.ops.k
    }

    /// The mass matrix.
    pub fn mass(&self) -> &Mass {
        &self.core.ops.mass
    }

    /// The assembler (pattern and colours).
    pub fn assembler(&self) -> &Assembler {
        &self.core.ops.asm
    }

    /// The free-dof numbering.
    pub fn dofs(&self) -> &DofMap {
        self.core.sys.dofs()
    }

    /// Relative residuals of the last step's equilibrium iterations, one per
    /// evaluation of the residual.
    pub fn residual_history(&self) -> &[f64] {
        self.core.scratch.history()
    }

    /// Time and counts of the contact correction, when the model has contact.
    pub fn contact_stats(&self) -> Option<crate::contact::implicit::ContactStats> {
        match &self.core.correction {
            Corrector::Contact(c) => Some(c.stats()),
            Corrector::Linear(_) => None,
        }
    }

    /// The effective system (matrix, factor, solves).
    pub fn system(&mut self) -> &mut EffectiveSystem {
        &mut self.core.sys
    }
}

impl<S: ImplicitKind> Integrator for Implicit<'_, S> {
    fn model(&self) -> &Model {
        self.core.model
    }

    fn h(&self) -> f64 {
        self.core.ops.h()
    }

    fn set_step(&mut self, h: f64) -> Result<()> {
        self.core.set_step(h)
    }

    fn initial_state(&mut self) -> Result<State> {
        Ok(Implicit::initial_state(self))
    }

    fn step(&mut self, s: &mut State) -> Result<StepOutcome> {
        self.core.step(s)
    }

    fn timing(&self) -> Timing {
        self.core.timing()
    }

    fn output_points(&self, s: &State) -> Option<Vec<crate::material::store::StateStore>> {
        self.core.ops.output_points(self.core.model, s)
    }

    fn solver(&self) -> SolverFacts {
        self.core.solver()
    }

    fn order(&self) -> Option<u32> {
        self.core.order()
    }

    fn local_error(
        &mut self,
        before: &State,
        after: &State,
        estimator: &mut super::local_error::Estimator,
    ) -> Option<f64> {
        self.core.local_error(before, after, estimator)
    }
}
