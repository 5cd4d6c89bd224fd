//! The step problem an implicit step hands to the equilibrium loop
//! ([`crate::nonlinear::StepProblem`]), and the step's scratch vectors.
//!
//! The step residual, with `Δu = u − u_n`, `v = Δu/h`:
//! - backward Euler: `r(u) = M(v − v_n)/h + (zeta + a_m) M v + a_k K v + f_int(u) − f_ext`,
//! - statics: `r(u) = f_int(u) − f_ext`,
//!
//! with `f_int(u) = f_int,n + K Δu` for linear elasticity and the Gauss-point loop
//! otherwise. Its derivative is the effective matrix
//! `K_eff = c_m M + c_k K + K_t` (`c_m = 1/h² + (zeta+a_m)/h` or 0, see
//! [`Operators::coefficients`]). See `theory/scheme.md`.

use super::kept_factor::KeptFactor;
use super::nodal::{MassProduct, NodalState};
use super::operators::{Operators, Response, Rule};
use super::residual::{residual_chunk, PassCoefficients, PassInputs, PassOutputs, PassSums};
use super::State;
use crate::assembly::internal::{PointPass, PointTotals};
use crate::error::Result;
use crate::halves;
use crate::model::{IterationMethod, Model};
use crate::nonlinear::{self, Evaluation, StepProblem};
use crate::system::{EffectiveSystem, Factored};

/// The vectors of the step being solved (reused from step to step).
#[derive(Default)]
pub(crate) struct Scratch {
    /// The iterate `u_{n+1}`.
    pub u_np1: Vec<f64>,
    /// `u − u_n`.
    pub du: Vec<f64>,
    /// `v_{n+1} = Δu/h`.
    pub v_np1: Vec<f64>,
    /// `M v_{n+1}`.
    pub mv_np1: Vec<f64>,
    /// `f_int(u)`.
    pub f_int_np1: Vec<f64>,
    /// Applied external forces at `t_{n+1}`; the reactions are added once converged.
    pub f_ext_np1: Vec<f64>,
    /// Predicted internal force of the following step (nodal fields: of this step).
    pub f_pred_np1: Vec<f64>,
    /// Trial nodal fields.
    pub nodal: NodalState,
    /// `K Δu` (elastic) or `K v` (stiffness damping of history materials).
    pub kdu: Vec<f64>,
    /// `M Δu_c` in a prediction.
    pub m_du: Vec<f64>,
    /// `K_t Δu_c` in a prediction.
    pub kt_du: Vec<f64>,
    /// The residual (all dofs).
    pub r: Vec<f64>,
    /// Generalized-α: the step's start vectors, and the new acceleration.
    pub alpha: super::step_start::StartVectors,
    pub a_np1: Vec<f64>,
    /// Tangent of the last evaluation (state-dependent materials).
    pub kt: Vec<f64>,
    /// The kept factor's policy and record.
    pub factor: KeptFactor,
    /// Corrections taken over the run (a step's count includes a failed attempt on
    /// a kept factor).
    pub corrections: usize,
    /// Material totals of the last evaluation.
    pub totals: PointTotals,
    /// The ledger sums of the last evaluation: the four work integrands (applied
    /// loads), kinetic energy, the scheme's loss, and for elastic models the stored
    /// energy and `½ Δu·K Δu`.
    pub ledger_sums: PassSums,
    pub nl: nonlinear::Scratch,
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
            factor: KeptFactor::default(),
            corrections: 0,
            totals: PointTotals::default(),
            ledger_sums: PassSums::default(),
            nl: nonlinear::Scratch::new(n_free, ops.test.max_iterations),
        }
    }
}

/// The step problem handed to the equilibrium loop.
pub(crate) struct ImplicitStep<'a> {
    pub model: &'a Model,
    pub ops: &'a Operators,
    /// The committed state (its Gauss-point stores take the trial states).
    pub s: &'a mut State,
    pub w: &'a mut Scratch,
    /// Prescribed displacements move in this step (`Δu_c ≠ 0`).
    pub moving: bool,
    /// The next evaluation keeps the histories committed (the first of a step with
    /// moving prescribed displacements and a material with a frozen form).
    pub frozen_first: bool,
    /// The factor is kept while the iterations converge on it
    /// ([`Convergence::refactor_rate`]); otherwise every tangent the iteration
    /// method asks for is refactorised.
    pub kept: bool,
    /// No evaluation of this step has run yet.
    pub first: bool,
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
                if self.kept && !self.moving && ops.rate_independent && w.factor.valid =>
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
            (Response::StateDependent(method), true) => {
                self.w
                    .factor
                    .wants_tangent(method, first, slow, self.frozen_first)
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

    /// The kept factor's decision ([`KeptFactor::update`]).
    fn update_matrix(&mut self, sys: &mut EffectiveSystem) -> Result<Factored> {
        let w = &mut *self.w;
        w.factor.update(self.ops, sys, &w.kt)
    }

    fn apply_correction(&mut self, u: &mut [f64], free: &[usize], delta: &[f64]) -> f64 {
        self.w.corrections += 1;
        nonlinear::add_on_free(free, delta, u, Some(&mut self.w.du))
    }
}
