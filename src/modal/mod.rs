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

mod critical;
pub mod lanczos;
pub mod step;
mod sturm;

pub use critical::{exact_stable_step, highest_frequency, ExactStep};

use crate::assembly::{Assembler, Mass};
use crate::error::{Error, Result};
use crate::linsolve::ldlt::Ldlt;
use crate::linsolve::Backend;
use crate::model::Model;
use crate::system::{DofMap, EffectiveSystem, Factored, ReducedMatrix};
use lanczos::dot;

/// What to compute.
#[derive(Clone, Copy, Debug)]
pub struct ModalOptions {
    /// Number of modes: the lowest, or the nearest `around`.
    pub count: usize,
    /// The shift `σ` (rad²/s², zero or negative) of the Cholesky factor; `None`:
    /// `−10⁻⁷ tr K / tr M` over the free dofs, below every mode of a discretised body.
    pub shift: Option<f64>,
    /// A frequency (Hz): the modes nearest it instead of the lowest, from an `LDLᵀ`
    /// of `K − (2πF)²M` (indefinite; faer whatever the backend).
    pub around: Option<f64>,
    /// The linear solver of the Cholesky factor.
    pub backend: Backend,
}

impl Default for ModalOptions {
    fn default() -> Self {
        ModalOptions {
            count: 10,
            shift: None,
            around: None,
            backend: Backend::default(),
        }
    }
}

/// One eigenpair.
#[derive(Clone, Debug)]
pub struct Mode {
    /// Its place in the spectrum, from 1 (the lowest; rigid modes counted).
    pub number: usize,
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

/// The Sturm check of a set of modes: the eigenvalues of `K x = λ M x` in
/// `[below, above)` counted by the inertia of `K − μM` at both ends (`LDLᵀ`,
/// Sylvester's law), equal to the number found there.
#[derive(Clone, Copy, Debug)]
pub struct Sturm {
    /// The lower end (`−∞` for the lowest modes: nothing to count there).
    pub below: f64,
    /// The upper end: just above the highest eigenvalue found.
    pub above: f64,
    /// Eigenvalues in the interval, by the inertia; all were found (the first
    /// Lanczos run's, plus the copies it missed), then cut to the count asked.
    pub count: usize,
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
    /// The Sturm check the modes passed.
    pub sturm: Sturm,
    /// `ι_rᵀ M ι_r`: the mass the free dofs carry along each direction.
    pub total_mass: [f64; 3],
    /// Mesh dimension.
    pub dim: usize,
    /// Whether the mass is lumped.
    pub lumped: bool,
    /// Free dofs.
    pub n_free: usize,
    /// The factor Lanczos solves with: its analysis, factorisation (a shift moved
    /// off an eigenvalue counts each attempt) and solves.
    pub timing: crate::system::SystemTiming,
    /// The Sturm check's `LDLᵀ` analysis and factorisations (s).
    pub sturm_s: f64,
    /// Wall time of the whole computation, assembly included (s).
    pub total_s: f64,
}

/// The factor Lanczos solves with: the Cholesky of the runs at a shift below the
/// spectrum, or an `LDLᵀ` at a shift inside it.
enum Factor {
    Definite(Box<EffectiveSystem>),
    Indefinite(Box<Ldlt>),
}

/// `K − μM` on the free dofs, its `LDLᵀ` and the time they take: the inertia at
/// any `μ`, and the factor of `--around`.
struct Shifted<'a> {
    reduced: ReducedMatrix,
    ldlt: Option<Ldlt>,
    dofs: &'a DofMap,
    mass: &'a Mass,
    k: &'a [f64],
    order: Option<Vec<usize>>,
    timing: crate::system::SystemTiming,
}

impl Shifted<'_> {
    /// Factorises `K − μM`; `μ` is moved off an eigenvalue (a zero pivot) by a
    /// relative `10⁻⁸` up to three times. Returns the `μ` used and the number of
    /// eigenvalues below it.
    fn factorize(&mut self, mut mu: f64, scale: f64) -> Result<(f64, usize)> {
        for attempt in 0.. {
            self.reduced
                .fill(self.dofs, -mu, self.mass, &[(1.0, self.k)]);
            if self.ldlt.is_none() {
                let t = std::time::Instant::now();
                self.ldlt = Some(Ldlt::analyze(&self.reduced.csc, self.order.as_deref())?);
                self.timing.analysis_s += t.elapsed().as_secs_f64();
            }
            let ldlt = self.ldlt.as_mut().expect("analysed above");
            let t = std::time::Instant::now();
            let res = ldlt.factorize(&self.reduced.csc);
            self.timing.factorization_s += t.elapsed().as_secs_f64();
            match res {
                Ok(inertia) => return Ok((mu, inertia.negative)),
                Err(_) if attempt < 3 => mu += 1e-8 * mu.abs().max(scale * 1e-6),
                Err(e) => return Err(e),
            }
        }
        unreachable!("the loop returns")
    }
}

/// The `count` lowest modes of `model`, or the `count` nearest `opts.around` (see
/// the module's text and `theory/modal.md`).
pub fn modes(model: &Model, opts: &ModalOptions) -> Result<Modes> {
    let started = std::time::Instant::now();
    if opts.count == 0 {
        return Err(Error::config("--count", "ask for at least one mode"));
    }
    if opts.shift.is_some() && opts.around.is_some() {
        return Err(Error::config(
            "--around",
            "give a shift (--shift, below the spectrum) or a frequency to look around \
             (--around), not both",
        ));
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
    let mut shifted = Shifted {
        reduced: ReducedMatrix::new(pattern, &dofs),
        ldlt: None,
        dofs: &dofs,
        mass: &mass,
        k: &k,
        order: None,
        timing: Default::default(),
    };
    let nested = model
        .analysis
        .iteration
        .ordering
        .nested_dissection(n_free, pattern.dim);
    let mut main_timing = crate::system::SystemTiming::default();
    let (mut sigma, mut factor, below_sigma) = match opts.around {
        Some(f) if !(f.is_finite() && f > 0.0) => {
            return Err(Error::config(
                "--around",
                format!("{f} Hz: the frequency to look around must be positive"),
            ))
        }
        Some(f) => {
            if nested {
                shifted.order = Some(shifted.reduced.nested_dissection(&dofs, &mesh.coords));
            }
            let sigma = (2.0 * std::f64::consts::PI * f).powi(2);
            let (sigma, below) = shifted.factorize(sigma, scale)?;
            let ldlt = shifted.ldlt.take().expect("factorised");
            main_timing = shifted.timing;
            shifted.timing = Default::default();
            (sigma, Factor::Indefinite(Box::new(ldlt)), below)
        }
        None => {
            let sigma = match opts.shift {
                Some(s) if !(s.is_finite() && s <= 0.0) => {
                    return Err(Error::config(
                        "--shift",
                        format!(
                            "{s} rad²/s²: the shift must be zero or negative (the factor of \
                             K − σM is a Cholesky, positive only below the lowest mode; \
                             --around F looks inside the spectrum)"
                        ),
                    ))
                }
                Some(s) => s,
                None => -1e-7 * scale,
            };
            let sys = EffectiveSystem::new(
                pattern,
                dofs.clone(),
                opts.backend,
                model.analysis.iteration.ordering,
                &mesh.coords,
            )?;
            shifted.order = sys.ordering();
            (sigma, Factor::Definite(Box::new(sys)), 0)
        }
    };
    // A shift at an eigenvalue (zero, for a free body) does not factor: the shift is
    // moved below it.
    if let Factor::Definite(sys) = &mut factor {
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
    }
    let search = sturm::Search {
        count: opts.count,
        sigma,
        nearest: opts.around.is_some(),
        below_sigma,
        scale,
    };
    let found = sturm::search(
        &search,
        n_free,
        |x, y| {
            y.copy_from_slice(x);
            match &mut factor {
                Factor::Definite(sys) => sys.solve(y),
                Factor::Indefinite(ldlt) => ldlt.solve(y),
            }
        },
        |x, y| apply(&m_full, x, y),
        |mu| shifted.factorize(mu, scale),
    )?;
    let (pairs, steps, first_number) = (found.pairs, found.steps, found.first_number);
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
    let mut modes = Vec::with_capacity(pairs.len());
    let (mut kx, mut mx) = (vec![0.0; n_free], vec![0.0; n_free]);
    for (i, (lambda, x)) in pairs.iter().enumerate() {
        let lambda = *lambda;
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
            number: first_number + i,
            lambda,
            rigid,
            shape,
            residual: r / reference,
            participation,
        });
    }
    let timing = match &factor {
        Factor::Definite(sys) => sys.timing(),
        Factor::Indefinite(_) => crate::system::SystemTiming {
            solves: steps,
            ..main_timing
        },
    };
    Ok(Modes {
        modes,
        shift: sigma,
        steps,
        sturm: found.sturm,
        total_mass,
        dim,
        lumped,
        n_free,
        timing,
        sturm_s: shifted.timing.analysis_s + shifted.timing.factorization_s,
        total_s: started.elapsed().as_secs_f64(),
    })
}

/// What the modes of a model with a material beyond linear elasticity are: those
/// of its initial, elastic stiffness (`None` when every material is linear elastic).
pub fn history_note(model: &Model) -> Option<&'static str> {
    model
        .materials
        .iter()
        .any(|m| !m.is_linear_elastic())
        .then_some(
            "the modes are those of the initial, elastic stiffness; a material with \
             viscosity, damage or plasticity damps or softens them as the run evolves",
        )
}

/// The frequency (Hz) of an eigenvalue `λ = ω²`, signed as `λ` (a shift below the
/// spectrum is negative).
pub fn hz(lambda: f64) -> f64 {
    lambda.signum() * lambda.abs().sqrt() / (2.0 * std::f64::consts::PI)
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

fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}
