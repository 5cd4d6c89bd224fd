//! Rankine-Hill plasticity, isotropic, plane stress (after Lourenço, de Borst & Rots
//! 1997, isotropic case): Rankine (maximum principal stress) in tension, Hill in
//! compression, which for an isotropic material is von Mises. Associated flow, one
//! hardening/softening variable per criterion.
//!
//! The return mapping works in the principal frame of the trial stress (isotropy
//! keeps the return coaxial): surfaces `R1: σ1 − σ̄_t(κ_t)`, `R2: σ2 − σ̄_t(κ_t)`,
//! `VM: q(σ) − σ̄_c(κ_c)` with `q = √(σ1² − σ1σ2 + σ2²)`; `κ_t = Σ Δλ_R`, `κ_c = Σ Δλ_VM`.
//! Closest-point projection by Newton on `(σ1, σ2, Δλ_active)` with an active-set
//! loop (corners: R1+VM, R1+R2, R1+R2+VM); consistent tangent from the local
//! Jacobian plus the spectral shear term. Plastic dissipation: the paper's trapezoid
//! `½(σⁿ + σⁿ⁺¹):Δεᵖ` evaluated per surface as `½(σ̄(κⁿ) + σ̄(κⁿ⁺¹)) Δλ`, each stress
//! paired with its own flow direction. See `theory/plasticity.md`.

use super::hardening::{Hardening, PreparedLaw};
use super::linalg::{inverse, solve_in_place, Small, MAX_DIM};
use super::principal::{
    principal_stress, principal_values, strain_from_principal, strain_to_frame, strain_transform,
    stress_from_principal,
};
use super::{dot3, mul3, Dissipation, PointResponse, PointStatus, StrainStep};

/// Rankine-Hill parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RankineHillParams {
    /// Tension law (Rankine surfaces).
    pub tension: Hardening,
    /// Compression law (von Mises surface).
    pub compression: Hardening,
    /// The laws' strengths before any plastic flow (`κ = 0`) at the material's
    /// Young's modulus: the elastic check of a point that never yielded reads them
    /// instead of evaluating the laws ([`RankineHillParams::new`] sets them).
    pub initial: [f64; 2],
    /// The tension and compression laws prepared for that modulus (the returns
    /// evaluate them at every iteration).
    pub prepared: [PreparedLaw; 2],
}

impl RankineHillParams {
    /// The parameters of the two laws for a material of Young's modulus `e`.
    pub fn new(tension: Hardening, compression: Hardening, e: f64) -> Self {
        RankineHillParams {
            tension,
            compression,
            initial: [tension.initial(e), compression.initial(e)],
            prepared: [tension.prepared(e), compression.prepared(e)],
        }
    }
}

/// Surfaces of the composite criterion.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Surface {
    R1,
    R2,
    Vm,
}

/// Outcome of a return in the principal frame.
struct Return {
    sigma: [f64; 2],
    dlambda: [f64; 3],
    /// Algorithmic tangent `∂σ_p/∂ε_p` (2x2) in the principal frame.
    d_alg: [[f64; 2]; 2],
}

fn q_and_n(s: &[f64; 2]) -> (f64, [f64; 2]) {
    let q = (s[0] * s[0] - s[0] * s[1] + s[1] * s[1]).max(0.0).sqrt();
    if q == 0.0 {
        return (0.0, [0.0, 0.0]);
    }
    (
        q,
        [
            (2.0 * s[0] - s[1]) / (2.0 * q),
            (2.0 * s[1] - s[0]) / (2.0 * q),
        ],
    )
}

fn normal(surf: Surface, s: &[f64; 2]) -> [f64; 2] {
    match surf {
        Surface::R1 => [1.0, 0.0],
        Surface::R2 => [0.0, 1.0],
        Surface::Vm => q_and_n(s).1,
    }
}

/// Hessian of `q`: `G/(2q) − n⊗n/q`, `G = [[2,−1],[−1,2]]`.
fn vm_hessian(s: &[f64; 2]) -> [[f64; 2]; 2] {
    let (q, n) = q_and_n(s);
    if q == 0.0 {
        return [[0.0; 2]; 2];
    }
    [
        [1.0 / q - n[0] * n[0] / q, -0.5 / q - n[0] * n[1] / q],
        [-0.5 / q - n[1] * n[0] / q, 1.0 / q - n[1] * n[1] / q],
    ]
}

/// A set of active surfaces (at most three), kept on the stack.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Active {
    items: [Surface; 3],
    len: usize,
}

impl Active {
    fn of(list: &[Surface]) -> Self {
        let mut items = [Surface::R1; 3];
        items[..list.len()].copy_from_slice(list);
        Active {
            items,
            len: list.len(),
        }
    }

    fn as_slice(&self) -> &[Surface] {
        &self.items[..self.len]
    }
}

/// Multipliers (first `m` used), principal stresses and the 2x2 algorithmic tangent
/// of a projection.
type Projection = ([f64; 3], [f64; 2], [[f64; 2]; 2]);

struct Ctx<'a> {
    p: &'a RankineHillParams,
    e: f64,
    h: f64,
    /// Plane-stress elasticity in the principal frame (normal part) and its inverse.
    d: [[f64; 2]; 2],
    dinv: [[f64; 2]; 2],
    kt_n: f64,
    kc_n: f64,
}

impl Ctx<'_> {
    fn f(&self, surf: Surface, s: &[f64; 2], kt: f64, kc: f64) -> (f64, f64) {
        match surf {
            Surface::R1 => {
                let (y, hh) = self.p.prepared[0].strength(kt, self.e, self.h);
                (s[0] - y, hh)
            }
            Surface::R2 => {
                let (y, hh) = self.p.prepared[0].strength(kt, self.e, self.h);
                (s[1] - y, hh)
            }
            Surface::Vm => {
                let (y, hh) = self.p.prepared[1].strength(kc, self.e, self.h);
                (q_and_n(s).0 - y, hh)
            }
        }
    }

    fn kappas(&self, active: &[Surface], dl: &[f64]) -> (f64, f64) {
        let (mut kt, mut kc) = (self.kt_n, self.kc_n);
        for (a, l) in active.iter().zip(dl) {
            match a {
                Surface::Vm => kc += l,
                _ => kt += l,
            }
        }
        (kt, kc)
    }

    /// Closest-point projection for a fixed active set (`f_t0` the initial tensile
    /// strength); `None` if Newton fails.
    fn project(&self, s_tr: &[f64; 2], active: &[Surface], f_t0: f64) -> Option<Projection> {
        let m = active.len();
        let n = 2 + m;
        let mut s = *s_tr;
        let mut dl = [0.0; 3];
        let scale = s_tr[0].abs().max(s_tr[1].abs()).max(f_t0).max(1.0);
        for _ in 0..60 {
            let (kt, kc) = self.kappas(active, &dl[..m]);
            // Residuals.
            let mut r = [0.0; MAX_DIM];
            let ds = [s[0] - s_tr[0], s[1] - s_tr[1]];
            for i in 0..2 {
                r[i] = self.dinv[i][0] * ds[0] + self.dinv[i][1] * ds[1];
            }
            let mut hs = [[0.0; 2]; 2];
            let mut jac: Small = [[0.0; MAX_DIM]; MAX_DIM];
            let mut hard = [0.0; 3];
            for (a, surf) in active.iter().enumerate() {
                let nv = normal(*surf, &s);
                r[0] += dl[a] * nv[0];
                r[1] += dl[a] * nv[1];
                let (f, hh) = self.f(*surf, &s, kt, kc);
                r[2 + a] = f;
                hard[a] = hh;
                if *surf == Surface::Vm {
                    let hv = vm_hessian(&s);
                    for i in 0..2 {
                        for j in 0..2 {
                            hs[i][j] += dl[a] * hv[i][j];
                        }
                    }
                }
                jac[0][2 + a] = nv[0];
                jac[1][2 + a] = nv[1];
                jac[2 + a][0] = nv[0];
                jac[2 + a][1] = nv[1];
            }
            for i in 0..2 {
                for j in 0..2 {
                    jac[i][j] = self.dinv[i][j] + hs[i][j];
                }
            }
            // ∂f_a/∂Δλ_b = −H_a when a, b drive the same variable.
            for (a, sa) in active.iter().enumerate() {
                for (b, sb) in active.iter().enumerate() {
                    if (*sa == Surface::Vm) == (*sb == Surface::Vm) {
                        jac[2 + a][2 + b] = -hard[a];
                    }
                }
            }
            let norm = (r[0].abs() + r[1].abs()) * self.d[0][0]
                + r[2..n].iter().map(|x| x.abs()).sum::<f64>();
            if norm <= 1e-12 * scale {
                // Algorithmic tangent: A = [D⁻¹ + Σ Δλ ∂n/∂σ]⁻¹, D_alg = A − A N (NᵀAN + H)⁻¹ NᵀA.
                let a = inverse(&jac, 2)?;
                let mut an = [[0.0; 2]; 3]; // A n_b
                for (b, surf) in active.iter().enumerate() {
                    let nv = normal(*surf, &s);
                    an[b] = [
                        a[0][0] * nv[0] + a[0][1] * nv[1],
                        a[1][0] * nv[0] + a[1][1] * nv[1],
                    ];
                }
                let mut g: Small = [[0.0; MAX_DIM]; MAX_DIM];
                for (x, sx) in active.iter().enumerate() {
                    let nx = normal(*sx, &s);
                    for y in 0..m {
                        g[x][y] = nx[0] * an[y][0] + nx[1] * an[y][1] - jac[2 + x][2 + y];
                    }
                }
                let gi = inverse(&g, m)?;
                let mut d_alg = [[0.0; 2]; 2];
                for i in 0..2 {
                    for j in 0..2 {
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
            s[0] += dx[0];
            s[1] += dx[1];
            for a in 0..m {
                dl[a] += dx[2 + a];
            }
        }
        None
    }

    /// Active-set return: starts from the surfaces violated at the trial state, drops
    /// surfaces with negative multipliers, adds violated ones, until KKT holds.
    fn ret(&self, s_tr: &[f64; 2]) -> Option<Return> {
        let [f_t0, f_c0] = self.p.initial;
        let tol = 1e-10 * f_c0.max(f_t0).max(1.0);
        let all = [Surface::R1, Surface::R2, Surface::Vm];
        let mut active = Active::of(&[]);
        for s in all {
            if self.f(s, s_tr, self.kt_n, self.kc_n).0 > tol {
                active.items[active.len] = s;
                active.len += 1;
            }
        }
        let candidates: [&[Surface]; 7] = [
            &[Surface::R1],
            &[Surface::Vm],
            &[Surface::R1, Surface::Vm],
            &[Surface::R1, Surface::R2],
            &[Surface::R2, Surface::Vm],
            &[Surface::R2],
            &[Surface::R1, Surface::R2, Surface::Vm],
        ];
        let admissible = |set: &[Surface]| -> Option<Return> {
            let (dl, s, d_alg) = self.project(s_tr, set, f_t0)?;
            let dl = &dl[..set.len()];
            if dl.iter().any(|&l| l < -tol / self.d[0][0]) {
                return None;
            }
            let (kt, kc) = self.kappas(set, dl);
            if all
                .iter()
                .any(|x| !set.contains(x) && self.f(*x, &s, kt, kc).0 > tol)
            {
                return None;
            }
            let mut lam = [0.0; 3];
            for (a, sf) in set.iter().enumerate() {
                lam[all.iter().position(|x| x == sf).expect("known surface")] = dl[a];
            }
            Some(Return {
                sigma: s,
                dlambda: lam,
                d_alg,
            })
        };
        // Surfaces were taken in the order of `all`, so the set is sorted already.
        if let Some(r) = admissible(active.as_slice()) {
            return Some(r);
        }
        candidates.iter().find_map(|set| admissible(set))
    }
}

/// The most substeps a strain increment is split into when its return fails.
const MAX_SUBSTEPS: usize = 64;

/// Rankine-Hill update. State: `[εᵖ_xx, εᵖ_yy, γᵖ_xy, κ_t, κ_c]`.
///
/// When the return of the whole increment finds no admissible state (the active-set
/// Newton projection fails on a large increment), the increment is split into 2, 4,
/// …, [`MAX_SUBSTEPS`] equal substeps, each returned from the state the last left;
/// the step's plastic dissipation is the substeps' sum, its stress and tangent the
/// last substep's, and `D_num` closes the step's split `σ¹:Δε = Δψ + D_plastic +
/// D_num` as for a single return. A strength that is exhausted fails at every
/// split and the failure is reported (theory/plasticity.md).
pub fn update(
    p: &RankineHillParams,
    c: &[[f64; 3]; 3],
    e: f64,
    nu: f64,
    step: &StrainStep,
    state_n: &[f64],
    state: &mut [f64],
) -> PointResponse {
    let whole = update_once(p, c, e, nu, step, state_n, state);
    if whole.status == PointStatus::Ok {
        return whole;
    }
    let mut n = 2;
    while n <= MAX_SUBSTEPS {
        if let Some(r) = substepped(p, c, e, nu, step, state_n, state, n) {
            return r;
        }
        n *= 2;
    }
    state.copy_from_slice(state_n);
    whole
}

/// The increment of `step` in `n` equal substeps; `None` if one of them fails.
#[allow(clippy::too_many_arguments)]
fn substepped(
    p: &RankineHillParams,
    c: &[[f64; 3]; 3],
    e: f64,
    nu: f64,
    step: &StrainStep,
    state_n: &[f64],
    state: &mut [f64],
    n: usize,
) -> Option<PointResponse> {
    let mut cur = [0.0; 5];
    cur.copy_from_slice(&state_n[..5]);
    let mut next = [0.0; 5];
    let mut plastic = 0.0;
    let mut eps_a = step.eps_n;
    let mut last = None;
    for k in 1..=n {
        let f = k as f64 / n as f64;
        let eps_b: [f64; 3] =
            std::array::from_fn(|i| step.eps_n[i] + f * (step.eps[i] - step.eps_n[i]));
        let sub = StrainStep {
            eps_n: eps_a,
            eps: if k == n { step.eps } else { eps_b },
            ..*step
        };
        let r = update_once(p, c, e, nu, &sub, &cur, &mut next);
        if r.status != PointStatus::Ok {
            return None;
        }
        plastic += r.dissipation.plastic;
        cur = next;
        eps_a = sub.eps;
        last = Some(r);
    }
    let r = last?;
    state[..5].copy_from_slice(&cur);
    let ee_n: [f64; 3] = std::array::from_fn(|i| step.eps_n[i] - state_n[i]);
    let psi_n = 0.5 * dot3(&ee_n, &mul3(c, &ee_n));
    let de: [f64; 3] = std::array::from_fn(|i| step.eps[i] - step.eps_n[i]);
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
fn update_once(
    p: &RankineHillParams,
    c: &[[f64; 3]; 3],
    e: f64,
    nu: f64,
    step: &StrainStep,
    state_n: &[f64],
    state: &mut [f64],
) -> PointResponse {
    let ep_n = [state_n[0], state_n[1], state_n[2]];
    let (kt_n, kc_n) = (state_n[3], state_n[4]);
    let ee_tr = [
        step.eps[0] - ep_n[0],
        step.eps[1] - ep_n[1],
        step.eps[2] - ep_n[2],
    ];
    let s_tr = mul3(c, &ee_tr);
    let ee_n = [
        step.eps_n[0] - ep_n[0],
        step.eps_n[1] - ep_n[1],
        step.eps_n[2] - ep_n[2],
    ];
    let sigma_n = mul3(c, &ee_n);
    // The trial's principal values decide; the frame is needed only for a return.
    let (s1, s2) = principal_values(s_tr[0], s_tr[1], s_tr[2]);
    let cc = c[0][0];
    let ctx = Ctx {
        p,
        e,
        h: step.length,
        d: [[cc, cc * nu], [cc * nu, cc]],
        dinv: [[1.0 / e, -nu / e], [-nu / e, 1.0 / e]],
        kt_n,
        kc_n,
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
    let trial_ok = s1 - y_t <= 0.0 && q_and_n(&[s1, s2]).0 - y_c <= 0.0;
    if trial_ok {
        return elastic;
    }
    let theta = principal_stress(&s_tr).2;
    let Some(ret) = ctx.ret(&[s1, s2]) else {
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
    let dsp = [s1 - ret.sigma[0], s2 - ret.sigma[1]];
    let dep1 = (dsp[0] - nu * dsp[1]) / e;
    let dep2 = (dsp[1] - nu * dsp[0]) / e;
    let dep = strain_from_principal(dep1, dep2, theta);
    for i in 0..3 {
        state[i] = ep_n[i] + dep[i];
    }
    state[3] = kt_n + ret.dlambda[0] + ret.dlambda[1];
    state[4] = kc_n + ret.dlambda[2];
    let sigma = stress_from_principal(ret.sigma[0], ret.sigma[1], theta);
    // Tangent: principal-frame normal block plus the spectral shear term.
    let et = strain_to_frame(&ee_tr, theta);
    let gap = et[0] - et[1];
    let g_alg = if gap.abs() > 1e-12 * (et[0].abs() + et[1].abs()).max(1e-30) {
        (ret.sigma[0] - ret.sigma[1]) / (2.0 * gap)
    } else {
        0.5 * (ret.d_alg[0][0] - ret.d_alg[0][1])
    };
    let dp = [
        [ret.d_alg[0][0], ret.d_alg[0][1], 0.0],
        [ret.d_alg[1][0], ret.d_alg[1][1], 0.0],
        [0.0, 0.0, g_alg],
    ];
    let t = strain_transform(theta);
    let mut tangent = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            let mut v = 0.0;
            for k in 0..3 {
                for l in 0..3 {
                    v += t[k][i] * dp[k][l] * t[l][j];
                }
            }
            tangent[i][j] = v;
        }
    }
    let ee = [
        step.eps[0] - state[0],
        step.eps[1] - state[1],
        step.eps[2] - state[2],
    ];
    let psi = 0.5 * dot3(&ee, &sigma);
    let psi_n = 0.5 * dot3(&ee_n, &sigma_n);
    // The paper's trapezoid ½(σⁿ + σⁿ⁺¹):Δεᵖ with each stress paired with its own
    // flow direction: σ:∂f/∂σ is the surface strength on every surface, so per surface
    // ½(σ̄(κⁿ) + σ̄(κⁿ⁺¹)) Δλ. Equal to the literal form for steps that start on the
    // surface with fixed principal axes (and a radial path for von Mises), never
    // above it, and non-negative always (theory/plasticity.md).
    let (yt0, _) = p.prepared[0].strength(kt_n, e, step.length);
    let (yt1, _) = p.prepared[0].strength(state[3], e, step.length);
    let (yc0, _) = p.prepared[1].strength(kc_n, e, step.length);
    let (yc1, _) = p.prepared[1].strength(state[4], e, step.length);
    let plastic =
        0.5 * (yt0 + yt1) * (ret.dlambda[0] + ret.dlambda[1]) + 0.5 * (yc0 + yc1) * ret.dlambda[2];
    let de = [
        step.eps[0] - step.eps_n[0],
        step.eps[1] - step.eps_n[1],
        step.eps[2] - step.eps_n[2],
    ];
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

fn numerical_elastic(c: &[[f64; 3]; 3], eps: &[f64; 3], eps_n: &[f64; 3]) -> f64 {
    let de = [eps[0] - eps_n[0], eps[1] - eps_n[1], eps[2] - eps_n[2]];
    0.5 * dot3(&de, &mul3(c, &de))
}
