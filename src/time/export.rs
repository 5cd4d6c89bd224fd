//! The matrices of a model's first step, for export (`rothe check --matrices`).

use super::operators::{Operators, Response, Scheme};
use crate::assembly::internal::new_stores;
use crate::assembly::{Assembler, Mass};
use crate::error::Result;
use crate::linsolve::Backend;
use crate::model::Model;
use crate::system::EffectiveSystem;

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
