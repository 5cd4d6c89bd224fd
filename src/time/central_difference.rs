//! Central differences with lumped mass (`analysis.scheme = "central_difference"`),
//! the explicit path of the paper's Section 4, in velocity-Verlet form:
//!
//! `v_{n+½} = v_n + (h/2) a_n`, `u_{n+1} = u_n + h v_{n+½}` (then the kinematic
//! contact corrects `v_{n+½}` and the increment), `a_{n+1} = M⁻¹(f_ext − f_int(u_{n+1})
//! − f_damp)`, `v_{n+1} = v_{n+½} + (h/2) a_{n+1}`,
//!
//! with the mass damping `c = zeta + a_m` taken at `v_{n+1}` (a diagonal, so still
//! explicit) and the stiffness damping `a_k K v_{n+½}`. Constrained dofs follow their
//! prescribed motion `g(t)`: `v_{n+½} = (g(t_{n+1}) − g(t_n))/h`, `a_n` the difference of
//! the half-step velocities over `h`, `v_n` their mean, so the Verlet relations hold
//! there too and the reactions are `M a − f_ext + f_int + f_damp`.
//!
//! The ledger uses the implicit path's trapezoidal work terms, so the two
//! `history.csv` files compare column by column. Velocity Verlet conserves the modified
//! energy `E_kin − (h²/8) aᵀMa`: the step identity is
//! `ΔE_kin + ΔE_int − ΔW_ext + ΔD_mass = (h²/8) Δ(aᵀMa)`, so the scheme's own line is
//! `ΔD_num = −(h²/8) Δ(aᵀMa)` (bounded, of either sign, `O(h²)`), and the ledger closes
//! to round-off for every material. The material's own algorithmic loss is the
//! trapezoidal one, `½(σ_n + σ_{n+1}):Δε − Δψ − ΔD`. See `theory/explicit.md`.

use std::time::Instant;

use super::forces::{external_force, gravity_force};
use super::{Integrator, Rejection, SolverFacts, State, StepOutcome, StepReport, Timing};
use crate::assembly::internal::{new_stores, PointPass, PointTotals};
use crate::assembly::{Assembler, Mass};
use crate::contact::kinematic::KinematicContact;
use crate::contact::ContactState;
use crate::energy::{Dissipation, Ledger, StepIncrements, StepWork};
use crate::error::{Error, Result};
use crate::model::{Constraint, Model};
use crate::nonlinear::Outcome;

/// The step's vectors, reused from step to step.
#[derive(Default)]
struct Work {
    v_half: Vec<f64>,
    v_hat: Vec<f64>,
    du: Vec<f64>,
    u1: Vec<f64>,
    f_int1: Vec<f64>,
    f_ext1: Vec<f64>,
    a1: Vec<f64>,
    v1: Vec<f64>,
    kv: Vec<f64>,
}

/// Central differences with lumped mass and the kinematic contact method.
pub struct CentralDifference<'m> {
    model: &'m Model,
    asm: Assembler,
    /// Elastic stiffness (the internal force of elastic models, stiffness damping).
    k: Vec<f64>,
    /// Lumped mass per dof, and its inverse on the free dofs (zero on constrained).
    m: Vec<f64>,
    m_inv: Vec<f64>,
    gravity: Option<Vec<f64>>,
    /// Every material linear elastic: `f_int = K u`.
    elastic: bool,
    /// The stored energy of elastic models, translation removed.
    stored: crate::energy::StoredEnergy,
    h: f64,
    damp_m: f64,
    damp_k: f64,
    contact: Option<KinematicContact<'m>>,
    w: Work,
    assembly_s: f64,
    step_s: f64,
}

impl<'m> CentralDifference<'m> {
    /// Assembles the stiffness and the lumped mass of `model`.
    pub fn new(model: &'m Model) -> Result<Self> {
        let t0 = Instant::now();
        let a = &model.analysis;
        let asm = Assembler::new(&model.mesh);
        let k = asm.stiffness(&model.mesh, &model.materials, model.idealisation);
        let mass = asm.mass(&model.mesh, &model.materials, true);
        let m = match &mass {
            Mass::Lumped(d) => d.clone(),
            Mass::Consistent(_) => mass.row_sums(&asm.pattern),
        };
        let mut m_inv: Vec<f64> = m
            .iter()
            .map(|&x| if x > 0.0 { 1.0 / x } else { 0.0 })
            .collect();
        for c in &model.constraints {
            m_inv[c.dof] = 0.0;
        }
        if let Some(d) = (0..m.len()).find(|&d| {
            (m[d].is_nan() || m[d] <= 0.0)
                && m_inv[d] == 0.0
                && !model.constraints.iter().any(|c| c.dof == d)
        }) {
            return Err(Error::Config {
                field: "bodies".into(),
                message: format!(
                    "central differences need a positive lumped mass at every free dof; {} has none",
                    model.describe_dof(d)
                ),
            });
        }
        let gravity = gravity_force(model, &mass, &asm.pattern);
        let n = model.mesh.n_dofs();
        let w = Work {
            v_half: vec![0.0; n],
            v_hat: vec![0.0; n],
            du: vec![0.0; n],
            u1: vec![0.0; n],
            f_int1: vec![0.0; n],
            f_ext1: vec![0.0; n],
            a1: vec![0.0; n],
            v1: vec![0.0; n],
            kv: vec![0.0; n],
        };
        Ok(CentralDifference {
            model,
            elastic: model.materials.iter().all(|m| m.is_linear_elastic()),
            stored: crate::energy::StoredEnergy::new(&model.mesh),
            asm,
            k,
            m,
            m_inv,
            gravity,
            h: a.time.dt,
            damp_m: a.damping.zeta + a.damping.rayleigh[0],
            damp_k: a.damping.rayleigh[1],
            contact: (!model.contacts.is_empty()).then(|| KinematicContact::new(model)),
            w,
            assembly_s: t0.elapsed().as_secs_f64(),
            step_s: 0.0,
        })
    }

    /// The lumped mass per dof.
    pub fn lumped_mass(&self) -> &[f64] {
        &self.m
    }

    /// The kinematic contact's counts so far.
    pub fn contact_stats(&self) -> Option<crate::contact::kinematic::KinematicStats> {
        self.contact.as_ref().map(|c| c.stats())
    }

    /// Half-step velocity of a constrained dof over `[t, t + h]`.
    fn prescribed_v(c: &Constraint, t: f64, h: f64) -> f64 {
        (c.at(t + h) - c.at(t)) / h
    }

    /// Internal forces at `u` into `f`, with the point states (trial) and their
    /// integrated energy and dissipation; `None` for elastic models.
    fn internal(
        &self,
        u: &[f64],
        at_rest: bool,
        points: &mut [crate::material::store::StateStore],
        f: &mut [f64],
    ) -> Option<PointTotals> {
        if self.elastic {
            self.asm.pattern.matvec(&self.k, u, f);
            None
        } else {
            Some(self.asm.internal_force(
                &self.model.mesh,
                &self.model.materials,
                self.model.idealisation,
                PointPass {
                    u,
                    dt: self.h,
                    at_rest,
                    frozen: false,
                },
                points,
                f,
                None,
                None,
                None,
            ))
        }
    }

    fn rejected(&self, outcome: Outcome, t1: f64) -> StepOutcome {
        let message = super::diagnostics::describe(self.model, &outcome, t1, self.h);
        StepOutcome::Rejected(Rejection { outcome, message })
    }
}

impl Integrator for CentralDifference<'_> {
    fn model(&self) -> &Model {
        self.model
    }

    fn h(&self) -> f64 {
        self.h
    }

    fn set_step(&mut self, h: f64) -> Result<()> {
        self.h = h;
        Ok(())
    }

    fn initial_state(&mut self) -> Result<State> {
        let model = self.model;
        let (h, n) = (self.h, model.mesh.n_dofs());
        let mut u = vec![0.0; n];
        let mut v = model.initial_velocity();
        let mut a = vec![0.0; n];
        for c in &model.constraints {
            u[c.dof] = c.at(0.0);
            let (before, after) = (Self::prescribed_v(c, -h, h), Self::prescribed_v(c, 0.0, h));
            v[c.dof] = 0.5 * (before + after);
            a[c.dof] = (after - before) / h;
        }
        let mut points = if self.elastic {
            Vec::new()
        } else {
            new_stores(&model.mesh, &model.materials)
        };
        let mut f_int = vec![0.0; n];
        let totals = self.internal(&u, true, &mut points, &mut f_int);
        points.iter_mut().for_each(|p| p.commit());
        let e_el0 = match totals {
            Some(t) => t.psi,
            None => self.stored.of(&u, &f_int),
        };
        let mut f_ext = vec![0.0; n];
        external_force(model, self.gravity.as_deref(), 0.0, &mut f_ext);
        let kv = &mut self.w.kv;
        if self.damp_k != 0.0 {
            self.asm.pattern.matvec(&self.k, &v, kv);
        } else {
            kv.fill(0.0);
        }
        for d in 0..n {
            if self.m_inv[d] > 0.0 {
                a[d] = self.m_inv[d] * (f_ext[d] - f_int[d] - self.damp_k * kv[d])
                    - self.damp_m * v[d];
            }
        }
        // Reactions on the constrained dofs: what makes M a = f_ext − f_int − f_damp.
        for c in &model.constraints {
            let d = c.dof;
            let f_damp = self.damp_m * self.m[d] * v[d] + self.damp_k * kv[d];
            f_ext[d] = self.m[d] * a[d] + f_int[d] + f_damp;
        }
        let mv: Vec<f64> = v.iter().zip(&self.m).map(|(x, m)| m * x).collect();
        let e_kin0 = 0.5 * super::dot(&v, &mv);
        let contact = ContactState::initial(model, &u);
        Ok(State {
            t: 0.0,
            step: 0,
            u,
            v,
            mv,
            a,
            f_int,
            f_ext,
            ledger: Ledger::new(e_kin0, e_el0),
            points,
            f_pred: Vec::new(),
            f_pred_h: h,
            contact,
            nodal: Default::default(),
            m_inv_r: Vec::new(),
            ma: Vec::new(),
        })
    }

    fn step(&mut self, s: &mut State) -> Result<StepOutcome> {
        let start = Instant::now();
        let model = self.model;
        let (h, n) = (self.h, model.mesh.n_dofs());
        let t1 = s.t + h;
        let w = &mut self.w;
        // Half-step velocities and the unconstrained increments.
        for d in 0..n {
            w.v_half[d] = s.v[d] + 0.5 * h * s.a[d];
        }
        for c in &model.constraints {
            w.v_half[c.dof] = Self::prescribed_v(c, s.t, h);
        }
        w.v_hat.copy_from_slice(&w.v_half);
        for d in 0..n {
            w.du[d] = h * w.v_half[d];
        }
        for c in &model.constraints {
            w.du[c.dof] = c.at(t1) - s.u[c.dof];
        }
        if let Some(kc) = self.contact.as_mut() {
            kc.correct(&s.u, &mut w.v_hat, &mut w.du, &self.m_inv, h)?;
        }
        for d in 0..n {
            w.u1[d] = s.u[d] + w.du[d];
        }
        for c in &model.constraints {
            w.u1[c.dof] = c.at(t1);
        }
        let mut f_int1 = std::mem::take(&mut self.w.f_int1);
        let u1 = std::mem::take(&mut self.w.u1);
        let totals = self.internal(&u1, false, &mut s.points, &mut f_int1);
        self.w.f_int1 = f_int1;
        self.w.u1 = u1;
        if let Some(f) = totals.and_then(|t| t.failure) {
            return Ok(self.rejected(Outcome::MaterialFailure(f), t1));
        }
        let w = &mut self.w;
        if let Some(d) = (0..n).find(|&d| !w.u1[d].is_finite() || !w.f_int1[d].is_finite()) {
            let (quantity, value) = if w.u1[d].is_finite() {
                ("internal force", w.f_int1[d])
            } else {
                ("displacement", w.u1[d])
            };
            let outcome = Outcome::NonFinite {
                quantity,
                dof: Some(d),
                value,
            };
            return Ok(self.rejected(outcome, t1));
        }
        external_force(model, self.gravity.as_deref(), t1, &mut w.f_ext1);
        if self.damp_k != 0.0 {
            self.asm.pattern.matvec(&self.k, &w.v_hat, &mut w.kv);
        }
        let (c_m, c_k) = (self.damp_m, self.damp_k);
        for d in 0..n {
            if self.m_inv[d] > 0.0 {
                let kv = if c_k != 0.0 { w.kv[d] } else { 0.0 };
                w.a1[d] = (self.m_inv[d] * (w.f_ext1[d] - w.f_int1[d] - c_k * kv)
                    - c_m * w.v_hat[d])
                    / (1.0 + 0.5 * c_m * h);
            }
        }
        for c in &model.constraints {
            let next = Self::prescribed_v(c, t1, h);
            w.a1[c.dof] = (next - w.v_half[c.dof]) / h;
        }
        for d in 0..n {
            w.v1[d] = w.v_hat[d] + 0.5 * h * w.a1[d];
        }
        // Reactions on the constrained dofs.
        for c in &model.constraints {
            let d = c.dof;
            let kv = if c_k != 0.0 { w.kv[d] } else { 0.0 };
            let f_damp = c_m * self.m[d] * w.v1[d] + c_k * kv;
            w.f_ext1[d] = self.m[d] * w.a1[d] + w.f_int1[d] + f_damp;
        }
        // The ledger's terms in one pass over the dofs.
        let (mut internal, mut external, mut damping) = (0.0, 0.0, 0.0);
        let (mut kinetic, mut ama0, mut ama1, mut dk_corr, mut mismatch) =
            (0.0, 0.0, 0.0, 0.0, 0.0);
        let mut jump = 0.0;
        for d in 0..n {
            let (m, du) = (self.m[d], w.du[d]);
            let kv = if c_k != 0.0 { w.kv[d] } else { 0.0 };
            let f0 = m * s.a[d];
            let f1 = m * w.a1[d];
            let fd0 = s.f_ext[d] - s.f_int[d] - f0;
            let fd1 = c_m * m * w.v1[d] + c_k * kv;
            internal += du * (s.f_int[d] + w.f_int1[d]);
            external += du * (s.f_ext[d] + w.f_ext1[d]);
            damping += du * (fd0 + fd1);
            jump += du * (w.f_int1[d] - s.f_int[d]);
            kinetic += m * w.v1[d] * w.v1[d];
            ama0 += f0 * s.a[d];
            ama1 += f1 * w.a1[d];
            dk_corr += m * (w.v_hat[d] * w.v_hat[d] - w.v_half[d] * w.v_half[d]);
            mismatch += f1 * (w.v_hat[d] - du / h) + f0 * (w.v_half[d] - du / h);
        }
        let work = StepWork {
            internal: 0.5 * internal,
            external: 0.5 * external,
            load_jump: 0.0,
            // Without damping the damping forces vanish; what the sum holds then is
            // the round-off of the reactions.
            damping: if c_m == 0.0 && c_k == 0.0 {
                0.0
            } else {
                0.5 * damping
            },
        };
        let (elastic, material) = match totals {
            Some(t) => {
                let mut d = t.dissipation;
                // The trapezoidal algorithmic loss: the point pass books σ_{n+1}:Δε.
                d.numerical -= 0.5 * jump;
                (t.psi, d)
            }
            None => (self.stored.of(&w.u1, &w.f_int1), Dissipation::default()),
        };
        let contact = -0.5 * dk_corr - 0.5 * h * mismatch;
        if let Some(d) = (0..n).find(|&d| !w.v1[d].is_finite() || !w.a1[d].is_finite()) {
            let (quantity, value) = if w.a1[d].is_finite() {
                ("velocity", w.v1[d])
            } else {
                ("acceleration", w.a1[d])
            };
            let outcome = Outcome::NonFinite {
                quantity,
                dof: Some(d),
                value,
            };
            return Ok(self.rejected(outcome, t1));
        }
        let mut ledger = s.ledger;
        ledger.record(&StepIncrements {
            kinetic: 0.5 * kinetic,
            elastic,
            work,
            material,
            scheme_loss: -h * h / 8.0 * (ama1 - ama0),
            // The kinematic method's impacts, friction interpolation included.
            contact,
            friction: 0.0,
            predictor: 0.0,
        });
        if let Some((quantity, value)) = ledger.first_non_finite() {
            let outcome = Outcome::NonFinite {
                quantity,
                dof: None,
                value,
            };
            return Ok(self.rejected(outcome, t1));
        }
        s.ledger = ledger;
        if let Some(kc) = self.contact.as_mut() {
            kc.finish(h, &mut s.contact);
        }
        s.points.iter_mut().for_each(|p| p.commit());
        std::mem::swap(&mut s.u, &mut w.u1);
        std::mem::swap(&mut s.v, &mut w.v1);
        std::mem::swap(&mut s.a, &mut w.a1);
        std::mem::swap(&mut s.f_int, &mut w.f_int1);
        std::mem::swap(&mut s.f_ext, &mut w.f_ext1);
        for d in 0..n {
            s.mv[d] = self.m[d] * s.v[d];
        }
        s.t = t1;
        s.step += 1;
        self.step_s += start.elapsed().as_secs_f64();
        Ok(StepOutcome::Accepted(StepReport {
            iterations: 0,
            nl_residual: 0.0,
        }))
    }

    fn timing(&self) -> Timing {
        Timing {
            assembly_s: self.assembly_s,
            factorization_s: 0.0,
            solve_s: 0.0,
            step_other_s: self.step_s,
        }
    }

    fn solver(&self) -> SolverFacts {
        SolverFacts {
            backend: "explicit",
            factorizations: 0,
            reused_factors: 0,
            fallbacks: 0,
            impact_steps: 0,
            impact_fallbacks: 0,
            factor_nnz: None,
        }
    }
}
