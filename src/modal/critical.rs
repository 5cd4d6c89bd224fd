//! The exact critical step of central differences: the mesh's own largest
//! frequency, not an element bound (`theory/modal.md`, `theory/explicit.md`).

use super::lanczos;
use crate::assembly::{Assembler, Mass};
use crate::error::{Error, Result};
use crate::mesh::ElementKind;
use crate::model::Model;
use crate::system::DofMap;

/// The mesh's stable step of central differences with lumped mass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExactStep {
    /// `ω_max`: the largest circular frequency of `K φ = ω² M_L φ` (rad/s).
    pub omega_max: f64,
    /// The largest damping rate the scheme takes at the half-step velocity:
    /// `a_k ω_max²` plus the largest eigenvalue of `M_L⁻¹ C_η` (the materials'
    /// dashpots) (1/s).
    pub damping_rate: f64,
    /// The stable step `2/(√(ω_max² + c²/4) + c/2)` (`2/ω_max` undamped) (s).
    pub dt: f64,
}

/// The largest circular frequency `ω_max` of `K φ = ω² M_L φ` on the free dofs,
/// `M_L` the lumped mass (the explicit path's), `K` the instantaneous stiffness (the
/// elastic one of every material, the SLS's Maxwell branch included): central
/// differences are stable for `h < 2/ω_max` without damping.
pub fn highest_frequency(model: &Model) -> Result<f64> {
    let top = Top::new(model)?;
    let k = top.stiffness(model, false);
    Ok(top.largest(&k)?.max(0.0).sqrt())
}

/// The mesh's stable step of central differences, `analysis.critical_step = "eigen"`:
/// `ω_max` as [`highest_frequency`], and the damping the scheme takes at the
/// half-step velocity (`C = a_k K + C_η`, Rayleigh's stiffness part and the
/// materials' dashpots) through the largest damping rate `c` it can give a mode,
/// `a_k ω_max² + λ_max(M_L⁻¹ C_η)`: the limit `2/(√(ω² + c²/4) + c/2)` falls with
/// both, so the step is exact when `C` is proportional to `K` (no dashpots, or
/// Kelvin-Voigt's `η = α C`: the same top mode) and a safe bound otherwise, as the
/// element bound is element by element. Mass damping does not enter (taken at the
/// new velocity, `time::cfl`).
pub fn exact_stable_step(model: &Model) -> Result<ExactStep> {
    let top = Top::new(model)?;
    let k = top.stiffness(model, false);
    let omega_max = top.largest(&k)?.max(0.0).sqrt();
    let a_k = model.analysis.damping.rayleigh[1];
    let mut damping_rate = a_k * omega_max * omega_max;
    let dashpots = model
        .mesh
        .blocks
        .iter()
        .any(|b| b.elements.kind != ElementKind::Bar2 && top.has_viscosity(model, b.material));
    if dashpots {
        let c = top.stiffness(model, true);
        damping_rate += top.largest(&c)?.max(0.0);
    }
    Ok(ExactStep {
        omega_max,
        damping_rate,
        dt: crate::time::cfl::damped_limit(omega_max, damping_rate),
    })
}

/// The pieces of `M_L⁻¹A` on the free dofs.
struct Top {
    asm: Assembler,
    /// The lumped mass, per dof.
    d: Vec<f64>,
    free: Vec<usize>,
}

impl Top {
    fn new(model: &Model) -> Result<Self> {
        let mesh = &model.mesh;
        let asm = Assembler::new(mesh);
        let Mass::Lumped(d) = asm.mass(mesh, &model.materials, true) else {
            return Err(Error::Internal("a lumped mass is a diagonal".into()));
        };
        let free = DofMap::new(mesh.n_dofs(), model.constraints.iter().map(|c| c.dof)).free;
        if free.is_empty() {
            return Err(Error::config(
                "supports",
                "every dof is fixed: the model has no free motion",
            ));
        }
        Ok(Top { asm, d, free })
    }

    fn has_viscosity(&self, model: &Model, material: usize) -> bool {
        let m = &model.materials[material];
        crate::dispatch_kinematics!(model.idealisation, <D, V, K> => m.viscosity::<V, K>().is_some())
    }

    /// The instantaneous stiffness, or (`dashpots`) the materials' viscosity matrix
    /// over the continuum blocks that have one.
    fn stiffness(&self, model: &Model, dashpots: bool) -> Vec<f64> {
        let (mesh, materials) = (&model.mesh, &model.materials);
        crate::dispatch_kinematics!(model.idealisation, <D, V, K> => if dashpots {
            self.asm.stiffness_of::<D, V, K>(
                mesh,
                materials,
                |bi| {
                    let b = &mesh.blocks[bi];
                    b.elements.kind != ElementKind::Bar2
                        && materials[b.material].viscosity::<V, K>().is_some()
                },
                |m| m.viscosity::<V, K>().unwrap_or([[0.0; V]; V]),
            )
        } else {
            self.asm.stiffness_of::<D, V, K>(
                mesh,
                materials,
                |_| true,
                |m| m.instantaneous_stiffness::<V, K>(),
            )
        })
    }

    /// The largest eigenvalue of `M_L⁻¹A` on the free dofs, `A` on the assembler's
    /// pattern. Lanczos on it (self-adjoint in the `M_L` inner product; no factor)
    /// finds the top of the spectrum first; its Ritz value is taken when the
    /// residual bound is below `10⁻⁸` of it, which puts the value itself far closer
    /// (the error goes with the residual squared).
    fn largest(&self, a: &[f64]) -> Result<f64> {
        let (d, free) = (&self.d, &self.free);
        let n = d.len();
        let (mut full, mut out) = (vec![0.0; n], vec![0.0; n]);
        // Lanczos hands the operator `z = M_L q` and wants `S q = M_L⁻¹ A q`.
        let op = |z: &[f64], y: &mut [f64]| {
            for (&f, &v) in free.iter().zip(z) {
                full[f] = v / d[f];
            }
            self.asm.pattern.matvec(a, &full, &mut out);
            for (yi, &f) in y.iter_mut().zip(free) {
                *yi = out[f] / d[f];
            }
            Ok(())
        };
        let mass = |x: &[f64], y: &mut [f64]| {
            for ((yi, &f), &v) in y.iter_mut().zip(free).zip(x) {
                *yi = d[f] * v;
            }
        };
        let wanted = lanczos::Wanted {
            count: 1,
            max_steps: 400,
            tol: 1e-8,
            nearest: false,
        };
        let r = lanczos::lanczos(free.len(), &wanted, &[], op, mass).map_err(|e| match e {
            lanczos::Shortfall::Operator(e) => e,
            lanczos::Shortfall::NotConverged { steps, .. } => Error::Modal(format!(
                "the largest frequency did not converge in {steps} Lanczos steps"
            )),
        })?;
        Ok(r.theta[0])
    }
}
