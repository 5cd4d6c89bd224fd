//! The explicit (central difference) critical step, for `rothe check` and the explicit
//! path: `Δt = ω min_e L_e / c_e` with the dilatational wave speed
//! `c = sqrt(E(1−ν) / (ρ(1+ν)(1−2ν)))` of the paper's formula (ω = 1 here), and
//! `c = sqrt(E/ρ)` for bars.

use crate::fe::{Kinematics, MAX_ELEMENT_DOFS};

/// The size of the largest element matrix.
const ELEMENT_MATRIX: usize = MAX_ELEMENT_DOFS * MAX_ELEMENT_DOFS;
use crate::mesh::ElementKind;
use crate::model::Model;

/// Critical step and the block/element that sets it.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct CriticalStep {
    /// `min L_e / c_e`.
    pub dt: f64,
    /// Block index of the limiting element.
    pub block: usize,
    /// Element index within the block.
    pub element: usize,
}

/// Critical explicit step of the model's mesh.
pub fn critical_step(model: &Model) -> Option<CriticalStep> {
    let mut best: Option<CriticalStep> = None;
    for (bi, b) in model.mesh.blocks.iter().enumerate() {
        let m = &model.materials[b.material];
        let c = match b.elements.kind {
            ElementKind::Bar2 => (m.e / m.rho).sqrt(),
            _ => (m.e * (1.0 - m.nu) / (m.rho * (1.0 + m.nu) * (1.0 - 2.0 * m.nu))).sqrt(),
        };
        for e in 0..b.elements.len() {
            let dt = model.mesh.element_length(bi, e) / c;
            if best.is_none_or(|s| dt < s.dt) {
                best = Some(CriticalStep {
                    dt,
                    block: bi,
                    element: e,
                });
            }
        }
    }
    best
}

/// The largest stable step of a mode of frequency `omega` whose damping rate
/// `c = 2ξω` the scheme takes at the half-step velocity:
/// `(2/ω)(√(1+ξ²) − ξ) = 2/(√(ω² + c²/4) + c/2)` (`2/ω` undamped), decreasing in both.
pub fn damped_limit(omega: f64, c: f64) -> f64 {
    2.0 / ((omega * omega + 0.25 * c * c).sqrt() + 0.5 * c)
}

/// The stable step of central differences with lumped mass, `2/ω_max`, bounded
/// element by element: the largest eigenvalue of `M⁻¹K` is at most the largest of
/// the elements' own `M_e⁻¹K_e` (lumped `M_e`), so `min_e 2/ω_e` is a step no mode of
/// the undamped linear mesh exceeds, and on a uniform mesh the mesh's highest mode
/// reaches it (`theory/explicit.md`). `K` is the instantaneous stiffness (the SLS's
/// Maxwell branch included). The damping the scheme takes at the half-step velocity
/// shortens the step: a mode of frequency `ω` whose damping rate is `c` is stable
/// for `h ≤` [`damped_limit`]`(ω, c)`, and `c` is bounded by `c_e`, the largest
/// eigenvalue of the element's `M_e⁻¹C_e` (Kelvin-Voigt dashpots, Rayleigh
/// `a_k K`): with benchmark 1's identity viscosity `β = 10⁶ Pa·s` on 0.1 m elements
/// `ξ_e ≈ 1.005` and the step falls to 0.41 of the undamped one. Mass damping
/// (`zeta`, Rayleigh `a_m`) does not enter: the scheme takes it at the new velocity
/// `v_{n+1}` (a diagonal, solved exactly), which leaves the limit at `2/ω` whatever
/// its size. Elements of one shape (the same relative coordinates, material and
/// section) are computed once.
pub fn stable_step(model: &Model) -> Option<CriticalStep> {
    use std::collections::HashMap;
    let mesh = &model.mesh;
    let mut best: Option<CriticalStep> = None;
    let mut seen: HashMap<(usize, Vec<i64>), f64> = HashMap::new();
    for (bi, b) in mesh.blocks.iter().enumerate() {
        let m = &model.materials[b.material];
        let a_k = model.analysis.damping.rayleigh[1];
        for e in 0..b.elements.len() {
            let nodes = b.elements.element(e);
            let x: Vec<[f64; 3]> = nodes.iter().map(|&n| mesh.coords[n]).collect();
            // Shape key: coordinates relative to the first node, to 1e-12 of the size.
            let size = mesh.element_length(bi, e).max(f64::MIN_POSITIVE);
            let key: Vec<i64> = x
                .iter()
                .flat_map(|p| [p[0] - x[0][0], p[1] - x[0][1], p[2] - x[0][2]])
                .map(|c| (c / size * 1e12).round() as i64)
                .collect();
            let dt = *seen.entry((bi, key)).or_insert_with(|| {
                let el = ElementStep {
                    kind: b.elements.kind,
                    x: &x,
                    material: m,
                    section: b.section,
                    a_k,
                };
                crate::dispatch_kinematics!(model.idealisation, <D, V, K> => el.limit::<D, V, K>(
                    &m.instantaneous_stiffness::<V, K>(),
                    m.viscosity::<V, K>(),
                ))
            });
            if dt.is_finite() && best.is_none_or(|s| dt < s.dt) {
                {
                    best = Some(CriticalStep {
                        dt,
                        block: bi,
                        element: e,
                    });
                }
            }
        }
    }
    best
}

/// One element's share of the stable step: its geometry, material and section.
struct ElementStep<'a> {
    kind: ElementKind,
    x: &'a [[f64; 3]],
    material: &'a crate::material::Material,
    section: f64,
    /// Rayleigh's stiffness coefficient.
    a_k: f64,
}

impl ElementStep<'_> {
    /// The damped limit `2/ω` of the element with instantaneous stiffness `d` and
    /// viscosity `eta` in the idealisation `K`, lumped mass.
    fn limit<const D: usize, const V: usize, K: Kinematics<D, V>>(
        &self,
        d: &[[f64; V]; V],
        eta: Option<[[f64; V]; V]>,
    ) -> f64 {
        let (m, x, dim) = (self.material, self.x, D);
        let nd = dim * x.len();
        let mut ke = [0.0; ELEMENT_MATRIX];
        let mut me = [0.0; ELEMENT_MATRIX];
        match self.kind {
            ElementKind::Bar2 => {
                crate::fe::element::bar_stiffness(x, dim, m.e * self.section, &mut ke);
                crate::fe::element::bar_mass(x, dim, m.rho * self.section, &mut me);
            }
            kind => {
                crate::fe::element::continuum_stiffness::<D, V, K>(
                    kind,
                    x,
                    d,
                    self.section,
                    &mut ke,
                );
                crate::fe::element::continuum_mass(kind, x, m.rho * self.section, &mut me);
            }
        }
        // Lumped: row sums. Symmetric form D^{-1/2} K D^{-1/2}.
        let mut s = [0.0; MAX_ELEMENT_DOFS];
        for i in 0..nd {
            let row: f64 = (0..nd).map(|j| me[i * nd + j]).sum();
            s[i] = if row > 0.0 { 1.0 / row.sqrt() } else { 0.0 };
        }
        let scaled = |k: &[f64; ELEMENT_MATRIX]| {
            let mut a = [0.0; ELEMENT_MATRIX];
            for i in 0..nd {
                for j in 0..nd {
                    a[i * nd + j] = s[i] * k[i * nd + j] * s[j];
                }
            }
            largest_eigenvalue(&mut a, nd)
        };
        let omega2 = scaled(&ke);
        if omega2 <= 0.0 {
            return f64::INFINITY;
        }
        let omega = omega2.sqrt();
        // The largest damping rate 2ξω the half-step velocity carries.
        let mut c_max = self.a_k * omega2;
        if let (Some(eta), true) = (eta, self.kind != ElementKind::Bar2) {
            let mut ce = [0.0; ELEMENT_MATRIX];
            crate::fe::element::continuum_stiffness::<D, V, K>(
                self.kind,
                x,
                &eta,
                self.section,
                &mut ce,
            );
            c_max += scaled(&ce);
        }
        damped_limit(omega, c_max)
    }
}

/// The stable step `2/ω_max` of the mesh itself (not element by element): `ω_max²`
/// the largest eigenvalue of `M⁻¹K` on the free dofs (lumped `M`, elastic `K`), by
/// `iterations` power iterations on `M^{-1/2} K M^{-1/2}` from a fixed start with
/// every mode in it. The Rayleigh quotients rise to `ω_max²` from below, so the
/// step returned is never below the true one; with enough iterations it is the
/// limit a run at a larger step exceeds. For studies and tests of the estimates.
pub fn mesh_stable_step(model: &Model, iterations: usize) -> f64 {
    let asm = crate::assembly::Assembler::new(&model.mesh);
    let k = asm.stiffness(&model.mesh, &model.materials, model.idealisation);
    let m = asm
        .mass(&model.mesh, &model.materials, true)
        .row_sums(&asm.pattern);
    let n = m.len();
    let mut s: Vec<f64> = m
        .iter()
        .map(|&x| if x > 0.0 { 1.0 / x.sqrt() } else { 0.0 })
        .collect();
    for c in &model.constraints {
        s[c.dof] = 0.0;
    }
    // A start with every mode: a fixed pseudo-random vector z; B = S K S.
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut z: Vec<f64> = (0..n)
        .map(|d| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            if s[d] > 0.0 {
                (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            } else {
                0.0
            }
        })
        .collect();
    let (mut x, mut t) = (vec![0.0; n], vec![0.0; n]);
    let mut lambda: f64 = 0.0;
    for _ in 0..iterations {
        let norm = z.iter().map(|v| v * v).sum::<f64>().sqrt();
        if norm.is_nan() || norm <= 0.0 {
            break;
        }
        for d in 0..n {
            z[d] /= norm;
            x[d] = s[d] * z[d];
        }
        asm.pattern.matvec(&k, &x, &mut t);
        let mut rq = 0.0;
        for d in 0..n {
            let y = s[d] * t[d];
            rq += z[d] * y;
            z[d] = y;
        }
        lambda = rq;
    }
    2.0 / lambda.sqrt()
}

/// The largest eigenvalue of the symmetric `n x n` (row-major, `n ≤ 8`) matrix `a`,
/// by cyclic Jacobi rotations (`a` is overwritten).
fn largest_eigenvalue(a: &mut [f64; ELEMENT_MATRIX], n: usize) -> f64 {
    for _ in 0..50 {
        let off: f64 = (0..n)
            .flat_map(|i| (0..n).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| a[i * n + j] * a[i * n + j])
            .sum();
        let diag: f64 = (0..n).map(|i| a[i * n + i] * a[i * n + i]).sum();
        if off <= 1e-30 * diag {
            break;
        }
        for p in 0..n {
            for q in p + 1..n {
                let apq = a[p * n + q];
                if apq == 0.0 {
                    continue;
                }
                let theta = (a[q * n + q] - a[p * n + p]) / (2.0 * apq);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for k in 0..n {
                    let akp = a[k * n + p];
                    let akq = a[k * n + q];
                    a[k * n + p] = c * akp - s * akq;
                    a[k * n + q] = s * akp + c * akq;
                }
                for k in 0..n {
                    let apk = a[p * n + k];
                    let aqk = a[q * n + k];
                    a[p * n + k] = c * apk - s * aqk;
                    a[q * n + k] = s * apk + c * aqk;
                }
            }
        }
    }
    (0..n)
        .map(|i| a[i * n + i])
        .fold(f64::NEG_INFINITY, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jacobi_finds_the_largest_eigenvalue() {
        // [[2, 1, 0], [1, 2, 1], [0, 1, 2]]: eigenvalues 2 − √2, 2, 2 + √2.
        let mut a = [0.0; ELEMENT_MATRIX];
        let m = [[2.0, 1.0, 0.0], [1.0, 2.0, 1.0], [0.0, 1.0, 2.0]];
        for i in 0..3 {
            for j in 0..3 {
                a[i * 3 + j] = m[i][j];
            }
        }
        let l = largest_eigenvalue(&mut a, 3);
        assert!((l - (2.0 + 2f64.sqrt())).abs() < 1e-13, "{l}");
    }
}
