//! The fused residual pass of an implicit step: one sweep over the dofs that forms
//! the residual, finishes `M v`, `v` and (elastic models) `f_int = f_int,n + K Δu`,
//! and sums the scales of the convergence test and the step's ledger terms, by name
//! ([`PassSums`]). Split in chunks by `crate::halves`, so the sums are the same in
//! every run.

use crate::energy::work_integrands;

/// Coefficients of the residual pass.
pub(crate) struct PassCoefficients {
    /// `1/h`.
    pub inv_h: f64,
    /// Mass-proportional damping.
    pub damp_m: f64,
    /// Stiffness-proportional damping.
    pub damp_k: f64,
    /// Generalized-α's step (`ALPHA` passes only).
    pub alpha: Option<super::generalized_alpha::AlphaStep>,
}

/// Generalized-α's vectors of the step's start, fixed through its iterations:
/// `a_{n+1−α_m} = c_in Δu − p`, `v_{n+1} = c_v Δu + q`, `M v_{n+1} = c_v M Δu + mq`,
/// and the damping force's part that does not depend on `Δu`, `d`.
#[derive(Clone, Copy)]
pub(crate) struct History<'a> {
    pub p: &'a [f64],
    pub q: &'a [f64],
    pub mq: &'a [f64],
    pub d: &'a [f64],
}

/// What the residual pass reads (whole vectors, or one chunk of each).
#[derive(Clone, Copy)]
pub(crate) struct PassInputs<'a> {
    /// Its increment over the step.
    pub du: &'a [f64],
    /// `K Δu`.
    pub kdu: &'a [f64],
    /// The applied loads at the new time.
    pub f_ext: &'a [f64],
    /// `M v` at the step's start.
    pub mv_n: &'a [f64],
    /// `v` at the step's start.
    pub v_n: &'a [f64],
    /// The internal force at the step's start.
    pub f_int_n: &'a [f64],
    /// The applied loads at the step's start.
    pub f_ext_n: &'a [f64],
    /// 1 on free dofs, 0 on constrained ones.
    pub free: &'a [f64],
    /// Generalized-α's vectors of the step's start (`ALPHA` passes only).
    pub history: Option<History<'a>>,
}

impl<'a> PassInputs<'a> {
    /// The same inputs restricted to the dofs `lo..hi`.
    pub fn range(&self, lo: usize, hi: usize) -> PassInputs<'a> {
        PassInputs {
            du: &self.du[lo..hi],
            kdu: &self.kdu[lo..hi],
            f_ext: &self.f_ext[lo..hi],
            mv_n: &self.mv_n[lo..hi],
            v_n: &self.v_n[lo..hi],
            f_int_n: &self.f_int_n[lo..hi],
            f_ext_n: &self.f_ext_n[lo..hi],
            free: &self.free[lo..hi],
            history: self.history.map(|h| History {
                p: &h.p[lo..hi],
                q: &h.q[lo..hi],
                mq: &h.mq[lo..hi],
                d: &h.d[lo..hi],
            }),
        }
    }
}

/// What the residual pass writes (one piece of each vector).
pub(crate) struct PassOutputs<'a> {
    /// The residual.
    pub r: &'a mut [f64],
    /// The internal force (written for elastic models, read otherwise).
    pub f_int: &'a mut [f64],
    /// `M Δu` on entry, `M v` on exit (dynamic).
    pub mv: &'a mut [f64],
    /// The new velocity (dynamic).
    pub v: &'a mut [f64],
}

/// The sums of one residual pass, by name.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct PassSums {
    /// `Σ_free (f_ext² + f_int² + inertia²)`: the scale of the residual test.
    pub force_scale2: f64,
    /// `Σ_free Δu²`.
    pub increment2: f64,
    /// `Σ (|f_ext| + |f_int| + |momenta| + |damping|)²` over every dof.
    pub magnitude2: f64,
    /// The four work integrands of `energy::work_integrands`.
    pub work: [f64; 4],
    /// `½ v·M v` at the new time (dynamic).
    pub kinetic: f64,
    /// `½ Δv·M Δv`, the scheme's loss (dynamic).
    pub scheme_loss: f64,
    /// `½ Δu·K Δu`, the elastic models' numerical loss.
    pub elastic_loss: f64,
    /// `½ Δu·(f_int,n+1 − f_int,n)` (the trapezoidal rule): what separates the work
    /// of the averaged internal force from backward Euler's `Δu·f_int,n+1`.
    pub internal_jump: f64,
}

impl PassSums {
    /// The sums of two pieces, field by field.
    pub fn merge(a: PassSums, b: PassSums) -> PassSums {
        PassSums {
            force_scale2: a.force_scale2 + b.force_scale2,
            increment2: a.increment2 + b.increment2,
            magnitude2: a.magnitude2 + b.magnitude2,
            work: std::array::from_fn(|k| a.work[k] + b.work[k]),
            kinetic: a.kinetic + b.kinetic,
            scheme_loss: a.scheme_loss + b.scheme_loss,
            elastic_loss: a.elastic_loss + b.elastic_loss,
            internal_jump: a.internal_jump + b.internal_jump,
        }
    }
}

/// The residual pass over one chunk of dofs, specialised for inertia (`DYN`), for
/// elastic models (`ELASTIC`, where `f_int = f_int,n + K Δu` is formed here) and for
/// the trapezoidal rule (`TRAP`, with `DYN`: `v = 2Δu/h − v_n`, the internal and
/// applied forces averaged, `C(v + v_n)/2`). Returns the chunk's [`PassSums`].
#[inline]
pub(crate) fn residual_chunk<
    const DYN: bool,
    const ELASTIC: bool,
    const TRAP: bool,
    const ALPHA: bool,
>(
    inp: &PassInputs,
    out: PassOutputs,
    c: &PassCoefficients,
) -> PassSums {
    let n = out.r.len();
    let PassOutputs { r, f_int, mv, v } = out;
    let (f_int, mv, v) = (&mut f_int[..n], &mut mv[..n], &mut v[..n]);
    let (du, kdu, f_ext) = (&inp.du[..n], &inp.kdu[..n], &inp.f_ext[..n]);
    let (mv_n, v_n, f_int_n) = (&inp.mv_n[..n], &inp.v_n[..n], &inp.f_int_n[..n]);
    let (f_ext_n, free) = (&inp.f_ext_n[..n], &inp.free[..n]);
    let mut acc = PassSums::default();
    let (alpha, hist) = if ALPHA {
        (
            c.alpha.expect("generalized-α coefficients"),
            inp.history.expect("generalized-α history"),
        )
    } else {
        (
            super::generalized_alpha::Alpha::of(1.0).at(1.0),
            History {
                p: &[],
                q: &[],
                mq: &[],
                d: &[],
            },
        )
    };
    for i in 0..n {
        if ELASTIC {
            f_int[i] = f_int_n[i] + kdu[i];
        }
        let (inertia, damping, momenta) = if ALPHA {
            // M a_{n+1−α_m} = c_in M Δu − p; M v_{n+1} = c_v M Δu + mq;
            // C v_{n+1−α_f} = w c_v C Δu + d.
            let m_du = mv[i];
            mv[i] = alpha.c_v * m_du + hist.mq[i];
            v[i] = alpha.c_v * du[i] + hist.q[i];
            let wc = alpha.w * alpha.c_v;
            (
                alpha.c_in * m_du - hist.p[i],
                c.damp_m * wc * m_du + c.damp_k * wc * kdu[i] + hist.d[i],
                (mv[i].abs() + mv_n[i].abs()) * c.inv_h,
            )
        } else if TRAP {
            // M v = 2 M Δu/h − M v_n; C (v + v_n)/2 = C Δu/h.
            let m_du_h = mv[i] * c.inv_h;
            mv[i] = 2.0 * m_du_h - mv_n[i];
            v[i] = 2.0 * du[i] * c.inv_h - v_n[i];
            (
                (mv[i] - mv_n[i]) * c.inv_h,
                c.damp_m * m_du_h + c.damp_k * kdu[i] * c.inv_h,
                (mv[i].abs() + mv_n[i].abs()) * c.inv_h,
            )
        } else if DYN {
            mv[i] *= c.inv_h;
            v[i] = du[i] * c.inv_h;
            (
                (mv[i] - mv_n[i]) * c.inv_h,
                c.damp_m * mv[i] + c.damp_k * kdu[i] * c.inv_h,
                (mv[i].abs() + mv_n[i].abs()) * c.inv_h,
            )
        } else {
            (0.0, 0.0, 0.0)
        };
        let fi = f_int[i];
        r[i] = if ALPHA {
            let w = alpha.w;
            inertia + damping + w * fi + (1.0 - w) * f_int_n[i]
                - w * f_ext[i]
                - (1.0 - w) * f_ext_n[i]
        } else if TRAP {
            inertia + damping + 0.5 * (fi + f_int_n[i]) - 0.5 * (f_ext[i] + f_ext_n[i])
        } else {
            inertia + damping + fi - f_ext[i]
        };
        acc.force_scale2 += free[i] * (f_ext[i] * f_ext[i] + fi * fi + inertia * inertia);
        acc.increment2 += free[i] * du[i] * du[i];
        // Over every dof: the reactions size the forces of a model whose free dofs
        // carry no load.
        let m = f_ext[i].abs() + fi.abs() + momenta + damping.abs();
        acc.magnitude2 += m * m;
        let work = work_integrands(du[i], f_int_n[i], fi, f_ext_n[i], f_ext[i], damping);
        for k in 0..4 {
            acc.work[k] += work[k];
        }
        if DYN {
            acc.kinetic += 0.5 * v[i] * mv[i];
        }
        if ALPHA {
            // The inertia's work less the kinetic energy's change: the scheme's loss.
            acc.internal_jump += 0.5 * du[i] * (fi - f_int_n[i]);
            acc.scheme_loss += du[i] * inertia - 0.5 * (v[i] * mv[i] - v_n[i] * mv_n[i]);
        } else if TRAP {
            acc.internal_jump += 0.5 * du[i] * (fi - f_int_n[i]);
        } else if DYN {
            acc.scheme_loss += 0.5 * (v[i] - v_n[i]) * (mv[i] - mv_n[i]);
        }
        if ELASTIC {
            acc.elastic_loss += 0.5 * du[i] * kdu[i];
        }
    }
    acc
}
