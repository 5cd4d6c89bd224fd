//! Linear viscoelasticity: Kelvin-Voigt and the standard linear solid of eq. (10),
//! with the Maxwell and Kelvin limits. All updates are backward Euler, exact in the
//! energy split `σ_{n+1}:Δε = Δψ + ΔD_viscous + ΔD_num` (see `theory/viscoelasticity.md`).

use super::{dot3, mul3, Dissipation, PointResponse, PointStatus, StrainStep};

/// Voigt matrix of the identity viscosity `η = β I` acting on engineering strain
/// rates: `σ = β ε̇` componentwise, so `σ_xy = β γ̇_xy / 2`.
pub fn identity_viscosity(beta: f64) -> [[f64; 3]; 3] {
    [[beta, 0.0, 0.0], [0.0, beta, 0.0], [0.0, 0.0, 0.5 * beta]]
}

fn sub(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn add_scaled(m: &[[f64; 3]; 3], a: f64, n: &[[f64; 3]; 3], b: f64) -> [[f64; 3]; 3] {
    let mut out = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            out[i][j] = a * m[i][j] + b * n[i][j];
        }
    }
    out
}

/// Kelvin-Voigt `σ = C ε + η ε̇`, `ε̇ ≈ (ε − ε_n)/h`. History-free (the committed
/// strain is the store's). Tangent `C + η/h`; `ΔD_viscous = Δε:η:Δε/h`;
/// `ΔD_num = ½ Δε:C:Δε`.
pub fn kelvin_voigt(c: &[[f64; 3]; 3], eta: &[[f64; 3]; 3], step: &StrainStep) -> PointResponse {
    let de = sub(&step.eps, &step.eps_n);
    let ce = mul3(c, &step.eps);
    let eta_de = mul3(eta, &de);
    let h = step.dt;
    let sigma = [
        ce[0] + eta_de[0] / h,
        ce[1] + eta_de[1] / h,
        ce[2] + eta_de[2] / h,
    ];
    PointResponse {
        sigma,
        tangent: add_scaled(c, 1.0, eta, 1.0 / h),
        psi: 0.5 * dot3(&step.eps, &ce),
        dissipation: Dissipation {
            viscous: dot3(&de, &eta_de) / h,
            numerical: 0.5 * dot3(&de, &mul3(c, &de)),
            ..Default::default()
        },
        status: PointStatus::Ok,
    }
}

/// Standard linear solid: `σ = p C ε + τ` with a Maxwell branch of spring `α C` and
/// dashpot `β C` (`β` in seconds), `p = 1` (SLS) or `p = 0` (Maxwell). State: the
/// dashpot strain `ε_d`; backward Euler `ε_d¹ = (ε_d⁰ + k ε)/(1 + k)`, `k = h α/β`,
/// so `τ = α C (ε − ε_d⁰)/(1 + k)`, the paper's eq. (10) second line.
pub fn standard_linear_solid(
    c: &[[f64; 3]; 3],
    parallel: f64,
    alpha: f64,
    beta: f64,
    step: &StrainStep,
    eps_d_n: &[f64],
    eps_d: &mut [f64],
) -> PointResponse {
    let h = step.dt;
    let k = h * alpha / beta;
    let inv = 1.0 / (1.0 + k);
    let ed_n = [eps_d_n[0], eps_d_n[1], eps_d_n[2]];
    let ed = [
        (ed_n[0] + k * step.eps[0]) * inv,
        (ed_n[1] + k * step.eps[1]) * inv,
        (ed_n[2] + k * step.eps[2]) * inv,
    ];
    eps_d[..3].copy_from_slice(&ed);
    // Four products with C; every other one follows by linearity.
    let ce = mul_iso(c, &step.eps);
    let ce_n = mul_iso(c, &step.eps_n);
    let ced = mul_iso(c, &ed);
    let ced_n = mul_iso(c, &ed_n);
    let ee = sub(&step.eps, &ed); // branch elastic strain
    let c_ee = sub(&ce, &ced);
    let de = sub(&step.eps, &step.eps_n);
    let c_de = sub(&ce, &ce_n);
    let ded = sub(&ed, &ed_n);
    let c_ded = sub(&ced, &ced_n);
    let dee = sub(&de, &ded);
    let c_dee = sub(&c_de, &c_ded);
    let sigma = [
        parallel * ce[0] + alpha * c_ee[0],
        parallel * ce[1] + alpha * c_ee[1],
        parallel * ce[2] + alpha * c_ee[2],
    ];
    PointResponse {
        sigma,
        tangent: add_scaled(c, parallel, c, alpha * inv),
        psi: 0.5 * parallel * dot3(&step.eps, &ce) + 0.5 * alpha * dot3(&ee, &c_ee),
        dissipation: Dissipation {
            viscous: beta * dot3(&ded, &c_ded) / h,
            numerical: 0.5 * parallel * dot3(&de, &c_de) + 0.5 * alpha * dot3(&dee, &c_dee),
            ..Default::default()
        },
        status: PointStatus::Ok,
    }
}

/// `C x` for an isotropic plane elasticity matrix (no normal-shear coupling).
#[inline]
fn mul_iso(c: &[[f64; 3]; 3], x: &[f64; 3]) -> [f64; 3] {
    [
        c[0][0] * x[0] + c[0][1] * x[1],
        c[1][0] * x[0] + c[1][1] * x[1],
        c[2][2] * x[2],
    ]
}
