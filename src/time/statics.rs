//! Static equilibrium `K u = f_ext(t)` with prescribed displacements: the free block
//! `K_ff u_f = f_f − K_fc u_c` is solved with the same machinery as the dynamics.

use std::time::Instant;

use super::system::{DofMap, ReducedMatrix};
use super::{external_force, gravity_force, Timing};
use crate::assembly::{Assembler, Mass};
use crate::error::{Error, Result};
use crate::linsolve::Backend;
use crate::model::Model;

/// A static solution.
#[derive(Clone, Debug)]
pub struct StaticSolution {
    /// Displacements.
    pub u: Vec<f64>,
    /// Internal forces `K u` (equal to the external forces plus reactions).
    pub fint: Vec<f64>,
    /// Stored elastic energy `½ uᵀ K u`.
    pub elastic: f64,
    /// Phase timings.
    pub timing: Timing,
}

/// Solves the static problem of `model` at times `times` (one factorisation).
pub fn solve(model: &Model, backend: Backend, times: &[f64]) -> Result<Vec<StaticSolution>> {
    if model.materials.iter().any(|m| !m.is_linear_elastic()) {
        return Err(Error::Stepping(
            "static analysis supports linear elastic materials only".into(),
        ));
    }
    let t0 = Instant::now();
    let asm = Assembler::new(&model.mesh);
    let k = asm.stiffness(&model.mesh, &model.materials, model.plane);
    let gravity = model.gravity.map(|_| {
        let mass = asm.mass(&model.mesh, &model.materials, false);
        gravity_force(model, &mass, &asm.pattern).expect("gravity is set")
    });
    let dofs = DofMap::new(model.mesh.n_dofs(), model.constraints.iter().map(|c| c.dof));
    let mut reduced = ReducedMatrix::new(&asm.pattern, &dofs);
    reduced.fill(
        &dofs,
        0.0,
        &Mass::Lumped(vec![0.0; model.mesh.n_dofs()]),
        &[(1.0, &k)],
    );
    let assembly_s = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let mut solver = backend.solver()?;
    if model.analysis.ordering.nested_dissection(dofs.n_free()) {
        solver.set_ordering(reduced.nested_dissection(&dofs, &model.mesh.coords));
    }
    solver.analyze(&reduced.csc)?;
    solver.factorize(&reduced.csc)?;
    let factorization_s = t1.elapsed().as_secs_f64();

    let n = model.mesh.n_dofs();
    let mut out = Vec::with_capacity(times.len());
    for &t in times {
        let t2 = Instant::now();
        let mut u = vec![0.0; n];
        for c in &model.constraints {
            u[c.dof] = c.at(t);
        }
        let mut f = vec![0.0; n];
        external_force(model, gravity.as_deref(), t, &mut f);
        let mut ku = vec![0.0; n];
        asm.pattern.matvec(&k, &u, &mut ku);
        let mut rhs: Vec<f64> = dofs.free.iter().map(|&d| f[d] - ku[d]).collect();
        solver.solve_in_place(&mut rhs)?;
        for (eq, &d) in dofs.free.iter().enumerate() {
            u[d] = rhs[eq];
        }
        asm.pattern.matvec(&k, &u, &mut ku);
        let elastic = 0.5 * u.iter().zip(&ku).map(|(a, b)| a * b).sum::<f64>();
        out.push(StaticSolution {
            u,
            fint: ku,
            elastic,
            timing: Timing {
                assembly_s,
                factorization_s,
                solve_s: t2.elapsed().as_secs_f64(),
                step_other_s: 0.0,
            },
        });
    }
    Ok(out)
}
