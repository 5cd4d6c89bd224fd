//! The start of a generalized-α step: the vectors of `v_n`, `a_n` and their mass
//! products that stay fixed through the step's iterations (what the residual pass
//! reads as its `History`), and the initial acceleration `a_0` they start from.
//! Theory: `theory/trapezoidal.md`.

use super::generalized_alpha::Alpha;
use super::operators::Operators;
use super::State;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::system::{EffectiveSystem, Factored};

/// Generalized-α's vectors of the step's start, fixed through its iterations (what
/// `residual::History` reads), and `M a_n`.
#[derive(Clone, Debug, Default)]
pub(crate) struct StartVectors {
    pub p: Vec<f64>,
    pub q: Vec<f64>,
    pub mq: Vec<f64>,
    pub d: Vec<f64>,
    ma_n: Vec<f64>,
}

impl StartVectors {
    /// The vectors as the residual pass reads them.
    pub fn history(&self) -> super::residual::History<'_> {
        super::residual::History {
            p: &self.p,
            q: &self.q,
            mq: &self.mq,
            d: &self.d,
        }
    }
}

/// Fills `out` for the step from `s`: `p`, `q`, `mq` and `d` from `v_n`, `M v_n`, `a_n`
/// and `M a_n`.
pub(crate) fn history(ops: &Operators, a: &Alpha, s: &State, out: &mut StartVectors) {
    let StartVectors { p, q, mq, d, ma_n } = out;
    let st = a.at(ops.h());
    let (_, damp_m, damp_k) = ops.dynamic().expect("generalized-α is dynamic");
    let n = s.v.len();
    if s.ma.len() == n {
        ma_n.clone_from(&s.ma);
    } else {
        ma_n.resize(n, 0.0);
        ops.mass.matvec(&ops.asm.pattern, &s.a, ma_n);
    }
    let (v, mv, acc, ma) = (&s.v, &s.mv, &s.a, &*ma_n);
    p.clear();
    p.extend((0..n).map(|i| st.p_v * mv[i] + st.p_a * ma[i]));
    q.clear();
    q.extend((0..n).map(|i| st.q_v * v[i] + st.q_a * acc[i]));
    mq.clear();
    mq.extend((0..n).map(|i| st.q_v * mv[i] + st.q_a * ma[i]));
    // C v_{n+1−α_f} less its Δu part: damp_m M(w q + (1 − w) v_n) + damp_k K(…).
    let wq = st.w;
    d.clear();
    d.extend((0..n).map(|i| damp_m * (wq * mq[i] + (1.0 - wq) * mv[i])));
    if damp_k != 0.0 {
        let x: Vec<f64> = (0..n).map(|i| wq * q[i] + (1.0 - wq) * v[i]).collect();
        let mut kx = vec![0.0; n];
        ops.asm.pattern.matvec(&ops.k, &x, &mut kx);
        for (di, k) in d.iter_mut().zip(&kx) {
            *di += damp_k * k;
        }
    }
}

/// Generalized-α's `a_0`: `M a_0 = f_ext(0) − f_int(u_0) − C v_0` on the free dofs
/// (zero on the constrained ones), one factorisation of `M` on the system's pattern.
pub(crate) fn initial_acceleration(
    model: &Model,
    ops: &Operators,
    sys: &mut EffectiveSystem,
) -> Result<Vec<f64>> {
    let r = out_of_balance(ops, &ops.initial_state(model), None);
    let free = sys.dofs().free.clone();
    let mut rhs: Vec<f64> = free.iter().map(|&d| r[d]).collect();
    sys.refill(1.0, &ops.mass, &[]);
    if let Factored::NotPositiveDefinite { message, .. } = sys.factorize()? {
        return Err(Error::Solver {
            backend: sys.backend(),
            message: format!("the mass matrix for generalized-α's initial acceleration: {message}"),
        });
    }
    sys.solve(&mut rhs)?;
    let mut a0 = vec![0.0; r.len()];
    for (&d, x) in free.iter().zip(rhs) {
        a0[d] = x;
    }
    Ok(a0)
}

/// `f_ext − f_int − C v + f_c` of the state `s` on the free dofs, zero on the
/// constrained ones (`f_c` the contact forces when given).
pub(crate) fn out_of_balance(ops: &Operators, s: &State, contact: Option<&[f64]>) -> Vec<f64> {
    let n = s.v.len();
    let (_, damp_m, damp_k) = ops.dynamic().expect("generalized-α is dynamic");
    let mut kv = vec![0.0; n];
    if damp_k != 0.0 {
        ops.asm.pattern.matvec(&ops.k, &s.v, &mut kv);
    }
    (0..n)
        .map(|d| {
            ops.free_mask[d]
                * (s.f_ext[d] - s.f_int[d] - damp_m * s.mv[d] - damp_k * kv[d]
                    + contact.map_or(0.0, |f| f[d]))
        })
        .collect()
}

/// The relative residual at which [`acceleration`]'s conjugate gradients stop:
/// round-off of the mass products.
pub const MASS_SOLVE_TOLERANCE: f64 = 1e-14;

/// The acceleration of the state `s` from its equilibrium,
/// `M a = f_ext − f_int − C v + f_c` on the free dofs (zero on the constrained
/// ones), `f_c` the contact forces when given ([`mass_solve`]).
pub(crate) fn acceleration(
    ops: &Operators,
    s: &State,
    contact: Option<&[f64]>,
) -> Result<Vec<f64>> {
    let (x, converged) = mass_solve(ops, &out_of_balance(ops, s, contact));
    if converged {
        Ok(x)
    } else {
        Err(Error::Stepping(format!(
            "generalized-α's acceleration after an impact step: conjugate gradients on the \
             mass matrix did not reach {MASS_SOLVE_TOLERANCE:e} in {MASS_SOLVE_ITERATIONS} \
             iterations (a mass matrix far from its lumped form)"
        )))
    }
}

/// `x = M⁻¹ b` on the free dofs (`b` zero on the constrained ones) from zero:
/// [`mass_solve_from`] to [`MASS_SOLVE_TOLERANCE`] of `|b|`.
pub(crate) fn mass_solve(ops: &Operators, b: &[f64]) -> (Vec<f64>, bool) {
    mass_solve_from(ops, b, vec![0.0; b.len()], 0.0)
}

/// `x = M⁻¹ b` on the free dofs (`b` zero on the constrained ones) from the guess
/// `x`: conjugate gradients on `M` preconditioned by its row sums (the lumped mass;
/// one iteration when the mass is lumped) until the residual is below
/// [`MASS_SOLVE_TOLERANCE`] of `|b|` or below `floor`, and whether they got there
/// (else the last iterate). A consistent mass is spectrally close to its lumped form
/// (eigenvalues of their quotient in [¼, 2] for linear elements), so a few tens of
/// products do what a factorisation of `M` would, without one; a good guess needs
/// none.
pub(crate) fn mass_solve_from(
    ops: &Operators,
    b: &[f64],
    mut x: Vec<f64>,
    floor: f64,
) -> (Vec<f64>, bool) {
    let pattern = &ops.asm.pattern;
    let diag = ops.mass.row_sums(pattern);
    let n = b.len();
    let precondition = |r: &[f64], z: &mut Vec<f64>| {
        z.clear();
        z.extend((0..n).map(|d| {
            if diag[d] > 0.0 {
                ops.free_mask[d] * r[d] / diag[d]
            } else {
                0.0
            }
        }));
    };
    let dot = |x: &[f64], y: &[f64]| -> f64 { x.iter().zip(y).map(|(a, b)| a * b).sum() };
    let stop = (MASS_SOLVE_TOLERANCE * dot(b, b).sqrt()).max(floor);
    let mut mp = vec![0.0; n];
    ops.mass.matvec(pattern, &x, &mut mp);
    let mut r: Vec<f64> = (0..n).map(|d| b[d] - ops.free_mask[d] * mp[d]).collect();
    if dot(&r, &r).sqrt() <= stop {
        return (x, true);
    }
    let mut z = Vec::with_capacity(n);
    precondition(&r, &mut z);
    let mut p = z.clone();
    let mut rz = dot(&r, &z);
    for _ in 0..MASS_SOLVE_ITERATIONS {
        ops.mass.matvec(pattern, &p, &mut mp);
        for (m, f) in mp.iter_mut().zip(&ops.free_mask) {
            *m *= f;
        }
        let alpha = rz / dot(&p, &mp);
        for d in 0..n {
            x[d] += alpha * p[d];
            r[d] -= alpha * mp[d];
        }
        if dot(&r, &r).sqrt() <= stop {
            return (x, true);
        }
        precondition(&r, &mut z);
        let rz_new = dot(&r, &z);
        let beta = rz_new / rz;
        rz = rz_new;
        for d in 0..n {
            p[d] = z[d] + beta * p[d];
        }
    }
    (x, false)
}

/// The most conjugate-gradient iterations [`acceleration`] takes.
const MASS_SOLVE_ITERATIONS: usize = 500;
