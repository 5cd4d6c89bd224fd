//! Mazars damage and Rankine-Hill plasticity: material-point curves against closed
//! forms, unloading, corner returns with KKT, consistent tangent against finite
//! differences, properties over random paths, and global runs (localisation past
//! peak, ledger closure to the iteration tolerance, step cuts, failure reports).
#![allow(clippy::needless_range_loop, clippy::too_many_arguments)]

use crate::common;

use proptest::prelude::*;
use rothe::config::MaterialSpec;
use rothe::fe::Idealisation;
use rothe::material::{Law as MaterialLaw, Material, StrainStep};
use rothe::model::TimeFunction;
use rothe::point_driver::{run_path, Control, PathKind, PathSpec};

const E: f64 = 33e9;
const NU: f64 = 0.2;
const MAZARS: &str = "eps_t0 = 1.0e-4\nA_t = 1.0\nB_t = 1.0e4\nA_c = 1.2\nB_c = 1.5e3";
const RH_BILINEAR: &str = "tension = { law = \"bilinear\", strength = 2.9e6, post_yield_modulus = 1.65e9 }\ncompression = { law = \"bilinear\", strength = 30.0e6, post_yield_modulus = 1.65e9 }";

/// Eq. (13) written out: `D(κ) = 1 − (1−A) κ₀/κ − A exp(−B(κ − κ₀))` above the
/// threshold `κ₀`, zero below.
fn eq13(kappa: f64, kappa0: f64, a: f64, b: f64) -> f64 {
    if kappa <= kappa0 {
        0.0
    } else {
        1.0 - (1.0 - a) * kappa0 / kappa - a * (-b * (kappa - kappa0)).exp()
    }
}

/// The strength laws of the Rankine-Hill tests, written out from their diagrams.
#[derive(Clone, Copy)]
enum Law {
    /// `σ̄ = f_y + H κ`, `H = E E_t / (E − E_t)` (the uniaxial diagram has slope
    /// `E_t` after yield: `dσ = E_t dε = E (dε − dκ)`).
    Bilinear { fy: f64, et: f64 },
    /// `σ̄ = f_t (1 − κ/κ_u)` down to zero, `κ_u = 2 G_f / (f_t h)`.
    Softening { ft: f64, gf: f64 },
    /// Eurocode 2: `σ(ε) = f_cm (kη − η²)/(1 + (k−2)η)`, `η = ε/ε_c1`,
    /// `k = 1.05 E ε_c1/f_cm`, elastic up to where the secant `σ/ε` meets `E`,
    /// `κ = ε − σ(ε)/E`, constant past `ε_cu1`.
    Ec2 { fcm: f64, ec1: f64, ecu1: f64 },
}

/// `σ̄(κ)` for element size `h`.
fn strength(law: Law, kappa: f64, h: f64) -> f64 {
    match law {
        Law::Bilinear { fy, et } => (fy + E * et / (E - et) * kappa).max(0.0),
        Law::Softening { ft, gf } => (ft * (1.0 - kappa * ft * h / (2.0 * gf))).max(0.0),
        Law::Ec2 { fcm, ec1, ecu1 } => {
            let k = 1.05 * E * ec1 / fcm;
            let sigma = |eps: f64| {
                let eta = eps / ec1;
                fcm * (k * eta - eta * eta) / (1.0 + (k - 2.0) * eta)
            };
            // Secant meets E: (k − η) = (k/1.05)(1 + (k−2)η).
            let eta_y = (k - k / 1.05) / (1.0 + k / 1.05 * (k - 2.0));
            let kap = |eps: f64| eps - sigma(eps) / E;
            if kappa >= kap(ecu1) {
                return sigma(ecu1);
            }
            // Bisection on ε ∈ [ε_y, ε_cu1], where κ(ε) increases.
            let (mut lo, mut hi) = (eta_y * ec1, ecu1);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if kap(mid) < kappa {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            sigma(0.5 * (lo + hi))
        }
    }
}

/// The Rankine and von Mises yield functions at a plane stress: `σ₁ − σ̄_t(κ_t)` and
/// `√(σ₁² − σ₁σ₂ + σ₂²) − σ̄_c(κ_c)`, principal stresses from Mohr's circle.
fn yield_functions(
    tension: Law,
    compression: Law,
    sigma: &[f64; 3],
    kt: f64,
    kc: f64,
) -> (f64, f64) {
    let c = 0.5 * (sigma[0] + sigma[1]);
    let r = (0.25 * (sigma[0] - sigma[1]).powi(2) + sigma[2] * sigma[2]).sqrt();
    let (s1, s2) = (c + r, c - r);
    (
        s1 - strength(tension, kt, 0.1),
        (s1 * s1 - s1 * s2 + s2 * s2).sqrt() - strength(compression, kc, 0.1),
    )
}

const BILINEAR_T: Law = Law::Bilinear {
    fy: 2.9e6,
    et: 1.65e9,
};
const BILINEAR_C: Law = Law::Bilinear {
    fy: 30e6,
    et: 1.65e9,
};
const SOFTENING_T: Law = Law::Softening {
    ft: 2.9e6,
    gf: 140.0,
};
const EC2_C: Law = Law::Ec2 {
    fcm: 38e6,
    ec1: 0.0022,
    ecu1: 0.0035,
};

fn mat(text: &str) -> Material {
    let spec: MaterialSpec =
        toml::from_str(&format!("{text}\nE = {E}\nnu = {NU}\nrho = 2400.0")).unwrap();
    rothe::config::material("m", "material", &spec).unwrap()
}

/// Strain-controlled uniaxial-stress path through the table `points` (t, ε_xx).
fn uniaxial(
    m: &Material,
    points: Vec<[f64; 2]>,
    n: usize,
) -> Vec<rothe::point_driver::PointRecord> {
    let t_end = points.last().unwrap()[0];
    let p = PathSpec {
        kind: PathKind::UniaxialStress,
        plane: Idealisation::PlaneStress,
        control: Control::Strain,
        amplitude: 1.0,
        function: TimeFunction::Table { points },
        ratio: 1.0,
        t_end,
        dt: t_end / n as f64,
        times: vec![],
        strains: vec![],
        length: 0.1,
    };
    run_path(m, &p).unwrap()
}

#[test]
fn mazars_paper_uniaxial_curves_match_closed_form() {
    // Reference: eqs. (11)-(13) in uniaxial stress: principal strains (ε, −νε, −νε)
    // give ε_t = ε in tension (r = 1) and ε_c = |ε| in compression (r = 0), so
    // σ = (1 − D(ε*)) E ε with D = 1 − (1−A)ε0/ε* − A e^{−B(ε*−ε0)} and the tension or
    // compression A, B. Checked along the whole curve (peak and post-peak), and the
    // peak in tension is E ε0 for A_t = 1.
    let m = mat(&format!("model = \"mazars\"\n{MAZARS}"));
    let recs = uniaxial(&m, vec![[0.0, 0.0], [1.0, 1e-3]], 1000);
    let mut peak: f64 = 0.0;
    for r in &recs[1..] {
        let e = r.eps[0];
        let want = (1.0 - eq13(e, 1e-4, 1.0, 1e4).min(0.99999)) * E * e;
        assert!(
            (r.response.sigma[0] - want).abs() <= 1e-9 * E * 1e-4,
            "tension at ε = {e}"
        );
        peak = peak.max(r.response.sigma[0]);
    }
    assert!((peak - E * 1e-4).abs() < 1e-6 * peak);
    let recs = uniaxial(&m, vec![[0.0, 0.0], [1.0, -5e-3]], 1000);
    for r in &recs[1..] {
        let e = r.eps[0];
        // With A_c > 1 the law dips below zero just past the threshold: D ≥ 0 holds.
        let want = (1.0 - eq13(-e, 1e-4, 1.2, 1.5e3).clamp(0.0, 0.99999)) * E * e;
        assert!(
            (r.response.sigma[0] - want).abs() <= 1e-9 * E * 1e-4,
            "compression at ε = {e}"
        );
    }
}

#[test]
fn mazars_classic_uniaxial_curves_match_closed_form() {
    // Reference: Mazars (1984): in tension ε̃ = ε, α_t = 1, σ = (1 − D_t(ε)) E ε; in
    // compression the positive strains are the lateral ones, ε̃ = √2 ν |ε| (NOTES.md),
    // α_c = 1, σ = (1 − D_c(√2 ν|ε|)) E ε.
    let m = mat(&format!(
        "model = \"mazars\"\nvariant = \"classic\"\n{MAZARS}"
    ));
    for r in &uniaxial(&m, vec![[0.0, 0.0], [1.0, 1e-3]], 500)[1..] {
        let e = r.eps[0];
        let want = (1.0 - eq13(e, 1e-4, 1.0, 1e4).min(0.99999)) * E * e;
        assert!(
            (r.response.sigma[0] - want).abs() <= 1e-9 * E * 1e-4,
            "tension at ε = {e}"
        );
    }
    for r in &uniaxial(&m, vec![[0.0, 0.0], [1.0, -8e-3]], 500)[1..] {
        let e = r.eps[0];
        let k = 2f64.sqrt() * NU * e.abs();
        let want = (1.0 - eq13(k, 1e-4, 1.2, 1.5e3).clamp(0.0, 0.99999)) * E * e;
        assert!(
            (r.response.sigma[0] - want).abs() <= 1e-9 * E * 1e-4,
            "compression at ε = {e}"
        );
    }
}

#[test]
fn mazars_unloads_to_the_origin_and_damage_only_grows() {
    for variant in ["paper", "classic"] {
        let m = mat(&format!(
            "model = \"mazars\"\nvariant = \"{variant}\"\n{MAZARS}"
        ));
        let recs = uniaxial(
            &m,
            vec![
                [0.0, 0.0],
                [1.0, 4e-4],
                [2.0, 1e-4],
                [3.0, 6e-4],
                [4.0, 0.0],
            ],
            800,
        );
        let mut d_prev = 0.0;
        for w in recs.windows(2) {
            let (a, b) = (&w[0], &w[1]);
            let d = b.state[2];
            assert!(d >= d_prev && d < 1.0, "{variant}: damage {d_prev} -> {d}");
            d_prev = d;
            if b.eps[0] < a.eps[0] && b.eps[0] > 0.0 {
                // Unloading: secant, σ/ε = (1 − D) E with D frozen.
                let secant = b.response.sigma[0] / b.eps[0];
                assert!(
                    (secant - (1.0 - d) * E).abs() < 1e-9 * E,
                    "{variant}: secant unloading"
                );
                assert_eq!(b.state[2], a.state[2]);
            }
        }
        let last = recs.last().unwrap();
        assert!(
            last.response.sigma[0].abs() < 1e-9 * E * 1e-4,
            "back to the origin"
        );
        assert!(last.dissipated[1] > 0.0);
    }
}

#[test]
fn rankine_hill_uniaxial_yield_hardening_and_elastic_unloading() {
    // Bilinear diagram (NOTES.md benchmark 1): yield at f_ct = 2.9 MPa in tension and
    // f_c = 30 MPa in compression, slope E_t = 0.05 E after yield, elastic slope E on
    // unloading.
    let m = mat(&format!("model = \"rankine_hill\"\n{RH_BILINEAR}"));
    let et = 1.65e9;
    for (fy, sign) in [(2.9e6, 1.0), (30e6, -1.0)] {
        let ey = fy / E;
        // Unload by half the yield strain: elastic in both cases.
        let recs = uniaxial(
            &m,
            vec![[0.0, 0.0], [1.0, sign * 5.0 * ey], [1.5, sign * 4.5 * ey]],
            1500,
        );
        for w in recs.windows(2) {
            let (a, b) = (&w[0], &w[1]);
            let e = b.eps[0].abs();
            let s = b.response.sigma[0] * sign;
            if b.t <= 1.0 {
                let want = if e <= ey { E * e } else { fy + et * (e - ey) };
                assert!(
                    (s - want).abs() < 1e-6 * fy,
                    "loading at ε = {e}: {s} vs {want}"
                );
            } else {
                let slope = (b.response.sigma[0] - a.response.sigma[0]) / (b.eps[0] - a.eps[0]);
                assert!((slope - E).abs() < 1e-6 * E, "unloading slope {slope}");
            }
        }
        // At the end of loading the plastic work is ∫σ̄ dκ = f_y κ + ½ H κ² exactly
        // (the trapezoid is exact for a linear hardening law).
        let top = recs.iter().find(|r| (r.t - 1.0).abs() < 1e-12).unwrap();
        let h = E * et / (E - et);
        let kappa = if sign > 0.0 {
            top.state[3]
        } else {
            top.state[4]
        };
        let want = fy * kappa + 0.5 * h * kappa * kappa;
        assert!(
            (top.dissipated[2] - want).abs() < 1e-9 * want,
            "plastic work {} vs {want}",
            top.dissipated[2]
        );
        assert!(recs.last().unwrap().dissipated[2] > 0.0);
    }
}

fn rh_point(
    m: &Material,
    eps_n: [f64; 3],
    eps: [f64; 3],
    state_n: &[f64],
) -> (rothe::material::PointResponse<3>, Vec<f64>) {
    common::point_update::<3, rothe::fe::PlaneStress>(m, eps_n, eps, state_n)
}

#[test]
fn rankine_hill_corner_return_satisfies_kkt() {
    // A trial state beyond the Rankine/von Mises corner (tension in x, strong
    // compression in y): both criteria end active, f_t = f_c = 0, Δλ_t, Δλ_c ≥ 0, and
    // the plastic strain increment lies in the normal cone, coaxial with the stress:
    // Δεᵖ = Δλ_t (1, 0) + Δλ_c ∂q/∂σ in the principal frame.
    let m = mat(&format!("model = \"rankine_hill\"\n{RH_BILINEAR}"));
    for (ex, ey, g) in [
        (1.5e-3, -1.6e-3, 0.0),
        (1.2e-3, -1.4e-3, 3e-4),
        (2e-3, -2e-3, -5e-4),
    ] {
        let (r, st) = rh_point(&m, [0.0; 3], [ex, ey, g], &[0.0; 5]);
        let (ft, fc) = yield_functions(BILINEAR_T, BILINEAR_C, &r.sigma, st[3], st[4]);
        let tol = 1e-6 * 30e6;
        assert!(
            ft.abs() < tol && fc.abs() < tol,
            "corner: f_t = {ft}, f_c = {fc}"
        );
        assert!(
            st[3] > 0.0 && st[4] > 0.0,
            "both multipliers positive: {:?}",
            &st[3..]
        );
        let (s1, s2, th) = rothe::fe::principal::principal_stress(&r.sigma);
        let dep = rothe::fe::principal::strain_to_frame(&[st[0], st[1], st[2]], th);
        assert!(
            dep[2].abs() < 1e-9 * (dep[0].abs() + dep[1].abs()),
            "coaxial"
        );
        let q = (s1 * s1 - s1 * s2 + s2 * s2).sqrt();
        let n = [(2.0 * s1 - s2) / (2.0 * q), (2.0 * s2 - s1) / (2.0 * q)];
        // dep = λt (1,0) + λc n  →  λc = dep[1]/n[1], λt = dep[0] − λc n[0].
        let lc = dep[1] / n[1];
        let lt = dep[0] - lc * n[0];
        assert!(
            (lc - st[4]).abs() < 1e-6 * st[4] && (lt - st[3]).abs() < 1e-6 * st[3],
            "normal cone: {lt} {lc} vs {:?}",
            &st[3..]
        );
        assert!(r.dissipation.plastic > 0.0);
    }
}

#[test]
fn rankine_hill_consistent_tangent_matches_finite_differences() {
    // Elastic, Rankine only, von Mises only, and corner states, from virgin and from
    // hardened histories; central differences with δε = 1e-9.
    let m = mat(&format!("model = \"rankine_hill\"\n{RH_BILINEAR}"));
    let soft = mat("model = \"rankine_hill\"\ntension = { law = \"linear_softening\", strength = 2.9e6, fracture_energy = 140.0 }\ncompression = { law = \"ec2\", f_cm = 38e6, eps_c1 = 0.0022, eps_cu1 = 0.0035 }");
    let hardened = [1e-5, -2e-5, 1e-5, 2e-5, 1e-4];
    for mm in [&m, &soft] {
        for (eps, st) in [
            ([3e-5, 1e-5, 0.0], [0.0; 5]),
            ([3e-4, 5e-5, 1e-4], [0.0; 5]),
            ([2e-4, 2e-4, 3e-5], [0.0; 5]),
            ([-2e-3, -4e-4, 6e-4], [0.0; 5]),
            ([6e-4, -1.6e-3, 2e-4], [0.0; 5]),
            ([4e-4, -1e-4, 2e-4], hardened),
            ([-2.5e-3, -1e-3, -5e-4], hardened),
        ] {
            common::assert_point_tangent::<3, rothe::fe::PlaneStress>(
                mm,
                [0.0; 3],
                eps,
                &st,
                1e-4 * E,
            );
        }
    }
}

proptest! {
    #![proptest_config(common::seeded(64, 0x5eed_0001))]

    #[test]
    fn random_paths_keep_the_invariants(path in common::strain_paths::<3>(60), variant in 0usize..4) {
        // Damage never decreases and stays below 1; dissipation per step is
        // non-negative; after every return the stress is admissible.
        let text = match variant {
            0 => format!("model = \"mazars\"\n{MAZARS}"),
            1 => format!("model = \"mazars\"\nvariant = \"classic\"\n{MAZARS}"),
            2 => format!("model = \"rankine_hill\"\n{RH_BILINEAR}"),
            _ => "model = \"rankine_hill\"\ntension = { law = \"linear_softening\", strength = 2.9e6, fracture_energy = 140.0 }\ncompression = { law = \"ec2\", f_cm = 38e6, eps_c1 = 0.0022, eps_cu1 = 0.0035 }".to_string(),
        };
        let m = mat(&text);
        let ns = m.n_state(3);
        let (mut st_n, mut st) = (vec![0.0; ns], vec![0.0; ns]);
        let mut eps_n = [0.0; 3];
        for eps in &path {
            let r = m.update::<3, rothe::fe::PlaneStress>(&StrainStep { eps_n, eps: *eps, dt: 1e-4, length: 0.1, tangent: true }, &st_n, &mut st);
            let d = r.dissipation;
            prop_assert!(d.damage >= 0.0 && d.plastic >= 0.0, "dissipation {:?}", d);
            match m.law {
                MaterialLaw::Mazars(_) => prop_assert!(st[2] >= st_n[2] && st[2] < 1.0),
                MaterialLaw::RankineHill(_) => {
                    let (t, c) = if variant == 2 { (BILINEAR_T, BILINEAR_C) } else { (SOFTENING_T, EC2_C) };
                    let (ft, fc) = yield_functions(t, c, &r.sigma, st[3], st[4]);
                    prop_assert!(ft <= 1e-6 * 2.9e6 && fc <= 1e-6 * 30e6, "f_t = {}, f_c = {}", ft, fc);
                    prop_assert!(st[3] >= st_n[3] && st[4] >= st_n[4]);
                }
                _ => unreachable!(),
            }
            eps_n = *eps;
            st_n.clone_from(&st);
        }
    }
}

/// `∫ ½E s² dD` along a monotone uniaxial path where `D = g(s; κ0, A, B)` of eq. (13):
/// `½E [(1−A) κ0 s + A B P(s)]` with `P(s) = −e^{−B(s−κ0)}(s²/B + 2s/B² + 2/B³)`, the
/// antiderivative of `s² e^{−B(s−κ0)}` (since `dD/ds = (1−A)κ0/s² + AB e^{−B(s−κ0)}`).
fn y_dd_antiderivative(s: f64, kappa0: f64, a: f64, b: f64) -> f64 {
    let p = -(-b * (s - kappa0)).exp() * (s * s / b + 2.0 * s / (b * b) + 2.0 / (b * b * b));
    0.5 * E * ((1.0 - a) * kappa0 * s + a * b * p)
}

/// Where the law of eq. (13) first becomes positive above `κ0` (for `A > 1` it dips
/// below zero first), by bisection on the closed form `eq13`.
fn first_damage(kappa0: f64, a: f64, b: f64) -> f64 {
    if eq13(kappa0 * (1.0 + 1e-12), kappa0, a, b) > 0.0 {
        return kappa0;
    }
    let (mut lo, mut hi) = (kappa0 * (1.0 + 1e-12), 100.0 * kappa0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if eq13(mid, kappa0, a, b) > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    0.5 * (lo + hi)
}

#[test]
fn mazars_damage_dissipation_is_the_integral_of_y_dd() {
    // A monotone uniaxial path in n steps: the ledger's damage line, the trapezoid
    // ½(Y⁰ + Y¹)ΔD of each step, against the exact ∫ Y dD, Y = ½Eε², along the law
    // (closed form above), for the identified concrete (NOTES.md) in tension (both
    // variants: D = g(ε; ε_t0, A_t, B_t)), and in compression (paper: g(|ε|; ε_c0, A_c,
    // B_c) from where it turns positive; classic: D_c(ν√2|ε|), so Y = ½E κ²/(2ν²) in
    // its own equivalent strain κ). The error falls at second order in the step: a
    // left-point rule (Y⁰ΔD) would fall at first order.
    let data = "identify = { f_ct = 2.9e6, f_cm = 38.0e6, eps_c1 = 2.2e-3 }";
    let (et0, ec0) = (2.9e6 / E, 2.9e6 / E / (NU * 2f64.sqrt()));
    let paper = mat(&format!("model = \"mazars\"\n{data}"));
    let classic = mat(&format!(
        "model = \"mazars\"\nvariant = \"classic\"\n{data}"
    ));
    let (MaterialLaw::Mazars(pp), MaterialLaw::Mazars(pc)) = (&paper.law, &classic.law) else {
        panic!()
    };
    let (a_t, b_t, a_c, b_c, b_c_classic) = (pp.a_t, pp.b_t, pp.a_c, pp.b_c, pc.b_c);
    let exact_tension =
        |e: f64| y_dd_antiderivative(e, et0, a_t, b_t) - y_dd_antiderivative(et0, et0, a_t, b_t);
    let k1 = first_damage(ec0, a_c, b_c);
    let exact_paper_compression =
        |e: f64| y_dd_antiderivative(e, ec0, a_c, b_c) - y_dd_antiderivative(k1, ec0, a_c, b_c);
    let kc1 = first_damage(et0, a_c, b_c_classic);
    let exact_classic_compression = |e: f64| {
        let k = NU * 2f64.sqrt() * e;
        (y_dd_antiderivative(k, et0, a_c, b_c_classic)
            - y_dd_antiderivative(kc1, et0, a_c, b_c_classic))
            / (2.0 * NU * NU)
    };
    type Exact<'a> = &'a dyn Fn(f64) -> f64;
    let cases: [(&str, &Material, f64, Exact); 4] = [
        ("paper, tension", &paper, 5.0 * et0, &exact_tension),
        ("classic, tension", &classic, 5.0 * et0, &exact_tension),
        (
            "paper, compression",
            &paper,
            -3.0e-3,
            &exact_paper_compression,
        ),
        (
            "classic, compression",
            &classic,
            -3.0e-3,
            &exact_classic_compression,
        ),
    ];
    for (what, m, e_end, exact) in cases {
        let want = exact(e_end.abs());
        let errors: Vec<f64> = [200usize, 400, 800]
            .iter()
            .map(|&n| {
                let recs = uniaxial(m, vec![[0.0, 0.0], [1.0, e_end]], n);
                let last = recs.last().unwrap();
                assert!(last.state[2] < 0.99999, "{what}: below D_max");
                (last.dissipated[1] - want) / want
            })
            .collect();
        let orders: Vec<f64> = errors
            .windows(2)
            .map(|w| (w[0] / w[1]).abs().log2())
            .collect();
        eprintln!(
            "{what}: ∫Y dD = {want:.6e} J/m³, relative errors {errors:?}, orders {orders:.2?}"
        );
        assert!(want > 0.0);
        assert!(errors[2].abs() < 1e-4, "{what}: {errors:?}");
        for p in &orders {
            assert!((1.8..2.3).contains(p), "{what}: order {p} ({errors:?})");
        }
    }
}

#[test]
fn rankine_hill_plastic_dissipation_is_the_integral_of_the_strength() {
    // Uniaxial compression along the Eurocode 2 curve (NOTES.md's realistic diagram:
    // f_cm = 38 MPa, ε_c1 = 2.2e-3), hardening to 2e-3: the plastic dissipation is
    // ∫ σ̄(κ) dκ over the path, here by Simpson's rule on the test's own EC2 law with
    // 20 000 intervals. The step's ½(σⁿ + σⁿ⁺¹):Δεᵖ is the trapezoid of that integral:
    // second order in the step (the bilinear test above finds it exact for a linear
    // law).
    let m = mat("model = \"rankine_hill\"\ntension = { law = \"bilinear\", strength = 2.9e6, post_yield_modulus = 1.65e9 }\ncompression = { law = \"ec2\", f_cm = 38.0e6, eps_c1 = 2.2e-3, eps_cu1 = 3.5e-3 }");
    let law = Law::Ec2 {
        fcm: 38e6,
        ec1: 2.2e-3,
        ecu1: 3.5e-3,
    };
    let errors: Vec<f64> = [100usize, 200, 400]
        .iter()
        .map(|&n| {
            let recs = uniaxial(&m, vec![[0.0, 0.0], [1.0, -2.0e-3]], n);
            let last = recs.last().unwrap();
            let kappa = last.state[4];
            let k = 20_000;
            let hstep = kappa / k as f64;
            let simpson: f64 = (0..=k)
                .map(|i| {
                    let w = if i == 0 || i == k {
                        1.0
                    } else if i % 2 == 1 {
                        4.0
                    } else {
                        2.0
                    };
                    w * strength(law, i as f64 * hstep, 0.1)
                })
                .sum::<f64>()
                * hstep
                / 3.0;
            (last.dissipated[2] - simpson) / simpson
        })
        .collect();
    let orders: Vec<f64> = errors
        .windows(2)
        .map(|w| (w[0] / w[1]).abs().log2())
        .collect();
    eprintln!("EC2 plastic dissipation: relative errors {errors:?}, orders {orders:?}");
    assert!(errors[2].abs() < 1e-4, "{errors:?}");
    for p in &orders {
        assert!((1.8..2.3).contains(p), "order {p} ({errors:?})");
    }
}
