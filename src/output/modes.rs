//! What `rothe modes` writes: `modes.csv` and `modes.json` (frequencies, generalised
//! and effective modal masses, what the scenario's step does to each mode), and the
//! shapes for ParaView (`modes.pvd`, one `vtk/mode_*.vtu` per mode, its "time" the
//! mode's number), and two charts (`spectrum`, `step_effect`).

use std::fmt::Write as _;
use std::path::Path;

use crate::error::{Error, Result};
use crate::modal::step::{backward_euler, generalized_alpha, trapezoidal};
use crate::modal::Modes;
use crate::model::Model;

/// Writes `modes.csv`, `modes.json`, the VTK shapes of `modes` and the charts into
/// `dir`; returns the files written.
pub fn write(model: &Model, modes: &Modes, dir: &Path) -> Result<Vec<std::path::PathBuf>> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let (csv, json) = tables(model, modes);
    let mut written = Vec::new();
    let path = dir.join("modes.csv");
    std::fs::write(&path, csv).map_err(|e| Error::io(&path, e))?;
    written.push(path);
    let path = dir.join("modes.json");
    let text = serde_json::to_string_pretty(&json).expect("plain values");
    std::fs::write(&path, text).map_err(|e| Error::io(&path, e))?;
    written.push(path);
    let mut vtk = super::vtk::VtkSeries::named(dir, &model.mesh, "modes", "mode")?;
    let zero = vec![0.0; model.mesh.n_dofs()];
    let cells = vec![[0.0; 6]; model.mesh.n_elements()];
    for m in &modes.modes {
        let peak = m.shape.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let shape: Vec<f64> = m.shape.iter().map(|x| x / peak).collect();
        vtk.write(m.number, m.number as f64, &shape, &zero, &[], &cells, &[])?;
    }
    written.push(dir.join("modes.pvd"));
    let (h, rho_inf) = (model.analysis.time.dt, model.analysis.time.rho_inf);
    written.extend(plots(modes, h, rho_inf, dir)?);
    Ok(written)
}

/// What `modes.json` holds, as a value (the Python module's `Modes.info`).
pub fn summary(model: &Model, modes: &Modes) -> serde_json::Value {
    tables(model, modes).1
}

/// The text of `modes.csv` and the value of `modes.json`.
fn tables(model: &Model, modes: &Modes) -> (String, serde_json::Value) {
    let h = model.analysis.time.dt;
    let dim = modes.dim;
    let axes = ["x", "y", "z"];
    let mut csv = String::from("index,omega_rad_s,f_hz,period_s,rigid,generalised_mass");
    for a in &axes[..dim] {
        write!(csv, ",eff_mass_{a},eff_mass_{a}_sum").expect("to a string");
    }
    csv.push_str(
        ",be_damping_ratio,be_period_ratio,trapezoidal_period_ratio,ga_damping_ratio,\
         ga_period_ratio,residual\n",
    );
    let rho_inf = model.analysis.time.rho_inf;
    let mut sums = [0.0; 3];
    let mut rows = Vec::new();
    for m in &modes.modes {
        let w = m.omega();
        let f = w / (2.0 * std::f64::consts::PI);
        let period = if w > 0.0 { 1.0 / f } else { f64::INFINITY };
        // The shape written with its largest component 1: its generalised mass.
        let peak = m.shape.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let gm = 1.0 / (peak * peak);
        let (be, tr) = (backward_euler(w, h), trapezoidal(w, h));
        let ga = generalized_alpha(w, h, rho_inf);
        write!(
            csv,
            "{},{:.12e},{:.12e},{:.12e},{},{:.12e}",
            m.number,
            w,
            f,
            period,
            u8::from(m.rigid),
            gm
        )
        .expect("to a string");
        let mut fractions = Vec::new();
        for r in 0..dim {
            // No free mass along a direction (all of it fixed): nothing to take part.
            let frac = if modes.total_mass[r] > 0.0 {
                m.participation[r].powi(2) / modes.total_mass[r]
            } else {
                0.0
            };
            sums[r] += frac;
            write!(csv, ",{frac:.9e},{:.9e}", sums[r]).expect("to a string");
            fractions
                .push(serde_json::json!({"direction": axes[r], "fraction": frac, "sum": sums[r]}));
        }
        writeln!(
            csv,
            ",{:.9e},{:.9e},{:.9e},{:.9e},{:.9e},{:.3e}",
            be.damping, be.period, tr.period, ga.damping, ga.period, m.residual
        )
        .expect("to a string");
        rows.push(serde_json::json!({
            "index": m.number,
            "omega_rad_s": w,
            "f_hz": f,
            "period_s": if period.is_finite() { serde_json::json!(period) } else { serde_json::Value::Null },
            "rigid": m.rigid,
            "generalised_mass": gm,
            "effective_mass": fractions,
            "backward_euler": {"damping_ratio": be.damping, "period_ratio": be.period},
            "trapezoidal": {"damping_ratio": tr.damping, "period_ratio": tr.period},
            "generalized_alpha": {"rho_inf": rho_inf, "damping_ratio": ga.damping, "period_ratio": ga.period},
            "residual": m.residual,
        }));
    }
    let json = serde_json::json!({
        "modes": rows,
        "shift_rad2_s2": modes.shift,
        "lanczos_steps": modes.steps,
        "free_dofs": modes.n_free,
        "mass": if modes.lumped { "lumped" } else { "consistent" },
        "dt": h,
        "total_mass_kg": &modes.total_mass[..dim],
        "stiffness": "linear, at the initial state",
        "note": crate::modal::history_note(model),
        "sturm": {
            "below_rad2_s2": if modes.sturm.below.is_finite() { serde_json::json!(modes.sturm.below) } else { serde_json::Value::Null },
            "above_rad2_s2": modes.sturm.above,
            "eigenvalues_counted": modes.sturm.count,
        },
    });
    (csv, json)
}

/// `spectrum.png/svg` (the frequencies by mode number) and `step_effect.png/svg`
/// (backward Euler's and generalized-α's damping ratios and the three schemes'
/// period errors at the scenario's step, against the frequency): which modes the
/// step resolves.
fn plots(modes: &Modes, h: f64, rho_inf: f64, dir: &Path) -> Result<Vec<std::path::PathBuf>> {
    use crate::plot::{draw, Figure, Series, Style};
    let elastic: Vec<(usize, f64)> = modes
        .modes
        .iter()
        .filter(|m| !m.rigid)
        .map(|m| (m.number, m.omega()))
        .collect();
    let hz = |w: f64| w / (2.0 * std::f64::consts::PI);
    let spectrum = Figure::new("Eigenfrequencies", "mode", "f [Hz]").with(Series::new(
        "elastic modes",
        elastic.iter().map(|&(i, w)| (i as f64, hz(w))).collect(),
        Style::LineWithMarkers,
    ));
    let f: Vec<f64> = elastic.iter().map(|&(_, w)| hz(w)).collect();
    let be: Vec<_> = elastic.iter().map(|&(_, w)| backward_euler(w, h)).collect();
    let tr: Vec<_> = elastic.iter().map(|&(_, w)| trapezoidal(w, h)).collect();
    let ga: Vec<_> = elastic
        .iter()
        .map(|&(_, w)| generalized_alpha(w, h, rho_inf))
        .collect();
    // Log–log: backward Euler's damping rises as ωh (slope 1), the period errors
    // as (ωh)² (slope 2), generalized-α's damping as (ωh)³; values that are not
    // positive (round-off at the lowest modes) are left out.
    let series = |label: String, y: Vec<f64>| {
        let points = f
            .iter()
            .zip(y)
            .filter(|&(_, y)| y > 0.0)
            .map(|(&x, y)| (x, y))
            .collect();
        Series::new(label, points, Style::LineWithMarkers)
    };
    let ga_label = |what: &str| format!("generalized-alpha (rho_inf {rho_inf}): {what}");
    let effect = Figure::new(
        format!("What the step h = {h:e} s does to each mode"),
        "f [Hz]",
        "ratio",
    )
    .log_log()
    .with(series(
        "backward Euler: damping ratio".into(),
        be.iter().map(|e| e.damping).collect(),
    ))
    .with(series(
        "backward Euler: period error T'/T - 1".into(),
        be.iter().map(|e| e.period - 1.0).collect(),
    ))
    .with(series(
        "trapezoidal: period error T'/T - 1".into(),
        tr.iter().map(|e| e.period - 1.0).collect(),
    ))
    .with(series(
        ga_label("damping ratio"),
        ga.iter().map(|e| e.damping).collect(),
    ))
    .with(series(
        ga_label("period error T'/T - 1"),
        ga.iter().map(|e| e.period - 1.0).collect(),
    ));
    let mut out = Vec::new();
    out.extend(draw(&spectrum, &dir.join("spectrum"))?);
    out.extend(draw(&effect, &dir.join("step_effect"))?);
    Ok(out)
}
