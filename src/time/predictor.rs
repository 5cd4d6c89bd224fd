//! The contact-stabilised predictor of the second-order implicit schemes
//! (`analysis.contact_predictor = "stabilised"`, `theory/trapezoidal.md`).
//!
//! Before a step from `(u_n, v_n)` the free flight `x = u_n + h v_n` is projected in
//! the mass norm onto the admissible set,
//!
//! `u_pred = argmin ½ (u − x)ᵀ M (u − x)   subject to   g(u) ≥ 0`,
//!
//! and the step starts from the velocity of the projection, `v̂_n = (u_pred − u_n)/h`,
//! instead of `v_n`. Only the dofs the contact rows reach (and, with a consistent
//! mass, their neighbours) change: a node that would have crossed its master in the
//! step arrives at rest on it, so the step's contact force no longer has to reverse
//! its momentum, and the velocity chatter of the trapezoidal rule's contact nodes
//! (`v_{n+1} = −v_n` at a node held still) goes. The kinetic energy the projection
//! removes, `½ v_nᵀ M v_n − ½ v̂_nᵀ M v̂_n`, is the predictor's loss `D_predictor`:
//! non-negative when the admissible set is convex and holds `u_n` (the projection
//! onto a convex set does not lengthen the step from a point of it), and booked as
//! computed in any case.
//!
//! The projection is the equilibrium problem of the step with the mass for the
//! effective matrix and `M (u − x)` for the residual, so it goes through the same
//! loop and the same contact correction (frictionless: the predictor enforces
//! impenetrability only) on a factor of `M` made once.

use super::operators::Operators;
use super::State;
use crate::contact::{ContactCorrection, ContactState};
use crate::error::{Error, Result};
use crate::linsolve::Backend;
use crate::model::Model;
use crate::nonlinear::{self, Convergence, Evaluation, Outcome, StepProblem};
use crate::system::{EffectiveSystem, Factored};

/// The projection's factor, contact correction and vectors.
pub(crate) struct Predictor<'m> {
    sys: EffectiveSystem,
    correction: ContactCorrection<'m>,
    /// The iterate `u`, and the work vectors of [`Projection`].
    u: Vec<f64>,
    work: Work,
    nl: nonlinear::Scratch,
    /// The committed `v_n` and `M v_n` of the step being taken (restored when it is
    /// rejected).
    saved_v: Vec<f64>,
    saved_mv: Vec<f64>,
    /// Steps whose projection changed the velocity.
    pub active: usize,
}

/// `h M v_n`, `u − u_n`, `M (u − u_n)` and the residual.
#[derive(Default)]
struct Work {
    lead: Vec<f64>,
    du: Vec<f64>,
    m_du: Vec<f64>,
    r: Vec<f64>,
}

/// The projection as a step problem: residual `M (u − u_n) − h M v_n`, matrix `M`.
struct Projection<'a> {
    ops: &'a Operators,
    u_n: &'a [f64],
    w: &'a mut Work,
    /// No evaluation yet: the first one never ends the projection, so that rows
    /// within the contact tolerance are closed to `g ≥ 0` by one QP.
    first: bool,
}

impl StepProblem for Projection<'_> {
    fn is_affine(&self) -> bool {
        true
    }

    fn predict(&mut self, _u: &[f64], _free: &[usize], _rhs: &mut Vec<f64>) -> bool {
        false
    }

    fn wants_tangent(&mut self, _iteration: usize, _slow: bool) -> bool {
        false
    }

    fn evaluate(&mut self, u: &[f64], _tangent: bool) -> Evaluation {
        let w = &mut *self.w;
        w.du.clear();
        w.du.extend(u.iter().zip(self.u_n).map(|(a, b)| a - b));
        self.ops
            .mass
            .matvec(&self.ops.asm.pattern, &w.du, &mut w.m_du);
        let mut ev = Evaluation {
            provisional: std::mem::take(&mut self.first),
            ..Default::default()
        };
        for (d, ((r, m_du), lead)) in w.r.iter_mut().zip(&w.m_du).zip(&w.lead).enumerate() {
            *r = m_du - lead;
            if self.ops.free_mask[d] != 0.0 {
                ev.force_scale2 += m_du * m_du + lead * lead;
                ev.magnitude2 += (m_du.abs() + lead.abs()).powi(2);
                ev.increment2 += w.du[d] * w.du[d];
            }
        }
        ev
    }

    fn residual(&self) -> &[f64] {
        &self.w.r
    }

    fn residual_mut(&mut self) -> &mut [f64] {
        &mut self.w.r
    }

    fn update_matrix(&mut self, _sys: &mut EffectiveSystem) -> Result<Factored> {
        Ok(Factored::Ok)
    }
}

impl<'m> Predictor<'m> {
    /// Factorises the mass on the free dofs (the pattern and ordering the steps use).
    pub fn new(model: &'m Model, ops: &Operators, backend: Backend) -> Result<Self> {
        let n = model.mesh.n_dofs();
        let mut sys = ops.analysed_system(model, backend)?;
        sys.refill(1.0, &ops.mass, &[]);
        if let Factored::NotPositiveDefinite { message, .. } = sys.factorize()? {
            return Err(Error::Solver {
                backend: sys.backend(),
                message: format!(
                    "the mass matrix of the contact predictor is not positive definite ({message})"
                ),
            });
        }
        let n_free = sys.dofs().n_free();
        let z = || vec![0.0; n];
        Ok(Predictor {
            sys,
            correction: ContactCorrection::new(model).frictionless(),
            u: z(),
            work: Work {
                lead: z(),
                du: z(),
                m_du: z(),
                r: z(),
            },
            nl: nonlinear::Scratch::new(n_free, ops.test.max_iterations),
            saved_v: Vec::new(),
            saved_mv: Vec::new(),
            active: 0,
        })
    }

    /// Projects the free flight of `s` over the step and replaces `s.v` and `s.mv`
    /// by the projection's velocity `v_n + (u_pred − x)/h` (exactly `v_n` where the
    /// projection moved nothing); returns the kinetic energy removed, or the
    /// outcome of a projection that did not converge (then `s` is unchanged).
    pub fn project(
        &mut self,
        ops: &Operators,
        s: &mut State,
    ) -> Result<std::result::Result<f64, Outcome>> {
        let h = ops.h();
        let Predictor {
            sys,
            correction,
            u,
            work,
            nl,
            saved_v,
            saved_mv,
            active,
        } = self;
        saved_v.clear();
        work.lead.clear();
        work.lead.extend(s.mv.iter().map(|m| h * m));
        u.clear();
        u.extend(s.u.iter().zip(&s.v).map(|(u, v)| u + h * v));
        // Without the step's multipliers (they are forces, the projection's are
        // impulses times h), from the geometry of the step's start, so that a slave
        // that would cross its master within the step is swept.
        correction.begin_step(&ContactState::default(), &s.u, None);
        let test = Convergence {
            refactor_rate: None,
            ..ops.test
        };
        let mut problem = Projection {
            ops,
            u_n: &s.u,
            w: work,
            first: true,
        };
        let outcome = nonlinear::solve(&mut problem, correction, sys, &test, u, nl)?;
        if !outcome.converged() {
            return Ok(Err(outcome));
        }
        if !correction.has_forces() {
            // Nothing to project: the committed velocity, not its round-off image.
            return Ok(Ok(0.0));
        }
        saved_v.clone_from(&s.v);
        saved_mv.clone_from(&s.mv);
        let mut changed = false;
        for (((v, u1), u0), v0) in s.v.iter_mut().zip(u.iter()).zip(&s.u).zip(saved_v.iter()) {
            let moved = u1 - (u0 + h * v0);
            if moved != 0.0 {
                changed = true;
                *v += moved / h;
            }
        }
        if !changed {
            return Ok(Ok(0.0));
        }
        *active += 1;
        ops.mass.matvec(&ops.asm.pattern, &s.v, &mut s.mv);
        // ½ v·Mv − ½ v̂·Mv̂ = ½ (v − v̂)·M(v + v̂): the change itself, not the
        // difference of two kinetic energies (whose round-off is the energy's).
        let loss = 0.5
            * saved_v
                .iter()
                .zip(&s.v)
                .zip(saved_mv.iter().zip(&s.mv))
                .map(|((v0, v1), (m0, m1))| (v0 - v1) * (m0 + m1))
                .sum::<f64>();
        Ok(Ok(loss))
    }

    /// Puts back the committed velocity of a step that was rejected after its
    /// projection.
    pub fn restore(&self, s: &mut State) {
        if !self.saved_v.is_empty() {
            s.v.clone_from(&self.saved_v);
            s.mv.clone_from(&self.saved_mv);
        }
    }
}
