//! What backward Euler and statics share: the operators (stiffness, mass, the
//! constant tangent), the step problem they hand to the equilibrium loop, the step's
//! scratch vectors, and the bookkeeping that turns a converged iterate into the new
//! state and its ledger line.
//!
//! The step residual, with `Δu = u − u_n`, `v = Δu/h`:
//! - backward Euler: `r(u) = M(v − v_n)/h + (zeta + a_m) M v + a_k K v + f_int(u) − f_ext`,
//! - statics: `r(u) = f_int(u) − f_ext`,
//!
//! with `f_int(u) = f_int,n + K Δu` for linear elasticity and the Gauss-point loop
//! otherwise. Its derivative is the effective matrix
//! `K_eff = c_m M + c_k K + K_t` (`c_m = 1/h² + (zeta+a_m)/h` or 0, see
//! [`Operators::coefficients`]). See `theory/scheme.md`.

use std::time::Instant;

use super::diagnostics::{describe, likely_cause};
use super::forces::external_force;
use super::nodal::{MassProduct, NodalState};
use super::operators::{Operators, Response, Rule, Scheme};
use super::predictor::Predictor;
use super::residual::{residual_chunk, PassCoefficients, PassInputs, PassOutputs, PassSums};
use super::{Rejection, State, StepOutcome, StepReport};
use crate::assembly::internal::{new_stores, PointPass, PointTotals};
use crate::assembly::{Assembler, Mass};
use crate::contact::ContactCorrection;
use crate::energy::{Dissipation, StepIncrements, StepWork};
use crate::error::{Error, Result};
use crate::halves;
use crate::linsolve::Backend;
use crate::model::{ContactPredictor, IterationMethod, Model};
use crate::nonlinear::{
    self, Convergence, Correction, Evaluation, LinearCorrection, Outcome, StepProblem,
};
use crate::system::{DofMap, EffectiveSystem, Factored};

/// The vectors of the step being solved (reused from step to step).
#[derive(Default)]
pub(crate) struct Scratch {
    /// The iterate `u_{n+1}`.
    u_np1: Vec<f64>,
    /// `u − u_n`.
    du: Vec<f64>,
    /// `v_{n+1} = Δu/h`.
    v_np1: Vec<f64>,
    /// `M v_{n+1}`.
    mv_np1: Vec<f64>,
    /// `f_int(u)`.
    f_int_np1: Vec<f64>,
    /// Applied external forces at `t_{n+1}`; the reactions are added once converged.
    f_ext_np1: Vec<f64>,
    /// Predicted internal force of the following step (nodal fields: of this step).
    f_pred_np1: Vec<f64>,
    /// Trial nodal fields.
    nodal: NodalState,
    /// `K Δu` (elastic) or `K v` (stiffness damping of history materials).
    kdu: Vec<f64>,
    /// `M Δu_c` in a prediction.
    m_du: Vec<f64>,
    /// `K_t Δu_c` in a prediction.
    kt_du: Vec<f64>,
    /// The residual (all dofs).
    r: Vec<f64>,
    /// Generalized-α: the step's start vectors, and the new acceleration.
    alpha: super::generalized_alpha::StartVectors,
    a_np1: Vec<f64>,
    /// Tangent of the last evaluation (state-dependent materials).
    kt: Vec<f64>,
    /// The tangent the factor holds, and the factorisation count and coefficients
    /// `(c_m, c_k, c_t)` it was made at: while a new tangent equals it bit for bit
    /// (every Gauss point kept its tangent: elastic, or on an unchanged damage
    /// state) the factor is kept instead of remade ([`ImplicitStep::update_matrix`]).
    factored_kt: Vec<f64>,
    kept: Option<(usize, (f64, f64, f64))>,
    /// Factorisations spared so.
    reused: usize,
    /// With a kept factor: the last step took too many iterations on it (Newton) or
    /// contracted too slowly (the fixed point), so the next step's first evaluation
    /// refactorises.
    refresh_pending: bool,
    /// Steps whose iterations on a kept factor failed and were redone refactorising
    /// at every changed tangent.
    fallbacks: usize,
    /// The factor can be solved with (its last factorisation succeeded).
    factor_valid: bool,
    /// Corrections taken over the run (a step's count includes a failed attempt on
    /// a kept factor).
    corrections: usize,
    /// Material totals of the last evaluation.
    totals: PointTotals,
    /// The ledger sums of the last evaluation: the four work integrands (applied
    /// loads), kinetic energy, the scheme's loss, and for elastic models the stored
    /// energy and `½ Δu·K Δu`.
    ledger_sums: PassSums,
    nl: nonlinear::Scratch,
}

impl Scratch {
    /// Relative residuals of the last step, one per evaluation.
    pub fn history(&self) -> &[f64] {
        self.nl.history()
    }

    pub fn new(n: usize, ops: &Operators, n_free: usize) -> Self {
        let z = || vec![0.0; n];
        Scratch {
            u_np1: z(),
            du: z(),
            v_np1: z(),
            mv_np1: z(),
            f_int_np1: z(),
            f_ext_np1: z(),
            f_pred_np1: if matches!(ops.response, Response::Constant | Response::Nodal) {
                z()
            } else {
                Vec::new()
            },
            nodal: NodalState::default(),
            kdu: z(),
            m_du: z(),
            kt_du: z(),
            r: z(),
            alpha: Default::default(),
            a_np1: Vec::new(),
            kt: if matches!(ops.response, Response::StateDependent(_)) {
                vec![0.0; ops.asm.pattern.nnz()]
            } else {
                Vec::new()
            },
            factored_kt: Vec::new(),
            kept: None,
            reused: 0,
            refresh_pending: false,
            fallbacks: 0,
            factor_valid: true,
            corrections: 0,
            totals: PointTotals::default(),
            ledger_sums: PassSums::default(),
            nl: nonlinear::Scratch::new(n_free, ops.test.max_iterations),
        }
    }
}

/// The step problem handed to the equilibrium loop.
struct ImplicitStep<'a> {
    model: &'a Model,
    ops: &'a Operators,
    /// The committed state (its Gauss-point stores take the trial states).
    s: &'a mut State,
    w: &'a mut Scratch,
    /// Prescribed displacements move in this step (`Δu_c ≠ 0`).
    moving: bool,
    /// The next evaluation keeps the histories committed (the first of a step with
    /// moving prescribed displacements and a material with a frozen form).
    frozen_first: bool,
    /// The factor is kept while the iterations converge on it
    /// ([`Convergence::refactor_rate`]); otherwise every tangent the iteration
    /// method asks for is refactorised.
    kept: bool,
    /// No evaluation of this step has run yet.
    first: bool,
}

impl StepProblem for ImplicitStep<'_> {
    fn is_affine(&self) -> bool {
        !matches!(self.ops.response, Response::StateDependent(_))
    }

    fn predict(&mut self, u: &[f64], free: &[usize], rhs: &mut Vec<f64>) -> bool {
        let (ops, s, w) = (self.ops, &*self.s, &mut *self.w);
        if let Some(laws) = &ops.nodal {
            laws.predicted_force(ops.h(), &s.nodal, &mut w.f_pred_np1);
        }
        let base: &[f64] = match ops.response {
            Response::Elastic => &s.f_int,
            Response::Nodal => &w.f_pred_np1,
            Response::Constant if s.f_pred_h == ops.h() && !s.f_pred.is_empty() => &s.f_pred,
            // Damage and plasticity at the unchanged start of the step: the committed
            // force (with a kept factor; full Newton starts from an evaluation).
            Response::StateDependent(_)
                if self.kept && !self.moving && ops.rate_independent && w.factor_valid =>
            {
                &s.f_int
            }
            _ => return false,
        };
        let _ = u; // The start of the step: its increment Δu_c is in `w.du`.
        let (c_m, c_k, c_t) = ops.coefficients();
        if self.moving {
            // Δu_c is nonzero on prescribed dofs only.
            let p = &ops.asm.pattern;
            ops.mass.matvec(p, &w.du, &mut w.m_du);
            p.matvec(&ops.k, &w.du, &mut w.kdu);
            if c_t != 0.0 {
                p.matvec(&ops.kt, &w.du, &mut w.kt_du);
            }
        }
        let inv_h = ops.dynamic().map(|(h, _, _)| 1.0 / h);
        let moving = self.moving;
        let (mv_n, f_ext, m_du, kdu, kt_du) = (&s.mv, &w.f_ext_np1, &w.m_du, &w.kdu, &w.kt_du);
        let (f_int_n, f_ext_n) = (&s.f_int, &s.f_ext);
        let rule = ops.rule();
        let (hist_p, hist_d) = (&w.alpha.p, &w.alpha.d);
        let value = |i: usize| {
            // The residual at Δu = Δu_c: the forces at the step's end (averaged with
            // the start's by the trapezoidal rule and generalized-α), the momentum of
            // the start.
            let mut r = match rule {
                Rule::BackwardEuler => base[i] - f_ext[i],
                Rule::Trapezoidal => 0.5 * (base[i] + f_int_n[i]) - 0.5 * (f_ext[i] + f_ext_n[i]),
                Rule::GeneralizedAlpha(a) => {
                    let w = 1.0 - a.alpha_f;
                    w * base[i] + (1.0 - w) * f_int_n[i] - w * f_ext[i] - (1.0 - w) * f_ext_n[i]
                }
            };
            if let Some(inv_h) = inv_h {
                r -= match rule {
                    Rule::BackwardEuler => mv_n[i] * inv_h,
                    Rule::Trapezoidal => 2.0 * mv_n[i] * inv_h,
                    Rule::GeneralizedAlpha(_) => hist_p[i] - hist_d[i],
                };
            }
            if moving {
                r += c_m * m_du[i] + c_k * kdu[i];
                if c_t != 0.0 {
                    r += c_t * kt_du[i];
                }
            }
            -r
        };
        nonlinear::fill_free(free, rhs, value, (), |_, _, _| (), |_, _| ());
        true
    }

    fn wants_tangent(&mut self, iteration: usize, slow: bool) -> bool {
        let first = std::mem::take(&mut self.first);
        match (self.ops.response, self.kept) {
            (Response::StateDependent(IterationMethod::Newton), false) => true,
            (Response::StateDependent(IterationMethod::Fixed), false) => iteration == 0,
            // A kept factor is remade with the tangent of the iterate after a slow
            // iteration (Newton), or at the start of the step after a slow one (the
            // fixed point keeps one factor through a step).
            // The paper's first estimate (the committed damage at the jump of the
            // prescribed values) is a secant solve: it gets its own factor.
            (Response::StateDependent(IterationMethod::Newton), true) => {
                let w = &mut *self.w;
                slow || self.frozen_first
                    || !w.factor_valid
                    || (first && std::mem::take(&mut w.refresh_pending))
            }
            (Response::StateDependent(IterationMethod::Fixed), true) => {
                let w = &mut *self.w;
                w.refresh_pending |= slow;
                !w.factor_valid || (first && std::mem::take(&mut w.refresh_pending))
            }
            _ => false,
        }
    }

    fn evaluate(&mut self, u: &[f64], tangent: bool) -> Evaluation {
        let (ops, model) = (self.ops, self.model);
        let (s, w) = (&mut *self.s, &mut *self.w);
        let h = ops.h();
        let dynamic = ops.dynamic();
        // `w.du` is `u − u_n`: set at the start of the step and kept by
        // `apply_correction`. `mv_np1` holds M Δu until the residual pass scales it to M v = M Δu/h, and
        // `kdu` holds K Δu (the elastic force increment, and h K v for damping).
        let p = &ops.asm.pattern;
        let mut failure = None;
        let mut provisional = false;
        let elastic = ops.response == Response::Elastic;
        if elastic {
            // K Δu (and M Δu with a consistent mass) in one pass over the pattern.
            if dynamic.is_some() {
                ops.mass
                    .with_product(p, &ops.k, &w.du, &mut w.kdu, &w.du, &mut w.mv_np1);
            } else {
                p.matvec(&ops.k, &w.du, &mut w.kdu);
            }
        } else if let Some(laws) = &ops.nodal {
            if w.nodal.is_empty() {
                w.nodal = s.nodal.clone();
            }
            let t = laws.evaluate(
                p,
                &ops.k,
                h,
                u,
                &w.du,
                &s.nodal,
                &mut w.nodal,
                &mut w.f_int_np1,
                &mut w.kdu,
                dynamic.is_some().then_some(MassProduct {
                    m: &ops.mass,
                    out: &mut w.mv_np1,
                }),
            );
            w.totals = PointTotals {
                psi: t.psi,
                dissipation: t.dissipation,
                failure: None,
            };
        } else {
            let pred = (!w.f_pred_np1.is_empty()).then_some(&mut w.f_pred_np1[..]);
            let kt = tangent.then_some(&mut w.kt[..]);
            // The first evaluation of a step whose prescribed displacements jump keeps
            // the damage of the last step (the paper's first estimate): evaluated at
            // the jump, the whole increment sits in the elements next to the moved
            // dofs and could damage them in an iterate the solution never visits.
            let frozen = std::mem::take(&mut self.frozen_first);
            provisional = frozen;
            let pass = PointPass {
                u,
                dt: h,
                at_rest: false,
                frozen,
            };
            w.totals = ops.internal(model, pass, &mut s.points, &mut w.f_int_np1, pred, kt);
            failure = w.totals.failure;
            if let Some((_, _, damp_k)) = dynamic {
                if damp_k != 0.0 {
                    ops.mass
                        .with_product(p, &ops.k, &w.du, &mut w.kdu, &w.du, &mut w.mv_np1);
                } else {
                    ops.mass.matvec(p, &w.du, &mut w.mv_np1);
                }
            }
        }
        // The residual and its scales in one pass; it also finishes M v, v and, for
        // elastic models, f_int = f_int,n + K Δu, and sums the step's ledger terms
        // (with the applied loads: `finish` adds what the reactions do).
        let (damp_m, damp_k) = dynamic.map_or((0.0, 0.0), |(_, m, k)| (m, k));
        let trapezoidal = ops.rule() == Rule::Trapezoidal;
        let alpha = match ops.rule() {
            Rule::GeneralizedAlpha(a) => Some(a.at(h)),
            _ => None,
        };
        let c = PassCoefficients {
            inv_h: 1.0 / h,
            damp_m,
            damp_k,
            alpha,
        };
        let inputs = PassInputs {
            du: &w.du,
            kdu: &w.kdu,
            f_ext: &w.f_ext_np1,
            mv_n: &s.mv,
            v_n: &s.v,
            f_int_n: &s.f_int,
            f_ext_n: &s.f_ext,
            free: &ops.free_mask,
            history: alpha.map(|_| w.alpha.history()),
        };
        // In halves of a fixed tree (`crate::halves`): the same sums in every run, on
        // any number of threads.
        let n = w.r.len();
        let outputs = [
            &mut w.r[..],
            &mut w.f_int_np1[..],
            &mut w.mv_np1[..],
            &mut w.v_np1[..],
        ];
        let leaf = |(lo, [r, f_int, mv, v]): halves::Slices<4>| {
            let inp = inputs.range(lo, lo + r.len());
            let out = PassOutputs { r, f_int, mv, v };
            match (dynamic.is_some(), elastic, trapezoidal, alpha.is_some()) {
                (true, true, _, true) => residual_chunk::<true, true, false, true>(&inp, out, &c),
                (true, false, _, true) => residual_chunk::<true, false, false, true>(&inp, out, &c),
                (true, true, true, _) => residual_chunk::<true, true, true, false>(&inp, out, &c),
                (true, false, true, _) => residual_chunk::<true, false, true, false>(&inp, out, &c),
                (true, true, false, _) => residual_chunk::<true, true, false, false>(&inp, out, &c),
                (true, false, false, _) => {
                    residual_chunk::<true, false, false, false>(&inp, out, &c)
                }
                (false, true, ..) => residual_chunk::<false, true, false, false>(&inp, out, &c),
                (false, false, ..) => residual_chunk::<false, false, false, false>(&inp, out, &c),
            }
        };
        let sums = halves::in_halves(
            (0, outputs),
            n,
            halves::VECTOR_LEAF,
            &halves::split_slices,
            &leaf,
            &PassSums::merge,
        );
        w.ledger_sums = sums;
        Evaluation {
            force_scale2: sums.force_scale2,
            magnitude2: sums.magnitude2,
            increment2: sums.increment2,
            tangent,
            failure,
            provisional,
        }
    }

    fn residual(&self) -> &[f64] {
        &self.w.r
    }

    fn residual_mut(&mut self) -> &mut [f64] {
        &mut self.w.r
    }

    /// Keeps the factor when the new tangent is the one it holds (same factor, same
    /// coefficients, the same values bit for bit: the solve is then the one a
    /// refactorisation would give), and refactorises otherwise.
    fn update_matrix(&mut self, sys: &mut EffectiveSystem) -> Result<Factored> {
        let w = &mut *self.w;
        let key = (sys.factorizations(), self.ops.coefficients());
        if w.kept == Some(key) && w.factored_kt == w.kt {
            w.reused += 1;
            return Ok(Factored::Ok);
        }
        let f = self.ops.refactor(sys, &w.kt)?;
        w.factor_valid = f == Factored::Ok;
        w.kept = None;
        if f == Factored::Ok {
            w.factored_kt.clone_from(&w.kt);
            w.kept = Some((sys.factorizations(), self.ops.coefficients()));
        }
        Ok(f)
    }

    fn apply_correction(&mut self, u: &mut [f64], free: &[usize], delta: &[f64]) -> f64 {
        self.w.corrections += 1;
        nonlinear::add_on_free(free, delta, u, Some(&mut self.w.du))
    }
}

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

/// Runs one implicit step from `s` to `t + h` with `correction`; on acceptance `s`
/// holds the new state and its ledger line, on rejection `s` is unchanged.
pub(crate) fn step(
    model: &Model,
    ops: &Operators,
    sys: &mut EffectiveSystem,
    w: &mut Scratch,
    correction: &mut Corrector,
    mut predictor: Option<&mut Predictor>,
    s: &mut State,
) -> Result<StepOutcome> {
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
                return Ok(StepOutcome::Rejected(Rejection { outcome, message }));
            }
        }
    }
    if let Rule::GeneralizedAlpha(a) = ops.rule() {
        super::generalized_alpha::history(ops, &a, s, &mut w.alpha);
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
        w.fallbacks += 1;
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
            // A step that needed more iterations on the kept factor than a refreshed
            // one would: the factor no longer fits the state (points that yielded and
            // now unload, a zone that stopped growing), so the next step remakes it.
            if kept && iterations > nonlinear::KEPT_ITERATIONS as usize + 1 {
                w.refresh_pending = true;
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
            return Ok(StepOutcome::Rejected(Rejection { outcome, message }));
        }
        other => {
            if let Some(p) = predictor {
                p.restore(s);
            }
            let message = describe(model, &other, t1, h);
            return Ok(StepOutcome::Rejected(Rejection {
                outcome: other,
                message,
            }));
        }
    };
    let contact = correction.finish(&w.du, s);
    finish(ops, sys.dofs(), w, s, t1, contact, predicted);
    if let Some((quantity, value)) = s.ledger.first_non_finite() {
        return Err(Error::NonFinite {
            quantity: format!("the ledger line {quantity}"),
            value,
            location: None,
            t: t1,
        });
    }
    Ok(StepOutcome::Accepted(report))
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

/// Books the converged step and makes it the state. The last evaluation summed the
/// step's ledger terms with the applied loads; the reactions (the residual on the
/// constrained dofs) are added here, with their part of the work terms.
fn finish(
    ops: &Operators,
    dofs: &DofMap,
    w: &mut Scratch,
    s: &mut State,
    t1: f64,
    (contact, friction): (f64, f64),
    predictor: f64,
) {
    let mut sums = w.ledger_sums;
    let trapezoidal = ops.rule() == Rule::Trapezoidal;
    // The residual on a constrained dof is the reaction the step's equation needs:
    // at the end (backward Euler), or in the average ½(R_n + R_{n+1}) (trapezoidal).
    let end_weight = 1.0 / ops.rule().theta();
    for &d in &dofs.constrained {
        let reaction = end_weight * w.r[d];
        w.f_ext_np1[d] += reaction;
        // External work and load jump are linear in f_ext,n+1.
        sums.work[1] += w.du[d] * reaction;
        sums.work[2] += w.du[d] * reaction;
    }
    let work = StepWork::from_sums(sums.work);
    let alpha_f = match ops.rule() {
        Rule::GeneralizedAlpha(a) => Some(a.alpha_f),
        _ => None,
    };
    let (elastic_energy, mut material) = if ops.response == Response::Elastic {
        (
            ops.stored.of(&w.u_np1, &w.f_int_np1),
            Dissipation {
                numerical: match (trapezoidal, alpha_f) {
                    (true, _) => 0.0,
                    // Δu·f_int,n+1−α_f = ΔE_el + (1 − 2α_f) ½Δu·KΔu.
                    (_, Some(af)) => (1.0 - 2.0 * af) * sums.elastic_loss,
                    _ => sums.elastic_loss,
                },
                ..Default::default()
            },
        )
    } else {
        (w.totals.psi, w.totals.dissipation)
    };
    // The trapezoidal rule works with ½Δu·(f_int,n + f_int,n+1) where the points book
    // σ_{n+1}:Δε (their algorithmic loss is backward Euler's), and with the averaged
    // loads, so the load jump is no loss of it (theory/trapezoidal.md). Generalized-α
    // weighs the start by α_f: 2α_f of the jumps, and its inertia's own loss.
    let scheme_loss = if trapezoidal {
        if ops.response != Response::Elastic {
            material.numerical -= sums.internal_jump;
        }
        work.load_jump
    } else if let Some(af) = alpha_f {
        if ops.response != Response::Elastic {
            material.numerical -= 2.0 * af * sums.internal_jump;
        }
        sums.scheme_loss + 2.0 * af * work.load_jump
    } else {
        sums.scheme_loss
    };
    if let Rule::GeneralizedAlpha(a) = ops.rule() {
        // a_{n+1} from v_{n+1} = v_n + h((1 − γ) a_n + γ a_{n+1}).
        let h = ops.h();
        let g = a.gamma;
        w.a_np1.clear();
        w.a_np1.extend(
            w.v_np1
                .iter()
                .zip(&s.v)
                .zip(&s.a)
                .map(|((v1, v0), a0)| (v1 - v0 - h * (1.0 - g) * a0) / (h * g)),
        );
        std::mem::swap(&mut s.a, &mut w.a_np1);
    }
    s.ledger.record(&StepIncrements {
        kinetic: sums.kinetic,
        elastic: elastic_energy,
        work,
        material,
        scheme_loss,
        contact,
        friction,
        predictor,
    });
    std::mem::swap(&mut s.u, &mut w.u_np1);
    std::mem::swap(&mut s.f_int, &mut w.f_int_np1);
    std::mem::swap(&mut s.f_ext, &mut w.f_ext_np1);
    if ops.dynamic().is_some() {
        std::mem::swap(&mut s.v, &mut w.v_np1);
        std::mem::swap(&mut s.mv, &mut w.mv_np1);
    }
    if ops.response == Response::Nodal {
        std::mem::swap(&mut s.nodal, &mut w.nodal);
    } else {
        if !w.f_pred_np1.is_empty() {
            std::mem::swap(&mut s.f_pred, &mut w.f_pred_np1);
            s.f_pred_h = ops.h();
        }
        s.points.iter_mut().for_each(|p| p.commit());
    }
    s.t = t1;
    s.step += 1;
}

/// The matrices of a model's first step, for export: `K` and `M` on the shared
/// pattern (with the assembler), and the effective matrix on the free dofs, analysed
/// but not factorised (the tangent at rest for materials with history).
pub fn first_matrices(model: &Model) -> Result<(Assembler, Vec<f64>, Mass, EffectiveSystem)> {
    let a = &model.analysis;
    let scheme = match a.time.kind {
        crate::model::AnalysisKind::Dynamic => Scheme::Dynamic {
            h: a.time.dt,
            damp_m: a.damping.zeta + a.damping.rayleigh[0],
            damp_k: a.damping.rayleigh[1],
            rule: super::operators::Rule::of(&a.time),
        },
        crate::model::AnalysisKind::Static => Scheme::Static { dt: a.time.dt },
    };
    let ops = Operators::new(model, scheme);
    let mut sys = ops.analysed_system(model, Backend::Faer)?;
    let kt = match ops.response {
        Response::StateDependent(_) => {
            let stores = new_stores(&model.mesh, &model.materials);
            let u0 = vec![0.0; model.mesh.n_dofs()];
            ops.asm.tangent(
                &model.mesh,
                &model.materials,
                model.idealisation,
                &u0,
                ops.h(),
                &stores,
            )
        }
        _ => ops.kt.clone(),
    };
    ops.refill(&mut sys, &kt);
    Ok((ops.asm, ops.k, ops.mass, sys))
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
            ops.a0 = super::generalized_alpha::initial_acceleration(model, &ops, &mut sys)?;
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
        let predictor = (ops.dynamic().is_some()
            && model.analysis.time.contact_predictor == ContactPredictor::Stabilised)
            .then(|| Predictor::new(model, &ops, backend))
            .transpose()?;
        let mut scratch = Scratch::new(model.mesh.n_dofs(), &ops, sys.dofs().n_free());
        if let Some(kt) = kt_at_rest {
            // The factor holds the tangent at rest: kept while the points stay there.
            scratch.factored_kt = kt;
            scratch.kept = Some((sys.factorizations(), ops.coefficients()));
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
        })
    }

    /// One step (see [`step`]), timed.
    pub fn step(&mut self, s: &mut State) -> Result<StepOutcome> {
        let t = Instant::now();
        let before = self.sys.timing();
        let r = step(
            self.model,
            &self.ops,
            &mut self.sys,
            &mut self.scratch,
            &mut self.correction,
            self.predictor.as_mut(),
            s,
        );
        let after = self.sys.timing();
        self.step_other_s += t.elapsed().as_secs_f64()
            - (after.solve_s - before.solve_s)
            - (after.factorization_s - before.factorization_s);
        r
    }

    /// Changes the step size; refactorises what depends on it.
    pub fn set_step(&mut self, h: f64) -> Result<()> {
        if h == self.ops.h() {
            return Ok(());
        }
        self.ops.set_h(self.model, h);
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
            self.scratch.factor_valid = f == Factored::Ok;
            return Ok(());
        }
        match self.ops.refactor(&mut self.sys, &self.ops.kt)? {
            Factored::Ok => Ok(()),
            Factored::NotPositiveDefinite { message, .. } => Err(Error::Stepping(format!(
                "the effective matrix for h = {h:e} is not positive definite ({message})"
            ))),
        }
    }

    /// Time per phase.
    pub fn timing(&self) -> super::Timing {
        let t = self.sys.timing();
        super::Timing {
            assembly_s: self.assembly_s,
            factorization_s: t.analysis_s + t.factorization_s,
            solve_s: t.solve_s,
            step_other_s: self.step_other_s,
        }
    }

    /// Solver facts.
    pub fn solver(&self) -> super::SolverFacts {
        super::SolverFacts {
            backend: self.sys.backend(),
            factorizations: self.sys.factorizations(),
            reused_factors: self.scratch.reused,
            fallbacks: self.scratch.fallbacks,
            factor_nnz: self.sys.factor_nnz(),
        }
    }
}
