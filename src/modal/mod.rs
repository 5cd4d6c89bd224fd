//! Modal analysis: the lowest eigenpairs of `K x = ω² M x` on the free dofs, by
//! shift-invert Lanczos ([`lanczos`]) on the same sparse Cholesky, pattern and
//! ordering the runs use (`theory/modal.md`).
//!
//! The factor is that of `K − σM` with a shift `σ < 0`: the matrix a backward-Euler
//! run factorises is `M/h² + K`, the same with `σ = −1/h²`, so any scenario that
//! runs factorises here, free bodies included (their rigid modes have `λ = 0 > σ`
//! and are found and flagged, not failed on). `K` is the linear stiffness at the
//! initial state (the elastic one of every material; history does not enter), `M`
//! the consistent or lumped mass as the scenario says; supports and prescribed
//! motion fix their dofs, bars are in `K` and `M` like any element.

pub mod lanczos;
pub mod step;

use crate::assembly::{Assembler, Mass};
use crate::error::{Error, Result};
use crate::linsolve::Backend;
use crate::model::Model;
use crate::system::{DofMap, EffectiveSystem, Factored};

/// What to compute.
#[derive(Clone, Copy, Debug)]
pub struct ModalOptions {
    /// Number of modes, the lowest.
    pub count: usize,
    /// The shift `σ` (rad²/s², negative); `None`: `−10⁻⁴ tr K / tr M` over the free
    /// dofs, below every mode of a discretised body.
    pub shift: Option<f64>,
    /// The linear solver.
    pub backend: Backend,
}

/// One eigenpair.
#[derive(Clone, Debug)]
pub struct Mode {
    /// `λ = ω²` (rad²/s²).
    pub lambda: f64,
    /// A rigid-body mode: `λ` below `10⁻¹⁰ tr K / tr M`, round-off of zero.
    pub rigid: bool,
    /// The shape on all dofs (constrained ones zero), `M`-normalised: `φᵀMφ = 1`.
    pub shape: Vec<f64>,
    /// `‖Kφ − λMφ‖ / ‖Kφ‖` on the free dofs (against `‖Mφ‖ (tr K / tr M)` for a rigid
    /// mode, whose `Kφ` is round-off).
    pub residual: f64,
    /// Participation factors `Γ_r = φᵀ M ι_r` for the unit translations `ι_r` of the
    /// free dofs along x, y (and z).
    pub participation: [f64; 3],
}

impl Mode {
    /// `ω` (rad/s); zero for a rigid mode.
    pub fn omega(&self) -> f64 {
        if self.rigid {
            0.0
        } else {
            self.lambda.max(0.0).sqrt()
        }
    }
}

/// The modes of a model.
#[derive(Clone, Debug)]
pub struct Modes {
    /// The modes, lowest first.
    pub modes: Vec<Mode>,
    /// The shift the factor was taken at.
    pub shift: f64,
    /// Lanczos steps (solves with the factor).
    pub steps: usize,
    /// `ι_rᵀ M ι_r`: the mass the free dofs carry along each direction.
    pub total_mass: [f64; 3],
    /// Mesh dimension.
    pub dim: usize,
    /// Whether the mass is lumped.
    pub lumped: bool,
    /// Free dofs.
    pub n_free: usize,
}

/// The `count` lowest modes of `model` (see the module's text).
pub fn modes(model: &Model, opts: &ModalOptions) -> Result<Modes> {
    if opts.count == 0 {
        return Err(Error::config("--count", "ask for at least one mode"));
    }
    let mesh = &model.mesh;
    let asm = Assembler::new(mesh);
    let k = asm.stiffness(mesh, &model.materials, model.idealisation);
    let lumped = model.analysis.time.lumped_mass;
    let mass = asm.mass(mesh, &model.materials, lumped);
    let dofs = DofMap::new(mesh.n_dofs(), model.constraints.iter().map(|c| c.dof));
    let n_free = dofs.n_free();
    if n_free == 0 {
        return Err(Error::config(
            "supports",
            "every dof is fixed: the model has no free motion, so no modes",
        ));
    }
    if opts.count > n_free {
        return Err(Error::config(
            "--count",
            format!(
                "{} modes asked for, the model has {n_free} free dofs",
                opts.count
            ),
        ));
    }
    let free = dofs.free.clone();
    let n = mesh.n_dofs();
    let pattern = &asm.pattern;
    let scatter = |x: &[f64], full: &mut Vec<f64>| {
        full.clear();
        full.resize(n, 0.0);
        for (&d, &v) in free.iter().zip(x) {
            full[d] = v;
        }
    };
    // `M` or `K` on a free-dof vector, through two all-dof buffers kept across the
    // Lanczos steps.
    let buffers = std::cell::RefCell::new((vec![0.0; n], vec![0.0; n]));
    let apply = |m: &dyn Fn(&[f64], &mut [f64]), x: &[f64], y: &mut [f64]| {
        let (full, out) = &mut *buffers.borrow_mut();
        scatter(x, full);
        m(full, out);
        for (yi, &d) in y.iter_mut().zip(&free) {
            *yi = out[d];
        }
    };
    let m_full = |x: &[f64], y: &mut [f64]| mass.matvec(pattern, x, y);
    let k_full = |x: &[f64], y: &mut [f64]| pattern.matvec(&k, x, y);
    // tr K / tr M over the free dofs: the scale of ω² an element resolves.
    let (tr_k, tr_m) = traces(&asm, &k, &mass, &free);
    if !(tr_k > 0.0 && tr_m > 0.0) {
        return Err(Error::config(
            "materials",
            "the free dofs carry no stiffness or no mass: no modes",
        ));
    }
    let scale = tr_k / tr_m;
    let mut sigma = match opts.shift {
        Some(s) if !(s.is_finite() && s <= 0.0) => {
            return Err(Error::config(
                "--shift",
                format!(
                    "{s} rad²/s²: the shift must be zero or negative (the factor of K − σM \
                     is a Cholesky, positive only below the lowest mode)"
                ),
            ))
        }
        Some(s) => s,
        None => -1e-4 * scale,
    };
    let mut sys = EffectiveSystem::new(
        pattern,
        dofs,
        opts.backend,
        model.analysis.iteration.ordering,
        &mesh.coords,
    )?;
    // A shift at an eigenvalue (zero, for a free body) does not factor: the shift is
    // moved below it.
    for attempt in 0.. {
        sys.refill(-sigma, &mass, &[(1.0, &k)]);
        match sys.factorize()? {
            Factored::Ok => break,
            Factored::NotPositiveDefinite { .. } if attempt < 3 => {
                sigma = sigma.min(0.0) - 1e-6 * scale * 100f64.powi(attempt);
            }
            Factored::NotPositiveDefinite { dof, message } => {
                return Err(Error::NotPositiveDefinite {
                    backend: sys.backend(),
                    column: dof,
                    message: format!("K − σM at σ = {sigma:e}: {message}"),
                })
            }
        }
    }
    let max_steps = (20 * opts.count + 60).min(n_free);
    let shortfall = |e: lanczos::Shortfall| match e {
        lanczos::Shortfall::Operator(e) => e,
        lanczos::Shortfall::NotConverged { converged, steps } => Error::Stepping(format!(
            "modal analysis: {converged} of {} modes converged in {steps} Lanczos steps; \
             ask for fewer or give a shift nearer the lowest (--shift)",
            opts.count
        )),
    };
    let mut run = |count: usize, locked: &[Vec<f64>]| {
        lanczos::lanczos(
            n_free,
            count,
            max_steps,
            1e-10,
            locked,
            |x, y| {
                y.copy_from_slice(x);
                sys.solve(y)
            },
            |x, y| apply(&m_full, x, y),
        )
    };
    // Found, then checked with what was found locked: a copy of a multiple
    // eigenvalue the first run missed comes out above the lowest found and enters.
    let first = run(opts.count, &[]).map_err(shortfall)?;
    let mut steps = first.steps;
    let mut pairs: Vec<(f64, Vec<f64>)> = first.theta.into_iter().zip(first.vectors).collect();
    while pairs.len() < n_free {
        let locked: Vec<Vec<f64>> = pairs.iter().map(|p| p.1.clone()).collect();
        let more = match run(1, &locked) {
            Ok(r) => r,
            Err(lanczos::Shortfall::NotConverged { .. }) => break,
            Err(e) => return Err(shortfall(e)),
        };
        steps += more.steps;
        let lowest = pairs.last().map_or(f64::INFINITY, |p| p.0);
        let (theta, x) = (more.theta[0], more.vectors[0].clone());
        if theta <= lowest * (1.0 + 1e-8) {
            break;
        }
        pairs.push((theta, x));
        pairs.sort_by(|a, b| b.0.total_cmp(&a.0));
        pairs.truncate(opts.count);
    }
    let ritz = lanczos::Ritz {
        theta: pairs.iter().map(|p| p.0).collect(),
        vectors: pairs.into_iter().map(|p| p.1).collect(),
        steps,
    };
    let dim = mesh.dim;
    let mut total_mass = [0.0; 3];
    let iota: Vec<Vec<f64>> = (0..dim)
        .map(|r| {
            free.iter()
                .map(|&d| f64::from(u8::from(d % dim == r)))
                .collect()
        })
        .collect();
    let mut m_iota = vec![vec![0.0; n_free]; dim];
    for r in 0..dim {
        apply(&m_full, &iota[r], &mut m_iota[r]);
        total_mass[r] = dot(&iota[r], &m_iota[r]);
    }
    let mut modes = Vec::with_capacity(ritz.theta.len());
    let (mut kx, mut mx) = (vec![0.0; n_free], vec![0.0; n_free]);
    for (theta, x) in ritz.theta.iter().zip(&ritz.vectors) {
        let lambda = sigma + 1.0 / theta;
        let rigid = lambda.abs() <= 1e-10 * scale;
        apply(&k_full, x, &mut kx);
        apply(&m_full, x, &mut mx);
        let r: f64 = kx
            .iter()
            .zip(&mx)
            .map(|(a, b)| (a - lambda * b).powi(2))
            .sum::<f64>()
            .sqrt();
        let reference = if rigid { norm(&mx) * scale } else { norm(&kx) };
        let mut participation = [0.0; 3];
        for r in 0..dim {
            participation[r] = dot(x, &m_iota[r]);
        }
        let mut shape = Vec::new();
        scatter(x, &mut shape);
        modes.push(Mode {
            lambda,
            rigid,
            shape,
            residual: r / reference,
            participation,
        });
    }
    Ok(Modes {
        modes,
        shift: sigma,
        steps: ritz.steps,
        total_mass,
        dim,
        lumped,
        n_free,
    })
}

/// `tr K` and `tr M` over the free dofs.
fn traces(asm: &Assembler, k: &[f64], mass: &Mass, free: &[usize]) -> (f64, f64) {
    let p = &asm.pattern;
    let d = p.dim;
    let at = |values: &[f64], f: usize| values[p.position(f / d, f % d, f / d, f % d)];
    free.iter().fold((0.0, 0.0), |(a, b), &f| {
        let m = match mass {
            Mass::Consistent(m) => at(m, f),
            Mass::Lumped(v) => v[f],
        };
        (a + at(k, f), b + m)
    })
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

/// The largest circular frequency `ω_max` of `K φ = ω² M_L φ` on the free dofs,
/// `M_L` the lumped mass (the explicit path's): central differences are stable for
/// `h < 2/ω_max` without damping. Lanczos on `M_L⁻¹K` (self-adjoint in the `M_L`
/// inner product; no factor) finds the top of the spectrum first; its Ritz value is
/// taken when the residual bound is below `10⁻⁸` of it, which puts the value itself
/// far closer (the error goes with the residual squared).
pub fn highest_frequency(model: &Model) -> Result<f64> {
    let mesh = &model.mesh;
    let asm = Assembler::new(mesh);
    let k = asm.stiffness(mesh, &model.materials, model.idealisation);
    let Mass::Lumped(d) = asm.mass(mesh, &model.materials, true) else {
        return Err(Error::Internal("a lumped mass is a diagonal".into()));
    };
    let dofs = DofMap::new(mesh.n_dofs(), model.constraints.iter().map(|c| c.dof));
    let free = dofs.free;
    if free.is_empty() {
        return Err(Error::config(
            "supports",
            "every dof is fixed: the model has no free motion",
        ));
    }
    let n = mesh.n_dofs();
    let (mut full, mut out) = (vec![0.0; n], vec![0.0; n]);
    // Lanczos hands the operator `z = M_L q` and wants `S q = M_L⁻¹ K q`.
    let op = |z: &[f64], y: &mut [f64]| {
        for (&f, &v) in free.iter().zip(z) {
            full[f] = v / d[f];
        }
        asm.pattern.matvec(&k, &full, &mut out);
        for (yi, &f) in y.iter_mut().zip(&free) {
            *yi = out[f] / d[f];
        }
        Ok(())
    };
    let mass = |x: &[f64], y: &mut [f64]| {
        for ((yi, &f), &v) in y.iter_mut().zip(&free).zip(x) {
            *yi = d[f] * v;
        }
    };
    let r = lanczos::lanczos(free.len(), 1, 400, 1e-8, &[], op, mass).map_err(|e| match e {
        lanczos::Shortfall::Operator(e) => e,
        lanczos::Shortfall::NotConverged { steps, .. } => Error::Stepping(format!(
            "the largest frequency did not converge in {steps} Lanczos steps"
        )),
    })?;
    Ok(r.theta[0].max(0.0).sqrt())
}
