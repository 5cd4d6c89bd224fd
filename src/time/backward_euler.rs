//! Backward Euler (Rothe) dynamics in displacement form, eq. (9) of the paper:
//!
//! `M (u_s − 2u_{s−1} + u_{s−2})/h² + C (u_s − u_{s−1})/h + f_int(u_s) = f_ext(t_s)`,
//! `C = (zeta + a_m) M + a_k K`, with `v_s = (u_s − u_{s−1})/h` carried as state so
//! `u_{−1} = u_0 − h v_0` holds for an initial velocity `v_0`.
//!
//! For linear elasticity `f_int = K u` and the step is one solve with the effective
//! matrix `K_eff = (1/h² + (zeta+a_m)/h) M + (1 + a_k/h) K`, factorised once:
//! `K_eff Δu = f_ext − f_int(u_{s−1}) + M v_{s−1}/h` on the free dofs, with prescribed
//! displacements moved to the right-hand side. Per step it costs one triangular
//! solve and one fused pass `K Δu, M v_s` over the pattern; `f_int`, `M v` are
//! carried from step to step. See `theory/scheme.md` and `theory/energy.md`.

use std::time::Instant;

use rayon::prelude::*;

use super::system::{DofMap, ReducedMatrix};
use super::{external_force, gravity_force, Timing};
use crate::assembly::internal::{new_stores, PointTotals};
use crate::assembly::{Assembler, Mass};
use crate::energy::{Ledger, StepIncrements};
use crate::error::{Error, Result};
use crate::linsolve::{Backend, SymmetricSolver};
use crate::material::store::StateStore;
use crate::material::Dissipation;
use crate::model::{IterationMethod, Model};

/// The state of a dynamic run after a step.
#[derive(Clone, Debug)]
pub struct DynState {
    /// Time.
    pub t: f64,
    /// Steps taken.
    pub step: usize,
    /// Displacements.
    pub u: Vec<f64>,
    /// Velocities `(u_s − u_{s−1})/h`.
    pub v: Vec<f64>,
    /// `M v`.
    pub mv: Vec<f64>,
    /// Internal forces `f_int(u)`.
    pub fint: Vec<f64>,
    /// External forces including support reactions.
    pub fext: Vec<f64>,
    /// Energy ledger.
    pub ledger: Ledger,
    /// Gauss-point history per element block (empty when every material is
    /// linear elastic and the step runs on global matrices only).
    pub points: Vec<StateStore>,
    /// Internal force of the next step at unchanged displacement (constant-tangent
    /// materials with history; empty otherwise): `f_int(u) = f_pred + K_t (u − u_s)`.
    pub fpred: Vec<f64>,
}

/// What a step reports besides the new state.
#[derive(Clone, Copy, Debug, Default)]
pub struct StepReport {
    /// Linear solves taken.
    pub iterations: usize,
    /// `sqrt(Σ r² / Σ (f_ext² + f_int² + (M a)²))` over the free dofs at the end of the step.
    pub nl_residual: f64,
}

/// Backward Euler integrator: matrices, solver and scratch.
pub struct BackwardEuler<'m> {
    model: &'m Model,
    /// Step size.
    pub h: f64,
    /// Assembly data (pattern, colours).
    pub asm: Assembler,
    /// Free-dof numbering.
    pub dofs: DofMap,
    /// Elastic stiffness on the pattern.
    pub k: Vec<f64>,
    /// Consistent tangent of materials with history (constant for a fixed `h` when
    /// every material has a constant tangent).
    pub kt: Option<Vec<f64>>,
    /// Relative residual tolerance of the equilibrium iterations.
    pub tolerance: f64,
    /// Iteration limit per step.
    pub max_iterations: usize,
    /// Relative tolerance on the last displacement correction (nonlinear models).
    pub displacement_tolerance: f64,
    /// How the effective matrix follows a state-dependent tangent.
    pub iteration: IterationMethod,
    /// Every material has a constant tangent (for a fixed `h`).
    constant_tangent: bool,
    /// Mass matrix.
    pub mass: Mass,
    gravity: Option<Vec<f64>>,
    reduced: ReducedMatrix,
    solver: Box<dyn SymmetricSolver>,
    c_m: f64,
    c_k: f64,
    damp_m: f64,
    damp_k: f64,
    /// Phase timings.
    pub timing: Timing,
    /// Numeric factorisations done.
    pub factorizations: usize,
    f1: Vec<f64>,
    du: Vec<f64>,
    kdu: Vec<f64>,
    v1: Vec<f64>,
    mv1: Vec<f64>,
    rhs: Vec<f64>,
    u1: Vec<f64>,
    fint1: Vec<f64>,
    fpred1: Vec<f64>,
    kv: Vec<f64>,
}

impl<'m> BackwardEuler<'m> {
    /// Assembles `K`, `M`, the effective matrix, analyses and factorises it.
    pub fn new(model: &'m Model, backend: Backend) -> Result<Self> {
        let a = &model.analysis;
        let h = a.dt;
        let t0 = Instant::now();
        let asm = Assembler::new(&model.mesh);
        let k = asm.stiffness(&model.mesh, &model.materials, model.plane);
        let mass = asm.mass(&model.mesh, &model.materials, a.lumped_mass);
        let gravity = gravity_force(model, &mass, &asm.pattern);
        let dofs = DofMap::new(model.mesh.n_dofs(), model.constraints.iter().map(|c| c.dof));
        let mut reduced = ReducedMatrix::new(&asm.pattern, &dofs);
        let damp_m = a.zeta + a.rayleigh[0];
        let damp_k = a.rayleigh[1];
        let c_m = 1.0 / (h * h) + damp_m / h;
        let c_k = 1.0 + damp_k / h;
        let kt = if model.materials.iter().all(|m| m.is_linear_elastic()) {
            None
        } else {
            let stores = new_stores(&model.mesh, &model.materials);
            let u0 = vec![0.0; model.mesh.n_dofs()];
            Some(asm.tangent(&model.mesh, &model.materials, model.plane, &u0, h, &stores))
        };
        match &kt {
            None => reduced.fill(&dofs, c_m, &mass, &[(c_k, &k)]),
            Some(kt) => reduced.fill(&dofs, c_m, &mass, &[(damp_k / h, &k), (1.0, kt)]),
        }
        let assembly_s = t0.elapsed().as_secs_f64();

        let t1 = Instant::now();
        let mut solver = backend.solver()?;
        if a.ordering.nested_dissection(dofs.n_free()) {
            solver.set_ordering(reduced.nested_dissection(&dofs, &model.mesh.coords));
        }
        solver.analyze(&reduced.csc)?;
        solver.factorize(&reduced.csc)?;
        let factorization_s = t1.elapsed().as_secs_f64();
        let n = model.mesh.n_dofs();
        Ok(BackwardEuler {
            model,
            h,
            asm,
            dofs,
            k,
            kt,
            tolerance: a.tolerance,
            max_iterations: a.max_iterations,
            displacement_tolerance: a.displacement_tolerance,
            iteration: a.iteration,
            constant_tangent: model.materials.iter().all(|m| m.has_constant_tangent()),
            mass,
            gravity,
            reduced,
            solver,
            c_m,
            c_k,
            damp_m,
            damp_k,
            timing: Timing {
                assembly_s,
                factorization_s,
                ..Default::default()
            },
            factorizations: 1,
            f1: vec![0.0; n],
            du: vec![0.0; n],
            kdu: vec![0.0; n],
            v1: vec![0.0; n],
            mv1: vec![0.0; n],
            rhs: Vec::with_capacity(n),
            u1: Vec::new(),
            fint1: Vec::new(),
            fpred1: Vec::new(),
            kv: Vec::new(),
        })
    }

    /// The model being integrated.
    pub fn model(&self) -> &'m Model {
        self.model
    }

    /// Solver backend name.
    pub fn backend(&self) -> &'static str {
        self.solver.name()
    }

    /// Number of nonzeros of the Cholesky factor.
    pub fn factor_nnz(&self) -> Option<usize> {
        self.solver.factor_nnz()
    }

    /// The state at `t = 0`: prescribed displacements, bodies' initial velocities.
    pub fn initial_state(&self) -> DynState {
        let model = self.model;
        let n = model.mesh.n_dofs();
        let mut u = vec![0.0; n];
        for c in &model.constraints {
            u[c.dof] = c.at(0.0);
        }
        let v = model.initial_velocity();
        let mut mv = vec![0.0; n];
        let mut fint = vec![0.0; n];
        self.mass.matvec(&self.asm.pattern, &v, &mut mv);
        let mut fext = vec![0.0; n];
        external_force(model, self.gravity.as_deref(), 0.0, &mut fext);
        let e_kin0 = 0.5 * dot(&v, &mv);
        let mut fpred = if self.kt.is_some() && self.constant_tangent {
            vec![0.0; n]
        } else {
            Vec::new()
        };
        let (e_el0, points) = if self.kt.is_none() {
            self.asm.pattern.matvec(&self.k, &u, &mut fint);
            (0.5 * dot(&u, &fint), Vec::new())
        } else {
            let mut points = new_stores(&model.mesh, &model.materials);
            let pred = if fpred.is_empty() {
                None
            } else {
                Some(&mut fpred[..])
            };
            let totals = self.internal(&u, true, &mut points, &mut fint, pred, None);
            points.iter_mut().for_each(StateStore::commit);
            (totals.psi, points)
        };
        DynState {
            t: 0.0,
            step: 0,
            u,
            v,
            mv,
            fint,
            fext,
            ledger: Ledger::new(e_kin0, e_el0),
            points,
            fpred,
        }
    }

    fn internal(
        &self,
        u: &[f64],
        at_rest: bool,
        points: &mut [StateStore],
        f: &mut [f64],
        f_pred: Option<&mut [f64]>,
        tangent: Option<&mut [f64]>,
    ) -> PointTotals {
        let m = self.model;
        self.asm.internal_force(
            &m.mesh,
            &m.materials,
            m.plane,
            u,
            self.h,
            at_rest,
            points,
            f,
            f_pred,
            tangent,
        )
    }

    /// Advances `s` by one step `h`. On error `s` is unchanged.
    pub fn step(&mut self, s: &mut DynState) -> Result<StepReport> {
        if self.kt.is_none() {
            self.step_linear(s)
        } else {
            self.step_history(s)
        }
    }

    /// Prescribed increments into `self.du` (zero elsewhere); true if any.
    fn prescribed_increments(&mut self, u: &[f64], t1: f64) -> bool {
        self.du.fill(0.0);
        let mut moving = false;
        for c in &self.model.constraints {
            let d = c.at(t1) - u[c.dof];
            if d != 0.0 {
                self.du[c.dof] = d;
                moving = true;
            }
        }
        moving
    }

    fn step_linear(&mut self, s: &mut DynState) -> Result<StepReport> {
        let t_start = Instant::now();
        let h = self.h;
        let t1 = s.t + h;
        let n = s.u.len();
        external_force(self.model, self.gravity.as_deref(), t1, &mut self.f1);

        let moving = self.prescribed_increments(&s.u, t1);
        // r = K_eff Δu_c − M v/h + f_int − f_ext¹, wanted on the free dofs only.
        if moving {
            self.asm.pattern.matvec(&self.k, &self.du, &mut self.kdu);
            self.mass.matvec(&self.asm.pattern, &self.du, &mut self.mv1);
        }
        self.rhs.clear();
        for &d in &self.dofs.free {
            let mut r = -s.mv[d] / h + s.fint[d] - self.f1[d];
            if moving {
                r += self.c_m * self.mv1[d] + self.c_k * self.kdu[d];
            }
            self.rhs.push(-r);
        }
        let t_solve = Instant::now();
        self.solver.solve_in_place(&mut self.rhs)?;
        let solve_s = t_solve.elapsed().as_secs_f64();
        self.timing.solve_s += solve_s;
        for (eq, &d) in self.dofs.free.iter().enumerate() {
            self.du[d] = self.rhs[eq];
        }

        // New velocity, M v¹ and K Δu in one pass.
        for (v, du) in self.v1.iter_mut().zip(&self.du) {
            *v = du / h;
        }
        let (v1, mv1) = (&self.v1, &mut self.mv1);
        match &self.mass {
            Mass::Consistent(m) => {
                self.asm
                    .pattern
                    .matvec2(&self.k, &self.du, &mut self.kdu, m, v1, mv1)
            }
            Mass::Lumped(_) => {
                self.asm.pattern.matvec(&self.k, &self.du, &mut self.kdu);
                self.mass.matvec(&self.asm.pattern, v1, mv1);
            }
        }
        let mv1 = &self.mv1;

        // Residual of the step equation; on constrained dofs it is the reaction.
        let mut inc = StepIncrements::default();
        let (mut r2, mut f2) = (0.0, 0.0);
        let mut e_el = 0.0;
        let mut mat_num = 0.0;
        for i in 0..n {
            let fint1 = s.fint[i] + self.kdu[i];
            let cv1 = self.damp_m * mv1[i] + self.damp_k * self.kdu[i] / h;
            let inertia = (mv1[i] - s.mv[i]) / h;
            let res = inertia + cv1 + fint1 - self.f1[i];
            let fext1 = if self.dofs.eq[i] == usize::MAX {
                self.f1[i] + res
            } else {
                r2 += res * res;
                f2 += self.f1[i].powi(2) + fint1.powi(2) + inertia.powi(2);
                self.f1[i]
            };
            let du = self.du[i];
            let u1 = s.u[i] + du;
            inc.kinetic += 0.5 * v1[i] * mv1[i];
            inc.internal_work += 0.5 * du * (s.fint[i] + fint1);
            inc.external_work += 0.5 * du * (s.fext[i] + fext1);
            inc.load_jump += 0.5 * du * (fext1 - s.fext[i]);
            inc.mass_damping += du * cv1;
            inc.kinetic_loss += 0.5 * (v1[i] - s.v[i]) * (mv1[i] - s.mv[i]);
            e_el += 0.5 * u1 * fint1;
            mat_num += 0.5 * du * self.kdu[i];
            s.u[i] = u1;
            s.fint[i] = fint1;
            s.fext[i] = fext1;
        }
        inc.elastic = e_el;
        inc.material = Dissipation {
            numerical: mat_num,
            ..Default::default()
        };
        std::mem::swap(&mut s.v, &mut self.v1);
        std::mem::swap(&mut s.mv, &mut self.mv1);
        s.t = t1;
        s.step += 1;
        s.ledger.record(&inc);
        let total = t_start.elapsed().as_secs_f64();
        self.timing.step_other_s += total - solve_s;
        Ok(StepReport {
            iterations: 1,
            nl_residual: if f2 > 0.0 {
                (r2 / f2).sqrt()
            } else {
                r2.sqrt()
            },
        })
    }

    /// A step for materials with Gauss-point history: equilibrium iterations
    /// `K_eff δ = −r(u)` with `r = M(v − v⁰)/h + C v + f_int(u) − f_ext¹`, `f_int`
    /// from the Gauss-point loop against the committed history. For constant-tangent
    /// materials the first solve starts from the force predicted at the end of the
    /// previous step (`DynState::fpred`), is exact up to round-off, and the one
    /// Gauss-point pass that follows confirms it and yields the final state (after
    /// `set_step` the prediction is for the old step and a second solve follows).
    fn step_history(&mut self, s: &mut DynState) -> Result<StepReport> {
        let t_start = Instant::now();
        let mut solve_s = 0.0;
        let h = self.h;
        let t1 = s.t + h;
        let n = s.u.len();
        external_force(self.model, self.gravity.as_deref(), t1, &mut self.f1);
        let moving = self.prescribed_increments(&s.u, t1);
        let mut u1 = std::mem::take(&mut self.u1);
        u1.clear();
        u1.extend(s.u.iter().zip(&self.du).map(|(u, d)| u + d));
        let mut fint1 = std::mem::take(&mut self.fint1);
        fint1.resize(n, 0.0);
        let mut fpred1 = std::mem::take(&mut self.fpred1);
        fpred1.resize(s.fpred.len(), 0.0);
        let mut kv = std::mem::take(&mut self.kv);
        kv.resize(n, 0.0);
        let mut history: Vec<f64> = Vec::new();
        let mut iterations = 0;
        let constant = !s.fpred.is_empty();
        if !constant && self.iteration == IterationMethod::Fixed {
            // Pay once per step: the tangent at the start of the step.
            let u_start = u1.clone();
            self.refactor_tangent(&u_start, &s.points)?;
        }
        let mut last_correction = 0.0f64;
        let newton = !constant && self.iteration == IterationMethod::Newton;
        if constant {
            // First solve from the predicted force, without a Gauss-point pass:
            // r(u_s + Δu_c) = −M v_s/h + f_pred − f_ext¹ + K_eff Δu_c.
            if moving {
                let kt = self.kt.as_ref().expect("history path");
                self.mass.matvec(&self.asm.pattern, &self.du, &mut self.mv1);
                self.asm.pattern.matvec(kt, &self.du, &mut fint1);
                if self.damp_k != 0.0 {
                    self.asm.pattern.matvec(&self.k, &self.du, &mut kv);
                }
            }
            self.rhs.clear();
            for &d in &self.dofs.free {
                let mut r = -s.mv[d] / h + s.fpred[d] - self.f1[d];
                if moving {
                    r += self.c_m * self.mv1[d] + fint1[d] + self.damp_k / h * kv[d];
                }
                self.rhs.push(-r);
            }
            let ts = Instant::now();
            self.solver.solve_in_place(&mut self.rhs)?;
            solve_s += ts.elapsed().as_secs_f64();
            for (eq, &d) in self.dofs.free.iter().enumerate() {
                u1[d] += self.rhs[eq];
            }
            iterations += 1;
        }
        let (totals, nl) = loop {
            let pred = if constant {
                Some(&mut fpred1[..])
            } else {
                None
            };
            // Newton takes the tangent of the updates this pass makes anyway.
            let mut kt = if newton { self.kt.take() } else { None };
            let totals = self.internal(
                &u1,
                false,
                &mut s.points,
                &mut fint1,
                pred,
                kt.as_deref_mut(),
            );
            self.du
                .par_iter_mut()
                .zip(self.v1.par_iter_mut())
                .zip(u1.par_iter().zip(s.u.par_iter()))
                .for_each(|((du, v), (a, b))| {
                    *du = a - b;
                    *v = *du / h;
                });
            self.mass.matvec(&self.asm.pattern, &self.v1, &mut self.mv1);
            if self.damp_k != 0.0 {
                self.asm.pattern.matvec(&self.k, &self.v1, &mut kv);
            }
            let (mut r2, mut f2) = (0.0, 0.0);
            self.rhs.clear();
            for &d in &self.dofs.free {
                let inertia = (self.mv1[d] - s.mv[d]) / h;
                let r = inertia + self.damp_m * self.mv1[d] + self.damp_k * kv[d] + fint1[d]
                    - self.f1[d];
                r2 += r * r;
                f2 += self.f1[d].powi(2) + fint1[d].powi(2) + inertia.powi(2);
                self.rhs.push(-r);
            }
            let nl = if f2 > 0.0 {
                (r2 / f2).sqrt()
            } else {
                r2.sqrt()
            };
            history.push(nl);
            // The displacement test matters only while a state-dependent tangent
            // iterates; it is skipped (and its pass over the dofs with it) otherwise.
            let small_correction = constant || iterations == 0 || {
                let du_norm = self
                    .dofs
                    .free
                    .iter()
                    .map(|&d| self.du[d] * self.du[d])
                    .sum::<f64>()
                    .sqrt();
                last_correction <= self.displacement_tolerance * du_norm.max(f64::MIN_POSITIVE)
            };
            if (nl <= self.tolerance && small_correction) || r2 == 0.0 {
                if kt.is_some() {
                    self.kt = kt;
                }
                break (totals, nl);
            }
            let failure = if iterations >= self.max_iterations || !nl.is_finite() {
                if kt.is_some() {
                    self.kt = kt.take();
                }
                let worst = self
                    .rhs
                    .iter()
                    .enumerate()
                    .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
                    .map(|(eq, r)| {
                        format!(
                            "; largest residual {:.3e} N at {}",
                            r.abs(),
                            self.locate_dof(self.dofs.free[eq])
                        )
                    })
                    .unwrap_or_default();
                Some(Error::Stepping(format!(
                    "no convergence at t = {t1:.6e} (h = {h:.3e}) after {iterations} iterations; relative residuals [{}]{worst}",
                    history.iter().map(|r| format!("{r:.2e}")).collect::<Vec<_>>().join(", ")
                )))
            } else if let Some(kt) = kt.take() {
                self.refactor_with(kt).err()
            } else {
                None
            };
            if let Some(e) = failure {
                // The trial states are simply not committed: the step leaves no trace.
                self.u1 = u1;
                self.fint1 = fint1;
                self.fpred1 = fpred1;
                self.kv = kv;
                return Err(e);
            }
            let ts = Instant::now();
            self.solver.solve_in_place(&mut self.rhs)?;
            solve_s += ts.elapsed().as_secs_f64();
            let mut c2 = 0.0;
            for (eq, &d) in self.dofs.free.iter().enumerate() {
                u1[d] += self.rhs[eq];
                c2 += self.rhs[eq] * self.rhs[eq];
            }
            last_correction = c2.sqrt();
            iterations += 1;
        };

        // The step's ledger terms, in parallel over the dofs (sums of products of
        // the vectors the iterations left behind).
        let (damp_m, damp_k, eq) = (self.damp_m, self.damp_k, &self.dofs.eq);
        let (mv1, v1, du, f1) = (&self.mv1, &self.v1, &self.du, &self.f1);
        let (mv0, v0, fint0) = (&s.mv, &s.v, &s.fint);
        let sums = s
            .fext
            .par_iter_mut()
            .enumerate()
            .fold(
                || [0.0f64; 6],
                |mut acc, (i, fext0)| {
                    let cv1 = damp_m * mv1[i] + damp_k * kv[i];
                    let fext1 = if eq[i] == usize::MAX {
                        (mv1[i] - mv0[i]) / h + cv1 + fint1[i]
                    } else {
                        f1[i]
                    };
                    let d = du[i];
                    acc[0] += 0.5 * v1[i] * mv1[i];
                    acc[1] += 0.5 * d * (fint0[i] + fint1[i]);
                    acc[2] += 0.5 * d * (*fext0 + fext1);
                    acc[3] += 0.5 * d * (fext1 - *fext0);
                    acc[4] += d * cv1;
                    acc[5] += 0.5 * (v1[i] - v0[i]) * (mv1[i] - mv0[i]);
                    *fext0 = fext1;
                    acc
                },
            )
            .reduce(|| [0.0; 6], |a, b| std::array::from_fn(|k| a[k] + b[k]));
        let inc = StepIncrements {
            elastic: totals.psi,
            material: totals.dissipation,
            kinetic: sums[0],
            internal_work: sums[1],
            external_work: sums[2],
            load_jump: sums[3],
            mass_damping: sums[4],
            kinetic_loss: sums[5],
            contact: 0.0,
        };
        self.u1 = std::mem::replace(&mut s.u, u1);
        self.fint1 = std::mem::replace(&mut s.fint, fint1);
        self.fpred1 = std::mem::replace(&mut s.fpred, fpred1);
        self.kv = kv;
        std::mem::swap(&mut s.v, &mut self.v1);
        std::mem::swap(&mut s.mv, &mut self.mv1);
        s.points.iter_mut().for_each(StateStore::commit);
        s.t = t1;
        s.step += 1;
        s.ledger.record(&inc);
        self.timing.solve_s += solve_s;
        self.timing.step_other_s += t_start.elapsed().as_secs_f64() - solve_s;
        Ok(StepReport {
            iterations,
            nl_residual: nl,
        })
    }

    /// Assembles the tangent at `u` from the committed history of `points`, refills
    /// the effective matrix and refactorises it.
    fn refactor_tangent(&mut self, u: &[f64], points: &[StateStore]) -> Result<()> {
        let m = self.model;
        let kt = self
            .asm
            .tangent(&m.mesh, &m.materials, m.plane, u, self.h, points);
        self.refactor_with(kt)
    }

    /// Refills the effective matrix with the tangent `kt`, keeps it, and
    /// refactorises.
    fn refactor_with(&mut self, kt: Vec<f64>) -> Result<()> {
        let t = Instant::now();
        self.reduced.fill(
            &self.dofs,
            self.c_m,
            &self.mass,
            &[(self.damp_k / self.h, &self.k), (1.0, &kt)],
        );
        self.kt = Some(kt);
        let res = self.solver.factorize(&self.reduced.csc);
        self.factorizations += 1;
        self.timing.factorization_s += t.elapsed().as_secs_f64();
        res.map_err(|e| {
            Error::Stepping(format!(
                "the effective matrix lost positive definiteness ({e})"
            ))
        })
    }

    /// Where dof `d` sits: node, coordinates, body and one element holding it.
    pub fn locate_dof(&self, d: usize) -> String {
        let mesh = &self.model.mesh;
        let n = d / 2;
        let body = &self.model.bodies[mesh.node_body[n]].name;
        let element = mesh.blocks.iter().enumerate().find_map(|(bi, b)| {
            (0..b.elements.len())
                .find(|&e| b.elements.element(e).contains(&n))
                .map(|e| format!("block {bi} element {e}"))
        });
        format!(
            "node {n} at ({:.4}, {:.4}) of body `{body}`, {}, component {}",
            mesh.coords[n][0],
            mesh.coords[n][1],
            element.unwrap_or_else(|| "no element".into()),
            if d % 2 == 0 { "x" } else { "y" }
        )
    }

    /// Refactorises after a change of `h` (same pattern, new values).
    pub fn set_step(&mut self, h: f64) -> Result<()> {
        self.h = h;
        self.c_m = 1.0 / (h * h) + self.damp_m / h;
        self.c_k = 1.0 + self.damp_k / h;
        if !self.constant_tangent {
            // The matrix follows the state: it is rebuilt at the next step anyway.
            return Ok(());
        }
        let t = Instant::now();
        let m = self.model;
        if self.kt.is_some() {
            let stores = new_stores(&m.mesh, &m.materials);
            let u0 = vec![0.0; m.mesh.n_dofs()];
            self.kt = Some(
                self.asm
                    .tangent(&m.mesh, &m.materials, m.plane, &u0, h, &stores),
            );
        }
        match &self.kt {
            None => self
                .reduced
                .fill(&self.dofs, self.c_m, &self.mass, &[(self.c_k, &self.k)]),
            Some(kt) => self.reduced.fill(
                &self.dofs,
                self.c_m,
                &self.mass,
                &[(self.damp_k / h, &self.k), (1.0, kt)],
            ),
        }
        self.solver.factorize(&self.reduced.csc)?;
        self.factorizations += 1;
        self.timing.factorization_s += t.elapsed().as_secs_f64();
        Ok(())
    }
}

/// Dot product.
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
