//! The operators of an implicit scheme: how the materials respond (which decides how
//! the effective matrix is kept and when it is refactorised), the time scheme's
//! coefficients, and the matrices, masks and convergence test a step reads.

use super::forces::{external_force, gravity_force};
use super::nodal::{NodalLaws, NodalState};
use super::State;
use crate::assembly::internal::{new_stores, PointPass, PointTotals};
use crate::assembly::{Assembler, Mass};
use crate::energy::Ledger;
use crate::error::Result;
use crate::linsolve::Backend;
use crate::material::store::StateStore;
use crate::model::{IterationMethod, Model, ViscoelasticState};
use crate::nonlinear::Convergence;
use crate::system::{DofMap, EffectiveSystem, Factored};

/// How the materials respond, which decides how the effective matrix is kept.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Response {
    /// Every material is linear elastic: `f_int = K u`, no Gauss-point state.
    Elastic,
    /// Materials with history whose tangent is constant for a fixed step (linear
    /// viscoelasticity), their state at the Gauss points: factorised once per step
    /// size, affine step, a Gauss-point pass per evaluation.
    Constant,
    /// The same materials with their state in nodal fields ([`super::nodal`]): a
    /// step of matrix-vector products.
    Nodal,
    /// A state-dependent tangent (damage, plasticity), followed as `iteration` says.
    StateDependent(IterationMethod),
}

/// The time discretisation of the step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Scheme {
    /// Inertia, with step `h` and damping `C = damp_m M + damp_k K`, by `rule`.
    Dynamic {
        /// Step size.
        h: f64,
        /// Mass-proportional damping `zeta + a_m` (1/s).
        damp_m: f64,
        /// Stiffness-proportional damping `a_k` (s).
        damp_k: f64,
        /// Backward Euler or the trapezoidal rule.
        rule: Rule,
    },
    /// Static equilibrium at load steps of size `dt` (the material rates use it).
    Static {
        /// Load step size.
        dt: f64,
    },
}

/// The rule of an implicit dynamic step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Rule {
    /// Backward Euler, eq. (9): `v = Δu/h`, the equation at the step's end.
    BackwardEuler,
    /// The trapezoidal rule in averaged-force form: `v = 2Δu/h − v_n`, the internal
    /// and applied forces averaged over the step, the contact force at its end
    /// (`theory/trapezoidal.md`).
    Trapezoidal,
    /// Chung and Hulbert's generalized-α (`theory/trapezoidal.md`): the acceleration
    /// carried, inertia at `n+1−α_m`, damping, internal and applied forces at
    /// `n+1−α_f`, the contact force at the step's end.
    GeneralizedAlpha(super::generalized_alpha::Alpha),
}

impl Rule {
    /// The rule of a dynamic scheme (central differences has none).
    pub fn of(time: &crate::model::TimeSettings) -> Rule {
        match time.scheme {
            crate::model::TimeScheme::Trapezoidal => Rule::Trapezoidal,
            crate::model::TimeScheme::GeneralizedAlpha => {
                Rule::GeneralizedAlpha(super::generalized_alpha::Alpha::of(time.rho_inf))
            }
            _ => Rule::BackwardEuler,
        }
    }

    /// The weight of the step's end in the internal and applied forces (1, ½ or
    /// `1 − α_f`); the start has the rest.
    pub fn theta(self) -> f64 {
        match self {
            Rule::BackwardEuler => 1.0,
            Rule::Trapezoidal => 0.5,
            Rule::GeneralizedAlpha(a) => 1.0 - a.alpha_f,
        }
    }
}

/// Matrices and settings of an implicit scheme: built once, read by every step.
pub(crate) struct Operators {
    pub asm: Assembler,
    /// Elastic stiffness on the shared pattern.
    pub k: Vec<f64>,
    pub mass: Mass,
    pub gravity: Option<Vec<f64>>,
    pub response: Response,
    /// The tangent at rest for the current step size: the constant tangent of
    /// `Response::Constant` and `Response::Nodal`, the base of the state-dependent
    /// tangent of `Response::StateDependent` (empty for elastic models).
    pub kt: Vec<f64>,
    /// The nodal-field laws of `Response::Nodal`.
    pub nodal: Option<NodalLaws>,
    pub scheme: Scheme,
    /// 1 on free dofs, 0 on constrained ones (sums over the free dofs without a
    /// branch).
    pub free_mask: Vec<f64>,
    pub test: Convergence,
    /// Every material is rate-independent ([`crate::material::Material::is_rate_independent`]).
    pub rate_independent: bool,
    /// Statics: the multiple of `M` added to the matrix (never to the residual) while
    /// a body in contact has rigid motions no support holds
    /// ([`super::seat::STATIC_SEAT`]).
    pub seat: f64,
    /// The stored energy of elastic models, translation removed.
    pub stored: crate::energy::StoredEnergy,
    /// Generalized-α: the initial acceleration (`M a_0 = f_ext − f_int − C v_0` on the
    /// free dofs), empty otherwise.
    pub a0: Vec<f64>,
}

impl Operators {
    /// Assembles `K`, `M` (statics: only for gravity), gravity, the constant tangent,
    /// and decides the response of the model's materials.
    pub fn new(model: &Model, scheme: Scheme) -> Self {
        let a = &model.analysis;
        let asm = Assembler::new(&model.mesh);
        let k = asm.stiffness(&model.mesh, &model.materials, model.idealisation);
        let mass = asm.mass(&model.mesh, &model.materials, a.time.lumped_mass);
        let gravity = gravity_force(model, &mass, &asm.pattern);
        let response = if model.materials.iter().all(|m| m.is_linear_elastic()) {
            Response::Elastic
        } else if model.materials.iter().all(|m| m.has_constant_tangent()) {
            match a.time.viscoelastic_state {
                ViscoelasticState::Nodal => Response::Nodal,
                ViscoelasticState::Points => Response::Constant,
            }
        } else {
            Response::StateDependent(a.iteration.method)
        };
        let mut free_mask = vec![1.0; model.mesh.n_dofs()];
        for c in &model.constraints {
            free_mask[c.dof] = 0.0;
        }
        let mut ops = Operators {
            asm,
            k,
            mass,
            gravity,
            response,
            kt: Vec::new(),
            nodal: None,
            scheme,
            free_mask,
            rate_independent: model.materials.iter().all(|m| m.is_rate_independent()),
            seat: 0.0,
            stored: crate::energy::StoredEnergy::new(&model.mesh),
            a0: Vec::new(),
            test: Convergence {
                tolerance: a.iteration.tolerance,
                displacement_tolerance: a.iteration.displacement_tolerance,
                max_iterations: a.iteration.max_iterations,
                penetration_tolerance: a.contact.tolerance,
                complementarity_tolerance: a.contact.tolerance,
                refactor_rate: a.iteration.refactor_rate,
            },
        };
        if response == Response::Nodal {
            ops.nodal = NodalLaws::new(model, &ops.asm);
            if ops.nodal.is_none() {
                // A constant-tangent material without a nodal-field form: its state
                // stays at the Gauss points.
                ops.response = Response::Constant;
            }
        }
        ops.update_constant_tangent(model);
        if matches!(scheme, Scheme::Static { .. }) {
            ops.seat = super::seat::seat(model, &ops.asm.pattern, &ops.k, &ops.mass);
        }
        ops
    }

    /// The step size (statics: the load step).
    pub fn h(&self) -> f64 {
        match self.scheme {
            Scheme::Dynamic { h, .. } => h,
            Scheme::Static { dt } => dt,
        }
    }

    /// Sets the rule of a dynamic step (generalized-α's impact steps take the
    /// trapezoidal rule's); statics has none.
    pub fn set_rule(&mut self, new: Rule) {
        if let Scheme::Dynamic { rule, .. } = &mut self.scheme {
            *rule = new;
        }
    }

    /// Sets the step size.
    pub fn set_h(&mut self, model: &Model, h_new: f64) {
        match &mut self.scheme {
            Scheme::Dynamic { h, .. } => *h = h_new,
            Scheme::Static { dt } => *dt = h_new,
        }
        self.update_constant_tangent(model);
    }

    /// The tangent at rest at the current step size, from fresh stores: the whole
    /// tangent of constant-tangent materials (it does not depend on the state), and
    /// for state-dependent ones the base their tangent is assembled on (every point
    /// elastic; `Assembler::internal_force` adds what departs from it).
    fn update_constant_tangent(&mut self, model: &Model) {
        if self.response != Response::Elastic {
            let stores = new_stores(&model.mesh, &model.materials);
            let u0 = vec![0.0; model.mesh.n_dofs()];
            self.kt = self.asm.tangent(
                &model.mesh,
                &model.materials,
                model.idealisation,
                &u0,
                self.h(),
                &stores,
            );
        }
    }

    /// `(c_m, c_k, c_t)` of `K_eff = c_m M + c_k K + c_t K_t`.
    pub fn coefficients(&self) -> (f64, f64, f64) {
        let c_t = if self.response == Response::Elastic {
            0.0
        } else {
            1.0
        };
        match self.scheme {
            Scheme::Dynamic {
                h,
                damp_m,
                damp_k,
                rule,
            } => {
                // r = M(v − v_n)/h + C(v + v_n)/2 or C v + θ f_int + …, with
                // ∂v/∂u = 1/(θh): the mass term 1/(θh²), the damping 1/h, the
                // internal force's θ. Generalized-α: ∂a_{n+1−α_m}/∂u = c_in,
                // ∂v_{n+1−α_f}/∂u = w c_v.
                let theta = rule.theta();
                let (mass, damp) = match rule {
                    Rule::GeneralizedAlpha(a) => {
                        let s = a.at(h);
                        (s.c_in, s.w * s.c_v)
                    }
                    _ => (1.0 / (theta * h * h), 1.0 / h),
                };
                let c_m = mass + damp_m * damp;
                let c_k = if c_t == 0.0 {
                    theta + damp_k * damp
                } else {
                    damp_k * damp
                };
                (c_m, c_k, theta * c_t)
            }
            Scheme::Static { .. } => (self.seat, 1.0 - c_t, c_t),
        }
    }

    /// Refills the effective matrix with the tangent `kt` (ignored for elastic
    /// models).
    pub fn refill(&self, sys: &mut EffectiveSystem, kt: &[f64]) {
        let (c_m, c_k, c_t) = self.coefficients();
        if c_t == 0.0 {
            sys.refill(c_m, &self.mass, &[(c_k, &self.k)]);
        } else if c_k == 0.0 {
            sys.refill(c_m, &self.mass, &[(c_t, kt)]);
        } else {
            sys.refill(c_m, &self.mass, &[(c_k, &self.k), (c_t, kt)]);
        }
    }

    /// Refills the effective matrix with the tangent `kt` and refactorises it.
    pub fn refactor(&self, sys: &mut EffectiveSystem, kt: &[f64]) -> Result<Factored> {
        self.refill(sys, kt);
        sys.factorize()
    }

    /// The initial effective matrix: the elastic or constant one, or for
    /// state-dependent materials the tangent at rest.
    pub fn initial_system(
        &self,
        model: &Model,
        backend: Backend,
        memory_limit: Option<u64>,
    ) -> Result<(EffectiveSystem, Factored, Option<Vec<f64>>)> {
        let mut sys = self.analysed_system(model, backend)?;
        // The analysis knows the factor's size: refuse before it is allocated.
        match sys.distributed() {
            Some(d) => {
                crate::memory::check_distributed(model, d, memory_limit, "the factorisation")?
            }
            None => crate::memory::of_model(model, sys.factor_nnz())
                .check(memory_limit, "the factorisation")?,
        }
        let factored = match self.response {
            Response::StateDependent(_) => {
                let f = self.refactor(&mut sys, &self.kt)?;
                return Ok((sys, f, Some(self.kt.clone())));
            }
            _ => self.refactor(&mut sys, &self.kt)?,
        };
        Ok((sys, factored, None))
    }

    /// A system on the run's pattern, free dofs and ordering, analysed (values zero
    /// until refilled): the effective matrix's, or the contact predictor's mass.
    pub fn analysed_system(&self, model: &Model, backend: Backend) -> Result<EffectiveSystem> {
        let dofs = DofMap::new(model.mesh.n_dofs(), model.constraints.iter().map(|c| c.dof));
        EffectiveSystem::new(
            &self.asm.pattern,
            dofs,
            backend,
            model.analysis.iteration.ordering,
            &model.mesh.coords,
        )
    }

    /// The rule of a dynamic step (statics: backward Euler's weights, θ = 1).
    pub(crate) fn rule(&self) -> Rule {
        match self.scheme {
            Scheme::Dynamic { rule, .. } => rule,
            Scheme::Static { .. } => Rule::BackwardEuler,
        }
    }

    /// Whether the scheme has inertia (backward Euler) or not (statics).
    pub(crate) fn dynamic(&self) -> Option<(f64, f64, f64)> {
        match self.scheme {
            Scheme::Dynamic {
                h, damp_m, damp_k, ..
            } => Some((h, damp_m, damp_k)),
            Scheme::Static { .. } => None,
        }
    }

    pub(crate) fn internal(
        &self,
        model: &Model,
        pass: PointPass,
        points: &mut [crate::material::store::StateStore],
        f: &mut [f64],
        f_pred: Option<&mut [f64]>,
        tangent: Option<&mut [f64]>,
    ) -> PointTotals {
        self.asm.internal_force(
            &model.mesh,
            &model.materials,
            model.idealisation,
            pass,
            points,
            f,
            f_pred,
            tangent,
            matches!(self.response, Response::StateDependent(_)).then_some(&self.kt[..]),
        )
    }

    /// The state at `t = 0`: prescribed displacements, the bodies' initial velocities
    /// (statics: at rest), history materials at rest.
    pub fn initial_state(&self, model: &Model) -> State {
        let n = model.mesh.n_dofs();
        let mut u = vec![0.0; n];
        for c in &model.constraints {
            u[c.dof] = c.at(0.0);
        }
        let v = match self.scheme {
            Scheme::Dynamic { .. } => model.initial_velocity(),
            Scheme::Static { .. } => vec![0.0; n],
        };
        let mut mv = vec![0.0; n];
        self.mass.matvec(&self.asm.pattern, &v, &mut mv);
        let mut f_ext = vec![0.0; n];
        external_force(model, self.gravity.as_deref(), 0.0, &mut f_ext);
        let mut f_int = vec![0.0; n];
        let mut f_pred = if self.response == Response::Constant {
            vec![0.0; n]
        } else {
            Vec::new()
        };
        let mut nodal = NodalState::default();
        let (e_el0, points) = if self.response == Response::Elastic {
            self.asm.pattern.matvec(&self.k, &u, &mut f_int);
            (self.stored.of(&u, &f_int), Vec::new())
        } else if let Some(laws) = &self.nodal {
            let (state, psi) = laws.initial(&self.asm.pattern, &self.k, &u, &mut f_int);
            nodal = state;
            (psi, Vec::new())
        } else {
            let mut points = new_stores(&model.mesh, &model.materials);
            let pred = (!f_pred.is_empty()).then_some(&mut f_pred[..]);
            let pass = PointPass {
                u: &u,
                dt: self.h(),
                at_rest: true,
                frozen: false,
            };
            let totals = self.internal(model, pass, &mut points, &mut f_int, pred, None);
            points.iter_mut().for_each(|p| p.commit());
            (totals.psi, points)
        };
        let e_kin0 = 0.5 * super::dot(&v, &mv);
        let contact = crate::contact::ContactState::initial(model, &u);
        State {
            t: 0.0,
            step: 0,
            u,
            v,
            mv,
            a: self.a0.clone(),
            f_int,
            f_ext,
            ledger: Ledger::new(e_kin0, e_el0),
            points,
            f_pred,
            f_pred_h: self.h(),
            contact,
            nodal,
            m_inv_r: Vec::new(),
            ma: Vec::new(),
        }
    }

    /// The Gauss-point stores of `s` for output: built from the nodal fields on the
    /// nodal path (see [`NodalLaws::materialise`]), `None` where `s.points` holds
    /// them already.
    pub fn output_points(&self, model: &Model, s: &State) -> Option<Vec<StateStore>> {
        self.nodal
            .as_ref()
            .map(|laws| laws.materialise(model, &s.u, &s.nodal))
    }
}
