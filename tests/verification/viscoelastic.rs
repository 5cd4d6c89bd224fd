//! Global checks of the viscoelastic models: free-vibration decay against the damping
//! ratio the material implies, ledger closure, monotone dissipation, one
//! factorisation per run.
#![allow(clippy::needless_range_loop, clippy::too_many_arguments)]

use rothe::linsolve::Backend;
use rothe::time::backward_euler::BackwardEuler;
use rothe::time::Integrator;

/// An axial bar 1 m x 0.05 m (40x2 Q4, plane stress, ν = 0), E = 1e8, ρ = 1000
/// (c = 316 m/s, first axial mode ω₁ = πc/2L ≈ 497 rad/s), left edge held in x and
/// its lower corner in y, released at t = 0 with a uniform axial velocity.
fn bar(material: &str, dt: f64, t_end: f64) -> String {
    format!(
        r#"
[analysis]
t_end = {t_end}
dt = {dt}
vtk_every = 0
[materials.m]
{material}
E = 1.0e8
nu = 0.0
rho = 1000.0
[[bodies]]
name = "bar"
material = "m"
thickness = 1.0
velocity = [0.1, 0.0]
mesh = {{ kind = "rectangle", size = [1.0, 0.05], divisions = [40, 2] }}
[[supports]]
set = "bar.left"
fix = ["x"]
[[supports]]
set = "bar.bottom_left"
fix = ["y"]
[[probes]]
name = "tip"
at = [1.0, 0.0]
"#
    )
}

/// Runs and returns (t, tip u_x) samples, checking the ledger on every step.
fn run(text: &str) -> (Vec<(f64, f64)>, rothe::energy::Ledger, usize) {
    let model = rothe::config::from_str(text, std::path::Path::new(".")).unwrap();
    let tip = model.probes[0].node;
    let mut be = BackwardEuler::new(&model, Backend::Faer).unwrap();
    let mut s = be.initial_state();
    let mut prev = s.ledger;
    let mut out = Vec::new();
    for _ in 0..model.analysis.n_steps() {
        let rep = be.step_accepted(&mut s).unwrap();
        assert!(
            rep.iterations <= 1,
            "a linear model needs one solve per step: step {} residual {}",
            s.step,
            rep.nl_residual
        );
        let l = &s.ledger;
        assert!(
            l.residual().abs() <= 1e-9 * l.scale(),
            "residual {} scale {}",
            l.residual(),
            l.scale()
        );
        assert!(
            l.dissipated().viscous >= prev.dissipated().viscous,
            "viscous dissipation decreased"
        );
        assert!(l.dissipated().numerical >= prev.dissipated().numerical - 1e-12 * l.scale());
        prev = *l;
        out.push((s.t, s.u[2 * tip]));
    }
    (out, s.ledger, be.factorizations())
}

/// Damping ratio and circular frequency from successive positive peaks after `skip`.
fn measured_damping(samples: &[(f64, f64)], skip: f64) -> (f64, f64) {
    let mut peaks = Vec::new();
    for w in samples.windows(3) {
        if w[0].0 > skip && w[1].1 > w[0].1 && w[1].1 >= w[2].1 && w[1].1 > 0.0 {
            // Parabolic refinement of the peak.
            let (y0, y1, y2) = (w[0].1, w[1].1, w[2].1);
            let denom = y0 - 2.0 * y1 + y2;
            let off = if denom != 0.0 {
                0.5 * (y0 - y2) / denom
            } else {
                0.0
            };
            let h = w[1].0 - w[0].0;
            peaks.push((w[1].0 + off * h, y1 - 0.25 * (y0 - y2) * off));
        }
    }
    assert!(peaks.len() >= 4, "too few peaks: {peaks:?}");
    let n = peaks.len() - 1;
    let delta = (peaks[0].1 / peaks[n].1).ln() / n as f64;
    let period = (peaks[n].0 - peaks[0].0) / n as f64;
    let zeta = delta / (4.0 * std::f64::consts::PI * std::f64::consts::PI + delta * delta).sqrt();
    let omega = 2.0 * std::f64::consts::PI / period / (1.0 - zeta * zeta).sqrt();
    (zeta, omega)
}

#[test]
fn kelvin_voigt_bar_decays_at_the_implied_damping_ratio() {
    // Reference: Kelvin-Voigt η = α C damps a mode of frequency ω with ratio ζ = α ω/2;
    // backward Euler adds ζ_h ≈ ω h/2 of its own (theory/scheme.md). α = 2e-4 s
    // (ζ₁ ≈ 5 %), h = T₁/1000. Higher modes (ζ ∝ ω) die in the first period; the
    // decay of the fundamental over the next periods is measured from the tip peaks.
    let alpha = 2e-4;
    let (samples, ledger, factorizations) = run(&bar(
        &format!("model = \"kelvin_voigt\"\nalpha = {alpha}"),
        1.26e-5,
        0.07,
    ));
    let (zeta, omega) = measured_damping(&samples, 0.015);
    let expected = alpha * omega / 2.0 + omega * 1.26e-5 / 2.0;
    assert!(
        (zeta - expected).abs() < 0.05 * expected,
        "measured ζ = {zeta}, expected {expected} (ω = {omega})"
    );
    assert!((omega - 497.0).abs() < 0.02 * 497.0, "ω = {omega}");
    assert!(
        ledger.dissipated().viscous
            > 0.9
                * (ledger.kinetic_0()
                    - ledger.kinetic()
                    - ledger.elastic()
                    - ledger.dissipated().numerical)
    );
    assert_eq!(
        factorizations, 1,
        "the effective matrix is constant: factorised once"
    );
}

#[test]
fn sls_bar_decays_at_its_loss_factor() {
    // Reference: an SLS with branch α C, dashpot β C has at frequency ω the storage and
    // loss moduli E' = E(1 + α ω²t_r²/(1+ω²t_r²)), E'' = E α ω t_r/(1+ω²t_r²),
    // t_r = β/α; a lightly damped mode decays at ζ ≈ E''/(2E'). With t_r = 2e-5 s
    // and α = 10 every mode of the mesh is damped more than the fundamental (ζ(y)
    // with y = ω t_r peaks near y = 1/sqrt(1+α) and stays above the fundamental's
    // value up to y ≈ 9), so the fundamental is left alone after the first period.
    let (alpha, beta) = (10.0, 2e-4);
    let (samples, _, factorizations) = run(&bar(
        &format!("model = \"sls\"\nalpha = {alpha}\nbeta = {beta}"),
        1.26e-5,
        0.07,
    ));
    let (zeta, omega) = measured_damping(&samples, 0.015);
    let tr = beta / alpha;
    let x = omega * omega * tr * tr;
    let (e1, e2) = (
        1.0 + alpha * x / (1.0 + x),
        alpha * (omega * tr) / (1.0 + x),
    );
    let expected = e2 / (2.0 * e1) + omega * 1.26e-5 / 2.0;
    assert!(
        (zeta - expected).abs() < 0.08 * expected,
        "measured ζ = {zeta}, expected {expected} (ω = {omega})"
    );
    assert_eq!(factorizations, 1);
}

#[test]
fn ledgers_close_for_every_viscoelastic_model() {
    // The balance closes to round-off step by step (checked inside `run`) and the
    // viscous line grows, for each model, including the paper's identity viscosity.
    for m in [
        "model = \"kelvin_voigt\"\nbeta = 1e4",
        "model = \"sls\"\nalpha = 0.5\nbeta = 1e-3",
        "model = \"maxwell\"\nbeta = 1e-2",
        "model = \"kelvin\"\nbeta = 1e-4",
    ] {
        let (_, l, _) = run(&bar(m, 2e-5, 4e-3));
        assert!(l.dissipated().viscous > 0.0, "{m}");
        let total = l.kinetic() + l.elastic() + l.dissipated().total();
        assert!((total - l.kinetic_0()).abs() < 1e-9 * l.kinetic_0(), "{m}");
    }
}

#[test]
fn initial_state_with_prescribed_displacement_is_at_rest() {
    // Eq. (10) starts from ε_d = 0: a displacement prescribed from t = 0 loads the
    // SLS with (1 + α) C ε(u₀) and evolves no history before the first step.
    let alpha = 0.5;
    let text = bar(
        &format!("model = \"sls\"\nalpha = {alpha}\nbeta = 1e-3"),
        1e-5,
        1e-4,
    ) + "[[prescribed]]\nset = \"bar.right\"\ncomponent = \"x\"\nvalue = 1.0e-4\n";
    let model = rothe::config::from_str(&text, std::path::Path::new(".")).unwrap();
    let be = BackwardEuler::new(&model, Backend::Faer).unwrap();
    let s = be.initial_state();
    assert!(
        s.points.iter().all(|p| (0..p.n_points()).all(|g| p
            .committed()
            .history(g)
            .iter()
            .all(|&x| x.abs() < 1e-200))),
        "no dashpot strain at t = 0"
    );
    let mut ku = vec![0.0; s.u.len()];
    be.assembler().pattern.matvec(be.stiffness(), &s.u, &mut ku);
    let scale = ku.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(scale > 0.0);
    for (f, k) in s.f_int.iter().zip(&ku) {
        assert!((f - (1.0 + alpha) * k).abs() <= 1e-9 * scale);
    }
    assert!(s.ledger.elastic_0() > 0.0);
}
