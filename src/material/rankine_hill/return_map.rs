//! Rankine-Hill's return mapping: the closest-point projection in the principal
//! frame of the trial stress, written once for `P` principal values (surfaces,
//! corners and apex, the active-set Newton iteration, the consistent tangent, the
//! substepping of a failed increment). The model around it is `super`'s.

use super::RankineHillParams;
use crate::fe::frame::Frame;
use crate::material::linalg::{inverse, solve_in_place, Small, MAX_DIM};
use crate::material::point::{
    dot3, mul3, Dissipation, PointResponse, PointStatus, StrainStep, MAX_STATE,
};

/// The surfaces of the composite criterion are numbered `0..P` for the Rankine
/// planes `σ_a − σ̄_t` on the principal stresses and `P` for von Mises.
type Surface = usize;

/// Outcome of a return in the principal frame.
struct Return<const P: usize> {
    sigma: [f64; P],
    /// Multipliers by surface (`P + 1` used).
    dlambda: [f64; 4],
    /// Algorithmic tangent `∂σ_p/∂ε_p` in the principal frame (zero when not
    /// asked for).
    d_alg: [[f64; P]; P],
}

/// `q = √(Σ σ_a² − Σ_{a<b} σ_a σ_b)` (von Mises; with `P = 2` the plane-stress
/// form with `σ3 = 0`) and its gradient `n_a = (2σ_a − Σ_{b≠a} σ_b)/(2q)`.
fn q_and_n<const P: usize>(s: &[f64; P]) -> (f64, [f64; P]) {
    let mut q2 = 0.0;
    for a in 0..P {
        q2 += s[a] * s[a];
        for b in a + 1..P {
            q2 -= s[a] * s[b];
        }
    }
    let q = q2.max(0.0).sqrt();
    if q == 0.0 {
        return (0.0, [0.0; P]);
    }
    (
        q,
        std::array::from_fn(|a| {
            let mut t = 2.0 * s[a];
            for b in (0..P).filter(|&b| b != a) {
                t -= s[b];
            }
            t / (2.0 * q)
        }),
    )
}

fn normal<const P: usize>(surf: Surface, s: &[f64; P]) -> [f64; P] {
    if surf < P {
        std::array::from_fn(|a| if a == surf { 1.0 } else { 0.0 })
    } else {
        q_and_n(s).1
    }
}

/// Hessian of `q`: `G/(2q) − n⊗n/q`, `G_aa = 2`, `G_ab = −1`.
fn vm_hessian<const P: usize>(s: &[f64; P]) -> [[f64; P]; P] {
    let (q, n) = q_and_n(s);
    if q == 0.0 {
        return [[0.0; P]; P];
    }
    std::array::from_fn(|a| {
        std::array::from_fn(|b| {
            let g = if a == b { 1.0 } else { -0.5 };
            g / q - n[a] * n[b] / q
        })
    })
}

/// A set of active surfaces (at most four), kept on the stack.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Active {
    items: [Surface; 4],
    len: usize,
}

impl Active {
    fn of(list: &[Surface]) -> Self {
        let mut items = [0; 4];
        items[..list.len()].copy_from_slice(list);
        Active {
            items,
            len: list.len(),
        }
    }

    fn push(&mut self, s: Surface) {
        self.items[self.len] = s;
        self.len += 1;
    }

    fn as_slice(&self) -> &[Surface] {
        &self.items[..self.len]
    }
}

/// The active sets a return tries after the surfaces its trial state violates, in
/// order: the planes of the largest principal stresses first, alone and with von
/// Mises, then the corners and (in a solid) the apex, then the rest.
fn candidates(p: usize) -> &'static [&'static [Surface]] {
    if p == 2 {
        &[&[0], &[2], &[0, 2], &[0, 1], &[1, 2], &[1], &[0, 1, 2]]
    } else {
        &[
            &[0],
            &[3],
            &[0, 3],
            &[0, 1],
            &[0, 1, 3],
            &[0, 1, 2],
            &[0, 1, 2, 3],
            &[1],
            &[1, 3],
            &[1, 2],
            &[1, 2, 3],
            &[2],
            &[2, 3],
            &[0, 2],
            &[0, 2, 3],
        ]
    }
}

/// Multipliers (first `m` used), principal stresses and the algorithmic tangent of
/// a projection.
type Projection<const P: usize> = ([f64; 4], [f64; P], [[f64; P]; P]);

struct Ctx<'a, const P: usize> {
    p: &'a RankineHillParams,
    e: f64,
    h: f64,
    /// `C₁₁` of the elasticity (the residual's stress scale).
    d00: f64,
    /// Elastic compliance in the principal frame (plane stress, or the solid's).
    dinv: [[f64; P]; P],
    kt_n: f64,
    kc_n: f64,
    /// Whether the algorithmic tangent is wanted (`StrainStep::tangent`).
    tangent: bool,
}

impl<const P: usize> Ctx<'_, P> {
    fn f(&self, surf: Surface, s: &[f64; P], kt: f64, kc: f64) -> (f64, f64) {
        if surf < P {
            let (y, hh) = self.p.prepared[0].strength(kt, self.e, self.h);
            (s[surf] - y, hh)
        } else {
            let (y, hh) = self.p.prepared[1].strength(kc, self.e, self.h);
            (q_and_n(s).0 - y, hh)
        }
    }

    fn kappas(&self, active: &[Surface], dl: &[f64]) -> (f64, f64) {
        let (mut kt, mut kc) = (self.kt_n, self.kc_n);
        for (a, l) in active.iter().zip(dl) {
            if *a == P {
                kc += l
            } else {
                kt += l
            }
        }
        (kt, kc)
    }

    /// Closest-point projection for a fixed active set (`f_t0` the initial tensile
    /// strength); `None` if Newton fails.
    fn project(&self, s_tr: &[f64; P], active: &[Surface], f_t0: f64) -> Option<Projection<P>> {
        let m = active.len();
        let n = P + m;
        let mut s = *s_tr;
        let mut dl = [0.0; 4];
        let mut scale = s_tr[0].abs();
        for v in &s_tr[1..] {
            scale = scale.max(v.abs());
        }
        let scale = scale.max(f_t0).max(1.0);
        for _ in 0..60 {
            let (kt, kc) = self.kappas(active, &dl[..m]);
            // Residuals.
            let mut r = [0.0; MAX_DIM];
            let ds: [f64; P] = std::array::from_fn(|i| s[i] - s_tr[i]);
            for i in 0..P {
                let mut v = self.dinv[i][0] * ds[0];
                for j in 1..P {
                    v += self.dinv[i][j] * ds[j];
                }
                r[i] = v;
            }
            let mut hs = [[0.0; P]; P];
            let mut jac: Small = [[0.0; MAX_DIM]; MAX_DIM];
            let mut hard = [0.0; 4];
            for (a, surf) in active.iter().enumerate() {
                let nv = normal(*surf, &s);
                for i in 0..P {
                    r[i] += dl[a] * nv[i];
                }
                let (f, hh) = self.f(*surf, &s, kt, kc);
                r[P + a] = f;
                hard[a] = hh;
                if *surf == P {
                    let hv = vm_hessian(&s);
                    for i in 0..P {
                        for j in 0..P {
                            hs[i][j] += dl[a] * hv[i][j];
                        }
                    }
                }
                for i in 0..P {
                    jac[i][P + a] = nv[i];
                    jac[P + a][i] = nv[i];
                }
            }
            for i in 0..P {
                for j in 0..P {
                    jac[i][j] = self.dinv[i][j] + hs[i][j];
                }
            }
            // ∂f_a/∂Δλ_b = −H_a when a, b drive the same variable.
            for (a, sa) in active.iter().enumerate() {
                for (b, sb) in active.iter().enumerate() {
                    if (*sa == P) == (*sb == P) {
                        jac[P + a][P + b] = -hard[a];
                    }
                }
            }
            let mut stress_part = r[0].abs();
            for v in &r[1..P] {
                stress_part += v.abs();
            }
            let norm = stress_part * self.d00 + r[P..n].iter().map(|x| x.abs()).sum::<f64>();
            if norm <= 1e-12 * scale {
                if !self.tangent {
                    return Some((dl, s, [[0.0; P]; P]));
                }
                // Algorithmic tangent: A = [D⁻¹ + Σ Δλ ∂n/∂σ]⁻¹, D_alg = A − A N (NᵀAN + H)⁻¹ NᵀA.
                let a = inverse(&jac, P)?;
                let mut an = [[0.0; P]; 4]; // A n_b
                for (b, surf) in active.iter().enumerate() {
                    let nv = normal(*surf, &s);
                    an[b] = std::array::from_fn(|i| {
                        let mut v = a[i][0] * nv[0];
                        for j in 1..P {
                            v += a[i][j] * nv[j];
                        }
                        v
                    });
                }
                let mut g: Small = [[0.0; MAX_DIM]; MAX_DIM];
                for (x, sx) in active.iter().enumerate() {
                    let nx = normal(*sx, &s);
                    for y in 0..m {
                        let mut v = nx[0] * an[y][0];
                        for i in 1..P {
                            v += nx[i] * an[y][i];
                        }
                        g[x][y] = v - jac[P + x][P + y];
                    }
                }
                let gi = inverse(&g, m)?;
                let mut d_alg = [[0.0; P]; P];
                for i in 0..P {
                    for j in 0..P {
                        let mut v = a[i][j];
                        for x in 0..m {
                            for y in 0..m {
                                v -= an[x][i] * gi[x][y] * an[y][j];
                            }
                        }
                        d_alg[i][j] = v;
                    }
                }
                return Some((dl, s, d_alg));
            }
            let mut dx = [0.0; MAX_DIM];
            for i in 0..n {
                dx[i] = -r[i];
            }
            if !solve_in_place(jac, &mut dx, n) {
                return None;
            }
            for i in 0..P {
                s[i] += dx[i];
            }
            for a in 0..m {
                dl[a] += dx[P + a];
            }
        }
        None
    }

    /// Active-set return: starts from the surfaces violated at the trial state, drops
    /// surfaces with negative multipliers, adds violated ones, until KKT holds.
    fn ret(&self, s_tr: &[f64; P]) -> Option<Return<P>> {
        let [f_t0, f_c0] = self.p.initial;
        let tol = 1e-10 * f_c0.max(f_t0).max(1.0);
        let mut active = Active::of(&[]);
        for s in 0..=P {
            if self.f(s, s_tr, self.kt_n, self.kc_n).0 > tol {
                active.push(s);
            }
        }
        let admissible = |set: &[Surface]| -> Option<Return<P>> {
            let (dl, s, d_alg) = self.project(s_tr, set, f_t0)?;
            let dl = &dl[..set.len()];
            if dl.iter().any(|&l| l < -tol / self.d00) {
                return None;
            }
            let (kt, kc) = self.kappas(set, dl);
            if (0..=P).any(|x| !set.contains(&x) && self.f(x, &s, kt, kc).0 > tol) {
                return None;
            }
            let mut lam = [0.0; 4];
            for (a, sf) in set.iter().enumerate() {
                lam[*sf] = dl[a];
            }
            Some(Return {
                sigma: s,
                dlambda: lam,
                d_alg,
            })
        };
        // Surfaces were taken in increasing order, so the set is sorted already.
        if let Some(r) = admissible(active.as_slice()) {
            return Some(r);
        }
        candidates(P).iter().find_map(|set| admissible(set))
    }
}

/// The most substeps a strain increment is split into when its return fails.
const MAX_SUBSTEPS: usize = 64;

/// Rankine-Hill update in the plane (`V = 3`, `P = 2`, plane stress) or a solid
/// (`V = 6`, `P = 3`). State: the plastic strain (`V` Voigt components), `κ_t`,
/// `κ_c`.
///
/// When the return of the whole increment finds no admissible state (the active-set
/// Newton projection fails on a large increment), the increment is split into 2, 4,
/// …, `MAX_SUBSTEPS` (64) equal substeps, each returned from the state the last left;
/// the step's plastic dissipation is the substeps' sum, its stress and tangent the
/// last substep's, and `D_num` closes the step's split `σ¹:Δε = Δψ + D_plastic +
/// D_num` as for a single return. A strength that is exhausted fails at every
/// split and the failure is reported (theory/plasticity.md).
pub fn update<const V: usize, const P: usize, F: Frame<V, P>>(
    p: &RankineHillParams,
    c: &[[f64; V]; V],
    e: f64,
    nu: f64,
    step: &StrainStep<V>,
    state_n: &[f64],
    state: &mut [f64],
) -> PointResponse<V> {
    let whole = update_once::<V, P, F>(p, c, e, nu, step, state_n, state);
    if whole.status == PointStatus::Ok {
        return whole;
    }
    let mut n = 2;
    while n <= MAX_SUBSTEPS {
        if let Some(r) = substepped::<V, P, F>(p, c, e, nu, step, state_n, state, n) {
            return r;
        }
        n *= 2;
    }
    state.copy_from_slice(state_n);
    whole
}

/// The number of history values of a point with `V` strain components.
pub const fn n_state(voigt: usize) -> usize {
    voigt + 2
}

/// The increment of `step` in `n` equal substeps; `None` if one of them fails.
#[allow(clippy::too_many_arguments)]
fn substepped<const V: usize, const P: usize, F: Frame<V, P>>(
    p: &RankineHillParams,
    c: &[[f64; V]; V],
    e: f64,
    nu: f64,
    step: &StrainStep<V>,
    state_n: &[f64],
    state: &mut [f64],
    n: usize,
) -> Option<PointResponse<V>> {
    let ns = n_state(V);
    let mut cur = [0.0; MAX_STATE];
    cur[..ns].copy_from_slice(&state_n[..ns]);
    let mut next = [0.0; MAX_STATE];
    let mut plastic = 0.0;
    let mut eps_a = step.eps_n;
    let mut last = None;
    for k in 1..=n {
        let f = k as f64 / n as f64;
        let eps_b: [f64; V] =
            std::array::from_fn(|i| step.eps_n[i] + f * (step.eps[i] - step.eps_n[i]));
        let sub = StrainStep {
            eps_n: eps_a,
            eps: if k == n { step.eps } else { eps_b },
            ..*step
        };
        let r = update_once::<V, P, F>(p, c, e, nu, &sub, &cur[..ns], &mut next[..ns]);
        if r.status != PointStatus::Ok {
            return None;
        }
        plastic += r.dissipation.plastic;
        cur = next;
        eps_a = sub.eps;
        last = Some(r);
    }
    let r = last?;
    state[..ns].copy_from_slice(&cur[..ns]);
    let ee_n: [f64; V] = std::array::from_fn(|i| step.eps_n[i] - state_n[i]);
    let psi_n = 0.5 * dot3(&ee_n, &mul3(c, &ee_n));
    let de: [f64; V] = std::array::from_fn(|i| step.eps[i] - step.eps_n[i]);
    let work = dot3(&r.sigma, &de);
    Some(PointResponse {
        dissipation: Dissipation {
            plastic,
            numerical: work - (r.psi - psi_n) - plastic,
            ..Default::default()
        },
        ..r
    })
}

/// One return of the whole increment (see [`update`]).
fn update_once<const V: usize, const P: usize, F: Frame<V, P>>(
    p: &RankineHillParams,
    c: &[[f64; V]; V],
    e: f64,
    nu: f64,
    step: &StrainStep<V>,
    state_n: &[f64],
    state: &mut [f64],
) -> PointResponse<V> {
    let ep_n: [f64; V] = std::array::from_fn(|i| state_n[i]);
    let (kt_n, kc_n) = (state_n[V], state_n[V + 1]);
    let ee_tr: [f64; V] = std::array::from_fn(|i| step.eps[i] - ep_n[i]);
    let s_tr = mul3(c, &ee_tr);
    let ee_n: [f64; V] = std::array::from_fn(|i| step.eps_n[i] - ep_n[i]);
    let sigma_n = mul3(c, &ee_n);
    // The trial's principal values decide; the frame is needed only for a return.
    let values = F::values(&s_tr);
    let ctx = Ctx::<P> {
        p,
        e,
        h: step.length,
        d00: c[0][0],
        dinv: std::array::from_fn(|a| {
            std::array::from_fn(|b| if a == b { 1.0 / e } else { -nu / e })
        }),
        kt_n,
        kc_n,
        tangent: step.tangent,
    };
    state.copy_from_slice(state_n);
    let elastic = PointResponse {
        sigma: s_tr,
        tangent: *c,
        psi: 0.5 * dot3(&ee_tr, &s_tr),
        dissipation: Dissipation {
            numerical: numerical_elastic(c, &step.eps, &step.eps_n),
            ..Default::default()
        },
        status: PointStatus::Ok,
    };
    // The strengths of the committed state: read, for a point that never yielded.
    let y_t = if kt_n == 0.0 {
        p.initial[0]
    } else {
        p.prepared[0].strength(kt_n, e, step.length).0
    };
    let y_c = if kc_n == 0.0 {
        p.initial[1]
    } else {
        p.prepared[1].strength(kc_n, e, step.length).0
    };
    let trial_ok = values[0] - y_t <= 0.0 && q_and_n(&values).0 - y_c <= 0.0;
    if trial_ok {
        return elastic;
    }
    let (frame, s_p) = F::decompose(&s_tr);
    let Some(ret) = ctx.ret(&s_p) else {
        // No admissible return (an exhausted strength, or a softening too steep for
        // the element): the trial response, flagged, so the equilibrium loop reports
        // the point, the step is cut, and a persisting failure stops the run with
        // its location. The history stays the committed one.
        return PointResponse {
            status: PointStatus::ReturnFailed,
            ..elastic
        };
    };
    // Plastic strain increment in the principal frame: D⁻¹(σ_tr − σ).
    let dsp: [f64; P] = std::array::from_fn(|a| s_p[a] - ret.sigma[a]);
    let dep_p: [f64; P] = std::array::from_fn(|a| {
        let others: f64 = (0..P).filter(|&b| b != a).map(|b| dsp[b]).sum();
        (dsp[a] - nu * others) / e
    });
    let dep = frame.strain_from(&dep_p);
    for i in 0..V {
        state[i] = ep_n[i] + dep[i];
    }
    let mut dl_t = ret.dlambda[0];
    for a in 1..P {
        dl_t += ret.dlambda[a];
    }
    state[V] = kt_n + dl_t;
    state[V + 1] = kc_n + ret.dlambda[P];
    let sigma = frame.stress_from(&ret.sigma);
    let tangent = if step.tangent {
        frame_tangent::<V, P, F>(&frame, &ee_tr, &ret)
    } else {
        *c
    };
    let ee: [f64; V] = std::array::from_fn(|i| step.eps[i] - state[i]);
    let psi = 0.5 * dot3(&ee, &sigma);
    let psi_n = 0.5 * dot3(&ee_n, &sigma_n);
    // The paper's trapezoid ½(σⁿ + σⁿ⁺¹):Δεᵖ with each stress paired with its own
    // flow direction: σ:∂f/∂σ is the surface strength on every surface, so per surface
    // ½(σ̄(κⁿ) + σ̄(κⁿ⁺¹)) Δλ. Equal to the literal form for steps that start on the
    // surface with fixed principal axes (and a radial path for von Mises), never
    // above it, and non-negative always (theory/plasticity.md).
    // The committed strengths were read above where the point had yielded.
    let yt0 = if kt_n == 0.0 {
        p.prepared[0].strength(kt_n, e, step.length).0
    } else {
        y_t
    };
    let (yt1, _) = p.prepared[0].strength(state[V], e, step.length);
    let yc0 = if kc_n == 0.0 {
        p.prepared[1].strength(kc_n, e, step.length).0
    } else {
        y_c
    };
    let (yc1, _) = p.prepared[1].strength(state[V + 1], e, step.length);
    let plastic = 0.5 * (yt0 + yt1) * dl_t + 0.5 * (yc0 + yc1) * ret.dlambda[P];
    let de: [f64; V] = std::array::from_fn(|i| step.eps[i] - step.eps_n[i]);
    let work = dot3(&sigma, &de);
    PointResponse {
        sigma,
        tangent,
        psi,
        dissipation: Dissipation {
            plastic,
            numerical: work - (psi - psi_n) - plastic,
            ..Default::default()
        },
        status: PointStatus::Ok,
    }
}

/// The consistent tangent in Voigt form of a return in `frame` from the trial
/// elastic strain `ee_tr`: the principal-frame normal block plus the spectral shear
/// terms, rotated back.
fn frame_tangent<const V: usize, const P: usize, F: Frame<V, P>>(
    frame: &F,
    ee_tr: &[f64; V],
    ret: &Return<P>,
) -> [[f64; V]; V] {
    // Tangent: principal-frame normal block plus the spectral shear terms.
    let et = frame.strain_to_frame(ee_tr);
    let mut dp = [[0.0; V]; V];
    for (a, &na) in F::NORMAL.iter().enumerate() {
        for (b, &nb) in F::NORMAL.iter().enumerate() {
            dp[na][nb] = ret.d_alg[a][b];
        }
    }
    for &(k, a, b) in F::SHEARS {
        let (ea, eb) = (et[F::NORMAL[a]], et[F::NORMAL[b]]);
        let gap = ea - eb;
        dp[k][k] = if gap.abs() > 1e-12 * (ea.abs() + eb.abs()).max(1e-30) {
            (ret.sigma[a] - ret.sigma[b]) / (2.0 * gap)
        } else {
            0.5 * (ret.d_alg[a][a] - ret.d_alg[a][b])
        };
    }
    let t = frame.transform();
    let mut tangent = [[0.0; V]; V];
    for i in 0..V {
        for j in 0..V {
            let mut v = 0.0;
            for k in 0..V {
                for l in 0..V {
                    v += t[k][i] * dp[k][l] * t[l][j];
                }
            }
            tangent[i][j] = v;
        }
    }
    tangent
}

fn numerical_elastic<const V: usize>(c: &[[f64; V]; V], eps: &[f64; V], eps_n: &[f64; V]) -> f64 {
    let de: [f64; V] = std::array::from_fn(|i| eps[i] - eps_n[i]);
    0.5 * dot3(&de, &mul3(c, &de))
}
