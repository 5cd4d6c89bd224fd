//! What `rothe modes` writes: `modes.csv` and `modes.json` (frequencies, generalised
//! and effective modal masses, what the scenario's step does to each mode), and the
//! shapes for ParaView (`modes.pvd`, one `vtk/mode_*.vtu` per mode, its "time" the
//! mode's number).

use std::fmt::Write as _;
use std::path::Path;

use super::Modes;
use crate::error::{Error, Result};
use crate::model::Model;

/// What a step `h` of a scheme does to an undamped mode of frequency `ω`: its
/// numerical damping ratio and the ratio of the computed to the true period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepEffect {
    /// `ξ̄ = −ln|z| / √(ln²|z| + arg² z)` of the step's amplification `z`.
    pub damping: f64,
    /// `T̄ / T = ωh / arg z`.
    pub period: f64,
}

/// Backward Euler on `ẍ + ω²x = 0`: `z = 1/(1 − iωh)`, so `|z| = (1 + ω²h²)^(−½)` and
/// `arg z = arctan(ωh)` (`theory/scheme.md`, eq. 6 read mode by mode).
pub fn backward_euler(omega: f64, h: f64) -> StepEffect {
    let wh = omega * h;
    if wh == 0.0 {
        return StepEffect {
            damping: 0.0,
            period: 1.0,
        };
    }
    let ln = -0.5 * wh.mul_add(wh, 1.0).ln();
    let arg = wh.atan();
    StepEffect {
        damping: -ln / ln.hypot(arg),
        period: wh / arg,
    }
}

/// The trapezoidal rule: `|z| = 1`, `arg z = 2 arctan(ωh/2)`.
pub fn trapezoidal(omega: f64, h: f64) -> StepEffect {
    let wh = omega * h;
    StepEffect {
        damping: 0.0,
        period: if wh == 0.0 {
            1.0
        } else {
            wh / (2.0 * (0.5 * wh).atan())
        },
    }
}

/// Writes `modes.csv`, `modes.json` and the VTK shapes of `modes` into `dir`;
/// returns the files written.
pub fn write(model: &Model, modes: &Modes, dir: &Path) -> Result<Vec<std::path::PathBuf>> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let h = model.analysis.time.dt;
    let dim = modes.dim;
    let axes = ["x", "y", "z"];
    let mut csv = String::from("index,omega_rad_s,f_hz,period_s,rigid,generalised_mass");
    for a in &axes[..dim] {
        write!(csv, ",eff_mass_{a},eff_mass_{a}_sum").expect("to a string");
    }
    csv.push_str(",be_damping_ratio,be_period_ratio,trapezoidal_period_ratio,residual\n");
    let mut sums = [0.0; 3];
    let mut rows = Vec::new();
    for (i, m) in modes.modes.iter().enumerate() {
        let w = m.omega();
        let f = w / (2.0 * std::f64::consts::PI);
        let period = if w > 0.0 { 1.0 / f } else { f64::INFINITY };
        // The shape written with its largest component 1: its generalised mass.
        let peak = m.shape.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let gm = 1.0 / (peak * peak);
        let (be, tr) = (backward_euler(w, h), trapezoidal(w, h));
        write!(
            csv,
            "{},{:.12e},{:.12e},{:.12e},{},{:.12e}",
            i + 1,
            w,
            f,
            period,
            u8::from(m.rigid),
            gm
        )
        .expect("to a string");
        let mut fractions = Vec::new();
        for r in 0..dim {
            let frac = m.participation[r].powi(2) / modes.total_mass[r];
            sums[r] += frac;
            write!(csv, ",{frac:.9e},{:.9e}", sums[r]).expect("to a string");
            fractions
                .push(serde_json::json!({"direction": axes[r], "fraction": frac, "sum": sums[r]}));
        }
        writeln!(
            csv,
            ",{:.9e},{:.9e},{:.9e},{:.3e}",
            be.damping, be.period, tr.period, m.residual
        )
        .expect("to a string");
        rows.push(serde_json::json!({
            "index": i + 1,
            "omega_rad_s": w,
            "f_hz": f,
            "period_s": if period.is_finite() { serde_json::json!(period) } else { serde_json::Value::Null },
            "rigid": m.rigid,
            "generalised_mass": gm,
            "effective_mass": fractions,
            "backward_euler": {"damping_ratio": be.damping, "period_ratio": be.period},
            "trapezoidal": {"damping_ratio": tr.damping, "period_ratio": tr.period},
            "residual": m.residual,
        }));
    }
    let mut written = Vec::new();
    let path = dir.join("modes.csv");
    std::fs::write(&path, csv).map_err(|e| Error::io(&path, e))?;
    written.push(path);
    let json = serde_json::json!({
        "modes": rows,
        "shift_rad2_s2": modes.shift,
        "lanczos_steps": modes.steps,
        "free_dofs": modes.n_free,
        "mass": if modes.lumped { "lumped" } else { "consistent" },
        "dt": h,
        "total_mass_kg": &modes.total_mass[..dim],
        "stiffness": "linear, at the initial state",
    });
    let path = dir.join("modes.json");
    let text = serde_json::to_string_pretty(&json).expect("plain values");
    std::fs::write(&path, text).map_err(|e| Error::io(&path, e))?;
    written.push(path);
    let mut vtk = crate::output::vtk::VtkSeries::named(dir, &model.mesh, "modes", "mode")?;
    let zero = vec![0.0; model.mesh.n_dofs()];
    let cells = vec![[0.0; 6]; model.mesh.n_elements()];
    for (i, m) in modes.modes.iter().enumerate() {
        let peak = m.shape.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let shape: Vec<f64> = m.shape.iter().map(|x| x / peak).collect();
        vtk.write(i + 1, (i + 1) as f64, &shape, &zero, &[], &cells, &[])?;
    }
    written.push(dir.join("modes.pvd"));
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn backward_eulers_damping_and_period_have_their_limits() {
        // Small ωh: ξ ≈ ωh/2, T̄/T ≈ 1 + (ωh)²/3; large: ξ → 1... of a decaying mode.
        let e = backward_euler(1.0, 1e-3);
        assert!((e.damping - 5e-4).abs() < 1e-9, "{e:?}");
        assert!((e.period - (1.0 + 1e-6 / 3.0)).abs() < 1e-12, "{e:?}");
        let t = trapezoidal(1.0, 1e-3);
        assert!((t.period - (1.0 + 1e-6 / 12.0)).abs() < 1e-12, "{t:?}");
        let big = backward_euler(1.0, 1e3);
        assert!(big.damping > 0.9 && big.period > 600.0, "{big:?}");
    }
}
